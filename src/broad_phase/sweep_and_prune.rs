use super::{BroadPhase, CellGrid, Pair, GONE};
use crate::groups::for_each_group_mut;
use crate::math::{Aabb, DVec3};
use crate::tight::{keep_room, resize_tight};
use rayon::prelude::*;

mod region;

use region::{Partner, Region};

/// Sweep and prune with insertion-sorted endpoint lists: the Linked Linear List (LLL) of
/// Schinner (1999, Granular Matter 2:35) as used for DEM by Muth, Eberhard & Luding, and the
/// "sweep and prune" of I-COLLIDE (Cohen, Lin, Manocha & Ponamgi 1995), on a uniform grid of
/// regions each with its own lists ("multi-SAP": Tracy, Dreiling & Heins 2009, IEEE VR; Bullet's
/// `btMultiSapBroadphase`).
///
/// **The LLL.** Every box is projected on x, y and z. For each axis a list of begin points
/// (`min`) and end points (`max`) is kept sorted. Between calls bodies move little, so the old
/// order is almost right: it is repaired by insertion sort, and every adjacent swap of a begin and
/// an end of two different bodies is an *event* — a begin moving below another body's end means
/// the two intervals start overlapping on that axis; an end moving below another body's begin
/// means they stop.
///
/// **Why regions.** In 3-D, at a fixed density, one list per axis over the whole domain holds
/// about `n^(2/3)` endpoints per unit length, so each moving endpoint makes `O(n^(2/3))` swaps and
/// a call costs `O(n^(5/3))`, with lists far larger than the caches besides. Here space is cut
/// into a uniform grid of box-shaped *regions*, chosen at a rebuild to hold about
/// `bodies_per_region` boxes each (default [`DEFAULT_BODIES_PER_REGION`]) and never narrower than
/// the largest box, so most boxes lie in one region and none in more than two per axis (boxes
/// that grow later may span more; that stays correct). Each region keeps the three LLL lists of
/// the boxes overlapping it (closed boxes against the region's cells, the outer regions reaching
/// to infinity), short and cache resident, so a call costs `O(n)` at a fixed density.
///
/// **A call** (after the first): each box's range of regions is recomputed (with a hysteresis of
/// 1/16 region, so that boxes vibrating across a boundary do not leave and re-enter at every call).
/// Then region by region — regions are independent, so they are updated side by side on the
/// threads, and each is touched once while it is in cache: (1) a box that left the region is
/// *removed*, with the lists still in the previous call's state: its pairs there leave, and its
/// endpoints stay as inert "dead" entries until they are an eighth of the lists, when one pass
/// sweeps them out; (2) the new coordinates are written into the lists and the lists are repaired
/// by insertion sort, with their events; (3) a box that entered the region is *inserted*: its pairs
/// with the members are found by testing their new boxes, and its endpoints are merged into the now
/// sorted lists. A removal or insertion costs a pass over the region's members; boxes cross region
/// boundaries rarely (a fraction `motion / region side` of them per call), so this is a small part
/// of the cost.
///
/// **Tie rule.** The lists are ordered by `(value, kind)` with a begin before an end at equal
/// values. Then "begin of `a` precedes end of `b`" is exactly `a.min <= b.max`, so two intervals
/// overlap as *closed* intervals (touching counts, as in [`Aabb::overlaps`]) iff each one's begin
/// precedes the other's end. Insertion sort only swaps neighbours that are strictly out of order,
/// so equal keys (two begins or two ends at one value) never swap and never make an event, and a
/// body's own begin never passes its own end (`min <= max`). `-0.0` is stored as `0.0` so the list
/// order agrees with `<=`.
///
/// **Count invariant.** In one region, define a pair's overlap on an axis by *list positions*
/// (begin of each precedes the end of the other), not by values. Each adjacent begin/end swap
/// flips that for exactly one pair on one axis and nothing else, so at every moment — also in the
/// middle of a sort, with other axes not yet repaired — the pairs overlapping in the region are
/// exactly those whose count of positionally overlapping axes is 3; once all three lists are
/// sorted, positions agree with values. That count is not stored per pair (a map of every pair
/// overlapping on at least one axis would be far larger than the candidate set): each member keeps
/// its begin and end *positions* on every axis (`rank`), and an event on one axis reads the pair's
/// overlap on the other two axes from them in O(1) (as Bullet's `btAxisSweep3` does): the pair
/// enters the region when its count goes 2 → 3 and leaves when it goes 3 → 2. A removal (in the
/// old state) makes every pair the box has in the region leave it, an insertion (in the new,
/// sorted state, where positions agree with values) makes every pair it has there enter.
///
/// **One report per pair.** Two boxes may overlap in several regions (when both straddle a
/// boundary). The candidate set keeps, per pair, the *number of regions* in which it overlaps,
/// and a pair is a candidate while that number is positive. This is exact: two closed boxes that
/// overlap share a point, hence the region of that point (the region index of a coordinate is
/// monotone in it), and in every region they share, sorted lists see them overlap. The
/// alternative rule, "only the region holding the lower corner of the intersection reports the
/// pair", needs no count but ties a pair's owner to coordinates that change without any list
/// event in the regions concerned (the corner moves to a neighbouring region when one box's
/// `min` crosses the boundary, while both boxes stay in both regions), so every boundary crossing
/// would have to re-examine the box's pairs in every region; the counts make each region an
/// independent LLL whose events are simply added up. The rule is used once, at a rebuild, where
/// the sweep of each region reports only the pairs whose first shared region it is, with their
/// count of shared regions computed from the two boxes' region ranges.
///
/// **Candidate set.** Per body `i`, the sorted list of its partners `j > i` with their counts.
/// Insertion and removal are a binary search and a short shift in a list of a few entries, and
/// the output, sorted ascending as the trait requires, is a plain concatenation — O(n + pairs), no
/// global sort.
///
/// **Renumbering.** A caller that renumbers its bodies says so ([`BroadPhase::renumber`],
/// [`BroadPhase::append`]): where the kept bodies keep their order, bodies that left are removed
/// from their regions at once, the lists and the candidate set take the new indices, and
/// appended bodies are inserted where their boxes are at the next call, like boxes that
/// teleported; a new order starts afresh (see [`SweepAndPrune::follow_renumbering`]). A share
/// of a decomposed world renumbers at every redraw, where a list made by a repair took 24 ms
/// against 58 ms from scratch (the 65,000-sphere bed, docs/benchmarks.md).
///
/// **Rebuilds.** The first call, a change in the number of bodies not announced that way, a
/// region grown far beyond the size chosen (bodies gathering; the grid is then chosen anew) or a
/// call whose region changes and swaps would cost more than a fresh start (e.g. every body
/// teleported; then the next calls rebuild directly for a while, with exponential backoff) sort
/// every region's lists from scratch and find the pairs by a sweep of each region or, when
/// estimated cheaper, a [`CellGrid`]. A few bodies teleporting are just removals and insertions.
///
/// A region's events (pairs starting or stopping to overlap there) are kept with it and applied
/// to the candidate set once every region is done, region by region in the order of a single
/// pass, so the result and the internal state are the same for any thread count.
///
/// No allocation per call in steady state: all buffers are kept and reused.
#[derive(Clone, Debug, Default)]
pub struct SweepAndPrune {
    /// Boxes a region is made for at a rebuild; 0 for [`DEFAULT_BODIES_PER_REGION`].
    bodies_per_region: usize,
    /// A region side imposed instead (tests: many small regions, boxes larger than regions).
    fixed_side: Option<f64>,
    grid: RegionGrid,
    regions: Vec<Region>,
    /// Per body, the first and last region coordinates its box overlaps, per axis.
    range: Vec<Range>,
    /// `partners[i]`: every `j > i` whose box overlaps box `i`, ascending, with the number of
    /// regions in which they overlap.
    partners: Vec<Vec<Partner>>,
    /// Whether the lists describe the boxes of the previous call.
    initialised: bool,
    /// Working memory of [`write_pairs`].
    pair_starts: Vec<u32>,
    /// Per work item of an update, the boxes whose regions change, with their new ones.
    changed: Vec<Vec<(u32, Range)>>,
    /// Rough cost of a full rebuild, in swap-sized units: an update gives up beyond it.
    rebuild_cost: usize,
    /// For a rebuild's pairs when it is cheaper than the sweeps (dense packings of similar sizes).
    cell_grid: CellGrid,
    /// A region holding more members than this makes the next call choose a new grid.
    crowded: usize,
    /// The next call rebuilds with a new grid.
    regrid: bool,
    /// Bodies appended since the last call ([`BroadPhase::append`]), in no region yet: the
    /// next call inserts them where their boxes are.
    pending: Vec<u32>,
    /// `(region, body)` of the boxes leaving and entering regions in this call.
    leaving: Vec<(u32, u32)>,
    entering: Vec<(u32, u32)>,
    /// Working memory of the updates' work items ([`WORK_ITEMS`]).
    scratch: Vec<region::Scratch>,
    /// Scratch of a rebuild's sweep.
    sweep_axis: Vec<u8>,
    active: Vec<(u32, [f64; 4])>,
    active_slot: Vec<u32>,
    swaps: usize,
    crossings: usize,
    rebuilds: usize,
    /// Whether the last rebuild took its pairs from `cell_grid`.
    grid_rebuild: bool,
    /// After an update gave up (too much motion per call), the next `skip` calls rebuild
    /// straight away; `backoff`, doubled on each consecutive give-up, is the next such wait.
    skip: u32,
    backoff: u32,
}

/// Boxes per region aimed at when the grid is chosen. Measured on the benchmark scenes (gas,
/// packing) at 10⁵ and 10⁶ bodies: 250–500 is the optimum, 2000 is 20–40 % slower and 4000
/// 50–80 % (swaps per body grow like `k^(2/3)`, and on lattices like the number of bodies sharing
/// a lattice plane in a region); below 250 boxes straddling boundaries and crossings dominate.
pub const DEFAULT_BODIES_PER_REGION: usize = 500;

/// How far (in region sides) a box's side may withdraw from a region before the box leaves it.
const HYSTERESIS: f64 = 1.0 / 16.0;

/// `[first, last]` region coordinates of a box, each `[x, y, z]`.
type Range = [[u16; 3]; 2];

/// A uniform grid of regions: region `(x, y, z)` covers `origin + side * [x, x + 1)` etc., the
/// first and last ones of each axis extending to infinity.
#[derive(Clone, Copy, Debug, Default)]
struct RegionGrid {
    origin: DVec3,
    inv_side: DVec3,
    dims: [usize; 3],
}

impl RegionGrid {
    /// Region coordinate of `v` on `axis`: monotone in `v`, so a box's range of regions holds
    /// the region of each of its points.
    #[inline]
    fn coord(&self, v: f64, axis: usize) -> u16 {
        self.clamp((v - self.origin[axis]) * self.inv_side[axis], axis)
    }

    /// The region of a coordinate in region units.
    #[inline]
    fn clamp(&self, c: f64, axis: usize) -> u16 {
        // Truncation is floor for `c >= 0` (and needs no call to `floor`); `as` saturates, and
        // `max` maps NaN to 0.
        (c.max(0.0) as usize).min(self.dims[axis] - 1) as u16
    }

    /// The regions a box is kept in, given those it was in: all it overlaps, and, on each side,
    /// the old bound if the box still reaches within [`HYSTERESIS`] of it — so that a box
    /// whose side hovers around a region boundary (a packing vibrating in place) does not leave
    /// and re-enter at every call. Any range holding the overlapped regions is correct.
    #[inline]
    fn membership(&self, b: &Aabb, old: &Range) -> Range {
        let mut r = *old;
        for axis in 0..3 {
            let lo = (b.min[axis] - self.origin[axis]) * self.inv_side[axis];
            let tight = self.clamp(lo, axis);
            if old[0][axis] != tight {
                let loose = self.clamp(lo - HYSTERESIS, axis);
                if !(loose <= old[0][axis] && old[0][axis] <= tight) {
                    r[0][axis] = tight;
                }
            }
            let hi = (b.max[axis] - self.origin[axis]) * self.inv_side[axis];
            let tight = self.clamp(hi, axis);
            if old[1][axis] != tight {
                let loose = self.clamp(hi + HYSTERESIS, axis);
                if !(tight <= old[1][axis] && old[1][axis] <= loose) {
                    r[1][axis] = tight;
                }
            }
        }
        r
    }

    #[inline]
    fn range(&self, b: &Aabb) -> Range {
        [
            [
                self.coord(b.min.x, 0),
                self.coord(b.min.y, 1),
                self.coord(b.min.z, 2),
            ],
            [
                self.coord(b.max.x, 0),
                self.coord(b.max.y, 1),
                self.coord(b.max.z, 2),
            ],
        ]
    }

    fn count(&self) -> usize {
        self.dims.iter().product()
    }

    #[inline]
    fn id(&self, c: [u16; 3]) -> usize {
        (c[2] as usize * self.dims[1] + c[1] as usize) * self.dims[0] + c[0] as usize
    }

    fn coords(&self, id: usize) -> [u16; 3] {
        let (nx, ny) = (self.dims[0], self.dims[1]);
        [
            (id % nx) as u16,
            (id / nx % ny) as u16,
            (id / (nx * ny)) as u16,
        ]
    }
}

/// The region coordinates of a range, x fastest.
fn regions_of(r: Range) -> impl Iterator<Item = [u16; 3]> {
    (r[0][2]..=r[1][2]).flat_map(move |z| {
        (r[0][1]..=r[1][1]).flat_map(move |y| (r[0][0]..=r[1][0]).map(move |x| [x, y, z]))
    })
}

#[inline]
fn contains(r: &Range, c: [u16; 3]) -> bool {
    (0..3).all(|k| r[0][k] <= c[k] && c[k] <= r[1][k])
}

/// Number of regions two ranges share.
#[inline]
fn shared(a: &Range, b: &Range) -> u32 {
    (0..3)
        .map(|k| {
            let lo = a[0][k].max(b[0][k]) as u32;
            (a[1][k].min(b[1][k]) as u32 + 1).saturating_sub(lo)
        })
        .product()
}

impl SweepAndPrune {
    /// Regions made for about `k` boxes each (the default is [`DEFAULT_BODIES_PER_REGION`]).
    pub fn with_bodies_per_region(k: usize) -> Self {
        Self {
            bodies_per_region: k.max(1),
            ..Self::default()
        }
    }

    /// Regions of side `side` (at least), whatever the box sizes: for tests.
    #[cfg(test)]
    pub(crate) fn with_region_side(side: f64) -> Self {
        Self {
            fixed_side: Some(side),
            ..Self::default()
        }
    }

    /// Forgets the lists, so the next call rebuilds from scratch. Never needed for correctness:
    /// bodies renumbered without their number changing are just bodies that moved (swaps, or a
    /// rebuild once those would cost more); this only saves that work when a caller knows.
    pub fn reset(&mut self) {
        self.initialised = false;
    }

    /// Follows a renumbering that keeps the order of the bodies it keeps (a share's redraw, see
    /// [`BroadPhase::renumber`]): the gone bodies leave their regions and the candidate set now,
    /// and the lists, ranges and candidate set take the new indices.
    ///
    /// Not after appends not yet inserted, nor a new order (a sort in space): the next call
    /// starts afresh then. Followed, a new order turns pairs and moves them between the
    /// per-body lists, which then keep the room of the largest list each slot ever held and
    /// fragment the allocator's heap: at 65,000 spheres sorted every thousand steps the peak
    /// memory rose by 7 MB, where a rebuild instead of a repair once in 1,000 steps costs some
    /// 34 ms in 12 s (58 against 24 ms).
    fn follow_renumbering(&mut self, new_index: &[u32]) -> bool {
        let mut next = 0;
        let in_order = new_index.iter().filter(|&&to| to != GONE).all(|&to| {
            let next_in_order = to == next;
            next += 1;
            next_in_order
        });
        if !in_order
            || !self.initialised
            || !self.pending.is_empty()
            || new_index.len() != self.range.len()
        {
            return false;
        }
        let grid = self.grid;
        self.leaving.clear();
        for (i, _) in new_index.iter().enumerate().filter(|(_, &to)| to == GONE) {
            let regions = regions_of(self.range[i]).map(|c| grid.id(c) as u32);
            self.leaving.extend(regions.map(|r| (r, i as u32)));
        }
        self.leaving.sort_unstable();
        let mut gone = Vec::new();
        let mut remap = Vec::new();
        for run in self.leaving.chunk_by(|a, b| a.0 == b.0) {
            gone.clear();
            gone.extend(run.iter().map(|&(_, body)| body));
            let region = &mut self.regions[run[0].0 as usize];
            region.remove_now(&gone, &mut remap);
            region::apply(&mut self.partners, &region.events);
            region.events.clear();
        }
        for region in &mut self.regions {
            for m in region.members.iter_mut().filter(|m| **m != region::DEAD) {
                *m = new_index[*m as usize];
            }
        }
        // Each list moves down to its body's new slot, ascending as it was, and keeps its room;
        // a gone body's list (empty now) is freed.
        let count = next as usize;
        for (i, &to) in new_index.iter().enumerate() {
            if to == GONE {
                continue;
            }
            let mut list = std::mem::take(&mut self.partners[i]);
            for p in &mut list {
                p.body = new_index[p.body as usize];
                debug_assert!(p.body != GONE, "a gone body's pairs left with it");
            }
            self.partners[to as usize] = list;
            self.range[to as usize] = self.range[i];
        }
        self.partners.truncate(count);
        self.range.truncate(count);
        true
    }

    /// Adjacent swaps made by the insertion sorts of the last call (0 after a rebuild).
    pub fn swaps_last_call(&self) -> usize {
        self.swaps
    }

    /// Removals of boxes from regions and insertions into regions in the last call.
    pub fn crossings_last_call(&self) -> usize {
        self.crossings
    }

    /// How many times the lists were rebuilt from scratch.
    pub fn rebuilds(&self) -> usize {
        self.rebuilds
    }

    /// Number of regions of the current grid.
    pub fn region_count(&self) -> usize {
        self.regions.len()
    }

    fn target(&self) -> f64 {
        match self.bodies_per_region {
            0 => DEFAULT_BODIES_PER_REGION as f64,
            k => k as f64,
        }
    }

    /// The grid for `boxes`: cubic cells of side about `(target * volume / n)^(1/3)`, no smaller
    /// than the largest box, stretched per axis to tile the bounds of the boxes exactly; at most
    /// a few regions per body and 65 536 per axis.
    fn choose_grid(&self, boxes: &[Aabb]) -> RegionGrid {
        let n = boxes.len();
        let Some(first) = boxes.first() else {
            return RegionGrid {
                origin: DVec3::ZERO,
                inv_side: DVec3::ZERO,
                dims: [1; 3],
            };
        };
        let (mut bounds, mut largest) = (*first, 0.0f64);
        for b in boxes {
            bounds = bounds.union(b);
            largest = largest.max(b.extent().max_element());
        }
        let extent = bounds.extent();
        let single = RegionGrid {
            origin: bounds.min,
            inv_side: DVec3::ZERO,
            dims: [1; 3],
        };
        if !extent.is_finite() || !largest.is_finite() {
            return single;
        }
        let target = self.target();
        let mut side = match self.fixed_side {
            Some(side) => side,
            None => {
                let span = extent.max(DVec3::splat(largest));
                (target * span.element_product() / n as f64)
                    .cbrt()
                    .max(largest)
            }
        };
        side = side.max(extent.max_element() * 1e-6).max(f64::MIN_POSITIVE);
        let mut min_side = self.fixed_side.unwrap_or(largest).max(f64::MIN_POSITIVE);
        let max_regions = (4 * n).max(4096);
        loop {
            // Whole regions per axis, of side about `side` but no smaller than `min_side`.
            let dims = (extent / side)
                .round()
                .min((extent / min_side).floor())
                .max(DVec3::ONE);
            let count = dims.element_product();
            if count > max_regions as f64 || dims.max_element() > u16::MAX as f64 {
                side *= 1.5;
                min_side *= 1.5;
                continue;
            }
            if self.fixed_side.is_none() && count > 1.0 && (n as f64) < 0.5 * target * count {
                // Flat or elongated domains: regions thinner than the domain hold too few.
                side *= 1.26;
                continue;
            }
            let inv_side = DVec3::select(extent.cmpgt(DVec3::ZERO), dims / extent, DVec3::ZERO);
            return RegionGrid {
                origin: bounds.min,
                inv_side,
                dims: [dims.x as usize, dims.y as usize, dims.z as usize],
            };
        }
    }

    /// Full rebuild: a new grid, every region's lists sorted from scratch, and the pairs found by
    /// sweeping each region along its best axis or, when estimated cheaper, by a [`CellGrid`]
    /// (using `scratch` for its pairs).
    fn rebuild(&mut self, boxes: &[Aabb], scratch: &mut Vec<Pair>) {
        let n = boxes.len();
        self.rebuilds += 1;
        self.pending.clear();
        self.swaps = 0;
        self.crossings = 0;
        self.regrid = false;
        self.grid = self.choose_grid(boxes);
        let grid = self.grid;
        let count = grid.count();
        self.regions.truncate(count);
        for r in &mut self.regions {
            r.clear();
        }
        self.regions.resize_with(count, Region::default);
        self.range.clear();
        self.range.extend(boxes.iter().map(|b| grid.range(b)));
        for (i, r) in self.range.iter().enumerate() {
            for c in regions_of(*r) {
                self.regions[grid.id(c)].members.push(i as u32);
            }
        }

        let (mut sort_cost, mut sweep_cost, mut largest_region) = (0, 0, 0);
        self.sweep_axis.clear();
        for region in &mut self.regions {
            let overlaps = region.build(boxes);
            let axis = (0..3).min_by_key(|&a| overlaps[a]).unwrap_or(0);
            self.sweep_axis.push(axis as u8);
            sweep_cost += overlaps[axis];
            let len = 2 * region.len();
            sort_cost += 3 * len * (usize::BITS - len.leading_zeros()) as usize;
            largest_region = largest_region.max(region.len());
        }
        self.crowded = 4 * largest_region.max(self.target() as usize);

        self.partners.truncate(n);
        for p in &mut self.partners {
            p.clear();
        }
        self.partners.resize_with(n, Vec::new);
        let grid_work = grid_work(boxes);
        let use_grid = grid_work < sweep_cost as f64;
        self.grid_rebuild = use_grid;
        let mut pairs = 0;
        if use_grid {
            self.cell_grid.find_pairs(boxes, scratch);
            // In ascending order, so each body's list comes out sorted.
            for &(i, j) in scratch.iter() {
                self.partners[i as usize].push(Partner {
                    body: j,
                    regions: shared(&self.range[i as usize], &self.range[j as usize]),
                });
            }
            pairs = scratch.len();
        } else {
            for (id, region) in self.regions.iter().enumerate() {
                region.sweep(
                    self.sweep_axis[id] as usize,
                    grid.coords(id),
                    &self.range,
                    boxes,
                    &mut self.active,
                    &mut self.active_slot,
                    &mut self.partners,
                );
            }
            for p in &mut self.partners {
                p.sort_unstable_by_key(|p| p.body);
                pairs += p.len();
            }
        }
        let search_cost = if use_grid {
            grid_work as usize
        } else {
            sweep_cost
        };
        self.rebuild_cost = sort_cost + search_cost + pairs + 1024;
        self.initialised = true;
    }

    /// Moves boxes between regions and insertion sorts every region's lists after new values are
    /// read from `boxes`, updating the candidate set. Returns false, leaving a state only fit for
    /// [`Self::rebuild`], once the work exceeds what a rebuild would cost.
    fn update(&mut self, boxes: &[Aabb]) -> bool {
        self.swaps = 0;
        self.leaving.clear();
        self.entering.clear();
        // Work of the removals and insertions: a pass over the region's members each.
        let mut work = 0usize;
        let grid = self.grid;
        // Appended bodies enter every region their boxes overlap; then their ranges are current,
        // like every other box's before its move.
        for i in std::mem::take(&mut self.pending) {
            let range = grid.range(&boxes[i as usize]);
            for c in regions_of(range) {
                let id = grid.id(c);
                work += self.regions[id].len() + 1;
                self.entering.push((id as u32, i));
            }
            self.range[i as usize] = range;
        }
        // The boxes whose regions change (few), found in parallel, each work item's in a list of
        // its own, then taken in order.
        let per_item = boxes.len().div_ceil(WORK_ITEMS).max(1);
        self.changed.resize_with(WORK_ITEMS, Vec::new);
        self.changed.iter_mut().for_each(Vec::clear);
        boxes
            .par_chunks(per_item)
            .zip(self.range.par_chunks(per_item))
            .zip(self.changed.par_iter_mut())
            .enumerate()
            .for_each(|(item, ((boxes, ranges), changed))| {
                let first = (item * per_item) as u32;
                for ((i, b), old) in (first..).zip(boxes).zip(ranges) {
                    let new = grid.membership(b, old);
                    if new != *old {
                        changed.push((i, new));
                    }
                }
            });
        for &(i, new) in self.changed.iter().flatten() {
            let i = i as usize;
            let old = self.range[i];
            for c in regions_of(old).filter(|&c| !contains(&new, c)) {
                let id = grid.id(c);
                work += self.regions[id].len() + 1;
                self.leaving.push((id as u32, i as u32));
            }
            for c in regions_of(new).filter(|&c| !contains(&old, c)) {
                let id = grid.id(c);
                work += self.regions[id].len() + 1;
                self.entering.push((id as u32, i as u32));
            }
            self.range[i] = new;
        }
        self.crossings = self.leaving.len() + self.entering.len();
        if work > self.rebuild_cost {
            return false;
        }

        // Region by region (regions are independent, and each is touched once while in cache),
        // the regions side by side: (1) removals, in the previous call's state; (2) the LLL; (3)
        // insertions, in the new sorted state. Each region keeps its overlap events, which are
        // then applied to the candidate set region by region, in the order a single pass would.
        self.leaving.sort_unstable();
        self.entering.sort_unstable();
        let (leaving, entering) = (&self.leaving[..], &self.entering[..]);
        let of_region = |list: &'_ [(u32, u32)], id: usize| {
            let start = list.partition_point(|&(r, _)| (r as usize) < id);
            let end = list.partition_point(|&(r, _)| (r as usize) <= id);
            start..end
        };
        let budget = self.rebuild_cost - work;
        let crowded = self.crowded;
        let per_item = self.regions.len().div_ceil(WORK_ITEMS).max(1);
        self.scratch.resize_with(WORK_ITEMS, Default::default);
        let outcome = self
            .regions
            .par_chunks_mut(per_item)
            .zip(self.scratch.par_iter_mut())
            .enumerate()
            .map(|(item, (regions, scratch))| {
                let (mut swaps, mut regrid) = (0, false);
                for (k, region) in regions.iter_mut().enumerate() {
                    let id = item * per_item + k;
                    let (leave, enter) = (of_region(leaving, id), of_region(entering, id));
                    swaps += region.update(
                        &leaving[leave],
                        &entering[enter.clone()],
                        boxes,
                        budget.checked_sub(swaps)?,
                        scratch,
                    )?;
                    regrid |= !enter.is_empty() && region.len() > crowded;
                }
                Some((swaps, regrid))
            })
            .try_reduce(|| (0, false), |a, b| Some((a.0 + b.0, a.1 || b.1)));
        let Some((swaps, regrid)) = outcome else {
            return false;
        };
        self.swaps = swaps;
        if swaps > budget {
            return false;
        }
        self.regrid |= regrid;
        for region in &self.regions {
            region::apply(&mut self.partners, &region.events);
        }
        true
    }
}

/// Parallel work items of an update, each a run of regions with working memory of its own (kept
/// from call to call): enough to balance the threads, as regions differ in their work.
const WORK_ITEMS: usize = 16;

impl BroadPhase for SweepAndPrune {
    fn find_pairs(&mut self, boxes: &[Aabb], pairs: &mut Vec<Pair>) {
        assert!(boxes.len() < 1 << 31, "too many bodies for 31-bit indices");
        if !self.initialised || self.range.len() != boxes.len() || self.regrid {
            self.rebuild(boxes, pairs);
        } else if self.skip > 0 {
            self.skip -= 1;
            self.rebuild(boxes, pairs);
        } else if self.update(boxes) {
            self.backoff = 0;
        } else {
            // Gave up half way: so as not to pay that twice per call while bodies move this
            // fast, rebuild directly for a while (exponential backoff, at most 64 calls).
            self.backoff = (2 * self.backoff).clamp(1, 64);
            self.skip = self.backoff;
            self.rebuild(boxes, pairs);
        }
        write_pairs(&self.partners, &mut self.pair_starts, pairs);
    }

    fn renumber(&mut self, new_index: &[u32]) -> bool {
        self.follow_renumbering(new_index)
    }

    fn append(&mut self, added: usize) -> bool {
        if self.initialised {
            let n = self.range.len();
            self.pending.extend(n as u32..(n + added) as u32);
            self.range.resize(n + added, [[0; 3]; 2]);
            self.partners.resize_with(n + added, Vec::new);
        }
        true
    }

    fn name(&self) -> &'static str {
        "sweep_and_prune"
    }
}

/// The pairs of the candidate set, ascending: body by body, each body's partners. Written in
/// parallel by groups of bodies, each body's place in the list counted first (`starts`, kept
/// from call to call).
fn write_pairs(partners: &[Vec<Partner>], starts: &mut Vec<u32>, pairs: &mut Vec<Pair>) {
    starts.clear();
    starts.push(0);
    let mut total = 0;
    for list in partners {
        total += list.len() as u32;
        starts.push(total);
    }
    pairs.clear();
    resize_tight(pairs, total as usize, (0, 0));
    // A rebuild may have pushed its pairs into the same list (doubling it).
    keep_room(pairs);
    for_each_group_mut(pairs, starts, |i, out| {
        for (slot, p) in out.iter_mut().zip(&partners[i]) {
            *slot = (i as u32, p.body);
        }
    });
}

/// Rough number of box tests a [`CellGrid`] makes: 27 cells of bodies per body, cells no smaller
/// than the largest box and at most 4 per body.
fn grid_work(boxes: &[Aabb]) -> f64 {
    let Some(first) = boxes.first() else {
        return 0.0;
    };
    let (mut bounds, mut largest) = (*first, 0.0f64);
    for b in boxes {
        bounds = bounds.union(b);
        largest = largest.max(b.extent().max_element());
    }
    let n = boxes.len() as f64;
    let cells = (bounds.extent() / largest.max(f64::MIN_POSITIVE) + DVec3::ONE)
        .floor()
        .element_product()
        .min(4.0 * n);
    27.0 * n * (1.0 + n / cells)
}

#[cfg(test)]
mod tests {
    use super::super::BruteForce;
    use super::*;
    use crate::math::DVec3;

    fn cube(x: f64, y: f64, z: f64, h: f64) -> Aabb {
        Aabb::around_sphere(DVec3::new(x, y, z), h)
    }

    fn check(sap: &mut SweepAndPrune, boxes: &[Aabb]) -> Vec<Pair> {
        let (mut expected, mut found) = (Vec::new(), Vec::new());
        BruteForce.find_pairs(boxes, &mut expected);
        sap.find_pairs(boxes, &mut found);
        assert_eq!(found, expected);
        found
    }

    #[test]
    fn touching_boxes_are_a_pair() {
        let mut sap = SweepAndPrune::default();
        let mut boxes = vec![
            cube(0.0, 0.0, 0.0, 0.5),
            cube(3.0, 0.0, 0.0, 0.5),
            cube(1.0, 0.0, 0.0, 0.5),
        ];
        assert_eq!(check(&mut sap, &boxes), vec![(0, 2)]);
        // Move into touching contact through the incremental path, on each axis in turn, and
        // with a corner contact (touching on all three axes at once).
        for target in [
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(2.0, 1.0, 0.0),
            DVec3::new(2.0, 1.0, -1.0),
            DVec3::new(4.0, -1.0, 1.0),
        ] {
            boxes[1] = Aabb::around_sphere(target, 0.5);
            check(&mut sap, &boxes);
        }
        boxes[1] = cube(2.0 + 1e-12, 0.0, 0.0, 0.5);
        assert_eq!(check(&mut sap, &boxes), vec![(0, 2)]);
        assert_eq!(sap.rebuilds(), 1);
    }

    #[test]
    fn identical_and_degenerate_boxes() {
        let mut sap = SweepAndPrune::default();
        let mut boxes = vec![cube(1.0, 1.0, 1.0, 0.5); 4];
        boxes.push(cube(1.5, 1.0, 1.0, 0.0)); // a point on the faces of the others
        boxes.push(cube(-0.0, 0.0, 0.0, 0.0)); // points at -0.0 and 0.0
        boxes.push(cube(0.0, -0.0, 0.0, 0.0));
        let pairs = check(&mut sap, &boxes);
        assert_eq!(pairs.len(), 6 + 4 + 1);
        // Shrink all to points at one place, then grow them back.
        for h in [0.25, 0.0, 0.0, 1.0] {
            for b in boxes.iter_mut() {
                *b = cube(1.0, 1.0, 1.0, h);
            }
            check(&mut sap, &boxes);
        }
        assert_eq!(sap.rebuilds(), 1);
    }

    #[test]
    fn negative_zero_touches_zero() {
        // A box ending at -0.0 touches one beginning at +0.0 (`-0.0 <= 0.0`).
        let boxes = [
            Aabb::new(DVec3::splat(-1.0), DVec3::splat(-0.0)),
            Aabb::new(DVec3::splat(0.0), DVec3::splat(1.0)),
        ];
        assert_eq!(check(&mut SweepAndPrune::default(), &boxes), vec![(0, 1)]);
    }

    #[test]
    fn body_passes_through_another() {
        // Body 1 (small) crosses body 0 (large) along x, then along a diagonal, over many calls:
        // it enters, stays in, and leaves, with touching steps on the way.
        let mut sap = SweepAndPrune::default();
        let mut history = Vec::new();
        for step in -12..=12 {
            let x = step as f64 * 0.25;
            let boxes = [cube(0.0, 0.0, 0.0, 1.0), cube(x, 0.1 * x, -0.2 * x, 0.5)];
            history.push(!check(&mut sap, &boxes).is_empty());
        }
        // Overlap (touching included) for |x| <= 1.5: steps -6..=6.
        let expected: Vec<bool> = (-12..=12).map(|s: i32| s.abs() <= 6).collect();
        assert_eq!(history, expected);
        assert_eq!(sap.rebuilds(), 1);
        assert!(sap.swaps_last_call() == 0);
    }

    #[test]
    fn dense_scene_rebuilds_with_the_grid() {
        // Dense and of similar sizes: the rebuild takes its pairs from the cell grid; then the
        // insertion sorts take over.
        let mut rng = crate::rng::SplitMix64::new(5);
        let mut centres: Vec<DVec3> = (0..3000)
            .map(|_| {
                DVec3::new(
                    rng.uniform(0.0, 20.0),
                    rng.uniform(0.0, 20.0),
                    rng.uniform(0.0, 20.0),
                )
            })
            .collect();
        let mut sap = SweepAndPrune::default();
        for _ in 0..5 {
            let boxes: Vec<Aabb> = centres.iter().map(|c| cube(c.x, c.y, c.z, 0.6)).collect();
            check(&mut sap, &boxes);
            for c in centres.iter_mut() {
                *c += DVec3::new(rng.normal(), rng.normal(), rng.normal()) * 0.05;
            }
        }
        assert!(sap.grid_rebuild);
        assert_eq!(sap.rebuilds(), 1);
        assert!(sap.swaps_last_call() > 1000);
    }

    /// Random boxes (half extents 0.05–1, 1:20) in `[0, side]³`.
    fn random_boxes(rng: &mut crate::rng::SplitMix64, n: usize, side: f64) -> Vec<Aabb> {
        (0..n)
            .map(|_| {
                let c = DVec3::new(
                    rng.uniform(0.0, side),
                    rng.uniform(0.0, side),
                    rng.uniform(0.0, side),
                );
                cube(c.x, c.y, c.z, rng.uniform(0.05, 1.0))
            })
            .collect()
    }

    fn shift(b: &Aabb, d: DVec3) -> Aabb {
        Aabb::new(b.min + d, b.max + d)
    }

    #[test]
    fn bodies_cross_small_regions_often() {
        // Regions of side 1 (smaller than the largest boxes, 2) in a gas moving fast: many boxes
        // change regions at every call, pairs are shared by several regions.
        let mut rng = crate::rng::SplitMix64::new(11);
        let mut boxes = random_boxes(&mut rng, 500, 12.0);
        let mut velocity: Vec<DVec3> = (0..boxes.len())
            .map(|_| DVec3::new(rng.normal(), rng.normal(), rng.normal()) * 0.15)
            .collect();
        let mut sap = SweepAndPrune::with_region_side(1.0);
        let mut crossings = 0;
        for _ in 0..40 {
            check(&mut sap, &boxes);
            crossings += sap.crossings_last_call();
            for (b, v) in boxes.iter_mut().zip(&mut velocity) {
                for axis in 0..3 {
                    if b.min[axis] < 0.0 || b.max[axis] > 12.0 {
                        v[axis] = v[axis].abs() * (6.0 - b.min[axis]).signum();
                    }
                }
                *b = shift(b, *v);
            }
        }
        assert!(sap.region_count() > 500, "{} regions", sap.region_count());
        assert!(crossings > 5000, "{crossings} crossings");
        assert_eq!(sap.rebuilds(), 1);
    }

    #[test]
    fn bodies_larger_than_regions() {
        // Boxes spanning up to 16 regions per axis, moving and resizing among small ones; a few
        // teleport every call (removal and insertion, no rebuild).
        let mut rng = crate::rng::SplitMix64::new(12);
        let mut boxes = random_boxes(&mut rng, 300, 8.0);
        for b in boxes.iter_mut().step_by(25) {
            *b = Aabb::new(b.min, b.min + DVec3::new(4.0, 2.5, 3.0));
        }
        let mut sap = SweepAndPrune::with_region_side(0.25);
        for step in 0..30 {
            check(&mut sap, &boxes);
            for (i, b) in boxes.iter_mut().enumerate() {
                let d = DVec3::new(rng.normal(), rng.normal(), rng.normal()) * 0.03;
                *b = shift(b, d);
                if i % 25 == step % 25 {
                    // Grow or shrink a big box on one side.
                    let grow = rng.uniform(-0.3, 0.3);
                    b.max = (b.max + DVec3::splat(grow)).max(b.min);
                }
            }
            for _ in 0..3 {
                let k = rng.next_u64() as usize % boxes.len();
                let to = DVec3::new(
                    rng.uniform(0.0, 8.0),
                    rng.uniform(0.0, 8.0),
                    rng.uniform(0.0, 8.0),
                );
                boxes[k] = shift(&boxes[k], to - boxes[k].min);
            }
        }
        assert_eq!(sap.rebuilds(), 1);
    }

    #[test]
    fn gathering_bodies_choose_a_new_grid() {
        // Regions made for 20 boxes; the bodies then gather towards the middle, crowding a few
        // regions until the grid is chosen anew.
        let mut rng = crate::rng::SplitMix64::new(13);
        let mut boxes = random_boxes(&mut rng, 1500, 40.0);
        let mut sap = SweepAndPrune::with_bodies_per_region(20);
        check(&mut sap, &boxes);
        let regions = sap.region_count();
        assert!(regions > 30, "{regions} regions");
        for _ in 0..25 {
            for b in boxes.iter_mut() {
                let centre = (b.min + b.max) * 0.5;
                *b = shift(b, (DVec3::splat(20.0) - centre) * 0.12);
            }
            check(&mut sap, &boxes);
        }
        assert!(
            sap.rebuilds() > 1 && sap.rebuilds() < 10,
            "{} rebuilds",
            sap.rebuilds()
        );
    }

    #[test]
    fn flat_and_degenerate_domains() {
        // Boxes in a plane, on a line and all at one point: the grid must stay sane.
        let mut rng = crate::rng::SplitMix64::new(14);
        for dims in [
            DVec3::new(30.0, 30.0, 0.0),
            DVec3::new(60.0, 0.0, 0.0),
            DVec3::ZERO,
        ] {
            let mut boxes: Vec<Aabb> = (0..800)
                .map(|_| {
                    let c = DVec3::new(
                        rng.uniform(0.0, 1.0),
                        rng.uniform(0.0, 1.0),
                        rng.uniform(0.0, 1.0),
                    ) * dims;
                    Aabb::new(c, c)
                })
                .collect();
            let mut sap = SweepAndPrune::with_bodies_per_region(25);
            for _ in 0..5 {
                check(&mut sap, &boxes);
                for b in boxes.iter_mut() {
                    *b = shift(
                        b,
                        DVec3::new(rng.normal(), rng.normal(), 0.0) * 0.1 * dims.signum(),
                    );
                }
            }
            assert!(sap.region_count() <= 4096);
        }
    }

    #[test]
    fn teleports_and_body_count_changes() {
        let mut rng = crate::rng::SplitMix64::new(3);
        let mut boxes: Vec<Aabb> = (0..300)
            .map(|_| {
                let c = DVec3::new(
                    rng.uniform(0.0, 10.0),
                    rng.uniform(0.0, 10.0),
                    rng.uniform(0.0, 10.0),
                );
                cube(c.x, c.y, c.z, rng.uniform(0.05, 1.0))
            })
            .collect();
        let mut sap = SweepAndPrune::default();
        for step in 0..60 {
            match step % 10 {
                3 => {
                    boxes.swap_remove(rng.next_u64() as usize % boxes.len());
                }
                7 => boxes.push(cube(5.0, 5.0, 5.0, 0.7)),
                9 => {
                    // Everybody teleports: more swaps than a rebuild, so it rebuilds.
                    boxes.reverse();
                }
                _ => {
                    let k = rng.next_u64() as usize % boxes.len();
                    boxes[k] = cube(rng.uniform(0.0, 10.0), 5.0, rng.uniform(0.0, 10.0), 2.0);
                    for b in boxes.iter_mut() {
                        let d = DVec3::new(rng.normal(), rng.normal(), rng.normal()) * 0.05;
                        *b = Aabb::new(b.min + d, b.max + d);
                    }
                }
            }
            check(&mut sap, &boxes);
        }
        assert!(
            sap.rebuilds() > 6 && sap.rebuilds() < 30,
            "{} rebuilds",
            sap.rebuilds()
        );
    }

    /// Renumbers `boxes` as a share of a decomposed world does at a redraw: drops some (the
    /// others keep their order, or are put in a random order if `shuffle`, as a sort in space
    /// does), tells `sap`, and returns the boxes in their new order, whether `sap` follows, and
    /// whether the kept boxes kept their order.
    fn renumber(
        sap: &mut SweepAndPrune,
        rng: &mut crate::rng::SplitMix64,
        boxes: &[Aabb],
        drop_one_in: u64,
        shuffle: bool,
    ) -> (Vec<Aabb>, bool, bool) {
        let mut kept: Vec<usize> = (0..boxes.len())
            .filter(|_| !rng.next_u64().is_multiple_of(drop_one_in))
            .collect();
        if shuffle {
            for k in (1..kept.len()).rev() {
                kept.swap(k, rng.next_u64() as usize % (k + 1));
            }
        }
        let mut new_index = vec![GONE; boxes.len()];
        for (to, &from) in kept.iter().enumerate() {
            new_index[from] = to as u32;
        }
        let followed = sap.renumber(&new_index);
        let in_order = kept.windows(2).all(|w| w[0] < w[1]);
        (kept.iter().map(|&i| boxes[i]).collect(), followed, in_order)
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(24))]

        /// Bodies dropped, put in a new order and appended between calls, with moves and small
        /// regions (boxes in several): the pairs stay exactly the brute force's, and the lists
        /// are repaired rather than rebuilt, but where a renumbering puts the bodies in a new
        /// order or follows appends not yet seen by a call (the caller starts afresh then).
        #[test]
        fn follows_drops_new_orders_and_appends(
            seed in 0u64..1_000_000,
            n in 50usize..400,
            side in 0.7f64..3.0,
            drop_one_in in 2u64..40,
        ) {
            let mut rng = crate::rng::SplitMix64::new(seed);
            let mut boxes = random_boxes(&mut rng, n, 10.0);
            let mut sap = SweepAndPrune::with_region_side(side);
            check(&mut sap, &boxes);
            for round in 0..12 {
                for b in boxes.iter_mut() {
                    *b = shift(b, DVec3::new(rng.normal(), rng.normal(), rng.normal()) * 0.05);
                }
                let (followed, in_order);
                (boxes, followed, in_order) =
                    renumber(&mut sap, &mut rng, &boxes, drop_one_in, round % 4 == 1);
                // A shuffle of a few boxes left may keep their order: then it is followed.
                proptest::prop_assert_eq!(followed, in_order);
                if !followed {
                    sap = SweepAndPrune::with_region_side(side);
                    check(&mut sap, &boxes);
                }
                let added = rng.next_u64() as usize % 8;
                boxes.extend(random_boxes(&mut rng, added, 10.0));
                proptest::prop_assert!(sap.append(added));
                if round % 4 == 3 {
                    // A new order after appends no call has seen: the lists start afresh.
                    let (followed, in_order);
                    (boxes, followed, in_order) =
                        renumber(&mut sap, &mut rng, &boxes, drop_one_in, true);
                    proptest::prop_assert_eq!(followed, added == 0 && in_order);
                    if !followed {
                        sap = SweepAndPrune::with_region_side(side);
                    }
                }
                check(&mut sap, &boxes);
            }
            proptest::prop_assert_eq!(sap.rebuilds(), 1);
        }
    }
}

/// Timing of the benchmark scenes with a chosen region size (`cargo test --release --lib
/// sap_region_size -- --ignored --nocapture`; `SAP_N`, `SAP_K` (comma separated lists),
/// `SAP_SCENES` (g, p, b)).
#[cfg(test)]
mod timing {
    use super::*;
    use crate::bench::broad_phase::{Bodies, Scene};

    fn list(var: &str, default: &str) -> Vec<usize> {
        std::env::var(var)
            .unwrap_or(default.into())
            .split(',')
            .map(|s| s.trim().parse().expect("a number"))
            .collect()
    }

    #[test]
    #[ignore]
    fn sap_region_size() {
        let scenes = std::env::var("SAP_SCENES").unwrap_or("gpb".into());
        for (key, scene) in [
            ('g', Scene::Gas),
            ('p', Scene::Packing),
            ('b', Scene::Bidisperse),
        ] {
            if !scenes.contains(key) {
                continue;
            }
            for n in list("SAP_N", "100000") {
                for k in list("SAP_K", "2000") {
                    let mut bodies = Bodies::new(scene, n, 1);
                    let mut sap = SweepAndPrune::with_bodies_per_region(k);
                    let (mut boxes, mut pairs) = (Vec::new(), Vec::new());
                    let mut samples = Vec::new();
                    let (mut swaps, mut crossings) = (0, 0);
                    for step in 0..13 {
                        bodies.advance();
                        bodies.boxes(&mut boxes);
                        let start = std::time::Instant::now();
                        sap.find_pairs(&boxes, &mut pairs);
                        if step >= 3 {
                            samples.push(start.elapsed().as_secs_f64());
                            swaps += sap.swaps_last_call();
                            crossings += sap.crossings_last_call();
                        }
                    }
                    samples.sort_by(f64::total_cmp);
                    println!(
                        "{:>16} n {:>8} k {:>6}: {:>8.3} ms, {} regions, {:.1} swaps/body, {:.4} crossings/body, {} rebuilds",
                        scene.name(),
                        bodies.len(),
                        k,
                        samples[samples.len() / 2] * 1e3,
                        sap.region_count(),
                        swaps as f64 / 10.0 / bodies.len() as f64,
                        crossings as f64 / 10.0 / bodies.len() as f64,
                        sap.rebuilds()
                    );
                }
            }
        }
    }
}
