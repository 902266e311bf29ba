//! The stages of a time step's contact pipeline, each a function with explicit inputs and outputs:
//!
//! 1. [`candidates`] — the neighbour search: which bodies and partners may touch (rebuilt only when
//!    something has moved more than half the skin);
//! 2. [`detect`] — the narrow phase: the contact geometry of every candidate, into the contact store;
//! 3. [`forces::evaluate`] — the contact laws: force, moment and energy of every contact;
//! 4. [`forces::accumulate`] — the sums onto the bodies; [`wall_loads`] the reactions on the walls.
//!
//! `World::advance` (src/world.rs) runs them between the two half-kicks of the integrator.

pub mod candidates;
pub mod detect;
pub mod forces;
pub mod wall_loads;

pub use candidates::NeighbourSearch;
pub use detect::{detect, RegionOutput, Scene};
pub use forces::{accumulate, evaluate, predict_end_velocities, LawInputs};
pub use wall_loads::WallLoads;
