//! Edge functions and the tie rule they share.
//!
//! - [`Triangle3D`]: the Plücker / signed-volume edge functions of paper
//!   §3.2, evaluated per sample with no projection.
//! - [`Triangle2D`]: projected 2D edge functions (paper §3.1).
//! - [`CurvedTriangle`]: 3D edge functions against the per-sample directions of
//!   a non-planar viewport (paper §3.5).
//! - [`Triangle2DFixed`] and [`Triangle3D64`]: the 2D functions on vertices
//!   snapped to 1/256 pixel and evaluated exactly (hardware rules), and the 3D
//!   functions in f64 (`--precision fixed`, `--precision f64`).
//!
//! Both decide a sample that lies exactly on an edge with the same top-left rule
//! ([`owns_tie`]), so every sample of a closed mesh is covered exactly once.

mod curved;
mod edge2d;
mod edge2d_lanes;
pub mod edge2d_fixed;
mod edge3d;
mod edge3d_f64;
mod edge3d_lanes;
mod exact;
mod homogeneous;

pub use curved::CurvedTriangle;
pub use edge2d::{ScreenVertex, Triangle2D};
pub use edge2d_fixed::Triangle2DFixed;
pub(crate) use edge2d_lanes::{EightVertices, vertices_of};
pub(crate) use edge3d::EPS;
pub(crate) use edge3d::HomogeneousVertex;
pub use edge3d::{Bound3D, Shared3D, Triangle3D};
pub use edge3d_f64::Triangle3D64;
// The GPU's exact fallback sets up one triangle at a time; the CPU, eight
// (`Triangle3D::setup_homogeneous_eight`).
#[cfg(feature = "gpu")]
pub(crate) use homogeneous::setup_homogeneous_from;

thread_local! {
    /// This thread's running count of 3D (and homogeneous) edge tests the f32 sign could not
    /// decide: `[evaluated in f64, of those decided exactly]`.
    static PRECISE_TESTS: std::cell::Cell<[u64; 2]> = const { std::cell::Cell::new([0, 0]) };
}

/// Counts one edge test decided past f32 (on the cold path only).
fn count_precise(exactly: bool) {
    PRECISE_TESTS.with(|c| {
        let mut n = c.get();
        n[0] += 1;
        n[1] += u64::from(exactly);
        c.set(n);
    });
}

/// This thread's running count of edge tests decided past f32, `[in f64,
/// of those exactly]`: a tile's share is the difference across its rendering.
pub(crate) fn precise_tests() -> [u64; 2] {
    PRECISE_TESTS.with(std::cell::Cell::get)
}

/// Up to eight triangles to set up together, one per lane: their corners,
/// their mesh vertex indices, and which lanes hold one (bit `l`: lane `l`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct EightTriangles<'a> {
    pub corners: [&'a [glam::Vec3; 3]; 8],
    pub vertices: [[u32; 3]; 8],
    pub present: u8,
}

impl EightTriangles<'_> {
    /// `setup(l)` for each present lane `l`, `None` for the others.
    #[inline]
    pub(crate) fn each<T>(&self, mut setup: impl FnMut(usize) -> Option<T>) -> [Option<T>; 8] {
        std::array::from_fn(|l| {
            if self.present >> l & 1 == 1 {
                setup(l)
            } else {
                None
            }
        })
    }
}

use crate::simd::{Lanes, first_lanes};

/// A set-up triangle as a setup stores it, and how a coverage loop reads
/// it: bound to what every triangle of its view shares and to its id. A
/// [`Triangle3D`] keeps its view's data in a [`Shared3D`] to fit a cache
/// line; the other set-up triangles hold everything they need and are read
/// as they are.
pub(crate) trait Stored: Send + Sync {
    /// What every triangle of one view shares.
    type Shared<'s>: Sync;
    /// The triangle as the coverage loops read it.
    type Bound<'b>: Coverage + Copy
    where
        Self: 'b;
    /// Triangle `id`, item `item` of the setup that made it for the view
    /// `shared` describes, as [`Coverage`] (`shared` says which of the two
    /// finds its vertices).
    fn bind<'b, 's: 'b>(
        &'b self,
        shared: &'b Self::Shared<'s>,
        item: u32,
        id: u32,
    ) -> Self::Bound<'b>;
}

impl Stored for Triangle3D {
    type Shared<'s> = Shared3D<'s>;
    type Bound<'b> = Bound3D<'b>;
    #[inline(always)]
    fn bind<'b, 's: 'b>(&'b self, shared: &'b Shared3D<'s>, item: u32, id: u32) -> Bound3D<'b> {
        Triangle3D::bind(self, shared, item, id)
    }
}

/// [`Stored`] for set-up triangles that are their own coverage.
macro_rules! stored_as_they_are {
    ($($t:ty),*) => {$(
        impl Stored for $t {
            type Shared<'s> = ();
            type Bound<'b> = &'b $t;
            #[inline(always)]
            fn bind<'b, 's: 'b>(&'b self, _: &'b (), _: u32, _: u32) -> &'b $t {
                self
            }
        }
    )*};
}

stored_as_they_are!(Triangle2D, Triangle2DFixed, Triangle3D64, CurvedTriangle);

/// The tie rule of paper §3.4 (Direct3D's top-left rule written with derivatives):
/// a sample on an edge (`E = 0`) belongs to the triangle whose edge function grows
/// to the right (`∂E/∂x > 0`), or, for a horizontal edge, downwards
/// (`∂E/∂x = 0 ∧ ∂E/∂y > 0`). `E` is normalised so the triangle's inside is `E > 0`.
/// A vertex is decided by its two edges, each by this rule.
#[inline]
pub fn owns_tie(de_dx: f32, de_dy: f32) -> bool {
    de_dx > 0.0 || (de_dx == 0.0 && de_dy > 0.0)
}

/// Whether a sample with edge value `e` is inside that edge: strictly inside, or on
/// it and owning the tie.
#[inline(always)]
pub fn inside_edge(e: f32, owns: bool) -> bool {
    e > 0.0 || (e == 0.0 && owns)
}

/// Where a block of samples stands against one triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlockTest {
    /// No sample of the block is covered.
    Outside,
    /// Every sample of the block is inside all three edges.
    Inside,
    /// Undecided: refine.
    Partial,
}

/// A triangle set up for one view, as every coverage loop sees it. `sample` is
/// the single decision all algorithms of a family share: edge values in one fixed
/// operation order, the tie rule, then depth.
pub trait Coverage {
    /// Whether [`Coverage::sample_run`] is this type's own walk along the
    /// row (curved edges' incremental evaluation) rather than groups of
    /// [`Coverage::sample8`], which callers may then take group by group.
    const OWN_SAMPLE_RUN: bool = false;

    /// Coverage and depth of the sample at `(x, y)`.
    fn sample(&self, x: f32, y: f32) -> Option<f32>;

    /// Coverage and depth of eight samples in a row, at `x0, x0 + 1, …, x0 + 7`,
    /// of which the lanes in `active` count: a bit mask of the covered ones
    /// (within `active`) and their depths. Bit for bit what [`Coverage::sample`]
    /// gives for each, on either instruction set `L` (implementations that
    /// vectorise it must round alike: no fused multiply-add, the same
    /// operation order).
    /// (The points `x0 + k` are rounded as a lane's `x0 + k` would be.)
    #[inline(always)]
    fn sample8<L: Lanes>(&self, x0: f32, y: f32, active: u8) -> (u8, [f32; 8]) {
        let x = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0].map(|k| x0 + k);
        self.sample_points8::<L>(x, [y; 8], active)
    }

    /// The triangle's groups of eight samples along rows ([`RowLanes`]), with
    /// what every group shares worked out once for many rows.
    #[inline(always)]
    fn rows<L: Lanes>(&self) -> impl RowLanes<L> {
        ByGroups { tri: self, y: 0.0 }
    }

    /// Coverage and depth of eight samples at any points `(x[k], y[k])` (the
    /// samples of anti-aliasing patterns, the rays of a packet), of which the
    /// lanes in `active` count: the same decisions as [`Coverage::sample`] per lane.
    #[inline(always)]
    fn sample_points8<L: Lanes>(&self, x: [f32; 8], y: [f32; 8], active: u8) -> (u8, [f32; 8]) {
        lanes8(active, |k| self.sample(x[k], y[k]))
    }

    /// Whether [`Coverage::sample_across`] tests eight triangles in one
    /// group of lanes; otherwise it is each lane's [`Coverage::sample`] in
    /// turn, and callers keep to one triangle per group.
    const ACROSS: bool = false;

    /// Coverage and depth of eight samples, each against its own triangle:
    /// lane `l`'s point `(x[l], y[l])` against `tris[l]` (all set up for
    /// one view), of which the lanes in `active` count. The same decisions
    /// as each lane's [`Coverage::sample`].
    #[inline(always)]
    fn sample_across<L: Lanes>(
        tris: [&Self; 8],
        x: [f32; 8],
        y: [f32; 8],
        active: u8,
    ) -> (u8, [f32; 8]) {
        lanes8(active, |k| tris[k].sample(x[k], y[k]))
    }

    /// Does the triangle cover each of eight points (CSAA's coverage-only
    /// positions), without computing depth where that can be avoided: the
    /// edges with the tie rule, in front of the eye and not nearer than `near`.
    /// Every algorithm decides coverage-only positions with this one function.
    #[inline(always)]
    fn covers8<L: Lanes>(&self, x: [f32; 8], y: [f32; 8]) -> u8 {
        self.sample_points8::<L>(x, y, 0xff).0
    }

    /// [`Coverage::depth_inside`] for eight points of a block found inside.
    #[inline(always)]
    fn depth_inside8<L: Lanes>(&self, x: [f32; 8], y: [f32; 8]) -> (u8, [f32; 8]) {
        lanes8(0xff, |k| self.depth_inside(x[k], y[k]))
    }

    /// Coverage of the `n` samples `(x0 + k, y)`, `k < n`: calls `hit(k, w)` for
    /// each covered one. The same decisions as [`Coverage::sample`] per sample.
    #[inline(always)]
    fn sample_run<L: Lanes>(&self, x0: f32, y: f32, n: u32, mut hit: impl FnMut(u32, f32)) {
        // Eight samples at a time, the last group with only its first lanes.
        for k in (0..n).step_by(8) {
            let active = first_lanes((n - k) as usize);
            let (mask, depth) = self.sample8::<L>(x0 + k as f32, y, active);
            let mut covered = mask;
            while covered != 0 {
                let b = covered.trailing_zeros();
                covered &= covered - 1;
                hit(k + b, depth[b as usize]);
            }
        }
    }

    /// Depth of a sample of a block that [`Coverage::classify_block`] found
    /// inside; `None` when the depth test rejects it (nearer than `near`).
    fn depth_inside(&self, x: f32, y: f32) -> Option<f32>;

    /// Conservative test of the block of samples with corner samples `(x0, y0)`
    /// and `(x1, y1)` (binning, paper §3.1, and for curved edges §3.5).
    fn classify_block(&self, x0: f32, y0: f32, x1: f32, y1: f32) -> BlockTest;

    /// No sample of the triangle has a smaller depth than this.
    fn min_depth(&self) -> f32;
}

/// A triangle's [`Coverage::sample8`] along rows of samples, group after
/// group ([`Coverage::rows`]): the row's `y` set once, each group's points
/// given as lanes. Bit for bit `sample8` at the same points.
pub trait RowLanes<L: Lanes> {
    /// The row at `y` (before the groups along it).
    fn set_row(&mut self, y: f32);

    /// [`Coverage::sample8`] at `x0, x0 + 1, …, x0 + 7` on the current row,
    /// with those points in lanes (`x`).
    fn sample8(&self, x0: f32, x: L, active: u8) -> (u8, [f32; 8]);

    /// [`Coverage::depth_inside8`] at the same points (a group known to be
    /// inside the edges).
    fn depth_inside8(&self, x: L) -> (u8, [f32; 8]);
}

/// [`RowLanes`] as calls of [`Coverage::sample8`], for triangles with no
/// row form of their own.
struct ByGroups<'a, C: ?Sized> {
    tri: &'a C,
    y: f32,
}

impl<L: Lanes, C: Coverage + ?Sized> RowLanes<L> for ByGroups<'_, C> {
    #[inline(always)]
    fn set_row(&mut self, y: f32) {
        self.y = y;
    }

    #[inline(always)]
    fn sample8(&self, x0: f32, _: L, active: u8) -> (u8, [f32; 8]) {
        self.tri.sample8::<L>(x0, self.y, active)
    }

    #[inline(always)]
    fn depth_inside8(&self, x: L) -> (u8, [f32; 8]) {
        self.tri.depth_inside8::<L>(x.to_array(), [self.y; 8])
    }
}

/// A reference reads as what it refers to (what [`Stored::bind`] gives the
/// set-up triangles that are their own coverage).
impl<C: Coverage> Coverage for &C {
    const OWN_SAMPLE_RUN: bool = C::OWN_SAMPLE_RUN;
    const ACROSS: bool = C::ACROSS;
    #[inline(always)]
    fn sample_across<L: Lanes>(
        tris: [&Self; 8],
        x: [f32; 8],
        y: [f32; 8],
        active: u8,
    ) -> (u8, [f32; 8]) {
        C::sample_across::<L>(tris.map(|t| *t), x, y, active)
    }
    #[inline(always)]
    fn sample(&self, x: f32, y: f32) -> Option<f32> {
        (**self).sample(x, y)
    }
    #[inline(always)]
    fn sample8<L: Lanes>(&self, x0: f32, y: f32, active: u8) -> (u8, [f32; 8]) {
        (**self).sample8::<L>(x0, y, active)
    }
    #[inline(always)]
    fn rows<L: Lanes>(&self) -> impl RowLanes<L> {
        (**self).rows::<L>()
    }
    #[inline(always)]
    fn sample_points8<L: Lanes>(&self, x: [f32; 8], y: [f32; 8], active: u8) -> (u8, [f32; 8]) {
        (**self).sample_points8::<L>(x, y, active)
    }
    #[inline(always)]
    fn covers8<L: Lanes>(&self, x: [f32; 8], y: [f32; 8]) -> u8 {
        (**self).covers8::<L>(x, y)
    }
    #[inline(always)]
    fn depth_inside8<L: Lanes>(&self, x: [f32; 8], y: [f32; 8]) -> (u8, [f32; 8]) {
        (**self).depth_inside8::<L>(x, y)
    }
    #[inline(always)]
    fn sample_run<L: Lanes>(&self, x0: f32, y: f32, n: u32, hit: impl FnMut(u32, f32)) {
        (**self).sample_run::<L>(x0, y, n, hit);
    }
    #[inline(always)]
    fn depth_inside(&self, x: f32, y: f32) -> Option<f32> {
        (**self).depth_inside(x, y)
    }
    #[inline(always)]
    fn classify_block(&self, x0: f32, y0: f32, x1: f32, y1: f32) -> BlockTest {
        (**self).classify_block(x0, y0, x1, y1)
    }
    #[inline(always)]
    fn min_depth(&self) -> f32 {
        (**self).min_depth()
    }
}

/// The scalar decisions of the `active` lanes as one lane mask and their
/// depths (the default of the 8-sample methods).
#[inline(always)]
fn lanes8(active: u8, sample: impl Fn(usize) -> Option<f32>) -> (u8, [f32; 8]) {
    let mut mask = 0;
    let mut depth = [0.0; 8];
    for (k, d) in depth.iter_mut().enumerate() {
        if active >> k & 1 == 0 {
            continue;
        }
        if let Some(w) = sample(k) {
            mask |= 1 << k;
            *d = w;
        }
    }
    (mask, depth)
}

/// Straight edges taken one at a time, for traversals that walk them from
/// row to row (`2dr-scanline`: the lectures' sweep-line algorithm, the
/// Princeton lecture's "Triangle Sweep-Line Algorithm").
///
/// Along a row of sample points `x + o` (integer `x`, a fixed offset `o`),
/// [`EdgeWalk::inside_edge_at`] is monotone in `x`: every operation of an
/// edge's evaluation (a difference, a product by a constant, a difference
/// from a constant; or exact integers) is monotone in `x` and rounds
/// monotonically, so the samples inside one edge are a prefix or a suffix of
/// the row, and those inside all three a run. Where the run starts and ends
/// can therefore be searched for with the edge's own decision, and is exact.
pub trait EdgeWalk {
    /// Edge `i` as the line `a·x + b·y + c = 0` in pixel coordinates, `a·x + b·y + c`
    /// positive inside: the row's crossing `x = −(b·y + c)/a` starts the search
    /// (it need not be exact), and the sign of `a` is exactly the direction in
    /// which the edge's decision grows along a row (`0`: constant along rows).
    fn edge_line(&self, i: usize) -> [f64; 3];

    /// Edge `i`'s part of the coverage decision at the sample point `(x, y)`:
    /// its value and the tie rule, bit for bit as [`Coverage::sample`] and
    /// every lane form compute them.
    fn inside_edge_at(&self, i: usize, x: f32, y: f32) -> bool;
}

impl<E: EdgeWalk> EdgeWalk for &E {
    #[inline(always)]
    fn edge_line(&self, i: usize) -> [f64; 3] {
        (**self).edge_line(i)
    }
    #[inline(always)]
    fn inside_edge_at(&self, i: usize, x: f32, y: f32) -> bool {
        (**self).inside_edge_at(i, x, y)
    }
}

/// Edge functions linear in the image point (planar viewports): the parts from
/// which [`Coverage`] is assembled by [`linear_sample`] and [`linear_classify`].
pub trait LinearEdges {
    /// The three edge values at image point `(x, y)`, positive inside.
    fn edge_values(&self, x: f32, y: f32) -> [f32; 3];

    /// Per edge: does it own samples exactly on it?
    fn owns(&self) -> [bool; 3];

    /// Depth `w` of the sample at `(x, y)` with edge values `edges`, or `None`
    /// when the sample is rejected (nearer than `near`, or not in front).
    fn depth(&self, edges: [f32; 3], x: f32, y: f32) -> Option<f32>;

    /// Per edge, a bound on how far two evaluations of [`LinearEdges::edge_values`]
    /// at points of the image can be off their exact values; binning rejects or
    /// accepts a block only beyond it.
    fn edge_error(&self) -> [f32; 3];
}

/// Coverage and depth of one sample: edge values, the tie rule, then depth.
#[inline(always)]
pub fn linear_sample<T: LinearEdges>(t: &T, x: f32, y: f32) -> Option<f32> {
    let e = t.edge_values(x, y);
    let o = t.owns();
    if inside_edge(e[0], o[0]) && inside_edge(e[1], o[1]) && inside_edge(e[2], o[2]) {
        t.depth(e, x, y)
    } else {
        None
    }
}

/// Straight edges at the block's four corner samples: outside if some edge is
/// negative beyond its error bound at all four, inside if every edge is positive
/// beyond it at all four (paper §3.1, "binning").
#[inline]
pub fn linear_classify<T: LinearEdges>(t: &T, x0: f32, y0: f32, x1: f32, y1: f32) -> BlockTest {
    let errors = t.edge_error();
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for (x, y) in [(x0, y0), (x1, y0), (x0, y1), (x1, y1)] {
        let e = t.edge_values(x, y);
        for k in 0..3 {
            lo[k] = lo[k].min(e[k]);
            hi[k] = hi[k].max(e[k]);
        }
    }
    if (0..3).any(|k| hi[k] < -errors[k]) {
        BlockTest::Outside
    } else if (0..3).all(|k| lo[k] > errors[k]) {
        BlockTest::Inside
    } else {
        BlockTest::Partial
    }
}

/// The check every vectorised [`Coverage`] passes: its 8-lane methods against
/// its scalar ones.
#[cfg(test)]
pub(crate) mod lanes_test {
    use super::{Coverage, RowLanes};
    use crate::simd::Lanes;

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    pub(crate) fn lanes_agree_avx2<T: Coverage>(t: &T, active: u8) -> (usize, Vec<u8>) {
        lanes_agree::<crate::simd::Avx2, T>(t, active)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn across_avx2<T: Coverage>(
        tris: [&T; 8],
        x: [f32; 8],
        y: [f32; 8],
        active: u8,
    ) -> (u8, [f32; 8]) {
        T::sample_across::<crate::simd::Avx2>(tris, x, y, active)
    }

    /// `groups` groups of eight samples on a quarter-pixel grid over the
    /// 64×48 image, each lane against a triangle of `tris` drawn at random:
    /// [`Coverage::sample_across`] on the portable lanes and on AVX2 gives
    /// each lane's [`Coverage::sample`] in the lanes asked for (all of
    /// them, or a random part). Returns the number of covered lanes compared.
    pub(crate) fn across_agree<T: Coverage>(
        tris: &[T],
        groups: usize,
        rng: &mut fastrand::Rng,
    ) -> usize {
        #[cfg(target_arch = "x86_64")]
        assert!(
            crate::simd::cpu_has_avx2(),
            "this test checks the AVX2 lanes"
        );
        let mut covered = 0;
        for group in 0..groups {
            let eight: [&T; 8] = std::array::from_fn(|_| &tris[rng.usize(..tris.len())]);
            let x = std::array::from_fn(|_| rng.u32(0..256) as f32 * 0.25);
            let y = std::array::from_fn(|_| rng.u32(0..192) as f32 * 0.25);
            let active = if group % 2 == 0 { 0xff } else { rng.u8(..) };
            let portable = T::sample_across::<crate::simd::Portable>(eight, x, y, active);
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the CPU has AVX2 (asserted above).
            let avx2 = unsafe { across_avx2(eight, x, y, active) };
            for l in 0..8 {
                let alone = eight[l].sample(x[l], y[l]).filter(|_| active >> l & 1 == 1);
                let lane = |(mask, w): (u8, [f32; 8])| (mask >> l & 1 == 1).then_some(w[l]);
                let at = format!("group {group}, lane {l}");
                assert_eq!(
                    lane(portable).map(f32::to_bits),
                    alone.map(f32::to_bits),
                    "{at}"
                );
                #[cfg(target_arch = "x86_64")]
                assert_eq!(
                    lane(avx2).map(f32::to_bits),
                    alone.map(f32::to_bits),
                    "AVX2: {at}"
                );
                covered += usize::from(alone.is_some());
            }
        }
        covered
    }

    /// Compares `t`'s `sample8` (and its row form, [`Coverage::rows`], with
    /// the row form's `depth_inside8`),
    /// `sample_points8`, `covers8` and `depth_inside8` on lanes `L` with the
    /// scalar path over the 64×48 image (`covers8`,
    /// which skips the depth clamp, against the other lanes); returns the
    /// number of covered samples compared and the `covers8` masks.
    pub(crate) fn lanes_agree<L: Lanes, T: Coverage>(t: &T, active: u8) -> (usize, Vec<u8>) {
        let (mut compared, mut covers) = (0, Vec::new());
        let mut rows = t.rows::<L>();
        for y in 0..48 {
            let yc = y as f32 + 0.5;
            rows.set_row(yc);
            for x0 in (0..64).step_by(8) {
                let (mask, depth) = t.sample8::<L>(x0 as f32 + 0.5, yc, active);
                // The same group along the row form.
                let x = L::from_array(std::array::from_fn(|k| (x0 + k) as f32 + 0.5));
                let (row_mask, row_depth) = rows.sample8(x0 as f32 + 0.5, x, active);
                assert_eq!(row_mask, mask, "row form: pixels from ({x0}, {y})");
                for k in (0..8).filter(|k| mask >> k & 1 == 1) {
                    assert_eq!(row_depth[k].to_bits(), depth[k].to_bits(), "row form depth");
                }
                let xs = x.to_array();
                let (inside_mask, inside_depth) = t.depth_inside8::<L>(xs, [yc; 8]);
                let (row_mask, row_depth) = rows.depth_inside8(x);
                assert_eq!(row_mask, inside_mask, "row form inside: from ({x0}, {y})");
                for k in (0..8).filter(|k| inside_mask >> k & 1 == 1) {
                    let [row, lane] = [row_depth[k], inside_depth[k]].map(f32::to_bits);
                    assert_eq!(row, lane, "row form inside depth");
                }
                // The same pixels as points, a quarter pixel off their centres.
                let xs = std::array::from_fn(|k| (x0 + k) as f32 + 0.25);
                let ys = [yc + 0.25; 8];
                let (point_mask, point_depth) = t.sample_points8::<L>(xs, ys, active);
                covers.push(t.covers8::<L>(xs, ys));
                let (inside_mask, inside_depth) = t.depth_inside8::<L>(xs, ys);
                for k in 0..8 {
                    let on = |m: u8| m >> k & 1 == 1;
                    let at = format!("pixel ({}, {y}), lanes {active:#010b}", x0 + k);
                    let scalar = t.sample((x0 + k) as f32 + 0.5, yc).filter(|_| on(active));
                    let lane = on(mask).then_some(depth[k]);
                    assert_eq!(scalar.map(f32::to_bits), lane.map(f32::to_bits), "{at}");
                    let scalar = t.sample(xs[k], ys[k]);
                    let lane = on(point_mask).then_some(point_depth[k]);
                    assert_eq!(
                        scalar.filter(|_| on(active)).map(f32::to_bits),
                        lane.map(f32::to_bits),
                        "points: {at}"
                    );
                    let scalar = t.depth_inside(xs[k], ys[k]);
                    let lane = on(inside_mask).then_some(inside_depth[k]);
                    assert_eq!(
                        scalar.map(f32::to_bits),
                        lane.map(f32::to_bits),
                        "inside: {at}"
                    );
                    compared += usize::from(scalar.is_some());
                }
            }
        }
        (compared, covers)
    }
}
