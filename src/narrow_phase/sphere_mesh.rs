//! A sphere against a triangle-mesh wall, independent of how the wall is triangulated.
//!
//! # The rule
//!
//! The contacts are the **local minima of the distance from the sphere's centre to the mesh
//! surface** that lie closer than the radius — one contact per minimum, however many triangles
//! meet there (the closest-feature approach of Hu et al. 2013, "Contact detection between
//! spheres and triangle meshes"; also Kremmer & Favier 2001 and the edge/corner-active flags of
//! LIGGGHTS' mesh walls serve the same end):
//!
//! 1. Every triangle near the sphere gives its closest point to the centre and the feature it
//!    lies on: the open face, one of its edges or one of its corners (Ericson 2005, §5.1.5).
//!    Those farther than the radius are dropped.
//! 2. A closest point is a local minimum of the distance over the surface when no triangle
//!    containing it (the face's own triangle, the edge's triangles, the vertex's triangles) has
//!    a closer point: otherwise the distance falls moving from it into that triangle, and it is
//!    dropped. On a flat region of any triangulation this keeps only the foot of the
//!    perpendicular; at a convex edge or corner, only the point on the edge or corner.
//! 3. Candidates are taken nearest first; one whose feature shares a triangle with a contact
//!    already taken is the same minimum reached through another triangle (a vertex shared by
//!    six triangles is found six times; a foot exactly on an edge by both triangles) and is
//!    merged into it, as is one whose closest point is within a rounding tolerance of a contact
//!    already taken (a foot a few ulps off a vertex lands in different features of the
//!    triangles around it). Distinct minima touch disjoint sets of triangles: a sphere in a concave
//!    corner gets one contact per wall it presses on.
//!
//! 4. Two face contacts whose normals differ by less than the mesh's `smooth_angle()` are facets
//!    of one smooth surface (a faceted drum, a coarse helicoid): only the deeper is kept, so a
//!    sphere rolling over a shallow concave fold sees the larger of the two overlaps, continuous,
//!    not their sum. The rule depends only on the pair of faces, never on where the sphere is,
//!    so it switches no force on or off. Faces at a sharper angle are separate walls.
//!
//! The contact of a face has the face's normal and overlap r − s for the signed height s of the
//! centre over the face (as for a plane, the centre may be behind the face down to −r). The
//! contact of an edge or vertex points from the closest point to the centre, with overlap r − d;
//! if the centre is behind the surface there (by the angle-weighted pseudo-normal, Bærentzen &
//! Aanæs 2005) the normal is reversed and the overlap is r + d, which continues the faces'
//! contacts. On the rim of an open mesh (an edge with one triangle, or a vertex on one) there is
//! no behind: the rim is a thin edge pushing away from itself.
//!
//! The contact point is the middle of the overlap, as for `sphere_plane`.

use super::Geometry;
pub use crate::geometry::triangle::{closest_point_on_triangle, TriangleRegion};
use crate::geometry::triangle_mesh::{Feature, TriangleMesh};
use crate::math::{Aabb, DVec3};

/// One contact of a sphere with a mesh wall and the feature of the wall it touches (a stable key
/// for the contact's history while the sphere stays on that feature).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshContact {
    pub geometry: Geometry,
    pub feature: Feature,
    /// The triangle through which the contact was found (one of the feature's triangles).
    pub triangle: u32,
}

/// Reusable buffers for [`sphere_mesh_contacts`].
#[derive(Clone, Debug, Default)]
pub struct MeshScratch {
    near: Vec<u32>,
    /// Distance from the centre to each triangle in `near` (infinite if beyond the radius).
    distance: Vec<f64>,
    candidates: Vec<Candidate>,
    /// Closest points of the contacts taken, parallel to the output.
    taken: Vec<DVec3>,
}

#[derive(Clone, Copy, Debug)]
struct Candidate {
    point: DVec3,
    distance: f64,
    feature: Feature,
    triangle: u32,
}

/// True when `x` is on the far side of the wall from where bodies live: behind the surface at
/// the point of the wall nearest to it (by the face normal or the edge's or vertex's
/// pseudo-normal, Bærentzen & Aanæs 2005). Inside a closed wall's solid (a screw's shaft, the
/// outside of a closed box facing inward) this is true however far from the surface. A point
/// nearest to the rim of an open wall is never behind it.
pub fn is_behind_mesh(x: DVec3, mesh: &TriangleMesh) -> bool {
    let bounds = mesh.bounds();
    let mut half = (bounds.extent().max_element() * 1e-3).max(f64::MIN_POSITIVE);
    let mut near = Vec::new();
    loop {
        // Distance from x to the box of the wall, so the first query reaches some triangle.
        let outside = (bounds.min - x)
            .max(x - bounds.max)
            .max(DVec3::ZERO)
            .length();
        mesh.triangles_near(&Aabb::around_sphere(x, half.max(outside)), &mut near);
        let best = near
            .iter()
            .map(|&t| {
                let [a, b, c] = mesh.corners(t);
                let (q, region) = closest_point_on_triangle(x, a, b, c);
                (t, q, region, (x - q).length())
            })
            .min_by(|p, q| p.3.total_cmp(&q.3));
        match best {
            // Every triangle outside the query box is farther than its half-size.
            Some((t, q, region, d)) if d <= half.max(outside) => {
                let tri = mesh.triangles()[t as usize];
                let feature = match region {
                    TriangleRegion::Face => Feature::Face(t),
                    TriangleRegion::Edge(k) => Feature::Edge(mesh.triangle_edges()[t as usize][k]),
                    TriangleRegion::Vertex(k) => Feature::Vertex(tri[k]),
                };
                if mesh.is_boundary(&feature) {
                    return false;
                }
                return (x - q).dot(mesh.feature_normal(&feature)) < 0.0;
            }
            Some((_, _, _, d)) => half = d,
            None => half = 2.0 * half.max(outside),
        }
    }
}

/// The contacts of a sphere (centre `x`, radius `r`) with a mesh wall, normals pointing from the
/// wall towards the sphere; empty if it touches nothing. See the module's rule.
pub fn sphere_mesh(x: DVec3, r: f64, mesh: &TriangleMesh) -> Vec<Geometry> {
    let mut out = Vec::new();
    sphere_mesh_contacts(x, r, mesh, &mut MeshScratch::default(), &mut out);
    out.into_iter().map(|c| c.geometry).collect()
}

/// As [`sphere_mesh`], with the touched features, into `out` (cleared first), nearest first.
pub fn sphere_mesh_contacts(
    x: DVec3,
    r: f64,
    mesh: &TriangleMesh,
    scratch: &mut MeshScratch,
    out: &mut Vec<MeshContact>,
) {
    let mut near = std::mem::take(&mut scratch.near);
    mesh.triangles_near(&Aabb::around_sphere(x, r), &mut near);
    sphere_mesh_contacts_among(x, r, mesh, &near, scratch, out);
    scratch.near = near;
}

/// Appends to `out` (cleared first), in increasing order, the triangles of `mesh` within `reach`
/// of `x` (their closest point to it, with a rounding margin): every triangle a sphere of radius
/// `r` can touch while its centre stays within `reach − r` of `x`, since the distance to a
/// triangle changes no faster than the point moves. A list for [`sphere_mesh_contacts_among`]
/// made once for a neighbour list's life: shorter than the triangles whose boxes come that near
/// (on a floor of squares cut in two, both halves' boxes are the whole square).
pub fn triangles_within(x: DVec3, reach: f64, mesh: &TriangleMesh, out: &mut Vec<u32>) {
    mesh.triangles_near(&Aabb::around_sphere(x, reach), out);
    // The computed distance is within a few ulps of the coordinates of the true one; a margin
    // well above that keeps every triangle the true distance would.
    let margin = 1e-9 * reach + 64.0 * f64::EPSILON * (x.abs().max_element() + reach);
    out.retain(|&t| {
        let [a, b, c] = mesh.corners(t);
        let (q, _) = closest_point_on_triangle(x, a, b, c);
        (x - q).length() < reach + margin
    });
}

/// As [`sphere_mesh_contacts`], given `near`: an increasing list of triangles that holds every
/// triangle whose box overlaps the sphere's (more do no harm: a triangle whose box is apart from
/// the sphere's is farther than the radius, and counts as it would not listed). A list made
/// once for a neighbour list's life, with a box enlarged by the skin, spares the mesh's grid a
/// query at every step; the contacts are the same to the bit.
pub fn sphere_mesh_contacts_among(
    x: DVec3,
    r: f64,
    mesh: &TriangleMesh,
    near: &[u32],
    scratch: &mut MeshScratch,
    out: &mut Vec<MeshContact>,
) {
    out.clear();
    debug_assert!(near.windows(2).all(|w| w[0] < w[1]));
    let MeshScratch {
        near: _,
        distance,
        candidates,
        taken,
    } = scratch;
    candidates.clear();
    distance.clear();
    let triangles = mesh.triangles();
    let edges = mesh.triangle_edges();
    for &t in near.iter() {
        let [a, b, c] = mesh.corners(t);
        let (q, region) = closest_point_on_triangle(x, a, b, c);
        let d = (x - q).length();
        if d >= r {
            distance.push(f64::INFINITY);
            continue;
        }
        distance.push(d);
        let tri = triangles[t as usize];
        let feature = match region {
            TriangleRegion::Face => Feature::Face(t),
            TriangleRegion::Edge(k) => Feature::Edge(edges[t as usize][k]),
            TriangleRegion::Vertex(k) => Feature::Vertex(tri[k]),
        };
        candidates.push(Candidate {
            point: q,
            distance: d,
            feature,
            triangle: t,
        });
    }
    // Nearest first; ties by feature and triangle so the result does not depend on the grid.
    candidates.sort_unstable_by(|p, q| {
        p.distance
            .total_cmp(&q.distance)
            .then(p.feature.cmp(&q.feature))
            .then(p.triangle.cmp(&q.triangle))
    });
    // Rounding in the distances: a few ulps of the coordinates, and a hair of the radius.
    let tolerance = 1e-12 * r + 64.0 * f64::EPSILON * (x.abs().max_element() + r);
    // Candidates that pass step 2 within the tolerance lie within 2 √(2 r tol) of each other
    // (the squared distance is strongly convex over a triangle); rounding can put the copies of
    // one minimum on features without a common triangle (a foot a few ulps off a vertex), so
    // points this close are the same minimum too.
    let same_point = 3.0 * (2.0 * r * tolerance).sqrt();
    taken.clear();
    let smooth_cos = mesh.smooth_cos();
    let distance_to = |t: u32| match near.binary_search(&t) {
        Ok(i) => distance[i],
        // Not near the sphere's box: farther than the radius, so farther than any candidate.
        Err(_) => f64::INFINITY,
    };
    for cand in candidates.iter() {
        let touching = mesh.triangles_of_feature(&cand.feature);
        // 2. A local minimum: no triangle through the point is closer.
        if touching
            .iter()
            .any(|&t| distance_to(t) < cand.distance - tolerance)
        {
            continue;
        }
        // 3. The same minimum as a contact already taken.
        if out.iter().zip(taken.iter()).any(|(contact, point)| {
            (*point - cand.point).length() <= same_point
                || shares_an_element(mesh.triangles_of_feature(&contact.feature), touching)
        }) {
            continue;
        }
        let Some(geometry) = contact_geometry(x, r, mesh, cand) else {
            continue;
        };
        let contact = MeshContact {
            geometry,
            feature: cand.feature,
            triangle: cand.triangle,
        };
        // 4. Facets of one smooth surface: the deepest only.
        if let Feature::Face(t) = cand.feature {
            let n = mesh.normals()[t as usize];
            if let Some(i) = out.iter().position(|c| match c.feature {
                Feature::Face(s) => mesh.normals()[s as usize].dot(n) >= smooth_cos,
                _ => false,
            }) {
                if geometry.overlap > out[i].geometry.overlap {
                    out[i] = contact;
                    taken[i] = cand.point;
                }
                continue;
            }
        }
        taken.push(cand.point);
        out.push(contact);
    }
}

/// Whether two increasing lists have an element in common.
fn shares_an_element(a: &[u32], b: &[u32]) -> bool {
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        match a[i].cmp(&b[j]) {
            std::cmp::Ordering::Less => i += 1,
            std::cmp::Ordering::Greater => j += 1,
            std::cmp::Ordering::Equal => return true,
        }
    }
    false
}

fn contact_geometry(x: DVec3, r: f64, mesh: &TriangleMesh, c: &Candidate) -> Option<Geometry> {
    let (normal, overlap) = match c.feature {
        Feature::Face(t) => {
            let n = mesh.normals()[t as usize];
            (n, r - (x - c.point).dot(n))
        }
        feature => {
            let pseudo = mesh.feature_normal(&feature);
            match (x - c.point).try_normalize() {
                None => (pseudo, r),
                Some(dir) if mesh.is_boundary(&feature) || dir.dot(pseudo) >= 0.0 => {
                    (dir, r - c.distance)
                }
                Some(dir) => (-dir, r + c.distance),
            }
        }
    };
    // Entirely behind the surface (overlap ≥ 2r) is outside the domain, as for a plane.
    if !(overlap > 0.0 && overlap < 2.0 * r) {
        return None;
    }
    Some(Geometry {
        normal,
        point: x - normal * (r - 0.5 * overlap),
        overlap,
        volume: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::narrow_phase::sphere_plane;
    use crate::rng::SplitMix64 as Rng;
    use crate::wall::generators::{box_mesh, rectangle};
    use crate::wall::{Facing, MeshWall};

    /// A flat square [-1, 1]² at z = 0 facing +z, of 2 n² triangles.
    fn floor(n: usize) -> MeshWall {
        rectangle(
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::X * 2.0,
            DVec3::Y * 2.0,
            n,
            n,
        )
        .unwrap()
        .into_wall(0)
        .unwrap()
    }

    fn same(a: &Geometry, b: &Geometry, tol: f64) -> bool {
        (a.normal - b.normal).length() < tol
            && (a.point - b.point).length() < tol
            && (a.overlap - b.overlap).abs() < tol
    }

    #[test]
    fn closest_point_regions() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let cases = [
            (
                DVec3::new(0.2, 0.2, 1.0),
                DVec3::new(0.2, 0.2, 0.0),
                TriangleRegion::Face,
            ),
            (DVec3::new(-1.0, -1.0, 1.0), a, TriangleRegion::Vertex(0)),
            (DVec3::new(2.0, -0.5, 0.0), b, TriangleRegion::Vertex(1)),
            (DVec3::new(-0.1, 3.0, 0.0), c, TriangleRegion::Vertex(2)),
            (
                DVec3::new(0.5, -1.0, 0.0),
                DVec3::new(0.5, 0.0, 0.0),
                TriangleRegion::Edge(0),
            ),
            (
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(0.5, 0.5, 0.0),
                TriangleRegion::Edge(1),
            ),
            (
                DVec3::new(-1.0, 0.5, 0.0),
                DVec3::new(0.0, 0.5, 0.0),
                TriangleRegion::Edge(2),
            ),
        ];
        for (p, q, region) in cases {
            let (got, got_region) = closest_point_on_triangle(p, a, b, c);
            assert!((got - q).length() < 1e-15, "{p}: {got}");
            assert_eq!(got_region, region, "{p}");
        }
    }

    #[test]
    fn flat_wall_of_2_or_200_triangles_gives_the_same_contact() {
        let (coarse, fine) = (floor(1), floor(10));
        assert_eq!(coarse.triangles().len(), 2);
        assert_eq!(fine.triangles().len(), 200);
        let r = 0.25;
        // Inside faces, exactly on fine edges, exactly over fine vertices, on the coarse diagonal,
        // and with the centre slightly behind the wall.
        let centres = [
            DVec3::new(0.37, -0.41, 0.2),
            DVec3::new(0.2, 0.33, 0.24),
            DVec3::new(0.4, 0.6, 0.1),
            DVec3::new(0.3, 0.3, 0.01),
            DVec3::new(-0.55, 0.123, -0.05),
            DVec3::new(0.0, 0.0, 0.2499),
        ];
        for x in centres {
            let a = sphere_mesh(x, r, &coarse);
            let b = sphere_mesh(x, r, &fine);
            let plane = sphere_plane(x, r, DVec3::ZERO, DVec3::Z).unwrap();
            assert_eq!(a.len(), 1, "{x}: {a:?}");
            assert_eq!(b.len(), 1, "{x}: {b:?}");
            assert!(same(&a[0], &b[0], 1e-12), "{x}: {a:?} vs {b:?}");
            assert!(same(&a[0], &plane, 1e-12), "{x}: {a:?} vs {plane:?}");
        }
        assert!(sphere_mesh(DVec3::new(0.1, 0.1, 0.25), r, &fine).is_empty());
        assert!(sphere_mesh(DVec3::new(0.1, 0.1, -0.26), r, &fine).is_empty());
    }

    #[test]
    fn random_spheres_on_flat_meshes_match_the_plane() {
        let walls = [floor(1), floor(3), floor(10), floor(25)];
        let mut rng = Rng::new(11);
        let mut scratch = MeshScratch::default();
        let mut out = Vec::new();
        for _ in 0..2000 {
            let r = rng.uniform(0.01, 0.3);
            // Keep the sphere's foot and contact inside the square.
            let x = DVec3::new(
                rng.uniform(-0.6, 0.6),
                rng.uniform(-0.6, 0.6),
                rng.uniform(-0.9 * r, 0.99 * r),
            );
            let plane = sphere_plane(x, r, DVec3::ZERO, DVec3::Z).unwrap();
            for w in &walls {
                sphere_mesh_contacts(x, r, w, &mut scratch, &mut out);
                assert_eq!(out.len(), 1, "{x} r {r}: {out:?}");
                assert!(same(&out[0].geometry, &plane, 1e-12), "{x}: {out:?}");
            }
        }
    }

    /// A flat floor, and the unit box facing in and facing out: flat faces, concave and convex
    /// edges and corners.
    fn floor_and_boxes() -> [MeshWall; 3] {
        [
            floor(10),
            box_mesh(DVec3::ZERO, DVec3::ONE, 4, Facing::Inward)
                .unwrap()
                .into_wall(0)
                .unwrap(),
            box_mesh(DVec3::ZERO, DVec3::ONE, 3, Facing::Outward)
                .unwrap()
                .into_wall(0)
                .unwrap(),
        ]
    }

    /// The contacts found among a longer list of triangles (those near a box enlarged by a
    /// skin) are those the mesh's own query gives, to the bit: on a flat floor, in the corners
    /// and along the edges of a closed box, on convex edges.
    #[test]
    fn contacts_among_a_longer_list_are_the_same() {
        let walls = floor_and_boxes();
        let mut rng = Rng::new(17);
        let (mut scratch, mut near) = (MeshScratch::default(), Vec::new());
        let (mut queried, mut among) = (Vec::new(), Vec::new());
        let mut touching = 0;
        for _ in 0..3000 {
            let r = rng.uniform(0.02, 0.2);
            let x = DVec3::new(
                rng.uniform(-0.2, 1.2),
                rng.uniform(-0.2, 1.2),
                rng.uniform(-0.2, 1.2),
            );
            for w in &walls {
                sphere_mesh_contacts(x, r, w, &mut scratch, &mut queried);
                let skin = rng.uniform(0.0, 0.3);
                w.triangles_near(&Aabb::around_sphere(x, r + skin), &mut near);
                sphere_mesh_contacts_among(x, r, w, &near, &mut scratch, &mut among);
                assert_eq!(format!("{queried:?}"), format!("{among:?}"), "{x} r {r}");
                touching += !queried.is_empty() as usize;
            }
        }
        assert!(touching > 1000, "only {touching} spheres touched a wall");
    }

    /// A list of the triangles within the radius and two skins of where a sphere was gives the
    /// contacts the mesh's own query gives, to the bit, wherever within two skins the sphere has
    /// gone since; and it drops triangles whose boxes come that near but which are farther (on
    /// a floor of squares cut in two, the far half of a square).
    #[test]
    fn contacts_among_the_triangles_within_reach_are_the_same() {
        let walls = floor_and_boxes();
        let mut rng = Rng::new(23);
        let (mut scratch, mut within, mut boxed) = (MeshScratch::default(), Vec::new(), Vec::new());
        let (mut queried, mut among) = (Vec::new(), Vec::new());
        let (mut touching, mut listed, mut boxes) = (0, 0, 0);
        for _ in 0..3000 {
            let r = rng.uniform(0.02, 0.2);
            let skin = rng.uniform(0.0, 0.1);
            let x0 = DVec3::new(
                rng.uniform(-0.2, 1.2),
                rng.uniform(-0.2, 1.2),
                rng.uniform(-0.2, 1.2),
            );
            // Moved by up to two skins, in a random direction; the last of the draws exactly
            // that far.
            let direction = DVec3::new(
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
            )
            .normalize_or(DVec3::X);
            for w in &walls {
                triangles_within(x0, r + 2.0 * skin, w, &mut within);
                w.triangles_near(&Aabb::around_sphere(x0, r + 2.0 * skin), &mut boxed);
                assert!(within.iter().all(|t| boxed.contains(t)));
                (listed, boxes) = (listed + within.len(), boxes + boxed.len());
                for moved in [rng.uniform(0.0, 2.0 * skin), 2.0 * skin] {
                    let x = x0 + direction * moved;
                    sphere_mesh_contacts(x, r, w, &mut scratch, &mut queried);
                    sphere_mesh_contacts_among(x, r, w, &within, &mut scratch, &mut among);
                    assert_eq!(format!("{queried:?}"), format!("{among:?}"), "{x} r {r}");
                    touching += !queried.is_empty() as usize;
                }
            }
        }
        assert!(touching > 2000, "only {touching} spheres touched a wall");
        // The exact lists are markedly shorter than the boxes' (what makes them worth it).
        assert!(
            4 * listed < 3 * boxes,
            "{listed} triangles within reach of {boxes}"
        );
    }

    /// Only the half of a floor square within reach is listed, where both halves' boxes are
    /// the whole square; a triangle exactly at the reach's distance is kept (the margin).
    #[test]
    fn triangles_within_reach_of_a_floor_square() {
        // floor(1): the square [-1, 1]² as two triangles cut along a diagonal.
        let w = floor(1);
        assert_eq!(w.triangles().len(), 2);
        let mut out = Vec::new();
        let [a, b, c] = w.corners(0);
        let centroid = (a + b + c) / 3.0 + DVec3::Z * 0.1;
        triangles_within(centroid, 0.2, &w, &mut out);
        assert_eq!(out, [0]);
        triangles_within(centroid, 3.0, &w, &mut out);
        assert_eq!(out, [0, 1]);
        // Above a corner shared by both, at height h: both at distance h exactly.
        let shared = w
            .corners(0)
            .into_iter()
            .find(|v| w.corners(1).contains(v))
            .unwrap();
        triangles_within(shared + DVec3::Z * 0.25, 0.25, &w, &mut out);
        assert_eq!(out, [0, 1]);
        triangles_within(shared + DVec3::Z * 0.25, 0.2499, &w, &mut out);
        assert!(out.is_empty());
    }

    #[test]
    fn vertex_shared_by_six_triangles_pushes_once() {
        // A fan of six triangles around the origin.
        let mut v = vec![DVec3::ZERO];
        for k in 0..6 {
            let a = std::f64::consts::TAU * k as f64 / 6.0;
            v.push(DVec3::new(a.cos(), a.sin(), 0.0));
        }
        let t: Vec<[u32; 3]> = (0..6u32).map(|k| [0, 1 + k, 1 + (k + 1) % 6]).collect();
        let fan = MeshWall::new(v, t, 0).unwrap();
        assert_eq!(fan.triangles_of_vertex(0).len(), 6);
        let mut scratch = MeshScratch::default();
        let mut out = Vec::new();
        sphere_mesh_contacts(DVec3::new(0.0, 0.0, 0.4), 0.5, &fan, &mut scratch, &mut out);
        assert_eq!(out.len(), 1, "{out:?}");
        assert_eq!(out[0].feature, Feature::Vertex(0));
        let g = out[0].geometry;
        assert!((g.normal - DVec3::Z).length() < 1e-15);
        assert!((g.overlap - 0.1).abs() < 1e-15);
        assert!((g.point - DVec3::new(0.0, 0.0, -0.05)).length() < 1e-15);
        // The interior vertices of the subdivided square are shared by six triangles too.
        let fine = floor(10);
        let g = sphere_mesh(DVec3::new(0.2, -0.4, 0.15), 0.2, &fine);
        assert_eq!(g.len(), 1);
        assert!((g[0].overlap - 0.05).abs() < 1e-12);
    }

    #[test]
    fn sliding_across_edges_and_vertices_keeps_the_overlap() {
        let fine = floor(10);
        let (r, h) = (0.05, 0.04);
        // Steps of 0.01 along a line at 30°: crosses edges, diagonals and vertices exactly.
        for i in 0..=150 {
            let s = -0.75 + 0.01 * i as f64;
            for dir in [
                DVec3::X,
                DVec3::new(1.0, 1.0, 0.0).normalize(),
                DVec3::new(0.8660254037844386, 0.5, 0.0),
            ] {
                let x = DVec3::new(0.0, 0.0, h) + s * dir;
                let g = sphere_mesh(x, r, &fine);
                assert_eq!(g.len(), 1, "{x}: {g:?}");
                assert!((g[0].overlap - (r - h)).abs() < 1e-12, "{x}: {g:?}");
                assert!((g[0].normal - DVec3::Z).length() < 1e-12);
            }
        }
    }

    #[test]
    fn concave_corner_of_a_box_gives_one_contact_per_wall() {
        for d in [1, 3, 8] {
            let b = box_mesh(DVec3::ZERO, DVec3::ONE, d, Facing::Inward)
                .unwrap()
                .into_wall(0)
                .unwrap();
            // Pressing on the floor (z = 0) and the wall x = 0, away from other walls.
            let x = DVec3::new(0.09, 0.53, 0.08);
            let mut g = sphere_mesh(x, 0.1, &b);
            g.sort_by(|p, q| p.normal.z.total_cmp(&q.normal.z));
            assert_eq!(g.len(), 2, "{d}: {g:?}");
            assert!((g[0].normal - DVec3::X).length() < 1e-12);
            assert!((g[0].overlap - 0.01).abs() < 1e-12);
            assert!((g[1].normal - DVec3::Z).length() < 1e-12);
            assert!((g[1].overlap - 0.02).abs() < 1e-12);
            // Into the corner of three walls: three contacts.
            let g = sphere_mesh(DVec3::new(0.09, 0.08, 0.07), 0.1, &b);
            assert_eq!(g.len(), 3, "{d}: {g:?}");
            let total: f64 = g.iter().map(|c| c.overlap).sum();
            assert!((total - 0.06).abs() < 1e-12);
            // A sphere in the middle of the box touches nothing.
            assert!(sphere_mesh(DVec3::splat(0.5), 0.1, &b).is_empty());
        }
    }

    #[test]
    fn convex_edge_of_a_box_gives_one_contact_towards_the_edge() {
        for d in [1, 4] {
            let b = box_mesh(DVec3::ZERO, DVec3::ONE, d, Facing::Outward)
                .unwrap()
                .into_wall(0)
                .unwrap();
            // Beyond the edge x = 1, z = 1, diagonally.
            let x = DVec3::new(1.06, 0.37, 1.08);
            let g = sphere_mesh(x, 0.2, &b);
            assert_eq!(g.len(), 1, "{d}: {g:?}");
            let to_edge = DVec3::new(0.06, 0.0, 0.08);
            assert!((g[0].normal - to_edge.normalize()).length() < 1e-12);
            assert!((g[0].overlap - (0.2 - to_edge.length())).abs() < 1e-12);
            // Over the top face near the edge: the face's contact only.
            let g = sphere_mesh(DVec3::new(0.97, 0.37, 1.15), 0.2, &b);
            assert_eq!(g.len(), 1, "{d}: {g:?}");
            assert!((g[0].normal - DVec3::Z).length() < 1e-12);
            assert!((g[0].overlap - 0.05).abs() < 1e-12);
            // Beyond a corner: one contact towards the corner.
            let x = DVec3::new(1.05, 1.05, 1.05);
            let g = sphere_mesh(x, 0.2, &b);
            assert_eq!(g.len(), 1);
            assert!((g[0].normal - DVec3::ONE.normalize()).length() < 1e-12);
        }
    }

    #[test]
    fn rolling_over_a_convex_edge_is_continuous() {
        let b = box_mesh(DVec3::ZERO, DVec3::ONE, 5, Facing::Outward)
            .unwrap()
            .into_wall(0)
            .unwrap();
        let (r, h) = (0.1, 0.09);
        // Around the edge x = 1, z = 1 at constant distance h from it, plus the flats before
        // and after: the overlap stays r − h throughout, one contact at a time.
        let mut previous: Option<Geometry> = None;
        for i in 0..=400 {
            let s = -0.2 + 0.4 * i as f64 / 400.0 + 0.5 * std::f64::consts::FRAC_PI_2 * h;
            let len = std::f64::consts::FRAC_PI_2 * h;
            let x = if s < 0.0 {
                DVec3::new(1.0 + s, 0.5, 1.0 + h)
            } else if s <= len {
                let a = s / h;
                DVec3::new(1.0 + h * a.sin(), 0.5, 1.0 + h * a.cos())
            } else {
                DVec3::new(1.0 + h, 0.5, 1.0 - (s - len))
            };
            let g = sphere_mesh(x, r, &b);
            assert_eq!(g.len(), 1, "{x}: {g:?}");
            assert!((g[0].overlap - (r - h)).abs() < 1e-12, "{x}: {g:?}");
            if let Some(p) = previous {
                assert!(
                    (g[0].normal - p.normal).length() < 0.02,
                    "{x}: normal jumps"
                );
            }
            previous = Some(g[0]);
        }
    }

    #[test]
    fn centre_behind_a_closed_wall_is_pushed_back_in() {
        let b = box_mesh(DVec3::ZERO, DVec3::ONE, 4, Facing::Inward)
            .unwrap()
            .into_wall(0)
            .unwrap();
        // Centre 0.03 below the floor, over a face, an edge and a vertex of its triangulation.
        for (x, y) in [(0.4, 0.6), (0.5, 0.6), (0.5, 0.5), (0.3, 0.3)] {
            let g = sphere_mesh(DVec3::new(x, y, -0.03), 0.1, &b);
            assert_eq!(g.len(), 1, "{x} {y}: {g:?}");
            assert!((g[0].normal - DVec3::Z).length() < 1e-12, "{g:?}");
            assert!((g[0].overlap - 0.13).abs() < 1e-12);
        }
    }

    #[test]
    fn rim_of_an_open_mesh_pushes_away_from_itself() {
        let w = floor(2);
        // Beyond the edge x = 1, slightly below the plane: a thin rim, pushed outwards-down.
        let x = DVec3::new(1.03, 0.2, -0.04);
        let g = sphere_mesh(x, 0.1, &w);
        assert_eq!(g.len(), 1);
        assert!((g[0].normal - DVec3::new(0.6, 0.0, -0.8)).length() < 1e-12);
        assert!((g[0].overlap - 0.05).abs() < 1e-12);
    }

    #[test]
    fn closed_box_pushes_every_sphere_near_or_through_a_wall_back_in() {
        let b = box_mesh(DVec3::ZERO, DVec3::ONE, 3, Facing::Inward)
            .unwrap()
            .into_wall(0)
            .unwrap();
        let mut rng = Rng::new(5);
        let r = 0.1;
        for _ in 0..3000 {
            // Centres from 0.9 r outside to 1.5 r inside every wall.
            let x = DVec3::new(
                rng.uniform(-0.09, 1.09),
                rng.uniform(-0.09, 1.09),
                rng.uniform(-0.09, 1.09),
            );
            let inside = x.min_element().min((DVec3::ONE - x).min_element());
            // How far outside the box the centre is (0 inside).
            let outside = (x - x.clamp(DVec3::ZERO, DVec3::ONE)).length();
            let g = sphere_mesh(x, r, &b);
            if inside >= r || outside >= r {
                assert!(g.is_empty(), "{x}: {g:?}");
                continue;
            }
            assert!(!g.is_empty(), "{x}");
            for c in &g {
                // Every contact pushes along an inward wall normal or into the box.
                assert!(c.overlap > 0.0 && c.overlap < 2.0 * r);
                assert!(c.normal.dot(DVec3::splat(0.5) - x) > 0.0, "{x}: {g:?}");
            }
            // A wall the centre is behind gives it an overlap of more than r.
            if inside < 0.0 {
                assert!(g.iter().any(|c| c.overlap > r), "{x}: {g:?}");
            }
        }
    }

    #[test]
    fn sphere_on_a_screw_flight() {
        use crate::wall::generators::{screw, Casing, Hand, Screw, ScrewPart};
        let s = Screw {
            shaft_radius: 0.02,
            flight_radius: 0.06,
            pitch: 0.08,
            turns: 2.0,
            thickness: 0.004,
            hand: Hand::Right,
            segments_per_turn: 90,
            radial_segments: 4,
            shaft: true,
            casing: Casing::Tube { clearance: 0.005 },
            part: ScrewPart::All,
        };
        let w = screw(&s).unwrap().into_wall(0).unwrap();
        let lead = s.pitch / std::f64::consts::TAU;
        // On the top face, mid-flight, at a quarter of the first turn.
        let (rho, theta, r, gap): (f64, f64, f64, f64) = (0.04, 1.0, 0.005, 0.004);
        let radial = DVec3::new(theta.cos(), theta.sin(), 0.0);
        let tangent = DVec3::new(-theta.sin(), theta.cos(), 0.0);
        let foot = rho * radial + DVec3::Z * (lead * theta + 0.5 * s.thickness);
        // The smooth helicoid's upward normal.
        let n = (lead * -tangent + rho * DVec3::Z).normalize();
        let g = sphere_mesh(foot + n * gap, r, &w);
        assert_eq!(g.len(), 1, "{g:?}");
        assert!(g[0].normal.angle_between(n) < 0.01, "{g:?}");
        assert!((g[0].overlap - (r - gap)).abs() < 2e-5, "{g:?}");
        // In the root, on the flight against the shaft: one contact each.
        let x = (s.shaft_radius + 0.004) * radial
            + DVec3::Z * (lead * theta + 0.5 * s.thickness + 0.004);
        let g = sphere_mesh(x, r, &w);
        assert_eq!(g.len(), 2, "{g:?}");
        // Against the tube, beyond the flight's rim.
        let x = (s.flight_radius + 0.004) * radial + DVec3::Z * (lead * theta + 0.04);
        let g = sphere_mesh(x, r, &w);
        assert_eq!(g.len(), 1, "{g:?}");
        assert!(g[0].normal.dot(-radial) > 0.99);
    }

    #[test]
    fn shallow_concave_fold_pushes_once_with_the_deeper_overlap() {
        // Two strips meeting along the y axis, each rising 5° away from it (a 10° fold).
        let t = 5f64.to_radians().tan();
        let v = vec![
            DVec3::new(-1.0, -1.0, t),
            DVec3::new(0.0, -1.0, 0.0),
            DVec3::new(1.0, -1.0, t),
            DVec3::new(-1.0, 1.0, t),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(1.0, 1.0, t),
        ];
        let tris = vec![[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]];
        let mut w = MeshWall::new(v, tris, 0).unwrap();
        let (r, h) = (0.1, 0.095);
        let mut previous: Option<f64> = None;
        for i in 0..=100 {
            let x = DVec3::new(-0.05 + 0.001 * i as f64, 0.0, h);
            let g = sphere_mesh(x, r, &w);
            assert_eq!(g.len(), 1, "{x}: {g:?}");
            if let Some(p) = previous {
                assert!((g[0].overlap - p).abs() < 2e-4, "{x}: jump");
            }
            previous = Some(g[0].overlap);
        }
        // Treated as separate walls, the sphere over the fold touches both.
        w.set_smooth_angle(0.0);
        assert_eq!(sphere_mesh(DVec3::new(0.0, 0.0, h), r, &w).len(), 2);
    }
}
