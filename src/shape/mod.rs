//! Particle shapes and their mass properties.
//!
//! Every shape is described in its own body frame, whose origin is the centre of mass and whose
//! axes are the principal axes of inertia, so that the integrator can use Euler's equations with a
//! diagonal inertia tensor.

mod error;
pub mod generators;
mod mass_properties;
mod polyhedron;
mod sphere;

pub use error::ShapeError;
pub use mass_properties::MassProperties;
pub use polyhedron::{ConvexPolyhedron, Edge, Face, FACE_MERGE_TOLERANCE};
pub use sphere::Sphere;

use crate::math::DVec3;

/// Mass properties of a shape of unit density, in its principal body frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnitMassProperties {
    /// Volume [m³] (equals the mass at density 1).
    pub volume: f64,
    /// Principal moments of inertia divided by density [m⁵].
    pub principal_inertia_per_density: DVec3,
}

/// The shape of a body.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    Sphere(Sphere),
}

impl Shape {
    pub fn unit_mass_properties(&self) -> UnitMassProperties {
        match self {
            Shape::Sphere(s) => s.unit_mass_properties(),
        }
    }

    /// Radius of the smallest sphere about the centre of mass that contains the shape.
    pub fn bounding_radius(&self) -> f64 {
        match self {
            Shape::Sphere(s) => s.radius,
        }
    }
}
