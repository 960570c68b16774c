//! Floor 2: a render request, typed — what every front end's words become
//! (through `RenderWords`) and what `render` takes.

use crate::aa::AaMode;
use crate::camera::Camera;
use crate::ground::AlgorithmId;
use crate::pipeline::Oracles;
use crate::precision::Precision;
use crate::texture::TextureFilter;

/// What to render: which algorithm, from where, at what size. Front ends
/// make one from a user's words through `RenderWords`; code makes
/// one with [`RenderRequest::new`] and changes the fields it cares about.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderRequest {
    pub algorithm: AlgorithmId,
    /// Explicit oracle settings on top of the algorithm's.
    pub oracles: Oracles,
    pub camera: Camera,
    pub width: u32,
    pub height: u32,
    /// Anti-aliasing mode (sample pattern and shading rate).
    pub aa: AaMode,
    /// The number representation coverage is decided in.
    pub precision: Precision,
    /// How texture lookups are filtered (when the scene has textures).
    pub texture_filter: TextureFilter,
    /// Record what the algorithm does ([`crate::Trace`]: tiles, binning's
    /// blocks, frusta, BVH nodes) for overlays; off, nothing is recorded.
    pub trace: bool,
    /// Keep the nearest sample (on, the default). Off — the paper's §5 GPU
    /// experiment, "we disabled depth-buffering and output all results
    /// colour-coded" — each sample keeps the smallest id covering it, with
    /// that triangle's depth; only the GPU compute algorithms render so.
    pub depth_test: bool,
    /// Write the per-pixel counters (`Framebuffer::edge_evals` and
    /// `coverage_writes`, what heat maps and the watertightness checks read)
    /// into the frame: on, the default. Off, the frame holds colours, depths
    /// and ids alone (the counters' planes are empty) and the counters reach
    /// only their totals in `Stats`, which are the same either way: what
    /// `compare` times, as a renderer writes no diagnostic planes unasked.
    pub counter_planes: bool,
}

impl RenderRequest {
    /// `algorithm` through `camera` at `width × height`: no oracle settings,
    /// no anti-aliasing, f32, the default texture filter.
    pub fn new(algorithm: AlgorithmId, camera: Camera, width: u32, height: u32) -> RenderRequest {
        RenderRequest {
            algorithm,
            oracles: Oracles::default(),
            camera,
            width,
            height,
            aa: AaMode::None,
            precision: Precision::F32,
            texture_filter: TextureFilter::default(),
            trace: false,
            depth_test: true,
            counter_planes: true,
        }
    }
}
