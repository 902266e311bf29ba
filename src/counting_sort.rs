//! A counting sort in parallel: items grouped by a small integer key (a body's index), in the
//! order a serial counting sort would give, whatever the number of threads.
//!
//! The neighbour list is grouped by body `a`, and the contact store's incoming lists by partner,
//! each time the candidate list is made. A serial counting sort there held the second thread
//! back (issue #18: the remake scaled 1.3× on two threads). Here the items are cut into one block
//! per thread; each block counts its items per bucket, the counts are turned into each block's
//! place in each bucket (bucket by bucket, block by block: the places a serial pass would give),
//! and each block then writes its items to its places. The result is stable, and the same bits
//! for any number of blocks.

use rayon::prelude::*;

/// Items below which one block does it all (the parallel passes would cost more than they save).
const SERIAL_BELOW: usize = 1 << 14;

/// The working memory of [`CountingSort::group`], kept between calls.
#[derive(Clone, Debug, Default)]
pub struct CountingSort {
    /// Per block, per bucket: the next free place of the block's items in the bucket.
    next: Vec<u32>,
    /// Per block, per bucket: where the block's places in the bucket end.
    end: Vec<u32>,
}

impl CountingSort {
    /// Writes `value(k)` of the items `k` in `0..items` whose `bucket(k)` is `Some` into `out`,
    /// grouped by bucket in ascending order and, within a bucket, in the order of `k`; `first`
    /// gets each bucket's first place (`buckets + 1` of them, the last the number kept). Buckets
    /// must be below `buckets`.
    ///
    /// `bucket` is asked twice for each item (once to count, once to place) and must answer the
    /// same both times.
    ///
    /// # Panics
    /// If a bucket is `buckets` or more, or `bucket` answers differently the second time.
    pub fn group<U: Copy + Send + Sync>(
        &mut self,
        items: usize,
        buckets: usize,
        bucket: impl Fn(usize) -> Option<u32> + Sync,
        value: impl Fn(usize) -> U + Sync,
        first: &mut Vec<u32>,
        out: &mut Vec<U>,
    ) {
        assert!(
            items <= u32::MAX as usize,
            "too many items for 32-bit places"
        );
        let blocks = if items < SERIAL_BELOW {
            1
        } else {
            rayon::current_num_threads().clamp(1, items / SERIAL_BELOW)
        };
        let block = |b: usize| b * items / blocks..(b + 1) * items / blocks;
        // 1. Each block's count per bucket (kept in `end` for now).
        self.end.clear();
        self.end.resize(blocks * buckets, 0);
        self.end
            .par_chunks_mut(buckets.max(1))
            .enumerate()
            .for_each(|(b, counts)| {
                for k in block(b) {
                    if let Some(j) = bucket(k) {
                        counts[j as usize] += 1;
                    }
                }
            });
        // 2. The places: bucket by bucket, and within a bucket block by block.
        first.clear();
        first.resize(buckets + 1, 0);
        self.next.clear();
        self.next.resize(blocks * buckets, 0);
        let mut place = 0u32;
        for (j, first) in first[..buckets].iter_mut().enumerate() {
            *first = place;
            for b in 0..blocks {
                let at = b * buckets + j;
                self.next[at] = place;
                place += self.end[at];
                self.end[at] = place;
            }
        }
        first[buckets] = place;
        // 3. Each block writes its items to its places. The places of different blocks and
        // buckets are disjoint ranges of `out` by their making above (whatever `bucket` answers,
        // a write is checked against its range's end), so the blocks never write the same place.
        out.clear();
        out.reserve(place as usize);
        let target = Places(out.spare_capacity_mut().as_mut_ptr().cast::<U>());
        let written: usize = self
            .next
            .par_chunks_mut(buckets.max(1))
            .zip(self.end.par_chunks(buckets.max(1)))
            .enumerate()
            .map(|(b, (next, end))| {
                let target = &target;
                let mut written = 0;
                for k in block(b) {
                    let Some(j) = bucket(k) else { continue };
                    let j = j as usize;
                    assert!(next[j] < end[j], "item {k}: its bucket {j} changed");
                    // SAFETY: `next[j]` lies in this block's range of places for bucket `j`
                    // (checked just above), which no other block or bucket shares, and is
                    // below `place`, the capacity reserved; each place is written once (`next`
                    // moves on).
                    unsafe { target.0.add(next[j] as usize).write(value(k)) };
                    next[j] += 1;
                    written += 1;
                }
                written
            })
            .sum();
        assert_eq!(written, place as usize, "an item's bucket changed");
        // SAFETY: every place below `place` was written once above: each block wrote as many items
        // as it counted, each within its own ranges, and the ranges together cover `0..place`.
        unsafe { out.set_len(place as usize) };
    }
}

/// The start of the places [`CountingSort::group`] writes, shared by its blocks.
struct Places<U>(*mut U);

// SAFETY: the blocks write disjoint places (see `CountingSort::group`).
unsafe impl<U: Send> Sync for Places<U> {}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// What a serial counting sort gives.
    fn serial(keys: &[Option<u32>], buckets: usize) -> (Vec<u32>, Vec<usize>) {
        let mut first = vec![0u32; buckets + 1];
        let mut out = Vec::new();
        for (j, first) in first[..buckets].iter_mut().enumerate() {
            *first = out.len() as u32;
            out.extend((0..keys.len()).filter(|&k| keys[k] == Some(j as u32)));
        }
        first[buckets] = out.len() as u32;
        (first, out)
    }

    fn grouped(keys: &[Option<u32>], buckets: usize, threads: usize) -> (Vec<u32>, Vec<usize>) {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let (mut first, mut out) = (Vec::new(), Vec::new());
        pool.install(|| {
            CountingSort::default().group(
                keys.len(),
                buckets,
                |k| keys[k],
                |k| k,
                &mut first,
                &mut out,
            )
        });
        (first, out)
    }

    proptest! {
        /// Small inputs (one block) and large ones (a block per thread) give what a serial
        /// counting sort gives: stable, the dropped items left out.
        #[test]
        fn groups_as_a_serial_counting_sort(
            seed in any::<u64>(),
            large in any::<bool>(),
            buckets in 1usize..300,
            dropped in 0u32..4,
        ) {
            let mut rng = crate::rng::SplitMix64::new(seed);
            let n = if large { 3 * SERIAL_BELOW + 17 } else { 200 };
            let keys: Vec<Option<u32>> = (0..n)
                .map(|_| {
                    let j = (rng.next_u64() % buckets as u64) as u32;
                    (rng.next_u64() % 4 >= dropped as u64).then_some(j)
                })
                .collect();
            let expected = serial(&keys, buckets);
            for threads in [1, 2, 3] {
                prop_assert_eq!(&grouped(&keys, buckets, threads), &expected);
            }
        }
    }

    #[test]
    fn nothing_to_group() {
        assert_eq!(grouped(&[], 3, 2), (vec![0; 4], vec![]));
        assert_eq!(grouped(&[None, None], 0, 2), (vec![0], vec![]));
    }

    #[test]
    #[should_panic(expected = "changed")]
    fn a_bucket_that_changes_is_caught() {
        let asked = std::sync::atomic::AtomicUsize::new(0);
        let (mut first, mut out) = (Vec::new(), Vec::new());
        CountingSort::default().group(
            4,
            2,
            |_| {
                let n = asked.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                Some(u32::from(n >= 4))
            },
            |k| k,
            &mut first,
            &mut out,
        );
    }
}
