//! Scene files, `scenes/NAME.toml`:
//!
//! ```toml
//! description = "What this scene is for"
//!
//! [[mesh]]                       # one or more
//! file = "assets/stanford_bunny.glb"   # relative to this file (.gltf/.glb/.obj), or
//! # generator = "teapots"              # a procedural generator, with
//! # params = { count = 4, resolution = 8 }, or
//! # positions = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]   # the triangles themselves
//! # triangles = [[0, 1, 2]]
//! translate = [0, 0, 0]          # optional transform: scale, then rotate (degrees, XYZ), then translate
//! rotate_deg = [0, 0, 0]
//! scale = 1.0                    # or [x, y, z]
//! material = "red"               # optional: a [[material]] for all of this mesh's triangles
//!
//! [[camera]]
//! name = "front"
//! eye = [0, 0.1, 0.3]
//! target = [0, 0.1, 0]
//! up = [0, 1, 0]                 # default
//! fov_y = 60                     # degrees, default 60
//! viewport = "perspective:60"    # optional: perspective[:FOV], orthographic:HEIGHT, parabolic, latlong
//! near = 0.001                   # optional
//!
//! [[light]]
//! kind = "directional"           # or "point", "spot"
//! direction = [-1, -1, -1]       # directional and spot
//! position = [0, 5, 0]           # point and spot
//! color = [1, 1, 1]
//! intensity = 1.0
//! shadows = false
//!
//! [[material]]                   # overrides a loaded material of that name, or defines one
//! name = "red"
//! base_color = [0.8, 0.1, 0.1, 1.0]
//! emissive = [0, 0, 0]
//! opacity = 1.0
//! reflectivity = 0.0
//! base_color_texture = "assets/checker.png"   # optional: PNG or JPEG, sRGB, on the mesh's uvs
//! texture_wrap = "repeat"        # or "clamp", "mirror" (with a texture)
//! ```
//! Unknown keys are errors that name the key.

use std::path::Path;

use glam::{EulerRot, Mat4, Quat, Vec3};
use serde::Deserialize;

use super::procedural::Generator;
use super::{
    ImageRef, ImageSource, Light, LightKind, Material, Mesh, PartLocation, Scene, SceneError,
    TextureRef, Wrap, load_path, validate_part,
};
use crate::camera::{Camera, Viewport};

/// The parsed TOML document.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    #[serde(default)]
    pub description: Option<String>,
    #[serde(default)]
    pub mesh: Vec<MeshEntry>,
    #[serde(default)]
    pub camera: Vec<CameraEntry>,
    #[serde(default)]
    pub light: Vec<LightEntry>,
    #[serde(default)]
    pub material: Vec<MaterialEntry>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshEntry {
    pub file: Option<String>,
    pub generator: Option<String>,
    #[serde(default)]
    pub params: toml::Table,
    /// Inline geometry: vertex positions and triangles indexing them.
    pub positions: Option<Vec<[f32; 3]>>,
    pub triangles: Option<Vec<[u32; 3]>>,
    pub translate: Option<[f32; 3]>,
    pub rotate_deg: Option<[f32; 3]>,
    pub scale: Option<Scale>,
    pub material: Option<String>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(untagged)]
pub enum Scale {
    Uniform(f32),
    Axes([f32; 3]),
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraEntry {
    pub name: String,
    pub eye: [f32; 3],
    pub target: [f32; 3],
    #[serde(default = "up")]
    pub up: [f32; 3],
    /// Vertical field of view of a perspective camera, degrees.
    pub fov_y: Option<f32>,
    /// A viewport in the CLI's words (`perspective:60`, `orthographic:10`,
    /// `parabolic`, `latlong`); default perspective with `fov_y`.
    pub viewport: Option<String>,
    pub near: Option<f32>,
}

fn up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightEntry {
    pub name: Option<String>,
    pub kind: String,
    pub direction: Option<[f32; 3]>,
    pub position: Option<[f32; 3]>,
    #[serde(default = "white")]
    pub color: [f32; 3],
    #[serde(default = "unit")]
    pub intensity: f32,
    #[serde(default)]
    pub shadows: bool,
    pub inner_cone_deg: Option<f32>,
    pub outer_cone_deg: Option<f32>,
}

fn white() -> [f32; 3] {
    [1.0; 3]
}
fn unit() -> f32 {
    1.0
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialEntry {
    pub name: String,
    pub base_color: Option<[f32; 4]>,
    pub emissive: Option<[f32; 3]>,
    pub opacity: Option<f32>,
    pub reflectivity: Option<f32>,
    /// A PNG or JPEG file (relative to the scene file) as the base-colour
    /// texture, on the mesh's first texture coordinates.
    pub base_color_texture: Option<String>,
    /// How its coordinates wrap outside [0, 1]: `repeat` (default), `clamp`
    /// or `mirror`, for both axes.
    pub texture_wrap: Option<String>,
}

impl SceneFile {
    /// The scene this document describes: `source` names it in messages,
    /// `dir` resolves the files it references.
    pub fn build(&self, source: &str, name: String, dir: &Path) -> Result<Scene, SceneError> {
        build(self, source, name, dir)
    }
}

/// A scene file's text (`source` names it in messages; files it references
/// are found in `dir`).
pub fn load_scene_file_str(text: &str, source: &str, dir: &Path) -> Result<Scene, SceneError> {
    let doc: SceneFile = toml::from_str(text).map_err(|e| SceneError::SceneFile {
        path: source.to_string(),
        message: e.to_string(),
    })?;
    build(&doc, source, source.to_string(), dir)
}

/// Loads `path` (a scene file) with everything it references.
pub fn load_scene_file(path: &Path) -> Result<Scene, SceneError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| SceneError::Io {
        path: file.clone(),
        message: e.to_string(),
    })?;
    let doc: SceneFile = toml::from_str(&text).map_err(|e| SceneError::SceneFile {
        path: file.clone(),
        message: e.to_string(),
    })?;
    let name = path
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("scene")
        .to_string();
    build(&doc, &file, name, path.parent().unwrap_or(Path::new(".")))
}

fn build(doc: &SceneFile, file: &str, name: String, dir: &Path) -> Result<Scene, SceneError> {
    let err = |message: String| SceneError::SceneFile {
        path: file.to_string(),
        message,
    };
    let mut scene = Scene {
        name,
        source: file.to_string(),
        ..Scene::default()
    };
    if doc.mesh.is_empty() {
        return Err(err(
            "no [[mesh]] entry: a scene needs at least one mesh".into()
        ));
    }

    // 1. Meshes, each with its own materials, cameras and lights appended.
    let mut mesh_ranges = Vec::new();
    for (k, entry) in doc.mesh.iter().enumerate() {
        if entry.triangles.is_some() != entry.positions.is_some() {
            return Err(err(format!(
                "mesh {k}: 'positions' and 'triangles' go together"
            )));
        }
        let part = match (&entry.file, &entry.generator, &entry.positions) {
            (Some(f), None, None) => {
                if !entry.params.is_empty() {
                    return Err(err(format!(
                        "mesh {k}: 'params' belongs with 'generator', not 'file'"
                    )));
                }
                load_path(&dir.join(f))?
            }
            (None, Some(g), None) => {
                let generator = Generator::from_table(g, entry.params.clone())
                    .map_err(|m| err(format!("mesh {k} (generator '{g}'): {m}")))?;
                let mesh = generator
                    .generate()
                    .map_err(|e| err(format!("mesh {k} (generator '{g}'): {e}")))?;
                Scene {
                    name: g.clone(),
                    source: format!("generator:{g}"),
                    mesh,
                    materials: vec![Material::default()],
                    ..Scene::default()
                }
            }
            (None, None, Some(positions)) => {
                let triangles = entry.triangles.clone().unwrap_or_default();
                let mesh = Mesh {
                    positions: positions.iter().map(|&p| Vec3::from(p)).collect(),
                    material_ids: vec![0; triangles.len()],
                    triangles,
                    ..Mesh::default()
                };
                let location = PartLocation::part(file, k.to_string(), None);
                validate_part(&mesh.positions, &mesh.triangles, &location)?;
                Scene {
                    name: format!("mesh {k}"),
                    source: file.to_string(),
                    mesh,
                    materials: vec![Material::default()],
                    ..Scene::default()
                }
            }
            _ => {
                return Err(err(format!(
                    "mesh {k}: give exactly one of 'file', 'generator' or 'positions' (with 'triangles')"
                )));
            }
        };
        let mut part = part;
        part.mesh
            .transform(entry_transform(entry).map_err(|m| err(format!("mesh {k}: {m}")))?);
        let first = scene.mesh.triangles.len();
        let material_offset = scene.materials.len() as u32;
        scene.mesh.append(&part.mesh, material_offset);
        mesh_ranges.push(first..scene.mesh.triangles.len());
        scene.materials.extend(part.materials);
        scene.cameras.extend(part.cameras);
        scene.lights.extend(part.lights);
        scene.images.extend(part.images);
        scene.warnings.extend(part.warnings);
    }

    // 2. Material overrides and definitions.
    for m in &doc.material {
        let existing = scene.materials.iter().position(|x| x.name == m.name);
        let index = existing.unwrap_or_else(|| {
            scene.materials.push(Material {
                name: m.name.clone(),
                ..Material::default()
            });
            scene.materials.len() - 1
        });
        let target = &mut scene.materials[index];
        if let Some(c) = m.base_color {
            target.base_color = c;
        }
        if let Some(e) = m.emissive {
            target.emissive = e;
        }
        if let Some(o) = m.opacity {
            if !(0.0..=1.0).contains(&o) {
                return Err(err(format!(
                    "material '{}': opacity must be in [0, 1]",
                    m.name
                )));
            }
            target.opacity = o;
        }
        if let Some(r) = m.reflectivity {
            if !(0.0..=1.0).contains(&r) {
                return Err(err(format!(
                    "material '{}': reflectivity must be in [0, 1]",
                    m.name
                )));
            }
            target.reflectivity = r;
        }
        let wrap = match m.texture_wrap.as_deref() {
            None => Wrap::Repeat,
            Some(word) => Wrap::parse(word).ok_or_else(|| {
                err(format!(
                    "material '{}': texture_wrap '{word}' is not one of {}",
                    m.name,
                    Wrap::WORDS
                ))
            })?,
        };
        if m.texture_wrap.is_some() && m.base_color_texture.is_none() {
            return Err(err(format!(
                "material '{}': texture_wrap needs a base_color_texture",
                m.name
            )));
        }
        if let Some(file) = &m.base_color_texture {
            let path = dir.join(file);
            if !path.is_file() {
                return Err(err(format!(
                    "material '{}': base_color_texture '{}' is not a file",
                    m.name,
                    path.display()
                )));
            }
            scene.images.push(ImageRef {
                name: Some(file.clone()),
                source: ImageSource::File(path),
            });
            scene.materials[index].base_color_texture = Some(TextureRef {
                image: scene.images.len() - 1,
                tex_coord: 0,
                wrap: [wrap; 2],
            });
        }
    }
    for (entry, range) in doc.mesh.iter().zip(mesh_ranges) {
        if let Some(name) = &entry.material {
            let index = scene
                .materials
                .iter()
                .position(|m| &m.name == name)
                .ok_or_else(|| {
                    err(format!(
                        "mesh material '{name}' is not defined by a [[material]] entry"
                    ))
                })?;
            scene.mesh.material_ids[range].fill(index as u32);
        }
    }

    // 3. Cameras and lights of the scene file come first.
    let mut cameras = Vec::new();
    for c in &doc.camera {
        let perspective = Viewport::Perspective {
            fov_y_deg: c.fov_y.unwrap_or(60.0),
        };
        let viewport = match &c.viewport {
            None => perspective,
            Some(text) => Viewport::parse(text, perspective)
                .map_err(|e| err(format!("camera '{}': {e}", c.name)))?,
        };
        let camera = Camera {
            name: c.name.clone(),
            eye: Vec3::from(c.eye),
            target: Vec3::from(c.target),
            up: Vec3::from(c.up),
            viewport,
            near: c.near,
        };
        camera
            .validate()
            .map_err(|e| err(format!("camera '{}': {e}", c.name)))?;
        cameras.push(camera);
    }
    cameras.append(&mut scene.cameras);
    scene.cameras = cameras;

    let mut lights = Vec::new();
    for (k, l) in doc.light.iter().enumerate() {
        lights.push(light(l).map_err(|m| err(format!("light {k}: {m}")))?);
    }
    lights.append(&mut scene.lights);
    scene.lights = lights;

    scene.validate()?;
    Ok(scene)
}

fn entry_transform(entry: &MeshEntry) -> Result<Mat4, String> {
    let scale = match entry.scale {
        None => Vec3::ONE,
        Some(Scale::Uniform(s)) => Vec3::splat(s),
        Some(Scale::Axes(a)) => Vec3::from(a),
    };
    if !(scale.is_finite() && scale.cmpne(Vec3::ZERO).all()) {
        return Err("scale must be finite and non-zero".into());
    }
    let r = Vec3::from(entry.rotate_deg.unwrap_or([0.0; 3]));
    let t = Vec3::from(entry.translate.unwrap_or([0.0; 3]));
    if !(r.is_finite() && t.is_finite()) {
        return Err("rotate_deg and translate must be finite".into());
    }
    let rotation = Quat::from_euler(
        EulerRot::XYZ,
        r.x.to_radians(),
        r.y.to_radians(),
        r.z.to_radians(),
    );
    Ok(Mat4::from_scale_rotation_translation(scale, rotation, t))
}

fn light(l: &LightEntry) -> Result<Light, String> {
    let vec = |field: &str, v: Option<[f32; 3]>| -> Result<Vec3, String> {
        let v = Vec3::from(v.ok_or(format!("a {} light needs '{field}'", l.kind))?);
        if !v.is_finite() {
            return Err(format!("{field} must be finite"));
        }
        Ok(v)
    };
    let dir = |v: Option<[f32; 3]>| -> Result<Vec3, String> {
        let d = vec("direction", v)?;
        d.try_normalize()
            .ok_or_else(|| "direction must not be zero".to_string())
    };
    let kind = match l.kind.as_str() {
        "directional" => LightKind::Directional {
            direction: dir(l.direction)?,
        },
        "point" => LightKind::Point {
            position: vec("position", l.position)?,
        },
        "spot" => LightKind::Spot {
            position: vec("position", l.position)?,
            direction: dir(l.direction)?,
            inner_cone: l.inner_cone_deg.unwrap_or(0.0).to_radians(),
            outer_cone: l.outer_cone_deg.unwrap_or(45.0).to_radians(),
        },
        other => {
            return Err(format!(
                "kind '{other}' is not one of directional, point, spot"
            ));
        }
    };
    if !(l.intensity.is_finite() && l.intensity >= 0.0) {
        return Err("intensity must be non-negative".into());
    }
    Ok(Light {
        name: l.name.clone().unwrap_or_else(|| l.kind.clone()),
        kind,
        color: l.color,
        intensity: l.intensity,
        shadows: l.shadows,
    })
}
