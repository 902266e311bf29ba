//! A bounding-volume hierarchy over the triangles of a mesh: axis-aligned boxes in a binary tree,
//! built once per shape, so that the queries of a shape with thousands of triangles (which
//! triangles a line or a box meets, the closest point of the surface) look at a few dozen
//! triangles instead of all of them.
//!
//! Built top-down: each node's triangles are split at the median of their centroids along the
//! longest axis of the centroids' box (Wald 2007 describes the trade-offs; the median split gives a
//! balanced tree of depth ⌈log₂(n / LEAF_SIZE)⌉ with no tuning). The nodes are stored depth-first
//! in one array: a node's left child follows it, and it stores the index of its right child.
//!
//! Every query visits the tree in a fixed order and reports triangles in that order, so results
//! never depend on anything but the mesh and the query.

use crate::math::{Aabb, DMat3, DVec3};

/// Triangles per leaf at most.
const LEAF_SIZE: usize = 4;

/// Depth of the traversal stack: the median split halves the triangles at every level, so 64
/// levels hold any mesh that fits in memory.
const STACK: usize = 64;

#[derive(Clone, Copy, Debug, PartialEq)]
struct Node {
    bounds: Aabb,
    /// Leaf: index of its first triangle in `order`. Inner node: index of its right child (the
    /// left child is the next node).
    first: u32,
    /// Leaf: its number of triangles (> 0). Inner node: 0.
    count: u32,
}

/// A bounding-volume hierarchy over the triangles of one mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Bvh {
    nodes: Vec<Node>,
    /// Triangle indices, leaf by leaf.
    order: Vec<u32>,
    /// The triangles' boxes, in the same order.
    boxes: Vec<Aabb>,
}

impl Bvh {
    /// The hierarchy of `triangles` (indices into `vertices`). An empty mesh gives an empty tree
    /// that reports nothing.
    pub fn new(vertices: &[DVec3], triangles: &[[usize; 3]]) -> Self {
        let boxes: Vec<Aabb> = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| vertices[i]);
                Aabb::new(a.min(b).min(c), a.max(b).max(c))
            })
            .collect();
        let centroids: Vec<DVec3> = boxes.iter().map(|b| 0.5 * (b.min + b.max)).collect();
        let mut order: Vec<u32> = (0..triangles.len() as u32).collect();
        let mut nodes = Vec::with_capacity(2 * triangles.len() / LEAF_SIZE + 1);
        if !triangles.is_empty() {
            build(&mut nodes, &mut order, 0, &boxes, &centroids);
        }
        let boxes = order.iter().map(|&t| boxes[t as usize]).collect();
        Self {
            nodes,
            order,
            boxes,
        }
    }

    /// The box around every triangle (a degenerate box at the origin for an empty tree).
    pub fn bounds(&self) -> Aabb {
        self.nodes
            .first()
            .map_or(Aabb::new(DVec3::ZERO, DVec3::ZERO), |n| n.bounds)
    }

    /// Calls `f` with every triangle whose box passes `enter` (called on the boxes of nodes and
    /// of triangles alike, so it must hold for a box whenever it holds for a box inside it) until
    /// `f` returns false. Returns false when stopped early.
    pub fn visit(&self, enter: impl Fn(&Aabb) -> bool, mut f: impl FnMut(u32) -> bool) -> bool {
        if self.nodes.is_empty() {
            return true;
        }
        let mut stack = [0u32; STACK];
        let mut top = 0;
        let mut node = 0u32;
        loop {
            let n = &self.nodes[node as usize];
            if enter(&n.bounds) {
                if n.count > 0 {
                    let range = n.first as usize..(n.first + n.count) as usize;
                    for (&t, b) in self.order[range.clone()].iter().zip(&self.boxes[range]) {
                        if enter(b) && !f(t) {
                            return false;
                        }
                    }
                } else {
                    stack[top] = n.first;
                    top += 1;
                    node += 1;
                    continue;
                }
            }
            if top == 0 {
                return true;
            }
            top -= 1;
            node = stack[top];
        }
    }

    /// Every triangle whose box overlaps `query` (closed boxes), in tree order.
    pub fn overlapping(&self, query: &Aabb, out: &mut Vec<u32>) {
        out.clear();
        self.visit(
            |b| b.overlaps(query),
            |t| {
                out.push(t);
                true
            },
        );
    }

    /// Calls `f` with every triangle whose box, enlarged by `margin`, meets the whole line
    /// through `point` along `direction` (both ways), until `f` returns false. Returns false when
    /// stopped early.
    pub fn visit_line(
        &self,
        point: DVec3,
        direction: DVec3,
        margin: f64,
        f: impl FnMut(u32) -> bool,
    ) -> bool {
        // The slab test with the reciprocal direction computed once (an axis the line runs
        // across, with a zero component, gives infinities that compare correctly, but 0 · ∞ does
        // not: such axes are tested directly).
        let inverse = direction.recip();
        let parallel = direction.cmpeq(DVec3::ZERO);
        let m = DVec3::splat(margin);
        self.visit(
            |b| {
                let (lo, hi) = (b.min - m - point, b.max + m - point);
                if parallel.any() {
                    let inside = lo.cmple(DVec3::ZERO) & hi.cmpge(DVec3::ZERO);
                    if (parallel & !inside).any() {
                        return false;
                    }
                }
                let (s0, s1) = (lo * inverse, hi * inverse);
                let (near, far) = (s0.min(s1), s0.max(s1));
                let near = DVec3::select(parallel, DVec3::NEG_INFINITY, near);
                let far = DVec3::select(parallel, DVec3::INFINITY, far);
                near.max_element() <= far.min_element()
            },
            f,
        )
    }

    /// The point of the mesh surface closest to `p`, its squared distance and its triangle, if
    /// some triangle lies closer than √`limit_squared`. Branch and bound: nearer children first,
    /// a subtree skipped when its box is farther than the best so far; ties go to the triangle
    /// met first in tree order.
    pub fn closest_point(
        &self,
        p: DVec3,
        vertices: &[DVec3],
        triangles: &[[usize; 3]],
        limit_squared: f64,
    ) -> Option<(DVec3, f64, u32)> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut best: Option<(DVec3, f64, u32)> = None;
        let mut best_d = limit_squared;
        let mut stack = [0u32; STACK];
        let mut top = 0;
        stack[top] = 0;
        top += 1;
        while top > 0 {
            top -= 1;
            let index = stack[top];
            let n = &self.nodes[index as usize];
            if box_distance_squared(p, &n.bounds) >= best_d {
                continue;
            }
            if n.count > 0 {
                for &t in &self.order[n.first as usize..(n.first + n.count) as usize] {
                    let [a, b, c] = triangles[t as usize].map(|i| vertices[i]);
                    let (q, _) = crate::geometry::triangle::closest_point_on_triangle(p, a, b, c);
                    let d = (q - p).length_squared();
                    if d < best_d {
                        best_d = d;
                        best = Some((q, d, t));
                    }
                }
            } else {
                let (left, right) = (index + 1, n.first);
                let dl = box_distance_squared(p, &self.nodes[left as usize].bounds);
                let dr = box_distance_squared(p, &self.nodes[right as usize].bounds);
                // Push the farther first so that the nearer is searched first.
                let (near, far) = if dl <= dr {
                    (left, right)
                } else {
                    (right, left)
                };
                stack[top] = far;
                stack[top + 1] = near;
                top += 2;
            }
        }
        best
    }
}

/// Builds the subtree of `order` (which holds the triangles' indices) and returns its node index.
fn build(
    nodes: &mut Vec<Node>,
    order: &mut [u32],
    offset: usize,
    boxes: &[Aabb],
    centroids: &[DVec3],
) -> u32 {
    let bounds = order
        .iter()
        .map(|&t| boxes[t as usize])
        .reduce(|a, b| a.union(&b))
        .expect("a node holds at least one triangle");
    let index = nodes.len() as u32;
    nodes.push(Node {
        bounds,
        first: offset as u32,
        count: order.len() as u32,
    });
    if order.len() <= LEAF_SIZE {
        return index;
    }
    let (lo, hi) = order
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &t| {
            let c = centroids[t as usize];
            (lo.min(c), hi.max(c))
        });
    let extent = hi - lo;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let middle = order.len() / 2;
    order.select_nth_unstable_by(middle, |&a, &b| {
        centroids[a as usize][axis]
            .total_cmp(&centroids[b as usize][axis])
            .then(a.cmp(&b))
    });
    let (left, right) = order.split_at_mut(middle);
    build(nodes, left, offset, boxes, centroids);
    let right_index = build(nodes, right, offset + middle, boxes, centroids);
    let node = &mut nodes[index as usize];
    node.first = right_index;
    node.count = 0;
    index
}

impl Bvh {
    /// Whether some triangle's box of this tree, moved by `rotation` and `translation` (as the
    /// box around the moved box), overlaps some triangle's box of `other`: a simultaneous descent
    /// of both trees that prunes every pair of subtrees whose boxes are apart, and stops at the
    /// first overlapping pair of triangles. Two bodies whose surfaces come near each other pass;
    /// most pairs that only the bounding spheres put together fail in a few steps.
    pub fn meets(&self, other: &Bvh, rotation: DMat3, translation: DVec3) -> bool {
        if self.nodes.is_empty() || other.nodes.is_empty() {
            return false;
        }
        let abs = DMat3::from_cols(
            rotation.x_axis.abs(),
            rotation.y_axis.abs(),
            rotation.z_axis.abs(),
        );
        let moved = |b: &Aabb| {
            let centre = rotation * (0.5 * (b.min + b.max)) + translation;
            let half = abs * (0.5 * (b.max - b.min));
            Aabb::new(centre - half, centre + half)
        };
        // Pairs (node of self, node of other) still to look at.
        let mut stack = [(0u32, 0u32); 2 * STACK];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let (i, j) = stack[top];
            let (a, b) = (&self.nodes[i as usize], &other.nodes[j as usize]);
            let box_a = moved(&a.bounds);
            if !box_a.overlaps(&b.bounds) {
                continue;
            }
            match (a.count > 0, b.count > 0) {
                (true, true) => {
                    let range_a = a.first as usize..(a.first + a.count) as usize;
                    let range_b = b.first as usize..(b.first + b.count) as usize;
                    for ta in &self.boxes[range_a] {
                        let ta = moved(ta);
                        if other.boxes[range_b.clone()]
                            .iter()
                            .any(|tb| ta.overlaps(tb))
                        {
                            return true;
                        }
                    }
                }
                // Descend into the leaf-less side, or the larger box.
                (false, true) => {
                    stack[top] = (i + 1, j);
                    stack[top + 1] = (a.first, j);
                    top += 2;
                }
                (true, false) => {
                    stack[top] = (i, j + 1);
                    stack[top + 1] = (i, b.first);
                    top += 2;
                }
                (false, false) => {
                    let size = |b: &Aabb| b.extent().length_squared();
                    if size(&box_a) >= size(&b.bounds) {
                        stack[top] = (i + 1, j);
                        stack[top + 1] = (a.first, j);
                    } else {
                        stack[top] = (i, j + 1);
                        stack[top + 1] = (i, b.first);
                    }
                    top += 2;
                }
            }
        }
        false
    }
}

/// Whether the line x = point + s · direction, s ∈ ℝ, meets the closed box (slab test).
pub fn line_meets_box(point: DVec3, direction: DVec3, b: &Aabb) -> bool {
    let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
    for axis in 0..3 {
        let (p, d) = (point[axis], direction[axis]);
        if d == 0.0 {
            if p < b.min[axis] || p > b.max[axis] {
                return false;
            }
            continue;
        }
        let (s0, s1) = ((b.min[axis] - p) / d, (b.max[axis] - p) / d);
        lo = lo.max(s0.min(s1));
        hi = hi.min(s0.max(s1));
        if lo > hi {
            return false;
        }
    }
    true
}

/// Squared distance from `p` to the closed box (0 inside).
pub fn box_distance_squared(p: DVec3, b: &Aabb) -> f64 {
    let d = (b.min - p).max(p - b.max).max(DVec3::ZERO);
    d.length_squared()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    fn random_soup(rng: &mut SplitMix64, n: usize) -> (Vec<DVec3>, Vec<[usize; 3]>) {
        let mut v = Vec::new();
        let mut t = Vec::new();
        for k in 0..n {
            let c = DVec3::new(
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
            );
            for _ in 0..3 {
                v.push(
                    c + 0.1
                        * DVec3::new(
                            rng.uniform(-1.0, 1.0),
                            rng.uniform(-1.0, 1.0),
                            rng.uniform(-1.0, 1.0),
                        ),
                );
            }
            t.push([3 * k, 3 * k + 1, 3 * k + 2]);
        }
        (v, t)
    }

    #[test]
    fn queries_agree_with_brute_force() {
        let mut rng = SplitMix64::new(3);
        for n in [1, 3, 4, 5, 17, 300] {
            let (v, t) = random_soup(&mut rng, n);
            let bvh = Bvh::new(&v, &t);
            let tri_box = |k: usize| {
                let [a, b, c] = t[k].map(|i| v[i]);
                Aabb::new(a.min(b).min(c), a.max(b).max(c))
            };
            let mut seen: Vec<u32> = Vec::new();
            bvh.visit(
                |_| true,
                |k| {
                    seen.push(k);
                    true
                },
            );
            seen.sort_unstable();
            assert_eq!(seen, (0..n as u32).collect::<Vec<_>>());
            for _ in 0..50 {
                let c = DVec3::new(
                    rng.uniform(-1.2, 1.2),
                    rng.uniform(-1.2, 1.2),
                    rng.uniform(-1.2, 1.2),
                );
                let q = Aabb::around_sphere(c, rng.uniform(0.0, 0.4));
                let mut got = Vec::new();
                bvh.overlapping(&q, &mut got);
                got.sort_unstable();
                let expected: Vec<u32> = (0..n)
                    .filter(|&k| tri_box(k).overlaps(&q))
                    .map(|k| k as u32)
                    .collect();
                assert_eq!(got, expected);

                let d = DVec3::new(rng.normal(), rng.normal(), rng.normal());
                let mut got = Vec::new();
                bvh.visit_line(c, d, 0.0, |k| {
                    got.push(k);
                    true
                });
                got.sort_unstable();
                let expected: Vec<u32> = (0..n)
                    .filter(|&k| line_meets_box(c, d, &tri_box(k)))
                    .map(|k| k as u32)
                    .collect();
                assert_eq!(got, expected);

                let (q, d2, k) = bvh.closest_point(c, &v, &t, f64::INFINITY).unwrap();
                let brute = (0..n)
                    .map(|k| {
                        let [a, b, cc] = t[k].map(|i| v[i]);
                        let (q, _) =
                            crate::geometry::triangle::closest_point_on_triangle(c, a, b, cc);
                        (q - c).length_squared()
                    })
                    .fold(f64::INFINITY, f64::min);
                assert_eq!(d2, brute);
                assert_eq!((q - c).length_squared(), d2);
                assert!((k as usize) < n);
                assert!(bvh.closest_point(c, &v, &t, 0.5 * brute).is_none() || brute == 0.0);
            }
        }
    }

    #[test]
    fn meets_agrees_with_brute_force() {
        let mut rng = SplitMix64::new(9);
        for n in [1, 7, 60] {
            let (v1, t1) = random_soup(&mut rng, n);
            let (v2, t2) = random_soup(&mut rng, n + 3);
            let (b1, b2) = (Bvh::new(&v1, &t1), Bvh::new(&v2, &t2));
            for _ in 0..200 {
                let q = crate::math::DQuat::from_axis_angle(
                    DVec3::new(rng.normal(), rng.normal(), rng.normal()).normalize(),
                    rng.uniform(0.0, 3.0),
                );
                let r = DMat3::from_quat(q);
                let shift = DVec3::new(
                    rng.uniform(-3.0, 3.0),
                    rng.uniform(-3.0, 3.0),
                    rng.uniform(-3.0, 3.0),
                );
                let moved_box = |k: usize| {
                    let [a, b, c] = t1[k].map(|i| v1[i]);
                    let bx = Aabb::new(a.min(b).min(c), a.max(b).max(c));
                    let abs = DMat3::from_cols(r.x_axis.abs(), r.y_axis.abs(), r.z_axis.abs());
                    let centre = r * (0.5 * (bx.min + bx.max)) + shift;
                    let half = abs * (0.5 * (bx.max - bx.min));
                    Aabb::new(centre - half, centre + half)
                };
                let expected = (0..t1.len()).any(|k| {
                    (0..t2.len()).any(|m| {
                        let [a, b, c] = t2[m].map(|i| v2[i]);
                        moved_box(k).overlaps(&Aabb::new(a.min(b).min(c), a.max(b).max(c)))
                    })
                });
                assert_eq!(b1.meets(&b2, r, shift), expected);
            }
        }
    }

    /// What the hierarchy is for: on a closed mesh of ~8,000 triangles a ray cast (a line through
    /// a point inside) visits a few dozen triangles, not all of them.
    #[test]
    fn a_line_visits_few_of_many_triangles() {
        let mut rng = SplitMix64::new(21);
        let points: Vec<DVec3> = (0..4000)
            .map(|_| DVec3::new(rng.normal(), rng.normal(), rng.normal()).normalize())
            .collect();
        let triangles = crate::geometry::convex_hull::convex_hull(&points).unwrap();
        assert!(triangles.len() > 7900, "{}", triangles.len());
        let bvh = Bvh::new(&points, &triangles);
        let mut visited = 0usize;
        let lines = 200;
        for _ in 0..lines {
            let p = DVec3::new(rng.normal(), rng.normal(), rng.normal()) * 0.3;
            let d = DVec3::new(rng.normal(), rng.normal(), rng.normal());
            bvh.visit_line(p, d, 1e-9, |_| {
                visited += 1;
                true
            });
        }
        let mean = visited as f64 / lines as f64;
        println!(
            "{mean:.1} of {} triangles visited per line",
            triangles.len()
        );
        assert!(mean < 100.0, "{mean}");
    }

    #[test]
    fn empty_tree_reports_nothing() {
        let bvh = Bvh::new(&[], &[]);
        let mut out = vec![7];
        bvh.overlapping(&Aabb::around_sphere(DVec3::ZERO, 1.0), &mut out);
        assert!(out.is_empty());
        assert!(bvh
            .closest_point(DVec3::ZERO, &[], &[], f64::INFINITY)
            .is_none());
    }
}
