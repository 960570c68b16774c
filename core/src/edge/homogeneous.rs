//! Olano–Greer homogeneous 2D rasterization (paper Fig. 10, middle column): the
//! vertices are transformed to homogeneous pixel coordinates `h = (X, Y, W)` with
//! `x = X/W`, and the edge functions are the rows of the adjugate,
//! `c_i = h_{i+1} × h_{i+2}`, evaluated as `E_i(x, y) = c_i · (x, y, 1)`. No
//! clipping and no division per vertex: triangles through the eye plane are
//! handled by the signs alone, and samples nearer than `near` are rejected.

use glam::Vec3;

use super::{Coverage, owns_tie};
use crate::camera::View;

/// A triangle set up for homogeneous rasterization against one view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHomogeneous {
    /// Per edge: `E = (c + x·a) + y·b`.
    c: [f32; 3],
    a: [f32; 3],
    b: [f32; 3],
    /// `1/w(x, y) = (Σc + x·Σa + y·Σb) / |D|`: `[ΣA, ΣB, ΣC]` sign-normalised.
    inv_w: [f32; 3],
    volume: f32,
    owns: [bool; 3],
    w_range: [f32; 2],
    near: f32,
    error: [f32; 3],
}

impl TriangleHomogeneous {
    /// Setup of Fig. 10 (middle): transform, three cross products, determinant.
    /// `None` when the determinant is zero (degenerate or seen edge-on).
    pub fn setup(p: &[Vec3; 3], view: &View) -> Option<TriangleHomogeneous> {
        // 1. Camera space → homogeneous pixel coordinates (X, Y, W), x = X/W.
        let (half_w, half_h) = (view.width as f32 * 0.5, view.height as f32 * 0.5);
        let h = p.map(|v| {
            let c = view.to_camera(v);
            Vec3::new(
                (c.x / view.tan_half_x + c.z) * half_w,
                (c.z - c.y / view.tan_half_y) * half_h,
                c.z,
            )
        });
        // 2. Edge functions: rows of the adjugate, c_i = h_{i+1} × h_{i+2}, written
        //    as midpoint × difference (equal in real arithmetic, as in §3.4
        //    "Numerics"): the plain cross product of two long, nearly parallel
        //    vectors cancels badly for small triangles. Swapping the endpoints
        //    negates the result exactly, so shared edges stay consistent.
        let row = |a: Vec3, b: Vec3| ((a + b) * 0.5).cross(b - a);
        let rows = [row(h[1], h[2]), row(h[2], h[0]), row(h[0], h[1])];
        // The determinant and 1/w's gradient from the triangle's own normal
        // (Σ rows, computed without the cancellation of summing them).
        let normal = (h[1] - h[0]).cross(h[2] - h[0]);
        let det = normal.dot(h[0]);
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let sign = if det > 0.0 { 1.0 } else { -1.0 };
        let mut t = TriangleHomogeneous {
            c: rows.map(|r| r.z * sign),
            a: rows.map(|r| r.x * sign),
            b: rows.map(|r| r.y * sign),
            inv_w: [0.0; 3],
            volume: det.abs(),
            owns: [false; 3],
            w_range: [
                h[0].z.min(h[1].z).min(h[2].z),
                h[0].z.max(h[1].z).max(h[2].z),
            ],
            near: view.near,
            error: [0.0; 3],
        };
        let (x_max, y_max) = (view.width as f32, view.height as f32);
        for i in 0..3 {
            t.owns[i] = owns_tie(t.a[i], t.b[i]);
            t.error[i] = (t.c[i].abs() + x_max * t.a[i].abs() + y_max * t.b[i].abs())
                * (1.0 / (1 << 20) as f32);
        }
        // 3. 1/w interpolates linearly in the pixel plane: 1/w(x, y) = (Σ_i c_i)·p / D.
        t.inv_w = [normal.z * sign, normal.x * sign, normal.y * sign];
        if !(t
            .c
            .iter()
            .chain(&t.a)
            .chain(&t.b)
            .chain(&t.inv_w)
            .all(|v| v.is_finite()))
        {
            return None;
        }
        Some(t)
    }
}

impl Coverage for TriangleHomogeneous {
    #[inline(always)]
    fn edge_values(&self, x: f32, y: f32) -> [f32; 3] {
        [
            self.c[0] + x * self.a[0] + y * self.b[0],
            self.c[1] + x * self.a[1] + y * self.b[1],
            self.c[2] + x * self.a[2] + y * self.b[2],
        ]
    }

    #[inline(always)]
    fn owns(&self) -> [bool; 3] {
        self.owns
    }

    #[inline(always)]
    fn depth(&self, _edges: [f32; 3], x: f32, y: f32) -> Option<f32> {
        let facing = self.inv_w[0] + x * self.inv_w[1] + y * self.inv_w[2];
        if facing <= 0.0 {
            return None;
        }
        let w = (self.volume / facing).clamp(self.w_range[0], self.w_range[1]);
        (w >= self.near).then_some(w)
    }

    fn edge_error(&self) -> [f32; 3] {
        self.error
    }

    fn min_depth(&self) -> f32 {
        self.w_range[0].max(self.near)
    }
}
