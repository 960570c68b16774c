//! 2D edge functions in fixed point, the way hardware rasterizers decide coverage
//! (Direct3D 11 functional spec §3.4 "Rasterization rules", Vulkan
//! `subPixelPrecisionBits = 8`): projected vertices are snapped to 1/256 pixel
//! (16.8 fixed point, round to nearest even), then every edge function is
//! evaluated exactly in integers. With no rounding left in the decision, the
//! top-left rule ([`owns_tie`]) alone settles every sample on an edge, and two
//! triangles sharing an edge get exactly negated edge values.
//!
//! Samples are placed on a 1/512-pixel grid, which holds every position of every
//! anti-aliasing pattern exactly (the densest, `ssaa:256`, is on the 1/512 grid);
//! snapped vertices are the even points of that grid.

use super::edge2d::ScreenVertex;
use super::{BlockTest, Coverage, EdgeWalk, owns_tie};

/// Fraction bits of snapped vertex positions (16.8 fixed point).
pub const SUBPIXEL_BITS: u32 = 8;

/// Fraction bits of the grid samples are evaluated on.
const SAMPLE_BITS: u32 = 9;

/// One pixel in sample-grid units.
const SAMPLE_ONE: f32 = (1u32 << SAMPLE_BITS) as f32;

/// Largest snapped coordinate magnitude in pixels: 2¹⁵, the range of 16.8 fixed
/// point. Edge functions of coordinates this large (2²⁴ sample-grid units, so
/// differences below 2²⁵) multiply into less than 2⁵⁰: exact in `i64`.
pub const MAX_COORDINATE: f32 = 32768.0;

/// Snaps a pixel coordinate to the 1/256 grid (round to nearest, ties to even),
/// in sample-grid units.
#[inline]
pub fn snap(v: f32) -> i64 {
    let steps = (v * (1u32 << SUBPIXEL_BITS) as f32).round_ties_even() as i64;
    steps << (SAMPLE_BITS - SUBPIXEL_BITS)
}

/// A sample coordinate (pixel units, on the 1/512 grid) in sample-grid units.
#[inline(always)]
fn sample_units(v: f32) -> i64 {
    (v * SAMPLE_ONE) as i64
}

/// A projected triangle with snapped vertices and exact integer edge functions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle2DFixed {
    /// Per edge `i` (opposite vertex `i`): its start vertex, sample-grid units.
    start: [[i64; 2]; 3],
    /// Per edge: end − start, oriented so the inside is `E > 0`.
    delta: [[i64; 2]; 3],
    pub owns: [bool; 3],
    /// The image-linear depth quantity at each vertex (see [`ScreenVertex::q`]).
    q: [f64; 3],
    /// `q` is `w` (orthographic) rather than `1/w`.
    affine: bool,
    /// Smallest and largest vertex `w`: sample depths are clamped into it.
    w_range: [f32; 2],
    /// Pixel bounds of the snapped vertices: `[min_x, min_y, max_x, max_y]`.
    pub bounds: [f32; 4],
}

impl Triangle2DFixed {
    /// Snaps the vertices and sets up the edge functions; `None` when the
    /// snapped triangle has zero area (hardware culls it too), a coordinate is
    /// beyond [`MAX_COORDINATE`], or a depth is not finite.
    pub fn setup(v: &[ScreenVertex; 3], affine: bool) -> Option<Triangle2DFixed> {
        if !v
            .iter()
            .all(|s| s.x.abs() < MAX_COORDINATE && s.y.abs() < MAX_COORDINATE)
        {
            return None;
        }
        let w = v.map(|s| if affine { s.q } else { 1.0 / s.q });
        let w_range = [w[0].min(w[1]).min(w[2]), w[0].max(w[1]).max(w[2])];
        if !(w_range[0].is_finite() && w_range[1].is_finite()) {
            return None;
        }
        // 1. Snap to 1/256 pixel.
        let p = v.map(|s| [snap(s.x), snap(s.y)]);
        // 2. Orientation: twice the signed area, exact.
        let area =
            (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0]);
        if area == 0 {
            return None;
        }
        // 3. Edge i runs p[i+1] → p[i+2]; E(s) = Δ × (s − start), which is the
        //    signed area at vertex i: negated for negative areas so the inside
        //    is positive.
        let sign = if area > 0 { 1 } else { -1 };
        let mut start = [[0; 2]; 3];
        let mut delta = [[0; 2]; 3];
        let mut owns = [false; 3];
        for i in 0..3 {
            let (a, b) = (p[(i + 1) % 3], p[(i + 2) % 3]);
            start[i] = a;
            delta[i] = [(b[0] - a[0]) * sign, (b[1] - a[1]) * sign];
            // E = Δx·(y − sy) − Δy·(x − sx): ∂E/∂x = −Δy, ∂E/∂y = Δx.
            owns[i] = owns_tie(-delta[i][1] as f32, delta[i][0] as f32);
        }
        let to_pixels = |u: i64| u as f32 / SAMPLE_ONE;
        let xs = p.map(|q| q[0]);
        let ys = p.map(|q| q[1]);
        let min = |a: [i64; 3]| a[0].min(a[1]).min(a[2]);
        let max = |a: [i64; 3]| a[0].max(a[1]).max(a[2]);
        Some(Triangle2DFixed {
            start,
            delta,
            owns,
            q: v.map(|s| f64::from(s.q)),
            affine,
            w_range,
            bounds: [
                to_pixels(min(xs)),
                to_pixels(min(ys)),
                to_pixels(max(xs)),
                to_pixels(max(ys)),
            ],
        })
    }

    /// The three exact edge values at a sample (sample-grid units).
    #[inline(always)]
    fn edge_values(&self, sx: i64, sy: i64) -> [i64; 3] {
        std::array::from_fn(|i| self.edge_value(i, sx, sy))
    }

    /// Edge `i`'s exact value at a sample (sample-grid units).
    #[inline(always)]
    fn edge_value(&self, i: usize, sx: i64, sy: i64) -> i64 {
        let [x0, y0] = self.start[i];
        let [dx, dy] = self.delta[i];
        dx * (sy - y0) - dy * (sx - x0)
    }

    #[inline(always)]
    fn inside(&self, e: [i64; 3]) -> bool {
        (0..3).all(|i| e[i] > 0 || (e[i] == 0 && self.owns[i]))
    }

    /// Perspective-correct depth from the exact edge values: `1/w = Σ λ_i / w_i`
    /// with `λ_i = E_i / ΣE` (orthographic: `w = Σ λ_i w_i`), clamped to the
    /// vertices' range.
    #[inline(always)]
    fn depth(&self, e: [i64; 3]) -> Option<f32> {
        let e = e.map(|v| v as f64);
        let sum = e[0] + e[1] + e[2];
        let q = e[0] * self.q[0] + e[1] * self.q[1] + e[2] * self.q[2];
        let w = (if self.affine { q / sum } else { sum / q }) as f32;
        (w > 0.0 && w < f32::INFINITY).then(|| w.max(self.w_range[0]).min(self.w_range[1]))
    }
}

impl EdgeWalk for Triangle2DFixed {
    /// `E = Δx·(sy − y0) − Δy·(sx − x0)` on sample-grid units `s = 512·p`.
    fn edge_line(&self, i: usize) -> [f64; 3] {
        let ([x0, y0], [dx, dy]) = (self.start[i], self.delta[i]);
        let (a, b) = (
            (-dy) as f64 * f64::from(SAMPLE_ONE),
            dx as f64 * f64::from(SAMPLE_ONE),
        );
        [a, b, (dy * x0 - dx * y0) as f64]
    }

    #[inline(always)]
    fn inside_edge_at(&self, i: usize, x: f32, y: f32) -> bool {
        let e = self.edge_value(i, sample_units(x), sample_units(y));
        e > 0 || (e == 0 && self.owns[i])
    }
}

impl Coverage for Triangle2DFixed {
    #[inline(always)]
    fn sample(&self, x: f32, y: f32) -> Option<f32> {
        let e = self.edge_values(sample_units(x), sample_units(y));
        if self.inside(e) { self.depth(e) } else { None }
    }

    #[inline(always)]
    fn depth_inside(&self, x: f32, y: f32) -> Option<f32> {
        self.depth(self.edge_values(sample_units(x), sample_units(y)))
    }

    /// Exact at the block's corners: a linear function takes its extremes there,
    /// so no error margin is needed.
    fn classify_block(&self, x0: f32, y0: f32, x1: f32, y1: f32) -> BlockTest {
        let (x0, y0, x1, y1) = (
            sample_units(x0),
            sample_units(y0),
            sample_units(x1),
            sample_units(y1),
        );
        let mut lo = [i64::MAX; 3];
        let mut hi = [i64::MIN; 3];
        for (x, y) in [(x0, y0), (x1, y0), (x0, y1), (x1, y1)] {
            let e = self.edge_values(x, y);
            for k in 0..3 {
                lo[k] = lo[k].min(e[k]);
                hi[k] = hi[k].max(e[k]);
            }
        }
        let holds = |k: usize, e: i64| e > 0 || (e == 0 && self.owns[k]);
        if (0..3).any(|k| !holds(k, hi[k])) {
            BlockTest::Outside
        } else if (0..3).all(|k| holds(k, lo[k])) {
            BlockTest::Inside
        } else {
            BlockTest::Partial
        }
    }

    fn min_depth(&self) -> f32 {
        self.w_range[0]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vertex(x: f32, y: f32) -> ScreenVertex {
        ScreenVertex { x, y, q: 1.0 }
    }

    #[test]
    fn snapping_rounds_to_the_nearest_256th_ties_to_even() {
        assert_eq!(snap(1.0), 512);
        assert_eq!(snap(1.0 + 1.0 / 256.0), 514);
        // Half a step: ties go to the even step.
        assert_eq!(snap(0.5 / 256.0), 0);
        assert_eq!(snap(1.5 / 256.0), 4);
        assert_eq!(snap(-1.5 / 256.0), -4);
    }

    /// Direct3D's worked example: a square from (0.5, 0.5) to (5.5, 5.5) split
    /// along its diagonal; the top-left rule gives every pixel to one triangle.
    #[test]
    fn shared_diagonal_splits_samples_exactly() {
        let (a, b, c, d) = (
            vertex(0.5, 0.5),
            vertex(5.5, 0.5),
            vertex(5.5, 5.5),
            vertex(0.5, 5.5),
        );
        let upper = Triangle2DFixed::setup(&[a, b, c], false).unwrap();
        let lower = Triangle2DFixed::setup(&[a, c, d], false).unwrap();
        let (mut n_upper, mut n_lower) = (0, 0);
        for y in 0..8 {
            for x in 0..8 {
                let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
                let u = upper.sample(px, py).is_some();
                let l = lower.sample(px, py).is_some();
                assert!(!(u && l), "({x}, {y}) covered twice");
                n_upper += u32::from(u);
                n_lower += u32::from(l);
            }
        }
        assert_eq!((n_upper, n_lower), (15, 10));
    }

    #[test]
    fn zero_area_after_snapping_is_not_drawn() {
        let t = [vertex(0.0, 0.0), vertex(10.0, 0.0), vertex(5.0, 0.001)];
        assert!(Triangle2DFixed::setup(&t, false).is_none());
    }
}
