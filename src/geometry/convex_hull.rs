//! Convex hull of a point set, built incrementally on exact predicates.
//!
//! Incremental construction (Clarkson & Shor 1989; the "beneath–beyond" method of Preparata &
//! Hong 1977): start from a tetrahedron, then add the points one by one; a point that lies strictly
//! beyond some faces replaces those faces by a fan from the point to their horizon. Visibility is
//! decided by the exact `orient3d`, so the result is the exact hull of the `f64` input: no
//! tolerance, no "almost coplanar" ambiguity, no topological inconsistency from rounding.
//!
//! Points coplanar with a face are NOT beyond it (strict test). The visible faces of a point
//! outside a convex polytope form a connected disk, so the horizon is a single cycle and the new
//! fan is non-degenerate (a fan triangle `(a, b, p)` on a horizon edge of a face that sees `p`
//! strictly cannot be flat). The surface may keep coplanar triangles and vertices that lie inside a
//! face or on an edge of the true hull; `ConvexPolyhedron` merges and drops those.
//!
//! Cost: O(n · f) orientation tests (every face is tested for every point). That is ample for
//! particle shapes (tens to a few thousand points).

use super::predicates::{collinear, orient3d};
use crate::math::DVec3;
use std::collections::HashMap;

/// Why a point set has no three-dimensional hull.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FlatPointSet {
    /// Fewer than four points.
    TooFew,
    /// All points coincide.
    Coincident,
    /// All points lie exactly on one line.
    Collinear,
    /// All points lie exactly in one plane.
    Coplanar,
}

/// The triangles of the exact convex hull of `points`, as indices into `points`, each
/// counter-clockwise seen from outside (so `(b − a) × (c − a)` points outward).
///
/// The points must be finite. The order of the output is deterministic (it depends only on the
/// input, in its order).
pub fn convex_hull(points: &[DVec3]) -> Result<Vec<[usize; 3]>, FlatPointSet> {
    let simplex = initial_simplex(points)?;
    let mut hull = IncrementalHull::new(points, simplex);
    for (i, &p) in points.iter().enumerate() {
        if !simplex.contains(&i) {
            hull.add(i, p);
        }
    }
    Ok(hull.into_triangles())
}

/// Four affinely independent points: the first along x, the farthest from it, the farthest from
/// their line, the farthest from their plane. "Farthest" is judged in floating point (it only
/// shapes the start), "independent" exactly.
fn initial_simplex(points: &[DVec3]) -> Result<[usize; 4], FlatPointSet> {
    if points.len() < 4 {
        return Err(FlatPointSet::TooFew);
    }
    let i0 = argmax(points, |p| -p.x).expect("non-empty");
    let p0 = points[i0];
    let i1 = argmax(points, |p| {
        if p == p0 {
            f64::NEG_INFINITY
        } else {
            (p - p0).length_squared()
        }
    })
    .filter(|&i| points[i] != p0)
    .ok_or(FlatPointSet::Coincident)?;
    let p1 = points[i1];
    let i2 = argmax(points, |p| {
        if collinear(p0, p1, p) {
            f64::NEG_INFINITY
        } else {
            (p - p0).cross(p1 - p0).length_squared()
        }
    })
    .filter(|&i| !collinear(p0, p1, points[i]))
    .ok_or(FlatPointSet::Collinear)?;
    let p2 = points[i2];
    let i3 = argmax(points, |p| {
        let o = orient3d(p0, p1, p2, p);
        if o == 0.0 {
            f64::NEG_INFINITY
        } else {
            o.abs()
        }
    })
    .filter(|&i| orient3d(p0, p1, p2, points[i]) != 0.0)
    .ok_or(FlatPointSet::Coplanar)?;
    Ok([i0, i1, i2, i3])
}

/// Index of the first maximum of `key` (deterministic on ties).
fn argmax(points: &[DVec3], key: impl Fn(DVec3) -> f64) -> Option<usize> {
    let mut best: Option<(usize, f64)> = None;
    for (i, &p) in points.iter().enumerate() {
        let k = key(p);
        if best.is_none_or(|(_, b)| k > b) {
            best = Some((i, k));
        }
    }
    best.map(|(i, _)| i)
}

struct IncrementalHull<'a> {
    points: &'a [DVec3],
    triangles: Vec<[usize; 3]>,
    alive: Vec<bool>,
    alive_count: usize,
    /// Directed edge (a, b) → the living triangle that has it in this direction.
    edge_owner: HashMap<(usize, usize), usize>,
    /// Scratch: which triangles see the current point.
    visible: Vec<bool>,
}

impl<'a> IncrementalHull<'a> {
    fn new(points: &'a [DVec3], s: [usize; 4]) -> Self {
        let mut hull = Self {
            points,
            triangles: Vec::new(),
            alive: Vec::new(),
            alive_count: 0,
            edge_owner: HashMap::new(),
            visible: Vec::new(),
        };
        // Each face of the tetrahedron, turned so that the fourth vertex lies beneath it.
        for (a, b, c, inner) in [
            (s[0], s[1], s[2], s[3]),
            (s[0], s[1], s[3], s[2]),
            (s[0], s[2], s[3], s[1]),
            (s[1], s[2], s[3], s[0]),
        ] {
            let p = |i: usize| points[i];
            if orient3d(p(a), p(b), p(c), p(inner)) < 0.0 {
                hull.push([a, b, c]);
            } else {
                hull.push([a, c, b]);
            }
        }
        hull
    }

    fn push(&mut self, t: [usize; 3]) {
        let id = self.triangles.len();
        for k in 0..3 {
            self.edge_owner.insert((t[k], t[(k + 1) % 3]), id);
        }
        self.triangles.push(t);
        self.alive.push(true);
        self.visible.push(false);
        self.alive_count += 1;
    }

    fn sees(&self, t: [usize; 3], p: DVec3) -> bool {
        let v = |i: usize| self.points[i];
        orient3d(v(t[0]), v(t[1]), v(t[2]), p) > 0.0
    }

    fn add(&mut self, index: usize, p: DVec3) {
        let mut seen = Vec::new();
        for (id, &t) in self.triangles.iter().enumerate() {
            if self.alive[id] && self.sees(t, p) {
                seen.push(id);
            }
        }
        if seen.is_empty() {
            return; // inside or on the current hull
        }
        for &id in &seen {
            self.visible[id] = true;
        }
        // Horizon: edges of visible triangles whose twin belongs to a hidden one.
        let mut horizon = Vec::new();
        for &id in &seen {
            let t = self.triangles[id];
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let twin = self.edge_owner[&(b, a)];
                if !self.visible[twin] {
                    horizon.push((a, b));
                }
            }
        }
        for &id in &seen {
            let t = self.triangles[id];
            for k in 0..3 {
                self.edge_owner.remove(&(t[k], t[(k + 1) % 3]));
            }
            self.alive[id] = false;
            self.visible[id] = false;
            self.alive_count -= 1;
        }
        for (a, b) in horizon {
            self.push([a, b, index]);
        }
        if self.triangles.len() > 4 * self.alive_count + 64 {
            self.compact();
        }
    }

    /// Drops dead triangles so that the visibility scan stays proportional to the hull size.
    fn compact(&mut self) {
        let living: Vec<[usize; 3]> = self.living().collect();
        self.triangles.clear();
        self.alive.clear();
        self.visible.clear();
        self.edge_owner.clear();
        self.alive_count = 0;
        for t in living {
            self.push(t);
        }
    }

    fn living(&self) -> impl Iterator<Item = [usize; 3]> + '_ {
        self.triangles
            .iter()
            .zip(&self.alive)
            .filter(|(_, &a)| a)
            .map(|(&t, _)| t)
    }

    fn into_triangles(self) -> Vec<[usize; 3]> {
        self.living().collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;
    use std::collections::HashSet;

    fn check_closed_and_convex(points: &[DVec3], tris: &[[usize; 3]]) {
        // Every directed edge has exactly one twin: a closed, consistently oriented surface.
        let mut edges = HashSet::new();
        for t in tris {
            for k in 0..3 {
                assert!(edges.insert((t[k], t[(k + 1) % 3])), "edge used twice");
            }
        }
        for &(a, b) in &edges {
            assert!(edges.contains(&(b, a)), "open edge");
        }
        // Every input point lies on the inner side of (or on) every face plane: exact convexity.
        for t in tris {
            for &p in points {
                assert!(orient3d(points[t[0]], points[t[1]], points[t[2]], p) <= 0.0);
            }
        }
        // Euler: V − E + F = 2 for the vertices used.
        let used: HashSet<usize> = tris.iter().flatten().copied().collect();
        assert_eq!(
            used.len() as i64 - (edges.len() / 2) as i64 + tris.len() as i64,
            2
        );
    }

    #[test]
    fn cube_with_interior_and_face_points() {
        let mut pts = Vec::new();
        for i in 0..27 {
            let (x, y, z) = (i % 3, (i / 3) % 3, i / 9);
            pts.push(DVec3::new(x as f64, y as f64, z as f64));
        }
        let tris = convex_hull(&pts).unwrap();
        check_closed_and_convex(&pts, &tris);
        // The centre (1,1,1), index 13, is never on the hull.
        assert!(!tris.iter().flatten().any(|&i| i == 13));
    }

    #[test]
    fn random_clouds_give_closed_convex_hulls() {
        let mut rng = SplitMix64::new(3);
        for n in [4, 5, 10, 50, 300] {
            // Integer coordinates from a small range: many exact coplanarities and duplicates.
            let pts: Vec<DVec3> = (0..n)
                .map(|_| {
                    DVec3::new(
                        (rng.next_u64() % 5) as f64,
                        (rng.next_u64() % 5) as f64,
                        (rng.next_u64() % 5) as f64,
                    )
                })
                .collect();
            if let Ok(tris) = convex_hull(&pts) {
                check_closed_and_convex(&pts, &tris);
            }
        }
        let pts: Vec<DVec3> = (0..2000)
            .map(|_| DVec3::new(rng.normal(), rng.normal(), rng.normal()).normalize())
            .collect();
        let tris = convex_hull(&pts).unwrap();
        check_closed_and_convex(&pts, &tris);
    }

    #[test]
    fn flat_sets_are_refused() {
        let p = DVec3::new(0.1, 0.2, 0.3);
        assert_eq!(convex_hull(&[p; 5]), Err(FlatPointSet::Coincident));
        let line: Vec<DVec3> = (0..6).map(|i| p * (1 << i) as f64).collect();
        assert_eq!(convex_hull(&line), Err(FlatPointSet::Collinear));
        let plane: Vec<DVec3> = (0..9)
            .map(|i| DVec3::new((i % 3) as f64 * 0.1, (i / 3) as f64 * 0.7, 0.3))
            .collect();
        assert_eq!(convex_hull(&plane), Err(FlatPointSet::Coplanar));
        assert_eq!(convex_hull(&plane[..3]), Err(FlatPointSet::TooFew));
    }
}
