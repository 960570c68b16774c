//! What a render did and what it cost: per-stage wall times, counters, the
//! coverage histogram and hashes of the result buffers.

use serde::{Deserialize, Serialize};

/// Wall time of each stage of one render, in milliseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StageTimes {
    /// Triangle setup (transform, clip, bounds, edge coefficients) and binning into bands.
    pub setup: f64,
    /// Scene traversal (the ray caster's BVH walk, leaf tests included).
    pub traversal: f64,
    /// Per-sample coverage and depth tests over bounding boxes.
    pub coverage: f64,
    /// The resolve: each pixel's samples into the frame (depth, triangle id,
    /// per-pixel counters, sample digests, the coverage histogram).
    pub resolve: f64,
    /// Shading of visible samples, the box filter and the sRGB encode.
    pub shading: f64,
    /// The frame around the algorithm: its planes taken and cut into tiles,
    /// and the finished frame's totals. (Not its hashes:
    /// `RenderOutput::hashes` takes them when asked, off the clock.)
    pub store: f64,
    /// The whole render; the stages above add up to it, less the few
    /// microseconds that set up the view and the shader.
    pub total: f64,
}

/// How many stored samples got zero, one, or more coverage writes. On a closed
/// mesh seen from inside (or a plane filling the screen) every sample must be in
/// `one`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct CoverageHistogram {
    pub zero: u64,
    pub one: u64,
    pub many: u64,
}

impl std::ops::AddAssign for CoverageHistogram {
    fn add_assign(&mut self, o: CoverageHistogram) {
        self.zero += o.zero;
        self.one += o.one;
        self.many += o.many;
    }
}

impl CoverageHistogram {
    #[inline]
    pub fn of(coverage_writes: &[u32]) -> CoverageHistogram {
        let mut h = CoverageHistogram::default();
        // Counted without a branch per pixel, in u32 that cannot overflow
        // (the counts vectorize).
        for chunk in coverage_writes.chunks(1 << 16) {
            let (mut zero, mut one) = (0u32, 0u32);
            for &c in chunk {
                zero += u32::from(c == 0);
                one += u32::from(c == 1);
            }
            h.zero += u64::from(zero);
            h.one += u64::from(one);
        }
        h.many = coverage_writes.len() as u64 - h.zero - h.one;
        h
    }
}

/// Counters and timings returned by every render.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Stats {
    pub time_ms: StageTimes,
    /// Triangles whose edge functions were set up (2D: clipped sub-triangles;
    /// BVH traversals: the triangles of a node's leaves whose boxes meet the
    /// frustum that rasterizes the first of them, set up together, some of
    /// which a later occlusion test may spare from rasterization).
    pub triangle_setups: u64,
    /// Sample-against-triangle evaluations of the three edge functions: per-sample
    /// coverage tests, the four corner samples of every binning tile test, and the
    /// samples of tiles accepted whole (their barycentrics still get evaluated).
    pub edge_evaluations: u64,
    /// BVH nodes whose children were tested against a ray.
    pub bvh_nodes_visited: u64,
    /// Coverage positions per pixel (`C` of the anti-aliasing mode; 1 without).
    pub samples_per_pixel: u32,
    /// Positions per pixel that keep depth and triangle id (`S`).
    pub stored_samples_per_pixel: u32,
    /// Coverage samples of the image: pixels × `samples_per_pixel`.
    pub coverage_samples: u64,
    /// Shading evaluations (SSAA: one per covered sample; MSAA and CSAA: one per
    /// pixel per triangle it shows).
    pub shading_samples: u64,
    pub coverage_histogram: CoverageHistogram,
    /// Largest per-pixel edge-evaluation count (the top of the heat map's scale).
    pub max_edge_evals_per_pixel: u32,
    /// Binning, early-z and traversal counters.
    #[serde(flatten)]
    pub counters: RasterCounters,
    /// The paper's Fig. 10 model: setups × setup cost + edge evaluations × per-sample
    /// cost (2D 72/14, homogeneous 73/14, 3D 57/12 scalar instructions).
    pub predicted_instructions: u64,
    /// Heap bytes of the prepared scene (mesh, per-triangle data, BVH,
    /// textures) per triangle, after this render built what it needs.
    pub scene_bytes_per_triangle: f64,
    /// The effects the scene called for and what each cost (empty when it
    /// calls for none).
    pub effects: Vec<crate::effects::EffectStats>,
    /// The GPU compute algorithms: the device's own time per stage.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gpu: Option<GpuTimes>,
}

/// Per stage of a GPU compute render, the device's time in milliseconds and
/// how it was measured.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct GpuTimes {
    /// The adapter's name, driver and backend.
    pub adapter: String,
    /// `timestamps` (the adapter's timestamp queries around each pass) or
    /// `wall` (host time from submit to a finished device poll).
    pub clock: String,
    pub setup: f64,
    pub binning: f64,
    pub raster: f64,
    /// Copy to host-visible memory, map and read (host wall time).
    pub readback: f64,
    /// How visibility was kept: `64-bit` (one atomic per sample),
    /// `32-bit two-pass`, or `none (registers)` (binned: a thread per pixel).
    pub atomics: String,
}

/// Hex xxh3-64 hashes of the result buffers (little-endian bytes), for comparing
/// renders without shipping images.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Hashes {
    pub triangle_id: String,
    pub color: String,
    /// Every sample's triangle id (with anti-aliasing, the per-pixel sample
    /// digests; without, the same as `triangle_id`).
    pub samples: String,
}

/// Counters of the hierarchical stages (binning, early-z, the BVH traversal).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct RasterCounters {
    /// Blocks tested against a triangle's edge functions at their corners.
    pub tiles_tested: u64,
    /// Blocks found wholly inside (filled without per-sample tests).
    pub tiles_accepted: u64,
    /// Blocks found wholly outside.
    pub tiles_rejected: u64,
    /// Blocks the test could not decide, refined into four.
    pub tiles_refined: u64,
    /// Refined blocks that turned out to hold no sample the triangle covers
    /// (needless refinements; with early-z, also blocks it then found hidden).
    pub tiles_refined_empty: u64,
    /// Blocks (or boxes) skipped because the hierarchical w-buffer hides them.
    pub early_z_rejects: u64,
    /// Frusta the traversal created (the initial ones included).
    pub frusta_created: u64,
    /// Frusta that were split into four.
    pub frusta_split: u64,
    /// BVH nodes culled because they lie outside the frustum.
    pub nodes_culled_outside: u64,
    /// BVH nodes culled because the hierarchical w-buffer hides them.
    pub nodes_culled_occluded: u64,
    /// Leaf triangles a frustum rasterized that an earlier frustum of the
    /// same work item had rasterized and the worker's leaf cache still held
    /// (their setup reused, not counted again in `triangle_setups`).
    pub leaf_setups_reused: u64,
    /// Runs of pixels (one per pixel row a triangle reaches) that the span
    /// traversal (`2dr-scanline`) found covered.
    pub spans: u64,
    /// Single-edge decisions the span traversal made to find where its spans
    /// start and end (the corrections to each edge's walked crossing).
    pub edge_steps: u64,
    /// 3D (and homogeneous) edge tests within the f32 rounding bound of
    /// zero, decided again in f64 (README: "Precision and exactness").
    pub edge_tests_f64: u64,
    /// Of those, the ones f64 could not decide either: decided exactly.
    pub edge_tests_exact: u64,
}

impl std::ops::AddAssign for RasterCounters {
    fn add_assign(&mut self, o: RasterCounters) {
        self.tiles_tested += o.tiles_tested;
        self.tiles_accepted += o.tiles_accepted;
        self.tiles_rejected += o.tiles_rejected;
        self.tiles_refined += o.tiles_refined;
        self.tiles_refined_empty += o.tiles_refined_empty;
        self.early_z_rejects += o.early_z_rejects;
        self.frusta_created += o.frusta_created;
        self.frusta_split += o.frusta_split;
        self.nodes_culled_outside += o.nodes_culled_outside;
        self.nodes_culled_occluded += o.nodes_culled_occluded;
        self.leaf_setups_reused += o.leaf_setups_reused;
        self.spans += o.spans;
        self.edge_steps += o.edge_steps;
        self.edge_tests_f64 += o.edge_tests_f64;
        self.edge_tests_exact += o.edge_tests_exact;
    }
}

#[cfg(test)]
mod tests {
    use super::CoverageHistogram;

    #[test]
    fn the_coverage_histogram_counts_zero_one_and_many_across_chunks() {
        // Longer than one 2¹⁶ chunk, with a known count of each kind.
        let writes: Vec<u32> = (0..200_003u32)
            .map(|i| [0, 1, 1, 2, 7, u32::MAX][i as usize % 6])
            .collect();
        let expect = |kind: &[u32]| writes.iter().filter(|c| kind.contains(c)).count() as u64;
        let h = CoverageHistogram::of(&writes);
        assert_eq!(
            h,
            CoverageHistogram {
                zero: expect(&[0]),
                one: expect(&[1]),
                many: expect(&[2, 7, u32::MAX]),
            }
        );
        assert_eq!(h.zero + h.one + h.many, 200_003);
        assert_eq!(CoverageHistogram::of(&[]), CoverageHistogram::default());
    }
}
