//! A tile's hierarchical w-buffer: what occlusion tests read instead of the
//! samples (paper §5 "early-z", Fig. 6a's `is_occluded`).
//!
//! Per [`HIZ_CELL`]² cell it keeps the farthest depth over the cell's samples
//! that hold one and a mask of the pixels whose every stored sample holds one —
//! the masked representation of Hasselgren, Andersson and Akenine-Möller's
//! "Masked Software Occlusion Culling" (HPG 2016) with a single layer. A cell
//! with one empty pixel has no finite farthest depth over all its samples, so a
//! plain hierarchical w-buffer culls nothing there (on `teapots` almost every
//! cell along a silhouette); the mask still hides what projects onto the
//! covered pixels alone.

use wide::f32x8;

use crate::ground::PixelRect;

/// Side of a hierarchical w-buffer cell in pixels (a cell's pixels are the
/// 64 bits of its mask, row by row).
pub const HIZ_CELL: u32 = 8;

#[derive(Clone, Copy, Debug)]
struct Cell {
    /// The farthest depth over the cell's samples that hold one
    /// (`−∞` when none does).
    far: f32,
    /// Bit `8·row + column`: every stored sample of that pixel holds a depth.
    /// Bits of pixels beyond the tile's edge are set (nothing lies there).
    covered: u64,
}

const EMPTY: Cell = Cell {
    far: f32::NEG_INFINITY,
    covered: 0,
};

/// The cells of one tile (pixels `x0..x1 × y0..y1`).
#[derive(Clone, Debug)]
pub(crate) struct Hiz {
    cells: Vec<Cell>,
    rect: PixelRect,
    columns: u32,
}

/// The mask bits of pixel columns `x0..x1` and rows `y0..y1` of a cell
/// (cell-local, each below [`HIZ_CELL`]).
#[inline]
fn cell_bits(x0: u32, x1: u32, y0: u32, y1: u32) -> u64 {
    let row = ((1u64 << (x1 - x0)) - 1) << x0;
    // One byte per row: the product spreads `row` into each (no carries).
    let rows = (u64::MAX >> (64 - 8 * (y1 - y0))) << (8 * y0) & 0x0101_0101_0101_0101;
    row * rows
}

impl Hiz {
    /// Empty cells over the pixels of `rect`.
    pub fn new(rect: PixelRect) -> Hiz {
        let mut hiz = Hiz {
            cells: Vec::new(),
            rect,
            columns: 0,
        };
        hiz.reset(rect);
        hiz
    }

    /// Empty cells over the pixels of `rect` (the memory kept).
    pub fn reset(&mut self, rect: PixelRect) {
        self.rect = rect;
        self.columns = rect.width().div_ceil(HIZ_CELL);
        let cells = (self.columns * rect.height().div_ceil(HIZ_CELL)) as usize;
        self.cells.clear();
        self.cells.resize(cells, EMPTY);
    }

    /// Each cell that the pixels of the non-empty `r` (inside the tile)
    /// touch, with the mask bits of `r`'s pixels in it.
    #[inline]
    fn touched(&self, r: PixelRect) -> impl Iterator<Item = (&Cell, u64)> {
        let t = self.rect;
        let (lx0, ly0, lx1, ly1) = (r.x0 - t.x0, r.y0 - t.y0, r.x1 - t.x0, r.y1 - t.y0);
        let (cx0, cx1) = (lx0 / HIZ_CELL, (lx1 - 1) / HIZ_CELL + 1);
        let (cy0, cy1) = (ly0 / HIZ_CELL, (ly1 - 1) / HIZ_CELL + 1);
        // Cell-local span of `r` along one axis in cell `c`.
        let local = |c: u32, lo: u32, hi: u32| {
            let base = c * HIZ_CELL;
            (lo.max(base) - base, hi.min(base + HIZ_CELL) - base)
        };
        (cy0..cy1).flat_map(move |cy| {
            let (y0, y1) = local(cy, ly0, ly1);
            (cx0..cx1).map(move |cx| {
                let (x0, x1) = local(cx, lx0, lx1);
                let cell = &self.cells[(cy * self.columns + cx) as usize];
                (cell, cell_bits(x0, x1, y0, y1))
            })
        })
    }

    /// The farthest stored depth over the cells that the pixels of `r` touch
    /// (`+∞` while any of their samples is empty).
    pub fn farthest(&self, r: PixelRect) -> f32 {
        self.depths(r).0
    }

    /// [`Hiz::farthest`] over the pixels of `r`, and the nearest of their
    /// cells' farthest held depths (`+∞` when no sample holds one): nothing at
    /// that depth or nearer is hidden anywhere in `r`.
    #[inline]
    pub fn depths(&self, r: PixelRect) -> (f32, f32) {
        self.touched(r).fold(
            (f32::NEG_INFINITY, f32::INFINITY),
            |(farthest, nearest), (c, _)| {
                let whole = if c.covered == u64::MAX {
                    c.far
                } else {
                    f32::INFINITY
                };
                let held = if c.far > f32::NEG_INFINITY {
                    c.far
                } else {
                    f32::INFINITY
                };
                (farthest.max(whole), nearest.min(held))
            },
        )
    }

    /// Is everything at depth `w` hidden over the pixels of `r`: every stored
    /// sample of them holds a depth, and in each cell they touch all held
    /// depths are nearer than `w`? (The depth test keeps the nearer sample, and
    /// a tie only where `w` equals the stored depth, so nothing at `w` or
    /// farther can be seen there.)
    pub fn hides(&self, r: PixelRect, w: f32) -> bool {
        self.touched(r)
            .all(|(c, bits)| c.covered & bits == bits && w > c.far)
    }

    /// Recomputes the cells that the pixels of `r` touch from the tile's
    /// stored depths (`depth`: layer-major, `pixels` per layer).
    pub fn update(&mut self, r: PixelRect, depth: &[f32], pixels: usize) {
        let t = self.rect;
        let (cx0, cx1) = ((r.x0 - t.x0) / HIZ_CELL, (r.x1 - 1 - t.x0) / HIZ_CELL + 1);
        let (cy0, cy1) = ((r.y0 - t.y0) / HIZ_CELL, (r.y1 - 1 - t.y0) / HIZ_CELL + 1);
        let width = t.width() as usize;
        for cy in cy0..cy1 {
            for cx in cx0..cx1 {
                let (px0, py0) = ((cx * HIZ_CELL) as usize, cy * HIZ_CELL);
                let columns = (HIZ_CELL as usize).min(width - px0);
                let rows = HIZ_CELL.min(t.height() - py0);
                let mut far = f32x8::splat(f32::NEG_INFINITY);
                let mut covered = u64::MAX;
                for row in 0..rows {
                    let start = (py0 + row) as usize * width + px0;
                    // Bit k: pixel k of the row holds every sample so far.
                    let mut held = 0xff;
                    for layer in depth.chunks_exact(pixels) {
                        let v = f32x8::from(std::array::from_fn(|k| {
                            if k < columns {
                                layer[start + k]
                            } else {
                                f32::NEG_INFINITY
                            }
                        }));
                        let finite = v.is_finite();
                        held &= finite.to_bitmask() | (0xff << columns);
                        far = far.fast_max(finite.bitselect(v, f32x8::splat(f32::NEG_INFINITY)));
                    }
                    covered &= !(u64::from(!held & 0xff) << (8 * row));
                }
                let far = far.to_array().into_iter().fold(f32::NEG_INFINITY, f32::max);
                self.cells[(cy * self.columns + cx) as usize] = Cell { far, covered };
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cell_bits_are_the_rectangle() {
        let mut checked = 0;
        for (x0, x1, y0, y1) in [(0, 8, 0, 8), (2, 5, 1, 7), (7, 8, 7, 8), (0, 1, 3, 4)] {
            let bits = cell_bits(x0, x1, y0, y1);
            for y in 0..8 {
                for x in 0..8 {
                    let inside = (x0..x1).contains(&x) && (y0..y1).contains(&y);
                    assert_eq!(
                        bits >> (8 * y + x) & 1 == 1,
                        inside,
                        "{x0}..{x1} × {y0}..{y1}"
                    );
                }
            }
            checked += 1;
        }
        assert_eq!(checked, 4);
    }

    /// A 12×10 tile (partial cells at both edges), one stored sample per pixel.
    #[test]
    fn farthest_and_hides_follow_the_samples() {
        let rect = PixelRect::new(16, 8, 28, 18);
        let (w, h) = (rect.width() as usize, rect.height() as usize);
        let mut depth = vec![f32::INFINITY; w * h];
        let mut hiz = Hiz::new(rect);
        hiz.update(rect, &depth, w * h);
        assert_eq!(hiz.farthest(rect), f32::INFINITY);
        assert!(!hiz.hides(PixelRect::new(16, 8, 17, 9), 1e30));
        // Cover the first cell but one pixel, at depth 2 (and 5 at one pixel).
        for y in 0..8 {
            for x in 0..8 {
                depth[y * w + x] = if (x, y) == (3, 4) { 5.0 } else { 2.0 };
            }
        }
        depth[7 * w + 7] = f32::INFINITY;
        hiz.update(PixelRect::new(16, 8, 24, 16), &depth, w * h);
        let first = PixelRect::new(16, 8, 24, 16);
        assert_eq!(hiz.farthest(first), f32::INFINITY);
        // The empty pixel (23, 15) is outside: hidden behind the farthest (5).
        let most = PixelRect::new(16, 8, 23, 16);
        assert!(hiz.hides(most, 5.5));
        assert!(!hiz.hides(most, 5.0), "a tie may still win the depth test");
        assert!(!hiz.hides(first, 5.5), "an empty pixel hides nothing");
        depth[7 * w + 7] = 1.0;
        hiz.update(PixelRect::new(23, 15, 24, 16), &depth, w * h);
        assert_eq!(hiz.farthest(first), 5.0);
        assert!(hiz.hides(first, 5.5));
        // The partial cell at the right edge: 4 pixel columns, covered whole.
        for y in 0..8 {
            for x in 8..12 {
                depth[y * w + x] = 3.0;
            }
        }
        hiz.update(PixelRect::new(24, 8, 28, 16), &depth, w * h);
        assert_eq!(hiz.farthest(PixelRect::new(24, 8, 28, 16)), 3.0);
        assert_eq!(hiz.farthest(PixelRect::new(16, 8, 28, 16)), 5.0);
        assert_eq!(
            hiz.farthest(rect),
            f32::INFINITY,
            "the bottom rows are empty"
        );
    }

    /// With several stored samples a pixel is covered only when all are.
    #[test]
    fn a_pixel_is_covered_when_every_sample_is() {
        let rect = PixelRect::new(0, 0, 8, 8);
        let mut depth = vec![1.0; 2 * 64];
        depth[64 + 9] = f32::INFINITY;
        let mut hiz = Hiz::new(rect);
        hiz.update(rect, &depth, 64);
        assert!(!hiz.hides(PixelRect::new(1, 1, 2, 2), 2.0));
        assert!(hiz.hides(PixelRect::new(2, 1, 8, 8), 2.0));
        assert_eq!(hiz.farthest(rect), f32::INFINITY);
    }
}
