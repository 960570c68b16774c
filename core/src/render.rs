//! Floor 9: the one entry point every front end calls: `render(&PreparedScene,
//! &RenderRequest) -> RenderOutput`.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use serde::Serialize;

use crate::algorithm;
use crate::camera::View;
use crate::capability::pipeline_for;
use crate::framebuffer::{Framebuffer, Optional};
use crate::ground::{AlgorithmId, FieldError};
use crate::precision::Precision;
use crate::prepared::PreparedScene;
use crate::request::RenderRequest;
use crate::shade::Shader;
use crate::stats::{Hashes, Stats};
use crate::trace::Trace;

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
    /// What the algorithm did, when the request asked ([`RenderRequest::trace`]).
    pub trace: Option<Trace>,
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
    pub hashes: Hashes,
}

impl RenderOutput {
    /// The hashes of the frame's ids, colours and samples, computed when
    /// asked: they check a render, they are not a part of it, so the render's
    /// clock ([`Stats::time_ms`]) does not run while they are taken (at 1080p
    /// they read 16 MB that the resolve wrote past the cache).
    pub fn hashes(&self) -> Hashes {
        Hashes::of(&self.framebuffer)
    }

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
            hashes: self.hashes(),
        }
    }
}

/// Renders `scene` as `request` asks.
pub fn render(scene: &PreparedScene, request: &RenderRequest) -> Result<RenderOutput, FieldError> {
    render_cancellable(scene, request, &AtomicBool::new(false))
}

/// [`render`], abandoned when `cancel` becomes true (checked once per tile or
/// band of rows, so a render stops within one tile's time of being
/// cancelled): then the answer is an error naming `cancelled`.
pub fn render_cancellable(
    scene: &PreparedScene,
    request: &RenderRequest,
    cancel: &AtomicBool,
) -> Result<RenderOutput, FieldError> {
    let total = Instant::now();
    let pipeline = pipeline_for(request, Some(scene))?;
    let view = View::new(
        &request.camera,
        request.width,
        request.height,
        scene.default_near,
    )?;
    let mut stats = Stats::default();
    let pattern = request.aa.pattern();
    let context = algorithm::TileContext {
        view: &view,
        pattern: &pattern,
        shader: Shader::new(scene, &view, request.texture_filter),
        opacity: &scene.triangle_opacity,
        cancel,
        trace: request.trace,
        depth_test: request.depth_test,
    };
    // Every path resolves every pixel through `Framebuffer::tile_planes`.
    let start = Instant::now();
    let optional = Optional {
        counters: request.counter_planes,
        digest: pattern.coverage() > 1,
        blended: context.shader.plan().transparency,
    };
    let mut fb = Framebuffer::for_tiles(request.width, request.height, optional);
    stats.time_ms.store = start.elapsed().as_secs_f64() * 1e3;
    let trace = algorithm::run(
        pipeline,
        request.precision,
        scene,
        &context,
        &mut fb,
        &mut stats,
    )?;
    if cancel.load(Ordering::Relaxed) {
        return Err(FieldError::new(
            "cancelled",
            "the render was cancelled before it finished",
        ));
    }

    let start = Instant::now();
    let pixels = u64::from(request.width) * u64::from(request.height);
    stats.samples_per_pixel = request.aa.coverage_samples();
    stats.stored_samples_per_pixel = request.aa.stored_samples();
    stats.coverage_samples = pixels * u64::from(stats.samples_per_pixel);
    let (setup_cost, sample_cost) = pipeline.instruction_costs();
    stats.predicted_instructions =
        stats.triangle_setups * setup_cost + stats.edge_evaluations * sample_cost;
    stats.scene_bytes_per_triangle = scene.bytes() as f64 / scene.triangle_count().max(1) as f64;
    stats.time_ms.store += start.elapsed().as_secs_f64() * 1e3;
    stats.time_ms.total = total.elapsed().as_secs_f64() * 1e3;
    Ok(RenderOutput {
        algorithm: request.algorithm,
        viewport: request.camera.viewport.to_string(),
        aa: request.aa.to_string(),
        precision: request.precision,
        view,
        framebuffer: fb,
        stats,
        trace,
    })
}
