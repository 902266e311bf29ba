//! The point-in-polyhedron test of non-convex particles (ray casting over the triangles a
//! bounding-volume hierarchy finds) against references that do not cast rays:
//!
//! - random star-shaped meshes (a sphere's triangulation with a random radius per vertex) and the
//!   built-in jack, ring and star at random orientations, against the generalised winding number
//!   w(p) = Σ Ω_t(p) / 4π (the solid angles of the triangles seen from p, Van Oosterom &
//!   Strackee 1983): 1 inside, 0 outside. The points are random in the bounding box, the vertices
//!   (exactly on the surface: `OnSurface`), and near-surface points at 10⁻³, 10⁻⁶ and 10⁻⁹ of the
//!   mesh's size in front of and behind random points of random triangles; the winding number is
//!   asserted to lie within 10⁻⁶ of 0 or 1, so that the reference itself is never in doubt;
//! - random unions of cells of an integer grid (non-convex, with re-entrant edges and corners,
//!   tunnels, several pieces, and edges where cells meet diagonally), against exact cell
//!   membership: a point is inside when every cell whose closed box holds it is filled, outside
//!   when none is, on the surface otherwise. Points on a grid of step 1/4 (on faces, edges and
//!   corners, exactly) and random points.
//!
//! Not one misclassification is allowed among the > 10⁵ points.

use polydem::geometry::bvh::Bvh;
use polydem::geometry::convex_hull::convex_hull;
use polydem::geometry::point_in_polyhedron::locate_point_bvh;
use polydem::geometry::Location;
use polydem::math::{DQuat, DVec3};
use polydem::rng::SplitMix64;
use polydem::shape::mesh_check::CheckOptions;
use polydem::shape::nonconvex_generators::{grid_union, jack, ring, star};
use polydem::shape::NonConvexPolyhedron;

/// Generalised winding number of the closed mesh about `p`.
fn winding_number(p: DVec3, v: &[DVec3], t: &[[usize; 3]]) -> f64 {
    let mut total = 0.0;
    for tri in t {
        let [a, b, c] = tri.map(|i| v[i] - p);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let det = a.dot(b.cross(c));
        let denominator = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
        total += 2.0 * det.atan2(denominator);
    }
    total / (4.0 * std::f64::consts::PI)
}

fn by_winding(p: DVec3, v: &[DVec3], t: &[[usize; 3]]) -> Location {
    let w = winding_number(p, v, t);
    if (w - 1.0).abs() < 1e-6 {
        Location::Inside
    } else if w.abs() < 1e-6 {
        Location::Outside
    } else {
        panic!("the reference is in doubt at {p}: winding number {w}")
    }
}

fn random_unit(rng: &mut SplitMix64) -> DVec3 {
    loop {
        let d = DVec3::new(rng.normal(), rng.normal(), rng.normal());
        if let Some(u) = d.try_normalize() {
            return u;
        }
    }
}

/// A random star-shaped closed mesh: the hull of `n` random directions, each vertex pushed to a
/// random radius in [0.35, 1].
fn star_shaped(rng: &mut SplitMix64, n: usize) -> (Vec<DVec3>, Vec<[usize; 3]>) {
    let directions: Vec<DVec3> = (0..n).map(|_| random_unit(rng)).collect();
    let triangles = convex_hull(&directions).expect("points on a sphere");
    let vertices = directions
        .iter()
        .map(|&d| d * rng.uniform(0.35, 1.0))
        .collect();
    (vertices, triangles)
}

/// Query points for a mesh: random in its (enlarged) box, its vertices, and points at several
/// tiny distances in front of and behind random points of random triangles.
fn queries(
    rng: &mut SplitMix64,
    v: &[DVec3],
    t: &[[usize; 3]],
    count: usize,
) -> (Vec<DVec3>, Vec<DVec3>) {
    let (lo, hi) = v
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        });
    let size = (hi - lo).length();
    let mut off_surface = Vec::with_capacity(count);
    for k in 0..count {
        if k % 2 == 0 {
            let e = (hi - lo) * 0.1;
            off_surface.push(DVec3::new(
                rng.uniform(lo.x - e.x, hi.x + e.x),
                rng.uniform(lo.y - e.y, hi.y + e.y),
                rng.uniform(lo.z - e.z, hi.z + e.z),
            ));
        } else {
            let [a, b, c] = t[(rng.next_u64() % t.len() as u64) as usize].map(|i| v[i]);
            let (mut s, mut r) = (rng.next_f64(), rng.next_f64());
            if s + r > 1.0 {
                (s, r) = (1.0 - s, 1.0 - r);
            }
            let on = a + (b - a) * s + (c - a) * r;
            let n = (b - a).cross(c - a).normalize();
            let distance = [1e-3, 1e-6, 1e-9][(k / 2) % 3] * size;
            let side = if (k / 6) % 2 == 0 { 1.0 } else { -1.0 };
            off_surface.push(on + n * side * distance);
        }
    }
    (off_surface, v.to_vec())
}

#[test]
fn ray_casting_matches_the_winding_number_on_non_convex_meshes() {
    let mut rng = SplitMix64::new(2024);
    let mut checked = 0usize;
    let mut counts = [0usize; 3];
    let mut check = |shape: &NonConvexPolyhedron, rng: &mut SplitMix64, count: usize| {
        let (v, t) = (shape.vertices(), shape.triangles());
        let (points, on_surface) = queries(rng, v, t, count);
        for p in points {
            let expected = by_winding(p, v, t);
            counts[expected as usize] += 1;
            assert_eq!(shape.locate(p), expected, "{p}");
            checked += 1;
        }
        for p in on_surface {
            assert_eq!(shape.locate(p), Location::OnSurface, "{p}");
            counts[2] += 1;
            checked += 1;
        }
    };
    for case in 0..40 {
        let (v, t) = star_shaped(&mut rng, 40 + 4 * case);
        let (shape, _, _) = NonConvexPolyhedron::from_mesh(&v, &t, CheckOptions::default())
            .expect("a star-shaped mesh is a valid solid");
        check(&shape, &mut rng, 1600);
    }
    let generated = [
        jack(3.0, 0.8).unwrap(),
        ring(2.0, 1.2, 0.7, 16).unwrap(),
        star(20, 1.0, 0.8).unwrap(),
    ];
    for m in generated {
        for _ in 0..3 {
            let q = DQuat::from_axis_angle(random_unit(&mut rng), rng.uniform(0.0, 6.3));
            let v: Vec<DVec3> = m.vertices.iter().map(|&x| q * x).collect();
            let (shape, _, _) =
                NonConvexPolyhedron::from_mesh(&v, &m.triangles, CheckOptions::default()).unwrap();
            check(&shape, &mut rng, 1000);
        }
    }
    println!(
        "{checked} points: {} inside, {} outside, {} on the surface",
        counts[0], counts[1], counts[2]
    );
    assert!(checked >= 70_000, "{checked}");
    assert!(counts.iter().all(|&c| c > 1000), "{counts:?}");
}

/// Exact location of `p` in the union of the filled unit cells (integer corners).
fn by_cells(p: DVec3, size: usize, filled: &[bool]) -> Location {
    // The cells whose closed box holds p: along each axis one cell, or two if p is on a plane.
    let range = |x: f64| -> Vec<i64> {
        let f = x.floor();
        if f == x {
            vec![f as i64 - 1, f as i64]
        } else {
            vec![f as i64]
        }
    };
    let cell = |i: i64, j: i64, k: i64| {
        let n = size as i64;
        (0..n).contains(&i)
            && (0..n).contains(&j)
            && (0..n).contains(&k)
            && filled[(i * n * n + j * n + k) as usize]
    };
    let (mut any, mut all) = (false, true);
    for i in range(p.x) {
        for j in range(p.y) {
            for k in range(p.z) {
                let f = cell(i, j, k);
                any |= f;
                all &= f;
            }
        }
    }
    match (any, all) {
        (true, true) => Location::Inside,
        (false, _) => Location::Outside,
        _ => Location::OnSurface,
    }
}

#[test]
fn ray_casting_is_exact_on_random_cell_unions() {
    let mut rng = SplitMix64::new(7);
    let n = 4;
    let planes: Vec<f64> = (0..=n).map(|i| i as f64).collect();
    let mut checked = 0usize;
    let mut counts = [0usize; 3];
    for _ in 0..40 {
        let filled: Vec<bool> = (0..n * n * n).map(|_| rng.next_f64() < 0.45).collect();
        if !filled.iter().any(|&f| f) {
            continue;
        }
        let (v, t) = grid_union(&planes, &planes, &planes, |i, j, k| {
            filled[i * n * n + j * n + k]
        });
        let bvh = Bvh::new(&v, &t);
        let mut points = Vec::new();
        // Every point of the quarter grid over the box and around it: faces, edges, corners.
        for i in -1..=4 * n as i64 + 1 {
            for j in -1..=4 * n as i64 + 1 {
                for k in [-1, 1, 2, 4, 6, 8, 9, 13, 16, 17] {
                    points.push(DVec3::new(i as f64, j as f64, k as f64) * 0.25);
                }
            }
        }
        for _ in 0..1000 {
            points.push(DVec3::new(
                rng.uniform(-0.5, n as f64 + 0.5),
                rng.uniform(-0.5, n as f64 + 0.5),
                rng.uniform(-0.5, n as f64 + 0.5),
            ));
        }
        for p in points {
            let expected = by_cells(p, n, &filled);
            counts[expected as usize] += 1;
            assert_eq!(locate_point_bvh(p, &v, &t, &bvh), expected, "{p}");
            checked += 1;
        }
    }
    println!(
        "{checked} points: {} inside, {} outside, {} on the surface",
        counts[0], counts[1], counts[2]
    );
    assert!(checked >= 30_000, "{checked}");
    assert!(counts.iter().all(|&c| c > 1000), "{counts:?}");
}
