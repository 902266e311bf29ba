//! Contacts of non-convex polyhedra: the seed paper's vertex law on closed triangle meshes, with
//! the contact split into separate regions.
//!
//! # Points
//!
//! For bodies A and B (either may be convex; at least one is a mesh) the springs of the vertex
//! law sit at:
//!
//! 1. vertices of one body inside the other — the ray-casting test of the seed paper
//!    (`geometry::point_in_polyhedron`, exact, accelerated by the shape's bounding-volume
//!    hierarchy); depth: the distance to the nearest point of the other's surface, force along
//!    the direction from the vertex to that point (the face normal when it lies inside a face);
//! 2. edges: each part of a sharp edge inside the other body is a spring at its deepest point,
//!    less what its deeper end vertex already carries (`edge_spring`: the potential is
//!    ½ k (D² − d_end²)). This takes the place of the convex case's edge–edge points: it covers
//!    two ridges crossing, and an edge pressed into a face with both its ends outside (crossed
//!    beams, ubiquitous between the arms of crosses), which no vertex and no crossing of edges
//!    sees; and it adds nothing to a face contact, where edges are deepest at their corners. Such
//!    a part starts and ends on the other body's surface, so its spring appears and vanishes at
//!    depth zero, and the force stays continuous as edges enter and leave;
//! 3. crossing points: where an edge of one surface passes through a triangle (face) of the other
//!    (exact orientation tests); depth zero, they outline the regions and delimit the parts of
//!    edges inside.
//!
//! Only the vertices and edges near the other body (from the hierarchy, by the other body's box)
//! are looked at. The parts of an edge between its crossings are told inside or outside by the
//! exact test at their middles.
//!
//! # Regions
//!
//! Two bodies that are not convex may touch in several places at once (two crosses hooked into
//! each other). The points are grouped into connected regions by the topology of the overlap, with
//! a union–find:
//!
//! - along an edge, the part inside the other body joins its two ends (a vertex inside, or a
//!   crossing point) and its spring;
//! - a face of A and a face of B that intersect do so in a segment whose two ends are crossing
//!   points (an edge of A's face through B's face, or an edge of B's face through A's face): the
//!   crossing points sharing a pair (face of A, face of B) are joined. These segments make up the
//!   intersection curves of the two surfaces, so each curve becomes one group.
//!
//! A connected piece of A ∩ B is bounded by pieces of both surfaces meeting along such curves, so
//! its points end up in one group; separate pieces share no edge and no face pair, so they stay
//! apart. Each region with penetrating depth becomes one contact: the springs of the vertex law at
//! the depth-weighted mean point, their exact moment as a couple (`aggregate`), and as
//! "area" the area of the region's points projected on the plane normal to the contact (so that
//! twisting friction and rocking damping act as for an area contact). At most [`MAX_REGIONS`]
//! regions are kept; beyond that the one with the least depth is merged into the nearest (the
//! forces stay exact: springs only add).
//!
//! # Files
//!
//! - `solid`: a body as these contacts see it (convex or mesh) and its queries: vertices and
//!   edges near a box, inside or outside, depth, crossings of a segment through its faces;
//! - `regions`: the points, their union–find, and one contact per region;
//! - `solid_solid`: two bodies, by the three kinds of points;
//! - `mesh_plane`: a mesh body behind a plane or a face of a mesh wall;
//! - `mesh_sphere`: a mesh body and a sphere.

mod mesh_plane;
mod mesh_sphere;
mod regions;
mod solid;
mod solid_solid;
#[cfg(test)]
mod test_bodies;

pub use mesh_plane::{mesh_plane, mesh_wall_regions};
pub use mesh_sphere::mesh_sphere;
pub use regions::RegionScratch;
pub use solid::Solid;
pub use solid_solid::solid_solid;

use crate::math::{DQuat, DVec3};

/// The most contacts one pair of bodies (or a body and a wall) keeps at once.
pub const MAX_REGIONS: usize = 8;

/// A body's pose.
#[derive(Clone, Copy, Debug)]
pub struct Pose {
    pub position: DVec3,
    pub orientation: DQuat,
}
