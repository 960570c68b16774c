//! Olano–Greer homogeneous 2D rasterization (paper Fig. 10, middle column): the
//! vertices are transformed to homogeneous pixel coordinates `h = (X, Y, W)` with
//! `x = X/W`, and the edge functions are the rows of the adjugate,
//! `c_i = h_{i+1} × h_{i+2}`, evaluated as `E_i(x, y) = c_i · (x, y, 1)`. No
//! clipping and no division per vertex: triangles through the eye plane are
//! handled by the signs alone, and samples nearer than `near` are rejected.
//!
//! Only the setup differs from 3D rasterization: "per-pixel operations of Woop's
//! variant and our 3DR are identical" (paper §5), so the result is a
//! [`Triangle3D`] evaluated by the same code.

use glam::Vec3;

use super::Triangle3D;
use crate::camera::View;

/// Setup of Fig. 10 (middle): transform, three cross products, determinant.
/// `None` when the determinant is zero (degenerate or seen edge-on).
/// Orthographic views have `W = 1` at every vertex, and `w` is interpolated
/// linearly: `w = Σ w_i·E_i / ΣE_i`.
pub fn setup_homogeneous(p: &[Vec3; 3], view: &View) -> Option<Triangle3D> {
    // 1. Camera space → homogeneous pixel coordinates (X, Y, W), x = X/W.
    let (half_w, half_h) = (view.width as f32 * 0.5, view.height as f32 * 0.5);
    let orthographic = view.is_orthographic();
    let cam = p.map(|v| view.to_camera(v));
    let h = cam.map(|c| {
        let w = if orthographic { 1.0 } else { c.z };
        Vec3::new(
            (c.x / view.half_x + w) * half_w,
            (w - c.y / view.half_y) * half_h,
            w,
        )
    });
    // 2. Edge functions: rows of the adjugate, c_i = h_{i+1} × h_{i+2}, written as
    //    midpoint × difference (equal in real arithmetic, as in §3.4 "Numerics"):
    //    the plain cross product of two long, nearly parallel vectors cancels
    //    badly for small triangles. Swapping the endpoints negates the result
    //    exactly, so shared edges stay consistent.
    let row = |a: Vec3, b: Vec3| ((a + b) * 0.5).cross(b - a);
    let rows = [row(h[1], h[2]), row(h[2], h[0]), row(h[0], h[1])];
    // 3. The determinant and 1/w's gradient from the triangle's own normal (Σ rows,
    //    computed without the cancellation of summing them): 1/w(x, y) = N·(x, y, 1) / D.
    let normal = (h[1] - h[0]).cross(h[2] - h[0]);
    let det = normal.dot(h[0]);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let sign = if det > 0.0 { 1.0 } else { -1.0 };
    let linear = |r: Vec3| [r.z * sign, r.x * sign, r.y * sign];
    let volume = if orthographic {
        linear(rows[0] * cam[0].z + rows[1] * cam[1].z + rows[2] * cam[2].z)
    } else {
        [det.abs(), 0.0, 0.0]
    };
    Triangle3D::from_linear(
        rows.map(linear),
        linear(normal),
        volume,
        cam.map(|c| c.z),
        view,
    )
}
