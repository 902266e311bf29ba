//! The domain decomposition computed together by every rank (issue #17): run under MPI,
//! `mpirun -np N target/release/deps/mpi_decomposition-…` (`.ci/mpi` does, with 2 and 3 ranks).
//! Each rank holds different bodies; the decomposition they build from global counts must be the
//! one a single process builds from all the bodies, to the bit, and must give every rank its
//! share of them.

use mpi::collective::SystemOperation;
use mpi::datatype::PartitionMut;
use mpi::traits::*;
use polydem::decomposition::mpi_count::DistributedBodies;
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
    let universe = mpi::initialize().expect("MPI initialises");
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
    let mut counts = vec![0i32; size as usize];
    world.all_gather_into(&(flat.len() as i32), &mut counts[..]);
    let displacements: Vec<i32> = counts
        .iter()
        .scan(0, |start, &c| {
            let at = *start;
            *start += c;
            Some(at)
        })
        .collect();
    let mut all = vec![0.0; counts.iter().sum::<i32>() as usize];
    world.all_gather_varcount_into(
        &flat[..],
        &mut PartitionMut::new(&mut all[..], &counts[..], &displacements[..]),
    );
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

    // Each check holds only if it holds on every rank.
    let checks = [
        (
            "the decomposition built together is the single-process one",
            same,
        ),
        ("every rank owns its share of the bodies", balanced),
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
