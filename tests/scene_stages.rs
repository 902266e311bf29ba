//! Runs in stages (issue #13, point 3): gravity and a wall's rotation rate that follow time tables,
//! driven through the scene file as a user would, against the exact integrals.

use polydem::math::DVec3;
use polydem::scene::Scene;
use std::f64::consts::TAU;

fn load(text: &str) -> Result<Scene, String> {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("stages.toml");
    std::fs::write(&file, text).unwrap();
    Scene::load(&file).map_err(|e| e.to_string())
}

const MATERIAL: &str = r#"
[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 5.0e6
poisson_ratio = 0.25
restitution = 0.5
friction = 0.5
"#;

/// A sphere alone, at rest, under gravity that is off for 0.05 s, then grows linearly to
/// −10 m/s² at 0.15 s and stays: z(t) is the double integral of g.
#[test]
fn a_body_falls_by_the_double_integral_of_a_gravity_table() {
    let text = format!(
        r#"
[simulation]
duration = 0.25
time_step = 1.0e-5
output_interval = 0.05
gravity_table = [[0.0, 0.0, 0.0, 0.0], [0.05, 0.0, 0.0, 0.0], [0.15, 0.0, 0.0, -10.0]]
{MATERIAL}
[[particle]]
radius = 0.001
material = "glass"
position = [0.0, 0.0, 1.0]
"#
    );
    let mut prepared = load(&text).unwrap().build().unwrap();
    let world = &mut prepared.world;
    assert_eq!(world.gravity(), DVec3::ZERO);
    let e0 = world.energy().total();
    world.run_steps(25_000);
    let t = world.time();
    assert!((t - 0.25).abs() < 1e-12);
    // g = −100 (t − 0.05) on the ramp: v(0.15) = −0.5, z drop 100/6 · 0.1³; then −10 for 0.1 s.
    let ramp_drop = 100.0 / 6.0 * 1e-3;
    let (v1, rest) = (-0.5, t - 0.15);
    let z = 1.0 - ramp_drop + v1 * rest - 0.5 * 10.0 * rest * rest;
    let v = v1 - 10.0 * rest;
    let b = world.bodies();
    // Gravity is taken in the middle of each step, exact for the velocity on linear pieces; only
    // the two steps holding a knot err, by |Δslope| dt²/8 = 1.25e-9 m/s each, and the position
    // by that over the rest of the run. Velocity Verlet's position error for a ramp is
    // (dg/dt) dt² t / 12 ≈ 1e-10 m. Round-off of 25,000 steps stays far below both bounds.
    assert!(
        (b.velocity[0].z - v).abs() < 1e-8,
        "{} vs {v}",
        b.velocity[0].z
    );
    assert!(
        (b.position[0].z - z).abs() < 1e-8,
        "{} vs {z}",
        b.position[0].z
    );
    assert_eq!(world.gravity(), DVec3::new(0.0, 0.0, -10.0));
    // The ledger closes: the potential energy gained as gravity grew is booked.
    let e = world.energy();
    assert!(e.gravity_work != 0.0);
    assert!(
        (e.total() - e0).abs() < 1e-9 * e.kinetic_translational,
        "total drifted by {:e} J (kinetic {:e} J)",
        e.total() - e0,
        e.kinetic_translational
    );
}

/// A drum at rest while it is filled, spun up from 0 to 30 rpm between 0.1 and 0.2 s.
#[test]
fn a_wall_turns_by_the_integral_of_its_rpm_table() {
    let text = format!(
        r#"
[simulation]
duration = 0.3
output_interval = 0.05
{MATERIAL}
[[mesh_wall]]
material = "glass"
generator = {{ type = "cylinder", radius = 0.05, height = 0.04, segments = 32, closed = true }}
motion = {{ rpm_table = [[0.1, 0.0], [0.2, 30.0]], axis = [0.0, 0.0, 1.0] }}
[[particle]]
radius = 0.003
material = "glass"
position = [0.0, 0.0, 0.02]
"#
    );
    let mut prepared = load(&text).unwrap().build().unwrap();
    let world = &mut prepared.world;
    let steps = (0.3 / world.time_step()).round() as u64;
    world.run_steps(steps);
    let motion = &world.mesh_walls()[0].motion;
    assert_eq!(motion.angular_velocity(0.05), DVec3::ZERO);
    assert!((motion.angular_velocity(0.15).z - 0.5 * TAU * 0.5).abs() < 1e-12);
    assert!((motion.angular_velocity(0.25).z - 0.5 * TAU).abs() < 1e-12);
    // Turned by ½ · 0.5 rev/s · 0.1 s on the ramp plus 0.5 rev/s since 0.2 s.
    let t = world.time();
    let turns = 0.5 * 0.5 * 0.1 + 0.5 * (t - 0.2);
    let pose = world.mesh_walls()[0].pose();
    let expected = DVec3::new((TAU * turns).cos(), (TAU * turns).sin(), 0.0);
    assert!((pose.to_world(DVec3::X) - expected).length() < 1e-12);
}

#[test]
fn tables_that_contradict_a_constant_or_go_back_in_time_are_refused() {
    let both = format!(
        "[simulation]\nduration = 0.1\ngravity = [0.0, 0.0, -9.81]\n\
         gravity_table = [[0.0, 0.0, 0.0, -1.0]]\n{MATERIAL}"
    );
    let e = load(&both).unwrap().build().err().unwrap().to_string();
    assert!(e.contains("gravity_table") && e.contains("not both"), "{e}");

    let backwards = format!(
        "[simulation]\nduration = 0.1\n\
         gravity_table = [[0.2, 0.0, 0.0, -1.0], [0.1, 0.0, 0.0, 0.0]]\n{MATERIAL}"
    );
    let e = load(&backwards).unwrap().build().err().unwrap().to_string();
    assert!(e.contains("gravity_table") && e.contains("row 1"), "{e}");

    let wall = |motion: &str| {
        format!(
            "[simulation]\nduration = 0.1\n{MATERIAL}\n[[mesh_wall]]\nmaterial = \"glass\"\n\
             generator = {{ type = \"cylinder\", radius = 0.05, height = 0.04, segments = 16 }}\n\
             motion = {motion}\n"
        )
    };
    let e = load(&wall(
        "{ rpm = 10.0, rpm_table = [[0.0, 10.0]], axis = [0.0, 0.0, 1.0] }",
    ))
    .unwrap()
    .build()
    .err()
    .unwrap()
    .to_string();
    assert!(e.contains("rpm_table") && e.contains("not both"), "{e}");
    let e = load(&wall("{ rpm_table = [], axis = [0.0, 0.0, 1.0] }"))
        .unwrap()
        .build()
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.contains("rpm_table") && e.contains("at least one row"),
        "{e}"
    );
}
