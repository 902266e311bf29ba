use super::{BroadPhase, CellGrid, Pair};
use crate::math::{Aabb, DVec3};

/// Sweep and prune with insertion-sorted endpoint lists: the Linked Linear List (LLL) of
/// Schinner (1999, Granular Matter 2:35) as used for DEM by Muth, Eberhard & Luding, and the
/// "sweep and prune" of I-COLLIDE (Cohen, Lin, Manocha & Ponamgi 1995).
///
/// Every box is projected on x, y and z. For each axis a list of all begin points (`min`) and end
/// points (`max`) is kept sorted. Between calls bodies move little, so the old order is almost
/// right: it is repaired by insertion sort, and every adjacent swap of a begin and an end of two
/// different bodies is an *event* — a begin moving below another body's end means the two
/// intervals start overlapping on that axis; an end moving below another body's begin means they
/// stop. A call costs O(n + swaps). Only the first call, a change in the number of bodies (indices
/// may have been renumbered) or a call whose swaps would cost more than a fresh start (e.g. every
/// body teleported; then the next calls rebuild directly for a while, with exponential backoff)
/// pays the full sort and sweep, O(n log n + overlaps along the best axis).
///
/// **Tie rule.** The lists are ordered by `(value, kind)` with a begin before an end at equal
/// values. Then "begin of `a` precedes end of `b`" is exactly `a.min <= b.max`, so two intervals
/// overlap as *closed* intervals (touching counts, as in [`Aabb::overlaps`]) iff each one's begin
/// precedes the other's end. Insertion sort only swaps neighbours that are strictly out of order,
/// so equal keys (two begins or two ends at one value) never swap and never make an event, and a
/// body's own begin never passes its own end (`min <= max`). `-0.0` is stored as `0.0` so the list
/// order agrees with `<=`.
///
/// **Count invariant.** Define a pair's overlap on an axis by *list positions* (begin of each
/// precedes the end of the other), not by values. Each adjacent begin/end swap flips that for
/// exactly one pair on one axis and nothing else, so at every moment — also in the middle of a
/// sort, with other axes not yet repaired — the candidate set is exactly the pairs whose count of
/// positionally overlapping axes is 3; once all three lists are sorted, positions agree with
/// values and the set is exactly the overlapping boxes. The count is not stored per pair: a
/// hash map of every pair overlapping on at least one axis holds O(n^(5/3)) entries in a dense 3-D
/// packing (some 10^8 at n = 10^5), against O(n) candidates. Instead each body keeps its begin and
/// end *positions* on every axis (`rank`), and an event on one axis reads the pair's overlap on
/// the other two axes from them in O(1) (as Bullet's `btAxisSweep3` does): the pair enters the
/// set when its count goes 2 → 3 and leaves when it goes 3 → 2.
///
/// **Candidate set.** Per body `i`, the sorted list of its partners `j > i`. Insertion and removal
/// are a binary search and a short shift in a list of a few entries, and the output, sorted
/// ascending as the trait requires, is a plain concatenation — O(n + pairs), no global sort.
///
/// No allocation per call in steady state: all buffers are kept and reused.
#[derive(Clone, Debug, Default)]
pub struct SweepAndPrune {
    /// Per axis, the `2n` endpoints in `(value, kind)` order.
    axes: [Vec<Endpoint>; 3],
    /// `rank[body][axis] = [position of begin, position of end]` in `axes[axis]`.
    rank: Vec<[[u32; 2]; 3]>,
    /// `partners[i]`: every `j > i` whose box overlaps box `i`, ascending.
    partners: Vec<Vec<u32>>,
    /// Whether the lists describe the boxes of the previous call.
    initialised: bool,
    /// Rough cost of a full rebuild, in swap-sized units: the insertion sorts give up beyond it.
    rebuild_cost: usize,
    /// For a rebuild's pairs when it is cheaper than the sweep (dense packings of similar sizes).
    grid: CellGrid,
    /// Scratch for the sweep of a rebuild.
    active: Vec<(u32, [f64; 4])>,
    active_slot: Vec<u32>,
    swaps: usize,
    rebuilds: usize,
    /// Whether the last rebuild took its pairs from `grid`.
    grid_rebuild: bool,
    /// After insertion sorts gave up (too much motion per call), the next `skip` calls rebuild
    /// straight away; `backoff`, doubled on each consecutive give-up, is the next such wait.
    skip: u32,
    backoff: u32,
}

/// A begin or end point of one body's interval on one axis.
#[derive(Clone, Copy, Debug)]
struct Endpoint {
    value: f64,
    /// `body << 1 | is_end`.
    tag: u32,
}

impl Endpoint {
    #[inline]
    fn body(self) -> usize {
        (self.tag >> 1) as usize
    }

    /// 0 for a begin, 1 for an end.
    #[inline]
    fn kind(self) -> usize {
        (self.tag & 1) as usize
    }

    /// Strictly after `other` in list order: greater value, or equal value with an end after a
    /// begin (the tie rule).
    #[inline]
    fn after(self, other: Endpoint) -> bool {
        self.value > other.value || (self.value == other.value && self.tag & 1 > other.tag & 1)
    }
}

impl SweepAndPrune {
    /// Forgets the lists, so the next call rebuilds from scratch. Never needed for correctness:
    /// bodies renumbered without their number changing are just bodies that moved (swaps, or a
    /// rebuild once those would cost more); this only saves that work when a caller knows.
    pub fn reset(&mut self) {
        self.initialised = false;
    }

    /// Adjacent swaps made by the insertion sorts of the last call (0 after a rebuild).
    pub fn swaps_last_call(&self) -> usize {
        self.swaps
    }

    /// How many times the lists were rebuilt by a full sort and sweep.
    pub fn rebuilds(&self) -> usize {
        self.rebuilds
    }

    /// Full sort and sweep: sorts the three lists, then sweeps along the axis on which the fewest
    /// pairs overlap, testing the other two axes for each pair that overlaps on it. The sweep
    /// costs one test per pair overlapping on that axis, O(n^(5/3)) in a dense 3-D packing;
    /// when a [`CellGrid`] is estimated cheaper (similar sizes) it finds the pairs instead, using
    /// `scratch` for them.
    fn rebuild(&mut self, boxes: &[Aabb], scratch: &mut Vec<Pair>) {
        let n = boxes.len();
        self.rebuilds += 1;
        self.swaps = 0;
        self.rank.clear();
        self.rank.resize(n, [[0; 2]; 3]);
        let mut overlaps_on = [0usize; 3];
        for (axis, list) in self.axes.iter_mut().enumerate() {
            list.clear();
            for (i, b) in boxes.iter().enumerate() {
                let tag = (i as u32) << 1;
                list.push(Endpoint {
                    value: canonical(b.min[axis]),
                    tag,
                });
                list.push(Endpoint {
                    value: canonical(b.max[axis]),
                    tag: tag | 1,
                });
            }
            list.sort_unstable_by(|a, b| a.value.total_cmp(&b.value).then(a.kind().cmp(&b.kind())));
            // Pairs overlapping on this axis: each begin overlaps every interval still open.
            let mut open = 0usize;
            for (pos, e) in list.iter().enumerate() {
                self.rank[e.body()][axis][e.kind()] = pos as u32;
                if e.kind() == 0 {
                    overlaps_on[axis] += open;
                    open += 1;
                } else {
                    open -= 1;
                }
            }
        }

        self.partners.truncate(n);
        for p in &mut self.partners {
            p.clear();
        }
        self.partners.resize_with(n, Vec::new);

        let axis = (0..3).min_by_key(|&a| overlaps_on[a]).unwrap_or(0);
        let mut pairs = 0;
        let grid_work = grid_work(boxes);
        let use_grid = grid_work < overlaps_on[axis] as f64;
        self.grid_rebuild = use_grid;
        if use_grid {
            self.grid.find_pairs(boxes, scratch);
            // In ascending order, so each body's list comes out sorted.
            for &(i, j) in scratch.iter() {
                self.partners[i as usize].push(j);
            }
            pairs = scratch.len();
        } else {
            self.sweep(boxes, axis);
            for p in &mut self.partners {
                p.sort_unstable();
                pairs += p.len();
            }
        }
        let sort_cost = 3 * 2 * n * (usize::BITS - (2 * n).leading_zeros()) as usize;
        let search_cost = if use_grid {
            grid_work as usize
        } else {
            overlaps_on[axis]
        };
        self.rebuild_cost = sort_cost + search_cost + pairs + 1024;
        self.initialised = true;
    }

    /// Fills `partners` (unsorted) by sweeping the sorted list of `axis`.
    fn sweep(&mut self, boxes: &[Aabb], axis: usize) {
        let n = boxes.len();
        let (o1, o2) = ((axis + 1) % 3, (axis + 2) % 3);
        self.active.clear();
        self.active_slot.clear();
        self.active_slot.resize(n, 0);
        for e in &self.axes[axis] {
            let a = e.body();
            if e.kind() == 1 {
                let slot = self.active_slot[a] as usize;
                self.active.swap_remove(slot);
                if let Some(&(moved, _)) = self.active.get(slot) {
                    self.active_slot[moved as usize] = slot as u32;
                }
                continue;
            }
            let b = &boxes[a];
            let ab = [b.min[o1], b.max[o1], b.min[o2], b.max[o2]];
            for &(other, ob) in &self.active {
                if ab[0] <= ob[1] && ob[0] <= ab[1] && ab[2] <= ob[3] && ob[2] <= ab[3] {
                    let (lo, hi) = order(a, other as usize);
                    self.partners[lo].push(hi as u32);
                }
            }
            self.active_slot[a] = self.active.len() as u32;
            self.active.push((a as u32, ab));
        }
    }

    /// Insertion sorts the three lists after new values are read from `boxes`, updating the
    /// candidate set on every begin/end swap. Returns false, leaving a state only fit for
    /// [`Self::rebuild`], once more swaps were made than a rebuild would cost.
    fn update(&mut self, boxes: &[Aabb]) -> bool {
        self.swaps = 0;
        for axis in 0..3 {
            let list = &mut self.axes[axis];
            for e in list.iter_mut() {
                let b = &boxes[e.body()];
                let v = if e.kind() == 0 {
                    b.min[axis]
                } else {
                    b.max[axis]
                };
                debug_assert!(b.min[axis] <= b.max[axis], "box {} is inverted", e.body());
                e.value = canonical(v);
            }
            let budget = self.rebuild_cost.saturating_sub(self.swaps);
            match insertion_sort(list, axis, &mut self.rank, &mut self.partners, budget) {
                Some(swaps) => self.swaps += swaps,
                None => return false,
            }
        }
        true
    }
}

impl BroadPhase for SweepAndPrune {
    fn find_pairs(&mut self, boxes: &[Aabb], pairs: &mut Vec<Pair>) {
        assert!(boxes.len() < 1 << 31, "too many bodies for 31-bit indices");
        if !self.initialised || self.rank.len() != boxes.len() {
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
        pairs.clear();
        for (i, partners) in self.partners.iter().enumerate() {
            pairs.extend(partners.iter().map(|&j| (i as u32, j)));
        }
    }

    fn name(&self) -> &'static str {
        "sweep_and_prune"
    }
}

/// Insertion sort of one axis's list, with the overlap events it implies. `None` once `budget`
/// swaps are exceeded.
fn insertion_sort(
    list: &mut [Endpoint],
    axis: usize,
    rank: &mut [[[u32; 2]; 3]],
    partners: &mut [Vec<u32>],
    budget: usize,
) -> Option<usize> {
    let (o1, o2) = ((axis + 1) % 3, (axis + 2) % 3);
    // Overlap of two bodies on another axis, by list positions (see the count invariant).
    let overlap = |r: &[[[u32; 2]; 3]], a: usize, b: usize, m: usize| {
        let (ra, rb) = (r[a][m], r[b][m]);
        ra[0] < rb[1] && rb[0] < ra[1]
    };
    let mut swaps = 0;
    for i in 1..list.len() {
        let e = list[i];
        if !list[i - 1].after(e) {
            continue;
        }
        let eb = e.body();
        let mut j = i;
        while j > 0 && list[j - 1].after(e) {
            let p = list[j - 1];
            let pb = p.body();
            // Begin/end swaps of two bodies flip their overlap on this axis; they are in the set
            // (before or after) iff they overlap on the other two axes.
            if p.kind() != e.kind()
                && pb != eb
                && overlap(rank, pb, eb, o1)
                && overlap(rank, pb, eb, o2)
            {
                let (lo, hi) = order(pb, eb);
                let list = &mut partners[lo];
                let found = list.binary_search(&(hi as u32));
                if e.kind() == 0 {
                    // e's begin moves below p's end: they start overlapping (count 2 → 3).
                    debug_assert!(found.is_err(), "pair ({lo}, {hi}) entered twice");
                    if let Err(at) = found {
                        list.insert(at, hi as u32);
                    }
                } else {
                    // e's end moves below p's begin: they stop overlapping (count 3 → 2).
                    debug_assert!(found.is_ok(), "pair ({lo}, {hi}) left without entering");
                    if let Ok(at) = found {
                        list.remove(at);
                    }
                }
            }
            list[j] = p;
            j -= 1;
        }
        list[j] = e;
        swaps += i - j;
        if swaps > budget {
            return None;
        }
    }
    // This axis's positions are read only by the other axes' sorts: one pass writes them all,
    // cheaper than a random write per swap (dense packings make several swaps per endpoint).
    if swaps > 0 {
        for (pos, e) in list.iter().enumerate() {
            rank[e.body()][axis][e.kind()] = pos as u32;
        }
    }
    Some(swaps)
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

#[inline]
fn order(a: usize, b: usize) -> (usize, usize) {
    if a < b {
        (a, b)
    } else {
        (b, a)
    }
}

/// `-0.0` becomes `0.0`, so that the total order used by the rebuild's sort agrees with `<=`.
#[inline]
fn canonical(v: f64) -> f64 {
    v + 0.0
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
}
