//! A closed convex polyhedron in its principal body frame: vertices, polygonal faces with outward
//! normals, edges with their two faces, and a triangulation of the faces.
//!
//! Built from a point cloud: exact convex hull (`geometry::convex_hull`), coplanar hull triangles
//! merged into polygon faces, vertices that are not corners dropped, mass properties computed from
//! the surface, and finally every vertex moved into the principal frame (origin at the centre of
//! mass, axes along the principal axes of inertia), as the integrator expects.

use super::{MassProperties, ShapeError, UnitMassProperties};
use crate::geometry::convex_hull::{convex_hull, FlatPointSet};
use crate::geometry::point_in_polyhedron::{locate_point_in_bounds, Location};
use crate::math::{Aabb, DVec3};
use std::collections::HashMap;

/// Hull triangles are merged into one face when every vertex of one lies within this distance,
/// relative to the diameter of the point cloud, of the plane of the other. Exact coplanarity
/// (`orient3d` = 0) is not used: points computed with irrational coordinates (a dodecahedron's
/// pentagons) are coplanar only up to rounding, and a fold of 10⁻¹⁰ is meaningless for contact
/// mechanics. So faces are planar to within 10⁻¹⁰ of the shape's size.
pub const FACE_MERGE_TOLERANCE: f64 = 1e-10;

/// A planar convex face.
#[derive(Clone, Debug, PartialEq)]
pub struct Face {
    /// Vertex indices, counter-clockwise seen from outside.
    pub vertices: Vec<usize>,
    /// Outward unit normal.
    pub normal: DVec3,
    /// Plane offset: the face lies in `normal · x = offset`.
    pub offset: f64,
}

/// An edge between two faces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Edge {
    pub vertices: [usize; 2],
    /// `faces[0]` runs along the edge from `vertices[0]` to `vertices[1]` in its
    /// counter-clockwise order, `faces[1]` the other way.
    pub faces: [usize; 2],
}

/// A closed convex polyhedron in its principal body frame.
#[derive(Clone, Debug, PartialEq)]
pub struct ConvexPolyhedron {
    vertices: Vec<DVec3>,
    faces: Vec<Face>,
    edges: Vec<Edge>,
    triangles: Vec<[usize; 3]>,
    volume: f64,
    principal_moments: DVec3,
    bounding_radius: f64,
    bounds: Aabb,
}

impl ConvexPolyhedron {
    /// The convex hull of `points`, moved into its principal frame.
    ///
    /// Also returns the mass properties of the hull in the frame of `points` (unit density):
    /// its `center_of_mass` and `principal_rotation()` place the body where the points were,
    /// `point = center_of_mass + principal_rotation() * vertex` (up to rounding).
    ///
    /// Points inside the hull, inside its faces or on its edges are not vertices.
    pub fn from_points(points: &[DVec3]) -> Result<(Self, MassProperties), ShapeError> {
        if points.len() < 4 {
            return Err(ShapeError::TooFewPoints {
                count: points.len(),
            });
        }
        if let Some((index, &point)) = points
            .iter()
            .enumerate()
            .find(|(_, p)| !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()))
        {
            return Err(ShapeError::NonFinite { index, point });
        }
        let hull = convex_hull(points).map_err(|e| match e {
            FlatPointSet::TooFew => ShapeError::TooFewPoints {
                count: points.len(),
            },
            FlatPointSet::Coincident => ShapeError::Coincident,
            FlatPointSet::Collinear => ShapeError::Collinear,
            FlatPointSet::Coplanar => ShapeError::Coplanar,
        })?;
        let (lo, hi) = bounds_of_points(points);
        let size = (hi - lo).length();
        let polygons = merge_coplanar_triangles(points, &hull, FACE_MERGE_TOLERANCE * size)?;
        let polygons = drop_non_corners(polygons)?;

        // Re-index: keep the corners, in the order of the input.
        let mut kept: Vec<usize> = polygons.iter().flatten().copied().collect();
        kept.sort_unstable();
        kept.dedup();
        let new_index: HashMap<usize, usize> =
            kept.iter().enumerate().map(|(n, &o)| (o, n)).collect();
        let polygons: Vec<Vec<usize>> = polygons
            .iter()
            .map(|p| p.iter().map(|o| new_index[o]).collect())
            .collect();
        let input_vertices: Vec<DVec3> = kept.iter().map(|&o| points[o]).collect();
        let triangles = fan_triangulation(&polygons);

        let mass = MassProperties::from_mesh(&input_vertices, &triangles)?;
        // Body frame: x_body = Aᵀ (x − c). With the axes as the matrix A (not the quaternion), an
        // axis-aligned box is only permuted: its coordinates stay exact.
        let axes = mass.principal_axes;
        let vertices: Vec<DVec3> = input_vertices
            .iter()
            .map(|&x| {
                let d = x - mass.center_of_mass;
                DVec3::new(axes.col(0).dot(d), axes.col(1).dot(d), axes.col(2).dot(d))
            })
            .collect();

        let faces = polygons
            .into_iter()
            .enumerate()
            .map(|(index, vertex_list)| face_plane(index, vertex_list, &vertices, size))
            .collect::<Result<Vec<Face>, ShapeError>>()?;
        let edges = edges_of(&faces)?;
        let (lo, hi) = bounds_of_points(&vertices);
        let polyhedron = Self {
            bounding_radius: vertices.iter().map(|v| v.length()).fold(0.0, f64::max),
            bounds: Aabb::new(lo, hi),
            vertices,
            faces,
            edges,
            triangles,
            volume: mass.volume,
            principal_moments: mass.principal_moments,
        };
        Ok((polyhedron, mass))
    }

    pub fn vertices(&self) -> &[DVec3] {
        &self.vertices
    }

    pub fn faces(&self) -> &[Face] {
        &self.faces
    }

    pub fn edges(&self) -> &[Edge] {
        &self.edges
    }

    /// The faces split into triangles (fans from each face's first vertex), outward.
    pub fn triangles(&self) -> &[[usize; 3]] {
        &self.triangles
    }

    /// Axis-aligned bounds in the body frame.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Volume and principal moments of inertia at unit density.
    pub fn unit_mass_properties(&self) -> UnitMassProperties {
        UnitMassProperties {
            volume: self.volume,
            principal_inertia_per_density: self.principal_moments,
        }
    }

    /// Radius of the smallest sphere about the centre of mass that contains the shape.
    pub fn bounding_radius(&self) -> f64 {
        self.bounding_radius
    }

    /// The same shape scaled by `factor` about its centre of mass.
    ///
    /// # Panics
    /// If `factor` is not a positive finite number.
    pub fn scaled(&self, factor: f64) -> Self {
        assert!(
            factor > 0.0 && factor.is_finite(),
            "scale factor must be positive and finite, got {factor}"
        );
        Self {
            vertices: self.vertices.iter().map(|&v| v * factor).collect(),
            faces: self
                .faces
                .iter()
                .map(|f| Face {
                    vertices: f.vertices.clone(),
                    normal: f.normal,
                    offset: f.offset * factor,
                })
                .collect(),
            edges: self.edges.clone(),
            triangles: self.triangles.clone(),
            volume: self.volume * factor.powi(3),
            principal_moments: self.principal_moments * factor.powi(5),
            bounding_radius: self.bounding_radius * factor,
            bounds: Aabb::new(self.bounds.min * factor, self.bounds.max * factor),
        }
    }

    /// Index of the vertex farthest along `direction` (the first of equals): the support mapping
    /// that GJK and separating-axis tests are built on.
    pub fn support_index(&self, direction: DVec3) -> usize {
        let mut best = (0, f64::NEG_INFINITY);
        for (i, v) in self.vertices.iter().enumerate() {
            let d = v.dot(direction);
            if d > best.1 {
                best = (i, d);
            }
        }
        best.0
    }

    /// The vertex farthest along `direction`.
    pub fn support(&self, direction: DVec3) -> DVec3 {
        self.vertices[self.support_index(direction)]
    }

    /// Where a body-frame point lies relative to the polyhedron (exact ray casting over its
    /// triangles, see `geometry::point_in_polyhedron`).
    pub fn locate(&self, point: DVec3) -> Location {
        locate_point_in_bounds(point, &self.vertices, &self.triangles, &self.bounds)
    }
}

fn bounds_of_points(points: &[DVec3]) -> (DVec3, DVec3) {
    points
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        })
}

/// Groups hull triangles into planar faces and returns each face's boundary polygon
/// (counter-clockwise seen from outside), as indices into `points`.
///
/// Greedy flood fill: the largest triangle not yet taken seeds a face (its normal is the most
/// accurate); neighbours across the face's edges join while all their vertices lie within
/// `tolerance` of the seed's plane and they face the same way.
fn merge_coplanar_triangles(
    points: &[DVec3],
    hull: &[[usize; 3]],
    tolerance: f64,
) -> Result<Vec<Vec<usize>>, ShapeError> {
    let mut owner: HashMap<(usize, usize), usize> = HashMap::new();
    for (t, tri) in hull.iter().enumerate() {
        for k in 0..3 {
            owner.insert((tri[k], tri[(k + 1) % 3]), t);
        }
    }
    let twin = |a: usize, b: usize| owner[&(b, a)];
    let normal = |t: usize| {
        let [a, b, c] = hull[t].map(|i| points[i]);
        (b - a).cross(c - a)
    };
    let mut order: Vec<usize> = (0..hull.len()).collect();
    order.sort_by(|&s, &t| {
        normal(t)
            .length()
            .total_cmp(&normal(s).length())
            .then(s.cmp(&t))
    });

    const FREE: usize = usize::MAX;
    let mut group = vec![FREE; hull.len()];
    let mut members_of: Vec<Vec<usize>> = Vec::new();
    for seed in order {
        if group[seed] != FREE {
            continue;
        }
        let g = members_of.len();
        let n = normal(seed).normalize();
        let origin = points[hull[seed][0]];
        group[seed] = g;
        let mut members = vec![seed];
        let mut stack = vec![seed];
        while let Some(t) = stack.pop() {
            for k in 0..3 {
                let nb = twin(hull[t][k], hull[t][(k + 1) % 3]);
                let flat = hull[nb]
                    .iter()
                    .all(|&i| n.dot(points[i] - origin).abs() <= tolerance);
                if group[nb] == FREE && flat && normal(nb).dot(n) > 0.0 {
                    group[nb] = g;
                    members.push(nb);
                    stack.push(nb);
                }
            }
        }
        members.sort_unstable();
        members_of.push(members);
    }

    // Each face's boundary: its triangles' edges whose twins belong to other faces, chained.
    let mut polygons = Vec::with_capacity(members_of.len());
    for (g, members) in members_of.iter().enumerate() {
        let mut next: HashMap<usize, usize> = HashMap::new();
        let mut start = usize::MAX;
        for &t in members {
            for k in 0..3 {
                let (a, b) = (hull[t][k], hull[t][(k + 1) % 3]);
                if group[twin(a, b)] != g {
                    if next.insert(a, b).is_some() {
                        return Err(ShapeError::MalformedFace { triangle: t });
                    }
                    start = start.min(a);
                }
            }
        }
        let mut polygon = vec![start];
        let mut current = next[&start];
        while current != start && polygon.len() <= next.len() {
            polygon.push(current);
            current = next[&current];
        }
        if polygon.len() != next.len() {
            return Err(ShapeError::MalformedFace {
                triangle: members[0],
            });
        }
        polygons.push(polygon);
    }
    Ok(polygons)
}

/// Removes from the polygons every vertex that lies on fewer than three faces: it sits inside an
/// edge of the polytope (two faces), so it is no corner. (Vertices inside a face are already
/// absent from the boundaries.)
fn drop_non_corners(polygons: Vec<Vec<usize>>) -> Result<Vec<Vec<usize>>, ShapeError> {
    let mut face_count: HashMap<usize, usize> = HashMap::new();
    for &v in polygons.iter().flatten() {
        *face_count.entry(v).or_default() += 1;
    }
    let polygons: Vec<Vec<usize>> = polygons
        .into_iter()
        .map(|p| p.into_iter().filter(|v| face_count[v] >= 3).collect())
        .collect();
    if let Some(face) = polygons.iter().position(|p: &Vec<usize>| p.len() < 3) {
        return Err(ShapeError::DegenerateFace {
            face,
            area: 0.0,
            size: 0.0,
        });
    }
    Ok(polygons)
}

/// Fans from each polygon's first vertex (the polygons are convex).
fn fan_triangulation(polygons: &[Vec<usize>]) -> Vec<[usize; 3]> {
    polygons
        .iter()
        .flat_map(|p| (1..p.len() - 1).map(move |i| [p[0], p[i], p[i + 1]]))
        .collect()
}

/// The face's outward unit normal by Newell's method (the polygon's vector area, Sutherland,
/// Sproull & Schumacker 1974; the best-fit normal for a slightly non-planar polygon) and the
/// plane offset as the mean over its vertices.
fn face_plane(
    index: usize,
    vertex_list: Vec<usize>,
    vertices: &[DVec3],
    size: f64,
) -> Result<Face, ShapeError> {
    let v0 = vertices[vertex_list[0]];
    let mut vector_area = DVec3::ZERO;
    for w in vertex_list.windows(2).skip(1) {
        vector_area += (vertices[w[0]] - v0).cross(vertices[w[1]] - v0);
    }
    let area = 0.5 * vector_area.length();
    // Zero area means: zero up to the rounding of coordinates of this size.
    if area.is_nan() || area <= f64::EPSILON * size * size {
        return Err(ShapeError::DegenerateFace {
            face: index,
            area,
            size,
        });
    }
    let normal = vector_area.normalize();
    let offset = vertex_list
        .iter()
        .map(|&i| normal.dot(vertices[i]))
        .sum::<f64>()
        / vertex_list.len() as f64;
    Ok(Face {
        vertices: vertex_list,
        normal,
        offset,
    })
}

/// Each undirected edge once, in order of first appearance, with its two faces.
fn edges_of(faces: &[Face]) -> Result<Vec<Edge>, ShapeError> {
    let mut index: HashMap<(usize, usize), usize> = HashMap::new();
    let mut edges: Vec<Edge> = Vec::new();
    const NONE: usize = usize::MAX;
    for (f, face) in faces.iter().enumerate() {
        let n = face.vertices.len();
        for k in 0..n {
            let (a, b) = (face.vertices[k], face.vertices[(k + 1) % n]);
            match index.get(&(b, a)) {
                Some(&e) if edges[e].faces[1] == NONE => edges[e].faces[1] = f,
                Some(_) => return Err(ShapeError::MalformedFace { triangle: f }),
                None => {
                    index.insert((a, b), edges.len());
                    edges.push(Edge {
                        vertices: [a, b],
                        faces: [f, NONE],
                    });
                }
            }
        }
    }
    if edges.iter().any(|e| e.faces[1] == NONE) {
        return Err(ShapeError::MalformedFace { triangle: 0 });
    }
    Ok(edges)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::predicates::orient3d;
    use crate::math::{DMat3, DQuat};
    use crate::rng::SplitMix64;
    use proptest::prelude::*;

    /// Structural invariants of any polyhedron built here.
    pub(crate) fn check_invariants(p: &ConvexPolyhedron) {
        let (v, f, e) = (p.vertices().len(), p.faces().len(), p.edges().len());
        assert_eq!(v as i64 - e as i64 + f as i64, 2, "Euler characteristic");
        let scale = p.bounding_radius();
        for face in p.faces() {
            assert!((face.normal.length() - 1.0).abs() < 1e-14);
            for &i in &face.vertices {
                assert!((face.normal.dot(p.vertices()[i]) - face.offset).abs() < 1e-9 * scale);
            }
            // Outward: every vertex on the inner side of every face plane.
            for x in p.vertices() {
                assert!(face.normal.dot(*x) <= face.offset + 1e-9 * scale);
            }
            // Convex polygon, counter-clockwise about the outward normal.
            let n = face.vertices.len();
            for k in 0..n {
                let [a, b, c] =
                    [k, (k + 1) % n, (k + 2) % n].map(|j| p.vertices()[face.vertices[j]]);
                assert!((b - a).cross(c - b).dot(face.normal) > 0.0);
            }
        }
        for edge in p.edges() {
            for (side, &fi) in edge.faces.iter().enumerate() {
                let fv = &p.faces()[fi].vertices;
                let pos = fv.iter().position(|&x| x == edge.vertices[side]).unwrap();
                assert_eq!(fv[(pos + 1) % fv.len()], edge.vertices[1 - side]);
            }
        }
        // Every vertex is a corner: at least three faces.
        for i in 0..v {
            assert!(p.faces().iter().filter(|f| f.vertices.contains(&i)).count() >= 3);
        }
        // In the principal frame: centre of mass at the origin, diagonal inertia (recomputed).
        let m = MassProperties::from_mesh(p.vertices(), p.triangles()).unwrap();
        assert!(m.center_of_mass.length() < 1e-12 * scale);
        let i = m.inertia;
        let off = i.col(0).y.abs() + i.col(0).z.abs() + i.col(1).z.abs();
        assert!(off < 1e-12 * m.principal_moments.z, "{i:?}");
        let diag = DVec3::new(i.col(0).x, i.col(1).y, i.col(2).z);
        assert!(
            (diag - p.unit_mass_properties().principal_inertia_per_density)
                .abs()
                .max_element()
                < 1e-12 * diag.z
        );
        assert!(diag.x <= diag.y * (1.0 + 1e-12) && diag.y <= diag.z * (1.0 + 1e-12));
    }

    #[test]
    fn cube_from_a_grid_drops_non_corners() {
        // 27 grid points: 8 corners, 12 edge midpoints, 6 face centres, 1 centre.
        let pts: Vec<DVec3> = (0..27)
            .map(|i| DVec3::new((i % 3) as f64, ((i / 3) % 3) as f64, (i / 9) as f64))
            .collect();
        let (p, mass) = ConvexPolyhedron::from_points(&pts).unwrap();
        check_invariants(&p);
        assert_eq!(
            (p.vertices().len(), p.edges().len(), p.faces().len()),
            (8, 12, 6)
        );
        assert!(p.faces().iter().all(|f| f.vertices.len() == 4));
        assert_eq!(p.triangles().len(), 12);
        assert!((mass.volume - 8.0).abs() < 1e-13);
        assert!((mass.center_of_mass - DVec3::ONE).length() < 1e-14);
        // Axis-aligned: the vertices stay exactly ±1 (up to the centroid's rounding, zero here).
        for x in p.vertices() {
            assert!((x.abs() - DVec3::ONE).abs().max_element() < 1e-15);
        }
        assert!((p.bounding_radius() - 3f64.sqrt()).abs() < 1e-14);
    }

    #[test]
    fn frame_places_the_body_where_the_points_were() {
        let mut rng = SplitMix64::new(5);
        let q0 = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
        let pts: Vec<DVec3> = (0..60)
            .map(|_| {
                q0 * DVec3::new(3.0 * rng.normal(), rng.normal(), 0.5 * rng.normal())
                    + DVec3::new(10.0, -4.0, 2.0)
            })
            .collect();
        let (p, mass) = ConvexPolyhedron::from_points(&pts).unwrap();
        check_invariants(&p);
        let q = mass.principal_rotation();
        for &v in p.vertices() {
            let x = mass.center_of_mass + q * v;
            let nearest = pts
                .iter()
                .map(|&y| (y - x).length())
                .fold(f64::INFINITY, f64::min);
            assert!(nearest < 1e-12, "{nearest}");
        }
        // Inertia tensor in the input frame is A diag(moments) Aᵀ.
        let a = mass.principal_axes;
        let rebuilt = a * DMat3::from_diagonal(mass.principal_moments) * a.transpose();
        let diff = rebuilt - mass.inertia;
        assert!((0..3).all(|j| diff.col(j).abs().max_element() < 1e-11 * mass.principal_moments.z));
    }

    #[test]
    fn errors_are_specific() {
        let p = DVec3::new(0.5, 1.5, -2.0);
        let e = |pts: &[DVec3]| ConvexPolyhedron::from_points(pts).unwrap_err();
        assert_eq!(e(&[p; 3]), ShapeError::TooFewPoints { count: 3 });
        assert_eq!(e(&[p; 6]), ShapeError::Coincident);
        let line: Vec<DVec3> = (0..5).map(|i| p * i as f64).collect();
        assert_eq!(e(&line), ShapeError::Collinear);
        let plane: Vec<DVec3> = (0..6)
            .map(|i| DVec3::new(i as f64, (i * i) as f64, 1.0))
            .collect();
        assert_eq!(e(&plane), ShapeError::Coplanar);
        let mut bad = plane.clone();
        bad[4].y = f64::NAN;
        assert!(matches!(e(&bad), ShapeError::NonFinite { index: 4, .. }));
        let message = e(&plane).to_string();
        assert!(message.contains("one plane"), "{message}");
    }

    #[test]
    fn support_and_scaling() {
        let pts: Vec<DVec3> = (0..8)
            .map(|k| {
                DVec3::new(
                    (k & 1) as f64 * 2.0,
                    ((k >> 1) & 1) as f64 * 4.0,
                    ((k >> 2) & 1) as f64 * 6.0,
                )
            })
            .collect();
        let (p, _) = ConvexPolyhedron::from_points(&pts).unwrap();
        // Principal frame of a 2×4×6 box: x along the longest side (smallest moment).
        assert_eq!(
            p.support(DVec3::new(1.0, 0.1, 0.1)),
            DVec3::new(3.0, 2.0, 1.0)
        );
        assert_eq!(p.support(-DVec3::ONE), DVec3::new(-3.0, -2.0, -1.0));
        for dir in [
            DVec3::X,
            DVec3::new(-0.3, 0.2, 0.9),
            DVec3::new(0.0, -1.0, 1e-9),
        ] {
            let s = p.support(dir);
            assert!(p.vertices().iter().all(|v| v.dot(dir) <= s.dot(dir)));
        }
        let big = p.scaled(2.0);
        check_invariants(&big);
        let (u, v) = (p.unit_mass_properties(), big.unit_mass_properties());
        assert!((v.volume - 8.0 * u.volume).abs() < 1e-12 * v.volume);
        assert!(
            (v.principal_inertia_per_density - 32.0 * u.principal_inertia_per_density)
                .abs()
                .max_element()
                < 1e-10
        );
        assert_eq!(big.bounding_radius(), 2.0 * p.bounding_radius());
    }

    /// `locate` on boxes, whose body-frame coordinates stay exact, against the exact half-space
    /// reference over the polyhedron's own triangles: corners, edge and face points (axis-aligned,
    /// so exactly on the surface), just inside/outside, and points sharing coordinates with
    /// vertices.
    #[test]
    fn locate_on_boxes_is_exact() {
        let mut checked = 0;
        for (a, b, c) in [
            (1.0, 1.0, 1.0),
            (1.0, 2.0, 3.0),
            (0.3, 0.7, 0.1),
            (5.0, 5.0, 0.5),
        ] {
            let pts: Vec<DVec3> = (0..8)
                .map(|k| {
                    DVec3::new(
                        (k & 1) as f64 * a,
                        ((k >> 1) & 1) as f64 * b,
                        ((k >> 2) & 1) as f64 * c,
                    )
                })
                .collect();
            let (p, _) = ConvexPolyhedron::from_points(&pts).unwrap();
            let (lo, hi) = (p.bounds().min, p.bounds().max);
            let coords = |i: usize| {
                let (l, h) = (lo[i], hi[i]);
                let ulp = |x: f64| x.abs().max(1e-300) * f64::EPSILON;
                [
                    l - 1.0,
                    l - ulp(l),
                    l,
                    l + ulp(l),
                    0.5 * (l + h),
                    0.3 * l + 0.7 * h,
                    h - ulp(h),
                    h,
                    h + ulp(h),
                    h + 0.25,
                ]
            };
            for x in coords(0) {
                for y in coords(1) {
                    for z in coords(2) {
                        let q = DVec3::new(x, y, z);
                        let mut expected = Location::Inside;
                        for &[i, j, k] in p.triangles() {
                            let s = orient3d(p.vertices()[i], p.vertices()[j], p.vertices()[k], q);
                            if s > 0.0 {
                                expected = Location::Outside;
                                break;
                            }
                            if s == 0.0 {
                                expected = Location::OnSurface;
                            }
                        }
                        assert_eq!(p.locate(q), expected, "{q}");
                        checked += 1;
                    }
                }
            }
        }
        assert_eq!(checked, 4000);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        #[test]
        fn random_clouds_give_valid_polyhedra(seed in any::<u64>(), n in 4usize..200) {
            let mut rng = SplitMix64::new(seed);
            let pts: Vec<DVec3> = (0..n)
                .map(|_| {
                    DVec3::new(
                        rng.uniform(-1.0, 1.0),
                        rng.uniform(-2.0, 2.0),
                        rng.uniform(-0.5, 0.5),
                    )
                })
                .collect();
            let (p, _) = ConvexPolyhedron::from_points(&pts).unwrap();
            check_invariants(&p);
        }

        /// Integer clouds: many exactly coplanar triangles and non-corner points to merge.
        #[test]
        fn integer_clouds_give_valid_polyhedra(seed in any::<u64>(), n in 8usize..80) {
            let mut rng = SplitMix64::new(seed);
            let pts: Vec<DVec3> = (0..n)
                .map(|_| {
                    let mut c = |m: u64| (rng.next_u64() % m) as f64;
                    DVec3::new(c(4), c(3), c(5))
                })
                .collect();
            match ConvexPolyhedron::from_points(&pts) {
                Ok((p, _)) => check_invariants(&p),
                Err(e) => {
                    let flat = matches!(e, ShapeError::Coplanar | ShapeError::Collinear);
                    prop_assert!(flat, "{}", e);
                }
            }
        }
    }
}
