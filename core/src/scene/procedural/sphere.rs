//! A closed, welded icosphere: the icosahedron with each face split in four per
//! level, midpoints shared through an edge map.

use std::collections::HashMap;

use glam::Vec3;
use serde::Deserialize;

use super::{ParamError, check_count, param_error};
use crate::scene::Mesh;

#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphereParams {
    #[serde(default = "radius")]
    pub radius: f32,
    #[serde(default)]
    pub center: [f32; 3],
    /// Levels of 4-way splits (20·4^n triangles).
    #[serde(default = "subdivisions")]
    pub subdivisions: u32,
}

fn radius() -> f32 {
    1.0
}
fn subdivisions() -> u32 {
    4
}

impl SphereParams {
    pub fn generate(&self) -> Result<Mesh, ParamError> {
        if !(self.radius.is_finite() && self.radius > 0.0) {
            return Err(param_error("radius", "must be positive"));
        }
        if !self.center.iter().all(|c| c.is_finite()) {
            return Err(param_error("center", "must be finite"));
        }
        if self.subdivisions > 11 {
            return Err(param_error("subdivisions", "must be at most 11"));
        }
        check_count("subdivisions", 20 * 4u64.pow(self.subdivisions))?;
        // 1. The icosahedron.
        let t = (1.0 + 5.0f32.sqrt()) / 2.0;
        let mut dirs: Vec<Vec3> = [
            [-1.0, t, 0.0],
            [1.0, t, 0.0],
            [-1.0, -t, 0.0],
            [1.0, -t, 0.0],
            [0.0, -1.0, t],
            [0.0, 1.0, t],
            [0.0, -1.0, -t],
            [0.0, 1.0, -t],
            [t, 0.0, -1.0],
            [t, 0.0, 1.0],
            [-t, 0.0, -1.0],
            [-t, 0.0, 1.0],
        ]
        .iter()
        .map(|p| Vec3::from_array(*p).normalize())
        .collect();
        let mut faces: Vec<[u32; 3]> = vec![
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ];
        // 2. Split every face in four; midpoints shared per edge.
        for _ in 0..self.subdivisions {
            let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
            let mut mid = |a: u32, b: u32, dirs: &mut Vec<Vec3>| {
                *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    dirs.push((dirs[a as usize] + dirs[b as usize]).normalize());
                    (dirs.len() - 1) as u32
                })
            };
            let mut next = Vec::with_capacity(faces.len() * 4);
            for [a, b, c] in faces {
                let (ab, bc, ca) = (
                    mid(a, b, &mut dirs),
                    mid(b, c, &mut dirs),
                    mid(c, a, &mut dirs),
                );
                next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
            }
            faces = next;
        }
        let center = Vec3::from(self.center);
        Ok(Mesh {
            positions: dirs.iter().map(|d| center + *d * self.radius).collect(),
            normals: dirs,
            triangles: faces,
            ..Mesh::default()
        })
    }
}
