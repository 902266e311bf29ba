//! Carrying the entries over to a new candidate list (`ContactStore::set_candidates`): first where
//! each old entry goes, found block by block in parallel; then each array moved there in place,
//! the arrays side by side in parallel. Both are pure data movement and lookups, so the store
//! comes out the same whatever the thread count.

use super::Candidate;
use crate::contact::key::ContactKey;
use crate::tight::resize_tight;
use rayon::prelude::*;

/// The fate of an old entry whose key is no longer among the candidates'.
pub(super) const GONE: u32 = u32::MAX;

/// Old entries per parallel work item when their fates are found.
const BLOCK: usize = 4096;

/// Where each old entry (by its key; `keys` in the store's order) goes among the entries of
/// `candidates` (in the store's order): its new index, or [`GONE`]. `first_entry`: each
/// candidate's first entry when some candidate has several, else empty (candidate `c`'s entry is
/// then `c`).
///
/// Each block of old keys finds where it starts among the candidates by bisection, then walks
/// both lists together, as one merge of the two sorted lists would.
pub(super) fn find_fates(
    keys: &[ContactKey],
    candidates: &[Candidate],
    first_entry: &[u32],
    ids: &[u64],
    fates: &mut Vec<u32>,
) {
    // The order of a key without its region: that of its pair's candidate.
    let rank = |a: u32, partner: crate::contact::Partner| (a, partner.rank(ids));
    fates.clear();
    fates.resize(keys.len(), GONE);
    keys.par_chunks(BLOCK)
        .zip(fates.par_chunks_mut(BLOCK))
        .for_each(|(keys, fates)| {
            let Some(first) = keys.first() else {
                return;
            };
            let start = rank(first.a, first.partner);
            let mut c = candidates.partition_point(|c| rank(c.a, c.partner) < start);
            for (key, fate) in keys.iter().zip(fates) {
                let order = rank(key.a, key.partner);
                while c < candidates.len() && rank(candidates[c].a, candidates[c].partner) < order {
                    c += 1;
                }
                let Some(candidate) = candidates.get(c) else {
                    break;
                };
                let same_pair = candidate.a == key.a && candidate.partner == key.partner;
                if same_pair && (key.region as usize) < candidate.entries() {
                    let first = first_entry.get(c).map_or(c, |&e| e as usize);
                    *fate = (first + key.region as usize) as u32;
                }
            }
        });
}

/// Moves `values`, one per old entry, to the new entries' places: old entry `o` to `fates[o]`,
/// dropped where that is [`GONE`]; the other new entries are set to `new`. `targets`: the fates
/// that are not [`GONE`], in order; `count`: the number of new entries.
///
/// In place, with no second copy: the kept values are first moved down over the dropped ones
/// (front to back), then spread out to their places with the new ones between them (back to
/// front). Both passes keep every value at or before (resp. after) where it was read, so nothing
/// is overwritten before it is moved.
pub(super) fn relocate<T: Copy>(
    values: &mut Vec<T>,
    fates: &[u32],
    targets: &[u32],
    count: usize,
    new: T,
) {
    debug_assert_eq!(values.len(), fates.len());
    let mut kept = 0;
    for (o, &fate) in fates.iter().enumerate() {
        if fate != GONE {
            values[kept] = values[o];
            kept += 1;
        }
    }
    debug_assert_eq!(kept, targets.len());
    values.truncate(kept);
    resize_tight(values, count, new);
    let mut o = kept;
    for k in (0..count).rev() {
        if o > 0 && targets[o - 1] as usize == k {
            o -= 1;
            values[k] = values[o];
        } else {
            values[k] = new;
        }
    }
    debug_assert_eq!(o, 0);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{PairKind, Partner};
    use proptest::prelude::*;

    /// Candidates of bodies `0..8` with any of bodies `0..8`, planes and mesh walls as partners,
    /// some regional, in the store's order (ids are the indices reversed, so that the order by
    /// id is not that by index).
    fn candidates(picks: &[(u32, u8, u32, bool)]) -> Vec<Candidate> {
        let ids: Vec<u64> = (0..8).map(|i| 100 - i).collect();
        let mut list: Vec<Candidate> = picks
            .iter()
            .map(|&(a, kind, p, regional)| {
                let partner = match kind % 3 {
                    0 => Partner::Body(p),
                    1 => Partner::Plane(p),
                    _ => Partner::Mesh(p),
                };
                let kind = if regional || matches!(partner, Partner::Mesh(_)) {
                    PairKind::Regional
                } else {
                    PairKind::Single
                };
                Candidate { a, partner, kind }
            })
            .collect();
        list.sort_by_key(|c| c.order(&ids));
        list.dedup_by_key(|c| (c.a, c.partner));
        list
    }

    fn keys(candidates: &[Candidate]) -> Vec<ContactKey> {
        candidates
            .iter()
            .flat_map(|c| c.keys().map(|(k, _)| k))
            .collect()
    }

    fn first_entries(candidates: &[Candidate]) -> Vec<u32> {
        if candidates.iter().all(|c| c.entries() == 1) {
            return Vec::new();
        }
        let mut next = 0;
        candidates
            .iter()
            .map(|c| {
                let first = next;
                next += c.entries() as u32;
                first
            })
            .collect()
    }

    fn pick() -> impl Strategy<Value = (u32, u8, u32, bool)> {
        (0..8u32, 0..3u8, 0..8u32, prop::bool::weighted(0.2))
    }

    proptest! {
        /// Every old entry whose key is still a candidate's goes to that key's new place, the
        /// others are dropped, and every new entry without an old one is `new`: against a
        /// lookup of each key in the new list; and over enough old entries to span several
        /// blocks.
        #[test]
        fn entries_go_where_their_keys_are(
            old in prop::collection::vec(pick(), 0..60),
            new in prop::collection::vec(pick(), 0..60),
            repeat in 1..200usize,
        ) {
            let ids: Vec<u64> = (0..8).map(|i| 100 - i).collect();
            let (old, new) = (candidates(&old), candidates(&new));
            let (old_keys, new_keys) = (keys(&old), keys(&new));
            let mut fates = Vec::new();
            find_fates(&old_keys, &new, &first_entries(&new), &ids, &mut fates);
            for (o, key) in old_keys.iter().enumerate() {
                let expected = new_keys.iter().position(|k| k == key).map_or(GONE, |k| k as u32);
                prop_assert_eq!(fates[o], expected, "entry {} ({:?})", o, key);
            }
            let targets: Vec<u32> = fates.iter().copied().filter(|&f| f != GONE).collect();
            let mut values: Vec<i64> = (0..old_keys.len() as i64).collect();
            relocate(&mut values, &fates, &targets, new_keys.len(), -1);
            for (k, key) in new_keys.iter().enumerate() {
                let expected = old_keys.iter().position(|o| o == key).map_or(-1, |o| o as i64);
                prop_assert_eq!(values[k], expected);
            }
            // Many old entries: blocks start in the middle of the lists.
            let many_old: Vec<ContactKey> = (0..repeat * 50)
                .map(|i| ContactKey { a: 0, partner: Partner::Body(i as u32 + 8), region: 0 })
                .collect();
            let many_ids: Vec<u64> = (0..repeat as u64 * 50 + 8).collect();
            let many_new: Vec<Candidate> = many_old
                .iter()
                .enumerate()
                .filter(|(i, _)| i % 3 != 1)
                .map(|(_, k)| Candidate { a: 0, partner: k.partner, kind: PairKind::Spheres })
                .collect();
            find_fates(&many_old, &many_new, &[], &many_ids, &mut fates);
            let kept = fates.iter().filter(|&&f| f != GONE).count();
            prop_assert_eq!(kept, many_new.len());
            for (o, &fate) in fates.iter().enumerate() {
                let expected = if o % 3 == 1 { GONE } else { (o - (o + 1) / 3) as u32 };
                prop_assert_eq!(fate, expected, "entry {}", o);
            }
        }
    }
}
