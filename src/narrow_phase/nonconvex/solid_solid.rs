//! Two bodies, at least one of them a mesh, under the vertex law: vertices inside the other,
//! edge parts inside it, and the crossings that outline and join the regions.

use super::super::separation::bounding_spheres_separated;
use super::super::Geometry;
use super::regions::{regions_of_points, Point, RegionScratch};
use super::solid::{Solid, Transform};
use super::Pose;
use crate::geometry::triangle::closest_point_on_triangle;
use crate::geometry::Location;
use crate::math::{Aabb, DMat3, DVec3};

/// The contact regions of solids `a` and `b` under the vertex law, normals pointing from `b`
/// towards `a`, into `out` (cleared first).
pub fn solid_solid(
    a: Solid,
    pa: Pose,
    b: Solid,
    pb: Pose,
    scratch: &mut RegionScratch,
    out: &mut Vec<Geometry>,
) {
    out.clear();
    scratch.clear();
    if bounding_spheres_separated(
        pa.position,
        a.bounding_radius(),
        pb.position,
        b.bounding_radius(),
    ) {
        return;
    }
    let (ma, mb) = (
        DMat3::from_quat(pa.orientation),
        DMat3::from_quat(pb.orientation),
    );
    let d = pb.position - pa.position;
    // Body frames to the pair frame (world axes, origin at A's centre) and to each other.
    let a_to_pair = Transform {
        rotation: ma,
        translation: DVec3::ZERO,
    };
    let b_to_pair = Transform {
        rotation: mb,
        translation: d,
    };
    let a_to_b = Transform {
        rotation: mb.transpose() * ma,
        translation: mb.transpose() * (-d),
    };
    let b_to_a = Transform {
        rotation: ma.transpose() * mb,
        translation: ma.transpose() * d,
    };
    // Two meshes: are any of their triangles' boxes near each other at all? (Bodies with arms,
    // like crosses and stars, have bounding spheres that overlap far more often than they touch.)
    if let (Solid::Mesh(ma), Solid::Mesh(mb)) = (a, b) {
        if !ma
            .bvh()
            .meets(mb.bvh(), a_to_b.rotation, a_to_b.translation)
        {
            return;
        }
    }
    // Each body's box in the other's frame, cut to the other's box: where the overlap can be.
    let size = a.bounding_radius() + b.bounding_radius();
    let margin = 1e-9 * size;
    let (box_a, box_b) = (a.bounds().enlarged(margin), b.bounds().enlarged(margin));
    let Some(zone_a) = intersection(&b_to_a.box_of(&box_b), &box_a) else {
        return;
    };
    let Some(zone_b) = intersection(&a_to_b.box_of(&box_a), &box_b) else {
        return;
    };

    // 1. Vertices inside the other body.
    for (own, other, to_other, to_pair, other_to_pair, zone, other_box, sign, is_a) in [
        (a, b, a_to_b, a_to_pair, b_to_pair, zone_a, box_b, 1.0, true),
        (
            b, a, b_to_a, b_to_pair, a_to_pair, zone_b, box_a, -1.0, false,
        ),
    ] {
        let RegionScratch {
            near,
            vertices,
            edges,
            ..
        } = scratch;
        // No triangle of this body near a triangle of the other (boxes): its surface near the
        // other does not cross the other's, so its vertices there are all outside (the common
        // case: bodies with arms have bounding spheres and boxes that overlap far more often
        // than they touch) or all inside (deep); one tells which.
        let meets = own.near(&zone, other, &to_other, near, vertices, edges);
        if !meets
            && vertices.first().is_none_or(|&v| {
                let local = to_other.apply(own.vertex(v));
                !contains(&other_box, local) || other.locate(local) != Location::Inside
            })
        {
            continue;
        }
        let candidates = std::mem::take(&mut scratch.vertices);
        for &v in &candidates {
            let local = to_other.apply(own.vertex(v));
            if !contains(&other_box, local) || other.locate(local) != Location::Inside {
                continue;
            }
            let (depth, n) = other.depth(local);
            let point = scratch.push_point(Point::spring(
                to_pair.apply(own.vertex(v)),
                depth,
                sign * (other_to_pair.rotation * n),
            ));
            if is_a {
                scratch.inside_a.push((v, point));
            } else {
                scratch.inside_b.push((v, point));
            }
        }
        scratch.vertices = candidates;
        // Edges from vertices inside, which may lie wholly inside (deep).
        if let Solid::Mesh(m) = own {
            let inside = if is_a {
                &scratch.inside_a
            } else {
                &scratch.inside_b
            };
            let before = scratch.edges.len();
            for &(v, _) in inside.iter() {
                for &t in m.surface().triangles_of_vertex(v) {
                    scratch
                        .edges
                        .extend_from_slice(&m.surface().triangle_edges()[t as usize]);
                }
            }
            if scratch.edges.len() > before {
                scratch.edges.sort_unstable();
                scratch.edges.dedup();
            }
        }

        // 2. Edges through the other's faces, and the parts of edges inside it.
        let edge_list = std::mem::take(&mut scratch.edges);
        for &e in &edge_list {
            let ([v0, v1], faces, sharp) = own.edge(e);
            let (p, q) = (
                to_other.apply(own.vertex(v0)),
                to_other.apply(own.vertex(v1)),
            );
            if !Aabb::new(p.min(q), p.max(q)).overlaps(&other_box) {
                continue;
            }
            let mut crossings = std::mem::take(&mut scratch.crossings);
            other.crossings(p, q, &mut scratch.near, &mut crossings);
            let inside_list = if is_a {
                &scratch.inside_a
            } else {
                &scratch.inside_b
            };
            let point_of = |v: u32| {
                inside_list
                    .binary_search_by_key(&v, |&(u, _)| u)
                    .ok()
                    .map(|k| inside_list[k].1)
            };
            let (first, last) = (point_of(v0), point_of(v1));
            let (pp, pq) = (to_pair.apply(own.vertex(v0)), to_pair.apply(own.vertex(v1)));
            let at = |t: f64| pp + (pq - pp) * t;
            if crossings.is_empty() {
                if first.is_none() && last.is_none() {
                    scratch.crossings = crossings;
                    continue;
                }
                // Wholly inside (or grazing the surface at an end: then ask the middle).
                let inside = (first.is_some() && last.is_some())
                    || other.locate(0.5 * (p + q)) == Location::Inside;
                if inside {
                    if let (Some(i), Some(j)) = (first, last) {
                        scratch.union(i, j);
                    }
                    if sharp {
                        let anchor = first.or(last).expect("one end is inside");
                        let part = EdgePart {
                            p,
                            q,
                            t0: 0.0,
                            t1: 1.0,
                            ends: [first, last],
                        };
                        edge_spring(other, &part, &other_to_pair, sign, anchor, scratch);
                    }
                }
                scratch.crossings = crossings;
                continue;
            }
            let base = scratch.points.len() as u32;
            for c in &crossings {
                let point = scratch.push_point(Point::mark(at(c.t)));
                for f in faces {
                    let (fa, fb) = if is_a { (f, c.face) } else { (c.face, f) };
                    scratch.keys.push((((fa as u64) << 32) | fb as u64, point));
                }
            }
            // The intervals between crossings, each classified by its middle (exact).
            let k = crossings.len();
            for j in 0..=k {
                let t0 = if j == 0 { 0.0 } else { crossings[j - 1].t };
                let t1 = if j == k { 1.0 } else { crossings[j].t };
                let middle = p + (q - p) * (0.5 * (t0 + t1));
                if other.locate(middle) != Location::Inside {
                    continue;
                }
                let start = if j == 0 {
                    first
                } else {
                    Some(base + j as u32 - 1)
                };
                let end = if j == k { last } else { Some(base + j as u32) };
                if let (Some(s), Some(e)) = (start, end) {
                    scratch.union(s, e);
                }
                if let (true, Some(anchor)) = (sharp, start.or(end)) {
                    let part = EdgePart {
                        p,
                        q,
                        t0,
                        t1,
                        ends: [
                            if j == 0 { first } else { None },
                            if j == k { last } else { None },
                        ],
                    };
                    edge_spring(other, &part, &other_to_pair, sign, anchor, scratch);
                }
            }
            scratch.crossings = crossings;
        }
        scratch.edges = edge_list;
    }

    // Crossing points on one pair of faces are the ends of one intersection segment.
    scratch.keys.sort_unstable();
    for k in 1..scratch.keys.len() {
        let ((k0, p0), (k1, p1)) = (scratch.keys[k - 1], scratch.keys[k]);
        if k0 == k1 {
            scratch.union(p0, p1);
        }
    }

    regions_of_points(scratch, pa.position, out);
}

/// The part [t0, t1] of an edge p q (in the other body's frame) inside the other body, and the
/// points of the vertices at its ends, if they are inside.
struct EdgePart {
    p: DVec3,
    q: DVec3,
    t0: f64,
    t1: f64,
    ends: [Option<u32>; 2],
}

/// Golden-section steps of the search for an edge part's deepest point: the bracket shrinks to
/// 0.618²⁴ ≈ 10⁻⁵ of the part.
const GOLDEN_STEPS: usize = 24;

/// The spring of an edge part inside the other body: at its deepest point, with depth D the
/// distance from there to the other's surface (the most the edge penetrates), minus what the
/// deeper of its end vertices already carries. Its potential is ½ (D² − d_end²) (per unit
/// stiffness): zero when the deepest point is the end vertex itself (an edge inside a face
/// contact adds nothing to its corners), D²/2 for an edge pressed into a face with both ends
/// outside (crossed beams), and for two ridges crossing each contributes its own depth, which
/// together make the convex case's edge–edge spring. The force is its gradient: k D g at the
/// deepest point with g the derivative of D (the outward direction there; at a kink of the depth
/// along the edge, where two faces are equally near, the mix of their normals that has no
/// component along the edge: the deepest point is stationary, so its own motion does no work),
/// and −k d_end n_end at the end vertex. D appears and vanishes with the part at zero, and equals
/// d_end when the deepest point reaches the end: the force stays continuous.
fn edge_spring(
    other: Solid,
    part: &EdgePart,
    other_to_pair: &Transform,
    sign: f64,
    anchor: u32,
    scratch: &mut RegionScratch,
) {
    let EdgePart { p, q, t0, t1, ends } = *part;
    let length = (q - p).length() * (t1 - t0);
    if length <= 0.0 {
        return;
    }
    // The deeper end vertex inside, whose spring already carries its depth.
    let end_vertex = [(ends[0], 1.0), (ends[1], -1.0)]
        .into_iter()
        .filter_map(|(e, away)| e.map(|e| (e, away)))
        .max_by(|&(i, _), &(j, _)| {
            let (pi, pj) = (&scratch.points[i as usize], &scratch.points[j as usize]);
            pi.depth.total_cmp(&pj.depth).then(j.cmp(&i))
        });
    if let Some((vertex, away)) = end_vertex {
        // Depth not growing from the vertex into the part: in a convex body (where the depth
        // along an edge is concave) the vertex is the deepest point.
        let v = &scratch.points[vertex as usize];
        let along = other_to_pair.rotation * (q - p) * away;
        if v.force.dot(along) * sign >= 0.0 {
            return;
        }
    }
    let end_vertex = end_vertex.map(|(e, _)| e);
    let x = |t: f64| p + (q - p) * t;
    // The triangles of a mesh that can be nearest to a point of the part: within the middle's
    // distance plus half the part's length of the part (distance is 1-Lipschitz).
    if let Solid::Mesh(m) = other {
        let middle = x(0.5 * (t0 + t1));
        let (c, _) = m.closest_point(middle);
        let r = (c - middle).length() + 0.5 * length;
        let (a, b) = (x(t0), x(t1));
        let query = Aabb::new(a.min(b), a.max(b)).enlarged(r * (1.0 + 1e-9));
        m.bvh().overlapping(&query, &mut scratch.nearest);
    }
    let depth_at = |t: f64, near: &[u32]| -> (f64, DVec3) {
        let y = x(t);
        match other {
            Solid::Convex(s) => {
                let (mut best, mut normal) = (f64::INFINITY, DVec3::Z);
                for f in s.faces() {
                    let d = f.offset - f.normal.dot(y);
                    if d < best {
                        (best, normal) = (d, f.normal);
                    }
                }
                (best.max(0.0), normal)
            }
            Solid::Mesh(m) => {
                let (mut best, mut closest, mut tri) = (f64::INFINITY, y, 0u32);
                for &t in near {
                    let [a, b, c] = m.triangles()[t as usize].map(|i| m.vertices()[i]);
                    let (z, _) = closest_point_on_triangle(y, a, b, c);
                    let d = (z - y).length_squared();
                    if d < best {
                        (best, closest, tri) = (d, z, t);
                    }
                }
                let d = best.sqrt();
                let normal = if d > 1e-12 * m.bounding_radius() {
                    (closest - y) / d
                } else {
                    m.normals()[tri as usize]
                };
                (d, normal)
            }
        }
    };
    // Golden-section search for the deepest point (the depth along a straight edge in a convex
    // body is concave; in a non-convex one this finds a local maximum, deterministically).
    let near_list = std::mem::take(&mut scratch.nearest);
    let f = |t: f64| depth_at(t, &near_list).0;
    let ratio = 0.5 * (5f64.sqrt() - 1.0);
    let (mut lo, mut hi) = (t0, t1);
    let (mut a, mut b) = (hi - ratio * (hi - lo), lo + ratio * (hi - lo));
    let (mut fa, mut fb) = (f(a), f(b));
    for _ in 0..GOLDEN_STEPS {
        if fa < fb {
            lo = a;
            a = b;
            fa = fb;
            b = lo + ratio * (hi - lo);
            fb = f(b);
        } else {
            hi = b;
            b = a;
            fb = fa;
            a = hi - ratio * (hi - lo);
            fa = f(a);
        }
    }
    // The bracket [lo, hi] holds the maximum. Where the sides' nearest faces differ there is a
    // kink: the maximum is where the two depths, linear in t for faces, meet, and the derivative
    // of the depth is the mix of the two normals with no component along the edge.
    let u = (q - p).normalize();
    let span = (q - p).length();
    let (d_lo, n_lo) = depth_at(lo, &near_list);
    let (d_hi, n_hi) = depth_at(hi, &near_list);
    let (a_lo, a_hi) = (n_lo.dot(u), n_hi.dot(u));
    let (t, depth, g) = if a_lo < -1e-9 && a_hi > 1e-9 {
        // d(t) = d_lo − a_lo·span·(t − lo) = d_hi − a_hi·span·(t − hi).
        let t =
            ((d_hi - d_lo + span * (a_hi * hi - a_lo * lo)) / (span * (a_hi - a_lo))).clamp(lo, hi);
        let depth = d_lo - a_lo * span * (t - lo);
        let lambda = a_hi / (a_hi - a_lo);
        (t, depth, lambda * n_lo + (1.0 - lambda) * n_hi)
    } else {
        let (t, depth) = if fa >= fb { (a, fa) } else { (b, fb) };
        (t, depth, depth_at(t, &near_list).1)
    };
    let end_depth = end_vertex.map_or(0.0, |i| scratch.points[i as usize].depth);
    if depth <= end_depth * (1.0 + 1e-9) {
        // The deepest point is the end vertex: nothing to add.
        scratch.nearest = near_list;
        return;
    }
    scratch.nearest = near_list;
    let point = scratch.push_point(Point {
        position: other_to_pair.apply(x(t)),
        depth,
        force: depth * sign * (other_to_pair.rotation * g),
        potential: 0.5 * depth * depth,
        counts: true,
    });
    scratch.union(point, anchor);
    if let Some(vertex) = end_vertex {
        // Take back the end vertex's spring once more (its own point carries it).
        let v = scratch.points[vertex as usize];
        let correction = scratch.push_point(Point {
            position: v.position,
            depth: 0.0,
            force: -v.force,
            potential: -v.potential,
            counts: false,
        });
        scratch.union(correction, anchor);
    }
}

/// The smallest box common to two boxes, if they meet.
fn intersection(a: &Aabb, b: &Aabb) -> Option<Aabb> {
    let lo = a.min.max(b.min);
    let hi = a.max.min(b.max);
    (lo.cmple(hi).all()).then(|| Aabb::new(lo, hi))
}

fn contains(b: &Aabb, p: DVec3) -> bool {
    p.cmpge(b.min).all() && p.cmple(b.max).all()
}

#[cfg(test)]
mod tests {
    use super::super::test_bodies::{at, mesh};
    use super::*;
    use crate::math::DQuat;
    use crate::shape::nonconvex_generators::{cross, jack};
    use crate::shape::{generators, NonConvexPolyhedron};

    #[test]
    fn separated_and_touching_bodies_give_nothing() {
        let j = mesh(jack(3.0, 1.0).unwrap());
        let mut s = RegionScratch::new();
        let mut out = Vec::new();
        solid_solid(
            j.solid(),
            j.at(DVec3::ZERO),
            j.solid(),
            j.at(DVec3::X * 10.0),
            &mut s,
            &mut out,
        );
        assert!(out.is_empty());
    }

    #[test]
    fn a_cube_on_a_jack_arm_is_one_region_with_the_convex_depths() {
        // A unit cube pressed 0.1 into the top of the +x arm of a jack (arms 1 wide, 3 long).
        let j = mesh(jack(3.0, 1.0).unwrap());
        let (cube, _) = generators::cuboid(0.6, 0.6, 0.6).unwrap();
        let mut s = RegionScratch::new();
        let mut out = Vec::new();
        let xc = DVec3::new(1.0, 0.0, 0.5 + 0.3 - 0.1);
        solid_solid(
            Solid::Convex(&cube),
            at(xc),
            j.solid(),
            j.at(DVec3::ZERO),
            &mut s,
            &mut out,
        );
        assert_eq!(out.len(), 1, "{out:?}");
        let g = out[0];
        assert!((g.normal - DVec3::Z).length() < 1e-12, "{}", g.normal);
        // Springs at the 4 bottom corners, 0.1 deep; the edges are deepest at their corners and
        // add nothing.
        let v = g.volume.unwrap();
        assert_eq!(v.points, 4);
        assert!((g.overlap - 0.1).abs() < 1e-12, "{}", g.overlap);
        assert!((v.load - 0.4).abs() < 1e-12, "{}", v.load);
        assert!((v.potential - 4.0 * 0.005).abs() < 1e-12, "{}", v.potential);
        assert!((v.area - 0.36).abs() < 1e-9, "{}", v.area);
        // Reversed order: the normal flips.
        solid_solid(
            j.solid(),
            j.at(DVec3::ZERO),
            Solid::Convex(&cube),
            at(xc),
            &mut s,
            &mut out,
        );
        assert_eq!(out.len(), 1);
        assert!((out[0].normal + DVec3::Z).length() < 1e-12);
    }

    #[test]
    fn crossed_crosses_touch_in_one_region() {
        // B, a flat cross turned 45° about z, set 0.05 into the top of A: their arms overlap
        // around the centre in one connected piece.
        let c = mesh(cross(3.0, 1.0, 0.4).unwrap());
        let mut s = RegionScratch::new();
        let mut out = Vec::new();
        let pb = c.pose(
            DVec3::new(0.0, 0.0, 0.4 - 0.05),
            DQuat::from_rotation_z(std::f64::consts::FRAC_PI_4),
        );
        solid_solid(
            c.solid(),
            c.at(DVec3::ZERO),
            c.solid(),
            pb,
            &mut s,
            &mut out,
        );
        assert_eq!(out.len(), 1, "{out:?}");
        assert!(
            (out[0].normal + DVec3::Z).length() < 1e-9,
            "{}",
            out[0].normal
        );
        assert!(out[0].overlap <= 0.05 + 1e-9, "{}", out[0].overlap);
    }

    #[test]
    fn a_bar_across_two_arms_touches_in_two_regions() {
        // A jack turned 45° about y: its +x and −z arms point up at 45° to either side. A
        // horizontal bar along x just below their upper corners cuts both arms, apart.
        let j = mesh(jack(3.0, 1.0).unwrap());
        let pj = j.pose(
            DVec3::ZERO,
            DQuat::from_rotation_y(std::f64::consts::FRAC_PI_4),
        );
        // The upper corners of the upward arms reach z = (1.5 + 0.5)/√2.
        let top = 2.0 / 2f64.sqrt();
        let (bar, _) = generators::cuboid(4.0, 0.3, 0.3).unwrap();
        let pl = Pose {
            position: DVec3::new(0.0, 0.0, top - 0.1 + 0.15),
            orientation: DQuat::IDENTITY,
        };
        let mut s = RegionScratch::new();
        let mut out = Vec::new();
        solid_solid(j.solid(), pj, Solid::Convex(&bar), pl, &mut s, &mut out);
        assert_eq!(out.len(), 2, "{out:?}");
        assert!(out[0].point.x * out[1].point.x < 0.0);
        for g in &out {
            // The bar pushes the jack down.
            assert!(g.normal.z < 0.0, "{}", g.normal);
            // Each arm's corner ridge dips 0.1 below the bar's underside.
            assert!(g.overlap > 0.0 && g.overlap <= 0.1 + 1e-9, "{}", g.overlap);
        }
    }

    /// The mesh queries (hierarchy ray casting, nearest surface point, segment crossings) against
    /// the convex ones, on random rocks given both ways: the same springs.
    #[test]
    fn a_rock_as_a_mesh_touches_like_the_rock() {
        use crate::narrow_phase::convex_convex::tests::random_quat;
        use crate::rng::SplitMix64;
        let mut rng = SplitMix64::new(11);
        let mut s = RegionScratch::new();
        let (mut out, mut reference) = (Vec::new(), Vec::new());
        let mut touching = 0;
        for case in 0..40u64 {
            let (a, _) = generators::random_rock(case, 18, DVec3::new(1.0, 0.8, 0.6), 1.0).unwrap();
            let (b, _) = generators::random_rock(100 + case, 22, DVec3::ONE, 1.1).unwrap();
            let (ma, mass, _) =
                NonConvexPolyhedron::from_mesh(a.vertices(), a.triangles(), Default::default())
                    .unwrap();
            // Same edges both ways: every hull face a triangle, every mesh edge sharp.
            let edges = ma.surface().edges().len();
            if edges != a.edges().len() || (0..edges as u32).any(|e| !ma.is_sharp(e)) {
                continue;
            }
            let (qa, qb) = (random_quat(&mut rng), random_quat(&mut rng));
            let xa = DVec3::new(0.3, -0.2, 0.1);
            let xb = xa + random_unit(&mut rng) * 0.85;
            // The mesh's frame differs from the rock's by its principal axes, recomputed.
            let pose_mesh = Pose {
                position: xa + qa * mass.center_of_mass,
                orientation: (qa * mass.principal_rotation()).normalize(),
            };
            let pb = Pose {
                position: xb,
                orientation: qb,
            };
            let pa = Pose {
                position: xa,
                orientation: qa,
            };
            solid_solid(
                Solid::Convex(&a),
                pa,
                Solid::Convex(&b),
                pb,
                &mut s,
                &mut reference,
            );
            solid_solid(
                Solid::Mesh(&ma),
                pose_mesh,
                Solid::Convex(&b),
                pb,
                &mut s,
                &mut out,
            );
            assert_eq!(out.len(), reference.len(), "case {case}");
            for (g, r) in out.iter().zip(&reference) {
                let (gv, rv) = (g.volume.unwrap(), r.volume.unwrap());
                assert_eq!(gv.points, rv.points, "case {case}");
                assert!(
                    (g.normal * gv.load - r.normal * rv.load).length() < 1e-9,
                    "case {case}"
                );
                assert!((gv.potential - rv.potential).abs() < 1e-9, "case {case}");
                touching += 1;
            }
        }
        assert!(touching > 10, "{touching}");
    }

    fn random_unit(rng: &mut crate::rng::SplitMix64) -> DVec3 {
        DVec3::new(rng.normal(), rng.normal(), rng.normal()).normalize()
    }
}
