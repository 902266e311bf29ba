//! Two convex polyhedra: the intersection polyhedron, for the volume law.
//!
//! The intersection A ∩ B is bounded by the parts of A's faces inside B and the parts of B's faces
//! inside A. Each face polygon is clipped by the other body's face planes (Sutherland–Hodgman,
//! `clip::clip_polygon`), and the divergence theorem over the kept polygons gives the overlap
//! volume and its centroid. The contact normal comes from the vector areas of the two sets of
//! parts: S_A = Σ area·n over A's parts inside B, S_B likewise. For a closed boundary S_A + S_B = 0,
//! and −S_A (the outward normals of A's surface inside B point into B, so −S_A points out of B
//! towards A) is the direction that pushes A out of B; |S_A| is the area of the overlap projected
//! on that direction.
//!
//! Special cases:
//! - coplanar faces (two cubes side by side, face on face): corners within `PLANE_TOLERANCE` of a
//!   plane are snapped onto it, and a polygon lying in a plane of the other body is kept once —
//!   A's face when both faces look the same way, neither when they look opposite ways (touching).
//!   The volume is then exact, not doubled or lost;
//! - edges crossing faces with no vertex inside (cubes turned 45° about different axes): nothing
//!   special, the clipping cuts both ridges;
//! - touching (zero volume, or a mean depth below the tolerance): `None`;
//! - one body inside the other: the vector areas vanish (the inner body's whole closed surface is
//!   inside); the normal falls back to the direction between the centres of mass (from B towards
//!   A; +z when they coincide), the depth to the overlap of the two bodies' projections on that
//!   direction, and the area to volume / depth.

use super::clip::{boundary_sums, narrows, ClipScratch, PLANE_TOLERANCE};
use super::separation::{bounding_spheres_separated, separated_by_face_planes};
use crate::math::{DQuat, DVec3};
use crate::shape::ConvexPolyhedron;

/// The overlap of two bodies (or of a body and a wall) as a volume.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VolumeContact {
    /// Overlap volume V > 0 [m³].
    pub volume: f64,
    /// Centroid of the overlap (world) [m]: where the normal force acts.
    pub centroid: DVec3,
    /// Unit normal from B (the second argument) towards A: the direction of the force on A.
    /// −(vector area of A's surface inside B), normalised; equivalently +(vector area of B's
    /// surface inside A).
    pub normal: DVec3,
    /// |vector area| [m²]: the overlap's area projected on the normal.
    pub area: f64,
    /// Mean penetration depth V / area [m].
    pub depth: f64,
    /// Elastic-foundation force on A per unit stiffness [m³] (V n for a face contact), its torque
    /// about the centroid [m⁴] and its potential [m⁴]: see `clip::Winkler`. A law k·(these) is
    /// the gradient of a potential, so it conserves energy (Feng, Han & Owen 2012).
    pub load: DVec3,
    pub couple: DVec3,
    pub potential: f64,
}

/// Below this fraction of the boundary's total area the vector area counts as zero (one body
/// inside the other): round-off in S is about 10⁻¹⁶ of the total area.
const NESTED_FRACTION: f64 = 1e-9;

/// The overlap of convex polyhedron `a` at `xa` turned by `qa` (body → world) and `b` at `xb`
/// turned by `qb`. `None` when they are separated or only touch.
pub fn convex_convex(
    a: &ConvexPolyhedron,
    xa: DVec3,
    qa: DQuat,
    b: &ConvexPolyhedron,
    xb: DVec3,
    qb: DQuat,
    scratch: &mut ClipScratch,
) -> Option<VolumeContact> {
    overlap(a, (xa, qa), b, (xb, qb), scratch, narrows(a, b))
}

/// [`convex_convex`], the faces clipped to a narrowed box or not (`ClipScratch::clip_pair`).
fn overlap(
    a: &ConvexPolyhedron,
    (xa, qa): (DVec3, DQuat),
    b: &ConvexPolyhedron,
    (xb, qb): (DVec3, DQuat),
    scratch: &mut ClipScratch,
    narrow: bool,
) -> Option<VolumeContact> {
    let (ra, rb) = (a.bounding_radius(), b.bounding_radius());
    if bounding_spheres_separated(xa, ra, xb, rb) {
        return None;
    }
    let tolerance = PLANE_TOLERANCE * (ra + rb);
    let t = xb - xa;
    scratch.pose_pair(a, qa, b, t, qb);
    if separated_by_face_planes(
        &scratch.a.vertices,
        &scratch.a.planes,
        &scratch.b.vertices,
        &scratch.b.planes,
        tolerance,
    ) {
        return None;
    }
    scratch.clip_pair(a, b, tolerance, narrow);
    let sums = boundary_sums(
        &scratch.points,
        &scratch.polygons,
        &scratch.a.planes,
        &scratch.b.planes,
        &mut scratch.depth,
    );
    let volume = sums.volume;
    if volume.is_nan() || volume <= 0.0 {
        return None;
    }
    // (S_B − S_A)/2 rather than either alone: the two differ only by round-off, and the mean
    // halves it.
    let s = sums.vector_area_b - sums.vector_area_a;
    let s_length = s.length();
    let (normal, area, depth) = if s_length > NESTED_FRACTION * sums.total_area {
        let area = 0.5 * s_length;
        (s / s_length, area, volume / area)
    } else {
        // One body inside the other: no surface direction. Push along the line between the
        // centres of mass, by the overlap of the projections on it.
        let normal = (-t).try_normalize().unwrap_or(DVec3::Z);
        let depth = projection_overlap(&scratch.a.vertices, &scratch.b.vertices, normal);
        (normal, volume / depth, depth)
    };
    if depth.is_nan() || depth <= tolerance {
        return None;
    }
    Some(VolumeContact {
        volume,
        centroid: xa + sums.centroid,
        normal,
        area,
        depth,
        load: sums.winkler.force,
        couple: sums.winkler.couple,
        potential: sums.winkler.potential,
    })
}

/// The overlap of the intervals that the two vertex sets project to on `axis`.
fn projection_overlap(a: &[DVec3], b: &[DVec3], axis: DVec3) -> f64 {
    let range = |v: &[DVec3]| {
        v.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &p| {
                let s = axis.dot(p);
                (lo.min(s), hi.max(s))
            })
    };
    let ((alo, ahi), (blo, bhi)) = (range(a), range(b));
    (ahi - blo).min(bhi - alo)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::narrow_phase::clip::Plane;
    use crate::rng::SplitMix64;
    use crate::shape::generators::{cuboid, random_rock};
    use std::f64::consts::{FRAC_PI_4, SQRT_2};

    pub(crate) fn cube(edge: f64) -> ConvexPolyhedron {
        cuboid(edge, edge, edge).unwrap().0
    }

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs().max(f64::MIN_POSITIVE)
    }

    /// Overlap of two axis-aligned unit cubes, A at `xa`, B at `xa + d`: a box with sides
    /// 1 − |dᵢ|, centred half-way; A's surface inside B is its three faces towards B, so
    /// S_A = (sign dₓ · o_y o_z, …).
    fn box_overlap(d: DVec3) -> (f64, DVec3) {
        let o = DVec3::ONE - d.abs();
        // Along an axis with no shift both faces of A are (coplanar) parts of the boundary and
        // cancel.
        let sign = d.map(|c| if c == 0.0 { 0.0 } else { c.signum() });
        let s_a = sign * DVec3::new(o.y * o.z, o.x * o.z, o.x * o.y);
        (o.x * o.y * o.z, s_a)
    }

    #[test]
    fn axis_aligned_cubes_with_coplanar_faces() {
        let c = cube(1.0);
        let mut s = ClipScratch::new();
        let xa = DVec3::new(10.0, -3.0, 7.0);
        // Dyadic shifts (exact) and decimal ones (rounded on input); faces coplanar where a shift
        // component is zero.
        for d in [
            DVec3::new(0.875, 0.25, 0.125),
            DVec3::new(-0.9, 0.2, 0.1),
            DVec3::new(0.5, 0.0, 0.0),
            DVec3::new(0.0, -0.7, 0.0),
            DVec3::new(0.3, 0.0, -0.6),
            DVec3::new(0.0, 0.0, 0.95),
        ] {
            let g = convex_convex(&c, xa, DQuat::IDENTITY, &c, xa + d, DQuat::IDENTITY, &mut s)
                .unwrap();
            let (volume, s_a) = box_overlap(d);
            // The coordinates (10 ± 0.5 …) carry rounding of a few 10⁻¹⁶, relative to overlaps
            // of 10⁻¹: 10⁻¹² is generous and still catches any double-counted face.
            assert!(
                close(g.volume, volume, 1e-12),
                "{d}: {} vs {volume}",
                g.volume
            );
            assert!(
                (g.centroid - (xa + 0.5 * d)).length() < 1e-12,
                "{d}: {}",
                g.centroid
            );
            assert!(
                (g.normal + s_a.normalize()).length() < 1e-12,
                "{d}: {}",
                g.normal
            );
            assert!(close(g.area, s_a.length(), 1e-12));
            assert!(close(g.depth, volume / s_a.length(), 1e-12));
        }
        // Face-on push mostly along x: the normal is along the axis of least penetration.
        let g = convex_convex(
            &c,
            DVec3::ZERO,
            DQuat::IDENTITY,
            &c,
            DVec3::new(0.9, 0.05, 0.0),
            DQuat::IDENTITY,
            &mut s,
        )
        .unwrap();
        assert!(g.normal.x < -0.99, "{}", g.normal);
    }

    #[test]
    fn nested_coincident_touching_separated() {
        let (big, small) = (cube(1.0), cube(0.5));
        let mut s = ClipScratch::new();
        let q = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 2.0).normalize(), 0.4);
        // A entirely inside B (axis-aligned, and both turned alike).
        for rot in [DQuat::IDENTITY, q] {
            let xa = rot * DVec3::new(0.1, 0.05, 0.0);
            let g = convex_convex(&small, xa, rot, &big, DVec3::ZERO, rot, &mut s).unwrap();
            assert!(close(g.volume, 0.125, 1e-12));
            assert!((g.centroid - xa).length() < 1e-12);
            assert!((g.normal - xa.normalize()).length() < 1e-12);
            // Projections on n = (2, 1, 0)/√5 (body frame): B covers ±0.5·3/√5, A is centred at
            // 0.25/√5 with half-width 0.25·3/√5; the overlap is B's top minus A's bottom, 2/√5.
            assert!(close(g.depth, 2.0 / 5f64.sqrt(), 1e-12), "{}", g.depth);
            assert!(close(g.area * g.depth, g.volume, 1e-12));
            // Swapped: B inside A, normal from B's centre towards A's.
            let h = convex_convex(&big, DVec3::ZERO, rot, &small, xa, rot, &mut s).unwrap();
            assert!(close(h.volume, 0.125, 1e-12));
            assert!((h.normal + xa.normalize()).length() < 1e-12);
        }
        // Identical coincident cubes, axis-aligned and turned: every face coplanar with one of the
        // other's. The volume is one cube, not two and not zero.
        for rot in [DQuat::IDENTITY, q] {
            let x = DVec3::new(1.0, 2.0, 3.0);
            let g = convex_convex(&big, x, rot, &big, x, rot, &mut s).unwrap();
            assert!(close(g.volume, 1.0, 1e-12), "{}", g.volume);
            assert!((g.centroid - x).length() < 1e-12);
            assert_eq!(g.normal, DVec3::Z);
        }
        // Touching face to face, edge to edge, corner to corner; separated.
        for d in [
            DVec3::new(1.0, 0.3, 0.2),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(-1.0, 1.0, 1.0),
            DVec3::new(1.5, 0.0, 0.0),
            DVec3::new(0.9, 1.2, 0.0),
        ] {
            for rot in [DQuat::IDENTITY, q] {
                let g = convex_convex(&big, DVec3::ZERO, rot, &big, rot * d, rot, &mut s);
                assert!(g.is_none(), "{d}: {g:?}");
            }
        }
    }

    /// Cube A turned 45° about z (a ridge along z at y = +√2/2), cube B turned 45° about x (a ridge
    /// along x at y = −√2/2 from its centre), B at y = √2 − δ: the ridges cross with depth δ, no
    /// vertex of either is inside the other. The overlap is {|x| + |z| ≤ δ} × the y-range between
    /// the ridges' faces: V = ∫∫ (δ − |x| − |z|) = 2δ³/3, centroid (0, √2/2 − δ/2, 0); B's two faces
    /// inside A project on the xz-plane to δ² each, so area = 2δ², normal −y (B above A).
    pub(crate) fn crossed_ridges(delta: f64) -> (ConvexPolyhedron, [(DVec3, DQuat); 2]) {
        (
            cube(1.0),
            [
                (DVec3::ZERO, DQuat::from_rotation_z(FRAC_PI_4)),
                (
                    DVec3::new(0.0, SQRT_2 - delta, 0.0),
                    DQuat::from_rotation_x(FRAC_PI_4),
                ),
            ],
        )
    }

    #[test]
    fn crossing_edges_without_vertices_inside() {
        let mut s = ClipScratch::new();
        for delta in [0.1, 0.01, 0.3] {
            let (c, [(xa, qa), (xb, qb)]) = crossed_ridges(delta);
            let g = convex_convex(&c, xa, qa, &c, xb, qb, &mut s).unwrap();
            // Vertex coordinates carry rounding ~10⁻¹⁶ (√2/2 from the quaternion), which moves the
            // volume by ~area × 10⁻¹⁶, relative 10⁻¹⁶/δ.
            assert!(
                close(g.volume, 2.0 * delta.powi(3) / 3.0, 1e-11),
                "{}",
                g.volume
            );
            let centroid = DVec3::new(0.0, SQRT_2 / 2.0 - delta / 2.0, 0.0);
            assert!((g.centroid - centroid).length() < 1e-12, "{}", g.centroid);
            assert!((g.normal + DVec3::Y).length() < 1e-12, "{}", g.normal);
            assert!(close(g.area, 2.0 * delta * delta, 1e-11));
            assert!(close(g.depth, delta / 3.0, 1e-11));
        }
        // Ridges apart: no face plane separates them, the clipping finds nothing.
        let (c, [(xa, qa), (xb, qb)]) = crossed_ridges(-0.01);
        assert!(convex_convex(&c, xa, qa, &c, xb, qb, &mut s).is_none());
    }

    pub(crate) fn random_quat(rng: &mut SplitMix64) -> DQuat {
        DQuat::from_xyzw(rng.normal(), rng.normal(), rng.normal(), rng.normal()).normalize()
    }

    fn planes_of(p: &ConvexPolyhedron, x: DVec3, q: DQuat) -> Vec<Plane> {
        p.faces()
            .iter()
            .map(|f| {
                let n = q * f.normal;
                Plane {
                    normal: n,
                    offset: f.offset + n.dot(x),
                }
            })
            .collect()
    }

    fn world_bounds(p: &ConvexPolyhedron, x: DVec3, q: DQuat) -> (DVec3, DVec3) {
        p.vertices()
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(x + q * v), hi.max(x + q * v))
            })
    }

    /// Random rocks in random poses against Monte Carlo: 2·10⁵ uniform points in the box common to
    /// both bodies' bounding boxes, inside both by the half-space test. The estimate V̂ = |box| k/N
    /// has standard deviation |box| √(p(1−p)/N); we allow 5σ. The centroid estimate (mean of the
    /// hits) has per-axis standard deviation √(var/k); 5σ again. Also the symmetries of swapping
    /// A and B, and the closure S_A + S_B = 0.
    #[test]
    fn random_rocks_against_monte_carlo() {
        let mut rng = SplitMix64::new(2024);
        let mut s = ClipScratch::new();
        let mut tested = 0;
        for case in 0..12u64 {
            let (a, _) = random_rock(
                100 + case,
                12 + 8 * case as usize % 40,
                DVec3::new(1.0, 0.8, 0.6),
                1.0,
            )
            .unwrap();
            let (b, _) = random_rock(
                200 + case,
                30,
                DVec3::new(1.5, 1.0, 0.7),
                0.8 + 0.05 * case as f64,
            )
            .unwrap();
            let (xa, qa) = (
                DVec3::new(rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0), 0.0),
                random_quat(&mut rng),
            );
            let direction = DVec3::new(rng.normal(), rng.normal(), rng.normal()).normalize();
            let distance = rng.uniform(0.3, 0.8);
            let (xb, qb) = (xa + direction * distance, random_quat(&mut rng));
            let Some(g) = convex_convex(&a, xa, qa, &b, xb, qb, &mut s) else {
                continue;
            };
            tested += 1;
            // Closure of the boundary.
            let mut depth = Default::default();
            let sums = boundary_sums(&s.points, &s.polygons, &s.a.planes, &s.b.planes, &mut depth);
            assert!(
                (sums.vector_area_a + sums.vector_area_b).length() < 1e-12 * sums.total_area,
                "open boundary"
            );
            // Swapped.
            let h = convex_convex(&b, xb, qb, &a, xa, qa, &mut s).unwrap();
            assert!(close(h.volume, g.volume, 1e-12));
            assert!((h.centroid - g.centroid).length() < 1e-12);
            assert!((h.normal + g.normal).length() < 1e-10);
            assert!(close(h.area, g.area, 1e-10));
            // Monte Carlo.
            let (pa, pb) = (planes_of(&a, xa, qa), planes_of(&b, xb, qb));
            let ((alo, ahi), (blo, bhi)) = (world_bounds(&a, xa, qa), world_bounds(&b, xb, qb));
            let (lo, hi) = (alo.max(blo), ahi.min(bhi));
            let n = 200_000;
            let (mut hits, mut sum, mut sum2) = (0usize, DVec3::ZERO, DVec3::ZERO);
            for _ in 0..n {
                let p = DVec3::new(
                    rng.uniform(lo.x, hi.x),
                    rng.uniform(lo.y, hi.y),
                    rng.uniform(lo.z, hi.z),
                );
                if pa.iter().chain(&pb).all(|pl| pl.distance(p) <= 0.0) {
                    hits += 1;
                    sum += p;
                    sum2 += p * p;
                }
            }
            let box_volume = (hi - lo).x * (hi - lo).y * (hi - lo).z;
            let p_hit = hits as f64 / n as f64;
            let estimate = box_volume * p_hit;
            let sigma = box_volume * (p_hit * (1.0 - p_hit) / n as f64).sqrt();
            assert!(
                (g.volume - estimate).abs() < 5.0 * sigma,
                "case {case}: {} vs {estimate} ± {sigma}",
                g.volume
            );
            let mean = sum / hits as f64;
            let sigma_c = ((sum2 / hits as f64 - mean * mean) / hits as f64).powf(0.5);
            let err = (g.centroid - mean).abs();
            assert!(
                err.cmplt(5.0 * sigma_c).all(),
                "case {case}: {} vs {mean} ± {sigma_c}",
                g.centroid
            );
            // The normal points out of B towards A, roughly along the line of centres.
            assert!(g.normal.dot(xa - xb) > 0.0);
        }
        assert!(tested >= 8, "only {tested} overlapping cases");
    }

    proptest::proptest! {
        /// The faces clipped to the box common to both bodies' bounding boxes, or to that box
        /// narrowed to each body's part inside the other's (as for polyhedra with many faces,
        /// `clip::NARROWING_FACES`), give one overlap: the narrowing only passes by what lies
        /// outside it. Rocks of 4 to 80 corners in random poses, cubes among them; volumes agree
        /// to the rounding of the clipping, relative to the bodies' size (10⁻¹² of a unit cube).
        #[test]
        fn the_narrowed_box_gives_the_same_overlap(
            (seed_a, seed_b) in (0u64..1000, 0u64..1000),
            (corners_a, corners_b) in (4usize..80, 4usize..80),
            cube_a in proptest::bool::ANY,
            pose_seed in 0u64..1_000_000,
            distance in 0.2f64..1.2,
        ) {
            let elongation = DVec3::new(1.2, 1.0, 0.8);
            let rock = |seed, corners| random_rock(seed, corners, elongation, 1.0).unwrap().0;
            let a = if cube_a { cube(1.0) } else { rock(seed_a, corners_a) };
            let b = rock(seed_b, corners_b);
            let mut rng = SplitMix64::new(pose_seed);
            let direction = DVec3::new(rng.normal(), rng.normal(), rng.normal()).normalize();
            let (pa, pb) = (
                (DVec3::new(3.0, -2.0, 1.0), random_quat(&mut rng)),
                (DVec3::new(3.0, -2.0, 1.0) + direction * distance, random_quat(&mut rng)),
            );
            let mut s = ClipScratch::new();
            let wide = overlap(&a, pa, &b, pb, &mut s, false);
            let narrow = overlap(&a, pa, &b, pb, &mut s, true);
            let volume = |g: &Option<VolumeContact>| g.map_or(0.0, |g| g.volume);
            proptest::prop_assert!(
                (volume(&wide) - volume(&narrow)).abs() <= 1e-12 + 1e-9 * volume(&wide),
                "{wide:?} against {narrow:?}"
            );
            if let (Some(w), Some(n)) = (wide, narrow) {
                proptest::prop_assert!((w.centroid - n.centroid).length() < 1e-9);
                proptest::prop_assert!((w.normal - n.normal).length() < 1e-6 || w.volume < 1e-9);
                let load_error = (w.load - n.load).length();
                proptest::prop_assert!(load_error <= 1e-12 + 1e-9 * w.load.length());
            }
        }
    }

    /// ns per call, printed (run with `--release -- --nocapture` for the number).
    #[test]
    fn timing() {
        let mut s = ClipScratch::new();
        let c = cube(1.0);
        let (ra, _) = random_rock(1, 50, DVec3::ONE, 1.0).unwrap();
        let (rb, _) = random_rock(2, 50, DVec3::ONE, 1.0).unwrap();
        let q = DQuat::from_axis_angle(DVec3::new(1.0, 1.0, 0.0).normalize(), 0.3);
        // Rocks: B moved along x until the overlap is slight (depth ~1% of the size).
        let mut gap = 1.0;
        while let Some(g) = convex_convex(
            &ra,
            DVec3::ZERO,
            q,
            &rb,
            DVec3::X * gap,
            DQuat::IDENTITY,
            &mut s,
        ) {
            if g.depth < 0.003 {
                break;
            }
            gap += 0.002;
        }
        let pairs: [(&ConvexPolyhedron, DQuat, &ConvexPolyhedron, DVec3); 2] = [
            (&c, q, &c, DVec3::new(0.95, 0.2, 0.1)),
            (&ra, q, &rb, DVec3::X * gap),
        ];
        for (name, (a, qa, b, xb)) in ["two cubes", "two 50-vertex rocks"].iter().zip(pairs) {
            let n = 20_000;
            let start = std::time::Instant::now();
            let mut v = 0.0;
            for i in 0..n {
                let x = xb + DVec3::X * (i % 2) as f64 * 1e-4;
                v += convex_convex(a, DVec3::ZERO, qa, b, x, DQuat::IDENTITY, &mut s)
                    .map_or(0.0, |g| g.volume);
            }
            let ns = start.elapsed().as_nanos() as f64 / n as f64;
            assert!(v > 0.0);
            println!("convex_convex, {name}: {ns:.0} ns per call");
        }
    }
}
