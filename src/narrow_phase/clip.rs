//! Shared machinery of the polyhedral contacts: the two shapes of a pair posed in one frame,
//! clipping of convex polygons by half-spaces (Sutherland & Hodgman 1974), and the
//! divergence-theorem sums (volume, centroid, vector areas) over the boundary polygons of a
//! clipped polyhedron.
//!
//! The pair frame has world axes and its origin at the first body's centre `xa`: coordinates stay
//! of the size of the bodies wherever the pair is, so rounding is relative to the bodies' size and
//! not to their distance from the world origin. Results are moved back by `xa` at the end.

use super::vertex_penetration::PenetratingPoint;
use crate::math::{DMat3, DQuat, DVec3};
use crate::shape::ConvexPolyhedron;

/// Vertices closer than this to a plane, relative to the pair's size (the sum of the bounding
/// radii), count as on the plane. Faces are planar only to `FACE_MERGE_TOLERANCE` = 10⁻¹⁰ of a
/// shape's diameter (see `shape::polyhedron`), so anything finer would be noise; with it, two faces
/// that lie in one plane (two cubes side by side) are recognised as coplanar.
pub(crate) const PLANE_TOLERANCE: f64 = 1e-10;

/// An oriented plane `normal · x = offset`; `distance(x)` > 0 on the side the normal points to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// Unit normal.
    pub normal: DVec3,
    pub offset: f64,
}

impl Plane {
    /// Signed distance of `p` from the plane, positive in front (outside a body).
    #[inline]
    pub fn distance(&self, p: DVec3) -> f64 {
        self.normal.dot(p) - self.offset
    }
}

/// A polyhedron's vertices and face planes (outward) in the pair frame, with their bounding box.
#[derive(Clone, Debug, Default)]
pub(crate) struct Posed {
    pub vertices: Vec<DVec3>,
    pub planes: Vec<Plane>,
    pub lo: DVec3,
    pub hi: DVec3,
}

impl Posed {
    /// Places `shape` with `rotation` (body → pair frame) and its centre at `translation`.
    pub fn pose(&mut self, shape: &ConvexPolyhedron, rotation: DMat3, translation: DVec3) {
        self.vertices.clear();
        self.vertices
            .extend(shape.vertices().iter().map(|&v| rotation * v + translation));
        self.planes.clear();
        self.planes.extend(shape.faces().iter().map(|f| {
            let normal = rotation * f.normal;
            Plane {
                normal,
                offset: f.offset + normal.dot(translation),
            }
        }));
        let (lo, hi) = self
            .vertices
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            });
        self.lo = lo;
        self.hi = hi;
    }
}

/// One boundary polygon of a clipped polyhedron: `points[start..end]` of the scratch, lying in a
/// face of body A (`from_a`) or of body B, whose outward normal is `normal`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ClippedPolygon {
    pub start: usize,
    pub end: usize,
    pub normal: DVec3,
    pub from_a: bool,
}

/// Per-pair working memory of the polyhedral contact routines, owned by the caller and reused from
/// pair to pair (one per thread), so that the narrow phase allocates nothing once the buffers have
/// grown to the largest pair seen.
#[derive(Clone, Debug, Default)]
pub struct ClipScratch {
    pub(crate) a: Posed,
    pub(crate) b: Posed,
    /// The polygon being clipped and the second buffer of the ping-pong.
    polygon: Vec<DVec3>,
    spare: Vec<DVec3>,
    distances: Vec<f64>,
    /// The other body's planes that pass through the common box.
    active: Vec<Plane>,
    outcodes: Vec<u8>,
    /// The boundary polygons of the intersection, their corners concatenated.
    pub(crate) points: Vec<DVec3>,
    pub(crate) polygons: Vec<ClippedPolygon>,
    /// The result of `vertex_penetration`.
    pub(crate) penetrating: Vec<PenetratingPoint>,
    /// Parts of A's edges inside B, of B's edges inside A (`vertex_penetration`).
    pub(crate) segments_a: Vec<[DVec3; 2]>,
    pub(crate) segments_b: Vec<[DVec3; 2]>,
    /// Working memory of the depth integrals over the boundary polygons ([`boundary_sums`]).
    pub(crate) depth: DepthScratch,
}

/// Working memory of [`depth_integrals`]: the planes that can give the depth somewhere on a
/// polygon, and the ping-pong buffers of its pieces. Three allocations per boundary polygon
/// when they were made afresh each time (a few per cent of a bed of cubes' step).
#[derive(Clone, Debug, Default)]
pub(crate) struct DepthScratch {
    candidates: Vec<usize>,
    piece: Vec<DVec3>,
    spare: Vec<DVec3>,
}

/// Polyhedra with more faces than this together have their common box narrowed to the parts of
/// each inside the other's before the faces are clipped ([`ClipScratch::clip_pair`]). Measured on
/// 1,000 bodies settling (`polydem bench scene bench/cubes_1k.toml`, and the same with random
/// rocks): the narrowing cost a cube pair (12 faces) 23 % of its step and a pair of 16-vertex
/// rocks (56 faces) 12 %, and gained nothing on 64-vertex rocks (248 faces); it is kept for the
/// larger shapes, where it leaves a few faces and planes of many (docs/benchmarks.md).
const NARROWING_FACES: usize = 256;

/// Whether the pair of `a` and `b` has its common box narrowed ([`NARROWING_FACES`]).
pub(crate) fn narrows(a: &ConvexPolyhedron, b: &ConvexPolyhedron) -> bool {
    a.faces().len() + b.faces().len() > NARROWING_FACES
}

impl ClipScratch {
    pub fn new() -> Self {
        Self::default()
    }

    /// Poses both bodies in the pair frame (world axes, origin at `xa`).
    pub(crate) fn pose_pair(
        &mut self,
        a: &ConvexPolyhedron,
        qa: DQuat,
        b: &ConvexPolyhedron,
        xb_relative: DVec3,
        qb: DQuat,
    ) {
        self.a.pose(a, DMat3::from_quat(qa), DVec3::ZERO);
        self.b.pose(b, DMat3::from_quat(qb), xb_relative);
    }

    /// Clips every face of A by B's planes and every face of B by A's planes, keeping the parts
    /// (the boundary of A ∩ B) in `points` / `polygons`.
    ///
    /// A ∩ B lies in a box J, so each face is first cut to J (a face part inside B is inside J),
    /// and then only by the planes that pass through J: a plane with all of J more than
    /// `tolerance` behind it cannot cut a polygon inside J. Faces with all corners beyond one side
    /// of J are skipped at once. J is the box common to both bodies' bounding boxes (I); with
    /// `narrow` (polyhedra with many faces, see [`narrows`]), narrowed to the boxes of A ∩ I and of
    /// B ∩ I, which for a slight overlap leaves a few faces and a few planes of many (for fewer
    /// faces, finding the narrower box cost more than it saved).
    pub(crate) fn clip_pair(
        &mut self,
        a: &ConvexPolyhedron,
        b: &ConvexPolyhedron,
        tolerance: f64,
        narrow: bool,
    ) {
        self.points.clear();
        self.polygons.clear();
        let (mut lo, mut hi) = (self.a.lo.max(self.b.lo), self.a.hi.min(self.b.hi));
        if lo.cmpgt(hi).any() {
            return;
        }
        if narrow {
            for (shape, own) in [(a, &self.a), (b, &self.b)] {
                let (plo, phi) = box_of_part_in_box(
                    shape,
                    own,
                    (lo, hi),
                    &mut self.outcodes,
                    &mut self.polygon,
                    &mut self.spare,
                    tolerance,
                );
                (lo, hi) = (lo.max(plo), hi.min(phi));
                if lo.cmpgt(hi).any() {
                    return;
                }
            }
        }
        let (centre, half) = ((lo + hi) * 0.5, (hi - lo) * 0.5);
        let Self {
            a: pa,
            b: pb,
            polygon,
            spare,
            distances,
            active,
            outcodes,
            points,
            polygons,
            ..
        } = self;
        for (shape, own, other, from_a) in [(a, &*pa, &*pb, true), (b, &*pb, &*pa, false)] {
            active.clear();
            active.extend(
                other
                    .planes
                    .iter()
                    .filter(|p| p.distance(centre) + p.normal.abs().dot(half) >= -tolerance),
            );
            // Outcodes (Cohen & Sutherland): one bit per side of I that a vertex is beyond; a
            // face whose vertices share a bit misses I.
            // J bounds the exact intersection, but the plane clipping below counts corners
            // within `tolerance` of a plane as on it. A face lying within the tolerance outside J
            // (a side face of A a hair outside B's coplanar side face, which the coplanar rule
            // keeps while it drops B's) must reach that clipping, or the boundary is left open
            // and the volume and centroid come out wrong: two stacked cubes set off sideways by
            // less than the tolerance lost 40 % of their overlap volume and had its centroid
            // moved by a tenth of their size. So the box test and cut snap like the planes do.
            let margin = DVec3::splat(tolerance);
            outcodes_for(&own.vertices, (lo - margin, hi + margin), outcodes);
            for (face, plane) in shape.faces().iter().zip(&own.planes) {
                if face.vertices.iter().fold(0x3f, |m, &i| m & outcodes[i]) != 0 {
                    continue;
                }
                polygon.clear();
                polygon.extend(face.vertices.iter().map(|&i| own.vertices[i]));
                let kept = clip_polygon_by_box_snapped(polygon, spare, lo, hi, tolerance)
                    && clip_polygon(
                        polygon,
                        spare,
                        distances,
                        active,
                        tolerance,
                        plane.normal,
                        from_a,
                    );
                if kept {
                    let start = points.len();
                    points.extend_from_slice(polygon);
                    polygons.push(ClippedPolygon {
                        start,
                        end: points.len(),
                        normal: plane.normal,
                        from_a,
                    });
                }
            }
        }
    }
}

/// Vertex outcodes (Cohen & Sutherland) for the box [lo, hi]: one bit per side that the vertex
/// is beyond.
fn outcodes_for(vertices: &[DVec3], (lo, hi): (DVec3, DVec3), out: &mut Vec<u8>) {
    out.clear();
    out.extend(
        vertices
            .iter()
            .map(|&v| (v.cmplt(lo).bitmask() | v.cmpgt(hi).bitmask() << 3) as u8),
    );
}

/// The bounding box of the part of a body inside the box `bx`: of its faces cut to the box and of
/// the box's corners inside the body (the vertices of body ∩ box are of these two kinds). Empty
/// (lo > hi) when nothing is inside.
fn box_of_part_in_box(
    shape: &ConvexPolyhedron,
    own: &Posed,
    bx: (DVec3, DVec3),
    outcodes: &mut Vec<u8>,
    polygon: &mut Vec<DVec3>,
    spare: &mut Vec<DVec3>,
    tolerance: f64,
) -> (DVec3, DVec3) {
    let (mut plo, mut phi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    outcodes_for(&own.vertices, bx, outcodes);
    for face in shape.faces() {
        if face.vertices.iter().fold(0x3f, |m, &i| m & outcodes[i]) != 0 {
            continue;
        }
        polygon.clear();
        polygon.extend(face.vertices.iter().map(|&i| own.vertices[i]));
        if clip_polygon_by_box(polygon, spare, bx.0, bx.1) {
            for &p in polygon.iter() {
                (plo, phi) = (plo.min(p), phi.max(p));
            }
        }
    }
    for k in 0..8 {
        let corner = DVec3::select(
            glam::BVec3::new(k & 1 != 0, k & 2 != 0, k & 4 != 0),
            bx.1,
            bx.0,
        );
        if own.planes.iter().all(|p| p.distance(corner) <= tolerance) {
            (plo, phi) = (plo.min(corner), phi.max(corner));
        }
    }
    (plo, phi)
}

/// Clips the convex polygon to the box [lo, hi], in place; corners on the box are kept. Cut
/// points get the box's coordinate exactly. Returns whether a polygon is left.
pub(crate) fn clip_polygon_by_box(
    polygon: &mut Vec<DVec3>,
    spare: &mut Vec<DVec3>,
    lo: DVec3,
    hi: DVec3,
) -> bool {
    clip_polygon_by_box_snapped(polygon, spare, lo, hi, 0.0)
}

/// [`clip_polygon_by_box`] with corners less than `tolerance` outside a side of the box counted
/// as on it (kept where they are, never cut), as [`clip_polygon`] does for planes.
fn clip_polygon_by_box_snapped(
    polygon: &mut Vec<DVec3>,
    spare: &mut Vec<DVec3>,
    lo: DVec3,
    hi: DVec3,
    tolerance: f64,
) -> bool {
    for axis in 0..3 {
        for (bound, sign) in [(hi[axis], 1.0), (lo[axis], -1.0)] {
            let distance = |p: &DVec3| {
                let d = sign * (p[axis] - bound);
                if d > 0.0 && d <= tolerance {
                    0.0
                } else {
                    d
                }
            };
            if polygon.iter().all(|p| distance(p) <= 0.0) {
                continue;
            }
            spare.clear();
            let n = polygon.len();
            for i in 0..n {
                let j = if i + 1 == n { 0 } else { i + 1 };
                let (di, dj) = (distance(&polygon[i]), distance(&polygon[j]));
                if di <= 0.0 {
                    spare.push(polygon[i]);
                }
                if (di < 0.0 && dj > 0.0) || (di > 0.0 && dj < 0.0) {
                    let mut p = polygon[i] + (polygon[j] - polygon[i]) * (di / (di - dj));
                    p[axis] = bound;
                    spare.push(p);
                }
            }
            std::mem::swap(polygon, spare);
            if polygon.len() < 3 {
                return false;
            }
        }
    }
    true
}

/// Clips the convex polygon `polygon` (corners in order) by the half-spaces behind `planes`, in
/// place. Returns whether a polygon (three corners or more) is left.
///
/// Distances within `tolerance` of a plane are set to zero: such corners are kept and never
/// produce an intersection point, so a polygon touching a plane is not split into slivers.
///
/// A polygon lying in a plane (all its distances zero) is kept or dropped by a fixed rule, so that
/// the intersection's boundary holds every piece of a shared face once:
/// - the plane faces the same way as the polygon's own face (two coplanar faces, bodies on the
///   same side): the face of A is kept, that of B dropped — they cover the same piece;
/// - opposite ways (the bodies on the two sides: face-to-face touching): dropped, no volume.
pub(crate) fn clip_polygon(
    polygon: &mut Vec<DVec3>,
    spare: &mut Vec<DVec3>,
    distances: &mut Vec<f64>,
    planes: &[Plane],
    tolerance: f64,
    own_normal: DVec3,
    keep_coplanar: bool,
) -> bool {
    // A ball around the polygon settles most planes with one distance: all of it more than the
    // tolerance behind (no change) or in front (nothing left).
    let (mut centre, mut radius) = bounding_ball(polygon);
    for plane in planes {
        let dc = plane.distance(centre);
        if dc + radius < -tolerance {
            continue;
        }
        if dc - radius > tolerance {
            return false;
        }
        distances.clear();
        let (mut any_in, mut any_out) = (false, false);
        for &p in polygon.iter() {
            let mut d = plane.distance(p);
            if d.abs() <= tolerance {
                d = 0.0;
            }
            any_in |= d < 0.0;
            any_out |= d > 0.0;
            distances.push(d);
        }
        if !any_in && !any_out {
            if keep_coplanar && own_normal.dot(plane.normal) > 0.0 {
                continue;
            }
            return false;
        }
        if !any_out {
            continue;
        }
        if !any_in {
            return false;
        }
        spare.clear();
        let n = polygon.len();
        for i in 0..n {
            let j = if i + 1 == n { 0 } else { i + 1 };
            let (di, dj) = (distances[i], distances[j]);
            if di <= 0.0 {
                spare.push(polygon[i]);
            }
            if (di < 0.0 && dj > 0.0) || (di > 0.0 && dj < 0.0) {
                let t = di / (di - dj);
                spare.push(polygon[i] + (polygon[j] - polygon[i]) * t);
            }
        }
        std::mem::swap(polygon, spare);
        if polygon.len() < 3 {
            return false;
        }
        (centre, radius) = bounding_ball(polygon);
    }
    true
}

/// A ball containing the points: centred at their mean, reaching the farthest one (slightly
/// enlarged against the rounding of the radius).
fn bounding_ball(points: &[DVec3]) -> (DVec3, f64) {
    let centre = points.iter().copied().sum::<DVec3>() / points.len() as f64;
    let radius_squared = points
        .iter()
        .map(|&p| (p - centre).length_squared())
        .fold(0.0, f64::max);
    (centre, radius_squared.sqrt() * (1.0 + 1e-12))
}

/// The divergence-theorem sums over closed boundary polygons.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct BoundarySums {
    pub volume: f64,
    /// Centroid in the frame of the polygons.
    pub centroid: DVec3,
    /// Σ area · outward normal over A's parts, over B's parts.
    pub vector_area_a: DVec3,
    pub vector_area_b: DVec3,
    /// Σ |area| over all polygons (a scale for round-off decisions).
    pub total_area: f64,
    /// The elastic-foundation (Winkler) resultant per unit stiffness, see [`Winkler`].
    pub winkler: Winkler,
}

/// Resultant of the elastic-foundation potential W = (k/2) ∫_{A∩B} (φ_A + φ_B) dV, per unit k,
/// with φ_X(x) the depth of x below body X's surface. Moving A moves only A's surface through B's
/// field (and B's surface through A's, by reaction), so the force on A is
/// F = (k/2) [∫_{∂B∩A} φ_A n_B dA − ∫_{∂A∩B} φ_B n_A dA]: a pressure proportional to the local
/// depth on each surface, as in an elastic foundation (Johnson 1985 §5.5). It gives k V along the
/// face normal for a face contact, the rocking stiffness of a pressure that grows with depth, and
/// — being the gradient of W — it conserves energy. The depth field of the other body is taken
/// from its face plane nearest each boundary polygon's centroid, which is exact wherever the
/// overlap lies under one face of each body (face, edge and vertex contacts on faces).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Winkler {
    /// Force on A per unit k [m³] (V n for a face contact).
    pub force: DVec3,
    /// Torque on A about the overlap's centroid per unit k [m⁴].
    pub couple: DVec3,
    /// W per unit k [m⁴]: ½ V (φ_A + φ_B) at the centroid.
    pub potential: f64,
}

/// ∫ φ dA and ∫ φ (x − r) dA over the convex polygon `corners` (normal `normal`), with
/// φ(x) = min over `planes` of the depth of x behind the plane. φ is linear on the pieces where
/// one plane gives the minimum: the polygon is cut into those pieces (by the planes' bisectors)
/// and each linear piece integrated exactly over a fan of triangles, using
/// ∫ φ x dA = A/12 (Σ φᵢ xᵢ + Σ φᵢ Σ xᵢ) on a triangle.
fn depth_integrals(
    corners: &[DVec3],
    r: DVec3,
    normal: DVec3,
    planes: &[Plane],
    scratch: &mut DepthScratch,
) -> (f64, DVec3) {
    let depth = |p: &Plane, x: DVec3| -p.distance(x);
    // A plane can be the minimum somewhere on the polygon only if its smallest depth over the
    // corners (a linear function's minimum) is below the largest depth the minimum reaches,
    // which is at most that of any single plane's largest corner depth.
    let bound = planes
        .iter()
        .map(|p| {
            corners
                .iter()
                .map(|&x| depth(p, x))
                .fold(f64::NEG_INFINITY, f64::max)
        })
        .fold(f64::INFINITY, f64::min);
    let DepthScratch {
        candidates,
        piece,
        spare,
    } = scratch;
    candidates.clear();
    candidates.extend((0..planes.len()).filter(|&k| {
        corners
            .iter()
            .map(|&x| depth(&planes[k], x))
            .fold(f64::INFINITY, f64::min)
            <= bound
    }));
    let (mut phi_area, mut phi_moment) = (0.0, DVec3::ZERO);
    for (i, f) in candidates.iter().map(|&k| &planes[k]).enumerate() {
        piece.clear();
        piece.extend_from_slice(corners);
        // Where f is the minimum: depth_f ≤ depth_g for every other candidate (ties to the
        // first, so shared boundaries are counted once).
        for (j, g) in candidates.iter().map(|&k| &planes[k]).enumerate() {
            if i == j || piece.len() < 3 {
                continue;
            }
            let excess = |x: DVec3| {
                let d = depth(f, x) - depth(g, x);
                if j < i && d == 0.0 {
                    f64::MIN_POSITIVE
                } else {
                    d
                }
            };
            spare.clear();
            let n = piece.len();
            for k in 0..n {
                let (a, b) = (piece[k], piece[(k + 1) % n]);
                let (da, db) = (excess(a), excess(b));
                if da <= 0.0 {
                    spare.push(a);
                }
                if (da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0) {
                    spare.push(a + (b - a) * (da / (da - db)));
                }
            }
            std::mem::swap(piece, spare);
        }
        if piece.len() < 3 {
            continue;
        }
        let q0 = piece[0] - r;
        let phi0 = depth(f, piece[0]).max(0.0);
        for w in piece[1..].windows(2) {
            let (q1, q2) = (w[0] - r, w[1] - r);
            let a = 0.5 * (q1 - q0).cross(q2 - q0).dot(normal);
            let (phi1, phi2) = (depth(f, w[0]).max(0.0), depth(f, w[1]).max(0.0));
            phi_area += a * (phi0 + phi1 + phi2) / 3.0;
            phi_moment += a / 12.0
                * (phi0 * q0 + phi1 * q1 + phi2 * q2 + (phi0 + phi1 + phi2) * (q0 + q1 + q2));
        }
    }
    (phi_area, phi_moment)
}

/// Volume and centroid of the polyhedron bounded by the clipped polygons: the sum of the signed
/// tetrahedra (r, p₀, pᵢ, pᵢ₊₁) over the fan of each polygon, with r the mean of all corners (close
/// to the polyhedron, which keeps the tetrahedra small and the cancellation mild).
pub(crate) fn boundary_sums(
    points: &[DVec3],
    polygons: &[ClippedPolygon],
    planes_a: &[Plane],
    planes_b: &[Plane],
    scratch: &mut DepthScratch,
) -> BoundarySums {
    let mut sums = BoundarySums::default();
    if points.is_empty() {
        return sums;
    }
    let r = points.iter().copied().sum::<DVec3>() / points.len() as f64;
    let mut moment = DVec3::ZERO;
    // Σ ±∫ φ n dA and Σ ±∫ φ (x − r) × n dA, + on B's parts, − on A's (see `Winkler`).
    let (mut load, mut couple_about_r) = (DVec3::ZERO, DVec3::ZERO);
    for poly in polygons {
        let corners = &points[poly.start..poly.end];
        let p0 = corners[0] - r;
        // Depth below the other body's surface, φ = min over its faces of the depth below the
        // face's plane: piecewise linear. Integrated exactly over the polygon's pieces.
        let other = if poly.from_a { planes_b } else { planes_a };
        let mut doubled_area = DVec3::ZERO;
        for w in corners[1..].windows(2) {
            let (p1, p2) = (w[0] - r, w[1] - r);
            let six_v = p0.dot(p1.cross(p2));
            sums.volume += six_v;
            moment += six_v * (p0 + p1 + p2);
            doubled_area += (p1 - p0).cross(p2 - p0);
        }
        let (phi_area, phi_moment) = depth_integrals(corners, r, poly.normal, other, scratch);
        let sign = if poly.from_a { -0.5 } else { 0.5 };
        load += sign * phi_area * poly.normal;
        couple_about_r += sign * phi_moment.cross(poly.normal);
        let area = 0.5 * doubled_area.dot(poly.normal);
        sums.total_area += area.abs();
        if poly.from_a {
            sums.vector_area_a += area * poly.normal;
        } else {
            sums.vector_area_b += area * poly.normal;
        }
    }
    // Σ 6V and Σ 6V (p₀+p₁+p₂): the tetrahedron's centroid is (r + p₀ + p₁ + p₂)/4, relative to r
    // (p₀ + p₁ + p₂)/4.
    sums.centroid = if sums.volume != 0.0 {
        r + moment / (4.0 * sums.volume)
    } else {
        r
    };
    let c = sums.centroid;
    let depth_at = |planes: &[Plane]| {
        planes
            .iter()
            .map(|p| -p.distance(c))
            .fold(f64::INFINITY, f64::min)
            .max(0.0)
    };
    sums.winkler = Winkler {
        force: load,
        // About the centroid: M_c = M_r − (c − r) × F.
        couple: couple_about_r - (c - r).cross(load),
        potential: 0.5 * sums.volume / 6.0 * (depth_at(planes_a) + depth_at(planes_b)),
    };
    sums.volume /= 6.0;
    sums
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_clipped_by_a_diagonal_plane() {
        let mut poly = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
        ];
        let plane = Plane {
            normal: DVec3::new(1.0, 1.0, 0.0).normalize(),
            offset: 0.5f64.sqrt(),
        };
        let (mut spare, mut d) = (Vec::new(), Vec::new());
        assert!(clip_polygon(
            &mut poly,
            &mut spare,
            &mut d,
            &[plane],
            1e-12,
            DVec3::Z,
            true
        ));
        // The triangle below x + y = 1: the diagonal's corners are on the plane and kept as they are.
        assert_eq!(
            poly,
            vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0)
            ]
        );
    }

    #[test]
    fn coplanar_polygons_follow_the_rule() {
        let square = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
        ];
        let up = Plane {
            normal: DVec3::Z,
            offset: 0.0,
        };
        let (mut spare, mut d) = (Vec::new(), Vec::new());
        for (own, keep, expected) in [
            (DVec3::Z, true, true),
            (DVec3::Z, false, false),
            (-DVec3::Z, true, false),
            (-DVec3::Z, false, false),
        ] {
            let mut poly = square.clone();
            let kept = clip_polygon(&mut poly, &mut spare, &mut d, &[up], 1e-12, own, keep);
            assert_eq!(kept, expected);
        }
    }
}
