//! Brute-force coverage over bounding boxes, shared by `2dr-brute` and `3dr-brute`:
//! triangles are sorted into horizontal bands of the screen (a counting sort by
//! the rows their box spans), and the bands are rasterized in parallel, each
//! testing every pixel of every box that reaches it.

use rayon::prelude::*;

use super::PixelRect;
use crate::camera::pixel_center;
use crate::framebuffer::Framebuffer;

/// Rows per band: small enough to balance two cores, large enough that a
/// typical triangle lands in one band.
const BAND_ROWS: u32 = 16;

/// A set-up triangle that can be tested at a sample.
pub(crate) trait BoxedTriangle: Sync {
    fn rect(&self) -> PixelRect;
    fn id(&self) -> u32;
    /// Coverage and depth at image point `(x, y)`.
    fn sample(&self, x: f32, y: f32) -> Option<f32>;
}

/// Tests every pixel of every triangle's box, writing coverage and depth.
pub(crate) fn rasterize_boxes<T: BoxedTriangle>(items: &[T], fb: &mut Framebuffer) {
    let band_count = fb.height.div_ceil(BAND_ROWS) as usize;

    // 1. Counting sort of triangle indices by band.
    let mut offsets = vec![0u32; band_count + 1];
    for t in items {
        let r = t.rect();
        for b in (r.y0 / BAND_ROWS)..=(r.y1 / BAND_ROWS) {
            offsets[b as usize + 1] += 1;
        }
    }
    for b in 0..band_count {
        offsets[b + 1] += offsets[b];
    }
    let mut fill = offsets.clone();
    let mut members = vec![0u32; offsets[band_count] as usize];
    for (k, t) in items.iter().enumerate() {
        let r = t.rect();
        for b in (r.y0 / BAND_ROWS)..=(r.y1 / BAND_ROWS) {
            members[fill[b as usize] as usize] = k as u32;
            fill[b as usize] += 1;
        }
    }

    // 2. Bands in parallel; within a band, each box's rows that fall in it.
    fb.bands_mut(BAND_ROWS)
        .into_par_iter()
        .enumerate()
        .for_each(|(b, mut band)| {
            for &k in &members[offsets[b] as usize..offsets[b + 1] as usize] {
                let t = &items[k as usize];
                let r = t.rect();
                let id = t.id();
                for y in r.y0.max(band.y0)..=r.y1.min(band.y1 - 1) {
                    let yc = pixel_center(y);
                    for x in r.x0..=r.x1 {
                        let i = band.index(x, y);
                        band.edge_evals[i] += 1;
                        if let Some(w) = t.sample(pixel_center(x), yc) {
                            band.write(i, w, id);
                        }
                    }
                }
            }
        });
}
