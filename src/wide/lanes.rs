//! Four numbers at once: the value types of the four-wide paths (the sphere kernel,
//! `step::sphere_lanes`; the isotropic bodies' drift, `integrate::isotropic`).
//!
//! [`F4`] is four `f64` lanes and [`V3`] a vector of them. Every operation is the scalar one
//! applied lane by lane, and each lane's result is the scalar result to the bit: IEEE addition,
//! multiplication, division and square root are correctly rounded at any width, `min` and `max`
//! keep the scalar NaN rules, comparisons give masks and branches become bitwise selects, and
//! nothing is fused into a multiply–add (Rust never contracts). So the four-wide path and the
//! scalar one give the same numbers, on any machine.
//!
//! On x86-64 an `F4` is one 256-bit AVX register, and its operations are AVX instructions: use
//! them only in code compiled for AVX and reached after the CPU was found to have it (as
//! `sphere_lanes::touching_pairs` does); elsewhere an `F4` is a plain array.

use crate::math::DVec3;
use std::ops::{Add, BitOr, Div, Mul, Neg, Sub};

/// Four `f64` lanes in an AVX register.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct F4(__m256d);

/// Four `f64` lanes, one after the other, elsewhere.
#[cfg(not(target_arch = "x86_64"))]
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct F4([f64; 4]);

/// A lane mask: all ones where a comparison holds.
#[derive(Clone, Copy, Debug)]
pub struct M4(F4);

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

#[cfg(target_arch = "x86_64")]
impl F4 {
    #[inline(always)]
    pub fn new(v: [f64; 4]) -> Self {
        // SAFETY (here and below): only code running on a CPU with AVX uses `F4` (module docs).
        unsafe { F4(_mm256_setr_pd(v[0], v[1], v[2], v[3])) }
    }

    #[inline(always)]
    pub fn to_array(self) -> [f64; 4] {
        let mut out = [0.0; 4];
        // SAFETY: `out` has room for the four lanes; unaligned stores have no other demand.
        unsafe {
            _mm256_storeu_pd(out.as_mut_ptr(), self.0);
        }
        out
    }

    #[inline(always)]
    pub fn splat(v: f64) -> Self {
        unsafe { F4(_mm256_set1_pd(v)) }
    }

    #[inline(always)]
    fn lanes(self, other: Self, f: impl Fn(__m256d, __m256d) -> __m256d) -> Self {
        F4(f(self.0, other.0))
    }

    #[inline(always)]
    pub fn sqrt(self) -> Self {
        unsafe { F4(_mm256_sqrt_pd(self.0)) }
    }

    /// `f64::min` lane by lane as x86-64 computes it for scalars: `a` if `b < a` fails, `b` if
    /// it holds or `a` is NaN.
    #[inline(always)]
    pub fn min(self, other: Self) -> Self {
        let smaller = self.lanes(other, |a, b| unsafe { _mm256_min_pd(b, a) });
        F4::select(
            M4(self.lanes(self, |a, _| unsafe { _mm256_cmp_pd::<_CMP_UNORD_Q>(a, a) })),
            other,
            smaller,
        )
    }

    /// `f64::max` lane by lane, the same way.
    #[inline(always)]
    pub fn max(self, other: Self) -> Self {
        let larger = self.lanes(other, |a, b| unsafe { _mm256_max_pd(b, a) });
        F4::select(
            M4(self.lanes(self, |a, _| unsafe { _mm256_cmp_pd::<_CMP_UNORD_Q>(a, a) })),
            other,
            larger,
        )
    }

    #[inline(always)]
    pub fn le(self, other: Self) -> M4 {
        M4(self.lanes(other, |a, b| unsafe { _mm256_cmp_pd::<_CMP_LE_OQ>(a, b) }))
    }

    #[inline(always)]
    pub fn gt(self, other: Self) -> M4 {
        M4(self.lanes(other, |a, b| unsafe { _mm256_cmp_pd::<_CMP_GT_OQ>(a, b) }))
    }

    #[inline(always)]
    pub fn eq(self, other: Self) -> M4 {
        M4(self.lanes(other, |a, b| unsafe { _mm256_cmp_pd::<_CMP_EQ_OQ>(a, b) }))
    }

    /// Lane `i` of `if_true` where `mask` holds, of `if_false` elsewhere: a bitwise blend, so
    /// the chosen lane is returned exactly (signs of zeros and NaN payloads included).
    #[inline(always)]
    pub fn select(mask: M4, if_true: Self, if_false: Self) -> Self {
        let m = mask.0;
        let t = m.lanes(if_true, |m, t| unsafe { _mm256_and_pd(m, t) });
        let f = m.lanes(if_false, |m, f| unsafe { _mm256_andnot_pd(m, f) });
        t.lanes(f, |t, f| unsafe { _mm256_or_pd(t, f) })
    }
}

#[cfg(not(target_arch = "x86_64"))]
impl F4 {
    #[inline(always)]
    pub fn new(v: [f64; 4]) -> Self {
        F4(v)
    }

    #[inline(always)]
    pub fn to_array(self) -> [f64; 4] {
        self.0
    }

    #[inline(always)]
    pub fn splat(v: f64) -> Self {
        F4([v; 4])
    }

    #[inline(always)]
    fn lanes(self, other: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        F4(std::array::from_fn(|i| f(self.0[i], other.0[i])))
    }

    #[inline(always)]
    fn mask(self, other: Self, f: impl Fn(f64, f64) -> bool) -> M4 {
        let bits = |holds: bool| f64::from_bits(if holds { u64::MAX } else { 0 });
        M4(F4(std::array::from_fn(|i| bits(f(self.0[i], other.0[i])))))
    }

    #[inline(always)]
    pub fn sqrt(self) -> Self {
        self.lanes(self, |a, _| a.sqrt())
    }

    #[inline(always)]
    pub fn min(self, other: Self) -> Self {
        self.lanes(other, f64::min)
    }

    #[inline(always)]
    pub fn max(self, other: Self) -> Self {
        self.lanes(other, f64::max)
    }

    #[inline(always)]
    pub fn le(self, other: Self) -> M4 {
        self.mask(other, |a, b| a <= b)
    }

    #[inline(always)]
    pub fn gt(self, other: Self) -> M4 {
        self.mask(other, |a, b| a > b)
    }

    #[inline(always)]
    pub fn eq(self, other: Self) -> M4 {
        self.mask(other, |a, b| a == b)
    }

    #[inline(always)]
    pub fn select(mask: M4, if_true: Self, if_false: Self) -> Self {
        let (m, t, f) = (mask.0 .0, if_true.0, if_false.0);
        F4(std::array::from_fn(|i| {
            let m = m[i].to_bits();
            f64::from_bits((t[i].to_bits() & m) | (f[i].to_bits() & !m))
        }))
    }
}

#[cfg(target_arch = "x86_64")]
impl F4 {
    /// The columns of four rows of four numbers: lane `i` of column `k` is `rows[i][k]` (four
    /// loads and eight shuffles, where gathering lane by lane takes sixteen loads).
    #[inline(always)]
    pub fn transpose(rows: [&[f64; 4]; 4]) -> [F4; 4] {
        let [r0, r1, r2, r3] = rows;
        // SAFETY: each row has four numbers to load; unaligned loads have no other demand. (No
        // closure: one would be compiled without AVX, and its loads would become calls.)
        let loaded = unsafe {
            [
                F4(_mm256_loadu_pd(r0.as_ptr())),
                F4(_mm256_loadu_pd(r1.as_ptr())),
                F4(_mm256_loadu_pd(r2.as_ptr())),
                F4(_mm256_loadu_pd(r3.as_ptr())),
            ]
        };
        // Turning rows into columns is the same shuffle as columns into rows.
        F4::rows(loaded)
    }
}

#[cfg(target_arch = "x86_64")]
impl F4 {
    /// The rows of four columns, the inverse of [`F4::transpose`]: lane `k` of row `i` is lane
    /// `i` of `columns[k]` (eight shuffles, all in registers).
    #[inline(always)]
    pub fn rows(columns: [F4; 4]) -> [F4; 4] {
        let [F4(c0), F4(c1), F4(c2), F4(c3)] = columns;
        // SAFETY: register shuffles only.
        unsafe {
            // (c0₀ c1₀ c0₂ c1₂), (c0₁ c1₁ c0₃ c1₃), and the same of c2 and c3.
            let (t0, t1) = (_mm256_unpacklo_pd(c0, c1), _mm256_unpackhi_pd(c0, c1));
            let (t2, t3) = (_mm256_unpacklo_pd(c2, c3), _mm256_unpackhi_pd(c2, c3));
            [
                F4(_mm256_permute2f128_pd(t0, t2, 0x20)),
                F4(_mm256_permute2f128_pd(t1, t3, 0x20)),
                F4(_mm256_permute2f128_pd(t0, t2, 0x31)),
                F4(_mm256_permute2f128_pd(t1, t3, 0x31)),
            ]
        }
    }

    /// Writes the four lanes to `to` in one store.
    #[inline(always)]
    pub fn store(self, to: &mut [f64; 4]) {
        // SAFETY: `to` has room for four numbers; unaligned stores have no other demand.
        unsafe { _mm256_storeu_pd(to.as_mut_ptr(), self.0) }
    }

    /// Writes the first two lanes to `to` (one 128-bit store).
    #[inline(always)]
    pub fn store2(self, to: &mut [f64; 2]) {
        // SAFETY: `to` has room for two numbers.
        unsafe { _mm_storeu_pd(to.as_mut_ptr(), _mm256_castpd256_pd128(self.0)) }
    }

    /// Writes the last two lanes to `to` (one 128-bit store).
    #[inline(always)]
    pub fn store_high2(self, to: &mut [f64; 2]) {
        // SAFETY: `to` has room for two numbers.
        unsafe { _mm_storeu_pd(to.as_mut_ptr(), _mm256_extractf128_pd::<1>(self.0)) }
    }

    /// Writes the four lanes to `to` rounded to single precision, as `f64 as f32` rounds each.
    #[inline(always)]
    pub fn store_f32(self, to: &mut [f32; 4]) {
        // SAFETY: `to` has room for four numbers. The conversion rounds as MXCSR says, to
        // nearest (ties to even) unless someone changed it, which Rust code does not do.
        unsafe { _mm_storeu_ps(to.as_mut_ptr(), _mm256_cvtpd_ps(self.0)) }
    }
}

#[cfg(not(target_arch = "x86_64"))]
impl F4 {
    /// The columns of four rows of four numbers: lane `i` of column `k` is `rows[i][k]`.
    #[inline(always)]
    pub fn transpose(rows: [&[f64; 4]; 4]) -> [F4; 4] {
        std::array::from_fn(|k| F4::new(std::array::from_fn(|i| rows[i][k])))
    }

    /// The rows of four columns: lane `k` of row `i` is lane `i` of `columns[k]`.
    #[inline(always)]
    pub fn rows(columns: [F4; 4]) -> [F4; 4] {
        std::array::from_fn(|i| F4::new(std::array::from_fn(|k| columns[k].0[i])))
    }

    /// Writes the four lanes to `to`.
    #[inline(always)]
    pub fn store(self, to: &mut [f64; 4]) {
        *to = self.0;
    }

    /// Writes the first two lanes to `to`.
    #[inline(always)]
    pub fn store2(self, to: &mut [f64; 2]) {
        to.copy_from_slice(&self.0[..2]);
    }

    /// Writes the last two lanes to `to`.
    #[inline(always)]
    pub fn store_high2(self, to: &mut [f64; 2]) {
        to.copy_from_slice(&self.0[2..]);
    }

    /// Writes the four lanes to `to` rounded to single precision.
    #[inline(always)]
    pub fn store_f32(self, to: &mut [f32; 4]) {
        *to = self.0.map(|v| v as f32);
    }
}

impl F4 {
    /// Lane `i`.
    #[inline(always)]
    pub fn lane(self, i: usize) -> f64 {
        self.to_array()[i]
    }
}

impl Default for F4 {
    fn default() -> Self {
        F4::splat(0.0)
    }
}

#[cfg(target_arch = "x86_64")]
impl BitOr for M4 {
    type Output = M4;
    #[inline(always)]
    fn bitor(self, other: M4) -> M4 {
        M4(self.0.lanes(other.0, |a, b| unsafe { _mm256_or_pd(a, b) }))
    }
}

#[cfg(not(target_arch = "x86_64"))]
impl BitOr for M4 {
    type Output = M4;
    #[inline(always)]
    fn bitor(self, other: M4) -> M4 {
        let (a, b) = (self.0.to_array(), other.0.to_array());
        M4(F4::new(std::array::from_fn(|i| {
            f64::from_bits(a[i].to_bits() | b[i].to_bits())
        })))
    }
}

impl M4 {
    /// Some lane holds.
    #[inline(always)]
    pub fn any(self) -> bool {
        // No closure: one would be compiled apart from the `#[target_feature]` code it serves.
        self.lane(0) || self.lane(1) || self.lane(2) || self.lane(3)
    }

    /// Lane `i` holds.
    #[inline(always)]
    pub fn lane(self, i: usize) -> bool {
        self.0.lane(i).to_bits() != 0
    }
}

#[cfg(target_arch = "x86_64")]
macro_rules! lane_operator {
    ($trait:ident, $method:ident, $intrinsic:ident) => {
        impl $trait for F4 {
            type Output = F4;
            #[inline(always)]
            fn $method(self, other: F4) -> F4 {
                // SAFETY: only code running on a CPU with AVX uses `F4` (module docs).
                self.lanes(other, |a, b| unsafe { $intrinsic(a, b) })
            }
        }
    };
}
#[cfg(target_arch = "x86_64")]
lane_operator!(Add, add, _mm256_add_pd);
#[cfg(target_arch = "x86_64")]
lane_operator!(Sub, sub, _mm256_sub_pd);
#[cfg(target_arch = "x86_64")]
lane_operator!(Mul, mul, _mm256_mul_pd);
#[cfg(target_arch = "x86_64")]
lane_operator!(Div, div, _mm256_div_pd);

#[cfg(not(target_arch = "x86_64"))]
macro_rules! lane_operator {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for F4 {
            type Output = F4;
            #[inline(always)]
            fn $method(self, other: F4) -> F4 {
                self.lanes(other, |a, b| a $op b)
            }
        }
    };
}
#[cfg(not(target_arch = "x86_64"))]
lane_operator!(Add, add, +);
#[cfg(not(target_arch = "x86_64"))]
lane_operator!(Sub, sub, -);
#[cfg(not(target_arch = "x86_64"))]
lane_operator!(Mul, mul, *);
#[cfg(not(target_arch = "x86_64"))]
lane_operator!(Div, div, /);

#[cfg(target_arch = "x86_64")]
impl Neg for F4 {
    type Output = F4;
    /// A flip of the sign bit, as scalar negation.
    #[inline(always)]
    fn neg(self) -> F4 {
        // SAFETY: only code running on a CPU with AVX uses `F4` (module docs).
        self.lanes(F4::splat(-0.0), |a, sign| unsafe { _mm256_xor_pd(a, sign) })
    }
}

#[cfg(not(target_arch = "x86_64"))]
impl Neg for F4 {
    type Output = F4;
    #[inline(always)]
    fn neg(self) -> F4 {
        self.lanes(self, |a, _| -a)
    }
}

/// `[f(0), f(1), f(2), f(3)]`: what `std::array::from_fn` gives, written out, because the
/// compiler left `from_fn` a function of its own in the sphere kernel (1 % of a settled step),
/// and a call out of a `#[target_feature]` function is one into baseline code.
#[inline(always)]
pub fn each<T>(mut f: impl FnMut(usize) -> T) -> [T; 4] {
    [f(0), f(1), f(2), f(3)]
}

/// A vector of [`F4`]: four 3-vectors, one per lane.
#[derive(Clone, Copy, Debug, Default)]
pub struct V3 {
    pub x: F4,
    pub y: F4,
    pub z: F4,
}

impl V3 {
    #[inline(always)]
    pub fn zero() -> V3 {
        V3::splat(DVec3::ZERO)
    }

    /// The four vectors `lane(0)` … `lane(3)`.
    #[inline(always)]
    pub fn gather(lane: impl Fn(usize) -> DVec3) -> Self {
        let v: [DVec3; 4] = each(lane);
        V3 {
            x: F4::new(each(|i| v[i].x)),
            y: F4::new(each(|i| v[i].y)),
            z: F4::new(each(|i| v[i].z)),
        }
    }

    /// The same vector in every lane.
    #[inline(always)]
    pub fn splat(v: DVec3) -> Self {
        V3 {
            x: F4::splat(v.x),
            y: F4::splat(v.y),
            z: F4::splat(v.z),
        }
    }

    /// The four vectors.
    #[inline(always)]
    pub fn lanes(&self) -> [DVec3; 4] {
        let (x, y, z) = (self.x.to_array(), self.y.to_array(), self.z.to_array());
        each(|i| DVec3::new(x[i], y[i], z[i]))
    }

    /// As glam's `DVec3::dot`: (x x' + y y') + z z'.
    #[inline(always)]
    pub fn dot(self, other: V3) -> F4 {
        self.x * other.x + self.y * other.y + self.z * other.z
    }

    #[inline(always)]
    pub fn length_squared(self) -> F4 {
        self.dot(self)
    }

    /// As glam's `DVec3::cross`, term for term.
    #[inline(always)]
    pub fn cross(self, rhs: V3) -> V3 {
        V3 {
            x: self.y * rhs.z - rhs.y * self.z,
            y: self.z * rhs.x - rhs.z * self.x,
            z: self.x * rhs.y - rhs.x * self.y,
        }
    }

    #[inline(always)]
    pub fn scale(self, s: F4) -> V3 {
        V3 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    #[inline(always)]
    pub fn select(mask: M4, if_true: V3, if_false: V3) -> V3 {
        V3 {
            x: F4::select(mask, if_true.x, if_false.x),
            y: F4::select(mask, if_true.y, if_false.y),
            z: F4::select(mask, if_true.z, if_false.z),
        }
    }
}

impl Add for V3 {
    type Output = V3;
    #[inline(always)]
    fn add(self, o: V3) -> V3 {
        V3 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

impl Sub for V3 {
    type Output = V3;
    #[inline(always)]
    fn sub(self, o: V3) -> V3 {
        V3 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

impl Neg for V3 {
    type Output = V3;
    #[inline(always)]
    fn neg(self) -> V3 {
        V3 {
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn special() -> impl Strategy<Value = f64> {
        prop_oneof![
            -1e3..1e3f64,
            Just(0.0),
            Just(-0.0),
            Just(f64::NAN),
            Just(f64::INFINITY),
            Just(-f64::INFINITY),
            Just(f64::MIN_POSITIVE / 4.0),
        ]
    }

    fn same(a: f64, b: f64) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    proptest! {
        /// Every lane operation is the scalar one to the bit, zeros' signs, infinities, NaN and
        /// subnormals included.
        #[test]
        fn lanes_are_the_scalar_operations(
            a in prop::array::uniform4(special()),
            b in prop::array::uniform4(special()),
        ) {
            if !has_lanes() {
                return Ok(());
            }
            let (x, y) = (F4::new(a), F4::new(b));
            type Scalar = fn(f64, f64) -> f64;
            let checks: [(F4, Scalar); 7] = [
                (x + y, |a, b| a + b),
                (x - y, |a, b| a - b),
                (x * y, |a, b| a * b),
                (x / y, |a, b| a / b),
                (x.min(y), f64::min),
                (x.max(y), f64::max),
                (x.sqrt(), |a, _| a.sqrt()),
            ];
            for (lanes, scalar) in checks {
                for i in 0..4 {
                    prop_assert!(same(lanes.lane(i), scalar(a[i], b[i])), "lane {i}: {a:?} {b:?}");
                }
            }
            for i in 0..4 {
                prop_assert_eq!(x.le(y).lane(i), a[i] <= b[i]);
                prop_assert_eq!(x.gt(y).lane(i), a[i] > b[i]);
                prop_assert_eq!(x.eq(y).lane(i), a[i] == b[i]);
                let chosen = F4::select(x.le(y), x, y).lane(i);
                let expected = if a[i] <= b[i] { a[i] } else { b[i] };
                prop_assert!(same(chosen, expected));
                prop_assert!(same((-x).lane(i), -a[i]));
            }
        }
    }

    proptest! {
        /// Lane `i` of column `k` is row `i`'s number `k`, bit for bit (NaNs, signed zeros).
        #[test]
        fn transpose_puts_row_i_in_lane_i(rows in prop::array::uniform4(prop::array::uniform4(special()))) {
            if !has_lanes() {
                return Ok(());
            }
            let columns = F4::transpose(std::array::from_fn(|i| &rows[i]));
            for (k, column) in columns.iter().enumerate() {
                for (i, row) in rows.iter().enumerate() {
                    prop_assert_eq!(column.lane(i).to_bits(), row[k].to_bits());
                }
            }
        }
    }

    fn wide_float() -> impl Strategy<Value = f64> {
        prop_oneof![
            special(),
            -1e300..1e300f64,
            // Halfway between two floats and beyond their range: the rounding's hard cases.
            Just(1.0 + f64::EPSILON * 0.5 + f64::EPSILON * 0.25),
            Just(f64::from(f32::MAX) * 1.5),
            Just(f64::from(f32::MIN_POSITIVE) / 3.0),
        ]
    }

    proptest! {
        /// The rows are the columns' transpose and the stores write every number where
        /// `as f32` and plain copies would, bit for bit.
        #[test]
        fn rows_and_stores_write_the_numbers_in_place(
            columns in prop::array::uniform4(prop::array::uniform4(wide_float())),
        ) {
            if !has_lanes() {
                return Ok(());
            }
            let rows = F4::rows(columns.map(F4::new));
            for (i, row) in rows.iter().enumerate() {
                let (mut four, mut single) = ([9.0; 4], [9.0f32; 4]);
                let (mut low, mut high) = ([9.0; 2], [9.0; 2]);
                row.store(&mut four);
                row.store_f32(&mut single);
                row.store2(&mut low);
                row.store_high2(&mut high);
                for k in 0..4 {
                    prop_assert!(same(four[k], columns[k][i]));
                    let rounded = columns[k][i] as f32;
                    prop_assert!(single[k].to_bits() == rounded.to_bits() || rounded.is_nan());
                }
                for k in 0..2 {
                    prop_assert!(same(low[k], columns[k][i]));
                    prop_assert!(same(high[k], columns[k + 2][i]));
                }
            }
        }
    }

    /// Whether this CPU can run `F4` (see the module docs); said aloud when it cannot.
    fn has_lanes() -> bool {
        #[cfg(target_arch = "x86_64")]
        if !std::arch::is_x86_feature_detected!("avx") {
            println!("no AVX here: the four-wide kernel is not used on this CPU");
            return false;
        }
        true
    }

    #[test]
    fn vectors_are_glam_to_the_bit() {
        if !has_lanes() {
            return;
        }
        let u = [
            DVec3::new(0.1, -2.0, 3.3),
            DVec3::new(1e-9, 7.0, -0.0),
            DVec3::new(5.5, 1.0 / 3.0, 2.0),
            DVec3::new(-1.0, 0.25, 1e12),
        ];
        let v = [
            DVec3::new(-4.0, 0.7, 1.0 / 7.0),
            DVec3::new(3.0, -1e-3, 2.0),
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(2.0, 9.0, -8.0),
        ];
        let (a, b) = (V3::gather(|i| u[i]), V3::gather(|i| v[i]));
        for i in 0..4 {
            assert_eq!(a.cross(b).lanes()[i], u[i].cross(v[i]));
            assert_eq!(a.dot(b).lane(i).to_bits(), u[i].dot(v[i]).to_bits());
            assert_eq!((a + b).lanes()[i], u[i] + v[i]);
            assert_eq!((a - b).lanes()[i], u[i] - v[i]);
            assert_eq!(a.scale(b.x).lanes()[i], u[i] * v[i].x);
        }
    }
}
