//! Moving mesh walls: the wall's surface velocity enters the contact law (a belt accelerates a
//! sphere to the analytic rolling speed, a turntable carries a particle round with it), a shaken
//! closed box keeps its contents, wall forces and the work of moving walls are booked.

mod common;

use polydem::body::BodyInit;
use polydem::material::Material;
use polydem::math::{DQuat, DVec3};
use polydem::shape::{generators as shapes, Shape, Sphere};
use polydem::wall::{generators, Ends, Facing, MeshWall, WallMotion};
use polydem::World;
use std::f64::consts::PI;
use std::sync::Arc;

const RADIUS: f64 = 0.005;
const G: f64 = 9.81;

fn world(friction: f64, rolling_friction: f64) -> World {
    world_with_gravity(friction, rolling_friction, DVec3::new(0.0, 0.0, -G))
}

fn world_with_gravity(friction: f64, rolling_friction: f64, gravity: DVec3) -> World {
    let material = Material {
        name: "m".into(),
        density: 2500.0,
        youngs_modulus: 1e7,
        poisson_ratio: 0.25,
        restitution: 0.5,
        friction,
        rolling_friction,
    };
    common::wall_free_world(material, gravity, 2e-6)
}

fn sphere_at(w: &mut World, position: DVec3) -> usize {
    w.add_body(BodyInit {
        shape: Shape::Sphere(Sphere::new(RADIUS)),
        material: 0,
        position,
        orientation: DQuat::IDENTITY,
        velocity: DVec3::ZERO,
        angular_velocity: DVec3::ZERO,
    })
}

fn floor(cells: usize) -> MeshWall {
    generators::rectangle(
        DVec3::new(-0.1, -0.1, 0.0),
        DVec3::new(0.2, 0.0, 0.0),
        DVec3::new(0.0, 0.2, 0.0),
        cells,
        cells,
    )
    .unwrap()
    .into_wall(0)
    .unwrap()
}

/// A sphere set down on a belt moving at u slides until its contact point moves with the belt,
/// then rolls: v = μ g t and ω R = 5/2 μ g t until v + ω R = u, so it ends at v = 2u/7 (a
/// textbook result). The ledger closes with the belt's work booked.
#[test]
fn belt_accelerates_a_sphere_to_two_sevenths_of_its_speed() {
    let (mu, u) = (0.3, 0.4);
    let mut w = world(mu, 0.0);
    let mut belt = floor(7);
    belt.motion = WallMotion::fixed()
        .with_surface_velocity(DVec3::new(u, 0.0, 0.0))
        .unwrap();
    w = w.with_mesh_walls(vec![belt]);
    // Resting on the belt (the static overlap of the Hertz law is a few µm).
    let i = sphere_at(&mut w, DVec3::new(-0.08, 0.0, RADIUS - 1.6e-6));
    let e0 = w.energy().total();
    let t_roll = 2.0 * u / (7.0 * mu * G);
    w.run_steps((1.6 * t_roll / w.time_step()) as u64);
    let v = w.bodies().velocity[i];
    assert!(
        (v.x - 2.0 * u / 7.0).abs() < 0.01 * 2.0 * u / 7.0,
        "final speed {} vs 2u/7 = {}",
        v.x,
        2.0 * u / 7.0
    );
    assert!(v.y.abs() < 1e-6 && v.z.abs() < 1e-3);
    // Rolling without slip on the belt: contact point speed = belt speed.
    let omega = w.bodies().angular_velocity[i];
    let contact_speed = v.x - omega.y * RADIUS;
    assert!((contact_speed - u).abs() < 0.01 * u, "{contact_speed}");
    // The belt did work: kinetic energy gained plus friction losses.
    let e = w.energy();
    assert!(e.wall_work > 0.0);
    let drift = (e.total() - e0).abs();
    assert!(
        drift < 0.01 * e.wall_work,
        "ledger drift {drift} vs belt work {}",
        e.wall_work
    );
}

/// A closed cylinder turning about its vertical axis at 30 rpm, a sphere on its floor off the
/// axis. Friction spins the sphere up; rolling resistance stops it rolling relative to the floor;
/// it then goes round with the floor: velocity Ω × r, without rolling.
#[test]
fn turntable_carries_a_resting_sphere_with_the_floor() {
    let rpm = 30.0;
    let omega = rpm * 2.0 * PI / 60.0;
    let mut w = world(0.5, 0.5);
    let mut drum = generators::cylinder(0.1, 0.05, 48, 1, Ends::Closed, Facing::Inward)
        .unwrap()
        .into_wall(0)
        .unwrap();
    drum.motion = WallMotion::fixed()
        .with_rotation(DVec3::ZERO, DVec3::Z, rpm)
        .unwrap();
    let z_floor = drum.bounds().min.z;
    w = w.with_mesh_walls(vec![drum]);
    let r0 = 0.05;
    let i = sphere_at(&mut w, DVec3::new(r0, 0.0, z_floor + RADIUS - 1.6e-6));
    w.run_steps((1.5 / w.time_step()) as u64);
    let x = w.bodies().position[i];
    let v = w.bodies().velocity[i];
    let carried = DVec3::Z.cross(x) * omega;
    assert!(
        (v - carried).length() < 0.01 * carried.length(),
        "velocity {v} vs floor's {carried}"
    );
    // No rolling relative to the floor (the spin about the vertical, a twist, is free).
    let spin = w.bodies().angular_velocity[i];
    assert!(spin.truncate().length() < 0.01 * omega, "spin {spin}");
    // It stays on its circle.
    let r = x.truncate().length();
    assert!((r - r0).abs() < 0.01 * r0, "{r}");
}

/// A closed box shaken hard in all directions (velocity table, ±1.5 m/s switching every 4 ms
/// on each axis) with a sphere rattling inside: the sphere never leaves it.
#[test]
fn shaken_closed_box_keeps_its_contents() {
    let mut w = world(0.3, 0.0);
    let (lo, hi) = (DVec3::splat(-0.02), DVec3::splat(0.02));
    let mut cage = generators::box_mesh(lo, hi, 2, Facing::Inward)
        .unwrap()
        .into_wall(0)
        .unwrap();
    let mut table = Vec::new();
    for k in 0..100 {
        let s = |phase: usize| {
            if (k + phase).is_multiple_of(2) {
                1.5
            } else {
                -1.5
            }
        };
        table.push((
            k as f64 * 4e-3,
            DVec3::new(s(0), s(1) * 0.8, s(k / 3) * 1.2),
        ));
    }
    cage.motion = WallMotion::fixed().with_velocity_table(table).unwrap();
    w = w.with_mesh_walls(vec![cage]);
    let i = sphere_at(&mut w, DVec3::ZERO);
    let mut deepest: f64 = 0.0;
    let mut hits = 0usize;
    for _ in 0..2000 {
        w.run_steps(100);
        let inside = w.mesh_walls()[0]
            .pose()
            .to_reference(w.bodies().position[i]);
        // Distance of the sphere's surface beyond the nearest wall (negative: clear of it).
        let beyond = (inside.abs() + RADIUS - hi).max_element();
        deepest = deepest.max(beyond);
        hits += usize::from(w.contacts().with_mesh_walls().next().is_some());
    }
    assert!(
        hits > 100,
        "the sphere should rattle against the walls ({hits})"
    );
    // Hertz overlap of this soft material at the fastest impacts (~4 m/s relative) is
    // δ = (15 m v² / (16 E* √R))^(2/5) ≈ 1.2 mm ≈ 0.24 R; a leak takes the centre through (≥ R).
    assert!(deepest < 0.3 * RADIUS, "deepest penetration {deepest}");
}

/// The mean force on a floor under a resting sphere is its weight; the torque about the
/// reference point (the origin) is r × F.
#[test]
fn wall_impulse_gives_the_weight_of_a_resting_sphere() {
    let mut w = world(0.3, 0.0);
    w = w.with_mesh_walls(vec![floor(3)]);
    let i = sphere_at(&mut w, DVec3::new(0.03, -0.02, RADIUS));
    w.run_steps(50_000);
    let (j0, h0, t0) = (
        w.wall_loads().impulse[0],
        w.wall_loads().angular_impulse[0],
        w.time(),
    );
    w.run_steps(20_000);
    let span = w.time() - t0;
    let force = (w.wall_loads().impulse[0] - j0) / span;
    let torque = (w.wall_loads().angular_impulse[0] - h0) / span;
    let weight = DVec3::new(0.0, 0.0, -w.bodies().mass[i] * G);
    assert!(
        (force - weight).length() < 1e-4 * weight.length(),
        "{force}"
    );
    let expected = DVec3::new(0.03, -0.02, 0.0).cross(weight);
    assert!(
        (torque - expected).length() < 1e-3 * expected.length(),
        "{torque}"
    );
}

/// A drum turning at 10 rpm about a horizontal axis (gravity along −y) with a cube resting on
/// its inside at the bottom. Friction (μ = 0.6, sliding only past 31°) carries the cube up with
/// the drum: while it rises it moves with the drum's surface, velocity Ω × r, and turns with it,
/// ω = Ω — a rigid co-rotation, the drum's surface velocity at the cube.
#[test]
fn drum_carries_a_resting_cube_with_its_surface_velocity() {
    let rpm = 10.0;
    let omega = rpm * 2.0 * PI / 60.0;
    let mut w = world_with_gravity(0.6, 0.0, DVec3::new(0.0, -G, 0.0));
    let radius = 0.1;
    let mut drum = generators::cylinder(radius, 0.04, 96, 1, Ends::Closed, Facing::Inward)
        .unwrap()
        .transformed(1.0, DQuat::IDENTITY, DVec3::new(0.0, 0.0, -0.02))
        .into_wall(0)
        .unwrap();
    drum.motion = WallMotion::fixed()
        .with_rotation(DVec3::ZERO, DVec3::Z, rpm)
        .unwrap();
    w = w.with_mesh_walls(vec![drum]);
    let edge = 0.01;
    let (cube, _) = shapes::cuboid(edge, edge, edge).unwrap();
    // On the flat facet at the bottom (the facets' inscribed radius), touching it.
    let floor = radius * (PI / 96.0).cos();
    let i = w.add_body(BodyInit {
        shape: Shape::Convex(Arc::new(cube)),
        material: 0,
        position: DVec3::new(0.0, -floor + 0.5 * edge, 0.0),
        orientation: DQuat::from_rotation_z(PI / 96.0),
        velocity: DVec3::ZERO,
        angular_velocity: DVec3::ZERO,
    });
    // 0.3 s: the drum has turned 18°, short of the 31° at which the cube would slide.
    w.run_steps((0.3 / w.time_step()) as u64);
    let x = w.bodies().position[i];
    let carried = DVec3::Z.cross(x) * omega;
    let v = w.bodies().velocity[i];
    assert!(
        (v - carried).length() < 0.01 * carried.length(),
        "velocity {v} vs drum surface {carried}"
    );
    let spin = w.bodies().angular_velocity[i];
    assert!(
        (spin - DVec3::Z * omega).length() < 0.01 * omega,
        "spin {spin} vs {omega}"
    );
    // It has risen with the drum by about 18° (not slid back to the bottom).
    let angle = x.x.atan2(-x.y);
    assert!((angle - 0.3 * omega).abs() < 0.05, "angle {angle}");
}

/// A floor rising at 0.5 m/s towards a sphere floating 5 mm above it (no gravity: far beyond the
/// skin when the neighbour list is first made, 1 mm). Only the wall moves, so only the wall's own
/// motion can make the list go stale: the neighbour search must be made again as the wall comes
/// (regression test for the candidate list of moving walls). The floor then hits the sphere
/// like an infinitely heavy wall: it leaves at (1 + e) u = 0.75 m/s, and never sinks into it by
/// more than a fraction of its radius.
#[test]
fn a_moving_wall_reaches_a_body_far_beyond_the_skin() {
    let mut w = world_with_gravity(0.3, 0.0, DVec3::ZERO);
    let mut wall = floor(3);
    let u = 0.5;
    wall.motion = WallMotion::fixed()
        .with_velocity(DVec3::new(0.0, 0.0, u))
        .unwrap();
    w = w.with_mesh_walls(vec![wall]);
    let i = sphere_at(&mut w, DVec3::new(0.01, 0.02, 0.01));
    assert!(w.skin() < 0.2 * 0.01, "the sphere starts beyond the skin");
    let mut deepest: f64 = 0.0;
    for _ in 0..100 {
        w.run_steps(100); // 20 ms in all
        let floor_z = u * w.time();
        deepest = deepest.max(floor_z - (w.bodies().position[i].z - RADIUS));
    }
    let v = w.bodies().velocity[i];
    assert!(
        (v.z - 1.5 * u).abs() < 0.05 * u && v.x.abs() < 1e-9 && v.y.abs() < 1e-9,
        "the sphere left at {v}, expected (0, 0, {})",
        1.5 * u
    );
    assert!(deepest < 0.05 * RADIUS, "sank {deepest} m into the floor");
    assert!(w.pair_rebuilds() > 1, "the list was made again");
}
