//! Conformance with the Vulkan rasterization rules as the GPU implements them:
//! the 2D family at `--precision fixed` (vertices snapped to 1/256 pixel,
//! exact integer edge functions, top-left rule) covers exactly the pixels
//! `gpu-raster` covers (wgpu on Mesa's lavapipe without a GPU), bit for bit.
//!
//! Coverage is compared per triangle: each scene's triangles cover disjoint
//! pixels (cells of their own, or quads that tile an area), so the triangle-id
//! image is the coverage of every triangle. Depth plays no part.
//!
//! The cases rebuild the Vulkan CTS fill-rule tests (`dEQP-VK.rasterization.fill_rules.*`)
//! from their description — grids of rotated quads in both diagonal orders, the
//! same with random `w`, one large rotated quad partly and fully clipped —
//! plus 210,000 random triangles on the 1/256 grid and the Direct3D
//! top-left examples.

use continuum::{
    AlgorithmId, BACKGROUND, Camera, Precision, PreparedScene, RenderOutput, Viewport,
};
use continuum_tests::{render_precise, scene_from_triangles};
use glam::Vec3;

/// The 2D algorithms in fixed point, and the GPU.
const FIXED: [AlgorithmId; 2] = [AlgorithmId::TwoDBrute, AlgorithmId::TwoDBin];

/// An orthographic camera over a `width × height` image where world `(x, y, 0)`
/// is pixel point `(x, y)` exactly (`y` down): image sizes are powers of two,
/// so every vertex on the 1/256 grid projects exactly.
fn pixel_camera(width: u32, height: u32) -> Camera {
    let (cx, cy) = (width as f32 * 0.5, height as f32 * 0.5);
    Camera {
        name: "pixels".into(),
        eye: Vec3::new(cx, -cy, 1.0),
        target: Vec3::new(cx, -cy, 0.0),
        up: Vec3::Y,
        viewport: Viewport::Orthographic {
            height: height as f32,
        },
        near: Some(0.5),
    }
}

/// World position of pixel point `(x, y)` under [`pixel_camera`].
fn pixel(x: f32, y: f32) -> Vec3 {
    Vec3::new(x, -y, 0.0)
}

/// A random coordinate on the 1/256 grid in `[lo, hi]`.
fn grid_coordinate(rng: &mut fastrand::Rng, lo: f32, hi: f32) -> f32 {
    let steps = ((hi - lo) * 256.0) as u32;
    lo + rng.u32(0..=steps) as f32 / 256.0
}

/// How exactly the GPU must agree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Expect {
    /// Every vertex inside the viewport: the same pixels, bit for bit.
    Exact,
    /// Vertices beyond the viewport: lavapipe clips such triangles and snaps
    /// the new vertices again, which moves an edge by up to half a snapping
    /// step, so pixel centres within 1/256 pixel of an edge may differ.
    ClippedEdges,
}

/// Distance in pixels from `(x, y)` to the nearest edge line of triangle `id`
/// (a [`pixel_camera`] scene).
fn edge_distance(scene: &PreparedScene, id: u32, x: f64, y: f64) -> f64 {
    let p = scene
        .triangle(id)
        .map(|v| (f64::from(v.x), -f64::from(v.y)));
    (0..3)
        .map(|i| {
            let (a, b) = (p[(i + 1) % 3], p[(i + 2) % 3]);
            let cross = (b.0 - a.0) * (y - a.1) - (b.1 - a.1) * (x - a.0);
            cross.abs() / (b.0 - a.0).hypot(b.1 - a.1)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Renders `scene` with the fixed-point 2D algorithms and the GPU from
/// `camera` and checks that they cover the same pixels with the same triangles
/// and count the same fragments (up to `expect`); returns the GPU's render.
fn assert_gpu_conformance(
    case: &str,
    scene: &PreparedScene,
    camera: &Camera,
    (width, height): (u32, u32),
    expect: Expect,
) -> RenderOutput {
    let gpu = render_precise(
        scene,
        AlgorithmId::GpuRaster,
        camera,
        (width, height),
        Precision::F32,
    );
    for algorithm in FIXED {
        let out = render_precise(scene, algorithm, camera, (width, height), Precision::Fixed);
        let (ours, theirs) = (&out.framebuffer.triangle_id, &gpu.framebuffer.triangle_id);
        let differing: Vec<(u32, u32, u32, u32)> = (0..width * height)
            .filter(|&i| ours[i as usize] != theirs[i as usize])
            .map(|i| (i % width, i / width, ours[i as usize], theirs[i as usize]))
            .collect();
        if expect == Expect::Exact {
            assert!(
                differing.is_empty(),
                "{case}: {algorithm} --precision fixed and gpu-raster differ at {} pixels; first (x, y, ours, gpu): {:?}",
                differing.len(),
                &differing[..differing.len().min(6)]
            );
            // 2dr-bin's early-z skips hidden blocks; with disjoint triangles nothing is hidden.
            assert_eq!(
                out.framebuffer.coverage_writes, gpu.framebuffer.coverage_writes,
                "{case}: {algorithm} and gpu-raster count different fragments"
            );
        }
        for &(x, y, a, b) in &differing {
            let (cx, cy) = (f64::from(x) + 0.5, f64::from(y) + 0.5);
            let distance = [a, b]
                .into_iter()
                .filter(|&id| id != BACKGROUND)
                .map(|id| edge_distance(scene, id, cx, cy))
                .fold(f64::INFINITY, f64::min);
            assert!(
                distance < 1.0 / 256.0,
                "{case}: {algorithm} and gpu-raster differ at ({x}, {y}) ({a} vs {b}), {distance} pixels from an edge"
            );
        }
    }
    gpu
}

/// Random triangles with vertices on the 1/256 grid, each inside its own
/// `cell × cell` square of a 1024² image (so no two share a pixel), from
/// sub-pixel to 256-pixel sizes; and triangles as large as the screen and
/// beyond it (partly clipped by the viewport), one per image.
#[test]
fn random_triangles_on_the_subpixel_grid_cover_what_the_gpu_covers() {
    const SIZE: u32 = 1024;
    let camera = pixel_camera(SIZE, SIZE);
    let mut triangles_compared = 0;
    let mut covered_pixels = 0u64;
    for seed in 1..=3u64 {
        let mut rng = fastrand::Rng::with_seed(seed);
        for cell in [4u32, 16, 64, 256] {
            let mut positions = Vec::new();
            let mut triangles = Vec::new();
            for cy in 0..SIZE / cell {
                for cx in 0..SIZE / cell {
                    // Vertices strictly inside the cell: pixel centres on its
                    // border lines cannot exist (they are at .5).
                    let (x0, y0) = ((cx * cell) as f32, (cy * cell) as f32);
                    let extent = cell as f32 * rng.f32().max(0.02);
                    let base = positions.len() as u32;
                    for _ in 0..3 {
                        let x = grid_coordinate(&mut rng, x0, x0 + extent);
                        let y = grid_coordinate(&mut rng, y0, y0 + extent);
                        positions.push(pixel(x.min(x0 + cell as f32), y.min(y0 + cell as f32)));
                    }
                    triangles.push([base, base + 1, base + 2]);
                }
            }
            let n = triangles.len();
            let scene = scene_from_triangles(positions, triangles, camera.clone());
            let gpu = assert_gpu_conformance(
                &format!("seed {seed}, {cell}-pixel cells"),
                &scene,
                &camera,
                (SIZE, SIZE),
                Expect::Exact,
            );
            triangles_compared += n;
            covered_pixels += gpu
                .framebuffer
                .triangle_id
                .iter()
                .filter(|&&t| t != BACKGROUND)
                .count() as u64;
        }
        // Screen-sized triangles inside the screen (exact), and reaching up
        // to half a screen beyond each side (clipped by the GPU).
        for (k, (lo, hi, expect)) in [
            (0.0, 1024.0, Expect::Exact),
            (-512.0, 1536.0, Expect::ClippedEdges),
        ]
        .into_iter()
        .cycle()
        .take(16)
        .enumerate()
        {
            let mut corner = || {
                pixel(
                    grid_coordinate(&mut rng, lo, hi),
                    grid_coordinate(&mut rng, lo, hi),
                )
            };
            let positions = vec![corner(), corner(), corner()];
            let scene = scene_from_triangles(positions, vec![[0, 1, 2]], camera.clone());
            assert_gpu_conformance(
                &format!("seed {seed}, screen-sized triangle {k}"),
                &scene,
                &camera,
                (SIZE, SIZE),
                expect,
            );
            triangles_compared += 1;
        }
    }
    assert!(
        triangles_compared >= 10_000,
        "{triangles_compared} triangles"
    );
    assert!(
        covered_pixels > 100_000,
        "only {covered_pixels} pixels covered"
    );
}

/// A `n × n` grid of quads (two triangles each) tiling a square of side `side`
/// pixels centred at `centre`, rotated by `angle`; vertices snapped to the
/// 1/256 grid (shared corners stay shared). `reversed` splits each quad along
/// its other diagonal. Returns the positions, the triangles and the outline.
fn rotated_quad_grid(
    n: u32,
    side: f32,
    centre: (f32, f32),
    angle: f32,
    reversed: bool,
) -> (Vec<(f32, f32)>, Vec<[u32; 3]>) {
    let (sin, cos) = angle.sin_cos();
    let snap = |v: f32| (v * 256.0).round() / 256.0;
    let mut corners = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let u = (i as f32 / n as f32 - 0.5) * side;
            let v = (j as f32 / n as f32 - 0.5) * side;
            corners.push((
                snap(centre.0 + u * cos - v * sin),
                snap(centre.1 + u * sin + v * cos),
            ));
        }
    }
    let at = |i: u32, j: u32| j * (n + 1) + i;
    let mut triangles = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            if reversed {
                triangles.push([a, b, d]);
                triangles.push([b, c, d]);
            } else {
                triangles.push([a, b, c]);
                triangles.push([a, c, d]);
            }
        }
    }
    (corners, triangles)
}

/// Is `(x, y)` inside the simple polygon `ring`, within `border` pixels of its
/// border (`None`), or outside? With `border = 0` exact for points and corners
/// on the 1/512 grid (every product is exact in f64).
fn inside_polygon(ring: &[(f32, f32)], x: f64, y: f64, border: f64) -> Option<bool> {
    let mut inside = false;
    for k in 0..ring.len() {
        let (ax, ay) = (f64::from(ring[k].0), f64::from(ring[k].1));
        let (bx, by) = (
            f64::from(ring[(k + 1) % ring.len()].0),
            f64::from(ring[(k + 1) % ring.len()].1),
        );
        let cross = (bx - ax) * (y - ay) - (by - ay) * (x - ax);
        let within = x >= ax.min(bx) && x <= ax.max(bx) && y >= ay.min(by) && y <= ay.max(by);
        if (cross == 0.0 && within) || segment_distance((ax, ay), (bx, by), (x, y)) < border {
            return None;
        }
        // Crossing number along +x.
        if (ay > y) != (by > y) && x < ax + (y - ay) * (bx - ax) / (by - ay) {
            inside = !inside;
        }
    }
    Some(inside)
}

/// Distance from `p` to the segment `a`–`b`.
fn segment_distance(a: (f64, f64), b: (f64, f64), p: (f64, f64)) -> f64 {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let t = (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
    (p.0 - a.0 - t * dx).hypot(p.1 - a.1 - t * dy)
}

/// The boundary of an `n × n` grid's corners ([`rotated_quad_grid`]) in order.
fn grid_outline(corners: &[(f32, f32)], n: u32) -> Vec<(f32, f32)> {
    let at = |i: u32, j: u32| corners[(j * (n + 1) + i) as usize];
    let mut ring = Vec::new();
    ring.extend((0..n).map(|i| at(i, 0)));
    ring.extend((0..n).map(|j| at(n, j)));
    ring.extend((0..n).map(|i| at(n - i, n)));
    ring.extend((0..n).map(|j| at(0, n - j)));
    ring
}

/// The grid's fragments: every pixel at most once, exactly once inside the
/// tiled square (its border decided by the top-left rule), none outside — for
/// the fixed-point algorithms and the GPU alike. `expect` says how near the
/// border pixels may go either way (see [`Expect`]).
fn assert_tiles_once(case: &str, out: &RenderOutput, outline: &[(f32, f32)], expect: Expect) {
    let border = match expect {
        Expect::Exact => 0.0,
        Expect::ClippedEdges => 1.0 / 256.0,
    };
    let fb = &out.framebuffer;
    for y in 0..fb.height {
        for x in 0..fb.width {
            let writes = fb.coverage_writes[(y * fb.width + x) as usize];
            let expected = inside_polygon(outline, f64::from(x) + 0.5, f64::from(y) + 0.5, border);
            let ok = match expected {
                Some(true) => writes == 1,
                Some(false) => writes == 0,
                None => writes <= 1,
            };
            assert!(
                ok,
                "{case}: {} pixel ({x}, {y}) has {writes} fragments, expected {expected:?}",
                out.algorithm
            );
        }
    }
}

/// `dEQP-VK.rasterization.fill_rules.basic_quad` and `basic_quad_reverse`: a
/// 4×4 grid of quads, rotated in small steps, in both diagonal orders.
#[test]
fn rotated_quad_grids_cover_every_pixel_once_like_the_gpu() {
    const SIZE: u32 = 256;
    let camera = pixel_camera(SIZE, SIZE);
    for reversed in [false, true] {
        for step in 0..16 {
            let angle = step as f32 * std::f32::consts::FRAC_PI_2 / 16.0 + 0.0123;
            let (corners, triangles) = rotated_quad_grid(4, 160.0, (128.0, 128.0), angle, reversed);
            let outline = grid_outline(&corners, 4);
            let positions = corners.iter().map(|&(x, y)| pixel(x, y)).collect();
            let scene = scene_from_triangles(positions, triangles, camera.clone());
            let case = format!("quad grid, step {step}, reversed {reversed}");
            let gpu = assert_gpu_conformance(&case, &scene, &camera, (SIZE, SIZE), Expect::Exact);
            assert_tiles_once(&case, &gpu, &outline, Expect::Exact);
            let fixed = render_precise(
                &scene,
                AlgorithmId::TwoDBrute,
                &camera,
                (SIZE, SIZE),
                Precision::Fixed,
            );
            assert_tiles_once(&case, &fixed, &outline, Expect::Exact);
        }
    }
}

/// `dEQP-VK.rasterization.fill_rules.projected`: the quad grid with every
/// vertex at a random depth `w ∈ [0.1, 4]` under a perspective camera, placed
/// so that it projects onto the same 1/256-grid point.
#[test]
fn projected_quad_grids_with_random_w_cover_every_pixel_once_like_the_gpu() {
    const SIZE: u32 = 256;
    // 90° field of view at the origin looking down −z: pixel point (x, y) is the
    // direction (x/128 − 1, 1 − y/128, −1).
    let camera = Camera {
        name: "projected".into(),
        eye: Vec3::ZERO,
        target: Vec3::NEG_Z,
        up: Vec3::Y,
        viewport: Viewport::Perspective { fov_y_deg: 90.0 },
        near: Some(0.01),
    };
    let mut rng = fastrand::Rng::with_seed(11);
    for reversed in [false, true] {
        for step in 0..8 {
            let angle = step as f32 * 0.19 + 0.05;
            let (corners, triangles) = rotated_quad_grid(4, 150.0, (128.0, 128.0), angle, reversed);
            let outline = grid_outline(&corners, 4);
            let positions = corners
                .iter()
                .map(|&(x, y)| {
                    let w = 0.1 + rng.f32() * 3.9;
                    Vec3::new((x / 128.0 - 1.0) * w, (1.0 - y / 128.0) * w, -w)
                })
                .collect();
            let scene = scene_from_triangles(positions, triangles, camera.clone());
            let case = format!("projected grid, step {step}, reversed {reversed}");
            let gpu = assert_gpu_conformance(&case, &scene, &camera, (SIZE, SIZE), Expect::Exact);
            assert_tiles_once(&case, &gpu, &outline, Expect::Exact);
        }
    }
}

/// `dEQP-VK.rasterization.fill_rules.clipped_full` and `clipped_partly`: one
/// large quad rotated over 15 steps, covering the whole viewport, or reaching
/// past one side of it.
#[test]
fn large_rotated_quads_partly_and_fully_clipped_cover_like_the_gpu() {
    const SIZE: u32 = 128;
    let camera = pixel_camera(SIZE, SIZE);
    for (kind, centre, side) in [
        ("full", (64.0, 64.0), 400.0),
        ("partly", (150.0, 40.0), 180.0),
    ] {
        for step in 0..15 {
            let angle = step as f32 * std::f32::consts::FRAC_PI_2 / 15.0;
            for reversed in [false, true] {
                let (corners, triangles) = rotated_quad_grid(1, side, centre, angle, reversed);
                let outline = grid_outline(&corners, 1);
                let positions = corners.iter().map(|&(x, y)| pixel(x, y)).collect();
                let scene = scene_from_triangles(positions, triangles, camera.clone());
                let case = format!("clipped {kind}, step {step}, reversed {reversed}");
                let gpu = assert_gpu_conformance(
                    &case,
                    &scene,
                    &camera,
                    (SIZE, SIZE),
                    Expect::ClippedEdges,
                );
                assert_tiles_once(&case, &gpu, &outline, Expect::ClippedEdges);
                let fixed = render_precise(
                    &scene,
                    AlgorithmId::TwoDBrute,
                    &camera,
                    (SIZE, SIZE),
                    Precision::Fixed,
                );
                assert_tiles_once(&case, &fixed, &outline, Expect::Exact);
                if kind == "full" {
                    assert_eq!(
                        gpu.stats.coverage_histogram.one,
                        u64::from(SIZE * SIZE),
                        "{case}"
                    );
                }
            }
        }
    }
}

/// The Direct3D 11 top-left examples (functional spec §3.4.2): edges through
/// pixel centres along every direction. Left and top edges own their pixel
/// centres, right and bottom edges do not; a vertex on a centre goes to the
/// triangle whose two edges at it both own it.
#[test]
fn direct3d_top_left_examples_match_the_gpu() {
    const SIZE: u32 = 16;
    let camera = pixel_camera(SIZE, SIZE);
    // (name, corners in pixels, triangles, pixels covered or 0 for unchecked)
    type Case = (&'static str, Vec<(f32, f32)>, Vec<[u32; 3]>, u32);
    let cases: [Case; 5] = [
        // Top edge through centres (row 2 included), bottom edge through centres (row 6 excluded).
        (
            "axis-aligned rectangle",
            vec![(2.5, 2.5), (9.5, 2.5), (9.5, 6.5), (2.5, 6.5)],
            vec![[0, 1, 2], [0, 2, 3]],
            7 * 4,
        ),
        // A right edge through centres is excluded, a left edge included.
        (
            "vertical edges",
            vec![(4.5, 1.0), (4.5, 9.0), (8.5, 1.0)],
            vec![[0, 1, 2]],
            0,
        ),
        // Diagonal edges through centres both ways.
        (
            "diamond",
            vec![(8.5, 2.5), (13.5, 7.5), (8.5, 12.5), (3.5, 7.5)],
            vec![[0, 1, 2], [0, 2, 3]],
            0,
        ),
        // A fan of four around a vertex on a pixel centre.
        (
            "fan on a centre",
            vec![
                (7.5, 7.5),
                (3.5, 3.5),
                (11.5, 3.5),
                (11.5, 11.5),
                (3.5, 11.5),
            ],
            vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]],
            64,
        ),
        // A sliver a quarter pixel high whose top edge runs through a row of
        // centres covers that row, and nothing else.
        (
            "sliver on a row of centres",
            vec![(0.0, 4.5), (16.0, 4.5), (0.0, 4.75)],
            vec![[0, 1, 2]],
            16,
        ),
    ];
    for (name, corners, triangles, expected) in cases {
        let positions = corners.iter().map(|&(x, y)| pixel(x, y)).collect();
        let scene = scene_from_triangles(positions, triangles, camera.clone());
        let gpu = assert_gpu_conformance(name, &scene, &camera, (SIZE, SIZE), Expect::Exact);
        assert_eq!(
            gpu.stats.coverage_histogram.many, 0,
            "{name}: a pixel covered twice"
        );
        let covered = gpu.stats.coverage_histogram.one;
        if expected > 0 {
            assert_eq!(covered, u64::from(expected), "{name}");
        }
        // The float 2D and 3D families follow the same rules on these exact inputs.
        for algorithm in [
            AlgorithmId::TwoDBrute,
            AlgorithmId::ThreeDBrute,
            AlgorithmId::Raycast,
        ] {
            let out = render_precise(&scene, algorithm, &camera, (SIZE, SIZE), Precision::F32);
            assert_eq!(
                out.framebuffer.triangle_id, gpu.framebuffer.triangle_id,
                "{name}: {algorithm} (f32) differs from the GPU"
            );
        }
    }
}
