//! The geometry of the vertex penetration law (the seed paper's, Muth, Eberhard & Luding): the
//! points of each body inside the other, each with a depth and the direction it is pushed out.
//!
//! For a pair A, B the set holds:
//! 1. vertices of A inside B (`VertexOfA`): found by the seed's ray-casting test
//!    (`ConvexPolyhedron::locate`, exact) on the vertex moved into B's body frame, after a cheap
//!    rejection by B's bounding sphere. Depth: the distance to the nearest face plane of B; the
//!    force on A points along that face's outward normal (B pushes the vertex out through it).
//!    A vertex exactly on B's surface has depth zero and is left out;
//! 2. vertices of B inside A (`VertexOfB`), alike; the force on A is minus A's face normal;
//! 3. crossing points (`EdgeOfACrossingB`, `EdgeOfBCrossingA`): where an edge of one body passes
//!    through a face of the other, found by clipping the edge by the other body's face planes
//!    (Cyrus & Beck 1978; for convex bodies the same as testing the edge against every face
//!    polygon). Depth zero; the normal of the crossed face (as a force on A). They outline the
//!    contact region;
//! 4. edge-edge points (`EdgeEdge`): an edge of A and an edge of B that cross each other inside the
//!    overlap, as when two cubes meet ridge on ridge and no vertex is inside. Without these the
//!    law would see only crossing points of depth zero and give no force, however deep the ridges
//!    cut. For each pair of edge parts inside the other body (from step 3) the closest points
//!    p_A, p_B of the two segments are taken; when both lie strictly inside their parts (so the
//!    edges are not parallel and the points are not at the crossings) the point is the midpoint,
//!    the depth |p_B − p_A| and the force on A along p_B − p_A: p_A is in B and p_B in A, so the
//!    segment between them lies in A ∩ B, perpendicular to both edges; moving A by it brings the
//!    two edges into line contact, which is the edge-edge axis of the separating-axis theorem.
//!    Such pairs also appear in face-face overlaps (a bottom edge of A crossing a top edge of B),
//!    where they measure the same depth as the vertices nearby.
//!
//! The points are written into the caller's `ClipScratch`; the set borrows them.

use super::clip::{ClipScratch, Plane};
use super::separation::bounding_spheres_separated;
use crate::geometry::Location;
use crate::math::{DMat3, DQuat, DVec3};
use crate::shape::ConvexPolyhedron;

/// What a penetrating point is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PointKind {
    VertexOfA,
    VertexOfB,
    EdgeOfACrossingB,
    EdgeOfBCrossingA,
    EdgeEdge,
}

/// A point of one body inside the other.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PenetratingPoint {
    /// World position [m].
    pub point: DVec3,
    /// Penetration depth ≥ 0 [m].
    pub depth: f64,
    /// Unit direction of the force on A (from B towards A).
    pub normal: DVec3,
    pub kind: PointKind,
}

/// The penetrating points of a pair, borrowed from the scratch.
#[derive(Clone, Copy, Debug)]
pub struct PenetrationSet<'s> {
    pub points: &'s [PenetratingPoint],
}

impl PenetrationSet<'_> {
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }
}

/// The penetrating points of convex polyhedra `a` (at `xa`, turned by `qa`) and `b` (at `xb`,
/// turned by `qb`); see the module notes.
pub fn vertex_penetration<'s>(
    a: &ConvexPolyhedron,
    xa: DVec3,
    qa: DQuat,
    b: &ConvexPolyhedron,
    xb: DVec3,
    qb: DQuat,
    scratch: &'s mut ClipScratch,
) -> PenetrationSet<'s> {
    scratch.penetrating.clear();
    scratch.segments_a.clear();
    scratch.segments_b.clear();
    let (ra, rb) = (a.bounding_radius(), b.bounding_radius());
    if bounding_spheres_separated(xa, ra, xb, rb) {
        return PenetrationSet { points: &[] };
    }
    let t = xb - xa;
    scratch.pose_pair(a, qa, b, t, qb);
    let (ma, mb) = (DMat3::from_quat(qa), DMat3::from_quat(qb));

    // 1, 2: vertices inside the other body (pair frame: origin xa, world axes).
    vertices_inside(
        b,
        &scratch.a.vertices,
        t,
        mb,
        1.0,
        PointKind::VertexOfA,
        xa,
        &mut scratch.penetrating,
    );
    vertices_inside(
        a,
        &scratch.b.vertices,
        DVec3::ZERO,
        ma,
        -1.0,
        PointKind::VertexOfB,
        xa,
        &mut scratch.penetrating,
    );

    // 3: edges crossing faces.
    let ClipScratch {
        a: pa,
        b: pb,
        penetrating,
        segments_a,
        segments_b,
        ..
    } = scratch;
    for (shape, own, other, centre, radius, sign, kind, segments) in [
        (
            a,
            &*pa,
            &*pb,
            t,
            rb,
            1.0,
            PointKind::EdgeOfACrossingB,
            &mut *segments_a,
        ),
        (
            b,
            &*pb,
            &*pa,
            DVec3::ZERO,
            ra,
            -1.0,
            PointKind::EdgeOfBCrossingA,
            &mut *segments_b,
        ),
    ] {
        for edge in shape.edges() {
            let [p, q] = edge.vertices.map(|i| own.vertices[i]);
            if segment_distance_squared(centre, p, q) >= radius * radius {
                continue;
            }
            let Some((t0, enter, t1, exit)) = clip_segment(p, q, &other.planes) else {
                continue;
            };
            let at = |s: f64| p + (q - p) * s;
            for (s, face) in [(t0, enter), (t1, exit)] {
                if let Some(face) = face {
                    penetrating.push(PenetratingPoint {
                        point: xa + at(s),
                        depth: 0.0,
                        normal: sign * other.planes[face].normal,
                        kind,
                    });
                }
            }
            segments.push([at(t0), at(t1)]);
        }
    }

    // 4: edge-edge crossings inside the overlap.
    for &[a0, a1] in segments_a.iter() {
        for &[b0, b1] in segments_b.iter() {
            if let Some((pa, pb)) = interior_closest_points(a0, a1, b0, b1) {
                let d = pb - pa;
                let depth = d.length();
                if depth > 0.0 {
                    penetrating.push(PenetratingPoint {
                        point: xa + 0.5 * (pa + pb),
                        depth,
                        normal: d / depth,
                        kind: PointKind::EdgeEdge,
                    });
                }
            }
        }
    }
    PenetrationSet {
        points: &scratch.penetrating,
    }
}

/// The vertices `posed` of one body (in the pair frame) inside `other`, whose centre is at
/// `other_centre` in the pair frame and whose rotation is `other_rotation`. `sign` turns the
/// crossed face's normal into the force direction on A.
#[allow(clippy::too_many_arguments)]
fn vertices_inside(
    other: &ConvexPolyhedron,
    posed: &[DVec3],
    other_centre: DVec3,
    other_rotation: DMat3,
    sign: f64,
    kind: PointKind,
    origin: DVec3,
    out: &mut Vec<PenetratingPoint>,
) {
    let radius_squared = other.bounding_radius().powi(2);
    let to_other = other_rotation.transpose();
    for &p in posed {
        let local = to_other * (p - other_centre);
        if local.length_squared() > radius_squared || other.locate(local) != Location::Inside {
            continue;
        }
        let (face, depth) = other
            .faces()
            .iter()
            .map(|f| f.offset - f.normal.dot(local))
            .enumerate()
            .fold(
                (0, f64::INFINITY),
                |best, (k, d)| if d < best.1 { (k, d) } else { best },
            );
        out.push(PenetratingPoint {
            point: origin + p,
            depth: depth.max(0.0),
            normal: sign * (other_rotation * other.faces()[face].normal),
            kind,
        });
    }
}

/// The part [t₀, t₁] of the segment p + s (q − p), s ∈ [0, 1], behind all `planes`, with the
/// planes through which it enters (at t₀ > 0) and leaves (at t₁ < 1); `None` when nothing of it is
/// strictly inside.
fn clip_segment(
    p: DVec3,
    q: DVec3,
    planes: &[Plane],
) -> Option<(f64, Option<usize>, f64, Option<usize>)> {
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    let (mut enter, mut exit) = (None, None);
    for (k, plane) in planes.iter().enumerate() {
        let (dp, dq) = (plane.distance(p), plane.distance(q));
        if dp >= 0.0 && dq >= 0.0 {
            return None;
        }
        if dp <= 0.0 && dq <= 0.0 {
            continue;
        }
        let s = dp / (dp - dq);
        if dp > 0.0 {
            if s > t0 {
                (t0, enter) = (s, Some(k));
            }
        } else if s < t1 {
            (t1, exit) = (s, Some(k));
        }
        if t0 >= t1 {
            return None;
        }
    }
    Some((t0, enter, t1, exit))
}

/// Squared distance from `c` to the segment [p, q].
fn segment_distance_squared(c: DVec3, p: DVec3, q: DVec3) -> f64 {
    let e = q - p;
    let s = ((c - p).dot(e) / e.length_squared()).clamp(0.0, 1.0);
    (p + e * s - c).length_squared()
}

/// The closest points of the lines through [a0, a1] and [b0, b1] when they lie strictly inside
/// both segments; `None` for (nearly) parallel segments or closest points outside.
pub(crate) fn interior_closest_points(
    a0: DVec3,
    a1: DVec3,
    b0: DVec3,
    b1: DVec3,
) -> Option<(DVec3, DVec3)> {
    let (u, v, w) = (a1 - a0, b1 - b0, a0 - b0);
    let (uu, uv, vv, uw, vw) = (u.dot(u), u.dot(v), v.dot(v), u.dot(w), v.dot(w));
    let det = uu * vv - uv * uv;
    if det <= 1e-12 * uu * vv {
        return None;
    }
    let s = (uv * vw - vv * uw) / det;
    let t = (uu * vw - uv * uw) / det;
    if s > 0.0 && s < 1.0 && t > 0.0 && t < 1.0 {
        Some((a0 + u * s, b0 + v * t))
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::narrow_phase::convex_convex::tests::{crossed_ridges, cube, random_quat};
    use crate::rng::SplitMix64;
    use crate::shape::generators::random_rock;
    use std::f64::consts::SQRT_2;

    fn count(set: &PenetrationSet, kind: PointKind) -> usize {
        set.points.iter().filter(|p| p.kind == kind).count()
    }

    #[test]
    fn ridges_crossing_without_vertices_inside() {
        let mut s = ClipScratch::new();
        let delta = 0.1;
        let (c, [(xa, qa), (xb, qb)]) = crossed_ridges(delta);
        let set = vertex_penetration(&c, xa, qa, &c, xb, qb, &mut s);
        assert_eq!(count(&set, PointKind::VertexOfA), 0);
        assert_eq!(count(&set, PointKind::VertexOfB), 0);
        // A's ridge (x = 0, y = √2/2) enters and leaves B at z = ±δ through B's two ridge faces;
        // B's ridge (z = 0, y = √2/2 − δ) crosses A's at x = ±δ.
        assert_eq!(count(&set, PointKind::EdgeOfACrossingB), 2);
        assert_eq!(count(&set, PointKind::EdgeOfBCrossingA), 2);
        for p in set
            .points
            .iter()
            .filter(|p| p.kind == PointKind::EdgeOfACrossingB)
        {
            let expected = DVec3::new(0.0, SQRT_2 / 2.0, p.point.z.signum() * delta);
            assert!((p.point - expected).length() < 1e-12, "{}", p.point);
            // B's ridge faces have outward normals (0, −1, ±1)/√2.
            assert!((p.normal.y + SQRT_2 / 2.0).abs() < 1e-12);
        }
        for p in set
            .points
            .iter()
            .filter(|p| p.kind == PointKind::EdgeOfBCrossingA)
        {
            let expected = DVec3::new(p.point.x.signum() * delta, SQRT_2 / 2.0 - delta, 0.0);
            assert!((p.point - expected).length() < 1e-12, "{}", p.point);
            // Minus A's ridge faces' normals (±1, 1, 0)/√2.
            assert!((p.normal.y + SQRT_2 / 2.0).abs() < 1e-12);
        }
        let ee: Vec<_> = set
            .points
            .iter()
            .filter(|p| p.kind == PointKind::EdgeEdge)
            .collect();
        assert_eq!(ee.len(), 1);
        assert!((ee[0].depth - delta).abs() < 1e-12);
        assert!((ee[0].normal + DVec3::Y).length() < 1e-12);
        let mid = DVec3::new(0.0, SQRT_2 / 2.0 - delta / 2.0, 0.0);
        assert!((ee[0].point - mid).length() < 1e-12);
    }

    #[test]
    fn cube_corner_into_a_face() {
        // A's lowest corner dips h into B's top face: one vertex of A inside, depth h, force on A
        // up; three edges of A cross B's top face.
        let mut s = ClipScratch::new();
        let c = cube(1.0);
        let qa = DQuat::from_rotation_arc(DVec3::new(-1.0, -1.0, -1.0).normalize(), -DVec3::Z);
        let corner = 3f64.sqrt() / 2.0;
        let h = 0.05;
        let xa = DVec3::new(0.1, 0.0, 0.5 + corner - h);
        let set = vertex_penetration(&c, xa, qa, &c, DVec3::ZERO, DQuat::IDENTITY, &mut s);
        assert_eq!(count(&set, PointKind::VertexOfA), 1);
        assert_eq!(count(&set, PointKind::VertexOfB), 0);
        assert_eq!(count(&set, PointKind::EdgeOfACrossingB), 3);
        assert_eq!(count(&set, PointKind::EdgeEdge), 0);
        let v = set
            .points
            .iter()
            .find(|p| p.kind == PointKind::VertexOfA)
            .unwrap();
        assert!((v.depth - h).abs() < 1e-12);
        assert_eq!(v.normal, DVec3::Z);
        for p in set.points {
            assert!((p.point.z - 0.5).abs() < 1e-12 || p.kind == PointKind::VertexOfA);
        }
        // Separated: empty.
        let set = vertex_penetration(
            &c,
            xa + DVec3::Z,
            qa,
            &c,
            DVec3::ZERO,
            DQuat::IDENTITY,
            &mut s,
        );
        assert!(set.is_empty());
    }

    /// The ray-casting classification against the half-space test (convex reference), and each
    /// depth against the direct minimum over the other body's face planes, for random rocks.
    #[test]
    fn vertices_agree_with_the_half_space_test() {
        let mut rng = SplitMix64::new(77);
        let mut s = ClipScratch::new();
        let mut found = 0;
        for case in 0..20u64 {
            let (a, _) = random_rock(case, 20, DVec3::new(1.0, 0.7, 0.5), 1.0).unwrap();
            let (b, _) = random_rock(50 + case, 25, DVec3::ONE, 1.2).unwrap();
            let (qa, qb) = (random_quat(&mut rng), random_quat(&mut rng));
            let xa = DVec3::new(1.0, 2.0, 3.0);
            let xb = xa + DVec3::new(rng.normal(), rng.normal(), rng.normal()).normalize() * 0.6;
            let set = vertex_penetration(&a, xa, qa, &b, xb, qb, &mut s);
            let inside = |p: DVec3, body: &ConvexPolyhedron, x: DVec3, q: DQuat| {
                let local = q.inverse() * (p - x);
                body.faces()
                    .iter()
                    .map(|f| f.offset - f.normal.dot(local))
                    .fold(f64::INFINITY, f64::min)
            };
            let mut expected = 0;
            for (shape, x, q, other, xo, qo, kind) in [
                (&a, xa, qa, &b, xb, qb, PointKind::VertexOfA),
                (&b, xb, qb, &a, xa, qa, PointKind::VertexOfB),
            ] {
                for &v in shape.vertices() {
                    let w = x + q * v;
                    let depth = inside(w, other, xo, qo);
                    if depth > 0.0 {
                        expected += 1;
                        let p = set
                            .points
                            .iter()
                            .find(|p| p.kind == kind && (p.point - w).length() < 1e-12)
                            .expect("vertex inside not found");
                        assert!((p.depth - depth).abs() < 1e-12);
                    }
                }
            }
            let got = count(&set, PointKind::VertexOfA) + count(&set, PointKind::VertexOfB);
            assert_eq!(got, expected, "case {case}");
            found += expected;
            // Every point's force direction pushes A away from B overall.
            for p in set.points {
                assert!((p.normal.length() - 1.0).abs() < 1e-12);
            }
        }
        assert!(found > 10);
    }
}
