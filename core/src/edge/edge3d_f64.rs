//! 3D edge functions in double precision (`--precision f64`): the same setup and
//! per-sample decision as [`Triangle3D`](super::Triangle3D) (paper §3.2–3.4),
//! every value in f64, vertices taken relative to the eye (or the orthographic
//! ray origin) before anything else so that geometry far from the world origin
//! loses nothing. The sample generator is the view's own (its f32 `d0`, `dx`,
//! `dy`, converted exactly), so f32 and f64 renders sample the same rays.

use glam::{DVec3, Vec3};

use super::{BlockTest, Coverage};
use crate::camera::View;

/// Linear functions of the image point in f64, `k[0] + x·k[1] + y·k[2]`.
type Linear64 = [f64; 3];

/// A triangle set up for 3D rasterization against one view, in f64.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle3D64 {
    /// Per edge `i` (opposite vertex `i`): `E_i = A_i + x·B_i + y·C_i`, inside positive.
    edges: [Linear64; 3],
    /// `N·d(x, y)`, sign-normalised like the edges.
    nd: Linear64,
    /// `|D|` as a linear function of the image point: `w = volume / (N·d)`.
    volume: Linear64,
    pub owns: [bool; 3],
    /// Nearest and farthest vertex `w`, rounded outward to f32.
    w_range: [f32; 2],
    near: f32,
    /// Per edge, a bound on the rounding error of an evaluation on the image.
    error: [f64; 3],
}

/// The §3.4 midpoint normal `(e − (a+b)/2) × (a − b)` with the eye at the origin.
#[inline]
fn edge_normal(a: DVec3, b: DVec3) -> DVec3 {
    -((a + b) * 0.5).cross(a - b)
}

impl Triangle3D64 {
    /// Paper §3.2 (perspective) and §3.3 (orthographic) setup in f64. `None`
    /// when the triangle is seen edge-on or values are not finite.
    pub fn setup(p: &[Vec3; 3], view: &View) -> Option<Triangle3D64> {
        let (d0, dx, dy) = (view.d0.as_dvec3(), view.dx.as_dvec3(), view.dy.as_dvec3());
        let forward = view.forward.as_dvec3();
        let eye = view.eye.as_dvec3();
        // 1. Vertices relative to the eye: exact for f32 inputs.
        let c = p.map(|v| v.as_dvec3() - eye);
        let normal = (c[1] - c[0]).cross(c[2] - c[0]);
        let w = c.map(|v| v.dot(forward));
        let (edges, nd, volume) = if view.is_orthographic() {
            // k·(q − o(x, y)) with o(x, y) − eye = (o0 − eye) + x·ox + y·oy.
            let (o0, ox, oy) = (view.o0.as_dvec3(), view.ox.as_dvec3(), view.oy.as_dvec3());
            let facing = normal.dot(forward);
            if facing == 0.0 || !facing.is_finite() {
                return None;
            }
            let sign = facing.signum();
            let toward = |k: DVec3, q: DVec3| [k.dot(q - o0), -k.dot(ox), -k.dot(oy)];
            let edges = [0, 1, 2].map(|i| {
                let (a, b) = (c[(i + 1) % 3], c[(i + 2) % 3]);
                toward(forward.cross(a - b) * sign, (a + b) * 0.5)
            });
            (edges, [facing.abs(), 0.0, 0.0], toward(normal * sign, c[0]))
        } else {
            let d = normal.dot(c[0]);
            if d == 0.0 || !d.is_finite() {
                return None;
            }
            let sign = d.signum();
            let along = |n: DVec3| [n.dot(d0), n.dot(dx), n.dot(dy)];
            let edges =
                [0, 1, 2].map(|i| along(edge_normal(c[(i + 1) % 3], c[(i + 2) % 3]) * sign));
            (edges, along(normal * sign), [d.abs(), 0.0, 0.0])
        };
        let (x_max, y_max) = (f64::from(view.width), f64::from(view.height));
        let lo = w[0].min(w[1]).min(w[2]);
        let hi = w[0].max(w[1]).max(w[2]);
        let t = Triangle3D64 {
            edges,
            nd,
            volume,
            owns: edges.map(|e| tie_f64(e[1], e[2])),
            // Rounded outward, so the clamp never moves a sample inside the range.
            w_range: [down_f32(lo), up_f32(hi)],
            near: view.near,
            // (A + x·B) + y·C rounds four times by at most 2⁻⁵³ of the terms'
            // magnitudes; 2⁻⁵⁰ leaves a margin.
            error: edges
                .map(|e| (e[0].abs() + x_max * e[1].abs() + y_max * e[2].abs()) * 2f64.powi(-50)),
        };
        let finite = edges
            .iter()
            .flatten()
            .chain(&nd)
            .chain(&volume)
            .all(|v| v.is_finite())
            && t.w_range.iter().all(|v| v.is_finite());
        finite.then_some(t)
    }

    #[inline(always)]
    fn edge_values(&self, x: f64, y: f64) -> [f64; 3] {
        self.edges.map(|e| e[0] + x * e[1] + y * e[2])
    }

    #[inline(always)]
    fn depth_at(&self, x: f64, y: f64) -> Option<f32> {
        let facing = self.nd[0] + x * self.nd[1] + y * self.nd[2];
        if facing <= 0.0 {
            return None;
        }
        let volume = self.volume[0] + x * self.volume[1] + y * self.volume[2];
        let w = ((volume / facing) as f32)
            .max(self.w_range[0])
            .min(self.w_range[1]);
        (w >= self.near).then_some(w)
    }
}

/// The tie rule ([`super::owns_tie`]) on f64 derivatives.
#[inline]
fn tie_f64(de_dx: f64, de_dy: f64) -> bool {
    de_dx > 0.0 || (de_dx == 0.0 && de_dy > 0.0)
}

/// The largest f32 not above `v`.
fn down_f32(v: f64) -> f32 {
    let f = v as f32;
    if f64::from(f) > v { f.next_down() } else { f }
}

/// The smallest f32 not below `v`.
fn up_f32(v: f64) -> f32 {
    let f = v as f32;
    if f64::from(f) < v { f.next_up() } else { f }
}

impl Coverage for Triangle3D64 {
    #[inline(always)]
    fn sample(&self, x: f32, y: f32) -> Option<f32> {
        let (x, y) = (f64::from(x), f64::from(y));
        let e = self.edge_values(x, y);
        let inside = (0..3).all(|i| e[i] > 0.0 || (e[i] == 0.0 && self.owns[i]));
        if inside { self.depth_at(x, y) } else { None }
    }

    #[inline(always)]
    fn depth_inside(&self, x: f32, y: f32) -> Option<f32> {
        self.depth_at(f64::from(x), f64::from(y))
    }

    fn classify_block(&self, x0: f32, y0: f32, x1: f32, y1: f32) -> BlockTest {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for (x, y) in [(x0, y0), (x1, y0), (x0, y1), (x1, y1)] {
            let e = self.edge_values(f64::from(x), f64::from(y));
            for k in 0..3 {
                lo[k] = lo[k].min(e[k]);
                hi[k] = hi[k].max(e[k]);
            }
        }
        if (0..3).any(|k| hi[k] < -self.error[k]) {
            BlockTest::Outside
        } else if (0..3).all(|k| lo[k] > self.error[k]) {
            BlockTest::Inside
        } else {
            BlockTest::Partial
        }
    }

    fn min_depth(&self) -> f32 {
        self.w_range[0].max(self.near)
    }
}
