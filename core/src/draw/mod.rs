//! The lectures' 2D primitives beside the triangle: lines (DDA and integer
//! Bresenham), anti-aliased and thick lines with caps and joins, midpoint
//! circles and discs, and polygons scan-converted with the even-odd and
//! non-zero rules (the Saarland lecture "Rasterization", slides "Lines",
//! "Thick Lines", "Bresenham: Circle", "Inside-Outside Tests").
//!
//! **Conventions**, as in the triangle rasterizers: image coordinates put
//! pixel `(i, j)`'s centre at `(i + 0.5, j + 0.5)`; a pixel belongs to a shape
//! when its centre does (or, anti-aliased, in the share of its sample
//! positions that do: [`sample_positions`], the triangles' for the same mode). The
//! integer algorithms (Bresenham, the midpoint circle) take pixel indices:
//! their points are those pixels' centres. Every primitive draws only inside
//! its `[width, height]` and gives each pixel at most one
//! [`Plot::plot`] call; coordinates far outside the image cost no more than
//! the image; NaN or infinite input is an error naming the field, degenerate
//! input (a zero-length line, a polygon without area) draws nothing.

mod circle;
mod line;
mod polygon;
mod stroke;

pub use circle::{midpoint_circle, midpoint_disc};
pub use line::{bresenham, dda};
pub use polygon::{FillRule, fill_polygon};
pub use stroke::{Cap, Join, Stroke, aa_line, stroke};

use crate::aa::{AaMode, SamplePattern};
use crate::ground::FieldError;

/// The sample positions within a pixel (`[0, 1)²`) that the triangle
/// rasterizers test under `aa` — every coverage position — for the
/// anti-aliased primitives, so `--aa` means the same for both.
pub fn sample_positions(aa: AaMode) -> Vec<[f32; 2]> {
    SamplePattern::of(aa).positions
}

/// Where a primitive puts its pixels: pixel `(x, y)` inside the image, and
/// the share of it the primitive covers, in `(0, 1]`.
pub trait Plot {
    fn plot(&mut self, x: u32, y: u32, coverage: f32);
}

impl<F: FnMut(u32, u32, f32)> Plot for F {
    fn plot(&mut self, x: u32, y: u32, coverage: f32) {
        self(x, y, coverage);
    }
}

/// Largest coordinate magnitude the float primitives take (NaN fails the
/// test too): sums and differences of two stay finite.
pub const MAX_COORDINATE: f64 = (1u64 << 52) as f64;

/// `points` are finite and within [`MAX_COORDINATE`]; else an error naming `field`.
fn finite(field: &'static str, points: &[[f64; 2]]) -> Result<(), FieldError> {
    let bad = |p: &[f64; 2]| !p.iter().all(|c| c.abs() <= MAX_COORDINATE);
    match points.iter().position(bad) {
        None => Ok(()),
        Some(k) => Err(FieldError::new(
            field,
            format!(
                "point {k} is {:?}: coordinates must be finite and within ±2⁵²",
                points[k]
            ),
        )),
    }
}
