//! 3D edge functions (paper §3.2–3.4).
//!
//! For eye `e` and an edge `(a, b)` the edge normal is built from the edge midpoint,
//! `n = (e − (a+b)/2) × (a − b)` (§3.4 "Numerics"), with every vertex taken
//! relative to the eye first: the two triangles that share an edge get bitwise
//! negated normals in f32, so they split every sample on it. With a sample
//! direction `d(x, y) = d0 + x·dx + y·dy` the edge function is
//! `V(x, y) = n·d = A + x·B + y·C` with `A = n·d0`, `B = n·dx`, `C = n·dy`.
//!
//! Orthographic views (§3.3) cast parallel rays `o(x, y) + t·d_p`; the edge
//! normal is `n = d_p × (a − b)` and the edge function `V = n·(m − o(x, y))`
//! with `m` the edge midpoint — the same triple product `[o − m, a − b, d]` as
//! the perspective one with the eye replaced by the ray origin, again linear.
//!
//! **Exact decisions.** Shared edges alone do not make a mesh watertight: at a
//! vertex that lies on a sample's ray every edge through it should be exactly
//! zero, and rounding makes the f32 values small numbers of arbitrary sign, so
//! a sample there could land in two triangles of a fan or in none. So every
//! edge carries a certified bound on how far its f32 value can be from the
//! exact one (`tolerance`); beyond it the f32 sign is the exact sign, and within
//! it the sign is computed exactly ([`super::exact`]) from the same f32 inputs,
//! an exact zero going to the §3.4 tie rule on exact derivatives. Every sample
//! is then decided exactly — consistently across the whole mesh — while almost
//! all of them take the f32 path: the band left to the exact sign is about
//! 2·10⁻³ pixel wide at 1920×1080 (median over the dragon's and Sponza's
//! edges seen whole), most of it the f32 evaluation over image coordinates
//! in the thousands, which no bound can remove.

use std::num::NonZeroU32;

use glam::{DVec3, Vec3};

use super::exact::{self, Expansion};
use super::{BlockTest, Coverage, RowLanes};
use crate::camera::View;
use crate::simd::Lanes;

/// Unit roundoff of f32.
pub(crate) const EPS: f32 = f32::EPSILON * 0.5;

/// A triangle set up for 3D rasterization against one view: per edge `i`
/// (opposite vertex `i`) the coefficients of `E_i(x, y) = A_i + x·B_i + y·C_i`,
/// normalised so the triangle's inside is `E_i > 0`, and its depth.
///
/// Depth is `w = |D| / ΣE_i` (paper Fig. 10), but `ΣE_i` is evaluated as its own
/// linear function `N·d(x, y)` (`N` the geometric normal; equal to `ΣV_i` in real
/// arithmetic). Summing the three edge values cancels catastrophically for
/// triangles that are small against their distance (each `E_i` is a difference of
/// terms ~10⁵× larger): on 1M-triangle scenes that gave `w` errors of 0.1%.
///
/// **One cache line.** What every triangle of a view shares — `near`, the
/// sample generator, and the scene's vertices that the exact decisions
/// recompute — is not stored here but in [`Shared3D`], and a triangle is read
/// as `Coverage` bound to it ([`Triangle3D::bind`]). Of `N·d` and the
/// volume `|D|` one is constant on the image — `|D|` in perspective, `N·d_p`
/// in parallel projection — and is kept as one number; each edge's error
/// tolerance is kept rounded up to two significant bits (a wider tolerance
/// only sends more samples to the exact decision, which gives the same
/// answer), the three in one word with the orientation (`Tolerances`).
/// So a record is 64 bytes, aligned to a line, where it was 112: a ray or a
/// tile reads one line per triangle, and setup writes 40% less.
///
/// Every algorithm of the 3D family and the ray caster decide coverage and depth
/// through `Coverage::sample` on these coefficients, in one fixed operation
/// order with no fused multiply-add, so they agree bit for bit.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct Triangle3D {
    pub(super) a: [f32; 3],
    pub(super) b: [f32; 3],
    pub(super) c: [f32; 3],
    /// The part of depth that varies on the image: `N·d(x, y)` in perspective,
    /// `|D|(x, y) = N·(p0 − o(x, y))` in parallel projection (sign-normalised
    /// like the edges).
    pub(super) varying: Linear,
    /// The constant part: `|D|` in perspective, `N·d_p` in parallel projection.
    pub(super) constant: f32,
    /// View-axis distance of the nearest and farthest vertex: every sample's `w`
    /// is clamped into this range (exact in real arithmetic, and it gives early-z
    /// and occlusion culling a bound no rounding can undercut).
    pub(super) w_range: [f32; 2],
    /// Per edge: a certified bound on how far [`Triangle3D::edge_values`] can be
    /// from the exact edge function anywhere on the image, within which the
    /// exact sign decides; and whether the edges were negated to make the
    /// inside positive.
    pub(super) tolerance: Tolerances,
}

const _: () = assert!(size_of::<Triangle3D>() == 64);
const _: () = assert!(size_of::<Option<Triangle3D>>() == 64);

/// A triangle's three edge tolerances and its orientation in one word: each
/// tolerance rounded up to a float of the f32 exponent and two mantissa bits
/// (at most 25% wider, 10 bits), bit 30 set when the edges were negated, and
/// bit 31 always set, so that `Option<Triangle3D>` takes no more room.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Tolerances(NonZeroU32);

/// The f32 bits a kept tolerance drops: all but the exponent and the first
/// two mantissa bits.
const DROPPED: u32 = 21;

/// The bit of [`Tolerances`] that is always set.
const ALWAYS_SET: NonZeroU32 = NonZeroU32::new(1 << 31).unwrap();

impl Tolerances {
    /// Tolerances `t` (finite, `≥ 0`) of edges negated or not. Each is kept
    /// as the least 10-bit float at or above it (zero stays zero; beyond the
    /// largest such finite float it is infinite).
    #[inline(always)]
    pub(super) fn new(t: [f32; 3], negated: bool) -> Tolerances {
        Tolerances(ALWAYS_SET | Tolerances::word(t, negated))
    }

    /// [`Tolerances::new`] of eight lanes (tolerances per edge and lane,
    /// bit per lane negated): one loop over plain words, which compiles to
    /// lanes.
    #[inline(always)]
    pub(super) fn eight(t: &[[f32; 8]; 3], negated: u8) -> [Tolerances; 8] {
        let mut words = [0u32; 8];
        for (l, word) in words.iter_mut().enumerate() {
            let lane = [t[0][l], t[1][l], t[2][l]];
            *word = Tolerances::word(lane, negated >> l & 1 == 1);
        }
        words.map(|word| Tolerances(ALWAYS_SET | word))
    }

    /// The word of [`Tolerances::new`] but for the bit always set.
    #[inline(always)]
    fn word(t: [f32; 3], negated: bool) -> u32 {
        let kept = |t: f32| {
            let bits = t.to_bits() & 0x7fff_ffff;
            let up = (bits >> DROPPED) + u32::from(bits & ((1 << DROPPED) - 1) != 0);
            up.min(f32::INFINITY.to_bits() >> DROPPED)
        };
        kept(t[0]) | kept(t[1]) << 10 | kept(t[2]) << 20 | u32::from(negated) << 30
    }

    /// The word's bits as a float (a record's sixteenth word).
    #[inline(always)]
    pub(super) fn as_word(self) -> f32 {
        f32::from_bits(self.0.get())
    }

    /// Edge `k`'s tolerance.
    #[inline(always)]
    pub(crate) fn get(self, k: usize) -> f32 {
        f32::from_bits((self.0.get() >> (10 * k) & 0x3ff) << DROPPED)
    }

    /// Were the edges negated to make the inside positive?
    #[inline(always)]
    pub(crate) fn negated(self) -> bool {
        self.0.get() >> 30 & 1 == 1
    }
}

/// What every [`Triangle3D`] of one view shares: the view (`near`, the
/// sample generator), which setup made them, and the triangles' vertices —
/// by id in a mesh, or by item in a list of corners (the BVH's slot-ordered
/// ones for a setup in slot order) — from which the rare exact decisions
/// recompute the edges.
#[derive(Clone, Copy, Debug)]
pub struct Shared3D<'a> {
    view: &'a View,
    near: f32,
    /// Parallel projection: the depth's constant part is `N·d_p`, not `|D|`.
    parallel: bool,
    form: ExactForm,
    corners: Corners<'a>,
}

/// Where a view's triangles' vertices are.
#[derive(Clone, Copy, Debug)]
enum Corners<'a> {
    /// A mesh: vertex positions and each triangle's three indices, by id.
    Indexed {
        positions: &'a [Vec3],
        triangles: &'a [[u32; 3]],
    },
    /// Each item's three corners.
    Listed(&'a [[Vec3; 3]]),
}

impl<'a> Shared3D<'a> {
    /// The triangles of a mesh (`positions`, `triangles` by id) set up for
    /// `view` by the 3D setup ([`Triangle3D::setup`]) or the homogeneous one.
    pub(crate) fn of_mesh(
        view: &'a View,
        homogeneous: bool,
        positions: &'a [Vec3],
        triangles: &'a [[u32; 3]],
    ) -> Shared3D<'a> {
        Self::new(
            view,
            homogeneous,
            Corners::Indexed {
                positions,
                triangles,
            },
        )
    }

    /// Triangles with these corners, by item, set up for `view` by
    /// [`Triangle3D::setup`] or (`homogeneous`) the homogeneous setup.
    pub fn of_corners(view: &'a View, homogeneous: bool, corners: &'a [[Vec3; 3]]) -> Shared3D<'a> {
        Self::new(view, homogeneous, Corners::Listed(corners))
    }

    fn new(view: &'a View, homogeneous: bool, corners: Corners<'a>) -> Shared3D<'a> {
        let parallel = view.is_orthographic();
        let form = match (homogeneous, parallel) {
            (true, _) => ExactForm::Homogeneous,
            (false, true) => ExactForm::Orthographic,
            (false, false) => ExactForm::Perspective,
        };
        Shared3D {
            view,
            near: view.near,
            parallel,
            form,
            corners,
        }
    }

    /// The corners of triangle `id`, item `item`, as its setup read them.
    fn corners(&self, item: u32, id: u32) -> [Vec3; 3] {
        match self.corners {
            Corners::Indexed {
                positions,
                triangles,
            } => triangles[id as usize].map(|v| positions[v as usize]),
            Corners::Listed(corners) => corners[item as usize],
        }
    }
}

/// A [`Triangle3D`] read with what its view shares, as every coverage loop
/// sees it ([`Coverage`]): the record, the shared data, and the triangle's
/// item and id (by which the exact decisions find its corners), three words
/// in registers.
#[derive(Clone, Copy, Debug)]
pub struct Bound3D<'a> {
    t: &'a Triangle3D,
    shared: &'a Shared3D<'a>,
    item: u32,
    id: u32,
}

/// Which exact edge functions a [`Triangle3D`] stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ExactForm {
    /// `det[a − e, b − e, d(x, y)]` (perspective, §3.2).
    Perspective,
    /// `det[a − o(x, y), b − o(x, y), d_p]` (orthographic, §3.3).
    Orthographic,
    /// `det[h_a, h_b, (x, y, 1)]` on homogeneous pixel coordinates (Olano–Greer).
    Homogeneous,
}

/// What the exact decisions need: the vertices (as the setup read them), the
/// view, and the orientation.
#[derive(Clone, Copy, Debug, PartialEq)]
struct ExactEdges<'a> {
    form: ExactForm,
    vertices: [Vec3; 3],
    view: &'a View,
    /// The edges were negated to make the inside positive.
    negated: bool,
}

/// The depth's two linear functions as a setup computed them: of `N·d` and
/// the volume one is constant on the image.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Depth {
    /// `N·d(x, y)` varies, the volume `|D|` is constant (perspective).
    Perspective { facing: Linear, volume: f32 },
    /// `N·d_p` is constant, the volume `N·(p0 − o(x, y))` varies.
    Parallel { facing: f32, volume: Linear },
}

/// The midpoint edge normal `(e − (a+b)/2) × (a − b)` of §3.4 with `a` and `b`
/// relative to the eye (`e = 0`). Swapping `a` and `b` negates the result
/// exactly: `a + b` is commutative and `a − b = −(b − a)`.
#[inline]
pub fn edge_normal(a: Vec3, b: Vec3) -> Vec3 {
    (-(a + b) * 0.5).cross(a - b)
}

/// `|a| ⊗ |b|`: per component the sum of the magnitudes of the two products a
/// cross-product component subtracts (what bounds its rounding).
#[inline]
pub(crate) fn abs_cross(a: Vec3, b: Vec3) -> Vec3 {
    let (a, b) = (a.abs(), b.abs());
    Vec3::new(
        a.y * b.z + a.z * b.y,
        a.z * b.x + a.x * b.z,
        a.x * b.y + a.y * b.x,
    )
}

/// Vertices beyond this many units make setup products overflow f32.
pub(super) const SCALE_ABOVE: f32 = (1u64 << 32) as f32;

/// `c` scaled by a power of two `2⁻ᵏ` so that its largest coordinate is about 1
/// when it exceeds [`SCALE_ABOVE`] (unscaled otherwise), and `2ᵏ`. Exact: every
/// product and sum of the setup scales with it, rounding alike, so the shared
/// edges of neighbours stay exactly negated whatever their scales.
#[inline(always)]
pub(crate) fn scaled(c: [Vec3; 3]) -> ([Vec3; 3], f32) {
    // Unrolled, not an iterator fold: this runs once per triangle setup and a
    // call here passed the vertices through memory.
    let largest = |v: Vec3| v.abs().max_element();
    let max = largest(c[0]).max(largest(c[1])).max(largest(c[2]));
    if max > SCALE_ABOVE && max.is_finite() {
        scaled_down(c, max)
    } else {
        (c, 1.0)
    }
}

/// [`scaled`] for vertices beyond [`SCALE_ABOVE`] (rare: far from the eye).
#[cold]
fn scaled_down(c: [Vec3; 3], max: f32) -> ([Vec3; 3], f32) {
    let k = max.log2().ceil() as i32;
    let down = 2f32.powi(-k);
    (c.map(|v| v * down), 2f32.powi(k))
}

/// Whether every value is finite, without a branch per value: a value is
/// finite when its magnitude's bits are below infinity's, so the largest
/// magnitude decides (an integer maximum, unrolled over the fixed count: a
/// running float sum of `v · 0` was a chain of dependent adds).
#[inline(always)]
fn all_finite<const N: usize>(values: &[[f32; 3]; N]) -> bool {
    let largest =
        (values.as_flattened().iter()).fold(0, |m: u32, v| m.max(v.to_bits() & 0x7fff_ffff));
    largest < f32::INFINITY.to_bits()
}

/// Linear functions of the image point, `k[0] + x·k[1] + y·k[2]`.
pub type Linear = [f32; 3];

/// The factor every error bound is taken with: the bounds are first-order
/// (multiples of ε of magnitudes), each leading constant at or above its
/// derivation's, and this covers what they leave out — the `O(ε²)` terms
/// and the rounding of the bound's own f32 evaluation, each a few ε of it.
pub(crate) const BOUND_MARGIN: f32 = 1.0 + 1.0 / 1024.0;

/// A vector's components along the sample generator: `[n·d0, n·dx, n·dy]`.
#[inline(always)]
fn along(n: Vec3, view: &View) -> Linear {
    [n.dot(view.d0), n.dot(view.dx), n.dot(view.dy)]
}

/// The perspective edge function of edge `(a, b)` (eye-relative vertices),
/// oriented by `sign`, and a bound on how far its coefficients' f32 values
/// put it from the exact edge function anywhere on the image.
///
/// The normal `ñ = fl(m × u)` (`m = −(a + b)/2`, `u = a − b`, each within ε
/// of exact; a product and a difference per component) is within
/// `4ε·(|m| ⊗ |u|)` of `n`, and moves the value at `(x, y)` by
/// `(ñ − n)·d(x, y)`: at most that along the largest `|d|`. Each coefficient
/// `ñ·d0`, `ñ·dx`, `ñ·dy` (three products, two sums) rounds by at most 3ε of
/// `|ñ|` along its direction, and they add up to 3ε of `|ñ|` along
/// `reach` ([`View`]'s direction bounds).
#[inline(always)]
fn perspective_edge(a: Vec3, b: Vec3, sign: f32, view: &View) -> (Linear, f32) {
    let directions = &view.directions;
    let n = edge_normal(a, b);
    let error = 4.0 * EPS * abs_cross((a + b) * 0.5, a - b).dot(directions.largest)
        + 3.0 * EPS * n.abs().dot(directions.reach);
    (along(n * sign, view), error)
}

impl Triangle3D {
    /// Paper §3.2 setup: three edge normals, their derivatives along the sample
    /// generator, and the triangle's volume as seen from the eye. `None` when the
    /// triangle is seen exactly edge-on (`D = 0`) or the values are not finite.
    #[inline]
    pub fn setup(p: &[Vec3; 3], view: &View) -> Option<Triangle3D> {
        // 1. Vertices relative to the eye (exact for geometry near the camera,
        //    however far both are from the world origin).
        let c = p.map(|v| v - view.eye);
        if view.is_orthographic() {
            return Self::setup_orthographic(&c, view);
        }
        let w = c.map(|v| v.dot(view.forward));
        // 2. Vertices 10¹² away would overflow D's products (~|c|³): scaled by a
        //    power of two, which is exact and changes no sign.
        let (c, scale) = scaled(c);
        // 3. Total volume D = N · (p0 − e) with the geometric normal N; its sign is
        //    the side the eye sees, and it orients the edge functions. Near zero
        //    the exact sign decides.
        let (e1, e2) = (c[1] - c[0], c[2] - c[0]);
        let normal = e1.cross(e2);
        let d = normal.dot(c[0]);
        let d_bound = 16.0 * EPS * abs_cross(e1, e2).dot(c[0].abs());
        let positive = orientation(d, d_bound, || {
            let v = c.map(|v| v.as_dvec3().to_array());
            exact::dot(&exact::cross(v[1], v[2]), v[0]).signum()
        })?;
        let sign = if positive { 1.0 } else { -1.0 };
        // 4. Edge i is opposite vertex i: (p[i+1], p[i+2]), with the bound of
        //    its coefficients' f32 error over the image.
        //    (Three calls, not an array `map`: closures there were compiled as calls.)
        let (e0, r0) = perspective_edge(c[1], c[2], sign, view);
        let (e1, r1) = perspective_edge(c[2], c[0], sign, view);
        let (e2, r2) = perspective_edge(c[0], c[1], sign, view);
        // w = |D|/(N·d) is homogeneous of degree 1 in the vertices: undo the scale.
        let depth = Depth::Perspective {
            facing: along(normal * sign, view),
            volume: d.abs() * scale,
        };
        Triangle3D::from_linear([e0, e1, e2], depth, w, view, [r0, r1, r2], !positive)
    }

    /// Paper §3.3: orthographic setup, `n_i = d_p × (p_{i+1} − p_{i+2})` and
    /// `V_i = n_i · (m_i − o(x, y))`; the depth `w = N·(p0 − o(x, y)) / (N·d_p)`.
    /// `c` are the vertices relative to the eye. `None` when the triangle is
    /// seen edge-on (`N·d_p = 0`).
    fn setup_orthographic(c: &[Vec3; 3], view: &View) -> Option<Triangle3D> {
        let dp = view.forward;
        let w = c.map(|v| v.dot(dp));
        // Far vertices and the ray origins scaled together by a power of two
        // (see [`scaled`]): the edges are of degree 2 in them, the volume 3.
        let (c, scale) = scaled(*c);
        let down = 1.0 / scale;
        let (o0, ox, oy) = (view.o0 * down, view.ox * down, view.oy * down);
        let (e1, e2) = (c[1] - c[0], c[2] - c[0]);
        let normal = e1.cross(e2);
        let facing = normal.dot(dp);
        let facing_bound = 16.0 * EPS * abs_cross(e1, e2).dot(dp.abs());
        let positive = orientation(facing, facing_bound, || {
            let v = c.map(|v| v.as_dvec3().to_array());
            let n = exact::cross_exact(
                &exact::difference(v[1], v[0]),
                &exact::difference(v[2], v[0]),
            );
            exact::dot(&n, dp.as_dvec3().to_array()).signum()
        })?;
        let sign = if positive { 1.0 } else { -1.0 };
        // k·(q − o(x, y)) = k·(q − o0) − x·k·ox − y·k·oy, all relative to the eye.
        let toward = |k: Vec3, q: Vec3| [k.dot(q - o0), -k.dot(ox), -k.dot(oy)];
        // The origins' reach at the vertices' scale (a power of two: exact).
        let o_abs = view.origin_reach * down;
        let mut coefficient_error = [0.0; 3];
        let edges = [0, 1, 2].map(|i| {
            let (a, b) = (c[(i + 1) % 3], c[(i + 2) % 3]);
            let q = (a + b) * 0.5;
            coefficient_error[i] = 8.0 * EPS * abs_cross(dp, a - b).dot(q.abs() + o_abs);
            toward(dp.cross(a - b) * sign, q)
        });
        let depth = Depth::Parallel {
            facing: facing.abs(),
            volume: toward(normal * sign, c[0]).map(|v| v * scale),
        };
        Triangle3D::from_linear(edges, depth, w, view, coefficient_error, !positive)
    }

    /// Assembles a triangle from its three sign-normalised edge functions, the
    /// depth as a ratio of linear functions `w = volume / (N·d)`, its
    /// vertices' `w`, the bound on each edge's coefficient error over the
    /// image, and whether the edges were negated; adds the evaluation's
    /// rounding to the tolerance. `None` on non-finite values.
    #[inline(always)]
    pub(crate) fn from_linear(
        edges: [Linear; 3],
        depth: Depth,
        vertex_w: [f32; 3],
        view: &View,
        coefficient_error: [f32; 3],
        negated: bool,
    ) -> Option<Triangle3D> {
        let (x_max, y_max) = view.sample_extent();
        // (A + x·B) + y·C rounds four times; no term passes through more
        // than three of them, so the value is within 3ε of the terms'
        // magnitudes. Both bounds are first-order: taken with BOUND_MARGIN.
        let tolerance: [f32; 3] = std::array::from_fn(|i| {
            let e = edges[i];
            let evaluation = 3.0 * EPS * (e[0].abs() + x_max * e[1].abs() + y_max * e[2].abs());
            BOUND_MARGIN * (coefficient_error[i] + evaluation)
        });
        let (varying, constant) = match depth {
            Depth::Perspective { facing, volume } => (facing, volume),
            Depth::Parallel { facing, volume } => (volume, facing),
        };
        let w_range = [
            vertex_w[0].min(vertex_w[1]).min(vertex_w[2]),
            vertex_w[0].max(vertex_w[1]).max(vertex_w[2]),
        ];
        let finite = all_finite(&[edges[0], edges[1], edges[2], varying, tolerance])
            && constant.is_finite()
            && w_range.iter().all(|w| w.is_finite());
        finite.then(|| Triangle3D {
            a: edges.map(|e| e[0]),
            b: edges.map(|e| e[1]),
            c: edges.map(|e| e[2]),
            varying,
            constant,
            w_range,
            tolerance: Tolerances::new(tolerance, negated),
        })
    }

    /// This triangle, triangle `id` and item `item` of the setup for the
    /// view `shared` describes, read as `Coverage`.
    #[inline(always)]
    pub fn bind<'s>(&'s self, shared: &'s Shared3D<'s>, item: u32, id: u32) -> Bound3D<'s> {
        Bound3D {
            t: self,
            shared,
            item,
            id,
        }
    }

    /// The three edge values at image point `(x, y)`: `(A + x·B) + y·C`.
    #[inline(always)]
    pub fn edge_values(&self, x: f32, y: f32) -> [f32; 3] {
        [
            self.a[0] + x * self.b[0] + y * self.c[0],
            self.a[1] + x * self.b[1] + y * self.c[1],
            self.a[2] + x * self.b[2] + y * self.c[2],
        ]
    }

    /// The triangle as the GPU kernels read it (`Tri` in `gpu/compute.wgsl`,
    /// linear layout): rows 0..2 `(A_i | nd0)`, `(B_i | nd1)`, `(C_i | nd2)`,
    /// row 3 `(volume, w_min)`, row 4 `(w_max, 0, 0, 0)`, row 5 the
    /// tolerances; and the flags (tie ownership per edge by the f32
    /// derivatives, which the kernels use only where an edge has no
    /// tolerance). `parallel`: set up for a parallel projection.
    #[cfg(feature = "gpu")]
    pub(crate) fn gpu_rows(&self, parallel: bool) -> ([[f32; 4]; 6], u32) {
        let mut flags = 0;
        for i in 0..3 {
            let (b, c) = (self.b[i], self.c[i]);
            flags |= u32::from(b > 0.0 || (b == 0.0 && c > 0.0)) << i;
        }
        let [t0, t1, t2] = [0, 1, 2].map(|k| self.tolerance.get(k));
        let constant = [self.constant, 0.0, 0.0];
        let (nd, volume) = if parallel {
            (constant, self.varying)
        } else {
            (self.varying, constant)
        };
        let rows = [
            [self.a[0], self.a[1], self.a[2], nd[0]],
            [self.b[0], self.b[1], self.b[2], nd[1]],
            [self.c[0], self.c[1], self.c[2], nd[2]],
            [volume[0], volume[1], volume[2], self.w_range[0]],
            [self.w_range[1], 0.0, 0.0, 0.0],
            [t0, t1, t2, 0.0],
        ];
        (rows, flags)
    }
}

impl Bound3D<'_> {
    /// Is the sample at `(x, y)` with f32 edge values `e` inside all three
    /// edges? The f32 sign where it is certain, the exact one where it is not.
    #[inline(always)]
    fn inside(&self, e: [f32; 3], x: f32, y: f32) -> bool {
        (0..3).all(|i| {
            let tolerance = self.t.tolerance.get(i);
            if e[i] > tolerance {
                true
            } else if e[i] < -tolerance {
                false
            } else {
                self.exact().inside(i, x, y)
            }
        })
    }

    /// The exact edges this triangle stands for.
    #[cold]
    fn exact(&self) -> ExactEdges<'_> {
        ExactEdges {
            form: self.shared.form,
            vertices: self.shared.corners(self.item, self.id),
            view: self.shared.view,
            negated: self.t.tolerance.negated(),
        }
    }

    /// `N·d` and the volume at `(x, y)`: `k[0] + x·k[1] + y·k[2]` for the
    /// varying one, the constant as it is (what that sum gives when
    /// `k[1] = k[2] = 0`, for every sample: `k[0] + ±0 = k[0]` but for zero,
    /// and a zero `N·d` is rejected, a zero volume is `+0` either way).
    #[inline(always)]
    fn facing_and_volume(&self, x: f32, y: f32) -> (f32, f32) {
        let k = self.t.varying;
        let varying = k[0] + x * k[1] + y * k[2];
        if self.shared.parallel {
            (self.t.constant, varying)
        } else {
            (varying, self.t.constant)
        }
    }

    /// `w = |D| / (N·d)`, clamped to the vertices' range; `None` below `near`.
    #[inline(always)]
    fn depth(&self, x: f32, y: f32) -> Option<f32> {
        let (facing, volume) = self.facing_and_volume(x, y);
        if facing <= 0.0 {
            return None;
        }
        let [w_min, w_max] = self.t.w_range;
        // max/min rather than clamp: never panics, and the 8-lane path rounds alike.
        let w = (volume / facing).max(w_min).min(w_max);
        (w >= self.shared.near).then_some(w)
    }
}

/// The orientation of a triangle from its f32 determinant `d` with error at
/// most `bound`, the exact sign (`exact`) deciding within it; `None` when the
/// exact determinant is zero or `d` is not finite.
#[inline]
pub(crate) fn orientation(d: f32, bound: f32, exact: impl FnOnce() -> i32) -> Option<bool> {
    if !(d.is_finite() && bound.is_finite()) {
        return None;
    }
    if d > bound {
        Some(true)
    } else if d < -bound {
        Some(false)
    } else {
        match exact() {
            0 => None,
            s => Some(s > 0),
        }
    }
}

impl ExactEdges<'_> {
    /// The vertices as the setup saw them: relative to the eye (3D), or in
    /// homogeneous pixel coordinates; exact in f64.
    fn points(&self) -> [[f64; 3]; 3] {
        let view = self.view;
        self.vertices.map(|p| {
            let v = match self.form {
                ExactForm::Homogeneous => homogeneous_point(p, view),
                _ => p - view.eye,
            };
            v.as_dvec3().to_array()
        })
    }

    /// Edge `i`'s exact function at `(x, y)` and its exact derivatives along
    /// `x` and `y`, oriented so the inside is positive.
    fn value(&self, i: usize, x: f32, y: f32, derivatives: bool) -> (Expansion, [Expansion; 2]) {
        let p = self.points();
        let (a, b) = (p[(i + 1) % 3], p[(i + 2) % 3]);
        let v3 = |v: Vec3| v.as_dvec3().to_array();
        let view = self.view;
        let (x, y) = (f64::from(x), f64::from(y));
        let (value, dx, dy) = match self.form {
            ExactForm::Perspective => {
                let n = exact::cross(a, b);
                let d = exact::affine(v3(view.d0), x, v3(view.dx), y, v3(view.dy));
                let deriv = |k: Vec3| {
                    if derivatives {
                        exact::dot(&n, v3(k))
                    } else {
                        Expansion::default()
                    }
                };
                (exact::dot_exact(&n, &d), deriv(view.dx), deriv(view.dy))
            }
            ExactForm::Orthographic => {
                // det[a, b, d_p] + det[o(x, y), a − b, d_p]
                let dp = v3(view.forward);
                let w = exact::cross_exact(&exact::difference(a, b), &exact::vector(dp));
                let o = exact::affine(v3(view.o0), x, v3(view.ox), y, v3(view.oy));
                let value = exact::dot(&exact::cross(a, b), dp).add(&exact::dot_exact(&o, &w));
                let deriv = |k: Vec3| {
                    if derivatives {
                        exact::dot(&w, v3(k))
                    } else {
                        Expansion::default()
                    }
                };
                (value, deriv(view.ox), deriv(view.oy))
            }
            ExactForm::Homogeneous => {
                let n = exact::cross(a, b);
                let value = exact::dot(&n, [x, y, 1.0]);
                (value, n[0].clone(), n[1].clone())
            }
        };
        if self.negated {
            let neg = |e: Expansion| Expansion::default().sub(&e);
            (neg(value), [neg(dx), neg(dy)])
        } else {
            (value, [dx, dy])
        }
    }

    /// Edge `i`'s value at `(x, y)` in f64 from the same inputs, oriented,
    /// with a rigorous bound on its error (products of two f32 are exact in
    /// f64; every other operation rounds by at most ε₆₄ = 2⁻⁵³ of its
    /// operands' magnitudes, bounded here with a factor-2 margin).
    fn value_f64(&self, i: usize, x: f32, y: f32) -> (f64, f64) {
        const EPS64: f64 = f64::EPSILON * 0.5;
        let p = self.points();
        let (a, b) = (DVec3::from(p[(i + 1) % 3]), DVec3::from(p[(i + 2) % 3]));
        let view = self.view;
        let (x, y) = (f64::from(x), f64::from(y));
        let abs_cross = |a: DVec3, b: DVec3| {
            let (a, b) = (a.abs(), b.abs());
            DVec3::new(
                a.y * b.z + a.z * b.y,
                a.z * b.x + a.x * b.z,
                a.x * b.y + a.y * b.x,
            )
        };
        let affine = |o: Vec3, dx: Vec3, dy: Vec3| {
            let (o, dx, dy) = (o.as_dvec3(), dx.as_dvec3(), dy.as_dvec3());
            (
                (o + dx * x) + dy * y,
                o.abs() + (dx * x).abs() + (dy * y).abs(),
            )
        };
        let (value, bound) = match self.form {
            ExactForm::Perspective => {
                let (d, d_abs) = affine(view.d0, view.dx, view.dy);
                (a.cross(b).dot(d), 16.0 * EPS64 * abs_cross(a, b).dot(d_abs))
            }
            ExactForm::Orthographic => {
                // det[a, b, d_p] + det[o(x, y), a − b, d_p]
                let dp = view.forward.as_dvec3();
                let (o, o_abs) = affine(view.o0, view.ox, view.oy);
                let u = a - b;
                let value = a.cross(b).dot(dp) + o.dot(u.cross(dp));
                let bound = abs_cross(a, b).dot(dp.abs()) + abs_cross(u, dp).dot(o_abs);
                (value, 32.0 * EPS64 * bound)
            }
            ExactForm::Homogeneous => {
                let q = DVec3::new(x, y, 1.0);
                (
                    a.cross(b).dot(q),
                    16.0 * EPS64 * abs_cross(a, b).dot(q.abs()),
                )
            }
        };
        (if self.negated { -value } else { value }, bound)
    }

    /// Is `(x, y)` inside edge `i`, exactly: a positive value, or zero and
    /// owning the tie (paper §3.4, on exact derivatives). The f64 value
    /// decides wherever it is certain (all but near-exact zeros), exact
    /// expansion arithmetic elsewhere.
    #[cold]
    fn inside(&self, i: usize, x: f32, y: f32) -> bool {
        let (v, bound) = self.value_f64(i, x, y);
        let certain = v.abs() > bound;
        super::count_precise(!certain);
        if certain {
            return v > 0.0;
        }
        let (value, _) = self.value(i, x, y, false);
        match value.signum() {
            1 => true,
            -1 => false,
            _ => {
                let (_, [dx, dy]) = self.value(i, x, y, true);
                dx.signum() > 0 || (dx.signum() == 0 && dy.signum() > 0)
            }
        }
    }
}

/// The 8-lane forms of the scalar operations (no fused multiply-add, the same
/// operation order, so every lane rounds as [`Coverage::sample`] does), on
/// either instruction set ([`crate::simd`]).
impl Bound3D<'_> {
    /// `k[0] + x·k[1] + y·k[2]` per lane, in [`Triangle3D::edge_values`]'s order.
    #[inline(always)]
    fn linear_lanes<L: Lanes>(k: [f32; 3], x: L, y: L) -> L {
        L::splat(k[0]) + x * L::splat(k[1]) + y * L::splat(k[2])
    }

    /// [`Bound3D::facing_and_volume`] per lane.
    #[inline(always)]
    fn facing_and_volume_lanes<L: Lanes>(&self, x: L, y: L) -> (L, L) {
        let varying = Self::linear_lanes(self.t.varying, x, y);
        let constant = L::splat(self.t.constant);
        if self.shared.parallel {
            (constant, varying)
        } else {
            (varying, constant)
        }
    }

    #[inline(always)]
    fn sample_lanes<L: Lanes>(&self, x: L, y: L, active: u8) -> (u8, [f32; 8]) {
        let (facing, volume) = self.facing_and_volume_lanes(x, y);
        let inside = self.edges_lanes(x, y, active & facing.gt(L::splat(0.0)));
        if inside == 0 {
            return (0, [0.0; 8]);
        }
        self.depth_lanes(facing, volume, inside)
    }

    /// The lanes of `active` whose points are inside all three edges: the f32
    /// signs where they are certain, the exact ones (lane by lane) where they
    /// are not.
    #[inline(always)]
    fn edges_lanes<L: Lanes>(&self, x: L, y: L, active: u8) -> u8 {
        let t = self.t;
        let mut e = [L::splat(0.0); 3];
        for (k, e) in e.iter_mut().enumerate() {
            *e = Self::linear_lanes([t.a[k], t.b[k], t.c[k]], x, y);
        }
        self.inside_lanes(e, self.tolerance_lanes(), active, x, y)
    }

    /// Per edge, its tolerance and the tolerance's negation, in lanes.
    #[inline(always)]
    fn tolerance_lanes<L: Lanes>(&self) -> [[L; 2]; 3] {
        let mut lanes = [[L::splat(0.0); 2]; 3];
        for (k, pair) in lanes.iter_mut().enumerate() {
            let tolerance = self.t.tolerance.get(k);
            *pair = [L::splat(tolerance), L::splat(-tolerance)];
        }
        lanes
    }

    /// [`Bound3D::edges_lanes`] on the edge values `e` at `(x, y)`, with the
    /// edges' [`Bound3D::tolerance_lanes`].
    #[inline(always)]
    fn inside_lanes<L: Lanes>(
        &self,
        e: [L; 3],
        tolerance: [[L; 2]; 3],
        active: u8,
        x: L,
        y: L,
    ) -> u8 {
        let (mut certain_in, mut certain_out) = (active, !active);
        for k in 0..3 {
            certain_in &= e[k].gt(tolerance[k][0]);
            certain_out |= e[k].lt(tolerance[k][1]);
        }
        let undecided = !(certain_in | certain_out);
        if undecided == 0 {
            certain_in
        } else {
            certain_in | self.decide_lanes(undecided, x.to_array(), y.to_array())
        }
    }

    /// The undecided lanes one by one, as [`Coverage::sample`] decides them
    /// (the scalar edge values round exactly as the lanes do).
    #[cold]
    fn decide_lanes(&self, mut undecided: u8, xs: [f32; 8], ys: [f32; 8]) -> u8 {
        let mut inside = 0;
        while undecided != 0 {
            let l = undecided.trailing_zeros() as usize;
            undecided &= undecided - 1;
            if self.inside(self.t.edge_values(xs[l], ys[l]), xs[l], ys[l]) {
                inside |= 1 << l;
            }
        }
        inside
    }

    /// `w` per lane, and `mask` narrowed to the lanes at or beyond `near`.
    #[inline(always)]
    fn depth_lanes<L: Lanes>(&self, facing: L, volume: L, mask: u8) -> (u8, [f32; 8]) {
        depth_in(facing, volume, mask, self.depth_limits())
    }

    /// `w_min`, `w_max` and `near` in lanes.
    #[inline(always)]
    fn depth_limits<L: Lanes>(&self) -> [L; 3] {
        let [w_min, w_max] = self.t.w_range;
        [L::splat(w_min), L::splat(w_max), L::splat(self.shared.near)]
    }
}

/// `w = volume / facing` per lane clamped to `w_min..w_max`, and `mask`
/// narrowed to the lanes at or beyond `near` (`limits`, in that order).
#[inline(always)]
fn depth_in<L: Lanes>(facing: L, volume: L, mask: u8, limits: [L; 3]) -> (u8, [f32; 8]) {
    let [w_min, w_max, near] = limits;
    let w = (volume / facing).max(w_min).min(w_max);
    (mask & w.ge(near), w.to_array())
}

/// A [`Bound3D`] along rows ([`RowLanes`]): its coefficients splatted into
/// lanes once, and per row the `y·C` terms, so that a group's values are
/// `(A + x·B) + y·C` in [`Bound3D::linear_lanes`]'s order with no per-group
/// loads or decoding.
struct Rows3D<'a, L> {
    tri: &'a Bound3D<'a>,
    /// Per edge: `A`, `B`, and `C` splatted; then the row's `y·C`.
    edges: [[L; 3]; 3],
    edge_y: [L; 3],
    tolerance: [[L; 2]; 3],
    /// The varying part of depth: `k0`, `k1`, `k2` splatted; then the
    /// row's `y·k2`.
    varying: [L; 3],
    varying_y: L,
    constant: L,
    limits: [L; 3],
    y: L,
}

impl<L: Lanes> RowLanes<L> for Rows3D<'_, L> {
    #[inline(always)]
    fn set_row(&mut self, y: f32) {
        self.y = L::splat(y);
        for k in 0..3 {
            self.edge_y[k] = self.y * self.edges[k][2];
        }
        self.varying_y = self.y * self.varying[2];
    }

    /// [`Bound3D::sample_lanes`] with the row's terms.
    #[inline(always)]
    fn sample8(&self, _: f32, x: L, active: u8) -> (u8, [f32; 8]) {
        let (facing, volume) = self.facing_and_volume(x);
        let mut e = [L::splat(0.0); 3];
        for (k, e) in e.iter_mut().enumerate() {
            let [a, b, _] = self.edges[k];
            *e = a + x * b + self.edge_y[k];
        }
        let active = active & facing.gt(L::splat(0.0));
        let inside = (self.tri).inside_lanes(e, self.tolerance, active, x, self.y);
        if inside == 0 {
            return (0, [0.0; 8]);
        }
        depth_in(facing, volume, inside, self.limits)
    }

    /// [`Coverage::depth_inside8`] of [`Bound3D`] with the row's terms.
    #[inline(always)]
    fn depth_inside8(&self, x: L) -> (u8, [f32; 8]) {
        let (facing, volume) = self.facing_and_volume(x);
        depth_in(facing, volume, facing.gt(L::splat(0.0)), self.limits)
    }
}

impl<L: Lanes> Rows3D<'_, L> {
    /// [`Bound3D::facing_and_volume_lanes`] with the row's terms.
    #[inline(always)]
    fn facing_and_volume(&self, x: L) -> (L, L) {
        let [k0, k1, _] = self.varying;
        let varying = k0 + x * k1 + self.varying_y;
        if self.tri.shared.parallel {
            (self.constant, varying)
        } else {
            (varying, self.constant)
        }
    }
}

impl Coverage for Bound3D<'_> {
    #[inline(always)]
    fn sample(&self, x: f32, y: f32) -> Option<f32> {
        if self.inside(self.t.edge_values(x, y), x, y) {
            self.depth(x, y)
        } else {
            None
        }
    }

    #[inline(always)]
    fn depth_inside(&self, x: f32, y: f32) -> Option<f32> {
        self.depth(x, y)
    }

    /// Corner values against the tolerance: outside when some edge is below
    /// `−tolerance` at all four (so exactly outside everywhere in the block),
    /// inside when every edge is above three tolerances at all four (so above
    /// one at every sample, where the f32 sign decides) — paper §3.1, "binning".
    fn classify_block(&self, x0: f32, y0: f32, x1: f32, y1: f32) -> BlockTest {
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for (x, y) in [(x0, y0), (x1, y0), (x0, y1), (x1, y1)] {
            let e = self.t.edge_values(x, y);
            for k in 0..3 {
                lo[k] = lo[k].min(e[k]);
                hi[k] = hi[k].max(e[k]);
            }
        }
        let t = [0, 1, 2].map(|k| self.t.tolerance.get(k));
        if (0..3).any(|k| hi[k] < -t[k]) {
            BlockTest::Outside
        } else if (0..3).all(|k| lo[k] > 3.0 * t[k]) {
            BlockTest::Inside
        } else {
            BlockTest::Partial
        }
    }

    #[inline(always)]
    fn sample_points8<L: Lanes>(&self, x: [f32; 8], y: [f32; 8], active: u8) -> (u8, [f32; 8]) {
        self.sample_lanes(L::from_array(x), L::from_array(y), active)
    }

    #[inline(always)]
    fn rows<L: Lanes>(&self) -> impl RowLanes<L> {
        let t = self.t;
        let zero = L::splat(0.0);
        let mut edges = [[zero; 3]; 3];
        for (k, edge) in edges.iter_mut().enumerate() {
            *edge = [L::splat(t.a[k]), L::splat(t.b[k]), L::splat(t.c[k])];
        }
        Rows3D {
            tri: self,
            edges,
            edge_y: [zero; 3],
            tolerance: self.tolerance_lanes(),
            varying: [
                L::splat(t.varying[0]),
                L::splat(t.varying[1]),
                L::splat(t.varying[2]),
            ],
            varying_y: zero,
            constant: L::splat(t.constant),
            limits: self.depth_limits(),
            y: zero,
        }
    }

    /// Edges, facing, and `w ≥ near` as `volume ≥ near·facing`: no division
    /// (and no clamp to the vertices' range).
    #[inline(always)]
    fn covers8<L: Lanes>(&self, x: [f32; 8], y: [f32; 8]) -> u8 {
        let (x, y) = (L::from_array(x), L::from_array(y));
        let (facing, volume) = self.facing_and_volume_lanes(x, y);
        let near = L::splat(self.shared.near);
        let front = facing.gt(L::splat(0.0)) & volume.ge(facing * near);
        self.edges_lanes(x, y, front)
    }

    #[inline(always)]
    fn depth_inside8<L: Lanes>(&self, x: [f32; 8], y: [f32; 8]) -> (u8, [f32; 8]) {
        let (x, y) = (L::from_array(x), L::from_array(y));
        let (facing, volume) = self.facing_and_volume_lanes(x, y);
        self.depth_lanes(facing, volume, facing.gt(L::splat(0.0)))
    }

    fn min_depth(&self) -> f32 {
        self.t.w_range[0].max(self.shared.near)
    }

    const ACROSS: bool = true;

    /// [`Bound3D::sample_lanes`] with each lane's coefficients its own
    /// triangle's ([`Triangle3D::words`], transposed into lanes): the same
    /// operations in the same order per lane, so the same decisions and
    /// depths.
    #[inline(always)]
    fn sample_across<L: Lanes>(
        tris: [&Self; 8],
        x: [f32; 8],
        y: [f32; 8],
        active: u8,
    ) -> (u8, [f32; 8]) {
        let shared = tris[0].shared;
        let [a0, a1, a2, b0, b1, b2, c0, c1] = L::transpose(tris.map(|tri| tri.t.words()[0]));
        let [c2, k0, k1, k2, constant, w_min, w_max, tolerance] =
            L::transpose(tris.map(|tri| tri.t.words()[1]));
        let (xs, ys) = (L::from_array(x), L::from_array(y));
        let varying = k0 + xs * k1 + ys * k2;
        let (facing, volume) = if shared.parallel {
            (constant, varying)
        } else {
            (varying, constant)
        };
        let active = active & facing.gt(L::splat(0.0));
        let (mut certain_in, mut certain_out) = (active, !active);
        for (k, [a, b, c]) in [[a0, b0, c0], [a1, b1, c1], [a2, b2, c2]]
            .into_iter()
            .enumerate()
        {
            let e = a + xs * b + ys * c;
            // Tolerances::get(k) per lane.
            let t = tolerance.bit_field(10 * k as u32, 10, DROPPED);
            certain_in &= e.gt(t);
            certain_out |= e.lt(L::splat(0.0) - t);
        }
        let mut undecided = !(certain_in | certain_out);
        let mut inside = certain_in;
        while undecided != 0 {
            let l = undecided.trailing_zeros() as usize;
            undecided &= undecided - 1;
            let tri = tris[l];
            if tri.inside(tri.t.edge_values(x[l], y[l]), x[l], y[l]) {
                inside |= 1 << l;
            }
        }
        if inside == 0 {
            return (0, [0.0; 8]);
        }
        depth_in(
            facing,
            volume,
            inside,
            [w_min, w_max, L::splat(shared.near)],
        )
    }
}

impl Triangle3D {
    /// The record as sixteen words in field order: `A`, `B`, `C`, the
    /// varying depth, the constant, `w_range`, and the tolerance word's
    /// bits as a float.
    #[inline(always)]
    fn words(&self) -> [[f32; 8]; 2] {
        let (a, b, c, k) = (self.a, self.b, self.c, self.varying);
        let tolerance = self.tolerance.as_word();
        [
            [a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1]],
            [
                c[2],
                k[0],
                k[1],
                k[2],
                self.constant,
                self.w_range[0],
                self.w_range[1],
                tolerance,
            ],
        ]
    }

    /// The record of sixteen words in [`Triangle3D::words`]' order.
    #[inline(always)]
    pub(super) fn from_words([first, second]: [[f32; 8]; 2]) -> Triangle3D {
        let [a0, a1, a2, b0, b1, b2, c0, c1] = first;
        let [c2, k0, k1, k2, constant, w_min, w_max, tolerance] = second;
        Triangle3D {
            a: [a0, a1, a2],
            b: [b0, b1, b2],
            c: [c0, c1, c2],
            varying: [k0, k1, k2],
            constant,
            w_range: [w_min, w_max],
            tolerance: Tolerances(ALWAYS_SET | tolerance.to_bits()),
        }
    }
}

/// A vertex in homogeneous pixel coordinates `(X, Y, W)`, `x = X/W`
/// (orthographic: `W = 1`).
pub(crate) fn homogeneous_point(p: Vec3, view: &View) -> Vec3 {
    HomogeneousVertex::of(p, view).h
}

/// A vertex transformed for the homogeneous setup: its homogeneous pixel
/// coordinates ([`homogeneous_point`]) and its view-axis distance `w`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct HomogeneousVertex {
    pub(super) h: Vec3,
    pub(super) w: f32,
}

impl HomogeneousVertex {
    #[inline]
    pub(crate) fn of(p: Vec3, view: &View) -> HomogeneousVertex {
        let (half_w, half_h) = (view.width as f32 * 0.5, view.height as f32 * 0.5);
        let c = view.to_camera(p);
        let w = if view.is_orthographic() { 1.0 } else { c.z };
        HomogeneousVertex {
            h: Vec3::new(
                (c.x / view.half_x + w) * half_w,
                (w - c.y / view.half_y) * half_h,
                w,
            ),
            w: c.z,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;
    #[cfg(target_arch = "x86_64")]
    use crate::edge::lanes_test::lanes_agree_avx2;
    use crate::edge::lanes_test::{across_agree, lanes_agree};

    /// A tolerance is kept as the least 10-bit float at or above it: never
    /// below it (a narrower bound would trust uncertain f32 signs), at most
    /// a quarter of its leading power of two above it, zero as zero,
    /// subnormals and the largest values too; each edge's apart from the
    /// others' and from the orientation.
    #[test]
    fn tolerances_round_up_to_two_mantissa_bits() {
        let mut rng = fastrand::Rng::with_seed(5);
        let mut cases = vec![
            0.0,
            f32::from_bits(1),
            f32::MIN_POSITIVE,
            1.0,
            1.3,
            3.0e-7,
            3e38,
        ];
        cases.extend((0..10_000).map(|_| f32::from_bits(rng.u32(0..0x7f80_0000))));
        let largest = f32::from_bits(0x3fb << DROPPED);
        for (n, &t) in cases.iter().enumerate() {
            let others = [cases[(n + 1) % cases.len()], cases[(n + 2) % cases.len()]];
            let negated = n % 3 == 0;
            let word = Tolerances::new([others[0], t, others[1]], negated);
            let kept = word.get(1);
            assert!(kept >= t, "{t:e} kept as {kept:e}");
            assert_eq!(kept.to_bits() & ((1 << DROPPED) - 1), 0, "{kept:e}");
            if t > largest {
                assert_eq!(kept, f32::INFINITY, "{t:e}");
            } else if t >= f32::MIN_POSITIVE {
                assert!(kept <= t * 1.25, "{t:e} kept as {kept:e}");
            } else {
                assert!(kept - t <= 2f32.powi(-128), "{t:e} kept as {kept:e}");
            }
            let alone = others.map(|o| Tolerances::new([o; 3], false).get(0));
            assert_eq!([word.get(0), word.get(2)], alone);
            assert_eq!(word.negated(), negated);
        }
        assert_eq!(cases.len(), 10_007);
    }

    /// Every 8-lane method gives exactly the scalar path's coverage and depth
    /// in the lanes it is asked for (and nothing in the others), on the
    /// portable lanes and on AVX2, on random triangles near and through the
    /// eye plane, including samples on edges.
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
        #[cfg(target_arch = "x86_64")]
        assert!(
            crate::simd::cpu_has_avx2(),
            "this test checks the AVX2 kernels, and this CPU has no AVX2"
        );
        let mut compared = 0;
        for n in 0..2000u32 {
            let p = [rand_point(), rand_point(), rand_point()];
            let Some(t) = Triangle3D::setup(&p, &view) else {
                continue;
            };
            let corners = [p];
            let shared = Shared3D::of_corners(&view, false, &corners);
            let t = t.bind(&shared, 0, 0);
            // Every lane, or a different part of them per triangle.
            let active = if n % 2 == 0 {
                0xff
            } else {
                (n / 2 % 255 + 1) as u8
            };
            let (count, portable_covers) = lanes_agree::<crate::simd::Portable, _>(&t, active);
            compared += count;
            #[cfg(target_arch = "x86_64")]
            {
                // SAFETY: the CPU has AVX2 (asserted above).
                let (count, avx2_covers) = unsafe { lanes_agree_avx2(&t, active) };
                assert_eq!(portable_covers, avx2_covers, "covers8, triangle {n}");
                compared += count;
            }
        }
        assert!(
            compared > 20_000,
            "only {compared} covered samples compared"
        );
    }

    /// Eight samples each against its own triangle
    /// ([`Coverage::sample_across`]) give each triangle's own decision and
    /// depth ([`Coverage::sample`]) in the lanes asked for, on the portable
    /// lanes and on AVX2, in perspective and in parallel projection: random
    /// triangles near and through the eye plane, sample points on a quarter
    /// pixel grid (some on edges and vertices, where the exact signs decide).
    #[test]
    fn samples_across_triangles_decide_as_each_alone() {
        let mut rng = fastrand::Rng::with_seed(11);
        // The second looks straight down the z axis, one unit to eight
        // pixels: edges between grid vertices pass through sample points.
        let viewports = [
            (
                Vec3::new(0.3, -0.2, 4.0),
                crate::camera::Viewport::Perspective { fov_y_deg: 60.0 },
            ),
            (
                Vec3::new(0.0, 0.0, 4.0),
                crate::camera::Viewport::Orthographic { height: 6.0 },
            ),
        ];
        let (mut covered, mut views) = (0, 0);
        let precise_before = crate::edge::precise_tests();
        for (eye, viewport) in viewports {
            let camera = Camera {
                name: "t".into(),
                eye,
                target: Vec3::new(0.0, 0.0, -1.0),
                up: Vec3::Y,
                viewport,
                near: Some(0.05),
            };
            let view = View::new(&camera, 64, 48, 0.01).unwrap();
            let mut corners = Vec::new();
            let mut set_up = Vec::new();
            while set_up.len() < 800 {
                // Vertices on a coarse grid, so that edges pass through
                // sample points.
                let mut p = || {
                    Vec3::new(
                        rng.i32(-8..=8) as f32,
                        rng.i32(-6..=6) as f32,
                        rng.i32(-10..=4) as f32,
                    ) * 0.5
                };
                let p = [p(), p(), p()];
                if let Some(t) = Triangle3D::setup(&p, &view) {
                    corners.push(p);
                    set_up.push(t);
                }
            }
            let shared = Shared3D::of_corners(&view, false, &corners);
            let bound: Vec<Bound3D> = (set_up.iter().enumerate())
                .map(|(k, t)| t.bind(&shared, k as u32, k as u32))
                .collect();
            covered += across_agree(&bound, 4000, &mut rng);
            views += 1;
        }
        assert_eq!(views, 2);
        assert!(covered > 2_000, "only {covered} covered samples compared");
        let precise = crate::edge::precise_tests()[0] - precise_before[0];
        assert!(precise > 100, "only {precise} edge tests went past f32");
    }

    /// Every edge's tolerance bounds how far its f32 value is from the
    /// exact edge function of the same inputs anywhere on the image — at
    /// its four corners, where the terms the bound sums are largest, and at
    /// random samples — in perspective (a camera off the axes, so that
    /// every component of the directions counts), in parallel projection
    /// and for the homogeneous setup, on triangles near and far, large and
    /// small. A bound below the error would let an f32 sign decide a sample
    /// whose exact sign differs. And the bound is no looser than it must
    /// be by much: the largest error seen reaches 0.15 of it (0.22 here;
    /// the doubled bound it replaced reached 0.11, and sent over twice the
    /// samples to the exact sign).
    #[test]
    fn tolerances_bound_the_f32_error() {
        let mut rng = fastrand::Rng::with_seed(13);
        let target = Vec3::new(0.2, -0.1, 0.3);
        let camera = |viewport| Camera {
            name: "t".into(),
            eye: Vec3::new(3.1, 2.3, 4.7),
            target,
            up: Vec3::Y,
            viewport,
            near: Some(0.05),
        };
        let views = [
            (
                camera(crate::camera::Viewport::Perspective { fov_y_deg: 60.0 }),
                false,
            ),
            (
                camera(crate::camera::Viewport::Perspective { fov_y_deg: 60.0 }),
                true,
            ),
            (
                camera(crate::camera::Viewport::Orthographic { height: 3.0 }),
                false,
            ),
        ];
        let (mut checked, mut largest) = (0, 0.0f64);
        for (camera, homogeneous) in views {
            let view = View::new(&camera, 1920, 1080, 0.01).unwrap();
            let (x_max, y_max) = view.sample_extent();
            let mut corners = Vec::new();
            let mut set_up = Vec::new();
            while set_up.len() < 600 {
                // Centred near the target or far behind it, edges from a
                // thousandth of the distance to the eye up to its size.
                let distance = [1.0, 30.0, 500.0][set_up.len() % 3];
                let size = distance * 10f32.powf(-3.0 * rng.f32());
                let centre = target + (target - camera.eye) * (distance / 6.0 - 1.0);
                let mut vertex =
                    || centre + Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, rng.f32() - 0.5) * size;
                let p = [vertex(), vertex(), vertex()];
                let t = if homogeneous {
                    let h = p.map(|v| HomogeneousVertex::of(v, &view));
                    crate::edge::homogeneous::setup_homogeneous_from(h, &view)
                } else {
                    Triangle3D::setup(&p, &view)
                };
                if let Some(t) = t {
                    corners.push(p);
                    set_up.push(t);
                }
            }
            let shared = Shared3D::of_corners(&view, homogeneous, &corners);
            for (k, t) in set_up.iter().enumerate() {
                let bound = t.bind(&shared, k as u32, k as u32);
                let exact = bound.exact();
                let mut points = vec![(0.0, 0.0), (x_max, 0.0), (0.0, y_max), (x_max, y_max)];
                points.extend((0..12).map(|_| (rng.f32() * x_max, rng.f32() * y_max)));
                for (x, y) in points {
                    let values = t.edge_values(x, y);
                    for (i, value) in values.iter().enumerate() {
                        let error =
                            (f64::from(*value) - exact.value(i, x, y, false).0.approximate()).abs();
                        let tolerance = f64::from(t.tolerance.get(i));
                        assert!(
                            error <= tolerance,
                            "edge {i} of triangle {k} at ({x}, {y}): f32 error {error:e} beyond its tolerance {tolerance:e}"
                        );
                        largest = largest.max(error / tolerance);
                        checked += 1;
                    }
                }
            }
        }
        assert_eq!(checked, 3 * 600 * 16 * 3);
        assert!(
            largest > 0.15,
            "the largest error seen is only {largest} of its tolerance"
        );
    }
}
