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

use crate::ground::PixelRect;
use crate::simd::{self, Lanes};

/// Side of a hierarchical w-buffer cell in pixels (a cell's pixels are the
/// 64 bits of its mask, row by row).
pub const HIZ_CELL: u32 = 8;

#[derive(Clone, Copy, Debug)]
struct Cell {
    /// No nearer than the farthest depth over the cell's samples that hold
    /// one, and exactly it once every pixel is covered (`−∞` when none holds
    /// one): see [`Hiz::update`].
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
    /// Per cell, what [`Hiz::depths`] takes of it, kept beside the cells
    /// as they change (a frustum's test reads them over every cell it spans,
    /// again after every update): its farthest depth where the cell is
    /// covered whole (`+∞` elsewhere), and its farthest held depth (`+∞`
    /// where none is held).
    whole: Vec<f32>,
    held: Vec<f32>,
    rect: PixelRect,
    columns: u32,
    /// Changes whenever a cell may have: what was read from the cells
    /// under one version holds until it changes.
    version: u64,
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

/// The cells (along one axis) that the tile-local pixels `lo..hi` touch.
#[inline]
fn cells(lo: u32, hi: u32) -> std::ops::Range<u32> {
    lo / HIZ_CELL..(hi - 1) / HIZ_CELL + 1
}

/// The part of the tile-local pixels `lo..hi` (along one axis) in cell `c`,
/// cell-local.
#[inline]
fn span(lo: u32, hi: u32, c: u32) -> (u32, u32) {
    let base = c * HIZ_CELL;
    (lo.max(base) - base, hi.min(base + HIZ_CELL) - base)
}

impl Hiz {
    /// Empty cells over the pixels of `rect`.
    pub fn new(rect: PixelRect) -> Hiz {
        let mut hiz = Hiz {
            cells: Vec::new(),
            whole: Vec::new(),
            held: Vec::new(),
            rect,
            columns: 0,
            version: 0,
        };
        hiz.reset(rect);
        hiz
    }

    /// Empty cells over the pixels of `rect` (the memory kept); the cells
    /// along its right and bottom edges with their bits beyond it set.
    pub fn reset(&mut self, rect: PixelRect) {
        self.version += 1;
        self.rect = rect;
        let (width, height) = (rect.width(), rect.height());
        self.columns = width.div_ceil(HIZ_CELL);
        let rows = height.div_ceil(HIZ_CELL);
        let n = (self.columns * rows) as usize;
        self.cells.clear();
        self.cells.resize(n, EMPTY);
        // No empty cell is covered whole (every cell has a pixel in the tile).
        for summary in [&mut self.whole, &mut self.held] {
            summary.clear();
            summary.resize(n, f32::INFINITY);
        }
        if self.cells.is_empty() {
            return;
        }
        let beyond = |cx: u32, cy: u32| {
            let inside = |n: u32, base: u32| n.min(base + HIZ_CELL) - base;
            !cell_bits(
                0,
                inside(width, cx * HIZ_CELL),
                0,
                inside(height, cy * HIZ_CELL),
            )
        };
        for cy in 0..rows {
            self.cells[((cy + 1) * self.columns - 1) as usize].covered =
                beyond(self.columns - 1, cy);
        }
        for cx in 0..self.columns {
            self.cells[((rows - 1) * self.columns + cx) as usize].covered = beyond(cx, rows - 1);
        }
    }

    /// The non-empty `r` (inside the tile) in tile-local pixels.
    #[inline]
    fn local(&self, r: PixelRect) -> [u32; 4] {
        let t = self.rect;
        [r.x0 - t.x0, r.y0 - t.y0, r.x1 - t.x0, r.y1 - t.y0]
    }

    /// Each cell that the pixels of the non-empty `r` (inside the tile)
    /// touch, with the mask bits of `r`'s pixels in it.
    #[cfg(test)]
    fn touched(&self, r: PixelRect) -> impl Iterator<Item = (&Cell, u64)> {
        let [lx0, ly0, lx1, ly1] = self.local(r);
        cells(ly0, ly1).flat_map(move |cy| {
            let (y0, y1) = span(ly0, ly1, cy);
            cells(lx0, lx1).map(move |cx| {
                let (x0, x1) = span(lx0, lx1, cx);
                let cell = &self.cells[(cy * self.columns + cx) as usize];
                (cell, cell_bits(x0, x1, y0, y1))
            })
        })
    }

    /// The farthest stored depth over the cells that the pixels of `r` touch
    /// (`+∞` while any of their samples is empty).
    #[inline]
    pub fn farthest(&self, r: PixelRect) -> f32 {
        self.depths(r).0
    }

    /// [`Hiz::farthest`] over the pixels of `r`, and the nearest of their
    /// cells' farthest held depths (`+∞` when no sample holds one): nothing at
    /// that depth or nearer is hidden anywhere in `r`.
    #[inline]
    pub fn depths(&self, r: PixelRect) -> (f32, f32) {
        let [lx0, ly0, lx1, ly1] = self.local(r);
        let columns = cells(lx0, lx1);
        let (mut farthest, mut nearest) = (f32::NEG_INFINITY, f32::INFINITY);
        for cy in cells(ly0, ly1) {
            let row = (cy * self.columns) as usize;
            let span = row + columns.start as usize..row + columns.end as usize;
            // No summary is NaN: a plain comparison is `max`/`min`, and
            // compiles to one instruction with no branch.
            for (&whole, &held) in self.whole[span.clone()].iter().zip(&self.held[span]) {
                farthest = if whole > farthest { whole } else { farthest };
                nearest = if held < nearest { held } else { nearest };
            }
        }
        (farthest, nearest)
    }

    /// The cells' version: [`Hiz::depths`] of a rectangle is the same
    /// while it is.
    #[inline]
    pub fn version(&self) -> u64 {
        self.version
    }

    /// Is everything at depth `w` hidden over the pixels of `r`: every stored
    /// sample of them holds a depth, and in each cell they touch all held
    /// depths are nearer than `w`? (The depth test keeps the nearer sample, and
    /// a tie only where `w` equals the stored depth, so nothing at `w` or
    /// farther can be seen there.)
    pub fn hides(&self, r: PixelRect, w: f32) -> bool {
        // Loops, not `touched`'s iterators: a frustum's tests call this for
        // most nodes they do not cull by distance alone.
        let [lx0, ly0, lx1, ly1] = self.local(r);
        for cy in cells(ly0, ly1) {
            let (y0, y1) = span(ly0, ly1, cy);
            for cx in cells(lx0, lx1) {
                let (x0, x1) = span(lx0, lx1, cx);
                let c = &self.cells[(cy * self.columns + cx) as usize];
                let bits = cell_bits(x0, x1, y0, y1);
                let hidden = c.covered & bits == bits && w > c.far;
                if !hidden {
                    return false;
                }
            }
        }
        true
    }

    /// Brings the cells that the pixels of `r` touch up to date after writes
    /// inside `r` (`depth`: the tile's stored depths, layer-major, `pixels`
    /// per layer). Stored depths only decrease, so only `r`'s pixels are read:
    /// their mask bits are recomputed, and the farthest held depth rises to
    /// theirs — an upper bound, which is all [`Hiz::hides`] needs. Once a
    /// cell is covered whole its farthest depth is kept exact (what
    /// [`Hiz::farthest`] reports): the whole cell is read again when it has
    /// just become covered, or when `r`'s depths fell below it (the farthest
    /// may have been one of them).
    pub fn update(&mut self, r: PixelRect, depth: &[f32], pixels: usize) {
        update_cells(self, r, depth, pixels);
    }
}

simd::dispatch! {
    /// [`Hiz::update`] on the lanes of this CPU: a row of a cell is one
    /// load of eight lanes.
    fn update_cells<>(hiz: &mut Hiz, r: PixelRect, depth: &[f32], pixels: usize) -> ()
        => update_cells_on
}

/// [`update_cells`] on lanes `L`.
#[inline(always)]
fn update_cells_on<L: Lanes>(hiz: &mut Hiz, r: PixelRect, depth: &[f32], pixels: usize) {
    hiz.version += 1;
    let [lx0, ly0, lx1, ly1] = hiz.local(r);
    for cy in cells(ly0, ly1) {
        for cx in cells(lx0, lx1) {
            let (bx, by) = (cx * HIZ_CELL, cy * HIZ_CELL);
            let (x0, x1) = span(lx0, lx1, cx);
            let (y0, y1) = span(ly0, ly1, cy);
            let i = (cy * hiz.columns + cx) as usize;
            let old = hiz.cells[i];
            let (held, far) = read::<L>(hiz.rect, depth, pixels, (bx, by), (x0, x1), (y0, y1));
            let bits = cell_bits(x0, x1, y0, y1);
            let covered = old.covered & !bits | held;
            let far = if covered != u64::MAX {
                old.far.max(far)
            } else if old.covered == u64::MAX && far >= old.far {
                // The other pixels are unchanged and no farther than before.
                far
            } else {
                let whole = (0, HIZ_CELL);
                read::<L>(hiz.rect, depth, pixels, (bx, by), whole, whole).1
            };
            hiz.cells[i] = Cell { far, covered };
            hiz.whole[i] = if covered == u64::MAX {
                far
            } else {
                f32::INFINITY
            };
            hiz.held[i] = if far > f32::NEG_INFINITY {
                far
            } else {
                f32::INFINITY
            };
        }
    }
}

/// Over the pixel columns `x0..x1` and rows `y0..y1` of the cell at
/// tile-local `(bx, by)` of the tile over `rect` (clipped to it): the mask
/// bits of the pixels whose every sample holds a depth, and the farthest
/// depth held — over whole rows of the cell where it lies inside the tile
/// (one load of eight lanes): the other pixels of those rows are unchanged
/// since the last update, so no farther than the cell's farthest depth
/// (which [`Hiz::update`] compares with).
#[inline(always)]
fn read<L: Lanes>(
    rect: PixelRect,
    depth: &[f32],
    pixels: usize,
    (bx, by): (u32, u32),
    (x0, x1): (u32, u32),
    (y0, y1): (u32, u32),
) -> (u64, f32) {
    let width = rect.width();
    let columns = HIZ_CELL.min(width - bx);
    let (x1, y1) = (x1.min(columns), y1.min(rect.height() - by));
    let lanes = (0xff >> (8 - (x1 - x0))) << x0;
    let empty = L::splat(f32::NEG_INFINITY);
    let mut far = empty;
    let mut held = 0u64;
    let layers = depth.len() / pixels;
    for row in y0..y1 {
        let start = ((by + row) * width + bx) as usize;
        let mut row_held = lanes;
        for layer in 0..layers {
            let start = layer * pixels + start;
            // A whole row of the cell is one load with one bounds check.
            let whole = (columns == HIZ_CELL)
                .then(|| depth.get(start..)?.first_chunk::<8>())
                .flatten();
            let v = match whole {
                Some(&row) => L::from_array(row),
                None => L::from_array(std::array::from_fn(|k| {
                    if (k as u32) < columns {
                        depth[start + k]
                    } else {
                        f32::NEG_INFINITY
                    }
                })),
            };
            let finite = simd::finite(v);
            row_held &= finite;
            far = far.max(L::select(finite, v, empty));
        }
        held |= u64::from(row_held) << (8 * row);
    }
    let far = far.to_array().into_iter().fold(f32::NEG_INFINITY, f32::max);
    (held, far)
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

    /// What a frustum keeps of [`Hiz::depths`] is kept under a version:
    /// every update and reset changes it (here each update also changes the
    /// depths, so a frustum holding the old ones must read them again).
    #[test]
    fn the_version_changes_with_the_cells() {
        let rect = PixelRect::new(0, 0, 16, 16);
        let mut hiz = Hiz::new(rect);
        let mut seen = vec![hiz.version()];
        let mut depth = vec![f32::INFINITY; 256];
        for (k, r) in [PixelRect::new(0, 0, 8, 8), PixelRect::new(4, 4, 16, 16)]
            .into_iter()
            .enumerate()
        {
            let (read, version) = (hiz.depths(rect), hiz.version());
            for y in r.y0..r.y1 {
                for x in r.x0..r.x1 {
                    depth[(y * 16 + x) as usize] = 1.0 + k as f32;
                }
            }
            hiz.update(r, &depth, 256);
            assert_ne!(hiz.version(), version);
            assert_ne!(hiz.depths(rect), read, "the update changed the depths");
            seen.push(hiz.version());
        }
        hiz.reset(rect);
        seen.push(hiz.version());
        seen.dedup();
        assert_eq!(seen.len(), 4, "{seen:?}");
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

    /// Random writes (depths only decrease, as the depth test keeps them),
    /// each followed by an update of its rectangle: `farthest` is always the
    /// exact farthest depth over the touched cells (`+∞` with an empty
    /// sample), and `hides` never hides a sample at or beyond `w`.
    #[test]
    fn updates_keep_farthest_exact_and_hides_sound() {
        let mut rng = fastrand::Rng::with_seed(3);
        let (mut hidden, mut checked) = (0, 0);
        for case in 0..60 {
            let rect = PixelRect::new(8, 16, 8 + rng.u32(1..40), 16 + rng.u32(1..30));
            let (w, h) = (rect.width(), rect.height());
            let layers = 1 + case % 3;
            let pixels = (w * h) as usize;
            let mut depth = vec![f32::INFINITY; pixels * layers];
            let mut hiz = Hiz::new(rect);
            let random_rect = |rng: &mut fastrand::Rng| {
                let (x0, y0) = (rng.u32(0..w), rng.u32(0..h));
                let (x1, y1) = (rng.u32(x0 + 1..=w), rng.u32(y0 + 1..=h));
                PixelRect::new(rect.x0 + x0, rect.y0 + y0, rect.x0 + x1, rect.y0 + y1)
            };
            for _ in 0..200 {
                let r = random_rect(&mut rng);
                for y in r.y0..r.y1 {
                    for x in r.x0..r.x1 {
                        for layer in 0..layers {
                            let i = layer * pixels + ((y - rect.y0) * w + x - rect.x0) as usize;
                            if rng.u32(0..3) > 0 {
                                depth[i] = depth[i].min(rng.f32() * 10.0);
                            }
                        }
                    }
                }
                hiz.update(r, &depth, pixels);
                let q = random_rect(&mut rng);
                // Brute force over the cells `q` touches.
                let cell = |v: u32, o: u32| (v - o) / HIZ_CELL;
                let mut farthest = f32::NEG_INFINITY;
                for y in rect.y0..rect.y1 {
                    for x in rect.x0..rect.x1 {
                        let (cx, cy) = (cell(x, rect.x0), cell(y, rect.y0));
                        let cols = cell(q.x0, rect.x0)..=cell(q.x1 - 1, rect.x0);
                        let rows = cell(q.y0, rect.y0)..=cell(q.y1 - 1, rect.y0);
                        if cols.contains(&cx) && rows.contains(&cy) {
                            for layer in 0..layers {
                                let i = layer * pixels + ((y - rect.y0) * w + x - rect.x0) as usize;
                                farthest = farthest.max(depth[i]);
                            }
                        }
                    }
                }
                assert_eq!(hiz.farthest(q), farthest, "case {case}: {q:?} in {rect:?}");
                // The nearest held farthest depth, from the cells themselves.
                let nearest = (hiz.touched(q).map(|(c, _)| c.far))
                    .filter(|&far| far > f32::NEG_INFINITY)
                    .fold(f32::INFINITY, f32::min);
                assert_eq!(hiz.depths(q).1, nearest, "case {case}: {q:?} in {rect:?}");
                let at = rng.f32() * 11.0;
                if hiz.hides(q, at) {
                    hidden += 1;
                    for y in q.y0..q.y1 {
                        for x in q.x0..q.x1 {
                            for layer in 0..layers {
                                let i = layer * pixels + ((y - rect.y0) * w + x - rect.x0) as usize;
                                assert!(depth[i] < at, "case {case}: ({x}, {y}) hidden at {at}");
                            }
                        }
                    }
                }
                checked += 1;
            }
        }
        assert_eq!(checked, 60 * 200);
        assert!(hidden > 1000, "{hidden} hidden");
    }

    /// The dispatched update (AVX2 where the CPU has it) leaves every cell
    /// as the portable lanes do, bit for bit: random writes and updates over
    /// tiles of one to three layers, with edge cells narrower than eight
    /// pixels and whole cells read again.
    #[test]
    fn both_lane_sets_update_the_cells_alike() {
        #[cfg(target_arch = "x86_64")]
        assert!(
            simd::cpu_has_avx2(),
            "this test checks the AVX2 kernel, and this CPU has no AVX2"
        );
        let mut rng = fastrand::Rng::with_seed(11);
        let (mut compared, mut narrow) = (0, 0);
        for case in 0..40 {
            let rect = PixelRect::new(0, 8, rng.u32(1..45), 8 + rng.u32(1..30));
            let (w, h) = (rect.width(), rect.height());
            narrow += usize::from(w % HIZ_CELL != 0);
            let layers = 1 + case % 3;
            let pixels = (w * h) as usize;
            let mut depth = vec![f32::INFINITY; pixels * layers];
            let (mut dispatched, mut portable) = (Hiz::new(rect), Hiz::new(rect));
            for _ in 0..150 {
                let (x0, y0) = (rng.u32(0..w), rng.u32(0..h));
                let (x1, y1) = (rng.u32(x0 + 1..=w), rng.u32(y0 + 1..=h));
                let r = PixelRect::new(x0, rect.y0 + y0, x1, rect.y0 + y1);
                for y in y0..y1 {
                    for x in x0..x1 {
                        for layer in 0..layers {
                            let i = layer * pixels + (y * w + x) as usize;
                            if rng.u32(0..3) > 0 {
                                depth[i] = depth[i].min(rng.f32() * 10.0);
                            }
                        }
                    }
                }
                dispatched.update(r, &depth, pixels);
                update_cells_on::<simd::Portable>(&mut portable, r, &depth, pixels);
                let bits = |hiz: &Hiz| -> Vec<(u32, u64)> {
                    hiz.cells
                        .iter()
                        .map(|c| (c.far.to_bits(), c.covered))
                        .collect()
                };
                assert_eq!(bits(&dispatched), bits(&portable), "case {case}: {r:?}");
                assert_eq!(dispatched.version(), portable.version());
                compared += 1;
            }
        }
        assert_eq!(compared, 40 * 150);
        assert!(narrow > 20, "{narrow} tiles with a narrow edge cell");
    }
}
