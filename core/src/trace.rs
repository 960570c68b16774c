//! What an algorithm did, recorded while it renders — the tiles it worked
//! in, the blocks binning tested, the frusta the traversal made, the BVH
//! nodes it met — for the overlays that draw it over the image
//! (`--overlay tiles,frusta,bvh`). Recorded only when a request asks
//! ([`crate::RenderRequest::trace`]); otherwise every recording site is one
//! untaken branch on an empty `Option`. [`Overlays`] names what a front
//! end draws of it.

use std::fmt;

use crate::ground::{FieldError, PixelRect};

/// How binning's tile test decided a block (paper §3.1, "binning").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BlockOutcome {
    /// No sample covered: skipped.
    Rejected,
    /// Every sample inside: filled without per-sample tests.
    Accepted,
    /// Undecided: split into four.
    Refined,
}

/// What became of a frustum of the Fig. 7 traversal.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FrustumEvent {
    /// Made (an initial frustum, or a quarter of a split one).
    Created,
    /// Split into four at some node.
    Split,
    /// Reached a leaf and rasterized its triangles.
    Rasterized,
}

/// What the traversal did with a BVH node it met.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum NodeOutcome {
    /// Entered: its children (or triangles) were visited.
    Entered,
    /// Culled: outside the frustum (`is_outside`).
    Outside,
    /// Culled: behind the hierarchical w-buffer (`is_occluded`).
    Occluded,
}

/// One render's record, in no particular order across tiles.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trace {
    /// Each parallel work item's pixels: a screen tile, an initial frustum, a band.
    pub tiles: Vec<PixelRect>,
    /// Every block binning tested, with the outcome.
    pub blocks: Vec<(PixelRect, BlockOutcome)>,
    /// Every frustum event, by the frustum's pixels.
    pub frusta: Vec<(PixelRect, FrustumEvent)>,
    /// Every node visit: the node's world box `[min, max]` and the outcome.
    pub nodes: Vec<([[f32; 3]; 2], NodeOutcome)>,
}

impl Trace {
    /// Appends `other`'s records.
    pub fn append(&mut self, mut other: Trace) {
        self.tiles.append(&mut other.tiles);
        self.blocks.append(&mut other.blocks);
        self.frusta.append(&mut other.frusta);
        self.nodes.append(&mut other.nodes);
    }
}

/// Which overlays to draw; in words, a comma-separated list of
/// [`Overlays::NAMES`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Overlays {
    pub wireframe: bool,
    pub tiles: bool,
    pub frusta: bool,
    pub bvh: bool,
}

impl Overlays {
    /// The overlays' names, in drawing order.
    pub const NAMES: [&'static str; 4] = ["wireframe", "tiles", "frusta", "bvh"];

    /// Parses `wireframe,tiles,frusta,bvh` (any subset, any order; empty:
    /// none). Errors name the field `overlays`.
    pub fn parse(text: &str) -> Result<Overlays, FieldError> {
        let mut o = Overlays::default();
        for word in text.split(',').map(str::trim).filter(|w| !w.is_empty()) {
            *o.flag(word).ok_or_else(|| {
                FieldError::new(
                    "overlays",
                    format!(
                        "unknown overlay '{word}'; overlays are: {}",
                        Overlays::NAMES.join(", ")
                    ),
                )
            })? = true;
        }
        Ok(o)
    }

    fn flag(&mut self, name: &str) -> Option<&mut bool> {
        match name {
            "wireframe" => Some(&mut self.wireframe),
            "tiles" => Some(&mut self.tiles),
            "frusta" => Some(&mut self.frusta),
            "bvh" => Some(&mut self.bvh),
            _ => None,
        }
    }

    /// No overlay asked for.
    pub fn is_empty(&self) -> bool {
        *self == Overlays::default()
    }

    /// Do these overlays need the render's [`Trace`]?
    pub fn need_trace(&self) -> bool {
        self.tiles || self.frusta || self.bvh
    }
}

impl fmt::Display for Overlays {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let on = [self.wireframe, self.tiles, self.frusta, self.bvh];
        let names: Vec<&str> = (Overlays::NAMES.iter().zip(on))
            .filter_map(|(n, on)| on.then_some(*n))
            .collect();
        f.write_str(&names.join(","))
    }
}
