//! Setup of the 3D family (paper §3.2) and of homogeneous 2D rasterization: edge
//! functions with no projection and no clipping; a conservative screen box only
//! bounds the search.

use glam::Vec3;
use rayon::prelude::*;

use super::PixelRect;
use super::tiles::Placed;
use crate::aa::SampleSpan;
use crate::camera::View;
use crate::clip::{ClipPlane, clip_triangle};
use crate::edge::{
    CurvedTriangle, EightTriangles, HomogeneousVertex, Triangle3D, Triangle3D64,
    setup_homogeneous_from,
};
use crate::prepared::PreparedScene;

/// Every drawable triangle with samples on screen, set up with 3D edge functions.
pub(crate) fn setup_3d<'a>(
    scene: &'a PreparedScene,
    view: &'a View,
    span: SampleSpan,
) -> Vec<Option<Placed<Triangle3D<'a>>>> {
    setup_visible(scene, view, span, Triangle3D::setup_eight)
}

/// [`setup_3d`] in f64.
pub(crate) fn setup_3d_f64(
    scene: &PreparedScene,
    view: &View,
    span: SampleSpan,
) -> Vec<Option<Placed<Triangle3D64>>> {
    setup_visible(scene, view, span, one_by_one(Triangle3D64::setup))
}

/// Every drawable triangle with samples on a non-planar viewport, set up with 3D
/// edge functions evaluated per sample direction (paper §3.5).
pub(crate) fn setup_curved(
    scene: &PreparedScene,
    view: &View,
    span: SampleSpan,
) -> Vec<Option<Placed<CurvedTriangle>>> {
    setup_visible(scene, view, span, one_by_one(CurvedTriangle::setup))
}

/// Every drawable triangle with samples on screen, set up for homogeneous 2D
/// rasterization (no clipping). Every vertex is transformed to homogeneous
/// pixel coordinates once (as a vertex shader would), not once per triangle.
pub(crate) fn setup_homogeneous<'a>(
    scene: &'a PreparedScene,
    view: &'a View,
    span: SampleSpan,
) -> Vec<Option<Placed<Triangle3D<'a>>>> {
    let points: Vec<HomogeneousVertex> = (scene.scene.mesh.positions.par_iter())
        .map(|&p| HomogeneousVertex::of(p, view))
        .collect();
    let setup = |t: &EightTriangles<'a>, view: &'a View| {
        t.each(|l| {
            let vertices = t.vertices[l].map(|v| points[v as usize]);
            setup_homogeneous_from(t.corners[l], vertices, view)
        })
    };
    setup_visible(scene, view, span, setup)
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

/// A BVH slot's triangle's screen box and id (`None`: nothing to test).
pub(crate) type SlotBox = Option<(PixelRect, u32)>;

/// Per BVH slot, its triangle's conservative screen box and id, and apart
/// from them its edge functions — so a ray caster reads the small box first
/// and the edge functions only where the box holds its rays. `None` (in
/// both) for a triangle off screen or edge-on.
pub(crate) struct SlotSetups<T> {
    pub boxes: Vec<SlotBox>,
    pub triangles: Vec<Option<T>>,
}

/// Every BVH slot's triangle set up by `setup` with its conservative screen
/// box, in slot order (from the scene's slot-ordered copies of positions and
/// vertex indices: memory read in order), eight slots at a time.
pub(crate) fn setup_slots<'a, T: Send>(
    scene: &'a PreparedScene,
    view: &'a View,
    span: SampleSpan,
    setup: impl SetupEight<'a, T>,
) -> SlotSetups<T> {
    let boxes = ScreenBoxes::new(scene, view);
    let chunks = (scene.slot_corners.par_chunks(8))
        .zip(scene.slot_vertices.par_chunks(8))
        .zip(scene.slot_triangles.par_chunks(8));
    let (boxes, triangles): (Vec<[SlotBox; 8]>, Vec<[Option<T>; 8]>) = chunks
        .map(|((p, vertices), ids)| {
            let (rects, present) =
                rects_of(p.len(), |l| boxes.rect(&p[l], vertices[l], view, span));
            let eight = EightTriangles {
                corners: lanes_of(p),
                vertices: lanes_of(vertices).map(|v| *v),
                present,
            };
            let triangles = setup(&eight, view);
            let mut boxes = [None; 8];
            for l in 0..p.len() {
                if triangles[l].is_some() {
                    boxes[l] = rects[l].map(|rect| (rect, ids[l]));
                }
            }
            (boxes, triangles)
        })
        .unzip();
    let (mut boxes, mut triangles) = (boxes.into_flattened(), triangles.into_flattened());
    boxes.truncate(scene.slot_triangles.len());
    triangles.truncate(scene.slot_triangles.len());
    SlotSetups { boxes, triangles }
}

/// Up to eight values as lanes (the last one repeated past the end).
#[inline]
fn lanes_of<T>(v: &[T]) -> [&T; 8] {
    std::array::from_fn(|l| &v[l.min(v.len() - 1)])
}

/// The screen boxes `rect(l)` of the first `n` lanes, and the mask of the
/// lanes that have one (the lanes to set up).
#[inline]
fn rects_of(n: usize, rect: impl Fn(usize) -> Option<PixelRect>) -> ([Option<PixelRect>; 8], u8) {
    let (mut rects, mut present) = ([None; 8], 0u8);
    for (l, slot) in rects.iter_mut().enumerate().take(n) {
        *slot = rect(l);
        present |= u8::from(slot.is_some()) << l;
    }
    (rects, present)
}

/// Every drawable triangle set up by `setup` with its conservative screen
/// box: one slot per triangle, in order (an exactly sized, parallel collect
/// of eight at a time: no chunks to concatenate); `None` for the ones off
/// screen or edge-on.
fn setup_visible<'a, T: Send>(
    scene: &'a PreparedScene,
    view: &'a View,
    span: SampleSpan,
    setup: impl SetupEight<'a, T>,
) -> Vec<Option<Placed<T>>> {
    let boxes = ScreenBoxes::new(scene, view);
    let corners = &scene.scene.mesh.triangles;
    let placed: Vec<[Option<Placed<T>>; 8]> = (scene.drawable.par_chunks(8))
        .map(|ids| {
            let id = lanes_of(ids).map(|&id| id as usize);
            let mut eight = EightTriangles {
                corners: id.map(|id| &scene.triangles[id]),
                vertices: id.map(|id| corners[id]),
                present: 0,
            };
            let (rects, present) = rects_of(ids.len(), |l| {
                boxes.rect(eight.corners[l], eight.vertices[l], view, span)
            });
            eight.present = present;
            let mut placed = [const { None }; 8];
            for (l, tri) in setup(&eight, view).into_iter().enumerate() {
                if let (Some(tri), Some(rect)) = (tri, rects[l]) {
                    placed[l] = Some(Placed {
                        tri,
                        rect,
                        id: ids[l],
                    });
                }
            }
            placed
        })
        .collect();
    let mut placed = placed.into_flattened();
    placed.truncate(scene.drawable.len());
    placed
}

/// A conservative screen box for the part of the triangle at `w ≥ near`: the
/// vertices (clipped at slightly less than `near` where the triangle reaches
/// nearer) projected, padded by 1/16 pixel plus a relative 2⁻¹⁶ so that rounding
/// in the projection never cuts off a sample the 3D edge functions cover.
/// Non-planar viewports: the bounds of the triangle's cap of directions
/// ([`crate::camera::SphereMap::bounds_of`]), padded by a pixel. The pixels
/// returned are those with a sample (at offsets `span`) in the box.
pub(crate) fn screen_rect(p: &[Vec3; 3], view: &View, span: SampleSpan) -> Option<PixelRect> {
    if let Some(map) = &view.sphere {
        let [x0, y0, x1, y1] = map.bounds_of(&p.map(|v| view.to_camera_f64(v)));
        return PixelRect::from_bounds(
            (x0 - 1.0) as f32,
            (y0 - 1.0) as f32,
            (x1 + 1.0) as f32,
            (y1 + 1.0) as f32,
            view.width,
            view.height,
            span,
        );
    }
    let near_bound = near_bound(view);
    let cam = [
        view.to_camera(p[0]),
        view.to_camera(p[1]),
        view.to_camera(p[2]),
    ];
    let mut image_box = ImageBox::EMPTY;
    if cam.iter().all(|c| c.z >= near_bound) {
        cam.into_iter()
            .for_each(|c| image_box.grow(view.project(c)));
    } else {
        let cam = p.map(|v| view.to_camera_f64(v));
        let poly = clip_triangle(cam, &[ClipPlane::near(f64::from(near_bound))])?;
        for &c in poly.as_slice() {
            let (x, y) = view.project_f64(c);
            image_box.grow((x as f32, y as f32));
        }
    }
    image_box.pixels(view, span)
}

/// Triangles reaching nearer than this are clipped for their screen box:
/// slightly less than `near`, so rounding never cuts off a sample at `near`.
fn near_bound(view: &View) -> f32 {
    view.near * (1.0 - 1.0 / 1024.0)
}

/// [`screen_rect`] of every triangle of one view, with planar views'
/// vertices projected once (not once per triangle using them): the image
/// point of every mesh vertex, `None` for vertices nearer than [`near_bound`].
pub(crate) struct ScreenBoxes {
    points: Option<Vec<Option<(f32, f32)>>>,
}

impl ScreenBoxes {
    pub(crate) fn new(scene: &PreparedScene, view: &View) -> ScreenBoxes {
        let near_bound = near_bound(view);
        let points = view.sphere.is_none().then(|| {
            scene
                .scene
                .mesh
                .positions
                .par_iter()
                .map(|&p| {
                    let c = view.to_camera(p);
                    (c.z >= near_bound).then(|| view.project(c))
                })
                .collect()
        });
        ScreenBoxes { points }
    }

    /// [`screen_rect`] of the triangle with positions `p` at mesh vertices
    /// `vertices` (planar views read the vertices' projections).
    #[inline]
    pub(crate) fn rect(
        &self,
        p: &[Vec3; 3],
        vertices: [u32; 3],
        view: &View,
        span: SampleSpan,
    ) -> Option<PixelRect> {
        let Some(points) = &self.points else {
            return screen_rect(p, view, span);
        };
        let points = vertices.map(|v| points[v as usize]);
        // Every vertex nearer than the bound: so is every point of the
        // triangle, which has no sample at `w ≥ near`.
        if points.iter().all(Option::is_none) {
            return None;
        }
        let mut image_box = ImageBox::EMPTY;
        for point in points {
            match point {
                Some(point) => image_box.grow(point),
                // Reaches nearer than near: clipped.
                None => return screen_rect(p, view, span),
            }
        }
        image_box.pixels(view, span)
    }
}

/// A box of image points.
#[derive(Clone, Copy, Debug)]
struct ImageBox {
    min: [f32; 2],
    max: [f32; 2],
}

impl ImageBox {
    const EMPTY: ImageBox = ImageBox {
        min: [f32::INFINITY; 2],
        max: [f32::NEG_INFINITY; 2],
    };

    #[inline]
    fn grow(&mut self, (x, y): (f32, f32)) {
        self.min = [self.min[0].min(x), self.min[1].min(y)];
        self.max = [self.max[0].max(x), self.max[1].max(y)];
    }

    /// The pixels with a sample in the box, padded by 1/16 pixel plus a
    /// relative 2⁻¹⁶ against rounding in the projection.
    fn pixels(self, view: &View, span: SampleSpan) -> Option<PixelRect> {
        let (min, max) = (self.min, self.max);
        let magnitude = min[0]
            .abs()
            .max(min[1].abs())
            .max(max[0].abs())
            .max(max[1].abs());
        let pad = 1.0 / 16.0 + magnitude / 65536.0;
        PixelRect::from_bounds(
            min[0] - pad,
            min[1] - pad,
            max[0] + pad,
            max[1] + pad,
            view.width,
            view.height,
            span,
        )
    }
}
