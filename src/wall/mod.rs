//! Walls: fixed geometry that bodies collide with.

pub mod generators;
mod mesh;
mod motion;
mod plane;

pub use generators::{Ends, Facing, GeneratorError, Hand, Screw, TriMesh};
pub use mesh::{Feature, MeshWall, MeshWallError, DEFAULT_SMOOTH_ANGLE};
pub use motion::{MotionError, WallMotion, WallPose, WallState};
pub use plane::Plane;
