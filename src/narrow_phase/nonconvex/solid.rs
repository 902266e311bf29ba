//! A body as the region contacts see it, convex or a mesh, and the queries they ask of it in its
//! own frame: which vertices and edges are near, is a point inside, how deep, where does a
//! segment cross its faces.

use super::super::clip::Plane;
use crate::geometry::predicates::orient3d;
use crate::geometry::Location;
use crate::math::{Aabb, DMat3, DVec3};
use crate::shape::{ConvexPolyhedron, NonConvexPolyhedron};

/// A crossing of a segment through a face of a body: its parameter on the segment and the face.
#[derive(Clone, Copy, Debug)]
pub(super) struct Crossing {
    pub(super) t: f64,
    pub(super) face: u32,
}

/// A body seen by the region contact: a convex polyhedron or a mesh.
#[derive(Clone, Copy)]
pub enum Solid<'a> {
    Convex(&'a ConvexPolyhedron),
    Mesh(&'a NonConvexPolyhedron),
}

impl Solid<'_> {
    pub(super) fn bounding_radius(&self) -> f64 {
        match self {
            Solid::Convex(p) => p.bounding_radius(),
            Solid::Mesh(p) => p.bounding_radius(),
        }
    }

    pub(super) fn bounds(&self) -> Aabb {
        match self {
            Solid::Convex(p) => p.bounds(),
            Solid::Mesh(p) => p.bounds(),
        }
    }

    pub(super) fn vertex(&self, i: u32) -> DVec3 {
        match self {
            Solid::Convex(p) => p.vertices()[i as usize],
            Solid::Mesh(p) => p.vertices()[i as usize],
        }
    }

    /// Edge `e`: its two vertices, its two faces, and whether it is sharp.
    pub(super) fn edge(&self, e: u32) -> ([u32; 2], [u32; 2], bool) {
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
    pub(super) fn near(
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

    pub(super) fn locate(&self, p: DVec3) -> Location {
        match self {
            Solid::Convex(s) => s.locate(p),
            Solid::Mesh(s) => s.locate(p),
        }
    }

    /// For a point inside: its distance to the surface and the outward direction there (from the
    /// point to the nearest surface point; the nearest face's normal for a convex body).
    pub(super) fn depth(&self, p: DVec3) -> (f64, DVec3) {
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
    pub(super) fn crossings(
        &self,
        p: DVec3,
        q: DVec3,
        near: &mut Vec<u32>,
        out: &mut Vec<Crossing>,
    ) {
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

/// The rigid map from one body's frame to another's (or to the pair frame).
#[derive(Clone, Copy, Debug)]
pub(super) struct Transform {
    pub(super) rotation: DMat3,
    pub(super) translation: DVec3,
}

impl Transform {
    pub(super) fn apply(&self, p: DVec3) -> DVec3 {
        self.rotation * p + self.translation
    }

    pub(super) fn box_of(&self, b: &Aabb) -> Aabb {
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
