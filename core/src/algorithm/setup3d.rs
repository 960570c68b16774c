//! Setup of the 3D family (paper §3.2) and of homogeneous 2D rasterization: edge
//! functions with no projection and no clipping; a conservative screen box only
//! bounds the search.

use glam::Vec3;
use rayon::prelude::*;

use super::tiles::{ItemBox, Setups};
use crate::camera::View;
use crate::edge::{
    CurvedTriangle, EightTriangles, HomogeneousVertex, Shared3D, Stored, Triangle3D, Triangle3D64,
};
use crate::ground::PixelRect;
use crate::ground::SampleSpan;
use crate::prepared::PreparedScene;
use crate::screen_boxes::ScreenBoxes;
use crate::simd;

/// Every drawable triangle with samples on screen, set up with 3D edge functions.
pub(crate) fn setup_3d<'a>(
    scene: &'a PreparedScene,
    view: &'a View,
    span: SampleSpan,
) -> Setups<'a, Triangle3D> {
    let shared = shared_3d(scene, view, false);
    setup_visible(scene, view, span, shared, Triangle3D::setup_eight)
}

/// What the view's [`Triangle3D`]s share, set up by the 3D setup or the
/// homogeneous one.
pub(crate) fn shared_3d<'a>(
    scene: &'a PreparedScene,
    view: &'a View,
    homogeneous: bool,
) -> Shared3D<'a> {
    let mesh = &scene.scene.mesh;
    Shared3D::of_mesh(view, homogeneous, &mesh.positions, &mesh.triangles)
}

/// What the view's [`Triangle3D`]s share, set up by the 3D setup, with their
/// vertices by BVH slot: a ray caster or a BVH traversal knows its leaf
/// triangles' slots, and finds their corners in one read.
pub(crate) fn slot_shared_3d<'a>(scene: &'a PreparedScene, view: &'a View) -> Shared3D<'a> {
    Shared3D::of_corners(view, false, &scene.slot_corners)
}

/// [`setup_3d`] in f64.
pub(crate) fn setup_3d_f64<'a>(
    scene: &'a PreparedScene,
    view: &'a View,
    span: SampleSpan,
) -> Setups<'a, Triangle3D64> {
    setup_visible(scene, view, span, (), one_by_one(Triangle3D64::setup))
}

/// Every drawable triangle with samples on a non-planar viewport, set up with 3D
/// edge functions evaluated per sample direction (paper §3.5).
pub(crate) fn setup_curved<'a>(
    scene: &'a PreparedScene,
    view: &'a View,
    span: SampleSpan,
) -> Setups<'a, CurvedTriangle> {
    setup_visible(scene, view, span, (), one_by_one(CurvedTriangle::setup))
}

/// Every drawable triangle with samples on screen, set up for homogeneous 2D
/// rasterization (no clipping). Every vertex is transformed to homogeneous
/// pixel coordinates once (as a vertex shader would), not once per triangle.
pub(crate) fn setup_homogeneous<'a>(
    scene: &'a PreparedScene,
    view: &'a View,
    span: SampleSpan,
) -> Setups<'a, Triangle3D> {
    let points: Vec<HomogeneousVertex> = (scene.scene.mesh.positions.par_iter())
        .map(|&p| HomogeneousVertex::of(p, view))
        .collect();
    let setup = |t: &EightTriangles<'a>, view: &'a View| {
        Triangle3D::setup_homogeneous_eight(t, &points, view)
    };
    let shared = shared_3d(scene, view, true);
    setup_visible(scene, view, span, shared, setup)
}

/// A setup of eight triangles at a time, such as [`Triangle3D::setup_eight`].
pub(crate) trait SetupEight<'a, T>:
    Fn(&EightTriangles<'a>, &'a View) -> [Option<T>; 8] + Sync
{
}

impl<'a, T, F> SetupEight<'a, T> for F where
    F: Fn(&EightTriangles<'a>, &'a View) -> [Option<T>; 8] + Sync
{
}

/// A one-triangle setup applied lane by lane.
pub(crate) fn one_by_one<'a, T>(
    setup: impl Fn(&'a [Vec3; 3], &'a View) -> Option<T> + Sync,
) -> impl SetupEight<'a, T> {
    move |t: &EightTriangles<'a>, view: &'a View| t.each(|l| setup(t.corners[l], view))
}

/// Every BVH slot's triangle set up by `setup` with its conservative screen
/// box, in slot order (from the scene's slot-ordered copies of positions and
/// vertex indices: memory read in order), eight slots at a time. `shared`
/// finds the vertices by slot ([`slot_shared_3d`] for a [`Triangle3D`]).
pub(crate) fn setup_slots<'a, T: Stored>(
    scene: &'a PreparedScene,
    view: &'a View,
    span: SampleSpan,
    shared: T::Shared<'a>,
    setup: impl SetupEight<'a, T>,
) -> Setups<'a, T> {
    let boxes = ScreenBoxes::new(scene, view);
    let chunks = (scene.slot_corners.par_chunks(8))
        .zip(scene.slot_vertices.par_chunks(8))
        .zip(scene.slot_triangles.par_chunks(8));
    let eights = chunks.map(|((p, vertices), ids)| {
        let mut eight = EightTriangles {
            corners: lanes_of(p),
            vertices: lanes_of(vertices).map(|v| *v),
            present: 0,
        };
        let rects = rects_of(&boxes, &mut eight, p.len(), view, span);
        paired(rects, lanes_of(ids), setup(&eight, view))
    });
    flattened(eights.unzip(), scene.slot_triangles.len(), shared)
}

/// Eight lanes' boxes (with the triangles' ids) and set-up triangles,
/// `None` in both where either is.
#[inline(always)]
fn paired<T>(
    rects: [Option<PixelRect>; 8],
    ids: [&u32; 8],
    mut triangles: [Option<T>; 8],
) -> ([ItemBox; 8], [Option<T>; 8]) {
    let mut boxes = [ItemBox::NONE; 8];
    for l in 0..8 {
        match rects[l] {
            Some(rect) if triangles[l].is_some() => boxes[l] = ItemBox::new(rect, *ids[l]),
            _ => triangles[l] = None,
        }
    }
    (boxes, triangles)
}

/// The first `len` items of chunks of eight, sharing `shared`.
fn flattened<'a, T: Stored>(
    (boxes, triangles): (Vec<[ItemBox; 8]>, Vec<[Option<T>; 8]>),
    len: usize,
    shared: T::Shared<'a>,
) -> Setups<'a, T> {
    let (mut boxes, mut triangles) = (boxes.into_flattened(), triangles.into_flattened());
    boxes.truncate(len);
    triangles.truncate(len);
    Setups {
        boxes,
        triangles,
        shared,
    }
}

/// Up to eight values as lanes (the last one repeated past the end).
#[inline]
fn lanes_of<T>(v: &[T]) -> [&T; 8] {
    std::array::from_fn(|l| &v[l.min(v.len() - 1)])
}

/// The screen boxes of the first `n` of `eight`'s triangles, whose
/// `present` mask becomes the lanes that have one (the lanes to set up).
#[inline]
fn rects_of(
    boxes: &ScreenBoxes,
    eight: &mut EightTriangles,
    n: usize,
    view: &View,
    span: SampleSpan,
) -> [Option<PixelRect>; 8] {
    let rects = boxes.rects_eight(&eight.corners, &eight.vertices, n, view, span);
    eight.present = 0;
    for (l, rect) in rects.iter().enumerate() {
        eight.present |= u8::from(rect.is_some()) << l;
    }
    rects
}

/// Every drawable triangle set up by `setup` with its conservative screen
/// box: one item per triangle, in order (exactly sized, parallel collects of
/// eight at a time: no chunks to concatenate); `None` for the ones off
/// screen or edge-on.
fn setup_visible<'a, T: Stored>(
    scene: &'a PreparedScene,
    view: &'a View,
    span: SampleSpan,
    shared: T::Shared<'a>,
    setup: impl SetupEight<'a, T>,
) -> Setups<'a, T> {
    let boxes = ScreenBoxes::new(scene, view);
    let corners = &scene.scene.mesh.triangles;
    let eights = (scene.drawable.par_chunks(8).enumerate()).map(|(chunk, ids)| {
        // The slot-ordered corners are scattered in id order: the next
        // eight triangles' are on their way while these are set up.
        let next = scene.drawable.get((chunk + 1) * 8..).unwrap_or_default();
        for &id in next.iter().take(8) {
            if let Some(corners) = scene.slot_corners.get(scene.slot_of[id as usize] as usize) {
                simd::prefetch(corners);
            }
        }
        let id = lanes_of(ids).map(|&id| id as usize);
        let mut eight = EightTriangles {
            corners: id.map(|id| &scene.slot_corners[scene.slot_of[id] as usize]),
            vertices: id.map(|id| corners[id]),
            present: 0,
        };
        let rects = rects_of(&boxes, &mut eight, ids.len(), view, span);
        paired(rects, lanes_of(ids), setup(&eight, view))
    });
    flattened(eights.unzip(), scene.drawable.len(), shared)
}
