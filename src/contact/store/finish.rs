//! Where in the contact loop each body's force sums become complete.
//!
//! The contact loop (`step::detect_and_evaluate`) runs over the store's chunks by halving their
//! range until one chunk is left, the halves in parallel. A body's sum is complete once every
//! chunk that writes a load for it is done: its own chunk (its contacts as `a`) and the chunks
//! of the entries whose partner it is. The smallest range of that halving that holds all of
//! them is where the body's sum is finished, right after the range's chunks were evaluated,
//! while their loads are still in cache (in a world whose step outgrows the last-level cache;
//! see `ContactStore::completes_sums`).
//!
//! The ranges are numbered in pre-order: the whole range is 0; a range numbered `id` that is
//! split at `mid` has its first half numbered `id + 1` and its second `id + 2 (mid − lo)` (a
//! range of `n` chunks holds `2n − 1` ranges). A body is finished in exactly one range, and no
//! other task touches its sums or the loads it reads while that range's task finishes it, so
//! the sums need no lock and come out the same for any thread count.

use std::ops::Range;

/// The point at which the range `chunks` is split in two (the contact loop's halving).
#[inline]
pub fn split_point(chunks: &Range<usize>) -> usize {
    chunks.start + chunks.len() / 2
}

/// The numbers of the two halves of the range `id`, which covers `chunks` and is split at `mid`.
#[inline]
pub fn halves(id: usize, chunks: &Range<usize>, mid: usize) -> (usize, usize) {
    (id + 1, id + 2 * (mid - chunks.start))
}

/// The number of the smallest range of the halving of `0..count` that holds the chunks `first`
/// to `last` (`first <= last < count`).
fn smallest_range(count: usize, first: usize, last: usize) -> usize {
    let (mut chunks, mut id) = (0..count, 0);
    while chunks.len() > 1 {
        let mid = split_point(&chunks);
        let (left, right) = halves(id, &chunks, mid);
        if last < mid {
            (chunks, id) = (chunks.start..mid, left);
        } else if first >= mid {
            (chunks, id) = (mid..chunks.end, right);
        } else {
            break;
        }
    }
    id
}

/// What the store knows of its entries that the lists need: the chunks' first bodies (the
/// count of bodies last), and each body's incoming entries with the body `a` of each entry.
pub(super) struct Layout<'a> {
    pub chunk_bodies: &'a [u32],
    pub incoming_first: &'a [u32],
    pub incoming: &'a [u32],
    pub a_of_entry: &'a dyn Fn(usize) -> usize,
}

/// The bodies finished in each range (see the module's comment): those of range `id` are
/// `bodies[first[id]..first[id + 1]]`, in increasing order. A body that is no entry's partner has
/// nothing to add and is in no list.
pub(super) fn finish_lists(layout: &Layout, first: &mut Vec<u32>, bodies: &mut Vec<u32>) {
    let chunk_bodies = layout.chunk_bodies;
    let count = chunk_bodies.len().saturating_sub(1);
    let body_count = chunk_bodies.last().copied().unwrap_or(0) as usize;
    let mut chunk_of = vec![0u32; body_count];
    for c in 0..count {
        chunk_of[chunk_bodies[c] as usize..chunk_bodies[c + 1] as usize].fill(c as u32);
    }
    let range_of: Vec<u32> = (0..body_count)
        .map(|b| {
            let incoming = &layout.incoming
                [layout.incoming_first[b] as usize..layout.incoming_first[b + 1] as usize];
            if incoming.is_empty() {
                return u32::MAX;
            }
            let (mut lo, mut hi) = (chunk_of[b], chunk_of[b]);
            for &e in incoming {
                let c = chunk_of[(layout.a_of_entry)(e as usize)];
                (lo, hi) = (lo.min(c), hi.max(c));
            }
            smallest_range(count, lo as usize, hi as usize) as u32
        })
        .collect();
    let ranges = (2 * count).saturating_sub(1);
    first.clear();
    first.resize(ranges + 1, 0);
    for &r in range_of.iter().filter(|&&r| r != u32::MAX) {
        first[r as usize + 1] += 1;
    }
    for r in 0..ranges {
        first[r + 1] += first[r];
    }
    let mut next = first.clone();
    bodies.clear();
    bodies.resize(first[ranges] as usize, 0);
    for (b, &r) in range_of.iter().enumerate().filter(|(_, &r)| r != u32::MAX) {
        bodies[next[r as usize] as usize] = b as u32;
        next[r as usize] += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Every range of the halving of `0..count`, by number, found by walking it as the contact
    /// loop does.
    fn ranges(count: usize) -> Vec<Range<usize>> {
        fn walk(id: usize, chunks: Range<usize>, out: &mut Vec<Option<Range<usize>>>) {
            out[id] = Some(chunks.clone());
            if chunks.len() > 1 {
                let mid = split_point(&chunks);
                let (left, right) = halves(id, &chunks, mid);
                walk(left, chunks.start..mid, out);
                walk(right, mid..chunks.end, out);
            }
        }
        let mut out = vec![None; 2 * count - 1];
        walk(0, 0..count, &mut out);
        out.into_iter()
            .map(|r| r.expect("every number used"))
            .collect()
    }

    proptest! {
        /// The range a body is finished in holds all its chunks, and neither of its halves does
        /// (against every range of the halving, listed by walking it).
        #[test]
        fn a_body_is_finished_in_the_smallest_range_that_holds_its_chunks(
            count in 1usize..40,
            a in 0usize..40,
            b in 0usize..40,
        ) {
            let (first, last) = ((a % count).min(b % count), (a % count).max(b % count));
            let all = ranges(count);
            let id = smallest_range(count, first, last);
            let range = &all[id];
            prop_assert!(range.contains(&first) && range.contains(&last));
            // No smaller range holds both: every range that does contains this one.
            for r in &all {
                if r.contains(&first) && r.contains(&last) {
                    prop_assert!(r.start <= range.start && range.end <= r.end);
                }
            }
        }
    }

    #[test]
    fn each_partner_body_is_listed_once_in_the_range_of_its_chunks() {
        // Six bodies in three chunks (0–1, 2–3, 4–5). Body 1's incoming entries come from
        // bodies 0 and 5 (chunks 0 and 2: the whole range); body 3's from body 2 (its own
        // chunk); body 4's from body 3 (chunks 1 and 2); the others are no entry's partner.
        let chunk_bodies = [0, 2, 4, 6];
        let incoming_first = [0, 0, 2, 2, 3, 4, 4];
        let incoming = [0, 1, 2, 3];
        let a = [0usize, 5, 2, 3];
        let layout = Layout {
            chunk_bodies: &chunk_bodies,
            incoming_first: &incoming_first,
            incoming: &incoming,
            a_of_entry: &|e| a[e],
        };
        let (mut first, mut bodies) = (Vec::new(), Vec::new());
        finish_lists(&layout, &mut first, &mut bodies);
        // Three chunks: ranges 0 (0..3), 1 (0..1), 2 (1..3), 3 (1..2), 4 (2..3).
        let all = ranges(3);
        assert_eq!(all, vec![0..3, 0..1, 1..3, 1..2, 2..3]);
        let listed = |id: usize| &bodies[first[id] as usize..first[id + 1] as usize];
        assert_eq!(listed(0), &[1]);
        assert_eq!(listed(1), &[] as &[u32]);
        assert_eq!(listed(2), &[4]);
        assert_eq!(listed(3), &[3]);
        assert_eq!(listed(4), &[] as &[u32]);
    }
}
