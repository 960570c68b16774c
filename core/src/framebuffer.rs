//! The framebuffer: colour, w-buffer, triangle ids, and the two per-pixel counters
//! that explain an image — edge evaluations (work) and coverage writes
//! (watertightness: a closed mesh gives exactly one per sample).

use crate::aa::SamplePattern;
use crate::ground::PixelRect;
use crate::hiz::Hiz;
use crate::prepared::is_see_through;
use crate::simd::Lanes;
use crate::stats::{CoverageHistogram, Hashes};

/// Triangle id of a pixel no triangle covers.
pub const BACKGROUND: u32 = u32::MAX;

/// The w-buffer test every algorithm uses: a sample at depth `w` of triangle `id`
/// replaces the stored `(depth, stored_id)` when it is nearer, or equally near
/// with a smaller id — so no result depends on drawing or traversal order.
#[inline(always)]
pub fn wins_depth_test(w: f32, id: u32, depth: f32, stored_id: u32) -> bool {
    w < depth || (w == depth && id < stored_id)
}

/// All per-pixel buffers of one render, row-major, `y` down. With anti-aliasing
/// the samples of a pixel are resolved into it: `color` is the box-filtered
/// colour, `depth` and `triangle_id` are those of the pattern's first sample,
/// `edge_evals` and `coverage_writes` count over all its samples, and
/// `sample_digest` identifies the triangle ids (and coverage masks) of all of them.
#[derive(Clone, Debug, PartialEq)]
pub struct Framebuffer {
    pub width: u32,
    pub height: u32,
    /// sRGB RGBA8.
    pub color: Vec<[u8; 4]>,
    /// View-axis distance `w` of the visible surface; `+∞` for background.
    pub depth: Vec<f32>,
    /// Id of the visible triangle; [`BACKGROUND`] where none.
    pub triangle_id: Vec<u32>,
    /// Samples-against-triangle tests made at each pixel (each evaluates three
    /// edges); empty when the request asked for no counter planes
    /// (`RenderRequest::counter_planes`).
    pub edge_evals: Vec<u32>,
    /// Samples that passed a coverage test at each pixel, before the depth test,
    /// summed over the pixel's stored samples. Algorithms with early-z or
    /// occlusion culling skip hidden blocks before testing them, so they count
    /// fewer here (never on a closed mesh seen from inside, where every sample has
    /// exactly one triangle). Empty when the request asked for no counter planes.
    pub coverage_writes: Vec<u32>,
    /// With anti-aliasing: per pixel, a 64-bit hash of its samples' triangle ids
    /// (and CSAA coverage masks), so renders can be compared sample by sample;
    /// empty without anti-aliasing, where `triangle_id` is the whole story.
    pub sample_digest: Vec<u64>,
    /// With transparency in the scene: per pixel, the transparent fragments
    /// blended into it, summed over its stored samples (a tessellated pane
    /// over a sample gives exactly one); empty otherwise.
    pub blended: Vec<u32>,
}

impl Framebuffer {
    pub fn new(width: u32, height: u32) -> Framebuffer {
        let n = width as usize * height as usize;
        Framebuffer {
            width,
            height,
            color: vec![[0, 0, 0, 255]; n],
            depth: vec![f32::INFINITY; n],
            triangle_id: vec![BACKGROUND; n],
            edge_evals: vec![0; n],
            coverage_writes: vec![0; n],
            sample_digest: Vec::new(),
            blended: Vec::new(),
        }
    }

    /// The image cut into `width × height` tiles (smaller at the right and
    /// bottom), row by row.
    pub(crate) fn tile_rects(&self, width: u32, height: u32) -> Vec<PixelRect> {
        let mut rects = Vec::new();
        for y0 in (0..self.height).step_by(height as usize) {
            for x0 in (0..self.width).step_by(width as usize) {
                rects.push(PixelRect::new(
                    x0,
                    y0,
                    (x0 + width).min(self.width),
                    (y0 + height).min(self.height),
                ));
            }
        }
        rects
    }

    /// Buffers for a render whose tiles resolve into every pixel
    /// ([`Framebuffer::tile_planes`]): those of an earlier render of the same
    /// size when one was [recycled](Framebuffer::recycle), as they are (every
    /// pixel is written, so nothing is cleared), else zeroed memory straight
    /// from the allocator. The counter planes (`edge_evals`,
    /// `coverage_writes`), `sample_digest` and `blended` are there when
    /// asked for, empty otherwise (keeping their memory for the next render
    /// that asks).
    pub(crate) fn for_tiles(width: u32, height: u32, optional: Optional) -> Framebuffer {
        let n = width as usize * height as usize;
        let spare = {
            let mut pool = FRAME_POOL.lock().unwrap_or_else(|e| e.into_inner());
            let fits = |f: &Framebuffer| {
                (f.width, f.height) == (width, height)
                    && [f.depth.len(), f.triangle_id.len(), f.color.len()]
                        .iter()
                        .all(|&len| len == n)
            };
            let at = pool.iter().position(fits);
            at.map(|i| pool.swap_remove(i))
        };
        let mut fb = spare.unwrap_or_else(|| Framebuffer {
            width,
            height,
            color: vec![[0; 4]; n],
            depth: vec![0.0; n],
            triangle_id: vec![0; n],
            edge_evals: Vec::new(),
            coverage_writes: Vec::new(),
            sample_digest: Vec::new(),
            blended: Vec::new(),
        });
        fn plane<T: Copy + Default>(plane: &mut Vec<T>, wanted: bool, n: usize) {
            if !wanted {
                plane.clear();
            } else if plane.capacity() < n {
                *plane = vec![T::default(); n];
            } else if plane.len() != n {
                plane.clear();
                plane.resize(n, T::default());
            }
        }
        plane(&mut fb.edge_evals, optional.counters, n);
        plane(&mut fb.coverage_writes, optional.counters, n);
        plane(&mut fb.sample_digest, optional.digest, n);
        plane(&mut fb.blended, optional.blended, n);
        fb
    }

    /// Gives this framebuffer's memory to the next render of the same size
    /// (the service, the viewer and `compare` render many frames of one size:
    /// a reused frame costs no page faults and no clearing). The pool keeps
    /// the two most recently recycled frames.
    pub fn recycle(self) {
        let mut pool = FRAME_POOL.lock().unwrap_or_else(|e| e.into_inner());
        if pool.len() == FRAME_POOL_SIZE {
            pool.remove(0);
        }
        pool.push(self);
    }

    /// Disjoint views of the frame's planes, one per tile of the grid of
    /// `size` tiles ([`Framebuffer::tile_rects`], in its order): the rows
    /// each tile resolves into. Each row of a plane is cut into its tiles'
    /// pieces by one `chunks_mut`.
    pub(crate) fn tile_planes(
        &mut self,
        [tile_width, tile_height]: [u32; 2],
    ) -> Vec<TilePlanes<'_>> {
        let rects = self.tile_rects(tile_width, tile_height);
        let grid = Grid {
            width: self.width as usize,
            tile: [tile_width as usize, tile_height as usize],
            columns: self.width.div_ceil(tile_width) as usize,
        };
        // Each tile's rows, allocated once (an optional plane the render
        // has not gets none).
        let counters = !self.edge_evals.is_empty();
        let (digest, blended) = (!self.sample_digest.is_empty(), !self.blended.is_empty());
        let mut planes: Vec<TilePlanes> = rects
            .iter()
            .map(|&rect| {
                let h = rect.height() as usize;
                let optional = |present: bool| if present { h } else { 0 };
                TilePlanes {
                    rect,
                    color: Vec::with_capacity(h),
                    depth: Vec::with_capacity(h),
                    triangle_id: Vec::with_capacity(h),
                    edge_evals: Vec::with_capacity(optional(counters)),
                    coverage_writes: Vec::with_capacity(optional(counters)),
                    sample_digest: Vec::with_capacity(optional(digest)),
                    blended: Vec::with_capacity(optional(blended)),
                }
            })
            .collect();
        grid.split(&mut self.color, &mut planes, |p| &mut p.color);
        grid.split(&mut self.depth, &mut planes, |p| &mut p.depth);
        grid.split(&mut self.triangle_id, &mut planes, |p| &mut p.triangle_id);
        grid.split(&mut self.edge_evals, &mut planes, |p| &mut p.edge_evals);
        grid.split(&mut self.coverage_writes, &mut planes, |p| {
            &mut p.coverage_writes
        });
        grid.split(&mut self.sample_digest, &mut planes, |p| {
            &mut p.sample_digest
        });
        grid.split(&mut self.blended, &mut planes, |p| &mut p.blended);
        planes
    }
}

/// A frame `width` pixels wide cut into tiles of `tile` pixels, `columns`
/// to a row of tiles ([`Framebuffer::tile_planes`]).
struct Grid {
    width: usize,
    tile: [usize; 2],
    columns: usize,
}

impl Grid {
    /// Each row of `plane` cut into its tiles' pieces, each pushed onto its
    /// tile's `field`. An empty plane (an optional buffer the render has
    /// not) gives every tile no rows.
    fn split<'f, T>(
        &self,
        plane: &'f mut [T],
        planes: &mut [TilePlanes<'f>],
        field: impl for<'t> Fn(&'t mut TilePlanes<'f>) -> &'t mut Vec<&'f mut [T]>,
    ) {
        let [tile_width, tile_height] = self.tile;
        for (y, row) in plane.chunks_mut(self.width).enumerate() {
            let first = y / tile_height * self.columns;
            for (piece, tile) in row.chunks_mut(tile_width).zip(&mut planes[first..]) {
                field(tile).push(piece);
            }
        }
    }
}

/// The planes of a frame that a render may go without
/// ([`Framebuffer::for_tiles`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Optional {
    /// `edge_evals` and `coverage_writes` ([`crate::RenderRequest::counter_planes`]).
    pub counters: bool,
    /// `sample_digest`: with anti-aliasing.
    pub digest: bool,
    /// `blended`: with transparency in the scene.
    pub blended: bool,
}

/// Frames kept by [`Framebuffer::recycle`]: two (the viewer shows two at once; the
/// service renders two at a time), so an idle process holds at most two frames.
const FRAME_POOL_SIZE: usize = 2;

static FRAME_POOL: std::sync::Mutex<Vec<Framebuffer>> = std::sync::Mutex::new(Vec::new());

/// A tile's pixels in the frame's planes: row `r` of each is the tile's row
/// `rect.y0 + r`, columns `rect.x0..rect.x1`. The resolve writes them in place;
/// an optional plane the render has not has no rows.
#[derive(Debug)]
pub(crate) struct TilePlanes<'f> {
    pub rect: PixelRect,
    pub color: Vec<&'f mut [[u8; 4]]>,
    pub depth: Vec<&'f mut [f32]>,
    pub triangle_id: Vec<&'f mut [u32]>,
    pub edge_evals: Vec<&'f mut [u32]>,
    pub coverage_writes: Vec<&'f mut [u32]>,
    pub sample_digest: Vec<&'f mut [u64]>,
    pub blended: Vec<&'f mut [u32]>,
}

/// What the resolve of one tile counted.
#[derive(Clone, Debug, Default)]
pub(crate) struct TileTotals {
    /// Coverage writes per stored sample: zero, one, many.
    pub histogram: CoverageHistogram,
    /// Sample-against-triangle tests made in the tile, and the most at one pixel.
    pub edge_evaluations: u64,
    pub max_edge_evals: u32,
    /// Shading evaluations made.
    pub shading_samples: u64,
    /// What the tile's effect rays cost.
    pub effects: crate::effects::EffectCounters,
}

/// A covered sample of a see-through triangle: kept beside the w-buffer, not
/// tested against it, until the resolve sorts the sample's fragments by depth
/// and blends those in front of its opaque surface (an A-buffer).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fragment {
    /// Index into the tile's sample buffers.
    pub sample: u32,
    pub w: f32,
    pub id: u32,
}

/// Pixels of a row the coverage kernel handles at once (its CSAA scratch).
pub(crate) const SCRATCH_PIXELS: usize = 64;

/// A rectangle of the framebuffer rendered by one worker: the visibility buffers
/// of pixels `x0..x1 × y0..y1` for every stored sample of the pattern, plus a
/// hierarchical w-buffer over them ([`Hiz`], paper §5 "early-z").
///
/// Sample buffers are layer-major: stored sample `s` of pixel `i` is at
/// `s · pixels + i`, so the samples of one position along a row are contiguous.
#[derive(Clone, Debug)]
pub struct TileBuffer<'p> {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
    /// Where the samples lie in a pixel.
    pub pattern: &'p SamplePattern,
    /// Pixels in the tile.
    pub pixels: usize,
    pub depth: Vec<f32>,
    pub triangle_id: Vec<u32>,
    /// Coverage writes per stored sample.
    pub coverage_writes: Vec<u32>,
    /// CSAA: per stored sample, the coverage positions its triangle covers in
    /// the pixel (empty when every position is stored).
    pub masks: Vec<u32>,
    /// Per pixel: sample-against-triangle tests.
    pub edge_evals: Vec<u32>,
    /// CSAA, per pixel: the coverage positions any triangle rasterized there
    /// covers (read only where a stored sample is background, where no
    /// algorithm culls a triangle, so every algorithm sees the same bits).
    pub covered_any: Vec<u32>,
    /// CSAA scratch of the coverage kernel: masks of [`SCRATCH_PIXELS`] pixels
    /// and the depths at their stored positions (empty otherwise).
    pub(crate) scratch_masks: Vec<u32>,
    pub(crate) scratch_depths: Vec<f32>,
    /// The hierarchical w-buffer over [`TileBuffer::depth`].
    pub(crate) hiz: Hiz,
    /// Opacity per triangle id ([`crate::PreparedScene::triangle_opacity`]);
    /// empty when every triangle is opaque.
    pub opacity: &'p [f32],
    /// Covered samples of see-through triangles, in no particular order.
    pub fragments: Vec<Fragment>,
    /// What the algorithm did in this tile, when the render records it.
    pub trace: Option<crate::trace::Trace>,
    /// Has a stored depth decreased since the last [`TileBuffer::update_hiz`]?
    depth_lowered: bool,
}

impl<'p> TileBuffer<'p> {
    /// Buffers for the pixels of `rect`; `opacity` per triangle id
    /// (empty: all opaque) tells which triangles leave fragments.
    pub fn new(
        PixelRect { x0, y0, x1, y1 }: PixelRect,
        pattern: &'p SamplePattern,
        opacity: &'p [f32],
    ) -> TileBuffer<'p> {
        let pixels = ((x1 - x0) * (y1 - y0)) as usize;
        let samples = pixels * pattern.stored;
        TileBuffer {
            x0,
            y0,
            x1,
            y1,
            pattern,
            pixels,
            depth: vec![f32::INFINITY; samples],
            triangle_id: vec![BACKGROUND; samples],
            coverage_writes: vec![0; samples],
            masks: if pattern.has_coverage_only() {
                vec![0; samples]
            } else {
                Vec::new()
            },
            edge_evals: vec![0; pixels],
            covered_any: if pattern.has_coverage_only() {
                vec![0; pixels]
            } else {
                Vec::new()
            },
            scratch_masks: if pattern.has_coverage_only() {
                vec![0; SCRATCH_PIXELS]
            } else {
                Vec::new()
            },
            scratch_depths: if pattern.has_coverage_only() {
                vec![0.0; SCRATCH_PIXELS * pattern.stored]
            } else {
                Vec::new()
            },
            hiz: Hiz::new(PixelRect { x0, y0, x1, y1 }),
            opacity,
            fragments: Vec::new(),
            trace: None,
            depth_lowered: false,
        }
    }

    /// Adds to the tile's trace, when the render records one (otherwise
    /// one untaken branch).
    #[inline(always)]
    pub(crate) fn record(&mut self, add: impl FnOnce(&mut crate::trace::Trace)) {
        if let Some(trace) = &mut self.trace {
            add(trace);
        }
    }

    /// The same buffers for the pixels `x0..x1 × y0..y1`, cleared (their
    /// memory kept).
    pub fn reset(&mut self, PixelRect { x0, y0, x1, y1 }: PixelRect) {
        let pixels = ((x1 - x0) * (y1 - y0)) as usize;
        let samples = pixels * self.pattern.stored;
        let refill = |v: &mut Vec<u32>, n: usize, value: u32| {
            v.clear();
            v.resize(n, value);
        };
        (self.x0, self.y0, self.x1, self.y1, self.pixels) = (x0, y0, x1, y1, pixels);
        self.depth.clear();
        self.depth.resize(samples, f32::INFINITY);
        refill(&mut self.triangle_id, samples, BACKGROUND);
        refill(&mut self.coverage_writes, samples, 0);
        refill(&mut self.edge_evals, pixels, 0);
        if self.pattern.has_coverage_only() {
            refill(&mut self.masks, samples, 0);
            refill(&mut self.covered_any, pixels, 0);
        }
        self.hiz.reset(PixelRect { x0, y0, x1, y1 });
        self.fragments.clear();
        self.depth_lowered = false;
    }

    /// Keeps what the tile holds (depths, triangle ids, coverage masks) and
    /// forgets how it got there: the per-pixel counts and the see-through
    /// fragments start again, and the hierarchical w-buffer is read afresh
    /// from the depths (exact, where updates keep upper bounds) — the
    /// `final_depth` oracle's start ([`crate::pipeline::TraversalOracles`]).
    pub(crate) fn restart_counts(&mut self) {
        self.coverage_writes.fill(0);
        self.edge_evals.fill(0);
        self.fragments.clear();
        let rect = self.rect();
        self.hiz.reset(rect);
        self.hiz.update(rect, &self.depth, self.pixels);
        self.depth_lowered = false;
    }

    /// Does every stored sample of the pixels of `r` (inside the tile) hold a
    /// depth nearer than `w`?
    pub(crate) fn all_nearer(&self, r: PixelRect, w: f32) -> bool {
        let width = (r.x1 - r.x0) as usize;
        (0..self.pattern.stored).all(|s| {
            (r.y0..r.y1).all(|y| {
                let start = s * self.pixels + self.index(r.x0, y);
                self.depth[start..start + width].iter().all(|&d| d < w)
            })
        })
    }

    /// The tile's pixels.
    pub(crate) fn rect(&self) -> PixelRect {
        PixelRect::new(self.x0, self.y0, self.x1, self.y1)
    }

    /// Index of pixel `(x, y)` (screen coordinates) in the tile's per-pixel
    /// buffers; stored sample `s` of it is at `s · pixels + index`.
    #[inline(always)]
    pub fn index(&self, x: u32, y: u32) -> usize {
        ((y - self.y0) * (self.x1 - self.x0) + (x - self.x0)) as usize
    }

    /// A covered sample (index `i` into the sample buffers): count the coverage
    /// write, then — for an opaque triangle — the w-buffer test with depth ties
    /// going to the smaller triangle id; a see-through triangle's sample is
    /// kept as a [`Fragment`] instead. Returns whether the sample now holds
    /// the triangle.
    #[inline(always)]
    pub fn write(&mut self, i: usize, w: f32, id: u32) -> bool {
        self.coverage_writes[i] += 1;
        if is_see_through(self.opacity, id) {
            self.fragments.push(Fragment {
                sample: i as u32,
                w,
                id,
            });
            return false;
        }
        let (d, t) = (self.depth[i], self.triangle_id[i]);
        if wins_depth_test(w, id, d, t) {
            self.depth_lowered |= w < d;
            self.depth[i] = w;
            self.triangle_id[i] = id;
            true
        } else {
            false
        }
    }

    /// [`TileBuffer::write`] of samples `i + l` at depths `w[l]` for the lanes
    /// `l` of `mask`, the depth test in lanes: the same winners, and the same
    /// buffers after, as eight writes in lane order (each sample is its own).
    /// A see-through triangle, or eight samples past the buffer's end, take
    /// the writes one by one.
    #[inline(always)]
    pub(crate) fn write_eight<L: Lanes>(&mut self, i: usize, mask: u8, w: &[f32; 8], id: u32) {
        let (Some(stored), Some(stored_ids)) =
            (self.depth.get(i..i + 8), self.triangle_id.get(i..i + 8))
        else {
            return self.write_each(i, mask, w, id);
        };
        if is_see_through(self.opacity, id) {
            return self.write_each(i, mask, w, id);
        }
        let (mut old, mut old_ids) = ([0.0; 8], [0u32; 8]);
        old.copy_from_slice(stored);
        old_ids.copy_from_slice(stored_ids);
        let (new, stored) = (L::from_array(*w), L::from_array(old));
        let nearer = new.lt(stored) & mask;
        // Equal depths: the smaller id wins (rare: decided one by one).
        let (mut wins, mut ties) = (nearer, new.eq(stored) & mask & !nearer);
        while ties != 0 {
            let l = ties.trailing_zeros() as usize;
            ties &= ties - 1;
            if id < old_ids[l] {
                wins |= 1 << l;
            }
        }
        let counts = &mut self.coverage_writes[i..i + 8];
        for (l, count) in counts.iter_mut().enumerate() {
            *count += u32::from(mask >> l & 1);
        }
        if wins == 0 {
            return;
        }
        self.depth_lowered |= nearer != 0;
        self.depth[i..i + 8].copy_from_slice(&L::select(wins, new, stored).to_array());
        // The ids blended as lanes of bits (a select moves bits, whatever
        // float they spell), not stored lane by lane behind a branch each.
        let old_ids = L::from_array(bytemuck::cast(old_ids));
        let ids = L::select(wins, L::splat(f32::from_bits(id)), old_ids);
        (self.triangle_id[i..i + 8])
            .copy_from_slice(&bytemuck::cast::<_, [u32; 8]>(ids.to_array()));
    }

    /// [`TileBuffer::write`] of each lane of `mask`, in lane order.
    #[inline]
    fn write_each(&mut self, i: usize, mask: u8, w: &[f32; 8], id: u32) {
        let mut lanes = mask;
        while lanes != 0 {
            let l = lanes.trailing_zeros() as usize;
            lanes &= lanes - 1;
            self.write(i + l, w[l], id);
        }
    }

    /// [`TileBuffer::write`] for CSAA: a winner also stores the coverage mask of
    /// its triangle in the pixel.
    #[inline(always)]
    pub fn write_masked(&mut self, i: usize, w: f32, id: u32, mask: u32) {
        if self.write(i, w, id) {
            self.masks[i] = mask;
        }
    }

    /// The farthest stored depth over the hierarchical w-buffer's cells that
    /// the pixels of `r` touch (`+∞` while any of their samples is empty).
    #[inline]
    pub fn hiz_max(&self, r: PixelRect) -> f32 {
        self.hiz.farthest(r)
    }

    /// Brings the hierarchical w-buffer's cells that the pixels of `r` touch up
    /// to date, if a depth has decreased since the last update (every write
    /// between two updates falls inside the rectangle the second one names).
    pub fn update_hiz(&mut self, r: PixelRect) {
        if std::mem::take(&mut self.depth_lowered) {
            self.hiz.update(r, &self.depth, self.pixels);
        }
    }
}

impl Hashes {
    /// xxh3 of the buffers' little-endian bytes, hashed in place (no copy of
    /// the image) and side by side.
    pub fn of(fb: &Framebuffer) -> Hashes {
        let hex = |hash: u64| format!("{hash:016x}");
        let ((triangle_id, color), digest) = rayon::join(
            || {
                rayon::join(
                    || hash_le(&fb.triangle_id, u32::to_le_bytes),
                    || xxhash_rust::xxh3::xxh3_64(fb.color.as_flattened()),
                )
            },
            || (!fb.sample_digest.is_empty()).then(|| hash_le(&fb.sample_digest, u64::to_le_bytes)),
        );
        Hashes {
            triangle_id: hex(triangle_id),
            color: hex(color),
            samples: hex(digest.unwrap_or(triangle_id)),
        }
    }
}

/// xxh3 of `values` as little-endian bytes, streamed through a small buffer.
fn hash_le<T: Copy, const N: usize>(values: &[T], bytes: fn(T) -> [u8; N]) -> u64 {
    let mut hasher = xxhash_rust::xxh3::Xxh3::new();
    let mut buffer = [0u8; 4096];
    for chunk in values.chunks(buffer.len() / N) {
        for (out, &v) in buffer.chunks_exact_mut(N).zip(chunk) {
            out.copy_from_slice(&bytes(v));
        }
        hasher.update(&buffer[..chunk.len() * N]);
    }
    hasher.digest()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aa::AaMode;
    use crate::simd::Portable;

    /// The tile planes of a grid hold, row by row, exactly their tiles'
    /// pixels — tiles cut short at the right and bottom edges included —
    /// and every pixel of the frame lies in one tile; a plane the frame
    /// has not (the counters of `Framebuffer::new`'s are there; the
    /// digest is not) gives no rows.
    #[test]
    fn tile_planes_cut_the_frame_into_its_tiles() {
        let mut checked = 0;
        for ([width, height], size) in [
            ([37, 23], [8, 5]),
            ([64, 48], [64, 48]),
            ([100, 7], [256, 16]),
        ] {
            let mut fb = Framebuffer::new(width, height);
            for (i, id) in fb.triangle_id.iter_mut().enumerate() {
                *id = i as u32;
            }
            let rects = fb.tile_rects(size[0], size[1]);
            let planes = fb.tile_planes(size);
            assert_eq!(planes.len(), rects.len());
            let mut seen = vec![0u32; (width * height) as usize];
            for (tile, rect) in planes.iter().zip(&rects) {
                assert_eq!(tile.rect, *rect);
                assert_eq!(tile.triangle_id.len(), rect.height() as usize);
                assert_eq!(tile.color.len(), rect.height() as usize);
                assert_eq!(tile.edge_evals.len(), rect.height() as usize);
                assert!(tile.sample_digest.is_empty());
                for (r, row) in tile.triangle_id.iter().enumerate() {
                    let y = rect.y0 + r as u32;
                    let expected: Vec<u32> = (rect.x0..rect.x1).map(|x| y * width + x).collect();
                    assert_eq!(**row, expected[..]);
                    row.iter().for_each(|&i| seen[i as usize] += 1);
                }
            }
            assert!(seen.iter().all(|&n| n == 1), "every pixel in one tile");
            checked += 1;
        }
        assert_eq!(checked, 3);
    }

    crate::simd::dispatch! {
        fn write_eight_dispatched<>(tile: &mut TileBuffer, i: usize, mask: u8, w: &[f32; 8], id: u32) -> () => write_eight_on
    }

    #[inline(always)]
    fn write_eight_on<L: Lanes>(tile: &mut TileBuffer, i: usize, mask: u8, w: &[f32; 8], id: u32) {
        tile.write_eight::<L>(i, mask, w, id);
    }

    /// [`TileBuffer::write_eight`], portable and dispatched (AVX2 where the
    /// CPU has it), leaves every buffer as the writes one by one do: random
    /// groups over a 40 × 3 tile whose depths take few values (many ties,
    /// decided by id), some groups running past the buffer's end, and a
    /// see-through triangle.
    #[test]
    fn eight_writes_at_once_are_the_writes_one_by_one() {
        let pattern = AaMode::None.pattern();
        let opacity: Vec<f32> = (0..16).map(|id| if id == 5 { 0.5 } else { 1.0 }).collect();
        let rect = PixelRect::new(0, 0, 40, 3);
        let mut rng = fastrand::Rng::with_seed(11);
        let (mut checked, mut lowered) = (0, 0);
        for _ in 0..4_000 {
            let mut one_by_one = TileBuffer::new(rect, &pattern, &opacity);
            for s in 0..one_by_one.pixels {
                if rng.bool() {
                    one_by_one.write(s, rng.u8(1..4) as f32, rng.u32(0..16));
                }
            }
            one_by_one.depth_lowered = false;
            let (mut portable, mut dispatched) = (one_by_one.clone(), one_by_one.clone());
            let i = rng.usize(0..one_by_one.pixels);
            let (mask, id) = (rng.u8(..), rng.u32(0..16));
            let w: [f32; 8] = std::array::from_fn(|_| rng.u8(1..4) as f32);
            // Past the buffer's end, only lanes inside may be covered.
            let mask = mask & crate::simd::first_lanes(one_by_one.pixels - i);
            one_by_one.write_each(i, mask, &w, id);
            portable.write_eight::<Portable>(i, mask, &w, id);
            write_eight_dispatched(&mut dispatched, i, mask, &w, id);
            for tile in [&portable, &dispatched] {
                assert_eq!(tile.depth, one_by_one.depth);
                assert_eq!(tile.triangle_id, one_by_one.triangle_id);
                assert_eq!(tile.coverage_writes, one_by_one.coverage_writes);
                assert_eq!(tile.fragments, one_by_one.fragments);
                assert_eq!(tile.depth_lowered, one_by_one.depth_lowered);
            }
            lowered += usize::from(one_by_one.depth_lowered);
            checked += 1;
        }
        assert_eq!(checked, 4_000);
        assert!(lowered > 1_000, "{lowered} groups lowered a depth");
    }

    /// The ids `write_eight` blends as float lanes keep their bits, those
    /// that spell a signalling or quiet NaN, an infinity or a subnormal
    /// included, on the portable lanes and the dispatched ones.
    #[test]
    fn eight_writes_keep_every_id_bit() {
        let pattern = AaMode::None.pattern();
        let ids = [
            0x7F80_0001,
            0xFFC0_0000,
            0x7F80_0000,
            1,
            0x8000_0001,
            0x7FBF_FFFF,
        ];
        let mut checked = 0;
        for (k, &id) in ids.iter().enumerate() {
            let old = ids[(k + 1) % ids.len()];
            let mut tile = TileBuffer::new(PixelRect::new(0, 0, 8, 1), &pattern, &[]);
            for s in 0..8 {
                tile.write(s, 2.0, old);
            }
            let mut portable = tile.clone();
            // Lanes 0, 2, 4, 6 nearer; the others behind.
            let w = [1.0, 3.0, 1.0, 3.0, 1.0, 3.0, 1.0, 3.0];
            portable.write_eight::<Portable>(0, u8::MAX, &w, id);
            write_eight_dispatched(&mut tile, 0, u8::MAX, &w, id);
            for t in [&portable, &tile] {
                let expected: Vec<u32> =
                    (0..8).map(|l| if l % 2 == 0 { id } else { old }).collect();
                assert_eq!(t.triangle_id, expected, "id {id:#x} over {old:#x}");
            }
            checked += 1;
        }
        assert_eq!(checked, ids.len());
    }
}
