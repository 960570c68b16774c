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
use crate::edge::{self, CurvedTriangle, Triangle3D};
use crate::prepared::PreparedScene;

/// Every drawable triangle with samples on screen, set up with 3D edge functions.
pub(crate) fn setup_3d(
    scene: &PreparedScene,
    view: &View,
    span: SampleSpan,
) -> Vec<Placed<Triangle3D>> {
    setup_visible(scene, view, span, Triangle3D::setup)
}

/// Every drawable triangle with samples on a non-planar viewport, set up with 3D
/// edge functions evaluated per sample direction (paper §3.5).
pub(crate) fn setup_curved(
    scene: &PreparedScene,
    view: &View,
    span: SampleSpan,
) -> Vec<Placed<CurvedTriangle>> {
    setup_visible(scene, view, span, CurvedTriangle::setup)
}

/// Every drawable triangle with samples on screen, set up for homogeneous 2D
/// rasterization (no clipping).
pub(crate) fn setup_homogeneous(
    scene: &PreparedScene,
    view: &View,
    span: SampleSpan,
) -> Vec<Placed<Triangle3D>> {
    setup_visible(scene, view, span, edge::setup_homogeneous)
}

fn setup_visible<T: Send>(
    scene: &PreparedScene,
    view: &View,
    span: SampleSpan,
    setup: impl Fn(&[Vec3; 3], &View) -> Option<T> + Sync,
) -> Vec<Placed<T>> {
    scene
        .drawable
        .par_iter()
        .filter_map(|&id| {
            let p = &scene.triangles[id as usize];
            let rect = screen_rect(p, view, span)?;
            Some(Placed {
                tri: setup(p, view)?,
                rect,
                id,
            })
        })
        .collect()
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
    let near_bound = view.near * (1.0 - 1.0 / 1024.0);
    let cam = [
        view.to_camera(p[0]),
        view.to_camera(p[1]),
        view.to_camera(p[2]),
    ];
    let mut min = [f32::INFINITY; 2];
    let mut max = [f32::NEG_INFINITY; 2];
    let mut grow = |c: Vec3| {
        let (x, y) = view.project(c);
        min = [min[0].min(x), min[1].min(y)];
        max = [max[0].max(x), max[1].max(y)];
    };
    if cam.iter().all(|c| c.z >= near_bound) {
        cam.into_iter().for_each(&mut grow);
    } else {
        let plane = ClipPlane {
            k: Vec3::Z,
            offset: near_bound,
        };
        let poly = clip_triangle(cam, &[plane])?;
        poly.as_slice().iter().copied().for_each(&mut grow);
    }
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
