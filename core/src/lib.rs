//! continuum: one renderer for the road between rasterization and ray casting.
//!
//! It follows "3D Rasterization: A Bridge between Rasterization and Ray Casting"
//! (Davidovič et al., GI 2012). Coverage is decided by edge functions — projected
//! 2D ones, or the paper's 3D (Plücker) ones — and the algorithms differ only in
//! how they enumerate triangles and samples. Every front end turns a user's
//! words into a request through [`RenderWords`] and calls [`render()`]:
//!
//! ```no_run
//! use continuum::{AlgorithmId, PreparedScene, RenderRequest, render};
//! let scene = continuum::scene::load_path("scenes/bunny.toml".as_ref()).unwrap();
//! let prepared = PreparedScene::new(scene);
//! let camera = prepared.scene.first_camera();
//! let request = RenderRequest::new(AlgorithmId::ThreeDBrute, camera, 640, 480);
//! let out = render(&prepared, &request).unwrap();
//! println!("{}", out.hashes().triangle_id);
//! ```
//!
//! # Floors
//! The modules below are declared floor by floor, lowest first, and a module
//! imports only modules declared before it (`scripts/floors.py`, run by CI,
//! fails on a back edge or a cycle). ARCHITECTURE.md draws the floors.

// floors: lowest first; a module imports only modules declared above it.
// Floor 0 — vocabulary: the one error type, rectangles, ids, boxes; lanes;
// copies past the cache.
mod ground;
pub mod mesa;
mod simd;
mod stream;
// Floor 1 — settings a request names.
mod aa;
mod color;
mod precision;
mod viewport;
mod pipeline;
pub mod draw;
// Floor 2 — geometry and scenes.
mod camera;
pub mod scene;
mod effects;
mod texture;
mod request;
mod clip;
// Floor 3 — edge functions.
mod edge;
// Floor 4 — the BVH.
mod bvh;
// Floor 5 — the prepared scene.
mod prepared;
// Floor 6 — frame buffers, statistics, images of them, screen boxes.
mod stats;
mod trace;
mod hiz;
mod framebuffer;
pub mod maps;
pub mod metrics;
mod screen_boxes;
// Floor 7 — the stages: shading, binning, traversal, the anti-aliasing resolve.
mod shade;
mod binning;
mod scanline;
mod traversal;
mod resolve;
// Floor 8 — the algorithms (the GPU's among them) and their one dispatch.
#[cfg(feature = "gpu")]
mod gpu;
mod algorithm;
// Floor 9 — what may be rendered, the words a user types, the entry point;
// kernels for benches and tests.
mod capability;
mod words;
mod render;
mod overlay;
pub mod internal;

pub use aa::AaMode;
pub use camera::{Camera, View, pixel_center};
pub use capability::{check, choose_gpu_adapter, force_gpu_two_pass, gpu_adapter, unavailable};
pub use color::{BACKGROUND_COLOR, decode_srgb};
pub use effects::EffectStats;
pub use framebuffer::{BACKGROUND, Framebuffer};
pub use ground::{AlgorithmId, Bounds, Family, FieldError, MAX_DIMENSION, UnknownAlgorithm};
pub use overlay::{LEGEND as OVERLAY_LEGEND, draw_overlays};
pub use pipeline::Oracles;
pub use precision::Precision;
pub use prepared::PreparedScene;
pub use render::{RenderOutput, RenderSummary, render, render_cancellable};
pub use request::RenderRequest;
pub use scene::{Scene, SceneError};
pub use simd::{Isa, isa};
pub use stats::{CoverageHistogram, GpuTimes, Hashes, RasterCounters, StageTimes, Stats};
pub use texture::TextureFilter;
pub use trace::{BlockOutcome, FrustumEvent, NodeOutcome, Overlays, Trace};
pub use viewport::Viewport;
pub use words::{
    CameraSpec, DEFAULT_SIZE, ExplicitCamera, RenderWords, Settings, parse_algorithm, parse_size,
};
