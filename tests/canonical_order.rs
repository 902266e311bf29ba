//! Results do not depend on how the bodies are numbered: a run whose bodies are put in a new
//! random order every few dozen steps stays bit-identical, body by body (by id), to a run that
//! keeps its order. Every body pair is seen from the body of smaller global id, and every body
//! sums its contacts in the order of its partners' ids (`contact::ContactKey::order`), so no
//! floating-point operation sees another operand order. This is what lets MPI ranks, which each
//! number a share of the bodies their own way, compute the same bits as one process (issue #17).
//!
//! The scene (`common::drum`) has every kind of contact.

mod common;

use common::drum::drum;
use polydem::World;
use std::collections::BTreeMap;

/// Every number of every body's state, as bits, by body id.
fn bodies_by_id(w: &World) -> BTreeMap<u64, Vec<u64>> {
    let b = w.bodies();
    (0..b.len())
        .map(|i| {
            let bits = b.motion_state(i).to_array().map(f64::to_bits).to_vec();
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
