//! The effect plan: simulate only what the scene calls for. From the scene
//! alone it decides which secondary rays a render casts — shadow rays for each
//! light with `shadows = true` (TOML) or from glTF, reflection rays when a
//! material has `reflectivity > 0`, texture lookups when a material has a
//! base-colour texture, sorted blending of fragments when a material has
//! `opacity < 1` — and the counters report what each cost.
//! A scene that asks for nothing runs nothing: no rays, no time.

use serde::Serialize;

use crate::scene::Scene;

/// Reflection rays followed from one sample: one, as in paper Fig. 8 (a
/// reflected surface is lit without further rays of its own).
pub const REFLECTION_DEPTH: u32 = 1;

/// What a render of a scene runs besides primary visibility and local shading.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct EffectPlan {
    /// Indices into `Scene::lights` of the lights that cast shadows.
    pub shadow_lights: Vec<usize>,
    /// Whether any material reflects.
    pub reflections: bool,
    /// Whether any material has a base-colour texture.
    pub textures: bool,
    /// Whether any material is see-through (`opacity < 1`): its fragments are
    /// kept per sample, sorted and blended (A-buffer).
    pub transparency: bool,
}

impl EffectPlan {
    pub fn of(scene: &Scene) -> EffectPlan {
        EffectPlan {
            shadow_lights: scene
                .lights
                .iter()
                .enumerate()
                .filter(|(_, l)| l.shadows)
                .map(|(i, _)| i)
                .collect(),
            reflections: scene.materials.iter().any(|m| m.reflectivity > 0.0),
            textures: scene
                .materials
                .iter()
                .any(|m| m.base_color_texture.is_some()),
            transparency: scene.materials.iter().any(|m| m.opacity < 1.0),
        }
    }

    /// The effects that run, in report order: `textures`, `shadows`,
    /// `reflections`, `transparency`.
    pub fn names(&self) -> Vec<&'static str> {
        [
            (self.textures, "textures"),
            (!self.shadow_lights.is_empty(), "shadows"),
            (self.reflections, "reflections"),
            (self.transparency, "transparency"),
        ]
        .into_iter()
        .filter_map(|(runs, name)| runs.then_some(name))
        .collect()
    }
}

/// What the effects of one tile cost: rays per shadow-casting light (in plan
/// order), reflection rays, and the worker time each took.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EffectCounters {
    /// Texture lookups (one per textured shading), the bilinear probes they
    /// took, and their time.
    pub texture_lookups: u64,
    pub texture_probes: u64,
    pub texture_s: f64,
    pub shadow_rays: Vec<u64>,
    pub shadow_s: f64,
    pub reflection_rays: u64,
    pub reflection_s: f64,
    /// Transparent fragments blended into samples, and the time sorting,
    /// shading and blending them took.
    pub fragments_blended: u64,
    pub transparency_s: f64,
}

impl EffectCounters {
    pub fn for_plan(plan: &EffectPlan) -> EffectCounters {
        EffectCounters {
            shadow_rays: vec![0; plan.shadow_lights.len()],
            ..EffectCounters::default()
        }
    }

    pub fn add(&mut self, o: &EffectCounters) {
        if self.shadow_rays.len() < o.shadow_rays.len() {
            self.shadow_rays.resize(o.shadow_rays.len(), 0);
        }
        for (a, b) in self.shadow_rays.iter_mut().zip(&o.shadow_rays) {
            *a += b;
        }
        self.shadow_s += o.shadow_s;
        self.texture_lookups += o.texture_lookups;
        self.texture_probes += o.texture_probes;
        self.texture_s += o.texture_s;
        self.reflection_rays += o.reflection_rays;
        self.reflection_s += o.reflection_s;
        self.fragments_blended += o.fragments_blended;
        self.transparency_s += o.transparency_s;
    }

    /// The `Stats.effects` entries: textures, one per shadow-casting light,
    /// reflections, transparency, in that order.
    pub fn report(&self, plan: &EffectPlan, scene: &Scene) -> Vec<EffectStats> {
        let mut out: Vec<EffectStats> = Vec::new();
        if plan.textures {
            out.push(EffectStats {
                effect: "textures",
                light: None,
                rays: 0,
                lookups: self.texture_lookups,
                texel_probes: self.texture_probes,
                fragments: 0,
                worker_ms: self.texture_s * 1e3,
            });
        }
        let shadows: Vec<EffectStats> = plan
            .shadow_lights
            .iter()
            .zip(&self.shadow_rays)
            .map(|(&light, &rays)| EffectStats {
                effect: "shadows",
                light: Some(scene.lights[light].name.clone()),
                rays,
                lookups: 0,
                texel_probes: 0,
                fragments: 0,
                worker_ms: 0.0,
            })
            .collect();
        out.extend(shadows);
        // The shadow time is measured for all lights together; share it by rays.
        let total_shadow: u64 = self.shadow_rays.iter().sum();
        for e in out.iter_mut().filter(|e| e.effect == "shadows") {
            if total_shadow > 0 {
                e.worker_ms = self.shadow_s * 1e3 * e.rays as f64 / total_shadow as f64;
            }
        }
        if plan.reflections {
            out.push(EffectStats {
                effect: "reflections",
                light: None,
                rays: self.reflection_rays,
                lookups: 0,
                texel_probes: 0,
                fragments: 0,
                worker_ms: self.reflection_s * 1e3,
            });
        }
        if plan.transparency {
            out.push(EffectStats {
                effect: "transparency",
                light: None,
                rays: 0,
                lookups: 0,
                texel_probes: 0,
                fragments: self.fragments_blended,
                worker_ms: self.transparency_s * 1e3,
            });
        }
        out
    }
}

/// One effect that ran, and what it cost.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EffectStats {
    /// `textures`, `shadows`, `reflections` or `transparency`.
    pub effect: &'static str,
    /// The light a shadow entry belongs to.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub light: Option<String>,
    /// Rays cast for it.
    pub rays: u64,
    /// Texture lookups (textures only) and the bilinear probes they took.
    pub lookups: u64,
    pub texel_probes: u64,
    /// Transparent fragments blended (transparency only).
    pub fragments: u64,
    /// Time the render's workers spent on it, summed over threads (shadow
    /// time is measured for all lights together and shared out by rays).
    pub worker_ms: f64,
}

impl Scene {
    /// The effects this scene calls for, from the scene alone (the
    /// effect plan's words): `textures`,
    /// `shadows`, `reflections`, `transparency`.
    pub fn effects(&self) -> Vec<&'static str> {
        EffectPlan::of(self).names()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Light, LightKind, Material};

    fn light(name: &str, shadows: bool) -> Light {
        Light {
            name: name.into(),
            kind: LightKind::Directional {
                direction: glam::Vec3::NEG_Y,
            },
            color: [1.0; 3],
            intensity: 1.0,
            shadows,
        }
    }

    #[test]
    fn the_plan_follows_the_scene_alone() {
        let mut scene = Scene {
            lights: vec![light("sun", true), light("fill", false), light("rim", true)],
            materials: vec![Material::default()],
            ..Scene::default()
        };
        let plan = EffectPlan::of(&scene);
        assert_eq!(plan.shadow_lights, vec![0, 2]);
        assert!(!plan.reflections);
        scene.materials.push(Material {
            reflectivity: 0.5,
            ..Material::default()
        });
        scene.lights[0].shadows = false;
        let plan = EffectPlan::of(&scene);
        assert_eq!(plan.shadow_lights, vec![2]);
        assert!(plan.reflections);
        assert!(EffectPlan::of(&Scene::default()).names().is_empty());
    }

    #[test]
    fn the_report_names_each_light_and_shares_time_by_rays() {
        let scene = Scene {
            lights: vec![light("sun", true), light("rim", true)],
            materials: vec![Material {
                reflectivity: 0.2,
                ..Material::default()
            }],
            ..Scene::default()
        };
        let plan = EffectPlan::of(&scene);
        let mut c = EffectCounters::for_plan(&plan);
        c.add(&EffectCounters {
            shadow_rays: vec![30, 10],
            shadow_s: 0.004,
            reflection_rays: 7,
            reflection_s: 0.001,
            ..EffectCounters::default()
        });
        let report = c.report(&plan, &scene);
        assert_eq!(report.len(), 3);
        assert_eq!(
            (report[0].light.as_deref(), report[0].rays),
            (Some("sun"), 30)
        );
        assert!(
            (report[0].worker_ms - 3.0).abs() < 1e-9 && (report[1].worker_ms - 1.0).abs() < 1e-9
        );
        assert_eq!((report[2].effect, report[2].rays), ("reflections", 7));
    }
}
