//! The store's arrays as a step's contact loop works on them (`step::detect_and_evaluate`): split
//! into chunks of whole bodies, so that each chunk can add up its bodies' own contacts itself,
//! and each chunk into runs, whose loads live in the loop's scratch until they are summed.

use super::{finish, ContactStore, EntryIds, EntryState, Persistent};
use crate::body::Bodies;
use crate::contact::key::{ContactKey, PairKind};
use crate::contact::load::{LawReport, OwnLoad, PartnerLoad};
use crate::contact_law::{History, OverlapVolume, SpinHistory};
use crate::narrow_phase::ContactPoint;
use std::ops::Range;

/// About how many entries a chunk of the contact loop holds: it ends at the first body boundary
/// at or after this many. Small enough to stay in the L1/L2 cache between the narrow phase, the
/// laws and the own sums, large enough to make the scheduling cost negligible.
pub const CHUNK_ENTRIES: usize = 256;

/// The store's arrays over a range of its entries. The side arrays a world does not keep
/// (geometry, volume, spin) are empty, and stay empty when split.
pub(crate) struct StorePass<'a> {
    pub key: &'a [ContactKey],
    pub kind: &'a [PairKind],
    pub touching: &'a mut [bool],
    pub geometry: &'a mut [ContactPoint],
    pub volume: &'a mut [Option<OverlapVolume>],
    pub history: &'a mut [History],
    pub spin: &'a mut [SpinHistory],
    /// Empty in a world that keeps no reports (see `StoreLayout::reports`).
    pub report: &'a mut [LawReport],
    /// The partner's side of each entry's load, which the force sums read.
    pub load: &'a mut [PartnerLoad],
}

/// `values` split at `mid`, or two empty slices if `values` is empty (an array not kept).
fn split_side<T>(values: &mut [T], mid: usize) -> (&mut [T], &mut [T]) {
    if values.is_empty() {
        (&mut [], &mut [])
    } else {
        values.split_at_mut(mid)
    }
}

/// `values[run]`, or an empty slice if `values` is empty (an array not kept).
fn side_run<T>(values: &mut [T], run: Range<usize>) -> &mut [T] {
    if values.is_empty() {
        values
    } else {
        &mut values[run]
    }
}

impl<'a> StorePass<'a> {
    pub fn len(&self) -> usize {
        self.key.len()
    }

    /// The same entries, borrowed for a shorter while.
    pub fn reborrow(&mut self) -> StorePass<'_> {
        StorePass {
            key: self.key,
            kind: self.kind,
            touching: self.touching,
            geometry: self.geometry,
            volume: self.volume,
            history: self.history,
            spin: self.spin,
            report: self.report,
            load: self.load,
        }
    }

    /// The entries before `mid` and from `mid` on.
    pub fn split_at(self, mid: usize) -> (Self, Self) {
        let (key, key_rest) = self.key.split_at(mid);
        let (kind, kind_rest) = self.kind.split_at(mid);
        let (touching, touching_rest) = self.touching.split_at_mut(mid);
        let (geometry, geometry_rest) = split_side(self.geometry, mid);
        let (volume, volume_rest) = split_side(self.volume, mid);
        let (history, history_rest) = self.history.split_at_mut(mid);
        let (spin, spin_rest) = split_side(self.spin, mid);
        let (report, report_rest) = split_side(self.report, mid);
        let (load, load_rest) = self.load.split_at_mut(mid);
        (
            StorePass {
                key,
                kind,
                touching,
                geometry,
                volume,
                history,
                spin,
                report,
                load,
            },
            StorePass {
                key: key_rest,
                kind: kind_rest,
                touching: touching_rest,
                geometry: geometry_rest,
                volume: volume_rest,
                history: history_rest,
                spin: spin_rest,
                report: report_rest,
                load: load_rest,
            },
        )
    }

    /// The entries `run` as the contact laws see them, numbered from 0, with `own` and
    /// `dissipated` (as long as the run) for body `a`'s side of their loads and the energy they
    /// dissipate (see [`EntryState`]).
    pub fn run<'b>(
        &'b mut self,
        run: Range<usize>,
        own: &'b mut [OwnLoad],
        dissipated: &'b mut [f64],
    ) -> (EntryIds<'b>, EntryState<'b>) {
        (
            EntryIds {
                key: &self.key[run.clone()],
                kind: &self.kind[run.clone()],
            },
            EntryState {
                touching: &mut self.touching[run.clone()],
                geometry: side_run(self.geometry, run.clone()),
                volume: side_run(self.volume, run.clone()),
                history: &mut self.history[run.clone()],
                spin: side_run(self.spin, run.clone()),
                load: &mut self.load[run.clone()],
                own,
                report: side_run(self.report, run),
                dissipated,
            },
        )
    }
}

impl StorePass<'_> {
    /// Sets what entry `k` touches this step (its contact point and, for a polyhedron, the
    /// overlap's volume; `None`: nothing); a contact that ends, or whose slot a new contact takes
    /// (`fresh`), drops its history. Returns the energy the dropped history held.
    ///
    /// A contact that ends also gives up its load and report here, so that a regional entry
    /// that does not touch holds what every entry apart holds (no history, a zero load and
    /// report) before the contact laws run, and they can pass it by: of a sphere's four slots on
    /// a mesh wall, one at most touches as a rule.
    #[inline(always)]
    pub fn set_region(
        &mut self,
        k: usize,
        point: Option<ContactPoint>,
        volume: Option<OverlapVolume>,
        fresh: bool,
    ) -> f64 {
        let mut lost = 0.0;
        if self.touching[k] && (fresh || point.is_none()) {
            lost = self.history[k].stored_energy()
                + self.spin.get(k).map_or(0.0, SpinHistory::stored_energy);
            self.history[k] = History::default();
            if let Some(spin) = self.spin.get_mut(k) {
                *spin = SpinHistory::default();
            }
        }
        if self.touching[k] && point.is_none() {
            self.load[k] = PartnerLoad::default();
            if let Some(report) = self.report.get_mut(k) {
                *report = LawReport::default();
            }
        }
        self.touching[k] = point.is_some();
        if let Some(point) = point {
            self.geometry[k] = point;
            if let Some(v) = self.volume.get_mut(k) {
                *v = volume;
            }
        }
        lost
    }

    /// Sets the slots of the pair whose entries start at `k` (each slot's contact point, volume
    /// and whether it is a new contact), adding the energy the dropped histories held to `lost`
    /// one by one (unless the pair's body is a ghost, whose energy its owner books).
    #[inline(always)]
    pub fn set_pair(
        &mut self,
        k: usize,
        slots: impl Iterator<Item = (Option<ContactPoint>, Option<OverlapVolume>, bool)>,
        bodies: &Bodies,
        lost: &mut f64,
    ) {
        let counts = bodies.counts(self.key[k].a as usize);
        for (i, (point, volume, fresh)) in slots.enumerate() {
            let l = self.set_region(k + i, point, volume, fresh);
            if counts {
                *lost += l;
            }
        }
    }
}

/// Where the contact loop's chunks start: `bodies[c]` is chunk `c`'s first body (the last
/// number is the count of bodies), and `own[i]` body `i`'s first entry; and the first entries
/// of the spheres on mesh walls, whose slots each chunk sets (`step::detect`).
#[derive(Clone, Copy)]
pub(crate) struct Chunks<'a> {
    pub bodies: &'a [u32],
    pub own: &'a [u32],
    pub spheres_on_mesh: &'a [u32],
    /// The bodies whose force sums are completed after each range of chunks (see
    /// [`Chunks::finishing`]), and the entries whose partner each body is.
    finishing_first: &'a [u32],
    finishing: &'a [u32],
    incoming_first: &'a [u32],
    incoming: &'a [u32],
}

impl Chunks<'_> {
    /// Number of chunks.
    pub fn len(&self) -> usize {
        self.bodies.len().saturating_sub(1)
    }

    /// The first entry of chunk `c` (`c` = [`Chunks::len`]: the end of the last).
    pub fn first_entry(&self, c: usize) -> usize {
        self.own[self.bodies[c] as usize] as usize
    }

    /// Whether the contact loop completes the bodies' force sums (see `ContactStore::completes_sums`).
    pub fn completes_sums(&self) -> bool {
        !self.finishing_first.is_empty()
    }

    /// The bodies whose force sums are complete once the chunks of the contact loop's range
    /// numbered `range` are done (see `contact::store::finish`); none where the loop leaves the
    /// sums to the bodies' pass.
    pub fn finishing(&self, range: usize) -> &[u32] {
        if self.finishing_first.is_empty() {
            return &[];
        }
        let (first, end) = (self.finishing_first[range], self.finishing_first[range + 1]);
        &self.finishing[first as usize..end as usize]
    }

    /// The entries whose partner body `b` is, in the order their loads are added up.
    pub fn incoming(&self, b: usize) -> &[u32] {
        &self.incoming[self.incoming_first[b] as usize..self.incoming_first[b + 1] as usize]
    }

    /// The spheres on mesh walls whose entries are in chunk `c`: indices into
    /// `spheres_on_mesh` (a sphere's entries are all in its body's chunk).
    pub fn spheres_on_mesh(&self, c: usize) -> Range<usize> {
        let first = |c: usize| {
            let entry = self.first_entry(c) as u32;
            self.spheres_on_mesh.partition_point(|&f| f < entry)
        };
        first(c)..first(c + 1)
    }
}

/// The chunks' first bodies (see [`Chunks`]) over the bodies' first entries `own` (one more than
/// the bodies): each chunk ends at the first body boundary at or after [`CHUNK_ENTRIES`] entries,
/// so a body's entries are all in one chunk.
pub(super) fn chunk_bodies(own: &[u32], bodies: &mut Vec<u32>) {
    bodies.clear();
    let count = own.len().saturating_sub(1);
    bodies.push(0);
    let mut first = 0;
    for i in 0..count {
        if (own[i + 1] - first) as usize >= CHUNK_ENTRIES && i + 1 < count {
            bodies.push(i as u32 + 1);
            first = own[i + 1];
        }
    }
    bodies.push(count as u32);
}

impl ContactStore {
    /// The entries for a step's pass, with where its chunks start.
    pub(crate) fn pass_mut(&mut self) -> (StorePass<'_>, Chunks<'_>) {
        // The chunks are not kept in checkpoints.
        if self.chunks.is_empty() && !self.own.is_empty() {
            self.make_chunks();
        }
        debug_assert!(
            self.entries.key.is_empty() || !self.own.is_empty(),
            "a pass over a store whose index lists are stale"
        );
        (
            pass_over(
                &mut self.entries,
                &mut self.volume,
                &mut self.report,
                &mut self.load,
            ),
            Chunks {
                bodies: &self.chunks,
                own: &self.own,
                spheres_on_mesh: &self.spheres_on_mesh,
                finishing_first: &self.finishing_first,
                finishing: &self.finishing,
                incoming_first: &self.incoming_first,
                incoming: &self.incoming,
            },
        )
    }

    /// The chunks of the contact loop from the bodies' first entries, and the bodies whose sums
    /// each range of them completes.
    pub(super) fn make_chunks(&mut self) {
        chunk_bodies(&self.own, &mut self.chunks);
        let bodies = self.own.len().saturating_sub(1);
        let in_loop = self
            .sums_in_loop
            .unwrap_or_else(|| crate::integrate::last_level_cache::outgrown_by(bodies));
        if !in_loop {
            self.finishing_first.clear();
            self.finishing.clear();
            return;
        }
        let keys = &self.entries.key;
        let layout = finish::Layout {
            chunk_bodies: &self.chunks,
            incoming_first: &self.incoming_first,
            incoming: &self.incoming,
            a_of_entry: &|e| keys[e].a as usize,
        };
        finish::finish_lists(&layout, &mut self.finishing_first, &mut self.finishing);
    }

    /// Every entry, as [`ContactStore::pass_mut`] gives them (without the chunks).
    pub(crate) fn entries_mut(&mut self) -> StorePass<'_> {
        pass_over(
            &mut self.entries,
            &mut self.volume,
            &mut self.report,
            &mut self.load,
        )
    }
}

/// The store's per-entry arrays as one pass.
fn pass_over<'a>(
    e: &'a mut Persistent,
    volume: &'a mut [Option<OverlapVolume>],
    report: &'a mut [LawReport],
    load: &'a mut [PartnerLoad],
) -> StorePass<'a> {
    StorePass {
        key: &e.key,
        kind: &e.kind,
        touching: &mut e.touching,
        geometry: &mut e.geometry,
        volume,
        history: &mut e.history,
        spin: &mut e.spin,
        report,
        load,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The chunks of bodies with `entries[i]` entries each.
    fn chunks_of(entries: &[u32]) -> Vec<u32> {
        let mut own = vec![0];
        for &n in entries {
            own.push(own.last().unwrap() + n);
        }
        let mut bodies = Vec::new();
        chunk_bodies(&own, &mut bodies);
        bodies
    }

    #[test]
    fn chunks_end_at_the_first_body_boundary_past_the_chunk_size() {
        let n = CHUNK_ENTRIES as u32;
        // Three bodies of n/2 + 1 entries: the first two pass n, the third is a chunk alone.
        assert_eq!(chunks_of(&[n / 2 + 1, n / 2 + 1, n / 2 + 1]), vec![0, 2, 3]);
        // A body with more than a chunk's worth of entries ends its chunk, whole.
        assert_eq!(chunks_of(&[1, 3 * n, 1]), vec![0, 2, 3]);
        // Exactly n entries close a chunk; bodies without entries go with the next.
        assert_eq!(chunks_of(&[n, 0, 0, 1]), vec![0, 1, 4]);
        // No bodies: no chunks; bodies without entries: one chunk.
        assert_eq!(chunks_of(&[]), vec![0, 0]);
        assert_eq!(chunks_of(&[0, 0]), vec![0, 2]);
    }
}
