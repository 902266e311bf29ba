//! A non-convex polyhedral particle: a closed, consistently outward triangle mesh in its
//! principal body frame.
//!
//! Built from any mesh that passes `mesh_check` (closed, manifold, outward, not
//! self-intersecting; duplicates welded). Mass properties are exact for the non-convex solid
//! (`MassProperties::from_mesh`: signed tetrahedra cancel outside it). What contact detection
//! needs is prepared once per shape:
//!
//! - a bounding-volume hierarchy over the triangles (`geometry::bvh`): the point-in-polyhedron
//!   test by ray casting ([`NonConvexPolyhedron::locate`], exact), the nearest point of the
//!   surface, and the triangles near a box, each in time ~ log(triangles);
//! - the surface as a [`TriangleMesh`] in the body frame: its edges with their two triangles, and what
//!   a sphere needs to touch it in several places at once;
//! - which edges are sharp (the triangles at them differ in direction by more than
//!   [`SHARP_EDGE_ANGLE`]): edges inside flat faces split into triangles are not, and take no part
//!   in edge–edge contacts;
//! - optionally, the body as a union of convex parts (given by the user or by a generator), each
//!   a [`ConvexPolyhedron`] placed in the body frame: then contacts may use the volume law per
//!   pair of parts.

use super::mesh_check::{check_mesh, CheckOptions, CheckReport, MeshCheckError};
use super::{ConvexPolyhedron, MassProperties, ShapeError, UnitMassProperties};
use crate::geometry::bvh::Bvh;
use crate::geometry::point_in_polyhedron::{locate_point_bvh, Location};
use crate::geometry::triangle_mesh::TriangleMesh;
use crate::math::{Aabb, DMat3, DQuat, DVec3};
use thiserror::Error;

/// Edges whose two triangles' normals differ by more than this angle [rad] (0.5°) are sharp.
pub const SHARP_EDGE_ANGLE: f64 = 0.5 * std::f64::consts::PI / 180.0;

/// The convex parts must add up to the mesh's volume to this relative tolerance.
pub const PARTS_VOLUME_TOLERANCE: f64 = 1e-6;

/// No corner of a convex part may lie farther outside the mesh than this, relative to the
/// diagonal of the mesh's box: far above the rounding of single-precision (STL) coordinates.
pub const PARTS_DISTANCE_TOLERANCE: f64 = 1e-6;

/// A convex part of a body, placed in the body's frame.
#[derive(Clone, Debug, PartialEq)]
pub struct ConvexPart {
    /// The part in its own principal frame.
    pub shape: ConvexPolyhedron,
    /// Where the part's centre of mass lies in the body frame.
    pub offset: DVec3,
    /// Part frame → body frame.
    pub rotation: DQuat,
}

/// Why a non-convex particle could not be built.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum NonConvexError {
    #[error(transparent)]
    Mesh(#[from] MeshCheckError),
    #[error(transparent)]
    Shape(#[from] ShapeError),
    #[error("convex part {index}: {error}")]
    Part { index: usize, error: ShapeError },
    #[error(
        "the convex parts add up to a volume of {parts:e}, the mesh encloses {mesh:e}: the parts \
         must fill the body without overlapping each other"
    )]
    PartsVolume { parts: f64, mesh: f64 },
    #[error(
        "corner [{}, {}, {}] of convex part {index} lies {distance:.3e} outside the mesh: the parts \
         must lie inside the body", point.x, point.y, point.z
    )]
    PartOutside {
        index: usize,
        point: DVec3,
        distance: f64,
    },
}

/// A closed non-convex polyhedron in its principal body frame.
#[derive(Clone, Debug)]
pub struct NonConvexPolyhedron {
    vertices: Vec<DVec3>,
    triangles: Vec<[usize; 3]>,
    /// Outward unit normal of each triangle.
    normals: Vec<DVec3>,
    /// The surface with its adjacency (edges, their triangles), in the body frame.
    surface: TriangleMesh,
    /// Per edge of `surface`: whether it is sharp.
    sharp: Vec<bool>,
    bvh: Bvh,
    volume: f64,
    principal_moments: DVec3,
    bounding_radius: f64,
    bounds: Aabb,
    /// Area and number of distinct corners of the largest flat face (triangles joined across
    /// edges that are not sharp).
    largest_face: (f64, usize),
    parts: Vec<ConvexPart>,
    /// Row-major: whether parts i and j touch (their boxes in the body frame meet).
    adjacent: Vec<bool>,
}

impl PartialEq for NonConvexPolyhedron {
    fn eq(&self, other: &Self) -> bool {
        self.vertices == other.vertices
            && self.triangles == other.triangles
            && self.parts == other.parts
    }
}

impl NonConvexPolyhedron {
    /// The solid bounded by `triangles` (indices into `vertices`, counter-clockwise seen from
    /// outside), checked and moved into its principal frame. Also returns the mass properties in
    /// the input frame (`center_of_mass` and `principal_rotation()` place the body where the mesh
    /// was) and what the checks repaired.
    pub fn from_mesh(
        vertices: &[DVec3],
        triangles: &[[usize; 3]],
        options: CheckOptions,
    ) -> Result<(Self, MassProperties, CheckReport), NonConvexError> {
        let checked = check_mesh(vertices, triangles, options)?;
        let mass = MassProperties::from_mesh(&checked.vertices, &checked.triangles)?;
        let axes = mass.principal_axes;
        let body: Vec<DVec3> = checked
            .vertices
            .iter()
            .map(|&x| to_body(axes, mass.center_of_mass, x))
            .collect();
        let shape = Self::in_body_frame(body, checked.triangles, mass)?;
        Ok((shape, mass, checked.report))
    }

    fn in_body_frame(
        vertices: Vec<DVec3>,
        triangles: Vec<[usize; 3]>,
        mass: MassProperties,
    ) -> Result<Self, NonConvexError> {
        let normals: Vec<DVec3> = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| vertices[i]);
                (b - a).cross(c - a).normalize_or_zero()
            })
            .collect();
        let surface = TriangleMesh::new(
            vertices.clone(),
            triangles.iter().map(|t| t.map(|i| i as u32)).collect(),
        )
        .map_err(|e| ShapeError::InvalidParameter(format!("the surface {e}")))?;
        let cos_sharp = SHARP_EDGE_ANGLE.cos();
        let sharp: Vec<bool> = (0..surface.edges().len() as u32)
            .map(|e| {
                let t = surface.triangles_of_edge(e);
                t.len() != 2 || normals[t[0] as usize].dot(normals[t[1] as usize]) < cos_sharp
            })
            .collect();
        let largest_face = largest_flat_face(&vertices, &triangles, &surface, &sharp);
        let bvh = Bvh::new(&vertices, &triangles);
        let (lo, hi) = vertices
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            });
        Ok(Self {
            bounding_radius: vertices.iter().map(|v| v.length()).fold(0.0, f64::max),
            bounds: Aabb::new(lo, hi),
            vertices,
            triangles,
            normals,
            surface,
            sharp,
            bvh,
            volume: mass.volume,
            principal_moments: mass.principal_moments,
            largest_face,
            parts: Vec::new(),
            adjacent: Vec::new(),
        })
    }

    /// The same body described also as the union of the convex hulls of `parts` (points in the
    /// input frame of the mesh, whose mass properties `mass` are, as `from_mesh` returned them).
    /// The parts must fill the body: their volumes add up to the mesh's (to
    /// [`PARTS_VOLUME_TOLERANCE`]) and no corner lies outside it.
    pub fn with_parts(
        mut self,
        mass: &MassProperties,
        parts: &[Vec<DVec3>],
    ) -> Result<Self, NonConvexError> {
        let axes = mass.principal_axes;
        let size = self.bounds.extent().length();
        let mut built = Vec::with_capacity(parts.len());
        let mut total = 0.0;
        for (index, points) in parts.iter().enumerate() {
            let (shape, part_mass) = ConvexPolyhedron::from_points(points)
                .map_err(|error| NonConvexError::Part { index, error })?;
            total += part_mass.volume;
            for &p in points {
                let local = to_body(axes, mass.center_of_mass, p);
                if self.locate(local) == Location::Outside {
                    let distance = self.distance_to_surface(local);
                    if distance > PARTS_DISTANCE_TOLERANCE * size {
                        return Err(NonConvexError::PartOutside {
                            index,
                            point: p,
                            distance,
                        });
                    }
                }
            }
            let rotation = axes.transpose() * part_mass.principal_axes;
            built.push(ConvexPart {
                shape,
                offset: to_body(axes, mass.center_of_mass, part_mass.center_of_mass),
                rotation: DQuat::from_mat3(&rotation).normalize(),
            });
        }
        if (total / self.volume - 1.0).abs() > PARTS_VOLUME_TOLERANCE {
            return Err(NonConvexError::PartsVolume {
                parts: total,
                mesh: self.volume,
            });
        }
        // Parts touch when their boxes in the body frame meet (to within rounding).
        let boxes: Vec<Aabb> = built
            .iter()
            .map(|part| {
                let (lo, hi) = part.shape.vertices().iter().fold(
                    (DVec3::INFINITY, DVec3::NEG_INFINITY),
                    |(lo, hi), &v| {
                        let x = part.offset + part.rotation * v;
                        (lo.min(x), hi.max(x))
                    },
                );
                Aabb::new(lo, hi).enlarged(1e-9 * size)
            })
            .collect();
        let n = built.len();
        self.adjacent = (0..n * n)
            .map(|k| k / n != k % n && boxes[k / n].overlaps(&boxes[k % n]))
            .collect();
        self.parts = built;
        Ok(self)
    }

    /// Whether convex parts `i` and `j` touch (share a face or an edge).
    pub fn parts_adjacent(&self, i: usize, j: usize) -> bool {
        self.adjacent[i * self.parts.len() + j]
    }

    pub fn vertices(&self) -> &[DVec3] {
        &self.vertices
    }

    /// Outward triangles, counter-clockwise seen from outside.
    pub fn triangles(&self) -> &[[usize; 3]] {
        &self.triangles
    }

    /// Outward unit normal of each triangle.
    pub fn normals(&self) -> &[DVec3] {
        &self.normals
    }

    /// The surface with its adjacency: `edges()`, `triangles_of_edge(e)`, `triangle_edges()`.
    pub fn surface(&self) -> &TriangleMesh {
        &self.surface
    }

    /// Whether edge `e` of [`Self::surface`] is sharp (see [`SHARP_EDGE_ANGLE`]).
    pub fn is_sharp(&self, e: u32) -> bool {
        self.sharp[e as usize]
    }

    pub fn bvh(&self) -> &Bvh {
        &self.bvh
    }

    /// Axis-aligned bounds in the body frame.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Radius of the smallest sphere about the centre of mass that contains the shape.
    pub fn bounding_radius(&self) -> f64 {
        self.bounding_radius
    }

    pub fn unit_mass_properties(&self) -> UnitMassProperties {
        UnitMassProperties {
            volume: self.volume,
            principal_inertia_per_density: self.principal_moments,
        }
    }

    /// Area of the largest flat face (triangles joined across edges that are not sharp) and the
    /// number of its corners.
    pub fn largest_face(&self) -> (f64, usize) {
        self.largest_face
    }

    /// The convex parts, if the body was given as their union (empty otherwise).
    pub fn parts(&self) -> &[ConvexPart] {
        &self.parts
    }

    /// Where a body-frame point lies: exact ray casting over the triangles the line meets.
    pub fn locate(&self, point: DVec3) -> Location {
        locate_point_bvh(point, &self.vertices, &self.triangles, &self.bvh)
    }

    /// The point of the surface nearest to `point` and the triangle it lies on.
    pub fn closest_point(&self, point: DVec3) -> (DVec3, u32) {
        let (q, _, t) = self
            .bvh
            .closest_point(point, &self.vertices, &self.triangles, f64::INFINITY)
            .expect("a checked mesh has triangles");
        (q, t)
    }

    /// Distance from a body-frame point to the surface.
    pub fn distance_to_surface(&self, point: DVec3) -> f64 {
        (self.closest_point(point).0 - point).length()
    }
}

/// x_body = Aᵀ (x − c).
fn to_body(axes: DMat3, centre: DVec3, x: DVec3) -> DVec3 {
    let d = x - centre;
    DVec3::new(axes.col(0).dot(d), axes.col(1).dot(d), axes.col(2).dot(d))
}

/// The largest group of triangles joined across edges that are not sharp: its area and distinct
/// corners.
fn largest_flat_face(
    vertices: &[DVec3],
    triangles: &[[usize; 3]],
    surface: &TriangleMesh,
    sharp: &[bool],
) -> (f64, usize) {
    let n = triangles.len();
    let mut group = vec![usize::MAX; n];
    let mut best = (0.0, 0);
    for seed in 0..n {
        if group[seed] != usize::MAX {
            continue;
        }
        group[seed] = seed;
        let mut stack = vec![seed];
        let (mut area, mut corners) = (0.0, Vec::new());
        while let Some(t) = stack.pop() {
            let [a, b, c] = triangles[t].map(|i| vertices[i]);
            area += 0.5 * (b - a).cross(c - a).length();
            corners.extend_from_slice(&triangles[t]);
            for &e in &surface.triangle_edges()[t] {
                if sharp[e as usize] {
                    continue;
                }
                for &u in surface.triangles_of_edge(e) {
                    if group[u as usize] == usize::MAX {
                        group[u as usize] = seed;
                        stack.push(u as usize);
                    }
                }
            }
        }
        corners.sort_unstable();
        corners.dedup();
        if area > best.0 {
            best = (area, corners.len());
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::test_meshes::{box_mesh, l_shape_mesh};

    #[test]
    fn l_shape_mass_properties_are_those_of_two_boxes() {
        let (v, t) = l_shape_mesh();
        let (p, mass, report) =
            NonConvexPolyhedron::from_mesh(&v, &t, CheckOptions::default()).expect("a valid mesh");
        assert_eq!(report, CheckReport::default());
        // [0,2]×[0,1]×[0,1] ∪ [0,1]×[1,2]×[0,1]: two boxes of volumes 2 and 1.
        let (va, ta) = box_mesh(DVec3::ZERO, DVec3::new(2.0, 1.0, 1.0));
        let (vb, tb) = box_mesh(DVec3::new(0.0, 1.0, 0.0), DVec3::new(1.0, 2.0, 1.0));
        let (ma, mb) = (
            MassProperties::from_mesh(&va, &ta).unwrap(),
            MassProperties::from_mesh(&vb, &tb).unwrap(),
        );
        let volume = ma.volume + mb.volume;
        let centre = (ma.volume * ma.center_of_mass + mb.volume * mb.center_of_mass) / volume;
        assert!((mass.volume - 3.0).abs() < 1e-14);
        assert!((mass.center_of_mass - centre).length() < 1e-14);
        // Parallel-axis theorem: I = Σ (I_k + m_k (|d|² 1 − d dᵀ)).
        let shift = |m: &MassProperties| {
            let d = m.center_of_mass - centre;
            m.inertia
                + (DMat3::from_diagonal(DVec3::splat(d.length_squared()))
                    - DMat3::from_cols(d * d.x, d * d.y, d * d.z))
                    * m.volume
        };
        let expected = shift(&ma) + shift(&mb);
        let diff = expected - mass.inertia;
        for j in 0..3 {
            assert!(diff.col(j).abs().max_element() < 1e-13, "{diff:?}");
        }
        assert!((p.unit_mass_properties().volume - 3.0).abs() < 1e-14);
        // In the principal frame: centre at the origin.
        let m = MassProperties::from_mesh(p.vertices(), p.triangles()).unwrap();
        assert!(m.center_of_mass.length() < 1e-14);
        // The largest flat face is the L itself (area 3, 6 corners).
        let (area, corners) = p.largest_face();
        assert!((area - 3.0).abs() < 1e-13);
        assert_eq!(corners, 6);
        // Only the triangulation diagonals are not sharp: 18 edges of the prism are.
        let sharp = (0..p.surface().edges().len() as u32)
            .filter(|&e| p.is_sharp(e))
            .count();
        assert_eq!(sharp, 18);
    }

    #[test]
    fn parts_must_fill_the_body() {
        let (v, t) = l_shape_mesh();
        let (p, mass, _) = NonConvexPolyhedron::from_mesh(&v, &t, CheckOptions::default()).unwrap();
        let corners = |lo: DVec3, hi: DVec3| box_mesh(lo, hi).0;
        let a = corners(DVec3::ZERO, DVec3::new(2.0, 1.0, 1.0));
        let b = corners(DVec3::new(0.0, 1.0, 0.0), DVec3::new(1.0, 2.0, 1.0));
        let good = p
            .clone()
            .with_parts(&mass, &[a.clone(), b.clone()])
            .unwrap();
        assert_eq!(good.parts().len(), 2);
        // Each part placed in the body frame covers its box.
        let q = mass.principal_rotation();
        for (part, expected_volume) in good.parts().iter().zip([2.0, 1.0]) {
            let u = part.shape.unit_mass_properties();
            assert!((u.volume - expected_volume).abs() < 1e-13);
            for &w in part.shape.vertices() {
                let body = part.offset + part.rotation * w;
                let input = mass.center_of_mass + q * body;
                // Every corner is a corner of the L's bounding boxes: integer coordinates.
                assert!(
                    (input - input.round()).abs().max_element() < 1e-12,
                    "{input}"
                );
            }
        }
        let e = p
            .clone()
            .with_parts(&mass, std::slice::from_ref(&a))
            .unwrap_err();
        assert!(matches!(e, NonConvexError::PartsVolume { .. }), "{e}");
        let big = corners(DVec3::ZERO, DVec3::new(2.0, 2.0, 1.0));
        let e = p.clone().with_parts(&mass, &[big]).unwrap_err();
        assert!(matches!(e, NonConvexError::PartOutside { .. }), "{e}");
        let e = p.with_parts(&mass, &[vec![DVec3::ZERO; 4]]).unwrap_err();
        assert!(matches!(e, NonConvexError::Part { index: 0, .. }), "{e}");
    }
}
