//! The algorithms of the continuum, by stable id, and what they share.
//!
//! | id | traversal | samples |
//! |---|---|---|
//! | `2dr-brute` | all triangles | bounding box, projected 2D edges, near + guard-band clipping |
//! | `3dr-brute` | all triangles | bounding box, 3D edges (paper §3.2), no projection |
//! | `raycast` | CWBVH walked per ray | one sample per ray, the same 3D edges |

mod bands;
mod brute2d;
mod brute3d;
mod raycast;

use std::fmt;
use std::str::FromStr;

use serde::{Serialize, Serializer};

pub(crate) use brute2d::render_2dr_brute;
pub(crate) use brute3d::render_3dr_brute;
pub(crate) use raycast::render_raycast;

/// Which algorithm renders a request. The string forms are stable ids.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AlgorithmId {
    /// Project, clip, 2D edge functions over the bounding box (the paper's reference).
    TwoDBrute,
    /// 3D edge functions over the bounding box, no projection.
    ThreeDBrute,
    /// One ray per sample through the BVH, hits decided by the 3D edge functions.
    Raycast,
}

/// The family an algorithm belongs to: within a family results agree bit for bit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Family {
    /// Projected 2D edge functions.
    #[serde(rename = "2d")]
    TwoD,
    /// 3D edge functions (rasterizers and the ray caster).
    #[serde(rename = "3d")]
    ThreeD,
}

impl AlgorithmId {
    pub const ALL: [AlgorithmId; 3] = [
        AlgorithmId::TwoDBrute,
        AlgorithmId::ThreeDBrute,
        AlgorithmId::Raycast,
    ];

    pub fn as_str(self) -> &'static str {
        match self {
            AlgorithmId::TwoDBrute => "2dr-brute",
            AlgorithmId::ThreeDBrute => "3dr-brute",
            AlgorithmId::Raycast => "raycast",
        }
    }

    pub fn family(self) -> Family {
        match self {
            AlgorithmId::TwoDBrute => Family::TwoD,
            AlgorithmId::ThreeDBrute | AlgorithmId::Raycast => Family::ThreeD,
        }
    }

    /// One line on what it does, for listings.
    pub fn description(self) -> &'static str {
        match self {
            AlgorithmId::TwoDBrute => {
                "2D rasterization: project, clip, 2D edge functions over each bounding box"
            }
            AlgorithmId::ThreeDBrute => {
                "3D rasterization: 3D edge functions over each bounding box, no projection"
            }
            AlgorithmId::Raycast => {
                "ray casting through a CWBVH, hits decided by the same 3D edge functions"
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

/// Inclusive pixel rectangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct PixelRect {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl PixelRect {
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
