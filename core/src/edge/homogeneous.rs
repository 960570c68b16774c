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
use super::edge3d::{Depth, EPS, HomogeneousVertex, abs_cross, orientation, scaled};
use super::exact;
use crate::camera::View;

/// Setup of Fig. 10 (middle) of the triangle `p` from its vertices,
/// transformed (once per render, shared by the triangles that meet there):
/// three cross products and the determinant. `None` when the determinant is
/// zero (degenerate or seen edge-on). Orthographic views have `W = 1` at
/// every vertex, and `w` is interpolated linearly: `w = Σ w_i·E_i / ΣE_i`.
pub(crate) fn setup_homogeneous_from(
    vertices: [HomogeneousVertex; 3],
    view: &View,
) -> Option<Triangle3D> {
    // 1. Camera space → homogeneous pixel coordinates (X, Y, W), x = X/W.
    let orthographic = view.is_orthographic();
    let w = vertices.map(|v| v.w);
    // Far vertices scaled by a power of two (exact, no sign changes; see
    // `edge3d::scaled`): the rows are ~|h|², the determinant's products ~|h|³.
    let (h, scale) = scaled(vertices.map(|v| v.h));
    // 2. Edge functions: rows of the adjugate, c_i = h_{i+1} × h_{i+2}, written as
    //    midpoint × difference (equal in real arithmetic, as in §3.4 "Numerics"):
    //    the plain cross product of two long, nearly parallel vectors cancels
    //    badly for small triangles. Swapping the endpoints negates the result
    //    exactly, so shared edges stay consistent.
    let row = |a: Vec3, b: Vec3| ((a + b) * 0.5).cross(b - a);
    let rows = [row(h[1], h[2]), row(h[2], h[0]), row(h[0], h[1])];
    // 3. The determinant and 1/w's gradient from the triangle's own normal (Σ rows,
    //    computed without the cancellation of summing them): 1/w(x, y) = N·(x, y, 1) / D.
    //    Near zero the exact sign of det[h0, h1, h2] decides.
    let (e1, e2) = (h[1] - h[0], h[2] - h[0]);
    let normal = e1.cross(e2);
    let det = normal.dot(h[0]);
    let det_bound = 16.0 * EPS * abs_cross(e1, e2).dot(h[0].abs());
    let positive = orientation(det, det_bound, || {
        let v = h.map(|v| v.as_dvec3().to_array());
        exact::dot(&exact::cross(v[1], v[2]), v[0]).signum()
    })?;
    let sign = if positive { 1.0 } else { -1.0 };
    let linear = |r: Vec3| [r.z * sign, r.x * sign, r.y * sign];
    // w is homogeneous of degree 1 in h (orthographic: 0, W = 1 and the rows
    // scale like the normal). Orthographic vertices all have W = 1 (scaled
    // alike), so both edges of the normal's cross product have z = 0
    // exactly and its x and y are ±0: N·(x, y, 1) is the constant N_z.
    let depth = if orthographic {
        Depth::Parallel {
            facing: normal.z * sign,
            volume: linear(rows[0] * w[0] + rows[1] * w[1] + rows[2] * w[2]),
        }
    } else {
        Depth::Perspective {
            facing: linear(normal),
            volume: det.abs() * scale,
        }
    };
    // Each row's rounding is at most 5ε of |m| ⊗ |u|, evaluated at (x, y, 1).
    let (x_max, y_max) = view.sample_extent();
    let coefficient_error = [0, 1, 2].map(|i| {
        let (a, b) = (h[(i + 1) % 3], h[(i + 2) % 3]);
        let t = abs_cross((a + b) * 0.5, b - a);
        6.0 * EPS * (t.z + x_max * t.x + y_max * t.y)
    });
    Triangle3D::from_linear(
        rows.map(linear),
        depth,
        w,
        view,
        coefficient_error,
        !positive,
    )
}
