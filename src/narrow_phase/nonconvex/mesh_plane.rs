//! A mesh body against a plane, or against the faces of one region of a mesh wall: its vertices
//! behind, joined into regions by the body's edges between them.

use super::super::clip::Plane;
use super::super::Geometry;
use super::regions::{regions_of_points, Point, RegionScratch};
use super::Pose;
use crate::math::{Aabb, DMat3, DVec3};
use crate::shape::NonConvexPolyhedron;

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

#[cfg(test)]
mod tests {
    use super::super::test_bodies::mesh;
    use super::*;
    use crate::math::DQuat;
    use crate::shape::nonconvex_generators::jack;

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
}
