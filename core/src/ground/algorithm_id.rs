//! Algorithm ids (the stable strings every front end speaks) and families.

use std::fmt;
use std::str::FromStr;

use serde::{Serialize, Serializer};

/// Which algorithm renders a request. The string forms are stable ids.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AlgorithmId {
    /// Project, clip, 2D edge functions over the bounding box (the paper's reference).
    TwoDBrute,
    /// 2D edge functions with hierarchical tile tests and early-z.
    TwoDBin,
    /// 2D edge functions, pixels enumerated span by span by walking the edges.
    TwoDScanline,
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

impl AlgorithmId {
    /// Every algorithm: the CPU ones and `gpu-raster`.
    pub const ALL: [AlgorithmId; 11] = [
        AlgorithmId::TwoDBrute,
        AlgorithmId::TwoDBin,
        AlgorithmId::TwoDScanline,
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
    pub const CPU: [AlgorithmId; 10] = [
        AlgorithmId::TwoDBrute,
        AlgorithmId::TwoDBin,
        AlgorithmId::TwoDScanline,
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
            AlgorithmId::TwoDScanline => "2dr-scanline",
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
            AlgorithmId::TwoDBrute | AlgorithmId::TwoDBin | AlgorithmId::TwoDScanline => {
                Family::TwoD
            }
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
            AlgorithmId::TwoDScanline => {
                "2D rasterization by spans: each edge walked from row to row, the pixels between filled"
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
