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
    /// 2D edge functions as wgpu compute kernels (paper §5).
    Gpu2dr,
    /// Homogeneous 2D edge functions as wgpu compute kernels (paper §5).
    Gpu2drHomogeneous,
    /// 3D edge functions as wgpu compute kernels (paper §5).
    Gpu3dr,
    /// 3D edge functions in a sort-middle compute pipeline (the paper's future work).
    Gpu3drBinned,
}

/// The family an algorithm belongs to: within a family results agree bit for
/// bit (the GPU's, which round as their driver does, excepted).
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
    /// Every algorithm: the CPU ones, `gpu-raster` and the compute kernels.
    pub const ALL: [AlgorithmId; 15] = [
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
        AlgorithmId::Gpu2dr,
        AlgorithmId::Gpu2drHomogeneous,
        AlgorithmId::Gpu3dr,
        AlgorithmId::Gpu3drBinned,
    ];

    /// The algorithms that run on the GPU (feature `gpu`).
    pub const GPU: [AlgorithmId; 5] = [
        AlgorithmId::GpuRaster,
        AlgorithmId::Gpu2dr,
        AlgorithmId::Gpu2drHomogeneous,
        AlgorithmId::Gpu3dr,
        AlgorithmId::Gpu3drBinned,
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
            AlgorithmId::Gpu2dr => "gpu-2dr",
            AlgorithmId::Gpu2drHomogeneous => "gpu-2dr-homogeneous",
            AlgorithmId::Gpu3dr => "gpu-3dr",
            AlgorithmId::Gpu3drBinned => "gpu-3dr-binned",
        }
    }

    pub fn family(self) -> Family {
        match self {
            AlgorithmId::TwoDBrute | AlgorithmId::TwoDBin | AlgorithmId::TwoDScanline => {
                Family::TwoD
            }
            AlgorithmId::TwoDHomogeneous => Family::Homogeneous,
            AlgorithmId::GpuRaster
            | AlgorithmId::Gpu2dr
            | AlgorithmId::Gpu2drHomogeneous
            | AlgorithmId::Gpu3dr
            | AlgorithmId::Gpu3drBinned => Family::Gpu,
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
            AlgorithmId::Gpu2dr => {
                "2D rasterization as GPU compute: a setup kernel, then each triangle's bounding box (paper section 5)"
            }
            AlgorithmId::Gpu2drHomogeneous => {
                "homogeneous 2D rasterization as GPU compute, no clipping (paper section 5)"
            }
            AlgorithmId::Gpu3dr => {
                "3D rasterization as GPU compute: 3D edge functions over each bounding box (paper section 5)"
            }
            AlgorithmId::Gpu3drBinned => {
                "3D rasterization in a GPU sort-middle pipeline: setup, bin into tiles, one workgroup per tile"
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
