//! The pinhole camera and its sample generator (paper §3.2).
//!
//! A [`View`] is a camera at one image size. It turns pixel coordinates into ray
//! directions `d(x, y) = d0 + x·dx + y·dy`, pixel centres at `(px + 0.5, py + 0.5)`,
//! `y` growing downwards. `d0 · forward = 1` and `dx, dy ⟂ forward`, so the ray
//! parameter `t` of a point `e + t·d` *is* its view-axis distance `w`: every
//! algorithm's depth buffer holds `w`.

use glam::{DVec3, Vec3};
use serde::{Deserialize, Serialize};

use crate::scene::Bounds;

/// A named pinhole camera: where it is, what it looks at, and its vertical field of
/// view. `near` is the distance below which nothing is drawn (the 2D family clips
/// there, the 3D family and the ray caster reject samples with `w < near`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Camera {
    pub name: String,
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    /// Vertical field of view in degrees, in (0, 180).
    pub fov_y_deg: f32,
    /// Near distance; `None` takes the prepared scene's default.
    pub near: Option<f32>,
}

/// A camera value that cannot be used, with the field at fault.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("camera {field}: {message}")]
pub struct CameraError {
    pub field: &'static str,
    pub message: String,
}

fn camera_error(field: &'static str, message: impl Into<String>) -> CameraError {
    CameraError {
        field,
        message: message.into(),
    }
}

impl Camera {
    /// Looks at the centre of `bounds` from the front-right-above, far enough that
    /// the bounding sphere fits a 45° vertical field of view.
    pub fn framing(bounds: &Bounds) -> Camera {
        let (center, radius) = if bounds.is_empty() {
            (Vec3::ZERO, 1.0)
        } else {
            (bounds.center(), bounds.radius().max(1e-6))
        };
        let fov_y_deg = 45.0_f32;
        let distance = radius / (fov_y_deg.to_radians() * 0.5).sin() * 1.05;
        let direction = Vec3::new(0.4, 0.35, 1.0).normalize();
        Camera {
            name: "default".into(),
            eye: center + direction * distance,
            target: center,
            up: Vec3::Y,
            fov_y_deg,
            near: None,
        }
    }

    /// Checks every field; the error names the first one at fault.
    pub fn validate(&self) -> Result<(), CameraError> {
        for (field, v) in [("eye", self.eye), ("target", self.target), ("up", self.up)] {
            if !v.is_finite() {
                return Err(camera_error(field, format!("must be finite, got {v}")));
            }
        }
        // In f64: huge but finite coordinates must not overflow the checks.
        let forward = self.target.as_dvec3() - self.eye.as_dvec3();
        let up = self.up.as_dvec3();
        if forward.length_squared() == 0.0 {
            return Err(camera_error("target", "must differ from eye"));
        }
        if forward.cross(up).length_squared()
            <= 1e-12 * forward.length_squared() * up.length_squared()
        {
            return Err(camera_error(
                "up",
                "must not be zero or parallel to the view direction",
            ));
        }
        if !(self.fov_y_deg > 0.0 && self.fov_y_deg < 180.0) {
            return Err(camera_error(
                "fov_y",
                format!("must be in (0, 180) degrees, got {}", self.fov_y_deg),
            ));
        }
        if let Some(near) = self.near
            && !(near > 0.0 && near.is_finite())
        {
            return Err(camera_error(
                "near",
                format!("must be positive and finite, got {near}"),
            ));
        }
        Ok(())
    }
}

/// A camera at one image size: the sample generator of paper §3.2.
#[derive(Clone, Debug, PartialEq)]
pub struct View {
    pub eye: Vec3,
    /// Unit view axis.
    pub forward: Vec3,
    /// Unit image-right axis.
    pub right: Vec3,
    /// Unit image-up axis (image rows grow along `-up`).
    pub up: Vec3,
    /// Direction through the image corner `(0, 0)`; `d0 · forward = 1`.
    pub d0: Vec3,
    /// `∂d/∂x`: one pixel to the right.
    pub dx: Vec3,
    /// `∂d/∂y`: one pixel down.
    pub dy: Vec3,
    pub width: u32,
    pub height: u32,
    /// Nothing nearer than this along the view axis is drawn.
    pub near: f32,
    /// `tan(fov_y / 2)`.
    pub tan_half_y: f32,
    /// `tan(fov_y / 2) · width / height`.
    pub tan_half_x: f32,
}

impl View {
    /// Builds the sample generator for `camera` at `width × height`, with
    /// `default_near` where the camera names none.
    pub fn new(
        camera: &Camera,
        width: u32,
        height: u32,
        default_near: f32,
    ) -> Result<View, CameraError> {
        camera.validate()?;
        if width == 0 || height == 0 {
            return Err(camera_error("size", "width and height must be positive"));
        }
        // The basis in f64 (no overflow for huge coordinates), rounded once.
        let forward64 = (camera.target.as_dvec3() - camera.eye.as_dvec3()).normalize();
        let right64 = forward64.cross(camera.up.as_dvec3()).normalize();
        let (forward, right) = (forward64.as_vec3(), right64.as_vec3());
        let up = right64.cross(forward64).as_vec3();
        // tan in f64 so that e.g. 90° gives exactly 1.
        let tan_half_y64 = (f64::from(camera.fov_y_deg).to_radians() * 0.5).tan();
        let tan_half_x64 = tan_half_y64 * f64::from(width) / f64::from(height);
        let (tan_half_y, tan_half_x) = (tan_half_y64 as f32, tan_half_x64 as f32);
        let dx = right * (2.0 * tan_half_x / width as f32);
        let dy = up * (-2.0 * tan_half_y / height as f32);
        let d0 = forward - right * tan_half_x + up * tan_half_y;
        Ok(View {
            eye: camera.eye,
            forward,
            right,
            up,
            d0,
            dx,
            dy,
            width,
            height,
            near: camera.near.unwrap_or(default_near),
            tan_half_y,
            tan_half_x,
        })
    }

    /// The ray direction through image point `(x, y)` (pixel units), evaluated as
    /// `(d0 + x·dx) + y·dy` with no fused multiply-add.
    #[inline]
    pub fn direction(&self, x: f32, y: f32) -> Vec3 {
        self.d0 + self.dx * x + self.dy * y
    }

    /// The same direction in f64 (for checks that need more precision than the
    /// renderer has).
    pub fn direction_f64(&self, x: f64, y: f64) -> DVec3 {
        self.d0.as_dvec3() + self.dx.as_dvec3() * x + self.dy.as_dvec3() * y
    }

    /// World point → camera space `(x_right, y_up, w)`.
    #[inline]
    pub fn to_camera(&self, p: Vec3) -> Vec3 {
        let v = p - self.eye;
        Vec3::new(v.dot(self.right), v.dot(self.up), v.dot(self.forward))
    }

    /// Camera-space point with `w > 0` → pixel coordinates; the exact inverse of
    /// [`View::direction`] in real arithmetic.
    #[inline]
    pub fn project(&self, c: Vec3) -> (f32, f32) {
        let half_w = self.width as f32 * 0.5;
        let half_h = self.height as f32 * 0.5;
        let x = (c.x / c.z / self.tan_half_x + 1.0) * half_w;
        let y = (1.0 - c.y / c.z / self.tan_half_y) * half_h;
        (x, y)
    }

    /// Number of pixels.
    pub fn pixel_count(&self) -> usize {
        self.width as usize * self.height as usize
    }
}

/// Pixel-centre coordinate of pixel index `p` along an axis.
#[inline]
pub fn pixel_center(p: u32) -> f32 {
    p as f32 + 0.5
}
