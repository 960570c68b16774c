//! Cameras and their sample generators (paper §3.2, §3.3, §3.5).
//!
//! A [`View`] is a camera at one image size. For the planar viewports it turns
//! pixel coordinates into rays `o(x, y) + t·d(x, y)` with `o` and `d` linear in
//! `(x, y)`: perspective `d(x, y) = d0 + x·dx + y·dy` from the eye, orthographic
//! `o(x, y) = eye + o0 + x·ox + y·oy` along the view axis. Pixel centres are at
//! `(px + 0.5, py + 0.5)`, `y` growing downwards. `d · forward = 1`, so the ray
//! parameter `t` *is* the view-axis distance `w` that the depth buffer holds.
//! The non-planar viewports ([`SphereMap`]) give unit-length-scaled rays from the
//! eye and store the Euclidean distance.

use glam::{DVec3, Vec3};

use crate::ground::{Bounds, FieldError};
pub use crate::viewport::{SphereMap, Viewport};

/// A named camera: where it is, what it looks at, and how pixels map to rays.
/// `near` is the distance below which nothing is drawn (the 2D family clips
/// there, the 3D family and the ray caster reject samples with `w < near`).
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub name: String,
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    pub viewport: Viewport,
    /// Near distance; `None` takes the prepared scene's default.
    pub near: Option<f32>,
}

/// A camera field that cannot be used: the error names the request field
/// `camera` and, first in its message, the camera's own field.
fn camera_error(field: &str, message: impl Into<String>) -> FieldError {
    FieldError::new("camera", format!("{field}: {}", message.into()))
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
            viewport: Viewport::Perspective { fov_y_deg },
            near: None,
        }
    }

    /// The height an orthographic view of this camera takes to frame what it
    /// shows at its target: its own height if orthographic, what a perspective
    /// field of view spans at the target's distance, twice that distance else.
    pub fn framing_height(&self) -> f32 {
        let distance = (self.target - self.eye).length();
        match self.viewport {
            Viewport::Orthographic { height } => height,
            Viewport::Perspective { fov_y_deg } => {
                2.0 * distance * (fov_y_deg.to_radians() * 0.5).tan()
            }
            _ => 2.0 * distance,
        }
    }

    /// Checks every field; the error names the first one at fault.
    pub fn validate(&self) -> Result<(), FieldError> {
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
        self.viewport
            .validate()
            .map_err(|e| camera_error("viewport", e.message))?;
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

/// [`View::sample_extent`] of an image `width × height`.
fn sample_extent(width: u32, height: u32) -> (f32, f32) {
    (width as f32 + 1.0, height as f32 + 1.0)
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
    pub viewport: Viewport,
    /// Planar: ray direction at image point `(0, 0)`, `d0 · forward = 1`
    /// (orthographic: `forward`).
    pub d0: Vec3,
    /// Planar: `∂d/∂x`, one pixel to the right (orthographic: zero).
    pub dx: Vec3,
    /// Planar: `∂d/∂y`, one pixel down (orthographic: zero).
    pub dy: Vec3,
    /// Planar: ray origin at image point `(0, 0)` relative to the eye
    /// (perspective: zero). Relative, so that it keeps its precision however
    /// far from the world origin the camera is.
    pub o0: Vec3,
    /// Planar: `∂o/∂x` (perspective: zero).
    pub ox: Vec3,
    /// Planar: `∂o/∂y` (perspective: zero).
    pub oy: Vec3,
    pub width: u32,
    pub height: u32,
    /// Nothing nearer than this is drawn (along the view axis; for non-planar
    /// viewports, from the eye).
    pub near: f32,
    /// Half the image height: perspective `tan(fov_y / 2)` per unit of `w`,
    /// orthographic in scene units.
    pub half_y: f32,
    /// Half the image width, `half_y · width / height`.
    pub half_x: f32,
    /// The sample generator of a non-planar viewport.
    pub sphere: Option<SphereMap>,
    /// Bounds on the planar sample directions over the image, for the
    /// error bounds of edge functions evaluated on it.
    pub(crate) directions: DirectionBounds,
    /// The largest `|o0| + |x|·|ox| + |y|·|oy|` over the image's samples
    /// ([`reach`] of the sample origins): what the error bounds of parallel
    /// projection's edge functions need of them.
    pub(crate) origin_reach: Vec3,
}

/// Per component, the largest `|v0| + |x|·|vx| + |y|·|vy|` over the
/// samples `(x, y) ∈ [−1, x_max] × [−1, y_max]` of an image
/// ([`View::sample_extent`]; `x_max`, `y_max` ≥ 1).
fn reach(v0: Vec3, vx: Vec3, vy: Vec3, (x_max, y_max): (f32, f32)) -> Vec3 {
    v0.abs() + vx.abs() * x_max + vy.abs() * y_max
}

/// What the error bounds of perspective edge functions need of the sample
/// direction `d(x, y) = d0 + x·dx + y·dy` over the image's samples,
/// `(x, y) ∈ [−1, x_max] × [−1, y_max]` ([`View::sample_extent`]), per
/// component: the largest `|d|` (at a corner, `|d|` being convex), and the
/// largest `|d0| + |x|·|dx| + |y|·|dy|`, which bounds how the errors of
/// three coefficients `n·d0`, `n·dx`, `n·dy` add up at a sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct DirectionBounds {
    pub(crate) largest: Vec3,
    pub(crate) reach: Vec3,
}

impl DirectionBounds {
    fn of(d0: Vec3, dx: Vec3, dy: Vec3, extent: (f32, f32)) -> DirectionBounds {
        let (x_max, y_max) = extent;
        let d = |x: f32, y: f32| (d0 + dx * x + dy * y).abs();
        let largest = (d(-1.0, -1.0).max(d(x_max, -1.0))).max(d(-1.0, y_max).max(d(x_max, y_max)));
        DirectionBounds {
            largest,
            reach: reach(d0, dx, dy, extent),
        }
    }
}

impl View {
    /// Builds the sample generator for `camera` at `width × height`, with
    /// `default_near` where the camera names none.
    pub fn new(
        camera: &Camera,
        width: u32,
        height: u32,
        default_near: f32,
    ) -> Result<View, FieldError> {
        camera.validate()?;
        if width == 0 || height == 0 {
            return Err(FieldError::new("size", "width and height must be positive"));
        }
        // The basis in f64 (no overflow for huge coordinates), rounded once.
        let forward64 = (camera.target.as_dvec3() - camera.eye.as_dvec3()).normalize();
        let right64 = forward64.cross(camera.up.as_dvec3()).normalize();
        let (forward, right) = (forward64.as_vec3(), right64.as_vec3());
        let up = right64.cross(forward64).as_vec3();
        // Half extents in f64 so that e.g. 90° gives exactly 1.
        let half_y64 = match camera.viewport {
            Viewport::Perspective { fov_y_deg } => (f64::from(fov_y_deg).to_radians() * 0.5).tan(),
            Viewport::Orthographic { height } => f64::from(height) * 0.5,
            Viewport::Parabolic | Viewport::LatLong => 1.0,
        };
        let half_x64 = half_y64 * f64::from(width) / f64::from(height);
        let (half_y, half_x) = (half_y64 as f32, half_x64 as f32);
        let step_x = right * (2.0 * half_x / width as f32);
        let step_y = up * (-2.0 * half_y / height as f32);
        // The image corner (0, 0) relative to the eye (orthographic) or along the
        // view axis at w = 1 (perspective).
        let corner = |base: Vec3| base - right * half_x + up * half_y;
        let (d0, dx, dy, o0, ox, oy) = match camera.viewport {
            Viewport::Orthographic { .. } => (
                forward,
                Vec3::ZERO,
                Vec3::ZERO,
                corner(Vec3::ZERO),
                step_x,
                step_y,
            ),
            _ => (
                corner(forward),
                step_x,
                step_y,
                Vec3::ZERO,
                Vec3::ZERO,
                Vec3::ZERO,
            ),
        };
        Ok(View {
            eye: camera.eye,
            forward,
            right,
            up,
            viewport: camera.viewport,
            d0,
            dx,
            dy,
            o0,
            ox,
            oy,
            width,
            height,
            near: camera.near.unwrap_or(default_near),
            half_y,
            half_x,
            sphere: SphereMap::new(camera.viewport, width, height),
            directions: DirectionBounds::of(d0, dx, dy, sample_extent(width, height)),
            origin_reach: reach(o0, ox, oy, sample_extent(width, height)),
        })
    }

    /// The image's largest sample coordinates: the pattern's offsets stay
    /// within one pixel of the image.
    #[inline]
    pub(crate) fn sample_extent(&self) -> (f32, f32) {
        sample_extent(self.width, self.height)
    }

    /// Is this an orthographic view?
    #[inline]
    pub fn is_orthographic(&self) -> bool {
        matches!(self.viewport, Viewport::Orthographic { .. })
    }

    /// Planar views: the ray direction through image point `(x, y)` (pixel
    /// units), evaluated as `(d0 + x·dx) + y·dy` with no fused multiply-add.
    #[inline]
    pub fn direction(&self, x: f32, y: f32) -> Vec3 {
        self.d0 + self.dx * x + self.dy * y
    }

    /// Planar views: the ray origin for image point `(x, y)` relative to the
    /// eye, `o0 + x·ox + y·oy`.
    #[inline]
    pub fn origin_offset(&self, x: f32, y: f32) -> Vec3 {
        self.o0 + self.ox * x + self.oy * y
    }

    /// Planar views: the ray origin for image point `(x, y)`.
    #[inline]
    pub fn origin(&self, x: f32, y: f32) -> Vec3 {
        self.eye + self.origin_offset(x, y)
    }

    /// The ray through image point `(x, y)`: origin and direction, scaled so that
    /// `origin + direction · depth` is the point a depth-buffer value names.
    /// `None` where the viewport has no ray (outside the parabolic disc).
    #[inline(always)]
    pub fn ray(&self, x: f32, y: f32) -> Option<(Vec3, Vec3)> {
        match &self.sphere {
            // Planar views, per shaded sample: inline, in registers.
            None => Some((self.origin(x, y), self.direction(x, y))),
            Some(map) => self.sphere_ray(map, x, y),
        }
    }

    /// [`View::ray`] of a non-planar viewport.
    #[inline(never)]
    fn sphere_ray(&self, map: &SphereMap, x: f32, y: f32) -> Option<(Vec3, Vec3)> {
        let d = map.direction(f64::from(x), f64::from(y))?;
        Some((self.eye, self.camera_to_world(d).normalize().as_vec3()))
    }

    /// A camera-space vector `(right, up, forward)` in world space.
    #[inline]
    pub fn camera_to_world(&self, c: DVec3) -> DVec3 {
        self.right.as_dvec3() * c.x + self.up.as_dvec3() * c.y + self.forward.as_dvec3() * c.z
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

    /// World point → camera space in f64 (the non-planar viewports' setup).
    #[inline]
    pub fn to_camera_f64(&self, p: Vec3) -> DVec3 {
        let v = p.as_dvec3() - self.eye.as_dvec3();
        DVec3::new(
            v.dot(self.right.as_dvec3()),
            v.dot(self.up.as_dvec3()),
            v.dot(self.forward.as_dvec3()),
        )
    }

    /// Planar views: camera-space point (perspective: with `w > 0`) → pixel
    /// coordinates; the exact inverse of the ray generator in real arithmetic.
    #[inline]
    pub fn project(&self, c: Vec3) -> (f32, f32) {
        let half_w = self.width as f32 * 0.5;
        let half_h = self.height as f32 * 0.5;
        let (px, py) = if self.is_orthographic() {
            (c.x, c.y)
        } else {
            (c.x / c.z, c.y / c.z)
        };
        let x = (px / self.half_x + 1.0) * half_w;
        let y = (1.0 - py / self.half_y) * half_h;
        (x, y)
    }

    /// [`View::project`] in f64 (clipped polygons keep f64 until they are on
    /// screen).
    #[inline]
    pub fn project_f64(&self, c: DVec3) -> (f64, f64) {
        let half_w = f64::from(self.width) * 0.5;
        let half_h = f64::from(self.height) * 0.5;
        let (px, py) = if self.is_orthographic() {
            (c.x, c.y)
        } else {
            (c.x / c.z, c.y / c.z)
        };
        let x = (px / f64::from(self.half_x) + 1.0) * half_w;
        let y = (1.0 - py / f64::from(self.half_y)) * half_h;
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
