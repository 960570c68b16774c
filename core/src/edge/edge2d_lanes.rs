//! [`Triangle2D::setup`] for eight projected triangles at once (paper §3.1).
//!
//! The setup's arithmetic — canonical endpoints, the orientation, each
//! vertex against its opposite edge, the error bounds — has no
//! data-dependent control flow once its inputs are finite, so eight
//! triangles go through it side by side, one per lane, in exactly the scalar
//! operation order with no fused multiply-add (see [`crate::simd`]): every
//! value equals the scalar setup's bit for bit. What is cheap per triangle
//! and has f32 `min`/`max` semantics (the vertices' `w` and their range, the
//! bounds, the tie ownership) is assembled lane by lane from those values as
//! the scalar setup computes it; a lane with a non-finite coordinate is set
//! up by the scalar setup itself.

use super::edge2d::{ScreenVertex, Triangle2D, w_range};
use crate::simd::{self, Lanes, abs, finite};

/// Eight triangles' vertices, coordinate by coordinate: `[x, y, q]`, then
/// vertex, then lane (the lanes' layout: no transposition after).
pub(crate) type EightVertices = [[[f32; 8]; 3]; 3];

/// Lane `l`'s vertices.
#[inline(always)]
pub(crate) fn vertices_of(v: &EightVertices, l: usize) -> [ScreenVertex; 3] {
    std::array::from_fn(|k| ScreenVertex {
        x: v[0][k][l],
        y: v[1][k][l],
        q: v[2][k][l],
    })
}

/// Puts `vertices` in lane `l` of `v`.
#[cfg(test)]
fn set_lane(v: &mut EightVertices, l: usize, vertices: [ScreenVertex; 3]) {
    for (k, s) in vertices.iter().enumerate() {
        (v[0][k][l], v[1][k][l], v[2][k][l]) = (s.x, s.y, s.q);
    }
}

impl Triangle2D {
    /// Sets up the triangles of the lanes of `present` into `out` (lane `l`
    /// into `out[l]`), each exactly as [`Triangle2D::setup`] sets it up;
    /// the other lanes of `out` are left as they are. (In place: a set-up
    /// triangle is written once, not moved.)
    #[inline]
    pub(crate) fn setup_eight(
        v: &EightVertices,
        present: u8,
        affine: bool,
        [width, height]: [u32; 2],
        out: &mut [Option<Triangle2D>; 8],
    ) {
        setup_eight_with(v, present, affine, [width, height], edge_lanes, out);
    }
}

/// [`Triangle2D::setup_eight`] with the lanes computed by `kernel`.
#[inline(always)]
fn setup_eight_with(
    v: &EightVertices,
    present: u8,
    affine: bool,
    [width, height]: [u32; 2],
    kernel: fn(&EightVertices, [u32; 2]) -> LaneEdges,
    out: &mut [Option<Triangle2D>; 8],
) {
    if present == 0 {
        return;
    }
    let s = kernel(v, [width, height]);
    for (l, out) in out.iter_mut().enumerate() {
        if present >> l & 1 == 0 {
            continue;
        }
        let v = vertices_of(v, l);
        if s.finite >> l & 1 == 0 {
            *out = Triangle2D::setup(&v, affine, width, height);
            continue;
        }
        // The scalar setup's three rejections, whichever it meets first.
        let w_range = w_range(&v, affine);
        if !(w_range[0].is_finite() && w_range[1].is_finite()) || s.kept >> l & 1 == 0 {
            *out = None;
            continue;
        }
        let lo = [0, 1, 2].map(|i| [s.lo[i][0][l], s.lo[i][1][l]]);
        let delta = [0, 1, 2].map(|i| [s.delta[i][0][l], s.delta[i][1][l]]);
        let sign = [0, 1, 2].map(|i| s.sign[i][l]);
        *out = Some(Triangle2D::from_parts(
            &v,
            affine,
            w_range,
            (lo, delta, sign),
            [0, 1, 2].map(|i| s.error[i][l]),
        ));
    }
}

/// What eight lanes of the setup computed, lane last.
struct LaneEdges {
    /// Per edge: its canonical start and `hi − lo`, per axis.
    lo: [[[f32; 8]; 2]; 3],
    delta: [[[f32; 8]; 2]; 3],
    /// Per edge: its sign for the triangle (canonical order × orientation).
    sign: [[f32; 8]; 3],
    /// Per edge: the bound on an evaluation's rounding error.
    error: [[f32; 8]; 3],
    /// Lanes whose orientation is non-zero and finite and whose every vertex
    /// is strictly inside its opposite edge.
    kept: u8,
    /// Lanes whose every coordinate is finite (the others: the scalar setup).
    finite: u8,
}

simd::dispatch! {
    /// [`edge_lanes_on`] on the lanes of this CPU.
    fn edge_lanes<>(v: &EightVertices, size: [u32; 2]) -> LaneEdges => edge_lanes_on
}

/// The lanes of [`Triangle2D::setup`]'s edge functions, step for step.
/// (No closures in lane code: only `#[inline(always)]` functions are sure to
/// be compiled for the caller's lanes.)
#[inline(always)]
fn edge_lanes_on<L: Lanes>(v: &EightVertices, [width, height]: [u32; 2]) -> LaneEdges {
    let (one, zero) = (L::splat(1.0), L::splat(0.0));
    let (mut x, mut y, mut all_finite) = ([zero; 3], [zero; 3], u8::MAX);
    for k in 0..3 {
        (x[k], y[k]) = (L::from_array(v[0][k]), L::from_array(v[1][k]));
        all_finite &= finite(x[k]) & finite(y[k]) & finite(L::from_array(v[2][k]));
    }
    // 1. Canonical endpoints per edge (lexicographic on (x, y); the lanes
    // compared are finite, where that is `a.x < b.x ∨ (a.x = b.x ∧ a.y ≤ b.y)`).
    let mut lo = [[zero; 2]; 3];
    let mut delta = [[zero; 2]; 3];
    let mut sign = [one; 3];
    for i in 0..3 {
        let (a, b) = ((i + 1) % 3, (i + 2) % 3);
        let in_order = x[a].lt(x[b]) | (x[a].eq(x[b]) & y[a].le(y[b]));
        let (lx, ly) = (
            L::select(in_order, x[a], x[b]),
            L::select(in_order, y[a], y[b]),
        );
        let (hx, hy) = (
            L::select(in_order, x[b], x[a]),
            L::select(in_order, y[b], y[a]),
        );
        lo[i] = [lx, ly];
        delta[i] = [hx - lx, hy - ly];
        sign[i] = L::select(in_order, one, L::splat(-1.0));
    }
    // 2. The orientation from edge 0 at its opposite vertex; every vertex
    // strictly inside its opposite edge.
    let orientation = raw_lanes(lo[0], delta[0], x[0], y[0]) * sign[0];
    let mut kept = !orientation.eq(zero) & finite(orientation);
    let orient = L::select(orientation.gt(zero), one, L::splat(-1.0));
    let mut error = [zero; 3];
    let (w, h) = (L::splat(width as f32), L::splat(height as f32));
    for i in 0..3 {
        sign[i] = sign[i] * orient;
        kept &= (raw_lanes(lo[i], delta[i], x[i], y[i]) * sign[i]).gt(zero);
        let ([lx, ly], [dx, dy]) = (lo[i], delta[i]);
        let span = abs(dx) * (h + abs(ly)) + abs(dy) * (w + abs(lx));
        error[i] = span * L::splat(1.0 / (1 << 20) as f32);
    }
    let mut out = LaneEdges {
        lo: [[[0.0; 8]; 2]; 3],
        delta: [[[0.0; 8]; 2]; 3],
        sign: [[0.0; 8]; 3],
        error: [[0.0; 8]; 3],
        kept,
        finite: all_finite,
    };
    for i in 0..3 {
        for a in 0..2 {
            out.lo[i][a] = lo[i][a].to_array();
            out.delta[i][a] = delta[i][a].to_array();
        }
        out.sign[i] = sign[i].to_array();
        out.error[i] = error[i].to_array();
    }
    out
}

/// The canonical (unsigned) edge function `Δx·(y − ly) − Δy·(x − lx)` in lanes.
#[inline(always)]
fn raw_lanes<L: Lanes>([lx, ly]: [L; 2], [dx, dy]: [L; 2], x: L, y: L) -> L {
    dx * (y - ly) - dy * (x - lx)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Eight lanes of `triangles` (lane `l` its triangle `l`).
    fn lanes_of(triangles: &[[ScreenVertex; 3]; 8]) -> EightVertices {
        let mut v = [[[0.0; 8]; 3]; 3];
        for (l, &t) in triangles.iter().enumerate() {
            set_lane(&mut v, l, t);
            let bits = |t: [ScreenVertex; 3]| t.map(|s| [s.x, s.y, s.q].map(f32::to_bits));
            assert_eq!(bits(vertices_of(&v, l)), bits(t));
        }
        v
    }

    /// A triangle every setup keeps.
    fn unit_triangle() -> [ScreenVertex; 3] {
        let at = |x, y| ScreenVertex { x, y, q: 1.0 };
        [at(1.0, 1.0), at(9.0, 1.0), at(1.0, 9.0)]
    }

    /// Every lane of `kernel`'s eight-at-once setup equals the scalar setup
    /// (every field, bit for bit, and the same rejections): random triangles
    /// on and off the image, half with vertices on sample centres (ties in
    /// the canonical order), shared coordinates, slivers, both
    /// orientations, zero and non-finite `q`, NaN and infinite coordinates,
    /// perspective and orthographic.
    fn lanes_set_up_as_the_scalar_setup(kernel: fn(&EightVertices, [u32; 2]) -> LaneEdges) {
        let mut rng = fastrand::Rng::with_seed(23);
        let (mut checked, mut set_up, mut rejected) = (0, 0, 0);
        for n in 0..20_000u32 {
            let special = |rng: &mut fastrand::Rng, v: f32| match rng.u32(0..200) {
                0 => f32::NAN,
                1 => f32::INFINITY,
                2 => -0.0,
                3 => 0.0,
                4 => 1e30,
                _ => v,
            };
            let vertex = |rng: &mut fastrand::Rng| {
                let (x, y) = (rng.f32() * 300.0 - 50.0, rng.f32() * 200.0 - 50.0);
                let (x, y) = match n % 3 {
                    0 => (x.floor() + 0.5, y.floor() + 0.5),
                    1 => (x.floor(), (y * 4.0).floor() / 4.0),
                    _ => (x, y),
                };
                let q = 0.01 + rng.f32() * 3.0;
                ScreenVertex {
                    x: special(rng, x),
                    y: special(rng, y),
                    q: special(rng, q),
                }
            };
            let mut triangles: [[ScreenVertex; 3]; 8] =
                std::array::from_fn(|_| [vertex(&mut rng), vertex(&mut rng), vertex(&mut rng)]);
            // Slivers and repeated vertices: the canonical order's ties.
            let (a, b) = (rng.usize(0..8), rng.usize(0..3));
            triangles[a][b] = triangles[a][(b + 1) % 3];
            let c = rng.usize(0..8);
            triangles[c][2].x = triangles[c][0].x;
            let present = rng.u8(..);
            let affine = n % 5 == 0;
            let (width, height) = (200, 150);
            // A lane outside `present` keeps what it held.
            let held = Triangle2D::setup(&unit_triangle(), false, width, height);
            assert!(held.is_some());
            let mut lanes = [held; 8];
            let v = lanes_of(&triangles);
            setup_eight_with(&v, present, affine, [width, height], kernel, &mut lanes);
            for (l, (lane, triangle)) in lanes.iter().zip(&triangles).enumerate() {
                let scalar = match present >> l & 1 {
                    1 => Triangle2D::setup(triangle, affine, width, height),
                    _ => held,
                };
                assert_eq!(
                    lane.map(|t| t.bits()),
                    scalar.map(|t| t.bits()),
                    "triangle {n}, lane {l}: {triangle:?}"
                );
                checked += 1;
                match (present >> l & 1, scalar) {
                    (1, Some(_)) => set_up += 1,
                    (1, None) => rejected += 1,
                    _ => {}
                }
            }
        }
        assert_eq!(checked, 8 * 20_000);
        assert!(
            set_up > 20_000 && rejected > 5_000,
            "{set_up} set up, {rejected} rejected"
        );
    }

    #[test]
    fn portable_lanes_set_up_as_the_scalar_setup() {
        lanes_set_up_as_the_scalar_setup(edge_lanes_on::<simd::Portable>);
    }

    #[test]
    fn avx2_lanes_set_up_as_the_scalar_setup() {
        #[cfg(target_arch = "x86_64")]
        assert!(
            simd::cpu_has_avx2(),
            "this test checks the AVX2 kernel, and this CPU has no AVX2"
        );
        // `edge_lanes` takes AVX2 where the CPU has it.
        lanes_set_up_as_the_scalar_setup(edge_lanes);
    }
}
