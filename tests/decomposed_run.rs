//! A world decomposed among ranks (`decomposition::InProcessRanks`: the shares of MPI ranks, run
//! in one process) gives every body the bits a single world gives it, step for step, on 2, 3 and
//! 5 ranks; its energy ledger, added up over the shares, is the single world's to round-off
//! (sums in another order). The scene (`common::drum`) has every kind of contact, and its bodies
//! tumble across the cuts, so bodies change owner with their contacts' histories.

mod common;

use common::drum::drum;
use polydem::body::BodyInit;
use polydem::decomposition::InProcessRanks;
use polydem::math::{DQuat, DVec3};
use polydem::shape::{Shape, Sphere};
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

/// Steps one world and its shares `spans` times `span` steps, and asserts after each span that
/// every owned body has the bits of the one world's.
fn step_alike(single: &mut World, shares: &mut InProcessRanks, spans: usize, span: u64) {
    for _ in 0..spans {
        single.run_steps(span);
        for _ in 0..span {
            shares.step().expect("every contact finds its entry");
        }
        let parts: Vec<&World> = shares.shares().collect();
        assert!(
            owned_bodies(&[&*single]) == owned_bodies(&parts),
            "{} ranks differ from one world after {} steps",
            parts.len(),
            single.steps_done()
        );
    }
}

/// Two rows of resting spheres, 20 on either side of the cut two ranks make, off the line of a
/// sphere that flies from far inside rank 0's region, deeper than any ghost layer, at a sphere
/// resting just across the cut (so each rank holds the target, and only its owner the flier).
fn flier_and_target() -> World {
    let mut w = common::wall_free_world(common::grain(0.0), DVec3::ZERO, 5e-6);
    let r = 1e-3;
    let mut sphere = |position: DVec3, velocity: DVec3| {
        w.add_body(BodyInit {
            shape: Shape::Sphere(Sphere { radius: r }),
            material: 0,
            position,
            orientation: DQuat::IDENTITY,
            velocity,
            angular_velocity: DVec3::ZERO,
        });
    };
    let target = 0.1;
    sphere(DVec3::ZERO, DVec3::new(5.0, 0.0, 0.0));
    // Rank 0's 19 others, up to half a radius short of the target: the cut falls there.
    for k in 0..19 {
        let x = target - 0.5 * r - 0.005 * (18 - k) as f64;
        sphere(DVec3::new(x, 0.05, 0.0), DVec3::ZERO);
    }
    sphere(DVec3::new(target, 0.0, 0.0), DVec3::ZERO);
    for k in 1..20 {
        sphere(
            DVec3::new(target + 0.005 * k as f64, 0.05, 0.0),
            DVec3::ZERO,
        );
    }
    w
}

/// A body deep in its owner's region may move farther than a redraw's distance before the shares
/// are redrawn (its slack, `decomposition::share::REDRAW_AT`), but not so far that a rank misses
/// a contact of its own body: the flier strikes the target, which rank 1 owns, as in one world,
/// while the flier's long way through rank 0's region calls for few redraws.
#[test]
fn a_body_flying_from_deep_in_a_share_strikes_as_in_one_world() {
    let mut single = flier_and_target();
    let mut shares = InProcessRanks::new(2, flier_and_target).expect("the shares are drawn");
    let cut = {
        let parts: Vec<&World> = shares.shares().collect();
        let target_owner = parts.iter().position(|w| {
            let b = w.bodies();
            (0..b.len()).any(|i| b.id[i] == 20 && !b.is_ghost(i))
        });
        assert_eq!(target_owner, Some(1), "the target is rank 1's");
        parts[0].bodies().len()
    };
    assert_eq!(
        cut, 21,
        "rank 0 holds its 20 bodies and the target as a ghost"
    );
    // 0.1 m at 5 m/s: the strike comes after about 3,900 steps.
    step_alike(&mut single, &mut shares, 100, 50);
    let target_speed = single.bodies().velocity[20].length();
    assert!(
        target_speed > 1.0,
        "the target was struck: {target_speed} m/s"
    );
    // Without the slack, every 0.9 skin of the flier's 0.1 m (some 550) would call for a redraw;
    // with it, those within a layer and a skin of the cut (the flier's last 2.5 mm, the
    // target's first 2 mm, some 30 at 0.9 skin each) and a few on the way.
    let skin = single.skin();
    println!(
        "{} redraws for a flight of {:.0} skins",
        shares.redraws,
        0.1 / skin
    );
    assert!(
        shares.redraws < 100,
        "{} redraws for a flight of {:.0} skins",
        shares.redraws,
        0.1 / skin
    );
}

/// Shares large enough to be sorted in space put their bodies in space order at their drawings,
/// at most every thousand steps (as a single world does), and give the bits of one world all the
/// same.
#[test]
fn shares_sorted_in_space_give_the_bits_of_one_world() {
    // 17³ = 4,913 bodies: each share holds more than the 2,048 a world is sorted from.
    let mut single = common::scrambled_bed(17, 1);
    let mut shares = InProcessRanks::new(2, || common::scrambled_bed(17, 1)).expect("drawn");
    let ids_in_order = |w: &World| w.bodies().id.windows(2).all(|p| p[0] < p[1]);
    // Bodies came in a scrambled order, kept by ids: a share that keeps its order keeps them
    // increasing.
    assert!(
        shares.shares().all(|w| !ids_in_order(w)),
        "sorted at the first drawing"
    );
    step_alike(&mut single, &mut shares, 12, 100);
    // Redraws after the thousandth step sort the shares again.
    assert!(shares.redraws >= 3, "only {} redraws", shares.redraws);
}
