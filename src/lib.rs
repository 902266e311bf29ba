//! polydem: a Discrete Element Method engine for spheres and polyhedra.
//!
//! Data flows one way through a step (see `World::step`): bodies are kicked and drifted by the
//! integrator, the broad phase finds close pairs, the narrow phase their contact geometry, the
//! contact laws their forces, and the forces are summed onto the bodies.

pub mod bench;
pub mod body;
pub mod broad_phase;
mod busy;
pub mod checkpoint;
pub mod contact;
pub mod contact_law;
pub mod decomposition;
pub mod energy;
pub mod flow;
pub mod geometry;
pub mod groups;
pub mod huge_pages;
pub mod integrate;
pub mod io;
pub mod material;
pub mod math;
pub mod narrow_phase;
pub mod picture;
pub mod rng;
pub mod run;
pub mod scene;
pub mod shape;
pub mod step;
pub mod tight;
pub mod time_table;
pub mod timestep;
pub mod wall;
pub(crate) mod wide;
pub mod world;

pub use world::{World, WorldConfig};
