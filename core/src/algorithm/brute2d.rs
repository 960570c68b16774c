//! `2dr-brute`: the classic pipeline (paper §3.1). Transform to camera space, clip
//! against the near plane and a guard band (Sutherland–Hodgman), project, set up
//! 2D edge functions and test every pixel of the bounding box, with the top-left
//! rule and a perspective-correct w-buffer.

use std::time::Instant;

use rayon::prelude::*;

use super::PixelRect;
use super::bands::{BoxedTriangle, rasterize_boxes};
use crate::camera::View;
use crate::clip::{clip_triangle, pipeline_planes};
use crate::edge::{ScreenVertex, Triangle2D};
use crate::framebuffer::Framebuffer;
use crate::prepared::PreparedScene;
use crate::stats::Stats;

struct Boxed2D {
    tri: Triangle2D,
    rect: PixelRect,
    id: u32,
}

impl BoxedTriangle for Boxed2D {
    fn rect(&self) -> PixelRect {
        self.rect
    }
    fn id(&self) -> u32 {
        self.id
    }
    #[inline(always)]
    fn sample(&self, x: f32, y: f32) -> Option<f32> {
        self.tri.sample(x, y)
    }
}

pub(crate) fn render_2dr_brute(
    scene: &PreparedScene,
    view: &View,
    fb: &mut Framebuffer,
    stats: &mut Stats,
) {
    let start = Instant::now();
    let planes = pipeline_planes(view.near, view.tan_half_x, view.tan_half_y);
    let items: Vec<Boxed2D> = scene
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
                inv_w: 0.0,
            }; crate::clip::MAX_CLIPPED];
            for (s, c) in screen.iter_mut().zip(poly.as_slice()) {
                let (x, y) = view.project(*c);
                *s = ScreenVertex {
                    x,
                    y,
                    inv_w: 1.0 / c.z,
                };
            }
            // 3. Fan-triangulate and set up each piece.
            for k in 1..poly.len - 1 {
                let Some(tri) = Triangle2D::setup(&[screen[0], screen[k], screen[k + 1]]) else {
                    continue;
                };
                let [x0, y0, x1, y1] = tri.bounds;
                if let Some(rect) = PixelRect::from_bounds(x0, y0, x1, y1, view.width, view.height)
                {
                    out.push(Boxed2D { tri, rect, id });
                }
            }
            out
        })
        .reduce(Vec::new, |mut a, mut b| {
            a.append(&mut b);
            a
        });
    stats.triangle_setups = items.len() as u64;
    stats.time_ms.setup = start.elapsed().as_secs_f64() * 1e3;

    let start = Instant::now();
    rasterize_boxes(&items, fb);
    stats.time_ms.coverage = start.elapsed().as_secs_f64() * 1e3;
}
