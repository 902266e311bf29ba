//! Cheap rejection before the detailed contact geometry: bounding spheres, then separating axes.
//!
//! Every test here answers "certainly separated (or only touching)" or "maybe overlapping"; a
//! `false` is never wrong, only less informative. Touching counts as separated: a contact of zero
//! overlap carries no force.
//!
//! Axes tried by `separated_by_face_planes`: the face normals of both bodies (for each face plane,
//! are all vertices of the other body on or in front of it?). For two convex polyhedra the full
//! separating-axis theorem also needs the cross products of edge pairs; `separated_by_edge_axes`
//! does those, at a cost of (edges A × edges B × vertices), worth it only for small shapes. The
//! volume clipping of `convex_convex` does not need it for correctness: two bodies separated
//! only along an edge-edge axis simply give an empty intersection.

use super::clip::Plane;
use crate::math::DVec3;

/// Two bounding spheres that do not overlap (touching counts as separated).
#[inline]
pub fn bounding_spheres_separated(xa: DVec3, ra: f64, xb: DVec3, rb: f64) -> bool {
    let reach = ra + rb;
    (xa - xb).length_squared() >= reach * reach
}

/// Whether every one of `vertices` lies on or in front of `plane`, to within `tolerance`: the
/// plane separates the body of those vertices from the body it belongs to.
#[inline]
pub fn plane_separates(plane: &Plane, vertices: &[DVec3], tolerance: f64) -> bool {
    vertices.iter().all(|&v| plane.distance(v) >= -tolerance)
}

/// A face plane of either body with all vertices of the other body on or in front of it
/// (vertices and outward planes in one frame). Touching to within `tolerance` counts as separated.
pub fn separated_by_face_planes(
    a_vertices: &[DVec3],
    a_planes: &[Plane],
    b_vertices: &[DVec3],
    b_planes: &[Plane],
    tolerance: f64,
) -> bool {
    a_planes
        .iter()
        .any(|p| plane_separates(p, b_vertices, tolerance))
        || b_planes
            .iter()
            .any(|p| plane_separates(p, a_vertices, tolerance))
}

/// The edge-edge axes of the separating-axis theorem: for each pair of edge directions
/// (`a_edges`, `b_edges` as vertex index pairs), the projections of the two vertex sets on their
/// cross product are disjoint (or only touch, to within `tolerance` in length units).
pub fn separated_by_edge_axes(
    a_vertices: &[DVec3],
    a_edges: &[[usize; 2]],
    b_vertices: &[DVec3],
    b_edges: &[[usize; 2]],
    tolerance: f64,
) -> bool {
    let project = |vertices: &[DVec3], axis: DVec3| {
        vertices
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                let s = axis.dot(v);
                (lo.min(s), hi.max(s))
            })
    };
    for ea in a_edges {
        let da = a_vertices[ea[1]] - a_vertices[ea[0]];
        for eb in b_edges {
            let db = b_vertices[eb[1]] - b_vertices[eb[0]];
            // Parallel edges give no new axis (their planes are face axes or combinations).
            let c = da.cross(db);
            if c.length_squared() <= 1e-20 * da.length_squared() * db.length_squared() {
                continue;
            }
            let axis = c.normalize();
            let (alo, ahi) = project(a_vertices, axis);
            let (blo, bhi) = project(b_vertices, axis);
            if ahi <= blo + tolerance || bhi <= alo + tolerance {
                return true;
            }
        }
    }
    false
}

/// A convex body (its vertices) entirely on or in front of the plane through `point` with unit
/// `normal`: nothing of it is behind the plane.
pub fn separated_from_half_space(vertices: &[DVec3], point: DVec3, normal: DVec3) -> bool {
    let plane = Plane {
        normal,
        offset: normal.dot(point),
    };
    plane_separates(&plane, vertices, 0.0)
}

/// A sphere that lies on or in front of one of a convex body's outward face planes cannot overlap
/// it (the converse does not hold near edges and vertices).
pub fn sphere_separated_by_face_planes(planes: &[Plane], centre: DVec3, radius: f64) -> bool {
    planes.iter().any(|p| p.distance(centre) >= radius)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_cube(shift: DVec3) -> (Vec<DVec3>, Vec<Plane>, Vec<[usize; 2]>) {
        let vertices: Vec<DVec3> = (0..8)
            .map(|k| {
                let s = |bit: u32| if k >> bit & 1 == 0 { -0.5 } else { 0.5 };
                DVec3::new(s(0), s(1), s(2)) + shift
            })
            .collect();
        let planes = [
            DVec3::X,
            -DVec3::X,
            DVec3::Y,
            -DVec3::Y,
            DVec3::Z,
            -DVec3::Z,
        ]
        .map(|n| Plane {
            normal: n,
            offset: 0.5 + n.dot(shift),
        })
        .to_vec();
        let mut edges = Vec::new();
        for i in 0..8usize {
            for bit in 0..3 {
                let j = i | 1 << bit;
                if j != i {
                    edges.push([i, j]);
                }
            }
        }
        (vertices, planes, edges)
    }

    #[test]
    fn spheres() {
        assert!(bounding_spheres_separated(
            DVec3::ZERO,
            1.0,
            DVec3::X * 2.0,
            1.0
        ));
        assert!(!bounding_spheres_separated(
            DVec3::ZERO,
            1.0,
            DVec3::X * 1.9,
            1.0
        ));
    }

    #[test]
    fn cubes_by_faces() {
        let (va, pa, _) = unit_cube(DVec3::ZERO);
        let (vb, pb, _) = unit_cube(DVec3::new(1.0, 0.3, 0.0));
        assert!(
            separated_by_face_planes(&va, &pa, &vb, &pb, 0.0),
            "touching"
        );
        let (vb, pb, _) = unit_cube(DVec3::new(0.9, 0.3, 0.0));
        assert!(!separated_by_face_planes(&va, &pa, &vb, &pb, 0.0));
    }

    #[test]
    fn edge_axes_find_what_faces_miss() {
        // Two cubes turned 45° about z and about x, ridges crossing at a distance: only the
        // axis along y (= z × x, the cross product of the two ridge edges) separates them.
        let qa = crate::math::DQuat::from_rotation_z(std::f64::consts::FRAC_PI_4);
        let qb = crate::math::DQuat::from_rotation_x(std::f64::consts::FRAC_PI_4);
        let (va, _, ea) = unit_cube(DVec3::ZERO);
        let (vb, _, eb) = unit_cube(DVec3::ZERO);
        let h = 0.5f64.sqrt();
        let pose = |v: &[DVec3], q, t| v.iter().map(|&p| q * p + t).collect::<Vec<_>>();
        let planes = |q: crate::math::DQuat, t: DVec3| {
            [
                DVec3::X,
                -DVec3::X,
                DVec3::Y,
                -DVec3::Y,
                DVec3::Z,
                -DVec3::Z,
            ]
            .map(|n| {
                let n = q * n;
                Plane {
                    normal: n,
                    offset: 0.5 + n.dot(t),
                }
            })
            .to_vec()
        };
        let wa = pose(&va, qa, DVec3::ZERO);
        let pa = planes(qa, DVec3::ZERO);
        for (gap, separated) in [(0.01, true), (-0.01, false)] {
            let t = DVec3::new(0.0, 2.0 * h + gap, 0.0);
            let wb = pose(&vb, qb, t);
            let pb = planes(qb, t);
            assert!(!separated_by_face_planes(&wa, &pa, &wb, &pb, 0.0));
            assert_eq!(separated_by_edge_axes(&wa, &ea, &wb, &eb, 0.0), separated);
        }
    }

    #[test]
    fn half_space_and_sphere() {
        let (va, pa, _) = unit_cube(DVec3::ZERO);
        assert!(separated_from_half_space(
            &va,
            DVec3::new(0.0, 0.0, -0.5),
            DVec3::Z
        ));
        assert!(!separated_from_half_space(
            &va,
            DVec3::new(0.0, 0.0, -0.4),
            DVec3::Z
        ));
        assert!(sphere_separated_by_face_planes(
            &pa,
            DVec3::new(0.0, 0.0, 1.0),
            0.5
        ));
        assert!(!sphere_separated_by_face_planes(
            &pa,
            DVec3::new(0.0, 0.0, 0.9),
            0.5
        ));
    }
}
