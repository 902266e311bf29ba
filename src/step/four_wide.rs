//! The entry point of a four-wide contact kernel (`sphere_lanes`, `plane_lanes`), written once.

/// Defines, in the module that calls it, `with_avx` and `with_avx512` (the module's `kernel`
/// compiled for AVX, and for AVX-512VL: the same 256-bit operations with 32 vector registers
/// instead of 16, which the kernels' many live values need; with 16 they spill to the stack), and
/// the entry point `$entry` that runs whichever the CPU has, or `$one(inputs, ids, state, k, dt)`
/// for each entry `k` (the same numbers) where it has neither.
///
/// The four entries may repeat one (a list's last one to three entries, padded): each kernel
/// reads all it needs of its four entries before it writes any, and a repeated entry is written
/// twice with the same numbers; the path one by one takes a repeated entry once.
///
/// A macro, because a closure or a generic argument would not be compiled with the wrappers'
/// target features (see `crate::wide`): every lane operation would become a call.
macro_rules! four_wide_kernel {
    ($(#[$doc:meta])* $entry:ident, $one:path) => {
        $(#[$doc])*
        #[inline]
        pub(crate) fn $entry(
            inputs: &LawInputs,
            ids: &EntryIds,
            state: &mut EntryState,
            entries: [usize; 4],
            dt: f64,
        ) {
            #[cfg(target_arch = "x86_64")]
            if crate::wide::available() {
                // SAFETY: the CPU has AVX-512VL (and so AVX), all `with_avx512` is compiled for.
                unsafe { with_avx512(inputs, ids, state, entries, dt) };
            } else if std::arch::is_x86_feature_detected!("avx") {
                // SAFETY: the CPU has AVX, which is all `with_avx` is compiled for.
                unsafe { with_avx(inputs, ids, state, entries, dt) };
            } else {
                for (n, &k) in entries.iter().enumerate() {
                    if !entries[..n].contains(&k) {
                        $one(inputs, ids, state, k, dt);
                    }
                }
            }
            #[cfg(not(target_arch = "x86_64"))]
            kernel(inputs, ids, state, entries, dt);
        }

        /// `kernel` compiled for AVX, whose 256-bit registers hold an `F4`.
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx")]
        unsafe fn with_avx(
            inputs: &LawInputs,
            ids: &EntryIds,
            state: &mut EntryState,
            entries: [usize; 4],
            dt: f64,
        ) {
            kernel(inputs, ids, state, entries, dt);
        }

        /// `kernel` compiled for AVX-512VL.
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx,avx512f,avx512vl")]
        unsafe fn with_avx512(
            inputs: &LawInputs,
            ids: &EntryIds,
            state: &mut EntryState,
            entries: [usize; 4],
            dt: f64,
        ) {
            kernel(inputs, ids, state, entries, dt);
        }
    };
}

/// In a wall kernel's property test (`plane_lanes`, `mesh_lanes`): runs the module's four-wide
/// kernel on entries 0..4 (`Lanes::Four`), its `$rest` on the first `n` (`Lanes::Rest(n)`), or
/// its `one_by_one` general path on the first `n` (`Lanes::OneByOne(n)`).
#[cfg(test)]
macro_rules! run_lanes {
    ($lanes:expr, $inputs:expr, $ids:expr, $state:expr, $dt:expr, $rest:path) => {
        match $lanes {
            Lanes::Rest(count) => {
                let rest: Vec<u32> = (0..count as u32).collect();
                $rest($inputs, $ids, $state, &rest, $dt);
            }
            Lanes::Four => {
                #[cfg(target_arch = "x86_64")]
                {
                    if !std::arch::is_x86_feature_detected!("avx") {
                        println!("no AVX here: the kernel is not used on this CPU");
                    } else {
                        // SAFETY: the CPU has AVX.
                        unsafe { with_avx($inputs, $ids, $state, [0, 1, 2, 3], $dt) };
                    }
                }
                #[cfg(not(target_arch = "x86_64"))]
                kernel($inputs, $ids, $state, [0, 1, 2, 3], $dt);
            }
            Lanes::OneByOne(count) => {
                for k in 0..count {
                    one_by_one($inputs, $ids, $state, k, $dt);
                }
            }
        }
    };
}
