//! What the viewer renders: one configuration (scene, camera, algorithm, oracles,
//! anti-aliasing, precision, size, threads), turned into the core's
//! [`RenderRequest`]. The words are the CLI's (`continuum render`), parsed by
//! the same functions in `continuum::request`.

use std::path::{Path, PathBuf};

use continuum::request::{parse_aa, parse_algorithm, parse_size, parse_viewport};
use continuum::shade::texture::TextureFilter;
use continuum::{AaMode, AlgorithmId, Camera, Precision, RenderRequest, Scene};

/// Whether `path` names a scene file or a model the loaders read.
pub fn has_scene_extension(path: &Path) -> bool {
    path.extension().is_some_and(|e| {
        continuum::scene::SCENE_EXTENSIONS
            .iter()
            .any(|x| e.eq_ignore_ascii_case(x))
    })
}

/// Where a scene comes from: a built-in name (in the scenes folder) or a path.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum SceneSource {
    Builtin(String),
    Path(PathBuf),
}

impl SceneSource {
    /// A user's word: a path when it names a file, otherwise a built-in name.
    pub fn parse(word: &str) -> SceneSource {
        let path = PathBuf::from(word);
        let has_extension = has_scene_extension(&path);
        if has_extension || path.components().count() > 1 {
            SceneSource::Path(path)
        } else {
            SceneSource::Builtin(word.to_owned())
        }
    }

    /// The name to show: the built-in name or the file name.
    pub fn label(&self) -> String {
        match self {
            SceneSource::Builtin(name) => name.clone(),
            SceneSource::Path(path) => path.file_name().map_or_else(
                || path.display().to_string(),
                |n| n.to_string_lossy().into_owned(),
            ),
        }
    }

    /// The argument `continuum::scene::load_named_or_path` takes.
    pub fn as_arg(&self) -> String {
        match self {
            SceneSource::Builtin(name) => name.clone(),
            SceneSource::Path(path) => path.display().to_string(),
        }
    }
}

/// Which scene camera the configuration starts from, and the user's edits to it.
#[derive(Clone, Debug, PartialEq)]
pub enum CameraChoice {
    /// The scene's camera of this name (`None`: its first camera), unmoved.
    Named(Option<String>),
    /// A camera the user orbited, panned or zoomed (or changed the viewport of).
    Moved(Camera),
}

/// The parts of a configuration that decide how a scene is rendered (what the
/// compare view's A and B may differ in).
#[derive(Clone, Debug, PartialEq)]
pub struct Method {
    pub algorithm: AlgorithmId,
    /// Explicit oracle settings on top of the algorithm's, the CLI's words; empty = none.
    pub oracles: String,
    pub aa: AaMode,
    pub precision: Precision,
    /// Texture filtering (for scenes with textures).
    pub texture_filter: TextureFilter,
}

impl Default for Method {
    fn default() -> Method {
        Method {
            algorithm: AlgorithmId::ThreeDBrute,
            oracles: String::new(),
            aa: AaMode::None,
            precision: Precision::F32,
            texture_filter: TextureFilter::default(),
        }
    }
}

/// One complete render configuration.
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    pub scene: SceneSource,
    pub camera: CameraChoice,
    /// A viewport in the CLI's words; empty = the camera's own.
    pub viewport: String,
    pub method: Method,
    pub width: u32,
    pub height: u32,
    /// Worker threads for the render (rayon pool size).
    pub threads: usize,
}

impl Default for Config {
    fn default() -> Config {
        Config {
            scene: SceneSource::Builtin("bunny".into()),
            camera: CameraChoice::Named(None),
            viewport: String::new(),
            method: Method::default(),
            width: 640,
            height: 480,
            threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
        }
    }
}

/// A configuration value that cannot be used, naming its field.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{field}: {message}")]
pub struct ConfigError {
    pub field: &'static str,
    pub message: String,
}

impl From<continuum::request::FieldError> for ConfigError {
    fn from(e: continuum::request::FieldError) -> ConfigError {
        ConfigError {
            field: e.field,
            message: e.message,
        }
    }
}

impl Config {
    /// The configuration the command line describes (the `render` flags' words).
    pub fn from_words(
        scene: &str,
        camera: Option<&str>,
        algorithm: &str,
        viewport: Option<&str>,
        aa: &str,
        precision: &str,
        size: &str,
    ) -> Result<Config, ConfigError> {
        let (width, height) = parse_size(size)?;
        Ok(Config {
            scene: SceneSource::parse(scene),
            camera: CameraChoice::Named(camera.map(str::to_owned)),
            viewport: viewport.unwrap_or_default().to_owned(),
            method: Method {
                algorithm: parse_algorithm(algorithm)?,
                oracles: String::new(),
                aa: parse_aa(aa)?,
                precision: Precision::parse(precision)?,
                texture_filter: TextureFilter::default(),
            },
            width,
            height,
            ..Config::default()
        })
    }

    /// The camera this configuration looks through in `scene`, viewport applied.
    pub fn camera_in(&self, scene: &Scene) -> Result<Camera, ConfigError> {
        let mut camera = match &self.camera {
            CameraChoice::Named(None) => scene.first_camera(),
            CameraChoice::Named(Some(name)) => scene.camera(name).map_err(|e| ConfigError {
                field: "camera",
                message: e.to_string(),
            })?,
            CameraChoice::Moved(camera) => camera.clone(),
        };
        if !self.viewport.trim().is_empty() {
            camera.viewport = parse_viewport(self.viewport.trim(), &camera)?;
        }
        Ok(camera)
    }

    /// The core request for `method` in `scene` (the compare view's B uses its own method).
    pub fn request(&self, scene: &Scene, method: &Method) -> Result<RenderRequest, ConfigError> {
        let oracles = method.oracles.trim();
        Ok(RenderRequest {
            algorithm: method.algorithm,
            oracles: (!oracles.is_empty()).then(|| oracles.to_owned()),
            camera: self.camera_in(scene)?,
            width: self.width,
            height: self.height,
            aa: method.aa,
            precision: method.precision,
            texture_filter: method.texture_filter,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_words_are_names_unless_they_look_like_files() {
        assert_eq!(
            SceneSource::parse("teapots"),
            SceneSource::Builtin("teapots".into())
        );
        assert_eq!(
            SceneSource::parse("model.GLB"),
            SceneSource::Path("model.GLB".into())
        );
        assert_eq!(
            SceneSource::parse("../shared/scenes/dragon"),
            SceneSource::Path("../shared/scenes/dragon".into())
        );
    }

    #[test]
    fn bad_words_name_their_field() {
        let err = |r: Result<Config, ConfigError>| r.expect_err("must be refused").field;
        let ok = ("bunny", None, "raycast", None, "none", "f32", "64x48");
        assert!(Config::from_words(ok.0, ok.1, ok.2, ok.3, ok.4, ok.5, ok.6).is_ok());
        assert_eq!(
            err(Config::from_words(
                "bunny", None, "4dr", None, "none", "f32", "64x48"
            )),
            "algorithm"
        );
        assert_eq!(
            err(Config::from_words(
                "bunny", None, "raycast", None, "msaa:3", "f32", "64x48"
            )),
            "aa"
        );
        assert_eq!(
            err(Config::from_words(
                "bunny", None, "raycast", None, "none", "f16", "64x48"
            )),
            "precision"
        );
        assert_eq!(
            err(Config::from_words(
                "bunny", None, "raycast", None, "none", "f32", "0x48"
            )),
            "size"
        );
    }
}
