//! Mesh validation shared by every loader: finite positions, indices in range,
//! something to draw. Degenerate triangles pass (they load but are never drawn).

use std::fmt;

use glam::Vec3;

use super::SceneError;

/// Where a part of a scene came from: file, mesh and primitive, for messages.
#[derive(Clone, Debug)]
pub struct PartLocation {
    pub file: String,
    /// E.g. `mesh 'Cube' (#0)` or `object 'bunny'`.
    pub mesh: Option<String>,
    /// E.g. `primitive 1`.
    pub primitive: Option<String>,
}

impl PartLocation {
    pub fn whole(file: &str) -> Self {
        PartLocation {
            file: file.to_string(),
            mesh: None,
            primitive: None,
        }
    }

    pub fn part(file: &str, mesh: String, primitive: Option<String>) -> Self {
        PartLocation {
            file: file.to_string(),
            mesh: Some(mesh),
            primitive,
        }
    }
}

impl fmt::Display for PartLocation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some(m) = &self.mesh {
            write!(f, ": {m}")?;
        }
        if let Some(p) = &self.primitive {
            write!(f, ", {p}")?;
        }
        Ok(())
    }
}

/// The largest coordinate a position may have: beyond it the BVH's quantized
/// child boxes (obvhs) break down and setup products approach f32's range.
pub const MAX_COORDINATE: f32 = 1e18;

/// Checks one part (a glTF primitive, an OBJ object, a generated mesh): every
/// position finite and within ±[`MAX_COORDINATE`], every index
/// `< positions.len()`, at least one triangle.
pub fn validate_part(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    location: &PartLocation,
) -> Result<(), SceneError> {
    if let Some((i, p)) = positions.iter().enumerate().find(|(_, p)| !p.is_finite()) {
        return Err(SceneError::Invalid {
            location: location.to_string(),
            problem: format!(
                "vertex {i} has a non-finite position [{}, {}, {}]",
                p.x, p.y, p.z
            ),
        });
    }
    if let Some((i, p)) = positions
        .iter()
        .enumerate()
        .find(|(_, p)| p.abs().max_element() > MAX_COORDINATE)
    {
        return Err(SceneError::Invalid {
            location: location.to_string(),
            problem: format!(
                "vertex {i} at [{}, {}, {}] is beyond ±{MAX_COORDINATE:e}, the largest coordinate continuum renders",
                p.x, p.y, p.z
            ),
        });
    }
    let n = positions.len();
    for (t, tri) in triangles.iter().enumerate() {
        for (k, &v) in tri.iter().enumerate() {
            if v as usize >= n {
                return Err(SceneError::Invalid {
                    location: location.to_string(),
                    problem: format!(
                        "index {} (triangle {t}, corner {k}) is {v}, out of range for {n} vertices",
                        3 * t + k
                    ),
                });
            }
        }
    }
    if triangles.is_empty() {
        return Err(SceneError::Empty {
            location: location.to_string(),
        });
    }
    Ok(())
}
