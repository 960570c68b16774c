//! The per-tile coverage kernel every rasterizing algorithm shares: one set-up
//! triangle against the samples of a rectangle of one tile, either every sample
//! of its bounding box (brute force) or hierarchically (binning, paper §3.1 and
//! §5 "2DR/3DR binning"): edge functions at a block's corner samples reject it,
//! accept it whole, or split it in four, down to a leaf size where samples are
//! tested one by one. With early-z a block is skipped when the triangle's nearest
//! possible depth lies behind everything the hierarchical w-buffer holds there.
//!
//! **Small triangles** (a box of at most [`SMALL`] samples, every position
//! stored) skip the hierarchy and are tested on those samples directly, in one
//! group of lanes across rows, as llvmpipe's and Nanite's small-triangle paths
//! do: the same sample points through the same [`Coverage`] decision, so the
//! same image bit for bit; the counters record the tests actually made. A tile
//! loop whose coverage type tests across triangles may instead queue those
//! samples and test eight of them at a time, each against its own triangle
//! ([`SmallQueue`]).

use crate::edge::{BlockTest, Coverage, RowLanes};
use crate::framebuffer::{SCRATCH_PIXELS, TileBuffer};
use crate::ground::PixelRect;
use crate::pipeline::SampleOracles;
use crate::simd::{self, Lanes, count_eight, first_lanes};
use crate::stats::RasterCounters;
use crate::trace::BlockOutcome;

/// Rasterizes `tri` (id `id`, screen box `rect`) into `tile`, limited to
/// `clip` (pixels inside the tile).
pub(crate) fn raster_triangle<T: Coverage>(
    tile: &mut TileBuffer,
    tri: &T,
    id: u32,
    clip: PixelRect,
    oracles: SampleOracles,
    counters: &mut RasterCounters,
) {
    if !oracles.binning || is_small(tile, clip) {
        sample_block(tile, tri, id, clip, oracles, counters);
        return;
    }
    // Start from the smallest block of the tile's power-of-two hierarchy that
    // holds the triangle's box ("binning starting from the bounding box").
    let (lx0, ly0) = (clip.x0 - tile.x0, clip.y0 - tile.y0);
    let (lx1, ly1) = (clip.x1 - 1 - tile.x0, clip.y1 - 1 - tile.y0);
    let mut side = oracles.leaf.max(1);
    while lx0 / side != lx1 / side || ly0 / side != ly1 / side {
        side *= 2;
    }
    let (bx, by) = (tile.x0 + lx0 / side * side, tile.y0 + ly0 / side * side);
    bin_block(tile, tri, id, clip, bx, by, side, oracles, counters);
}

/// Samples a box may hold to take the small-triangle path: one group of lanes.
const SMALL: usize = 8;

/// Does `r` take the small-triangle path: at most [`SMALL`] samples, every
/// coverage position stored (CSAA's coverage-only positions take the general
/// path, which gathers their masks per pixel)?
#[inline]
fn is_small(tile: &TileBuffer, r: PixelRect) -> bool {
    let pattern = tile.pattern;
    !pattern.has_coverage_only()
        && (r.width() as usize * r.height() as usize) * pattern.coverage() <= SMALL
}

/// The samples of `r` one by one (the leaf of every strategy), after early-z and
/// keeping the hierarchical w-buffer current when early-z reads it. Returns the
/// number of samples the triangle covers (before the depth test); early-z
/// rejects count none.
fn sample_block<T: Coverage>(
    tile: &mut TileBuffer,
    tri: &T,
    id: u32,
    r: PixelRect,
    oracles: SampleOracles,
    counters: &mut RasterCounters,
) -> u32 {
    if oracles.early_z && early_z_rejects(tile, tri, r, counters) {
        return 0;
    }
    let covered = test_samples(tile, tri, id, r);
    if oracles.early_z {
        tile.update_hiz(r);
    }
    covered
}

/// Early-z: is the triangle's nearest depth behind everything stored under `r`?
/// Strictly behind: an equal depth may still win by the smaller id.
#[inline]
fn early_z_rejects<T: Coverage>(
    tile: &TileBuffer,
    tri: &T,
    r: PixelRect,
    counters: &mut RasterCounters,
) -> bool {
    if tri.min_depth() > tile.hiz_max(r) {
        counters.early_z_rejects += 1;
        return true;
    }
    false
}

simd::dispatch! {
    /// Tests every sample of `r` (per-sample coverage, the leaf of every strategy);
    /// returns how many coverage samples the triangle covers.
    pub(crate) fn test_samples<T: Coverage>(tile: &mut TileBuffer, tri: &T, id: u32, r: PixelRect) -> u32
        => test_samples_on
}

/// [`test_samples`] on lanes `L`.
#[inline(always)]
fn test_samples_on<L: Lanes, T: Coverage>(
    tile: &mut TileBuffer,
    tri: &T,
    id: u32,
    r: PixelRect,
) -> u32 {
    if r.height() > 1 && is_small(tile, r) {
        return sample_small::<L, T>(tile, tri, id, r);
    }
    sample_rows::<L, T>(tile, tri, id, r)
}

/// [`test_samples`] row by row: the general path.
#[inline(always)]
fn sample_rows<L: Lanes, T: Coverage>(
    tile: &mut TileBuffer,
    tri: &T,
    id: u32,
    r: PixelRect,
) -> u32 {
    if tile.pattern.coverage() > 1 {
        return sample_pattern::<L, T>(tile, tri, id, r, Samples::Test);
    }
    // One sample per pixel: runs along rows (which curved edges may evaluate
    // incrementally, §3.5 eq. 3).
    let mut covered = 0;
    let n = r.width();
    let x0 = r.x0 as f32 + 0.5;
    // Runs shorter than a group (small triangles) are written sample by
    // sample: cheaper there than a group's loads and blends.
    if T::OWN_SAMPLE_RUN || n < 8 {
        for y in r.y0..r.y1 {
            let i = tile.index(r.x0, y);
            count_tests(tile, i, n);
            tri.sample_run::<L>(x0, y as f32 + 0.5, n, |k, w| {
                covered += 1;
                tile.write(i + k as usize, w, id);
            });
        }
        return covered;
    }
    along_rows::<L, T>(tile, tri, id, r, Samples::Test)
}

/// One sample per pixel: the samples of `r` (rows of at least a group)
/// eight at a time along its rows through the triangle's row form
/// ([`Coverage::rows`]: its lanes set out once), written (depth-tested)
/// eight at a time. The points `x0 + k` are integers and a half, exact in
/// f32, so stepping the lanes by eight forms each group's points as
/// `sample8` would. Returns the number of samples covered.
#[inline(always)]
fn along_rows<L: Lanes, T: Coverage>(
    tile: &mut TileBuffer,
    tri: &T,
    id: u32,
    r: PixelRect,
    how: Samples,
) -> u32 {
    debug_assert_eq!(tile.pattern.coverage(), 1);
    let mut covered = 0;
    let n = r.width();
    debug_assert!(n >= 8, "rows shorter than a group take sample_run");
    let x0 = r.x0 as f32 + 0.5;
    let mut rows = tri.rows::<L>();
    let first = L::from_array([0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]) + L::splat(x0);
    for y in r.y0..r.y1 {
        let i = tile.index(r.x0, y);
        rows.set_row(y as f32 + 0.5);
        let mut x = first;
        for k in (0..n).step_by(8) {
            let active = first_lanes((n - k) as usize);
            count_eight(&mut tile.edge_evals, i + k as usize, active);
            let (mask, w) = match how {
                Samples::Test => rows.sample8(x0 + k as f32, x, active),
                Samples::Inside => {
                    let (mask, w) = rows.depth_inside8(x);
                    (mask & active, w)
                }
            };
            x = x + L::splat(8.0);
            if mask != 0 {
                covered += mask.count_ones();
                tile.write_eight::<L>(i + k as usize, mask, &w, id);
            }
        }
    }
    covered
}

/// Counts a test at each of the `n` pixels from index `i`, eight at a time.
#[inline(always)]
fn count_tests(tile: &mut TileBuffer, i: usize, n: u32) {
    for k in (0..n).step_by(8) {
        count_eight(
            &mut tile.edge_evals,
            i + k as usize,
            first_lanes((n - k) as usize),
        );
    }
}

/// The small-triangle path: every sample of `r` (at most [`SMALL`], every
/// position stored; see [`is_small`]) in one group of lanes, pixel by pixel
/// in row order and position by position within a pixel. Each lane's point is
/// the one the general paths form for that sample (`x + offset` on integer
/// pixel coordinates, exact in f32), so each decision is theirs. Returns how
/// many samples the triangle covers.
#[inline(always)]
fn sample_small<L: Lanes, T: Coverage>(
    tile: &mut TileBuffer,
    tri: &T,
    id: u32,
    r: PixelRect,
) -> u32 {
    let pattern = tile.pattern;
    let count = pattern.positions.len() as u32;
    let (mut xs, mut ys, mut at) = ([0.0; 8], [0.0; 8], [0usize; 8]);
    let mut n = 0;
    for y in r.y0..r.y1 {
        let i = tile.index(r.x0, y);
        for (k, x) in (r.x0..r.x1).enumerate() {
            tile.edge_evals[i + k] += count;
            for (c, [ox, oy]) in pattern.positions.iter().enumerate() {
                (xs[n], ys[n], at[n]) = (x as f32 + ox, y as f32 + oy, c * tile.pixels + i + k);
                n += 1;
            }
        }
    }
    // Spare lanes repeat the last sample; their bits are dropped.
    for l in n..8 {
        (xs[l], ys[l], at[l]) = (xs[n - 1], ys[n - 1], at[n - 1]);
    }
    let (mask, w) = tri.sample_points8::<L>(xs, ys, first_lanes(n));
    let mut covered = mask;
    while covered != 0 {
        let l = covered.trailing_zeros() as usize;
        covered &= covered - 1;
        tile.write(at[l], w[l], id);
    }
    mask.count_ones()
}

/// Samples of small triangles waiting to be tested eight at a time, each
/// lane against its own triangle ([`Coverage::sample_across`]): the
/// small-triangle path of a tile that renders many triangles of a few
/// samples each (a mesh of sub-pixel triangles averages under three), where
/// [`sample_small`] would fill a group of lanes with one triangle's few
/// samples. Each triangle's box is small ([`SmallQueue::takes`]: at most
/// eight samples, every position stored); its samples are queued in the
/// order [`sample_small`] forms them, at the same points, their tests
/// counted as it counts them.
/// Writes then come later than in input order, which changes no buffer: the
/// depth test keeps the nearest sample and, at equal depth, the smaller id,
/// whatever the order — so the queue is only for opaque triangles
/// ([`SmallQueue::applies`]).
#[derive(Debug)]
pub(crate) struct SmallQueue<B> {
    /// Each lane's triangle (spare lanes: an earlier one, not tested).
    tris: [B; 8],
    x: [f32; 8],
    y: [f32; 8],
    /// Each lane's stored sample and triangle id.
    at: [u32; 8],
    ids: [u32; 8],
    n: usize,
}

impl<B: Coverage + Copy> SmallQueue<B> {
    /// Whether the queue may take `tile`'s small triangles: every triangle
    /// opaque, and no trace recorded.
    pub(crate) fn applies(tile: &TileBuffer) -> bool {
        tile.opacity.is_empty() && tile.trace.is_none()
    }

    /// Does the box `r` in `tile` take the small-triangle path?
    #[inline(always)]
    pub(crate) fn takes(tile: &TileBuffer, r: PixelRect) -> bool {
        is_small(tile, r)
    }

    /// An empty queue (`tri` fills its lanes until samples do).
    pub(crate) fn new(tri: B) -> SmallQueue<B> {
        SmallQueue {
            tris: [tri; 8],
            x: [0.0; 8],
            y: [0.0; 8],
            at: [0; 8],
            ids: [0; 8],
            n: 0,
        }
    }

    /// Queues the samples of `r` (a box [`SmallQueue::takes`]) of `tri`,
    /// triangle `id`, and counts their tests; tests them whenever eight are
    /// queued.
    #[inline(always)]
    pub(crate) fn push(&mut self, tile: &mut TileBuffer, tri: B, id: u32, r: PixelRect) {
        let pattern = tile.pattern;
        if let [offset] = pattern.positions[..] {
            return self.push_pixels(tile, tri, id, r, offset);
        }
        let count = pattern.positions.len() as u32;
        // The queue's length in a local, below eight where lanes are written.
        let mut n = self.n;
        for y in r.y0..r.y1 {
            let i = tile.index(r.x0, y);
            for (k, x) in (r.x0..r.x1).enumerate() {
                tile.edge_evals[i + k] += count;
                for (c, [ox, oy]) in pattern.positions.iter().enumerate() {
                    if n >= 8 {
                        self.n = n;
                        self.flush(tile);
                        n = 0;
                    }
                    (self.x[n], self.y[n]) = (x as f32 + ox, y as f32 + oy);
                    self.at[n] = (c * tile.pixels + i + k) as u32;
                    (self.tris[n], self.ids[n]) = (tri, id);
                    n += 1;
                }
            }
        }
        self.n = n;
    }

    /// [`SmallQueue::push`] with one sample a pixel, at `offset` in it: the
    /// box's pixels in row order by one loop, its column and row stepped
    /// without a branch. (Loops over its rows and then its columns — a
    /// sub-pixel triangle's box is one, two, three or four pixels in a row
    /// or a square, as no predictor foresees — mispredicted their exits
    /// about three times a triangle.)
    #[inline(always)]
    fn push_pixels(
        &mut self,
        tile: &mut TileBuffer,
        tri: B,
        id: u32,
        r: PixelRect,
        offset: [f32; 2],
    ) {
        let [ox, oy] = offset;
        let (width, stride) = (r.width(), tile.x1 - tile.x0);
        let start = tile.index(r.x0, r.y0);
        let (mut column, mut row) = (0, 0);
        let mut n = self.n;
        for _ in 0..width * r.height() {
            if n >= 8 {
                self.n = n;
                self.flush(tile);
                n = 0;
            }
            let at = start + (row * stride + column) as usize;
            tile.edge_evals[at] += 1;
            (self.x[n], self.y[n]) = ((r.x0 + column) as f32 + ox, (r.y0 + row) as f32 + oy);
            self.at[n] = at as u32;
            (self.tris[n], self.ids[n]) = (tri, id);
            n += 1;
            column += 1;
            let wrap = column == width;
            row += u32::from(wrap);
            column *= u32::from(!wrap);
        }
        self.n = n;
    }

    /// Tests the queued samples (if any) and writes the covered ones.
    #[inline(always)]
    pub(crate) fn flush(&mut self, tile: &mut TileBuffer) {
        if self.n > 0 {
            test_across(tile, self);
            self.n = 0;
        }
    }
}

simd::dispatch! {
    /// The queued samples of `queue`, lane `l` against its triangle,
    /// written where covered.
    fn test_across<B: Coverage>(tile: &mut TileBuffer, queue: &SmallQueue<B>) -> ()
        => test_across_on
}

#[inline(always)]
fn test_across_on<L: Lanes, B: Coverage>(tile: &mut TileBuffer, q: &SmallQueue<B>) {
    let (mask, w) = B::sample_across::<L>(q.tris.each_ref(), q.x, q.y, first_lanes(q.n));
    let mut covered = mask;
    while covered != 0 {
        let l = covered.trailing_zeros() as usize;
        covered &= covered - 1;
        tile.write(q.at[l] as usize, w[l], q.ids[l]);
    }
}

/// The narrowest block found inside that [`fill_samples`] walks through the
/// row form. With every block through it, bunny's `3dr-bin` and `3dr-full`
/// were 4–5% slower; from 16 pixels on, sponza's and bunny's `3dr-full`
/// gained 3–7% and no cell lost beyond the noise (two alternated A/Bs at
/// 1080p).
const ROW_FORM_WIDTH: u32 = 16;

simd::dispatch! {
    /// Writes every sample of `r`, known to be inside the edges: only depth is
    /// computed (with its `near` test). Returns the number of samples written.
    pub(crate) fn fill_samples<T: Coverage>(tile: &mut TileBuffer, tri: &T, id: u32, r: PixelRect) -> u32
        => fill_samples_on
}

/// [`fill_samples`] on lanes `L`: with one sample a pixel, a block at least
/// [`ROW_FORM_WIDTH`] pixels wide along its rows through the triangle's row
/// form, where splatting its lanes once pays for itself; narrower blocks,
/// and every anti-aliasing pattern, through [`sample_pattern`].
#[inline(always)]
fn fill_samples_on<L: Lanes, T: Coverage>(
    tile: &mut TileBuffer,
    tri: &T,
    id: u32,
    r: PixelRect,
) -> u32 {
    if tile.pattern.coverage() > 1 || r.width() < ROW_FORM_WIDTH {
        return sample_pattern::<L, T>(tile, tri, id, r, Samples::Inside);
    }
    along_rows::<L, T>(tile, tri, id, r, Samples::Inside)
}

/// What [`sample_pattern`] evaluates per sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Samples {
    /// Edges, tie rule and depth ([`Coverage::sample_points8`]).
    Test,
    /// Depth only, the block being inside ([`Coverage::depth_inside8`]).
    Inside,
}

/// Every coverage position of every pixel of `r`, eight samples at a time:
/// along a row, lane `l` of group `g` is position `c` of pixel `k` with
/// `k·C + c = 8g + l`, so small patterns share a group between pixels. Covered
/// stored samples go through the depth test; under CSAA a stored sample that
/// wins keeps the triangle's mask over all positions of its pixel (coverage-only
/// positions are decided by [`Coverage::covers8`], without depth).
#[inline(always)]
fn sample_pattern<L: Lanes, T: Coverage>(
    tile: &mut TileBuffer,
    tri: &T,
    id: u32,
    r: PixelRect,
    how: Samples,
) -> u32 {
    // Rows in chunks of at most CHUNK pixels (the CSAA scratch's size).
    const CHUNK: u32 = SCRATCH_PIXELS as u32;
    let pattern = tile.pattern;
    let (positions, stored, pixels) = (&pattern.positions, pattern.stored, tile.pixels);
    let count = positions.len();
    let shift = count.trailing_zeros();
    let masked = pattern.has_coverage_only();
    // CSAA scratch per chunk: each pixel's mask, and the depths at its stored
    // positions (row `s` of `depths` for stored position `s`).
    let mut masks = std::mem::take(&mut tile.scratch_masks);
    let mut depths = std::mem::take(&mut tile.scratch_depths);
    let mut covered = 0;
    for y in r.y0..r.y1 {
        for x0 in (r.x0..r.x1).step_by(CHUNK as usize) {
            let n = (r.x1 - x0).min(CHUNK) as usize;
            let i = tile.index(x0, y);
            for evals in &mut tile.edge_evals[i..i + n] {
                *evals += count as u32;
            }
            if masked {
                masks[..n].fill(0);
            }
            let total = n << shift;
            for q in (0..total).step_by(8) {
                let lanes = (total - q).min(8);
                let (mut xs, mut ys) = ([0.0; 8], [0.0; 8]);
                for l in 0..8 {
                    // Spare lanes repeat the last sample; their bits are dropped.
                    let p = q + l.min(lanes - 1);
                    let [ox, oy] = positions[p & (count - 1)];
                    xs[l] = (x0 + (p >> shift) as u32) as f32 + ox;
                    ys[l] = y as f32 + oy;
                }
                // Lanes at coverage-only positions (CSAA) need coverage, not depth.
                let mut coverage_only = 0u8;
                if masked {
                    for l in 0..lanes {
                        if (q + l) & (count - 1) >= stored {
                            coverage_only |= 1 << l;
                        }
                    }
                }
                let (mut mask, w) = if coverage_only == 0xff {
                    (0, [0.0; 8])
                } else {
                    match how {
                        Samples::Test => tri.sample_points8::<L>(xs, ys, first_lanes(lanes)),
                        Samples::Inside => tri.depth_inside8::<L>(xs, ys),
                    }
                };
                if coverage_only != 0 {
                    mask = (mask & !coverage_only) | (tri.covers8::<L>(xs, ys) & coverage_only);
                }
                let mut mask = u32::from(mask) & ((1 << lanes) - 1);
                covered += mask.count_ones();
                if count == 1 && !masked && lanes == 8 {
                    // One position per pixel: lane `l` is pixel `q + l` (a
                    // whole group; partial ones, small blocks, one by one).
                    tile.write_eight::<L>(i + q, mask as u8, &w, id);
                    continue;
                }
                while mask != 0 {
                    let l = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    let (k, c) = ((q + l) >> shift, (q + l) & (count - 1));
                    if masked {
                        masks[k] |= 1 << c;
                        if c < stored {
                            depths[c * CHUNK as usize + k] = w[l];
                        }
                    } else {
                        tile.write(c * pixels + i + k, w[l], id);
                    }
                }
            }
            if masked {
                for (any, &mask) in tile.covered_any[i..i + n].iter_mut().zip(&masks[..n]) {
                    *any |= mask;
                }
                for (k, &mask) in masks[..n].iter().enumerate() {
                    let mut at_stored = mask & ((1 << stored) - 1);
                    while at_stored != 0 {
                        let s = at_stored.trailing_zeros() as usize;
                        at_stored &= at_stored - 1;
                        let w = depths[s * CHUNK as usize + k];
                        tile.write_masked(s * pixels + i + k, w, id, mask);
                    }
                }
            }
        }
    }
    tile.scratch_masks = masks;
    tile.scratch_depths = depths;
    covered
}

/// The triangle's block test over every sample of `r`: the corners of the box
/// of its samples (pixel corners plus the pattern's span; paper §3.1:
/// "binning"; curved edges §3.5), each corner pixel charged one evaluation.
#[inline]
fn test_block<T: Coverage>(tile: &mut TileBuffer, tri: &T, r: PixelRect) -> BlockTest {
    let (x1, y1) = (r.x1 - 1, r.y1 - 1);
    for (x, y) in [(r.x0, r.y0), (x1, r.y0), (r.x0, y1), (x1, y1)] {
        let i = tile.index(x, y);
        tile.edge_evals[i] += 1;
    }
    let span = tile.pattern.span;
    tri.classify_block(
        r.x0 as f32 + span.lo[0],
        r.y0 as f32 + span.lo[1],
        x1 as f32 + span.hi[0],
        y1 as f32 + span.hi[1],
    )
}

#[allow(
    clippy::too_many_arguments,
    reason = "one recursion step of the binning hierarchy"
)]
fn bin_block<T: Coverage>(
    tile: &mut TileBuffer,
    tri: &T,
    id: u32,
    clip: PixelRect,
    bx: u32,
    by: u32,
    side: u32,
    oracles: SampleOracles,
    counters: &mut RasterCounters,
) -> u32 {
    // 1. The block's samples inside the triangle's box.
    let block = PixelRect::new(bx, by, bx + side, by + side);
    let Some(r) = block.intersect(clip) else {
        return 0;
    };
    // 2. Leaf: sample by sample.
    if side <= oracles.leaf {
        return sample_block(tile, tri, id, r, oracles, counters);
    }
    // 3. Early-z against the hierarchical w-buffer.
    if oracles.early_z && early_z_rejects(tile, tri, r, counters) {
        return 0;
    }
    // 4. The tile test.
    counters.tiles_tested += 1;
    let test = test_block(tile, tri, r);
    tile.record(|t| {
        let outcome = match test {
            BlockTest::Outside => BlockOutcome::Rejected,
            BlockTest::Inside => BlockOutcome::Accepted,
            BlockTest::Partial => BlockOutcome::Refined,
        };
        t.blocks.push((r, outcome));
    });
    match test {
        BlockTest::Outside => {
            counters.tiles_rejected += 1;
            0
        }
        BlockTest::Inside => {
            counters.tiles_accepted += 1;
            let written = fill_samples(tile, tri, id, r);
            if oracles.early_z {
                tile.update_hiz(r);
            }
            written
        }
        BlockTest::Partial => {
            counters.tiles_refined += 1;
            let half = side / 2;
            let covered: u32 = [(0, 0), (half, 0), (0, half), (half, half)]
                .into_iter()
                .map(|(dx, dy)| {
                    let (x, y) = (bx + dx, by + dy);
                    bin_block(tile, tri, id, clip, x, y, half, oracles, counters)
                })
                .sum();
            if covered == 0 {
                counters.tiles_refined_empty += 1;
            }
            covered
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aa::{AaMode, SamplePattern};
    use crate::edge::{ScreenVertex, Triangle2D};
    use crate::simd::Portable;

    /// A random triangle of about 0.5, 1.5 or 3 pixels (by `id`) inside a
    /// 16×16 tile, with its box under `pattern`; `None` where it has no area
    /// or no samples.
    fn small_triangle(
        rng: &mut fastrand::Rng,
        id: u32,
        pattern: &SamplePattern,
    ) -> Option<(Triangle2D, PixelRect)> {
        let centre = [1.0 + 14.0 * rng.f32(), 1.0 + 14.0 * rng.f32()];
        let size = [0.5, 1.5, 3.0][id as usize % 3];
        let v: [ScreenVertex; 3] = std::array::from_fn(|_| ScreenVertex {
            x: centre[0] + size * (rng.f32() - 0.5),
            y: centre[1] + size * (rng.f32() - 0.5),
            q: 1.0 / (1.0 + rng.f32()),
        });
        let tri = Triangle2D::setup(&v, false, 16, 16)?;
        let [x0, y0, x1, y1] = tri.bounds;
        let r = PixelRect::from_bounds(x0, y0, x1, y1, 16, 16, pattern.span)?;
        Some((tri, r))
    }

    /// The queue of small triangles leaves every buffer as the row path
    /// does: random small triangles of every box shape (one row included),
    /// queued and flushed at the end, against the same triangles sampled
    /// row by row — one sample a pixel (its own loop over a box's pixels)
    /// and four.
    #[test]
    fn queued_small_triangles_match_the_general_path() {
        let mut rng = fastrand::Rng::with_seed(9);
        let mut queued = Vec::new();
        for aa in ["none", "msaa:4"] {
            let pattern = SamplePattern::of(AaMode::parse(aa).unwrap());
            let rect = PixelRect::new(0, 0, 16, 16);
            let (mut queue_tile, mut rows) = (
                TileBuffer::new(rect, &pattern, &[]),
                TileBuffer::new(rect, &pattern, &[]),
            );
            let mut small = Vec::new();
            for id in 0..3000u32 {
                let Some((tri, r)) = small_triangle(&mut rng, id, &pattern) else {
                    continue;
                };
                if SmallQueue::<&Triangle2D>::takes(&rows, r) {
                    small.push((tri, id, r));
                }
            }
            let mut queue = SmallQueue::new(&small[0].0);
            for (tri, id, r) in &small {
                queue.push(&mut queue_tile, tri, *id, *r);
                sample_rows::<Portable, _>(&mut rows, tri, *id, *r);
            }
            queue.flush(&mut queue_tile);
            let bits = |v: &[f32]| v.iter().map(|d| d.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&queue_tile.depth), bits(&rows.depth), "{aa}: depth");
            assert_eq!(queue_tile.triangle_id, rows.triangle_id, "{aa}: ids");
            assert_eq!(
                queue_tile.coverage_writes, rows.coverage_writes,
                "{aa}: writes"
            );
            assert_eq!(
                queue_tile.edge_evals, rows.edge_evals,
                "{aa}: edge evaluations"
            );
            let shapes: std::collections::HashSet<_> = small
                .iter()
                .map(|(_, _, r)| (r.width(), r.height()))
                .collect();
            queued.push((small.len(), shapes.len()));
        }
        // One sample a pixel: boxes of one to eight pixels in many shapes;
        // four: one pixel, or two in a row or a column.
        let [(none, none_shapes), (msaa4, msaa4_shapes)] = queued[..] else {
            unreachable!()
        };
        assert!(
            none > 1000 && none_shapes >= 8,
            "queued (triangles, shapes): {queued:?}"
        );
        assert!(
            msaa4 > 300 && msaa4_shapes == 3,
            "queued (triangles, shapes): {queued:?}"
        );
    }

    /// The small-triangle path decides and writes every sample as the
    /// general row path does: random small triangles, with their neighbours
    /// sharing the tile (so depth ties and overwrites happen), rasterized
    /// both ways into one tile each give the same depths, ids, write counts
    /// and edge-evaluation counts, bit for bit, under every pattern it serves.
    #[test]
    fn small_triangles_match_the_general_path() {
        let mut rng = fastrand::Rng::with_seed(5);
        let (mut small, mut covered) = (Vec::new(), 0);
        for aa in ["none", "msaa:2", "msaa:4", "ssaa:4", "msaa:8"] {
            let pattern = SamplePattern::of(AaMode::parse(aa).unwrap());
            let rect = PixelRect::new(0, 0, 16, 16);
            let mut fast = TileBuffer::new(rect, &pattern, &[]);
            let mut rows = TileBuffer::new(rect, &pattern, &[]);
            small.push(0);
            for id in 0..3000 {
                let Some((tri, r)) = small_triangle(&mut rng, id, &pattern) else {
                    continue;
                };
                if !(r.height() > 1 && is_small(&fast, r)) {
                    continue;
                }
                *small.last_mut().unwrap() += 1;
                let a = sample_small::<Portable, _>(&mut fast, &tri, id, r);
                let b = sample_rows::<Portable, _>(&mut rows, &tri, id, r);
                assert_eq!(a, b, "{aa}: triangle {id} covers");
                covered += a;
            }
            let bits = |v: &[f32]| v.iter().map(|d| d.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&fast.depth), bits(&rows.depth), "{aa}: depth");
            assert_eq!(fast.triangle_id, rows.triangle_id, "{aa}: ids");
            assert_eq!(fast.coverage_writes, rows.coverage_writes, "{aa}: writes");
            assert_eq!(fast.edge_evals, rows.edge_evals, "{aa}: edge evaluations");
        }
        // Boxes of at most eight samples over more than one row: up to 2×4
        // pixels under one sample a pixel, 1×2 boxes under four, none under
        // eight (which must not take the path).
        let [none, msaa2, msaa4, ssaa4, msaa8] = small[..] else {
            unreachable!()
        };
        assert!(
            none > 300 && msaa2 > 300,
            "small triangles per pattern: {small:?}"
        );
        assert!(
            msaa4 > 100 && ssaa4 > 100 && msaa8 == 0,
            "small triangles per pattern: {small:?}"
        );
        assert!(covered > 1000, "{covered} samples covered");
    }
}
