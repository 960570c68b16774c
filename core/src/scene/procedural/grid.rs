//! A tessellated plane with shared vertices: at y = 0 (`plane = "xz"`, the
//! default) or at z = 0 (`plane = "xy"`).

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
    /// `xz` (the default) or `xy`: the plane the grid lies in.
    #[serde(default)]
    pub plane: Option<String>,
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
        let xy = match self.plane.as_deref() {
            None | Some("xz") => false,
            Some("xy") => true,
            Some(other) => {
                return Err(param_error("plane", format!("'{other}' is not xz or xy")));
            }
        };
        let mut mesh = Mesh::default();
        for j in 0..=nz {
            for i in 0..=nx {
                let (u, v) = (i as f32 / nx as f32, j as f32 / nz as f32);
                let (a, b) = ((u - 0.5) * sx, (v - 0.5) * sz);
                if xy {
                    mesh.positions.push(Vec3::new(a, b, 0.0));
                    mesh.normals.push(Vec3::Z);
                } else {
                    mesh.positions.push(Vec3::new(a, 0.0, b));
                    mesh.normals.push(Vec3::Y);
                }
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
