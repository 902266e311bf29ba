//! Spheres on triangle-mesh walls must see the same forces as on the analytic plane, however the
//! wall is triangulated: resting and sliding on a flat wall of 2 or of 200 triangles, and rolling
//! across its edges and vertices without a force spike.

mod common;

use polydem::body::BodyInit;
use polydem::material::Material;
use polydem::math::{DQuat, DVec3};
use polydem::shape::{Shape, Sphere};
use polydem::World;

use common::Floor;

const RADIUS: f64 = 0.005;
const MU: f64 = 0.3;

/// A floor as an analytic plane (`cells` = 0) or as a mesh of 2 × cells² triangles, with one
/// sphere launched along x from just touching it.
fn world(cells: usize, velocity: DVec3) -> World {
    let material = Material {
        name: "m".into(),
        density: 2500.0,
        youngs_modulus: 1e7,
        poisson_ratio: 0.25,
        restitution: 0.5,
        friction: MU,
        rolling_friction: 0.0,
    };
    let floor = if cells == 0 {
        Floor::Plane
    } else {
        Floor::Mesh(cells)
    };
    let mut w = common::world_on_floor(material, floor, 2e-6);
    w.add_body(BodyInit {
        shape: Shape::Sphere(Sphere::new(RADIUS)),
        material: 0,
        position: DVec3::new(-0.05, 0.0, RADIUS),
        orientation: DQuat::IDENTITY,
        velocity,
        angular_velocity: DVec3::ZERO,
    });
    w
}

fn wall_contact_count(w: &World) -> usize {
    w.contacts().with_planes().count() + w.contacts().with_mesh_walls().count()
}

fn normal_force(w: &World) -> f64 {
    w.contacts()
        .iter()
        .filter(|c| c.key.partner.is_wall())
        .map(|c| c.report.normal_force)
        .sum()
}

#[test]
fn resting_sphere_sees_the_plane_whatever_the_triangulation() {
    let mut reference = world(0, DVec3::ZERO);
    reference.run_steps(50_000);
    for cells in [1, 10] {
        let mut w = world(cells, DVec3::ZERO);
        w.run_steps(50_000);
        assert_eq!(wall_contact_count(&w), 1, "{cells} cells: one contact");
        let (f, f0) = (normal_force(&w), normal_force(&reference));
        let (z, z0) = (w.bodies().position[0].z, reference.bodies().position[0].z);
        println!(
            "{} triangles: F = {f:.9e} N (plane {f0:.9e}), z = {z:.12e} (plane {z0:.12e})",
            2 * cells * cells
        );
        // The mesh contact is computed as for the plane: identical to round-off.
        assert!((f / f0 - 1.0).abs() < 1e-9);
        assert!((z - z0).abs() < 1e-12);
    }
}

#[test]
fn sliding_and_rolling_across_triangles_match_the_plane() {
    // Launched sliding at 0.5 m/s: slides, then rolls across many triangle edges and vertices.
    let v0 = DVec3::new(0.5, 0.0, 0.0);
    let mut reference = world(0, v0);
    let mut meshes = [world(1, v0), world(10, v0)];
    let mut worst_spike: f64 = 0.0;
    for _ in 0..100 {
        reference.run_steps(500);
        for w in &mut meshes {
            w.run_steps(500);
            // Still one contact, pressing as on the plane: no spike at edges or vertices.
            assert_eq!(wall_contact_count(w), 1);
            let (f, f0) = (normal_force(w), normal_force(&reference));
            worst_spike = worst_spike.max((f / f0 - 1.0).abs());
        }
    }
    let x0 = reference.bodies().position[0];
    for (w, cells) in meshes.iter().zip([1, 10]) {
        let x = w.bodies().position[0];
        println!(
            "{} triangles: travelled {:.9e} m (plane {:.9e}), v = {:?}",
            2 * cells * cells,
            x.x + 0.05,
            x0.x + 0.05,
            w.bodies().velocity[0]
        );
        // The same force history as on the plane, so the same path: within 1 %, in fact to
        // round-off.
        assert!(((x.x + 0.05) / (x0.x + 0.05) - 1.0).abs() < 1e-9);
        assert!((w.bodies().velocity[0] - reference.bodies().velocity[0]).length() < 1e-9);
    }
    // The normal force, sampled every 500 steps while the sphere crosses edges and vertices,
    // equals the plane's: a spike at an edge would show here.
    println!("largest deviation of the normal force from the plane's: {worst_spike:.2e}");
    assert!(worst_spike < 1e-9);
}

/// Nothing leaks through a closed wall: fast spheres bouncing for a long time in a closed box
/// made of a coarse triangle mesh all stay inside it.
#[test]
fn nothing_leaks_out_of_a_closed_mesh_box() {
    let text = r#"
[simulation]
duration = 0.3
gravity = [0.0, 0.0, 0.0]

[[material]]
name = "m"
density = 2500.0
youngs_modulus = 1.0e7
poisson_ratio = 0.25
restitution = 0.9
friction = 0.3

[[mesh_wall]]
material = "m"
generator = { type = "box", min = [0.0, 0.0, 0.0], max = [0.05, 0.05, 0.05], divisions = 2 }

[[insert]]
method = "random"
material = "m"
region_min = [0.0, 0.0, 0.0]
region_max = [0.05, 0.05, 0.05]
count = 60
radius = 0.003
seed = 3
velocity = [2.0, -1.5, 1.0]
"#;
    let mut p = polydem::scene::Scene::parse(std::path::Path::new("box.toml"), text.into())
        .unwrap()
        .build()
        .unwrap();
    let w = &mut p.world;
    let steps = (0.3 / w.time_step()) as u64;
    let mut wall_hits = 0;
    for _ in 0..100 {
        w.run_steps(steps / 100);
        wall_hits += w.contacts().with_mesh_walls().count();
        for x in &w.bodies().position {
            assert!(
                x.cmpgt(DVec3::ZERO).all() && x.cmplt(DVec3::splat(0.05)).all(),
                "a sphere left the box: {x:?}"
            );
        }
    }
    // At 2.7 m/s the spheres cross the 5 cm box in ~20 ms: they hit the walls many times.
    assert!(wall_hits > 50, "only {wall_hits} wall contacts seen");
    assert_eq!(w.bodies().len(), 60);
}

/// A sphere on a mesh wall has four contact slots (`PairKind::SphereOnMesh`): pushed into the
/// corner of a triangulated box by gravity along the diagonal, it rests on the three walls at
/// once, each holding the component of its weight along the wall's normal (m g / √3 each,
/// without friction), as three planes would.
#[test]
fn a_sphere_in_a_corner_of_a_mesh_box_rests_on_all_three_walls() {
    let g = 9.81 / 3f64.sqrt();
    let text = format!(
        r#"
[simulation]
duration = 0.2
time_step = 2.0e-6
gravity = [-{g}, -{g}, -{g}]

[[material]]
name = "m"
density = 2500.0
youngs_modulus = 1.0e7
poisson_ratio = 0.25
restitution = 0.3
friction = 0.0

[[mesh_wall]]
material = "m"
generator = {{ type = "box", min = [0.0, 0.0, 0.0], max = [0.05, 0.05, 0.05], divisions = 3 }}

[[particle]]
radius = 0.004
material = "m"
position = [0.0045, 0.0045, 0.0045]
"#
    );
    let mut p = polydem::scene::Scene::parse(std::path::Path::new("corner.toml"), text)
        .unwrap()
        .build()
        .unwrap();
    let w = &mut p.world;
    w.run_steps((0.2 / w.time_step()) as u64);
    let contacts: Vec<_> = w.contacts().with_mesh_walls().collect();
    assert_eq!(contacts.len(), 3, "{contacts:?}");
    let weight = w.bodies().mass[0] * 9.81;
    let mut normals: Vec<DVec3> = Vec::new();
    for c in &contacts {
        let n = c.geometry.normal;
        // Along a coordinate axis, into the box.
        assert!(n.max_element() > 1.0 - 1e-9, "{n}");
        normals.push(n);
        let share = c.report.normal_force / (weight / 3f64.sqrt());
        assert!(
            (share - 1.0).abs() < 1e-6,
            "normal force {share} of m g / √3"
        );
    }
    let sum: DVec3 = normals.iter().sum();
    assert!(
        (sum - DVec3::ONE).length() < 1e-9,
        "one contact per wall: {normals:?}"
    );
}

/// Spheres on mesh walls have their contacts found and their slots set inside the contact
/// loop's parallel chunks: a bed falling into a triangulated box, thrown sideways so that they
/// bounce and slide, gives the same bits on one and on two threads (positions,
/// velocities, and the energy ledger's dissipated figure, which books the histories of the
/// regions that end).
#[test]
fn spheres_on_mesh_walls_agree_bit_for_bit_on_one_and_two_threads() {
    let world = |threads: usize| {
        let text = format!(
            r#"
[simulation]
duration = 0.05
time_step = 8.0e-6
gravity = [1.5, -0.8, -9.81]
threads = {threads}

[[material]]
name = "m"
density = 2500.0
youngs_modulus = 1.0e7
poisson_ratio = 0.25
restitution = 0.5
friction = 0.4

[[mesh_wall]]
material = "m"
generator = {{ type = "box", min = [0.0, 0.0, 0.0], max = [0.04, 0.04, 0.04], divisions = 4 }}

[[insert]]
method = "random"
material = "m"
region_min = [0.0, 0.0, 0.0]
region_max = [0.04, 0.04, 0.04]
count = 1000
radius = 0.0015
seed = 7
velocity = [0.3, 0.2, -0.5]
"#
        );
        polydem::scene::Scene::parse(std::path::Path::new("bed.toml"), text)
            .unwrap()
            .build()
            .unwrap()
            .world
    };
    let mut worlds = [world(1), world(2)];
    assert_eq!((worlds[0].threads(), worlds[1].threads()), (1, 2));
    let mut most_on_walls = 0;
    for part in 0..8 {
        for w in &mut worlds {
            w.run_steps(1000);
        }
        let [a, b] = &worlds;
        let on_walls = a.contacts().with_mesh_walls().count();
        most_on_walls = most_on_walls.max(on_walls);
        assert_eq!(
            on_walls,
            b.contacts().with_mesh_walls().count(),
            "part {part}"
        );
        for i in 0..a.bodies().len() {
            let (x, y) = (a.bodies(), b.bodies());
            assert_eq!(
                x.position[i].to_array().map(f64::to_bits),
                y.position[i].to_array().map(f64::to_bits),
                "position of {i}, part {part}"
            );
            assert_eq!(
                x.velocity[i].to_array().map(f64::to_bits),
                y.velocity[i].to_array().map(f64::to_bits),
                "velocity of {i}, part {part}"
            );
        }
        let (ea, eb) = (a.energy(), b.energy());
        assert_eq!(
            ea.dissipated.to_bits(),
            eb.dissipated.to_bits(),
            "part {part}"
        );
        assert_eq!(ea.total().to_bits(), eb.total().to_bits(), "part {part}");
    }
    // Enough spheres on the walls to fill several chunks of the contact loop.
    assert!(
        most_on_walls > 200,
        "only {most_on_walls} contacts with the walls"
    );
}
