//! A fan: `count` triangles around one shared centre vertex in the plane z = 0
//! (the hard cases put that vertex on a pixel centre).

use glam::Vec3;
use serde::Deserialize;

use super::{ParamError, check_count, param_error};
use crate::scene::Mesh;

#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FanParams {
    /// Triangles around the centre, at least 3.
    pub count: u32,
    /// Distance of the ring vertices from the centre.
    #[serde(default = "radius")]
    pub radius: f32,
    /// Angle of the first ring vertex, degrees from +x towards +y.
    #[serde(default)]
    pub start_deg: f32,
}

fn radius() -> f32 {
    1.0
}

impl FanParams {
    pub fn generate(&self) -> Result<Mesh, ParamError> {
        if self.count < 3 {
            return Err(param_error("count", "a fan needs at least 3 triangles"));
        }
        check_count("count", u64::from(self.count))?;
        if !(self.radius.is_finite() && self.radius > 0.0) {
            return Err(param_error("radius", "must be positive"));
        }
        if !self.start_deg.is_finite() {
            return Err(param_error("start_deg", "must be finite"));
        }
        let mut mesh = Mesh::default();
        mesh.positions.push(Vec3::ZERO);
        let start = f64::from(self.start_deg).to_radians();
        for k in 0..self.count {
            let a = start + std::f64::consts::TAU * f64::from(k) / f64::from(self.count);
            let r = f64::from(self.radius);
            mesh.positions
                .push(Vec3::new((r * a.cos()) as f32, (r * a.sin()) as f32, 0.0));
        }
        let n = self.count;
        mesh.triangles = (0..n).map(|k| [0, 1 + k, 1 + (k + 1) % n]).collect();
        Ok(mesh)
    }
}
