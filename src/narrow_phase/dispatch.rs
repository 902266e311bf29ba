//! Which contact routine a pair of bodies needs, by the kinds of their shapes.

use super::{
    convex_convex, convex_plane, convex_sphere, sphere_plane, sphere_sphere, vertex_penetration,
    ClipScratch, Geometry, VolumeContact,
};
use crate::contact_law::{OverlapVolume, PolyhedralLaw};
use crate::math::{DQuat, DVec3};
use crate::shape::ConvexPolyhedron;
use crate::shape::Shape;

/// Where a body is: its shape, centre of mass and orientation (body → world).
#[derive(Clone, Copy)]
pub struct Posed<'a> {
    pub shape: &'a Shape,
    pub position: DVec3,
    pub orientation: DQuat,
}

/// The contact of two bodies, normal pointing from `b` towards `a`; `None` if they do not touch.
pub fn body_body(
    a: Posed,
    b: Posed,
    law: PolyhedralLaw,
    scratch: &mut ClipScratch,
) -> Option<Geometry> {
    match (a.shape, b.shape) {
        (Shape::Convex(pa), Shape::Convex(pb)) if law == PolyhedralLaw::Vertex => {
            let set = vertex_penetration(
                pa,
                a.position,
                a.orientation,
                pb,
                b.position,
                b.orientation,
                scratch,
            );
            springs(set.points.iter().map(|p| (p.point, p.depth, p.normal)))
        }
        (Shape::Sphere(sa), Shape::Sphere(sb)) => {
            sphere_sphere(a.position, sa.radius, b.position, sb.radius)
        }
        (Shape::Convex(pa), Shape::Convex(pb)) => convex_convex(
            pa,
            a.position,
            a.orientation,
            pb,
            b.position,
            b.orientation,
            scratch,
        )
        .map(volume_geometry),
        (Shape::Convex(pa), Shape::Sphere(sb)) => {
            convex_sphere(pa, a.position, a.orientation, b.position, sb.radius).map(|c| {
                // The routine's normal points from the sphere (b) towards the polyhedron (a).
                Geometry {
                    normal: c.normal,
                    point: c.point,
                    overlap: c.depth,
                    volume: None,
                }
            })
        }
        (Shape::Sphere(sa), Shape::Convex(pb)) => {
            convex_sphere(pb, b.position, b.orientation, a.position, sa.radius).map(|c| Geometry {
                normal: -c.normal,
                point: c.point,
                overlap: c.depth,
                volume: None,
            })
        }
    }
}

/// The contact of a body with the half-space behind a plane (`normal` into the free side).
pub fn body_plane(a: Posed, point: DVec3, normal: DVec3, law: PolyhedralLaw) -> Option<Geometry> {
    match a.shape {
        Shape::Sphere(s) => sphere_plane(a.position, s.radius, point, normal),
        Shape::Convex(p) if law == PolyhedralLaw::Vertex => {
            springs(vertices_behind(p, a, point, normal))
        }
        Shape::Convex(p) => {
            convex_plane(p, a.position, a.orientation, point, normal).map(volume_geometry)
        }
    }
}

/// The vertices of a polyhedron behind a plane, with their depths and the plane's normal.
fn vertices_behind<'a>(
    p: &'a ConvexPolyhedron,
    a: Posed<'a>,
    point: DVec3,
    normal: DVec3,
) -> impl Iterator<Item = (DVec3, f64, DVec3)> + 'a {
    p.vertices().iter().filter_map(move |&v| {
        let x = a.position + a.orientation * v;
        let depth = -(x - point).dot(normal);
        (depth > 0.0).then_some((x, depth, normal))
    })
}

/// One contact for the vertex law's springs (point, depth, direction of the force on the first
/// body): their resultant Σ dᵢ nᵢ and its moment about the depth-weighted mean point, which is
/// where the contact acts. `None` without a penetrating point.
pub(super) fn springs(points: impl Iterator<Item = (DVec3, f64, DVec3)>) -> Option<Geometry> {
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
        (Shape::Sphere(s), Shape::Convex(_)) | (Shape::Convex(_), Shape::Sphere(s)) => s.radius,
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
