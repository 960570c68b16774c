//! The algorithms of the continuum, by stable id, and what they share.
//!
//! | id | traversal | samples |
//! |---|---|---|
//! | `2dr-brute` | all triangles | bounding box, projected 2D edges, near + guard-band clipping |
//! | `2dr-bin` | all triangles | hierarchical tiles + early-z |
//! | `2dr-scanline` | all triangles | spans: edges walked row to row, span ends by each edge's decision |
//! | `2dr-homogeneous` | all triangles | bounding box, homogeneous edges (Olano–Greer), no clipping |
//! | `3dr-brute` | all triangles | bounding box, 3D edges (paper §3.2), no projection |
//! | `3dr-bin` | all triangles | hierarchical tiles + early-z |
//! | `3dr-frustum-cull` | BVH, 256² frusta, outside culling | binning at leaves |
//! | `3dr-frustum-split` | BVH, frusta split to 8², outside + occlusion culling | per sample at leaves |
//! | `3dr-full` | as split | binning + early-z at leaves |
//! | `raycast` | CWBVH walked per ray | one sample per ray, the same 3D edges |
//! | `gpu-raster` | the wgpu hardware pipeline (feature `gpu`) | the driver's fixed-point rules |
//! | `gpu-2dr`, `gpu-2dr-homogeneous`, `gpu-3dr` | wgpu compute: setup kernel, one thread per triangle | bounding box |
//! | `gpu-3dr-binned` | wgpu compute: setup → bin → prefix sum → a workgroup per tile | tile tests, then per pixel |

mod gate;
#[cfg(feature = "gpu")]
mod gpu_compute;
mod raycast;
pub(crate) mod setup2d;
pub(crate) mod setup3d;
pub(crate) mod tiles;

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use rayon::prelude::*;

use crate::aa::SamplePattern;
use crate::binning::raster_triangle;
use crate::camera::View;
use crate::edge::{CurvedTriangle, Stored, Triangle3D64};
use crate::framebuffer::{Framebuffer, TileBuffer, TilePlanes, TileTotals};
use crate::ground::{FieldError, PixelRect};
use crate::pipeline::{EdgeKind, Pipeline, TraversalOracles};
use crate::precision::Precision;
use crate::prepared::PreparedScene;
use crate::resolve::finish_tile;
use crate::scanline::raster_spans;
use crate::screen_boxes::ScreenBoxes;
use crate::shade::Shader;
use crate::stats::{CoverageHistogram, RasterCounters, Stats};
use crate::trace::Trace;
use crate::traversal::{Setup, Traversal};
use tiles::rasterize_tiled;

/// Renders `view` of `scene` with `pipeline` at `precision` into `fb`: the
/// pixels, counters and stage times. The viewport must be one the pipeline
/// [serves](Pipeline::serves), the precision one its family computes in
/// (f64 on non-planar viewports is their f64 curved edges). Returns the
/// tiles' trace when `context` records one.
pub(crate) fn run(
    pipeline: Pipeline,
    precision: Precision,
    scene: &PreparedScene,
    context: &TileContext,
    fb: &mut Framebuffer,
    stats: &mut Stats,
) -> Result<Option<Trace>, FieldError> {
    let (view, span) = (context.view, context.pattern.span);
    let f64 = precision == Precision::F64;
    let pass = match pipeline {
        Pipeline::AllTriangles { edges, samples } => {
            let start = Instant::now();
            // One generic call per edge kind (a closure cannot be generic),
            // each triangle rasterized by the box or hierarchy of `binning`,
            // or (`spans`, straight edges) by the sweep line of `scanline`.
            macro_rules! tiles {
                ($items:expr, spans) => {
                    tiles!($items, false, |tile, tri, id, clip, n| raster_spans(
                        tile, tri, id, clip, n
                    ))
                };
                // Without early-z, a small box's samples are all the
                // kernel does there.
                ($items:expr) => {
                    tiles!($items, !samples.early_z, |tile, tri, id, clip, n| {
                        raster_triangle(tile, tri, id, clip, samples, n)
                    })
                };
                ($items:expr, $small:expr, $kernel:expr) => {
                    timed_tiles(&$items, fb, context, stats, start, $small, $kernel)
                };
            }
            let fixed = precision == Precision::Fixed;
            match edges {
                EdgeKind::TwoD if fixed && samples.spans => {
                    tiles!(setup2d::setup_2d_fixed(scene, view, span), spans)
                }
                EdgeKind::TwoD if fixed => tiles!(setup2d::setup_2d_fixed(scene, view, span)),
                EdgeKind::TwoD if samples.spans => {
                    tiles!(setup2d::setup_2d(scene, view, span), spans)
                }
                EdgeKind::TwoD => tiles!(setup2d::setup_2d(scene, view, span)),
                EdgeKind::Homogeneous => {
                    tiles!(setup3d::setup_homogeneous(scene, view, span))
                }
                EdgeKind::ThreeD if view.sphere.is_some() => {
                    let mut items = setup3d::setup_curved(scene, view, span);
                    if samples.incremental {
                        (items.triangles.iter_mut().flatten()).for_each(|t| t.incremental = true);
                    }
                    tiles!(items)
                }
                EdgeKind::ThreeD if f64 => {
                    tiles!(setup3d::setup_3d_f64(scene, view, span))
                }
                EdgeKind::ThreeD => tiles!(setup3d::setup_3d(scene, view, span)),
            }
        }
        Pipeline::Frusta(oracles) if f64 => render_frusta(
            scene,
            context,
            oracles,
            fb,
            stats,
            &(),
            setup3d::leaf_setups_3d_f64,
        ),
        Pipeline::Frusta(oracles) => {
            let shared = setup3d::slot_shared_3d(scene, view);
            render_frusta(
                scene,
                context,
                oracles,
                fb,
                stats,
                &shared,
                setup3d::leaf_setups_3d,
            )
        }
        Pipeline::Rays { packet } if view.sphere.is_some() => {
            let setup = setup3d::one_by_one(CurvedTriangle::setup);
            let setups = || setup3d::setup_slots(scene, view, span, (), setup);
            raycast::render_raycast(scene, context, packet, fb, stats, setups)
        }
        Pipeline::Rays { packet } if f64 => {
            let setup = setup3d::one_by_one(Triangle3D64::setup);
            let setups = || setup3d::setup_slots(scene, view, span, (), setup);
            raycast::render_raycast(scene, context, packet, fb, stats, setups)
        }
        Pipeline::Rays { packet } => {
            let setups = || setup3d::setup_slots_3d(scene, view, span);
            raycast::render_raycast(scene, context, packet, fb, stats, setups)
        }
        Pipeline::Gpu => render_gpu(scene, context, fb, stats)?,
        Pipeline::Compute(kind) => compute(scene, kind, context, fb, stats)?,
    };
    stats.time_ms.store += pass.store_ms;
    stats.counters = pass.counters;
    stats.coverage_histogram = pass.histogram;
    stats.edge_evaluations = pass.edge_evaluations;
    stats.max_edge_evals_per_pixel = pass.max_edge_evals;
    stats.shading_samples = pass.shading_samples;
    stats.effects = pass.effects.report(context.shader.plan(), &scene.scene);
    Ok(pass.trace)
}

/// Why the GPU algorithms cannot run in a build without the `gpu` feature.
#[cfg(not(feature = "gpu"))]
pub(crate) const NO_GPU_FEATURE: &str =
    "the GPU algorithms need continuum built with the `gpu` feature";

/// `gpu-raster`: one sample per pixel through the hardware pipeline, read
/// back and resolved by the CPU's resolve, in bands of rows in parallel as
/// the compute kernels' samples are.
#[cfg(feature = "gpu")]
fn render_gpu(
    scene: &PreparedScene,
    context: &TileContext,
    fb: &mut Framebuffer,
    stats: &mut Stats,
) -> Result<Pass, FieldError> {
    let view = context.view;
    let samples = crate::gpu::draw_gpu_raster(scene, view, stats)
        .map_err(|e| FieldError::new(e.field(), e.to_string()))?;
    let start = Instant::now();
    let pass =
        gpu_compute::resolve_bands(context, fb, |tile| copy_drawn(&samples, tile, view.width));
    let [_, resolve, shading] = pass.split(start);
    (stats.time_ms.resolve, stats.time_ms.shading) = (resolve, shading);
    Ok(pass)
}

/// The rows of `tile` from `gpu-raster`'s frame-sized read-back: triangle
/// id, depth, and the fragments drawn as coverage writes.
#[cfg(feature = "gpu")]
fn copy_drawn(samples: &crate::gpu::Samples, tile: &mut TileBuffer, width: u32) {
    let (x0, x1) = (tile.x0 as usize, tile.x1 as usize);
    for y in tile.y0..tile.y1 {
        let (from, to) = (y as usize * width as usize + x0, tile.index(tile.x0, y));
        let n = x1 - x0;
        tile.triangle_id[to..to + n].copy_from_slice(&samples.triangle_id[from..from + n]);
        tile.depth[to..to + n].copy_from_slice(&samples.depth[from..from + n]);
        tile.coverage_writes[to..to + n].copy_from_slice(&samples.fragments[from..from + n]);
    }
}

#[cfg(not(feature = "gpu"))]
fn render_gpu(
    _: &PreparedScene,
    _: &TileContext,
    _: &mut Framebuffer,
    _: &mut Stats,
) -> Result<Pass, FieldError> {
    Err(FieldError::new("algorithm", NO_GPU_FEATURE))
}

#[cfg(feature = "gpu")]
use gpu_compute::render_compute as compute;

#[cfg(not(feature = "gpu"))]
fn compute(
    _: &PreparedScene,
    _: crate::pipeline::ComputeKind,
    _: &TileContext,
    _: &mut Framebuffer,
    _: &mut Stats,
) -> Result<Pass, FieldError> {
    Err(FieldError::new("algorithm", NO_GPU_FEATURE))
}

/// The Fig. 7 traversal, one initial frustum per parallel work item, leaf
/// triangles set up by `setup`.
fn render_frusta<'a, T: Stored + Copy>(
    scene: &'a PreparedScene,
    context: &TileContext<'a>,
    oracles: TraversalOracles,
    fb: &mut Framebuffer,
    stats: &mut Stats,
    shared: &T::Shared<'a>,
    setup: Setup<'a, T>,
) -> Pass {
    let start = Instant::now();
    // Leaves box their triangles by slot.
    let boxes = ScreenBoxes::of_slots(scene, context.view);
    let boxes = &boxes;
    let mut pass = Pass::default();
    let size = [oracles.frustum; 2];
    let done = context.run_tiles(&mut pass, fb, size, |_, leaves, tile| {
        let how = (setup, shared, boxes);
        let mut t = Traversal::new(scene, context.view, oracles, tile, how, leaves);
        t.run();
        (t.counters, t.nodes_visited, t.setups)
    });
    pass.add(done.into_iter().map(|finished| {
        let (counters, nodes, setups) = finished.result;
        stats.bvh_nodes_visited += nodes;
        stats.triangle_setups += setups;
        finished.map(|_| counters)
    }));
    let [traversal, resolve, shading] = pass.split(start);
    stats.time_ms.traversal = traversal;
    (stats.time_ms.resolve, stats.time_ms.shading) = (resolve, shading);
    pass
}

fn timed_tiles<T: Stored>(
    items: &tiles::Setups<T>,
    fb: &mut Framebuffer,
    context: &TileContext,
    stats: &mut Stats,
    start: Instant,
    small: bool,
    kernel: impl Fn(&mut TileBuffer, &T::Bound<'_>, u32, PixelRect, &mut RasterCounters) + Sync,
) -> Pass {
    stats.time_ms.setup = start.elapsed().as_secs_f64() * 1e3;
    let start = Instant::now();
    let pass = rasterize_tiled(items, fb, context, small, kernel);
    stats.triangle_setups = items.placed();
    let [coverage, resolve, shading] = pass.split(start);
    stats.time_ms.coverage = coverage;
    (stats.time_ms.resolve, stats.time_ms.shading) = (resolve, shading);
    pass
}

/// What every tile worker needs besides its own work: where samples lie and
/// how to shade them.
#[derive(Debug)]
pub(crate) struct TileContext<'a> {
    pub view: &'a View,
    pub pattern: &'a SamplePattern,
    pub shader: Shader<'a>,
    /// Opacity per triangle id (empty: every triangle opaque).
    pub opacity: &'a [f32],
    /// Set by the caller to abandon the render: tiles not yet started are
    /// neither rendered nor resolved (checked once per tile or band).
    pub cancel: &'a std::sync::atomic::AtomicBool,
    /// Record each tile's [`Trace`].
    pub trace: bool,
    /// Keep the nearest sample (off: the GPU compute kernels' §5 mode).
    #[cfg_attr(
        not(feature = "gpu"),
        expect(dead_code, reason = "read by the GPU compute kernels only")
    )]
    pub depth_test: bool,
}

/// A tile rendered and resolved by one worker, with what its rendering returned.
#[derive(Debug)]
pub(crate) struct Finished<R> {
    pub totals: TileTotals,
    pub result: R,
    /// Edge tests decided past f32 while rendering, `[f64 + exact, exact]`.
    pub precise: [u64; 2],
    /// Worker seconds spent rendering, resolving and shading.
    pub seconds: [f64; 3],
    /// What rendering did, when the context records it.
    pub trace: Option<Trace>,
}

impl<R> Finished<R> {
    fn map<S>(self, f: impl FnOnce(R) -> S) -> Finished<S> {
        Finished {
            totals: self.totals,
            result: f(self.result),
            precise: self.precise,
            seconds: self.seconds,
            trace: self.trace,
        }
    }
}

impl<'a> TileContext<'a> {
    /// Renders the pixels of `planes.rect` with `render`, then resolves and
    /// shades their samples straight into the frame's `planes`. The sample
    /// buffers are `cache`'s, reused from the worker's previous tile when
    /// there is one (no fresh pages to fault in per tile).
    fn run_tile<R: Default>(
        &self,
        cache: &mut Option<TileBuffer<'a>>,
        mut planes: TilePlanes,
        render: impl FnOnce(&mut TileBuffer<'a>) -> R,
    ) -> Finished<R> {
        // A cancelled render neither renders nor resolves what is left (its
        // frame is not returned).
        if self.cancel.load(std::sync::atomic::Ordering::Relaxed) {
            return Finished {
                totals: TileTotals::default(),
                result: R::default(),
                precise: [0; 2],
                seconds: [0.0; 3],
                trace: None,
            };
        }
        let start = Instant::now();
        let tile = match cache {
            Some(tile) => {
                tile.reset(planes.rect);
                tile
            }
            None => cache.insert(TileBuffer::new(planes.rect, self.pattern, self.opacity)),
        };
        if self.trace {
            let mut trace = Trace::default();
            trace.tiles.push(planes.rect);
            tile.trace = Some(trace);
        }
        let precise = crate::edge::precise_tests();
        let result = render(tile);
        let trace = tile.trace.take();
        let precise_after = crate::edge::precise_tests();
        let rendered = start.elapsed().as_secs_f64();
        let (totals, [resolved, shaded]) = finish_tile(tile, self.view, &self.shader, &mut planes);
        Finished {
            totals,
            result,
            precise: [0, 1].map(|k| precise_after[k] - precise[k]),
            seconds: [rendered, resolved, shaded],
            trace,
        }
    }

    /// Renders every tile of `size` pixels ([`Framebuffer::tile_rects`]) with
    /// `render` (given the tile's index, its worker's `W`, and its sample
    /// buffers) and resolves it into `fb`'s planes; returns the finished tiles
    /// in the grid's order. One worker per thread of
    /// the pool, at most one per core at once (a [`gate::Gate`]), takes the
    /// next tile from a shared counter until none is left, keeping its tile
    /// buffers and its `W` (a traversal's leaf cache) from one tile to the
    /// next: made once per worker and frame, however the pool is split.
    /// (rayon's `map_init` makes them once per split, and a pool of more
    /// threads than cores splits a frame nearly once per tile.)
    pub fn run_tiles<W: Default, R: Default + Send>(
        &self,
        pass: &mut Pass,
        fb: &mut Framebuffer,
        size: [u32; 2],
        render: impl Fn(usize, &mut W, &mut TileBuffer<'a>) -> R + Sync,
    ) -> Vec<Finished<R>> {
        let planes: Vec<_> = pass
            .planes(fb, size)
            .into_iter()
            .map(|p| Mutex::new(Some(p)))
            .collect();
        let next = AtomicUsize::new(0);
        let workers = rayon::current_num_threads().min(planes.len());
        let gate = gate::Gate::new(gate::cores());
        let worker = |_| {
            // No more workers render at once than there are cores; the rest
            // wait here, and find no tile left when let in.
            let _place = gate.enter();
            let (mut cache, mut mine) = (None, W::default());
            let mut done = Vec::new();
            loop {
                let t = next.fetch_add(1, Ordering::Relaxed);
                let Some(slot) = planes.get(t) else {
                    return done;
                };
                // Each index is taken once: the lock is never contended, and
                // the slot still holds its planes.
                let taken = slot.lock().unwrap_or_else(|e| e.into_inner()).take();
                let Some(planes) = taken else {
                    continue;
                };
                done.push((
                    t,
                    self.run_tile(&mut cache, planes, |tile| render(t, &mut mine, tile)),
                ));
            }
        };
        let mut done: Vec<_> = (0..workers)
            .into_par_iter()
            .with_max_len(1)
            .flat_map_iter(worker)
            .collect();
        done.sort_unstable_by_key(|&(t, _)| t);
        done.into_iter().map(|(_, finished)| finished).collect()
    }
}

/// The totals of one parallel pass over tiles.
#[derive(Debug, Default)]
pub(crate) struct Pass {
    pub counters: RasterCounters,
    pub histogram: CoverageHistogram,
    /// Sample-against-triangle tests over all tiles, and the most at one pixel.
    pub edge_evaluations: u64,
    pub max_edge_evals: u32,
    pub shading_samples: u64,
    pub effects: crate::effects::EffectCounters,
    /// Worker seconds rendering, resolving and shading, over all tiles.
    seconds: [f64; 3],
    /// Milliseconds spent cutting the frame into tiles.
    store_ms: f64,
    /// The tiles' traces, when recorded.
    pub trace: Option<Trace>,
}

impl Pass {
    /// The frame's planes cut into tiles of `size` pixels (the time it
    /// takes counted as the frame's `store`).
    pub fn planes<'f>(&mut self, fb: &'f mut Framebuffer, size: [u32; 2]) -> Vec<TilePlanes<'f>> {
        let start = Instant::now();
        let planes = fb.tile_planes(size);
        self.store_ms += start.elapsed().as_secs_f64() * 1e3;
        planes
    }

    /// Adds up the finished tiles' counters.
    pub fn add(&mut self, finished: impl IntoIterator<Item = Finished<RasterCounters>>) {
        for finished in finished {
            self.counters += finished.result;
            self.counters.edge_tests_f64 += finished.precise[0];
            self.counters.edge_tests_exact += finished.precise[1];
            self.histogram += finished.totals.histogram;
            self.edge_evaluations += finished.totals.edge_evaluations;
            self.max_edge_evals = self.max_edge_evals.max(finished.totals.max_edge_evals);
            self.shading_samples += finished.totals.shading_samples;
            self.effects.add(&finished.totals.effects);
            for (sum, s) in self.seconds.iter_mut().zip(finished.seconds) {
                *sum += s;
            }
            if let Some(trace) = finished.trace {
                self.trace.get_or_insert_with(Trace::default).append(trace);
            }
        }
    }

    /// The wall time since `start`, less the cutting into tiles, split into
    /// rendering, resolving and shading in proportion to the worker time
    /// each took (workers do all three, tile by tile), in milliseconds.
    pub fn split(&self, start: Instant) -> [f64; 3] {
        let wall_ms = start.elapsed().as_secs_f64() * 1e3 - self.store_ms;
        let busy: f64 = self.seconds.iter().sum();
        if busy <= 0.0 {
            return [wall_ms, 0.0, 0.0];
        }
        self.seconds.map(|s| wall_ms * s / busy)
    }
}
