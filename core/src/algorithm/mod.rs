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

mod raycast;
pub(crate) mod setup2d;
pub(crate) mod setup3d;
pub(crate) mod tiles;

use std::fmt;
use std::str::FromStr;
use std::time::Instant;

use rayon::prelude::*;
use serde::{Serialize, Serializer};

pub use crate::binning::SampleOracles;

use crate::camera::{View, Viewport};
use crate::edge::{CurvedTriangle, Triangle3D};
use crate::framebuffer::Framebuffer;
use crate::prepared::PreparedScene;
use crate::request::FieldError;
use crate::stats::{RasterCounters, Stats};
use crate::traversal::{Traversal, TraversalOracles};
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
}

impl AlgorithmId {
    pub const ALL: [AlgorithmId; 9] = [
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
        }
    }

    pub fn family(self) -> Family {
        match self {
            AlgorithmId::TwoDBrute | AlgorithmId::TwoDBin => Family::TwoD,
            AlgorithmId::TwoDHomogeneous => Family::Homogeneous,
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

    /// How samples are enumerated (`None` for the ray caster).
    pub fn samples(self) -> Option<SampleOracles> {
        match self {
            Pipeline::AllTriangles { samples, .. } => Some(samples),
            Pipeline::Frusta(t) => Some(t.samples),
            Pipeline::Rays => None,
        }
    }

    /// The paper's Fig. 10 scalar instruction costs: (setup, per sample).
    pub fn instruction_costs(self) -> (u64, u64) {
        match self {
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

/// Runs `pipeline`, filling visibility buffers and counters. The viewport must
/// be one the pipeline [serves](Pipeline::serves).
pub(crate) fn run(
    pipeline: Pipeline,
    scene: &PreparedScene,
    view: &View,
    fb: &mut Framebuffer,
    stats: &mut Stats,
) {
    match pipeline {
        Pipeline::AllTriangles { edges, samples } => {
            let start = Instant::now();
            let counters = match edges {
                EdgeKind::TwoD => {
                    timed_tiles(&setup2d::setup_2d(scene, view), fb, samples, stats, start)
                }
                EdgeKind::Homogeneous => timed_tiles(
                    &setup3d::setup_homogeneous(scene, view),
                    fb,
                    samples,
                    stats,
                    start,
                ),
                EdgeKind::ThreeD if view.sphere.is_some() => {
                    let mut items = setup3d::setup_curved(scene, view);
                    if samples.incremental {
                        items.iter_mut().for_each(|p| p.tri.incremental = true);
                    }
                    timed_tiles(&items, fb, samples, stats, start)
                }
                EdgeKind::ThreeD => {
                    timed_tiles(&setup3d::setup_3d(scene, view), fb, samples, stats, start)
                }
            };
            stats.counters = counters;
        }
        Pipeline::Frusta(oracles) => {
            let start = Instant::now();
            let done: Vec<Traversal> = fb
                .tile_rects(oracles.frustum)
                .into_par_iter()
                .map(|rect| {
                    let mut t = Traversal::new(scene, view, oracles, rect);
                    t.run();
                    t
                })
                .collect();
            let mut counters = RasterCounters::default();
            for t in &done {
                fb.store(&t.tile);
                counters += t.counters;
                stats.bvh_nodes_visited += t.nodes_visited;
                stats.triangle_setups += t.setups;
            }
            stats.counters = counters;
            stats.time_ms.traversal = start.elapsed().as_secs_f64() * 1e3;
        }
        Pipeline::Rays if view.sphere.is_some() => {
            raycast::render_raycast(scene, view, fb, stats, CurvedTriangle::setup);
        }
        Pipeline::Rays => raycast::render_raycast(scene, view, fb, stats, Triangle3D::setup),
    }
}

fn timed_tiles<T: crate::edge::Coverage + Sync>(
    items: &[tiles::Placed<T>],
    fb: &mut Framebuffer,
    samples: SampleOracles,
    stats: &mut Stats,
    start: Instant,
) -> RasterCounters {
    stats.triangle_setups = items.len() as u64;
    stats.time_ms.setup = start.elapsed().as_secs_f64() * 1e3;
    let start = Instant::now();
    let counters = rasterize_tiled(items, fb, samples);
    stats.time_ms.coverage = start.elapsed().as_secs_f64() * 1e3;
    counters
}

impl fmt::Display for AlgorithmId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
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

    /// The pixels whose centres lie in `[min_x, max_x] × [min_y, max_y]`, clamped
    /// to a `width × height` image; `None` when there are none.
    pub fn from_bounds(
        min_x: f32,
        min_y: f32,
        max_x: f32,
        max_y: f32,
        width: u32,
        height: u32,
    ) -> Option<PixelRect> {
        // Pixel p's centre is p + 0.5: first p with p + 0.5 ≥ min, last with p + 0.5 ≤ max.
        let lo = |v: f32| (v - 0.5).ceil().max(0.0);
        let hi = |v: f32, n: u32| (v - 0.5).floor().min(n as f32 - 1.0);
        let (x0, y0, x1, y1) = (lo(min_x), lo(min_y), hi(max_x, width), hi(max_y, height));
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
