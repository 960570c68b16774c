//! Screen tiles: triangles are sorted into tiles of the image (rows of 256
//! pixels, 16 deep) by their bounding boxes (a counting sort), and the tiles
//! are rendered in parallel, each into its own
//! [`TileBuffer`](crate::framebuffer::TileBuffer) and resolved there.

use rayon::prelude::*;

use super::{Pass, PixelRect, TileContext};
use crate::binning::SmallQueue;
use crate::edge::{Coverage, Stored};
use crate::framebuffer::{Framebuffer, TileBuffer};
use crate::simd;
use crate::stats::RasterCounters;

/// A screen tile's width and height in pixels: 4096 pixels, in rows four
/// times wider than a square tile's. What a tile leaves behind — its
/// samples resolved, shaded and stored into the frame's rows — runs along
/// rows, and 256-pixel rows make those stages 15–40% cheaper than 64-pixel
/// ones (1080p frames 0.85–0.93× on bunny, teapots and the dragon; a
/// tile's buffers keep their size).
const TILE_WIDTH: u32 = 256;
const TILE_HEIGHT: u32 = 16;

/// How many items ahead of the one rasterized a tile fetches records.
const PREFETCH_AHEAD: usize = 8;

/// Items per run of the parallel binning.
const BIN_RUN: usize = 1 << 14;

/// One run's items sorted by tile: tile `t`'s are `members[offsets[t]..offsets[t + 1]]`.
struct Binned {
    offsets: Vec<u32>,
    members: Vec<u32>,
}

impl Binned {
    fn of(&self, t: usize) -> &[u32] {
        &self.members[self.offsets[t] as usize..self.offsets[t + 1] as usize]
    }
}

/// An item's conservative screen box and triangle id, in 12 bytes (five
/// items to a cache line; as an `Option<(PixelRect, u32)>` it took 24): the
/// box's pixel bounds fit 16 bits, images being at most
/// [`MAX_DIMENSION`](crate::ground::MAX_DIMENSION) pixels on a side.
/// An empty box is an item with nothing to test ([`ItemBox::NONE`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct ItemBox {
    x0: u16,
    y0: u16,
    x1: u16,
    y1: u16,
    id: u32,
}

const _: () = assert!(crate::ground::MAX_DIMENSION <= u16::MAX as u32);
const _: () = assert!(size_of::<ItemBox>() == 12);

impl ItemBox {
    /// Nothing to test.
    pub(crate) const NONE: ItemBox = ItemBox {
        x0: 0,
        y0: 0,
        x1: 0,
        y1: 0,
        id: 0,
    };

    /// Triangle `id`'s pixels `rect` (non-empty, within an image).
    #[inline]
    pub(crate) fn new(rect: PixelRect, id: u32) -> ItemBox {
        debug_assert!(!rect.is_empty() && rect.x1.max(rect.y1) <= u32::from(u16::MAX));
        let side = |v: u32| v as u16;
        ItemBox {
            x0: side(rect.x0),
            y0: side(rect.y0),
            x1: side(rect.x1),
            y1: side(rect.y1),
            id,
        }
    }

    /// Triangle `id`'s pixel bounds `[x0, y0, x1, y1]` (a non-empty box
    /// within an image) where `keep`, else [`ItemBox::NONE`], with no
    /// branch: the lanes of a setup write every box, kept or not.
    #[inline(always)]
    pub(crate) fn kept(bounds: [u32; 4], id: u32, keep: bool) -> ItemBox {
        let [x0, y0, x1, y1] = bounds;
        debug_assert!(!keep || (x0 < x1 && y0 < y1 && x1.max(y1) <= u32::from(u16::MAX)));
        let k = u32::from(keep);
        let side = |v: u32| (v * k) as u16;
        ItemBox {
            x0: side(x0),
            y0: side(y0),
            x1: side(x1),
            y1: side(y1),
            id: id * k,
        }
    }

    /// The box and the triangle's id, or `None` when there is nothing to test.
    #[inline(always)]
    pub(crate) fn get(self) -> Option<(PixelRect, u32)> {
        (self.x0 < self.x1).then_some(self.unchecked())
    }

    /// The box and the triangle's id with no branch: the box of
    /// [`ItemBox::NONE`] is empty, so a caller that intersects it with its
    /// pixels rejects it there.
    #[inline(always)]
    pub(crate) fn unchecked(self) -> (PixelRect, u32) {
        let rect = PixelRect::new(
            self.x0.into(),
            self.y0.into(),
            self.x1.into(),
            self.y1.into(),
        );
        (rect, self.id)
    }
}

/// Set-up triangles as two arrays of one item each: the conservative screen
/// box and id, and apart from them the edge functions (`None` for a triangle
/// off screen, edge-on or degenerate, whose box is [`ItemBox::NONE`]); and
/// what the view's triangles share. Binning and a ray caster read the small
/// boxes alone — 12 bytes an item, where a set-up triangle is 64 or more —
/// and the edge functions only where a box reaches their tile or their rays.
pub(crate) struct Setups<'s, T: Stored> {
    pub boxes: Vec<ItemBox>,
    pub triangles: Vec<Option<T>>,
    pub shared: T::Shared<'s>,
}

impl<T: Stored> Setups<'_, T> {
    /// How many items have something to test.
    pub(crate) fn placed(&self) -> u64 {
        self.boxes.iter().filter_map(|b| b.get()).count() as u64
    }

    /// Item `k`'s box, triangle id and coverage; `None` when it has nothing
    /// to test.
    #[inline(always)]
    pub(crate) fn get(&self, k: usize) -> Option<(PixelRect, u32, T::Bound<'_>)> {
        let (rect, id) = self.boxes[k].get()?;
        let tri = self.triangles[k].as_ref()?;
        Some((rect, id, self.bind(tri, k, id)))
    }

    /// `tri`, item `k` and triangle `id`, as coverage.
    #[inline(always)]
    pub(crate) fn bind<'b>(&'b self, tri: &'b T, k: usize, id: u32) -> T::Bound<'b> {
        tri.bind(&self.shared, k as u32, id)
    }
}

/// The tiles of an image, row by row.
struct TileGrid {
    columns: usize,
}

impl TileGrid {
    /// Calls `f` with the index of every tile that the non-empty `r` reaches,
    /// row by row. A box in one tile (nearly every box of a mesh of small
    /// triangles) takes no loop: the loops' exits, one to four tiles wide
    /// as no predictor foresees, were mispredicted every few boxes.
    #[inline(always)]
    fn each(&self, r: &PixelRect, mut f: impl FnMut(usize)) {
        let (tx0, tx1) = (r.x0 / TILE_WIDTH, (r.x1 - 1) / TILE_WIDTH);
        let (ty0, ty1) = (r.y0 / TILE_HEIGHT, (r.y1 - 1) / TILE_HEIGHT);
        if tx0 == tx1 && ty0 == ty1 {
            return f(ty0 as usize * self.columns + tx0 as usize);
        }
        for ty in ty0..=ty1 {
            let row = ty as usize * self.columns;
            for tx in tx0..=tx1 {
                f(row + tx as usize);
            }
        }
    }
}

/// Renders `items` into `fb`, tile by tile in parallel (`None` items are
/// triangles the setup dropped), each triangle within each tile by `kernel`
/// (tile, triangle, id, the pixels of its box in the tile, counters).
/// `small`: the kernel tests a box that [`SmallQueue::takes`] sample by
/// sample and does nothing else there (no early-z), so such boxes may go
/// through a [`SmallQueue`] instead, where the coverage tests across
/// triangles ([`Coverage::ACROSS`]).
pub(crate) fn rasterize_tiled<T: Stored>(
    items: &Setups<T>,
    fb: &mut Framebuffer,
    context: &TileContext,
    small: bool,
    kernel: impl Fn(&mut TileBuffer, &T::Bound<'_>, u32, PixelRect, &mut RasterCounters) + Sync,
) -> Pass {
    let grid = TileGrid {
        columns: fb.width.div_ceil(TILE_WIDTH) as usize,
    };
    let tile_count = grid.columns * fb.height.div_ceil(TILE_HEIGHT) as usize;

    // 1. Counting sorts of item indices by tile, one per run of items, in
    // parallel: a tile's items are its lists of every run, in run order.
    let runs: Vec<Binned> = (items.boxes)
        .par_chunks(BIN_RUN)
        .enumerate()
        .map(|(run, chunk)| {
            let base = (run * BIN_RUN) as u32;
            let mut offsets = vec![0u32; tile_count + 1];
            for (rect, _) in chunk.iter().filter_map(|b| b.get()) {
                grid.each(&rect, |t| offsets[t + 1] += 1);
            }
            for t in 0..tile_count {
                offsets[t + 1] += offsets[t];
            }
            let mut fill = offsets.clone();
            let mut members = vec![0u32; offsets[tile_count] as usize];
            for (k, item) in chunk.iter().enumerate() {
                let Some((rect, _)) = item.get() else {
                    continue;
                };
                grid.each(&rect, |t| {
                    members[fill[t] as usize] = base + k as u32;
                    fill[t] += 1;
                });
            }
            Binned { offsets, members }
        })
        .collect();

    // 2. Tiles in parallel, in input order within a tile, each resolved by
    // its worker (the samples never outlive their tile).
    let mut pass = Pass::default();
    let size = [TILE_WIDTH, TILE_HEIGHT];
    let done = context.run_tiles(&mut pass, fb, size, |t, members: &mut Vec<u32>, tile| {
        let mut counters = RasterCounters::default();
        // The tile's items, gathered into the worker's list (kept from tile
        // to tile).
        members.clear();
        for run in &runs {
            members.extend_from_slice(run.of(t));
        }
        let across = small
            && <T::Bound<'_> as Coverage>::ACROSS
            && SmallQueue::<T::Bound<'_>>::applies(tile);
        let mut queue = None;
        for (i, &k) in members.iter().enumerate() {
            // The records of an item a few places on are on their way while
            // this one is rasterized (they are far apart in memory, and a
            // small triangle takes less time than a miss).
            if let Some(&next) = members.get(i + PREFETCH_AHEAD) {
                simd::prefetch(&items.boxes[next as usize]);
                simd::prefetch(&items.triangles[next as usize]);
            }
            // Only items with a box (and so a triangle) were sorted into tiles.
            let Some((rect, id, tri)) = items.get(k as usize) else {
                continue;
            };
            // Non-empty: the item was sorted into this tile by its rect.
            if let Some(clip) = rect.intersect(tile.rect()) {
                if across && SmallQueue::<T::Bound<'_>>::takes(tile, clip) {
                    let queue = queue.get_or_insert_with(|| SmallQueue::new(tri));
                    queue.push(tile, tri, id, clip);
                } else {
                    kernel(tile, &tri, id, clip, &mut counters);
                }
            }
        }
        if let Some(queue) = &mut queue {
            queue.flush(tile);
        }
        counters
    });
    pass.add(done);
    pass
}
