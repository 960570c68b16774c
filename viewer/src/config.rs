//! What the viewer renders: one configuration (scene, camera, algorithm, oracles,
//! anti-aliasing, precision, size, threads), turned into the core's
//! [`RenderRequest`]. The words are the CLI's (`continuum render`), through the
//! same front door (`continuum::RenderWords`) and capability check (`continuum::check`).

use std::path::{Path, PathBuf};

use continuum::{
    AaMode, AlgorithmId, Camera, CameraSpec, FieldError, Oracles, Overlays, Precision,
    PreparedScene, RenderRequest, RenderWords, Scene, Settings, TextureFilter,
};

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
    /// What to draw over the images (the render records its trace when one needs it).
    pub overlays: Overlays,
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
            overlays: Overlays::default(),
        }
    }
}

impl Config {
    /// The configuration the command line describes (the `render` flags'
    /// words, through the front door every front end shares).
    pub fn from_words(words: &RenderWords) -> Result<Config, FieldError> {
        let settings = words.settings()?;
        let camera = match &settings.camera {
            None => None,
            Some(CameraSpec::Named(name)) => Some(name.clone()),
            Some(CameraSpec::Explicit(_)) => {
                return Err(FieldError::new(
                    "camera",
                    "the viewer takes a camera's name",
                ));
            }
        };
        Ok(Config {
            scene: SceneSource::parse(&words.scene),
            camera: CameraChoice::Named(camera),
            viewport: settings.viewport.clone().unwrap_or_default(),
            method: Method {
                algorithm: settings.algorithm,
                oracles: settings.oracles.to_string(),
                aa: settings.aa,
                precision: settings.precision,
                texture_filter: settings.texture_filter,
            },
            width: settings.width,
            height: settings.height,
            overlays: settings.overlays,
            ..Config::default()
        })
    }

    /// The camera before the viewport words: the scene's, or the one the user moved.
    fn base_camera(&self, scene: &Scene) -> Result<Camera, FieldError> {
        match &self.camera {
            CameraChoice::Named(name) => {
                let spec = name.clone().map(CameraSpec::Named);
                CameraSpec::resolve(spec.as_ref(), scene)
            }
            CameraChoice::Moved(camera) => Ok(camera.clone()),
        }
    }

    /// The settings `method` renders this configuration with, through the
    /// front door every front end shares.
    fn settings(&self, method: &Method) -> Result<Settings, FieldError> {
        let oracles = method.oracles.trim();
        let viewport = self.viewport.trim();
        Ok(Settings {
            oracles: if oracles.is_empty() {
                Oracles::default()
            } else {
                Oracles::parse(oracles)?
            },
            viewport: (!viewport.is_empty()).then(|| viewport.to_owned()),
            aa: method.aa,
            precision: method.precision,
            texture_filter: method.texture_filter,
            overlays: self.overlays,
            ..Settings::new(method.algorithm, self.width, self.height)
        })
    }

    /// The core request for `method` in `scene` (the compare view's B uses
    /// its own method), checked by the renderer's capability check.
    pub fn request(
        &self,
        scene: &PreparedScene,
        method: &Method,
    ) -> Result<RenderRequest, FieldError> {
        let request = self
            .settings(method)?
            .request_through(self.base_camera(&scene.scene)?)?;
        continuum::check(&request, Some(scene))?;
        Ok(request)
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
        let words = |algorithm: &str, aa: &str, precision: &str, size: &str| RenderWords {
            scene: "bunny".into(),
            aa: Some(aa.into()),
            precision: Some(precision.into()),
            size: Some(size.into()),
            ..RenderWords::new(algorithm)
        };
        let err = |w: RenderWords| Config::from_words(&w).expect_err("must be refused").field;
        assert!(Config::from_words(&words("raycast", "none", "f32", "64x48")).is_ok());
        assert_eq!(err(words("4dr", "none", "f32", "64x48")), "algorithm");
        assert_eq!(err(words("raycast", "msaa:3", "f32", "64x48")), "aa");
        assert_eq!(err(words("raycast", "none", "f16", "64x48")), "precision");
        assert_eq!(err(words("raycast", "none", "f32", "0x48")), "size");
        let mut w = words("3dr-full", "none", "f32", "64x48");
        w.oracles = Some("split=3".into());
        assert_eq!(err(w), "oracles");
    }
}
