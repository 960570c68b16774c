//! The one entry point every front end calls: `render(&PreparedScene,
//! &RenderRequest) -> RenderOutput`.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use crate::aa::AaMode;
use crate::algorithm::{self, AlgorithmId, Pipeline};
use crate::camera::{Camera, CameraError, View, Viewport};
use crate::framebuffer::Framebuffer;
use crate::precision::Precision;
use crate::prepared::PreparedScene;
use crate::request::FieldError;
use crate::shade::Shader;
use crate::shade::texture::TextureFilter;
use crate::stats::{Hashes, Stats};

/// Largest width or height a render accepts.
pub const MAX_DIMENSION: u32 = 16384;

/// What to render: which algorithm, from where, at what size.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderRequest {
    pub algorithm: AlgorithmId,
    /// Explicit oracle settings on top of the algorithm's, in the CLI's words
    /// (`outside=on,split=8,binning=off`); see [`crate::Pipeline::with_oracles`].
    pub oracles: Option<String>,
    pub camera: Camera,
    pub width: u32,
    pub height: u32,
    /// Anti-aliasing mode (sample pattern and shading rate).
    pub aa: AaMode,
    /// The number representation coverage is decided in.
    pub precision: Precision,
    /// How texture lookups are filtered (when the scene has textures).
    pub texture_filter: TextureFilter,
}

/// A request that cannot be rendered, with the field at fault.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{field}: {message}")]
pub struct RenderError {
    pub field: &'static str,
    pub message: String,
}

impl From<FieldError> for RenderError {
    fn from(e: FieldError) -> Self {
        RenderError {
            field: e.field,
            message: e.message,
        }
    }
}

impl From<CameraError> for RenderError {
    fn from(e: CameraError) -> Self {
        if e.field == "size" {
            return RenderError {
                field: "size",
                message: e.message,
            };
        }
        RenderError {
            field: "camera",
            message: format!("{}: {}", e.field, e.message),
        }
    }
}

/// Images and statistics of one render.
#[derive(Clone, Debug)]
pub struct RenderOutput {
    pub algorithm: AlgorithmId,
    /// The viewport in the CLI's words, e.g. `perspective:60`.
    pub viewport: String,
    /// The anti-aliasing mode in the CLI's words.
    pub aa: String,
    pub precision: Precision,
    pub view: View,
    pub framebuffer: Framebuffer,
    pub stats: Stats,
    pub hashes: Hashes,
}

/// The summary document of a render (the `render --json` output).
#[derive(Clone, Debug, Serialize)]
pub struct RenderSummary<'a> {
    pub scene: &'a str,
    pub algorithm: AlgorithmId,
    pub camera: &'a str,
    pub viewport: &'a str,
    pub aa: &'a str,
    pub precision: Precision,
    pub width: u32,
    pub height: u32,
    pub stats: &'a Stats,
    pub hashes: &'a Hashes,
}

impl RenderOutput {
    pub fn summary<'a>(&'a self, scene: &'a str, camera: &'a str) -> RenderSummary<'a> {
        RenderSummary {
            scene,
            algorithm: self.algorithm,
            camera,
            viewport: &self.viewport,
            aa: &self.aa,
            precision: self.precision,
            width: self.view.width,
            height: self.view.height,
            stats: &self.stats,
            hashes: &self.hashes,
        }
    }
}

/// Renders `scene` as `request` asks.
pub fn render(scene: &PreparedScene, request: &RenderRequest) -> Result<RenderOutput, RenderError> {
    render_cancellable(scene, request, &AtomicBool::new(false))
}

/// [`render`], abandoned when `cancel` becomes true (checked once per tile or
/// band of rows, so a render stops within one tile's time of being
/// cancelled): then the answer is an error naming `cancelled`.
pub fn render_cancellable(
    scene: &PreparedScene,
    request: &RenderRequest,
    cancel: &AtomicBool,
) -> Result<RenderOutput, RenderError> {
    let total = Instant::now();
    if request.width == 0
        || request.height == 0
        || request.width > MAX_DIMENSION
        || request.height > MAX_DIMENSION
    {
        return Err(RenderError {
            field: "size",
            message: format!(
                "{}x{} is out of range: width and height must be in 1..={MAX_DIMENSION}",
                request.width, request.height
            ),
        });
    }
    let view = View::new(
        &request.camera,
        request.width,
        request.height,
        scene.default_near,
    )?;
    // Every path stores every pixel through `Framebuffer::store_tiles`.
    let mut fb = Framebuffer::for_tiles(request.width, request.height);
    let mut stats = Stats::default();
    let pattern = request.aa.pattern();

    let mut pipeline = request.algorithm.pipeline();
    if let Some(text) = &request.oracles {
        pipeline = pipeline.with_oracles(text)?;
    }
    if !pipeline.serves(&view.viewport) {
        return Err(view.viewport.unsupported(request.algorithm).into());
    }
    if !request.precision.serves(request.algorithm.family()) {
        return Err(request.precision.unsupported(request.algorithm).into());
    }
    if pipeline.samples().is_some_and(|s| s.incremental) && view.viewport != Viewport::Parabolic {
        return Err(FieldError::new(
            "oracles",
            format!(
                "incremental: the double-incremental scheme serves the parabolic viewport only, not {}",
                view.viewport.kind()
            ),
        )
        .into());
    }
    if pipeline.samples().is_some_and(|s| s.incremental) && request.aa != AaMode::None {
        return Err(FieldError::new(
            "oracles",
            format!(
                "incremental: the double-incremental scheme steps along rows of pixel centres; not with aa {}",
                request.aa
            ),
        )
        .into());
    }
    let shader = Shader::new(scene, &view, request.texture_filter);
    if pipeline == Pipeline::Gpu && shader.plan().transparency {
        return Err(FieldError::new(
            "algorithm",
            "gpu-raster draws opaque surfaces only; this scene has see-through materials (opacity < 1)",
        )
        .into());
    }
    if pipeline == Pipeline::Gpu {
        render_on_gpu(scene, request, &view, &shader, &mut fb, &mut stats)?;
    } else {
        let context = algorithm::TileContext {
            view: &view,
            pattern: &pattern,
            shader,
            opacity: &scene.triangle_opacity,
            cancel,
        };
        algorithm::run(
            pipeline,
            request.precision,
            scene,
            &context,
            &mut fb,
            &mut stats,
        );
    }
    if cancel.load(Ordering::Relaxed) {
        return Err(RenderError {
            field: "cancelled",
            message: "the render was cancelled before it finished".into(),
        });
    }

    (stats.edge_evaluations, stats.max_edge_evals_per_pixel) = fb
        .edge_evals
        .par_chunks(4096)
        .map(|chunk| {
            chunk.iter().fold((0u64, 0u32), |(sum, max), &e| {
                (sum + u64::from(e), max.max(e))
            })
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1.max(b.1)));
    let pixels = u64::from(request.width) * u64::from(request.height);
    stats.samples_per_pixel = request.aa.coverage_samples();
    stats.stored_samples_per_pixel = request.aa.stored_samples();
    stats.coverage_samples = pixels * u64::from(stats.samples_per_pixel);
    let (setup_cost, sample_cost) = pipeline.instruction_costs();
    stats.predicted_instructions =
        stats.triangle_setups * setup_cost + stats.edge_evaluations * sample_cost;
    let hashes = Hashes::of(&fb);
    stats.time_ms.total = total.elapsed().as_secs_f64() * 1e3;
    Ok(RenderOutput {
        algorithm: request.algorithm,
        viewport: request.camera.viewport.to_string(),
        aa: request.aa.to_string(),
        precision: request.precision,
        view,
        framebuffer: fb,
        stats,
        hashes,
    })
}

/// Why this process cannot run `algorithm` on this machine, or `None` when it
/// can: `gpu-raster` needs the `gpu` feature and a device that renders its
/// formats (opened on first ask). Front ends list, grey out or skip what this
/// names; a render of it fails with the same message.
pub fn unavailable(algorithm: AlgorithmId) -> Option<String> {
    match algorithm.pipeline() {
        Pipeline::Gpu => gpu_unavailable(),
        _ => None,
    }
}

#[cfg(feature = "gpu")]
fn gpu_unavailable() -> Option<String> {
    crate::gpu::gpu().err().map(|e| e.to_string())
}

#[cfg(not(feature = "gpu"))]
fn gpu_unavailable() -> Option<String> {
    Some("gpu-raster needs continuum built with the `gpu` feature".into())
}

/// `gpu-raster`: one sample per pixel through the hardware pipeline.
#[cfg(feature = "gpu")]
fn render_on_gpu(
    scene: &PreparedScene,
    request: &RenderRequest,
    view: &View,
    shader: &Shader,
    fb: &mut Framebuffer,
    stats: &mut Stats,
) -> Result<(), RenderError> {
    use crate::gpu::GpuError;
    if request.aa != AaMode::None {
        return Err(FieldError::new(
            "aa",
            format!(
                "gpu-raster renders one sample per pixel; not aa {}",
                request.aa
            ),
        )
        .into());
    }
    crate::gpu::render_gpu_raster(scene, view, shader, fb, stats).map_err(|e| RenderError {
        field: match e {
            GpuError::TooLarge { .. } => "size",
            GpuError::SceneTooLarge { .. } => "scene",
            _ => "algorithm",
        },
        message: e.to_string(),
    })
}

#[cfg(not(feature = "gpu"))]
fn render_on_gpu(
    _: &PreparedScene,
    _: &RenderRequest,
    _: &View,
    _: &Shader,
    _: &mut Framebuffer,
    _: &mut Stats,
) -> Result<(), RenderError> {
    Err(RenderError {
        field: "algorithm",
        message: gpu_unavailable().unwrap_or_default(),
    })
}
