//! Geometric algorithms on points and triangle meshes: exact predicates, convex hull, symmetric
//! eigen-decomposition (for principal axes), point-in-polyhedron classification.

pub mod bvh;
pub mod convex_hull;
pub mod point_in_polyhedron;
pub mod predicates;
pub mod symmetric_eigen;
#[cfg(test)]
pub(crate) mod test_meshes;
pub mod triangle;

pub use point_in_polyhedron::{locate_point, locate_point_bvh, Location};
