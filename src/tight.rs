//! Vectors grown to their new length and a sixteenth rather than doubled, for the arrays that
//! hold most of a run's memory: the contact store's, and the neighbour search's lists. Their
//! lengths change a little at each neighbour search, so `Vec`'s doubling would leave up to half
//! of each unused at the peak (issue #18's memory target). A regrowth is cheap: in the `polydem`
//! program arrays this large are mappings of their own (`src/bin/polydem.rs` sets glibc's mmap
//! threshold), which `realloc` moves with `mremap`, without copying.

/// The room kept beyond the length: a `ROOM`th of it.
pub const ROOM: usize = 16;

/// The capacity kept for `len` values: `len` and a [`ROOM`]th.
#[inline]
pub fn with_room(len: usize) -> usize {
    len + len / ROOM
}

/// Makes room for `additional` more values: when the capacity is short, it grows to
/// [`with_room`] of the new length.
#[inline]
pub fn reserve_tight<T>(values: &mut Vec<T>, additional: usize) {
    let len = values.len() + additional;
    if len > values.capacity() {
        values.reserve_exact(with_room(len) - values.len());
    }
}

/// `values.resize(len, value)`, growing the capacity by [`reserve_tight`].
#[inline]
pub fn resize_tight<T: Clone>(values: &mut Vec<T>, len: usize, value: T) {
    reserve_tight(values, len.saturating_sub(values.len()));
    values.resize(len, value);
}

/// Sets the capacity to [`with_room`] of the length: gives back what pushes (which double it)
/// left beyond it, or makes the room, after a list was filled anew.
#[inline]
pub fn keep_room<T>(values: &mut Vec<T>) {
    let keep = with_room(values.len());
    if values.capacity() > keep {
        values.shrink_to(keep);
    } else {
        values.reserve_exact(keep - values.len());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn growth_keeps_a_sixteenth_not_a_doubling() {
        let mut v: Vec<u32> = Vec::new();
        resize_tight(&mut v, 800, 1);
        assert_eq!(v.len(), 800);
        assert_eq!(v.capacity(), 850);
        // Within the capacity: no regrowth.
        resize_tight(&mut v, 850, 2);
        assert_eq!(v.capacity(), 850);
        reserve_tight(&mut v, 150);
        assert_eq!(v.capacity(), 1000 + 62);
        // Shrinking keeps the capacity; values past the old length take the new value.
        resize_tight(&mut v, 10, 3);
        assert_eq!((v.len(), v[9]), (10, 1));
        assert!(v.capacity() >= 1000);
    }

    #[test]
    fn keep_room_gives_back_or_makes_a_sixteenth() {
        let mut v: Vec<u64> = Vec::with_capacity(4096);
        v.extend(0..1000);
        keep_room(&mut v);
        assert!(
            v.capacity() >= 1062 && v.capacity() < 4096,
            "{}",
            v.capacity()
        );
        assert_eq!(v.iter().sum::<u64>(), 999 * 1000 / 2);
        let before = v.capacity();
        keep_room(&mut v);
        assert_eq!(v.capacity(), before);
        let mut exact: Vec<u64> = (0..1600).collect();
        keep_room(&mut exact);
        assert!(exact.capacity() >= 1700);
    }
}
