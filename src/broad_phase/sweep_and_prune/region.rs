//! One region of the multi-SAP: a Linked Linear List over the boxes that overlap the region, and
//! the global candidate set its events update.

use crate::math::Aabb;
#[cfg(test)]
use crate::tight::with_room;
use crate::tight::{keep_room, reserve_tight, resize_tight};

/// A begin or end point of one member's interval on one axis.
#[derive(Clone, Copy, Debug)]
pub(super) struct Endpoint {
    pub value: f64,
    /// `local << 1 | is_end`, with `local` the member's index in its region.
    pub tag: u32,
}

impl Endpoint {
    #[inline]
    fn local(self) -> usize {
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

/// One axis's endpoints in list order, values and tags side by side: 12 bytes an endpoint
/// rather than 16 with padding, as the lists are most of the memory a call streams through.
#[derive(Clone, Debug, Default)]
struct List {
    value: Vec<f64>,
    tag: Vec<u32>,
}

impl List {
    fn len(&self) -> usize {
        self.tag.len()
    }

    fn clear(&mut self) {
        self.value.clear();
        self.tag.clear();
    }

    #[inline]
    fn get(&self, i: usize) -> Endpoint {
        Endpoint {
            value: self.value[i],
            tag: self.tag[i],
        }
    }

    #[inline]
    fn set(&mut self, i: usize, e: Endpoint) {
        self.value[i] = e.value;
        self.tag[i] = e.tag;
    }

    fn endpoints(&self) -> impl Iterator<Item = Endpoint> + '_ {
        self.value
            .iter()
            .zip(&self.tag)
            .map(|(&value, &tag)| Endpoint { value, tag })
    }
}

/// List order as a total order (for `sort_unstable_by`); agrees with [`Endpoint::after`] for the
/// canonical values stored (no `-0.0`, no NaN).
#[inline]
fn list_order(a: &Endpoint, b: &Endpoint) -> std::cmp::Ordering {
    a.value
        .total_cmp(&b.value)
        .then((a.tag & 1).cmp(&(b.tag & 1)))
}

/// `-0.0` becomes `0.0`, so that the total order used by sorts agrees with `<=`.
#[inline]
fn canonical(v: f64) -> f64 {
    v + 0.0
}

/// An entry of the candidate set: partner `body` of a smaller body, and the number of regions in
/// whose lists the two boxes overlap (the pair is a candidate while it is above 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Partner {
    pub body: u32,
    pub regions: u32,
}

#[inline]
fn order(a: u32, b: u32) -> (u32, u32) {
    if a < b {
        (a, b)
    } else {
        (b, a)
    }
}

/// Two bodies start (`true`) or stop overlapping in one region: what a region's update finds,
/// applied to the candidate set afterwards ([`apply`]), so that regions can be updated side by
/// side.
pub(super) type Event = (u32, u32, bool);

/// Applies `events` to the candidate set, in order.
pub(super) fn apply(partners: &mut [Vec<Partner>], events: &[Event]) {
    for &(a, b, starts) in events {
        if starts {
            enter(partners, a, b);
        } else {
            leave(partners, a, b);
        }
    }
}

/// One more region in which bodies `a` and `b` overlap.
#[inline]
fn enter(partners: &mut [Vec<Partner>], a: u32, b: u32) {
    let (lo, hi) = order(a, b);
    let list = &mut partners[lo as usize];
    match list.binary_search_by_key(&hi, |p| p.body) {
        Ok(at) => list[at].regions += 1,
        Err(at) => list.insert(
            at,
            Partner {
                body: hi,
                regions: 1,
            },
        ),
    }
}

/// One region fewer in which bodies `a` and `b` overlap.
#[inline]
fn leave(partners: &mut [Vec<Partner>], a: u32, b: u32) {
    let (lo, hi) = order(a, b);
    let list = &mut partners[lo as usize];
    match list.binary_search_by_key(&hi, |p| p.body) {
        Ok(at) => {
            list[at].regions -= 1;
            if list[at].regions == 0 {
                list.remove(at);
            }
        }
        Err(_) => debug_assert!(false, "pair ({lo}, {hi}) left a region it was not in"),
    }
}

/// `[axis] = [position of begin, position of end]` in the region's list of that axis.
type Rank = [[u32; 2]; 3];

/// Overlap of two members on `axis` by list positions (see the count invariant).
#[inline]
fn overlap_on(a: &Rank, b: &Rank, axis: usize) -> bool {
    a[axis][0] < b[axis][1] && b[axis][0] < a[axis][1]
}

pub(super) const DEAD: u32 = u32::MAX;

/// The boxes overlapping one region and their three sorted endpoint lists.
///
/// Between calls of the broad phase (and at every step of one, see the count invariant), every
/// pair of members contributes 1 to its entry in the candidate set iff the two overlap on all
/// three axes *by list positions*.
#[derive(Clone, Debug, Default)]
pub(super) struct Region {
    /// Global body index of each member; a member's local index is its place here.
    pub members: Vec<u32>,
    /// Per axis, the `2 * members` endpoints in `(value, kind)` order.
    lists: [List; 3],
    /// Per member, its exact positions in the three lists.
    rank: Vec<Rank>,
    /// Members removed (`DEAD` in `members`) whose endpoints are still in the lists, with the
    /// values they last had: they never move again and make no events, and are swept out once
    /// they are a good part of the lists, so that a removal costs no pass over the lists.
    dead: usize,
    /// The overlap events of the last update, in the order they were found.
    pub events: Vec<Event>,
}

/// Working memory of one region's update (see [`Region::update`]).
#[derive(Clone, Debug, Default)]
pub(super) struct Scratch {
    bodies: Vec<u32>,
    remap: Vec<u32>,
    endpoints: Vec<Endpoint>,
    gathered: Vec<Aabb>,
}

impl Region {
    /// Number of (live) members.
    pub fn len(&self) -> usize {
        self.members.len() - self.dead
    }

    pub fn clear(&mut self) {
        self.dead = 0;
        self.events.clear();
        self.members.clear();
        self.rank.clear();
        for list in &mut self.lists {
            list.clear();
        }
    }

    /// Sorts the lists of freshly listed `members` from scratch. Returns, per axis, the number of
    /// pairs of members whose intervals overlap on that axis (the cost of a sweep along it).
    pub fn build(&mut self, boxes: &[Aabb]) -> [usize; 3] {
        keep_room(&mut self.members);
        self.rank.clear();
        self.rank.resize(self.members.len(), [[0; 2]; 3]);
        keep_room(&mut self.rank);
        let mut overlaps = [0; 3];
        let mut sorted = Vec::with_capacity(2 * self.members.len());
        for (axis, list) in self.lists.iter_mut().enumerate() {
            let list_ = &mut sorted;
            list_.clear();
            for (local, &body) in self.members.iter().enumerate() {
                let b = &boxes[body as usize];
                let tag = (local as u32) << 1;
                list_.push(Endpoint {
                    value: canonical(b.min[axis]),
                    tag,
                });
                list_.push(Endpoint {
                    value: canonical(b.max[axis]),
                    tag: tag | 1,
                });
            }
            list_.sort_unstable_by(list_order);
            list.clear();
            list.value.extend(list_.iter().map(|e| e.value));
            list.tag.extend(list_.iter().map(|e| e.tag));
            // Room for the few members that enter before the next rebuild, no more: the lists
            // are most of the search's memory, and doubling them on the first entrant would
            // leave half of every region's lists unused.
            keep_room(&mut list.value);
            keep_room(&mut list.tag);
            let mut open = 0usize;
            for (pos, e) in list_.iter().enumerate() {
                self.rank[e.local()][axis][e.kind()] = pos as u32;
                if e.kind() == 0 {
                    overlaps[axis] += open;
                    open += 1;
                } else {
                    open -= 1;
                }
            }
        }
        overlaps
    }

    /// After [`Self::build`]: sweeps the list of `axis` and reports every overlapping pair of
    /// members whose *first* shared region is this one (`here`, region coordinates), so that over
    /// all regions each pair is found once; its entry counts all the regions the two share.
    /// Partner lists are left unsorted.
    #[allow(clippy::too_many_arguments)]
    pub fn sweep(
        &self,
        axis: usize,
        here: [u16; 3],
        ranges: &[[[u16; 3]; 2]],
        boxes: &[Aabb],
        active: &mut Vec<(u32, [f64; 4])>,
        slot: &mut Vec<u32>,
        partners: &mut [Vec<Partner>],
    ) {
        let (o1, o2) = ((axis + 1) % 3, (axis + 2) % 3);
        active.clear();
        slot.clear();
        slot.resize(self.members.len(), 0);
        for e in self.lists[axis].endpoints() {
            let local = e.local();
            if e.kind() == 1 {
                let s = slot[local] as usize;
                active.swap_remove(s);
                if let Some(&(moved, _)) = active.get(s) {
                    slot[moved as usize] = s as u32;
                }
                continue;
            }
            let a = self.members[local];
            let b = &boxes[a as usize];
            let ab = [b.min[o1], b.max[o1], b.min[o2], b.max[o2]];
            let ra = &ranges[a as usize];
            for &(other, ob) in active.iter() {
                if ab[0] <= ob[1] && ob[0] <= ab[1] && ab[2] <= ob[3] && ob[2] <= ab[3] {
                    let o = self.members[other as usize];
                    let ro = &ranges[o as usize];
                    let mut shared = 1u32;
                    let mut first = true;
                    for k in 0..3 {
                        let lo = ra[0][k].max(ro[0][k]);
                        shared *= (ra[1][k].min(ro[1][k]) - lo) as u32 + 1;
                        first &= lo == here[k];
                    }
                    if first {
                        let (lo, hi) = order(a, o);
                        partners[lo as usize].push(Partner {
                            body: hi,
                            regions: shared,
                        });
                    }
                }
            }
            slot[local] = active.len() as u32;
            active.push((local as u32, ab));
        }
    }

    /// One call's update of the region, its overlap events into [`Region::events`]: (1) the
    /// bodies `leaving` it are removed, in the previous call's state; (2) the lists are repaired
    /// by insertion sort after new values are read from `boxes`; (3) the bodies `entering` it are
    /// inserted, in the new sorted state. `leaving` and `entering` are `(region, body)` pairs of
    /// this region. Returns the swaps made, or `None` once they exceed `budget`.
    pub fn update(
        &mut self,
        leaving: &[(u32, u32)],
        entering: &[(u32, u32)],
        boxes: &[Aabb],
        budget: usize,
        scratch: &mut Scratch,
    ) -> Option<usize> {
        self.events.clear();
        if !leaving.is_empty() {
            scratch.bodies.clear();
            scratch.bodies.extend(leaving.iter().map(|&(_, body)| body));
            self.remove(&scratch.bodies, &mut scratch.remap);
        }
        let mut swaps = 0;
        if self.len() > 0 {
            self.refresh(boxes, &mut scratch.gathered);
            for axis in 0..3 {
                swaps += self.sort(axis, budget.checked_sub(swaps)?)?;
            }
        }
        if !entering.is_empty() {
            scratch.bodies.clear();
            scratch
                .bodies
                .extend(entering.iter().map(|&(_, body)| body));
            let Scratch {
                bodies,
                endpoints,
                gathered,
                ..
            } = scratch;
            self.insert(bodies, boxes, gathered, endpoints);
        }
        Some(swaps)
    }

    /// Removes the members `gone` (global indices, each a member once) between calls, their
    /// events (every pair they form here leaves) into [`Region::events`]: bodies that left the
    /// world (see `SweepAndPrune::renumber`).
    pub fn remove_now(&mut self, gone: &[u32], remap: &mut Vec<u32>) {
        self.events.clear();
        self.remove(gone, remap);
    }

    /// Removes the members `leaving` (global indices, each a member once), with the state of the
    /// previous call: every pair a leaver forms in this region leaves it.
    fn remove(&mut self, leaving: &[u32], remap: &mut Vec<u32>) {
        for &body in leaving {
            let Some(l) = self.members.iter().position(|&m| m == body) else {
                debug_assert!(false, "body {body} leaves a region it is not in");
                continue;
            };
            let rl = self.rank[l];
            for (k, (&other, rk)) in self.members.iter().zip(&self.rank).enumerate() {
                if k != l
                    && other != DEAD
                    && overlap_on(&rl, rk, 0)
                    && overlap_on(&rl, rk, 1)
                    && overlap_on(&rl, rk, 2)
                {
                    self.events.push((body, other, false));
                }
            }
            self.members[l] = DEAD;
            self.dead += 1;
        }
        if self.dead * 8 > self.members.len() {
            self.compact(remap);
        }
    }

    /// Drops the dead members and their endpoints; the others keep their relative order in every
    /// list.
    fn compact(&mut self, remap: &mut Vec<u32>) {
        self.dead = 0;
        remap.clear();
        let mut next = 0u32;
        for k in 0..self.members.len() {
            let body = self.members[k];
            if body == DEAD {
                remap.push(DEAD);
            } else {
                remap.push(next);
                self.members[next as usize] = body;
                next += 1;
            }
        }
        self.members.truncate(next as usize);
        self.rank.truncate(next as usize);
        for (axis, list) in self.lists.iter_mut().enumerate() {
            let mut w = 0;
            for i in 0..list.len() {
                let e = list.get(i);
                let local = remap[e.local()];
                if local != DEAD {
                    let tag = local << 1 | (e.tag & 1);
                    list.set(
                        w,
                        Endpoint {
                            value: e.value,
                            tag,
                        },
                    );
                    self.rank[local as usize][axis][(tag & 1) as usize] = w as u32;
                    w += 1;
                }
            }
            list.value.truncate(w);
            list.tag.truncate(w);
            // A region that bodies have left (a column that fell, a hopper that emptied) gives
            // back what they took, rather than keep its largest size for the rest of the run.
            keep_room(&mut list.value);
            keep_room(&mut list.tag);
        }
        keep_room(&mut self.members);
        keep_room(&mut self.rank);
    }

    /// Writes the members' new coordinates into the lists (at their old places). `gathered` is
    /// scratch: the boxes are first copied in a tight loop (one random read per member, many in
    /// flight at once), then scattered.
    fn refresh(&mut self, boxes: &[Aabb], gathered: &mut Vec<Aabb>) {
        gathered.clear();
        gathered.extend(
            self.members
                .iter()
                .map(|&body| boxes[(body as usize).min(boxes.len() - 1)]),
        );
        // In list order: the lists stream in sequentially (they are cold at this point of a
        // call when the regions outgrow the caches), reads of `gathered` hit the cache. The
        // endpoints of dead members keep their values.
        for (axis, list) in self.lists.iter_mut().enumerate() {
            for (value, &tag) in list.value.iter_mut().zip(&list.tag) {
                let local = (tag >> 1) as usize;
                if self.members[local] != DEAD {
                    let b = &gathered[local];
                    debug_assert!(b.min[axis] <= b.max[axis], "an inverted box");
                    *value = canonical(if tag & 1 == 0 {
                        b.min[axis]
                    } else {
                        b.max[axis]
                    });
                }
            }
        }
    }

    /// Insertion sort of the list of `axis` after [`Self::refresh`], with the overlap events it
    /// implies. `None` once more than `budget` swaps were made (the state is then only fit for a
    /// rebuild).
    fn sort(&mut self, axis: usize, budget: usize) -> Option<usize> {
        let (o1, o2) = ((axis + 1) % 3, (axis + 2) % 3);
        let Region {
            members,
            lists,
            rank,
            events,
            ..
        } = self;
        let list = &mut lists[axis];
        let mut swaps = 0;
        for i in 1..list.len() {
            let e = list.get(i);
            if !list.get(i - 1).after(e) {
                continue;
            }
            let el = e.local();
            let mut j = i;
            while j > 0 && list.get(j - 1).after(e) {
                let p = list.get(j - 1);
                let pl = p.local();
                // Begin/end swaps of two members flip their overlap on this axis; they count in
                // this region (before or after) iff they overlap on the other two axes.
                if p.kind() != e.kind()
                    && pl != el
                    && overlap_on(&rank[pl], &rank[el], o1)
                    && overlap_on(&rank[pl], &rank[el], o2)
                    && members[pl] != DEAD
                    && members[el] != DEAD
                {
                    if e.kind() == 0 {
                        // e's begin moves below p's end: they start overlapping (count 2 → 3).
                        events.push((members[pl], members[el], true));
                    } else {
                        // e's end moves below p's begin: they stop overlapping (count 3 → 2).
                        events.push((members[pl], members[el], false));
                    }
                }
                list.set(j, p);
                j -= 1;
            }
            list.set(j, e);
            swaps += i - j;
            if swaps > budget {
                return None;
            }
        }
        // This axis's positions are read only by the other axes' sorts: one pass writes them all,
        // cheaper than a write per swap (dense packings make several swaps per endpoint).
        if swaps > 0 {
            for (pos, e) in list.endpoints().enumerate() {
                rank[e.local()][axis][e.kind()] = pos as u32;
            }
        }
        Some(swaps)
    }

    /// Adds the bodies `entering` (global indices, none a member yet) after the sorts of this
    /// call, when list positions agree with the new coordinates: every pair an entrant forms
    /// with a member or another entrant enters this region. `gathered` holds the members' boxes
    /// from this call's [`Self::refresh`] (needed only if there are live members).
    fn insert(
        &mut self,
        entering: &[u32],
        boxes: &[Aabb],
        gathered: &[Aabb],
        scratch: &mut Vec<Endpoint>,
    ) {
        let old = self.members.len();
        let live = self.len() > 0;
        debug_assert!(!live || gathered.len() == old);
        for (n, &body) in entering.iter().enumerate() {
            let b = &boxes[body as usize];
            if live {
                for (&other, o) in self.members.iter().zip(gathered) {
                    if b.overlaps(o) && other != DEAD {
                        self.events.push((body, other, true));
                    }
                }
            }
            for &other in &entering[..n] {
                if b.overlaps(&boxes[other as usize]) {
                    self.events.push((body, other, true));
                }
            }
        }
        reserve_tight(&mut self.members, entering.len());
        self.members.extend_from_slice(entering);
        resize_tight(&mut self.rank, self.members.len(), [[0; 2]; 3]);
        for (axis, list) in self.lists.iter_mut().enumerate() {
            scratch.clear();
            for (n, &body) in entering.iter().enumerate() {
                let b = &boxes[body as usize];
                let tag = ((old + n) as u32) << 1;
                scratch.push(Endpoint {
                    value: canonical(b.min[axis]),
                    tag,
                });
                scratch.push(Endpoint {
                    value: canonical(b.max[axis]),
                    tag: tag | 1,
                });
            }
            scratch.sort_unstable_by(list_order);
            let moved = merge(list, scratch);
            for (pos, e) in list.endpoints().enumerate().skip(moved) {
                self.rank[e.local()][axis][e.kind()] = pos as u32;
            }
        }
    }
}

/// Merges the sorted `add` into the sorted `list`, in place from the back. Returns the first
/// position that changed.
fn merge(list: &mut List, add: &[Endpoint]) -> usize {
    let mut i = list.len();
    reserve_tight(&mut list.value, add.len());
    reserve_tight(&mut list.tag, add.len());
    list.value.extend(add.iter().map(|e| e.value));
    list.tag.extend(add.iter().map(|e| e.tag));
    let (mut j, mut w) = (add.len(), list.len());
    while j > 0 {
        w -= 1;
        if i > 0 && list.get(i - 1).after(add[j - 1]) {
            let e = list.get(i - 1);
            list.set(w, e);
            i -= 1;
        } else {
            list.set(w, add[j - 1]);
            j -= 1;
        }
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::DVec3;

    /// A row of `n` unit boxes along x, `spacing` apart.
    fn row(n: usize, spacing: f64) -> Vec<Aabb> {
        (0..n)
            .map(|i| Aabb::around_sphere(DVec3::new(i as f64 * spacing, 0.0, 0.0), 0.5))
            .collect()
    }

    fn widest(region: &Region) -> usize {
        let lists = region
            .lists
            .iter()
            .flat_map(|l| [l.value.capacity(), l.tag.capacity()]);
        lists.max().unwrap_or(0)
    }

    /// Regression (issue #18, memory): a region's lists were filled by pushes and then doubled by
    /// the first body entering, so at the peak up to half of the broad phase's memory was unused.
    #[test]
    fn a_region_keeps_a_little_room_not_twice_its_lists() {
        let mut boxes = row(1000, 2.0);
        let mut region = Region::default();
        region.members.extend(0..999);
        region.build(&boxes);
        let endpoints = 2 * 999;
        assert!(
            widest(&region) <= with_room(endpoints),
            "{}",
            widest(&region)
        );
        assert!(region.members.capacity() <= with_room(999));

        // One body enters, overlapping the last member: its pair enters, and the room kept
        // takes it without a regrowth.
        boxes[999] = Aabb::around_sphere(DVec3::new(1996.5, 0.0, 0.0), 0.5);
        let mut scratch = Scratch::default();
        region.update(&[], &[(0, 999)], &boxes, usize::MAX, &mut scratch);
        assert_eq!(region.events, vec![(999, 998, true)]);
        assert_eq!(region.len(), 1000);
        assert!(widest(&region) <= with_room(endpoints));

        // A hundred enter: the lists grow to their new length and a little, where a doubling
        // would have taken them to twice the length before.
        let more = row(1100, 2.0);
        let entering: Vec<(u32, u32)> = (1000..1100).map(|b| (0, b)).collect();
        region.update(&[], &entering, &more, usize::MAX, &mut scratch);
        assert_eq!(region.len(), 1100);
        let endpoints = 2 * 1100;
        assert!(
            widest(&region) <= with_room(endpoints),
            "{}",
            widest(&region)
        );
        assert!(region.members.capacity() <= with_room(1100));
        assert!(region.rank.capacity() <= with_room(1100));
    }

    /// A region the bodies leave (a column that fell past it, a hopper that emptied) gives back
    /// their room when its dead entries are swept out, instead of keeping its largest size.
    #[test]
    fn a_region_left_by_its_bodies_gives_back_their_room() {
        // Neighbours overlap: 999 pairs.
        let boxes = row(1000, 0.9);
        let mut region = Region::default();
        region.members.extend(0..1000);
        region.build(&boxes);
        let leaving: Vec<(u32, u32)> = (0..990).map(|b| (0, b)).collect();
        let mut scratch = Scratch::default();
        region.update(&leaving, &[], &boxes, usize::MAX, &mut scratch);
        assert_eq!(region.len(), 10);
        // Every pair with a body that left leaves, once; the ten left keep their order.
        assert_eq!(region.events.len(), 990);
        assert!(region.events.iter().all(|&(_, _, starts)| !starts));
        assert!(region.events.contains(&(989, 990, false)));
        assert_eq!(region.members, (990..1000).collect::<Vec<u32>>());
        assert!(widest(&region) <= with_room(20), "{}", widest(&region));
        assert!(region.members.capacity() <= with_room(10));
        assert!(region.rank.capacity() <= with_room(10));
    }
}
