//! An allocator that asks Linux to back a large world's big arrays with 2 MiB pages.
//!
//! With 4 KiB pages, every random access of the step — a partner's motion, the loads of the
//! contacts whose partner a body is — needs its own entry in the processor's address cache
//! (TLB): a 65,000-sphere bed's step reads ~56 MB, 14,000 small pages, several times what the
//! TLB holds, and in a virtual machine each miss walks two page tables. Backed by 2 MiB pages,
//! the same arrays need a few dozen entries; the settled window of that bed ran 6–7.5 % faster
//! (docs/benchmarks.md, "Big arrays on 2 MiB pages"). A world that fits in the cache (10,000
//! spheres) has no array this large and is unchanged.
//!
//! Linux gives 2 MiB pages to memory a process marks with `madvise(MADV_HUGEPAGE)`, where
//! transparent huge pages are set to `madvise` (the usual default) or `always`; with `never`,
//! or elsewhere than Linux with glibc, [`HugePageAlloc`] is the system allocator and nothing
//! more. The whole 2 MiB pages inside each block of at least [`HUGE_MIN_BYTES`] are marked
//! when it is allocated or moved; a page is backed when first touched, so an array's unused
//! tail costs no memory, but for the part of a 2 MiB page that a touched byte falls in. Blocks
//! keep the system allocator's placement (not aligned to 2 MiB, which would cost a copy at each
//! growth where glibc moves a big block's pages instead): a block loses the partial pages at
//! its two ends.
//!
//! The binary (`src/bin/polydem.rs`) and the Python module install it as the global allocator;
//! a library user may do the same in their own program.

use std::alloc::{GlobalAlloc, Layout, System};

/// The size of a huge page on x86-64 and of the usual ARM configuration.
pub const HUGE_PAGE_BYTES: usize = 2 << 20;

/// Blocks from this size on are marked: smaller ones hold at most one whole huge page.
pub const HUGE_MIN_BYTES: usize = 2 * HUGE_PAGE_BYTES;

/// The system allocator, with blocks of [`HUGE_MIN_BYTES`] or more on 2 MiB pages (module docs).
pub struct HugePageAlloc;

/// The whole huge pages of the block at `ptr` of `size` bytes: where they start, and how many
/// bytes they cover (0 if none).
#[inline]
fn whole_pages(ptr: *const u8, size: usize) -> (usize, usize) {
    let start = (ptr as usize).next_multiple_of(HUGE_PAGE_BYTES);
    let end = (ptr as usize).saturating_add(size) / HUGE_PAGE_BYTES * HUGE_PAGE_BYTES;
    (start, end.saturating_sub(start))
}

/// `madvise`'s advice to back a range with huge pages now, copying what its small pages hold
/// (Linux 6.1 on; older kernels refuse it, and the pages stay as they are).
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const MADV_COLLAPSE: libc::c_int = 25;

/// Marks the whole huge pages of the block at `ptr` of `size` bytes, if it is big enough; and
/// if `moved` (a block that grew or shrank, whose pages the system allocator remapped as they
/// were), has them collapsed into huge pages now.
#[inline]
fn mark(ptr: *mut u8, size: usize, moved: bool) {
    if size < HUGE_MIN_BYTES || ptr.is_null() {
        return;
    }
    let (start, bytes) = whole_pages(ptr, size);
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    if bytes > 0 {
        let start = start as *mut libc::c_void;
        // SAFETY: the range lies inside the block just allocated; madvise only advises the
        // kernel how to back it (a failure, as where transparent huge pages are not built in,
        // leaves small pages, which is what it would be without the call).
        unsafe {
            libc::madvise(start, bytes, libc::MADV_HUGEPAGE);
            if moved {
                libc::madvise(start, bytes, MADV_COLLAPSE);
            }
        }
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    let _ = (start, bytes, moved);
}

/// The alignment up to which the system allocator's blocks are aligned anyway (glibc's on
/// 64-bit machines): a block zeroed with a larger one is zeroed by `System` after allocating.
const SYSTEM_ALIGN: usize = 16;

// SAFETY: every block comes from `System` and goes back to it, with the caller's layouts
// unchanged; the allocator only adds advice on how the kernel backs the pages.
unsafe impl GlobalAlloc for HugePageAlloc {
    #[inline]
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's promises are the system allocator's.
        let ptr = unsafe { System.alloc(layout) };
        mark(ptr, layout.size(), false);
        ptr
    }

    #[inline]
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if layout.size() >= HUGE_MIN_BYTES && layout.align() > SYSTEM_ALIGN {
            // The system allocator would zero it itself, and the pages it touched before the
            // mark would stay small: marked first, then zeroed.
            // SAFETY: as in `alloc`; the block holds `layout.size()` bytes.
            unsafe {
                let ptr = self.alloc(layout);
                if !ptr.is_null() {
                    std::ptr::write_bytes(ptr, 0, layout.size());
                }
                return ptr;
            }
        }
        // SAFETY: as in `alloc`. glibc leaves a block it maps afresh untouched (the kernel's
        // pages are zero), so marked after, its pages are still to be backed; one it zeroed
        // itself (taken from its heap) stays on small pages.
        let ptr = unsafe { System.alloc_zeroed(layout) };
        mark(ptr, layout.size(), false);
        ptr
    }

    #[inline]
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `System` with `layout` (the caller's promise and ours).
        unsafe { System.dealloc(ptr, layout) }
    }

    #[inline]
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: as in `alloc`. glibc moves a big block by remapping its small pages as they
        // are: the new range is marked, and a block that was big already collapsed.
        let new = unsafe { System.realloc(ptr, layout, new_size) };
        mark(new, new_size, layout.size() >= HUGE_PAGE_BYTES);
        new
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A block of `size` bytes of alignment `align` from the allocator, filled with a pattern.
    fn filled(size: usize, align: usize) -> (*mut u8, Layout) {
        let layout = Layout::from_size_align(size, align).unwrap();
        let ptr = unsafe { HugePageAlloc.alloc(layout) };
        assert!(!ptr.is_null());
        assert_eq!(ptr as usize % align, 0);
        for k in (0..size).step_by(4093) {
            unsafe { *ptr.add(k) = (k % 251) as u8 };
        }
        (ptr, layout)
    }

    fn holds_pattern(ptr: *mut u8, size: usize) -> bool {
        (0..size)
            .step_by(4093)
            .all(|k| unsafe { *ptr.add(k) } == (k % 251) as u8)
    }

    /// Blocks small and big, grown across the threshold and shrunk back, keep their bytes and
    /// alignment (the packed motion is aligned to 64), and zeroed ones are zero, the
    /// over-aligned big one included (zeroed here, not by the system allocator).
    #[test]
    fn blocks_keep_their_bytes_and_alignment_across_the_threshold() {
        for align in [8, 64] {
            let small_size = 100_000;
            let (small, layout) = filled(small_size, align);
            let grown_size = 3 * HUGE_MIN_BYTES + 4321;
            let grown = unsafe { HugePageAlloc.realloc(small, layout, grown_size) };
            assert_eq!(grown as usize % align, 0);
            assert!(holds_pattern(grown, small_size));
            let grown_layout = Layout::from_size_align(grown_size, align).unwrap();
            let shrunk = unsafe { HugePageAlloc.realloc(grown, grown_layout, small_size) };
            assert!(holds_pattern(shrunk, small_size));
            unsafe { HugePageAlloc.dealloc(shrunk, layout) };
            let zeroed_layout = Layout::from_size_align(HUGE_MIN_BYTES + 100, align).unwrap();
            let zeroed = unsafe { HugePageAlloc.alloc_zeroed(zeroed_layout) };
            assert_eq!(zeroed as usize % align, 0);
            assert!((0..zeroed_layout.size())
                .step_by(4093)
                .all(|k| unsafe { *zeroed.add(k) } == 0));
            unsafe { HugePageAlloc.dealloc(zeroed, zeroed_layout) };
        }
    }

    /// A big block lies in memory the kernel may back with huge pages (`THPeligible` in
    /// `/proc/self/smaps`) exactly where transparent huge pages are on: with the setting
    /// `madvise`, only because the allocator marked it.
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    #[test]
    fn a_big_block_is_eligible_for_huge_pages_where_the_kernel_gives_them() {
        let setting = std::fs::read_to_string("/sys/kernel/mm/transparent_hugepage/enabled")
            .unwrap_or_default();
        let on = setting.contains("[madvise]") || setting.contains("[always]");
        let size = 4 * HUGE_MIN_BYTES;
        let (ptr, layout) = filled(size, 8);
        let (start, bytes) = whole_pages(ptr, size);
        assert!(bytes >= 2 * HUGE_PAGE_BYTES);
        let smaps = std::fs::read_to_string("/proc/self/smaps").unwrap();
        let mut eligible = None;
        let mut inside = false;
        for line in smaps.lines() {
            let range = line
                .split_whitespace()
                .next()
                .and_then(|r| r.split_once('-'));
            let bounds = range.and_then(|(lo, hi)| {
                let lo = usize::from_str_radix(lo, 16).ok()?;
                Some((lo, usize::from_str_radix(hi, 16).ok()?))
            });
            if let Some((lo, hi)) = bounds {
                inside = lo <= start && start < hi;
            } else if let Some(flag) = line.strip_prefix("THPeligible:").filter(|_| inside) {
                eligible = Some(flag.trim() == "1");
            }
        }
        unsafe { HugePageAlloc.dealloc(ptr, layout) };
        assert_eq!(
            eligible,
            Some(on),
            "transparent huge pages: {}",
            setting.trim()
        );
    }

    /// The pages marked are the whole 2 MiB pages inside the block, none outside it.
    #[test]
    fn only_whole_huge_pages_inside_a_block_are_marked() {
        let page = HUGE_PAGE_BYTES;
        let at = |offset: usize| (64 * page + offset) as *const u8;
        assert_eq!(whole_pages(at(0), 2 * page), (64 * page, 2 * page));
        assert_eq!(whole_pages(at(16), 2 * page), (65 * page, page));
        assert_eq!(whole_pages(at(16), 3 * page), (65 * page, 2 * page));
        assert_eq!(whole_pages(at(page - 1), page + 1), (65 * page, page));
        assert_eq!(whole_pages(at(16), page), (65 * page, 0));
    }
}
