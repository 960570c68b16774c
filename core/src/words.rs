//! Floor 9: the front door for a user's words. The command line, the HTTP
//! service and the viewer all hand their words (`--algorithm 3dr-full
//! --viewport parabolic --aa msaa:4 …`, the same in JSON or in the viewer's
//! fields) to [`RenderWords`], which parses each into its typed value and,
//! with a scene, into a [`RenderRequest`]. Errors name the field.

use std::str::FromStr;

use glam::Vec3;
use serde::Deserialize;

use crate::aa::AaMode;
use crate::camera::Camera;
use crate::ground::{AlgorithmId, FieldError, MAX_DIMENSION};
use crate::pipeline::Oracles;
use crate::precision::Precision;
use crate::request::RenderRequest;
use crate::scene::Scene;
use crate::texture::TextureFilter;
use crate::trace::Overlays;
use crate::viewport::Viewport;

/// A render as a user says it, every value in the command line's words.
/// Only `algorithm` is required; the rest default as `continuum render` does.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderWords {
    /// A built-in scene name or a path: which scenes a front end offers, and
    /// how it loads them, is its own business; the words carry the name.
    #[serde(default)]
    pub scene: String,
    pub algorithm: String,
    pub camera: Option<CameraSpec>,
    pub oracles: Option<String>,
    pub viewport: Option<String>,
    pub aa: Option<String>,
    pub precision: Option<String>,
    pub texture_filter: Option<String>,
    pub size: Option<String>,
    /// Overlays to draw over the images: `wireframe,tiles,frusta,bvh`.
    pub overlays: Option<String>,
}

/// The words parsed: everything of a request but the scene's camera.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    pub algorithm: AlgorithmId,
    pub oracles: Oracles,
    pub camera: Option<CameraSpec>,
    /// The viewport in words (resolved against the camera: bare
    /// `perspective` keeps its field of view, bare `orthographic` its
    /// framing height); `None`: the camera's own.
    pub viewport: Option<String>,
    pub aa: AaMode,
    pub precision: Precision,
    pub texture_filter: TextureFilter,
    pub width: u32,
    pub height: u32,
    /// What to draw over the images (the request records a trace when an
    /// overlay needs one).
    pub overlays: Overlays,
}

/// The size `continuum render` and the service render at when none is given.
pub const DEFAULT_SIZE: (u32, u32) = (640, 480);

impl RenderWords {
    /// Words for `algorithm`, everything else defaulted.
    pub fn new(algorithm: impl Into<String>) -> RenderWords {
        RenderWords {
            algorithm: algorithm.into(),
            ..RenderWords::default()
        }
    }

    /// Parses every word that needs no scene; the first bad one is the error.
    pub fn settings(&self) -> Result<Settings, FieldError> {
        let algorithm = parse_algorithm(&self.algorithm)?;
        let (width, height) = match &self.size {
            Some(text) => parse_size(text)?,
            None => DEFAULT_SIZE,
        };
        fn word(w: &Option<String>) -> Option<&str> {
            w.as_deref().map(str::trim).filter(|w| !w.is_empty())
        }
        if let Some(text) = word(&self.viewport) {
            // The words now; bare `orthographic` takes its height from the camera later.
            Viewport::parse(text, Viewport::Orthographic { height: 1.0 })?;
        }
        Ok(Settings {
            algorithm,
            oracles: word(&self.oracles)
                .map(Oracles::parse)
                .transpose()?
                .unwrap_or_default(),
            camera: self.camera.clone(),
            viewport: word(&self.viewport).map(str::to_owned),
            aa: word(&self.aa)
                .map(AaMode::parse)
                .transpose()?
                .unwrap_or_default(),
            precision: word(&self.precision)
                .map(Precision::parse)
                .transpose()?
                .unwrap_or_default(),
            texture_filter: word(&self.texture_filter)
                .map(TextureFilter::parse)
                .transpose()?
                .unwrap_or_default(),
            width,
            height,
            overlays: word(&self.overlays)
                .map(Overlays::parse)
                .transpose()?
                .unwrap_or_default(),
        })
    }

    /// The typed request these words make in `scene`.
    pub fn request(&self, scene: &Scene) -> Result<RenderRequest, FieldError> {
        self.settings()?.request(scene)
    }
}

impl Settings {
    /// Settings for `algorithm` at `width × height`, everything else default.
    pub fn new(algorithm: AlgorithmId, width: u32, height: u32) -> Settings {
        Settings {
            algorithm,
            oracles: Oracles::default(),
            camera: None,
            viewport: None,
            aa: AaMode::None,
            precision: Precision::F32,
            texture_filter: TextureFilter::default(),
            width,
            height,
            overlays: Overlays::default(),
        }
    }

    /// The request in `scene`: its camera named by [`Settings::camera`] (the
    /// first one when none is), through [`Settings::viewport`].
    pub fn request(&self, scene: &Scene) -> Result<RenderRequest, FieldError> {
        self.request_through(CameraSpec::resolve(self.camera.as_ref(), scene)?)
    }

    /// The request through `camera` (a front end's own, e.g. one the user
    /// moved), its viewport replaced by [`Settings::viewport`] when given.
    pub fn request_through(&self, mut camera: Camera) -> Result<RenderRequest, FieldError> {
        if let Some(text) = &self.viewport {
            camera.viewport = Viewport::parse(text, camera.viewport)?;
        }
        Ok(RenderRequest {
            algorithm: self.algorithm,
            oracles: self.oracles,
            camera,
            width: self.width,
            height: self.height,
            aa: self.aa,
            precision: self.precision,
            texture_filter: self.texture_filter,
            trace: self.overlays.need_trace(),
            depth_test: true,
            counter_planes: true,
        })
    }

    /// A request that stands for these settings before a scene is at hand:
    /// the explicit camera if one is given, else a camera at the origin. What
    /// `check` says of it holds for every scene but the scene's own
    /// part (see-through materials; a named camera's existence).
    pub fn probe(&self) -> Result<RenderRequest, FieldError> {
        let mut camera = match &self.camera {
            Some(spec @ CameraSpec::Explicit(_)) => {
                CameraSpec::resolve(Some(spec), &Scene::default())?
            }
            _ => Camera::framing(&crate::ground::Bounds::EMPTY),
        };
        if self.viewport.is_some() {
            // Bare words take the camera's own values, unknown yet: any will do.
            camera.viewport = Viewport::Orthographic { height: 1.0 };
        }
        self.request_through(camera)
    }
}

/// Parses `WxH` (e.g. `640x480`), each side in `1..=16384`.
pub fn parse_size(s: &str) -> Result<(u32, u32), FieldError> {
    let bad = || {
        FieldError::new(
            "size",
            format!("'{s}' is not WIDTHxHEIGHT with both in 1..={MAX_DIMENSION}, e.g. 640x480"),
        )
    };
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
    if w == 0 || h == 0 || w > MAX_DIMENSION || h > MAX_DIMENSION {
        return Err(bad());
    }
    Ok((w, h))
}

/// Parses an algorithm id; the error lists the valid ones.
pub fn parse_algorithm(s: &str) -> Result<AlgorithmId, FieldError> {
    AlgorithmId::from_str(s.trim()).map_err(|e| FieldError::new("algorithm", e.to_string()))
}

/// A camera as a request gives it: a scene camera's name, or an explicit one.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum CameraSpec {
    Named(String),
    Explicit(ExplicitCamera),
}

/// `{ "eye": [x,y,z], "target": [x,y,z], "up": [x,y,z], "fov_y": 60, "near": 0.01 }`
/// (a perspective camera; a request's `viewport` can change that).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExplicitCamera {
    pub eye: [f32; 3],
    pub target: [f32; 3],
    #[serde(default = "default_up")]
    pub up: [f32; 3],
    #[serde(default = "default_fov")]
    pub fov_y: f32,
    pub near: Option<f32>,
}

fn default_up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}
fn default_fov() -> f32 {
    60.0
}

impl CameraSpec {
    /// The camera this names in `scene` (`None`: the scene's first camera).
    pub fn resolve(spec: Option<&CameraSpec>, scene: &Scene) -> Result<Camera, FieldError> {
        let camera = match spec {
            None => scene.first_camera(),
            Some(CameraSpec::Named(name)) => scene
                .camera(name)
                .map_err(|e| FieldError::new("camera", e.to_string()))?,
            Some(CameraSpec::Explicit(c)) => Camera {
                name: "custom".into(),
                eye: Vec3::from(c.eye),
                target: Vec3::from(c.target),
                up: Vec3::from(c.up),
                viewport: Viewport::Perspective { fov_y_deg: c.fov_y },
                near: c.near,
            },
        };
        camera.validate()?;
        Ok(camera)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes() {
        assert_eq!(parse_size("640x480"), Ok((640, 480)));
        for bad in ["", "640", "0x10", "10x0", "axb", "99999x1", "-1x5"] {
            assert_eq!(parse_size(bad).map_err(|e| e.field), Err("size"), "{bad}");
        }
    }

    #[test]
    fn algorithms() {
        for a in AlgorithmId::ALL {
            assert_eq!(parse_algorithm(a.as_str()), Ok(a));
        }
        let e = parse_algorithm("zbuffer").unwrap_err();
        assert!(e.message.contains("3dr-brute"), "{e}");
    }
}
