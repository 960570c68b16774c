//! 3D edge functions (paper §3.2–3.4).
//!
//! For eye `e` and an edge `(a, b)` the edge normal is built from the edge midpoint,
//! `n = (e − (a+b)/2) × (a − b)` (§3.4 "Numerics"): the two triangles that share an
//! edge get bitwise negated normals in f32, so they split every sample on it.
//! With a sample direction `d(x, y) = d0 + x·dx + y·dy` the edge function is
//! `V(x, y) = n·d = A + x·B + y·C` with `A = n·d0`, `B = n·dx`, `C = n·dy`.
//!
//! Orthographic views (§3.3) cast parallel rays `o(x, y) + t·d_p`; the edge
//! normal is `n = d_p × (a − b)` and the edge function `V = n·(m − o(x, y))`
//! with `m` the edge midpoint — the same triple product `[o − m, a − b, d]` as
//! the perspective one with the eye replaced by the ray origin, again linear.

use glam::Vec3;

use wide::f32x8;

use super::{BlockTest, Coverage, LinearEdges, linear_classify, linear_sample, owns_tie};
use crate::camera::View;

/// A triangle set up for 3D rasterization against one view: per edge `i`
/// (opposite vertex `i`) the coefficients of `E_i(x, y) = A_i + x·B_i + y·C_i`,
/// normalised so the triangle's inside is `E_i > 0`, and the total volume
/// `|D| = |det(p0 − e, p1 − e, p2 − e)|`.
///
/// Depth is `w = |D| / ΣE_i` (paper Fig. 10), but `ΣE_i` is evaluated as its own
/// linear function `N·d(x, y)` (`N` the geometric normal; equal to `ΣV_i` in real
/// arithmetic). Summing the three edge values cancels catastrophically for
/// triangles that are small against their distance (each `E_i` is a difference of
/// terms ~10⁵× larger): on 1M-triangle scenes that gave `w` errors of 0.1%.
///
/// Every algorithm of the 3D family and the ray caster decide coverage and depth
/// through [`Coverage::sample`] on these coefficients, in one fixed operation
/// order with no fused multiply-add, so they agree bit for bit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle3D {
    pub a: [f32; 3],
    pub b: [f32; 3],
    pub c: [f32; 3],
    /// `|D|` as a linear function of the image point: `w = volume(x, y) / (N·d)`.
    /// Perspective: the constant `|D|`; orthographic: `N·(p0 − o(x, y))`.
    pub volume: [f32; 3],
    /// `N·d(x, y) = nd[0] + x·nd[1] + y·nd[2]`, sign-normalised like the edges.
    pub nd: [f32; 3],
    /// Per edge: does it own samples exactly on it (the §3.4 tie rule)?
    pub owns: [bool; 3],
    /// View-axis distance of the nearest and farthest vertex: every sample's `w`
    /// is clamped into this range (exact in real arithmetic, and it gives early-z
    /// and occlusion culling a bound no rounding can undercut).
    pub w_range: [f32; 2],
    /// Samples nearer than this are rejected.
    pub near: f32,
    /// Per edge: a bound on the rounding error of [`LinearEdges::edge_values`] anywhere
    /// on the image (for conservative binning).
    pub error: [f32; 3],
}

/// The midpoint edge normal `(e − (a+b)/2) × (a − b)` of §3.4. Swapping `a` and `b`
/// negates the result exactly: `a + b` is commutative and `a − b = −(b − a)`.
#[inline]
pub fn edge_normal(eye: Vec3, a: Vec3, b: Vec3) -> Vec3 {
    let mid = (a + b) * 0.5;
    (eye - mid).cross(a - b)
}

/// Linear functions of the image point, `k[0] + x·k[1] + y·k[2]`.
pub type Linear = [f32; 3];

impl Triangle3D {
    /// Paper §3.2 setup: three edge normals, their derivatives along the sample
    /// generator, and the triangle's volume as seen from the eye. `None` when the
    /// triangle is seen exactly edge-on (`D = 0`) or the values are not finite.
    #[inline]
    pub fn setup(p: &[Vec3; 3], view: &View) -> Option<Triangle3D> {
        if view.is_orthographic() {
            return Self::setup_orthographic(p, view);
        }
        let eye = view.eye;
        // 1. Total volume D = N · (p0 − e) with the geometric normal N; its sign is
        //    the side the eye sees, and it orients the edge functions.
        let normal = (p[1] - p[0]).cross(p[2] - p[0]);
        let d = normal.dot(p[0] - eye);
        if d == 0.0 || !d.is_finite() {
            return None;
        }
        let sign = if d > 0.0 { 1.0 } else { -1.0 };
        let along = |n: Vec3| [n.dot(view.d0), n.dot(view.dx), n.dot(view.dy)];
        // 2. Edge i is opposite vertex i: (p[i+1], p[i+2]).
        let edges =
            [0, 1, 2].map(|i| along(edge_normal(eye, p[(i + 1) % 3], p[(i + 2) % 3]) * sign));
        let w = p.map(|v| (v - eye).dot(view.forward));
        Triangle3D::from_linear(edges, along(normal * sign), [d.abs(), 0.0, 0.0], w, view)
    }

    /// Paper §3.3: orthographic setup, `n_i = d_p × (p_{i+1} − p_{i+2})` and
    /// `V_i = n_i · (m_i − o(x, y))`; the depth `w = N·(p0 − o(x, y)) / (N·d_p)`.
    /// `None` when the triangle is seen edge-on (`N·d_p = 0`).
    pub fn setup_orthographic(p: &[Vec3; 3], view: &View) -> Option<Triangle3D> {
        let dp = view.forward;
        let normal = (p[1] - p[0]).cross(p[2] - p[0]);
        let facing = normal.dot(dp);
        if facing == 0.0 || !facing.is_finite() {
            return None;
        }
        let sign = if facing > 0.0 { 1.0 } else { -1.0 };
        // k·(q − o(x, y)) = k·(q − o0) − x·k·ox − y·k·oy.
        let toward = |k: Vec3, q: Vec3| [k.dot(q - view.o0), -k.dot(view.ox), -k.dot(view.oy)];
        let edges = [0, 1, 2].map(|i| {
            let (a, b) = (p[(i + 1) % 3], p[(i + 2) % 3]);
            toward(dp.cross(a - b) * sign, (a + b) * 0.5)
        });
        let w = p.map(|v| (v - view.eye).dot(dp));
        Triangle3D::from_linear(
            edges,
            [facing.abs(), 0.0, 0.0],
            toward(normal * sign, p[0]),
            w,
            view,
        )
    }

    /// Assembles a triangle from its three sign-normalised edge functions, the
    /// depth as a ratio of linear functions `w = volume / nd`, and its vertices'
    /// `w`: derives the tie rule and the error bounds. `None` on non-finite values.
    pub fn from_linear(
        edges: [Linear; 3],
        nd: Linear,
        volume: Linear,
        vertex_w: [f32; 3],
        view: &View,
    ) -> Option<Triangle3D> {
        let (x_max, y_max) = (view.width as f32, view.height as f32);
        let t = Triangle3D {
            a: edges.map(|e| e[0]),
            b: edges.map(|e| e[1]),
            c: edges.map(|e| e[2]),
            nd,
            volume,
            owns: edges.map(|e| owns_tie(e[1], e[2])),
            w_range: [
                vertex_w[0].min(vertex_w[1]).min(vertex_w[2]),
                vertex_w[0].max(vertex_w[1]).max(vertex_w[2]),
            ],
            near: view.near,
            // (A + x·B) + y·C rounds four times, each by at most 2⁻²⁴ of the sum of
            // the terms' magnitudes; 2⁻²⁰ leaves a factor-4 margin.
            error: edges.map(|e| {
                (e[0].abs() + x_max * e[1].abs() + y_max * e[2].abs()) * (1.0 / (1 << 20) as f32)
            }),
        };
        let finite = edges
            .iter()
            .flatten()
            .chain(&nd)
            .chain(&volume)
            .chain(&t.w_range)
            .all(|v| v.is_finite());
        finite.then_some(t)
    }
}

impl LinearEdges for Triangle3D {
    /// The three edge values at image point `(x, y)`: `(A + x·B) + y·C`.
    #[inline(always)]
    fn edge_values(&self, x: f32, y: f32) -> [f32; 3] {
        [
            self.a[0] + x * self.b[0] + y * self.c[0],
            self.a[1] + x * self.b[1] + y * self.c[1],
            self.a[2] + x * self.b[2] + y * self.c[2],
        ]
    }

    #[inline(always)]
    fn owns(&self) -> [bool; 3] {
        self.owns
    }

    /// `w = |D| / (N·d)`, clamped to the vertices' range; `None` below `near`.
    #[inline(always)]
    fn depth(&self, _edges: [f32; 3], x: f32, y: f32) -> Option<f32> {
        let facing = self.nd[0] + x * self.nd[1] + y * self.nd[2];
        if facing <= 0.0 {
            return None;
        }
        let volume = self.volume[0] + x * self.volume[1] + y * self.volume[2];
        // max/min rather than clamp: never panics, and the 8-lane path rounds alike.
        let w = (volume / facing).max(self.w_range[0]).min(self.w_range[1]);
        (w >= self.near).then_some(w)
    }

    fn edge_error(&self) -> [f32; 3] {
        self.error
    }
}

/// The 8-lane forms of the scalar operations (no fused multiply-add, the same
/// operation order, so every lane rounds as [`Coverage::sample`] does).
impl Triangle3D {
    #[inline(always)]
    fn sample_lanes(&self, x: f32x8, y: f32x8) -> (u8, [f32; 8]) {
        let facing = self.facing_lanes(x, y);
        let inside = self.edges_lanes(x, y) & facing.simd_gt(f32x8::ZERO);
        let mask = inside.to_bitmask() as u8;
        if mask == 0 {
            return (0, [0.0; 8]);
        }
        self.depth_lanes(x, y, facing, mask)
    }

    /// All-ones lanes where the three edges (with the tie rule) hold the point.
    #[inline(always)]
    fn edges_lanes(&self, x: f32x8, y: f32x8) -> f32x8 {
        let zero = f32x8::ZERO;
        let mut inside = f32x8::from([f32::from_bits(u32::MAX); 8]);
        for k in 0..3 {
            let e =
                f32x8::splat(self.a[k]) + x * f32x8::splat(self.b[k]) + y * f32x8::splat(self.c[k]);
            let on_edge = if self.owns[k] {
                e.simd_eq(zero)
            } else {
                zero.simd_ne(zero)
            };
            inside &= e.simd_gt(zero) | on_edge;
        }
        inside
    }

    #[inline(always)]
    fn facing_lanes(&self, x: f32x8, y: f32x8) -> f32x8 {
        f32x8::splat(self.nd[0]) + x * f32x8::splat(self.nd[1]) + y * f32x8::splat(self.nd[2])
    }

    /// `w` per lane, and `mask` narrowed to the lanes at or beyond `near`.
    #[inline(always)]
    fn depth_lanes(&self, x: f32x8, y: f32x8, facing: f32x8, mask: u8) -> (u8, [f32; 8]) {
        let volume = f32x8::splat(self.volume[0])
            + x * f32x8::splat(self.volume[1])
            + y * f32x8::splat(self.volume[2]);
        let w = (volume / facing)
            .fast_max(f32x8::splat(self.w_range[0]))
            .fast_min(f32x8::splat(self.w_range[1]));
        let mask = mask & w.simd_ge(f32x8::splat(self.near)).to_bitmask() as u8;
        (mask, w.to_array())
    }
}

impl Coverage for Triangle3D {
    #[inline(always)]
    fn sample(&self, x: f32, y: f32) -> Option<f32> {
        linear_sample(self, x, y)
    }

    #[inline(always)]
    fn depth_inside(&self, x: f32, y: f32) -> Option<f32> {
        self.depth(self.edge_values(x, y), x, y)
    }

    fn classify_block(&self, x0: f32, y0: f32, x1: f32, y1: f32) -> BlockTest {
        linear_classify(self, x0, y0, x1, y1)
    }

    /// Eight samples side by side (8 lanes, `wide`): the scalar operations of
    /// [`LinearEdges::edge_values`], the tie rule and [`LinearEdges::depth`], lane by lane.
    #[inline(always)]
    fn sample8(&self, x0: f32, y: f32) -> (u8, [f32; 8]) {
        let x = f32x8::splat(x0) + f32x8::from([0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]);
        self.sample_lanes(x, f32x8::splat(y))
    }

    #[inline(always)]
    fn sample_points8(&self, x: [f32; 8], y: [f32; 8]) -> (u8, [f32; 8]) {
        self.sample_lanes(f32x8::from(x), f32x8::from(y))
    }

    /// Edges, facing, and `w ≥ near` as `volume ≥ near·facing`: no division
    /// (and no clamp to the vertices' range).
    #[inline(always)]
    fn covers8(&self, x: [f32; 8], y: [f32; 8]) -> u8 {
        let (x, y) = (f32x8::from(x), f32x8::from(y));
        let facing = self.facing_lanes(x, y);
        let volume = f32x8::splat(self.volume[0])
            + x * f32x8::splat(self.volume[1])
            + y * f32x8::splat(self.volume[2]);
        let inside = self.edges_lanes(x, y)
            & facing.simd_gt(f32x8::ZERO)
            & volume.simd_ge(facing * f32x8::splat(self.near));
        inside.to_bitmask() as u8
    }

    #[inline(always)]
    fn depth_inside8(&self, x: [f32; 8], y: [f32; 8]) -> (u8, [f32; 8]) {
        let (x, y) = (f32x8::from(x), f32x8::from(y));
        let facing = self.facing_lanes(x, y);
        self.depth_lanes(x, y, facing, facing.simd_gt(f32x8::ZERO).to_bitmask() as u8)
    }

    fn min_depth(&self) -> f32 {
        self.w_range[0].max(self.near)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;

    /// The 8-lane path gives exactly the scalar path's coverage and depth, on
    /// random triangles near and through the eye plane, including samples on edges.
    #[test]
    fn eight_lanes_round_like_the_scalar_path() {
        let mut rng = fastrand::Rng::with_seed(7);
        let camera = Camera {
            name: "t".into(),
            eye: Vec3::new(0.3, -0.2, 4.0),
            target: Vec3::new(0.0, 0.1, 0.0),
            up: Vec3::Y,
            viewport: crate::camera::Viewport::Perspective { fov_y_deg: 60.0 },
            near: Some(0.05),
        };
        let view = View::new(&camera, 64, 48, 0.01).unwrap();
        let mut rand_point = || {
            Vec3::new(
                rng.f32() * 8.0 - 4.0,
                rng.f32() * 6.0 - 3.0,
                rng.f32() * 9.0 - 5.0,
            )
        };
        let mut compared = 0;
        for _ in 0..2000 {
            let p = [rand_point(), rand_point(), rand_point()];
            let Some(t) = Triangle3D::setup(&p, &view) else {
                continue;
            };
            for y in 0..48 {
                let yc = y as f32 + 0.5;
                for x0 in (0..64).step_by(8) {
                    let (mask, depth) = t.sample8(x0 as f32 + 0.5, yc);
                    for (k, &lane_depth) in depth.iter().enumerate() {
                        let scalar = t.sample((x0 + k) as f32 + 0.5, yc);
                        let lane = (mask >> k & 1 == 1).then_some(lane_depth);
                        assert_eq!(
                            scalar.map(f32::to_bits),
                            lane.map(f32::to_bits),
                            "pixel ({}, {y})",
                            x0 + k
                        );
                        compared += usize::from(scalar.is_some());
                    }
                }
            }
        }
        assert!(
            compared > 10_000,
            "only {compared} covered samples compared"
        );
    }
}
