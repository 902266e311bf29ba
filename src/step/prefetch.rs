//! Cache hints for the contact loops. A contact's partner is near in space but not in memory, so
//! in a large world the loops waited for a miss per entry, one after the other; asked for some
//! entries ahead, the misses overlap with the work between.

/// Asks the CPU to bring every cache line of `value` into the cache. A hint only: it reads
/// nothing and changes no result; a no-op where the architecture has no such hint here.
#[inline(always)]
pub(crate) fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        const LINE: usize = 64;
        let start = (value as *const T).cast::<i8>();
        let first = start as usize / LINE;
        let last = (start as usize + std::mem::size_of::<T>().max(1) - 1) / LINE;
        for line in 0..=last - first {
            // SAFETY: a prefetch reads nothing and cannot fault; the addresses are those of the
            // lines `value` lies in.
            unsafe { _mm_prefetch(start.wrapping_add(line * LINE), _MM_HINT_T0) };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}
