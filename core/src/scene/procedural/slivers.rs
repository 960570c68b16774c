//! Slivers: `count` long thin triangles side by side, sharing their long edges,
//! in the plane z = 0. Each has a base of `length / aspect` on the x axis and
//! its apex at `(0, length)`, all the same apex: together they partition a
//! thin wedge, and every one has the aspect ratio `aspect`.

use glam::Vec3;
use serde::Deserialize;

use super::{ParamError, check_count, param_error};
use crate::scene::Mesh;

#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SliverParams {
    /// Slivers side by side.
    pub count: u32,
    /// Height of each sliver (distance from the base to the shared apex).
    #[serde(default = "length")]
    pub length: f32,
    /// Height over base width, at least 1.
    #[serde(default = "aspect")]
    pub aspect: f64,
}

fn length() -> f32 {
    1.0
}
fn aspect() -> f64 {
    1e6
}

impl SliverParams {
    pub fn generate(&self) -> Result<Mesh, ParamError> {
        if self.count == 0 {
            return Err(param_error("count", "must be at least 1"));
        }
        check_count("count", u64::from(self.count))?;
        if !(self.length.is_finite() && self.length > 0.0) {
            return Err(param_error("length", "must be positive"));
        }
        if !(self.aspect.is_finite() && self.aspect >= 1.0) {
            return Err(param_error("aspect", "must be at least 1"));
        }
        let width = f64::from(self.length) / self.aspect;
        let half = f64::from(self.count) * 0.5;
        let mut mesh = Mesh::default();
        for k in 0..=self.count {
            let x = (f64::from(k) - half) * width;
            mesh.positions.push(Vec3::new(x as f32, 0.0, 0.0));
        }
        let apex = self.count + 1;
        mesh.positions.push(Vec3::new(0.0, self.length, 0.0));
        mesh.triangles = (0..self.count).map(|k| [k, k + 1, apex]).collect();
        Ok(mesh)
    }
}
