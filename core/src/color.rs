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

/// Buckets of the encoding table over [0, 1].
const SRGB_BUCKETS: usize = 4096;

/// [`encode_srgb_formula`] as a table of [`SRGB_BUCKETS`] equal buckets
/// over [0, 1] (and one for `1.0`, past the last). A bucket is narrower than
/// the transfer function's smallest byte step (2.4e-4 against 3.0e-4, the
/// step of its linear part, which is also its steepest), so at most one
/// byte starts inside it — checked when the table is built: each bucket
/// holds its first byte and where the next byte starts (`+∞` when not inside
/// it). The byte starts ("thresholds", the smallest linear value encoding to
/// each byte) are found by bisection over `f32` bit patterns, which order
/// non-negative values.
struct SrgbTable {
    buckets: [Bucket; SRGB_BUCKETS + 1],
    /// The buckets' fields apart, as lanes gather them: `next`, and
    /// `first` as a float.
    nexts: [f32; SRGB_BUCKETS + 1],
    firsts: [f32; SRGB_BUCKETS + 1],
    #[cfg(test)]
    thresholds: [f32; 257],
}

/// One bucket of an [`SrgbTable`]: the byte its first value encodes to, and
/// the smallest value of the next byte (may lie past the bucket).
#[derive(Clone, Copy, Default)]
struct Bucket {
    next: f32,
    first: u8,
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
        let mut buckets = [Bucket::default(); SRGB_BUCKETS + 1];
        for (i, bucket) in buckets.iter_mut().enumerate() {
            let first = encode_srgb_formula(i as f32 / SRGB_BUCKETS as f32);
            let (next, after) = match usize::from(first) {
                255 => (f32::INFINITY, f32::INFINITY),
                b => (thresholds[b + 1], thresholds[b + 2]),
            };
            // The bucket's values lie below (i + 1) / SRGB_BUCKETS (exact).
            assert!(
                after >= (i + 1) as f32 / SRGB_BUCKETS as f32,
                "sRGB bucket {i} holds two byte steps"
            );
            *bucket = Bucket { next, first };
        }
        SrgbTable {
            buckets,
            nexts: buckets.map(|b| b.next),
            firsts: buckets.map(|b| f32::from(b.first)),
            #[cfg(test)]
            thresholds,
        }
    })
}

impl SrgbTable {
    /// [`encode_srgb`] without a branch for its special values: `v ≥ 1`
    /// (`+∞` too) is read as `1`, whose bucket's byte is 255 with no next;
    /// NaN and `v ≤ 0` land in bucket 0 (the float-to-integer cast
    /// saturates, NaN to 0) and never reach its next byte's start (`> 0`).
    /// Two independent loads (one bucket record), no loop.
    #[inline(always)]
    fn encode(&self, v: f32) -> u8 {
        let v = if v >= 1.0 { 1.0 } else { v };
        // Exact: scaling by a power of two does not round.
        let bucket = &self.buckets[((v * SRGB_BUCKETS as f32) as usize).min(SRGB_BUCKETS)];
        bucket.first + u8::from(v >= bucket.next)
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
/// green, blue), all in lanes: the clamp and the bucket index (`v ≥ 1` → 1,
/// then `v · 4096` truncated, a NaN or negative lane to bucket 0, as the
/// scalar `as usize` gives), the bucket's first byte and next start
/// gathered, and the byte `first + (v ≥ next)` (a NaN lane: not `≥`). The
/// three bytes are packed into one word per lane in lanes too (`r + 2⁸g +
/// 2¹⁶b` is below 2²⁴: exact in f32), so the pixels leave in one store (a
/// pixel built byte by byte and then copied whole waits for its stores).
#[inline(always)]
pub(crate) fn encode_rgb_eight<L: Lanes>(channels: [L; 3]) -> [[u8; 4]; 8] {
    let table = srgb_table();
    let (one, zero) = (L::splat(1.0), L::splat(0.0));
    let mut packed = zero;
    for (v, weight) in channels.into_iter().zip([1.0, 256.0, 65536.0]) {
        let v = L::select(v.ge(one), one, v);
        // `maxps` gives its second operand, 0, for a NaN lane.
        let at = (v * L::splat(SRGB_BUCKETS as f32)).max(zero).truncate();
        let (next, first) = (L::gather(&table.nexts, at), L::gather(&table.firsts, at));
        // Small whole numbers, and their weighted sum: exact.
        packed = packed + (first + L::select(v.ge(next), one, zero)) * L::splat(weight);
    }
    // Byte order in memory: red first, alpha last.
    let words = packed.truncate().map(|rgb| (rgb | 0xff00_0000).to_le());
    bytemuck::cast(words)
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

    #[test]
    fn every_srgb_byte_survives_decoding_and_encoding() {
        for b in 0..=255u8 {
            assert_eq!(encode_srgb(decode_srgb(b)), b);
        }
    }
}
