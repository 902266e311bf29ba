//! Results do not depend on how the bodies are numbered: a run whose bodies are put in a new
//! random order every few dozen steps stays bit-identical, body by body (by id), to a run that
//! keeps its order. Every body pair is seen from the body of smaller global id, and every body
//! sums its contacts in the order of its partners' ids (`contact::ContactKey::order`), so no
//! floating-point operation sees another operand order. This is what lets MPI ranks, which each
//! number a share of the bodies their own way, compute the same bits as one process (issue #17).
//!
//! The scene has every kind of contact: spheres with rolling friction, cubes (the volume law),
//! non-convex stars and L-shapes (the vertex law with several regions per pair), a rotating drum
//! of triangles (regions on a moving mesh wall) and a plane.

use polydem::scene::Scene;
use polydem::World;
use std::collections::BTreeMap;
use std::path::Path;

const DRUM: &str = r#"
[simulation]
time_step = "auto"
duration = 1.0
gravity = [0.0, 0.0, -9.81]

[[material]]
name = "grain"
density = 1200.0
youngs_modulus = 1.0e6
poisson_ratio = 0.3
restitution = 0.4
friction = 0.5
rolling_friction = 0.05

[[material]]
name = "steel"
density = 7800.0
youngs_modulus = 1.0e6
poisson_ratio = 0.3
restitution = 0.4
friction = 0.4

[shape.star]
type = "star"
spikes = 8
radius = 0.003
spike_length = 0.004

[shape.ell]
type = "l_shape"
length_x = 0.009
length_y = 0.007
width = 0.003
height = 0.003

[shape.cube]
type = "box"
edges = [0.007, 0.007, 0.007]

# A drum 12 cm across and 6 cm deep turning about y, cut by a plane below its axis (a
# heap's floor).
[[mesh_wall]]
material = "steel"
generator = { type = "cylinder", radius = 0.06, height = 0.06, segments = 32, closed = true }
rotation = [1.5707963267948966, 0.0, 0.0]
translation = [0.0, 0.03, 0.0]
motion = { rpm = 40.0, axis = [0.0, 1.0, 0.0] }

[[plane]]
point = [0.0, 0.0, -0.054]
normal = [0.0, 0.0, 1.0]
material = "steel"

[[insert]]
method = "random"
material = "grain"
region_min = [-0.035, -0.026, -0.04]
region_max = [0.035, 0.026, 0.03]
count = 120
seed = 2
radius_distribution = { kind = "uniform", min = 0.002, max = 0.003 }

[[insert]]
method = "random"
shape = "cube"
material = "grain"
region_min = [-0.035, -0.023, -0.04]
region_max = [0.035, 0.023, 0.03]
count = 10
seed = 3

[[insert]]
method = "random"
shape = "star"
material = "grain"
region_min = [-0.035, -0.021, -0.04]
region_max = [0.035, 0.021, 0.03]
count = 8
seed = 4

[[insert]]
method = "random"
shape = "ell"
material = "grain"
region_min = [-0.035, -0.018, -0.04]
region_max = [0.035, 0.018, 0.03]
count = 6
seed = 5
"#;

fn drum() -> World {
    Scene::parse(Path::new("drum.toml"), DRUM.to_string())
        .expect("scene parses")
        .build()
        .expect("scene builds")
        .world
}

/// Every number of every body's state, as bits, by body id.
fn bodies_by_id(w: &World) -> BTreeMap<u64, Vec<u64>> {
    let b = w.bodies();
    (0..b.len())
        .map(|i| {
            let mut bits = Vec::new();
            for v in [
                b.position[i],
                b.velocity[i],
                b.angular_momentum[i],
                b.angular_velocity[i],
                b.force[i],
                b.torque[i],
            ] {
                bits.extend(v.to_array().map(f64::to_bits));
            }
            bits.extend(b.orientation[i].to_array().map(f64::to_bits));
            (b.id[i], bits)
        })
        .collect()
}

/// A permutation of `0..n` from a fixed sequence (xorshift, Fisher–Yates).
fn shuffled(n: usize, seed: &mut u64) -> Vec<u32> {
    let mut order: Vec<u32> = (0..n as u32).collect();
    for k in (1..n).rev() {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 7;
        *seed ^= *seed << 17;
        order.swap(k, (*seed % (k as u64 + 1)) as usize);
    }
    order
}

#[test]
fn bodies_in_a_new_order_give_the_same_bits() {
    let (mut kept, mut shuffled_world) = (drum(), drum());
    for w in [&mut kept, &mut shuffled_world] {
        w.set_sort_interval(0);
    }
    let mut seed = 0x2545_f491_4f6c_dd1d;
    let (mut steps, mut most) = (0, (0, 0, 0, 0));
    // 0.25 s: the bodies fall into the drum, which lifts them into a tumbling heap.
    let total = (0.25 / kept.time_step()).round() as u64;
    while steps < total {
        let order = shuffled(shuffled_world.bodies().len(), &mut seed);
        shuffled_world.permute_bodies(&order);
        let n = 37.min(total - steps);
        kept.run_steps(n);
        shuffled_world.run_steps(n);
        steps += n;
        assert!(
            bodies_by_id(&kept) == bodies_by_id(&shuffled_world),
            "the two orders differ after {steps} steps"
        );
        let c = kept.contacts();
        most = (
            most.0.max(c.between_bodies().count()),
            most.1.max(c.with_mesh_walls().count()),
            most.2.max(c.with_planes().count()),
            most.3.max(c.iter().filter(|c| c.key.region > 0).count()),
        );
    }
    let (e, e_shuffled) = (kept.energy(), shuffled_world.energy());
    println!("{steps} steps; up to {most:?} body, mesh-wall, plane and second-region contacts");
    assert!(
        most.0 >= 100 && most.1 >= 20 && most.2 >= 10 && most.3 >= 5,
        "too few contacts of some kind to test anything: {most:?}"
    );
    // The ledger's sums over contacts run in store order, which does not feed back into the
    // motion: equal to round-off.
    for (what, a, b) in [
        ("dissipated", e.dissipated, e_shuffled.dissipated),
        ("elastic", e.elastic, e_shuffled.elastic),
    ] {
        assert!(
            (a - b).abs() <= 1e-12 * a.abs().max(b.abs()),
            "{what}: {a} against {b}"
        );
    }
}
