//! A run whose world is stepped elsewhere than in its own `World`: as shares on MPI ranks
//! (`decomposition::mpi_run`). The run loop (`run.rs`) is the same; its world is then a view of
//! the whole, assembled from the shares when something reads it (an output, a checkpoint, a
//! check that found something), and between those only its clock goes on.

use super::RunError;
use crate::energy::EnergyReport;
use crate::shape::Shape;
use crate::World;

/// What the per-chunk checks of a run find over the whole world.
#[derive(Clone, Copy, Debug)]
pub struct SharedCheck {
    /// Some body's state is no longer finite ([`super::blow_up`]).
    pub not_finite: bool,
    /// Some body moves faster than the scene's speed limit ([`super::too_fast`]).
    pub too_fast: bool,
    /// The energy ledger of the whole.
    pub energy: EnergyReport,
}

/// A world stepped as shares (every method is a collective step of all of them).
pub trait SharedSteps {
    /// Takes `n` steps of the whole; returns its clock then: time and steps done.
    fn steps(&mut self, n: u64) -> Result<(f64, u64), RunError>;
    /// The checks of [`SharedCheck`], bodies faster than `speed_limit` [m/s] counting as too fast.
    fn check(&mut self, speed_limit: f64) -> Result<SharedCheck, RunError>;
    /// Makes `whole` (built from the same scene) the whole world as it is now (see
    /// `World::assemble`).
    fn gather(&mut self, whole: &mut World) -> Result<(), RunError>;
    /// Starts the shares again from `whole` (after bodies were inserted into it, or to resume a
    /// run), its polyhedral shapes named by their place in `templates`.
    fn scatter(&mut self, whole: &World, templates: &[Shape]) -> Result<(), RunError>;
}
