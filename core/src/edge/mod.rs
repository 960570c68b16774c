//! Edge functions and the tie rule they share.
//!
//! - [`Triangle3D`]: the Plücker / signed-volume edge functions of paper
//!   §3.2, evaluated per sample with no projection.
//! - [`Triangle2D`]: projected 2D edge functions (paper §3.1).
//!
//! Both decide a sample that lies exactly on an edge with the same top-left rule
//! ([`owns_tie`]), so every sample of a closed mesh is covered exactly once.

mod edge2d;
mod edge3d;
mod homogeneous;

pub use edge2d::{ScreenVertex, Triangle2D};
pub use edge3d::Triangle3D;
pub use homogeneous::setup_homogeneous;

/// The tie rule of paper §3.4 (Direct3D's top-left rule written with derivatives):
/// a sample on an edge (`E = 0`) belongs to the triangle whose edge function grows
/// to the right (`∂E/∂x > 0`), or, for a horizontal edge, downwards
/// (`∂E/∂x = 0 ∧ ∂E/∂y > 0`). `E` is normalised so the triangle's inside is `E > 0`.
/// A vertex is decided by its two edges, each by this rule.
#[inline]
pub fn owns_tie(de_dx: f32, de_dy: f32) -> bool {
    de_dx > 0.0 || (de_dx == 0.0 && de_dy > 0.0)
}

/// Whether a sample with edge value `e` is inside that edge: strictly inside, or on
/// it and owning the tie.
#[inline(always)]
pub fn inside_edge(e: f32, owns: bool) -> bool {
    e > 0.0 || (e == 0.0 && owns)
}

/// A triangle set up for one view, as every coverage loop sees it. `sample` is
/// the single decision all algorithms of a family share: edge values in one fixed
/// operation order, the tie rule, then depth.
pub trait Coverage {
    /// The three edge values at image point `(x, y)`, positive inside.
    fn edge_values(&self, x: f32, y: f32) -> [f32; 3];

    /// Per edge: does it own samples exactly on it?
    fn owns(&self) -> [bool; 3];

    /// Depth `w` of the sample at `(x, y)` with edge values `edges`, or `None`
    /// when the sample is rejected (nearer than `near`, or not in front).
    fn depth(&self, edges: [f32; 3], x: f32, y: f32) -> Option<f32>;

    /// Per edge, a bound on how far two evaluations of [`Coverage::edge_values`]
    /// at points of the image can be off their exact values; binning rejects or
    /// accepts a block only beyond it.
    fn edge_error(&self) -> [f32; 3];

    /// No sample of the triangle has a smaller depth than this.
    fn min_depth(&self) -> f32;

    /// Coverage and depth of eight samples in a row, at `x0, x0 + 1, …, x0 + 7`:
    /// a bit mask of the covered ones and their depths. Bit for bit what
    /// [`Coverage::sample`] gives for each (implementations that vectorise it
    /// must round alike: no fused multiply-add, the same operation order).
    #[inline(always)]
    fn sample8(&self, x0: f32, y: f32) -> (u8, [f32; 8]) {
        let mut mask = 0;
        let mut depth = [0.0; 8];
        for (k, d) in depth.iter_mut().enumerate() {
            if let Some(w) = self.sample(x0 + k as f32, y) {
                mask |= 1 << k;
                *d = w;
            }
        }
        (mask, depth)
    }

    /// Coverage and depth of the sample at `(x, y)`.
    #[inline(always)]
    fn sample(&self, x: f32, y: f32) -> Option<f32> {
        let e = self.edge_values(x, y);
        let o = self.owns();
        if inside_edge(e[0], o[0]) && inside_edge(e[1], o[1]) && inside_edge(e[2], o[2]) {
            self.depth(e, x, y)
        } else {
            None
        }
    }
}
