//! The solid side of a closed mesh wall: inside the surface for a wall whose triangles face out (a
//! block, a screw's blade), outside it for one whose triangles face in (a closed container). No
//! body's centre can be there: one found there at the start was placed wrong, one found there
//! during a run has gone through the wall. Open sheets (a chute) and closed meshes enclosing no
//! volume (a plate with a back) have no solid side.

use super::MeshWall;
use crate::geometry::bvh::Bvh;
use crate::geometry::point_in_polyhedron::{locate_point_bvh, Location};
use crate::math::DVec3;

/// A closed mesh wall's surface in its reference placement, ready for point queries.
pub struct SolidSide {
    vertices: Vec<DVec3>,
    triangles: Vec<[usize; 3]>,
    bvh: Bvh,
    /// Whether the solid side is inside the surface. Decided by the sign of the enclosed volume,
    /// so a container holding a block is right for both: a point is on the solid side when its
    /// crossing parity says `Inside` for a net outward wall and `Outside` for a net inward one.
    solid_inside: bool,
}

impl SolidSide {
    /// The solid side of `wall`, or `None` for an open wall or one that encloses no volume.
    pub fn of(wall: &MeshWall) -> Option<Self> {
        if !wall.is_closed() {
            return None;
        }
        let vertices = wall.vertices().to_vec();
        let triangles: Vec<[usize; 3]> = wall
            .triangles()
            .iter()
            .map(|t| t.map(|v| v as usize))
            .collect();
        let volume: f64 = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| vertices[v]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum();
        // A sheet wound both ways (a plate with a back) is closed but encloses nothing: its
        // volume is rounding noise, and it has no solid side.
        if !(volume.is_finite() && volume.abs() > 1e-9 * wall.area().powf(1.5)) {
            return None;
        }
        let bvh = Bvh::new(&vertices, &triangles);
        Some(Self {
            vertices,
            triangles,
            bvh,
            solid_inside: volume > 0.0,
        })
    }

    /// Whether `point` (world frame) lies on the solid side of `wall` where it is now (`wall`
    /// must be the wall this was made of). A non-finite point is not.
    pub fn contains(&self, wall: &MeshWall, point: DVec3) -> bool {
        let p = wall.pose().to_reference(point);
        let solid = if self.solid_inside {
            Location::Inside
        } else {
            Location::Outside
        };
        p.is_finite() && locate_point_bvh(p, &self.vertices, &self.triangles, &self.bvh) == solid
    }

    /// Which side is solid, for messages.
    pub fn describe(&self) -> &'static str {
        if self.solid_inside {
            "inside the solid its triangles enclose"
        } else {
            "outside the closed container it forms"
        }
    }
}
