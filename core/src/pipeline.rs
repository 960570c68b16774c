//! Points of the continuum: the oracle settings of Fig. 7 (paper §5) that make
//! each algorithm, the typed settings a request adds on top, and the paper's
//! Fig. 10 instruction costs.

use std::fmt;

use crate::ground::{AlgorithmId, FieldError};
use crate::viewport::Viewport;

/// Oracle settings a request puts on top of its algorithm's (paper §5, Fig. 7),
/// in the CLI's words `key=value,…`: `outside`, `occluded`, `final_depth`,
/// `binning`, `early_z`, `incremental` (`on`/`off`), `split` (`off` or a size
/// in pixels), `frustum` and `leaf` (sizes in pixels), and `raycast`'s
/// `packet` (the side in pixels of the block whose rays walk the BVH
/// together: 4, 8 or 16). `None` keeps the algorithm's own.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Oracles {
    pub outside: Option<bool>,
    pub occluded: Option<bool>,
    pub final_depth: Option<bool>,
    pub split: Option<Option<u32>>,
    pub frustum: Option<u32>,
    pub binning: Option<bool>,
    pub early_z: Option<bool>,
    pub leaf: Option<u32>,
    pub incremental: Option<bool>,
    pub packet: Option<u32>,
}

impl Oracles {
    /// No setting given.
    pub fn is_empty(&self) -> bool {
        *self == Oracles::default()
    }

    /// Parses `key=value` pairs separated by commas; a later pair of a key
    /// replaces an earlier one. Errors name the field `oracles`.
    pub fn parse(text: &str) -> Result<Oracles, FieldError> {
        let bad = |m: String| FieldError::new("oracles", m);
        let mut o = Oracles::default();
        for pair in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let (key, value) = pair
                .split_once('=')
                .ok_or_else(|| bad(format!("'{pair}' is not key=value")))?;
            let switch = || match value {
                "on" | "true" => Ok(Some(true)),
                "off" | "false" => Ok(Some(false)),
                _ => Err(bad(format!("{key}: '{value}' is not on or off"))),
            };
            let size = || match value.parse::<u32>() {
                Ok(n) if n.is_power_of_two() && (4..=1024).contains(&n) => Ok(n),
                _ => Err(bad(format!(
                    "{key}: '{value}' is not a power of two in 4..=1024"
                ))),
            };
            match key {
                "outside" => o.outside = switch()?,
                "occluded" => o.occluded = switch()?,
                "final_depth" => o.final_depth = switch()?,
                "binning" => o.binning = switch()?,
                "early_z" => o.early_z = switch()?,
                "incremental" => o.incremental = switch()?,
                "leaf" => o.leaf = Some(size()?),
                "frustum" => o.frustum = Some(size()?),
                "packet" => o.packet = Some(size()?),
                "split" => o.split = Some(if value == "off" { None } else { Some(size()?) }),
                _ => {
                    return Err(bad(format!(
                        "unknown oracle '{key}'; oracles are: outside, occluded, final_depth, split, frustum, binning, early_z, leaf, incremental, packet"
                    )));
                }
            }
        }
        Ok(o)
    }
}

impl fmt::Display for Oracles {
    /// The settings given, in the words [`Oracles::parse`] reads.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let word = |on: bool| if on { "on" } else { "off" };
        let mut pairs: Vec<String> = Vec::new();
        let switches = [
            ("outside", self.outside),
            ("occluded", self.occluded),
            ("final_depth", self.final_depth),
            ("binning", self.binning),
            ("early_z", self.early_z),
            ("incremental", self.incremental),
        ];
        for (key, v) in switches {
            if let Some(v) = v {
                pairs.push(format!("{key}={}", word(v)));
            }
        }
        if let Some(split) = self.split {
            pairs.push(match split {
                Some(n) => format!("split={n}"),
                None => "split=off".into(),
            });
        }
        for (key, v) in [
            ("frustum", self.frustum),
            ("leaf", self.leaf),
            ("packet", self.packet),
        ] {
            if let Some(n) = v {
                pairs.push(format!("{key}={n}"));
            }
        }
        f.write_str(&pairs.join(","))
    }
}

/// How samples are enumerated inside a triangle's box.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SampleOracles {
    /// Hierarchical tile tests instead of testing every sample of the box.
    pub binning: bool,
    /// Spans instead of the box: each row's run of covered pixels found by
    /// walking the straight edges (`2dr-scanline`; the others off).
    pub spans: bool,
    /// Blocks of this many pixels square (a power of two) are tested sample by sample.
    pub leaf: u32,
    /// Skip blocks that the hierarchical w-buffer shows are hidden.
    pub early_z: bool,
    /// Parabolic viewport: evaluate edges along rows with the double-incremental
    /// scheme of §3.5 eq. 3 (same decisions as direct evaluation).
    pub incremental: bool,
}

impl SampleOracles {
    pub const BRUTE: SampleOracles = SampleOracles {
        binning: false,
        spans: false,
        leaf: 8,
        early_z: false,
        incremental: false,
    };
    pub const BINNED: SampleOracles = SampleOracles {
        binning: true,
        spans: false,
        leaf: 8,
        early_z: true,
        incremental: false,
    };
}

/// The oracles of Fig. 7 for a BVH traversal.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TraversalOracles {
    /// Side of the initial frusta in pixels (each is one parallel work item).
    pub frustum: u32,
    /// `is_outside`: cull nodes outside the frustum.
    pub outside: bool,
    /// `is_occluded`: cull nodes behind the hierarchical w-buffer.
    pub occluded: bool,
    /// An oracle that knows the future: `is_occluded` reads the depths each
    /// tile ends with (an uncounted first traversal renders them), sample by
    /// sample over the node's screen box, so the counted traversal culls
    /// every node that any test of a box's nearest depth against the depth
    /// buffer could — the bound of occlusion culling with this BVH and these
    /// frusta. Its times are of both traversals.
    pub final_depth: bool,
    /// `split_frustum`: split down to this many pixels square (`None`: never).
    pub split: Option<u32>,
    /// `generate_samples` at leaves: how samples are enumerated.
    pub samples: SampleOracles,
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
    /// One ray per sample through the BVH, in packets of rays through
    /// blocks of this many pixels on a side ([`RAY_PACKETS`]).
    Rays { packet: u32 },
    /// The GPU's hardware pipeline.
    Gpu,
    /// The continuum's own edge functions as GPU compute kernels (paper §5).
    Compute(ComputeKind),
}

/// Which compute kernels render a GPU algorithm of the continuum.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ComputeKind {
    /// `gpu-2dr`: projected 2D edge functions (§3.1), clipped triangles set
    /// up by the CPU.
    TwoD,
    /// `gpu-2dr-homogeneous`: Olano–Greer, no clipping.
    Homogeneous,
    /// `gpu-3dr`: 3D edge functions (§3.2–3.4), no projection, no clipping.
    ThreeD,
    /// `gpu-3dr-binned`: 3D edge functions in a sort-middle pipeline.
    ThreeDBinned,
}

impl ComputeKind {
    /// The edge functions the kernels set up.
    pub fn edges(self) -> EdgeKind {
        match self {
            ComputeKind::TwoD => EdgeKind::TwoD,
            ComputeKind::Homogeneous => EdgeKind::Homogeneous,
            ComputeKind::ThreeD | ComputeKind::ThreeDBinned => EdgeKind::ThreeD,
        }
    }
}

/// `3dr-full`'s frustum side and split size in pixels: measured, not the
/// paper's 256² split down to 8². With binning and early-z at the leaves, a
/// frustum rarely gains from splitting below 32². On the five benchmark
/// scenes (1920×1080, two threads, `compare --algorithms 3dr-full,3dr-brute
/// --oracles 'frustum=128,split=32;frustum=64,split=16;…'`, three runs) 128²
/// split to 32² first took 0.51–0.82× the paper's time, the best geometric
/// mean of frusta of 32² to 256² and split sizes 8 to 64. Once tiles were
/// depth-tested eight samples at a time, the frame around them (each tile's
/// rows copied and shaded into the frame) cost more per tile than the
/// traversal saved: 256² split to 32² then took 0.87–0.99× the time of
/// 128² on every one of the five (`--oracles 'frustum=256,split=32;
/// frustum=256,split=16;frustum=256,split=64;frustum=512,split=32'`, three
/// runs; split to 64² was faster on `soup` and `sponza` but slower on the
/// dragon and `teapots`). `--oracles frustum=256,split=8` restores the
/// paper's.
pub(crate) const FULL_FRUSTUM: u32 = 256;
/// See [`FULL_FRUSTUM`].
pub(crate) const FULL_SPLIT: u32 = 32;

impl AlgorithmId {
    /// The oracle settings that make this algorithm (paper §5).
    pub fn pipeline(self) -> Pipeline {
        let frusta = |frustum, outside, occluded, split, samples| {
            Pipeline::Frusta(TraversalOracles {
                frustum,
                outside,
                occluded,
                final_depth: false,
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
            AlgorithmId::TwoDScanline => Pipeline::AllTriangles {
                edges: EdgeKind::TwoD,
                samples: SampleOracles {
                    spans: true,
                    ..SampleOracles::BRUTE
                },
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
            // The paper's sizes: 256² frusta, split down to 8².
            AlgorithmId::ThreeDFrustumCull => frusta(256, true, false, None, binning_only),
            AlgorithmId::ThreeDFrustumSplit => {
                frusta(256, true, true, Some(8), SampleOracles::BRUTE)
            }
            AlgorithmId::ThreeDFull => frusta(
                FULL_FRUSTUM,
                true,
                true,
                Some(FULL_SPLIT),
                SampleOracles::BINNED,
            ),
            AlgorithmId::Raycast => Pipeline::Rays { packet: RAY_PACKET },
            AlgorithmId::GpuRaster => Pipeline::Gpu,
            AlgorithmId::Gpu2dr => Pipeline::Compute(ComputeKind::TwoD),
            AlgorithmId::Gpu2drHomogeneous => Pipeline::Compute(ComputeKind::Homogeneous),
            AlgorithmId::Gpu3dr => Pipeline::Compute(ComputeKind::ThreeD),
            AlgorithmId::Gpu3drBinned => Pipeline::Compute(ComputeKind::ThreeDBinned),
        }
    }
}

/// The packet sides `raycast` walks (pixels): groups of 4×4 rays, one, four
/// or sixteen to a packet.
pub const RAY_PACKETS: [u32; 3] = [4, 8, 16];

/// `raycast`'s own packet side: four 4×4 groups share each node's read and
/// decode, each tested against its own culling distance. At 1920×1080 on
/// two threads this took 0.80–1.00× the time of 4×4 packets on `teapots`,
/// `bunny`, `soup`, the dragon and sponza, and 16×16 packets were slower on
/// all five (`compare --oracles 'packet=4;packet=16' --algorithms raycast`).
pub const RAY_PACKET: u32 = 8;

/// The ray caster with `oracles` (only `packet`, one of [`RAY_PACKETS`]),
/// or what is wrong with them.
fn rays_with(oracles: &Oracles) -> Result<Pipeline, String> {
    let others = Oracles {
        packet: None,
        ..*oracles
    };
    if !others.is_empty() {
        return Err(format!("raycast takes only 'packet', not '{others}'"));
    }
    match oracles.packet {
        Some(packet) if !RAY_PACKETS.contains(&packet) => Err(format!(
            "packet: '{packet}' is not one of {RAY_PACKETS:?} (pixels on a side)"
        )),
        packet => Ok(Pipeline::Rays {
            packet: packet.unwrap_or(RAY_PACKET),
        }),
    }
}

impl AlgorithmId {
    /// A setting of the oracles this algorithm takes, for forms and help
    /// texts to show (each is accepted: a test renders every one); `None`
    /// when it takes none (`2dr-scanline`, the GPU).
    pub fn oracles_example(self) -> Option<&'static str> {
        match self.pipeline() {
            Pipeline::AllTriangles { samples, .. } if samples.spans => None,
            Pipeline::AllTriangles { .. } => Some("binning=off,early_z=on"),
            Pipeline::Frusta(_) => Some("split=16,occluded=off"),
            Pipeline::Rays { .. } => Some("packet=4"),
            Pipeline::Gpu | Pipeline::Compute(_) => None,
        }
    }
}

impl Pipeline {
    /// This pipeline with `oracles` set on top of its own. The traversal
    /// keys need a BVH algorithm, `packet` the ray caster, which takes no
    /// other; the GPU takes none.
    pub fn with_oracles(self, oracles: &Oracles) -> Result<Pipeline, FieldError> {
        if oracles.is_empty() {
            return Ok(self);
        }
        let bad = |m: &str| FieldError::new("oracles", m);
        let mut p = self;
        let samples = match &mut p {
            Pipeline::AllTriangles { samples, .. } if samples.spans => {
                return Err(bad("2dr-scanline walks spans and takes no oracles"));
            }
            Pipeline::AllTriangles { samples, .. } => samples,
            Pipeline::Frusta(t) => &mut t.samples,
            Pipeline::Rays { .. } => return rays_with(oracles).map_err(|m| bad(&m)),
            Pipeline::Gpu | Pipeline::Compute(_) => {
                return Err(bad("the GPU algorithms take no oracles"));
            }
        };
        if oracles.packet.is_some() {
            return Err(bad("'packet' needs raycast"));
        }
        let set = |to: &mut bool, v: Option<bool>| *to = v.unwrap_or(*to);
        set(&mut samples.binning, oracles.binning);
        set(&mut samples.incremental, oracles.incremental);
        set(&mut samples.early_z, oracles.early_z);
        samples.leaf = oracles.leaf.unwrap_or(samples.leaf);
        match &mut p {
            Pipeline::Frusta(t) => {
                set(&mut t.outside, oracles.outside);
                set(&mut t.occluded, oracles.occluded);
                set(&mut t.final_depth, oracles.final_depth);
                if t.final_depth && !t.occluded {
                    return Err(bad("'final_depth' needs occluded=on"));
                }
                t.split = oracles.split.unwrap_or(t.split);
                t.frustum = oracles.frustum.unwrap_or(t.frustum);
            }
            _ => {
                let traversal = [
                    ("outside", oracles.outside.is_some()),
                    ("occluded", oracles.occluded.is_some()),
                    ("final_depth", oracles.final_depth.is_some()),
                    ("split", oracles.split.is_some()),
                    ("frustum", oracles.frustum.is_some()),
                ];
                if let Some((key, _)) = traversal.iter().find(|(_, given)| *given) {
                    return Err(bad(&format!(
                        "'{key}' needs a BVH algorithm (3dr-frustum-cull, 3dr-frustum-split, 3dr-full)"
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
                } | Pipeline::Rays { .. }
            )
    }

    /// How samples are enumerated (`None` for the ray caster and the GPU).
    pub fn samples(self) -> Option<SampleOracles> {
        match self {
            Pipeline::AllTriangles { samples, .. } => Some(samples),
            Pipeline::Frusta(t) => Some(t.samples),
            Pipeline::Rays { .. } | Pipeline::Gpu | Pipeline::Compute(_) => None,
        }
    }

    /// The paper's Fig. 10 scalar instruction costs: (setup, per sample); the
    /// GPU's are not modelled (zero).
    pub fn instruction_costs(self) -> (u64, u64) {
        let edges = match self {
            Pipeline::Gpu => return (0, 0),
            Pipeline::AllTriangles { edges, .. } => edges,
            Pipeline::Compute(kind) => kind.edges(),
            Pipeline::Frusta(_) | Pipeline::Rays { .. } => EdgeKind::ThreeD,
        };
        match edges {
            EdgeKind::TwoD => (72, 14),
            EdgeKind::Homogeneous => (73, 14),
            EdgeKind::ThreeD => (57, 12),
        }
    }
}
