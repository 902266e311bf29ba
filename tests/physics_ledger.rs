//! The energy ledger closes or the scene says why (issue #11, point 4), one test per case that
//! used to break it:
//! - overlaps tolerated at the start were not booked as elastic energy, so the total jumped at the
//!   first step (and the watchdog stopped the run);
//! - 20 m cubes of E = 10 MPa falling hundreds of metres gained 7× their energy: the overlaps
//!   reached several times the cubes' size, where no contact law holds; such scenes are refused,
//!   naming the modulus that would do;
//! - 10 µm jacks booked more dissipated energy than the system ever held;
//! - damped pours of non-convex bodies were off by 1–2 % of the energy dissipated: the dashpots'
//!   work was booked against the predicted end-of-step velocity, which misses the step's own
//!   forces (now booked a step late against the velocity they met).

use polydem::run::run;
use polydem::scene::Scene;
use std::path::{Path, PathBuf};

/// The scene `text` written to a folder that also holds the examples' meshes.
fn scene_file(dir: &Path, text: &str) -> PathBuf {
    let data = dir.join("data");
    std::fs::create_dir_all(&data).unwrap();
    let jack = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data/jack.stl");
    std::fs::copy(jack, data.join("jack.stl")).unwrap();
    let file = dir.join("scene.toml");
    std::fs::write(&file, text).unwrap();
    file
}

/// Runs `text` as `polydem run` would; returns the ledger at the start and at the end.
fn run_scene(text: &str) -> (polydem::energy::EnergyReport, polydem::energy::EnergyReport) {
    let dir = tempfile::tempdir().unwrap();
    let file = scene_file(dir.path(), text);
    let mut prepared = Scene::load(&file)
        .unwrap()
        .build()
        .unwrap_or_else(|e| panic!("{e}"));
    let start = prepared.world.energy();
    run(&mut prepared, &dir.path().join("out"), |_| {}).unwrap_or_else(|e| panic!("{e}"));
    (start, prepared.world.energy())
}

const MATERIAL: &str = r#"
[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 5.0e6
poisson_ratio = 0.25
restitution = 1.0
friction = 0.3
"#;

/// Two spheres overlapping by a fifth of their radius at the start fly apart: the spring's energy
/// is in the first report, and the ledger closes through the release.
#[test]
fn overlaps_at_the_start_are_booked_as_elastic_energy() {
    let text = format!(
        r#"
[simulation]
duration = 0.01
gravity = [0.0, 0.0, 0.0]
initial_overlap_tolerance = 0.5
threads = 1
{MATERIAL}
[[particle]]
radius = 0.005
material = "glass"
position = [0.0, 0.0, 0.0]
[[particle]]
radius = 0.005
material = "glass"
position = [0.0, 0.0, 0.009]
"#
    );
    let (start, end) = run_scene(&text);
    // Hertz: 8/15 E* δ² √(R* δ) for δ = 1 mm, R* = 2.5 mm, E* = E/(2(1 − ν²)).
    let e_star = 5.0e6 / (2.0 * (1.0 - 0.25f64 * 0.25));
    let expected = 8.0 / 15.0 * e_star * 1e-6 * (2.5e-3f64 * 1e-3).sqrt();
    assert!(
        (start.elastic - expected).abs() < 1e-9 * expected,
        "{} vs {expected}",
        start.elastic
    );
    assert_eq!(end.elastic, 0.0, "the spheres have flown apart");
    // A release at 1.3 m/s at the step chosen for resting bodies: resolved to about 1 %.
    let drift = (end.total() - start.total()) / start.total();
    assert!(drift.abs() < 0.02, "ledger off by {drift}");
}

/// Regression test of issue #11 point 4: 20 m cubes of E = 10 MPa dropped from 400 m would
/// overlap by 2.4 times their radius; the scene is refused with the modulus that would do.
#[test]
fn bodies_too_soft_for_their_size_and_speed_are_refused() {
    let text = r#"
[simulation]
duration = 12.0
gravity = [0.0, 0.0, -9.81]
[[material]]
name = "stone"
density = 2600.0
youngs_modulus = 1.0e7
poisson_ratio = 0.25
restitution = 0.4
friction = 0.6
[shape.cube]
type = "box"
edges = [20.0, 20.0, 20.0]
[[plane]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
material = "stone"
[[particle]]
shape = "cube"
material = "stone"
position = [0.0, 0.0, 400.0]
"#;
    let dir = tempfile::tempdir().unwrap();
    let file = scene_file(dir.path(), text);
    let err = match Scene::load(&file).unwrap().build() {
        Ok(_) => panic!("a 20 m cube of 10 MPa falling 400 m was accepted"),
        Err(e) => e.to_string(),
    };
    for needle in [
        "scene.toml:8",
        "youngs_modulus",
        "too soft",
        "% of the radius",
        "give 'stone' a youngs_modulus of at least",
    ] {
        assert!(err.contains(needle), "missing {needle:?} in: {err}");
    }
    // The advice holds: at the modulus it names the scene is accepted.
    let advised: f64 = err
        .split("at least ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no modulus in: {err}"));
    let stiffer = text.replace(
        "youngs_modulus = 1.0e7",
        &format!("youngs_modulus = {advised:e}"),
    );
    std::fs::write(&file, stiffer).unwrap();
    Scene::load(&file)
        .unwrap()
        .build()
        .unwrap_or_else(|e| panic!("at the advised modulus: {e}"));
}

/// A damped pour of non-convex bodies under the vertex law, `size` the jacks' scale (1e-3: jacks
/// of 20 mm; 5e-7: of 10 µm), box and fall scaled with them. Returns the ledger's drift relative
/// to the energy dissipated, and the energy dissipated relative to the energy the bodies had
/// (potential above the floor).
fn jack_pour(scale: f64, duration: f64) -> (f64, f64) {
    let l = scale * 80.0; // the box's side: four jacks
    let text = format!(
        r#"
[simulation]
duration = {duration:e}
gravity = [0.0, 0.0, -9.81]
threads = 1
[[material]]
name = "plastic"
density = 1200.0
youngs_modulus = 1.0e6
poisson_ratio = 0.3
restitution = 0.4
friction = 0.5
[shape.jack]
type = "mesh"
file = "data/jack.stl"
scale = {scale:e}
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
point = [{l:e}, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]
material = "plastic"
[[plane]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
material = "plastic"
[[plane]]
point = [0.0, {l:e}, 0.0]
normal = [0.0, -1.0, 0.0]
material = "plastic"
[[insert]]
method = "random"
shape = "jack"
material = "plastic"
region_min = [{a:e}, {a:e}, {lo:e}]
region_max = [{b:e}, {b:e}, {hi:e}]
count = 4
seed = 1
"#,
        a = 0.025 * l,
        b = 0.975 * l,
        lo = 0.6 * l,
        hi = 1.4 * l,
    );
    let (start, end) = run_scene(&text);
    println!(
        "jacks at scale {scale:e}: ledger {:.2e} of the dissipated {:.3e} J",
        (end.total() - start.total()) / end.dissipated,
        end.dissipated
    );
    let held = start.potential - end.potential.min(start.potential) + start.kinetic_translational;
    (
        (end.total() - start.total()) / end.dissipated,
        end.dissipated / held.max(f64::MIN_POSITIVE),
    )
}

/// Regression test of issue #11 point 4: 10 µm jacks booked more energy as dissipated than the
/// system ever held. Now the ledger closes to 1 % of the dissipated energy (measured 0.2 %) and
/// no more is dissipated than was released by the fall.
#[test]
fn ten_micron_jacks_keep_the_ledger() {
    let (drift, dissipated) = jack_pour(5e-7, 0.004);
    assert!(
        drift.abs() < 0.01,
        "ledger off by {drift} of the dissipated energy"
    );
    assert!(
        dissipated > 0.1 && dissipated <= 1.0,
        "dissipated {dissipated} of the energy released"
    );
}

/// Damped pours of non-convex bodies: the ledger closes to 1 % of the energy dissipated (it was
/// 1–2 %; `examples/jacks_box.toml` now closes to 0.02 %).
#[test]
fn a_damped_pour_of_jacks_keeps_the_ledger() {
    let (drift, dissipated) = jack_pour(1e-3, 0.3);
    assert!(
        drift.abs() < 0.01,
        "ledger off by {drift} of the dissipated energy"
    );
    assert!(
        dissipated > 0.1 && dissipated <= 1.0,
        "dissipated {dissipated}"
    );
}
