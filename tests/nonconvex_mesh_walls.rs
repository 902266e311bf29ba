//! Non-convex bodies (jacks) against triangle-mesh walls: the same contacts as against a plane on
//! a flat mesh however it is triangulated, and no way out of a closed mesh box.

mod common;

use polydem::body::BodyInit;
use polydem::material::Material;
use polydem::math::{DQuat, DVec3};
use polydem::rng::SplitMix64;
use polydem::scene::Scene;
use polydem::shape::nonconvex_generators::jack;
use polydem::shape::Shape;
use polydem::World;
use std::path::Path;
use std::sync::Arc;

use common::Floor;

/// A 20 mm jack (4 mm bars) dropped tilted from 1 cm onto the floor, left to bounce and settle.
fn drop_a_jack(floor: Floor) -> World {
    let material = Material {
        name: "m".into(),
        density: 2500.0,
        youngs_modulus: 1.0e7,
        poisson_ratio: 0.25,
        restitution: 0.5,
        friction: 0.4,
        rolling_friction: 0.0,
    };
    let mut w = common::world_on_floor(material, floor, 2.0e-6);
    let (shape, _) = jack(0.02, 0.004).unwrap().build(false).unwrap();
    w.add_body(BodyInit {
        shape: Shape::NonConvex(Arc::new(shape)),
        material: 0,
        position: DVec3::new(0.003, 0.002, 0.025),
        orientation: DQuat::from_scaled_axis(DVec3::new(0.4, -0.25, 0.3)),
        velocity: DVec3::new(0.05, 0.0, 0.0),
        angular_velocity: DVec3::ZERO,
    });
    // 0.25 s: the fall, the first impacts on one arm and then others, and the rocking after.
    w.run_steps(125_000);
    w
}

/// The jack's trajectory on meshes of 2 and of 200 triangles is the plane's: the contacts are
/// equal to round-off (each arm on the floor its own contact with its own friction history, as
/// on the plane), so after 125,000 steps of impacts, rocking and friction the centre agrees to
/// 1 µm (5e-5 of the jack's size; measured 3e-10 m) and the orientation to 0.01 rad. Matching a
/// region to last step's by its normal alone would swap the arms' friction histories (same
/// normal) and move the jack by 0.3 mm.
#[test]
fn a_jack_dropped_on_a_mesh_floor_moves_as_on_the_plane() {
    let reference = drop_a_jack(Floor::Plane);
    let x0 = reference.bodies().position[0];
    let q0 = reference.bodies().orientation[0];
    // It has landed and stays on the floor, resting on arm ends (centre at 10 mm or lower).
    assert!(x0.z > 0.0 && x0.z < 0.011, "{x0}");
    assert!(reference.bodies().velocity[0].length() < 0.05);
    for cells in [1, 10] {
        let w = drop_a_jack(Floor::Mesh(cells));
        let (x, q) = (w.bodies().position[0], w.bodies().orientation[0]);
        assert!(
            (x - x0).length() < 1e-6,
            "{cells}² cells: centre {x} vs {x0} on the plane"
        );
        assert!(
            q.angle_between(q0) < 0.01,
            "{cells}² cells: turned {}",
            q.angle_between(q0)
        );
        println!(
            "{cells}² cells: centre off by {:.2e} m, turned {:.2e} rad",
            (x - x0).length(),
            q.angle_between(q0)
        );
        assert!(w.contacts().with_mesh_walls().next().is_some());
    }
}

/// Six jacks in a closed mesh box, kicked every 100 steps to random velocities of 1–3 m/s and
/// spins up to 300 rad/s, for 30,000 steps: none ever gets out, and no vertex gets through a wall
/// by more than a bar's width.
#[test]
fn shaken_jacks_never_leave_a_closed_mesh_box() {
    const SIZE: f64 = 0.06;
    let text = format!(
        r#"
[simulation]
duration = 1.0
gravity = [0.0, 0.0, 0.0]
threads = 1

[[material]]
name = "m"
density = 2500.0
youngs_modulus = 1.0e7
poisson_ratio = 0.25
restitution = 0.9
friction = 0.3

[shape.jack]
type = "jack"
length = 0.012
width = 0.003

[[mesh_wall]]
material = "m"
generator = {{ type = "box", min = [0.0, 0.0, 0.0], max = [{SIZE}, {SIZE}, {SIZE}], divisions = 2 }}

[[insert]]
method = "random"
material = "m"
shape = "jack"
region_min = [0.0, 0.0, 0.0]
region_max = [{SIZE}, {SIZE}, {SIZE}]
count = 6
seed = 1
"#
    );
    let mut p = Scene::parse(Path::new("shaken.toml"), text)
        .unwrap()
        .build()
        .unwrap();
    let w = &mut p.world;
    assert_eq!(w.bodies().len(), 6);
    let mut rng = SplitMix64::new(7);
    let (mut wall_contacts, mut deepest) = (0usize, 0.0f64);
    for _ in 0..300 {
        common::kick(w, &mut rng, (1.0, 3.0), 300.0);
        for _ in 0..100 {
            w.step();
            wall_contacts += w.contacts().with_mesh_walls().count();
        }
        deepest = deepest.max(common::deepest_outside_box(w, SIZE, "jacks"));
    }
    println!(
        "{wall_contacts} wall contacts over 30 000 steps; deepest vertex {deepest:.2e} m outside \
         the box (bars 3e-3 m wide)"
    );
    assert!(wall_contacts > 1000, "{wall_contacts}");
    assert!(deepest < 0.003, "a vertex went {deepest} m through a wall");
}
