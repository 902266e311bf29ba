//! A convex polyhedron against a triangle-mesh wall, independent of how the wall is triangulated.
//!
//! # Cells
//!
//! The space behind the wall is cut into one **cell** per triangle: the part behind the
//! triangle's plane and inside planes through its three edges. Across an edge shared with one
//! other triangle that plane bisects the dihedral angle of the two faces (the points equally deep
//! below both planes); between coplanar triangles it is the plane perpendicular to the face, so
//! over a flat stretch the cells are the prisms over the triangles. Across a rim edge (one
//! triangle) it is perpendicular to the face. Both triangles of an edge compute the same plane
//! (oppositely oriented, bit for bit), so the cells of neighbours share their boundary:
//! - over a flat region the cells tile the half-space behind it, and any triangulation of the
//!   region cuts the body's submerged part into pieces whose volumes, first moments and section
//!   areas add up to those of the plane (`convex_plane`), to rounding;
//! - at a convex edge (the rim of a table) the region behind both faces is split between them
//!   along the bisector, not counted twice; at a concave one (inside a box) the wedge behind both
//!   walls is covered, not left out.
//!
//! Faces that fold convexly (each one's triangle behind the other's plane) are also separated by
//! their bisector where their triangles meet only at a vertex (the second triangle of a square
//! next to a box's edge) or not at all: every cell of a triangle near the body is cut by the
//! bisectors with the other acting planes near the body that fold convexly from its own.
//!
//! A triangle acts only on a body whose **centre is in front of its plane**: the back faces of a
//! thin wall (the underside of a screw flight a body sits on) never pull the body through. A cell
//! next to a convex fold whose other face does not act ends at that face's plane instead of the
//! bisector: it then holds all of the wall behind both faces and nothing in front of the other
//! (the part of a body hanging over a hopper's sloping rim is not taken for a part under its
//! floor). So a body sunk through a thin wall is pushed back by the part of it inside the wall.
//!
//! Where the cells reach past a fold (concave folds, and convex ones whose other face does not act
//! and meets this one at more than a right angle), the planes through the triangles' other edges
//! bound them laterally, and at the vertices of the fold those of consecutive triangles need not
//! meet: a body sunk by a good part of its size can be counted slightly too much or too little
//! there (a term of third order in the depth; measured ≤ 2.5 % of the volume for bodies sunk by
//! more than a seventh of their size at a frustum's 144° folds, exact below a tenth).
//!
//! # Volume law
//!
//! Each triangle t whose cell holds part of the body gives that part's volume V_t, centroid c_t and
//! the area of its section by the triangle's plane. The energy is that of an elastic foundation
//! under each face, W = k Σ_t ∫_{cell t} φ_t dV with φ_t the depth below plane t (linear, so
//! ∫ φ_t dV = V_t φ_t(c_t)), and the force on the body is k Σ_t V_t n_t, each term acting
//! through c_t. Moving the body changes W also through the pressure k φ_t on the side faces of the
//! cells; across a shared side plane these terms cancel, since both cells see the same depth
//! there (the plane is the bisector) with opposite normals. So wherever the body's submerged part
//! lies in cells of acting triangles, the force and its moment are the exact gradient of W: the
//! contact conserves energy across edges, corners and folds, as the volume law does against a
//! plane.
//!
//! The parts are integrated with the divergence theorem: the body's faces clipped by the cell's
//! half-spaces, plus the caps the cell's side planes cut from the body (the cap on the triangle's
//! plane adds nothing, the tetrahedra's apex being on it; its area is what closes the vector
//! areas of the others). A part wrapped round a convex edge may meet its triangle's plane only
//! along the edge; the area of its contact (the stiffness k A, the depth V/A) is the section plus
//! the shadow on the plane of the caps on tilted side planes that face away from it (nothing on a
//! flat region, whose side planes are perpendicular).
//!
//! # Regions
//!
//! Triangles whose normals differ by less than the wall's `smooth_angle`, directly or through a
//! chain of touched triangles (a flat floor, the facets of a drum), are one region and give one
//! contact: the sums of their pieces' volumes, loads Σ V_t n_t, section areas and potentials, at
//! the centroid of the whole, with the moment of the loads about it as a couple (zero on a flat
//! region). Faces at a sharper angle (a box's floor and side) are separate contacts. At most
//! [`MAX_REGIONS`] contacts, the largest first.
//!
//! # Vertex law
//!
//! The body's vertices in a cell, behind its triangle, are springs along the triangle's normal
//! with their depth below its plane, gathered per region as against a plane (`body_plane`); a
//! vertex on the boundary of two cells of one region (on a shared edge) counts once.

use super::clip::{clip_polygon, Plane, PLANE_TOLERANCE};
use super::dispatch::{springs, volume_geometry};
use super::nonconvex::{mesh_wall_regions, RegionScratch};
use super::Geometry;
use super::MAX_REGIONS;
use crate::contact_law::PolyhedralLaw;
use crate::math::{Aabb, DMat3, DQuat, DVec3};
use crate::shape::{ConvexPolyhedron, NonConvexPolyhedron};
use crate::wall::MeshWall;
use cells::{edge_planes, face_plane, is_active};
use region_sum::{region_contact, Sums};

mod cells;
mod region_sum;

/// Triangles are searched in the body's box enlarged by this fraction of its bounding radius:
/// the cells behind a concave fold widen with depth, so a cell can reach under the body from a
/// triangle just beside it.
const SEARCH_MARGIN: f64 = 0.25;

/// Normals closer than this (length of the difference) are one plane's, up to rounding.
const SAME_NORMAL: f64 = 1e-10;

/// Planes that meet at less than this angle [rad] get no bisector between their cells beyond the
/// one on a shared edge: the bisector of two almost parallel planes is ill-determined (a mesh
/// written in single precision has folds of 10⁻⁷ between coplanar triangles), and the volume it
/// would move between them is as small as the angle.
const FOLD_ANGLE: f64 = 0.01;

/// Reusable buffers for [`convex_mesh_contacts`] (one per thread).
#[derive(Clone, Debug, Default)]
pub struct ConvexMeshScratch {
    /// The body's vertices and face planes, world axes, origin at its centre.
    vertices: Vec<DVec3>,
    planes: Vec<Plane>,
    near: Vec<u32>,
    candidates: Vec<Candidate>,
    classes: Vec<Class>,
    /// Planes bounding the cells of a class's triangles besides their edges: (class, plane
    /// with the cell behind it).
    bounds: Vec<(usize, Plane)>,
    cell: Vec<Plane>,
    clip_planes: Vec<Plane>,
    polygon: Vec<DVec3>,
    spare: Vec<DVec3>,
    distances: Vec<f64>,
    pieces: Vec<Piece>,
    /// Vertex law: (vertex, depth) of the vertices in each piece's cell.
    points: Vec<(u32, f64)>,
    /// Vertex law: (vertex, depth, plane it is behind) of a region.
    springs: Vec<(u32, f64, Plane)>,
    /// Grouping a non-convex body's springs into connected regions.
    regions: RegionScratch,
}

/// A triangle that may press on the body: the body's centre is in front of its plane and part
/// of the body behind it.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    triangle: u32,
    /// The triangle's plane, relative to the body's centre.
    face: Plane,
    /// The body's vertex deepest behind it.
    deepest: usize,
    class: usize,
}

/// Triangles near the body in one plane.
#[derive(Clone, Copy, Debug)]
struct Class {
    /// The plane of its first triangle, and that triangle's centroid (relative to the body).
    face: Plane,
    centroid: DVec3,
    /// The body's centre is in front of the plane; some of its triangles are candidates.
    active: bool,
    pressing: bool,
    /// Union–find parent over classes within the smooth angle; the root's index names the
    /// region.
    parent: usize,
    touched: bool,
}

/// The part of the body in one triangle's cell.
#[derive(Clone, Copy, Debug)]
struct Piece {
    /// The plane of the piece's triangle.
    face: Plane,
    volume: f64,
    /// V times the centroid (relative to the body's centre).
    moment: DVec3,
    /// Area of the section by the triangle's plane.
    area: f64,
    /// ∫ φ dV.
    potential: f64,
    /// Range of `points`.
    points: (usize, usize),
    class: usize,
}

/// The contacts of convex polyhedron `p` (centre `x`, orientation `q`) with a mesh wall, normals
/// pointing from the wall towards the body; empty if it touches nothing. See the module's rules.
pub fn convex_mesh(
    p: &ConvexPolyhedron,
    x: DVec3,
    q: DQuat,
    wall: &MeshWall,
    law: PolyhedralLaw,
) -> Vec<Geometry> {
    let mut out = Vec::new();
    convex_mesh_contacts(
        p,
        x,
        q,
        wall,
        law,
        &mut ConvexMeshScratch::default(),
        &mut out,
    );
    out
}

/// As [`convex_mesh`], into `out` (cleared first): at most [`MAX_REGIONS`] contacts, in the
/// form `body_plane` gives for `law`, the largest first (volume, or total depth of the vertex
/// law's springs).
pub fn convex_mesh_contacts(
    p: &ConvexPolyhedron,
    x: DVec3,
    q: DQuat,
    wall: &MeshWall,
    law: PolyhedralLaw,
    scratch: &mut ConvexMeshScratch,
    out: &mut Vec<Geometry>,
) {
    pressed_contacts(Pressed::Convex(p), x, q, wall, law, scratch, out);
}

/// The contacts of a non-convex (mesh) body with a mesh wall, into `out` (cleared first): the
/// vertex law in the cells of the wall's triangles as for a convex body, each region of the wall
/// split further into the connected groups of the body's vertices in it, as against a plane
/// (`nonconvex::mesh_plane`: the arms of a jack lying on a floor are contacts of their own). At
/// most [`MAX_REGIONS`] contacts, the largest first.
pub fn nonconvex_mesh_contacts(
    shape: &NonConvexPolyhedron,
    x: DVec3,
    q: DQuat,
    wall: &MeshWall,
    scratch: &mut ConvexMeshScratch,
    out: &mut Vec<Geometry>,
) {
    pressed_contacts(
        Pressed::Mesh(shape),
        x,
        q,
        wall,
        PolyhedralLaw::Vertex,
        scratch,
        out,
    );
}

/// A body pressed against a mesh wall.
#[derive(Clone, Copy)]
enum Pressed<'a> {
    Convex(&'a ConvexPolyhedron),
    /// Under the vertex law only.
    Mesh(&'a NonConvexPolyhedron),
}

fn pressed_contacts(
    body: Pressed,
    x: DVec3,
    q: DQuat,
    wall: &MeshWall,
    law: PolyhedralLaw,
    scratch: &mut ConvexMeshScratch,
    out: &mut Vec<Geometry>,
) {
    out.clear();
    let ConvexMeshScratch {
        vertices,
        planes,
        near,
        candidates,
        classes,
        bounds,
        cell,
        clip_planes,
        polygon,
        spare,
        distances,
        pieces,
        points,
        springs: spring_list,
        regions,
    } = scratch;
    let (radius, body_vertices, faces) = match body {
        Pressed::Convex(p) => (p.bounding_radius(), p.vertices(), p.faces()),
        Pressed::Mesh(m) => (m.bounding_radius(), m.vertices(), &[][..]),
    };
    if !wall
        .bounds()
        .overlaps(&Aabb::around_sphere(x, (1.0 + SEARCH_MARGIN) * radius))
    {
        return;
    }
    let tolerance = PLANE_TOLERANCE * radius;
    let rotation = DMat3::from_quat(q);
    vertices.clear();
    vertices.extend(body_vertices.iter().map(|&v| rotation * v));
    let (lo, hi) = vertices
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    let reach = Aabb::new(x + lo, x + hi).enlarged(SEARCH_MARGIN * radius);
    if !wall.bounds().overlaps(&reach) {
        return;
    }
    wall.triangles_near(&reach, near);

    // The planes of the triangles near the body, and the triangles that may press on it.
    candidates.clear();
    classes.clear();
    for &t in near.iter() {
        let face = face_plane(wall, t, x);
        // The offsets first: a cheap test that rules out most classes.
        let class = match classes.iter().position(|c| {
            (c.face.offset - face.offset).abs() <= tolerance
                && (c.face.normal - face.normal).length() < SAME_NORMAL
        }) {
            Some(c) => c,
            None => {
                let [a, b, c] = wall.corners(t);
                classes.push(Class {
                    face,
                    centroid: (a + b + c) / 3.0 - x,
                    active: is_active(&face),
                    pressing: false,
                    parent: classes.len(),
                    touched: false,
                });
                classes.len() - 1
            }
        };
        if !is_active(&face) {
            continue;
        }
        let deepest = deepest_index(vertices, face.normal);
        if face.distance(vertices[deepest]) >= -tolerance {
            continue;
        }
        classes[class].pressing = true;
        candidates.push(Candidate {
            triangle: t,
            face,
            deepest,
            class,
        });
    }
    if candidates.is_empty() {
        return;
    }
    // Planes folding convexly (each one's triangles behind the other's plane: the rim of a
    // table, a box's corner from outside) share the region behind both along their bisector,
    // also where their triangles meet only at a vertex or not at all. Behind a plane that does
    // not act (the body's centre behind it), the cells of an acting one end at that plane: what
    // is in front of it is outside the wall.
    bounds.clear();
    let fold_cos = FOLD_ANGLE.cos();
    for i in 0..classes.len() {
        for j in 0..i {
            let (a, b) = (&classes[i], &classes[j]);
            if !(a.pressing || b.pressing)
                || a.face.normal.dot(b.face.normal) > fold_cos
                || b.face.distance(a.centroid) >= -tolerance
                || a.face.distance(b.centroid) >= -tolerance
            {
                continue;
            }
            match (a.active, b.active) {
                (true, true) => {
                    // φ_a ≤ φ_b ⟺ (n_b − n_a)·p ≤ offset_b − offset_a.
                    let d = b.face.normal - a.face.normal;
                    let length = d.length();
                    let plane = Plane {
                        normal: d / length,
                        offset: (b.face.offset - a.face.offset) / length,
                    };
                    bounds.push((i, plane));
                    bounds.push((
                        j,
                        Plane {
                            normal: -plane.normal,
                            offset: -plane.offset,
                        },
                    ));
                }
                (true, false) => bounds.push((i, b.face)),
                (false, true) => bounds.push((j, a.face)),
                (false, false) => {}
            }
        }
    }

    // By class (stable: each class keeps its planes' order), so a cell finds its own at once.
    bounds.sort_by_key(|&(c, _)| c);

    planes.clear();
    planes.extend(faces.iter().map(|f| Plane {
        normal: rotation * f.normal,
        offset: f.offset,
    }));
    pieces.clear();
    points.clear();
    for candidate in candidates.iter() {
        let Candidate {
            triangle: t,
            face,
            deepest,
            class,
        } = *candidate;
        cell.clear();
        cell.push(face);
        cell.extend(edge_planes(wall, t, x));
        let own = bounds.partition_point(|&(c, _)| c < class)
            ..bounds.partition_point(|&(c, _)| c <= class);
        for &(_, plane) in &bounds[own] {
            // A plane with the whole body on its inner side changes neither the piece nor its
            // caps: left out, so a facet of a curved wall (bounded by bisectors with every
            // facet it folds with) keeps a cell of a few planes.
            if extent(vertices, &plane).1 <= tolerance {
                continue;
            }
            // The plane across an edge to the other plane is already there (a second copy
            // would make the cap on it coplanar with a clipping plane, and drop it).
            if !cell.iter().any(|c| {
                (c.normal - plane.normal).length() < 1e-9
                    && (c.offset - plane.offset).abs() <= tolerance
            }) {
                cell.push(plane);
            }
        }
        // Beyond a side of the cell: nothing in it. Across one: a cap on it.
        let mut crosses = 0u64;
        let mut outside = false;
        for (k, side) in cell.iter().enumerate().skip(1) {
            let (least, most) = extent(vertices, side);
            outside |= least >= -tolerance;
            if most > tolerance && k < 64 {
                crosses |= 1 << k;
            }
        }
        if outside {
            continue;
        }
        let first_point = points.len();
        let mut piece = Piece {
            face,
            volume: 0.0,
            moment: DVec3::ZERO,
            area: 0.0,
            potential: 0.0,
            points: (first_point, first_point),
            class,
        };
        match law {
            PolyhedralLaw::Vertex => {
                for (i, &v) in vertices.iter().enumerate() {
                    let depth = -face.distance(v);
                    if depth > 0.0 && cell[1..].iter().all(|s| s.distance(v) <= tolerance) {
                        points.push((i as u32, depth));
                    }
                }
                piece.points.1 = points.len();
                if piece.points.1 == first_point {
                    continue;
                }
            }
            PolyhedralLaw::Volume => {
                // On the triangle's plane, next to the submerged part: the cap there adds no
                // volume, and the tetrahedra are small.
                let deepest = vertices[deepest];
                let r = deepest - face.normal * face.distance(deepest);
                let mut sums = Sums::default();
                for (f, plane) in faces.iter().zip(planes.iter()) {
                    polygon.clear();
                    polygon.extend(f.vertices.iter().map(|&i| vertices[i]));
                    if clip_polygon(
                        polygon,
                        spare,
                        distances,
                        cell,
                        tolerance,
                        plane.normal,
                        true,
                    ) {
                        sums.add(polygon, plane.normal, r);
                    }
                }
                // Caps on bisectors that face away from the triangle: the part of the piece's
                // shadow on the plane that is not under its section (a piece wrapped round a
                // convex edge may touch the plane only along the edge).
                let mut shadow = 0.0;
                for (k, side) in cell.iter().enumerate() {
                    if crosses & (1 << k) == 0 {
                        continue;
                    }
                    clip_planes.clear();
                    clip_planes.extend(
                        cell.iter()
                            .enumerate()
                            .filter(|&(j, _)| j != k)
                            .map(|(_, s)| *s),
                    );
                    clip_planes.extend_from_slice(planes);
                    // A square on the side plane holding the body's section (within the bounding
                    // sphere about the centre), counter-clockwise seen from outside the cell.
                    let centre = side.normal * side.offset;
                    let u = side.normal.any_orthonormal_vector() * (radius * (1.0 + 1e-6));
                    let v = side.normal.cross(u);
                    polygon.clear();
                    polygon.extend([
                        centre - u - v,
                        centre + u - v,
                        centre + u + v,
                        centre - u + v,
                    ]);
                    // A body face in the side plane is the cap itself: kept as a face (when the
                    // body is inside) or not at all, so the cap is dropped.
                    if clip_polygon(
                        polygon,
                        spare,
                        distances,
                        clip_planes,
                        tolerance,
                        side.normal,
                        false,
                    ) {
                        let area = sums.add(polygon, side.normal, r);
                        shadow += area * (-side.normal.dot(face.normal)).max(0.0);
                    }
                }
                if sums.six_volume.is_nan() || sums.six_volume <= 0.0 {
                    continue;
                }
                piece.volume = sums.six_volume / 6.0;
                let centroid = r + sums.moment / (4.0 * sums.six_volume);
                piece.moment = piece.volume * centroid;
                // Closed boundary: the cap on the triangle's plane has vector area −Σ(others),
                // along +n. The contact's area (its stiffness k A, its depth V/A) is that
                // section's, as against a plane, and the shadow of the rest.
                piece.area = -sums.vector_area.dot(face.normal) + shadow;
                piece.potential = -piece.volume * face.distance(centroid);
            }
        }
        classes[class].touched = true;
        pieces.push(piece);
    }
    if pieces.is_empty() {
        return;
    }

    // Regions: touched classes within the smooth angle of each other, transitively.
    let smooth_cos = wall.smooth_cos();
    for i in 0..classes.len() {
        for j in 0..i {
            if classes[i].touched
                && classes[j].touched
                && classes[i].face.normal.dot(classes[j].face.normal) >= smooth_cos
            {
                let (a, b) = (root(classes, i), root(classes, j));
                if a != b {
                    classes[a.max(b)].parent = a.min(b);
                }
            }
        }
    }
    for i in 0..classes.len() {
        classes[i].parent = root(classes, i);
    }

    for region in 0..classes.len() {
        if classes[region].parent != region || !classes[region].touched {
            continue;
        }
        let in_region = |piece: &&Piece| classes[piece.class].parent == region;
        let geometry = match law {
            PolyhedralLaw::Vertex => {
                spring_list.clear();
                for piece in pieces.iter().filter(in_region) {
                    spring_list.extend(
                        points[piece.points.0..piece.points.1]
                            .iter()
                            .map(|&(v, depth)| (v, depth, piece.face)),
                    );
                }
                // Once per vertex: the first triangle's (in mesh order) of those it lies in.
                spring_list.sort_by_key(|s| s.0);
                spring_list.dedup_by_key(|s| s.0);
                match body {
                    Pressed::Mesh(shape) => {
                        mesh_wall_regions(shape, rotation, x, spring_list, regions, out);
                        None
                    }
                    Pressed::Convex(_) => springs(
                        spring_list
                            .iter()
                            .map(|&(v, depth, f)| (x + vertices[v as usize], depth, f.normal)),
                    ),
                }
            }
            PolyhedralLaw::Volume => {
                region_contact(pieces, classes, region, x, tolerance).map(volume_geometry)
            }
        };
        if let Some(g) = geometry {
            out.push(g);
        }
    }
    // The largest first; ties by normal, so the order does not depend on the triangulation.
    let size = |g: &Geometry| {
        g.volume.map_or(0.0, |v| match v.law {
            PolyhedralLaw::Volume => v.volume,
            PolyhedralLaw::Vertex => v.load,
        })
    };
    out.sort_by(|a, b| {
        size(b)
            .total_cmp(&size(a))
            .then(a.normal.x.total_cmp(&b.normal.x))
            .then(a.normal.y.total_cmp(&b.normal.y))
            .then(a.normal.z.total_cmp(&b.normal.z))
    });
    out.truncate(MAX_REGIONS);
}

/// Union–find root (the classes are few: no path compression needed).
fn root(classes: &[Class], mut i: usize) -> usize {
    while classes[i].parent != i {
        i = classes[i].parent;
    }
    i
}

/// The index of the point farthest along −`direction` (the first of equals).
fn deepest_index(points: &[DVec3], direction: DVec3) -> usize {
    let mut best = (0, f64::INFINITY);
    for (i, v) in points.iter().enumerate() {
        let d = v.dot(direction);
        if d < best.1 {
            best = (i, d);
        }
    }
    best.0
}

/// Smallest and largest signed distance of the points from a plane.
fn extent(points: &[DVec3], plane: &Plane) -> (f64, f64) {
    points
        .iter()
        .map(|&v| plane.distance(v))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), d| {
            (lo.min(d), hi.max(d))
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::narrow_phase::convex_convex::tests::{cube, random_quat};
    use crate::narrow_phase::{body_plane, Posed};
    use crate::rng::SplitMix64;
    use crate::shape::generators::regular_tetrahedron;
    use crate::shape::Shape;
    use crate::wall::generators::{box_mesh, cylinder, rectangle};
    use crate::wall::{Ends, Facing};

    const LAWS: [PolyhedralLaw; 2] = [PolyhedralLaw::Volume, PolyhedralLaw::Vertex];

    /// The square [-1, 1]² of the plane through `origin` with normal `turn`·z, of 2 n² triangles.
    fn square(n: usize, origin: DVec3, turn: DQuat) -> MeshWall {
        rectangle(
            origin + turn * DVec3::new(-1.0, -1.0, 0.0),
            turn * DVec3::X * 2.0,
            turn * DVec3::Y * 2.0,
            n,
            n,
        )
        .unwrap()
        .into_wall(0)
        .unwrap()
    }

    /// A square wall of 2 and one of 200 triangles in the same plane, turned at random half the
    /// time: its centre, its turn and the two walls.
    fn random_squares(rng: &mut SplitMix64) -> (DVec3, DQuat, [MeshWall; 2]) {
        let turn = if rng.next_f64() < 0.5 {
            DQuat::IDENTITY
        } else {
            random_quat(rng)
        };
        let origin = DVec3::new(rng.uniform(-2.0, 2.0), 0.3, rng.uniform(-1.0, 1.0));
        (
            origin,
            turn,
            [square(1, origin, turn), square(10, origin, turn)],
        )
    }

    fn unit_box(divisions: usize, facing: Facing) -> MeshWall {
        box_mesh(DVec3::ZERO, DVec3::ONE, divisions, facing)
            .unwrap()
            .into_wall(0)
            .unwrap()
    }

    fn overlap(g: &Geometry) -> crate::contact_law::OverlapVolume {
        g.volume.expect("a polyhedral contact has its overlap")
    }

    /// Every quantity of `g` equals `reference`'s to `rel` of its scale (`size`: the body's).
    fn assert_same(g: &Geometry, reference: &Geometry, size: f64, rel: f64, what: &str) {
        let (v, v0) = (overlap(g), overlap(reference));
        let close = |a: f64, b: f64, scale: f64| (a - b).abs() <= rel * scale;
        assert_eq!(v.law, v0.law, "{what}");
        assert_eq!(v.points, v0.points, "{what}: {g:?} vs {reference:?}");
        assert!(
            (g.normal - reference.normal).length() <= rel,
            "{what}: {g:?} vs {reference:?}"
        );
        assert!(
            (g.point - reference.point).length() <= rel * size,
            "{what}: {g:?} vs {reference:?}"
        );
        assert!(
            close(g.overlap, reference.overlap, reference.overlap),
            "{what}"
        );
        assert!(
            close(v.volume, v0.volume, v0.volume),
            "{what}: {v:?} vs {v0:?}"
        );
        assert!(close(v.area, v0.area, v0.area), "{what}: {v:?} vs {v0:?}");
        assert!(close(v.load, v0.load, v0.load), "{what}: {v:?} vs {v0:?}");
        assert!(
            close(v.potential, v0.potential, v0.potential),
            "{what}: {v:?} vs {v0:?}"
        );
        assert!(
            (v.couple - v0.couple).length() <= rel * v0.load * size,
            "{what}: {v:?} vs {v0:?}"
        );
    }

    /// Random cubes and tetrahedra sunk into a flat square wall (turned at random too) of 2 or
    /// of 200 triangles: one contact, equal to the plane's (`body_plane`) to 1e-9, for both laws.
    #[test]
    fn flat_wall_of_2_or_200_triangles_matches_the_plane() {
        let shapes = [
            Shape::Convex(cube(0.5).into()),
            Shape::Convex(regular_tetrahedron(0.7).unwrap().0.into()),
        ];
        let mut rng = SplitMix64::new(21);
        let mut scratch = ConvexMeshScratch::default();
        let mut out = Vec::new();
        let mut compared = 0;
        for _ in 0..300 {
            let (origin, turn, walls) = random_squares(&mut rng);
            for shape in &shapes {
                let Shape::Convex(p) = shape else {
                    unreachable!()
                };
                let q = random_quat(&mut rng);
                let radius = p.bounding_radius();
                // Deepest vertex sunk by 0.1 % to 40 % of the radius, centre over the square.
                let lowest = -(q * p.support(q.inverse() * -DVec3::Z)).z;
                let sink = radius * 10f64.powf(rng.uniform(-3.0, -0.4));
                let local = DVec3::new(
                    rng.uniform(-0.45, 0.45),
                    rng.uniform(-0.45, 0.45),
                    lowest - sink,
                );
                let (x, orientation) = (origin + turn * local, turn * q);
                let posed = Posed {
                    shape,
                    position: x,
                    orientation,
                };
                for law in LAWS {
                    let Some(reference) = body_plane(posed, origin, turn * DVec3::Z, law) else {
                        continue;
                    };
                    for wall in &walls {
                        convex_mesh_contacts(p, x, orientation, wall, law, &mut scratch, &mut out);
                        let what = format!("{law:?}, {} triangles", wall.triangles().len());
                        assert_eq!(out.len(), 1, "{what}: {out:?}");
                        assert_same(&out[0], &reference, radius, 1e-9, &what);
                        compared += 1;
                    }
                }
            }
        }
        assert!(compared > 2000, "{compared}");
    }

    /// Jacks and crosses sunk into a flat square wall (turned at random) of 2 or of 200
    /// triangles: the same contacts as against the plane (`body_plane_regions`: one per group of
    /// the body's vertices behind it, so each arm on the floor is its own), to 1e-9.
    #[test]
    fn non_convex_bodies_on_a_flat_wall_match_the_plane() {
        use crate::narrow_phase::{body_plane_regions, RegionScratch};
        use crate::shape::nonconvex_generators::{cross, jack};
        let shapes = [
            Shape::NonConvex(jack(0.6, 0.2).unwrap().build(false).unwrap().0.into()),
            Shape::NonConvex(
                cross(0.6, 0.15, 0.1)
                    .unwrap()
                    .build(false)
                    .unwrap()
                    .0
                    .into(),
            ),
        ];
        let mut rng = SplitMix64::new(5);
        let (mut scratch, mut regions) = (ConvexMeshScratch::default(), RegionScratch::new());
        let (mut out, mut reference) = (Vec::new(), Vec::new());
        let (mut compared, mut several) = (0, 0);
        let by_size = |g: &Geometry| -overlap(g).load;
        for _ in 0..200 {
            let (origin, turn, walls) = random_squares(&mut rng);
            for shape in &shapes {
                let Shape::NonConvex(p) = shape else {
                    unreachable!()
                };
                let q = random_quat(&mut rng);
                let radius = p.bounding_radius();
                // Deepest vertex sunk by 0.1 % to 20 % of the radius, the body over the square.
                let lowest = p
                    .vertices()
                    .iter()
                    .map(|&v| (q * v).z)
                    .fold(f64::INFINITY, f64::min);
                let sink = radius * 10f64.powf(rng.uniform(-3.0, -0.7));
                let local = DVec3::new(
                    rng.uniform(-0.3, 0.3),
                    rng.uniform(-0.3, 0.3),
                    -lowest - sink,
                );
                let (x, orientation) = (origin + turn * local, turn * q);
                let posed = Posed {
                    shape,
                    position: x,
                    orientation,
                };
                body_plane_regions(
                    posed,
                    origin,
                    turn * DVec3::Z,
                    PolyhedralLaw::Vertex,
                    &mut regions,
                    &mut reference,
                );
                reference.sort_by(|a, b| by_size(a).total_cmp(&by_size(b)));
                reference.truncate(MAX_REGIONS);
                several += usize::from(reference.len() > 1);
                for wall in &walls {
                    nonconvex_mesh_contacts(p, x, orientation, wall, &mut scratch, &mut out);
                    let what = format!("{} triangles", wall.triangles().len());
                    assert_eq!(out.len(), reference.len(), "{what}: {out:?}");
                    for (g, r) in out.iter().zip(&reference) {
                        assert_same(g, r, radius, 1e-9, &what);
                    }
                    compared += 1;
                }
            }
        }
        assert!(compared == 800 && several > 20, "{compared}, {several}");
    }

    /// A cube whose bottom vertices lie exactly on edges, or exactly on vertices, shared by
    /// several triangles (of the subdivided square, and on the diagonal of the 2-triangle one):
    /// one contact, each vertex counted once, as on the plane.
    #[test]
    fn cube_straddling_shared_edges_and_vertices_is_one_contact() {
        let c = Shape::Convex(cube(0.4).into());
        let Shape::Convex(p) = &c else { unreachable!() };
        let walls = [
            square(1, DVec3::ZERO, DQuat::IDENTITY),
            square(10, DVec3::ZERO, DQuat::IDENTITY),
        ];
        // Bottom vertices on the lines x = 0, 0.4 of the fine square (between its vertices), on
        // its vertices, and (turned 45°) with two on the coarse square's diagonal.
        let poses = [
            (DVec3::new(0.2, 0.1, 0.19), DQuat::IDENTITY),
            (DVec3::new(0.2, 0.2, 0.17), DQuat::IDENTITY),
            (
                DVec3::new(0.0, 0.0, 0.195),
                DQuat::from_rotation_z(std::f64::consts::FRAC_PI_4),
            ),
        ];
        for (x, q) in poses {
            let posed = Posed {
                shape: &c,
                position: x,
                orientation: q,
            };
            for law in LAWS {
                let reference = body_plane(posed, DVec3::ZERO, DVec3::Z, law).unwrap();
                for wall in &walls {
                    let g = convex_mesh(p, x, q, wall, law);
                    let what = format!("{x} {law:?}, {} triangles", wall.triangles().len());
                    assert_eq!(g.len(), 1, "{what}: {g:?}");
                    assert_same(&g[0], &reference, 0.4, 1e-12, &what);
                    if law == PolyhedralLaw::Vertex {
                        assert_eq!(overlap(&g[0]).points, 4, "{what}");
                    }
                }
            }
        }
    }

    /// A cube pressed into a closed box's edge and corner from inside: one contact per wall, with
    /// the wall's normal; the volumes are the cube's part behind each wall, the wedge behind two
    /// walls split between them by the bisector (so they add up to the part outside the box),
    /// whatever the subdivision.
    #[test]
    fn cube_in_a_box_corner_gets_a_contact_per_wall() {
        for d in [1, 3] {
            let b = unit_box(d, Facing::Inward);
            for law in LAWS {
                // x ∈ [−0.01, 0.19], z ∈ [−0.02, 0.18]: into the wall x = 0 and the floor.
                let g = convex_mesh(
                    &cube(0.2),
                    DVec3::new(0.09, 0.5, 0.08),
                    DQuat::IDENTITY,
                    &b,
                    law,
                );
                assert_eq!(g.len(), 2, "{d} {law:?}: {g:?}");
                // The floor is pressed more: first.
                assert!((g[0].normal - DVec3::Z).length() < 1e-12, "{g:?}");
                assert!((g[1].normal - DVec3::X).length() < 1e-12, "{g:?}");
                if law == PolyhedralLaw::Volume {
                    // Floor: the 0.02 slab less the wedge x < z < 0 (½ 0.01² × 0.2); wall: the
                    // 0.01 slab less the wedge z ≤ x < 0 (0.2 ∫(x + 0.02) dx over [−0.01, 0]).
                    assert!((overlap(&g[0]).volume - 7.9e-4).abs() < 1e-15, "{g:?}");
                    assert!((overlap(&g[1]).volume - 3.7e-4).abs() < 1e-15, "{g:?}");
                } else {
                    // Four bottom vertices, and the two at x = −0.01, z = 0.18 in the wall.
                    assert_eq!(overlap(&g[0]).points, 4);
                    assert_eq!(overlap(&g[1]).points, 2);
                }
                // Into the corner of three walls, 0.01, 0.02, 0.03 deep.
                let g = convex_mesh(
                    &cube(0.2),
                    DVec3::new(0.09, 0.08, 0.07),
                    DQuat::IDENTITY,
                    &b,
                    law,
                );
                assert_eq!(g.len(), 3, "{d} {law:?}: {g:?}");
                for (c, n) in g.iter().zip([DVec3::Z, DVec3::Y, DVec3::X]) {
                    assert!((c.normal - n).length() < 1e-12, "{g:?}");
                }
                if law == PolyhedralLaw::Volume {
                    // The cube's part outside the box, by inclusion–exclusion.
                    let outside = (4e-4 + 8e-4 + 1.2e-3) - (4e-5 + 6e-5 + 1.2e-4) + 6e-6;
                    let total: f64 = g.iter().map(|c| overlap(c).volume).sum();
                    assert!((total - outside).abs() < 1e-15, "{total} vs {outside}");
                }
            }
        }
    }

    /// W (per unit stiffness) and the force and torque of all contacts of a body.
    fn energy_and_load(
        p: &ConvexPolyhedron,
        x: DVec3,
        q: DQuat,
        wall: &MeshWall,
        law: PolyhedralLaw,
    ) -> (f64, DVec3, DVec3, usize) {
        let g = convex_mesh(p, x, q, wall, law);
        let (mut w, mut f, mut m) = (0.0, DVec3::ZERO, DVec3::ZERO);
        for c in &g {
            let v = overlap(c);
            let load = c.normal * v.load;
            w += v.potential;
            f += load;
            m += (c.point - x).cross(load) + v.couple;
        }
        (w, f, m, g.len())
    }

    /// The contacts are the gradient of their potential across the folds of a closed mesh: at a
    /// convex edge and corner (outside a box) and in a concave corner (inside one), with the body
    /// turned at random, the force and torque equal −dW/dx and −dW/dθ by central differences.
    #[test]
    fn force_and_torque_are_the_gradient_of_the_energy_at_edges_and_corners() {
        let mut rng = SplitMix64::new(3);
        let c = cube(0.2);
        let outside = unit_box(2, Facing::Outward);
        let inside = unit_box(3, Facing::Inward);
        let mut checked = 0;
        for _ in 0..40 {
            let q = random_quat(&mut rng);
            let cases = [
                // Beyond the edge x = 1, z = 1, and beyond the corner (1, 1, 1).
                (&outside, DVec3::new(1.06, 0.5, 1.05), 2),
                (&outside, DVec3::new(1.05, 1.06, 1.07), 3),
                // Into the corner (0, 0, 0) of the inside.
                (&inside, DVec3::new(0.06, 0.07, 0.05), 3),
            ];
            for (wall, x, touching) in cases {
                for law in LAWS {
                    let (_, force, torque, count) = energy_and_load(&c, x, q, wall, law);
                    if count < touching {
                        continue;
                    }
                    let h = 1e-7;
                    let mut numeric_force = DVec3::ZERO;
                    let mut numeric_torque = DVec3::ZERO;
                    for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
                        let energy = |dx: DVec3, angle: f64| {
                            let turned = DQuat::from_axis_angle(axis, angle) * q;
                            energy_and_load(&c, x + dx, turned, wall, law).0
                        };
                        numeric_force -=
                            axis * (energy(axis * h, 0.0) - energy(-axis * h, 0.0)) / (2.0 * h);
                        numeric_torque -=
                            axis * (energy(DVec3::ZERO, h) - energy(DVec3::ZERO, -h)) / (2.0 * h);
                    }
                    let scale = force.length();
                    assert!(
                        (force - numeric_force).length() < 1e-5 * scale,
                        "{law:?} at {x}: {force} vs {numeric_force}"
                    );
                    assert!(
                        (torque - numeric_torque).length() < 1e-5 * scale * 0.2,
                        "{law:?} at {x}: {torque} vs {numeric_torque}"
                    );
                    checked += 1;
                }
            }
        }
        assert!(checked > 60, "{checked}");
    }

    /// A cube resting on a thin slab: the slab's underside, which the cube's centre is behind,
    /// does not act, and the top acts as the plane does; a cube sunk through the whole slab is
    /// pushed back by the part of it inside the slab (the vertex law: by none, its vertices are
    /// all through).
    #[test]
    fn cube_on_a_thin_slab_feels_only_the_top() {
        use crate::narrow_phase::{convex_convex, ClipScratch};
        let (slab_solid, _) = crate::shape::generators::cuboid(2.0, 2.0, 0.01).unwrap();
        for d in [1, 4] {
            let slab = box_mesh(
                DVec3::new(-1.0, -1.0, -0.005),
                DVec3::new(1.0, 1.0, 0.005),
                d,
                Facing::Outward,
            )
            .unwrap()
            .into_wall(0)
            .unwrap();
            let c = Shape::Convex(cube(0.3).into());
            let Shape::Convex(p) = &c else { unreachable!() };
            let q = DQuat::from_rotation_z(0.3) * DQuat::from_rotation_x(0.02);
            for sink in [0.001, 0.004, 0.02] {
                let x = DVec3::new(0.1, -0.2, 0.005 + 0.15 - sink);
                let posed = Posed {
                    shape: &c,
                    position: x,
                    orientation: q,
                };
                for law in LAWS {
                    let g = convex_mesh(p, x, q, &slab, law);
                    if sink > 0.01 && law == PolyhedralLaw::Vertex {
                        // Every vertex is through the slab: no spring is inside it.
                        assert!(g.is_empty(), "{g:?}");
                        continue;
                    }
                    assert_eq!(g.len(), 1, "{d} {sink} {law:?}: {g:?}");
                    assert!((g[0].normal - DVec3::Z).length() < 1e-12);
                    let top = DVec3::new(0.0, 0.0, 0.005);
                    let reference = body_plane(posed, top, DVec3::Z, law).unwrap();
                    if sink < 0.01 {
                        assert_same(
                            &g[0],
                            &reference,
                            0.3,
                            1e-9,
                            &format!("slab {d} {sink} {law:?}"),
                        );
                    } else {
                        let inside = convex_convex(
                            p,
                            x,
                            q,
                            &slab_solid,
                            DVec3::ZERO,
                            DQuat::IDENTITY,
                            &mut ClipScratch::default(),
                        )
                        .unwrap();
                        let v = overlap(&g[0]).volume;
                        assert!((v / inside.volume - 1.0).abs() < 1e-9, "{v} {inside:?}");
                        assert!(v < overlap(&reference).volume);
                    }
                }
            }
        }
    }

    /// Facets of a drum (7.5° apart, below the smooth angle) are one contact; a coarse drum
    /// (30°) gives one per facet.
    #[test]
    fn facets_within_the_smooth_angle_are_one_contact() {
        for (segments, expected) in [(48, 1), (12, 2)] {
            let drum = cylinder(1.0, 2.0, segments, 1, Ends::Closed, Facing::Inward)
                .unwrap()
                .into_wall(0)
                .unwrap();
            // A long bar pressed into the side wall, across several facets (across the corner
            // between two of the coarse drum's facets at angle 0).
            let (bar, _) = crate::shape::generators::cuboid(0.1, 0.8, 0.1).unwrap();
            let x = DVec3::new(0.96, 0.0, 1.0);
            for law in LAWS {
                let g = convex_mesh(&bar, x, DQuat::IDENTITY, &drum, law);
                assert_eq!(g.len(), expected, "{segments} {law:?}: {g:?}");
                // Pushed back towards the axis, without sideways push (the pose is symmetric).
                let total: DVec3 = g.iter().map(|c| c.normal * overlap(c).load).sum();
                assert!(
                    total.x < 0.0 && total.y.abs() < 1e-12 * total.length(),
                    "{g:?}"
                );
            }
        }
    }

    /// Outside a closed convex mesh (a box, a faceted frustum with its ends), the cells of the
    /// faces the body's centre is in front of split the body's overlap with the solid along the
    /// bisectors of its faces: the contacts' volumes add up to the overlap of the body with the
    /// solid (the convex polyhedron of the mesh's vertices, by `convex_convex`), and every vertex
    /// of the body inside the solid is one spring of the vertex law.
    #[test]
    fn pieces_add_up_to_the_overlap_with_a_convex_solid() {
        use crate::narrow_phase::{convex_convex, ClipScratch};
        let meshes = [
            box_mesh(DVec3::ZERO, DVec3::ONE, 1, Facing::Outward).unwrap(),
            box_mesh(DVec3::ZERO, DVec3::ONE, 3, Facing::Outward).unwrap(),
            crate::wall::generators::frustum(0.8, 0.5, 1.0, 10, 2, Ends::Closed, Facing::Outward)
                .unwrap(),
        ];
        let shapes = [cube(0.2), regular_tetrahedron(0.3).unwrap().0];
        let mut rng = SplitMix64::new(17);
        let mut clip = ClipScratch::default();
        let mut compared = 0;
        for (m, mesh) in meshes.into_iter().enumerate() {
            let (solid, mass) = ConvexPolyhedron::from_points(&mesh.vertices).unwrap();
            let (solid_x, solid_q) = (mass.center_of_mass, mass.principal_rotation());
            let lo = mesh.vertices.iter().fold(DVec3::INFINITY, |a, &v| a.min(v));
            let hi = mesh
                .vertices
                .iter()
                .fold(DVec3::NEG_INFINITY, |a, &v| a.max(v));
            let wall = mesh.into_wall(0).unwrap();
            for _ in 0..1500 {
                let p = &shapes[compared % 2];
                let x = DVec3::new(
                    rng.uniform(lo.x - 0.15, hi.x + 0.15),
                    rng.uniform(lo.y - 0.15, hi.y + 0.15),
                    rng.uniform(lo.z - 0.15, hi.z + 0.15),
                );
                let outside = solid
                    .faces()
                    .iter()
                    .any(|f| (solid_q * f.normal).dot(x - solid_x) > f.offset);
                if !outside {
                    continue;
                }
                let q = random_quat(&mut rng);
                let Some(exact) = convex_convex(p, x, q, &solid, solid_x, solid_q, &mut clip)
                else {
                    continue;
                };
                let g = convex_mesh(p, x, q, &wall, PolyhedralLaw::Volume);
                let total: f64 = g.iter().map(|c| overlap(c).volume).sum();
                // Exact on the box (its folds are right angles); on the frustum, whose faces
                // meet at 144° and 107°, a body sunk by more than a tenth of its size (mean
                // depth) is counted up to a few per cent too much where the cells reaching past
                // a fold meet at its vertices (measured: ≤ 2.5 % at mean depths 0.03–0.05).
                let error = total / exact.volume - 1.0;
                let depth = exact.volume / exact.area;
                if m < 2 || depth < 0.02 {
                    assert!(error.abs() < 1e-9, "{m}: {x} {q:?}: {error:e}: {g:?}");
                } else {
                    assert!(error > -1e-9 && error < 0.03, "{m}: {x} {q:?}: {error:e}");
                }
                let inside = p
                    .vertices()
                    .iter()
                    .filter(|&&v| {
                        let y = solid_q.inverse() * (x + q * v - solid_x);
                        solid.faces().iter().all(|f| f.normal.dot(y) < f.offset)
                    })
                    .count();
                let g = convex_mesh(p, x, q, &wall, PolyhedralLaw::Vertex);
                let points: usize = g.iter().map(|c| overlap(c).points).sum();
                assert_eq!(points, inside, "{x}: {g:?}");
                compared += 1;
            }
        }
        assert!(compared > 1000, "{compared}");
    }

    /// Nothing leaks out of a closed box: any pose of a cube or tetrahedron with its centre
    /// inside and part of it outside gets contacts, and together they push it back in.
    #[test]
    fn closed_box_pushes_every_body_that_pokes_out_back_in() {
        let b = unit_box(2, Facing::Inward);
        let shapes = [cube(0.2), regular_tetrahedron(0.3).unwrap().0];
        let mut rng = SplitMix64::new(8);
        let mut poking = 0;
        for _ in 0..3000 {
            for p in &shapes {
                let q = random_quat(&mut rng);
                let x = DVec3::new(
                    rng.uniform(0.01, 0.99),
                    rng.uniform(0.01, 0.99),
                    rng.uniform(0.01, 0.99),
                );
                let out_by = p
                    .vertices()
                    .iter()
                    .map(|&v| {
                        let y = x + q * v;
                        (-y.min_element()).max((y - DVec3::ONE).max_element())
                    })
                    .fold(f64::NEG_INFINITY, f64::max);
                for law in LAWS {
                    let (_, force, _, count) = energy_and_load(p, x, q, &b, law);
                    if out_by <= 1e-9 {
                        assert_eq!(count, 0, "{x}");
                        continue;
                    }
                    poking += 1;
                    assert!(count > 0, "{law:?}: {x} pokes out by {out_by} untouched");
                    assert!(
                        force.dot(DVec3::splat(0.5) - x) > 0.0,
                        "{law:?}: {x} {force}"
                    );
                }
            }
        }
        assert!(poking > 1000, "{poking}");
    }
}
