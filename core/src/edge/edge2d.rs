//! 2D edge functions on projected vertices (paper §3.1).
//!
//! Each edge is evaluated relative to its canonical endpoint (the lexicographically
//! smaller one), `E(p) = (hi − lo) × (p − lo)`, then signed for the triangle. Two
//! triangles sharing an edge compute the same canonical value bit for bit and
//! apply opposite signs, so a sample on the edge goes to exactly one of them; a
//! sample exactly on a vertex gets `E = 0` exactly on both of its edges.

use super::{
    BlockTest, Coverage, EdgeWalk, LinearEdges, RowLanes, inside_edge, linear_classify,
    linear_sample, owns_tie,
};
use crate::simd::Lanes;

/// A projected vertex: pixel coordinates and the depth quantity that is linear in
/// the image: `1/w` under perspective, `w` itself under orthographic projection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScreenVertex {
    pub x: f32,
    pub y: f32,
    pub q: f32,
}

/// A projected triangle set up for 2D rasterization.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle2D {
    /// Canonical edge start per edge `i` (opposite vertex `i`).
    lo: [[f32; 2]; 3],
    /// `hi − lo` per edge.
    delta: [[f32; 2]; 3],
    /// ±1: the edge's sign for this triangle (canonical order × orientation).
    sign: [f32; 3],
    pub owns: [bool; 3],
    /// The image-linear depth quantity at each vertex (see [`ScreenVertex::q`]).
    q: [f32; 3],
    /// `q` is `w` (orthographic) rather than `1/w`.
    affine: bool,
    /// Smallest and largest vertex `w`: sample depths are clamped into it.
    w_range: [f32; 2],
    /// Per edge, a bound on the rounding error of an evaluation on the image.
    error: [f32; 3],
    /// Pixel-coordinate bounds of the vertices: `[min_x, min_y, max_x, max_y]`.
    pub bounds: [f32; 4],
}

impl Triangle2D {
    /// Sets up the three edge functions; `None` for triangles that are degenerate
    /// in f32 after projection (some vertex not strictly inside its opposite edge).
    /// `affine`: the vertices' `q` is `w` (orthographic), not `1/w`.
    pub fn setup(
        v: &[ScreenVertex; 3],
        affine: bool,
        width: u32,
        height: u32,
    ) -> Option<Triangle2D> {
        let w_range = w_range(v, affine);
        // 1. Canonical endpoints per edge (lexicographic on (x, y)).
        let (mut lo, mut delta, mut sign) = ([[0.0; 2]; 3], [[0.0; 2]; 3], [1.0; 3]);
        for i in 0..3 {
            let a = v[(i + 1) % 3];
            let b = v[(i + 2) % 3];
            let (l, h, flip) = if (a.x, a.y) <= (b.x, b.y) {
                (a, b, 1.0)
            } else {
                (b, a, -1.0)
            };
            lo[i] = [l.x, l.y];
            delta[i] = [h.x - l.x, h.y - l.y];
            sign[i] = flip;
        }
        if !(w_range[0].is_finite() && w_range[1].is_finite()) {
            return None;
        }
        // 2. Orientation from edge 0 at its opposite vertex; the triangle is kept
        //    only if every vertex is strictly inside its opposite edge.
        let orientation = raw_edge(lo[0], delta[0], v[0].x, v[0].y) * sign[0];
        if !(orientation != 0.0 && orientation.is_finite()) {
            return None;
        }
        let orient = if orientation > 0.0 { 1.0 } else { -1.0 };
        let mut error = [0.0; 3];
        for (i, vertex) in v.iter().enumerate() {
            sign[i] *= orient;
            let inside = raw_edge(lo[i], delta[i], vertex.x, vertex.y) * sign[i];
            if inside.is_nan() || inside <= 0.0 {
                return None;
            }
            // Δx·(y − ly) − Δy·(x − lx) rounds five times, each by at most 2⁻²⁴ of
            // the terms' magnitudes; 2⁻²⁰ leaves a margin.
            let [lx, ly] = lo[i];
            let [dx, dy] = delta[i];
            let span = dx.abs() * (height as f32 + ly.abs()) + dy.abs() * (width as f32 + lx.abs());
            error[i] = span * (1.0 / (1 << 20) as f32);
        }
        Some(Triangle2D::from_parts(
            v,
            affine,
            w_range,
            (lo, delta, sign),
            error,
        ))
    }

    /// The set-up triangle of vertices `v` from its edges (canonical starts,
    /// `hi − lo` and signs, orientation applied), the range of its vertices'
    /// `w` and its error bounds: the tie ownership and the bounds follow.
    #[inline(always)]
    pub(super) fn from_parts(
        v: &[ScreenVertex; 3],
        affine: bool,
        w_range: [f32; 2],
        (lo, delta, sign): ([[f32; 2]; 3], [[f32; 2]; 3], [f32; 3]),
        error: [f32; 3],
    ) -> Triangle2D {
        Triangle2D {
            lo,
            delta,
            sign,
            // ∂E/∂x = −Δy·s, ∂E/∂y = Δx·s.
            owns: [0, 1, 2].map(|i| owns_tie(-delta[i][1] * sign[i], delta[i][0] * sign[i])),
            q: [v[0].q, v[1].q, v[2].q],
            affine,
            w_range,
            error,
            bounds: [
                v[0].x.min(v[1].x).min(v[2].x),
                v[0].y.min(v[1].y).min(v[2].y),
                v[0].x.max(v[1].x).max(v[2].x),
                v[0].y.max(v[1].y).max(v[2].y),
            ],
        }
    }

    /// Every field's bits, to compare set-ups exactly.
    #[cfg(test)]
    pub(super) fn bits(&self) -> Vec<u32> {
        let floats = (self.lo.iter().chain(&self.delta).flatten())
            .chain(&self.sign)
            .chain(&self.q)
            .chain(&self.w_range)
            .chain(&self.error)
            .chain(&self.bounds);
        (floats.map(|f| f.to_bits()))
            .chain(self.owns.map(u32::from))
            .chain([u32::from(self.affine)])
            .collect()
    }

    /// The triangle as the GPU kernels read it (`Tri` in `gpu/compute.wgsl`,
    /// 2D layout): rows 0..2 `(lo, Δ)` per edge, row 3 `(signs, q0)`, row 4
    /// `(q1, q2, w_min, w_max)`; and the flags (tie ownership per edge, 2D,
    /// affine).
    #[cfg(feature = "gpu")]
    pub(crate) fn gpu_rows(&self) -> ([[f32; 4]; 5], u32) {
        let edge = |i: usize| {
            [
                self.lo[i][0],
                self.lo[i][1],
                self.delta[i][0],
                self.delta[i][1],
            ]
        };
        let mut flags = 8 | if self.affine { 16 } else { 0 };
        for (i, &owns) in self.owns.iter().enumerate() {
            flags |= u32::from(owns) << i;
        }
        let rows = [
            edge(0),
            edge(1),
            edge(2),
            [self.sign[0], self.sign[1], self.sign[2], self.q[0]],
            [self.q[1], self.q[2], self.w_range[0], self.w_range[1]],
        ];
        (rows, flags)
    }

    /// Canonical (unsigned) edge function `(hi − lo) × (p − lo)`.
    #[inline(always)]
    fn raw(&self, i: usize, x: f32, y: f32) -> f32 {
        raw_edge(self.lo[i], self.delta[i], x, y)
    }
}

/// The smallest and largest `w` of vertices `v` (`q` itself when `affine`,
/// else `1/q`).
#[inline(always)]
pub(super) fn w_range(v: &[ScreenVertex; 3], affine: bool) -> [f32; 2] {
    let w = v.map(|s| if affine { s.q } else { 1.0 / s.q });
    [w[0].min(w[1]).min(w[2]), w[0].max(w[1]).max(w[2])]
}

/// A canonical edge function `Δx·(y − ly) − Δy·(x − lx)` at `(x, y)`.
#[inline(always)]
fn raw_edge([lx, ly]: [f32; 2], [dx, dy]: [f32; 2], x: f32, y: f32) -> f32 {
    dx * (y - ly) - dy * (x - lx)
}

/// The 8-lane forms of [`LinearEdges::edge_values`], the tie rule and
/// [`LinearEdges::depth`]: the same operations in the same order, so every
/// lane rounds as [`linear_sample`] does ([`crate::simd`]).
impl Triangle2D {
    /// The three signed edge values per lane. (No closures in lane code: only
    /// `#[inline(always)]` functions are sure to be compiled for the caller's lanes.)
    #[inline(always)]
    fn edge_lanes<L: Lanes>(&self, x: L, y: L) -> [L; 3] {
        [
            self.edge_lane(0, x, y),
            self.edge_lane(1, x, y),
            self.edge_lane(2, x, y),
        ]
    }

    /// Edge `i`'s signed value per lane.
    #[inline(always)]
    fn edge_lane<L: Lanes>(&self, i: usize, x: L, y: L) -> L {
        let ([lx, ly], [dx, dy]) = (self.lo[i], self.delta[i]);
        (L::splat(dx) * (y - L::splat(ly)) - L::splat(dy) * (x - L::splat(lx)))
            * L::splat(self.sign[i])
    }

    /// The lanes of `mask` with a depth, and the depths (clamped like the scalar's).
    #[inline(always)]
    fn depth_lanes<L: Lanes>(&self, e: [L; 3], mask: u8) -> (u8, [f32; 8]) {
        let sum = e[0] + e[1] + e[2];
        let q =
            e[0] * L::splat(self.q[0]) + e[1] * L::splat(self.q[1]) + e[2] * L::splat(self.q[2]);
        let w = if self.affine { q / sum } else { sum / q };
        let mask = mask & w.gt(L::splat(0.0)) & w.lt(L::splat(f32::INFINITY));
        let w = w
            .max(L::splat(self.w_range[0]))
            .min(L::splat(self.w_range[1]));
        (mask, w.to_array())
    }

    #[inline(always)]
    fn sample_lanes<L: Lanes>(&self, x: L, y: L, active: u8) -> (u8, [f32; 8]) {
        self.decide_lanes(self.edge_lanes(x, y), active)
    }

    /// The lanes of `active` inside the edges with values `e` (the tie rule
    /// on zeros), and their depths.
    #[inline(always)]
    fn decide_lanes<L: Lanes>(&self, e: [L; 3], active: u8) -> (u8, [f32; 8]) {
        let zero = L::splat(0.0);
        let mut inside = active;
        for (i, &e) in e.iter().enumerate() {
            let on = if self.owns[i] { e.eq(zero) } else { 0 };
            inside &= e.gt(zero) | on;
        }
        if inside == 0 {
            return (0, [0.0; 8]);
        }
        self.depth_lanes(e, inside)
    }
}

/// A [`Triangle2D`] along rows ([`RowLanes`]): its coefficients splatted
/// into lanes once, and per row each edge's `Δx·(y − ly)`, so that a group's
/// edge values are [`Triangle2D::edge_lane`]'s with no per-group loads.
struct Rows2D<'a, L> {
    tri: &'a Triangle2D,
    /// Per edge: `lx`, `Δy`, the sign; then the row's `Δx·(y − ly)`.
    edges: [[L; 3]; 3],
    edge_y: [L; 3],
}

impl<L: Lanes> RowLanes<L> for Rows2D<'_, L> {
    #[inline(always)]
    fn set_row(&mut self, y: f32) {
        let y = L::splat(y);
        for i in 0..3 {
            let ([_, ly], [dx, _]) = (self.tri.lo[i], self.tri.delta[i]);
            self.edge_y[i] = L::splat(dx) * (y - L::splat(ly));
        }
    }

    /// [`Triangle2D::sample_lanes`] with the row's terms.
    #[inline(always)]
    fn sample8(&self, _: f32, x: L, active: u8) -> (u8, [f32; 8]) {
        self.tri.decide_lanes(self.edge_values(x), active)
    }

    #[inline(always)]
    fn depth_inside8(&self, x: L) -> (u8, [f32; 8]) {
        self.tri.depth_lanes(self.edge_values(x), 0xff)
    }
}

impl<L: Lanes> Rows2D<'_, L> {
    /// [`Triangle2D::edge_lanes`] with the row's terms.
    #[inline(always)]
    fn edge_values(&self, x: L) -> [L; 3] {
        let mut e = [L::splat(0.0); 3];
        for (i, e) in e.iter_mut().enumerate() {
            let [lx, dy, sign] = self.edges[i];
            *e = (self.edge_y[i] - dy * (x - lx)) * sign;
        }
        e
    }
}

impl Coverage for Triangle2D {
    #[inline(always)]
    fn sample(&self, x: f32, y: f32) -> Option<f32> {
        linear_sample(self, x, y)
    }

    #[inline(always)]
    fn sample_points8<L: Lanes>(&self, x: [f32; 8], y: [f32; 8], active: u8) -> (u8, [f32; 8]) {
        self.sample_lanes(L::from_array(x), L::from_array(y), active)
    }

    #[inline(always)]
    fn rows<L: Lanes>(&self) -> impl RowLanes<L> {
        let zero = L::splat(0.0);
        let mut edges = [[zero; 3]; 3];
        for (i, edge) in edges.iter_mut().enumerate() {
            let ([lx, _], [_, dy]) = (self.lo[i], self.delta[i]);
            *edge = [L::splat(lx), L::splat(dy), L::splat(self.sign[i])];
        }
        Rows2D {
            tri: self,
            edges,
            edge_y: [zero; 3],
        }
    }

    #[inline(always)]
    fn depth_inside8<L: Lanes>(&self, x: [f32; 8], y: [f32; 8]) -> (u8, [f32; 8]) {
        let e = self.edge_lanes(L::from_array(x), L::from_array(y));
        self.depth_lanes(e, 0xff)
    }

    #[inline(always)]
    fn depth_inside(&self, x: f32, y: f32) -> Option<f32> {
        self.depth(self.edge_values(x, y), x, y)
    }

    fn classify_block(&self, x0: f32, y0: f32, x1: f32, y1: f32) -> BlockTest {
        linear_classify(self, x0, y0, x1, y1)
    }

    fn min_depth(&self) -> f32 {
        self.w_range[0]
    }

    const ACROSS: bool = true;

    /// [`Triangle2D::sample_lanes`] with each lane's coefficients its own
    /// triangle's ([`Triangle2D::words`], transposed into lanes): the same
    /// operations in the same order per lane, so the same decisions and
    /// depths.
    #[inline(always)]
    fn sample_across<L: Lanes>(
        tris: [&Self; 8],
        x: [f32; 8],
        y: [f32; 8],
        active: u8,
    ) -> (u8, [f32; 8]) {
        let [lx0, ly0, dx0, dy0, lx1, ly1, dx1, dy1] = L::transpose(tris.map(|t| t.words()[0]));
        let [lx2, ly2, dx2, dy2, s0, s1, s2, q0] = L::transpose(tris.map(|t| t.words()[1]));
        let [q1, q2, w_min, w_max, ..] = L::transpose(tris.map(|t| t.words()[2]));
        let (x, y) = (L::from_array(x), L::from_array(y));
        let e = [
            (dx0 * (y - ly0) - dy0 * (x - lx0)) * s0,
            (dx1 * (y - ly1) - dy1 * (x - lx1)) * s1,
            (dx2 * (y - ly2) - dy2 * (x - lx2)) * s2,
        ];
        let zero = L::splat(0.0);
        let mut inside = active;
        for (i, &e) in e.iter().enumerate() {
            let owns = (0..8).fold(0u8, |m, l| m | u8::from(tris[l].owns[i]) << l);
            inside &= e.gt(zero) | (e.eq(zero) & owns);
        }
        if inside == 0 {
            return (0, [0.0; 8]);
        }
        // Triangle2D::depth_lanes with each lane's q and w range.
        let sum = e[0] + e[1] + e[2];
        let q = e[0] * q0 + e[1] * q1 + e[2] * q2;
        let w = if tris[0].affine { q / sum } else { sum / q };
        let mask = inside & w.gt(zero) & w.lt(L::splat(f32::INFINITY));
        (mask, w.max(w_min).min(w_max).to_array())
    }
}

impl Triangle2D {
    /// What [`Coverage::sample_across`] reads of the triangle, as 24 words:
    /// per edge its start and delta (edges 0 and 1, then 2), the signs, `q`,
    /// and the `w` range.
    #[inline(always)]
    fn words(&self) -> [[f32; 8]; 3] {
        let ([l0, l1, l2], [d0, d1, d2]) = (self.lo, self.delta);
        let ([s0, s1, s2], [q0, q1, q2], [w0, w1]) = (self.sign, self.q, self.w_range);
        [
            [l0[0], l0[1], d0[0], d0[1], l1[0], l1[1], d1[0], d1[1]],
            [l2[0], l2[1], d2[0], d2[1], s0, s1, s2, q0],
            [q1, q2, w0, w1, 0.0, 0.0, 0.0, 0.0],
        ]
    }
}

impl EdgeWalk for Triangle2D {
    /// `E = s·(Δx·(y − ly) − Δy·(x − lx))`: `a = −s·Δy`, `b = s·Δx`, both exact.
    fn edge_line(&self, i: usize) -> [f64; 3] {
        let ([lx, ly], [dx, dy], s) = (self.lo[i], self.delta[i], self.sign[i]);
        let (a, b) = (f64::from(-dy * s), f64::from(dx * s));
        [a, b, -a * f64::from(lx) - b * f64::from(ly)]
    }

    #[inline(always)]
    fn inside_edge_at(&self, i: usize, x: f32, y: f32) -> bool {
        inside_edge(self.raw(i, x, y) * self.sign[i], self.owns[i])
    }
}

impl LinearEdges for Triangle2D {
    /// The three signed edge values at pixel point `(x, y)`.
    #[inline(always)]
    fn edge_values(&self, x: f32, y: f32) -> [f32; 3] {
        [
            self.raw(0, x, y) * self.sign[0],
            self.raw(1, x, y) * self.sign[1],
            self.raw(2, x, y) * self.sign[2],
        ]
    }

    #[inline(always)]
    fn owns(&self) -> [bool; 3] {
        self.owns
    }

    /// Perspective-correct depth: `1/w = Σ λ_i / w_i`, `λ_i = E_i / ΣE` (paper
    /// §3.1); orthographic: `w = Σ λ_i w_i`. Clamped to the vertices' range.
    #[inline(always)]
    fn depth(&self, e: [f32; 3], _x: f32, _y: f32) -> Option<f32> {
        let sum = e[0] + e[1] + e[2];
        let q = e[0] * self.q[0] + e[1] * self.q[1] + e[2] * self.q[2];
        let w = if self.affine { q / sum } else { sum / q };
        // max/min rather than clamp: never panics, equal for ordered bounds.
        (w > 0.0 && w < f32::INFINITY).then(|| w.max(self.w_range[0]).min(self.w_range[1]))
    }

    fn edge_error(&self) -> [f32; 3] {
        self.error
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edge::lanes_test::{across_agree, lanes_agree};

    /// The 8-lane methods give exactly the scalar coverage and depth on the
    /// portable lanes and on AVX2: random projected triangles, half of them
    /// with vertices on sample centres (edges and vertices through samples,
    /// where the tie rule decides), perspective and orthographic depth.
    #[test]
    fn eight_lanes_round_like_the_scalar_path() {
        #[cfg(target_arch = "x86_64")]
        assert!(
            crate::simd::cpu_has_avx2(),
            "this test checks the AVX2 kernels, and this CPU has no AVX2"
        );
        let mut rng = fastrand::Rng::with_seed(5);
        let mut compared = 0;
        for n in 0..3000u32 {
            let on_centres = n % 2 == 0;
            let mut vertex = || {
                let (x, y) = (rng.f32() * 84.0 - 10.0, rng.f32() * 68.0 - 10.0);
                let (x, y) = if on_centres {
                    (x.floor() + 0.5, y.floor() + 0.5)
                } else {
                    (x, y)
                };
                ScreenVertex {
                    x,
                    y,
                    q: 0.05 + rng.f32() * 2.0,
                }
            };
            let v = [vertex(), vertex(), vertex()];
            let Some(t) = Triangle2D::setup(&v, n % 3 == 0, 64, 48) else {
                continue;
            };
            let active = if n % 4 < 2 { 0xff } else { (n % 255 + 1) as u8 };
            let (count, portable) = lanes_agree::<crate::simd::Portable, _>(&t, active);
            compared += count;
            #[cfg(target_arch = "x86_64")]
            {
                // SAFETY: the CPU has AVX2 (asserted above).
                let (count, avx2) =
                    unsafe { crate::edge::lanes_test::lanes_agree_avx2(&t, active) };
                assert_eq!(portable, avx2, "covers8, triangle {n}");
                compared += count;
            }
        }
        assert!(
            compared > 100_000,
            "only {compared} covered samples compared"
        );
    }

    /// Eight samples each against its own triangle
    /// ([`Coverage::sample_across`]) give each triangle's own decision and
    /// depth, on the portable lanes and on AVX2: random projected
    /// triangles with vertices on sample points (edges and vertices through
    /// samples, where the tie rule decides), perspective and orthographic.
    #[test]
    fn samples_across_triangles_decide_as_each_alone() {
        let mut rng = fastrand::Rng::with_seed(13);
        let mut covered = 0;
        for affine in [false, true] {
            let mut tris = Vec::new();
            while tris.len() < 500 {
                let mut vertex = || ScreenVertex {
                    x: rng.i32(-16..320) as f32 * 0.25,
                    y: rng.i32(-16..240) as f32 * 0.25,
                    q: 0.05 + rng.f32() * 2.0,
                };
                let v = [vertex(), vertex(), vertex()];
                tris.extend(Triangle2D::setup(&v, affine, 64, 48));
            }
            covered += across_agree(&tris, 4000, &mut rng);
        }
        assert!(covered > 2_000, "only {covered} covered samples compared");
    }
}
