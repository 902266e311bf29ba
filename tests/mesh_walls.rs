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
