//! Recursive coordinate bisection (RCB) by body count.
//!
//! The bodies' box is cut across its longest axis where the count splits ⌊P/2⌋ : ⌈P/2⌉ for P
//! ranks, and each side again, until every rank has a box. The cut is found by bisection on the
//! coordinate, each probe a count of the bodies below it ([`BodyCounter`]): with global counts
//! (every rank adding up its own), every rank makes the same probes, sees the same counts and
//! builds the same tree, with no other communication. The regions are half-open (a body exactly
//! on a cut belongs to the upper side) and the outermost ones reach to infinity, so every point
//! has exactly one owner, also when it leaves the box the cuts were made in.

use crate::math::DVec3;

/// A box of space, [lower, upper) on each axis; bounds may be infinite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Region {
    pub lower: DVec3,
    pub upper: DVec3,
}

impl Region {
    /// All of space.
    pub fn everything() -> Self {
        Region {
            lower: DVec3::splat(f64::NEG_INFINITY),
            upper: DVec3::splat(f64::INFINITY),
        }
    }

    pub fn contains(&self, p: DVec3) -> bool {
        (0..3).all(|k| self.lower[k] <= p[k] && p[k] < self.upper[k])
    }

    /// The two sides of a cut at `cut` across `axis`.
    fn split(&self, axis: usize, cut: f64) -> (Region, Region) {
        let (mut below, mut above) = (*self, *self);
        below.upper[axis] = cut;
        above.lower[axis] = cut;
        (below, above)
    }

    /// The part of the (closed, finite) box `[lower, upper]` inside this region.
    fn clip(&self, lower: DVec3, upper: DVec3) -> (DVec3, DVec3) {
        (lower.max(self.lower), upper.min(self.upper))
    }
}

/// Counts bodies: in one process, or added up over every rank.
pub trait BodyCounter {
    /// The number of bodies in `region` whose coordinate on `axis` is below `cut`
    /// (`f64::INFINITY`: all in the region).
    fn count_below(&mut self, region: &Region, axis: usize, cut: f64) -> u64;

    /// The smallest box holding every body (`None` if there are none).
    fn bounds(&mut self) -> Option<(DVec3, DVec3)>;
}

/// The bodies of one process, by centre.
pub struct LocalBodies<'a>(pub &'a [DVec3]);

impl LocalBodies<'_> {
    /// The count of [`BodyCounter::count_below`] over this process's bodies.
    pub fn count(&self, region: &Region, axis: usize, cut: f64) -> u64 {
        self.0
            .iter()
            .filter(|p| region.contains(**p) && p[axis] < cut)
            .count() as u64
    }

    /// The bounds of [`BodyCounter::bounds`] over this process's bodies.
    pub fn local_bounds(&self) -> Option<(DVec3, DVec3)> {
        let first = *self.0.first()?;
        Some(
            self.0
                .iter()
                .fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p))),
        )
    }
}

impl BodyCounter for LocalBodies<'_> {
    fn count_below(&mut self, region: &Region, axis: usize, cut: f64) -> u64 {
        self.count(region, axis, cut)
    }

    fn bounds(&mut self) -> Option<(DVec3, DVec3)> {
        self.local_bounds()
    }
}

#[derive(Clone, Debug, PartialEq)]
enum Node {
    Rank(usize),
    Cut {
        axis: usize,
        at: f64,
        below: Box<Node>,
        above: Box<Node>,
    },
}

/// Which rank owns which part of space.
#[derive(Clone, Debug, PartialEq)]
pub struct Decomposition {
    ranks: usize,
    root: Node,
}

/// Bisection probes per cut at most: enough to get from any finite interval down to adjacent
/// floating-point numbers.
const MAX_PROBES: usize = 2100;

impl Decomposition {
    /// Cuts space among `ranks` ranks so that each owns as many of the counted bodies as the cuts
    /// can give it: ⌊n·k/P⌋ below each cut between k and P − k ranks, more only where bodies share
    /// the cut's coordinate.
    pub fn new(ranks: usize, bodies: &mut impl BodyCounter) -> Self {
        assert!(ranks > 0, "a decomposition needs a rank");
        let bounds = bodies.bounds().unwrap_or((DVec3::ZERO, DVec3::ZERO));
        let root = Self::build(Region::everything(), bounds, 0..ranks, bodies);
        Decomposition { ranks, root }
    }

    fn build(
        region: Region,
        bounds: (DVec3, DVec3),
        ranks: std::ops::Range<usize>,
        bodies: &mut impl BodyCounter,
    ) -> Node {
        if ranks.len() == 1 {
            return Node::Rank(ranks.start);
        }
        let (lower, upper) = region.clip(bounds.0, bounds.1);
        // The longest side of the bodies' box within the region (the first of equal ones).
        let extent = upper - lower;
        let axis = (0..3).fold(0, |best, k| if extent[k] > extent[best] { k } else { best });
        let total = bodies.count_below(&region, axis, f64::INFINITY);
        let ranks_below = ranks.len() / 2;
        let target = total * ranks_below as u64 / ranks.len() as u64;
        // The lowest cut with at least `target` bodies below: between `low` (none below, as no
        // body is below the box) and `high` (all below).
        let (mut low, mut high) = (lower[axis], upper[axis].next_up());
        if !(low.is_finite() && high.is_finite()) || low >= high {
            (low, high) = (0.0, 0.0);
        }
        for _ in 0..MAX_PROBES {
            let middle = low + 0.5 * (high - low);
            if middle <= low || middle >= high {
                break;
            }
            if bodies.count_below(&region, axis, middle) >= target {
                high = middle;
            } else {
                low = middle;
            }
        }
        let at = if target == 0 { low } else { high };
        let (below, above) = region.split(axis, at);
        let middle = ranks.start + ranks_below;
        Node::Cut {
            axis,
            at,
            below: Box::new(Self::build(below, bounds, ranks.start..middle, bodies)),
            above: Box::new(Self::build(above, bounds, middle..ranks.end, bodies)),
        }
    }

    pub fn ranks(&self) -> usize {
        self.ranks
    }

    /// The rank that owns the point `p`.
    pub fn owner(&self, p: DVec3) -> usize {
        let mut node = &self.root;
        loop {
            match node {
                Node::Rank(rank) => return *rank,
                Node::Cut {
                    axis,
                    at,
                    below,
                    above,
                } => node = if p[*axis] < *at { below } else { above },
            }
        }
    }

    /// How deep `p` lies in its owner's region: the distance, along one axis, to the nearest cut
    /// that bounds the region (`f64::INFINITY` for a single rank). Within that distance on every
    /// axis there is no other rank's region: [`Decomposition::ranks_near`] finds only the owner
    /// for any halo below it.
    pub fn depth(&self, p: DVec3) -> f64 {
        let mut node = &self.root;
        let mut depth = f64::INFINITY;
        loop {
            match node {
                Node::Rank(_) => return depth,
                Node::Cut {
                    axis,
                    at,
                    below,
                    above,
                } => {
                    depth = depth.min((p[*axis] - *at).abs());
                    node = if p[*axis] < *at { below } else { above };
                }
            }
        }
    }

    /// Every rank whose region comes within `halo` of `p` (on each axis: the closed box of half
    /// side `halo` about `p` meets it), the owner included, in increasing order: a body there
    /// must be a ghost on each of them but its owner.
    pub fn ranks_near(&self, p: DVec3, halo: f64) -> Vec<usize> {
        let mut found = Vec::new();
        self.ranks_near_into(p, halo, &mut found);
        found
    }

    /// [`Decomposition::ranks_near`] into `found` (cleared first), with no allocation once
    /// `found` has room: a redraw asks this of every body.
    pub fn ranks_near_into(&self, p: DVec3, halo: f64, found: &mut Vec<usize>) {
        found.clear();
        // Depth-first; the stack holds at most one node per level of the tree, which has fewer
        // levels than a usize has bits (each cut halves the ranks).
        let mut stack: [&Node; usize::BITS as usize + 1] = [&self.root; usize::BITS as usize + 1];
        let mut depth = 1;
        while depth > 0 {
            depth -= 1;
            match stack[depth] {
                Node::Rank(rank) => found.push(*rank),
                Node::Cut {
                    axis,
                    at,
                    below,
                    above,
                } => {
                    if p[*axis] + halo >= *at {
                        stack[depth] = above;
                        depth += 1;
                    }
                    if p[*axis] - halo < *at {
                        stack[depth] = below;
                        depth += 1;
                    }
                }
            }
        }
        found.sort_unstable();
    }

    /// Each rank's region, by rank.
    pub fn regions(&self) -> Vec<Region> {
        let mut regions = vec![Region::everything(); self.ranks];
        let mut stack = vec![(&self.root, Region::everything())];
        while let Some((node, region)) = stack.pop() {
            match node {
                Node::Rank(rank) => regions[*rank] = region,
                Node::Cut {
                    axis,
                    at,
                    below,
                    above,
                } => {
                    let (b, a) = region.split(*axis, *at);
                    stack.push((below, b));
                    stack.push((above, a));
                }
            }
        }
        regions
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn point(r: f64) -> impl Strategy<Value = DVec3> {
        (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| DVec3::new(x, y, z))
    }

    /// Bodies in a flat layer, in a cluster, or on a coarse lattice (many share coordinates).
    fn bodies() -> impl Strategy<Value = Vec<DVec3>> {
        prop_oneof![
            prop::collection::vec(
                point(1.0).prop_map(|p| p * DVec3::new(5.0, 3.0, 0.2)),
                0..300
            ),
            prop::collection::vec(point(1.0).prop_map(|p| p * p.length_squared()), 1..300),
            prop::collection::vec(point(4.0).prop_map(|p| p.round()), 1..300),
        ]
    }

    proptest! {
        /// Every body has one owner; the counts are as even as the bodies allow (exactly
        /// ⌊n/P⌋ or ⌈n/P⌉ when no two bodies share a coordinate); the regions tile space.
        #[test]
        fn bisection_balances_the_bodies(positions in bodies(), ranks in 1..9usize) {
            let d = Decomposition::new(ranks, &mut LocalBodies(&positions));
            let regions = d.regions();
            let mut owned = vec![0usize; ranks];
            for p in &positions {
                let owner = d.owner(*p);
                owned[owner] += 1;
                let holders: Vec<usize> =
                    (0..ranks).filter(|&r| regions[r].contains(*p)).collect();
                prop_assert_eq!(holders, vec![owner]);
            }
            let distinct = (0..3).all(|k| {
                let mut c: Vec<u64> = positions.iter().map(|p| p[k].to_bits()).collect();
                c.sort_unstable();
                c.windows(2).all(|w| w[0] != w[1])
            });
            let n = positions.len();
            if distinct {
                for &count in &owned {
                    prop_assert!(count == n / ranks || count == n.div_ceil(ranks), "{owned:?}");
                }
            }
            prop_assert_eq!(owned.iter().sum::<usize>(), n);
        }

        /// `ranks_near` is every rank whose region meets the halo box, by brute force over the
        /// regions.
        #[test]
        fn ghost_ranks_are_the_regions_within_the_halo(
            positions in bodies(),
            ranks in 1..9usize,
            probes in prop::collection::vec(point(6.0), 1..20),
            halo in 0.0..2.0f64,
        ) {
            let d = Decomposition::new(ranks, &mut LocalBodies(&positions));
            let regions = d.regions();
            for p in probes {
                let expected: Vec<usize> = (0..ranks)
                    .filter(|&r| {
                        (0..3).all(|k| {
                            p[k] + halo >= regions[r].lower[k] && p[k] - halo < regions[r].upper[k]
                        })
                    })
                    .collect();
                prop_assert_eq!(d.ranks_near(p, halo), expected);
                prop_assert!(d.ranks_near(p, halo).contains(&d.owner(p)));
            }
        }
    }

    proptest! {
        /// Within its depth a point has no rank near it but its owner; a little beyond a finite
        /// depth, another rank's region.
        #[test]
        fn depth_is_the_distance_to_the_nearest_other_region(
            positions in bodies(),
            ranks in 1..9usize,
            probes in prop::collection::vec(point(6.0), 1..20),
        ) {
            let d = Decomposition::new(ranks, &mut LocalBodies(&positions));
            for p in probes {
                let depth = d.depth(p);
                prop_assert!(depth >= 0.0);
                if depth.is_infinite() {
                    prop_assert_eq!(ranks, 1);
                    continue;
                }
                prop_assert_eq!(d.ranks_near(p, 0.999 * depth), vec![d.owner(p)]);
                let beyond = 1.001 * depth + 1e-12;
                prop_assert!(d.ranks_near(p, beyond).len() > 1, "depth {depth} at {p:?}");
            }
        }
    }

    #[test]
    fn cuts_go_across_the_longest_side() {
        let positions: Vec<DVec3> = (0..100)
            .map(|i| DVec3::new(i as f64, (i % 7) as f64 * 0.1, 0.0))
            .collect();
        let d = Decomposition::new(2, &mut LocalBodies(&positions));
        let regions = d.regions();
        assert_eq!(regions[0].upper.x, regions[1].lower.x);
        assert!((49.0..=50.0).contains(&regions[0].upper.x), "{regions:?}");
        assert_eq!(regions[0].upper.y, f64::INFINITY);
    }
}
