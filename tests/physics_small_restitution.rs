//! Small restitution (issue #11, point 3). An explicit dashpot stiffer than the step can follow
//! reverses the approach within a step and creates energy: restitution 1e-3 used to shoot a
//! sphere dropped at 0.5 m/s out at many times its speed. Now the dashpot is held to what the
//! step can take (γ dt/m* ≤ ½, `contact_law::DASHPOT_BOUND`), the automatic step resolves the
//! dashpot of restitutions down to 0.01, and below that (down to e = 0, perfectly plastic) a
//! contact gets the strongest dashpot the step can take. The ledger books each dashpot's work
//! against the velocity it met, so it closes whatever the dashpot's strength.

use polydem::run::run;
use polydem::scene::Scene;

/// A glass sphere hitting a plate head-on at 0.5 m/s with restitution `e` (no gravity), run as
/// `polydem run` would, with `extra` lines in `[simulation]` and `law` in `[contact]`. Returns
/// the normal velocity after the impact, the ledger's drift relative to the impact energy, and
/// the time step.
fn impact(e: f64, extra: &str, law: &str) -> (f64, f64, f64) {
    let text = format!(
        r#"
[simulation]
duration = 0.01
gravity = [0.0, 0.0, 0.0]
threads = 1
{extra}
[contact]
{law}
[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 5.0e6
poisson_ratio = 0.25
restitution = {e:?}
friction = 0.3
[[plane]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
material = "glass"
[[particle]]
radius = 0.005
material = "glass"
position = [0.0, 0.0, 0.0051]
velocity = [0.0, 0.0, -0.5]
"#
    );
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("impact.toml");
    std::fs::write(&file, text).unwrap();
    let mut prepared = Scene::load(&file).unwrap().build().unwrap();
    let dt = prepared.world.time_step();
    let start = prepared.world.energy();
    run(&mut prepared, &dir.path().join("out"), |_| {}).unwrap_or_else(|e| panic!("{e}"));
    let end = prepared.world.energy();
    (
        prepared.world.bodies().velocity[0].z,
        (end.total() - start.total()) / start.kinetic_translational,
        dt,
    )
}

const HERTZ: &str = "";
const LINEAR: &str = "normal = \"linear\"\nstiffness = 1000.0";

#[test]
fn ordinary_restitutions_keep_their_rebound() {
    for e in [0.5, 0.9] {
        let (v, drift, _) = impact(e, "", HERTZ);
        // The automatic step resolves an impact in 25 steps or more; the rebound is within 3 %
        // of e × 0.5 m/s (docs/validation.md, time-step accuracy).
        assert!(
            (v - e * 0.5).abs() < 0.03 * e * 0.5,
            "e = {e}: rebound {v} m/s"
        );
        assert!(drift.abs() < 0.01, "e = {e}: ledger off by {drift}");
    }
}

/// The automatic step gives strongly damped pairs the steps their dashpot needs: restitutions
/// from 0.05 down to 0.01 rebound within 5 % (Hertz; measured 0.3–3 %), and the step is smaller
/// than for e = 0.5.
#[test]
fn the_automatic_step_resolves_strong_dashpots() {
    let (_, _, ordinary_step) = impact(0.5, "", HERTZ);
    for e in [0.05, 0.03, 0.01] {
        let (v, drift, dt) = impact(e, "", HERTZ);
        assert!(
            dt < ordinary_step,
            "e = {e}: step {dt} not below {ordinary_step}"
        );
        assert!((v - e * 0.5).abs() < 0.05 * e * 0.5, "e = {e}: rebound {v}");
        assert!(drift.abs() < 1e-3, "e = {e}: ledger off by {drift}");
    }
}

/// Regression test of issue #11 point 3: restitutions from 1e-3 down to 0 no longer create
/// energy. Whatever the step (automatic, or forced at the step of e = 0.5, far too coarse for
/// these dashpots), the sphere stays on the plate: it leaves at under 2 % of its impact speed
/// (measured: 0.05 % Hertz, 0.3 % linear at the automatic step; 1.3 % linear at the forced
/// one, where the strongest dashpot the step takes is that of e ≈ 0.01), and the ledger closes
/// to 1e-3 of the impact energy. A finer step brings the rebound towards e.
#[test]
fn tiny_restitutions_and_zero_are_plastic_and_keep_the_ledger() {
    let (_, _, ordinary_step) = impact(0.5, "", HERTZ);
    let forced = format!("time_step = {ordinary_step:e}\nforce_time_step = true");
    for law in [HERTZ, LINEAR] {
        for e in [1e-3, 1e-6, 0.0] {
            for extra in ["", forced.as_str()] {
                let (v, drift, _) = impact(e, extra, law);
                assert!(
                    v.abs() < 0.02 * 0.5,
                    "{law} e = {e} {extra}: leaves at {v} m/s"
                );
                assert!(drift.abs() < 1e-3, "{law} e = {e} {extra}: ledger {drift}");
            }
        }
    }
    let (coarse, _, _) = impact(0.0, "", HERTZ);
    let (fine, _, _) = impact(0.0, "time_step = 1.0e-6", HERTZ);
    assert!(fine.abs() < coarse.abs() * 0.1, "{fine} vs {coarse}");
}

/// Many contacts at once, each damped as strongly as the step allows: 150 spheres with e = 0
/// poured into a box settle into a bed (no body thrown about by an unstable dashpot) and the
/// ledger closes to 1 % of the energy dissipated.
#[test]
fn a_plastic_pour_settles_and_keeps_the_ledger() {
    let text = r#"
[simulation]
duration = 0.5
gravity = [0.0, 0.0, -9.81]
threads = 1
output_interval = 0.05
[[material]]
name = "clay"
density = 2000.0
youngs_modulus = 5.0e6
poisson_ratio = 0.3
restitution = 0.0
friction = 0.4
[[plane]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
material = "clay"
[[plane]]
point = [-0.025, 0.0, 0.0]
normal = [1.0, 0.0, 0.0]
material = "clay"
[[plane]]
point = [0.025, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]
material = "clay"
[[plane]]
point = [0.0, -0.025, 0.0]
normal = [0.0, 1.0, 0.0]
material = "clay"
[[plane]]
point = [0.0, 0.025, 0.0]
normal = [0.0, -1.0, 0.0]
material = "clay"
[[insert]]
method = "random"
material = "clay"
region_min = [-0.02, -0.02, 0.01]
region_max = [0.02, 0.02, 0.09]
count = 150
radius = 0.003
seed = 3
"#;
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("pour.toml");
    std::fs::write(&file, text).unwrap();
    let mut prepared = Scene::load(&file).unwrap().build().unwrap();
    let start = prepared.world.energy();
    run(&mut prepared, &dir.path().join("out"), |_| {}).unwrap_or_else(|e| panic!("{e}"));
    let w = &prepared.world;
    let end = w.energy();
    let bodies = w.bodies();
    assert_eq!(bodies.len(), 150);
    let fastest = bodies
        .velocity
        .iter()
        .map(|v| v.length())
        .fold(0.0, f64::max);
    assert!(fastest < 0.05, "a body still moves at {fastest} m/s");
    let highest = bodies.position.iter().map(|p| p.z).fold(0.0, f64::max);
    assert!(highest < 0.05, "a body at {highest} m: not settled");
    let drift = end.total() - start.total();
    println!(
        "plastic pour: fastest {fastest:.2e} m/s, ledger {:.2e} of the dissipated {:.3e} J",
        drift / end.dissipated,
        end.dissipated
    );
    assert!(
        drift.abs() < 0.01 * end.dissipated,
        "ledger off by {drift} J of {} J dissipated",
        end.dissipated
    );
}
