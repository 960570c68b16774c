//! Setup of the 2D family (paper §3.1): transform to camera space, clip against
//! the near plane and a guard band (Sutherland–Hodgman), project, set up 2D edge
//! functions (top-left rule, perspective-correct w) per piece of the clipped polygon.

use rayon::prelude::*;

use super::PixelRect;
use super::tiles::Placed;
use crate::aa::SampleSpan;
use crate::camera::View;
use crate::clip::{clip_triangle, pipeline_planes};
use crate::edge::{ScreenVertex, Triangle2D};
use crate::prepared::PreparedScene;

/// Every drawable triangle, clipped, projected and set up; pieces without
/// samples on screen are dropped.
pub(crate) fn setup_2d(
    scene: &PreparedScene,
    view: &View,
    span: SampleSpan,
) -> Vec<Placed<Triangle2D>> {
    let planes = pipeline_planes(view);
    let affine = view.is_orthographic();
    scene
        .drawable
        .par_iter()
        .fold(Vec::new, |mut out, &id| {
            // 1. Transform and clip.
            let p = &scene.triangles[id as usize];
            let cam = [
                view.to_camera(p[0]),
                view.to_camera(p[1]),
                view.to_camera(p[2]),
            ];
            let Some(poly) = clip_triangle(cam, &planes) else {
                return out;
            };
            // 2. Project (the polygon has at most 8 vertices).
            let mut screen = [ScreenVertex {
                x: 0.0,
                y: 0.0,
                q: 0.0,
            }; crate::clip::MAX_CLIPPED];
            for (s, c) in screen.iter_mut().zip(poly.as_slice()) {
                let (x, y) = view.project(*c);
                *s = ScreenVertex {
                    x,
                    y,
                    q: if affine { c.z } else { 1.0 / c.z },
                };
            }
            // 3. Fan-triangulate and set up each piece.
            for k in 1..poly.len - 1 {
                let Some(tri) = Triangle2D::setup(
                    &[screen[0], screen[k], screen[k + 1]],
                    affine,
                    view.width,
                    view.height,
                ) else {
                    continue;
                };
                let [x0, y0, x1, y1] = tri.bounds;
                if let Some(rect) =
                    PixelRect::from_bounds(x0, y0, x1, y1, view.width, view.height, span)
                {
                    out.push(Placed { tri, rect, id });
                }
            }
            out
        })
        .reduce(Vec::new, |mut a, mut b| {
            a.append(&mut b);
            a
        })
}
