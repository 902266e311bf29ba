//! Walls: fixed geometry that bodies collide with.

mod plane;

pub use plane::Plane;
