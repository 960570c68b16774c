//! The resolve: a tile's samples become pixels. Each coverage sample takes the
//! colour of the surface it sees, and the pixel is their box-filtered mean in
//! linear light.
//!
//! - Every position stored (none, SSAA, MSAA): coverage sample `s` sees the
//!   triangle stored at `s`. SSAA shades each sample at its own position; MSAA
//!   shades each distinct triangle of the pixel once, at the first sample that
//!   holds it.
//! - CSAA: a stored position as above. A coverage-only position sees, of the
//!   triangles stored in the pixel whose coverage mask holds it, the nearest by
//!   its stored depth (ties to the smaller id). If none covers it and a stored
//!   sample is background, the pixel's `covered_any` mask (every triangle
//!   rasterized there) tells background from a triangle that won no stored
//!   sample, which the nearest stored triangle then stands in for; where no
//!   stored sample is background, the nearest stored surface. (Hardware CSAA
//!   shows background for a lost triangle; on meshes of small triangles that
//!   turns silhouettes ragged.) This depends only on what the stored samples
//!   hold — not on drawing order or culling — so it is the same in every
//!   algorithm.
//! - Transparency (an A-buffer): the fragments see-through triangles left at a
//!   stored sample are sorted by depth (ties to the smaller id) and those in
//!   front of its opaque surface are blended over it, far to near, in linear
//!   light: `c ← α·c_f + (1 − α)·c`. The order depends only on the fragments,
//!   so every algorithm that finds the same fragments blends the same colour.

use std::time::Instant;

use glam::Vec3;

use crate::camera::View;
use crate::color::{
    BACKGROUND_COLOR, OUTSIDE_VIEWPORT_COLOR, encode_rgb, encode_rgb_eight, linear_rgb,
};
use crate::effects::EffectCounters;
use crate::framebuffer::{
    BACKGROUND, Fragment, TileBuffer, TilePlanes, TileTotals, wins_depth_test,
};
use crate::shade::Shader;
use crate::shade::eight::EightSamples;
use crate::simd::{self, Lanes};
use crate::stats::CoverageHistogram;
use crate::stream;

/// Most stored samples a pattern has (`ssaa:256`).
const MAX_STORED: usize = 256;
/// Most stored samples a CSAA pattern has.
const MAX_CSAA_STORED: usize = 8;

/// Start of a pixel's sample digest.
const DIGEST_SEED: u64 = 0x9e37_79b9_7f4a_7c15;

/// One step of the sample digest (a multiply–rotate hash; the digest only has
/// to tell differing sample sets apart).
#[inline(always)]
fn mix(h: u64, v: u32) -> u64 {
    (h ^ u64::from(v))
        .wrapping_mul(0x2127_599b_f432_5c37)
        .rotate_left(29)
}

/// A tile's fragments grouped by sample (a counting sort), each group sorted
/// near to far (ties to the smaller id).
struct FragmentLayers {
    /// Fragments of sample `j` are `sorted[start[j]..start[j + 1]]`; empty
    /// when the tile has none.
    start: Vec<u32>,
    sorted: Vec<Fragment>,
}

impl FragmentLayers {
    fn of(tile: &TileBuffer) -> FragmentLayers {
        if tile.fragments.is_empty() {
            return FragmentLayers {
                start: Vec::new(),
                sorted: Vec::new(),
            };
        }
        let samples = tile.pixels * tile.pattern.stored;
        let mut start = vec![0u32; samples + 1];
        for f in &tile.fragments {
            start[f.sample as usize + 1] += 1;
        }
        for j in 0..samples {
            start[j + 1] += start[j];
        }
        let mut fill = start.clone();
        let mut sorted = vec![tile.fragments[0]; tile.fragments.len()];
        for f in &tile.fragments {
            sorted[fill[f.sample as usize] as usize] = *f;
            fill[f.sample as usize] += 1;
        }
        for j in 0..samples {
            sorted[start[j] as usize..start[j + 1] as usize]
                .sort_unstable_by(|a, b| a.w.total_cmp(&b.w).then(a.id.cmp(&b.id)));
        }
        FragmentLayers { start, sorted }
    }

    /// The fragments of sample `j`, near to far.
    #[inline]
    fn at(&self, j: usize) -> &[Fragment] {
        if self.start.is_empty() {
            return &[];
        }
        &self.sorted[self.start[j] as usize..self.start[j + 1] as usize]
    }

    /// Whether any stored sample of pixel `i` has fragments.
    fn pixel_has(&self, i: usize, pixels: usize, stored: usize) -> bool {
        !self.start.is_empty() && (0..stored).any(|s| !self.at(s * pixels + i).is_empty())
    }
}

/// The resolve of `tile` into its place in the frame, `out`: each pixel's
/// first stored sample (depth, triangle id), its counters summed over its
/// samples and, with anti-aliasing, its sample digest; returns the tile's
/// coverage histogram and edge evaluations (counted here, while the tile's
/// buffers are in cache, not over the frame afterwards). Colours are
/// [`shade_tile`]'s.
fn resolve_tile(tile: &TileBuffer, out: &mut TilePlanes) -> TileTotals {
    let pattern = tile.pattern;
    let (stored, pixels) = (pattern.stored, tile.pixels);
    let width = (tile.x1 - tile.x0) as usize;
    let masks = pattern.has_coverage_only();
    // The first sample's planes, copied past the cache (`stream`); with one
    // sample a pixel, the coverage writes too (more are summed below). A
    // frame without counter planes has no rows of them to copy into.
    stream::copy_rows(&mut out.depth, &tile.depth[..pixels]);
    stream::copy_rows(&mut out.triangle_id, &tile.triangle_id[..pixels]);
    stream::copy_rows(&mut out.edge_evals, &tile.edge_evals[..pixels]);
    if stored == 1 {
        stream::copy_rows(&mut out.coverage_writes, &tile.coverage_writes[..pixels]);
    }
    let (edge_evaluations, max_edge_evals, histogram) = tile_counts(tile);
    let summed_writes = stored > 1 && !out.coverage_writes.is_empty();
    for (r, start) in (0..pixels).step_by(width).enumerate() {
        if summed_writes {
            let writes = &mut *out.coverage_writes[r];
            writes.copy_from_slice(&tile.coverage_writes[start..start + width]);
            for s in 1..stored {
                let layer = &tile.coverage_writes[s * pixels + start..][..width];
                for (sum, &w) in writes.iter_mut().zip(layer) {
                    *sum += w;
                }
            }
        }
        // The digest of every sample's id (and mask), sample by sample.
        if let Some(digest) = out.sample_digest.get_mut(r) {
            digest.fill(DIGEST_SEED);
            for s in 0..stored {
                let ids = &tile.triangle_id[s * pixels + start..][..width];
                for (d, &id) in digest.iter_mut().zip(ids) {
                    *d = mix(*d, id);
                }
                if masks {
                    let masks = &tile.masks[s * pixels + start..][..width];
                    for (d, &m) in digest.iter_mut().zip(masks) {
                        *d = mix(*d, m);
                    }
                }
            }
        }
    }
    TileTotals {
        histogram,
        edge_evaluations,
        max_edge_evals,
        ..TileTotals::default()
    }
}

simd::dispatch! {
    /// The counters of `tile`, from the tile (in cache): its edge
    /// evaluations, the most at one pixel, and the histogram of its stored
    /// samples' coverage writes — plain reductions, which vectorize (to
    /// AVX2's width where the CPU has it).
    fn tile_counts<>(tile: &TileBuffer) -> (u64, u32, CoverageHistogram) => tile_counts_on
}

/// [`tile_counts`], compiled for lanes `L`.
#[inline(always)]
fn tile_counts_on<L: Lanes>(tile: &TileBuffer) -> (u64, u32, CoverageHistogram) {
    let pixels = tile.pixels;
    let evals = &tile.edge_evals[..pixels];
    let edge_evaluations = evals.iter().map(|&e| u64::from(e)).sum::<u64>();
    let max_edge_evals = evals.iter().copied().max().unwrap_or(0);
    let mut histogram = CoverageHistogram::default();
    for layer in tile
        .coverage_writes
        .chunks_exact(pixels)
        .take(tile.pattern.stored)
    {
        histogram += CoverageHistogram::of(layer);
    }
    (edge_evaluations, max_edge_evals, histogram)
}

/// A rendered tile into the frame: [`resolve_tile`], then [`shade_tile`];
/// with the seconds each took (the resolve and shading stages).
pub(crate) fn finish_tile(
    tile: &TileBuffer,
    view: &View,
    shader: &Shader,
    out: &mut TilePlanes,
) -> (TileTotals, [f64; 2]) {
    let start = Instant::now();
    let counted = resolve_tile(tile, out);
    let resolved = Instant::now();
    let totals = TileTotals {
        histogram: counted.histogram,
        edge_evaluations: counted.edge_evaluations,
        max_edge_evals: counted.max_edge_evals,
        ..shade_tile(tile, view, shader, out)
    };
    let seconds = [resolved - start, resolved.elapsed()].map(|d| d.as_secs_f64());
    (totals, seconds)
}

/// The colour of every pixel of `tile`, written into `out` (and, with
/// transparency, the fragments blended there): the shading of its samples
/// and the box filter over them. Returns what the shading counted.
fn shade_tile(tile: &TileBuffer, view: &View, shader: &Shader, out: &mut TilePlanes) -> TileTotals {
    let pattern = tile.pattern;
    let (stored, pixels) = (pattern.stored, tile.pixels);
    debug_assert!(stored <= MAX_STORED);
    let mut totals = TileTotals {
        effects: EffectCounters::for_plan(shader.plan()),
        ..TileTotals::default()
    };
    if stored == 1 && pattern.coverage() == 1 && tile.fragments.is_empty() && !force_general() {
        shade_single(tile, view, shader, out, &mut totals);
        return totals;
    }
    let background = linear_rgb(BACKGROUND_COLOR);
    let outside = linear_rgb(OUTSIDE_VIEWPORT_COLOR);
    let anti_aliased = pattern.coverage() > 1;
    // Layer by layer (contiguous, independent per pixel): whether a pixel's
    // stored samples all hold one triangle.
    let mut uniform = vec![!pattern.shade_per_sample; pixels];
    if anti_aliased && !pattern.shade_per_sample {
        let ids = &tile.triangle_id;
        for layer in ids.chunks_exact(pixels).skip(1) {
            for ((u, &id), &first) in uniform.iter_mut().zip(layer).zip(&ids[..pixels]) {
                *u &= id == first;
            }
        }
    }
    let layers = FragmentLayers::of(tile);
    let mut surface_color = [Vec3::ZERO; MAX_STORED];
    let mut slot_color = [Vec3::ZERO; MAX_STORED];
    // Per pixel without per-sample shading: the colour of each transparent
    // triangle, shaded once (as its opaque counterpart would be).
    let mut fragment_colors: Vec<(u32, (Vec3, f32))> = Vec::new();
    for (r, y) in (tile.y0..tile.y1).enumerate() {
        for (c, x) in (tile.x0..tile.x1).enumerate() {
            let i = tile.index(x, y);
            let id_at = |s: usize| tile.triangle_id[s * pixels + i];
            let depth_at = |s: usize| tile.depth[s * pixels + i];
            let layered = layers.pixel_has(i, pixels, stored);
            // 1. The colour each stored sample sees (one shading when they all
            // hold the same triangle and need not be shaded apart).
            // (Background samples of a non-planar view may lie on both sides
            // of the viewport's border, so they are not taken as one.)
            let uniform =
                uniform[i] && !layered && (id_at(0) != BACKGROUND || view.sphere.is_none());
            fragment_colors.clear();
            let mut blended = 0;
            for s in 0..if uniform { 1 } else { stored } {
                let id = id_at(s);
                let [ox, oy] = pattern.positions[s];
                let at = (x as f32 + ox, y as f32 + oy);
                let fragments = layers.at(s * pixels + i);
                let shaded_before = (!pattern.shade_per_sample && id != BACKGROUND)
                    .then(|| (0..s).find(|&t| id_at(t) == id))
                    .flatten();
                let ray = (shaded_before.is_none() || !fragments.is_empty())
                    .then(|| view.ray(at.0, at.1))
                    .flatten();
                surface_color[s] = match (shaded_before, ray) {
                    (Some(t), _) => surface_color[t],
                    (None, None) => outside,
                    (None, Some(_)) if id == BACKGROUND => background,
                    (None, Some(ray)) => {
                        totals.shading_samples += 1;
                        shader.shade(id, at, ray, depth_at(s), &mut totals.effects)
                    }
                };
                slot_color[s] = surface_color[s];
                // 2. Transparent fragments in front of the opaque surface,
                // blended far to near (their shading's own effects counted
                // there too).
                if let (false, Some(ray)) = (fragments.is_empty(), ray) {
                    let start = Instant::now();
                    let front = fragments
                        .iter()
                        .take_while(|f| wins_depth_test(f.w, f.id, depth_at(s), id))
                        .count();
                    for f in fragments[..front].iter().rev() {
                        let cached = fragment_colors.iter().find(|(t, _)| *t == f.id);
                        let (color, alpha) = match cached {
                            Some(&(_, c)) if !pattern.shade_per_sample => c,
                            _ => {
                                totals.shading_samples += 1;
                                let c =
                                    shader.shade_fragment(f.id, at, ray, f.w, &mut totals.effects);
                                fragment_colors.push((f.id, c));
                                c
                            }
                        };
                        slot_color[s] = color * alpha + slot_color[s] * (1.0 - alpha);
                    }
                    blended += front as u32;
                    totals.effects.fragments_blended += front as u64;
                    totals.effects.transparency_s += start.elapsed().as_secs_f64();
                }
            }
            if let Some(row) = out.blended.get_mut(r) {
                row[c] = blended;
            }
            // 3. The box filter over the coverage samples.
            out.color[r][c] = if !anti_aliased {
                // Exactly the stored colours, not a round trip through linear light.
                if id_at(0) != BACKGROUND || blended > 0 {
                    encode_rgb(slot_color[0])
                } else if slot_color[0] == outside {
                    OUTSIDE_VIEWPORT_COLOR
                } else {
                    BACKGROUND_COLOR
                }
            } else if uniform && view.sphere.is_none() {
                // Every coverage sample sees this one surface.
                encode_rgb(slot_color[0])
            } else {
                if uniform {
                    let first = slot_color[0];
                    slot_color[1..stored].fill(first);
                }
                let sum = mixed_color(tile, view, i, (x, y), &slot_color, [background, outside]);
                encode_rgb(sum / pattern.coverage() as f32)
            };
        }
    }
    totals
}

/// [`shade_tile`] of a tile with one sample per pixel and no see-through
/// fragments (no anti-aliasing, opaque surfaces): each pixel's colour is
/// its sample's, exactly as the general path computes it, without its
/// per-sample bookkeeping ([`shade_rows`]), written into the frame past the
/// cache (the frame's colours are not read again while they would be cached).
fn shade_single(
    tile: &TileBuffer,
    view: &View,
    shader: &Shader,
    out: &mut TilePlanes,
    totals: &mut TileTotals,
) {
    stream::streamed(&mut out.color, |colors| {
        shade_rows(tile, view, shader, colors, totals);
    });
}

/// Pixels a row of [`shade_rows`] is shaded in at a time, into a buffer
/// that stays in the L1 cache, before that piece of the row is written out.
const ROW_PIECE: usize = 256;
const _: () = assert!(ROW_PIECE.is_multiple_of(8));

simd::dispatch! {
    /// [`shade_single`]'s colours, row by row, eight pixels of a row at a
    /// time where the view is planar and the material allows
    /// ([`Shader::shade_eight`]).
    fn shade_rows<>(
        tile: &TileBuffer,
        view: &View,
        shader: &Shader,
        colors: &mut stream::Rows<[u8; 4]>,
        totals: &mut TileTotals,
    ) -> () => shade_rows_on
}

/// [`shade_rows`] on lanes `L`.
#[inline(always)]
fn shade_rows_on<L: Lanes>(
    tile: &TileBuffer,
    view: &View,
    shader: &Shader,
    rows: &mut stream::Rows<[u8; 4]>,
    totals: &mut TileTotals,
) {
    let [ox, oy] = tile.pattern.positions[0];
    let width = (tile.x1 - tile.x0) as usize;
    let mut piece = [[[0u8; 4]; 8]; ROW_PIECE / 8];
    for (r, y) in (tile.y0..tile.y1).enumerate() {
        let ids = &tile.triangle_id[r * width..][..width];
        let depths = &tile.depth[r * width..][..width];
        // A row of background alone (most rows of most frames) is one fill:
        // a planar view has a ray through every pixel. The test is a fold
        // with no early exit, which vectorizes.
        if view.sphere.is_none() && ids.iter().fold(true, |all, &id| all & (id == BACKGROUND)) {
            rows.fill(r, BACKGROUND_COLOR);
            continue;
        }
        for p0 in (0..width).step_by(ROW_PIECE) {
            let len = (width - p0).min(ROW_PIECE);
            for (k, colors) in piece[..len.div_ceil(8)].iter_mut().enumerate() {
                let at = (p0 + 8 * k, y);
                *colors = shade_eight_pixels::<L>(
                    tile,
                    view,
                    shader,
                    (ids, depths),
                    at,
                    (ox, oy),
                    totals,
                );
            }
            rows.write(r, p0, &piece.as_flattened()[..len]);
        }
    }
}

/// The colours of the eight pixels of row `y` from column `c0` on, whose
/// samples (at offset `(ox, oy)`) hold `ids[c0..]` at `depths[c0..]`; those
/// past the row's end are background's.
#[inline(always)]
fn shade_eight_pixels<L: Lanes>(
    tile: &TileBuffer,
    view: &View,
    shader: &Shader,
    (ids, depths): (&[u32], &[f32]),
    (c0, y): (usize, u32),
    (ox, oy): (f32, f32),
    totals: &mut TileTotals,
) -> [[u8; 4]; 8] {
    // (Whole eights as one copy, not a call to `memcpy`.)
    let ids8: [u32; 8] = match ids[c0..].first_chunk() {
        Some(eight) => *eight,
        None => std::array::from_fn(|l| ids.get(c0 + l).map_or(BACKGROUND, |&id| id)),
    };
    // Lanes past the row's end hold BACKGROUND: no bit there.
    let surface = L::differ(ids8, BACKGROUND);
    if surface == 0 && view.sphere.is_none() {
        // A planar view has a ray through every pixel.
        return [BACKGROUND_COLOR; 8];
    }
    let eight = EightSamples {
        lanes: shader.lanes_shaded(&ids8, surface),
        ids: ids8,
        x: (tile.x0 + c0 as u32) as f32,
        ox,
        y: y as f32 + oy,
    };
    let (encoded, done) = match eight.lanes {
        0 => ([[0; 4]; 8], 0),
        _ => {
            let (linear, done) = shader.shade_eight::<L>(&eight);
            (encode_rgb_eight::<L>(linear), done)
        }
    };
    totals.shading_samples += u64::from(done.count_ones());
    // Every lane shaded here or background (a planar view's, which
    // has a ray through every pixel): one blend.
    if done | !surface == u8::MAX && view.sphere.is_none() {
        return std::array::from_fn(|l| match done >> l & 1 {
            1 => encoded[l],
            _ => BACKGROUND_COLOR,
        });
    }
    let xs = eight.lane_x::<L>().to_array();
    std::array::from_fn(|l| {
        let (id, at) = (eight.ids[l], (xs[l], eight.y));
        if done & (1 << l) != 0 {
            encoded[l]
        } else if id == BACKGROUND {
            // Only non-planar viewports have pixels without a ray.
            match view.sphere.is_some() && view.ray(at.0, at.1).is_none() {
                true => OUTSIDE_VIEWPORT_COLOR,
                false => BACKGROUND_COLOR,
            }
        } else {
            match view.ray(at.0, at.1) {
                Some(ray) => {
                    totals.shading_samples += 1;
                    let effects = &mut totals.effects;
                    encode_rgb(shader.shade(id, at, ray, depths[c0 + l], effects))
                }
                None => encode_rgb(linear_rgb(OUTSIDE_VIEWPORT_COLOR)),
            }
        }
    })
}

/// Tests: send every tile down the general path.
#[cfg(test)]
static FORCE_GENERAL: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

#[inline(always)]
fn force_general() -> bool {
    #[cfg(test)]
    return FORCE_GENERAL.load(std::sync::atomic::Ordering::Relaxed);
    #[cfg(not(test))]
    false
}

/// The sum of what every coverage sample of pixel `i` (at `(x, y)`) sees, given
/// the colours of its stored samples (`slot_color`).
fn mixed_color(
    tile: &TileBuffer,
    view: &View,
    i: usize,
    (x, y): (u32, u32),
    slot_color: &[Vec3; MAX_STORED],
    [background, outside]: [Vec3; 2],
) -> Vec3 {
    let pattern = tile.pattern;
    let (stored, pixels) = (pattern.stored, tile.pixels);
    let id_at = |s: usize| tile.triangle_id[s * pixels + i];
    let depth_at = |s: usize| tile.depth[s * pixels + i];
    let mut sum: Vec3 = slot_color[..stored].iter().sum();
    if !pattern.has_coverage_only() {
        return sum;
    }
    // Each stored triangle's coverage over the pixel: the union of what each of
    // its stored samples recorded.
    let mut union = [0u32; MAX_CSAA_STORED];
    for (s, mask) in union[..stored].iter_mut().enumerate() {
        for t in 0..stored {
            if id_at(t) == id_at(s) {
                *mask |= tile.masks[t * pixels + i];
            }
        }
    }
    let any_background = (0..stored).any(|s| id_at(s) == BACKGROUND);
    for (c, &[ox, oy]) in pattern.positions.iter().enumerate().skip(stored) {
        let mut best: Option<usize> = None;
        for (s, &mask) in union[..stored].iter().enumerate() {
            let id = id_at(s);
            if id != BACKGROUND
                && mask & (1 << c) != 0
                && best.is_none_or(|b| wins_depth_test(depth_at(s), id, depth_at(b), id_at(b)))
            {
                best = Some(s);
            }
        }
        sum += match best {
            Some(s) => slot_color[s],
            None if view.sphere.is_some() && view.ray(x as f32 + ox, y as f32 + oy).is_none() => {
                outside
            }
            // No stored sample is background: nothing tells what is there;
            // take the nearest stored surface.
            None if !any_background => slot_color[usize::from(pattern.nearest[c][0])],
            // Nothing covers it: background.
            None if tile.covered_any[i] & (1 << c) == 0 => background,
            // A triangle that won no stored sample covers it: the nearest
            // stored triangle stands in for it.
            None => pattern.nearest[c]
                .iter()
                .map(|&s| s as usize)
                .find(|&s| id_at(s) != BACKGROUND)
                .map_or(background, |s| slot_color[s]),
        };
    }
    sum
}

#[cfg(test)]
mod tests {
    use std::sync::atomic::Ordering;

    use super::FORCE_GENERAL;
    use crate::framebuffer::BACKGROUND;
    use crate::{AlgorithmId, PreparedScene, RenderRequest, Viewport, render};

    /// The single-sample path — eight pixels at a time where it can — gives
    /// every pixel the colour the general, scalar path gives it: a headlight,
    /// directional and point lights, interpolated normals, shadowed, mirrored
    /// and textured scenes; perspective, orthographic and parabolic views
    /// (pixels without a ray); a rasterizer and the ray caster; and a
    /// sphere with every third vertex normal zero (the face normal shades
    /// its triangles); eights of one triangle (the box's faces, fig8's
    /// floor under a second material) and of several; and, 300 pixels
    /// wide, rows longer than one shaded piece (`ROW_PIECE`) that end in
    /// part of an eight.
    #[test]
    fn the_single_sample_resolve_matches_the_general_one() {
        let names = [
            ("box", false),
            ("fig8", false),
            ("soup", false),
            ("sphere", false),
            ("sphere", true),
            ("teapots", false),
            ("checker", false),
            ("shadows", false),
            ("mirror", false),
        ];
        let (mut rendered, mut background_rows) = (0, 0);
        for (name, zero_normals) in names {
            let path = format!("{}/../scenes/{name}.toml", env!("CARGO_MANIFEST_DIR"));
            let mut scene = crate::scene::load_path(path.as_ref()).expect("built-in scene loads");
            if zero_normals {
                let normals = scene.mesh.normals.iter_mut().step_by(3);
                normals.for_each(|n| *n = glam::Vec3::ZERO);
            }
            let scene = PreparedScene::new(scene);
            let camera = scene.scene.first_camera();
            let parabolic = crate::Camera {
                viewport: Viewport::Parabolic,
                ..camera.clone()
            };
            let orthographic = crate::Camera {
                viewport: Viewport::Orthographic {
                    height: 2.0 * scene.bounds.radius(),
                },
                ..camera.clone()
            };
            for (algorithm, camera) in [
                (AlgorithmId::ThreeDBrute, &camera),
                (AlgorithmId::Raycast, &camera),
                (AlgorithmId::TwoDBrute, &orthographic),
                (AlgorithmId::Raycast, &parabolic),
            ] {
                let request = RenderRequest::new(algorithm, camera.clone(), 300, 64);
                let colors = |general: bool| {
                    FORCE_GENERAL.store(general, Ordering::Relaxed);
                    let out = render(&scene, &request);
                    FORCE_GENERAL.store(false, Ordering::Relaxed);
                    let out = out.expect("renders");
                    let fb = out.framebuffer;
                    (fb.color, out.stats.shading_samples, fb.triangle_id)
                };
                let (fast, general) = (colors(false), colors(true));
                assert!(fast.1 > 0, "{name} {algorithm}: something is shaded");
                assert_eq!(fast, general, "{name} {algorithm} {}", camera.viewport);
                rendered += 1;
                // Rows with no triangle (a tile's, here a whole image row)
                // take the one-fill path.
                background_rows += (fast.2.chunks(300))
                    .filter(|row| row.iter().all(|&id| id == BACKGROUND))
                    .count();
            }
        }
        assert_eq!(rendered, names.len() * 4);
        assert!(background_rows > 0, "some row is background alone");
    }
}
