//! The GPU compute algorithms (`gpu-2dr`, `gpu-2dr-homogeneous`, `gpu-3dr`,
//! `gpu-3dr-binned`; paper §5) on the CPU's side: the kernels run in
//! [`crate::gpu`], and their samples — triangle id, depth and coverage
//! writes per stored sample, edge evaluations per pixel — come back into the
//! frame through the same per-tile resolve and shading as every CPU
//! algorithm's, so colours, maps, hashes and counters mean the same.
//!
//! `gpu-2dr` clips as the paper says hardware rarely needs to: the setup
//! kernel lists the triangles that cross the near plane or the guard band,
//! and the CPU clips those in f64 and sets up their pieces exactly as
//! `2dr-brute` does ([`super::setup2d::clipped_pieces`]); the pieces are
//! rasterized by the same kernel as the rest.
//!
//! The 3D and homogeneous kernels decide exactly, as the CPU's 3D family
//! does (`edge/edge3d.rs`, "Exact decisions"), by leaving to the CPU what
//! f32 cannot be sure of: a triangle whose determinant lies within its
//! error bound is set up here with the exact sign ([`set_up_exactly`]), and
//! a sample whose edge value lies within the edge's tolerance is decided
//! here by the CPU's own `Coverage::sample` ([`decide_unsure`]) and merged
//! by the kernels' rule. Every other decision is certain, so it is the
//! exact one too: a vertex on a sample's ray covers the sample once, in
//! fans of any size.

use std::time::Instant;

use super::{Pass, TileContext, setup2d};
use crate::aa::SamplePattern;
use crate::camera::View;
use crate::edge::{Coverage, HomogeneousVertex, Shared3D, Triangle3D, setup_homogeneous_from};
use crate::framebuffer::{Framebuffer, TileBuffer, wins_depth_test};
use crate::gpu::{ComputeSamples, TriWords, atomics, gpu};
use crate::ground::{FieldError, PixelRect, SampleSpan};
use crate::pipeline::ComputeKind;
use crate::prepared::PreparedScene;
use crate::screen_boxes::ScreenBoxes;
use crate::stats::Stats;

/// Rows of pixels per resolve band.
const BAND: u32 = 16;

/// Renders with the compute kernels of `kind`, then resolves and shades.
pub(crate) fn render_compute(
    scene: &PreparedScene,
    kind: ComputeKind,
    context: &TileContext,
    fb: &mut Framebuffer,
    stats: &mut Stats,
) -> Result<Pass, FieldError> {
    let failed = |e: crate::gpu::GpuError| FieldError::new(e.field(), e.to_string());
    let (view, pattern) = (context.view, context.pattern);
    let start = Instant::now();
    let gpu = gpu().map_err(failed)?;
    let mesh = gpu.mesh(scene).map_err(failed)?;
    let upload_ms = start.elapsed().as_secs_f64() * 1e3;
    let cpu_setup = |ids: &[u32]| -> Vec<TriWords> {
        match kind {
            ComputeKind::TwoD => setup2d::clipped_pieces(scene, view, pattern.span, ids)
                .into_iter()
                .map(|(t, rect, id)| {
                    let (rows, flags) = t.gpu_rows();
                    record(rows.iter().flatten(), id, rect, flags)
                })
                .collect(),
            _ => set_up_exactly(scene, kind, view, pattern.span, ids),
        }
    };
    let mut samples = gpu
        .compute(
            mesh,
            kind,
            view,
            pattern,
            (atomics(), context.depth_test),
            &cpu_setup,
        )
        .map_err(failed)?;
    let start = Instant::now();
    let precise = crate::edge::precise_tests();
    decide_unsure(scene, kind, view, pattern, context.depth_test, &mut samples);
    let precise = [0, 1].map(|k| crate::edge::precise_tests()[k] - precise[k]);
    let exact_ms = start.elapsed().as_secs_f64() * 1e3;
    let times = samples.times.clone();
    stats.triangle_setups = samples.setups;
    // The frame's stages in host time, so that they add up to the total
    // (the device's own per pass are in `stats.gpu`).
    let [setup, binning, raster] = samples.wall;
    stats.time_ms.setup = upload_ms + setup + binning;
    stats.time_ms.coverage = raster + exact_ms;
    stats.time_ms.store += times.readback;
    stats.gpu = Some(times);

    // Resolve and shade in bands of rows, in parallel, from the frame-sized
    // read-back.
    let start = Instant::now();
    let mut pass = resolve_bands(context, fb, |tile| {
        copy_band(&samples, tile, view.width, view.height);
    });
    let c = &mut pass.counters;
    [c.tiles_tested, c.tiles_accepted, c.tiles_rejected] = samples.tiles;
    [c.edge_tests_f64, c.edge_tests_exact] = precise;
    let [_, resolve, shading] = pass.split(start);
    (stats.time_ms.resolve, stats.time_ms.shading) = (resolve, shading);
    Ok(pass)
}

/// A frame-sized read-back resolved and shaded in bands of [`BAND`] rows in
/// parallel, `copy` filling each band's tile from it.
pub(super) fn resolve_bands(
    context: &TileContext,
    fb: &mut Framebuffer,
    copy: impl Fn(&mut TileBuffer) + Sync,
) -> Pass {
    let mut pass = Pass::default();
    let size = [context.view.width, BAND];
    let done = context.run_tiles(&mut pass, fb, size, |_, (), tile| {
        copy(tile);
        crate::stats::RasterCounters::default()
    });
    pass.add(done);
    pass
}

/// A set-up triangle's GPU record (`Tri` in compute.wgsl): its rows, then
/// the id, its pixel box and the flags.
fn record<'f>(
    rows: impl Iterator<Item = &'f f32>,
    id: u32,
    rect: PixelRect,
    flags: u32,
) -> TriWords {
    let mut words = [0u32; 28];
    for (k, v) in rows.enumerate() {
        words[k] = v.to_bits();
    }
    words[24] = id;
    words[25] = rect.x0 | (rect.y0 << 16);
    words[26] = rect.x1 | (rect.y1 << 16);
    words[27] = flags;
    words
}

/// The CPU's 3D or homogeneous setup of triangle `p` (`None`: no triangle,
/// e.g. an exactly zero determinant).
fn set_up_on_cpu(kind: ComputeKind, p: &[glam::Vec3; 3], view: &View) -> Option<Triangle3D> {
    match kind {
        ComputeKind::Homogeneous => {
            setup_homogeneous_from(p.map(|v| HomogeneousVertex::of(v, view)), view)
        }
        _ => Triangle3D::setup(p, view),
    }
}

/// The GPU records of the triangles `ids`, which the 3D or homogeneous
/// setup kernel listed because the f32 sign of their determinant was not
/// certain: set up by the CPU's code, which takes the exact sign there
/// (`edge3d::orientation`), with the CPU's conservative screen boxes.
fn set_up_exactly(
    scene: &PreparedScene,
    kind: ComputeKind,
    view: &View,
    span: SampleSpan,
    ids: &[u32],
) -> Vec<TriWords> {
    let corners: Vec<[glam::Vec3; 3]> = ids.iter().map(|&id| scene.triangle(id)).collect();
    let flat: Vec<glam::Vec3> = corners.iter().flatten().copied().collect();
    let boxes = ScreenBoxes::of(&flat, view);
    (ids.iter().zip(&corners).enumerate())
        .filter_map(|(k, (&id, p))| {
            let t = set_up_on_cpu(kind, p, view)?;
            let k = 3 * k as u32;
            let rect = boxes.rect(p, [k, k + 1, k + 2], view, span)?;
            let (rows, flags) = t.gpu_rows(view.is_orthographic());
            Some(record(rows.iter().flatten(), id, rect, flags))
        })
        .collect()
}

/// Decides the samples the kernels were unsure of with the CPU's
/// `Coverage::sample` of each triangle (exact near edges) and merges the
/// covered ones as the kernels do: nearest, an exact depth tie to the
/// smaller id (with the depth test off, the smallest id).
fn decide_unsure(
    scene: &PreparedScene,
    kind: ComputeKind,
    view: &View,
    pattern: &SamplePattern,
    depth_test: bool,
    samples: &mut ComputeSamples,
) {
    let mut unsure = std::mem::take(&mut samples.unsure);
    unsure.sort_unstable();
    let pixels = view.width as usize * view.height as usize;
    for group in unsure.chunk_by(|a, b| a[0] == b[0]) {
        let id = group[0][0];
        let p = [scene.triangle(id)];
        let Some(t) = set_up_on_cpu(kind, &p[0], view) else {
            continue;
        };
        let homogeneous = kind == ComputeKind::Homogeneous;
        let shared = Shared3D::of_corners(view, homogeneous, &p);
        let t = t.bind(&shared, 0, id);
        for &[_, i] in group {
            let i = i as usize;
            let pixel = i % pixels;
            let [ox, oy] = pattern.positions[i / pixels];
            let x = (pixel % view.width as usize) as f32 + ox;
            let y = (pixel / view.width as usize) as f32 + oy;
            let Some(w) = t.sample(x, y) else {
                continue;
            };
            samples.coverage_writes[i] += 1;
            // An empty sample holds the background id at +∞.
            let (held, held_w) = (samples.triangle_id[i], samples.depth[i]);
            let wins = if depth_test {
                wins_depth_test(w, id, held_w, held)
            } else {
                id < held
            };
            if wins {
                (samples.triangle_id[i], samples.depth[i]) = (id, w);
            }
        }
    }
}

/// The tile's samples from the frame-sized, layer-major read-back.
fn copy_band(samples: &ComputeSamples, tile: &mut TileBuffer, width: u32, height: u32) {
    let frame = width as usize * height as usize;
    let (x0, x1) = (tile.x0 as usize, tile.x1 as usize);
    for y in tile.y0..tile.y1 {
        let row = y as usize * width as usize;
        let local = tile.index(tile.x0, y);
        let n = x1 - x0;
        tile.edge_evals[local..local + n].copy_from_slice(&samples.edge_evals[row + x0..row + x1]);
        for s in 0..tile.pattern.stored {
            let (from, to) = (s * frame + row + x0, s * tile.pixels + local);
            tile.triangle_id[to..to + n].copy_from_slice(&samples.triangle_id[from..from + n]);
            tile.depth[to..to + n].copy_from_slice(&samples.depth[from..from + n]);
            tile.coverage_writes[to..to + n]
                .copy_from_slice(&samples.coverage_writes[from..from + n]);
        }
    }
}
