//! Bodies that arrive during a run (timed and repeated insertions) and leave it (an open
//! boundary), driven through the scene file as a user would.

use polydem::run::{run, RunEvent};
use polydem::scene::Scene;
use std::path::Path;

const HOPPER: &str = r#"
[simulation]
duration = 0.3
time_step = "auto"
output_interval = 0.05

[[material]]
name = "beads"
density = 2500.0
youngs_modulus = 1.0e7
poisson_ratio = 0.25
restitution = 0.5
friction = 0.4

# A tilted chute; what slides off its lower end falls out of the domain.
[[plane]]
point = [0.0, 0.0, 0.0]
normal = [0.3, 0.0, 1.0]
material = "beads"

[domain]
min = [-0.1, -0.05, -0.05]
max = [0.1, 0.05, 0.2]

# 20 beads every 0.05 s from t = 0.02 s until t = 0.17 s: four insertions.
[[insert]]
method = "random"
material = "beads"
region_min = [-0.05, -0.03, 0.06]
region_max = [0.05, 0.03, 0.1]
count = 20
radius = 0.004
seed = 9
time = 0.02
every = 0.05
until = 0.17

# One bead present from the start so the scene has a body at t = 0.
[[particle]]
radius = 0.004
material = "beads"
position = [0.0, 0.0, 0.15]
"#;

#[test]
fn timed_insertions_and_open_boundary() {
    let scene = Scene::parse(Path::new("hopper.toml"), HOPPER.to_string()).unwrap();
    let mut prepared = scene.build().unwrap();
    assert_eq!(prepared.world.bodies().len(), 1);
    let dir = tempfile::tempdir().unwrap();
    let mut insertions = Vec::new();
    let mut most = 0;
    run(&mut prepared, dir.path(), |event| match event {
        RunEvent::Inserted(r) => insertions.push(r.clone()),
        RunEvent::Progress(w) => most = most.max(w.bodies().len()),
        _ => {}
    })
    .unwrap();

    let times: Vec<f64> = insertions.iter().map(|r| r.time).collect();
    assert_eq!(insertions.len(), 4, "insertions at {times:?}");
    for (r, expected) in insertions.iter().zip([0.02, 0.07, 0.12, 0.17]) {
        // Insertions happen at the first step boundary at or after their time.
        assert!(
            (r.time - expected).abs() <= prepared.world.time_step(),
            "{r:?}"
        );
        assert_eq!(r.inserted, 20);
        assert!(r.shortfall.is_none());
    }
    let w = &prepared.world;
    // Every body that came in is still there or was counted out, and ids are never reused.
    assert!(
        w.bodies_removed() > 0,
        "beads should have left the chute's lower end"
    );
    assert_eq!(w.bodies().len() as u64 + w.bodies_removed(), 81);
    let mut ids = w.bodies().id.clone();
    ids.sort_unstable();
    ids.dedup();
    assert_eq!(ids.len(), w.bodies().len());
    assert!(ids.iter().all(|&id| id < 81));
    // Everyone left is inside the domain.
    let domain = w.domain().unwrap();
    assert!(w
        .bodies()
        .position
        .iter()
        .all(|x| x.cmpge(domain.min).all() && x.cmple(domain.max).all()));
    // The ledger closes with the energy brought in and carried out.
    let e = w.energy();
    assert!(e.inserted > 0.0 && e.removed != 0.0);
    // Total at the start is the first bead's energy; the scale of what moved through the ledger
    // is everything that came in. 1 % is the ledger tolerance of the energy tests.
    let scale = e.inserted + initial_energy();
    let drift = (e.total() - initial_energy()).abs() / scale;
    println!("ledger drift {drift:.3e} of {scale:.3e} J; {e:?}");
    assert!(drift < 0.01, "ledger drift {drift}");
    assert!(most > 20);
    assert!(dir.path().join("energy.csv").exists());
}

/// Energy of the single bead present at the start (its potential energy above the origin).
fn initial_energy() -> f64 {
    let m = 2500.0 * 4.0 / 3.0 * std::f64::consts::PI * 0.004f64.powi(3);
    m * 9.81 * 0.15
}
