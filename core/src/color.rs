//! sRGB: the transfer function both ways, exactly, and the fixed colours of
//! an image's background.

use glam::Vec3;

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

/// [`encode_srgb_formula`] as tables: the first byte of each of
/// [`SRGB_BUCKETS`] equal buckets, and per byte the smallest linear value
/// that encodes to it (found by bisection over `f32` bit patterns, which
/// order non-negative values), with `+∞` after the last: no byte past 255.
struct SrgbTable {
    bucket_start: Vec<u8>,
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
        let bucket_start = (0..=SRGB_BUCKETS)
            .map(|i| encode_srgb_formula(i as f32 / SRGB_BUCKETS as f32))
            .collect();
        SrgbTable {
            bucket_start,
            thresholds,
        }
    })
}

/// Linear [0, 1] → sRGB byte, exactly the transfer function (tested on
/// every threshold and millions of values) without its `powf`: the bucket's
/// first byte, then up past the thresholds `v` reaches (at most a step or two).
#[inline]
pub fn encode_srgb(v: f32) -> u8 {
    // NaN and v ≤ 0 encode to 0; v ≥ 1 to 255.
    if v.is_nan() || v <= 0.0 {
        return 0;
    }
    if v >= 1.0 {
        return 255;
    }
    let table = srgb_table();
    // Exact: scaling by a power of two does not round.
    let mut b = table.bucket_start[(v * SRGB_BUCKETS as f32) as usize];
    // A bucket is narrower than a byte's step almost everywhere: the first
    // step without a branch, a second in the loop's rare turn.
    b += u8::from(v >= table.thresholds[usize::from(b) + 1]);
    while v >= table.thresholds[usize::from(b) + 1] {
        b += 1;
    }
    b
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
    [encode_srgb(c.x), encode_srgb(c.y), encode_srgb(c.z), 255]
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
        for v in values {
            assert_eq!(
                encode_srgb(v),
                encode_srgb_formula(v),
                "{v} ({:#x})",
                v.to_bits()
            );
        }
    }

    #[test]
    fn every_srgb_byte_survives_decoding_and_encoding() {
        for b in 0..=255u8 {
            assert_eq!(encode_srgb(decode_srgb(b)), b);
        }
    }
}
