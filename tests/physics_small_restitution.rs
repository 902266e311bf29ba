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
    impact_from(0.0051, e, extra, law, "")
}

/// [`impact`] with the sphere's centre starting at `height` (0.0051: just above the plate), and
/// `more` at the end of the scene.
fn impact_from(height: f64, e: f64, extra: &str, law: &str, more: &str) -> (f64, f64, f64) {
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
position = [0.0, 0.0, {height:?}]
velocity = [0.0, 0.0, -0.5]
{more}
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

/// A contact found between steps (here before the first: the sphere starts touching the plate,
/// on its way in) gets a bounded dashpot too. Those forces are found with histories that advance
/// by nothing, and the bound used to be taken on that zero interval: with e = 0 the force was
/// infinite and the sphere's state NaN after the first step (issue #11, jacks with e = 0). The
/// dashpot found before the first step acts over one half kick only, and the ledger books it so
/// (it was off by 6 % of the impact energy, by 56 % when the force was booked over a whole step).
#[test]
fn a_plastic_contact_found_between_steps_is_bounded() {
    for law in [HERTZ, LINEAR] {
        let tolerance = "initial_overlap_tolerance = 0.01";
        let (v, drift, _) = impact_from(0.004_99, 0.0, tolerance, law, "");
        assert!(v.abs() < 0.02 * 0.5, "{law}: leaves at {v} m/s");
        assert!(drift.abs() < 1e-3, "{law}: ledger {drift}");
    }
}

/// Forces found again between steps in the middle of an impact (a small sphere added far away
/// every 0.2 ms) replace the last step's for one half kick: the ledger books each over its half
/// step, and what the change of force gives the kinetic energy beyond that work. It closes to
/// 1e-4 of the impact energy (measured: under 5e-5); booking the new dashpot force over a whole
/// step and dropping the old one put 12 % of a plastic impact's energy out of it.
#[test]
fn forces_found_again_during_an_impact_keep_the_ledger() {
    let insertions = r#"
[[insert]]
method = "random"
material = "glass"
region_min = [0.1, 0.1, 0.1]
region_max = [0.5, 0.5, 0.5]
count = 1
radius = 0.001
seed = 3
every = 0.0002
until = 0.005
"#;
    for law in [HERTZ, LINEAR] {
        for e in [0.0, 0.01, 0.1] {
            let (v, drift, _) = impact_from(0.0051, e, "", law, insertions);
            assert!(
                (v - e * 0.5).abs() < 0.05 * 0.5,
                "{law} e = {e}: rebound {v}"
            );
            assert!(drift.abs() < 1e-4, "{law} e = {e}: ledger {drift}");
        }
    }
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

/// Regression test of issue #11 (its last point): jacks poured into a box with restitution 0
/// blew up at the first insertion among touching bodies (`examples/jacks_box.toml` at
/// t = 0.12 s). After bodies are added the forces are found again before the next step, with
/// histories that advance by nothing (dt = 0), and the dashpots were bounded on that zero
/// interval: no bound at all, and with e = 0 (an infinite dashpot, held to the bound) an infinite
/// force. Now the bound is taken on the world's step, over which the force acts. Three batches
/// of three jacks, the later ones landing on the first: no body leaves faster than the fall
/// allows, the bodies come to rest, and the ledger closes.
#[test]
fn jacks_with_zero_restitution_stay_stable() {
    for e in [0.0, 1e-3] {
        let text = format!(
            r#"
[simulation]
duration = 0.25
gravity = [0.0, 0.0, -9.81]
threads = 1
output_interval = 0.05
[[material]]
name = "plastic"
density = 1200.0
youngs_modulus = 1.0e6
poisson_ratio = 0.3
restitution = {e:?}
friction = 0.5
[shape.jack]
type = "mesh"
file = "data/jack.stl"
scale = 0.001
nonconvex = true
[[plane]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
material = "plastic"
[[plane]]
point = [0.0, 0.0, 0.0]
normal = [1.0, 0.0, 0.0]
material = "plastic"
[[plane]]
point = [0.06, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]
material = "plastic"
[[plane]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
material = "plastic"
[[plane]]
point = [0.0, 0.06, 0.0]
normal = [0.0, -1.0, 0.0]
material = "plastic"
[[insert]]
method = "random"
shape = "jack"
material = "plastic"
region_min = [0.001, 0.001, 0.011]
region_max = [0.059, 0.059, 0.07]
count = 3
seed = 1
every = 0.03
until = 0.06
"#
        );
        let dir = tempfile::tempdir().unwrap();
        let data = dir.path().join("data");
        std::fs::create_dir_all(&data).unwrap();
        let jack = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data/jack.stl");
        std::fs::copy(jack, data.join("jack.stl")).unwrap();
        let file = dir.path().join("jacks.toml");
        std::fs::write(&file, text).unwrap();
        let mut prepared = Scene::load(&file).unwrap().build().unwrap();
        let start = prepared.world.energy();
        // The fastest any body is during the run, seen after every chunk of steps.
        let mut fastest = 0.0f64;
        run(&mut prepared, &dir.path().join("out"), |event| {
            if let polydem::run::RunEvent::Progress(w) = event {
                let v = w.bodies().velocity.iter().map(|v| v.length());
                fastest = v.fold(fastest, f64::max);
            }
        })
        .unwrap_or_else(|err| panic!("e = {e}: {err}"));
        let w = &prepared.world;
        let end = w.energy();
        assert_eq!(w.bodies().len(), 9, "e = {e}");
        // Free fall from the top of the region (7 cm) gives 1.2 m/s.
        assert!(fastest < 1.3, "e = {e}: a body reached {fastest} m/s");
        let kinetic = end.kinetic_translational + end.kinetic_rotational;
        let drift = end.total() - start.total();
        println!(
            "jacks e = {e}: fastest {fastest:.3} m/s, kinetic at the end {kinetic:.2e} J, ledger \
             {:.2e} of the dissipated {:.3e} J",
            drift / end.dissipated,
            end.dissipated
        );
        assert!(
            kinetic < 1e-2 * end.dissipated,
            "e = {e}: still {kinetic} J of kinetic energy"
        );
        assert!(
            drift.abs() < 1e-2 * end.dissipated,
            "e = {e}: ledger off by {drift} J of {} J dissipated",
            end.dissipated
        );
    }
}
