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

use std::time::Instant;

use rayon::prelude::*;

use super::{Pass, TileContext, setup2d};
use crate::framebuffer::Framebuffer;
use crate::gpu::{ComputeSamples, TriWords, atomics, gpu};
use crate::ground::FieldError;
use crate::pipeline::ComputeKind;
use crate::prepared::PreparedScene;
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
    let clip = |ids: &[u32]| -> Vec<TriWords> {
        setup2d::clipped_pieces(scene, view, pattern.span, ids)
            .into_iter()
            .map(|(t, rect, id)| {
                let (rows, flags) = t.gpu_rows();
                let mut words = [0u32; 28];
                for (k, v) in rows.iter().flatten().enumerate() {
                    words[k] = v.to_bits();
                }
                words[24] = id;
                words[25] = rect.x0 | (rect.y0 << 16);
                words[26] = rect.x1 | (rect.y1 << 16);
                words[27] = flags;
                words
            })
            .collect()
    };
    let samples = gpu
        .compute(
            mesh,
            kind,
            view,
            pattern,
            (atomics(), context.depth_test),
            &clip,
        )
        .map_err(failed)?;
    let times = samples.times.clone();
    stats.triangle_setups = samples.setups;
    // The frame's stages in host time, so that they add up to the total
    // (the device's own per pass are in `stats.gpu`).
    let [setup, binning, raster] = samples.wall;
    stats.time_ms.setup = upload_ms + setup + binning;
    stats.time_ms.coverage = raster;
    stats.time_ms.store += times.readback;
    stats.gpu = Some(times);

    // Resolve and shade in bands of rows, in parallel, from the frame-sized
    // read-back.
    let start = Instant::now();
    let mut pass = Pass::default();
    let rects = fb.tile_rects(view.width, BAND);
    let done: Vec<_> = pass
        .planes(fb, &rects)
        .into_par_iter()
        .map_init(
            || None,
            |cache, planes| {
                context.run_tile(cache, planes, |tile| {
                    copy_band(&samples, tile, view.width, view.height);
                    Default::default()
                })
            },
        )
        .collect();
    pass.add(done);
    let c = &mut pass.counters;
    [c.tiles_tested, c.tiles_accepted, c.tiles_rejected] = samples.tiles;
    let [_, resolve, shading] = pass.split(start);
    (stats.time_ms.resolve, stats.time_ms.shading) = (resolve, shading);
    Ok(pass)
}

/// The tile's samples from the frame-sized, layer-major read-back.
fn copy_band(
    samples: &ComputeSamples,
    tile: &mut crate::framebuffer::TileBuffer,
    width: u32,
    height: u32,
) {
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
