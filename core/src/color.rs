//! sRGB: the transfer function both ways, exactly, and the fixed colours of
//! an image's background.

use glam::Vec3;

use crate::simd::Lanes;

/// Background colour (sRGB).
pub const BACKGROUND_COLOR: [u8; 4] = [24, 24, 28, 255];

/// Colour of pixels the viewport casts no ray through (outside the parabolic disc).
pub const OUTSIDE_VIEWPORT_COLOR: [u8; 4] = [0, 0, 0, 255];

/// Linear [0, 1] → sRGB byte: the transfer function, rounded to nearest.
#[inline]
fn encode_srgb_formula(v: f32) -> u8 {
    let v = v.clamp(0.0, 1.0);
    let s = if v <= 0.003_130_8 {
        v * 12.92
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0 + 0.5) as u8
}

/// Mantissa bits that pick a bucket within its octave: 2⁷ buckets per
/// octave, each narrower than the transfer function's byte steps there.
const BUCKET_BITS: u32 = 7;
/// The bits of a value below its bucket's: where in the bucket it lies.
const LOW_BITS: u32 = 23 - BUCKET_BITS;
/// The smallest value with a bucket of its own, 2⁻¹³ (1.2e-4): every value
/// below it encodes to 0 (byte 1 starts at 1.5e-4), so it shares bucket 0.
const FIRST_BUCKETED: f32 = 1.0 / 8192.0;
/// The bit pattern of [`FIRST_BUCKETED`] above [`LOW_BITS`]: bucket 0's.
const FIRST_BUCKET: u32 = FIRST_BUCKETED.to_bits() >> LOW_BITS;
/// Buckets of [2⁻¹³, 1) — 13 octaves — and one for `1.0`, past the last.
const SRGB_BUCKETS: usize = ((1.0f32.to_bits() >> LOW_BITS) - FIRST_BUCKET) as usize + 1;
/// A bucket's `next` when no byte starts inside it: above every low part.
const NO_STEP: u32 = 1 << LOW_BITS;

/// [`encode_srgb_formula`] as a table of buckets over [0, 1] by bit pattern:
/// the bucket of a value in [2⁻¹³, 1] is its exponent and top
/// [`BUCKET_BITS`] mantissa bits. A bucket is narrower than the transfer
/// function's byte step wherever it lies (checked when the table is built:
/// the steps widen as `v^0.58` and the buckets as `v`, and the top octave's,
/// 3.9e-3 against 6.0e-3, are the closest), so at most one byte starts inside
/// it. Each bucket is one word: the byte its first value encodes to (bits
/// 0–7) and where the next byte starts (bits 8–), as the low [`LOW_BITS`]
/// bits of that start's pattern ([`NO_STEP`] when no byte starts inside the
/// bucket) — positive floats order as their bit patterns, so a value reaches
/// the next byte where its own low bits reach those. One load a channel, from
/// 6.7 KB that stay in the L1 cache. The byte starts ("thresholds", the
/// smallest linear value encoding to each byte) are found by bisection over
/// `f32` bit patterns.
struct SrgbTable {
    words: [u32; SRGB_BUCKETS],
    #[cfg(test)]
    thresholds: [f32; 257],
}

fn srgb_table() -> &'static SrgbTable {
    static TABLE: std::sync::OnceLock<SrgbTable> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        let mut thresholds = [f32::INFINITY; 257];
        thresholds[0] = 0.0;
        for (b, t) in thresholds.iter_mut().enumerate().take(256).skip(1) {
            let (mut lo, mut hi) = (0u32, 1.0f32.to_bits());
            while lo < hi {
                let mid = lo + (hi - lo) / 2;
                if usize::from(encode_srgb_formula(f32::from_bits(mid))) >= b {
                    hi = mid;
                } else {
                    lo = mid + 1;
                }
            }
            *t = f32::from_bits(lo);
        }
        // Below bucket 0's first value, byte 0 alone.
        assert!(thresholds[1] >= FIRST_BUCKETED, "byte 1 starts below 2^-13");
        let mut words = [0u32; SRGB_BUCKETS];
        for (i, word) in words.iter_mut().enumerate() {
            let high = FIRST_BUCKET + i as u32;
            let start = f32::from_bits(high << LOW_BITS);
            let first = encode_srgb_formula(start);
            let (next, after) = match usize::from(first) {
                255 => (f32::INFINITY, f32::INFINITY),
                b => (thresholds[b + 1], thresholds[b + 2]),
            };
            // Patterns at or above `end` lie in later buckets (`1.0`'s
            // bucket is the last: nothing above it is looked up).
            let end = (high + 1) << LOW_BITS;
            assert!(
                after.to_bits() >= end,
                "sRGB bucket {i} holds two byte steps"
            );
            let next = match next.to_bits() {
                n if n < end => n & (NO_STEP - 1),
                _ => NO_STEP,
            };
            *word = u32::from(first) | next << 8;
        }
        SrgbTable {
            words,
            #[cfg(test)]
            thresholds,
        }
    })
}

/// The table's bucket of `bits`, the pattern of a value in [0, 1] (a value
/// below 2⁻¹³ in bucket 0).
#[inline(always)]
fn bucket_of(bits: u32) -> usize {
    ((bits >> LOW_BITS).max(FIRST_BUCKET) - FIRST_BUCKET) as usize
}

/// The byte of the value with pattern `bits` in the bucket whose word is `word`.
#[inline(always)]
fn byte_in(word: u32, bits: u32) -> u32 {
    (word & 0xff) + u32::from(bits & (NO_STEP - 1) >= word >> 8)
}

impl SrgbTable {
    /// [`encode_srgb`] without a branch for its special values: `v ≥ 1`
    /// (`+∞` too) is read as `1`, whose bucket's byte is 255 with no next;
    /// NaN, `−0` and `v < 0` are read as `+0` (bucket 0, byte 0).
    #[inline(always)]
    fn encode(&self, v: f32) -> u8 {
        let v = if v >= 1.0 {
            1.0
        } else if v > 0.0 {
            v
        } else {
            0.0
        };
        let bits = v.to_bits();
        byte_in(self.words[bucket_of(bits)], bits) as u8
    }
}

/// Linear [0, 1] → sRGB byte, exactly the transfer function (tested on
/// every threshold and millions of values) without its `powf`: the
/// bucket's first byte, and the next where `v` reaches its start.
#[cfg(test)]
fn encode_srgb(v: f32) -> u8 {
    srgb_table().encode(v)
}

/// sRGB byte → linear [0, 1].
#[inline]
pub fn decode_srgb(b: u8) -> f32 {
    let s = f32::from(b) / 255.0;
    if s <= 0.040_45 {
        s / 12.92
    } else {
        ((s + 0.055) / 1.055).powf(2.4)
    }
}

/// An sRGB colour in linear light.
pub fn linear_rgb(c: [u8; 4]) -> Vec3 {
    Vec3::new(decode_srgb(c[0]), decode_srgb(c[1]), decode_srgb(c[2]))
}

/// Linear RGB → opaque sRGB RGBA8.
#[inline]
pub fn encode_rgb(c: Vec3) -> [u8; 4] {
    let table = srgb_table();
    [table.encode(c.x), table.encode(c.y), table.encode(c.z), 255]
}

/// [`encode_rgb`] of eight colours in lanes, channel by channel (red,
/// green, blue): the clamp in lanes (`v > 1` → 1, then `maxps(v, 0)`, which
/// gives `+0` for a NaN, `−0` or negative lane, as the scalar path reads
/// them), then each lane's bucket word gathered (one load a channel) and its
/// byte `first + (low bits ≥ next)` on the lanes' bit patterns. The three
/// bytes and the opaque alpha are packed into one word per lane, so the
/// pixels leave in one store (a pixel built byte by byte and then copied
/// whole waits for its stores).
#[inline(always)]
pub(crate) fn encode_rgb_eight<L: Lanes>(channels: [L; 3]) -> [[u8; 4]; 8] {
    let words: &[f32] = bytemuck::cast_slice(&srgb_table().words);
    let (one, zero) = (L::splat(1.0), L::splat(0.0));
    // Byte order in memory: red first, alpha last.
    let mut packed = [0xff00_0000u32; 8];
    for (v, shift) in channels.into_iter().zip([0, 8, 16]) {
        // `minps(1, v)`: 1 where `1 < v`, else `v` (a NaN lane too).
        let v = one.min(v).max(zero);
        let bits: [u32; 8] = bytemuck::cast(v.to_array());
        // The table's words travel as float lanes, bit for bit.
        let bucket: [u32; 8] = bits.map(|b| bucket_of(b) as u32);
        let word: [u32; 8] = bytemuck::cast(L::gather(words, bucket).to_array());
        for l in 0..8 {
            packed[l] |= byte_in(word[l], bits[l]) << shift;
        }
    }
    bytemuck::cast(packed.map(u32::to_le))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_encoding_tables_give_exactly_the_transfer_function() {
        let table = srgb_table();
        let mut values: Vec<f32> = vec![
            0.0,
            -0.0,
            -1.0,
            1.0,
            2.0,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            -f32::NAN,
            f32::MAX,
            f32::MIN_POSITIVE,
            f32::from_bits(1),
            1.0f32.next_down(),
            1.0f32.next_up(),
            0.003_130_8,
        ];
        for &t in &table.thresholds[..256] {
            for d in -3i32..=3 {
                values.push(f32::from_bits(t.to_bits().saturating_add_signed(d)));
            }
        }
        let mut rng = fastrand::Rng::with_seed(5);
        values.extend((0..2_000_000).map(|_| rng.f32()));
        values.extend((0..200_000).map(|_| rng.f32() * 0.01));
        for v in &values {
            assert_eq!(
                encode_srgb(*v),
                encode_srgb_formula(*v),
                "{v} ({:#x})",
                v.to_bits()
            );
        }
        // Eight at a time in lanes, portable and dispatched (AVX2 where the
        // CPU has it), each channel from its own place in the list.
        let mut groups = 0;
        for chunk in values.chunks_exact(24) {
            let channels: [[f32; 8]; 3] =
                std::array::from_fn(|c| std::array::from_fn(|l| chunk[8 * c + l]));
            for eight in [
                encode_group_on::<crate::simd::Portable>(&channels),
                encode_group(&channels),
            ] {
                for (l, rgba) in eight.iter().enumerate() {
                    let c = Vec3::new(channels[0][l], channels[1][l], channels[2][l]);
                    assert_eq!(*rgba, encode_rgb(c), "{c}");
                }
            }
            groups += 1;
        }
        assert_eq!(groups, values.len() / 24);
    }

    crate::simd::dispatch! {
        fn encode_group<>(channels: &[[f32; 8]; 3]) -> [[u8; 4]; 8] => encode_group_on
    }

    #[inline(always)]
    fn encode_group_on<L: Lanes>([r, g, b]: &[[f32; 8]; 3]) -> [[u8; 4]; 8] {
        encode_rgb_eight([L::from_array(*r), L::from_array(*g), L::from_array(*b)])
    }

    /// Every `f32` in [0, 1] (2³⁰ of them), against the thresholds: the
    /// table's byte is the number of byte starts at or below the value.
    #[test]
    fn the_table_encodes_every_value_in_the_unit_interval() {
        let table = srgb_table();
        let mut byte = 0;
        let mut checked = 0u64;
        for bits in 0..=1.0f32.to_bits() {
            let v = f32::from_bits(bits);
            while v >= table.thresholds[byte + 1] {
                byte += 1;
            }
            assert_eq!(usize::from(table.encode(v)), byte, "{v} ({bits:#x})");
            checked += 1;
        }
        assert_eq!(byte, 255);
        assert_eq!(checked, u64::from(1.0f32.to_bits()) + 1);
    }

    #[test]
    fn every_srgb_byte_survives_decoding_and_encoding() {
        for b in 0..=255u8 {
            assert_eq!(encode_srgb(decode_srgb(b)), b);
        }
    }
}
