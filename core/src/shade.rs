//! Shading of visible samples. For now: Lambert with the scene's first light (or a
//! headlight at the eye), base colour from the material, two-sided face normals.
//! Shading reads only the triangle id and `w` of a pixel, so algorithms that agree
//! on those produce identical colours.

use glam::Vec3;
use rayon::prelude::*;

use crate::camera::{View, pixel_center};
use crate::framebuffer::{BACKGROUND, Framebuffer};
use crate::prepared::PreparedScene;
use crate::scene::LightKind;

/// Background colour (sRGB).
pub const BACKGROUND_COLOR: [u8; 4] = [24, 24, 28, 255];

/// Colour of pixels the viewport casts no ray through (outside the parabolic disc).
pub const OUTSIDE_VIEWPORT_COLOR: [u8; 4] = [0, 0, 0, 255];

/// Share of the base colour that is lit regardless of the light direction.
const AMBIENT: f32 = 0.12;

/// Shades every pixel of `fb` from its triangle id and depth.
pub fn shade(scene: &PreparedScene, view: &View, fb: &mut Framebuffer) {
    let light = scene.scene.lights.first();
    let width = fb.width as usize;
    let (ids, depth) = (&fb.triangle_id, &fb.depth);
    fb.color
        .par_chunks_mut(width)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, out) in row.iter_mut().enumerate() {
                let i = y * width + x;
                let Some((origin, dir)) = view.ray(pixel_center(x as u32), pixel_center(y as u32))
                else {
                    *out = OUTSIDE_VIEWPORT_COLOR;
                    continue;
                };
                let id = ids[i];
                if id == BACKGROUND {
                    *out = BACKGROUND_COLOR;
                    continue;
                }
                let point = origin + dir * depth[i];
                // Direction towards the light and its colour.
                let (to_light, light_color) = match light {
                    None => (-dir.normalize(), Vec3::ONE),
                    Some(l) => {
                        let to = match &l.kind {
                            LightKind::Directional { direction } => -*direction,
                            LightKind::Point { position } | LightKind::Spot { position, .. } => {
                                *position - point
                            }
                        };
                        (to.normalize_or_zero(), Vec3::from(l.color).min(Vec3::ONE))
                    }
                };
                let normal = scene.face_normals[id as usize];
                let lambert = normal.dot(to_light).abs();
                let material =
                    &scene.scene.materials[scene.scene.mesh.material_ids[id as usize] as usize];
                let base = Vec3::new(
                    material.base_color[0],
                    material.base_color[1],
                    material.base_color[2],
                );
                let emissive = Vec3::from(material.emissive);
                let linear = base * light_color * (AMBIENT + (1.0 - AMBIENT) * lambert) + emissive;
                *out = [
                    encode_srgb(linear.x),
                    encode_srgb(linear.y),
                    encode_srgb(linear.z),
                    255,
                ];
            }
        });
}

/// Linear [0, 1] → sRGB byte.
#[inline]
pub fn encode_srgb(v: f32) -> u8 {
    let v = v.clamp(0.0, 1.0);
    let s = if v <= 0.003_130_8 {
        v * 12.92
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0 + 0.5) as u8
}
