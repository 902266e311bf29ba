//! The domain decomposition computed together by every rank, and a run decomposed among them
//! (issue #17): run under MPI, `mpirun -np N target/release/deps/mpi_decomposition-…`
//! (`.ci/mpi` does, with 2 and 3 ranks).
//! - Each rank holds different bodies; the decomposition they build from global counts must be
//!   the one a single process builds from all the bodies, to the bit, and must give every rank
//!   its share of them.
//! - The drum of every contact kind (`common::drum`), stepped by the ranks together
//!   (`MpiRanks`), must give every body the bits a single world gives it, which rank 0 steps
//!   beside them; and the ledger, added up over the ranks, the single world's to round-off.
//! - The whole world assembled on rank 0 from the shares (what `polydem run` on ranks writes its
//!   outputs and checkpoints from) must be the single world: the same bodies to the bit, the same
//!   contacts, and, stepped on by itself, the single world's bits still (which holds only if
//!   every contact's history and last load came along).

mod common;

use common::drum::drum;
use mpi::collective::SystemOperation;
use mpi::datatype::PartitionMut;
use mpi::traits::*;
use polydem::decomposition::mpi_count::DistributedBodies;
use polydem::decomposition::mpi_ranks::MpiRanks;
use polydem::decomposition::{Decomposition, LocalBodies};
use polydem::math::DVec3;
use polydem::rng::SplitMix64;

/// This rank's bodies: a number and a cloud that differ from rank to rank.
fn bodies_of(rank: i32) -> Vec<DVec3> {
    let mut rng = SplitMix64::new(17 + rank as u64);
    let count = 400 + 137 * rank as usize;
    let centre = DVec3::new(rank as f64 * 0.3, 0.0, 0.0);
    (0..count)
        .map(|_| {
            centre
                + DVec3::new(
                    rng.uniform(0.0, 2.0),
                    rng.uniform(0.0, 0.7),
                    rng.uniform(0.0, 0.2),
                )
        })
        .collect()
}

fn main() {
    // As `polydem` does, so that `MpiRanks::run_steps` steps on the world's pool (not the
    // fallback from this thread, which `assembled_world_is_one_world` covers with `step`).
    let (universe, threading) =
        mpi::initialize_with_threading(mpi::Threading::Serialized).expect("MPI initialises");
    assert!(
        threading >= mpi::Threading::Serialized,
        "MPI gives {threading:?}, not the Serialized level a rank steps on its pool with"
    );
    let world = universe.world();
    let (rank, size) = (world.rank(), world.size());
    let local = bodies_of(rank);

    let distributed = Decomposition::new(
        size as usize,
        &mut DistributedBodies {
            local: LocalBodies(&local),
            communicator: &world,
        },
    );

    // Every rank's bodies on every rank, in rank order.
    let flat: Vec<f64> = local.iter().flat_map(|p| p.to_array()).collect();
    let all = gathered(&world, &flat);
    let everyone: Vec<DVec3> = all.chunks(3).map(DVec3::from_slice).collect();
    let single = Decomposition::new(size as usize, &mut LocalBodies(&everyone));
    let same = distributed == single;

    // Every body has one owner, and each rank owns ⌊n/P⌋ or ⌈n/P⌉ of them.
    let mut owned = vec![0u64; size as usize];
    for p in &local {
        owned[distributed.owner(*p)] += 1;
    }
    let mut total = vec![0u64; size as usize];
    world.all_reduce_into(&owned[..], &mut total[..], SystemOperation::sum());
    let n = everyone.len() as u64;
    let (floor, ceil) = (n / size as u64, n.div_ceil(size as u64));
    let balanced = total.iter().sum::<u64>() == n && total.iter().all(|&c| c == floor || c == ceil);

    let decomposed = decomposed_run_is_one_world(&world);
    let assembled = assembled_world_is_one_world(&world);

    // Each check holds only if it holds on every rank.
    let checks = [
        (
            "the decomposition built together is the single-process one",
            same,
        ),
        ("every rank owns its share of the bodies", balanced),
        (
            "a decomposed run gives every body the bits of one world",
            decomposed,
        ),
        (
            "the whole assembled from the shares is one world, and steps on as one",
            assembled,
        ),
    ];
    let mut failed = 0;
    for (what, holds) in checks {
        let mut everywhere = 0i32;
        world.all_reduce_into(&(holds as i32), &mut everywhere, SystemOperation::min());
        if everywhere == 0 {
            failed += 1;
            if rank == 0 {
                eprintln!("FAILED on {size} ranks: {what} (owned {total:?} of {n})");
            }
        }
    }
    if rank == 0 {
        println!("mpi_decomposition on {size} ranks, {n} bodies, owned {total:?}");
        println!("{} passed, {failed} failed", checks.len() - failed);
    }
    if failed > 0 {
        std::process::exit(1);
    }
}

/// Every owned body's id and state as bits, this rank's, as one array (id, then 22 numbers).
fn owned_bits(w: &polydem::World) -> Vec<u64> {
    let b = w.bodies();
    let mut bits = Vec::new();
    for i in (0..b.len()).filter(|&i| !b.is_ghost(i)) {
        bits.push(b.id[i]);
        bits.extend(b.motion_state(i).to_array().map(f64::to_bits));
    }
    bits
}

/// The drum stepped by the ranks together and, on rank 0, by a single world beside them: the
/// bodies' states gathered on rank 0 must be the single world's, bit for bit, after every stretch
/// of steps. True on every rank if so.
fn decomposed_run_is_one_world(world: &impl Communicator) -> bool {
    let rank = world.rank();
    let mut ranks = MpiRanks::new(drum(), world).expect("the shares are drawn");
    let mut single = (rank == 0).then(drum);
    let dt = ranks.world().time_step();
    // 0.15 s: the bodies fall into the drum and tumble in it.
    let total = (0.15 / dt).round() as u64;
    let (mut steps, mut ok) = (0, true);
    while steps < total && ok {
        let n = 1000.min(total - steps);
        // On the world's thread pool, MPI calls included, as `polydem` steps a rank.
        ranks.run_steps(n).expect("every contact finds its entry");
        steps += n;
        let mine = owned_bits(ranks.world());
        let all = gathered(world, &mine);
        let mut same = true;
        if let Some(single) = single.as_mut() {
            single.run_steps(n);
            let gathered: std::collections::BTreeMap<u64, &[u64]> =
                all.chunks(23).map(|c| (c[0], &c[1..])).collect();
            let expected = owned_bits(single);
            let expected: std::collections::BTreeMap<u64, &[u64]> =
                expected.chunks(23).map(|c| (c[0], &c[1..])).collect();
            same = gathered == expected && all.len() == 23 * expected.len();
            if !same {
                eprintln!("rank 0: the decomposed run differs from one world after {steps} steps");
            }
        }
        let mut everywhere = 0i32;
        world.all_reduce_into(&(same as i32), &mut everywhere, SystemOperation::min());
        ok = everywhere == 1;
    }
    let energy = ranks.energy();
    let redraws = ranks.total(ranks.redraws);
    let migrations = ranks.total(ranks.migrations);
    if let Some(single) = &single {
        let e = single.energy();
        let scale = e.dissipated.abs() + e.potential.abs();
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * scale;
        ok &= close(e.kinetic_translational, energy.kinetic_translational)
            && close(e.elastic, energy.elastic)
            && close(e.dissipated, energy.dissipated)
            && e.contacts == energy.contacts;
        println!(
            "decomposed drum on {} ranks: {steps} steps, {} redraws (summed over ranks), {} \
             bodies changed owner; dissipated {:e} (one world {:e})",
            world.size(),
            redraws,
            migrations,
            energy.dissipated,
            e.dissipated
        );
    }
    ok
}

/// The drum stepped by the ranks, assembled on rank 0 (`MpiRanks::gather`) after a stretch of
/// steps, against a single world stepped as far beside them: the same bodies to the bit, the
/// same ledger to round-off; then both stepped on by themselves, the same bits again. True on
/// every rank if so.
fn assembled_world_is_one_world(world: &impl Communicator) -> bool {
    let rank = world.rank();
    let mut ranks = MpiRanks::new(drum(), world).expect("the shares are drawn");
    let dt = ranks.world().time_step();
    // 0.08 s: the bodies are in the drum and touch each other and its wall.
    let steps = (0.08 / dt).round() as u64;
    for _ in 0..steps {
        ranks.step().expect("every contact finds its entry");
    }
    let mut whole = (rank == 0).then(drum);
    ranks.gather(whole.as_mut()).expect("the parts assemble");
    let Some(mut whole) = whole else {
        return true;
    };
    let mut single = drum();
    single.run_steps(steps);
    let by_id = |w: &polydem::World| -> std::collections::BTreeMap<u64, Vec<u64>> {
        owned_bits(w)
            .chunks(23)
            .map(|c| (c[0], c[1..].to_vec()))
            .collect()
    };
    let (e, s) = (whole.energy(), single.energy());
    let scale = s.dissipated.abs() + s.potential.abs();
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * scale;
    let mut ok = by_id(&whole) == by_id(&single)
        && e.contacts == s.contacts
        && s.contacts > 0
        && close(e.kinetic_translational, s.kinetic_translational)
        && close(e.elastic, s.elastic)
        && close(e.dissipated, s.dissipated)
        && close(e.wall_work, s.wall_work);
    if !ok {
        eprintln!("rank 0: the assembled world differs from one world after {steps} steps");
    }
    // 0.04 s more, each by itself: the contacts' histories decide these bits.
    let more = (0.04 / dt).round() as u64;
    whole.run_steps(more);
    single.run_steps(more);
    let on = by_id(&whole) == by_id(&single);
    if !on {
        eprintln!("rank 0: the assembled world, stepped on, parts from one world");
    }
    ok &= on;
    println!(
        "assembled drum on {} ranks: {} bodies, {} contacts after {steps} steps, and the same \
         bits {more} steps on: {ok}",
        world.size(),
        whole.bodies().len(),
        e.contacts
    );
    ok
}

/// Every rank's `mine`, one after the other in rank order, on every rank.
fn gathered<T: Equivalence + Default + Clone>(world: &impl Communicator, mine: &[T]) -> Vec<T> {
    let mut counts = vec![0i32; world.size() as usize];
    world.all_gather_into(&(mine.len() as i32), &mut counts[..]);
    let starts: Vec<i32> = counts
        .iter()
        .scan(0, |at, &c| {
            let start = *at;
            *at += c;
            Some(start)
        })
        .collect();
    let mut all = vec![T::default(); counts.iter().sum::<i32>() as usize];
    world.all_gather_varcount_into(
        mine,
        &mut PartitionMut::new(&mut all[..], &counts[..], &starts[..]),
    );
    all
}
