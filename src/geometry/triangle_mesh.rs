//! A triangle mesh with the adjacency that contact detection needs: the surface of a mesh wall
//! (`wall::MeshWall`) and of a non-convex particle (`shape::NonConvexPolyhedron`).
//!
//! A [`TriangleMesh`] holds the triangles, one unit normal per triangle (pointing to the side
//! bodies live on, given by the winding: counter-clockwise seen from that side), the adjacency
//! that tells a face from an edge from a vertex (for each edge its triangles, for each vertex its
//! triangles, angle-weighted pseudo-normals of edges and vertices), and a uniform grid of triangle
//! bounding boxes that answers "which triangles are near this sphere".
//!
//! The mesh must be welded: triangles that meet share vertex indices (`geometry::weld`). Unwelded
//! copies of a vertex make the contact routines see a boundary where there is none.

use super::compressed_rows::compressed_rows;
use super::triangle_grid::{triangle_bounds, TriangleGrid};
use crate::math::{is_finite_vec, Aabb, DQuat, DVec3};
use std::collections::HashMap;
use thiserror::Error;

/// A triangle whose area is below this fraction of its longest edge squared is degenerate.
pub const DEGENERATE_TRIANGLE_RATIO: f64 = 1e-12;

/// Default [`TriangleMesh::smooth_angle`]: 20°.
pub const DEFAULT_SMOOTH_ANGLE: f64 = 20.0 * std::f64::consts::PI / 180.0;

/// Why a triangle mesh could not be built. The messages read after the name of what the mesh is
/// ("mesh wall triangle 3 uses vertex 7 twice").
#[derive(Debug, Error, Clone, PartialEq)]
pub enum TriangleMeshError {
    #[error("needs at least one triangle")]
    Empty,
    #[error("vertex {index} is [{}, {}, {}]: every coordinate must be a finite number", point.x, point.y, point.z)]
    NonFiniteVertex { index: usize, point: DVec3 },
    #[error("triangle {triangle} uses vertex {index}, but there are only {count} vertices")]
    IndexOutOfRange {
        triangle: usize,
        index: u32,
        count: usize,
    },
    #[error("triangle {triangle} uses vertex {index} twice")]
    RepeatedCorner { triangle: usize, index: u32 },
    #[error("triangle {triangle} has (almost) zero area {area}: its corners are collinear")]
    Degenerate { triangle: usize, area: f64 },
    #[error("has too many vertices or triangles for 32-bit indices")]
    TooLarge,
}

/// A point feature of a mesh: the open interior of a triangle, an edge or a vertex (indices into
/// the mesh's triangles, edges and vertices).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Feature {
    Face(u32),
    Edge(u32),
    Vertex(u32),
}

/// A welded triangle mesh with its adjacency and a grid of its triangles.
#[derive(Clone, Debug)]
pub struct TriangleMesh {
    vertices: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    normals: Vec<DVec3>,
    /// Faces whose normals differ by less than this angle [rad] are facets of one smooth
    /// surface: a sphere touching several of them gets one contact, the deepest (a sphere in a
    /// faceted drum or on a coarse helicoid is not pushed once per facet). Faces meeting at a
    /// sharper angle are separate walls (a box's corner pushes once per wall).
    smooth_angle: f64,
    /// Its cosine, which the contact rules compare with (worked out once, not per contact).
    smooth_cos: f64,
    /// Each edge's two vertices, smaller index first.
    edges: Vec<[u32; 2]>,
    /// For each triangle the edge between its corners k and k+1 (mod 3), k = 0, 1, 2.
    triangle_edges: Vec<[u32; 3]>,
    /// Compressed rows: the triangles of edge e are `edge_triangles[edge_start[e]..edge_start[e+1]]`.
    edge_start: Vec<u32>,
    edge_triangles: Vec<u32>,
    /// Compressed rows: the triangles of vertex v.
    vertex_start: Vec<u32>,
    vertex_triangles: Vec<u32>,
    /// Unit pseudo-normals (sum of the adjacent triangles' normals, for vertices weighted by the
    /// corner angle; Bærentzen & Aanæs 2005): which side of the surface a point near an edge or
    /// vertex is on.
    edge_normals: Vec<DVec3>,
    vertex_normals: Vec<DVec3>,
    /// Vertices on an edge that does not have exactly two triangles (the rim of an open mesh).
    vertex_on_boundary: Vec<bool>,
    bounds: Aabb,
    grid: TriangleGrid,
    /// Identity map 0..n, so that a face feature can lend out a one-element slice.
    triangle_ids: Vec<u32>,
}

impl TriangleMesh {
    /// Builds a mesh from vertices and triangles (indices into `vertices`, counter-clockwise seen
    /// from the side bodies live on). Vertices no triangle uses are kept but never touched.
    pub fn new(vertices: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> Result<Self, TriangleMeshError> {
        if triangles.is_empty() {
            return Err(TriangleMeshError::Empty);
        }
        if vertices.len() >= u32::MAX as usize || triangles.len() >= u32::MAX as usize {
            return Err(TriangleMeshError::TooLarge);
        }
        if let Some((index, &point)) = vertices
            .iter()
            .enumerate()
            .find(|(_, v)| !is_finite_vec(**v))
        {
            return Err(TriangleMeshError::NonFiniteVertex { index, point });
        }
        let mut normals = Vec::with_capacity(triangles.len());
        for (t, tri) in triangles.iter().enumerate() {
            for &i in tri {
                if i as usize >= vertices.len() {
                    return Err(TriangleMeshError::IndexOutOfRange {
                        triangle: t,
                        index: i,
                        count: vertices.len(),
                    });
                }
            }
            if tri[0] == tri[1] || tri[0] == tri[2] {
                return Err(TriangleMeshError::RepeatedCorner {
                    triangle: t,
                    index: tri[0],
                });
            }
            if tri[1] == tri[2] {
                return Err(TriangleMeshError::RepeatedCorner {
                    triangle: t,
                    index: tri[1],
                });
            }
            let [a, b, c] = tri.map(|i| vertices[i as usize]);
            let cross = (b - a).cross(c - a);
            let longest = (b - a)
                .length_squared()
                .max((c - b).length_squared())
                .max((a - c).length_squared());
            let twice_area = cross.length();
            // The corners are finite, so the area is a number.
            if twice_area <= DEGENERATE_TRIANGLE_RATIO * longest {
                return Err(TriangleMeshError::Degenerate {
                    triangle: t,
                    area: 0.5 * twice_area,
                });
            }
            normals.push(cross / twice_area);
        }

        // Edges, numbered in order of first appearance.
        let mut edge_index: HashMap<[u32; 2], u32> = HashMap::new();
        let mut edges = Vec::new();
        let mut triangle_edges = Vec::with_capacity(triangles.len());
        for tri in &triangles {
            let mut te = [0u32; 3];
            for k in 0..3 {
                let (i, j) = (tri[k], tri[(k + 1) % 3]);
                let key = [i.min(j), i.max(j)];
                te[k] = *edge_index.entry(key).or_insert_with(|| {
                    edges.push(key);
                    (edges.len() - 1) as u32
                });
            }
            triangle_edges.push(te);
        }
        let (edge_start, edge_triangles) = compressed_rows(
            edges.len(),
            triangle_edges
                .iter()
                .enumerate()
                .flat_map(|(t, te)| te.iter().map(move |&e| (e, t as u32))),
        );
        let (vertex_start, vertex_triangles) = compressed_rows(
            vertices.len(),
            triangles
                .iter()
                .enumerate()
                .flat_map(|(t, tri)| tri.iter().map(move |&v| (v, t as u32))),
        );

        let edge_normals = (0..edges.len())
            .map(|e| {
                let ts = &edge_triangles[edge_start[e] as usize..edge_start[e + 1] as usize];
                ts.iter()
                    .map(|&t| normals[t as usize])
                    .sum::<DVec3>()
                    .try_normalize()
                    .unwrap_or(normals[ts[0] as usize])
            })
            .collect();
        let mut vertex_normals = vec![DVec3::ZERO; vertices.len()];
        for (t, tri) in triangles.iter().enumerate() {
            for k in 0..3 {
                let p = vertices[tri[k] as usize];
                let u = vertices[tri[(k + 1) % 3] as usize] - p;
                let w = vertices[tri[(k + 2) % 3] as usize] - p;
                vertex_normals[tri[k] as usize] += u.angle_between(w) * normals[t];
            }
        }
        for (v, n) in vertex_normals.iter_mut().enumerate() {
            let first = vertex_triangles
                .get(vertex_start[v] as usize)
                .filter(|_| vertex_start[v] < vertex_start[v + 1]);
            *n = n
                .try_normalize()
                .unwrap_or_else(|| first.map_or(DVec3::Z, |&t| normals[t as usize]));
        }

        let mut vertex_on_boundary = vec![false; vertices.len()];
        for (e, ends) in edges.iter().enumerate() {
            if edge_start[e + 1] - edge_start[e] != 2 {
                for &v in ends {
                    vertex_on_boundary[v as usize] = true;
                }
            }
        }

        let bounds = triangles
            .iter()
            .map(|tri| triangle_bounds(&vertices, tri))
            .reduce(|a, b| a.union(&b))
            .expect("at least one triangle");
        let grid = TriangleGrid::new(&vertices, &triangles, bounds);
        let triangle_ids = (0..triangles.len() as u32).collect();
        Ok(Self {
            vertices,
            triangles,
            normals,
            smooth_angle: DEFAULT_SMOOTH_ANGLE,
            smooth_cos: DEFAULT_SMOOTH_ANGLE.cos(),
            edges,
            triangle_edges,
            edge_start,
            edge_triangles,
            vertex_start,
            vertex_triangles,
            edge_normals,
            vertex_normals,
            vertex_on_boundary,
            bounds,
            grid,
            triangle_ids,
        })
    }

    /// The mesh with every vertex x moved to `rotation * (scale * x) + translation` (`scale` > 0,
    /// `rotation` a unit quaternion), with the same smooth angle.
    pub fn transformed(
        &self,
        scale: f64,
        rotation: DQuat,
        translation: DVec3,
    ) -> Result<Self, TriangleMeshError> {
        let vertices = self
            .vertices
            .iter()
            .map(|&v| rotation * (scale * v) + translation)
            .collect();
        let mut moved = Self::new(vertices, self.triangles.clone())?;
        moved.set_smooth_angle(self.smooth_angle);
        Ok(moved)
    }

    /// Faces whose normals differ by less than this angle [rad] are facets of one smooth
    /// surface (see the field); [`DEFAULT_SMOOTH_ANGLE`] unless set.
    pub fn smooth_angle(&self) -> f64 {
        self.smooth_angle
    }

    /// The cosine of [`TriangleMesh::smooth_angle`].
    pub fn smooth_cos(&self) -> f64 {
        self.smooth_cos
    }

    pub fn set_smooth_angle(&mut self, angle: f64) {
        self.smooth_angle = angle;
        self.smooth_cos = angle.cos();
    }

    /// The vertices (a wall's in its reference placement).
    pub fn vertices(&self) -> &[DVec3] {
        &self.vertices
    }

    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Unit normal of each triangle, towards the side bodies live on.
    pub fn normals(&self) -> &[DVec3] {
        &self.normals
    }

    /// Each edge's two vertices, smaller index first.
    pub fn edges(&self) -> &[[u32; 2]] {
        &self.edges
    }

    /// For each triangle, its edges between corners (0,1), (1,2), (2,0).
    pub fn triangle_edges(&self) -> &[[u32; 3]] {
        &self.triangle_edges
    }

    /// The triangles sharing edge `e` (two for an interior edge of a manifold mesh).
    pub fn triangles_of_edge(&self, e: u32) -> &[u32] {
        let e = e as usize;
        &self.edge_triangles[self.edge_start[e] as usize..self.edge_start[e + 1] as usize]
    }

    /// The triangles with vertex `v` as a corner, in increasing order.
    pub fn triangles_of_vertex(&self, v: u32) -> &[u32] {
        let v = v as usize;
        &self.vertex_triangles[self.vertex_start[v] as usize..self.vertex_start[v + 1] as usize]
    }

    /// The triangles whose closure holds a point of `feature`, in increasing order.
    pub fn triangles_of_feature(&self, feature: &Feature) -> &[u32] {
        match *feature {
            Feature::Face(t) => std::slice::from_ref(&self.triangles_index()[t as usize]),
            Feature::Edge(e) => self.triangles_of_edge(e),
            Feature::Vertex(v) => self.triangles_of_vertex(v),
        }
    }

    /// Unit pseudo-normal of an edge (the normalised sum of its triangles' normals).
    pub fn edge_normal(&self, e: u32) -> DVec3 {
        self.edge_normals[e as usize]
    }

    /// Unit angle-weighted pseudo-normal of a vertex.
    pub fn vertex_normal(&self, v: u32) -> DVec3 {
        self.vertex_normals[v as usize]
    }

    /// The pseudo-normal of a feature (a face's own normal).
    pub fn feature_normal(&self, feature: &Feature) -> DVec3 {
        match *feature {
            Feature::Face(t) => self.normals[t as usize],
            Feature::Edge(e) => self.edge_normal(e),
            Feature::Vertex(v) => self.vertex_normal(v),
        }
    }

    /// True for an edge or vertex on the rim of an open mesh (an edge without exactly two
    /// triangles, or a vertex on such an edge); never for a face.
    pub fn is_boundary(&self, feature: &Feature) -> bool {
        match *feature {
            Feature::Face(_) => false,
            Feature::Edge(e) => self.triangles_of_edge(e).len() != 2,
            Feature::Vertex(v) => self.vertex_on_boundary[v as usize],
        }
    }

    /// The three corners of triangle `t`.
    pub fn corners(&self, t: u32) -> [DVec3; 3] {
        self.triangles[t as usize].map(|i| self.vertices[i as usize])
    }

    /// Bounding box of all triangles.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Total area of the triangles.
    pub fn area(&self) -> f64 {
        (0..self.triangles.len() as u32)
            .map(|t| {
                let [a, b, c] = self.corners(t);
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }

    /// True when every edge is shared by exactly two triangles.
    pub fn is_closed(&self) -> bool {
        self.edge_start.windows(2).all(|w| w[1] - w[0] == 2)
    }

    /// Appends to `out` (cleared first), in increasing order and without repeats, the triangles
    /// whose bounding boxes overlap `query`: a superset of the triangles that meet it.
    pub fn triangles_near(&self, query: &Aabb, out: &mut Vec<u32>) {
        out.clear();
        self.grid.query(query, out);
    }

    /// Whether some triangle's bounding box overlaps `query` (no triangle near: nothing to touch).
    pub fn has_triangles_near(&self, query: &Aabb) -> bool {
        self.grid.any(query)
    }

    /// Identity map 0..n, so that a face feature can lend out a one-element slice.
    fn triangles_index(&self) -> &[u32] {
        &self.triangle_ids
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> (Vec<DVec3>, Vec<[u32; 3]>) {
        (
            vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        )
    }

    #[test]
    fn adjacency_of_a_square() {
        let (v, t) = square();
        let w = TriangleMesh::new(v, t).unwrap();
        assert_eq!(w.edges().len(), 5);
        assert_eq!(w.normals(), &[DVec3::Z, DVec3::Z]);
        let diagonal = w.triangle_edges()[0][2];
        assert_eq!(w.edges()[diagonal as usize], [0, 2]);
        assert_eq!(w.triangles_of_edge(diagonal), &[0, 1]);
        assert_eq!(w.triangles_of_vertex(0), &[0, 1]);
        assert_eq!(w.triangles_of_vertex(1), &[0]);
        assert_eq!(w.triangles_of_feature(&Feature::Face(1)), &[1]);
        assert!((w.vertex_normal(0) - DVec3::Z).length() < 1e-15);
        assert!(!w.is_closed());
        assert!(!w.is_boundary(&Feature::Edge(diagonal)));
        assert!(w.is_boundary(&Feature::Edge(w.triangle_edges()[0][0])));
        assert!(w.is_boundary(&Feature::Vertex(0)));
        assert!((w.area() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn rejects_bad_input_naming_the_triangle() {
        let (mut v, t) = square();
        assert_eq!(
            TriangleMesh::new(v.clone(), vec![[0, 1, 2], [0, 1, 1]]).unwrap_err(),
            TriangleMeshError::RepeatedCorner {
                triangle: 1,
                index: 1
            }
        );
        assert!(matches!(
            TriangleMesh::new(v.clone(), vec![[0, 1, 9]]),
            Err(TriangleMeshError::IndexOutOfRange {
                triangle: 0,
                index: 9,
                ..
            })
        ));
        v.push(DVec3::new(2.0, 0.0, 0.0));
        let err = TriangleMesh::new(v.clone(), vec![[0, 1, 2], [0, 1, 4]]).unwrap_err();
        assert!(matches!(
            err,
            TriangleMeshError::Degenerate { triangle: 1, .. }
        ));
        assert!(err.to_string().contains("triangle 1"));
        v[4] = DVec3::new(f64::NAN, 0.0, 0.0);
        assert!(matches!(
            TriangleMesh::new(v, t),
            Err(TriangleMeshError::NonFiniteVertex { index: 4, .. })
        ));
        assert_eq!(
            TriangleMesh::new(vec![], vec![]).unwrap_err(),
            TriangleMeshError::Empty
        );
    }

    #[test]
    fn grid_finds_every_triangle_that_a_box_meets() {
        // A fine, tilted, wavy sheet: compare the grid with brute force.
        let n = 20;
        let mut v = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
                v.push(DVec3::new(x, y, 0.3 * x + 0.1 * (7.0 * y).sin()));
            }
        }
        let mut t = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let a = (j * (n + 1) + i) as u32;
                let (b, c, d) = (a + 1, a + n as u32 + 2, a + n as u32 + 1);
                t.push([a, b, c]);
                t.push([a, c, d]);
            }
        }
        let w = TriangleMesh::new(v.clone(), t.clone()).unwrap();
        let mut rng = crate::rng::SplitMix64::new(7);
        let mut found = Vec::new();
        for _ in 0..300 {
            let c = DVec3::new(
                rng.uniform(-0.2, 1.2),
                rng.uniform(-0.2, 1.2),
                rng.uniform(-0.3, 0.6),
            );
            let q = Aabb::around_sphere(c, rng.uniform(0.001, 0.2));
            w.triangles_near(&q, &mut found);
            let brute: Vec<u32> = (0..t.len() as u32)
                .filter(|&i| triangle_bounds(&v, &t[i as usize]).overlaps(&q))
                .collect();
            assert_eq!(found, brute);
        }
    }
}
