//! Refusing mesh walls that face away from the bodies: a mesh wall pushes bodies out of its front
//! (where its triangles' normals point, by the right-hand rule of their winding), so a body
//! reaching a wall from behind falls through it or is shot out of it. A box whose triangles face
//! out holding spheres, or a chute whose STL file is wound the other way, would run to the end
//! with nonsense (issue #12). The test: every body and every insertion region, falling along
//! gravity, must land on the front of the first mesh-wall triangle under it.

use super::{KeyPath, Scene, SceneError};
use crate::body::BodyInit;
use crate::math::DVec3;
use crate::wall::{MeshWall, SolidSide};

/// At most this many bodies placed at the start are tried (evenly spread over them): enough to
/// catch a wall facing the wrong way under a bed, cheap for a bed of 10⁶.
const BODIES_TRIED: usize = 2000;

impl Scene {
    /// Refuses a start in which a body, or a point of an insertion region, would fall onto the
    /// back of a mesh wall (see the module's note).
    pub(super) fn check_mesh_wall_sides(
        &self,
        bodies: &[(BodyInit, KeyPath)],
        walls: &[MeshWall],
        gravity: DVec3,
    ) -> Result<(), SceneError> {
        let Some(down) = gravity.try_normalize() else {
            return Ok(());
        };
        if walls.is_empty() {
            return Ok(());
        }
        let stride = bodies.len().div_ceil(BODIES_TRIED).max(1);
        let from_bodies = bodies
            .iter()
            .step_by(stride)
            .map(|(b, key)| (b.position, key.clone(), "the particle"));
        let from_regions = self.spec.insertions.iter().enumerate().flat_map(|(n, i)| {
            let (lo, hi) = i.bounds();
            let (lo, hi) = (DVec3::from(lo), DVec3::from(hi));
            // The centre and the middles of the region's four upright quarters; for an inlet,
            // points of the layer it fills (its box may reach beyond it).
            let points: Vec<DVec3> = match &i.inlet {
                Some(inlet) => inlet
                    .probe_points(i.inlet_depth())
                    .into_iter()
                    .map(DVec3::from)
                    .collect(),
                None => [0.5, 0.25, 0.75]
                    .into_iter()
                    .flat_map(|a| [0.25, 0.5, 0.75].into_iter().map(move |b| (a, b)))
                    .map(|(a, b)| lo + (hi - lo) * DVec3::new(a, b, 0.5))
                    .collect(),
            };
            let key = if i.inlet.is_some() {
                "inlet"
            } else {
                "region_min"
            };
            points
                .into_iter()
                .map(move |p| (p, KeyPath::entry("insert", n).key(key), "bodies inserted"))
        });
        for (point, key, what) in from_bodies.chain(from_regions) {
            if let Some((n, triangle, normal)) = back_landing(point, down, walls) {
                return Err(self.error(
                    key,
                    format!(
                        "{what} at {:?} would fall onto the back of [[mesh_wall]] #{} (its \
                         triangle {triangle} faces along gravity, normal {:?}), through which it \
                         would fall or be shot out: a wall pushes bodies out of the side its \
                         triangles face (their corners counter-clockwise seen from there). Reverse \
                         the winding: `flip = true` on a mesh file, `facing = \"outward\"` / \
                         \"inward\" on a generated wall",
                        point.to_array(),
                        n + 1,
                        normal.to_array()
                    ),
                ));
            }
        }
        Ok(())
    }
}

impl Scene {
    /// Refuses a start with a body on the solid side of a closed mesh wall — outside a closed
    /// container, inside a block — as a plane refuses a body behind it (issue #12: such a body
    /// was accepted, and shot out at the first contact).
    pub(super) fn check_bodies_behind_closed_walls(
        &self,
        bodies: &[(BodyInit, KeyPath)],
        walls: &[MeshWall],
    ) -> Result<(), SceneError> {
        for (n, wall) in walls.iter().enumerate() {
            let Some(side) = SolidSide::of(wall) else {
                continue;
            };
            if let Some((b, key)) = bodies.iter().find(|(b, _)| side.contains(wall, b.position)) {
                return Err(self.error(
                    key.clone(),
                    format!(
                        "the particle at {:?} lies behind [[mesh_wall]] #{}: {}, where no body \
                         can be; move it to the open side (or, if the wall faces the wrong way, \
                         reverse its winding: `flip = true` on a mesh file, `facing` on a \
                         generated wall)",
                        b.position.to_array(),
                        n + 1,
                        side.describe()
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// The first mesh-wall triangle a point falling along `down` meets, if it meets its back:
/// (wall, triangle, normal).
fn back_landing(point: DVec3, down: DVec3, walls: &[MeshWall]) -> Option<(usize, usize, DVec3)> {
    let mut first: Option<(f64, usize, usize, DVec3)> = None;
    for (n, wall) in walls.iter().enumerate() {
        let pose = wall.pose();
        for (t, tri) in wall.triangles().iter().enumerate() {
            let [a, b, c] = tri.map(|v| pose.to_world(wall.vertices()[v as usize]));
            if let Some(distance) = ray_hits(point, down, a, b, c) {
                if first.is_none_or(|(d, ..)| distance < d) {
                    let normal = (b - a).cross(c - a).normalize_or_zero();
                    first = Some((distance, n, t, normal));
                }
            }
        }
    }
    let (_, n, t, normal) = first?;
    (normal.dot(down) > 0.0).then_some((n, t, normal))
}

/// Distance along the ray `origin + s·direction` (s > 0) to where it crosses triangle abc
/// (Möller & Trumbore 1997), or `None`. A ray grazing an edge may be counted for either
/// neighbour: both lie on the same side of the body when the wall is wound consistently.
fn ray_hits(origin: DVec3, direction: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Option<f64> {
    let (e1, e2) = (b - a, c - a);
    let p = direction.cross(e2);
    let det = e1.dot(p);
    if det.abs() <= 1e-14 * e1.length() * e2.length() {
        return None; // the ray runs along the triangle's plane
    }
    let inv = 1.0 / det;
    let s = origin - a;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = direction.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let distance = e2.dot(q) * inv;
    (distance > 0.0).then_some(distance)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ray_down_hits_a_floor_triangle_once_at_its_height() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let down = DVec3::NEG_Z;
        let hit = ray_hits(DVec3::new(0.2, 0.2, 3.0), down, a, b, c);
        assert_eq!(hit, Some(3.0));
        assert_eq!(ray_hits(DVec3::new(0.8, 0.8, 3.0), down, a, b, c), None);
        assert_eq!(ray_hits(DVec3::new(0.2, 0.2, -1.0), down, a, b, c), None);
        assert_eq!(ray_hits(DVec3::new(0.2, 0.2, 3.0), DVec3::X, a, b, c), None);
    }
}
