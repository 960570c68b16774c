//! A tessellated plane at y = 0 with shared vertices.

use glam::{Vec2, Vec3};
use serde::Deserialize;

use super::{ParamError, check_count, param_error};
use crate::scene::Mesh;

#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridParams {
    /// Extent along x and z, centred on the origin.
    #[serde(default = "size")]
    pub size: [f32; 2],
    /// Quads along x and z.
    #[serde(default = "divisions")]
    pub divisions: [u32; 2],
}

fn size() -> [f32; 2] {
    [10.0, 10.0]
}
fn divisions() -> [u32; 2] {
    [16, 16]
}

impl GridParams {
    pub fn generate(&self) -> Result<Mesh, ParamError> {
        let [sx, sz] = self.size;
        if !(sx.is_finite() && sz.is_finite() && sx > 0.0 && sz > 0.0) {
            return Err(param_error("size", "both extents must be positive"));
        }
        let [nx, nz] = self.divisions;
        if nx == 0 || nz == 0 {
            return Err(param_error("divisions", "both must be at least 1"));
        }
        check_count("divisions", 2 * u64::from(nx) * u64::from(nz))?;
        let mut mesh = Mesh::default();
        for j in 0..=nz {
            for i in 0..=nx {
                let (u, v) = (i as f32 / nx as f32, j as f32 / nz as f32);
                mesh.positions
                    .push(Vec3::new((u - 0.5) * sx, 0.0, (v - 0.5) * sz));
                mesh.normals.push(Vec3::Y);
                mesh.uvs.push(Vec2::new(u, v));
            }
        }
        let at = |i: u32, j: u32| j * (nx + 1) + i;
        for j in 0..nz {
            for i in 0..nx {
                mesh.triangles
                    .push([at(i, j), at(i, j + 1), at(i + 1, j + 1)]);
                mesh.triangles
                    .push([at(i, j), at(i + 1, j + 1), at(i + 1, j)]);
            }
        }
        Ok(mesh)
    }
}
