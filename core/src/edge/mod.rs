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

pub use edge2d::{ScreenVertex, Triangle2D};
pub use edge3d::Triangle3D;

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
