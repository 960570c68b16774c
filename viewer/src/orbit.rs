//! Mouse camera control: orbit around the target, pan in the image plane, zoom
//! toward the target. Each keeps the camera valid (eye off the target, the view
//! direction off the up axis).

use continuum::{Camera, Viewport};
use glam::{Quat, Vec3};

/// Smallest angle kept between the view direction and the up axis.
const POLE_MARGIN: f32 = 0.01;

/// Turns the eye around the target: `yaw` about the up axis, `pitch` about the
/// camera's right axis (radians; positive pitch lifts the eye).
pub fn orbit(camera: &mut Camera, yaw: f32, pitch: f32) {
    let up = camera.up.normalize_or(Vec3::Y);
    let offset = camera.eye - camera.target;
    let radius = offset.length();
    if radius == 0.0 || !radius.is_finite() {
        return;
    }
    // The elevation above the up axis' equator, clamped short of the poles.
    let polar = up.dot(offset / radius).clamp(-1.0, 1.0).acos();
    let pitch = pitch.clamp(
        polar - (std::f32::consts::PI - POLE_MARGIN),
        polar - POLE_MARGIN,
    );
    let right = offset.cross(up).normalize_or(Vec3::X);
    let turn = Quat::from_axis_angle(up, yaw) * Quat::from_axis_angle(right, pitch);
    camera.eye = camera.target + turn * offset;
}

/// Moves eye and target together by `dx`, `dy` image heights (right and down,
/// as the mouse moves: the scene follows the cursor).
pub fn pan(camera: &mut Camera, dx: f32, dy: f32) {
    let forward = camera.target - camera.eye;
    let distance = forward.length();
    if distance == 0.0 || !distance.is_finite() {
        return;
    }
    let up = camera.up.normalize_or(Vec3::Y);
    let right = forward.cross(up).normalize_or(Vec3::X);
    let image_up = right.cross(forward).normalize_or(up);
    let height = match camera.viewport {
        Viewport::Perspective { fov_y_deg } => {
            2.0 * distance * (fov_y_deg.to_radians() / 2.0).tan()
        }
        Viewport::Orthographic { height } => height,
        Viewport::Parabolic | Viewport::LatLong => distance,
    };
    let shift = (-dx * right + dy * image_up) * height;
    camera.eye += shift;
    camera.target += shift;
}

/// Scales the eye's distance to the target by `factor` (< 1 moves closer); an
/// orthographic camera's image height scales with it.
pub fn zoom(camera: &mut Camera, factor: f32) {
    if !(factor.is_finite() && factor > 0.0) {
        return;
    }
    let offset = (camera.eye - camera.target) * factor;
    if offset.length() > 0.0 && offset.is_finite() {
        camera.eye = camera.target + offset;
    }
    if let Viewport::Orthographic { height } = &mut camera.viewport {
        *height *= factor;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera {
            name: "test".into(),
            eye: Vec3::new(0.0, 1.0, 5.0),
            target: Vec3::new(0.0, 1.0, 0.0),
            up: Vec3::Y,
            viewport: Viewport::Perspective { fov_y_deg: 60.0 },
            near: None,
        }
    }

    #[test]
    fn orbit_keeps_the_distance_and_turns_the_eye() {
        let mut c = camera();
        orbit(&mut c, std::f32::consts::FRAC_PI_2, 0.0);
        assert!((c.eye.distance(c.target) - 5.0).abs() < 1e-4);
        assert!(
            (c.eye - Vec3::new(5.0, 1.0, 0.0)).length() < 1e-4,
            "{}",
            c.eye
        );
        assert_eq!(c.target, Vec3::new(0.0, 1.0, 0.0));
    }

    #[test]
    fn orbit_stops_short_of_the_pole() {
        let mut c = camera();
        orbit(&mut c, 0.0, 10.0);
        let direction = (c.eye - c.target).normalize();
        assert!(direction.y < 1.0 && direction.y > 0.99, "{direction}");
        assert!((c.eye.distance(c.target) - 5.0).abs() < 1e-4);
        assert!(c.validate().is_ok());
    }

    #[test]
    fn pan_moves_eye_and_target_together() {
        let mut c = camera();
        pan(&mut c, 0.5, 0.0);
        // Half an image height at distance 5 with a 60° field: 5 tan 30° = 2.887.
        assert!(
            (c.target.x + 5.0 * (30f32).to_radians().tan()).abs() < 1e-4,
            "{}",
            c.target
        );
        assert_eq!(c.eye - c.target, Vec3::new(0.0, 0.0, 5.0));
    }

    #[test]
    fn zoom_scales_distance_and_orthographic_height() {
        let mut c = camera();
        zoom(&mut c, 0.5);
        assert!((c.eye.distance(c.target) - 2.5).abs() < 1e-5);
        c.viewport = Viewport::Orthographic { height: 4.0 };
        zoom(&mut c, 2.0);
        assert_eq!(c.viewport, Viewport::Orthographic { height: 8.0 });
        zoom(&mut c, f32::NAN);
        assert!((c.eye.distance(c.target) - 5.0).abs() < 1e-5);
    }
}
