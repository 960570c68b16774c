//! `raycast`: the ray-casting end of the continuum. One ray per sample walks the
//! CWBVH front to back; each leaf triangle is tested with the *same* 3D edge
//! function coefficients ([`Triangle3D`](crate::edge::Triangle3D)) and the
//! same `Coverage::sample` as `3dr-brute`, so the two agree bit for bit
//! (obvhs's own triangle test is not watertight and is not used).

use std::time::Instant;

use glam::Vec3;

use super::tiles::Setups;
use super::{Pass, PixelRect, TileContext};
use crate::aa::SamplePattern;
use crate::bvh::{PACKET, PacketRays};
use crate::camera::View;
use crate::edge::{Coverage, Stored};
use crate::framebuffer::{BACKGROUND, Fragment, Framebuffer, TileBuffer, wins_depth_test};
use crate::prepared::PreparedScene;
use crate::prepared::is_see_through;
use crate::simd::{self, Lanes, Portable, count_eight};
use crate::stats::Stats;
use crate::trace::NodeOutcome;

/// Nodes are culled only when entered beyond the best hit's `w` times this: the
/// computed `w` of a triangle can differ from the exact distance the box test
/// sees by a few ulps, and a node holding an equal-`w` triangle with a smaller id
/// must still be visited.
const CULL_MARGIN: f32 = 1.0 + 1.0 / 1024.0;

/// Side of the pixel block of one group of rays.
const BLOCK: u32 = 4;
const _: () = assert!((BLOCK * BLOCK) as usize == PACKET);
/// 8-lane halves of a group of rays.
const HALVES: usize = PACKET.div_ceil(8);
const _: () = assert!(HALVES == 2 && BLOCK == 4);
// The halves of the largest packet (sixteen groups) fit a `u32`, bit per half.
const _: () = assert!(16 * HALVES <= 32);
/// Each lane's column and row in its group's 4×4 block, per half.
const LANE_X: [f32; 8] = [0.0, 1.0, 2.0, 3.0, 0.0, 1.0, 2.0, 3.0];
const LANE_Y: [[f32; 8]; HALVES] = [
    [0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
    [2.0, 2.0, 2.0, 2.0, 3.0, 3.0, 3.0, 3.0],
];

/// The pixel of lane `l` of the group at `corner`: `corner + (l % 4, l / 4)`.
#[inline(always)]
fn lane_pixel((x, y): (u32, u32), l: usize) -> (u32, u32) {
    (x + l as u32 % BLOCK, y + l as u32 / BLOCK)
}

/// Casts one ray per stored sample; `setup` gives the same triangles the 3D
/// rasterizers of this viewport use. Under CSAA the coverage-only positions are
/// decided as the rasterizers decide them: each triangle a stored ray found is
/// tested at every coverage position of the pixel.
pub(crate) fn render_raycast<'a, T: Stored>(
    scene: &'a PreparedScene,
    context: &TileContext<'a>,
    packet: u32,
    fb: &mut Framebuffer,
    stats: &mut Stats,
    setup: impl FnOnce() -> Setups<'a, T>,
) -> Pass {
    let view = context.view;
    // 1. Setup: the 3D edge functions of every triangle with samples on
    // screen, in BVH slot order, with the conservative screen box the
    // rasterizers bound their search with: a ray tests a triangle only inside it.
    // All of them, before the rays, rather than each the first time a packet
    // reaches it: a per-view cache that set up eight slots at a time on first
    // reach (a `OnceLock` per eight) made every scene slower, teapots 1.3×
    // (95 → 124 ms at 1080p on two threads). Its gathers of slot corners and
    // screen boxes, in the order rays reach them, miss the cache where this
    // pass streams them; and the packets reach most set-up triangles anyway
    // (teapots: 94% of those with a box, 79% with a sample in a packet's
    // block), so little setup is saved.
    let start = Instant::now();
    let setups = setup();
    stats.triangle_setups = setups.placed();
    stats.time_ms.setup = start.elapsed().as_secs_f64() * 1e3;

    // 2. Rays per sample, bands of rows in parallel, each resolved by its worker.
    let start = Instant::now();
    let mut pass = Pass::default();
    let bands = [fb.width, packet];
    let done = context.run_tiles(&mut pass, fb, bands, |_, (), tile| {
        // One ray group, four, or sixteen to a packet (`RAY_PACKETS`).
        match packet {
            4 => cast_band::<T, 1>(scene, view, &setups, tile),
            8 => cast_band::<T, 4>(scene, view, &setups, tile),
            _ => cast_band::<T, 16>(scene, view, &setups, tile),
        }
    });
    pass.add(done.into_iter().map(|finished| {
        stats.bvh_nodes_visited += finished.result;
        finished.map(|_| Default::default())
    }));
    let [traversal, resolve, shading] = pass.split(start);
    stats.time_ms.traversal = traversal;
    (stats.time_ms.resolve, stats.time_ms.shading) = (resolve, shading);
    pass
}

simd::dispatch! {
    /// [`cast_band_on`] on the lanes of this CPU.
    fn cast_band<T: Stored; const G: usize>(
        scene: &PreparedScene,
        view: &View,
        setups: &Setups<T>,
        tile: &mut TileBuffer,
    ) -> u64 => cast_band_on
}

/// Every stored sample of the band's pixels, cast as packets: the rays of one
/// sample position through the pixels of a square block of `G` groups of
/// 4×4 rays (one band of packets: the band is as tall as a packet) walk the
/// BVH together
/// ([`SceneBvh::walk_packet`](crate::bvh::SceneBvh::walk_packet)), each
/// ray tested on its own against every triangle the packet reaches, so each
/// finds exactly the hit its single walk would. Returns the BVH nodes
/// visited.
#[inline(always)]
fn cast_band_on<L: Lanes, T: Stored, const G: usize>(
    scene: &PreparedScene,
    view: &View,
    setups: &Setups<T>,
    tile: &mut TileBuffer,
) -> u64 {
    // Groups on a side of the packet, and its side in pixels.
    let columns = G.isqrt() as u32;
    let side = BLOCK * columns;
    let pattern = tile.pattern;
    let (stored, pixels) = (pattern.stored, tile.pixels);
    let mut nodes = 0;
    // The nodes the packets entered, when the render is traced.
    let mut trace_nodes: Option<Vec<u32>> = tile.trace.is_some().then(Vec::new);
    // Planar views: every ray leaves the eye (perspective) or its own
    // origin on the image plane (orthographic) along `View::direction`,
    // computed here for the packet eight lanes at a time.
    let planar = view.sphere.is_none();
    let perspective = planar && !view.is_orthographic();
    // Per group and lane: the BVH slot of each stored sample's triangle (CSAA).
    let mut slots = [[[0u32; 8]; PACKET]; G];
    // Each lane's pixel offset in its group's 4×4 block.
    let lane_x = L::from_array(LANE_X);
    let lane_y = [L::from_array(LANE_Y[0]), L::from_array(LANE_Y[1])];
    let width = (tile.x1 - tile.x0) as usize;
    for y in (tile.y0..tile.y1).step_by(side as usize) {
        for x in (tile.x0..tile.x1).step_by(side as usize) {
            // Each group's corner, and its pixels inside the tile (bit per
            // lane; all sixteen but at the band's right and bottom edges).
            let corner: [(u32, u32); G] = std::array::from_fn(|g| {
                let (gx, gy) = (g as u32 % columns, g as u32 / columns);
                (x + gx * BLOCK, y + gy * BLOCK)
            });
            let inside_tile = group_masks::<G>(tile.rect(), x, y);
            for (s, &[ox, oy]) in pattern.positions[..stored].iter().enumerate() {
                // Each group's samples as two 8-lane halves (lane `l` at
                // pixel `corner + (l % 4, l / 4)`: `px as f32 + ox`, exact
                // as the pixel's integer coordinates are), and the rays cast
                // (`cast`: bit per lane; none outside the viewport, e.g. the
                // parabolic disc: background). Lanes outside the tile hold
                // points that take no part.
                let mut rays = [[None; PACKET]; G];
                let mut xs = [[[0.0; 8]; HALVES]; G];
                let mut ys = [[[0.0; 8]; HALVES]; G];
                let mut cast = inside_tile;
                for g in 0..G {
                    let (cx, cy) = (corner[g].0 as f32, corner[g].1 as f32);
                    for half in 0..HALVES {
                        xs[g][half] = ((L::splat(cx) + lane_x) + L::splat(ox)).to_array();
                        ys[g][half] = ((L::splat(cy) + lane_y[half]) + L::splat(oy)).to_array();
                    }
                    if !planar {
                        for l in 0..PACKET {
                            if cast[g] >> l & 1 == 1 {
                                rays[g][l] = view.ray(xs[g][l / 8][l % 8], ys[g][l / 8][l % 8]);
                                cast[g] &= !(u16::from(rays[g][l].is_none()) << l);
                            }
                        }
                    }
                }
                let mut packet = [PacketRays::Rays(&rays[0]); G];
                for g in 0..G {
                    packet[g] = if perspective {
                        PacketRays::OneOrigin {
                            origin: view.eye,
                            directions: directions_lanes::<L>(view, &xs[g], &ys[g]),
                            present: cast[g],
                        }
                    } else if planar {
                        PacketRays::Planar {
                            origins: origins_lanes::<L>(view, &xs[g], &ys[g]),
                            directions: directions_lanes::<L>(view, &xs[g], &ys[g]),
                            present: cast[g],
                        }
                    } else {
                        PacketRays::Rays(&rays[g])
                    };
                }
                // Per group and lane, the nearest hit: its depth, triangle
                // id and BVH slot.
                let mut best_w = [[f32::INFINITY; PACKET]; G];
                let mut best_id = [[BACKGROUND; PACKET]; G];
                let mut best_slot = [[0u32; PACKET]; G];
                // Every ray of the packet tests every triangle it reaches
                // whose screen box holds its pixel.
                let (mut tested, mut covered) = ([[0u32; PACKET]; G], [[0u32; PACKET]; G]);
                // See-through triangles leave fragments, as in the rasterizers'
                // `TileBuffer::write`; the walk still culls beyond the nearest
                // opaque hit, behind which no fragment shows.
                let (x0, y0) = (tile.x0, tile.y0);
                let opacity = tile.opacity;
                let fragments = &mut tile.fragments;
                let entered = trace_nodes.as_mut();
                nodes += scene.bvh.walk_packet::<L, G>(&packet, entered, |k, cull| {
                    // The box first: most leaf triangles miss a packet's
                    // block. (A triangle with nothing to test has an empty
                    // box, which no block meets: one branch for both.)
                    let (rect, id) = setups.boxes[k as usize].unchecked();
                    if G > 1 && !overlaps(rect, x, y, side) {
                        return false;
                    }
                    let mut inside = group_masks::<G>(rect, x, y);
                    let mut any = 0;
                    for g in 0..G {
                        inside[g] &= cast[g];
                        any |= inside[g];
                    }
                    if any == 0 {
                        return false;
                    }
                    let Some(tri) = &setups.triangles[k as usize] else {
                        return false;
                    };
                    let tri = setups.bind(tri, k as usize, id);
                    let see_through = is_see_through(opacity, id);
                    let mut moved = false;
                    // The groups' halves with lanes to test, bit per half: a
                    // loop over those alone (a tiny triangle meets one or
                    // two), not an unpredictable branch on each of them.
                    let mut halves = 0u32;
                    for (c, four) in inside.chunks(4).enumerate() {
                        let groups = four.iter().rev().fold(0, |v, &m| v << 16 | u64::from(m));
                        halves |= nonzero_bytes(groups) << (8 * c);
                    }
                    while halves != 0 {
                        let h = halves.trailing_zeros() as usize;
                        halves &= halves - 1;
                        let (g, half) = (h / HALVES, h % HALVES);
                        let active = (inside[g] >> (8 * half)) as u8;
                        count_eight(tested.as_flattened_mut(), h * 8, active);
                        let (xs, ys) = (xs[g][half], ys[g][half]);
                        let (mut hits, depth) = tri.sample_points8::<L>(xs, ys, active);
                        count_eight(covered.as_flattened_mut(), h * 8, hits);
                        while hits != 0 {
                            let l = hits.trailing_zeros() as usize;
                            hits &= hits - 1;
                            let (w, lane) = (depth[l], half * 8 + l);
                            if see_through {
                                let (px, py) = lane_pixel(corner[g], lane);
                                let i = (py - y0) as usize * width + (px - x0) as usize;
                                fragments.push(Fragment {
                                    sample: (s * pixels + i) as u32,
                                    w,
                                    id,
                                });
                            } else if wins_depth_test(w, id, best_w[g][lane], best_id[g][lane]) {
                                (best_w[g][lane], best_id[g][lane]) = (w, id);
                                best_slot[g][lane] = k;
                                cull[g][lane] = w * CULL_MARGIN;
                                moved = true;
                            }
                        }
                    }
                    moved
                });
                // Each group's results into the tile, a row of four lanes at
                // a time where the row is in the tile (lanes not cast keep
                // no result: outside the tile, or without a ray).
                for g in 0..G {
                    let (cx, cy) = corner[g];
                    let first = (cy - y0) as usize * width + (cx - x0) as usize;
                    for r in 0..BLOCK as usize {
                        let row = (inside_tile[g] >> (r * 4)) & 0xf;
                        if row == 0 {
                            continue;
                        }
                        let (i, lanes) = (first + r * width, r * 4..r * 4 + 4);
                        let j = s * pixels + i;
                        if row == 0xf && cast[g] >> (r * 4) & 0xf == 0xf {
                            for (e, &t) in tile.edge_evals[i..i + 4]
                                .iter_mut()
                                .zip(&tested[g][lanes.clone()])
                            {
                                *e += t;
                            }
                            tile.coverage_writes[j..j + 4]
                                .copy_from_slice(&covered[g][lanes.clone()]);
                            tile.depth[j..j + 4].copy_from_slice(&best_w[g][lanes.clone()]);
                            tile.triangle_id[j..j + 4].copy_from_slice(&best_id[g][lanes]);
                        } else {
                            for (c, l) in lanes.enumerate() {
                                if cast[g] >> l & 1 == 1 {
                                    tile.edge_evals[i + c] += tested[g][l];
                                    tile.coverage_writes[j + c] = covered[g][l];
                                    (tile.depth[j + c], tile.triangle_id[j + c]) =
                                        (best_w[g][l], best_id[g][l]);
                                }
                            }
                        }
                    }
                    if pattern.has_coverage_only() {
                        for l in 0..PACKET {
                            slots[g][l][s] = best_slot[g][l];
                        }
                    }
                }
            }
            if pattern.has_coverage_only() {
                for g in 0..G {
                    for (l, slots) in slots[g].iter().enumerate() {
                        if inside_tile[g] >> l & 1 == 1 {
                            let p = lane_pixel(corner[g], l);
                            stored_masks::<L, T>(setups, slots, tile, p);
                            nodes += lost_coverage::<T>(scene, view, setups, tile, p);
                        }
                    }
                }
            }
        }
    }
    if let Some(mut entered) = trace_nodes {
        entered.sort_unstable();
        entered.dedup();
        tile.record(|t| {
            let boxes = entered.iter().map(|&n| scene.bvh.node_box(n as usize));
            t.nodes.extend(boxes.map(|b| (b, NodeOutcome::Entered)));
        });
    }
    nodes
}

/// `View::direction` of the packet's samples `(xs, ys)`, per axis and lane:
/// `(d0 + x·dx) + y·dy` per component in the order the scalar form rounds
/// (no FMA), so each lane equals it bit for bit.
#[inline(always)]
fn directions_lanes<L: Lanes>(
    view: &View,
    xs: &[[f32; 8]; HALVES],
    ys: &[[f32; 8]; HALVES],
) -> [[f32; PACKET]; 3] {
    planar_lanes::<L>([view.d0, view.dx, view.dy], xs, ys, None)
}

/// `View::origin` of the packet's samples `(xs, ys)`, per axis and lane:
/// `eye + ((o0 + x·ox) + y·oy)` per component, bit for bit as the scalar form.
#[inline(always)]
fn origins_lanes<L: Lanes>(
    view: &View,
    xs: &[[f32; 8]; HALVES],
    ys: &[[f32; 8]; HALVES],
) -> [[f32; PACKET]; 3] {
    planar_lanes::<L>([view.o0, view.ox, view.oy], xs, ys, Some(view.eye))
}

/// `(v0 + x·vx) + y·vy` per component and lane, in that order (no FMA),
/// added to `base` when there is one.
#[inline(always)]
fn planar_lanes<L: Lanes>(
    [v0, vx, vy]: [Vec3; 3],
    xs: &[[f32; 8]; HALVES],
    ys: &[[f32; 8]; HALVES],
    base: Option<Vec3>,
) -> [[f32; PACKET]; 3] {
    let [v0, vx, vy] = [v0, vx, vy].map(|v| v.to_array());
    let mut out = [[0.0; PACKET]; 3];
    for half in 0..HALVES {
        let (x, y) = (L::from_array(xs[half]), L::from_array(ys[half]));
        for a in 0..3 {
            let mut v = L::splat(v0[a]) + L::splat(vx[a]) * x + L::splat(vy[a]) * y;
            if let Some(base) = base {
                v = L::splat(base[a]) + v;
            }
            out[a][half * 8..half * 8 + 8].copy_from_slice(&v.to_array());
        }
    }
    out
}

/// CSAA: the coverage mask of each triangle the stored rays of pixel `(x, y)`
/// found (`slots[s]`: the BVH slot of stored sample `s`'s triangle), computed
/// once per triangle.
#[inline(always)]
fn stored_masks<L: Lanes, T: Stored>(
    setups: &Setups<T>,
    slots: &[u32; 8],
    tile: &mut TileBuffer,
    (x, y): (u32, u32),
) {
    let pattern = tile.pattern;
    let (i, pixels) = (tile.index(x, y), tile.pixels);
    let id_at = |tile: &TileBuffer, s: usize| tile.triangle_id[s * pixels + i];
    for (s, &slot) in slots.iter().enumerate().take(pattern.stored) {
        let id = id_at(tile, s);
        if id == BACKGROUND {
            continue;
        }
        let mask = match (0..s).find(|&t| id_at(tile, t) == id) {
            Some(t) => tile.masks[t * pixels + i],
            None => {
                let Some(tri) = &setups.triangles[slot as usize] else {
                    continue;
                };
                tile.edge_evals[i] += pattern.coverage() as u32;
                coverage_mask::<L, _>(&setups.bind(tri, slot as usize, id), pattern, x, y)
            }
        };
        tile.masks[s * pixels + i] = mask;
    }
}

/// The coverage mask of `tri` over pixel `(x, y)` as the rasterizers compute it:
/// [`Coverage::sample`] at stored positions, [`Coverage::covers8`] at
/// coverage-only ones.
#[inline(always)]
fn coverage_mask<L: Lanes, T: Coverage>(tri: &T, pattern: &SamplePattern, x: u32, y: u32) -> u32 {
    let mut mask = 0;
    for (g, group) in pattern.positions.chunks(8).enumerate() {
        let (mut xs, mut ys) = ([0.0; 8], [0.0; 8]);
        for l in 0..8 {
            let [ox, oy] = group[l.min(group.len() - 1)];
            xs[l] = x as f32 + ox;
            ys[l] = y as f32 + oy;
        }
        let covers = tri.covers8::<L>(xs, ys);
        for l in 0..group.len() {
            let c = g * 8 + l;
            let bit = if c < pattern.stored {
                tri.sample(xs[l], ys[l]).is_some()
            } else {
                covers >> l & 1 == 1
            };
            mask |= u32::from(bit) << c;
        }
    }
    mask
}

/// CSAA, in a pixel where a stored sample is background and another holds a
/// triangle: which coverage-only positions no stored triangle covers are
/// covered by some other triangle (the rasterizers' `covered_any`, at the
/// positions the resolve reads it). One any-hit ray per such position; returns
/// the BVH nodes visited.
#[inline(always)]
fn lost_coverage<T: Stored>(
    scene: &PreparedScene,
    view: &View,
    setups: &Setups<T>,
    tile: &mut TileBuffer,
    (x, y): (u32, u32),
) -> u64 {
    let pattern = tile.pattern;
    let (stored, pixels) = (pattern.stored, tile.pixels);
    let i = tile.index(x, y);
    let ids = || (0..stored).map(|s| tile.triangle_id[s * pixels + i]);
    if !ids().any(|id| id == BACKGROUND) || ids().all(|id| id == BACKGROUND) {
        return 0;
    }
    let union = (0..stored).fold(0, |m, s| m | tile.masks[s * pixels + i]);
    let mut covered = union;
    let mut nodes = 0;
    for (c, &[ox, oy]) in pattern.positions.iter().enumerate().skip(stored) {
        if union & (1 << c) != 0 {
            continue;
        }
        let (xs, ys) = (x as f32 + ox, y as f32 + oy);
        let Some((origin, direction)) = view.ray(xs, ys) else {
            continue;
        };
        nodes += scene
            .bvh
            .walk(origin, direction, |k| match setups.get(k as usize) {
                // Portable lanes (bit for bit the AVX2 ones): the walk's
                // closure may not be inlined into the caller's AVX2 code.
                Some((_, _, tri)) if tri.covers8::<Portable>([xs; 8], [ys; 8]) & 1 == 1 => {
                    covered |= 1 << c;
                    // Found: cull everything left.
                    f32::NEG_INFINITY
                }
                _ if covered & (1 << c) != 0 => f32::NEG_INFINITY,
                _ => f32::INFINITY,
            });
    }
    tile.covered_any[i] = covered;
    nodes
}

/// Does `rect` share a pixel with the `side`² block at `(x, y)`?
#[inline(always)]
fn overlaps(rect: PixelRect, x: u32, y: u32, side: u32) -> bool {
    // (`&`, not `&&`: one branch on the answer, not one per side.)
    (rect.x0 < x + side) & (x < rect.x1) & (rect.y0 < y + side) & (y < rect.y1)
}

/// Per group of the square packet at `(x, y)` (group `g` at
/// `(x, y) + BLOCK · (g % √G, g / √G)`), the lanes of its 4×4 block whose
/// pixel lies in `rect` (bit `l` for pixel `corner + (l % 4, l / 4)`), from one
/// span of the packet's columns and one of its rows, with no branch: each
/// of a group's four row bits moves to the first bit of its row in the
/// mask, and the product with the group's four column bits copies those
/// into every row the rect holds (the copies never overlap: no carries).
#[inline(always)]
fn group_masks<const G: usize>(rect: PixelRect, x: u32, y: u32) -> [u16; G] {
    let side = G.isqrt() as u32;
    let columns = span_bits(rect.x0, rect.x1, x, BLOCK * side);
    let rows = span_bits(rect.y0, rect.y1, y, BLOCK * side);
    std::array::from_fn(|g| {
        let (gx, gy) = (g as u32 % side, g as u32 / side);
        let four = |span: u32, at: u32| (span >> (BLOCK * at) & 0xf) as u16;
        let rows = four(rows, gy);
        let spread = (rows | rows << 3 | rows << 6 | rows << 9) & 0x1111;
        four(columns, gx) * spread
    })
}

/// Bits `i < width` (at most 16) with `from + i` in `lo..hi`.
#[inline(always)]
fn span_bits(lo: u32, hi: u32, from: u32, width: u32) -> u32 {
    let start = lo.saturating_sub(from).min(width);
    // (An empty span, `end ≤ start`, gives no bits: no branch on it.)
    let end = hi.saturating_sub(from).clamp(start, width);
    (1 << end) - (1 << start)
}

/// Bit `b` for each byte `b` of `x` that is not zero, with no branch.
#[inline(always)]
fn nonzero_bytes(x: u64) -> u32 {
    const LOW: u64 = 0x7f7f_7f7f_7f7f_7f7f;
    // Each byte's top bit: set where its low seven bits add up past 0x7f
    // (no carry leaves the byte) or where it was set.
    let tops = (((x & LOW) + LOW) | x) & !LOW;
    // Byte `b`'s top bit, shifted to bit `8b`, times the magic lands on bit
    // `56 + b` alone (every other product on a bit of its own: no carries).
    ((tops >> 7).wrapping_mul(0x0102_0408_1020_4080) >> 56) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lanes of the 4×4 block at `(x, y)` whose pixel lies in `rect`.
    fn block_mask(rect: PixelRect, x: u32, y: u32) -> u16 {
        group_masks::<1>(rect, x, y)[0]
    }

    /// The packet's directions, eight lanes at a time, are `View::direction`
    /// bit for bit (portable lanes; the AVX2 ones round alike, see `simd`).
    #[test]
    fn packet_directions_are_the_views_directions() {
        let mut rng = fastrand::Rng::with_seed(4);
        for case in 0..200 {
            let camera = crate::Camera {
                name: "test".into(),
                eye: glam::Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 100.0 - 50.0,
                target: glam::Vec3::new(rng.f32(), rng.f32(), rng.f32()),
                up: glam::Vec3::Y,
                viewport: crate::Viewport::Perspective {
                    fov_y_deg: 10.0 + rng.f32() * 150.0,
                },
                near: None,
            };
            let view = View::new(&camera, 1920, 1080, 1e-3).expect("a valid view");
            let (mut xs, mut ys) = ([[0.0; 8]; HALVES], [[0.0; 8]; HALVES]);
            for l in 0..PACKET {
                xs[l / 8][l % 8] = rng.f32() * 1921.0;
                ys[l / 8][l % 8] = rng.f32() * 1081.0;
            }
            let lanes = directions_lanes::<crate::simd::Portable>(&view, &xs, &ys);
            for l in 0..PACKET {
                let d = view.direction(xs[l / 8][l % 8], ys[l / 8][l % 8]);
                let lane = [lanes[0][l], lanes[1][l], lanes[2][l]];
                assert_eq!(
                    lane.map(f32::to_bits),
                    d.to_array().map(f32::to_bits),
                    "case {case}"
                );
            }
        }
    }

    /// Every byte of random words, zero or not (about half of each), is
    /// named by its bit.
    #[test]
    fn nonzero_bytes_name_every_byte_that_is_not_zero() {
        let mut rng = fastrand::Rng::with_seed(6);
        let mut zeros = 0;
        for _ in 0..20_000 {
            let bytes: [u8; 8] = std::array::from_fn(|_| match rng.bool() {
                true => 0,
                false => rng.u8(1..),
            });
            let expected = (0..8).fold(0, |m, b| m | u32::from(bytes[b] != 0) << b);
            assert_eq!(
                nonzero_bytes(u64::from_le_bytes(bytes)),
                expected,
                "{bytes:?}"
            );
            zeros += expected.count_zeros() - 24;
        }
        assert!((70_000..90_000).contains(&zeros), "{zeros} zero bytes");
    }

    /// Each group's mask of a packet is its block's mask at its corner:
    /// packets of one, four and sixteen groups.
    #[test]
    fn group_masks_are_the_blocks_masks() {
        fn check<const G: usize>(rng: &mut fastrand::Rng) -> u32 {
            let (x0, y0) = (rng.u32(0..40), rng.u32(0..40));
            let rect = PixelRect::new(x0, y0, x0 + rng.u32(0..20), y0 + rng.u32(0..20));
            let (x, y) = (rng.u32(0..48), rng.u32(0..48));
            let side = G.isqrt() as u32;
            let masks = group_masks::<G>(rect, x, y);
            for (g, &mask) in masks.iter().enumerate() {
                let (gx, gy) = (x + BLOCK * (g as u32 % side), y + BLOCK * (g as u32 / side));
                assert_eq!(
                    mask,
                    block_mask(rect, gx, gy),
                    "{rect:?} at ({x}, {y}), group {g}"
                );
            }
            masks.iter().map(|m| m.count_ones()).sum()
        }
        let mut rng = fastrand::Rng::with_seed(8);
        let mut lanes = 0;
        for _ in 0..5_000 {
            lanes += check::<1>(&mut rng) + check::<4>(&mut rng) + check::<16>(&mut rng);
        }
        assert!(lanes > 40_000, "{lanes} lanes inside");
    }

    #[test]
    fn block_masks_hold_exactly_the_pixels_in_the_rect() {
        let mut rng = fastrand::Rng::with_seed(3);
        for _ in 0..20_000 {
            let (x0, y0) = (rng.u32(0..24), rng.u32(0..24));
            let rect = PixelRect::new(x0, y0, x0 + rng.u32(0..9), y0 + rng.u32(0..9));
            let (x, y) = (rng.u32(0..32), rng.u32(0..32));
            let mask = block_mask(rect, x, y);
            for l in 0..PACKET as u32 {
                let (px, py) = (x + l % BLOCK, y + l / BLOCK);
                let inside = rect.contains(px, py);
                assert_eq!(
                    mask >> l & 1 == 1,
                    inside,
                    "{rect:?} at ({x}, {y}), lane {l}"
                );
            }
        }
    }
}
