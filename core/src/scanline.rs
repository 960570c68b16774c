//! The sweep-line traversal of one triangle in one tile (`2dr-scanline`): the
//! lectures' third way to enumerate a triangle's pixels, beside the bounding
//! box and the hierarchy of [`crate::binning`] (Princeton, "Triangle
//! Sweep-Line Algorithm": walk the edges from the top, row by row, and fill
//! the span between them).
//!
//! Each edge's crossing of a row is walked from the row above by adding its
//! inverse slope (the lectures' `x_L += dx_L/dy_L`, a DDA on the crossing).
//! That walked crossing is only a guess: the span's ends are then found with
//! the edge's own decision ([`EdgeWalk::inside_edge_at`]), searching outwards
//! from the guess and bisecting. An edge's decision is monotone along a row,
//! so the ends found are exactly where the edge functions' samples change —
//! the same samples as `2dr-brute` tests, decided by the same arithmetic and
//! the same tie rule, bit for bit (in f32 and in fixed point).
//!
//! Anti-aliasing: each coverage position of the pattern has its own sample
//! rows, so each gets its own run per pixel row. Pixels where every position
//! is inside are filled (depth only, as binning fills accepted blocks); the
//! pixels at the ends, where only some are, go through the per-sample test.

use crate::binning::{fill_samples, test_samples};
use crate::edge::{Coverage, EdgeWalk};
use crate::framebuffer::TileBuffer;
use crate::ground::PixelRect;
use crate::stats::RasterCounters;

/// Rasterizes `tri` (id `id`) into `tile` span by span, within `clip`
/// (pixels inside the tile).
pub(crate) fn raster_spans<T: Coverage + EdgeWalk>(
    tile: &mut TileBuffer,
    tri: &T,
    id: u32,
    clip: PixelRect,
    counters: &mut RasterCounters,
) {
    let pattern = tile.pattern;
    // Per edge: inside grows along rows (a > 0), shrinks (a < 0), or is
    // constant (a = 0, a horizontal edge); the crossing at the row's top
    // (y = clip.y0, offset 0) and its change per row.
    let lines = [0, 1, 2].map(|i| tri.edge_line(i));
    let mut crossing = lines.map(|[a, b, c]| -(b * f64::from(clip.y0) + c) / a);
    let slope = lines.map(|[a, b, _]| -b / a);
    for y in clip.y0..clip.y1 {
        let (mut union, mut every) = ((clip.x1, clip.x0), (clip.x0, clip.x1));
        for &[ox, oy] in &pattern.positions {
            let sy = y as f32 + oy;
            let (mut lo, mut hi) = (clip.x0, clip.x1);
            for (i, &[a, ..]) in lines.iter().enumerate() {
                if lo >= hi {
                    break;
                }
                let inside = |x: u32| tri.inside_edge_at(i, x as f32 + ox, sy);
                if a == 0.0 {
                    counters.edge_steps += 1;
                    if !inside(lo) {
                        hi = lo;
                    }
                    continue;
                }
                // The pixel whose sample `x + ox` the edge crosses.
                let guess = crossing[i] + slope[i] * f64::from(oy) - f64::from(ox);
                if a > 0.0 {
                    lo = first(lo, hi, guess, &mut counters.edge_steps, inside);
                } else {
                    hi = first(lo, hi, guess, &mut counters.edge_steps, |x| !inside(x));
                }
            }
            if lo < hi {
                union = (union.0.min(lo), union.1.max(hi));
            }
            every = (every.0.max(lo), every.1.min(hi));
        }
        for (c, s) in crossing.iter_mut().zip(slope) {
            *c += s;
        }
        if union.0 >= union.1 {
            continue;
        }
        counters.spans += 1;
        let row = |x0: u32, x1: u32| PixelRect {
            x0,
            y0: y,
            x1,
            y1: y + 1,
        };
        if every.0 < every.1 {
            fill_samples(tile, tri, id, row(every.0, every.1));
            for (x0, x1) in [(union.0, every.0), (every.1, union.1)] {
                if x0 < x1 {
                    test_samples(tile, tri, id, row(x0, x1));
                }
            }
        } else {
            test_samples(tile, tri, id, row(union.0, union.1));
        }
    }
}

/// The first `x` in `lo..hi` where `holds` (monotone: false, then true) is
/// true, or `hi` where it never is: from the pixel at `guess`, outwards in
/// doubling steps until the change is bracketed, then by bisection. Each
/// decision made is counted in `steps`.
#[inline]
fn first(lo: u32, hi: u32, guess: f64, steps: &mut u64, holds: impl Fn(u32) -> bool) -> u32 {
    // `false_at < answer <= true_at`, with `lo − 1` and `hi` as sentinels.
    let (lo, hi) = (i64::from(lo), i64::from(hi));
    let start = if guess.is_nan() {
        lo
    } else {
        (guess.ceil().clamp(lo as f64, (hi - 1) as f64)) as i64
    };
    let mut test = |x: i64| {
        *steps += 1;
        holds(x as u32)
    };
    let (mut false_at, mut true_at);
    let mut step = 1;
    if test(start) {
        true_at = start;
        false_at = lo - 1;
        let mut x = start - step;
        while x >= lo {
            if test(x) {
                true_at = x;
                step *= 2;
                x -= step;
            } else {
                false_at = x;
                break;
            }
        }
    } else {
        false_at = start;
        true_at = hi;
        let mut x = start + step;
        while x < hi {
            if test(x) {
                true_at = x;
                break;
            }
            false_at = x;
            step *= 2;
            x += step;
        }
    }
    while true_at - false_at > 1 {
        let mid = false_at + (true_at - false_at) / 2;
        if test(mid) {
            true_at = mid;
        } else {
            false_at = mid;
        }
    }
    true_at as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The search finds the change of every monotone predicate on a range,
    /// from every guess (in range, outside it, not a number).
    #[test]
    fn first_finds_the_change_from_any_guess() {
        let mut checked = 0;
        for (lo, hi) in [(0u32, 1u32), (3, 4), (0, 64), (10, 73)] {
            for change in lo..=hi {
                for guess in [f64::NAN, -1e30, 1e30, -5.0, 0.2, 7.5, 33.0, 80.0] {
                    let mut steps = 0;
                    let got = first(lo, hi, guess, &mut steps, |x| x >= change);
                    assert_eq!(got, change, "lo {lo} hi {hi} guess {guess}");
                    assert!(steps <= 2 * 8 + 2, "{steps} steps");
                    checked += 1;
                }
            }
        }
        assert_eq!(checked, 8 * (2 + 2 + 65 + 64));
    }
}
