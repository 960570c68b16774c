//! Setup of the 2D family (paper §3.1): transform to camera space, clip against
//! the near plane and a guard band (Sutherland–Hodgman), project, set up 2D edge
//! functions (top-left rule, perspective-correct w) per piece of the clipped
//! polygon — in f32 ([`Triangle2D`]) or on snapped vertices in fixed point
//! ([`Triangle2DFixed`]).

use glam::DVec3;
use rayon::prelude::*;

use super::tiles::{ItemBox, Setups};
use crate::camera::View;
use crate::clip::{
    ClipPlane, GUARD_BAND, MAX_CLIPPED, clip_triangle, fixed_guard_band, pipeline_planes,
};
use crate::edge::{EightVertices, ScreenVertex, Stored, Triangle2D, Triangle2DFixed, vertices_of};
use crate::ground::PixelRect;
use crate::ground::SampleSpan;
use crate::prepared::PreparedScene;
use crate::screen_boxes::{PixelRects, pixels_lanes};
use crate::simd::{self, EightIds, Lanes, finite, first_lanes};

/// Every drawable triangle, clipped, projected and set up with f32 edge
/// functions; pieces without samples on screen are dropped.
pub(crate) fn setup_2d(
    scene: &PreparedScene,
    view: &View,
    span: SampleSpan,
) -> Setups<'static, Triangle2D> {
    let (affine, size) = (view.is_orthographic(), [view.width, view.height]);
    let make_eight = move |v: &EightVertices, present: u8, out: &mut [Option<Triangle2D>; 8]| {
        Triangle2D::setup_eight(v, present, affine, size, out);
    };
    setup_pieces(
        scene,
        view,
        span,
        [GUARD_BAND; 2],
        make_2d(view),
        make_eight,
    )
}

/// The f32 setup of one projected piece.
fn make_2d(view: &View) -> impl Fn(&[ScreenVertex; 3]) -> Option<Triangle2D> + Sync {
    let affine = view.is_orthographic();
    move |v| Triangle2D::setup(v, affine, view.width, view.height)
}

/// A set-up projected triangle: its vertices' pixel bounds
/// `[min_x, min_y, max_x, max_y]`.
trait Projected: Stored<Shared<'static> = ()> {
    /// Whether the bounds are those of the vertices the setup was given
    /// (so that [`kept_eight`]'s rects are the triangle's pixels).
    const BOUNDS_OF_VERTICES: bool;
    fn bounds(&self) -> [f32; 4];
}

impl Projected for Triangle2D {
    const BOUNDS_OF_VERTICES: bool = true;
    fn bounds(&self) -> [f32; 4] {
        self.bounds
    }
}

impl Projected for Triangle2DFixed {
    const BOUNDS_OF_VERTICES: bool = false;
    fn bounds(&self) -> [f32; 4] {
        self.bounds
    }
}

/// As [`setup_2d`], with vertices snapped to 1/256 pixel and exact edge
/// functions, and a guard band as wide as fixed point allows (clipping moves
/// edges by up to half a snapping step; hardware clips as rarely).
pub(crate) fn setup_2d_fixed(
    scene: &PreparedScene,
    view: &View,
    span: SampleSpan,
) -> Setups<'static, Triangle2DFixed> {
    let affine = view.is_orthographic();
    let make = move |v: &[ScreenVertex; 3]| Triangle2DFixed::setup(v, affine);
    let make_eight = move |v: &EightVertices, present: u8, out: &mut [Option<_>; 8]| {
        for (l, out) in out.iter_mut().enumerate() {
            if present >> l & 1 == 1 {
                *out = make(&vertices_of(v, l));
            }
        }
    };
    setup_pieces(scene, view, span, fixed_guard_band(view), make, make_eight)
}

/// Clips (the guard band `guard` in units of the half-extents), projects and
/// fan-triangulates every drawable triangle; `make` sets up each piece, and
/// `make_eight` does what `make` does for the present lanes of eight
/// unclipped triangles at once, into its third argument's lanes. One item per drawable triangle holds its first piece (exactly
/// sized, parallel collects written in place, eight items at a time); the
/// further pieces of the few triangles clipping cuts into several follow,
/// set up again in a second, small pass.
///
/// Vertices are transformed and projected once each, as a vertex shader
/// would ([`screen_vertices`]): a triangle whose three vertices are inside
/// every plane is its own clipped polygon and takes them as they are — the
/// very values [`pieces_of`] would compute for it — while the others are
/// clipped.
fn setup_pieces<T: Projected>(
    scene: &PreparedScene,
    view: &View,
    span: SampleSpan,
    guard: [f32; 2],
    make: impl Fn(&[ScreenVertex; 3]) -> Option<T> + Sync,
    make_eight: impl Fn(&EightVertices, u8, &mut [Option<T>; 8]) + Sync,
) -> Setups<'static, T> {
    let planes = pipeline_planes(view, guard);
    let kept = screen_vertices(scene, view, &planes);
    let size = [view.width, view.height];
    let lanes = LaneVertices::new(&kept, &scene.scene.mesh.triangles, size, span);
    let pieces = |id: u32| pieces_of(scene, view, span, &planes, &make, id);
    let item = |piece: Option<Piece<T>>| match piece {
        Some(Piece { tri, rect, id }) => (ItemBox::new(rect, id), Some(tri)),
        None => (ItemBox::NONE, None),
    };
    let (first, more): (Columns<T>, Vec<u8>) = (scene.drawable.par_chunks(8))
        .map(|ids| {
            // The lanes whose three vertices are all kept, set up together.
            let eight = kept_eight(&lanes, EightIds::of(ids).get(), ids.len());
            let unclipped = eight.kept;
            // Set up in place: each lane's triangle stays where it is made.
            let mut triangles = [const { None }; 8];
            make_eight(&eight.vertices, unclipped, &mut triangles);
            let (mut boxes, mut more) = ([ItemBox::NONE; 8], 0u8);
            for (l, &id) in ids.iter().enumerate() {
                if unclipped >> l & 1 == 1 {
                    let rect = |t: &T| match T::BOUNDS_OF_VERTICES && eight.bounded >> l & 1 == 1 {
                        true => eight.rects.get(l),
                        false => pixels(view, span, t),
                    };
                    match triangles[l].as_ref().and_then(rect) {
                        Some(rect) => boxes[l] = ItemBox::new(rect, id),
                        None => triangles[l] = None,
                    }
                } else {
                    let mut pieces = pieces(id).into_iter().flatten();
                    (boxes[l], triangles[l]) = item(pieces.next());
                    more |= u8::from(pieces.next().is_some()) << l;
                }
            }
            ((boxes, triangles), more)
        })
        .unzip();
    let rest: Vec<(ItemBox, Option<T>)> = (scene.drawable.par_chunks(8))
        .zip(&more)
        .filter(|&(_, &more)| more != 0)
        .flat_map_iter(|(ids, &more)| {
            let several = ids
                .iter()
                .enumerate()
                .filter(move |&(l, _)| more >> l & 1 == 1);
            several.flat_map(|(_, &id)| {
                pieces(id)
                    .into_iter()
                    .flatten()
                    .skip(1)
                    .map(|p| item(Some(p)))
            })
        })
        .collect();
    let (boxes, triangles) = first;
    let (mut boxes, mut triangles) = (boxes.into_flattened(), triangles.into_flattened());
    boxes.truncate(scene.drawable.len());
    triangles.truncate(scene.drawable.len());
    for (b, t) in rest {
        boxes.push(b);
        triangles.push(t);
    }
    Setups {
        boxes,
        triangles,
        shared: (),
    }
}

/// The set-up pieces of the triangles `ids` after clipping (near plane and
/// guard band, in f64), each with its pixels and its triangle's id: what
/// [`setup_2d`] makes of the triangles it clips.
#[cfg(feature = "gpu")]
pub(crate) fn clipped_pieces(
    scene: &PreparedScene,
    view: &View,
    span: SampleSpan,
    ids: &[u32],
) -> Vec<(Triangle2D, PixelRect, u32)> {
    let make = make_2d(view);
    let planes = pipeline_planes(view, [GUARD_BAND; 2]);
    ids.par_iter()
        .flat_map_iter(|&id| {
            pieces_of(scene, view, span, &planes, &make, id)
                .into_iter()
                .flatten()
                .map(|p| (p.tri, p.rect, p.id))
        })
        .collect()
}

/// Items' boxes and triangles, eight at a time, before they are [`Setups`].
type Columns<T> = (Vec<[ItemBox; 8]>, Vec<[Option<T>; 8]>);

/// One set-up piece of a triangle with its pixels and the triangle's id.
struct Piece<T> {
    tri: T,
    rect: PixelRect,
    id: u32,
}

/// Per mesh vertex, `[x, y, q, kept]`: its projection and 1 when it is inside
/// every clip plane, zeros when some plane would clip it — the layout the
/// lanes gather ([`kept_eight`]).
fn screen_vertices(scene: &PreparedScene, view: &View, planes: &[ClipPlane]) -> Vec<[f32; 4]> {
    let positions = &scene.scene.mesh.positions;
    (positions.par_iter())
        .map(|&p| {
            let c = view.to_camera_f64(p);
            match planes.iter().all(|plane| plane.keeps(c)) {
                true => {
                    let s = screen_vertex(view, c);
                    [s.x, s.y, s.q, 1.0]
                }
                false => [0.0; 4],
            }
        })
        .collect()
}

/// What [`kept_eight`] gathers from: the projected vertices (x, y, q and
/// kept, a row each) and the triangles' vertex records, flat.
struct LaneVertices<'a> {
    points: &'a [[f32; 4]],
    records: &'a [u32],
    size: [u32; 2],
    span: SampleSpan,
}

impl<'a> LaneVertices<'a> {
    fn new(
        points: &'a [[f32; 4]],
        records: &'a [[u32; 3]],
        size: [u32; 2],
        span: SampleSpan,
    ) -> LaneVertices<'a> {
        // 32-bit lane offsets: half a billion vertices or 700 million
        // triangles (tens of gigabytes of mesh before any setup).
        assert!(
            points.len() < (i32::MAX / 4) as usize && records.len() < (i32::MAX / 3) as usize,
            "a mesh of {} vertices and {} triangles is beyond the 2D setup's 32-bit lane offsets",
            points.len(),
            records.len()
        );
        LaneVertices {
            points,
            records: records.as_flattened(),
            size,
            span,
        }
    }
}

simd::dispatch! {
    /// The vertices of the first `n` of triangles `ids` in lanes (lanes
    /// past `n` repeat a triangle), and the lanes whose three vertices are
    /// all kept: gathered, and stored a whole lane group at a time, which is
    /// how the setup's lanes read them back.
    fn kept_eight<>(lanes: &LaneVertices, ids: &[u32; 8], n: usize) -> KeptEight => kept_eight_on
}

#[inline(always)]
fn kept_eight_on<L: Lanes>(lanes: &LaneVertices, ids: &[u32; 8], n: usize) -> KeptEight {
    let mut v: EightVertices = [[[0.0; 8]; 3]; 3];
    let mut kept = first_lanes(n);
    let zero = L::splat(0.0);
    // Per vertex: x, y and a pad of zero (the bounds are the vertices').
    let mut points = [[zero; 3]; 3];
    let mut finite_xy = u8::MAX;
    let vertices = simd::gather_xyz_u32::<L>(lanes.records, 3, *ids);
    for k in 0..3 {
        let [x, y, q, is_kept] = L::gather_xyzw(lanes.points, vertices[k]);
        (v[0][k], v[1][k], v[2][k]) = (x.to_array(), y.to_array(), q.to_array());
        points[k] = [x, y, zero];
        finite_xy &= finite(x) & finite(y);
        kept &= is_kept.eq(L::splat(1.0));
    }
    KeptEight {
        vertices: v,
        kept,
        rects: pixels_lanes(&points, lanes.size, lanes.span),
        bounded: kept & finite_xy,
    }
}

/// A chunk's vertices as [`kept_eight`] gathers them.
struct KeptEight {
    vertices: EightVertices,
    /// The lanes whose three vertices are kept.
    kept: u8,
    /// In the lanes of `bounded`, the pixels with a sample in the box of the
    /// lane's vertices: [`PixelRect::from_bounds`] of a [`Triangle2D`]'s
    /// bounds (the lanes' `minps`/`maxps` differ from `f32::min`/`max`
    /// only in the sign of a zero, which the pixels do not see).
    rects: PixelRects,
    /// Kept lanes whose coordinates are finite.
    bounded: u8,
}

/// A camera-space point projected to the image, with its depth quantity
/// (`1/w` under perspective, `w` under orthographic projection).
#[inline]
fn screen_vertex(view: &View, c: DVec3) -> ScreenVertex {
    let (x, y) = view.project_f64(c);
    let q = if view.is_orthographic() {
        c.z
    } else {
        1.0 / c.z
    };
    ScreenVertex {
        x: x as f32,
        y: y as f32,
        q: q as f32,
    }
}

/// A set-up piece of triangle `id` with its pixels; `None` when it has no
/// samples on screen.
#[inline]
fn placed<T: Projected>(
    view: &View,
    span: SampleSpan,
    tri: Option<T>,
    id: u32,
) -> Option<Piece<T>> {
    let tri = tri?;
    let rect = pixels(view, span, &tri)?;
    Some(Piece { tri, rect, id })
}

/// The pixels with a sample in `tri`'s bounds; `None` when none has.
#[inline]
fn pixels<T: Projected>(view: &View, span: SampleSpan, tri: &T) -> Option<PixelRect> {
    let [x0, y0, x1, y1] = tri.bounds();
    PixelRect::from_bounds(x0, y0, x1, y1, view.width, view.height, span)
}

/// The set-up pieces of triangle `id` after clipping and fan triangulation,
/// in fan order (`None` where a piece has no samples on screen).
fn pieces_of<T: Projected>(
    scene: &PreparedScene,
    view: &View,
    span: SampleSpan,
    planes: &[ClipPlane],
    make: &impl Fn(&[ScreenVertex; 3]) -> Option<T>,
    id: u32,
) -> [Option<Piece<T>>; MAX_CLIPPED - 2] {
    let mut pieces: [Option<Piece<T>>; MAX_CLIPPED - 2] = std::array::from_fn(|_| None);
    // 1. Transform and clip.
    let p = scene.triangle(id);
    let cam = p.map(|v| view.to_camera_f64(v));
    let Some(poly) = clip_triangle(cam, planes) else {
        return pieces;
    };
    // 2. Project (the polygon has at most 8 vertices).
    let mut screen = [ScreenVertex {
        x: 0.0,
        y: 0.0,
        q: 0.0,
    }; MAX_CLIPPED];
    for (s, &c) in screen.iter_mut().zip(poly.as_slice()) {
        *s = screen_vertex(view, c);
    }
    // 3. Fan-triangulate and set up each piece.
    for k in 1..poly.len - 1 {
        pieces[k - 1] = placed(view, span, make(&[screen[0], screen[k], screen[k + 1]]), id);
    }
    pieces
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aa::{AaMode, SamplePattern};

    type Gather = fn(&LaneVertices, &[u32; 8], usize) -> KeptEight;

    /// `gather` gives each of the first `n` lanes its triangle's vertices
    /// (bit for bit), marks it kept exactly when its three vertices are, and
    /// gives a kept lane with finite coordinates the pixels of its
    /// vertices' box as `PixelRect::from_bounds` finds them: random points
    /// on and off the image, about one in five clipped and one in forty
    /// not finite, random triangles and sample spans, full and short chunks.
    fn lanes_hold_the_kept_vertices(gather: Gather) {
        let mut rng = fastrand::Rng::with_seed(7);
        let (mut checked, mut kept_lanes, mut with_pixels) = (0, 0, 0);
        for case in 0..2_000 {
            let coordinate = |rng: &mut fastrand::Rng, scale: f32| match rng.u32(0..80) {
                0 => f32::INFINITY,
                1 => f32::NAN,
                _ => rng.f32() * scale - 20.0,
            };
            let points: Vec<[f32; 4]> = (0..30)
                .map(|_| match rng.u32(0..5) {
                    0 => [0.0; 4],
                    _ => [
                        coordinate(&mut rng, 140.0),
                        coordinate(&mut rng, 90.0),
                        0.5,
                        1.0,
                    ],
                })
                .collect();
            let records: Vec<[u32; 3]> = (0..40)
                .map(|_| [rng.u32(0..30), rng.u32(0..30), rng.u32(0..30)])
                .collect();
            let n = rng.usize(1..=8);
            let mut ids: [u32; 8] = std::array::from_fn(|_| rng.u32(0..40));
            for l in n..8 {
                ids[l] = ids[n - 1];
            }
            let size = [rng.u32(1..120), rng.u32(1..80)];
            let aa = [AaMode::None, AaMode::Ssaa(4), AaMode::Msaa(8)][case % 3];
            let span = SamplePattern::of(aa).span;
            let lanes = LaneVertices::new(&points, &records, size, span);
            let eight = gather(&lanes, &ids, n);
            for l in 0..n {
                let corners = records[ids[l] as usize].map(|i| points[i as usize]);
                let all = corners.iter().all(|p| p[3] == 1.0);
                let at = format!("case {case}, lane {l} of {n}");
                assert_eq!(eight.kept >> l & 1 == 1, all, "{at}");
                let lane =
                    vertices_of(&eight.vertices, l).map(|s| [s.x, s.y, s.q].map(f32::to_bits));
                let expected = corners.map(|p| [p[0], p[1], p[2]].map(f32::to_bits));
                assert_eq!(lane, expected, "{at}");
                let finite = corners.iter().all(|p| p[0].is_finite() && p[1].is_finite());
                assert_eq!(eight.bounded >> l & 1 == 1, all && finite, "{at}");
                if all && finite {
                    let (x, y) = (corners.map(|p| p[0]), corners.map(|p| p[1]));
                    let expected = PixelRect::from_bounds(
                        x[0].min(x[1]).min(x[2]),
                        y[0].min(y[1]).min(y[2]),
                        x[0].max(x[1]).max(x[2]),
                        y[0].max(y[1]).max(y[2]),
                        size[0],
                        size[1],
                        span,
                    );
                    assert_eq!(eight.rects.get(l), expected, "{at}");
                    with_pixels += usize::from(expected.is_some());
                }
                (checked, kept_lanes) = (checked + 1, kept_lanes + usize::from(all));
            }
            let past = u32::from(eight.kept | eight.bounded) >> n;
            assert_eq!(past, 0, "case {case}: no lane past {n} is kept");
        }
        assert!(
            checked > 5_000 && kept_lanes > 2_000 && with_pixels > 1_000,
            "{checked} lanes, {kept_lanes} kept, {with_pixels} with pixels"
        );
    }

    #[test]
    fn portable_lanes_hold_the_kept_vertices() {
        lanes_hold_the_kept_vertices(kept_eight_on::<simd::Portable>);
    }

    #[test]
    fn avx2_lanes_hold_the_kept_vertices() {
        #[cfg(target_arch = "x86_64")]
        assert!(
            simd::cpu_has_avx2(),
            "this test checks the AVX2 kernel, and this CPU has no AVX2"
        );
        // `kept_eight` takes AVX2 where the CPU has it.
        lanes_hold_the_kept_vertices(kept_eight);
    }
}
