//! A convex polyhedron against a sphere.
//!
//! Worked in the polyhedron's body frame. With the sphere's centre c outside the polyhedron the
//! contact is at the point p of the polyhedron closest to c (in a face, on an edge or at a vertex,
//! whichever region c is in): depth = r − |c − p|, normal along p − c. With c inside, the sphere
//! is pushed out through the nearest face plane: depth = r + (distance of c to that plane), normal
//! the face's inward normal (the force on the polyhedron points away from the sphere, into itself
//! on that side).
//!
//! The overlap volume is taken as the spherical cap of height `depth`, πh²(3r − h)/3. It is exact
//! when the sphere crosses one face plane only and the cut circle lies inside that face (the
//! common case, a sphere on a face). Near an edge or a vertex the true overlap is the sphere cut
//! by two or more planes, smaller than the cap of the same depth (a wedge or a corner of it); the
//! cap is an approximation there, continuous with the face case and of the right order (it is the
//! overlap of the sphere with the half-space behind the tangent plane at p).

use crate::math::{DQuat, DVec3};
use crate::shape::ConvexPolyhedron;
use std::f64::consts::PI;

/// A sphere's overlap with a polyhedron.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereContact {
    /// Unit normal from the sphere (the second argument) towards the polyhedron: the direction of
    /// the force on the polyhedron.
    pub normal: DVec3,
    /// The middle of the overlap along the normal, half-way between the polyhedron's surface point
    /// and the sphere's deepest point [m].
    pub point: DVec3,
    /// Penetration depth > 0 [m].
    pub depth: f64,
    /// Overlap volume: the spherical cap of height `depth` (see the module notes) [m³].
    pub volume: f64,
}

/// Volume of the cap of height `h` (0 ≤ h ≤ 2r) of a sphere of radius `r`.
pub fn spherical_cap_volume(r: f64, h: f64) -> f64 {
    let h = h.clamp(0.0, 2.0 * r);
    PI * h * h * (3.0 * r - h) / 3.0
}

/// Polyhedron `a` (centre `xa`, orientation `qa`) against the sphere at `centre` with `radius`.
/// `None` when they do not overlap (touching included).
pub fn convex_sphere(
    a: &ConvexPolyhedron,
    xa: DVec3,
    qa: DQuat,
    centre: DVec3,
    radius: f64,
) -> Option<SphereContact> {
    let reach = a.bounding_radius() + radius;
    if (centre - xa).length_squared() >= reach * reach {
        return None;
    }
    let c = qa.inverse() * (centre - xa);
    let faces = a.faces();
    let vertices = a.vertices();
    // The face plane the centre is farthest in front of (or, inside, least behind).
    let (mut nearest, mut height) = (0, f64::NEG_INFINITY);
    for (k, f) in faces.iter().enumerate() {
        let d = f.normal.dot(c) - f.offset;
        if d > height {
            (nearest, height) = (k, d);
        }
    }
    if height >= radius {
        return None;
    }
    let (normal_body, depth) = if height <= 0.0 {
        (-faces[nearest].normal, radius - height)
    } else {
        // Outside: the closest point lies in a face that c is in front of.
        let mut best = (f64::INFINITY, DVec3::ZERO);
        for f in faces {
            let d = f.normal.dot(c) - f.offset;
            if d <= 0.0 || d >= best.0.sqrt() {
                continue;
            }
            let p = closest_point_in_face(c, d, f.normal, &f.vertices, vertices);
            let distance_squared = (p - c).length_squared();
            if distance_squared < best.0 {
                best = (distance_squared, p);
            }
        }
        let distance = best.0.sqrt();
        if distance >= radius {
            return None;
        }
        ((best.1 - c) / distance, radius - distance)
    };
    let normal = qa * normal_body;
    Some(SphereContact {
        normal,
        point: centre + normal * (radius - 0.5 * depth),
        depth,
        volume: spherical_cap_volume(radius, depth),
    })
}

/// The point of the convex face polygon (corners `indices` counter-clockwise about `normal`)
/// closest to `c`, which is at height `d` above the face's plane.
fn closest_point_in_face(
    c: DVec3,
    d: f64,
    normal: DVec3,
    indices: &[usize],
    vertices: &[DVec3],
) -> DVec3 {
    let projected = c - normal * d;
    let m = indices.len();
    let inside = (0..m).all(|k| {
        let (u, v) = (vertices[indices[k]], vertices[indices[(k + 1) % m]]);
        (v - u).cross(projected - u).dot(normal) >= 0.0
    });
    if inside {
        return projected;
    }
    let mut best = (f64::INFINITY, projected);
    for k in 0..m {
        let (u, v) = (vertices[indices[k]], vertices[indices[(k + 1) % m]]);
        let e = v - u;
        let t = ((c - u).dot(e) / e.length_squared()).clamp(0.0, 1.0);
        let p = u + e * t;
        let dd = (p - c).length_squared();
        if dd < best.0 {
            best = (dd, p);
        }
    }
    best.1
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::narrow_phase::convex_convex::tests::{cube, random_quat};
    use crate::rng::SplitMix64;

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs()
    }

    /// Unit cube turned by q at x; the sphere approaches along the body direction `towards` (a
    /// face normal, an edge's or a vertex's bisector) so that its surface dips h into the cube.
    #[test]
    fn face_edge_vertex_and_inside() {
        let c = cube(1.0);
        let mut rng = SplitMix64::new(4);
        let r = 0.3;
        let h = 0.05;
        for q in [DQuat::IDENTITY, random_quat(&mut rng)] {
            let x = DVec3::new(-1.0, 2.0, 0.5);
            for (feature, towards) in [
                (DVec3::new(0.0, 0.0, 0.5), DVec3::Z),
                (
                    DVec3::new(0.5, 0.0, 0.5),
                    DVec3::new(1.0, 0.0, 1.0).normalize(),
                ),
                (DVec3::new(0.5, 0.5, 0.5), DVec3::ONE.normalize()),
                (
                    DVec3::new(-0.5, 0.2, -0.5),
                    DVec3::new(-1.0, 0.0, -1.0).normalize(),
                ),
            ] {
                let centre = x + q * (feature + towards * (r - h));
                let g = convex_sphere(&c, x, q, centre, r).unwrap();
                assert!(close(g.depth, h, 1e-13), "{feature}: {}", g.depth);
                assert!((g.normal + q * towards).length() < 1e-13, "{feature}");
                let surface = x + q * feature;
                assert!((g.point - (surface - q * towards * (0.5 * h))).length() < 1e-13);
                // The cap: exact on the face; at edges and vertices the same formula by definition.
                assert!(close(g.volume, PI * h * h * (3.0 * r - h) / 3.0, 1e-12));
            }
            // Cap exact on a face, against the direct integral of the slices π(r² − z²).
            let centre = x + q * DVec3::new(0.1, -0.2, 0.5 + r - h);
            let g = convex_sphere(&c, x, q, centre, r).unwrap();
            let slices = PI * ((r * r * h) - (r.powi(3) - (r - h).powi(3)) / 3.0);
            assert!(close(g.volume, slices, 1e-12));
            // Centre inside, 0.1 below the top face: pushed out through it, depth r + 0.1, the
            // cap of that height is the part of the sphere below the top plane.
            let r_in = 0.2;
            let centre = x + q * DVec3::new(0.05, 0.0, 0.4);
            let g = convex_sphere(&c, x, q, centre, r_in).unwrap();
            assert!(close(g.depth, r_in + 0.1, 1e-13));
            assert!((g.normal + q * DVec3::Z).length() < 1e-13);
            assert!(close(g.volume, PI * 0.09 * (3.0 * r_in - 0.3) / 3.0, 1e-12));
            // Near misses: just beyond a face, an edge and a vertex (inside the face planes'
            // reach but not the closest point's); touching.
            for (feature, towards) in [
                (DVec3::new(0.0, 0.0, 0.5), DVec3::Z),
                (
                    DVec3::new(0.5, 0.0, 0.5),
                    DVec3::new(1.0, 0.0, 1.0).normalize(),
                ),
                (DVec3::new(0.5, 0.5, 0.5), DVec3::ONE.normalize()),
            ] {
                let centre = x + q * (feature + towards * (r + 1e-9));
                assert!(convex_sphere(&c, x, q, centre, r).is_none(), "{feature}");
            }
        }
        assert!(convex_sphere(&c, DVec3::ZERO, DQuat::IDENTITY, DVec3::Z, 0.5).is_none());
    }
}
