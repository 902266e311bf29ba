//! Spatial domain decomposition for runs on several MPI ranks (issue #17; the plan is
//! `docs/mpi-plan.md`).
//!
//! - [`bisection`]: recursive coordinate bisection by body count, which every rank computes
//!   identically from global counts, and the questions the step asks of it: which rank owns a
//!   point, and which ranks need a body as a ghost. Counting goes through [`BodyCounter`]:
//!   [`LocalBodies`] counts bodies held in one process; with the `mpi` feature,
//!   `mpi_count::DistributedBodies` adds every rank's count up.
//! - [`share`]: one rank's share of the world (owned bodies and ghosts) and its half of every
//!   exchange: the ghosts' states after each step, the redraw that hands bodies over with their
//!   contacts' histories. The design is described there.
//! - The transports: [`InProcessRanks`] (every share in this process: the reference, and the
//!   tests) and, with the `mpi` feature, `mpi_ranks::MpiRanks` (one share per MPI rank). Both
//!   give every body the bits a single world gives it.
//!
//! - [`rank_times`]: where a rank's time goes (its own step, the collectives, the redraws).
//! - [`mpi_run`] (feature `mpi`): `polydem run` and `resume` on ranks, rank 0 leading the run
//!   loop (`run::run_shared`) and writing outputs and checkpoints from the whole world assembled
//!   from the shares (`World::assemble`); insertions are made in the whole, from which the
//!   shares start again (`MpiRanks::restart`).

pub mod bisection;
pub mod in_process;
#[cfg(feature = "mpi")]
pub mod mpi_count;
#[cfg(feature = "mpi")]
pub mod mpi_ranks;
#[cfg(feature = "mpi")]
pub mod mpi_run;
pub mod rank_times;
pub mod share;

pub use bisection::{BodyCounter, Decomposition, LocalBodies, Region};
pub use in_process::InProcessRanks;
pub use rank_times::RankTimes;

/// The number of processes an MPI launcher started this one among, read from the variables Open
/// MPI (`OMPI_COMM_WORLD_SIZE`) and MPICH-derived launchers (`PMI_SIZE`) set; 1 when none is set.
pub fn launched_ranks() -> usize {
    ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE"]
        .iter()
        .filter_map(|name| std::env::var(name).ok()?.trim().parse::<usize>().ok())
        .max()
        .unwrap_or(1)
}
