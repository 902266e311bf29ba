//! A convex particle from a closed triangle mesh (an imported STL or OBJ file).
//!
//! The particle is always a [`ConvexPolyhedron`] built from the mesh's vertices; the question this
//! module answers is whether that hull *is* the mesh, i.e. whether the mesh is convex. Unless the
//! caller asks for the hull regardless, a mesh is accepted as convex when
//!
//! 1. it is a closed, consistently oriented surface: every edge is shared by exactly two
//!    triangles that run along it in opposite directions (otherwise it bounds no definite solid and
//!    its volume means nothing). Inward-facing meshes are turned outward;
//! 2. its volume (divergence theorem, [`MassProperties::from_mesh`]) equals that of its convex
//!    hull to within [`CONVEXITY_VOLUME_TOLERANCE`] relative. A closed surface lies inside its
//!    hull, so a dent, a groove or a re-entrant corner of any shape makes the hull larger; and
//! 3. no vertex lies deeper inside the hull than [`CONVEXITY_DEPTH_TOLERANCE`] × the diagonal of
//!    the mesh's bounding box. This catches thin inward spikes that cost too little volume for
//!    test 2.
//!
//! Both tolerances are far above the rounding of single-precision STL coordinates (≈ 6·10⁻⁸
//! relative), so a convex mesh with flat faces split into many coplanar triangles passes, and far
//! below any non-convexity that matters mechanically.

use super::{ConvexPolyhedron, MassProperties, ShapeError};
use crate::math::DVec3;
use std::collections::HashMap;
use thiserror::Error;

/// Largest relative excess of the hull's volume over the mesh's for a mesh taken as convex.
pub const CONVEXITY_VOLUME_TOLERANCE: f64 = 1e-6;

/// Largest depth of a vertex inside the hull, relative to the mesh's bounding-box diagonal, for a
/// mesh taken as convex.
pub const CONVEXITY_DEPTH_TOLERANCE: f64 = 1e-6;

/// A convex polyhedron made from a mesh.
#[derive(Clone, Debug)]
pub struct ConvexFromMesh {
    pub polyhedron: ConvexPolyhedron,
    /// Mass properties of the hull in the mesh's frame, as [`ConvexPolyhedron::from_points`]
    /// returns them.
    pub mass: MassProperties,
    /// How much larger the hull's volume is than the mesh's, relative (0 for a convex mesh);
    /// `None` when the hull was asked for and the mesh does not bound a definite solid.
    pub hull_excess: Option<f64>,
}

#[derive(Clone, Debug, Error, PartialEq)]
pub enum MeshShapeError {
    #[error(transparent)]
    Shape(#[from] ShapeError),
    #[error(
        "the mesh is not closed: the edge between vertices {a} and {b} belongs to {count} \
         triangle(s), not 2"
    )]
    NotClosed { a: usize, b: usize, count: usize },
    #[error(
        "the mesh is not consistently oriented: both triangles at the edge between vertices {a} \
         and {b} run along it the same way (one of them is turned over)"
    )]
    Inconsistent { a: usize, b: usize },
    #[error(
        "the mesh encloses {mesh_volume:e}, more than its convex hull ({hull_volume:e}): it \
         intersects itself"
    )]
    SelfIntersecting { mesh_volume: f64, hull_volume: f64 },
    #[error("{}", not_convex_message(*hull_excess, *deepest))]
    NotConvex {
        /// (hull volume − mesh volume) / mesh volume.
        hull_excess: f64,
        /// The vertex lying deepest inside the hull, its position and depth, when that depth is
        /// beyond the tolerance.
        deepest: Option<(usize, DVec3, f64)>,
    },
}

fn not_convex_message(hull_excess: f64, deepest: Option<(usize, DVec3, f64)>) -> String {
    let mut s = format!(
        "the mesh is not convex (its convex hull is {} % larger",
        percent(hull_excess)
    );
    if let Some((index, p, depth)) = deepest {
        s += &format!(
            "; vertex {index} at [{}, {}, {}] lies {depth:.3e} inside the hull",
            p.x, p.y, p.z
        );
    }
    s + ")"
}

/// A relative excess as a percentage with three significant digits ("23.4", "0.0153").
pub fn percent(relative: f64) -> String {
    let p = 100.0 * relative;
    if p >= 10.0 {
        format!("{p:.1}")
    } else if p >= 1.0 {
        format!("{p:.2}")
    } else {
        format!("{}", format!("{p:.3e}").parse::<f64>().unwrap_or(p))
    }
}

/// The convex polyhedron of a closed triangle mesh.
///
/// With `use_hull` false the mesh must be convex (see the module documentation) and the result is
/// the mesh itself; with `use_hull` true it is the convex hull of the vertices, whatever the mesh.
/// Either way, fewer than 4 vertices, a flat mesh or non-finite coordinates are refused.
pub fn convex_from_mesh(
    vertices: &[DVec3],
    triangles: &[[usize; 3]],
    use_hull: bool,
) -> Result<ConvexFromMesh, MeshShapeError> {
    let (polyhedron, mass) = ConvexPolyhedron::from_points(vertices)?;
    let closed = check_closed(triangles);
    if use_hull {
        let hull_excess = match closed {
            Ok(()) => mesh_volume(vertices, triangles)
                .ok()
                .map(|v| mass.volume / v - 1.0),
            Err(_) => None,
        };
        return Ok(ConvexFromMesh {
            polyhedron,
            mass,
            hull_excess,
        });
    }
    closed?;
    let volume = mesh_volume(vertices, triangles)?;
    let hull_excess = mass.volume / volume - 1.0;
    if hull_excess < -CONVEXITY_VOLUME_TOLERANCE {
        return Err(MeshShapeError::SelfIntersecting {
            mesh_volume: volume,
            hull_volume: mass.volume,
        });
    }
    let deepest = deepest_vertex(vertices, &polyhedron, &mass);
    let size = diagonal(vertices);
    let deep = deepest.filter(|&(_, _, depth)| depth > CONVEXITY_DEPTH_TOLERANCE * size);
    if hull_excess > CONVEXITY_VOLUME_TOLERANCE || deep.is_some() {
        return Err(MeshShapeError::NotConvex {
            hull_excess: hull_excess.max(0.0),
            deepest: deep,
        });
    }
    Ok(ConvexFromMesh {
        polyhedron,
        mass,
        hull_excess: Some(hull_excess.max(0.0)),
    })
}

/// Every edge shared by exactly two triangles running along it in opposite directions. The first
/// offending edge in triangle order is reported.
fn check_closed(triangles: &[[usize; 3]]) -> Result<(), MeshShapeError> {
    // Per undirected edge: (triangles using it, net direction: +1 for a→b with a < b, −1 back).
    let mut edges: HashMap<(usize, usize), (usize, i64)> = HashMap::new();
    let directed = |t: &[usize; 3]| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])];
    for t in triangles {
        for (a, b) in directed(t) {
            let entry = edges.entry((a.min(b), a.max(b))).or_default();
            entry.0 += 1;
            entry.1 += if a < b { 1 } else { -1 };
        }
    }
    for t in triangles {
        for (a, b) in directed(t) {
            let (lo, hi) = (a.min(b), a.max(b));
            let (count, net) = edges[&(lo, hi)];
            if count != 2 {
                return Err(MeshShapeError::NotClosed {
                    a: lo,
                    b: hi,
                    count,
                });
            }
            if net != 0 {
                return Err(MeshShapeError::Inconsistent { a: lo, b: hi });
            }
        }
    }
    Ok(())
}

/// The volume a closed, consistently oriented mesh encloses, whichever way it faces.
fn mesh_volume(vertices: &[DVec3], triangles: &[[usize; 3]]) -> Result<f64, ShapeError> {
    match MassProperties::from_mesh(vertices, triangles) {
        Ok(m) => Ok(m.volume),
        Err(ShapeError::NonPositiveVolume { .. }) => {
            let turned: Vec<[usize; 3]> = triangles.iter().map(|&[a, b, c]| [a, c, b]).collect();
            MassProperties::from_mesh(vertices, &turned).map(|m| m.volume)
        }
        Err(e) => Err(e),
    }
}

/// The vertex deepest inside the hull (the first of equals) and its depth: the distance to the
/// nearest face plane, negative outside.
fn deepest_vertex(
    vertices: &[DVec3],
    hull: &ConvexPolyhedron,
    mass: &MassProperties,
) -> Option<(usize, DVec3, f64)> {
    let axes = mass.principal_axes;
    vertices
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            // Into the hull's body frame, as `from_points` moved its vertices.
            let d = p - mass.center_of_mass;
            let b = DVec3::new(axes.col(0).dot(d), axes.col(1).dot(d), axes.col(2).dot(d));
            let depth = hull
                .faces()
                .iter()
                .map(|f| f.offset - f.normal.dot(b))
                .fold(f64::INFINITY, f64::min);
            (i, p, depth)
        })
        .fold(None, |best: Option<(usize, DVec3, f64)>, v| match best {
            Some(b) if b.2 >= v.2 => Some(b),
            _ => Some(v),
        })
}

fn diagonal(vertices: &[DVec3]) -> f64 {
    let (lo, hi) = vertices
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    (hi - lo).length()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::test_meshes::{box_mesh, flipped, l_shape_mesh};

    #[test]
    fn a_box_is_convex_whichever_way_it_faces() {
        let (v, t) = box_mesh(DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0));
        for triangles in [t.clone(), flipped(&t)] {
            let c = convex_from_mesh(&v, &triangles, false).unwrap();
            assert!((c.mass.volume - 6.0).abs() < 1e-12);
            assert!(c.hull_excess.unwrap() < 1e-12);
            assert_eq!(c.polyhedron.faces().len(), 6);
        }
    }

    #[test]
    fn the_l_shape_is_refused_unless_the_hull_is_asked_for() {
        let (v, t) = l_shape_mesh();
        let e = convex_from_mesh(&v, &t, false).unwrap_err();
        let MeshShapeError::NotConvex { hull_excess, .. } = e else {
            panic!("{e}")
        };
        // Hull: the 2 × 2 square less the corner triangle, 3.5, against 3.
        assert!((hull_excess - 0.5 / 3.0).abs() < 1e-12);
        assert!(e.to_string().contains("16.7 % larger"), "{e}");
        let hull = convex_from_mesh(&v, &t, true).unwrap();
        assert!((hull.mass.volume - 3.5).abs() < 1e-12);
        assert!((hull.hull_excess.unwrap() - 0.5 / 3.0).abs() < 1e-12);
    }

    #[test]
    fn a_thin_inward_spike_is_caught_by_the_vertex_test() {
        // A unit cube whose top face is a flat pyramid pushed in by d = 2.5e-6 at its centre: it
        // loses d / 3 ≈ 8e-7 of its volume, within the volume tolerance, but the apex lies deeper
        // than the depth tolerance (1e-6 × √3).
        let (mut v, t) = box_mesh(DVec3::ZERO, DVec3::ONE);
        let top = [4, 5, 7, 6];
        let apex = v.len();
        v.push(DVec3::new(0.5, 0.5, 1.0 - 2.5e-6));
        let mut triangles: Vec<[usize; 3]> = t
            .into_iter()
            .filter(|tri| !tri.iter().all(|i| top.contains(i)))
            .collect();
        for k in 0..4 {
            triangles.push([top[k], top[(k + 1) % 4], apex]);
        }
        let e = convex_from_mesh(&v, &triangles, false).unwrap_err();
        let MeshShapeError::NotConvex {
            hull_excess,
            deepest,
        } = e
        else {
            panic!("{e}")
        };
        let (index, _, depth) = deepest.unwrap();
        assert_eq!(index, apex);
        assert!((depth - 2.5e-6).abs() < 1e-12);
        assert!(hull_excess < CONVEXITY_VOLUME_TOLERANCE);
    }

    #[test]
    fn open_and_inconsistent_meshes_are_refused() {
        let (v, t) = box_mesh(DVec3::ZERO, DVec3::ONE);
        let open = &t[1..];
        assert!(matches!(
            convex_from_mesh(&v, open, false),
            Err(MeshShapeError::NotClosed { count: 1, .. })
        ));
        // The hull of an open mesh is still available.
        assert!(convex_from_mesh(&v, open, true)
            .unwrap()
            .hull_excess
            .is_none());
        let mut turned = t.clone();
        turned[0] = [turned[0][0], turned[0][2], turned[0][1]];
        assert!(matches!(
            convex_from_mesh(&v, &turned, false),
            Err(MeshShapeError::Inconsistent { .. })
        ));
    }

    #[test]
    fn flat_and_tiny_meshes_are_refused() {
        let square = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)];
        let t = [[0, 1, 3], [0, 3, 2], [0, 3, 1], [0, 2, 3]];
        assert_eq!(
            convex_from_mesh(&square, &t, true).unwrap_err(),
            MeshShapeError::Shape(ShapeError::Coplanar)
        );
        assert!(matches!(
            convex_from_mesh(&square[..3], &[[0, 1, 2]], true),
            Err(MeshShapeError::Shape(ShapeError::TooFewPoints { count: 3 }))
        ));
    }

    #[test]
    fn percentages_keep_three_digits() {
        assert_eq!(percent(0.234), "23.4");
        assert_eq!(percent(0.01234), "1.23");
        assert_eq!(percent(0.000153), "0.0153");
    }
}
