//! Scenes: one flattened triangle mesh in world space, its materials, cameras and
//! lights, and the loaders that build them (glTF, OBJ, TOML scene files, procedural
//! generators).
//!
//! Every loader ends in [`validate_part`] and [`Scene::validate`], so a `Scene` that
//! exists has finite positions and in-range indices; degenerate triangles are kept
//! (they load) but the renderer never draws them.

mod error;
mod gltf_loader;
mod obj_loader;
pub mod procedural;
mod scene_file;
mod validate;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Vec2, Vec3};

pub use error::SceneError;
pub use gltf_loader::{load_gltf, load_gltf_slice};
pub use obj_loader::{load_obj, load_obj_slice};
pub use scene_file::{SceneFile, load_scene_file, load_scene_file_str};
pub use validate::{MAX_COORDINATE, PartLocation, validate_part};

use crate::camera::Camera;
use crate::ground::Bounds;

/// Triangle geometry in world space, structure-of-arrays.
///
/// Invariants (checked by [`Scene::validate`]): every position is finite; every index
/// is `< positions.len()`; `material_ids.len() == triangles.len()`; `normals`,
/// `uvs` and `colors` are either empty or one per vertex.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Vertex positions, world space.
    pub positions: Vec<Vec3>,
    /// Per-vertex shading normals, or empty when the source has none (a zero
    /// vector marks a vertex of a part that had none).
    pub normals: Vec<Vec3>,
    /// Per-vertex texture coordinates (the set the material's base-colour
    /// texture names, else set 0), or empty.
    pub uvs: Vec<Vec2>,
    /// Per-vertex colours (linear RGBA, glTF `COLOR_0`), multiplying the base
    /// colour; empty when the source has none (white pads parts without).
    pub colors: Vec<glam::Vec4>,
    /// Vertex indices, three per triangle. The index of a triangle in this list is
    /// its *triangle id* everywhere in continuum.
    pub triangles: Vec<[u32; 3]>,
    /// Material index per triangle, into [`Scene::materials`].
    pub material_ids: Vec<u32>,
}

impl Mesh {
    /// Number of triangles, degenerate ones included.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The three vertex positions of triangle `id`.
    #[inline]
    pub fn triangle_positions(&self, id: usize) -> [Vec3; 3] {
        let [a, b, c] = self.triangles[id];
        [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ]
    }

    /// Appends `other`, offsetting its indices and material ids. Normals, uvs
    /// and colours stay one per vertex: the side that lacks them is padded
    /// with zeros (colours with white).
    pub fn append(&mut self, other: &Mesh, material_offset: u32) {
        let base = self.positions.len();
        let with_normals = !self.normals.is_empty() || !other.normals.is_empty();
        let with_uvs = !self.uvs.is_empty() || !other.uvs.is_empty();
        let with_colors = !self.colors.is_empty() || !other.colors.is_empty();
        self.positions.extend_from_slice(&other.positions);
        if with_normals {
            self.normals.resize(base, Vec3::ZERO);
            self.normals.extend_from_slice(&other.normals);
            self.normals.resize(self.positions.len(), Vec3::ZERO);
        }
        if with_uvs {
            self.uvs.resize(base, Vec2::ZERO);
            self.uvs.extend_from_slice(&other.uvs);
            self.uvs.resize(self.positions.len(), Vec2::ZERO);
        }
        if with_colors {
            self.colors.resize(base, glam::Vec4::ONE);
            self.colors.extend_from_slice(&other.colors);
            self.colors.resize(self.positions.len(), glam::Vec4::ONE);
        }
        let base = base as u32;
        self.triangles.extend(
            other
                .triangles
                .iter()
                .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
        );
        self.material_ids
            .extend(other.material_ids.iter().map(|m| m + material_offset));
    }

    /// Applies an affine transform to positions (and its inverse transpose to normals).
    pub fn transform(&mut self, m: glam::Mat4) {
        for p in &mut self.positions {
            *p = m.transform_point3(*p);
        }
        let nm = glam::Mat3::from_mat4(m).inverse().transpose();
        for n in &mut self.normals {
            if *n != Vec3::ZERO {
                *n = (nm * *n).normalize_or_zero();
            }
        }
    }

    /// Axis-aligned bounds of all vertices that triangles use.
    pub fn bounds(&self) -> Bounds {
        let mut b = Bounds::EMPTY;
        for t in &self.triangles {
            for &i in t {
                b.grow(self.positions[i as usize]);
            }
        }
        b
    }
}

/// A surface description. Colours are linear RGB(A).
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    /// glTF `baseColorFactor` (linear RGBA).
    pub base_color: [f32; 4],
    /// glTF `baseColorTexture`, if any.
    pub base_color_texture: Option<TextureRef>,
    /// glTF `emissiveFactor` (linear RGB).
    pub emissive: [f32; 3],
    /// 1 = opaque. glTF alpha mode BLEND sets it from the base colour alpha.
    pub opacity: f32,
    /// 0 = no mirror reflection.
    pub reflectivity: f32,
    pub double_sided: bool,
}

impl Default for Material {
    fn default() -> Self {
        Material {
            name: "default".into(),
            base_color: [0.8, 0.8, 0.8, 1.0],
            base_color_texture: None,
            emissive: [0.0; 3],
            opacity: 1.0,
            reflectivity: 0.0,
            double_sided: true,
        }
    }
}

/// A reference to a texture image of the scene (decoded when an effect needs it).
#[derive(Clone, Debug, PartialEq)]
pub struct TextureRef {
    /// Index into [`Scene::images`].
    pub image: usize,
    /// Which texture coordinate set the texture uses (the loaders read that
    /// set into [`Mesh::uvs`] for the material's triangles).
    pub tex_coord: u32,
    /// How coordinates outside [0, 1] wrap, along u (glTF `wrapS`) and v (`wrapT`).
    pub wrap: [Wrap; 2],
}

/// A texture sampler's wrap mode (glTF's three).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Wrap {
    /// The texture tiles (glTF's default).
    #[default]
    Repeat,
    /// Coordinates clamp to the edge texels.
    ClampToEdge,
    /// The texture tiles, every other copy mirrored.
    MirroredRepeat,
}

impl Wrap {
    /// The TOML words.
    pub const WORDS: &'static str = "repeat, clamp, mirror";

    pub fn parse(s: &str) -> Option<Wrap> {
        match s {
            "repeat" => Some(Wrap::Repeat),
            "clamp" => Some(Wrap::ClampToEdge),
            "mirror" => Some(Wrap::MirroredRepeat),
            _ => None,
        }
    }

    /// Texel `i` of a row of `n` texels, for any integer `i`.
    #[inline]
    pub fn texel(self, i: i64, n: u32) -> usize {
        let n = i64::from(n);
        (match self {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::ClampToEdge => i.clamp(0, n - 1),
            Wrap::MirroredRepeat => {
                let m = i.rem_euclid(2 * n);
                if m < n { m } else { 2 * n - 1 - m }
            }
        }) as usize
    }
}

/// Where a texture image lives.
#[derive(Clone, Debug, PartialEq)]
pub enum ImageSource {
    /// A file next to the scene (resolved to an absolute or scene-relative path).
    File(PathBuf),
    /// Bytes embedded in a `.glb` buffer or a data URI.
    Embedded { mime_type: String, bytes: Arc<[u8]> },
    /// A `data:` URI, kept verbatim.
    DataUri(String),
}

/// A texture image referenced by materials.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageRef {
    pub name: Option<String>,
    pub source: ImageSource,
}

/// A punctual light (glTF KHR_lights_punctual or a TOML `[[light]]`).
#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    pub name: String,
    pub kind: LightKind,
    /// Linear RGB.
    pub color: [f32; 3],
    pub intensity: f32,
    /// Whether the light casts shadows (TOML `shadows = true`; glTF lights do).
    pub shadows: bool,
}

#[derive(Clone, Debug, PartialEq)]
pub enum LightKind {
    /// Light travelling along `direction` (unit length).
    Directional {
        direction: Vec3,
    },
    Point {
        position: Vec3,
    },
    Spot {
        position: Vec3,
        direction: Vec3,
        inner_cone: f32,
        outer_cone: f32,
    },
}

/// A loaded scene, ready to be prepared for rendering.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// Short name (a built-in scene's name, or the file stem).
    pub name: String,
    /// Where it came from (a path or `generator:NAME`), for messages.
    pub source: String,
    pub mesh: Mesh,
    pub materials: Vec<Material>,
    /// Named cameras; may be empty (then [`Scene::default_camera`] frames the bounds).
    pub cameras: Vec<Camera>,
    pub lights: Vec<Light>,
    pub images: Vec<ImageRef>,
    /// Things the loader skipped or changed, for the user to read.
    pub warnings: Vec<String>,
}

impl Scene {
    /// Bounds of the geometry.
    pub fn bounds(&self) -> Bounds {
        self.mesh.bounds()
    }

    /// The camera named `name`, or an error listing the cameras there are.
    pub fn camera(&self, name: &str) -> Result<Camera, SceneError> {
        if name == "default" && !self.cameras.iter().any(|c| c.name == "default") {
            return Ok(self.default_camera());
        }
        self.cameras
            .iter()
            .find(|c| c.name == name)
            .cloned()
            .ok_or_else(|| SceneError::UnknownCamera {
                scene: self.name.clone(),
                camera: name.to_string(),
                available: self.camera_names(),
            })
    }

    /// The scene's cameras plus `default` (which always exists: it frames the
    /// bounds unless the scene names a camera so).
    pub fn all_cameras(&self) -> Vec<Camera> {
        let mut cameras = self.cameras.clone();
        if !cameras.iter().any(|c| c.name == "default") {
            cameras.push(self.default_camera());
        }
        cameras
    }

    /// Names of [`Scene::all_cameras`].
    pub fn camera_names(&self) -> Vec<String> {
        self.all_cameras().into_iter().map(|c| c.name).collect()
    }

    /// The scene's first camera, or one that frames its bounds.
    pub fn first_camera(&self) -> Camera {
        self.cameras
            .first()
            .cloned()
            .unwrap_or_else(|| self.default_camera())
    }

    /// A camera looking at the centre of the bounds from the front-right-above,
    /// far enough that the bounding sphere fits a 45° vertical field of view.
    pub fn default_camera(&self) -> Camera {
        Camera::framing(&self.bounds())
    }

    /// Checks the invariants of [`Mesh`] and that material ids are in range.
    pub fn validate(&self) -> Result<(), SceneError> {
        let location = PartLocation::whole(&self.source);
        validate_part(&self.mesh.positions, &self.mesh.triangles, &location)?;
        if self.mesh.triangles.is_empty() {
            return Err(SceneError::Empty {
                location: location.to_string(),
            });
        }
        if let Some((t, &m)) = self
            .mesh
            .material_ids
            .iter()
            .enumerate()
            .find(|(_, m)| **m as usize >= self.materials.len())
        {
            return Err(SceneError::Invalid {
                location: location.to_string(),
                problem: format!(
                    "triangle {t} uses material {m}, but there are {} materials",
                    self.materials.len()
                ),
            });
        }
        Ok(())
    }
}

/// The file extensions [`load_path`] reads (lower case).
pub const SCENE_EXTENSIONS: [&str; 4] = ["toml", "gltf", "glb", "obj"];

/// Loads a scene from a path, by extension: `.gltf`/`.glb`, `.obj`, `.toml`.
pub fn load_path(path: &Path) -> Result<Scene, SceneError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    match ext.as_str() {
        "gltf" | "glb" => load_gltf(path),
        "obj" => load_obj(path),
        "toml" => load_scene_file(path),
        _ => Err(SceneError::UnsupportedFormat {
            path: path.display().to_string(),
        }),
    }
}

/// Resolves a scene argument: a built-in name found in `scenes_dir`
/// (`scenes_dir/NAME.toml`), or a path to a `.toml`, `.gltf`, `.glb` or `.obj`.
pub fn load_named_or_path(arg: &str, scenes_dir: &Path) -> Result<Scene, SceneError> {
    let as_path = Path::new(arg);
    let has_ext = as_path.extension().is_some();
    if !has_ext && !arg.contains('/') {
        let file = scenes_dir.join(format!("{arg}.toml"));
        if file.is_file() {
            return load_scene_file(&file);
        }
        return Err(SceneError::UnknownScene {
            name: arg.to_string(),
            // Listing what is there is a courtesy of this error message.
            available: builtin_names(scenes_dir).unwrap_or_default(),
        });
    }
    if !as_path.exists() {
        return Err(SceneError::Io {
            path: arg.to_string(),
            message: "no such file".into(),
        });
    }
    load_path(as_path)
}

/// Names of the `*.toml` scenes in `scenes_dir`, sorted; an error naming the
/// folder when it cannot be read (never an empty list standing for one).
pub fn builtin_names(scenes_dir: &Path) -> Result<Vec<String>, SceneError> {
    let io = |e: std::io::Error| SceneError::Io {
        path: scenes_dir.display().to_string(),
        message: e.to_string(),
    };
    let mut names = Vec::new();
    for entry in std::fs::read_dir(scenes_dir).map_err(io)? {
        let p = entry.map_err(io)?.path();
        if p.extension().and_then(|x| x.to_str()) == Some("toml")
            && let Some(stem) = p.file_stem().and_then(|s| s.to_str())
        {
            names.push(stem.to_string());
        }
    }
    names.sort();
    Ok(names)
}

/// The folder of built-in scenes: `$CONTINUUM_SCENES`, else `scenes/` beside the
/// executable (or one level up), else the repository's `scenes/` this crate was
/// built from.
pub fn default_scenes_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("CONTINUUM_SCENES") {
        return PathBuf::from(dir);
    }
    if let Ok(exe) = std::env::current_exe() {
        for up in exe.ancestors().skip(1).take(3) {
            let candidate = up.join("scenes");
            if candidate.join("bunny.toml").is_file() {
                return candidate;
            }
        }
    }
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes")
}
