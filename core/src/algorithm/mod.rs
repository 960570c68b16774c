//! The algorithms of the continuum, by stable id, and what they share.
//!
//! | id | traversal | samples |
//! |---|---|---|
//! | `2dr-brute` | all triangles | bounding box, projected 2D edges, near + guard-band clipping |
//! | `2dr-bin` | all triangles | hierarchical tiles + early-z |
//! | `2dr-homogeneous` | all triangles | bounding box, homogeneous edges (Olano–Greer), no clipping |
//! | `3dr-brute` | all triangles | bounding box, 3D edges (paper §3.2), no projection |
//! | `3dr-bin` | all triangles | hierarchical tiles + early-z |
//! | `3dr-frustum-cull` | BVH, 256² frusta, outside culling | binning at leaves |
//! | `3dr-frustum-split` | BVH, frusta split to 8², outside + occlusion culling | per sample at leaves |
//! | `3dr-full` | as split | binning + early-z at leaves |
//! | `raycast` | CWBVH walked per ray | one sample per ray, the same 3D edges |
//! | `gpu-raster` | the wgpu hardware pipeline (feature `gpu`) | the driver's fixed-point rules |

mod raycast;
pub(crate) mod screen_boxes;
pub(crate) mod setup2d;
pub(crate) mod setup3d;
pub(crate) mod tiles;

use std::fmt;
use std::str::FromStr;
use std::time::Instant;

use rayon::prelude::*;
use serde::{Serialize, Serializer};

pub use crate::binning::SampleOracles;

use crate::aa::resolve::resolve_tile;
use crate::aa::{SamplePattern, SampleSpan};
use crate::camera::{View, Viewport};
use crate::edge::{CurvedTriangle, Triangle3D, Triangle3D64};
use crate::framebuffer::{Framebuffer, ResolvedTile, TileBuffer};
use crate::precision::Precision;
use crate::prepared::PreparedScene;
use crate::request::FieldError;
use crate::shade::Shader;
use crate::stats::{CoverageHistogram, RasterCounters, Stats};
use crate::traversal::{Setup, Traversal, TraversalOracles};
use tiles::rasterize_tiled;

/// Which algorithm renders a request. The string forms are stable ids.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AlgorithmId {
    /// Project, clip, 2D edge functions over the bounding box (the paper's reference).
    TwoDBrute,
    /// 2D edge functions with hierarchical tile tests and early-z.
    TwoDBin,
    /// Olano–Greer homogeneous 2D rasterization, no clipping.
    TwoDHomogeneous,
    /// 3D edge functions over the bounding box, no projection.
    ThreeDBrute,
    /// 3D edge functions with hierarchical tile tests and early-z.
    ThreeDBin,
    /// BVH frustum culling with 256² frusta, binning at leaves.
    ThreeDFrustumCull,
    /// Frusta split down to 8², occlusion culling, per-sample tests at leaves.
    ThreeDFrustumSplit,
    /// Splitting and occlusion culling, then binning with early-z.
    ThreeDFull,
    /// One ray per sample through the BVH, hits decided by the 3D edge functions.
    Raycast,
    /// The wgpu hardware pipeline (lavapipe without a GPU): reference and peer.
    GpuRaster,
}

/// The family an algorithm belongs to: within a family results agree bit for bit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Family {
    /// Projected 2D edge functions.
    #[serde(rename = "2d")]
    TwoD,
    /// Homogeneous 2D edge functions.
    #[serde(rename = "homogeneous")]
    Homogeneous,
    /// 3D edge functions (rasterizers and the ray caster).
    #[serde(rename = "3d")]
    ThreeD,
    /// The GPU's own rasterizer.
    #[serde(rename = "gpu")]
    Gpu,
}

/// Which edge functions an all-triangles pipeline sets up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeKind {
    TwoD,
    Homogeneous,
    ThreeD,
}

/// A point of the continuum: how triangles and samples are enumerated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pipeline {
    /// Every triangle, samples by bounding box or binning.
    AllTriangles {
        edges: EdgeKind,
        samples: SampleOracles,
    },
    /// The Fig. 7 traversal of frusta through the BVH.
    Frusta(TraversalOracles),
    /// One ray per sample through the BVH.
    Rays,
    /// The GPU's hardware pipeline.
    Gpu,
}

impl AlgorithmId {
    /// Every algorithm: the CPU ones and `gpu-raster`.
    pub const ALL: [AlgorithmId; 10] = [
        AlgorithmId::TwoDBrute,
        AlgorithmId::TwoDBin,
        AlgorithmId::TwoDHomogeneous,
        AlgorithmId::ThreeDBrute,
        AlgorithmId::ThreeDBin,
        AlgorithmId::ThreeDFrustumCull,
        AlgorithmId::ThreeDFrustumSplit,
        AlgorithmId::ThreeDFull,
        AlgorithmId::Raycast,
        AlgorithmId::GpuRaster,
    ];

    /// The algorithms continuum computes itself, on the CPU: within each family
    /// their results agree bit for bit.
    pub const CPU: [AlgorithmId; 9] = [
        AlgorithmId::TwoDBrute,
        AlgorithmId::TwoDBin,
        AlgorithmId::TwoDHomogeneous,
        AlgorithmId::ThreeDBrute,
        AlgorithmId::ThreeDBin,
        AlgorithmId::ThreeDFrustumCull,
        AlgorithmId::ThreeDFrustumSplit,
        AlgorithmId::ThreeDFull,
        AlgorithmId::Raycast,
    ];

    pub fn as_str(self) -> &'static str {
        match self {
            AlgorithmId::TwoDBrute => "2dr-brute",
            AlgorithmId::TwoDBin => "2dr-bin",
            AlgorithmId::TwoDHomogeneous => "2dr-homogeneous",
            AlgorithmId::ThreeDBrute => "3dr-brute",
            AlgorithmId::ThreeDBin => "3dr-bin",
            AlgorithmId::ThreeDFrustumCull => "3dr-frustum-cull",
            AlgorithmId::ThreeDFrustumSplit => "3dr-frustum-split",
            AlgorithmId::ThreeDFull => "3dr-full",
            AlgorithmId::Raycast => "raycast",
            AlgorithmId::GpuRaster => "gpu-raster",
        }
    }

    pub fn family(self) -> Family {
        match self {
            AlgorithmId::TwoDBrute | AlgorithmId::TwoDBin => Family::TwoD,
            AlgorithmId::TwoDHomogeneous => Family::Homogeneous,
            AlgorithmId::GpuRaster => Family::Gpu,
            _ => Family::ThreeD,
        }
    }

    /// One line on what it does, for listings.
    pub fn description(self) -> &'static str {
        match self {
            AlgorithmId::TwoDBrute => {
                "2D rasterization: project, clip, 2D edge functions over each bounding box"
            }
            AlgorithmId::TwoDBin => {
                "2D rasterization with hierarchical tile tests and early-z (hierarchical w-buffer)"
            }
            AlgorithmId::TwoDHomogeneous => "Olano-Greer homogeneous 2D rasterization, no clipping",
            AlgorithmId::ThreeDBrute => {
                "3D rasterization: 3D edge functions over each bounding box, no projection"
            }
            AlgorithmId::ThreeDBin => "3D rasterization with hierarchical tile tests and early-z",
            AlgorithmId::ThreeDFrustumCull => {
                "BVH frustum culling with 256x256-pixel frusta, binning at leaves"
            }
            AlgorithmId::ThreeDFrustumSplit => {
                "frusta split down to 8x8 pixels, occlusion culling, per-sample tests at leaves"
            }
            AlgorithmId::ThreeDFull => {
                "frustum splitting and occlusion culling, then binning with early-z"
            }
            AlgorithmId::Raycast => {
                "ray casting through a CWBVH, hits decided by the same 3D edge functions"
            }
            AlgorithmId::GpuRaster => {
                "the GPU's hardware pipeline through wgpu (Mesa lavapipe without a GPU): the reference from outside"
            }
        }
    }

    /// The oracle settings that make this algorithm (paper §5).
    pub fn pipeline(self) -> Pipeline {
        let frusta = |outside, occluded, split, samples| {
            Pipeline::Frusta(TraversalOracles {
                frustum: 256,
                outside,
                occluded,
                split,
                samples,
            })
        };
        let binning_only = SampleOracles {
            early_z: false,
            ..SampleOracles::BINNED
        };
        match self {
            AlgorithmId::TwoDBrute => Pipeline::AllTriangles {
                edges: EdgeKind::TwoD,
                samples: SampleOracles::BRUTE,
            },
            AlgorithmId::TwoDBin => Pipeline::AllTriangles {
                edges: EdgeKind::TwoD,
                samples: SampleOracles::BINNED,
            },
            AlgorithmId::TwoDHomogeneous => Pipeline::AllTriangles {
                edges: EdgeKind::Homogeneous,
                samples: SampleOracles::BRUTE,
            },
            AlgorithmId::ThreeDBrute => Pipeline::AllTriangles {
                edges: EdgeKind::ThreeD,
                samples: SampleOracles::BRUTE,
            },
            AlgorithmId::ThreeDBin => Pipeline::AllTriangles {
                edges: EdgeKind::ThreeD,
                samples: SampleOracles::BINNED,
            },
            AlgorithmId::ThreeDFrustumCull => frusta(true, false, None, binning_only),
            AlgorithmId::ThreeDFrustumSplit => frusta(true, true, Some(8), SampleOracles::BRUTE),
            AlgorithmId::ThreeDFull => frusta(true, true, Some(8), SampleOracles::BINNED),
            AlgorithmId::Raycast => Pipeline::Rays,
            AlgorithmId::GpuRaster => Pipeline::Gpu,
        }
    }
}

impl Pipeline {
    /// Applies explicit oracle settings, `key=value` pairs separated by commas:
    /// `outside`, `occluded`, `binning`, `early_z`, `incremental` (`on`/`off`), `split`
    /// (`off` or a size in pixels), `frustum` and `leaf` (sizes in pixels). The
    /// traversal keys need a BVH algorithm; the ray caster takes none.
    pub fn with_oracles(self, text: &str) -> Result<Pipeline, FieldError> {
        let bad = |m: String| FieldError::new("oracles", m);
        let mut p = self;
        for pair in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let (key, value) = pair
                .split_once('=')
                .ok_or_else(|| bad(format!("'{pair}' is not key=value")))?;
            let switch = || match value {
                "on" | "true" => Ok(true),
                "off" | "false" => Ok(false),
                _ => Err(bad(format!("{key}: '{value}' is not on or off"))),
            };
            let size = || match value.parse::<u32>() {
                Ok(n) if n.is_power_of_two() && (4..=1024).contains(&n) => Ok(n),
                _ => Err(bad(format!(
                    "{key}: '{value}' is not a power of two in 4..=1024"
                ))),
            };
            let samples = match &mut p {
                Pipeline::AllTriangles { samples, .. } => samples,
                Pipeline::Frusta(t) => &mut t.samples,
                Pipeline::Rays => return Err(bad("raycast takes no oracles".into())),
                Pipeline::Gpu => return Err(bad("gpu-raster takes no oracles".into())),
            };
            match key {
                "binning" => samples.binning = switch()?,
                "incremental" => samples.incremental = switch()?,
                "early_z" => samples.early_z = switch()?,
                "leaf" => samples.leaf = size()?,
                "outside" | "occluded" | "split" | "frustum" => {
                    let Pipeline::Frusta(t) = &mut p else {
                        return Err(bad(format!(
                            "'{key}' needs a BVH algorithm (3dr-frustum-cull, 3dr-frustum-split, 3dr-full)"
                        )));
                    };
                    match key {
                        "outside" => t.outside = switch()?,
                        "occluded" => t.occluded = switch()?,
                        "frustum" => t.frustum = size()?,
                        _ => t.split = if value == "off" { None } else { Some(size()?) },
                    }
                }
                _ => {
                    return Err(bad(format!(
                        "unknown oracle '{key}'; oracles are: outside, occluded, split, frustum, binning, early_z, leaf, incremental"
                    )));
                }
            }
        }
        Ok(p)
    }

    /// Can this pipeline render `viewport`? Straight edges (the 2D family) and
    /// planar frusta (the BVH traversal) need a planar viewport; 3D edge
    /// functions over all triangles and the ray caster serve every viewport.
    pub fn serves(self, viewport: &Viewport) -> bool {
        viewport.is_planar()
            || matches!(
                self,
                Pipeline::AllTriangles {
                    edges: EdgeKind::ThreeD,
                    ..
                } | Pipeline::Rays
            )
    }

    /// How samples are enumerated (`None` for the ray caster and the GPU).
    pub fn samples(self) -> Option<SampleOracles> {
        match self {
            Pipeline::AllTriangles { samples, .. } => Some(samples),
            Pipeline::Frusta(t) => Some(t.samples),
            Pipeline::Rays | Pipeline::Gpu => None,
        }
    }

    /// The paper's Fig. 10 scalar instruction costs: (setup, per sample); the
    /// GPU's are not modelled (zero).
    pub fn instruction_costs(self) -> (u64, u64) {
        match self {
            Pipeline::Gpu => (0, 0),
            Pipeline::AllTriangles {
                edges: EdgeKind::TwoD,
                ..
            } => (72, 14),
            Pipeline::AllTriangles {
                edges: EdgeKind::Homogeneous,
                ..
            } => (73, 14),
            _ => (57, 12),
        }
    }
}

/// Renders `view` of `scene` with `pipeline` at `precision` into `fb`: the
/// pixels, counters and stage times. The viewport must be one the pipeline
/// [serves](Pipeline::serves), the precision one its family computes in
/// (f64 on non-planar viewports is their f64 curved edges).
pub(crate) fn run(
    pipeline: Pipeline,
    precision: Precision,
    scene: &PreparedScene,
    context: &TileContext,
    fb: &mut Framebuffer,
    stats: &mut Stats,
) {
    let (view, pattern) = (context.view, context.pattern);
    let f64 = precision == Precision::F64;
    let pass = match pipeline {
        Pipeline::AllTriangles { edges, samples } => {
            let start = Instant::now();
            let span = pattern.span;
            // One generic call per edge kind (a closure cannot be generic).
            macro_rules! tiles {
                ($items:expr) => {
                    timed_tiles(&$items, fb, samples, context, stats, start)
                };
            }
            match edges {
                EdgeKind::TwoD if precision == Precision::Fixed => {
                    tiles!(setup2d::setup_2d_fixed(scene, view, span))
                }
                EdgeKind::TwoD => tiles!(setup2d::setup_2d(scene, view, span)),
                EdgeKind::Homogeneous => {
                    tiles!(setup3d::setup_homogeneous(scene, view, span))
                }
                EdgeKind::ThreeD if view.sphere.is_some() => {
                    let mut items = setup3d::setup_curved(scene, view, span);
                    if samples.incremental {
                        items
                            .iter_mut()
                            .flatten()
                            .for_each(|p| p.tri.incremental = true);
                    }
                    tiles!(items)
                }
                EdgeKind::ThreeD if f64 => {
                    tiles!(setup3d::setup_3d_f64(scene, view, span))
                }
                EdgeKind::ThreeD => tiles!(setup3d::setup_3d(scene, view, span)),
            }
        }
        Pipeline::Frusta(oracles) if f64 => {
            render_frusta(scene, context, oracles, fb, stats, Triangle3D64::setup)
        }
        Pipeline::Frusta(oracles) => {
            render_frusta(scene, context, oracles, fb, stats, Triangle3D::setup)
        }
        Pipeline::Rays if view.sphere.is_some() => raycast::render_raycast(
            scene,
            context,
            fb,
            stats,
            setup3d::one_by_one(CurvedTriangle::setup),
        ),
        Pipeline::Rays if f64 => raycast::render_raycast(
            scene,
            context,
            fb,
            stats,
            setup3d::one_by_one(Triangle3D64::setup),
        ),
        Pipeline::Rays => {
            raycast::render_raycast(scene, context, fb, stats, Triangle3D::setup_eight)
        }
        Pipeline::Gpu => unreachable!("gpu-raster renders through crate::gpu"),
    };
    stats.counters = pass.counters;
    stats.coverage_histogram = pass.histogram;
    stats.shading_samples = pass.shading_samples;
    stats.effects = pass.effects.report(context.shader.plan(), &scene.scene);
}

/// The Fig. 7 traversal, one initial frustum per parallel work item, leaf
/// triangles set up by `setup`.
fn render_frusta<'a, T: crate::edge::Coverage>(
    scene: &'a PreparedScene,
    context: &TileContext<'a>,
    oracles: TraversalOracles,
    fb: &mut Framebuffer,
    stats: &mut Stats,
    setup: Setup<'a, T>,
) -> Pass {
    let start = Instant::now();
    let boxes = screen_boxes::ScreenBoxes::new(scene, context.view);
    let boxes = &boxes;
    let done: Vec<_> = fb
        .tile_rects(oracles.frustum)
        .into_par_iter()
        .map_init(
            || None,
            |cache, rect| {
                context.run_tile(cache, rect, |tile| {
                    let mut t = Traversal::new(scene, context.view, oracles, tile, setup, boxes);
                    t.run();
                    (t.counters, t.nodes_visited, t.setups)
                })
            },
        )
        .collect();
    let mut pass = Pass::default();
    pass.store(
        fb,
        done.into_iter().map(|finished| {
            let (counters, nodes, setups) = finished.result;
            stats.bvh_nodes_visited += nodes;
            stats.triangle_setups += setups;
            finished.map(|_| counters)
        }),
    );
    let (traversal, shading) = pass.split(start.elapsed().as_secs_f64() * 1e3);
    stats.time_ms.traversal = traversal;
    stats.time_ms.shading = shading;
    pass
}

fn timed_tiles<T: crate::edge::Coverage + Sync>(
    items: &[Option<tiles::Placed<T>>],
    fb: &mut Framebuffer,
    samples: SampleOracles,
    context: &TileContext,
    stats: &mut Stats,
    start: Instant,
) -> Pass {
    stats.time_ms.setup = start.elapsed().as_secs_f64() * 1e3;
    let start = Instant::now();
    let (pass, placed) = rasterize_tiled(items, fb, samples, context);
    stats.triangle_setups = placed;
    let (coverage, shading) = pass.split(start.elapsed().as_secs_f64() * 1e3);
    stats.time_ms.coverage = coverage;
    stats.time_ms.shading = shading;
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
}

/// A tile rendered and resolved by one worker, with what its rendering returned.
#[derive(Debug)]
pub(crate) struct Finished<R> {
    pub resolved: ResolvedTile,
    pub result: R,
    /// Edge tests decided past f32 while rendering, `[f64 + exact, exact]`.
    pub precise: [u64; 2],
    /// Worker seconds spent rendering and resolving.
    pub render_s: f64,
    pub resolve_s: f64,
}

impl<R> Finished<R> {
    fn map<S>(self, f: impl FnOnce(R) -> S) -> Finished<S> {
        Finished {
            resolved: self.resolved,
            result: f(self.result),
            precise: self.precise,
            render_s: self.render_s,
            resolve_s: self.resolve_s,
        }
    }
}

impl<'a> TileContext<'a> {
    /// Renders the pixels `(x0, y0, x1, y1)` (exclusive ends) with `render`,
    /// then resolves their samples. The sample buffers are `cache`'s, reused
    /// from the worker's previous tile when there is one (no fresh pages to
    /// fault in per tile).
    pub fn run_tile<R: Default>(
        &self,
        cache: &mut Option<TileBuffer<'a>>,
        (x0, y0, x1, y1): (u32, u32, u32, u32),
        render: impl FnOnce(&mut TileBuffer<'a>) -> R,
    ) -> Finished<R> {
        // A cancelled render neither renders nor resolves what is left.
        if self.cancel.load(std::sync::atomic::Ordering::Relaxed) {
            return Finished {
                resolved: ResolvedTile::blank([x0, y0, x1, y1]),
                result: R::default(),
                precise: [0; 2],
                render_s: 0.0,
                resolve_s: 0.0,
            };
        }
        let start = Instant::now();
        let tile = match cache {
            Some(tile) => {
                tile.reset(x0, y0, x1, y1);
                tile
            }
            None => cache.insert(TileBuffer::new(
                (x0, y0, x1, y1),
                self.pattern,
                self.opacity,
            )),
        };
        let precise = crate::edge::precise_tests();
        let result = render(tile);
        let precise_after = crate::edge::precise_tests();
        let render_s = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let resolved = resolve_tile(tile, self.view, &self.shader);
        Finished {
            resolved,
            result,
            precise: [0, 1].map(|k| precise_after[k] - precise[k]),
            render_s,
            resolve_s: start.elapsed().as_secs_f64(),
        }
    }
}

/// The totals of one parallel pass over tiles.
#[derive(Debug, Default)]
pub(crate) struct Pass {
    pub counters: RasterCounters,
    pub histogram: CoverageHistogram,
    pub shading_samples: u64,
    pub effects: crate::shade::plan::EffectCounters,
    render_s: f64,
    resolve_s: f64,
}

impl Pass {
    /// Adds up the finished tiles' counters and stores their pixels.
    pub fn store(
        &mut self,
        fb: &mut Framebuffer,
        finished: impl IntoIterator<Item = Finished<RasterCounters>>,
    ) {
        let resolved: Vec<ResolvedTile> = finished
            .into_iter()
            .map(|finished| {
                self.counters += finished.result;
                self.counters.edge_tests_f64 += finished.precise[0];
                self.counters.edge_tests_exact += finished.precise[1];
                self.histogram += finished.resolved.histogram;
                self.shading_samples += finished.resolved.shading_samples;
                self.effects.add(&finished.resolved.effects);
                self.render_s += finished.render_s;
                self.resolve_s += finished.resolve_s;
                finished.resolved
            })
            .collect();
        fb.store_tiles(&resolved);
    }

    /// The pass's wall time split into rendering and shading (with the resolve)
    /// in proportion to the worker time each took: workers do both, tile by tile.
    pub fn split(&self, wall_ms: f64) -> (f64, f64) {
        let busy = self.render_s + self.resolve_s;
        if busy <= 0.0 {
            return (wall_ms, 0.0);
        }
        let shading = wall_ms * self.resolve_s / busy;
        (wall_ms - shading, shading)
    }
}

impl fmt::Display for AlgorithmId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Every f32 of magnitude 2²³ or more is an integer.
const INTEGRAL_ABOVE: f32 = 8_388_608.0;

/// `v.floor()` up to the sign of a zero result, inline: baseline x86-64 has
/// no rounding instruction and `f32::floor` is a libm call (once per triangle
/// bound in every setup). Truncation is exact below [`INTEGRAL_ABOVE`]; at and
/// beyond it (and for ±∞ and NaN) `v` is its own floor.
#[inline(always)]
fn floor(v: f32) -> f32 {
    if v.abs() < INTEGRAL_ABOVE {
        let t = v as i32 as f32;
        if t > v { t - 1.0 } else { t }
    } else {
        v
    }
}

/// `v.ceil()` up to the sign of a zero result (see [`floor`]).
#[inline(always)]
fn ceil(v: f32) -> f32 {
    if v.abs() < INTEGRAL_ABOVE {
        let t = v as i32 as f32;
        if t < v { t + 1.0 } else { t }
    } else {
        v
    }
}

/// An algorithm id that is not one of [`AlgorithmId::ALL`].
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown algorithm '{given}'; valid ids are: {}", AlgorithmId::ALL.map(|a| a.as_str()).join(", "))]
pub struct UnknownAlgorithm {
    pub given: String,
}

impl FromStr for AlgorithmId {
    type Err = UnknownAlgorithm;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        AlgorithmId::ALL
            .into_iter()
            .find(|a| a.as_str() == s)
            .ok_or_else(|| UnknownAlgorithm {
                given: s.to_string(),
            })
    }
}

impl Serialize for AlgorithmId {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.as_str())
    }
}

/// Inclusive pixel rectangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct PixelRect {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl PixelRect {
    /// The pixels in both rectangles, or `None`.
    #[inline]
    pub fn intersect(self, o: PixelRect) -> Option<PixelRect> {
        let r = PixelRect {
            x0: self.x0.max(o.x0),
            y0: self.y0.max(o.y0),
            x1: self.x1.min(o.x1),
            y1: self.y1.min(o.y1),
        };
        (r.x0 <= r.x1 && r.y0 <= r.y1).then_some(r)
    }

    /// The pixels with a sample in `[min_x, max_x] × [min_y, max_y]` (sample
    /// offsets within `span` of the pixel corner), clamped to a `width × height`
    /// image; `None` when there are none.
    pub fn from_bounds(
        min_x: f32,
        min_y: f32,
        max_x: f32,
        max_y: f32,
        width: u32,
        height: u32,
        span: SampleSpan,
    ) -> Option<PixelRect> {
        // Pixel p's samples lie in [p + lo, p + hi]: first p with p + hi ≥ min,
        // last with p + lo ≤ max.
        let first = |v: f32, hi: f32| ceil(v - hi).max(0.0);
        let last = |v: f32, lo: f32, n: u32| floor(v - lo).min(n as f32 - 1.0);
        let (x0, y0) = (first(min_x, span.hi[0]), first(min_y, span.hi[1]));
        let (x1, y1) = (
            last(max_x, span.lo[0], width),
            last(max_y, span.lo[1], height),
        );
        // Also rejects NaN bounds.
        if !(x0 <= x1 && y0 <= y1) {
            return None;
        }
        Some(PixelRect {
            x0: x0 as u32,
            y0: y0 as u32,
            x1: x1 as u32,
            y1: y1 as u32,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::{ceil, floor};

    /// Equal to the library's, zero signs aside, on random values of every
    /// magnitude, on and around integers, halves, the integral threshold and
    /// the specials.
    #[test]
    fn inline_floor_and_ceil_are_the_library_ones() {
        let mut rng = fastrand::Rng::with_seed(3);
        let mut values = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            8_388_607.5,
            -8_388_607.5,
            8_388_608.0,
            -8_388_609.0,
            1e30,
            -1e30,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ];
        for _ in 0..100_000 {
            let v = (rng.f32() - 0.5) * 10f32.powi(rng.i32(-8..12));
            values.extend([
                v,
                v.round(),
                v.round() + 0.5,
                f32::from_bits(v.to_bits() + 1),
            ]);
        }
        for v in values {
            assert_eq!(floor(v), v.floor(), "floor({v:e})");
            assert_eq!(ceil(v), v.ceil(), "ceil({v:e})");
        }
        assert!(floor(f32::NAN).is_nan() && ceil(f32::NAN).is_nan());
    }
}
