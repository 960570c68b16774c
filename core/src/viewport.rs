//! Viewports: how pixels map to rays (paper §3.2, §3.3, §3.5).
//!
//! - `perspective:FOV`: the pinhole; rays from the eye through a plane,
//!   `d(x, y) = d0 + x·dx + y·dy`.
//! - `orthographic:HEIGHT`: parallel rays along the view axis from a plane through
//!   the eye, `o(x, y) = o0 + x·ox + y·oy`; `HEIGHT` is the image height in scene units.
//! - `parabolic`: the hemisphere in front of the eye on the unit disc inscribed in
//!   the image, `d = (u, v, ½ − ½(u² + v²))` in camera space (`u` right, `v` up,
//!   the third axis forward); pixels outside the disc are background.
//! - `latlong`: the full sphere of directions, 360° × 180° equirectangular;
//!   longitude 0 (image centre) looks forward, the top row looks up.
//!
//! The two planar viewports have edge functions linear in the pixel coordinates
//! and are served by every algorithm; the two non-planar ones are evaluated per
//! sample (paper §3.5) by the 3D rasterizers without BVH frusta and the ray caster.

use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::fmt;

use glam::DVec3;

use crate::ground::FieldError;

/// How a camera maps pixels to rays.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Viewport {
    /// Pinhole with this vertical field of view, in degrees in (0, 180).
    Perspective { fov_y_deg: f32 },
    /// Parallel projection; the image is `height` scene units tall.
    Orthographic { height: f32 },
    /// Hemispherical (paraboloid) mapping onto the disc inscribed in the image.
    Parabolic,
    /// Latitude–longitude (equirectangular) mapping of the whole sphere.
    LatLong,
}

/// The viewport names, for error messages.
pub const VIEWPORT_FORMS: &str = "perspective[:FOV], orthographic[:HEIGHT], parabolic, latlong";

impl Viewport {
    /// One viewport of each kind (with example values), for listings.
    pub const KINDS: [Viewport; 4] = [
        Viewport::Perspective { fov_y_deg: 60.0 },
        Viewport::Orthographic { height: 1.0 },
        Viewport::Parabolic,
        Viewport::LatLong,
    ];

    /// Parses the CLI's words. `perspective` and `orthographic` without a value
    /// take `default` (a camera's own field of view and framing).
    pub fn parse(s: &str, default: Viewport) -> Result<Viewport, FieldError> {
        let bad = |m: String| FieldError::new("viewport", m);
        let (kind, arg) = s
            .trim()
            .split_once(':')
            .map_or((s.trim(), None), |(k, a)| (k, Some(a.trim())));
        let number = |a: &str, what: &str| {
            a.parse::<f32>()
                .map_err(|_| bad(format!("'{a}' is not a number ({what})")))
        };
        let v = match (kind, arg) {
            ("perspective", None) => match default {
                p @ Viewport::Perspective { .. } => p,
                _ => Viewport::Perspective { fov_y_deg: 60.0 },
            },
            ("perspective", Some(a)) => Viewport::Perspective {
                fov_y_deg: number(a, "vertical field of view in degrees")?,
            },
            ("orthographic", None) => match default {
                o @ Viewport::Orthographic { .. } => o,
                _ => {
                    return Err(bad(
                        "orthographic needs the image height in scene units, e.g. orthographic:10"
                            .into(),
                    ));
                }
            },
            ("orthographic", Some(a)) => Viewport::Orthographic {
                height: number(a, "image height in scene units")?,
            },
            ("parabolic", None) => Viewport::Parabolic,
            ("latlong", None) => Viewport::LatLong,
            ("parabolic" | "latlong", Some(_)) => {
                return Err(bad(format!(
                    "'{kind}' takes no value; forms: {VIEWPORT_FORMS}"
                )));
            }
            _ => {
                return Err(bad(format!(
                    "unknown viewport '{s}'; forms: {VIEWPORT_FORMS}"
                )));
            }
        };
        v.validate()
            .map_err(|e| bad(format!("'{s}': {}", e.message)))?;
        Ok(v)
    }

    /// Checks the parameter; the message says what is wrong.
    pub fn validate(&self) -> Result<(), FieldError> {
        match *self {
            Viewport::Perspective { fov_y_deg } if !(fov_y_deg > 0.0 && fov_y_deg < 180.0) => {
                Err(FieldError::new(
                    "viewport",
                    format!("the field of view must be in (0, 180) degrees, got {fov_y_deg}"),
                ))
            }
            Viewport::Orthographic { height } if !(height > 0.0 && height.is_finite()) => {
                Err(FieldError::new(
                    "viewport",
                    format!("the height must be positive and finite, got {height}"),
                ))
            }
            _ => Ok(()),
        }
    }

    /// Planar viewports have edge functions linear in pixel coordinates.
    pub fn is_planar(&self) -> bool {
        matches!(
            self,
            Viewport::Perspective { .. } | Viewport::Orthographic { .. }
        )
    }

    /// The viewport's name without its value.
    pub fn kind(&self) -> &'static str {
        match self {
            Viewport::Perspective { .. } => "perspective",
            Viewport::Orthographic { .. } => "orthographic",
            Viewport::Parabolic => "parabolic",
            Viewport::LatLong => "latlong",
        }
    }
}

impl fmt::Display for Viewport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Viewport::Perspective { fov_y_deg } => write!(f, "perspective:{fov_y_deg}"),
            Viewport::Orthographic { height } => write!(f, "orthographic:{height}"),
            Viewport::Parabolic => f.write_str("parabolic"),
            Viewport::LatLong => f.write_str("latlong"),
        }
    }
}

/// The sample generator of a non-planar viewport (paper §3.5): pixel coordinates
/// → a camera-space direction (`x` right, `y` up, `z` forward) and its
/// derivatives, in f64. Every algorithm calls these same functions with the same
/// arguments, so they see bitwise the same directions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SphereMap {
    /// Disc of radius `radius` pixels centred at `(cx, cy)`.
    Parabolic { cx: f64, cy: f64, radius: f64 },
    /// `width × height` pixels over 360° × 180°.
    LatLong { width: f64, height: f64 },
}

impl SphereMap {
    /// The map for a non-planar viewport at `width × height`; `None` for planar ones.
    pub fn new(viewport: Viewport, width: u32, height: u32) -> Option<SphereMap> {
        let (w, h) = (f64::from(width), f64::from(height));
        match viewport {
            Viewport::Parabolic => Some(SphereMap::Parabolic {
                cx: w * 0.5,
                cy: h * 0.5,
                radius: w.min(h) * 0.5,
            }),
            Viewport::LatLong => Some(SphereMap::LatLong {
                width: w,
                height: h,
            }),
            _ => None,
        }
    }

    /// Parabolic disc coordinates `(u, v)` of image point `(x, y)`.
    #[inline]
    pub(crate) fn disc(cx: f64, cy: f64, radius: f64, x: f64, y: f64) -> (f64, f64) {
        ((x - cx) / radius, (cy - y) / radius)
    }

    /// Longitude and latitude of image point `(x, y)`.
    #[inline]
    fn angles(width: f64, height: f64, x: f64, y: f64) -> (f64, f64) {
        (x / width * TAU - PI, FRAC_PI_2 - y / height * PI)
    }

    /// The (unnormalised) camera-space direction through image point `(x, y)`, or
    /// `None` outside the viewport (the parabolic disc).
    #[inline]
    pub fn direction(&self, x: f64, y: f64) -> Option<DVec3> {
        match *self {
            SphereMap::Parabolic { cx, cy, radius } => {
                let (u, v) = Self::disc(cx, cy, radius, x, y);
                let r2 = u * u + v * v;
                (r2 <= 1.0).then(|| DVec3::new(u, v, 0.5 - 0.5 * r2))
            }
            SphereMap::LatLong { width, height } => {
                let (theta, phi) = Self::angles(width, height, x, y);
                let (st, ct) = theta.sin_cos();
                let (sp, cp) = phi.sin_cos();
                Some(DVec3::new(cp * st, sp, cp * ct))
            }
        }
    }

    /// `∂d/∂x` and `∂d/∂y` at image point `(x, y)` (one pixel right, one down).
    pub fn derivatives(&self, x: f64, y: f64) -> (DVec3, DVec3) {
        match *self {
            SphereMap::Parabolic { cx, cy, radius } => {
                let (u, v) = Self::disc(cx, cy, radius, x, y);
                let k = 1.0 / radius;
                (DVec3::new(k, 0.0, -u * k), DVec3::new(0.0, -k, v * k))
            }
            SphereMap::LatLong { width, height } => {
                let (theta, phi) = Self::angles(width, height, x, y);
                let (st, ct) = theta.sin_cos();
                let (sp, cp) = phi.sin_cos();
                let (kx, ky) = (TAU / width, -PI / height);
                (
                    DVec3::new(cp * ct, 0.0, -cp * st) * kx,
                    DVec3::new(-sp * st, cp, -sp * ct) * ky,
                )
            }
        }
    }

    /// Image-space bounds `[min_x, min_y, max_x, max_y]` (pixels, before
    /// clamping to the image) of the directions a camera-space triangle covers.
    ///
    /// The triangle's directions lie in the spherical cap around the normalised
    /// sum of its vertex directions whose angle reaches the farthest vertex (a
    /// cap below 90° is convex, so it holds the geodesic triangle). Latitude–
    /// longitude: the cap's latitude band, and its longitude span
    /// `asin(sin α / cos φ_c)` unless it holds a pole or crosses the seam (then
    /// the full width). Parabolic: the map is a stereographic projection from
    /// the backward pole, so the cap maps to the disc whose diameter joins the
    /// images of the cap's two points on the centre's meridian (unless it holds
    /// that pole: then the whole image).
    pub fn bounds_of(&self, c: &[DVec3; 3]) -> [f64; 4] {
        let full = match *self {
            SphereMap::Parabolic { cx, cy, radius } => {
                [cx - radius, cy - radius, cx + radius, cy + radius]
            }
            SphereMap::LatLong { width, height } => [0.0, 0.0, width, height],
        };
        let lengths = c.map(|v| v.length());
        if lengths.iter().any(|&l| !(l > 0.0 && l.is_finite())) {
            return full;
        }
        let u = [c[0] / lengths[0], c[1] / lengths[1], c[2] / lengths[2]];
        let Some(centre) = (u[0] + u[1] + u[2]).try_normalize() else {
            return full;
        };
        // Cap angle, with a margin for the rounding of the directions.
        let alpha = u
            .iter()
            .map(|v| v.dot(centre).clamp(-1.0, 1.0).acos())
            .fold(0.0, f64::max)
            + 1e-9;
        if alpha >= FRAC_PI_2 - 1e-6 {
            return full;
        }
        match *self {
            SphereMap::LatLong { width, height } => {
                let phi_c = centre.y.clamp(-1.0, 1.0).asin();
                let (top, bottom) = (phi_c + alpha, phi_c - alpha);
                let y = |phi: f64| (FRAC_PI_2 - phi) / PI * height;
                if top >= FRAC_PI_2 || bottom <= -FRAC_PI_2 {
                    return [0.0, y(top.min(FRAC_PI_2)), width, y(bottom.max(-FRAC_PI_2))];
                }
                let theta_c = centre.x.atan2(centre.z);
                let span = (alpha.sin() / phi_c.cos()).min(1.0).asin();
                let (left, right) = (theta_c - span, theta_c + span);
                if left <= -PI || right >= PI {
                    return [0.0, y(top), width, y(bottom)];
                }
                let x = |theta: f64| (theta + PI) / TAU * width;
                [x(left), y(top), x(right), y(bottom)]
            }
            SphereMap::Parabolic { cx, cy, radius } => {
                // Polar angle from the view axis and azimuth of the cap centre.
                let beta = centre.z.clamp(-1.0, 1.0).acos();
                if beta + alpha >= PI - 1e-6 {
                    return full;
                }
                let psi = centre.y.atan2(centre.x);
                // Signed disc radius of the meridian points at polar angle γ.
                let (r1, r2) = (((beta - alpha) * 0.5).tan(), ((beta + alpha) * 0.5).tan());
                let (mid, half) = ((r1 + r2) * 0.5, (r2 - r1) * 0.5);
                let (u, v) = (mid * psi.cos(), mid * psi.sin());
                let (x, y) = (cx + u * radius, cy - v * radius);
                let h = half * radius;
                [x - h, y - h, x + h, y + h]
            }
        }
    }

    /// Image point of a camera-space direction (the inverse of [`Self::direction`]
    /// up to scale), for bounds; parabolic directions behind the eye map outside the disc.
    pub fn image_point(&self, d: DVec3) -> (f64, f64) {
        let d = d.normalize();
        match *self {
            SphereMap::Parabolic { cx, cy, radius } => {
                let s = 1.0 / (1.0 + d.z).max(1e-300);
                (cx + d.x * s * radius, cy - d.y * s * radius)
            }
            SphereMap::LatLong { width, height } => {
                let theta = d.x.atan2(d.z);
                let phi = d.y.clamp(-1.0, 1.0).asin();
                ((theta + PI) / TAU * width, (FRAC_PI_2 - phi) / PI * height)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_and_print_round_trip() {
        let default = Viewport::Perspective { fov_y_deg: 45.0 };
        for (text, want) in [
            ("perspective", Viewport::Perspective { fov_y_deg: 45.0 }),
            ("perspective:60", Viewport::Perspective { fov_y_deg: 60.0 }),
            ("orthographic:10", Viewport::Orthographic { height: 10.0 }),
            ("parabolic", Viewport::Parabolic),
            ("latlong", Viewport::LatLong),
        ] {
            let v = Viewport::parse(text, default).unwrap();
            assert_eq!(v, want, "{text}");
            assert_eq!(Viewport::parse(&v.to_string(), default), Ok(v));
        }
        for bad in [
            "fisheye",
            "perspective:0",
            "perspective:180",
            "perspective:x",
            "orthographic",
            "orthographic:-1",
            "orthographic:inf",
            "latlong:2",
            "",
        ] {
            let e = Viewport::parse(bad, default).unwrap_err();
            assert_eq!(e.field, "viewport", "{bad}");
        }
    }

    /// The derivatives are those of the direction (central differences).
    #[test]
    fn derivatives_match_differences() {
        for map in [
            SphereMap::new(Viewport::Parabolic, 64, 48).unwrap(),
            SphereMap::new(Viewport::LatLong, 64, 32).unwrap(),
        ] {
            for (x, y) in [(20.5, 20.5), (33.25, 17.75), (40.5, 10.5)] {
                let h = 1e-4;
                let (dx, dy) = map.derivatives(x, y);
                let d = |x, y| map.direction(x, y).unwrap();
                let nx = (d(x + h, y) - d(x - h, y)) / (2.0 * h);
                let ny = (d(x, y + h) - d(x, y - h)) / (2.0 * h);
                assert!((nx - dx).length() < 1e-6, "{map:?} {nx} {dx}");
                assert!((ny - dy).length() < 1e-6, "{map:?} {ny} {dy}");
                let (ix, iy) = map.image_point(d(x, y));
                assert!((ix - x).abs() < 1e-9 && (iy - y).abs() < 1e-9);
            }
        }
    }
}
