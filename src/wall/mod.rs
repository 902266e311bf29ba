//! Walls: fixed geometry that bodies collide with.

pub mod generators;
mod mesh;
mod motion;
mod plane;
mod solid_side;

pub use generators::{Casing, Ends, Facing, GeneratorError, Hand, Screw, ScrewPart, TriMesh};
pub use mesh::{MeshWall, MeshWallError};
pub use motion::{MotionError, WallMotion, WallPose, WallState};
pub use plane::Plane;
pub use solid_side::SolidSide;
