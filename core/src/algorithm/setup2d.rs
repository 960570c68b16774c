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
use crate::edge::{
    EightVertices, ScreenVertex, Stored, Triangle2D, Triangle2DFixed, set_lane, vertices_of,
};
use crate::ground::PixelRect;
use crate::ground::SampleSpan;
use crate::prepared::PreparedScene;

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
    fn bounds(&self) -> [f32; 4];
}

impl Projected for Triangle2D {
    fn bounds(&self) -> [f32; 4] {
        self.bounds
    }
}

impl Projected for Triangle2DFixed {
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
    let corners = &scene.scene.mesh.triangles;
    let pieces = |id: u32| pieces_of(scene, view, span, &planes, &make, id);
    let item = |piece: Option<Piece<T>>| match piece {
        Some(Piece { tri, rect, id }) => (ItemBox::new(rect, id), Some(tri)),
        None => (ItemBox::NONE, None),
    };
    let (first, more): (Columns<T>, Vec<u8>) = (scene.drawable.par_chunks(8))
        .map(|ids| {
            // The lanes whose three vertices are all kept, set up together.
            let mut vertices: EightVertices = [[[0.0; 8]; 3]; 3];
            let mut unclipped = 0u8;
            for (l, &id) in ids.iter().enumerate() {
                if let [Some(a), Some(b), Some(c)] = corners[id as usize].map(|v| kept[v as usize])
                {
                    set_lane(&mut vertices, l, [a, b, c]);
                    unclipped |= 1 << l;
                }
            }
            // Set up in place: each lane's triangle stays where it is made.
            let mut triangles = [const { None }; 8];
            make_eight(&vertices, unclipped, &mut triangles);
            let (mut boxes, mut more) = ([ItemBox::NONE; 8], 0u8);
            for (l, &id) in ids.iter().enumerate() {
                if unclipped >> l & 1 == 1 {
                    match triangles[l].as_ref().and_then(|t| pixels(view, span, t)) {
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

/// Per mesh vertex: its projection when it is inside every clip plane (`None`
/// when some plane would clip it).
fn screen_vertices(
    scene: &PreparedScene,
    view: &View,
    planes: &[ClipPlane],
) -> Vec<Option<ScreenVertex>> {
    let positions = &scene.scene.mesh.positions;
    (positions.par_iter())
        .map(|&p| {
            let c = view.to_camera_f64(p);
            planes
                .iter()
                .all(|plane| plane.keeps(c))
                .then(|| screen_vertex(view, c))
        })
        .collect()
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
