//! 3D edge functions on non-planar viewports (paper §3.5).
//!
//! With the eye at the origin of camera space the edge function of edge `(a, b)`
//! is `V(d) = n·d`, `n = −(a+b)/2 × (a − b)` (the §3.4 midpoint normal), and `d`
//! the sample direction the viewport generates. Under a parabolic or latitude–
//! longitude mapping `d(x, y)` is not linear, so `V` is evaluated directly per
//! sample (`d` once per sample, three dot products per triangle), in f64. The
//! projected edges are curves: parabolic edges are circle arcs, which binning
//! handles by shifting its evaluation points toward the circle centre; the
//! latitude–longitude curves are bounded through the angular size of a block.
//!
//! Depth is the Euclidean distance from the eye, `|D|·|d| / (N·d)`.

use glam::DVec3;

use super::{BlockTest, Coverage};
use crate::camera::{SphereMap, View};
use crate::simd::Lanes;

/// A triangle set up against a non-planar viewport.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurvedTriangle {
    /// Camera-space edge normals, oriented so the inside is `n·d > 0`.
    pub n: [DVec3; 3],
    /// Geometric normal, oriented like the edges.
    pub normal: DVec3,
    /// `|D| = |N·p0|` (camera space, eye at the origin).
    pub volume: f64,
    /// Distance to the triangle's plane and to its farthest vertex: every
    /// sample's distance is clamped into this range.
    pub range: [f32; 2],
    pub near: f32,
    pub map: SphereMap,
    /// Parabolic runs of samples evaluate the edges with the double-incremental
    /// scheme of §3.5 eq. 3 instead of directly.
    pub incremental: bool,
}

/// Relative rounding bound of an f64 edge value (a few ulps, with a wide margin).
const F64_ERROR: f64 = 1e-12;

impl CurvedTriangle {
    /// Setup in camera space: three midpoint edge normals and the volume.
    /// `None` for planar views, and for triangles seen edge-on (`D = 0`) or with
    /// values that are not finite.
    pub fn setup(p: &[glam::Vec3; 3], view: &View) -> Option<CurvedTriangle> {
        let map = view.sphere?;
        let c = p.map(|v| view.to_camera_f64(v));
        let normal = (c[1] - c[0]).cross(c[2] - c[0]);
        let d = normal.dot(c[0]);
        if d == 0.0 || !d.is_finite() {
            return None;
        }
        let sign = if d > 0.0 { 1.0 } else { -1.0 };
        let n = [0, 1, 2].map(|i| {
            let (a, b) = (c[(i + 1) % 3], c[(i + 2) % 3]);
            -((a + b) * 0.5).cross(a - b) * sign
        });
        let plane = d.abs() / normal.length();
        let far = c[0].length().max(c[1].length()).max(c[2].length());
        let t = CurvedTriangle {
            n,
            normal: normal * sign,
            volume: d.abs(),
            range: [plane as f32, far as f32],
            near: view.near,
            map,
            incremental: false,
        };
        let finite = n.iter().chain(&[t.normal]).all(|v| v.is_finite())
            && t.range.iter().all(|v| v.is_finite());
        finite.then_some(t)
    }

    /// Distance of the sample with direction `d`, or `None` when rejected.
    #[inline]
    fn distance(&self, d: DVec3) -> Option<f32> {
        let facing = self.normal.dot(d);
        if facing <= 0.0 {
            return None;
        }
        let distance = (self.volume * d.length() / facing) as f32;
        let distance = distance.max(self.range[0]).min(self.range[1]);
        (distance >= self.near).then_some(distance)
    }

    /// Direct evaluation: is the sample with direction `d` at `(x, y)` inside
    /// edge `k` (strictly, or on it and owning the tie)?
    #[inline]
    fn inside_edge(&self, k: usize, d: DVec3, x: f64, y: f64) -> bool {
        let v = self.n[k].dot(d);
        v > 0.0 || (v == 0.0 && self.owns_at(k, x, y))
    }

    /// Paper §3.5 eq. 3 along a row: `V` and its derivative `G = ∂V/∂u =
    /// n_x − n_z·u` are carried from sample to sample, `V ← V + h·G − n_z·h²/2`,
    /// `G ← G − n_z·h` (`h` one pixel in disc units). Where `|V|` is within the
    /// bound on the accumulated rounding error the sample is decided by direct
    /// evaluation, so the decisions equal [`Coverage::sample`]'s exactly.
    fn sample_run_incremental(
        &self,
        (cx, cy, radius): (f64, f64, f64),
        x0: f32,
        y: f32,
        n: u32,
        mut hit: impl FnMut(u32, f32),
    ) {
        let yf = f64::from(y);
        let h = 1.0 / radius;
        let (u0, v) = SphereMap::disc(cx, cy, radius, f64::from(x0), yf);
        let u_max = u0.abs().max((u0 + h * f64::from(n)).abs());
        let mut value = self.n.map(|e| Self::parabolic_value(e, u0, v));
        let mut slope = self.n.map(|e| e.x - e.z * u0);
        // Every term of V is at most this large; each step adds a few ulps of it.
        let scale = self.n.map(|e| {
            e.x.abs() * u_max
                + e.y.abs() * v.abs()
                + e.z.abs() * (0.5 + 0.5 * (u_max * u_max + v * v))
        });
        const STEP_ERROR: f64 = 64.0 * f64::EPSILON;
        // The second differences are constant along the row.
        let curvature = self.n.map(|e| e.z * h * h * 0.5);
        let slope_step = self.n.map(|e| e.z * h);
        for j in 0..n {
            let x = x0 + j as f32;
            let xf = f64::from(x);
            let band = f64::from(j + 1) * STEP_ERROR;
            let mut direction = None;
            let mut inside = true;
            for k in 0..3 {
                inside &= if value[k].abs() > band * scale[k] {
                    value[k] > 0.0
                } else {
                    // Too close to the edge for the increments: decide directly.
                    let d = *direction.get_or_insert_with(|| self.map.direction(xf, yf));
                    d.is_some_and(|d| self.inside_edge(k, d, xf, yf))
                };
                value[k] += h * slope[k] - curvature[k];
                slope[k] -= slope_step[k];
            }
            if inside
                && let Some(d) = direction.unwrap_or_else(|| self.map.direction(xf, yf))
                && let Some(w) = self.distance(d)
            {
                hit(j, w);
            }
        }
    }

    /// The §3.4 tie rule at a sample exactly on edge `k`, with the derivatives
    /// of `V` there: the edge belongs to the triangle where `V` grows to the
    /// right, or, where it does not change along x, downwards.
    #[inline(never)]
    fn owns_at(&self, k: usize, x: f64, y: f64) -> bool {
        let (ddx, ddy) = self.map.derivatives(x, y);
        let (vx, vy) = (self.n[k].dot(ddx), self.n[k].dot(ddy));
        vx > 0.0 || (vx == 0.0 && vy > 0.0)
    }

    /// The edge value of edge `k` at parabolic disc point `(u, v)` (any point of
    /// the plane, inside the disc or not).
    #[inline]
    fn parabolic_value(n: DVec3, u: f64, v: f64) -> f64 {
        n.x * u + n.y * v + n.z * (0.5 - 0.5 * (u * u + v * v))
    }

    /// Paper §3.5 binning for parabolic edges. The edge `V = 0` is a circle of
    /// radius `r = |n| / |n_z|` around `(n_x, n_y) / n_z` in disc coordinates. A
    /// block's corners miss the circle's disc when it reaches into the block
    /// through one side only, by at most `p = r − sqrt(r² − m²/4)`; so the side
    /// facing the centre (the larger coordinate of centre − block centre) is
    /// evaluated shifted toward it by `p`. Blocks with `r < m` are always
    /// refined: the paper's `r < m/2` leaves a gap where the circle reaches the
    /// block through a corner and the shifted corner overshoots it (for `r ≥ m`,
    /// `p ≤ 0.134 r` and the shifted corner stays inside).
    fn classify_parabolic(&self, cx: f64, cy: f64, radius: f64, rect: [f64; 4]) -> BlockTest {
        let [x0, y0, x1, y1] = rect;
        // Disc coordinates of the corners: u grows right, v up.
        let (u0, u1) = ((x0 - cx) / radius, (x1 - cx) / radius);
        let (v0, v1) = ((cy - y1) / radius, (cy - y0) / radius);
        let m = (u1 - u0).max(v1 - v0);
        let (mid_u, mid_v) = ((u0 + u1) * 0.5, (v0 + v1) * 0.5);
        let mut all_inside = true;
        for n in self.n {
            let error = n.length() * F64_ERROR;
            let mut corners = [(u0, v0), (u1, v0), (u0, v1), (u1, v1)];
            if n.z != 0.0 {
                let (ccx, ccy) = (n.x / n.z, n.y / n.z);
                let r = n.length() / n.z.abs();
                if r < m {
                    all_inside = false;
                    continue;
                }
                let p = r - (r * r - m * m * 0.25).sqrt();
                let (sx, sy) = (ccx - mid_u, ccy - mid_v);
                for (u, v) in &mut corners {
                    if sx.abs() >= sy.abs() {
                        if (sx > 0.0) == (*u == u1) {
                            *u += p.copysign(sx);
                        }
                    } else if (sy > 0.0) == (*v == v1) {
                        *v += p.copysign(sy);
                    }
                }
            }
            let values = corners.map(|(u, v)| Self::parabolic_value(n, u, v));
            if values.iter().all(|&e| e < -error) {
                return BlockTest::Outside;
            }
            all_inside &= values.iter().all(|&e| e > error);
        }
        if all_inside {
            BlockTest::Inside
        } else {
            BlockTest::Partial
        }
    }

    /// Latitude–longitude binning: every sample direction of the block lies
    /// within angle `α ≤ Δφ/2 + cos φ_max · Δθ/2` of the block centre's
    /// direction (a meridian then a parallel), so `|V(d) − V(d_c)| ≤ |n|·α`.
    fn classify_latlong(&self, width: f64, height: f64, rect: [f64; 4]) -> BlockTest {
        let [x0, y0, x1, y1] = rect;
        let Some(dc) = self.map.direction((x0 + x1) * 0.5, (y0 + y1) * 0.5) else {
            return BlockTest::Partial;
        };
        let half_theta = (x1 - x0) * 0.5 / width * std::f64::consts::TAU;
        let half_phi = (y1 - y0) * 0.5 / height * std::f64::consts::PI;
        let phi = |y: f64| std::f64::consts::FRAC_PI_2 - y / height * std::f64::consts::PI;
        let (top, bottom) = (phi(y0), phi(y1));
        let cos_max = if top >= 0.0 && bottom <= 0.0 {
            1.0
        } else {
            top.abs().min(bottom.abs()).cos()
        };
        let angle = half_phi + cos_max * half_theta;
        let mut all_inside = true;
        for n in self.n {
            let bound = n.length() * (angle + F64_ERROR);
            let v = n.dot(dc);
            if v < -bound {
                return BlockTest::Outside;
            }
            all_inside &= v > bound;
        }
        if all_inside {
            BlockTest::Inside
        } else {
            BlockTest::Partial
        }
    }
}

impl Coverage for CurvedTriangle {
    const OWN_SAMPLE_RUN: bool = true;

    /// `V_i = n_i·d(x, y)` for the three edges, the tie rule on `V_i = 0`, then
    /// the distance.
    #[inline]
    fn sample(&self, x: f32, y: f32) -> Option<f32> {
        let (x, y) = (f64::from(x), f64::from(y));
        let d = self.map.direction(x, y)?;
        if (0..3).all(|k| self.inside_edge(k, d, x, y)) {
            self.distance(d)
        } else {
            None
        }
    }

    fn sample_run<L: Lanes>(&self, x0: f32, y: f32, n: u32, mut hit: impl FnMut(u32, f32)) {
        match self.map {
            SphereMap::Parabolic { cx, cy, radius } if self.incremental => {
                self.sample_run_incremental((cx, cy, radius), x0, y, n, hit);
            }
            _ => {
                for k in 0..n {
                    if let Some(w) = self.sample(x0 + k as f32, y) {
                        hit(k, w);
                    }
                }
            }
        }
    }

    fn depth_inside(&self, x: f32, y: f32) -> Option<f32> {
        self.distance(self.map.direction(f64::from(x), f64::from(y))?)
    }

    fn classify_block(&self, x0: f32, y0: f32, x1: f32, y1: f32) -> BlockTest {
        let rect = [x0, y0, x1, y1].map(f64::from);
        match self.map {
            SphereMap::Parabolic { cx, cy, radius } => {
                self.classify_parabolic(cx, cy, radius, rect)
            }
            SphereMap::LatLong { width, height } => self.classify_latlong(width, height, rect),
        }
    }

    fn min_depth(&self) -> f32 {
        self.range[0].max(self.near)
    }
}
