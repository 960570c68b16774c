//! Setup of the 2D family (paper §3.1): transform to camera space, clip against
//! the near plane and a guard band (Sutherland–Hodgman), project, set up 2D edge
//! functions (top-left rule, perspective-correct w) per piece of the clipped
//! polygon — in f32 ([`Triangle2D`]) or on snapped vertices in fixed point
//! ([`Triangle2DFixed`]).

use rayon::prelude::*;

use super::PixelRect;
use super::tiles::Placed;
use crate::aa::SampleSpan;
use crate::camera::View;
use crate::clip::{
    ClipPlane, GUARD_BAND, MAX_CLIPPED, clip_triangle, fixed_guard_band, pipeline_planes,
};
use crate::edge::{ScreenVertex, Triangle2D, Triangle2DFixed};
use crate::prepared::PreparedScene;

/// Every drawable triangle, clipped, projected and set up with f32 edge
/// functions; pieces without samples on screen are dropped.
pub(crate) fn setup_2d(
    scene: &PreparedScene,
    view: &View,
    span: SampleSpan,
) -> Vec<Option<Placed<Triangle2D>>> {
    let affine = view.is_orthographic();
    setup_pieces(scene, view, span, [GUARD_BAND; 2], |v| {
        let t = Triangle2D::setup(v, affine, view.width, view.height)?;
        Some((t, t.bounds))
    })
}

/// As [`setup_2d`], with vertices snapped to 1/256 pixel and exact edge
/// functions, and a guard band as wide as fixed point allows (clipping moves
/// edges by up to half a snapping step; hardware clips as rarely).
pub(crate) fn setup_2d_fixed(
    scene: &PreparedScene,
    view: &View,
    span: SampleSpan,
) -> Vec<Option<Placed<Triangle2DFixed>>> {
    let affine = view.is_orthographic();
    setup_pieces(scene, view, span, fixed_guard_band(view), |v| {
        let t = Triangle2DFixed::setup(v, affine)?;
        Some((t, t.bounds))
    })
}

/// Clips (the guard band `guard` in units of the half-extents), projects and
/// fan-triangulates every drawable triangle; `make` sets up each piece and
/// gives its pixel bounds `[min_x, min_y, max_x, max_y]`. One slot per drawable
/// triangle holds its first piece (an exactly sized, parallel collect written
/// in place); the further pieces of the few triangles clipping cuts into
/// several follow, set up again in a second, small pass.
fn setup_pieces<T: Send>(
    scene: &PreparedScene,
    view: &View,
    span: SampleSpan,
    guard: [f32; 2],
    make: impl Fn(&[ScreenVertex; 3]) -> Option<(T, [f32; 4])> + Sync,
) -> Vec<Option<Placed<T>>> {
    let planes = pipeline_planes(view, guard);
    let pieces = |id: u32| pieces_of(scene, view, span, &planes, &make, id);
    let (mut placed, more): (Vec<Option<Placed<T>>>, Vec<bool>) = scene
        .drawable
        .par_iter()
        .map(|&id| {
            let mut pieces = pieces(id).into_iter().flatten();
            (pieces.next(), pieces.next().is_some())
        })
        .unzip();
    let rest: Vec<Option<Placed<T>>> = scene
        .drawable
        .par_iter()
        .zip(&more)
        .filter(|&(_, &more)| more)
        .flat_map_iter(|(&id, _)| pieces(id).into_iter().flatten().skip(1).map(Some))
        .collect();
    placed.extend(rest);
    placed
}

/// The set-up pieces of triangle `id` after clipping and fan triangulation,
/// in fan order (`None` where a piece has no samples on screen).
fn pieces_of<T>(
    scene: &PreparedScene,
    view: &View,
    span: SampleSpan,
    planes: &[ClipPlane],
    make: &impl Fn(&[ScreenVertex; 3]) -> Option<(T, [f32; 4])>,
    id: u32,
) -> [Option<Placed<T>>; MAX_CLIPPED - 2] {
    let affine = view.is_orthographic();
    let mut pieces: [Option<Placed<T>>; MAX_CLIPPED - 2] = std::array::from_fn(|_| None);
    // 1. Transform and clip.
    let p = &scene.triangles[id as usize];
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
    for (s, c) in screen.iter_mut().zip(poly.as_slice()) {
        let (x, y) = view.project_f64(*c);
        *s = ScreenVertex {
            x: x as f32,
            y: y as f32,
            q: (if affine { c.z } else { 1.0 / c.z }) as f32,
        };
    }
    // 3. Fan-triangulate and set up each piece.
    for k in 1..poly.len - 1 {
        let Some((tri, [x0, y0, x1, y1])) = make(&[screen[0], screen[k], screen[k + 1]]) else {
            continue;
        };
        if let Some(rect) = PixelRect::from_bounds(x0, y0, x1, y1, view.width, view.height, span) {
            pieces[k - 1] = Some(Placed { tri, rect, id });
        }
    }
    pieces
}
