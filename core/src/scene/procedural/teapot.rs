//! The Newell teapot, tessellated from its 32 bicubic Bézier patches (public
//! domain; `scenes/assets/teapot.bpt`), welded, copied on a grid.

use glam::{DVec3, Mat4, Vec3};
use serde::Deserialize;

use super::weld::weld;
use super::{ParamError, check_count, param_error};
use crate::scene::Mesh;

/// The patch file: the patch count, then per patch a `3 3` line and 16 `x y z`
/// control points, row-major, z up.
pub const TEAPOT_PATCHES: &str = include_str!("../../../../scenes/assets/teapot.bpt");

#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TeapotParams {
    /// Copies, on a square grid in the xz plane.
    #[serde(default = "one")]
    pub count: u32,
    /// Quads per patch side (each patch gives 2·resolution² triangles).
    #[serde(default = "eight")]
    pub resolution: u32,
    /// Distance between neighbouring copies.
    #[serde(default = "spacing")]
    pub spacing: f32,
}

fn one() -> u32 {
    1
}
fn eight() -> u32 {
    8
}
fn spacing() -> f32 {
    8.0
}

/// Parses the patch file into 32 patches of 16 control points.
pub fn parse_patches(text: &str) -> Result<Vec<[DVec3; 16]>, String> {
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
    let count: usize = lines
        .next()
        .and_then(|l| l.parse().ok())
        .ok_or("missing patch count")?;
    let mut patches = Vec::with_capacity(count);
    for p in 0..count {
        let degree = lines
            .next()
            .ok_or(format!("patch {p}: missing degree line"))?;
        if degree.split_whitespace().collect::<Vec<_>>() != ["3", "3"] {
            return Err(format!(
                "patch {p}: only bicubic (3 3) patches are supported, got '{degree}'"
            ));
        }
        let mut cp = [DVec3::ZERO; 16];
        for (k, slot) in cp.iter_mut().enumerate() {
            let line = lines
                .next()
                .ok_or(format!("patch {p}: missing control point {k}"))?;
            let v: Vec<f64> = line
                .split_whitespace()
                .filter_map(|s| s.parse().ok())
                .collect();
            if v.len() != 3 {
                return Err(format!(
                    "patch {p}: control point {k} is not 'x y z': '{line}'"
                ));
            }
            *slot = DVec3::new(v[0], v[1], v[2]);
        }
        patches.push(cp);
    }
    Ok(patches)
}

fn bernstein(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t]
}

/// One welded teapot, y up, standing on y = 0.
pub fn teapot(resolution: u32) -> Mesh {
    let patches = parse_patches(TEAPOT_PATCHES).expect("the shipped patch file parses");
    let r = resolution as usize;
    let side = r + 1;
    // 1. Evaluate every patch on a (r+1)² grid, in f64.
    let mut points = Vec::with_capacity(patches.len() * side * side);
    for cp in &patches {
        for i in 0..side {
            let bu = bernstein(i as f64 / r as f64);
            for j in 0..side {
                let bv = bernstein(j as f64 / r as f64);
                let mut p = DVec3::ZERO;
                for a in 0..4 {
                    for b in 0..4 {
                        p += cp[a * 4 + b] * (bu[a] * bv[b]);
                    }
                }
                // z up → y up.
                points.push(DVec3::new(p.x, p.z, -p.y));
            }
        }
    }
    // 2. Weld patch seams (and the collapsed poles) so patches share vertices.
    let (positions, remap) = weld(&points, 1e-4);
    // 3. Two triangles per grid quad.
    let mut triangles = Vec::with_capacity(patches.len() * r * r * 2);
    for patch in 0..patches.len() {
        let base = patch * side * side;
        let at = |i: usize, j: usize| remap[base + i * side + j];
        for i in 0..r {
            for j in 0..r {
                triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
    }
    Mesh {
        positions,
        triangles,
        ..Mesh::default()
    }
}

impl TeapotParams {
    pub fn generate(&self) -> Result<Mesh, ParamError> {
        if self.count == 0 {
            return Err(param_error("count", "must be at least 1"));
        }
        if self.resolution == 0 || self.resolution > 1024 {
            return Err(param_error("resolution", "must be in 1..=1024"));
        }
        if !(self.spacing.is_finite() && self.spacing > 0.0) {
            return Err(param_error("spacing", "must be positive"));
        }
        check_count(
            "count",
            u64::from(self.count) * 64 * u64::from(self.resolution).pow(2),
        )?;
        let one = teapot(self.resolution);
        let columns = (self.count as f32).sqrt().ceil() as u32;
        let rows = self.count.div_ceil(columns);
        let mut mesh = Mesh::default();
        for k in 0..self.count {
            let (cx, cz) = (k % columns, k / columns);
            let offset = Vec3::new(
                (cx as f32 - (columns - 1) as f32 * 0.5) * self.spacing,
                0.0,
                (cz as f32 - (rows - 1) as f32 * 0.5) * self.spacing,
            );
            // A different heading per copy, so the copies do not line up.
            let m = Mat4::from_translation(offset)
                * Mat4::from_rotation_y((k as f32 * 37.0).to_radians());
            let mut copy = one.clone();
            copy.transform(m);
            copy.material_ids.clear();
            mesh.append(&copy, 0);
        }
        Ok(mesh)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shipped_patches_parse() {
        let p = parse_patches(TEAPOT_PATCHES).unwrap();
        assert_eq!(p.len(), 32);
    }

    #[test]
    fn patches_are_welded() {
        let m = teapot(4);
        assert_eq!(m.triangles.len(), 32 * 4 * 4 * 2);
        // Unwelded there would be 32·25 = 800 vertices.
        assert!(m.positions.len() < 700, "{}", m.positions.len());
        // Every edge of the body is shared: count edges used once.
        let mut edges = std::collections::HashMap::new();
        for t in &m.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if a != b {
                    *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
                }
            }
        }
        let border = edges.values().filter(|&&n| n == 1).count();
        // Only the spout's opening and the handle/spout rims stay open.
        assert!(border < edges.len() / 10, "{border} of {}", edges.len());
    }
}
