//! The framebuffer: colour, w-buffer, triangle ids, and the two per-pixel counters
//! that explain an image — edge evaluations (work) and coverage writes
//! (watertightness: a closed mesh gives exactly one per pixel).

/// Triangle id of a pixel no triangle covers.
pub const BACKGROUND: u32 = u32::MAX;

/// The w-buffer test every algorithm uses: a sample at depth `w` of triangle `id`
/// replaces the stored `(depth, stored_id)` when it is nearer, or equally near
/// with a smaller id — so no result depends on drawing or traversal order.
#[inline(always)]
pub fn wins_depth_test(w: f32, id: u32, depth: f32, stored_id: u32) -> bool {
    w < depth || (w == depth && id < stored_id)
}

/// All per-pixel buffers of one render, row-major, `y` down.
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
    /// Samples-against-triangle tests made at each pixel (each evaluates three edges).
    pub edge_evals: Vec<u32>,
    /// Samples that passed a coverage test at each pixel, before the depth test.
    /// Algorithms with early-z or occlusion culling skip hidden blocks before
    /// testing them, so they count fewer here (never on a closed mesh seen from
    /// inside, where every sample has exactly one triangle).
    pub coverage_writes: Vec<u32>,
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
        }
    }

    /// Splits the buffers into horizontal bands of `rows` rows for parallel work.
    pub fn bands_mut(&mut self, rows: u32) -> Vec<Band<'_>> {
        let width = self.width as usize;
        let chunk = width * rows.max(1) as usize;
        self.depth
            .chunks_mut(chunk)
            .zip(self.triangle_id.chunks_mut(chunk))
            .zip(self.edge_evals.chunks_mut(chunk))
            .zip(self.coverage_writes.chunks_mut(chunk))
            .enumerate()
            .map(
                |(i, (((depth, triangle_id), edge_evals), coverage_writes))| {
                    let y0 = i as u32 * rows.max(1);
                    Band {
                        y0,
                        y1: y0 + (depth.len() / width) as u32,
                        width: self.width,
                        depth,
                        triangle_id,
                        edge_evals,
                        coverage_writes,
                    }
                },
            )
            .collect()
    }
}

/// Rows `y0..y1` of a framebuffer's visibility buffers.
#[derive(Debug)]
pub struct Band<'a> {
    pub y0: u32,
    pub y1: u32,
    pub width: u32,
    pub depth: &'a mut [f32],
    pub triangle_id: &'a mut [u32],
    pub edge_evals: &'a mut [u32],
    pub coverage_writes: &'a mut [u32],
}

impl Band<'_> {
    /// Index into the band's slices of pixel `(x, y)` (`y` in `y0..y1`).
    #[inline(always)]
    pub fn index(&self, x: u32, y: u32) -> usize {
        (y - self.y0) as usize * self.width as usize + x as usize
    }
}

/// Side of a hierarchical w-buffer cell in pixels.
pub const HIZ_CELL: u32 = 8;

/// A rectangle of the framebuffer rendered by one worker: the visibility buffers
/// of pixels `x0..x1 × y0..y1` plus a hierarchical w-buffer holding, per
/// [`HIZ_CELL`]² cell, the farthest depth stored in it (paper §5 "early-z").
#[derive(Clone, Debug)]
pub struct TileBuffer {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
    pub depth: Vec<f32>,
    pub triangle_id: Vec<u32>,
    pub edge_evals: Vec<u32>,
    pub coverage_writes: Vec<u32>,
    /// Farthest depth per cell (`+∞` while any pixel of it is empty).
    pub hiz: Vec<f32>,
    hiz_columns: u32,
    /// Has a stored depth decreased since the last [`TileBuffer::update_hiz`]?
    depth_lowered: bool,
}

impl TileBuffer {
    pub fn new(x0: u32, y0: u32, x1: u32, y1: u32) -> TileBuffer {
        let n = ((x1 - x0) * (y1 - y0)) as usize;
        let hiz_columns = (x1 - x0).div_ceil(HIZ_CELL);
        let hiz_rows = (y1 - y0).div_ceil(HIZ_CELL);
        TileBuffer {
            x0,
            y0,
            x1,
            y1,
            depth: vec![f32::INFINITY; n],
            triangle_id: vec![BACKGROUND; n],
            edge_evals: vec![0; n],
            coverage_writes: vec![0; n],
            hiz: vec![f32::INFINITY; (hiz_columns * hiz_rows) as usize],
            hiz_columns,
            depth_lowered: false,
        }
    }

    /// The tile's pixels as an inclusive rectangle.
    pub(crate) fn rect(&self) -> crate::algorithm::PixelRect {
        crate::algorithm::PixelRect {
            x0: self.x0,
            y0: self.y0,
            x1: self.x1 - 1,
            y1: self.y1 - 1,
        }
    }

    /// Index of pixel `(x, y)` (screen coordinates) in the tile's buffers.
    #[inline(always)]
    pub fn index(&self, x: u32, y: u32) -> usize {
        ((y - self.y0) * (self.x1 - self.x0) + (x - self.x0)) as usize
    }

    /// A covered sample: count the coverage write, then the w-buffer test with
    /// depth ties going to the smaller triangle id.
    #[inline(always)]
    pub fn write(&mut self, i: usize, w: f32, id: u32) {
        self.coverage_writes[i] += 1;
        let (d, t) = (self.depth[i], self.triangle_id[i]);
        if wins_depth_test(w, id, d, t) {
            self.depth_lowered |= w < d;
            self.depth[i] = w;
            self.triangle_id[i] = id;
        }
    }

    /// The farthest stored depth over the cells that pixels `[x0, x1] × [y0, y1]`
    /// (inclusive, screen coordinates) touch.
    pub fn hiz_max(&self, x0: u32, y0: u32, x1: u32, y1: u32) -> f32 {
        let (cx0, cx1) = ((x0 - self.x0) / HIZ_CELL, (x1 - self.x0) / HIZ_CELL);
        let (cy0, cy1) = ((y0 - self.y0) / HIZ_CELL, (y1 - self.y0) / HIZ_CELL);
        let mut max = f32::NEG_INFINITY;
        for cy in cy0..=cy1 {
            for cx in cx0..=cx1 {
                max = max.max(self.hiz[(cy * self.hiz_columns + cx) as usize]);
            }
        }
        max
    }

    /// Recomputes the cells that pixels `[x0, x1] × [y0, y1]` touch, if a depth
    /// has decreased since the last update (every write between two updates
    /// falls inside the rectangle the second one names).
    pub fn update_hiz(&mut self, x0: u32, y0: u32, x1: u32, y1: u32) {
        if !std::mem::take(&mut self.depth_lowered) {
            return;
        }
        let (cx0, cx1) = ((x0 - self.x0) / HIZ_CELL, (x1 - self.x0) / HIZ_CELL);
        let (cy0, cy1) = ((y0 - self.y0) / HIZ_CELL, (y1 - self.y0) / HIZ_CELL);
        for cy in cy0..=cy1 {
            for cx in cx0..=cx1 {
                let px0 = self.x0 + cx * HIZ_CELL;
                let py0 = self.y0 + cy * HIZ_CELL;
                let mut max = f32::NEG_INFINITY;
                for y in py0..(py0 + HIZ_CELL).min(self.y1) {
                    for x in px0..(px0 + HIZ_CELL).min(self.x1) {
                        max = max.max(self.depth[self.index(x, y)]);
                    }
                }
                self.hiz[(cy * self.hiz_columns + cx) as usize] = max;
            }
        }
    }
}

impl Framebuffer {
    /// The image cut into `size × size` tiles (smaller at the right and bottom),
    /// as `(x0, y0, x1, y1)` with exclusive ends, row by row.
    pub fn tile_rects(&self, size: u32) -> Vec<(u32, u32, u32, u32)> {
        let mut rects = Vec::new();
        for y0 in (0..self.height).step_by(size as usize) {
            for x0 in (0..self.width).step_by(size as usize) {
                rects.push((
                    x0,
                    y0,
                    (x0 + size).min(self.width),
                    (y0 + size).min(self.height),
                ));
            }
        }
        rects
    }

    /// Copies a rendered tile's visibility buffers into place.
    pub fn store(&mut self, tile: &TileBuffer) {
        let w = (tile.x1 - tile.x0) as usize;
        for y in tile.y0..tile.y1 {
            let src = tile.index(tile.x0, y);
            let dst = y as usize * self.width as usize + tile.x0 as usize;
            self.depth[dst..dst + w].copy_from_slice(&tile.depth[src..src + w]);
            self.triangle_id[dst..dst + w].copy_from_slice(&tile.triangle_id[src..src + w]);
            self.edge_evals[dst..dst + w].copy_from_slice(&tile.edge_evals[src..src + w]);
            self.coverage_writes[dst..dst + w].copy_from_slice(&tile.coverage_writes[src..src + w]);
        }
    }
}
