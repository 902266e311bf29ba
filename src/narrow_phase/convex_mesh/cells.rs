//! The cell of a mesh-wall triangle: the region of space that the triangle answers for, bounded
//! by its face plane and one plane through each edge (see the parent module).

use super::super::clip::Plane;
use super::FOLD_ANGLE;
use crate::math::DVec3;
use crate::wall::MeshWall;

/// The plane of triangle `t`, relative to `origin` (from its first corner, so every caller gets
/// the same numbers).
pub(super) fn face_plane(wall: &MeshWall, t: u32, origin: DVec3) -> Plane {
    let normal = wall.normals()[t as usize];
    let corner = wall.vertices()[wall.triangles()[t as usize][0] as usize] - origin;
    Plane {
        normal,
        offset: normal.dot(corner),
    }
}

/// Whether a triangle acts on the body: its centre (the origin of `face`'s frame) is in front.
pub(super) fn is_active(face: &Plane) -> bool {
    face.offset < 0.0
}

/// The planes through the edges of triangle `t`'s cell (relative to `origin`), normals out of
/// the cell. Across an edge shared with one other triangle: the bisector of the two faces
/// (perpendicular to both when they are coplanar), except where the other face folds away
/// convexly and does not act on the body (its centre behind it): then the other face's plane, so
/// that the cell holds what is behind both faces and nothing in front of the other. Across a rim
/// (one triangle) or a non-manifold edge: the plane perpendicular to the face. Both triangles of
/// an edge get the same bisector, oppositely oriented, bit for bit.
pub(super) fn edge_planes(wall: &MeshWall, t: u32, origin: DVec3) -> [Plane; 3] {
    let vertices = wall.vertices();
    let triangles = wall.triangles();
    let normals = wall.normals();
    let tri = triangles[t as usize];
    let n = normals[t as usize];
    let fold_cos = FOLD_ANGLE.cos();
    // Out of triangle `s` across its edge from corner i to corner j (its winding order).
    let outward = |s: u32, i: u32, j: u32| {
        (vertices[j as usize] - vertices[i as usize])
            .normalize()
            .cross(normals[s as usize])
    };
    std::array::from_fn(|k| {
        let (i, j) = (tri[k], tri[(k + 1) % 3]);
        let own = outward(t, i, j);
        let mut normal = own;
        if let &[a, b] = wall.triangles_of_edge(wall.triangle_edges()[t as usize][k]) {
            let s = if a == t { b } else { a };
            let st = triangles[s as usize];
            let m = (0..3)
                .find(|&m| {
                    let (p, q) = (st[m], st[(m + 1) % 3]);
                    (p == i && q == j) || (p == j && q == i)
                })
                .expect("the edge's other triangle has the edge");
            let far = st[(m + 2) % 3];
            let other_face = face_plane(wall, s, origin);
            if !is_active(&other_face)
                && n.dot(normals[s as usize]) < fold_cos
                && n.dot(vertices[far as usize] - vertices[i as usize]) < 0.0
            {
                return other_face;
            }
            let other = outward(s, st[m], st[(m + 1) % 3]);
            // −other points into the neighbour; own − other is normal to the bisector. Zero
            // only when the two faces fold onto each other (a fin of no thickness).
            let d = own - other;
            if d.length_squared() > 1e-12 {
                normal = d.normalize();
            }
        }
        let anchor = vertices[i.min(j) as usize] - origin;
        Plane {
            normal,
            offset: normal.dot(anchor),
        }
    })
}
