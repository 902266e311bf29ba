//! A world decomposed among ranks (`decomposition::InProcessRanks`: the shares of MPI ranks, run
//! in one process) gives every body the bits a single world gives it, step for step, on 2, 3 and
//! 5 ranks; its energy ledger, added up over the shares, is the single world's to round-off
//! (sums in another order). The scene (`common::drum`) has every kind of contact, and its bodies
//! tumble across the cuts, so bodies change owner with their contacts' histories.

mod common;

use common::drum::drum;
use polydem::decomposition::InProcessRanks;
use polydem::World;
use std::collections::BTreeMap;

/// Every number of every owned body's state, as bits, by body id.
fn owned_bodies(worlds: &[&World]) -> BTreeMap<u64, Vec<u64>> {
    let mut all = BTreeMap::new();
    for w in worlds {
        let b = w.bodies();
        for i in (0..b.len()).filter(|&i| !b.is_ghost(i)) {
            let bits = b.motion_state(i).to_array().map(f64::to_bits).to_vec();
            assert!(
                all.insert(b.id[i], bits).is_none(),
                "body {} owned twice",
                b.id[i]
            );
        }
    }
    all
}

fn decomposed_run_matches_a_single_world(ranks: usize) {
    let mut single = drum();
    let mut shares = InProcessRanks::new(ranks, drum).expect("the shares are drawn");
    let dt = single.time_step();
    // 0.15 s: the bodies fall into the drum and tumble in it.
    let total = (0.15 / dt).round() as u64;
    let (mut steps, mut most_ghosts) = (0, 0);
    while steps < total {
        let n = 50.min(total - steps);
        single.run_steps(n);
        for _ in 0..n {
            shares.step().expect("every contact finds its entry");
        }
        steps += n;
        let parts: Vec<&World> = shares.shares().collect();
        assert!(
            owned_bodies(&[&single]) == owned_bodies(&parts),
            "{ranks} ranks differ from one world after {steps} steps"
        );
        let ghosts: usize = parts
            .iter()
            .map(|w| {
                (0..w.bodies().len())
                    .filter(|&i| w.bodies().is_ghost(i))
                    .count()
            })
            .sum();
        most_ghosts = most_ghosts.max(ghosts);
    }
    let (one, all) = (single.energy(), shares.energy());
    println!(
        "{ranks} ranks, {steps} steps: {} redraws, {} cuts, {} bodies changed owner, up to \
         {most_ghosts} ghosts; dissipated {:e} vs {:e}, elastic {:e} vs {:e}",
        shares.redraws,
        shares.rebalances,
        shares.migrations,
        one.dissipated,
        all.dissipated,
        one.elastic,
        all.elastic
    );
    assert!(shares.redraws >= 5, "only {} redraws", shares.redraws);
    assert!(
        shares.migrations >= 10,
        "only {} migrations",
        shares.migrations
    );
    assert!(most_ghosts >= 10, "only {most_ghosts} ghosts");
    assert_eq!(one.contacts, all.contacts, "contacts counted once each");
    for (what, a, b) in [
        (
            "kinetic",
            one.kinetic_translational,
            all.kinetic_translational,
        ),
        ("rotational", one.kinetic_rotational, all.kinetic_rotational),
        ("potential", one.potential, all.potential),
        ("elastic", one.elastic, all.elastic),
        ("dissipated", one.dissipated, all.dissipated),
        ("wall work", one.wall_work, all.wall_work),
    ] {
        // Sums of the same terms in another order: a few ulps of the largest term each.
        assert!(
            (a - b).abs() <= 1e-12 * (one.dissipated.abs() + one.potential.abs()),
            "{what}: one world {a}, {ranks} ranks {b}"
        );
    }
}

#[test]
fn two_ranks_give_the_bits_of_one_world() {
    decomposed_run_matches_a_single_world(2);
}

#[test]
fn three_ranks_give_the_bits_of_one_world() {
    decomposed_run_matches_a_single_world(3);
}

#[test]
fn five_ranks_give_the_bits_of_one_world() {
    decomposed_run_matches_a_single_world(5);
}
