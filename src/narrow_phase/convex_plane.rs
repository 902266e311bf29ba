//! A convex polyhedron against a plane wall: the part of the body behind the plane.
//!
//! Worked in the body frame (the plane is turned into it, not the body into the world). Each face
//! is clipped by the plane on the fly and its kept part summed into the divergence-theorem
//! integrals at once, so nothing is stored. The reference point of the tetrahedra is on the plane,
//! so the cut section (the "cap" that closes the submerged part) contributes no volume and no
//! moment and need not be built: its vector area is minus that of the clipped faces.

use super::clip::{Plane, PLANE_TOLERANCE};
use super::convex_convex::VolumeContact;
use crate::math::{DQuat, DVec3};
use crate::shape::ConvexPolyhedron;

/// The part of `a` (centre `xa`, orientation `qa`) behind the plane through `point` with unit
/// `normal` (pointing into the free side). The contact normal is the plane's `normal` (from the
/// wall towards the body), the area that of the cut section, the centroid that of the submerged
/// part.
///
/// `None` when nothing is behind the plane (touching included) and, as for `sphere_plane`, when
/// the whole body is behind it: such a body is outside the domain, not in contact.
pub fn convex_plane(
    a: &ConvexPolyhedron,
    xa: DVec3,
    qa: DQuat,
    point: DVec3,
    normal: DVec3,
) -> Option<VolumeContact> {
    let to_body = qa.inverse();
    let n = to_body * normal;
    let plane = Plane {
        normal: n,
        offset: n.dot(to_body * (point - xa)),
    };
    let tolerance = PLANE_TOLERANCE * a.bounding_radius();
    let vertices = a.vertices();
    let deepest = vertices[a.support_index(-n)];
    let highest = vertices[a.support_index(n)];
    let deepest_distance = plane.distance(deepest);
    if deepest_distance >= -tolerance || plane.distance(highest) <= tolerance {
        return None;
    }
    // On the plane, next to the submerged part.
    let r = deepest - n * deepest_distance;

    let (mut six_volume, mut moment, mut vector_area) = (0.0, DVec3::ZERO, DVec3::ZERO);
    for face in a.faces() {
        // Sutherland–Hodgman by one plane, streamed: the kept corners (relative to r) are fanned
        // from the first one as they come.
        let mut first: Option<DVec3> = None;
        let mut previous: Option<DVec3> = None;
        let mut face_area = DVec3::ZERO;
        let mut emit = |p: DVec3| {
            match (first, previous) {
                (Some(p0), Some(p1)) => {
                    let v = p0.dot(p1.cross(p));
                    six_volume += v;
                    moment += v * (p0 + p1 + p);
                    face_area += (p1 - p0).cross(p - p0);
                }
                (None, _) => first = Some(p),
                _ => {}
            }
            previous = Some(p);
        };
        let m = face.vertices.len();
        let distance = |k: usize| {
            let d = plane.distance(vertices[face.vertices[k]]);
            if d.abs() <= tolerance {
                0.0
            } else {
                d
            }
        };
        let mut dj = distance(0);
        for k in 0..m {
            let (pi, di) = (vertices[face.vertices[k]], dj);
            let next = if k + 1 == m { 0 } else { k + 1 };
            let pj = vertices[face.vertices[next]];
            dj = distance(next);
            if di <= 0.0 {
                emit(pi - r);
            }
            if (di < 0.0 && dj > 0.0) || (di > 0.0 && dj < 0.0) {
                emit(pi + (pj - pi) * (di / (di - dj)) - r);
            }
        }
        // Only the face's own normal direction counts (exact direction, fan round-off dropped).
        vector_area += 0.5 * face_area.dot(face.normal) * face.normal;
    }
    let volume = six_volume / 6.0;
    // Closed boundary: the cap's vector area is −Σ(faces) and points along +n.
    let area = -vector_area.dot(n);
    if !(volume > 0.0 && area > 0.0) {
        return None;
    }
    let depth = volume / area;
    if depth.is_nan() || depth <= tolerance {
        return None;
    }
    let centroid_body = r + moment / (4.0 * six_volume);
    // The wall is the foundation: W = k ∫ φ dV with φ the depth below the plane, linear, so
    // W = k V φ(centroid) and its gradient is k V along the normal through the centroid.
    let centroid_depth = -plane.distance(centroid_body);
    Some(VolumeContact {
        volume,
        centroid: xa + qa * centroid_body,
        normal,
        area,
        depth,
        load: volume * normal,
        couple: DVec3::ZERO,
        potential: volume * centroid_depth,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::narrow_phase::convex_convex::tests::{cube, random_quat};
    use crate::rng::SplitMix64;
    use crate::shape::generators::regular_tetrahedron;
    use std::f64::consts::SQRT_2;

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs()
    }

    /// Unit cube under the plane x + z = s (normal (1, 0, 1)/√2). In the xz cross-section the free
    /// part is the corner triangle x + z > s; s = 0 halves the cube, s = 1/2 leaves a triangle of
    /// area 1/8 free. Each case is also turned as a whole by a random rotation R (cube R,
    /// plane R·n through R·p): the results turn with it.
    #[test]
    fn cube_under_a_tilted_plane() {
        let c = cube(1.0);
        let n = DVec3::new(1.0, 0.0, 1.0) / SQRT_2;
        // (s, volume, centroid, section area)
        let cases = [
            (0.0, 0.5, DVec3::new(-1.0 / 6.0, 0.0, -1.0 / 6.0), SQRT_2),
            (
                0.5,
                7.0 / 8.0,
                DVec3::new(-1.0 / 21.0, 0.0, -1.0 / 21.0),
                SQRT_2 / 2.0,
            ),
            // s = −1/2: the submerged part is the corner triangle x + z ≤ −1/2, area 1/8, centroid
            // (−1/2 + 1/6)·(1, 0, 1).
            (
                -0.5,
                1.0 / 8.0,
                DVec3::new(-1.0 / 3.0, 0.0, -1.0 / 3.0),
                SQRT_2 / 2.0,
            ),
        ];
        let mut rng = SplitMix64::new(9);
        for (s, volume, centroid, area) in cases {
            for turn in [DQuat::IDENTITY, random_quat(&mut rng)] {
                let x = DVec3::new(3.0, -1.0, 2.0);
                let point = x + turn * (n * (s / SQRT_2));
                let g = convex_plane(&c, x, turn, point, turn * n).unwrap();
                // Rounding of the turned coordinates (~10⁻¹⁶ of the size 1) only.
                assert!(close(g.volume, volume, 1e-13), "{s}: {}", g.volume);
                assert!((g.centroid - (x + turn * centroid)).length() < 1e-13, "{s}");
                assert!(close(g.area, area, 1e-13), "{s}: {}", g.area);
                assert!(close(g.depth, volume / area, 1e-13));
                assert!((g.normal - turn * n).length() < 1e-15);
            }
        }
        // Just touching with a face, an edge; above; entirely below.
        let up = DVec3::Z;
        assert!(convex_plane(&c, DVec3::ZERO, DQuat::IDENTITY, DVec3::Z * -0.5, up).is_none());
        let tilted = (DVec3::Z + DVec3::X) / SQRT_2;
        assert!(convex_plane(
            &c,
            DVec3::ZERO,
            DQuat::IDENTITY,
            DVec3::new(-0.5, 0.0, -0.5),
            tilted
        )
        .is_none());
        assert!(convex_plane(&c, DVec3::ZERO, DQuat::IDENTITY, DVec3::Z * -2.0, up).is_none());
        assert!(convex_plane(&c, DVec3::ZERO, DQuat::IDENTITY, DVec3::Z * 0.5, up).is_none());
    }

    /// A regular tetrahedron standing on a vertex, sunk by h: the submerged part is a tetrahedron
    /// similar to the whole, scaled by h/H (H the height): V = V₀ (h/H)³, section area
    /// A₀ (h/H)², centroid 3h/4 above the tip.
    #[test]
    fn tetrahedron_vertex_down() {
        let edge = 1.3;
        let (t, mass) = regular_tetrahedron(edge).unwrap();
        let height = edge * (2.0f64 / 3.0).sqrt();
        let face_area = 3f64.sqrt() / 4.0 * edge * edge;
        let tip = t.vertices()[0];
        let q = DQuat::from_rotation_arc(tip.normalize(), -DVec3::Z);
        let x = DVec3::new(0.5, 0.25, 2.0);
        let tip_world = x + q * tip;
        for h in [1e-3, 0.05, 0.4, 1.0] {
            let g = convex_plane(&t, x, q, tip_world + DVec3::Z * h, DVec3::Z).unwrap();
            let ratio = h / height;
            assert!(close(g.volume, mass.volume * ratio.powi(3), 1e-11), "{h}");
            assert!(close(g.area, face_area * ratio * ratio, 1e-11), "{h}");
            let centroid = tip_world + DVec3::Z * 0.75 * h;
            assert!((g.centroid - centroid).length() < 1e-12 * height, "{h}");
        }
    }
}
