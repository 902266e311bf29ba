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

use super::clip::{ClipScratch, Plane};
use super::separation::bounding_spheres_separated;
use super::sphere_mesh::{sphere_mesh_contacts, MeshContact, MeshScratch};
use super::Geometry;
use crate::geometry::predicates::orient3d;
use crate::geometry::Location;
use crate::math::{Aabb, DMat3, DQuat, DVec3};
use crate::shape::{ConvexPolyhedron, NonConvexPolyhedron};

/// The most contacts one pair of bodies (or a body and a wall) keeps at once.
pub const MAX_REGIONS: usize = 8;

/// A penetrating point in the pair frame (world axes, origin at A's centre).
#[derive(Clone, Copy, Debug)]
struct Point {
    position: DVec3,
    /// Depth of the spring (≥ 0; 0 for a crossing point).
    depth: f64,
    /// Its contribution to the load on A, depth × direction of the force (per unit stiffness);
    /// negative for the correction of an edge spring (see `edge_spring`).
    force: DVec3,
    /// Its contribution to the potential, ½ depth² (per unit stiffness), or the correction's.
    potential: f64,
    /// Whether it counts as a spring (for the contact's tangent stiffness).
    counts: bool,
}

impl Point {
    /// A vertex spring: `depth` along the unit `normal` (the force on A).
    fn spring(position: DVec3, depth: f64, normal: DVec3) -> Self {
        Self {
            position,
            depth,
            force: depth * normal,
            potential: 0.5 * depth * depth,
            counts: depth > 0.0,
        }
    }

    /// A point that only marks the outline (a crossing).
    fn mark(position: DVec3) -> Self {
        Self {
            position,
            depth: 0.0,
            force: DVec3::ZERO,
            potential: 0.0,
            counts: false,
        }
    }
}

/// A crossing of a segment through a face of a body: its parameter on the segment and the face.
#[derive(Clone, Copy, Debug)]
struct Crossing {
    t: f64,
    face: u32,
}

/// Working memory of the region contacts, reused from pair to pair (one per thread).
#[derive(Clone, Debug, Default)]
pub struct RegionScratch {
    pub clip: ClipScratch,
    mesh: MeshScratch,
    mesh_contacts: Vec<MeshContact>,
    points: Vec<Point>,
    parent: Vec<u32>,
    /// (face of A, face of B) → crossing point.
    keys: Vec<(u64, u32)>,
    crossings: Vec<Crossing>,
    near: Vec<u32>,
    /// Triangles that may be nearest to an edge part (`edge_spring`).
    nearest: Vec<u32>,
    vertices: Vec<u32>,
    edges: Vec<u32>,
    /// (vertex, its point) for the vertices of A and of B inside the other.
    inside_a: Vec<(u32, u32)>,
    inside_b: Vec<(u32, u32)>,
    region_of: Vec<u32>,
    members: Vec<(u32, u32)>,
    hull: Vec<[f64; 2]>,
}

impl RegionScratch {
    pub fn new() -> Self {
        Self::default()
    }

    fn clear(&mut self) {
        self.points.clear();
        self.parent.clear();
        self.keys.clear();
        self.inside_a.clear();
        self.inside_b.clear();
    }

    fn push_point(&mut self, p: Point) -> u32 {
        self.points.push(p);
        self.parent.push(self.parent.len() as u32);
        (self.points.len() - 1) as u32
    }

    fn find(&mut self, mut i: u32) -> u32 {
        while self.parent[i as usize] != i {
            let up = self.parent[self.parent[i as usize] as usize];
            self.parent[i as usize] = up;
            i = up;
        }
        i
    }

    fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        // The smaller index becomes the root: the grouping does not depend on the order of joins.
        if ra < rb {
            self.parent[rb as usize] = ra;
        } else if rb < ra {
            self.parent[ra as usize] = rb;
        }
    }
}

/// A body seen by the region contact: a convex polyhedron or a mesh.
#[derive(Clone, Copy)]
pub enum Solid<'a> {
    Convex(&'a ConvexPolyhedron),
    Mesh(&'a NonConvexPolyhedron),
}

impl Solid<'_> {
    fn bounding_radius(&self) -> f64 {
        match self {
            Solid::Convex(p) => p.bounding_radius(),
            Solid::Mesh(p) => p.bounding_radius(),
        }
    }

    fn bounds(&self) -> Aabb {
        match self {
            Solid::Convex(p) => p.bounds(),
            Solid::Mesh(p) => p.bounds(),
        }
    }

    fn vertex(&self, i: u32) -> DVec3 {
        match self {
            Solid::Convex(p) => p.vertices()[i as usize],
            Solid::Mesh(p) => p.vertices()[i as usize],
        }
    }

    /// Edge `e`: its two vertices, its two faces, and whether it is sharp.
    fn edge(&self, e: u32) -> ([u32; 2], [u32; 2], bool) {
        match self {
            Solid::Convex(p) => {
                let edge = p.edges()[e as usize];
                (
                    edge.vertices.map(|v| v as u32),
                    edge.faces.map(|f| f as u32),
                    true,
                )
            }
            Solid::Mesh(p) => {
                let s = p.surface();
                let t = s.triangles_of_edge(e);
                (s.edges()[e as usize], [t[0], t[1]], p.is_sharp(e))
            }
        }
    }

    /// The vertices inside `query` and the edges whose box meets it, sorted, into `vertices` and
    /// `edges`.
    /// The vertices inside `query` (own frame) into `vertices`, and into `edges` the edges that
    /// may cross the other body's surface: of a mesh, the edges of the triangles whose boxes, in
    /// the other's frame (`to_other`), meet a triangle's box of the other (an edge through a
    /// triangle has both its triangles meeting it); of a convex body, those whose box meets the
    /// query. Both sorted. Returns false when no triangle meets: the bodies do not touch.
    fn near(
        &self,
        query: &Aabb,
        other: Solid,
        to_other: &Transform,
        near: &mut Vec<u32>,
        vertices: &mut Vec<u32>,
        edges: &mut Vec<u32>,
    ) -> bool {
        vertices.clear();
        edges.clear();
        let inside = |p: DVec3| p.cmpge(query.min).all() && p.cmple(query.max).all();
        match self {
            Solid::Convex(p) => {
                vertices.extend(
                    (0..p.vertices().len() as u32).filter(|&i| inside(p.vertices()[i as usize])),
                );
                edges.extend((0..p.edges().len() as u32).filter(|&e| {
                    let [a, b] = p.edges()[e as usize].vertices.map(|i| p.vertices()[i]);
                    Aabb::new(a.min(b), a.max(b)).overlaps(query)
                }));
                true
            }
            Solid::Mesh(p) => {
                p.bvh().overlapping(query, near);
                let s = p.surface();
                let other_box = other.bounds();
                for &t in near.iter() {
                    let corners = p.triangles()[t as usize];
                    for &v in &corners {
                        if inside(p.vertices()[v]) {
                            vertices.push(v as u32);
                        }
                    }
                    let [a, b, c] = corners.map(|i| to_other.apply(p.vertices()[i]));
                    let tri = Aabb::new(a.min(b).min(c), a.max(b).max(c));
                    let meets = tri.overlaps(&other_box)
                        && match other {
                            Solid::Convex(_) => true,
                            Solid::Mesh(o) => !o.bvh().visit(|b| b.overlaps(&tri), |_| false),
                        };
                    if meets {
                        edges.extend_from_slice(&s.triangle_edges()[t as usize]);
                    }
                }
                vertices.sort_unstable();
                vertices.dedup();
                edges.sort_unstable();
                edges.dedup();
                !edges.is_empty()
            }
        }
    }

    fn locate(&self, p: DVec3) -> Location {
        match self {
            Solid::Convex(s) => s.locate(p),
            Solid::Mesh(s) => s.locate(p),
        }
    }

    /// For a point inside: its distance to the surface and the outward direction there (from the
    /// point to the nearest surface point; the nearest face's normal for a convex body).
    fn depth(&self, p: DVec3) -> (f64, DVec3) {
        match self {
            Solid::Convex(s) => {
                let (face, depth) = s
                    .faces()
                    .iter()
                    .map(|f| f.offset - f.normal.dot(p))
                    .enumerate()
                    .fold(
                        (0, f64::INFINITY),
                        |best, (k, d)| {
                            if d < best.1 {
                                (k, d)
                            } else {
                                best
                            }
                        },
                    );
                (depth.max(0.0), s.faces()[face].normal)
            }
            Solid::Mesh(s) => {
                let (q, t) = s.closest_point(p);
                let d = q - p;
                let length = d.length();
                let normal = if length > 1e-12 * s.bounding_radius() {
                    d / length
                } else {
                    s.normals()[t as usize]
                };
                (length, normal)
            }
        }
    }

    /// The crossings of the segment p q (body frame) through the faces, in order along it.
    fn crossings(&self, p: DVec3, q: DVec3, near: &mut Vec<u32>, out: &mut Vec<Crossing>) {
        out.clear();
        match self {
            Solid::Convex(s) => {
                // Cyrus & Beck: the part of the segment behind every face plane.
                let (mut t0, mut t1) = (0.0f64, 1.0f64);
                let (mut enter, mut exit) = (None, None);
                for (k, f) in s.faces().iter().enumerate() {
                    let plane = Plane {
                        normal: f.normal,
                        offset: f.offset,
                    };
                    let (dp, dq) = (plane.distance(p), plane.distance(q));
                    if dp >= 0.0 && dq >= 0.0 {
                        return;
                    }
                    if dp <= 0.0 && dq <= 0.0 {
                        continue;
                    }
                    let t = dp / (dp - dq);
                    if dp > 0.0 {
                        if t > t0 {
                            (t0, enter) = (t, Some(k));
                        }
                    } else if t < t1 {
                        (t1, exit) = (t, Some(k));
                    }
                    if t0 >= t1 {
                        return;
                    }
                }
                for (t, face) in [(t0, enter), (t1, exit)] {
                    if let Some(face) = face {
                        out.push(Crossing {
                            t,
                            face: face as u32,
                        });
                    }
                }
            }
            Solid::Mesh(s) => {
                s.bvh().overlapping(&Aabb::new(p.min(q), p.max(q)), near);
                for &t in near.iter() {
                    let [a, b, c] = s.triangles()[t as usize].map(|i| s.vertices()[i]);
                    let (sp, sq) = (orient3d(a, b, c, p), orient3d(a, b, c, q));
                    if !((sp > 0.0 && sq < 0.0) || (sp < 0.0 && sq > 0.0)) {
                        continue;
                    }
                    let e = [
                        orient3d(p, q, a, b),
                        orient3d(p, q, b, c),
                        orient3d(p, q, c, a),
                    ];
                    if !(e.iter().all(|&x| x > 0.0) || e.iter().all(|&x| x < 0.0)) {
                        continue;
                    }
                    out.push(Crossing {
                        t: (sp / (sp - sq)).clamp(0.0, 1.0),
                        face: t,
                    });
                }
                out.sort_unstable_by(|x, y| x.t.total_cmp(&y.t).then(x.face.cmp(&y.face)));
            }
        }
    }
}

/// A body's pose.
#[derive(Clone, Copy, Debug)]
pub struct Pose {
    pub position: DVec3,
    pub orientation: DQuat,
}

/// The rigid map from one body's frame to another's (or to the pair frame).
#[derive(Clone, Copy, Debug)]
struct Transform {
    rotation: DMat3,
    translation: DVec3,
}

impl Transform {
    fn apply(&self, p: DVec3) -> DVec3 {
        self.rotation * p + self.translation
    }

    fn box_of(&self, b: &Aabb) -> Aabb {
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for k in 0..8 {
            let c = DVec3::new(
                if k & 1 == 0 { b.min.x } else { b.max.x },
                if k & 2 == 0 { b.min.y } else { b.max.y },
                if k & 4 == 0 { b.min.z } else { b.max.z },
            );
            let p = self.apply(c);
            lo = lo.min(p);
            hi = hi.max(p);
        }
        Aabb::new(lo, hi)
    }
}

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
                    let (z, _) = super::closest_point_on_triangle(y, a, b, c);
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

/// Groups the scratch's points by their union–find roots and writes one contact per region with
/// penetration (pair-frame points moved by `origin`).
fn regions_of_points(scratch: &mut RegionScratch, origin: DVec3, out: &mut Vec<Geometry>) {
    let n = scratch.points.len();
    if n == 0 {
        return;
    }
    // Region ids in order of first appearance.
    scratch.region_of.clear();
    scratch.region_of.resize(n, u32::MAX);
    scratch.members.clear();
    let mut id_of_root: Vec<(u32, u32)> = Vec::new();
    for i in 0..n as u32 {
        let root = scratch.find(i);
        let id = match id_of_root.iter().find(|&&(r, _)| r == root) {
            Some(&(_, id)) => id,
            None => {
                let id = id_of_root.len() as u32;
                id_of_root.push((root, id));
                id
            }
        };
        scratch.region_of[i as usize] = id;
        scratch.members.push((id, i));
    }
    let mut labels: Vec<u32> = scratch.region_of.clone();
    loop {
        let geometries = region_geometries(scratch, &labels, origin);
        if geometries.len() <= MAX_REGIONS {
            out.extend(geometries.into_iter().map(|(g, _, _)| g));
            return;
        }
        // Merge the region of least total depth into the one whose centre is nearest.
        let (weakest, _) = geometries
            .iter()
            .enumerate()
            .min_by(|x, y| x.1 .1.total_cmp(&y.1 .1))
            .expect("regions");
        let centre = geometries[weakest].0.point;
        let (nearest, _) = geometries
            .iter()
            .enumerate()
            .filter(|&(k, _)| k != weakest)
            .min_by(|x, y| {
                (x.1 .0.point - centre)
                    .length_squared()
                    .total_cmp(&(y.1 .0.point - centre).length_squared())
            })
            .expect("another region");
        let (from, to) = (geometries[weakest].2 as u32, geometries[nearest].2 as u32);
        for l in labels.iter_mut() {
            if *l == from {
                *l = to;
            }
        }
    }
}

/// One contact per label with penetration: (geometry, total depth, label).
fn region_geometries(
    scratch: &mut RegionScratch,
    labels: &[u32],
    origin: DVec3,
) -> Vec<(Geometry, f64, usize)> {
    let regions = labels.iter().copied().max().map_or(0, |m| m as usize + 1);
    let mut result = Vec::new();
    for r in 0..regions as u32 {
        let members = || {
            labels
                .iter()
                .enumerate()
                .filter(move |&(_, &l)| l == r)
                .map(|(i, _)| i)
        };
        let points = &scratch.points;
        let total: f64 = members()
            .filter(|&i| points[i].counts)
            .map(|i| points[i].depth)
            .sum();
        let Some(mut g) = aggregate(members().map(|i| &points[i]), origin) else {
            continue;
        };
        let area = projected_area(
            members().map(|i| points[i].position),
            g.normal,
            &mut scratch.hull,
        );
        if let Some(v) = g.volume.as_mut() {
            v.area = area;
        }
        result.push((g, total, r as usize));
    }
    result
}

/// One contact for the springs of a region: their resultant load Σ fᵢ, acting at the
/// depth-weighted mean point of the springs, with the exact moment of the individual springs as a
/// couple (as `dispatch::springs`, with signed contributions). `None` without a spring.
fn aggregate<'p>(points: impl Iterator<Item = &'p Point>, origin: DVec3) -> Option<Geometry> {
    let (mut load, mut weighted, mut total, mut potential, mut count) =
        (DVec3::ZERO, DVec3::ZERO, 0.0, 0.0, 0usize);
    let mut first_moment = DVec3::ZERO;
    for p in points {
        let x = p.position + origin;
        load += p.force;
        first_moment += x.cross(p.force);
        potential += p.potential;
        if p.counts && p.depth > 0.0 {
            weighted += p.depth * x;
            total += p.depth;
            count += 1;
        }
    }
    if count == 0 {
        return None;
    }
    let normal = load.try_normalize()?;
    let centre = weighted / total;
    Some(Geometry {
        normal,
        point: centre,
        overlap: total / count as f64,
        volume: Some(crate::contact_law::OverlapVolume {
            law: crate::contact_law::PolyhedralLaw::Vertex,
            points: count,
            volume: 0.0,
            area: 0.0,
            load: load.length(),
            couple: first_moment - centre.cross(load),
            potential,
        }),
    })
}

/// Area of the convex hull of the points projected on the plane normal to `normal` (Andrew's
/// monotone chain).
fn projected_area(
    points: impl Iterator<Item = DVec3>,
    normal: DVec3,
    hull: &mut Vec<[f64; 2]>,
) -> f64 {
    let (u, w) = normal.any_orthonormal_pair();
    let mut pts: Vec<[f64; 2]> = points.map(|p| [u.dot(p), w.dot(p)]).collect();
    if pts.len() < 3 {
        return 0.0;
    }
    pts.sort_unstable_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    hull.clear();
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &[f64; 2]>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    let m = hull.len();
    if m < 3 {
        return 0.0;
    }
    let mut twice = 0.0;
    for k in 0..m {
        let (a, b) = (hull[k], hull[(k + 1) % m]);
        twice += a[0] * b[1] - a[1] * b[0];
    }
    0.5 * twice.abs()
}

/// The contact regions of a mesh body with the half-space behind a plane (`normal` into the free
/// side): connected groups of its vertices behind the plane (joined by the edges between them),
/// each a contact of the vertex law along the plane's normal.
pub fn mesh_plane(
    shape: &NonConvexPolyhedron,
    pose: Pose,
    point: DVec3,
    normal: DVec3,
    scratch: &mut RegionScratch,
    out: &mut Vec<Geometry>,
) {
    out.clear();
    scratch.clear();
    let to_body = pose.orientation.inverse();
    let n = to_body * normal;
    let height = n.dot(to_body * (point - pose.position));
    // Nothing behind, or the whole body behind (outside the domain, as for a sphere).
    let lowest = shape.bvh().bounds().min.dot(n.max(DVec3::ZERO))
        + shape.bvh().bounds().max.dot(n.min(DVec3::ZERO));
    if lowest >= height {
        return;
    }
    let below = |b: &Aabb| {
        let low = b.min.dot(n.max(DVec3::ZERO)) + b.max.dot(n.min(DVec3::ZERO));
        low < height
    };
    let RegionScratch { near, .. } = scratch;
    near.clear();
    shape.bvh().visit(below, |t| {
        near.push(t);
        true
    });
    let near = std::mem::take(&mut scratch.near);
    let (vertices, surface) = (shape.vertices(), shape.surface());
    scratch.vertices.clear();
    scratch.edges.clear();
    for &t in &near {
        scratch
            .vertices
            .extend(shape.triangles()[t as usize].iter().map(|&v| v as u32));
        scratch
            .edges
            .extend_from_slice(&surface.triangle_edges()[t as usize]);
    }
    scratch.near = near;
    scratch.vertices.sort_unstable();
    scratch.vertices.dedup();
    scratch.edges.sort_unstable();
    scratch.edges.dedup();
    if scratch.vertices.len() == vertices.len() && vertices.iter().all(|v| n.dot(*v) < height) {
        return;
    }
    let rotation = DMat3::from_quat(pose.orientation);
    let candidates = std::mem::take(&mut scratch.vertices);
    for &v in &candidates {
        let depth = height - n.dot(vertices[v as usize]);
        if depth > 0.0 {
            let p = scratch.push_point(Point::spring(
                rotation * vertices[v as usize],
                depth,
                normal,
            ));
            scratch.inside_a.push((v, p));
        }
    }
    scratch.vertices = candidates;
    let edges = std::mem::take(&mut scratch.edges);
    for &e in &edges {
        let [v0, v1] = surface.edges()[e as usize];
        let find = |v: u32| {
            scratch
                .inside_a
                .binary_search_by_key(&v, |&(u, _)| u)
                .ok()
                .map(|k| scratch.inside_a[k].1)
        };
        match (find(v0), find(v1)) {
            (Some(i), Some(j)) => scratch.union(i, j),
            (Some(i), None) | (None, Some(i)) => {
                // The crossing of the plane outlines the region (for its area).
                let (p, q) = (vertices[v0 as usize], vertices[v1 as usize]);
                let (dp, dq) = (height - n.dot(p), height - n.dot(q));
                if dp != dq {
                    let x = p + (q - p) * (dp / (dp - dq));
                    let c = scratch.push_point(Point::mark(rotation * x));
                    scratch.union(i, c);
                }
            }
            (None, None) => {}
        }
    }
    scratch.edges = edges;
    regions_of_points(scratch, pose.position, out);
}

/// The contact regions of a mesh body pressed into one region of a mesh wall (see
/// `convex_mesh`): `springs` are its vertices behind the wall, sorted by vertex, each with its
/// depth and the plane of the wall face it lies behind (relative to the body's centre `origin`,
/// world axes; `rotation` turns the body frame to the world). As against a plane (`mesh_plane`),
/// vertices joined by an edge of the body are one region, and the crossings of that face's plane
/// by the edges that leave it outline the region (for its area).
pub fn mesh_wall_regions(
    shape: &NonConvexPolyhedron,
    rotation: DMat3,
    origin: DVec3,
    springs: &[(u32, f64, Plane)],
    scratch: &mut RegionScratch,
    out: &mut Vec<Geometry>,
) {
    scratch.clear();
    let (vertices, surface) = (shape.vertices(), shape.surface());
    let position = |v: u32| rotation * vertices[v as usize];
    for &(v, depth, face) in springs {
        let p = scratch.push_point(Point::spring(position(v), depth, face.normal));
        scratch.inside_a.push((v, p));
    }
    let mut edges = std::mem::take(&mut scratch.edges);
    edges.clear();
    for &(v, ..) in springs {
        for &t in surface.triangles_of_vertex(v) {
            edges.extend_from_slice(&surface.triangle_edges()[t as usize]);
        }
    }
    edges.sort_unstable();
    edges.dedup();
    // Index in `springs` (and `inside_a`) of a vertex behind the wall.
    let spring_of = |inside: &[(u32, u32)], v: u32| inside.binary_search_by_key(&v, |&(u, _)| u);
    for &e in &edges {
        let [v0, v1] = surface.edges()[e as usize];
        let (inside, outside, k) = match (
            spring_of(&scratch.inside_a, v0),
            spring_of(&scratch.inside_a, v1),
        ) {
            (Ok(i), Ok(j)) => {
                let (i, j) = (scratch.inside_a[i].1, scratch.inside_a[j].1);
                scratch.union(i, j);
                continue;
            }
            (Ok(k), Err(_)) => (v0, v1, k),
            (Err(_), Ok(k)) => (v1, v0, k),
            (Err(_), Err(_)) => continue,
        };
        let (_, depth, face) = springs[k];
        let (p, q) = (position(inside), position(outside));
        let beyond = -face.distance(q);
        // Only an edge that comes out in front of the face crosses it.
        if beyond < 0.0 {
            let x = p + (q - p) * (depth / (depth - beyond));
            let c = scratch.push_point(Point::mark(x));
            let i = scratch.inside_a[k].1;
            scratch.union(i, c);
        }
    }
    scratch.edges = edges;
    regions_of_points(scratch, origin, out);
}

/// The contacts of a mesh body with a sphere (`centre`, `radius`), normals pointing from the
/// sphere towards the body: the sphere–mesh contacts of the body's surface (one per local
/// minimum of the distance, see `sphere_mesh`), worked in the body frame.
pub fn mesh_sphere(
    shape: &NonConvexPolyhedron,
    pose: Pose,
    centre: DVec3,
    radius: f64,
    scratch: &mut RegionScratch,
    out: &mut Vec<Geometry>,
) {
    out.clear();
    if bounding_spheres_separated(pose.position, shape.bounding_radius(), centre, radius) {
        return;
    }
    let local = pose.orientation.inverse() * (centre - pose.position);
    let RegionScratch {
        mesh,
        mesh_contacts,
        ..
    } = scratch;
    sphere_mesh_contacts(local, radius, shape.surface(), mesh, mesh_contacts);
    for c in mesh_contacts.iter().take(MAX_REGIONS) {
        let g = c.geometry;
        out.push(Geometry {
            normal: -(pose.orientation * g.normal),
            point: pose.position + pose.orientation * g.point,
            overlap: g.overlap,
            volume: None,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::nonconvex_generators::{cross, jack};
    use crate::shape::{generators, nonconvex_generators::NonConvexMesh};

    /// A generated body and the pose that puts it at `x`, turned by `q`, as it was described.
    struct Body {
        shape: NonConvexPolyhedron,
        mass: crate::shape::MassProperties,
    }

    impl Body {
        fn pose(&self, x: DVec3, q: DQuat) -> Pose {
            Pose {
                position: x + q * self.mass.center_of_mass,
                orientation: (q * self.mass.principal_rotation()).normalize(),
            }
        }

        fn at(&self, x: DVec3) -> Pose {
            self.pose(x, DQuat::IDENTITY)
        }

        fn solid(&self) -> Solid<'_> {
            Solid::Mesh(&self.shape)
        }
    }

    fn mesh(m: NonConvexMesh) -> Body {
        let (shape, mass) = m.build(false).unwrap();
        Body { shape, mass }
    }

    fn at(x: DVec3) -> Pose {
        Pose {
            position: x,
            orientation: DQuat::IDENTITY,
        }
    }

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

    #[test]
    fn jack_on_a_plane_touches_with_each_arm_end() {
        let j = mesh(jack(3.0, 1.0).unwrap());
        let mut s = RegionScratch::new();
        let mut out = Vec::new();
        // Turned so that three arms point down at equal angles: the body diagonal (1,1,1) up.
        let q = DQuat::from_rotation_arc(DVec3::new(1.0, 1.0, 1.0).normalize(), -DVec3::Z);
        let probe = j.pose(DVec3::ZERO, q);
        let lowest = j
            .shape
            .vertices()
            .iter()
            .map(|&v| (probe.position + probe.orientation * v).z)
            .fold(f64::INFINITY, f64::min);
        let pose = j.pose(DVec3::new(0.0, 0.0, -lowest - 0.01), q);
        mesh_plane(&j.shape, pose, DVec3::ZERO, DVec3::Z, &mut s, &mut out);
        assert_eq!(out.len(), 3, "{out:?}");
        for g in &out {
            assert_eq!(g.normal, DVec3::Z);
            assert!((g.overlap - 0.01).abs() < 1e-9);
            assert_eq!(g.volume.unwrap().points, 1);
        }
        // High above: nothing.
        mesh_plane(
            &j.shape,
            j.pose(DVec3::Z * 10.0, q),
            DVec3::ZERO,
            DVec3::Z,
            &mut s,
            &mut out,
        );
        assert!(out.is_empty());
    }

    #[test]
    fn sphere_in_the_crook_of_a_jack_touches_two_arms() {
        let j = mesh(jack(3.0, 1.0).unwrap());
        let mut s = RegionScratch::new();
        let mut out = Vec::new();
        // Between the +x and +y arms (faces y = 0.5 and x = 0.5), radius 0.5, 0.01 deep each.
        let r = 0.5;
        let c = DVec3::new(1.0 - 0.01, 1.0 - 0.01, 0.0);
        mesh_sphere(&j.shape, j.at(DVec3::ZERO), c, r, &mut s, &mut out);
        assert_eq!(out.len(), 2, "{out:?}");
        for g in &out {
            assert!((g.overlap - 0.01).abs() < 1e-12);
            // From the sphere towards the jack: −x or −y.
            assert!(
                (g.normal + DVec3::X).length() < 1e-12 || (g.normal + DVec3::Y).length() < 1e-12
            );
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
