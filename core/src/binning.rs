//! The per-tile coverage kernel every rasterizing algorithm shares: one set-up
//! triangle against the samples of a rectangle of one tile, either every sample
//! of its bounding box (brute force) or hierarchically (binning, paper §3.1 and
//! §5 "2DR/3DR binning"): edge functions at a block's corner samples reject it,
//! accept it whole, or split it in four, down to a leaf size where samples are
//! tested one by one. With early-z a block is skipped when the triangle's nearest
//! possible depth lies behind everything the hierarchical w-buffer holds there.

use crate::algorithm::PixelRect;
use crate::camera::pixel_center;
use crate::edge::Coverage;
use crate::framebuffer::TileBuffer;
use crate::stats::RasterCounters;

/// How samples are enumerated inside a triangle's box.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SampleOracles {
    /// Hierarchical tile tests instead of testing every sample of the box.
    pub binning: bool,
    /// Blocks of this many pixels square (a power of two) are tested sample by sample.
    pub leaf: u32,
    /// Skip blocks that the hierarchical w-buffer shows are hidden.
    pub early_z: bool,
}

impl SampleOracles {
    pub const BRUTE: SampleOracles = SampleOracles {
        binning: false,
        leaf: 8,
        early_z: false,
    };
    pub const BINNED: SampleOracles = SampleOracles {
        binning: true,
        leaf: 8,
        early_z: true,
    };
}

/// Rasterizes `tri` (id `id`, screen box `rect`) into `tile`, limited to
/// `clip` (inclusive pixel bounds inside the tile).
pub(crate) fn raster_triangle<T: Coverage>(
    tile: &mut TileBuffer,
    tri: &T,
    id: u32,
    clip: PixelRect,
    oracles: SampleOracles,
    counters: &mut RasterCounters,
) {
    if !oracles.binning {
        return sample_block(tile, tri, id, clip, oracles, counters);
    }
    // Start from the smallest block of the tile's power-of-two hierarchy that
    // holds the triangle's box ("binning starting from the bounding box").
    let (lx0, ly0) = (clip.x0 - tile.x0, clip.y0 - tile.y0);
    let (lx1, ly1) = (clip.x1 - tile.x0, clip.y1 - tile.y0);
    let mut side = oracles.leaf.max(1);
    while lx0 / side != lx1 / side || ly0 / side != ly1 / side {
        side *= 2;
    }
    let (bx, by) = (tile.x0 + lx0 / side * side, tile.y0 + ly0 / side * side);
    bin_block(
        tile,
        tri,
        id,
        clip,
        bx,
        by,
        side,
        tri.edge_error(),
        oracles,
        counters,
    );
}

/// The samples of `r` one by one (the leaf of every strategy), after early-z and
/// keeping the hierarchical w-buffer current when early-z reads it.
fn sample_block<T: Coverage>(
    tile: &mut TileBuffer,
    tri: &T,
    id: u32,
    r: PixelRect,
    oracles: SampleOracles,
    counters: &mut RasterCounters,
) {
    if oracles.early_z && early_z_rejects(tile, tri, r, counters) {
        return;
    }
    test_samples(tile, tri, id, r);
    if oracles.early_z {
        tile.update_hiz(r.x0, r.y0, r.x1, r.y1);
    }
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
    if tri.min_depth() > tile.hiz_max(r.x0, r.y0, r.x1, r.y1) {
        counters.early_z_rejects += 1;
        return true;
    }
    false
}

/// Tests every sample of `r` (per-sample coverage, the leaf of every strategy).
#[inline]
fn test_samples<T: Coverage>(tile: &mut TileBuffer, tri: &T, id: u32, r: PixelRect) {
    for y in r.y0..=r.y1 {
        let yc = pixel_center(y);
        let mut x = r.x0;
        // Eight samples at a time, then the rest one by one.
        while x + 7 <= r.x1 {
            let (mask, depth) = tri.sample8(pixel_center(x), yc);
            let i = tile.index(x, y);
            for count in &mut tile.edge_evals[i..i + 8] {
                *count += 1;
            }
            let mut covered = mask;
            while covered != 0 {
                let k = covered.trailing_zeros() as usize;
                covered &= covered - 1;
                tile.write(i + k, depth[k], id);
            }
            x += 8;
        }
        for x in x..=r.x1 {
            let i = tile.index(x, y);
            tile.edge_evals[i] += 1;
            if let Some(w) = tri.sample(pixel_center(x), yc) {
                tile.write(i, w, id);
            }
        }
    }
}

/// Writes every sample of `r`, known to be covered: only depth is computed.
#[inline]
fn fill_samples<T: Coverage>(tile: &mut TileBuffer, tri: &T, id: u32, r: PixelRect) {
    for y in r.y0..=r.y1 {
        let yc = pixel_center(y);
        for x in r.x0..=r.x1 {
            let i = tile.index(x, y);
            tile.edge_evals[i] += 1;
            let xc = pixel_center(x);
            if let Some(w) = tri.depth(tri.edge_values(xc, yc), xc, yc) {
                tile.write(i, w, id);
            }
        }
    }
}

/// Where a block stands against one triangle.
enum BlockTest {
    Outside,
    Inside,
    Partial,
}

/// Edge functions at the four corner samples of `r`: outside if some edge is
/// negative beyond its error bound at all four, inside if every edge is positive
/// beyond it at all four (paper §3.1: "binning"). The four corner pixels are
/// charged one evaluation each.
#[inline]
fn test_block<T: Coverage>(
    tile: &mut TileBuffer,
    tri: &T,
    r: PixelRect,
    errors: [f32; 3],
) -> BlockTest {
    let corners = [(r.x0, r.y0), (r.x1, r.y0), (r.x0, r.y1), (r.x1, r.y1)];
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for (x, y) in corners {
        let i = tile.index(x, y);
        tile.edge_evals[i] += 1;
        let e = tri.edge_values(pixel_center(x), pixel_center(y));
        for k in 0..3 {
            lo[k] = lo[k].min(e[k]);
            hi[k] = hi[k].max(e[k]);
        }
    }
    if (0..3).any(|k| hi[k] < -errors[k]) {
        BlockTest::Outside
    } else if (0..3).all(|k| lo[k] > errors[k]) {
        BlockTest::Inside
    } else {
        BlockTest::Partial
    }
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
    errors: [f32; 3],
    oracles: SampleOracles,
    counters: &mut RasterCounters,
) {
    // 1. The block's samples inside the triangle's box.
    let block = PixelRect {
        x0: bx,
        y0: by,
        x1: bx + side - 1,
        y1: by + side - 1,
    };
    let Some(r) = block.intersect(clip) else {
        return;
    };
    // 2. Leaf: sample by sample.
    if side <= oracles.leaf {
        return sample_block(tile, tri, id, r, oracles, counters);
    }
    // 3. Early-z against the hierarchical w-buffer.
    if oracles.early_z && early_z_rejects(tile, tri, r, counters) {
        return;
    }
    // 4. The tile test.
    counters.tiles_tested += 1;
    match test_block(tile, tri, r, errors) {
        BlockTest::Outside => counters.tiles_rejected += 1,
        BlockTest::Inside => {
            counters.tiles_accepted += 1;
            fill_samples(tile, tri, id, r);
            if oracles.early_z {
                tile.update_hiz(r.x0, r.y0, r.x1, r.y1);
            }
        }
        BlockTest::Partial => {
            let half = side / 2;
            for (dx, dy) in [(0, 0), (half, 0), (0, half), (half, half)] {
                bin_block(
                    tile,
                    tri,
                    id,
                    clip,
                    bx + dx,
                    by + dy,
                    half,
                    errors,
                    oracles,
                    counters,
                );
            }
        }
    }
}
