//! Lists grouped by body, as counting sorts leave them: the values of group `j` (a body's
//! candidates, the contacts whose partner it is, the sweep and prune's pairs of body `j`) are
//! `values[first[j]..first[j + 1]]`. Such lists are made again with each neighbour list, and
//! each group then written or sorted on its own.
//!
//! [`for_each_group_mut`] works on the groups in parallel, cut where `first` says, with no test
//! of neighbouring values to find where a group ends (that test read two keys at random per
//! value, issue #18); [`sort_short_by_key`] sorts a short group asking for each key once.

/// Groups per parallel work item of [`for_each_group_mut`].
const GROUP_BLOCK: usize = 2048;

/// Calls `f(j, group)` on each group `j` of `values` (`values[first[j]..first[j + 1]]`), the
/// groups in parallel.
pub fn for_each_group_mut<U: Send>(
    values: &mut [U],
    first: &[u32],
    f: impl Fn(usize, &mut [U]) + Sync,
) {
    let Some(&start) = first.first() else {
        return;
    };
    let values = &mut values[start as usize..first[first.len() - 1] as usize];
    groups_halved(values, first, 0, &f);
}

/// [`for_each_group_mut`] of `values`, which hold the groups `first` bounds, the first of them
/// group `j`: halved until a block of groups is left, the halves in parallel.
fn groups_halved<U: Send>(
    values: &mut [U],
    first: &[u32],
    j: usize,
    f: &(impl Fn(usize, &mut [U]) + Sync),
) {
    let groups = first.len() - 1;
    if groups <= GROUP_BLOCK {
        let mut rest = values;
        for (j, w) in (j..).zip(first.windows(2)) {
            let (group, after) = rest.split_at_mut((w[1] - w[0]) as usize);
            f(j, group);
            rest = after;
        }
        return;
    }
    let mid = groups / 2;
    let (values, values_rest) = values.split_at_mut((first[mid] - first[0]) as usize);
    rayon::join(
        || groups_halved(values, &first[..=mid], j, f),
        || groups_halved(values_rest, &first[mid..], j + mid, f),
    );
}

/// Lists this long or shorter are sorted by [`sort_short_by_key`] with their keys at hand.
const SHORT: usize = 16;

/// Sorts `values` by `key`, each key asked for once when the list is short (a body's candidates
/// or incoming contacts: a few), where a key means reads from arrays at random and a sort asks
/// for each about twice the logarithm of the length times. Keys must differ (the order of equal
/// ones is not kept).
pub fn sort_short_by_key<T: Copy, K: Ord + Copy>(values: &mut [T], key: impl Fn(&T) -> K) {
    match values.len() {
        0 | 1 => {}
        n if n <= SHORT => {
            let mut keyed = [(key(&values[0]), values[0]); SHORT];
            for (slot, v) in keyed[1..n].iter_mut().zip(&values[1..]) {
                *slot = (key(v), *v);
            }
            keyed[..n].sort_unstable_by_key(|&(k, _)| k);
            for (v, (_, sorted)) in values.iter_mut().zip(&keyed[..n]) {
                *v = *sorted;
            }
        }
        _ => values.sort_unstable_by_key(key),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Every group is handed over once, as the slice `first` bounds, also when the groups are
    /// more than a block (the halves in parallel), with empty groups among them.
    #[test]
    fn each_group_is_handed_over_once() {
        for groups in [0usize, 1, 5, 3 * GROUP_BLOCK + 7] {
            let first: Vec<u32> = (0..=groups as u32).map(|j| j * j / 3 + j % 2).collect();
            let mut values: Vec<u32> = (0..*first.last().unwrap()).collect();
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(2)
                .build()
                .unwrap();
            // Each group reversed in place and its first value raised by a million times its
            // index: the groups' contents, each the other way round, each told its own index.
            pool.install(|| {
                for_each_group_mut(&mut values, &first, |j, g| {
                    g.reverse();
                    if let Some(v) = g.first_mut() {
                        *v += 1_000_000 * j as u32;
                    }
                })
            });
            let expected: Vec<u32> = first
                .windows(2)
                .enumerate()
                .flat_map(|(j, w)| {
                    (w[0]..w[1]).rev().enumerate().map(move |(k, v)| {
                        if k == 0 {
                            v + 1_000_000 * j as u32
                        } else {
                            v
                        }
                    })
                })
                .collect();
            assert_eq!(values, expected);
        }
        for_each_group_mut(&mut [0u32; 0], &[], |_, _| panic!("no group"));
    }

    proptest! {
        /// Short lists (keys at hand) and long ones sort as a plain sort does.
        #[test]
        fn short_lists_sort_as_a_plain_sort(
            values in proptest::collection::hash_set(any::<u16>(), 0..40)
        ) {
            let values: Vec<u16> = values.into_iter().collect();
            let key = |v: &u16| v.wrapping_mul(40503);
            let mut sorted = values.clone();
            sort_short_by_key(&mut sorted, key);
            let mut expected = values;
            expected.sort_by_key(key);
            prop_assert_eq!(sorted, expected);
        }
    }
}
