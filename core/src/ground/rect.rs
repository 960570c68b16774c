//! Pixel rectangles and the sample span that turns a continuous box into one.

/// Every f32 of magnitude 2²³ or more is an integer.
const INTEGRAL_ABOVE: f32 = 8_388_608.0;

/// `v.floor()` up to the sign of a zero result, inline: baseline x86-64 has
/// no rounding instruction and `f32::floor` is a libm call (once per triangle
/// bound in every setup). Truncation is exact below [`INTEGRAL_ABOVE`]; at and
/// beyond it (and for ±∞ and NaN) `v` is its own floor.
#[inline(always)]
fn floor(v: f32) -> f32 {
    if v.abs() < INTEGRAL_ABOVE {
        let t = v as i32 as f32;
        if t > v { t - 1.0 } else { t }
    } else {
        v
    }
}

/// `v.ceil()` up to the sign of a zero result (see [`floor`]).
#[inline(always)]
fn ceil(v: f32) -> f32 {
    if v.abs() < INTEGRAL_ABOVE {
        let t = v as i32 as f32;
        if t < v { t + 1.0 } else { t }
    } else {
        v
    }
}

/// A rectangle of pixels, half-open: the pixels `x0..x1 × y0..y1` (the one
/// convention of the crate: tiles, screen boxes, frusta and bands alike).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct PixelRect {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl PixelRect {
    pub const fn new(x0: u32, y0: u32, x1: u32, y1: u32) -> PixelRect {
        PixelRect { x0, y0, x1, y1 }
    }

    #[inline]
    pub fn width(self) -> u32 {
        self.x1.saturating_sub(self.x0)
    }

    #[inline]
    pub fn height(self) -> u32 {
        self.y1.saturating_sub(self.y0)
    }

    /// No pixel inside.
    #[inline]
    pub fn is_empty(self) -> bool {
        self.x0 >= self.x1 || self.y0 >= self.y1
    }

    /// Is pixel `(x, y)` inside? (The tests' reference for the rectangle
    /// queries.)
    #[cfg(test)]
    pub fn contains(self, x: u32, y: u32) -> bool {
        (self.x0..self.x1).contains(&x) && (self.y0..self.y1).contains(&y)
    }

    /// The pixels in both rectangles, or `None`.
    #[inline]
    pub fn intersect(self, o: PixelRect) -> Option<PixelRect> {
        let r = PixelRect {
            x0: self.x0.max(o.x0),
            y0: self.y0.max(o.y0),
            x1: self.x1.min(o.x1),
            y1: self.y1.min(o.y1),
        };
        (!r.is_empty()).then_some(r)
    }

    /// The pixels with a sample in `[min_x, max_x] × [min_y, max_y]` (sample
    /// offsets within `span` of the pixel corner), clamped to a `width × height`
    /// image; `None` when there are none.
    pub fn from_bounds(
        min_x: f32,
        min_y: f32,
        max_x: f32,
        max_y: f32,
        width: u32,
        height: u32,
        span: SampleSpan,
    ) -> Option<PixelRect> {
        // Pixel p's samples lie in [p + lo, p + hi]: first p with p + hi ≥ min,
        // last with p + lo ≤ max.
        let first = |v: f32, hi: f32| ceil(v - hi).max(0.0);
        let last = |v: f32, lo: f32, n: u32| floor(v - lo).min(n as f32 - 1.0);
        let (x0, y0) = (first(min_x, span.hi[0]), first(min_y, span.hi[1]));
        let (x1, y1) = (
            last(max_x, span.lo[0], width),
            last(max_y, span.lo[1], height),
        );
        // Also rejects NaN bounds.
        if !(x0 <= x1 && y0 <= y1) {
            return None;
        }
        Some(PixelRect {
            x0: x0 as u32,
            y0: y0 as u32,
            x1: x1 as u32 + 1,
            y1: y1 as u32 + 1,
        })
    }
}

/// The box of sample offsets inside a pixel: a sample of pixel `p` lies in
/// `[p + lo, p + hi]` per axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleSpan {
    pub lo: [f32; 2],
    pub hi: [f32; 2],
}

#[cfg(test)]
mod tests {
    use super::{ceil, floor};

    /// Equal to the library's, zero signs aside, on random values of every
    /// magnitude, on and around integers, halves, the integral threshold and
    /// the specials.
    #[test]
    fn inline_floor_and_ceil_are_the_library_ones() {
        let mut rng = fastrand::Rng::with_seed(3);
        let mut values = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            8_388_607.5,
            -8_388_607.5,
            8_388_608.0,
            -8_388_609.0,
            1e30,
            -1e30,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ];
        for _ in 0..100_000 {
            let v = (rng.f32() - 0.5) * 10f32.powi(rng.i32(-8..12));
            values.extend([
                v,
                v.round(),
                v.round() + 0.5,
                f32::from_bits(v.to_bits() + 1),
            ]);
        }
        for v in values {
            assert_eq!(floor(v), v.floor(), "floor({v:e})");
            assert_eq!(ceil(v), v.ceil(), "ceil({v:e})");
        }
        assert!(floor(f32::NAN).is_nan() && ceil(f32::NAN).is_nan());
    }
}
