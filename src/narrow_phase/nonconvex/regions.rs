//! The points of a region contact (springs of the vertex law and marks of the outline), grouped
//! by a union–find into connected regions, each made one contact (see the parent module).

use super::super::clip::ClipScratch;
use super::super::sphere_mesh::{MeshContact, MeshScratch};
use super::super::Geometry;
use super::solid::Crossing;
use super::MAX_REGIONS;
use crate::math::DVec3;

/// A penetrating point in the pair frame (world axes, origin at A's centre).
#[derive(Clone, Copy, Debug)]
pub(super) struct Point {
    pub(super) position: DVec3,
    /// Depth of the spring (≥ 0; 0 for a crossing point).
    pub(super) depth: f64,
    /// Its contribution to the load on A, depth × direction of the force (per unit stiffness);
    /// negative for the correction of an edge spring (see `edge_spring`).
    pub(super) force: DVec3,
    /// Its contribution to the potential, ½ depth² (per unit stiffness), or the correction's.
    pub(super) potential: f64,
    /// Whether it counts as a spring (for the contact's tangent stiffness).
    pub(super) counts: bool,
}

impl Point {
    /// A vertex spring: `depth` along the unit `normal` (the force on A).
    pub(super) fn spring(position: DVec3, depth: f64, normal: DVec3) -> Self {
        Self {
            position,
            depth,
            force: depth * normal,
            potential: 0.5 * depth * depth,
            counts: depth > 0.0,
        }
    }

    /// A point that only marks the outline (a crossing).
    pub(super) fn mark(position: DVec3) -> Self {
        Self {
            position,
            depth: 0.0,
            force: DVec3::ZERO,
            potential: 0.0,
            counts: false,
        }
    }
}

/// Working memory of the region contacts, reused from pair to pair (one per thread).
#[derive(Clone, Debug, Default)]
pub struct RegionScratch {
    pub clip: ClipScratch,
    pub(super) mesh: MeshScratch,
    pub(super) mesh_contacts: Vec<MeshContact>,
    pub(super) points: Vec<Point>,
    pub(super) parent: Vec<u32>,
    /// (face of A, face of B) → crossing point.
    pub(super) keys: Vec<(u64, u32)>,
    pub(super) crossings: Vec<Crossing>,
    pub(super) near: Vec<u32>,
    /// Triangles that may be nearest to an edge part (`edge_spring`).
    pub(super) nearest: Vec<u32>,
    pub(super) vertices: Vec<u32>,
    pub(super) edges: Vec<u32>,
    /// (vertex, its point) for the vertices of A and of B inside the other.
    pub(super) inside_a: Vec<(u32, u32)>,
    pub(super) inside_b: Vec<(u32, u32)>,
    pub(super) region_of: Vec<u32>,
    pub(super) members: Vec<(u32, u32)>,
    pub(super) hull: Vec<[f64; 2]>,
}

impl RegionScratch {
    pub fn new() -> Self {
        Self::default()
    }

    pub(super) fn clear(&mut self) {
        self.points.clear();
        self.parent.clear();
        self.keys.clear();
        self.inside_a.clear();
        self.inside_b.clear();
    }

    pub(super) fn push_point(&mut self, p: Point) -> u32 {
        self.points.push(p);
        self.parent.push(self.parent.len() as u32);
        (self.points.len() - 1) as u32
    }

    pub(super) fn find(&mut self, mut i: u32) -> u32 {
        while self.parent[i as usize] != i {
            let up = self.parent[self.parent[i as usize] as usize];
            self.parent[i as usize] = up;
            i = up;
        }
        i
    }

    pub(super) fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        // The smaller index becomes the root: the grouping does not depend on the order of joins.
        if ra < rb {
            self.parent[rb as usize] = ra;
        } else if rb < ra {
            self.parent[ra as usize] = rb;
        }
    }
}

/// Groups the scratch's points by their union–find roots and writes one contact per region with
/// penetration (pair-frame points moved by `origin`).
pub(super) fn regions_of_points(
    scratch: &mut RegionScratch,
    origin: DVec3,
    out: &mut Vec<Geometry>,
) {
    let n = scratch.points.len();
    if n == 0 {
        return;
    }
    // Region ids in order of first appearance.
    scratch.region_of.clear();
    scratch.region_of.resize(n, u32::MAX);
    scratch.members.clear();
    let mut id_of_root: Vec<(u32, u32)> = Vec::new();
    for i in 0..n as u32 {
        let root = scratch.find(i);
        let id = match id_of_root.iter().find(|&&(r, _)| r == root) {
            Some(&(_, id)) => id,
            None => {
                let id = id_of_root.len() as u32;
                id_of_root.push((root, id));
                id
            }
        };
        scratch.region_of[i as usize] = id;
        scratch.members.push((id, i));
    }
    let mut labels: Vec<u32> = scratch.region_of.clone();
    loop {
        let geometries = region_geometries(scratch, &labels, origin);
        if geometries.len() <= MAX_REGIONS {
            out.extend(geometries.into_iter().map(|(g, _, _)| g));
            return;
        }
        // Merge the region of least total depth into the one whose centre is nearest.
        let (weakest, _) = geometries
            .iter()
            .enumerate()
            .min_by(|x, y| x.1 .1.total_cmp(&y.1 .1))
            .expect("regions");
        let centre = geometries[weakest].0.point;
        let (nearest, _) = geometries
            .iter()
            .enumerate()
            .filter(|&(k, _)| k != weakest)
            .min_by(|x, y| {
                (x.1 .0.point - centre)
                    .length_squared()
                    .total_cmp(&(y.1 .0.point - centre).length_squared())
            })
            .expect("another region");
        let (from, to) = (geometries[weakest].2 as u32, geometries[nearest].2 as u32);
        for l in labels.iter_mut() {
            if *l == from {
                *l = to;
            }
        }
    }
}

/// One contact per label with penetration: (geometry, total depth, label).
fn region_geometries(
    scratch: &mut RegionScratch,
    labels: &[u32],
    origin: DVec3,
) -> Vec<(Geometry, f64, usize)> {
    let regions = labels.iter().copied().max().map_or(0, |m| m as usize + 1);
    let mut result = Vec::new();
    for r in 0..regions as u32 {
        let members = || {
            labels
                .iter()
                .enumerate()
                .filter(move |&(_, &l)| l == r)
                .map(|(i, _)| i)
        };
        let points = &scratch.points;
        let total: f64 = members()
            .filter(|&i| points[i].counts)
            .map(|i| points[i].depth)
            .sum();
        let Some(mut g) = aggregate(members().map(|i| &points[i]), origin) else {
            continue;
        };
        let area = projected_area(
            members().map(|i| points[i].position),
            g.normal,
            &mut scratch.hull,
        );
        if let Some(v) = g.volume.as_mut() {
            v.area = area;
        }
        result.push((g, total, r as usize));
    }
    result
}

/// One contact for the springs of a region: their resultant load Σ fᵢ, acting at the
/// depth-weighted mean point of the springs, with the exact moment of the individual springs as a
/// couple (as `dispatch::springs`, with signed contributions). `None` without a spring.
fn aggregate<'p>(points: impl Iterator<Item = &'p Point>, origin: DVec3) -> Option<Geometry> {
    let (mut load, mut weighted, mut total, mut potential, mut count) =
        (DVec3::ZERO, DVec3::ZERO, 0.0, 0.0, 0usize);
    let mut first_moment = DVec3::ZERO;
    for p in points {
        let x = p.position + origin;
        load += p.force;
        first_moment += x.cross(p.force);
        potential += p.potential;
        if p.counts && p.depth > 0.0 {
            weighted += p.depth * x;
            total += p.depth;
            count += 1;
        }
    }
    if count == 0 {
        return None;
    }
    let normal = load.try_normalize()?;
    let centre = weighted / total;
    Some(Geometry {
        normal,
        point: centre,
        overlap: total / count as f64,
        volume: Some(crate::contact_law::OverlapVolume {
            law: crate::contact_law::PolyhedralLaw::Vertex,
            points: count,
            volume: 0.0,
            area: 0.0,
            load: load.length(),
            couple: first_moment - centre.cross(load),
            potential,
        }),
    })
}

/// Area of the convex hull of the points projected on the plane normal to `normal` (Andrew's
/// monotone chain).
fn projected_area(
    points: impl Iterator<Item = DVec3>,
    normal: DVec3,
    hull: &mut Vec<[f64; 2]>,
) -> f64 {
    let (u, w) = normal.any_orthonormal_pair();
    let mut pts: Vec<[f64; 2]> = points.map(|p| [u.dot(p), w.dot(p)]).collect();
    if pts.len() < 3 {
        return 0.0;
    }
    pts.sort_unstable_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    hull.clear();
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &[f64; 2]>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    let m = hull.len();
    if m < 3 {
        return 0.0;
    }
    let mut twice = 0.0;
    for k in 0..m {
        let (a, b) = (hull[k], hull[(k + 1) % m]);
        twice += a[0] * b[1] - a[1] * b[0];
    }
    0.5 * twice.abs()
}
