//! Vectors grown by an eighth rather than doubled, for the arrays that hold most of a run's
//! memory: the contact store's, and the neighbour search's lists. Their lengths change a little
//! at each neighbour search, so `Vec`'s doubling would leave up to half of each unused at the
//! peak (issue #18's memory target), while an eighth keeps regrowths rare.

/// Makes room for `additional` more values: when the capacity is short, it grows to the new
/// length and an eighth of it.
#[inline]
pub fn reserve_tight<T>(values: &mut Vec<T>, additional: usize) {
    let len = values.len() + additional;
    if len > values.capacity() {
        values.reserve_exact(len + len / 8 - values.len());
    }
}

/// `values.resize(len, value)`, growing the capacity by [`reserve_tight`].
#[inline]
pub fn resize_tight<T: Clone>(values: &mut Vec<T>, len: usize, value: T) {
    reserve_tight(values, len.saturating_sub(values.len()));
    values.resize(len, value);
}

/// Gives back what the capacity holds beyond the length and an eighth (after a list was filled
/// by pushes, which double it).
#[inline]
pub fn trim<T>(values: &mut Vec<T>) {
    let keep = values.len() + values.len() / 8;
    if values.capacity() > keep {
        values.shrink_to(keep);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn growth_is_an_eighth_not_a_doubling() {
        let mut v: Vec<u32> = Vec::new();
        resize_tight(&mut v, 800, 1);
        assert_eq!(v.len(), 800);
        assert_eq!(v.capacity(), 900);
        // Within the capacity: no regrowth.
        resize_tight(&mut v, 900, 2);
        assert_eq!(v.capacity(), 900);
        reserve_tight(&mut v, 100);
        assert_eq!(v.capacity(), 1000 + 125);
        // Shrinking keeps the capacity; values past the old length take the new value.
        resize_tight(&mut v, 10, 3);
        assert_eq!((v.len(), v[9]), (10, 1));
        assert!(v.capacity() >= 1000);
    }

    #[test]
    fn trim_keeps_an_eighth() {
        let mut v: Vec<u64> = Vec::with_capacity(4096);
        v.extend(0..1000);
        trim(&mut v);
        assert!(
            v.capacity() >= 1125 && v.capacity() < 4096,
            "{}",
            v.capacity()
        );
        assert_eq!(v.iter().sum::<u64>(), 999 * 1000 / 2);
        let before = v.capacity();
        trim(&mut v);
        assert_eq!(v.capacity(), before);
    }
}
