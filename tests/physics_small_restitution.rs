//! Small restitution (issue #11, point 3): a dashpot stiffer than the explicit step can take used
//! to reverse the approach within a step and create energy (restitution 1e-3…1e-6 shot a sphere
//! dropped at 0.5 m/s out at up to 39 m/s). Now the dashpot is held to what the step can take:
//! tiny restitutions no longer throw bodies out, and ordinary restitutions keep their calibrated
//! rebound and a closed ledger.

use polydem::scene::Scene;

/// A glass sphere hitting a plate head-on at 0.5 m/s with restitution `e` (Hertz, no gravity, the
/// automatic step); returns the normal velocity after the impact and the ledger's drift relative
/// to the impact energy.
fn impact(e: f64, normal: &str) -> (f64, f64) {
    impact_with(e, normal, "")
}

/// As [`impact`], with `extra` lines in `[simulation]` (a time step).
fn impact_with(e: f64, normal: &str, extra: &str) -> (f64, f64) {
    let stiffness = if normal == "linear" {
        "stiffness = 1000.0"
    } else {
        ""
    };
    let text = format!(
        r#"
[simulation]
duration = 0.01
gravity = [0.0, 0.0, 0.0]
threads = 1
{extra}
[contact]
normal = "{normal}"
{stiffness}
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
    let w = &mut prepared.world;
    let start = w.energy();
    let steps = (0.01 / w.time_step()).round() as u64;
    w.run_steps(steps);
    let end = w.energy();
    let impact_energy = start.kinetic_translational;
    (
        w.bodies().velocity[0].z,
        (end.total() - start.total()) / impact_energy,
    )
}

#[test]
fn tiny_restitutions_do_not_throw_bodies_out() {
    for normal in ["hertz", "linear"] {
        for e in [1e-6, 1e-4, 1e-3] {
            let (v, drift) = impact(e, normal);
            // Rest, or a rebound far below the impact speed: at most what the elastic energy of
            // one step's approach (0.5 m/s × dt) gives back, a few per cent.
            assert!(v.abs() < 0.02 * 0.5, "{normal} e = {e}: leaves at {v} m/s");
            // (The ledger books too much dissipation where the dashpot is held to its bound, up to
            // the impact energy: see normal::dissipated. Not asserted here; issue #11.)
            let _ = drift;
        }
    }
}

#[test]
fn ordinary_restitutions_keep_their_rebound() {
    for normal in ["hertz", "linear"] {
        for e in [0.5, 0.9] {
            let (v, drift) = impact(e, normal);
            // The automatic step resolves an impact in 25 steps or more; the rebound is within
            // 3 % of e × 0.5 m/s (docs/validation.md, time-step accuracy).
            assert!(
                (v - e * 0.5).abs() < 0.03 * e * 0.5 + 1e-6,
                "{normal} e = {e}: rebound {v} m/s, expected {}",
                e * 0.5
            );
            assert!(
                drift.abs() < 0.01,
                "{normal} e = {e}: ledger off by {drift}"
            );
        }
    }
}

/// e = 0.01 is still the calibrated rebound once the impact is resolved finely enough: the
/// automatic step gives 8 % less (a heavily damped impact is short, see docs/validation.md); a
/// quarter of it gives the rebound within 3 %, and the bound on the dashpot does not get in the
/// way.
#[test]
fn a_heavily_damped_impact_converges_to_its_restitution() {
    let (v_auto, _) = impact(0.01, "hertz");
    let (v, drift) = impact_with(0.01, "hertz", "time_step = 1.0e-5");
    assert!((v - 0.005).abs() < 0.03 * 0.005, "rebound {v} m/s");
    assert!(
        (v - 0.005).abs() < (v_auto - 0.005).abs(),
        "{v} vs {v_auto} at the auto step"
    );
    assert!(drift < 0.01, "the total grew by {drift}");
}
