//! The framebuffer: colour, w-buffer, triangle ids, and the two per-pixel counters
//! that explain an image — edge evaluations (work) and coverage writes
//! (watertightness: a closed mesh gives exactly one per pixel).

/// Triangle id of a pixel no triangle covers.
pub const BACKGROUND: u32 = u32::MAX;

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

    /// A covered sample: count the coverage write, then the w-buffer test. Depth
    /// ties go to the smaller triangle id, so no result depends on drawing order.
    #[inline(always)]
    pub fn write(&mut self, i: usize, w: f32, id: u32) {
        self.coverage_writes[i] += 1;
        let (d, t) = (self.depth[i], self.triangle_id[i]);
        if w < d || (w == d && id < t) {
            self.depth[i] = w;
            self.triangle_id[i] = id;
        }
    }
}
