//! Particle shapes and their mass properties.
//!
//! Every shape is described in its own body frame, whose origin is the centre of mass and whose
//! axes are the principal axes of inertia, so that the integrator can use Euler's equations with a
//! diagonal inertia tensor.

mod error;
pub mod generators;
pub mod import;
mod mass_properties;
pub mod mesh_check;
pub mod nonconvex;
pub mod nonconvex_generators;
mod polyhedron;
mod sphere;

pub use error::ShapeError;
pub use mass_properties::MassProperties;
pub use nonconvex::{ConvexPart, NonConvexPolyhedron};
pub use polyhedron::{ConvexPolyhedron, Edge, Face, FACE_MERGE_TOLERANCE};
pub use sphere::Sphere;

use crate::math::DVec3;
use std::sync::Arc;

/// Mass properties of a shape of unit density, in its principal body frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnitMassProperties {
    /// Volume [m³] (equals the mass at density 1).
    pub volume: f64,
    /// Principal moments of inertia divided by density [m⁵].
    pub principal_inertia_per_density: DVec3,
}

/// The shape of a body.
#[derive(Clone, Debug)]
pub enum Shape {
    Sphere(Sphere),
    /// Shared: many bodies usually have the same polyhedron.
    Convex(Arc<ConvexPolyhedron>),
    /// A closed triangle mesh, convex or not (shared like `Convex`).
    NonConvex(Arc<NonConvexPolyhedron>),
}

impl PartialEq for Shape {
    /// Polyhedra are equal when they are the same shared shape: comparing vertex lists would
    /// cost more than it saves.
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (Shape::Sphere(a), Shape::Sphere(b)) => a == b,
            (Shape::Convex(a), Shape::Convex(b)) => Arc::ptr_eq(a, b),
            (Shape::NonConvex(a), Shape::NonConvex(b)) => Arc::ptr_eq(a, b),
            _ => false,
        }
    }
}

impl Shape {
    pub fn unit_mass_properties(&self) -> UnitMassProperties {
        match self {
            Shape::Sphere(s) => s.unit_mass_properties(),
            Shape::Convex(p) => p.unit_mass_properties(),
            Shape::NonConvex(p) => p.unit_mass_properties(),
        }
    }

    /// Radius of the smallest sphere about the centre of mass that contains the shape.
    pub fn bounding_radius(&self) -> f64 {
        match self {
            Shape::Sphere(s) => s.radius,
            Shape::Convex(p) => p.bounding_radius(),
            Shape::NonConvex(p) => p.bounding_radius(),
        }
    }

    /// Area of the largest face of a polyhedron (`None` for a sphere): the largest contact area
    /// a flat contact can have, which sets the stiffest contact under the volume law. For a
    /// non-convex body described by convex parts, the largest face of a part; otherwise its
    /// largest flat face.
    pub fn largest_face_area(&self) -> Option<f64> {
        match self {
            Shape::Sphere(_) => None,
            Shape::Convex(p) => Some(convex_largest_face_area(p)),
            Shape::NonConvex(p) if !p.parts().is_empty() => p
                .parts()
                .iter()
                .map(|part| convex_largest_face_area(&part.shape))
                .reduce(f64::max),
            Shape::NonConvex(p) => Some(p.largest_face().0),
        }
    }

    /// The most vertex-law springs one flat contact of this shape can hold: the corners of its
    /// largest flat face (`None` for a sphere or a convex polyhedron, whose vertex law is bounded
    /// by the volume law's estimate).
    pub fn largest_face_corners(&self) -> Option<usize> {
        match self {
            Shape::NonConvex(p) if p.parts().is_empty() => Some(p.largest_face().1),
            _ => None,
        }
    }

    /// Whether a contact with this shape may touch in several separate regions at once (each a
    /// contact of its own).
    pub fn has_regions(&self) -> bool {
        matches!(self, Shape::NonConvex(_))
    }

    /// Radius of the sphere of equal volume: the size that enters contact laws (R*) and the
    /// time-step estimate for a non-spherical body.
    pub fn equivalent_radius(&self) -> f64 {
        match self {
            Shape::Sphere(s) => s.radius,
            Shape::Convex(_) | Shape::NonConvex(_) => {
                (3.0 * self.unit_mass_properties().volume / (4.0 * std::f64::consts::PI)).cbrt()
            }
        }
    }
}

fn convex_largest_face_area(p: &ConvexPolyhedron) -> f64 {
    let v = p.vertices();
    p.faces()
        .iter()
        .map(|f| {
            let first = v[f.vertices[0]];
            let twice: DVec3 = f
                .vertices
                .windows(2)
                .map(|w| (v[w[0]] - first).cross(v[w[1]] - first))
                .sum();
            0.5 * twice.length()
        })
        .fold(0.0, f64::max)
}
