//! Seeded random triangles ("triangle soup"): no shared vertices, random sizes
//! and orientations, reproducible from the seed.

use glam::Vec3;
use serde::Deserialize;

use super::{ParamError, check_count, param_error};
use crate::scene::Mesh;

#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SoupParams {
    #[serde(default = "count")]
    pub count: u32,
    #[serde(default = "seed")]
    pub seed: u64,
    /// Smallest and largest triangle size (distance of the vertices from its centre, ×2).
    #[serde(default = "min_size")]
    pub min_size: f32,
    #[serde(default = "max_size")]
    pub max_size: f32,
    /// Triangle centres lie in the cube `[-extent, extent]³`.
    #[serde(default = "extent")]
    pub extent: f32,
}

fn count() -> u32 {
    10_000
}
fn seed() -> u64 {
    1
}
fn min_size() -> f32 {
    0.05
}
fn max_size() -> f32 {
    1.0
}
fn extent() -> f32 {
    5.0
}

impl SoupParams {
    pub fn generate(&self) -> Result<Mesh, ParamError> {
        if !(self.min_size.is_finite() && self.min_size > 0.0) {
            return Err(param_error("min_size", "must be positive"));
        }
        if !(self.max_size.is_finite() && self.max_size >= self.min_size) {
            return Err(param_error("max_size", "must be at least min_size"));
        }
        if !(self.extent.is_finite() && self.extent > 0.0) {
            return Err(param_error("extent", "must be positive"));
        }
        if self.count == 0 {
            return Err(param_error("count", "must be at least 1"));
        }
        check_count("count", u64::from(self.count))?;
        let mut rng = fastrand::Rng::with_seed(self.seed);
        let mut uniform = |lo: f32, hi: f32| lo + (hi - lo) * rng.f32();
        let mut mesh = Mesh::default();
        for t in 0..self.count {
            let e = self.extent;
            let center = Vec3::new(uniform(-e, e), uniform(-e, e), uniform(-e, e));
            let size = uniform(self.min_size, self.max_size);
            for _ in 0..3 {
                // A random direction: rejection-sample the unit ball.
                let dir = loop {
                    let v = Vec3::new(uniform(-1.0, 1.0), uniform(-1.0, 1.0), uniform(-1.0, 1.0));
                    let l = v.length_squared();
                    if l > 1e-4 && l <= 1.0 {
                        break v / l.sqrt();
                    }
                };
                mesh.positions.push(center + dir * (size * 0.5));
            }
            mesh.triangles.push([3 * t, 3 * t + 1, 3 * t + 2]);
        }
        Ok(mesh)
    }
}
