//! Eight f32 lanes for the per-sample loops, in the instruction set the CPU has.
//!
//! The coverage kernels (the 8-lane methods of the edge functions' `Coverage`, on 2D,
//! homogeneous and 3D edge functions) are
//! written once, generic over [`Lanes`], and compiled twice: on [`Portable`]
//! (`wide::f32x8`: two SSE halves on x86-64, whatever the target has
//! elsewhere) and on [`Avx2`] (one 256-bit register). Which one runs is
//! decided at run time, once per kernel call, by [`avx2`]: the loops that call
//! the kernels come in a portable form and an `#[target_feature(enable =
//! "avx2")]` form. Both perform the same IEEE operations in the same order
//! with no fused multiply-add (AVX2 does not include FMA, and nothing here asks
//! for it), so every lane rounds exactly as the scalar `Coverage::sample`
//! does, on either path.
//!
//! Lane code is written in `#[inline(always)]` functions, never in closures:
//! only what is inlined into the `#[target_feature]` loop is compiled for
//! AVX2, and an intrinsic left outside it becomes a call per instruction
//! (`.ci/run` checks the binary for such calls).

use std::ops::{Add, Div, Mul, Sub};
use std::sync::OnceLock;

/// The portable eight lanes.
pub type Portable = wide::f32x8;

/// Eight f32 lanes: arithmetic, x86 `minps`/`maxps` and comparisons to lane
/// bit masks (bit `l` for lane `l`). Sealed: only this crate builds lanes.
pub trait Lanes:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + sealed::Ops
{
}

impl<L> Lanes for L where
    L: Copy + Add<Output = L> + Sub<Output = L> + Mul<Output = L> + Div<Output = L> + sealed::Ops
{
}

/// `|x|` per lane (`maxps(x, −x)`): `f32::abs` on every lane but a NaN.
#[inline(always)]
pub(crate) fn abs<L: Lanes>(x: L) -> L {
    x.max(L::splat(0.0) - x)
}

/// The lanes holding a finite value (`v · 0` is ±0 exactly there, NaN elsewhere).
#[inline(always)]
pub(crate) fn finite<L: Lanes>(v: L) -> u8 {
    let zero = L::splat(0.0);
    (v * zero).eq(zero)
}

mod sealed {
    /// The lane operations beyond arithmetic. `max`/`min` are x86's `maxps`/
    /// `minps`: `self > o ? self : o` (the second operand when either is NaN),
    /// on every path.
    pub trait Ops: Sized {
        fn splat(v: f32) -> Self;
        fn from_array(v: [f32; 8]) -> Self;
        fn to_array(self) -> [f32; 8];
        fn max(self, o: Self) -> Self;
        fn min(self, o: Self) -> Self;
        /// The correctly rounded square root (IEEE, as `f32::sqrt`).
        fn sqrt(self) -> Self;
        /// The largest integer not above each lane (exact, as `f32::floor`).
        fn floor(self) -> Self;
        /// The smallest integer not below each lane (exact, as `f32::ceil`).
        fn ceil(self) -> Self;
        fn gt(self, o: Self) -> u8;
        fn lt(self, o: Self) -> u8;
        fn ge(self, o: Self) -> u8;
        fn le(self, o: Self) -> u8;
        fn eq(self, o: Self) -> u8;
        /// Lane `l` of `a` where bit `l` of `mask` is set, of `b` elsewhere.
        fn select(mask: u8, a: Self, b: Self) -> Self;
        /// Each lane truncated toward zero, as `f32 as u32` (for lanes in
        /// `[0, 2³¹)`: the only ones callers pass).
        fn truncate(self) -> [u32; 8];
        /// `base[index[l]]` in lane `l`; panics, as indexing does, when an
        /// index is out of bounds.
        fn gather(base: &[f32], index: [u32; 8]) -> Self;
        /// Fields 0, 1 and 2 of the rows `index` of `base` read as rows of
        /// `stride` (at least 3) floats: `base[stride·index[l] + k]` in lane
        /// `l` of field `k`, as three [`Ops::gather`]s of them read it
        /// (and panicking where they would).
        fn gather_xyz(base: &[f32], stride: u32, index: [u32; 8]) -> [Self; 3];
        /// The four fields of the rows `index` of `base`: `base[index[l]][k]`
        /// in lane `l` of field `k`; panics, as indexing does, when an
        /// index is out of bounds.
        fn gather_xyzw(base: &[[f32; 4]], index: [u32; 8]) -> [Self; 4];
        /// Eight rows as lanes: lane `l` of field `k` is `rows[l][k]`.
        fn transpose(rows: [[f32; 8]; 8]) -> [Self; 8];
        /// Each lane's bits `shift..shift + width` moved up to `up..`, the
        /// other bits cleared: `(bits >> shift & (2^width − 1)) << up`.
        fn bit_field(self, shift: u32, width: u32, up: u32) -> Self;
        /// Bit `l` set where `v[l] != x`.
        fn differ(v: [u32; 8], x: u32) -> u8;
    }
}

impl sealed::Ops for Portable {
    #[inline(always)]
    fn splat(v: f32) -> Self {
        wide::f32x8::splat(v)
    }
    #[inline(always)]
    fn from_array(v: [f32; 8]) -> Self {
        wide::f32x8::from(v)
    }
    #[inline(always)]
    fn to_array(self) -> [f32; 8] {
        wide::f32x8::to_array(self)
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        self.fast_max(o)
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        self.fast_min(o)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        wide::f32x8::sqrt(self)
    }
    #[inline(always)]
    fn floor(self) -> Self {
        wide::f32x8::floor(self)
    }
    #[inline(always)]
    fn ceil(self) -> Self {
        wide::f32x8::ceil(self)
    }
    #[inline(always)]
    fn gt(self, o: Self) -> u8 {
        self.simd_gt(o).to_bitmask() as u8
    }
    #[inline(always)]
    fn lt(self, o: Self) -> u8 {
        self.simd_lt(o).to_bitmask() as u8
    }
    #[inline(always)]
    fn ge(self, o: Self) -> u8 {
        self.simd_ge(o).to_bitmask() as u8
    }
    #[inline(always)]
    fn le(self, o: Self) -> u8 {
        self.simd_le(o).to_bitmask() as u8
    }
    #[inline(always)]
    fn eq(self, o: Self) -> u8 {
        self.simd_eq(o).to_bitmask() as u8
    }
    #[inline(always)]
    fn select(mask: u8, a: Self, b: Self) -> Self {
        let (a, mut b) = (a.to_array(), b.to_array());
        for l in 0..8 {
            if mask & (1 << l) != 0 {
                b[l] = a[l];
            }
        }
        Self::from_array(b)
    }
    #[inline(always)]
    fn truncate(self) -> [u32; 8] {
        self.to_array().map(|v| v as u32)
    }
    #[inline(always)]
    fn gather(base: &[f32], index: [u32; 8]) -> Self {
        Self::from_array(index.map(|i| base[i as usize]))
    }
    #[inline(always)]
    fn gather_xyz(base: &[f32], stride: u32, index: [u32; 8]) -> [Self; 3] {
        let at = |k: u32| index.map(|i| i.wrapping_mul(stride).wrapping_add(k));
        [0, 1, 2].map(|k| Self::gather(base, at(k)))
    }
    #[inline(always)]
    fn gather_xyzw(base: &[[f32; 4]], index: [u32; 8]) -> [Self; 4] {
        let rows = index.map(|i| base[i as usize]);
        [0, 1, 2, 3].map(|k| Self::from_array(rows.map(|r| r[k])))
    }
    #[inline(always)]
    fn transpose(rows: [[f32; 8]; 8]) -> [Self; 8] {
        std::array::from_fn(|k| Self::from_array(rows.map(|r| r[k])))
    }
    #[inline(always)]
    fn bit_field(self, shift: u32, width: u32, up: u32) -> Self {
        let field = |v: f32| f32::from_bits((v.to_bits() >> shift & ((1 << width) - 1)) << up);
        Self::from_array(self.to_array().map(field))
    }
    #[inline(always)]
    fn differ(v: [u32; 8], x: u32) -> u8 {
        (0..8).fold(0, |m, l| m | u8::from(v[l] != x) << l)
    }
}

/// [`Ops::gather_xyz`] of `u32`s: the bits of fields 0, 1 and 2 of the rows
/// `index` of `base`, rows of `stride` (at least 3).
#[inline(always)]
pub(crate) fn gather_xyz_u32<L: Lanes>(
    base: &[u32],
    stride: u32,
    index: [u32; 8],
) -> [[u32; 8]; 3] {
    L::gather_xyz(bytemuck::cast_slice(base), stride, index)
        .map(|field| bytemuck::cast(field.to_array()))
}

#[cfg(target_arch = "x86_64")]
pub(crate) use avx2_lanes::Avx2;

#[cfg(target_arch = "x86_64")]
mod avx2_lanes {
    use std::arch::x86_64::*;
    use std::ops::{Add, Div, Mul, Sub};

    /// Eight lanes in one AVX register. No value of this type exists except
    /// inside a function compiled with `#[target_feature(enable = "avx2")]`
    /// that was entered after [`super::avx2`] said the CPU has it: the only
    /// constructors are the sealed `Ops` methods, called by
    /// this crate's kernels on that path alone.
    #[derive(Clone, Copy, Debug)]
    pub struct Avx2(__m256);

    /// One AVX instruction on lanes.
    macro_rules! avx {
        ($e:expr) => {
            // SAFETY: an `Avx2` value is only ever made and used on the AVX2
            // path (see the type's documentation), so the CPU supports the
            // instruction; the intrinsics take and return registers only.
            unsafe { $e }
        };
    }

    impl Add for Avx2 {
        type Output = Avx2;
        #[inline(always)]
        fn add(self, o: Avx2) -> Avx2 {
            Avx2(avx!(_mm256_add_ps(self.0, o.0)))
        }
    }
    impl Sub for Avx2 {
        type Output = Avx2;
        #[inline(always)]
        fn sub(self, o: Avx2) -> Avx2 {
            Avx2(avx!(_mm256_sub_ps(self.0, o.0)))
        }
    }
    impl Mul for Avx2 {
        type Output = Avx2;
        #[inline(always)]
        fn mul(self, o: Avx2) -> Avx2 {
            Avx2(avx!(_mm256_mul_ps(self.0, o.0)))
        }
    }
    impl Div for Avx2 {
        type Output = Avx2;
        #[inline(always)]
        fn div(self, o: Avx2) -> Avx2 {
            Avx2(avx!(_mm256_div_ps(self.0, o.0)))
        }
    }

    impl super::sealed::Ops for Avx2 {
        // Moves between lanes and arrays are bit casts, not broadcast, load or
        // store intrinsics: nothing that must be inlined to be fast.
        #[inline(always)]
        fn splat(v: f32) -> Self {
            Self::from_array([v; 8])
        }
        #[inline(always)]
        fn from_array(v: [f32; 8]) -> Self {
            // SAFETY: `[f32; 8]` and `__m256` are both 32 bytes of eight f32.
            Avx2(unsafe { std::mem::transmute::<[f32; 8], __m256>(v) })
        }
        #[inline(always)]
        fn to_array(self) -> [f32; 8] {
            // SAFETY: as in `from_array`.
            unsafe { std::mem::transmute::<__m256, [f32; 8]>(self.0) }
        }
        #[inline(always)]
        fn max(self, o: Self) -> Self {
            Avx2(avx!(_mm256_max_ps(self.0, o.0)))
        }
        #[inline(always)]
        fn min(self, o: Self) -> Self {
            Avx2(avx!(_mm256_min_ps(self.0, o.0)))
        }
        #[inline(always)]
        fn sqrt(self) -> Self {
            Avx2(avx!(_mm256_sqrt_ps(self.0)))
        }
        #[inline(always)]
        fn floor(self) -> Self {
            Avx2(avx!(_mm256_floor_ps(self.0)))
        }
        #[inline(always)]
        fn ceil(self) -> Self {
            Avx2(avx!(_mm256_ceil_ps(self.0)))
        }
        #[inline(always)]
        fn gt(self, o: Self) -> u8 {
            avx!(_mm256_movemask_ps(_mm256_cmp_ps::<_CMP_GT_OQ>(self.0, o.0))) as u8
        }
        #[inline(always)]
        fn lt(self, o: Self) -> u8 {
            avx!(_mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(self.0, o.0))) as u8
        }
        #[inline(always)]
        fn ge(self, o: Self) -> u8 {
            avx!(_mm256_movemask_ps(_mm256_cmp_ps::<_CMP_GE_OQ>(self.0, o.0))) as u8
        }
        #[inline(always)]
        fn le(self, o: Self) -> u8 {
            avx!(_mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(self.0, o.0))) as u8
        }
        #[inline(always)]
        fn eq(self, o: Self) -> u8 {
            avx!(_mm256_movemask_ps(_mm256_cmp_ps::<_CMP_EQ_OQ>(self.0, o.0))) as u8
        }
        #[inline(always)]
        fn select(mask: u8, a: Self, b: Self) -> Self {
            // Lane `l` of the blend mask is all ones where bit `l` is set.
            avx!({
                let bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
                let set = _mm256_and_si256(_mm256_set1_epi32(i32::from(mask)), bits);
                let lanes = _mm256_castsi256_ps(_mm256_cmpeq_epi32(set, bits));
                Avx2(_mm256_blendv_ps(b.0, a.0, lanes))
            })
        }
        #[inline(always)]
        fn truncate(self) -> [u32; 8] {
            let v = avx!(_mm256_cvttps_epi32(self.0));
            // SAFETY: `__m256i` and `[u32; 8]` are both 32 bytes.
            unsafe { std::mem::transmute::<__m256i, [u32; 8]>(v) }
        }
        #[inline(always)]
        fn gather(base: &[f32], index: [u32; 8]) -> Self {
            let index = in_bounds(index, base.len());
            // SAFETY: every lane's index is below `base.len()` (`in_bounds`
            // panics otherwise), so each lane reads an element of `base`.
            Avx2(unsafe { _mm256_i32gather_ps::<4>(base.as_ptr(), index) })
        }
        #[inline(always)]
        fn gather_xyz(base: &[f32], stride: u32, index: [u32; 8]) -> [Self; 3] {
            let offsets = index.map(|i| i.wrapping_mul(stride));
            // Each row read whole, four floats in one load, where every row
            // has a fourth float after its three (all but a last row of
            // three): a load a row beats a gather a field.
            if !all_below(offsets, base.len().saturating_sub(3)) {
                // Field by field (no closure around a lane operation: it
                // would be compiled without AVX2).
                return [
                    Self::gather(base, offsets),
                    Self::gather(base, offsets.map(|o| o.wrapping_add(1))),
                    Self::gather(base, offsets.map(|o| o.wrapping_add(2))),
                ];
            }
            // SAFETY: every offset `o` is below `base.len() − 3`, so the
            // four floats from `o` lie in `base`.
            let [x, y, z, _] = unsafe { transposed(base.as_ptr(), offsets, 1) };
            [x, y, z]
        }
        #[inline(always)]
        fn gather_xyzw(base: &[[f32; 4]], index: [u32; 8]) -> [Self; 4] {
            if !all_below(index, base.len()) {
                panic!(
                    "gather index out of bounds: {index:?} for length {}",
                    base.len()
                );
            }
            // SAFETY: every index is below `base.len()`, so the four floats
            // of row `index[l]`, from float `4·index[l]`, lie in `base`.
            unsafe { transposed(base.as_flattened().as_ptr(), index, 4) }
        }
        #[inline(always)]
        fn transpose(rows: [[f32; 8]; 8]) -> [Self; 8] {
            let r = rows.map(|row| Self::from_array(row).0);
            // Straight-line intrinsics, no closures: a closure would not
            // carry this function's target features, and each intrinsic
            // would become a call.
            avx!({
                // Pairs of rows interleaved, then quads, then the halves.
                let (t0, t1) = (
                    _mm256_unpacklo_ps(r[0], r[1]),
                    _mm256_unpackhi_ps(r[0], r[1]),
                );
                let (t2, t3) = (
                    _mm256_unpacklo_ps(r[2], r[3]),
                    _mm256_unpackhi_ps(r[2], r[3]),
                );
                let (t4, t5) = (
                    _mm256_unpacklo_ps(r[4], r[5]),
                    _mm256_unpackhi_ps(r[4], r[5]),
                );
                let (t6, t7) = (
                    _mm256_unpacklo_ps(r[6], r[7]),
                    _mm256_unpackhi_ps(r[6], r[7]),
                );
                let q0 = _mm256_shuffle_ps::<0x44>(t0, t2);
                let q1 = _mm256_shuffle_ps::<0xee>(t0, t2);
                let q2 = _mm256_shuffle_ps::<0x44>(t1, t3);
                let q3 = _mm256_shuffle_ps::<0xee>(t1, t3);
                let q4 = _mm256_shuffle_ps::<0x44>(t4, t6);
                let q5 = _mm256_shuffle_ps::<0xee>(t4, t6);
                let q6 = _mm256_shuffle_ps::<0x44>(t5, t7);
                let q7 = _mm256_shuffle_ps::<0xee>(t5, t7);
                [
                    Avx2(_mm256_permute2f128_ps::<0x20>(q0, q4)),
                    Avx2(_mm256_permute2f128_ps::<0x20>(q1, q5)),
                    Avx2(_mm256_permute2f128_ps::<0x20>(q2, q6)),
                    Avx2(_mm256_permute2f128_ps::<0x20>(q3, q7)),
                    Avx2(_mm256_permute2f128_ps::<0x31>(q0, q4)),
                    Avx2(_mm256_permute2f128_ps::<0x31>(q1, q5)),
                    Avx2(_mm256_permute2f128_ps::<0x31>(q2, q6)),
                    Avx2(_mm256_permute2f128_ps::<0x31>(q3, q7)),
                ]
            })
        }
        #[inline(always)]
        fn bit_field(self, shift: u32, width: u32, up: u32) -> Self {
            avx!({
                let bits = _mm256_castps_si256(self.0);
                let down = _mm256_srl_epi32(bits, _mm_cvtsi32_si128(shift as i32));
                let kept = _mm256_and_si256(down, _mm256_set1_epi32(((1u32 << width) - 1) as i32));
                let moved = _mm256_sll_epi32(kept, _mm_cvtsi32_si128(up as i32));
                Avx2(_mm256_castsi256_ps(moved))
            })
        }
        #[inline(always)]
        fn differ(v: [u32; 8], x: u32) -> u8 {
            // SAFETY: `[u32; 8]` and `__m256i` are both 32 bytes, any bits.
            let v = unsafe { std::mem::transmute::<[u32; 8], __m256i>(v) };
            let same = avx!(_mm256_cmpeq_epi32(v, _mm256_set1_epi32(x as i32)));
            !(avx!(_mm256_movemask_ps(_mm256_castsi256_ps(same))) as u8)
        }
    }

    /// The four floats from `base + stride·index[l]` in lane `l`, field by
    /// field: one 16-byte load per lane and a 4×4 transpose in each half.
    ///
    /// # Safety
    /// For every lane, the four floats from `base + stride·index[l]` lie in
    /// one live allocation; the CPU has AVX2.
    #[inline(always)]
    unsafe fn transposed(base: *const f32, index: [u32; 8], stride: usize) -> [Avx2; 4] {
        // Lanes `a` and `b` (= a + 4) side by side: the halves transpose apart.
        macro_rules! pair {
            ($a:expr, $b:expr) => {
                _mm256_insertf128_ps::<1>(
                    _mm256_castps128_ps256(_mm_loadu_ps(base.add(index[$a] as usize * stride))),
                    _mm_loadu_ps(base.add(index[$b] as usize * stride)),
                )
            };
        }
        // SAFETY: the caller's: each load reads four floats of one
        // allocation; the shuffles take and return registers only.
        unsafe {
            let (t0, t1, t2, t3) = (pair!(0, 4), pair!(1, 5), pair!(2, 6), pair!(3, 7));
            let (xy01, zw01) = (_mm256_unpacklo_ps(t0, t1), _mm256_unpackhi_ps(t0, t1));
            let (xy23, zw23) = (_mm256_unpacklo_ps(t2, t3), _mm256_unpackhi_ps(t2, t3));
            [
                Avx2(_mm256_shuffle_ps::<0x44>(xy01, xy23)),
                Avx2(_mm256_shuffle_ps::<0xEE>(xy01, xy23)),
                Avx2(_mm256_shuffle_ps::<0x44>(zw01, zw23)),
                Avx2(_mm256_shuffle_ps::<0xEE>(zw01, zw23)),
            ]
        }
    }

    /// Whether every lane of `v` is below `len` (unsigned).
    #[inline(always)]
    fn all_below(v: [u32; 8], len: usize) -> bool {
        let Some(last) = len.min(i32::MAX as usize).checked_sub(1) else {
            return false;
        };
        // SAFETY: `[u32; 8]` and `__m256i` are both 32 bytes.
        let v = unsafe { std::mem::transmute::<[u32; 8], __m256i>(v) };
        let last = avx!(_mm256_set1_epi32(last as i32));
        // Every lane `≤ last` (unsigned): its minimum with `last` is itself.
        let below = avx!(_mm256_cmpeq_epi32(_mm256_min_epu32(v, last), v));
        avx!(_mm256_movemask_epi8(below)) == -1
    }

    /// `index` as a register of i32 lanes, after checking that every lane is
    /// below `len` (and so, with `len` capped at `i32::MAX`, a non-negative
    /// i32: the gathers' offsets cannot wrap). Panics, as indexing does,
    /// otherwise.
    #[inline(always)]
    fn in_bounds(index: [u32; 8], len: usize) -> __m256i {
        if len == 0 {
            panic!("gather from an empty slice");
        }
        if !all_below(index, len) {
            panic!("gather index out of bounds: {index:?} for length {len}");
        }
        // SAFETY: `[u32; 8]` and `__m256i` are both 32 bytes.
        unsafe { std::mem::transmute::<[u32; 8], __m256i>(index) }
    }
}

/// The instruction sets the kernels can run on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    /// The portable lanes (`wide`).
    Portable,
    /// AVX2 lanes (x86-64 CPUs that have AVX2).
    Avx2,
}

/// The instruction set the kernels run on in this process: AVX2 where the CPU
/// has it, unless the environment variable `CONTINUUM_SIMD=portable` asks for
/// the portable lanes (to compare the two; both give the same images).
pub fn isa() -> Isa {
    static ISA: OnceLock<Isa> = OnceLock::new();
    *ISA.get_or_init(|| {
        let portable = std::env::var("CONTINUUM_SIMD").is_ok_and(|v| v == "portable");
        if !portable && cpu_has_avx2() {
            Isa::Avx2
        } else {
            Isa::Portable
        }
    })
}

/// Does the CPU support AVX2?
pub fn cpu_has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Whether the kernels take the AVX2 path ([`isa`]).
#[inline(always)]
pub fn avx2() -> bool {
    isa() == Isa::Avx2
}

/// The mask of the first `n` lanes (all eight for `n ≥ 8`).
#[inline(always)]
pub(crate) fn first_lanes(n: usize) -> u8 {
    ((1u16 << n.min(8)) - 1) as u8
}

/// Adds one to `counts[i + l]` for each lane `l` of `lanes`: eight adds
/// with no branch on how many lanes there are (rows of small triangles are
/// short, and a loop over their pixels mispredicts its exit at every row),
/// one by one where the eight would run past the buffer's end.
#[inline(always)]
pub(crate) fn count_eight(counts: &mut [u32], i: usize, lanes: u8) {
    match counts.get_mut(i..i + 8) {
        Some(eight) => {
            for (l, count) in eight.iter_mut().enumerate() {
                *count += u32::from(lanes >> l & 1);
            }
        }
        None => {
            let mut left = lanes;
            while left != 0 {
                counts[i + left.trailing_zeros() as usize] += 1;
                left &= left - 1;
            }
        }
    }
}

/// A chunk of one to eight ids as eight lanes' worth: the chunk itself
/// when it is full (read in one load from where it lies: an array built
/// lane by lane would be read back before its stores land), else a copy
/// whose lanes past its end repeat its last id.
pub(crate) enum EightIds<'a> {
    Full(&'a [u32; 8]),
    Padded([u32; 8]),
}

impl<'a> EightIds<'a> {
    #[inline(always)]
    pub(crate) fn of(ids: &'a [u32]) -> EightIds<'a> {
        match ids.try_into() {
            Ok(full) => EightIds::Full(full),
            Err(_) => EightIds::Padded(std::array::from_fn(|l| ids[l.min(ids.len() - 1)])),
        }
    }

    #[inline(always)]
    pub(crate) fn get(&self) -> &[u32; 8] {
        match self {
            EightIds::Full(ids) => ids,
            EightIds::Padded(ids) => ids,
        }
    }
}

/// Defines `fn NAME<G: Bound, ..>(args) -> R` (or `fn NAME<G: Bound, ..; const
/// C: Type, ..>`: const parameters after a semicolon) that runs
/// `BODY::<L, G, .., C, ..>(args)`
/// on the lanes [`isa`] picks: `BODY` (generic over `L: Lanes` first, and
/// `#[inline(always)]` down to the lane operations, so that all of it is
/// compiled into the AVX2 form) once with [`Avx2`] inside an
/// `#[target_feature(enable = "avx2")]` function, once with [`Portable`].
macro_rules! dispatch {
    ($(#[$meta:meta])* $vis:vis fn $name:ident<$($g:ident: $bound:path),*>($($arg:ident: $ty:ty),* $(,)?) -> $ret:ty => $body:ident) => {
        $crate::simd::dispatch! {
            $(#[$meta])* $vis fn $name<$($g: $bound),*; >($($arg: $ty),*) -> $ret => $body
        }
    };
    ($(#[$meta:meta])* $vis:vis fn $name:ident<$($g:ident: $bound:path),*; $(const $c:ident: $cty:ty),*>($($arg:ident: $ty:ty),* $(,)?) -> $ret:ty => $body:ident) => {
        $(#[$meta])*
        $vis fn $name<$($g: $bound,)* $(const $c: $cty),*>($($arg: $ty),*) -> $ret {
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx2")]
                fn on_avx2<$($g: $bound,)* $(const $c: $cty),*>($($arg: $ty),*) -> $ret {
                    $body::<$crate::simd::Avx2, $($g,)* $($c),*>($($arg),*)
                }
                if $crate::simd::avx2() {
                    // SAFETY: `avx2()` found that this CPU has AVX2.
                    return unsafe { on_avx2::<$($g,)* $($c),*>($($arg),*) };
                }
            }
            $body::<$crate::simd::Portable, $($g,)* $($c),*>($($arg),*)
        }
    };
}
pub(crate) use dispatch;

/// Asks the CPU to bring every cache line of `value` toward L1 ahead of its
/// use: a hint, not a read, so nothing waits for it (a plain early load
/// would hold up retirement until it arrived). For loops that know the next
/// element's address while they work on the current one.
#[inline(always)]
pub(crate) fn prefetch<T: ?Sized>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        let first = (value as *const T).cast::<i8>();
        let size = size_of_val(value);
        // SAFETY: `_mm_prefetch` needs SSE, which every x86-64 CPU has; it
        // is a hint that neither reads nor faults, whatever the address (and
        // these lie within a live reference).
        let hint =
            |offset: usize| unsafe { _mm_prefetch::<_MM_HINT_T0>(first.wrapping_add(offset)) };
        // A line every 64 bytes and the last byte's: every line the value
        // touches holds one of them. (A counted loop: for a sized value the
        // count is a constant and the loop unrolls into bare prefetches,
        // where `(0..size).step_by(64).chain(..)` kept an iterator's state
        // and branches in every call: 4% of a dragon frame's instructions
        // under `3dr-brute`.)
        for line in 0..size.div_ceil(64) {
            hint(line * 64);
        }
        hint(size.saturating_sub(1));
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}

/// [`prefetch`] of a few values spanning at most 128 bytes (a BVH leaf's
/// records): hints at its first byte, 64 bytes on and its last byte —
/// every line such a span touches — with no loop over its length.
#[inline(always)]
pub(crate) fn prefetch_short<T>(values: &[T]) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        let first = values.as_ptr().cast::<i8>();
        let last = size_of_val(values).saturating_sub(1);
        debug_assert!(last < 128, "a short span");
        // SAFETY: as in `prefetch`: a hint that neither reads nor faults.
        let hint =
            |offset: usize| unsafe { _mm_prefetch::<_MM_HINT_T0>(first.wrapping_add(offset)) };
        hint(0);
        hint(last.min(64));
        hint(last);
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = values;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `count_eight` adds one at exactly the lanes it is given, eight at once
    /// or, where the eight would run past the buffer's end, one by one: the
    /// counts after random groups are those of adding lane by lane.
    #[test]
    fn counting_eight_adds_one_at_each_given_lane() {
        let mut rng = fastrand::Rng::with_seed(5);
        let (mut counts, mut expected) = (vec![0u32; 21], vec![0u32; 21]);
        let (mut groups, mut at_end) = (0, 0);
        for _ in 0..2_000 {
            let i = rng.usize(0..counts.len());
            // Lanes past the buffer's end are never given.
            let lanes = rng.u8(..) & first_lanes(counts.len() - i);
            count_eight(&mut counts, i, lanes);
            for l in (0..8).filter(|l| lanes >> l & 1 == 1) {
                expected[i + l] += 1;
            }
            groups += 1;
            at_end += usize::from(i + 8 > counts.len());
        }
        assert_eq!(counts, expected);
        assert_eq!(groups, 2_000);
        assert!(at_end > 300, "{at_end} groups ran past the end");
    }

    dispatch! {
        /// [`Ops::differ`] on the dispatched lanes.
        fn differ_dispatched<>(v: [u32; 8], x: u32) -> u8 => differ_on
    }

    #[inline(always)]
    fn differ_on<L: Lanes>(v: [u32; 8], x: u32) -> u8 {
        L::differ(v, x)
    }

    /// `differ` marks exactly the lanes unlike its value, on both paths, for
    /// values at the ends of `u32` (the background id among them) and between.
    #[test]
    fn differing_lanes_are_marked() {
        let mut rng = fastrand::Rng::with_seed(9);
        let mut checked = 0;
        for _ in 0..1_000 {
            let x = [0, u32::MAX, i32::MAX as u32 + 1, rng.u32(..)][rng.usize(0..4)];
            let v: [u32; 8] = std::array::from_fn(|_| match rng.bool() {
                true => x,
                false => [0, u32::MAX, x ^ 1, rng.u32(..)][rng.usize(0..4)],
            });
            let expected = (0..8).fold(0u8, |m, l| m | u8::from(v[l] != x) << l);
            assert_eq!(differ_dispatched(v, x), expected, "{v:?} {x}");
            assert_eq!(<Portable as sealed::Ops>::differ(v, x), expected);
            checked += 1;
        }
        assert_eq!(checked, 1_000);
    }

    /// What a gather reads: single floats, rows of three of floats and
    /// of `u32` bits, rows of four.
    type Gathered = ([f32; 8], [[f32; 8]; 3], [[u32; 8]; 3], [[f32; 8]; 4]);

    /// The bases of the four gathers: single floats, rows of three floats,
    /// rows of three `u32`s, rows of four floats.
    type Bases<'a> = (&'a [f32], &'a [f32], &'a [u32], &'a [[f32; 4]]);

    dispatch! {
        /// The lanes' four gathers, gather `k` of rows `index[k]`.
        fn gathered<>(bases: Bases, index: [[u32; 8]; 4]) -> Gathered => gathered_on
    }

    #[inline(always)]
    fn gathered_on<L: Lanes>((g, f, u, q): Bases, index: [[u32; 8]; 4]) -> Gathered {
        let [x, y, z] = L::gather_xyz(f, 3, index[1]);
        let [a, b, c, d] = L::gather_xyzw(q, index[3]);
        (
            L::gather(g, index[0]).to_array(),
            [x.to_array(), y.to_array(), z.to_array()],
            gather_xyz_u32::<L>(u, 3, index[2]),
            [a.to_array(), b.to_array(), c.to_array(), d.to_array()],
        )
    }

    /// Gathers read `base[index]` (and rows of it) per lane on both paths,
    /// the last row of three included (which a whole-row load would read
    /// past), every bit of a NaN kept, and each panics on an index out of
    /// bounds, the first one past the end and `u32::MAX` included.
    #[test]
    fn gathers_read_their_indices_and_check_bounds() {
        // A hundred rows in each base.
        let g: Vec<f32> = (0..100).map(|i| i as f32 * 0.75).collect();
        let f: Vec<f32> = (0..300).map(|i| i as f32 * 0.5).collect();
        // Signalling and quiet NaNs, infinities, subnormals among the bits.
        let u: Vec<u32> = (0..300)
            .map(|i: u32| 0x7f80_0001_u32.wrapping_add(i.wrapping_mul(0x0101_0101)))
            .collect();
        let q: Vec<[f32; 4]> = (0..100)
            .map(|i| [i as f32, -(i as f32), 0.25, i as f32 * 8.0])
            .collect();
        let bases = (&g[..], &f[..], &u[..], &q[..]);
        for index in [
            [0, 99, 5, 5, 17, 64, 1, 98],
            [99; 8],
            [3, 2, 1, 0, 99, 98, 97, 96],
        ] {
            let fields = |k: u32| index.map(|i| f[(3 * i + k) as usize]);
            let bits = |k: u32| index.map(|i| u[(3 * i + k) as usize]);
            let expected = (
                index.map(|i| g[i as usize]),
                [fields(0), fields(1), fields(2)],
                [bits(0), bits(1), bits(2)],
                [0, 1, 2, 3].map(|k| index.map(|i| q[i as usize][k])),
            );
            assert_eq!(gathered_on::<Portable>(bases, [index; 4]), expected);
            assert_eq!(gathered(bases, [index; 4]), expected);
        }
        let index = [0, 99, 5, 5, 17, 64, 1, 98];
        let mut checked = 0;
        for bad in [100, 101, u32::MAX, 1 << 31] {
            for lane in [0, 7] {
                let mut wrong = index;
                wrong[lane] = bad;
                for path in [gathered_on::<Portable>, gathered] {
                    for which in 0..4 {
                        let mut indices = [index; 4];
                        indices[which] = wrong;
                        let result = std::panic::catch_unwind(|| path(bases, indices));
                        assert!(
                            result.is_err(),
                            "gather {which}: index {bad} in lane {lane} read"
                        );
                        checked += 1;
                    }
                }
            }
        }
        assert_eq!(checked, 64);
    }
}
