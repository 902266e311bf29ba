//! Bodies renumbered in space order (`World::sort_bodies_in_space`, done by the world itself every
//! 1000 steps once it has 2048 bodies): the renumbering changes nothing but the numbering, not
//! even the bits of the steps that follow, and runs that sort stay bit-identical for any thread
//! count.

mod common;

use polydem::contact::Partner;
use polydem::math::DVec3;
use polydem::World;
use std::collections::HashMap;

/// Each body's state by id, and each contact's history by the ids of its two bodies (seen from
/// the body of lower id).
#[derive(Debug, PartialEq)]
struct Snapshot {
    bodies: HashMap<u64, [DVec3; 5]>,
    contacts: HashMap<(u64, Option<u64>, u8), [DVec3; 4]>,
}

fn snapshot(w: &World) -> Snapshot {
    let b = w.bodies();
    let bodies = (0..b.len())
        .map(|i| {
            let state = [
                b.position[i],
                b.velocity[i],
                b.angular_momentum[i],
                b.force[i],
                b.torque[i],
            ];
            (b.id[i], state)
        })
        .collect();
    let contacts = w
        .contacts()
        .iter()
        .map(|c| {
            let a = b.id[c.key.a as usize];
            let h = [
                c.history.tangential_spring,
                c.spin.map_or(DVec3::ZERO, |s| s.rolling_torque),
                c.geometry.normal,
                c.history.damper_force.as_dvec3(),
            ];
            match c.key.partner {
                Partner::Body(j) => {
                    let j = b.id[j as usize];
                    if a < j {
                        ((a, Some(j), c.key.region), h)
                    } else {
                        ((j, Some(a), c.key.region), h.map(|v| -v))
                    }
                }
                // Walls by body and wall kind/number in the region slot's place.
                Partner::Plane(p) => ((a, None, 100 + p as u8), h),
                Partner::Mesh(m) => ((a, None, 200 + m as u8), h),
            }
        })
        .collect();
    Snapshot { bodies, contacts }
}

#[test]
fn sorting_bodies_changes_only_their_numbering() {
    let mut w = common::scrambled_bed(13, 1);
    w.set_sort_interval(0);
    w.run_steps(2500);
    let before = snapshot(&w);
    assert!(
        before.contacts.len() > 1000,
        "{} contacts",
        before.contacts.len()
    );
    assert!(
        before.contacts.values().any(|h| h[1] != DVec3::ZERO),
        "no rolling history"
    );
    let ids_before = w.bodies().id.clone();
    w.sort_bodies_in_space();
    assert_ne!(w.bodies().id, ids_before, "the bodies kept their order");
    assert_eq!(snapshot(&w), before);

    // The next steps are those of an unsorted twin, bit for bit: pairs are seen from the body
    // of smaller id and each body sums its contacts in the order of its partners' ids, whatever
    // the numbering.
    let mut twin = common::scrambled_bed(13, 1);
    twin.set_sort_interval(0);
    twin.run_steps(2500);
    w.run_steps(20);
    twin.run_steps(20);
    assert_eq!(snapshot(&w), snapshot(&twin));
    // The ledger sums over contacts in store order, which does not feed back into the motion:
    // equal to round-off.
    let (d, d_twin) = (w.dissipated(), twin.dissipated());
    assert!(
        (d - d_twin).abs() < 1e-12 * d_twin,
        "dissipated {d} vs {d_twin}"
    );
}

#[test]
fn runs_that_sort_are_bit_identical_for_any_thread_count() {
    let run = |threads| {
        let mut w = common::scrambled_bed(13, threads);
        w.set_sort_interval(150);
        w.run_steps(400);
        (
            w.bodies().id.clone(),
            w.bodies().position.clone(),
            w.bodies().angular_momentum.clone(),
        )
    };
    let one = run(1);
    assert_eq!(one, run(2));
    assert_ne!(
        one.0,
        (0..one.0.len() as u64).collect::<Vec<_>>(),
        "no sorting happened"
    );
}
