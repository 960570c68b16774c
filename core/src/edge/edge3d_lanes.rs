//! [`Triangle3D::setup`] for eight perspective triangles at once (paper §3.2),
//! and the homogeneous setup of Fig. 10 (middle) likewise.
//!
//! The setup is some 350 additions and multiplications per triangle and no
//! data-dependent control flow but three rare branches: vertices so far away
//! that they are scaled, a volume whose f32 sign is uncertain (the exact sign
//! decides), and non-finite values. So eight triangles go through it side by
//! side, one per lane, in exactly the scalar operation order with no fused
//! multiply-add (see [`crate::simd`]): every coefficient equals the scalar
//! setup's bit for bit. A lane that meets one of the three branches is set up
//! again by the scalar setup, which takes it.

use glam::Vec3;

use super::EightTriangles;
use super::edge3d::{BOUND_MARGIN, EPS, HomogeneousVertex, SCALE_ABOVE, Tolerances, Triangle3D};
use super::homogeneous::setup_homogeneous_from;
use crate::camera::View;
use crate::simd::{self, Lanes, Portable};

impl Triangle3D {
    /// The triangles of `t` set up for `view`, each exactly as
    /// [`Triangle3D::setup`] sets it up.
    pub(crate) fn setup_eight(t: &EightTriangles, view: &View) -> [Option<Triangle3D>; 8] {
        setup_eight_with(t.corners, t.present, view, planar_lanes)
    }

    /// [`Triangle3D::setup_eight`] of triangles whose corners are in lanes
    /// already (per vertex, per axis), for the lanes of `present`, each
    /// lane's setup given to `put`; `corners(l)` gives lane `l`'s corners to
    /// the scalar setup where the lanes cannot decide.
    #[inline(always)]
    pub(crate) fn setup_lanes<L: Lanes>(
        c: &[[L; 3]; 3],
        present: u8,
        view: &View,
        corners: impl Fn(usize) -> [Vec3; 3],
        put: impl FnMut(usize, Option<Triangle3D>),
    ) {
        let [c0, c1, c2] = [V::of(c[0]), V::of(c[1]), V::of(c[2])];
        let s = planar_of(c0, c1, c2, view);
        assembled::<L>(present, &s, |l| Triangle3D::setup(&corners(l), view), put);
    }

    /// The triangles of `t` set up for homogeneous 2D rasterization from
    /// their transformed vertices (`points`, indexed by `t.vertices`), each
    /// exactly as [`setup_homogeneous_from`] sets it up.
    pub(crate) fn setup_homogeneous_eight(
        t: &EightTriangles,
        points: &[HomogeneousVertex],
        view: &View,
    ) -> [Option<Triangle3D>; 8] {
        homogeneous_eight_with(t, points, view, homogeneous_lanes)
    }
}

/// [`Triangle3D::setup_homogeneous_eight`] with the lanes computed by `kernel`.
#[inline(always)]
fn homogeneous_eight_with(
    t: &EightTriangles,
    points: &[HomogeneousVertex],
    view: &View,
    kernel: fn(&Corners, &[[f32; 8]; 3], &View) -> LaneSetups,
) -> [Option<Triangle3D>; 8] {
    let vertices = |l: usize| t.vertices[l].map(|v| points[v as usize]);
    if view.is_orthographic() {
        return t.each(|l| setup_homogeneous_from(vertices(l), view));
    }
    // Absent lanes stay at zero: degenerate, undecided.
    let (mut h, mut w): (Corners, [[f32; 8]; 3]) = Default::default();
    for l in 0..8 {
        if t.present >> l & 1 == 1 {
            for (v, vertex) in vertices(l).iter().enumerate() {
                (h[v][0][l], h[v][1][l], h[v][2][l]) = (vertex.h.x, vertex.h.y, vertex.h.z);
                w[v][l] = vertex.w;
            }
        }
    }
    let s = kernel(&h, &w, view);
    let mut out = [None; 8];
    let scalar = |l| setup_homogeneous_from(vertices(l), view);
    assembled::<Portable>(t.present, &s, scalar, |l, t| out[l] = t);
    out
}

/// Vertex, axis, lane.
type Corners = [[[f32; 8]; 3]; 3];

/// [`setup_eight`] with the lanes computed by `kernel`.
#[inline(always)]
fn setup_eight_with(
    p: [&[Vec3; 3]; 8],
    present: u8,
    view: &View,
    kernel: fn(&Corners, &View) -> LaneSetups,
) -> [Option<Triangle3D>; 8] {
    // Off-screen triangles come in runs (the mesh's order is spatial):
    // eight at once with no box skip the kernel.
    if present == 0 {
        return [None; 8];
    }
    // Absent lanes stay at zero: degenerate, undecided.
    let mut corners: Corners = [[[0.0; 8]; 3]; 3];
    for l in 0..8 {
        if present >> l & 1 == 1 {
            for (v, corner) in corners.iter_mut().enumerate() {
                let q = p[l][v];
                (corner[0][l], corner[1][l], corner[2][l]) = (q.x, q.y, q.z);
            }
        }
    }
    let s = kernel(&corners, view);
    let mut out = [None; 8];
    let scalar = |l| Triangle3D::setup(p[l], view);
    assembled::<Portable>(present, &s, scalar, |l, t| out[l] = t);
    out
}

/// The present lanes' triangles from what the lanes computed, each given
/// to `put` with its lane: a decided lane's values as they are, an
/// undecided one set up by `scalar`. The records are the lanes' sixteen
/// fields turned into each lane's sixteen words by two transposes
/// ([`Triangle3D::from_words`]), where copying them field by field took
/// some sixty instructions a triangle.
#[inline(always)]
fn assembled<L: Lanes>(
    present: u8,
    s: &LaneSetups,
    scalar: impl Fn(usize) -> Option<Triangle3D>,
    mut put: impl FnMut(usize, Option<Triangle3D>),
) {
    // `w_range` lane by lane in the scalar order of operations (min and max
    // of ±0 or NaN keep the scalar record's bits).
    let (mut near, mut far) = ([0.0; 8], [0.0; 8]);
    for l in 0..8 {
        let w = [s.w[0][l], s.w[1][l], s.w[2][l]];
        (near[l], far[l]) = (w[0].min(w[1]).min(w[2]), w[0].max(w[1]).max(w[2]));
    }
    let tolerances = Tolerances::eight(&s.tolerance, s.negated).map(Tolerances::as_word);
    let [e0, e1, e2] = &s.edges;
    let [first, second] = [
        L::transpose([e0[0], e1[0], e2[0], e0[1], e1[1], e2[1], e0[2], e1[2]]),
        L::transpose([
            e2[2], s.nd[0], s.nd[1], s.nd[2], s.volume, near, far, tolerances,
        ]),
    ];
    for l in 0..8 {
        if present >> l & 1 == 0 {
            continue;
        }
        // A call per branch: `put` writes the record where it goes, not a
        // value picked between the two (one the branches met in, built in
        // pieces and read back whole, which the CPU cannot forward).
        if s.decided >> l & 1 == 0 {
            put(l, scalar(l));
        } else {
            let words = [first[l].to_array(), second[l].to_array()];
            put(l, Some(Triangle3D::from_words(words)));
        }
    }
}

/// What eight lanes of a setup computed, lane last.
struct LaneSetups {
    /// Per edge, its `[A, B, C]`.
    edges: [[[f32; 8]; 3]; 3],
    nd: [[f32; 8]; 3],
    /// `|D|`.
    volume: [f32; 8],
    /// Each vertex's view-axis distance.
    w: [[f32; 8]; 3],
    tolerance: [[f32; 8]; 3],
    /// Lanes whose edges were negated (the eye sees the back).
    negated: u8,
    /// Lanes whose values are final: unscaled, certain orientation, finite.
    decided: u8,
}

simd::dispatch! {
    /// [`planar_lanes_on`] on the lanes of this CPU.
    fn planar_lanes<>(corners: &Corners, view: &View) -> LaneSetups => planar_lanes_on
}

/// Three lanes of coordinates: eight points or vectors.
#[derive(Clone, Copy)]
struct V<L> {
    x: L,
    y: L,
    z: L,
}

/// Glam's `Vec3` operations lane by lane, in its operation order.
impl<L: Lanes> V<L> {
    #[inline(always)]
    fn of([x, y, z]: [L; 3]) -> V<L> {
        V { x, y, z }
    }
    #[inline(always)]
    fn splat(v: Vec3) -> V<L> {
        V::of([L::splat(v.x), L::splat(v.y), L::splat(v.z)])
    }
    #[inline(always)]
    fn load(c: &[[f32; 8]; 3]) -> V<L> {
        V {
            x: L::from_array(c[0]),
            y: L::from_array(c[1]),
            z: L::from_array(c[2]),
        }
    }
    #[inline(always)]
    fn add(self, o: V<L>) -> V<L> {
        V {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
    #[inline(always)]
    fn sub(self, o: V<L>) -> V<L> {
        V {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
    #[inline(always)]
    fn scale(self, k: L) -> V<L> {
        V {
            x: self.x * k,
            y: self.y * k,
            z: self.z * k,
        }
    }
    #[inline(always)]
    fn abs(self) -> V<L> {
        V {
            x: abs(self.x),
            y: abs(self.y),
            z: abs(self.z),
        }
    }
    /// `(x·ox + y·oy) + z·oz`.
    #[inline(always)]
    fn dot(self, o: V<L>) -> L {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    #[inline(always)]
    fn dot_with(self, o: Vec3) -> L {
        self.x * L::splat(o.x) + self.y * L::splat(o.y) + self.z * L::splat(o.z)
    }
    #[inline(always)]
    fn cross(self, o: V<L>) -> V<L> {
        V {
            x: self.y * o.z - o.y * self.z,
            y: self.z * o.x - o.z * self.x,
            z: self.x * o.y - o.x * self.y,
        }
    }
    /// `max(max(x, y), z)`, as `Vec3::max_element` (`a > b ? a : b`).
    #[inline(always)]
    fn max_element(self) -> L {
        self.x.max(self.y).max(self.z)
    }
    /// [`super::edge3d::abs_cross`].
    #[inline(always)]
    fn abs_cross(self, o: V<L>) -> V<L> {
        let (a, b) = (self.abs(), o.abs());
        V {
            x: a.y * b.z + a.z * b.y,
            y: a.z * b.x + a.x * b.z,
            z: a.x * b.y + a.y * b.x,
        }
    }
    /// `[n·d0, n·dx, n·dy]` ([`super::edge3d`]'s `along`).
    #[inline(always)]
    fn along(self, view: &View) -> [L; 3] {
        [
            self.dot_with(view.d0),
            self.dot_with(view.dx),
            self.dot_with(view.dy),
        ]
    }
}

/// `|v|` exactly, like `f32::abs` (`max(v, 0 − v)`: `+0` for both zeros).
#[inline(always)]
fn abs<L: Lanes>(v: L) -> L {
    v.max(L::splat(0.0) - v)
}

/// `from_linear`'s tolerance of edge `e` with coefficient error `r`:
/// `BOUND_MARGIN·(r + 3ε·((|A| + x_max·|B|) + y_max·|C|))`.
#[inline(always)]
fn tolerance<L: Lanes>(e: [L; 3], r: L, (x_max, y_max): (f32, f32)) -> L {
    let evaluation = L::splat(3.0 * EPS)
        * (abs(e[0]) + L::splat(x_max) * abs(e[1]) + L::splat(y_max) * abs(e[2]));
    L::splat(BOUND_MARGIN) * (r + evaluation)
}

/// `nan` plus zero times each of `values`: NaN when one is not finite.
#[inline(always)]
fn add_nan_if_not_finite<L: Lanes>(mut nan: L, values: [L; 3]) -> L {
    for v in values {
        nan = nan + v * L::splat(0.0);
    }
    nan
}

#[inline(always)]
fn arrays<L: Lanes>(v: [L; 3]) -> [[f32; 8]; 3] {
    [v[0].to_array(), v[1].to_array(), v[2].to_array()]
}

/// The perspective edge function of edge `(a, b)` oriented by `sign`, and its
/// coefficient error bound (`perspective_edge` of [`super::edge3d`]).
#[inline(always)]
fn edge_lanes<L: Lanes>(a: V<L>, b: V<L>, sign: L, view: &View) -> ([L; 3], L) {
    let directions = &view.directions;
    let (sum, u) = (a.add(b), a.sub(b));
    // `edge_normal`: (−(a + b)·½) × (a − b); negation is a product by −1.
    let n = sum.scale(L::splat(-1.0)).scale(L::splat(0.5)).cross(u);
    let error = L::splat(4.0 * EPS)
        * sum
            .scale(L::splat(0.5))
            .abs_cross(u)
            .dot_with(directions.largest)
        + L::splat(3.0 * EPS) * n.abs().dot_with(directions.reach);
    (n.scale(sign).along(view), error)
}

/// The lanes of [`Triangle3D::setup`], step for step: its perspective
/// branch or its orthographic one.
#[inline(always)]
fn planar_lanes_on<L: Lanes>(corners: &Corners, view: &View) -> LaneSetups {
    let [c0, c1, c2] = [
        V::load(&corners[0]),
        V::load(&corners[1]),
        V::load(&corners[2]),
    ];
    planar_of::<L>(c0, c1, c2, view)
}

/// [`planar_lanes_on`] of corners in lanes: the vertices relative to the
/// eye and their view-axis distances `w` (both branches' first step), then
/// the branch.
#[inline(always)]
fn planar_of<L: Lanes>(c0: V<L>, c1: V<L>, c2: V<L>, view: &View) -> LaneSetups {
    let eye = V::splat(view.eye);
    let c = [c0.sub(eye), c1.sub(eye), c2.sub(eye)];
    // (No closure around a lane operation: it would be compiled without the
    // lanes' instruction set.)
    let w = [
        c[0].dot_with(view.forward),
        c[1].dot_with(view.forward),
        c[2].dot_with(view.forward),
    ];
    match view.is_orthographic() {
        true => orthographic_of(c, w, view),
        false => perspective_of(c, w, view),
    }
}

/// The perspective branch of [`planar_of`], on eye-relative vertices `c`
/// with view-axis distances `w`.
#[inline(always)]
fn perspective_of<L: Lanes>([c0, c1, c2]: [V<L>; 3], w: [L; 3], view: &View) -> LaneSetups {
    // 2. The volume D = N·c0 and its certain signs.
    let o = Orientation::of(c0, c1, c2);
    // 3. The three edges (edge i opposite vertex i) and their errors.
    let extent = view.sample_extent();
    let edges = [
        edge_lanes(c1, c2, o.sign, view),
        edge_lanes(c2, c0, o.sign, view),
        edge_lanes(c0, c1, o.sign, view),
    ];
    let nd = o.normal.scale(o.sign).along(view);
    finished(edges, nd, w, &o, extent)
}

/// The orthographic branch of [`planar_of`]: `Triangle3D::setup_orthographic`
/// (paper §3.3) step for step, on the lanes whose vertices it leaves
/// unscaled (where a scale of 1 changes none of its values); eye-relative
/// vertices `c` with view-axis distances `w`.
#[inline(always)]
fn orthographic_of<L: Lanes>([c0, c1, c2]: [V<L>; 3], w: [L; 3], view: &View) -> LaneSetups {
    let dp = view.forward;
    // 2. The facing N·d_p and its certain signs.
    let (e1, e2) = (c1.sub(c0), c2.sub(c0));
    let normal = e1.cross(e2);
    let facing = normal.dot_with(dp);
    let bound = L::splat(16.0 * EPS) * e1.abs_cross(e2).dot_with(dp.abs());
    let o = Orientation::decided(normal, facing, bound, unscaled(c0, c1, c2));
    // 3. The edges, `d_p × (a − b)` through the midpoint, and their errors.
    let extent = view.sample_extent();
    let o_abs = view.origin_reach;
    let edges = [
        parallel_edge(c1, c2, o.sign, o_abs, view),
        parallel_edge(c2, c0, o.sign, o_abs, view),
        parallel_edge(c0, c1, o.sign, o_abs, view),
    ];
    let volume = toward(normal.scale(o.sign), c0, view);
    finished(edges, volume, w, &o, extent)
}

/// `k·(q − o(x, y))` as a linear function of the image point:
/// `[k·(q − o0), −k·ox, −k·oy]`.
#[inline(always)]
fn toward<L: Lanes>(k: V<L>, q: V<L>, view: &View) -> [L; 3] {
    let minus = L::splat(-1.0);
    [
        k.dot(q.sub(V::splat(view.o0))),
        k.dot_with(view.ox) * minus,
        k.dot_with(view.oy) * minus,
    ]
}

/// The orthographic edge function of edge `(a, b)`, `(d_p × (a − b))·(m − o)`
/// through the midpoint `m`, oriented by `sign`, and its coefficient error
/// bound: 8ε of `|d_p| ⊗ |a − b|` along `|m| + o_abs`.
#[inline(always)]
fn parallel_edge<L: Lanes>(a: V<L>, b: V<L>, sign: L, o_abs: Vec3, view: &View) -> ([L; 3], L) {
    let dp = V::splat(view.forward);
    let (u, m) = (a.sub(b), a.add(b).scale(L::splat(0.5)));
    let error = L::splat(8.0 * EPS) * dp.abs_cross(u).dot(m.abs().add(V::splat(o_abs)));
    (toward(dp.cross(u).scale(sign), m, view), error)
}

/// The lanes whose vertices `scaled` leaves as they are (no coordinate
/// beyond [`SCALE_ABOVE`]); the others are the scalar setup's.
#[inline(always)]
fn unscaled<L: Lanes>(v0: V<L>, v1: V<L>, v2: V<L>) -> u8 {
    let largest = (v0.abs().max_element())
        .max(v1.abs().max_element())
        .max(v2.abs().max_element());
    largest.le(L::splat(SCALE_ABOVE))
}

simd::dispatch! {
    /// [`homogeneous_lanes_on`] on the lanes of this CPU.
    fn homogeneous_lanes<>(h: &Corners, w: &[[f32; 8]; 3], view: &View) -> LaneSetups => homogeneous_lanes_on
}

/// The lanes of [`setup_homogeneous_from`]'s perspective branch, step for
/// step, on vertices `h` in homogeneous pixel coordinates with view-axis
/// distances `w`.
#[inline(always)]
fn homogeneous_lanes_on<L: Lanes>(h: &Corners, w: &[[f32; 8]; 3], view: &View) -> LaneSetups {
    let (h0, h1, h2) = (V::<L>::load(&h[0]), V::load(&h[1]), V::load(&h[2]));
    // 1. The determinant det[h0, h1, h2] = N·h0 and its certain signs.
    let o = Orientation::of(h0, h1, h2);
    // 2. The rows of the adjugate (edge i opposite vertex i) and their errors.
    let extent = view.sample_extent();
    let edges = [
        row_lanes(h1, h2, o.sign, extent),
        row_lanes(h2, h0, o.sign, extent),
        row_lanes(h0, h1, o.sign, extent),
    ];
    let nd = linear(o.normal, o.sign);
    let w = [
        L::from_array(w[0]),
        L::from_array(w[1]),
        L::from_array(w[2]),
    ];
    finished(edges, nd, w, &o, extent)
}

/// What both setups compute alike from the three (unscaled) vertices: the
/// normal `N = (v1 − v0) × (v2 − v0)`, the determinant `N·v0` and its sign
/// where its f32 error bound makes it certain.
struct Orientation<L> {
    normal: V<L>,
    /// `|N·v0|`.
    volume: L,
    /// `+1` or `−1`.
    sign: L,
    positive: u8,
    /// Lanes the lanes decide: unscaled vertices and a certain sign (the
    /// others are the scalar setup's).
    certain: u8,
}

impl<L: Lanes> Orientation<L> {
    #[inline(always)]
    fn of(v0: V<L>, v1: V<L>, v2: V<L>) -> Orientation<L> {
        let (e1, e2) = (v1.sub(v0), v2.sub(v0));
        let normal = e1.cross(e2);
        let d = normal.dot(v0);
        let bound = L::splat(16.0 * EPS) * e1.abs_cross(e2).dot(v0.abs());
        Orientation::decided(normal, d, bound, unscaled(v0, v1, v2))
    }

    /// The orientation by the sign of `d` where `bound` (its f32 error)
    /// makes it certain, in the lanes of `unscaled` (`orientation` of
    /// [`super::edge3d`]); `volume` is `|d|`.
    #[inline(always)]
    fn decided(normal: V<L>, d: L, bound: L, unscaled: u8) -> Orientation<L> {
        let positive = d.gt(bound);
        let negative = d.lt(L::splat(0.0) - bound);
        Orientation {
            normal,
            volume: abs(d),
            sign: signs(positive),
            positive,
            certain: unscaled & (positive | negative),
        }
    }
}

/// The lane setups from the three edges with their coefficient errors, the
/// depth's denominator `nd`, the vertices' `w` and the orientation: the
/// tolerances, and the lanes decided where every value is finite (the
/// scalar setup says `None` to the others).
#[inline(always)]
fn finished<L: Lanes>(
    edges: [([L; 3], L); 3],
    nd: [L; 3],
    w: [L; 3],
    o: &Orientation<L>,
    extent: (f32, f32),
) -> LaneSetups {
    let [(edge0, r0), (edge1, r1), (edge2, r2)] = edges;
    let tolerances = [
        tolerance(edge0, r0, extent),
        tolerance(edge1, r1, extent),
        tolerance(edge2, r2, extent),
    ];
    let mut nan = o.volume * L::splat(0.0);
    for values in [edge0, edge1, edge2, nd, tolerances, w] {
        nan = add_nan_if_not_finite(nan, values);
    }
    let finite = nan.eq(L::splat(0.0));
    LaneSetups {
        edges: [arrays(edge0), arrays(edge1), arrays(edge2)],
        nd: arrays(nd),
        volume: o.volume.to_array(),
        w: arrays(w),
        tolerance: arrays(tolerances),
        negated: !o.positive,
        decided: o.certain & finite,
    }
}

/// The homogeneous edge function of edge `(a, b)`, the adjugate's row
/// `((a + b)·½) × (b − a)` oriented by `sign`, and its coefficient error
/// bound: 6ε of `|m| ⊗ |u|` at the image's far corner.
#[inline(always)]
fn row_lanes<L: Lanes>(a: V<L>, b: V<L>, sign: L, (x_max, y_max): (f32, f32)) -> ([L; 3], L) {
    let (m, u) = (a.add(b).scale(L::splat(0.5)), b.sub(a));
    let t = m.abs_cross(u);
    let error = L::splat(6.0 * EPS) * (t.z + L::splat(x_max) * t.x + L::splat(y_max) * t.y);
    (linear(m.cross(u), sign), error)
}

/// `[r.z, r.x, r.y]` times `sign`: a row as a linear function of the pixel.
#[inline(always)]
fn linear<L: Lanes>(r: V<L>, sign: L) -> [L; 3] {
    [r.z * sign, r.x * sign, r.y * sign]
}

/// `+1` in the lanes of `positive`, `−1` in the others.
#[inline(always)]
fn signs<L: Lanes>(positive: u8) -> L {
    let mut signs = [-1.0; 8];
    for (l, s) in signs.iter_mut().enumerate() {
        if positive >> l & 1 == 1 {
            *s = 1.0;
        }
    }
    L::from_array(signs)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::{Camera, Viewport};

    fn views() -> Vec<View> {
        let camera = |eye: Vec3, target: Vec3| Camera {
            name: "t".into(),
            eye,
            target,
            up: Vec3::Y,
            viewport: Viewport::Perspective { fov_y_deg: 60.0 },
            near: Some(0.05),
        };
        let far = Vec3::new(3.0e5, 1.0e5, -2.0e5);
        let near = camera(Vec3::new(0.3, -0.2, 4.0), Vec3::new(0.0, 0.1, 0.0));
        let far = camera(far, far + Vec3::new(0.1, 0.2, 1.0));
        let parallel = |c: &Camera, height| Camera {
            viewport: Viewport::Orthographic { height },
            ..c.clone()
        };
        [parallel(&near, 3.0), parallel(&far, 40.0), near, far]
            .iter()
            .map(|c| View::new(c, 64, 48, 0.01).unwrap())
            .collect()
    }

    /// Triangles of every kind the setup branches on: ordinary, tiny, huge,
    /// beyond scaling, edge-on (the eye, or the view axis, in their plane),
    /// degenerate, and neighbours across a shared edge.
    fn triangles(view: &View, rng: &mut fastrand::Rng) -> Vec<[Vec3; 3]> {
        let mut out = Vec::new();
        let mut unit = || Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, rng.f32() - 0.5);
        for k in 0..4000 {
            let size = [1e-4, 0.01, 1.0, 100.0, 1e12][k % 5];
            let centre = view.eye + view.forward * (0.5 + 10.0 * unit().x.abs()) + unit() * 4.0;
            let (a, b, c) = (
                centre + unit() * size,
                centre + unit() * size,
                centre + unit() * size,
            );
            out.extend([
                [a, b, c],
                match view.is_orthographic() {
                    true => [a, b, a + view.forward * size],
                    false => [a, b, view.eye + (a - view.eye) * 2.0],
                },
                [a, a, c],
                [b, a, c + (b - a) * 0.5],
            ]);
        }
        out
    }

    /// Debug prints every f32 exactly, the sign of zero included.
    fn same(a: &Option<Triangle3D>, b: &Option<Triangle3D>) -> bool {
        format!("{a:?}") == format!("{b:?}")
    }

    /// Every lane of `kernel`'s eight-at-once setup equals the scalar setup,
    /// on all lanes or some.
    fn lanes_set_up_as_the_scalar_setup(kernel: fn(&Corners, &View) -> LaneSetups) {
        let mut rng = fastrand::Rng::with_seed(11);
        let mut per_view = Vec::new();
        for view in views() {
            let mut in_lanes = 0;
            let tris = triangles(&view, &mut rng);
            for (k, chunk) in tris.chunks(8).enumerate() {
                let present = if k % 3 == 0 { 0b1011_0110 } else { 0xff };
                let p: [&[Vec3; 3]; 8] = std::array::from_fn(|l| &chunk[l % chunk.len()]);
                let lanes = setup_eight_with(p, present, &view, kernel);
                for l in 0..8 {
                    let scalar = (present >> l & 1 == 1)
                        .then(|| Triangle3D::setup(p[l], &view))
                        .flatten();
                    assert!(
                        same(&lanes[l], &scalar),
                        "{:?}: lanes {:?}, scalar {scalar:?}",
                        p[l],
                        lanes[l]
                    );
                }
                let s = kernel(
                    &{
                        let mut corners: Corners = [[[0.0; 8]; 3]; 3];
                        for l in 0..8 {
                            for v in 0..3 {
                                let q = p[l][v];
                                (corners[v][0][l], corners[v][1][l], corners[v][2][l]) =
                                    (q.x, q.y, q.z);
                            }
                        }
                        corners
                    },
                    &view,
                );
                in_lanes += s.decided.count_ones();
            }
            per_view.push(in_lanes);
        }
        // Half the cases are edge-on or degenerate and a fifth of the rest
        // are scaled (the scalar fallback's); most others take the lanes,
        // in every view (orthographic ones first).
        assert_eq!(per_view.len(), 4);
        assert!(
            per_view.iter().all(|&n| n > 3_000),
            "{per_view:?} set up in lanes"
        );
    }

    /// Every lane of `kernel`'s eight-at-once homogeneous setup equals the
    /// scalar one, on all lanes or some, with triangles through the eye plane
    /// as well (no clipping: the signs handle them).
    fn homogeneous_lanes_set_up_as_the_scalar_setup(
        kernel: fn(&Corners, &[[f32; 8]; 3], &View) -> LaneSetups,
    ) {
        let mut rng = fastrand::Rng::with_seed(12);
        let (mut checked, mut set_up) = (0, 0);
        for view in views() {
            let mut tris = triangles(&view, &mut rng);
            let behind: Vec<[Vec3; 3]> = (tris.iter())
                .map(|&[a, b, c]| [a, b, view.eye - (c - view.eye)])
                .collect();
            tris.extend(behind);
            let points: Vec<HomogeneousVertex> = (tris.iter().flatten())
                .map(|&p| HomogeneousVertex::of(p, &view))
                .collect();
            for (k, chunk) in tris.chunks(8).enumerate() {
                let lane = |l: usize| 8 * k + l % chunk.len();
                let t = EightTriangles {
                    corners: std::array::from_fn(|l| &tris[lane(l)]),
                    vertices: std::array::from_fn(|l| [0, 1, 2].map(|v| (3 * lane(l) + v) as u32)),
                    present: if k % 3 == 0 { 0b1011_0110 } else { 0xff },
                };
                let lanes = homogeneous_eight_with(&t, &points, &view, kernel);
                for (l, lane) in lanes.iter().enumerate() {
                    let vertices = t.vertices[l].map(|v| points[v as usize]);
                    let scalar = (t.present >> l & 1 == 1)
                        .then(|| setup_homogeneous_from(vertices, &view))
                        .flatten();
                    assert!(
                        same(lane, &scalar),
                        "{:?}: lanes {lane:?}, scalar {scalar:?}",
                        t.corners[l],
                    );
                    checked += 1;
                    set_up += usize::from(scalar.is_some());
                }
            }
        }
        assert_eq!(checked, 4 * 2 * 16_000);
        assert!(set_up > 16_000, "{set_up} set up");
    }

    /// The AVX2 tests check the AVX2 kernels: the dispatched kernel takes
    /// them where the CPU has AVX2, and on x86-64 it must.
    fn require_avx2() {
        #[cfg(target_arch = "x86_64")]
        assert!(
            simd::cpu_has_avx2(),
            "this test checks the AVX2 kernel, and this CPU has no AVX2"
        );
    }

    #[test]
    fn portable_homogeneous_lanes_set_up_as_the_scalar_setup() {
        homogeneous_lanes_set_up_as_the_scalar_setup(homogeneous_lanes_on::<simd::Portable>);
    }

    #[test]
    fn avx2_homogeneous_lanes_set_up_as_the_scalar_setup() {
        require_avx2();
        homogeneous_lanes_set_up_as_the_scalar_setup(homogeneous_lanes);
    }

    #[test]
    fn portable_lanes_set_up_as_the_scalar_setup() {
        lanes_set_up_as_the_scalar_setup(planar_lanes_on::<simd::Portable>);
    }

    #[test]
    fn avx2_lanes_set_up_as_the_scalar_setup() {
        require_avx2();
        // `planar_lanes` takes AVX2 where the CPU has it.
        lanes_set_up_as_the_scalar_setup(planar_lanes);
    }
}
