//! Geometric algorithms on points and triangle meshes: exact predicates, convex hull, symmetric
//! eigen-decomposition (for principal axes), point-in-polyhedron classification, welding, and the
//! triangle mesh with adjacency shared by mesh walls and non-convex particles.

pub mod bvh;
pub mod compressed_rows;
pub mod convex_hull;
pub mod point_in_polyhedron;
pub mod predicates;
pub mod symmetric_eigen;
#[cfg(test)]
pub(crate) mod test_meshes;
pub mod triangle;
pub mod triangle_grid;
pub mod triangle_mesh;
pub mod weld;

pub use point_in_polyhedron::{locate_point, locate_point_bvh, Location};
