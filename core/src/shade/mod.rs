//! Shading of visible samples: Lambert with every light of the scene (or a
//! headlight at the eye), base colour and emission from the material, normals
//! interpolated from the vertices where the mesh has them, and the effects the
//! scene calls for ([`plan`]): shadow rays, reflection rays ([`secondary`]),
//! and the colour and opacity of transparent fragments. Shading reads only the
//! triangle id and the sample's ray (the shaded point is where the ray meets
//! the triangle's plane), so algorithms that agree on the triangle produce
//! identical colours, whatever depth their family computed. Colours are
//! linear until the resolve ([`crate::aa`]) encodes the filtered pixel as sRGB.

pub(crate) mod eight;
pub(crate) mod secondary;

use std::time::Instant;

use glam::Vec3;

use glam::Vec2;

use crate::camera::View;
use crate::color::{BACKGROUND_COLOR, linear_rgb};
use crate::effects::{EffectCounters, EffectPlan, REFLECTION_DEPTH};
use crate::prepared::PreparedScene;
use crate::scene::LightKind;
use crate::texture::{self, TextureFilter};
use secondary::{Rays, barycentrics, plane_distance};

/// Share of the base colour that is lit regardless of the light direction.
const AMBIENT: f32 = 0.12;

/// Secondary rays start this far (relative to the scene's radius) from the
/// surface they leave, besides skipping its own triangle.
const SECONDARY_OFFSET: f32 = 1e-5;

/// Where a light shines from: the unit direction toward it (directional
/// lights), or its position.
#[derive(Clone, Copy, Debug)]
enum LightFrom {
    Direction(Vec3),
    Position(Vec3),
}

/// Shades samples of one scene.
#[derive(Clone, Debug)]
pub struct Shader<'a> {
    scene: &'a PreparedScene,
    view: &'a View,
    filter: TextureFilter,
    plan: EffectPlan,
    /// Per light: its slot among the plan's shadow lights.
    shadow_slot: Vec<Option<usize>>,
    /// Per light, what every sample uses alike: where it shines from, and its
    /// colour (at most one per channel).
    light_terms: Vec<(LightFrom, Vec3)>,
    rays: Rays<'a>,
    t_min: f32,
    /// Per material: are its samples shaded by [`Shader::shade_eight`]
    /// (a planar view, no texture, vertex colours, mirror or shadow ray)?
    lane_materials: Vec<bool>,
    /// Per material when there are several, for [`Shader::shade_eight`]:
    /// its base colour and emission as one row, `[r, g, b, 0, r, g, b, 0]`.
    material_rows: Vec<[f32; 8]>,
    /// Every material's samples are shaded in lanes (`lane_materials` all
    /// true and not empty): no per-sample material read decides it.
    all_in_lanes: bool,
    /// A light shines from a position: shading needs the shaded point, not
    /// only the ray's direction.
    point_lights: bool,
}

impl<'a> Shader<'a> {
    pub fn new(scene: &'a PreparedScene, view: &'a View, filter: TextureFilter) -> Shader<'a> {
        let plan = EffectPlan::of(&scene.scene);
        let shadow_slot = (0..scene.scene.lights.len())
            .map(|l| plan.shadow_lights.iter().position(|&s| s == l))
            .collect();
        let light_terms = (scene.scene.lights.iter())
            .map(|light| {
                let toward = match &light.kind {
                    LightKind::Directional { direction } => {
                        LightFrom::Direction(-direction.normalize_or_zero())
                    }
                    LightKind::Point { position } | LightKind::Spot { position, .. } => {
                        LightFrom::Position(*position)
                    }
                };
                (toward, Vec3::from(light.color).min(Vec3::ONE))
            })
            .collect::<Vec<_>>();
        let mesh = &scene.scene.mesh;
        // Lanes find vertices and materials by 32-bit offsets.
        let fits = |n: usize| n < (i32::MAX / 8) as usize;
        let lanes_fit = view.sphere.is_none()
            && fits(mesh.positions.len())
            && fits(mesh.triangles.len())
            && fits(scene.scene.materials.len())
            && plan.shadow_lights.is_empty()
            && mesh.colors.is_empty()
            && light_terms.iter().all(|(_, color)| color.is_finite());
        let lane_materials = match lanes_fit {
            false => Vec::new(),
            true => (scene.scene.materials.iter())
                .map(|m| {
                    (m.base_color_texture.is_none() || mesh.uvs.is_empty())
                        && m.reflectivity.clamp(0.0, 1.0) == 0.0
                })
                .collect(),
        };
        let material_rows = match scene.scene.materials.len() {
            1 => Vec::new(),
            _ => (scene.scene.materials.iter())
                .map(|m| {
                    let [r, g, b, _] = m.base_color;
                    let [er, eg, eb] = m.emissive;
                    [r, g, b, 0.0, er, eg, eb, 0.0]
                })
                .collect(),
        };
        let all_in_lanes = !lane_materials.is_empty() && lane_materials.iter().all(|&m| m);
        let point_lights =
            (light_terms.iter()).any(|(from, _)| matches!(from, LightFrom::Position(_)));
        Shader {
            scene,
            view,
            filter,
            plan,
            shadow_slot,
            light_terms,
            rays: Rays::new(scene),
            t_min: scene.bounds.radius().max(f32::MIN_POSITIVE) * SECONDARY_OFFSET,
            lane_materials,
            material_rows,
            all_in_lanes,
            point_lights,
        }
    }

    /// Triangle `id`'s material: read from the mesh only when the scene has
    /// more than one (a scene of one material — most scanned models — then
    /// costs no per-sample read for it).
    #[inline(always)]
    fn material_of(&self, id: u32) -> u32 {
        match self.scene.scene.materials.len() {
            1 => 0,
            _ => self.scene.scene.mesh.material_ids[id as usize],
        }
    }

    /// What this shader runs besides local shading.
    pub fn plan(&self) -> &EffectPlan {
        &self.plan
    }

    /// Linear colour of triangle `id` seen along the ray `origin + t·dir`
    /// from the sample at pixel position `at`; effect rays and texture lookups
    /// are counted into `effects`. `depth`, the family's own ray parameter
    /// there, stands in only where the ray runs along the triangle's plane.
    #[inline]
    pub fn shade(
        &self,
        id: u32,
        at: (f32, f32),
        (origin, dir): (Vec3, Vec3),
        depth: f32,
        effects: &mut EffectCounters,
    ) -> Vec3 {
        self.shade_fragment(id, at, (origin, dir), depth, effects).0
    }

    /// [`Shader::shade`] for a fragment of a see-through triangle: its colour
    /// and its opacity there — the material's opacity times the vertex
    /// colours' and the texture's alpha (glTF alpha mode `BLEND`).
    #[inline]
    pub fn shade_fragment(
        &self,
        id: u32,
        at: (f32, f32),
        ray: (Vec3, Vec3),
        depth: f32,
        effects: &mut EffectCounters,
    ) -> (Vec3, f32) {
        // The shaded point from the triangle's plane and the ray alone (not the
        // family's own depth), so every algorithm that finds the triangle
        // shades it alike — the 2D family included.
        let (origin, dir) = ray;
        let t = plane_distance(&self.scene.triangle(id), origin, dir).unwrap_or(depth);
        self.shade_surface(id, Some(at), origin, dir, t, 0, effects)
    }

    #[allow(
        clippy::too_many_arguments,
        reason = "one recursion step: the sample, its ray, the bounce and the counters"
    )]
    /// Triangle `id` where the ray `origin + t·dir` meets its plane (at `t`,
    /// from [`plane_distance`] for primary samples, from the hit for
    /// reflection rays): colour and opacity.
    fn shade_surface(
        &self,
        id: u32,
        at: Option<(f32, f32)>,
        origin: Vec3,
        dir: Vec3,
        t: f32,
        bounce: u32,
        effects: &mut EffectCounters,
    ) -> (Vec3, f32) {
        let point = origin + dir * t;
        let scene = &self.scene.scene;
        let mesh = &scene.mesh;
        let material = &scene.materials[self.material_of(id) as usize];
        let textured = material.base_color_texture.is_some() && !mesh.uvs.is_empty();
        // The §3.2 barycentrics, once per sample, when normals, texture
        // coordinates or vertex colours are interpolated.
        let lambda = (textured || !mesh.normals.is_empty() || !mesh.colors.is_empty())
            .then(|| barycentrics(&self.scene.triangle(id), origin, dir));
        let normal = self.shading_normal(id, lambda, dir);

        // 1. Direct light: Lambert per light, each shadow-casting light's term
        // only where its shadow ray reaches it, dimmed by the see-through
        // surfaces it passes (primary surfaces only, Fig. 8).
        let mut lit = Vec3::ZERO;
        if scene.lights.is_empty() {
            lit = Vec3::splat(normal.dot(-dir.normalize_or_zero()).max(0.0));
        }
        for (l, &(from, color)) in self.light_terms.iter().enumerate() {
            let (to_light, distance) = match from {
                LightFrom::Direction(toward) => (toward, f32::INFINITY),
                LightFrom::Position(position) => {
                    let to = position - point;
                    (to.normalize_or_zero(), to.length())
                }
            };
            let mut lambert = normal.dot(to_light);
            if lambert <= 0.0 {
                continue;
            }
            if bounce == 0
                && let Some(slot) = self.shadow_slot[l]
            {
                let start = Instant::now();
                effects.shadow_rays[slot] += 1;
                let passed = self
                    .rays
                    .transmittance(point, to_light, self.t_min, distance, id);
                effects.shadow_s += start.elapsed().as_secs_f64();
                if passed == 0.0 {
                    continue;
                }
                lambert *= passed;
            }
            lit += color * lambert;
        }
        let mut base = Vec3::new(
            material.base_color[0],
            material.base_color[1],
            material.base_color[2],
        );
        let mut alpha = material.opacity;
        if let Some(l) = lambda.filter(|_| !mesh.colors.is_empty()) {
            let [a, b, c] = mesh.triangles[id as usize].map(|v| mesh.colors[v as usize]);
            let color = a * l[0] + b * l[1] + c * l[2];
            base *= color.truncate();
            alpha *= color.w;
        }
        if let Some(texture) = &material.base_color_texture
            && let Some(Ok(chain)) = self.scene.textures.get(texture.image)
            && let Some(lambda) = lambda.filter(|_| textured)
        {
            let start = Instant::now();
            let (color, probes) = self.texture_lookup((chain, texture.wrap), id, at, lambda);
            effects.texture_lookups += 1;
            effects.texture_probes += u64::from(probes);
            effects.texture_s += start.elapsed().as_secs_f64();
            base *= color.truncate();
            alpha *= color.w;
        }
        let local = base * (AMBIENT + (1.0 - AMBIENT) * lit) + Vec3::from(material.emissive);

        // 2. A mirror's reflection ray, shaded where it lands.
        let r = material.reflectivity.clamp(0.0, 1.0);
        if r == 0.0 || bounce >= REFLECTION_DEPTH {
            return (local, alpha);
        }
        let start = Instant::now();
        effects.reflection_rays += 1;
        let view_dir = dir.normalize_or_zero();
        let mirrored = view_dir - 2.0 * view_dir.dot(normal) * normal;
        let hit = self.rays.closest(point, mirrored, self.t_min, id);
        effects.reflection_s += start.elapsed().as_secs_f64();
        let reflected = match hit {
            Some(h) => {
                self.shade_surface(h.id, None, point, mirrored, h.t, bounce + 1, effects)
                    .0
            }
            None => linear_rgb(BACKGROUND_COLOR),
        };
        (local * (1.0 - r) + reflected * r, alpha)
    }

    /// Triangle `id`'s texture at the sample, whose §3.2 barycentrics are
    /// `lambda`. The coordinates' derivatives come from the sample's 2×2
    /// pixel quad — the rays through the quad's first pixel and its right and
    /// lower neighbours, all met with this triangle's plane (`ddx_coarse`, the
    /// same in every algorithm, `raycast` included). A reflected surface (`at`
    /// = `None`) has no quad: the full-resolution level, bilinear.
    fn texture_lookup(
        &self,
        (chain, wrap): (&texture::MipChain, [crate::scene::Wrap; 2]),
        id: u32,
        at: Option<(f32, f32)>,
        lambda: [f32; 3],
    ) -> (glam::Vec4, u32) {
        let mesh = &self.scene.scene.mesh;
        let corners = &self.scene.triangle(id);
        let [a, b, c] = mesh.triangles[id as usize];
        let uv_of = |l: [f32; 3]| {
            mesh.uvs[a as usize] * l[0] + mesh.uvs[b as usize] * l[1] + mesh.uvs[c as usize] * l[2]
        };
        let uv_along = |o: Vec3, d: Vec3| uv_of(barycentrics(corners, o, d));
        let uv = uv_of(lambda);
        let Some((x, y)) = at else {
            return chain.sample(uv, (Vec2::ZERO, Vec2::ZERO), TextureFilter::Bilinear, wrap);
        };
        let qx = (x.floor() as i64 & !1) as f32 + 0.5;
        let qy = (y.floor() as i64 & !1) as f32 + 0.5;
        let uv_at = |px: f32, py: f32| self.view.ray(px, py).map(|(o, d)| uv_along(o, d));
        let (ddx, ddy) = match (uv_at(qx, qy), uv_at(qx + 1.0, qy), uv_at(qx, qy + 1.0)) {
            (Some(q), right, down) => (
                right.map_or(Vec2::ZERO, |r| r - q),
                down.map_or(Vec2::ZERO, |d| d - q),
            ),
            _ => (Vec2::ZERO, Vec2::ZERO),
        };
        chain.sample(uv, (ddx, ddy), self.filter, wrap)
    }

    /// The unit normal that shades triangle `id` where the ray along `dir`
    /// meets it, facing the ray: interpolated from the vertex normals with the
    /// perspective-correct barycentrics `λ_i = V_i / ΣV` (paper §3.2), `lambda`,
    /// when the mesh has them, the face normal otherwise.
    fn shading_normal(&self, id: u32, lambda: Option<[f32; 3]>, dir: Vec3) -> Vec3 {
        let face = self.scene.face_normals[id as usize];
        let toward = if face.dot(dir) > 0.0 { -1.0 } else { 1.0 };
        let mesh = &self.scene.scene.mesh;
        let Some(lambda) = lambda.filter(|_| !mesh.normals.is_empty()) else {
            return face * toward;
        };
        let [a, b, c] = mesh.triangles[id as usize];
        let vertex = [a, b, c].map(|v| mesh.normals[v as usize]);
        if vertex.contains(&Vec3::ZERO) {
            return face * toward;
        }
        let n = vertex[0] * lambda[0] + vertex[1] * lambda[1] + vertex[2] * lambda[2];
        match n.try_normalize() {
            Some(n) => n * toward,
            None => face * toward,
        }
    }
}
