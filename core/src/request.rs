//! Parsing of the words a user gives (CLI flags, HTTP fields) into typed values,
//! shared by every front end so both speak the same language. Errors name the field.

use std::str::FromStr;

use glam::Vec3;
use serde::Deserialize;

use crate::aa::AaMode;

use crate::algorithm::AlgorithmId;
use crate::camera::{Camera, Viewport};
use crate::render::MAX_DIMENSION;
use crate::scene::Scene;

/// A user value that cannot be used, with the field it came from.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{field}: {message}")]
pub struct FieldError {
    pub field: &'static str,
    pub message: String,
}

impl FieldError {
    pub fn new(field: &'static str, message: impl Into<String>) -> FieldError {
        FieldError {
            field,
            message: message.into(),
        }
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
    AlgorithmId::from_str(s).map_err(|e| FieldError::new("algorithm", e.to_string()))
}

/// Parses a viewport for `camera` (see [`Viewport::parse`]): bare `perspective`
/// keeps a perspective camera's field of view, bare `orthographic` an
/// orthographic camera's height.
pub fn parse_viewport(s: &str, camera: &Camera) -> Result<Viewport, FieldError> {
    Viewport::parse(s, camera.viewport)
}

/// Parses an anti-aliasing mode (`none`, `ssaa:N`, `msaa:N`, `csaa:CxS`).
pub fn parse_aa(s: &str) -> Result<AaMode, FieldError> {
    AaMode::parse(s)
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
        camera
            .validate()
            .map_err(|e| FieldError::new("camera", format!("{}: {}", e.field, e.message)))?;
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
