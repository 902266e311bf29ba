//! Cache hints for the contact loops. A contact's partner is near in space but not in memory, so
//! in a large world the loops waited for a miss per entry, one after the other; asked for some
//! entries ahead, the misses overlap with the work between.

/// Asks the CPU to bring every cache line of `value` into the cache. A hint only: it reads
/// nothing and changes no result; a no-op where the architecture has no such hint here.
///
/// The hints are laid out from the type's size and alignment alone, so the compiler unrolls them
/// into one instruction a line: the loops ask for several values per entry, and working out the
/// lines at run time had cost about 40 instructions per contact candidate (cachegrind).
#[inline(always)]
pub(crate) fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        const LINE: usize = 64;
        let size = std::mem::size_of::<T>().max(1);
        let start = (value as *const T).cast::<i8>();
        // A hint every line's length from the start reaches every line but perhaps the last...
        let mut offset = 0;
        while offset < size {
            // SAFETY: a prefetch reads nothing and cannot fault.
            unsafe { _mm_prefetch(start.wrapping_add(offset), _MM_HINT_T0) };
            offset += LINE;
        }
        // ...which the last byte's hint reaches, unless the alignment keeps the value off it.
        let aligned = std::mem::align_of::<T>();
        let straddles = !(size <= aligned || (aligned >= LINE && size.is_multiple_of(LINE)));
        if straddles {
            // SAFETY: as above.
            unsafe { _mm_prefetch(start.wrapping_add(size - 1), _MM_HINT_T0) };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}
