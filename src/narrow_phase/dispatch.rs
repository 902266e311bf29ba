//! Which contact routine a pair of bodies needs, by the kinds of their shapes.

use super::nonconvex::{mesh_plane, mesh_sphere, solid_solid, Pose, RegionScratch, Solid};
use super::{
    convex_convex, convex_plane, convex_sphere, sphere_plane, sphere_sphere, vertex_penetration,
    ClipScratch, Geometry, VolumeContact,
};
use crate::contact_law::{OverlapVolume, PolyhedralLaw};
use crate::math::{DQuat, DVec3};
use crate::shape::Shape;
use crate::shape::{ConvexPart, ConvexPolyhedron, NonConvexPolyhedron};

/// Where a body is: its shape, centre of mass and orientation (body → world).
#[derive(Clone, Copy)]
pub struct Posed<'a> {
    pub shape: &'a Shape,
    pub position: DVec3,
    pub orientation: DQuat,
}

/// The contact of two bodies, normal pointing from `b` towards `a`; `None` if they do not touch.
/// A body that can touch in several regions (a non-convex one) gives its deepest region here;
/// [`body_body_regions`] gives them all.
pub fn body_body(
    a: Posed,
    b: Posed,
    law: PolyhedralLaw,
    scratch: &mut ClipScratch,
) -> Option<Geometry> {
    match (a.shape, b.shape) {
        (Shape::NonConvex(_), _) | (_, Shape::NonConvex(_)) => {
            let mut regions = RegionScratch::new();
            let mut out = Vec::new();
            body_body_regions(a, b, law, &mut regions, &mut out);
            out.into_iter()
                .max_by(|x, y| x.overlap.total_cmp(&y.overlap))
        }
        (Shape::Sphere(sa), Shape::Sphere(sb)) => {
            sphere_sphere(a.position, sa.radius, b.position, sb.radius)
        }
        (Shape::Convex(pa), Shape::Convex(pb)) => convex_pair(
            pa,
            a.position,
            a.orientation,
            pb,
            b.position,
            b.orientation,
            law,
            scratch,
        ),
        (Shape::Convex(pa), Shape::Sphere(sb)) => {
            convex_sphere_geometry(pa, a.position, a.orientation, b.position, sb.radius)
        }
        (Shape::Sphere(sa), Shape::Convex(pb)) => {
            convex_sphere_geometry(pb, b.position, b.orientation, a.position, sa.radius).map(|g| {
                Geometry {
                    normal: -g.normal,
                    ..g
                }
            })
        }
    }
}

/// Two convex polyhedra under the polyhedral law.
#[allow(clippy::too_many_arguments)]
fn convex_pair(
    pa: &ConvexPolyhedron,
    xa: DVec3,
    qa: DQuat,
    pb: &ConvexPolyhedron,
    xb: DVec3,
    qb: DQuat,
    law: PolyhedralLaw,
    scratch: &mut ClipScratch,
) -> Option<Geometry> {
    if law == PolyhedralLaw::Vertex {
        let set = vertex_penetration(pa, xa, qa, pb, xb, qb, scratch);
        springs(set.points.iter().map(|p| (p.point, p.depth, p.normal)))
    } else {
        convex_convex(pa, xa, qa, pb, xb, qb, scratch).map(volume_geometry)
    }
}

/// A convex polyhedron and a sphere, normal from the sphere towards the polyhedron.
fn convex_sphere_geometry(
    p: &ConvexPolyhedron,
    x: DVec3,
    q: DQuat,
    centre: DVec3,
    radius: f64,
) -> Option<Geometry> {
    convex_sphere(p, x, q, centre, radius).map(|c| Geometry {
        normal: c.normal,
        point: c.point,
        overlap: c.depth,
        volume: None,
    })
}

/// A convex part of a body where the body is.
fn part_pose(part: &ConvexPart, x: DVec3, q: DQuat) -> (DVec3, DQuat) {
    (x + q * part.offset, (q * part.rotation).normalize())
}

/// How a body takes part in a contact that may have several regions.
enum Description<'a> {
    Sphere(f64),
    /// Convex pieces, each with its pose: one convex polyhedron, or the convex parts of a
    /// non-convex body (then also the body, which knows which parts touch).
    Pieces(
        Vec<(&'a ConvexPolyhedron, DVec3, DQuat)>,
        Option<&'a NonConvexPolyhedron>,
    ),
    Mesh(&'a NonConvexPolyhedron),
}

fn description<'a>(body: &Posed<'a>, prefer_parts: bool) -> Description<'a> {
    match body.shape {
        Shape::Sphere(s) => Description::Sphere(s.radius),
        Shape::Convex(p) => Description::Pieces(vec![(p, body.position, body.orientation)], None),
        Shape::NonConvex(p) if prefer_parts && !p.parts().is_empty() => Description::Pieces(
            p.parts()
                .iter()
                .map(|part| {
                    let (x, q) = part_pose(part, body.position, body.orientation);
                    (&part.shape, x, q)
                })
                .collect(),
            Some(p),
        ),
        Shape::NonConvex(p) => Description::Mesh(p),
    }
}

fn pose(body: &Posed) -> Pose {
    Pose {
        position: body.position,
        orientation: body.orientation,
    }
}

/// Every contact region of two bodies, normals pointing from `b` towards `a`, into `out`
/// (cleared first); at most `nonconvex::MAX_REGIONS`.
///
/// A non-convex body described by convex parts meets spheres, planes, convex bodies and other
/// bodies with parts part by part, each touching pair of pieces a region under `law`; otherwise
/// (a mesh without parts, or a pair in which one body has no convex description) the mesh
/// contact of the vertex law with its connected regions (`nonconvex`).
pub fn body_body_regions(
    a: Posed,
    b: Posed,
    law: PolyhedralLaw,
    scratch: &mut RegionScratch,
    out: &mut Vec<Geometry>,
) {
    out.clear();
    if !(a.shape.has_regions() || b.shape.has_regions()) {
        out.extend(body_body(a, b, law, &mut scratch.clip));
        return;
    }
    // Parts are used when the other body has a convex description too (or is a sphere).
    let convex_like = |s: &Shape| match s {
        Shape::NonConvex(p) => !p.parts().is_empty(),
        _ => true,
    };
    let parts = convex_like(a.shape) && convex_like(b.shape);
    match (description(&a, parts), description(&b, parts)) {
        (Description::Sphere(_), Description::Sphere(_)) => {
            out.extend(body_body(a, b, law, &mut scratch.clip));
        }
        (Description::Mesh(m), Description::Sphere(r)) => {
            mesh_sphere(m, pose(&a), b.position, r, scratch, out);
        }
        (Description::Sphere(r), Description::Mesh(m)) => {
            mesh_sphere(m, pose(&b), a.position, r, scratch, out);
            for g in out.iter_mut() {
                g.normal = -g.normal;
            }
        }
        (Description::Pieces(pieces, body), Description::Sphere(r)) => {
            let mut found = Vec::new();
            for (k, (p, x, q)) in pieces.into_iter().enumerate() {
                found.extend(convex_sphere_geometry(p, x, q, b.position, r).map(|g| (g, k, 0)));
            }
            merge_part_contacts(&mut found, body, None, Merge::Deepest, out);
        }
        (Description::Sphere(r), Description::Pieces(pieces, body)) => {
            let mut found = Vec::new();
            for (k, (p, x, q)) in pieces.into_iter().enumerate() {
                found.extend(convex_sphere_geometry(p, x, q, a.position, r).map(|g| {
                    let g = Geometry {
                        normal: -g.normal,
                        ..g
                    };
                    (g, 0, k)
                }));
            }
            merge_part_contacts(&mut found, None, body, Merge::Deepest, out);
        }
        (Description::Pieces(pa, body_a), Description::Pieces(pb, body_b)) => {
            let mut found = Vec::new();
            for (i, &(p, x, q)) in pa.iter().enumerate() {
                for (j, &(r, y, s)) in pb.iter().enumerate() {
                    found.extend(
                        convex_pair(p, x, q, r, y, s, law, &mut scratch.clip).map(|g| (g, i, j)),
                    );
                }
            }
            merge_part_contacts(&mut found, body_a, body_b, Merge::Sum, out);
        }
        (da, db) => {
            fn solid<'s>(d: Description<'s>, body: &Posed<'s>) -> Solid<'s> {
                match (d, body.shape) {
                    (Description::Mesh(m), _) => Solid::Mesh(m),
                    (_, Shape::Convex(p)) => Solid::Convex(p),
                    _ => unreachable!("a mesh meets only meshes and convex bodies here"),
                }
            }
            let (sa, sb) = (solid(da, &a), solid(db, &b));
            solid_solid(sa, pose(&a), sb, pose(&b), scratch, out);
        }
    }
    cap(out);
}

/// How the contacts of touching parts with one region of the other body combine.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Merge {
    /// Into one contact carrying all their springs (polyhedra): one dashpot for the region, as
    /// the body described by its mesh has, so that restitution and rocking match.
    Sum,
    /// Only the deepest (a sphere over the seam of two parts presses on one surface, not two).
    Deepest,
}

/// Contacts of touching parts, with normals within 5°, are one region of the body: combines
/// each such group of `found` (geometry, part of the first body, part of the second) into one
/// contact, appended to `out`. `None` for a body stands for a single piece.
fn merge_part_contacts(
    found: &mut [(Geometry, usize, usize)],
    body_a: Option<&NonConvexPolyhedron>,
    body_b: Option<&NonConvexPolyhedron>,
    how: Merge,
    out: &mut Vec<Geometry>,
) {
    let n = found.len();
    let near = |body: Option<&NonConvexPolyhedron>, i: usize, j: usize| {
        i == j || body.is_some_and(|b| b.parts_adjacent(i, j))
    };
    let cos_limit = 5f64.to_radians().cos();
    let mut group: Vec<usize> = (0..n).collect();
    for k in 0..n {
        for l in 0..k {
            let ((gk, ak, bk), (gl, al, bl)) = (found[k], found[l]);
            if near(body_a, ak, al) && near(body_b, bk, bl) && gk.normal.dot(gl.normal) >= cos_limit
            {
                // Join k's group into l's (groups are labelled by their first member).
                let (from, to) = (group[k].max(group[l]), group[k].min(group[l]));
                for g in group.iter_mut() {
                    if *g == from {
                        *g = to;
                    }
                }
            }
        }
    }
    for first in 0..n {
        let mut members = (0..n).filter(|&k| group[k] == first).map(|k| found[k].0);
        let Some(mut merged) = members.next() else {
            continue;
        };
        for g in members {
            merged = match how {
                Merge::Deepest if g.overlap > merged.overlap => g,
                Merge::Deepest => merged,
                Merge::Sum => sum_geometries(&merged, &g),
            };
        }
        out.push(merged);
    }
}

/// One contact carrying the springs (or the foundation) of two: their loads add as vectors and
/// their moments about the new contact point, the volume- (or depth-) weighted mean of the two.
fn sum_geometries(a: &Geometry, b: &Geometry) -> Geometry {
    let (Some(va), Some(vb)) = (a.volume, b.volume) else {
        return if a.overlap >= b.overlap { *a } else { *b };
    };
    let (la, lb) = (a.normal * va.load, b.normal * vb.load);
    let load = la + lb;
    let (wa, wb) = match va.law {
        PolyhedralLaw::Volume => (va.volume, vb.volume),
        PolyhedralLaw::Vertex => (a.overlap * va.points as f64, b.overlap * vb.points as f64),
    };
    let total = wa + wb;
    let point = if total > 0.0 {
        (a.point * wa + b.point * wb) / total
    } else {
        0.5 * (a.point + b.point)
    };
    let couple = va.couple + vb.couple + (a.point - point).cross(la) + (b.point - point).cross(lb);
    let area = va.area + vb.area;
    let points = va.points + vb.points;
    let overlap = match va.law {
        PolyhedralLaw::Volume if area > 0.0 => (va.volume + vb.volume) / area,
        _ if points > 0 => total / points as f64,
        _ => a.overlap.max(b.overlap),
    };
    Geometry {
        normal: load.try_normalize().unwrap_or(a.normal),
        point,
        overlap,
        volume: Some(OverlapVolume {
            law: va.law,
            points,
            volume: va.volume + vb.volume,
            area,
            load: load.length(),
            couple,
            potential: va.potential + vb.potential,
        }),
    }
}

/// Keeps at most `MAX_REGIONS` contacts, the deepest (part pairs can touch in more places than
/// there are slots; the mesh routines cap their own output).
fn cap(out: &mut Vec<Geometry>) {
    use super::nonconvex::MAX_REGIONS;
    if out.len() > MAX_REGIONS {
        out.sort_by(|x, y| y.overlap.total_cmp(&x.overlap));
        out.truncate(MAX_REGIONS);
    }
}

/// Every contact region of a body with the half-space behind a plane (`normal` into the free
/// side), into `out` (cleared first): for a non-convex body one per connected group of vertices
/// behind the plane (vertex law), or one per convex part behind it (under `law`).
pub fn body_plane_regions(
    a: Posed,
    point: DVec3,
    normal: DVec3,
    law: PolyhedralLaw,
    scratch: &mut RegionScratch,
    out: &mut Vec<Geometry>,
) {
    out.clear();
    match a.shape {
        Shape::NonConvex(p) if !p.parts().is_empty() => {
            let mut found = Vec::new();
            for (k, part) in p.parts().iter().enumerate() {
                let (x, q) = part_pose(part, a.position, a.orientation);
                found.extend(
                    convex_plane_geometry(&part.shape, x, q, point, normal, law).map(|g| (g, k, 0)),
                );
            }
            merge_part_contacts(&mut found, Some(p), None, Merge::Sum, out);
            cap(out);
        }
        Shape::NonConvex(p) => mesh_plane(p, pose(&a), point, normal, scratch, out),
        _ => out.extend(body_plane(a, point, normal, law)),
    }
}

/// The contact of a body with the half-space behind a plane (`normal` into the free side). A
/// non-convex body gives its deepest region; [`body_plane_regions`] gives them all.
pub fn body_plane(a: Posed, point: DVec3, normal: DVec3, law: PolyhedralLaw) -> Option<Geometry> {
    match a.shape {
        Shape::Sphere(s) => sphere_plane(a.position, s.radius, point, normal),
        Shape::Convex(p) => convex_plane_geometry(p, a.position, a.orientation, point, normal, law),
        Shape::NonConvex(_) => {
            let mut out = Vec::new();
            body_plane_regions(a, point, normal, law, &mut RegionScratch::new(), &mut out);
            out.into_iter()
                .max_by(|x, y| x.overlap.total_cmp(&y.overlap))
        }
    }
}

fn convex_plane_geometry(
    p: &ConvexPolyhedron,
    x: DVec3,
    q: DQuat,
    point: DVec3,
    normal: DVec3,
    law: PolyhedralLaw,
) -> Option<Geometry> {
    if law == PolyhedralLaw::Vertex {
        springs(vertices_behind(p, x, q, point, normal))
    } else {
        convex_plane(p, x, q, point, normal).map(volume_geometry)
    }
}

/// The vertices of a polyhedron behind a plane, with their depths and the plane's normal.
fn vertices_behind(
    p: &ConvexPolyhedron,
    position: DVec3,
    orientation: DQuat,
    point: DVec3,
    normal: DVec3,
) -> impl Iterator<Item = (DVec3, f64, DVec3)> + '_ {
    p.vertices().iter().filter_map(move |&v| {
        let x = position + orientation * v;
        let depth = -(x - point).dot(normal);
        (depth > 0.0).then_some((x, depth, normal))
    })
}

/// One contact for the vertex law's springs (point, depth, direction of the force on the first
/// body): their resultant Σ dᵢ nᵢ and its moment about the depth-weighted mean point, which is
/// where the contact acts. `None` without a penetrating point.
pub(crate) fn springs(points: impl Iterator<Item = (DVec3, f64, DVec3)>) -> Option<Geometry> {
    let (mut load, mut weighted, mut total, mut potential, mut count) =
        (DVec3::ZERO, DVec3::ZERO, 0.0, 0.0, 0usize);
    let mut first_moment = DVec3::ZERO;
    for (x, depth, n) in points {
        if depth <= 0.0 {
            continue;
        }
        load += depth * n;
        weighted += depth * x;
        first_moment += x.cross(depth * n);
        total += depth;
        potential += 0.5 * depth * depth;
        count += 1;
    }
    let normal = load.try_normalize()?;
    let centre = weighted / total;
    Some(Geometry {
        normal,
        point: centre,
        overlap: total / count as f64,
        volume: Some(OverlapVolume {
            law: PolyhedralLaw::Vertex,
            points: count,
            volume: 0.0,
            area: 0.0,
            load: load.length(),
            // Σ (xᵢ − c) × dᵢnᵢ = Σ xᵢ × dᵢnᵢ − c × Σ dᵢnᵢ.
            couple: first_moment - centre.cross(load),
            potential,
        }),
    })
}

/// R* for the contact law: the harmonic mean of the radii for two spheres or two polyhedra
/// (volume-equivalent radii), the sphere's radius for a sphere on a polyhedron's face (a flat
/// face has no curvature of its own).
pub fn effective_radius(a: &Shape, b: &Shape) -> f64 {
    match (a, b) {
        (Shape::Sphere(s), Shape::Convex(_) | Shape::NonConvex(_))
        | (Shape::Convex(_) | Shape::NonConvex(_), Shape::Sphere(s)) => s.radius,
        _ => {
            let (ra, rb) = (a.equivalent_radius(), b.equivalent_radius());
            ra * rb / (ra + rb)
        }
    }
}

/// The contact of a volume overlap. Its normal is the direction of the elastic-foundation force
/// (the gradient of the law's energy); for an overlap under one face of a body it is that face's
/// normal, as is the vector area's, and where the overlap meets several faces (crossing edges,
/// corners) it is the direction that conserves energy.
pub(super) fn volume_geometry(c: VolumeContact) -> Geometry {
    Geometry {
        normal: c.load.try_normalize().unwrap_or(c.normal),
        point: c.centroid,
        overlap: c.depth,
        volume: Some(OverlapVolume {
            law: PolyhedralLaw::Volume,
            points: 0,
            volume: c.volume,
            area: c.area,
            load: c.load.length(),
            couple: c.couple,
            potential: c.potential,
        }),
    }
}
