//! The seed paper's contact law for polyhedra (`[contact] polyhedra = "vertex"`): a spring at every
//! vertex of one body inside the other, along the normal of the face it penetrates.
//!
//! Statics of a cube resting on a plane: its four bottom vertices sink by the same depth d, and
//! the four springs k_p = E* R* (R* the volume-equivalent radius on a wall) carry the weight:
//! 4 k_p d = m g. Dynamics: the law is the gradient of ½ k_p Σ dᵢ², so an elastic cube dropped
//! tilted onto the plane (vertex, then edge, then face contacts) must leave with its energy.

use polydem::scene::Scene;
use std::path::Path;

const EDGE: f64 = 0.01;
const DENSITY: f64 = 2500.0;
const YOUNG: f64 = 1.0e7;
const POISSON: f64 = 0.25;

fn scene(restitution: f64, friction: f64, rotation: [f64; 3], height: f64) -> String {
    format!(
        r#"
[simulation]
duration = 1.0
gravity = [0.0, 0.0, -9.81]

[contact]
polyhedra = "vertex"

[[material]]
name = "m"
density = {DENSITY}
youngs_modulus = {YOUNG}
poisson_ratio = {POISSON}
restitution = {restitution}
friction = {friction}

[shape.cube]
type = "box"
edges = [{EDGE}, {EDGE}, {EDGE}]

[[plane]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
material = "m"

[[particle]]
shape = "cube"
material = "m"
position = [0.0, 0.0, {height}]
rotation = [{}, {}, {}]
"#,
        rotation[0], rotation[1], rotation[2]
    )
}

#[test]
fn resting_cube_sinks_by_the_statics_of_four_springs() {
    let text = scene(0.5, 0.5, [0.0; 3], 0.5 * EDGE);
    let mut p = Scene::parse(Path::new("vertex.toml"), text)
        .unwrap()
        .build()
        .unwrap();
    let w = &mut p.world;
    w.run_steps((0.5 / w.time_step()) as u64);
    let speed = w.bodies().velocity[0].length();
    let mass = w.bodies().mass[0];
    let e_star = YOUNG / (2.0 * (1.0 - POISSON * POISSON));
    let r_eq = (3.0 * EDGE.powi(3) / (4.0 * std::f64::consts::PI)).cbrt();
    let depth = mass * 9.81 / (4.0 * e_star * r_eq);
    let sunk = 0.5 * EDGE - w.bodies().position[0].z;
    println!("depth {sunk:.6e} m vs m g/(4 k_p) = {depth:.6e} m, speed {speed:.1e} m/s");
    assert!(speed < 1e-6, "not at rest: {speed} m/s");
    // At rest the dashpots are idle: the springs alone hold the weight, to round-off; 1e-6
    // leaves room for the last of the settling.
    assert!((sunk / depth - 1.0).abs() < 1e-6, "sank {sunk} m");
    let c = w.contacts().with_planes().next().unwrap();
    assert_eq!(c.geometry.volume.unwrap().points, 4);
}

#[test]
fn elastic_tilted_drop_keeps_its_energy() {
    // Tilted about a skew axis so that a vertex lands first, then an edge, then a face.
    let text = scene(1.0, 0.0, [0.35, 0.2, 0.1], 0.012);
    let mut p = Scene::parse(Path::new("vertex.toml"), text)
        .unwrap()
        .build()
        .unwrap();
    let w = &mut p.world;
    let energy = |w: &polydem::World| {
        let e = w.energy();
        e.kinetic_translational + e.kinetic_rotational + e.potential
    };
    let e0 = energy(w);
    let mut touched = false;
    let mut worst: f64 = 0.0;
    while w.time() < 0.2 {
        w.run_steps(10);
        if w.contacts().with_planes().next().is_none() {
            // In flight: all the energy is kinetic and potential.
            if touched {
                worst = worst.max((energy(w) / e0 - 1.0).abs());
            }
        } else {
            touched = true;
        }
    }
    println!("largest energy change between contacts: {worst:.2e}");
    assert!(touched);
    // Frictionless and undamped: only the normal springs act, and they are the gradient of
    // ½ k_p Σ dᵢ², so the energy may change only where a point starts or stops penetrating
    // within a step and by the integration error: < 1 % (measured 5.8e-4).
    assert!(worst < 0.01, "energy changed by {worst}");
}
