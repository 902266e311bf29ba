//! Benchmarks run by `polydem bench`: shared scenes and timing loops whose figures go into
//! `docs/benchmarks.md` with the command that produced them.

pub mod broad_phase;
#[cfg(feature = "mpi")]
pub mod mpi_scene;
pub mod scene;
