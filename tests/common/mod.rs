//! Helpers shared by the integration tests.

// Each test file compiles this module on its own and uses only some of it.
#![allow(dead_code)]

pub mod drum;

use polydem::body::BodyInit;
use polydem::contact_law::NormalLaw;
use polydem::material::{Material, PairTable};
use polydem::math::{DQuat, DVec3};
use polydem::rng::SplitMix64;
use polydem::shape::{Shape, Sphere};
use polydem::wall::{generators, Plane};
use polydem::{World, WorldConfig};

/// Glass-like beads, soft enough for large time steps (E = 10 MPa): the material of the tests'
/// settling beds, with `rolling_friction` as each test needs.
pub fn grain(rolling_friction: f64) -> Material {
    Material {
        name: "grain".into(),
        density: 2500.0,
        youngs_modulus: 1e7,
        poisson_ratio: 0.25,
        restitution: 0.5,
        friction: 0.5,
        rolling_friction,
    }
}

/// Kicks every body to a random velocity of `speed` (range, m/s) in a random direction and a
/// random spin of up to `spin` rad/s about a random axis.
pub fn kick(w: &mut World, rng: &mut SplitMix64, speed: (f64, f64), spin: f64) {
    for i in 0..w.bodies().len() {
        let direction = DVec3::new(rng.normal(), rng.normal(), rng.normal()).normalize();
        w.bodies_mut().velocity[i] = direction * rng.uniform(speed.0, speed.1);
        let omega = DVec3::new(rng.normal(), rng.normal(), rng.normal()).normalize()
            * rng.uniform(0.0, spin);
        // L = R I Rᵀ ω (principal moments in the body frame).
        let q = w.bodies().orientation[i];
        w.bodies_mut().angular_momentum[i] = q * (w.bodies().inertia[i] * (q.inverse() * omega));
        w.bodies_mut().angular_velocity[i] = omega;
    }
}

/// How far the farthest vertex of any polyhedron pokes out of the box [0, size]³; panics,
/// naming the body and `what`, if a body's centre has left it.
pub fn deepest_outside_box(w: &World, size: f64, what: &str) -> f64 {
    let mut deepest = 0.0f64;
    for i in 0..w.bodies().len() {
        let x = w.bodies().position[i];
        assert!(
            x.cmpgt(DVec3::ZERO).all() && x.cmplt(DVec3::splat(size)).all(),
            "{what}: body {i} left the box: {x:?}"
        );
        let vertices = match &w.shapes()[w.bodies().shape[i] as usize] {
            Shape::Convex(p) => p.vertices(),
            Shape::NonConvex(p) => p.vertices(),
            Shape::Sphere(_) => &[],
        };
        for &v in vertices {
            let y = x + w.bodies().orientation[i] * v;
            let out = (-y.min_element()).max((y - DVec3::splat(size)).max_element());
            deepest = deepest.max(out);
        }
    }
    deepest
}

/// The floor z = 0 of the floor tests: an analytic plane, or a 0.2 m square mesh of
/// 2 × cells² triangles (offset so that bodies cross its edges and vertices at all angles rather
/// than running along one edge).
#[derive(Clone, Copy, Debug)]
pub enum Floor {
    Plane,
    Mesh(usize),
}

/// A world under gravity −9.81 z with one material (Hertz, k_t/k_n = 2/7) and an open box of
/// planes of that material: the floor z = 0 and four side walls around [0, width]², facing in;
/// no bodies yet.
pub fn open_box_world(
    material: Material,
    width: f64,
    time_step: f64,
    broad_phase: polydem::broad_phase::Method,
    threads: usize,
) -> World {
    let laws = PairTable::new(
        std::slice::from_ref(&material),
        NormalLaw::Hertz,
        2.0 / 7.0,
        &[],
    );
    let wall = |point: DVec3, normal: DVec3| Plane {
        point,
        normal,
        material: 0,
    };
    let planes = vec![
        wall(DVec3::ZERO, DVec3::Z),
        wall(DVec3::ZERO, DVec3::X),
        wall(DVec3::new(width, 0.0, 0.0), -DVec3::X),
        wall(DVec3::ZERO, DVec3::Y),
        wall(DVec3::new(0.0, width, 0.0), -DVec3::Y),
    ];
    World::new(WorldConfig {
        time_step,
        gravity: DVec3::new(0.0, 0.0, -9.81),
        materials: vec![material],
        pair_laws: laws,
        planes,
        broad_phase,
        skin: None,
        threads,
    })
    .unwrap()
}

/// A one-thread world under `gravity` with one material (Hertz, k_t/k_n = 2/7) and `planes`; no
/// bodies yet.
fn one_material_world(
    material: Material,
    gravity: DVec3,
    planes: Vec<Plane>,
    time_step: f64,
) -> World {
    let laws = PairTable::new(
        std::slice::from_ref(&material),
        NormalLaw::Hertz,
        2.0 / 7.0,
        &[],
    );
    World::new(WorldConfig {
        time_step,
        gravity,
        materials: vec![material],
        pair_laws: laws,
        planes,
        broad_phase: Default::default(),
        skin: None,
        threads: 1,
    })
    .unwrap()
}

/// A one-thread world under `gravity` with one material (Hertz, k_t/k_n = 2/7) and no walls; no
/// bodies yet.
pub fn wall_free_world(material: Material, gravity: DVec3, time_step: f64) -> World {
    one_material_world(material, gravity, Vec::new(), time_step)
}

/// A one-thread world under gravity −9.81 z with one material (Hertz, k_t/k_n = 2/7) and the
/// floor, made of that material; no bodies yet.
pub fn world_on_floor(material: Material, floor: Floor, time_step: f64) -> World {
    let planes = match floor {
        Floor::Plane => vec![Plane {
            point: DVec3::ZERO,
            normal: DVec3::Z,
            material: 0,
        }],
        Floor::Mesh(_) => Vec::new(),
    };
    let mut w = one_material_world(material, DVec3::new(0.0, 0.0, -9.81), planes, time_step);
    if let Floor::Mesh(cells) = floor {
        let mesh = generators::rectangle(
            DVec3::new(-0.1, -0.1037, 0.0),
            DVec3::new(0.2, 0.0, 0.0),
            DVec3::new(0.0, 0.2, 0.0),
            cells,
            cells,
        )
        .unwrap();
        w = w.with_mesh_walls(vec![mesh.into_wall(0).unwrap()]);
    }
    w
}

/// n³ spheres (13³ = 2,197 is above the size at which a world sorts its bodies in space by
/// itself) of 1 mm radius on a jittered lattice 2.05 mm apart, added in a scrambled order, with
/// random velocities and spins, falling into an open box, in a world of `threads` threads: many
/// contacts with friction and rolling-friction history.
pub fn scrambled_bed(n: usize, threads: usize) -> World {
    let material = grain(0.1);
    let spacing = 2.05e-3;
    let width = spacing * n as f64 + 1e-3;
    let mut w = open_box_world(material, width, 1e-5, Default::default(), threads);
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut random = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let count = n * n * n;
    for k in 0..count {
        // Cells in a scrambled order (multiplication by a number prime to the count).
        let cell = (k * 1_000_003) % count;
        let (i, j, l) = (cell % n, cell / n % n, cell / (n * n));
        let jitter = DVec3::new(random(), random(), random()) * 4e-5;
        w.add_body(BodyInit {
            shape: Shape::Sphere(Sphere { radius: 1e-3 }),
            material: 0,
            position: DVec3::new(i as f64, j as f64, l as f64) * spacing
                + DVec3::splat(1.5e-3)
                + jitter,
            orientation: DQuat::IDENTITY,
            velocity: DVec3::new(random(), random(), random()) * 0.2,
            angular_velocity: DVec3::new(random(), random(), random()) * 100.0,
        });
    }
    w
}
