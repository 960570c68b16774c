//! `raycast`: the ray-casting end of the continuum. One ray per pixel walks the
//! CWBVH front to back; each leaf triangle is tested with the *same* 3D edge
//! function coefficients and the same [`Triangle3D::sample`] as `3dr-brute`, so
//! the two agree bit for bit (obvhs's own triangle test is not watertight and is
//! not used).

use std::time::Instant;

use rayon::prelude::*;

use glam::Vec3;

use crate::camera::{View, pixel_center};
use crate::edge::Coverage;
use crate::framebuffer::{BACKGROUND, Framebuffer, wins_depth_test};
use crate::prepared::PreparedScene;
use crate::stats::Stats;

/// Nodes are culled only when entered beyond the best hit's `w` times this: the
/// computed `w` of a triangle can differ from the exact distance the box test
/// sees by a few ulps, and a node holding an equal-`w` triangle with a smaller id
/// must still be visited.
const CULL_MARGIN: f32 = 1.0 + 1.0 / 1024.0;

const BAND_ROWS: u32 = 4;

/// Casts one ray per pixel; `setup` gives the same triangles the 3D rasterizers
/// of this viewport use.
pub(crate) fn render_raycast<T: Coverage + Send + Sync>(
    scene: &PreparedScene,
    view: &View,
    fb: &mut Framebuffer,
    stats: &mut Stats,
    setup: impl Fn(&[Vec3; 3], &View) -> Option<T> + Sync,
) {
    // 1. Setup: the 3D edge functions of every drawable triangle for this view.
    let start = Instant::now();
    let setups: Vec<Option<T>> = scene
        .slot_triangles
        .par_iter()
        .map(|&id| setup(&scene.triangles[id as usize], view))
        .collect();
    stats.triangle_setups = setups.iter().filter(|s| s.is_some()).count() as u64;
    stats.time_ms.setup = start.elapsed().as_secs_f64() * 1e3;

    // 2. One ray per pixel, bands of rows in parallel.
    let start = Instant::now();
    let nodes: u64 = fb
        .bands_mut(BAND_ROWS)
        .into_par_iter()
        .map(|band| {
            let mut nodes = 0;
            for y in band.y0..band.y1 {
                let yc = pixel_center(y);
                for x in 0..band.width {
                    let xc = pixel_center(x);
                    let (mut best_w, mut best_id) = (f32::INFINITY, BACKGROUND);
                    let (mut evals, mut covered) = (0u32, 0u32);
                    // No ray outside the viewport (the parabolic disc): background.
                    let Some((origin, direction)) = view.ray(xc, yc) else {
                        continue;
                    };
                    nodes += scene.bvh.walk(origin, direction, |k| {
                        if let Some(tri) = &setups[k as usize] {
                            evals += 1;
                            if let Some(w) = tri.sample(xc, yc) {
                                covered += 1;
                                let id = scene.slot_triangles[k as usize];
                                if wins_depth_test(w, id, best_w, best_id) {
                                    best_w = w;
                                    best_id = id;
                                }
                            }
                        }
                        best_w * CULL_MARGIN
                    });
                    let i = band.index(x, y);
                    band.edge_evals[i] = evals;
                    band.coverage_writes[i] = covered;
                    band.depth[i] = best_w;
                    band.triangle_id[i] = best_id;
                }
            }
            nodes
        })
        .sum();
    stats.bvh_nodes_visited = nodes;
    stats.time_ms.traversal = start.elapsed().as_secs_f64() * 1e3;
}
