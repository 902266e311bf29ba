//! Narrow phase: the contact geometry of a pair that the broad phase found close.
//!
//! One file per pair of shape kinds. Each returns `None` when the bodies do not touch.

mod sphere_plane;
mod sphere_sphere;

pub use sphere_plane::sphere_plane;
pub use sphere_sphere::sphere_sphere;

use crate::math::DVec3;

/// Where and how deeply two bodies overlap.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geometry {
    /// Unit normal pointing from the second body (or wall) towards the first.
    pub normal: DVec3,
    /// Contact point: the middle of the overlap [m].
    pub point: DVec3,
    /// Overlap depth δ > 0 [m].
    pub overlap: f64,
}
