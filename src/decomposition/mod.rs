//! Spatial domain decomposition for runs on several MPI ranks (issue #17; the plan is
//! `docs/mpi-plan.md`).
//!
//! What exists so far is the decomposition itself: recursive coordinate bisection by body count
//! ([`bisection`]), which every rank computes identically from global counts, and the questions
//! the distributed step will ask of it: which rank owns a point, and which ranks need a body as a
//! ghost. Counting goes through [`BodyCounter`]: [`LocalBodies`] counts bodies held in one
//! process; with the `mpi` feature, `mpi_count::DistributedBodies` adds every rank's count up.
//! The distributed step (ghost exchange, migration with contact history) is not built yet, and
//! `polydem run` refuses to start under `mpirun` with more than one rank rather than run the same
//! scene several times over.

pub mod bisection;
pub mod in_process;
#[cfg(feature = "mpi")]
pub mod mpi_count;
#[cfg(feature = "mpi")]
pub mod mpi_ranks;
pub mod share;

pub use bisection::{BodyCounter, Decomposition, LocalBodies, Region};
pub use in_process::InProcessRanks;

/// The number of processes an MPI launcher started this one among, read from the variables Open
/// MPI (`OMPI_COMM_WORLD_SIZE`) and MPICH-derived launchers (`PMI_SIZE`) set; 1 when none is set.
pub fn launched_ranks() -> usize {
    ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE"]
        .iter()
        .filter_map(|name| std::env::var(name).ok()?.trim().parse::<usize>().ok())
        .max()
        .unwrap_or(1)
}
