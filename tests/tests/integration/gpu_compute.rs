//! The GPU compute algorithms (paper §5) against their CPU families: on every
//! built-in scene and camera, in both planar viewports, `gpu-3dr` and
//! `gpu-3dr-binned` give the triangle ids of `3dr-brute`, `gpu-2dr` those of
//! `2dr-brute` and `gpu-2dr-homogeneous` those of `2dr-homogeneous`, except
//! at pixels the f64 explanation accounts for (a sample within 1e-3 pixel of
//! an edge, at the near plane, or a depth tie — within 1e-5, or 1e-4 for the
//! GPU's own rounding); the counts are printed per scene. The 3D and
//! homogeneous kernels decide coverage exactly, so for them only depth ties
//! may differ. (Run on Mesa's lavapipe in CI.)

use std::collections::{BTreeMap, HashMap};

use continuum::{AaMode, AlgorithmId, RenderOutput, RenderRequest, render};
use continuum_tests::matrix::{Cameras, Matrix, ViewportChoice};
use continuum_tests::{DifferenceReport, builtin_scenes, depths_at, explain_2d_3d, prepared};

/// Each GPU kernel and the CPU algorithm it must agree with.
const PAIRS: [(AlgorithmId, AlgorithmId); 4] = [
    (AlgorithmId::Gpu2dr, AlgorithmId::TwoDBrute),
    (AlgorithmId::Gpu2drHomogeneous, AlgorithmId::TwoDHomogeneous),
    (AlgorithmId::Gpu3dr, AlgorithmId::ThreeDBrute),
    (AlgorithmId::Gpu3drBinned, AlgorithmId::ThreeDBrute),
];

fn reference_of(gpu: AlgorithmId) -> Option<AlgorithmId> {
    PAIRS.iter().find(|(g, _)| *g == gpu).map(|&(_, cpu)| cpu)
}

#[test]
fn gpu_kernels_differ_from_their_cpu_family_only_where_explained() {
    let mut algorithms = vec![
        AlgorithmId::TwoDBrute,
        AlgorithmId::TwoDHomogeneous,
        AlgorithmId::ThreeDBrute,
    ];
    algorithms.extend(PAIRS.map(|(g, _)| g));
    let mut references: HashMap<AlgorithmId, RenderOutput> = HashMap::new();
    let mut per_scene: BTreeMap<(String, &'static str), DifferenceReport> = BTreeMap::new();
    let mut compared = 0;
    let mut near_ties = 0;
    let rendered = Matrix {
        cameras: Cameras::All,
        viewports: vec![ViewportChoice::Own, ViewportChoice::Orthographic],
        algorithms,
        size: (160, 120),
        ..Matrix::new()
    }
    .run(|cell| {
        let algorithm = cell.request.algorithm;
        let Some(cpu) = reference_of(algorithm) else {
            references.insert(algorithm, cell.output.clone());
            return;
        };
        let reference = &references[&cpu];
        let mut r = explain_2d_3d(cell.prepared, cell.output, reference);
        // Near-ties: the GPU's f32 (its driver may fuse multiplies and adds)
        // and the CPU's round a depth differently; between surfaces within
        // 1e-4 of each other in depth (f64) either may win.
        let view = &reference.view;
        r.unexplained.retain(|&(x, y, a, b)| {
            let near_tie = a != continuum::BACKGROUND && b != continuum::BACKGROUND && {
                let [wa, wb] = depths_at(cell.prepared, view, (x, y), [a, b]);
                (wa - wb).abs() <= 1e-4 * wa.abs().max(wb.abs())
            };
            near_ties += usize::from(near_tie);
            !near_tie
        });
        assert!(
            r.unexplained.is_empty(),
            "{} against {cpu}: unexplained differences (x, y, gpu id, cpu id): {:?}",
            cell.label(),
            &r.unexplained[..r.unexplained.len().min(10)]
        );
        assert!(
            r.explained() * 1_000 <= r.covered.max(1),
            "{}: {} differing pixels is more than 0.1% of {} covered",
            cell.label(),
            r.explained(),
            r.covered
        );
        // The 3D and homogeneous kernels decide coverage exactly (what f32
        // cannot be sure of, the CPU decides): no pixel may differ at an
        // edge, only where the driver's rounding of a depth decides (a
        // depth tie, or a sample at the near plane).
        if algorithm != AlgorithmId::Gpu2dr {
            assert_eq!(r.edge, 0, "{}: coverage differs at an edge", cell.label());
        }
        assert!(cell.output.stats.edge_evaluations > 0, "{}", cell.label());
        let total = per_scene
            .entry((cell.scene.to_string(), algorithm.as_str()))
            .or_default();
        total.covered += r.covered;
        total.edge += r.edge;
        total.near_plane += r.near_plane;
        total.depth_tie += r.depth_tie;
        compared += 1;
    });
    println!(
        "GPU against CPU, per scene (160x120, every camera, own viewport and orthographic); {near_ties} depth near-ties (within 1e-4) in all:"
    );
    for ((scene, algorithm), r) in &per_scene {
        println!(
            "  {scene:10} {algorithm:20} covered {:7}  differing {:4} (edge {}, near plane {}, depth tie {})",
            r.covered,
            r.explained(),
            r.edge,
            r.near_plane,
            r.depth_tie
        );
    }
    // Every scene and camera in two viewports; scenes with see-through
    // materials are refused to the GPU (and so compared on opaque scenes only).
    let opaque = builtin_scenes()
        .iter()
        .filter(|name| prepared(name).triangle_opacity.is_empty())
        .count();
    assert!(opaque >= 10, "only {opaque} opaque built-in scenes");
    assert!(
        compared >= opaque * 2 * 2 * PAIRS.len(),
        "only {compared} compared"
    );
    assert!(rendered > compared, "no CPU reference rendered");
    assert!(
        near_ties <= compared,
        "{near_ties} depth near-ties in {compared} views"
    );
}

/// With anti-aliasing the kernels test the pattern's sample positions: the
/// per-pixel sample digests match the CPU's but for a few pixels at edges.
#[test]
fn gpu_kernels_render_the_aa_patterns() {
    let scene = prepared("teapots");
    let camera = scene.scene.first_camera();
    let mut checked = 0;
    for aa in ["msaa:2", "msaa:4", "ssaa:4"] {
        let aa = AaMode::parse(aa).expect("aa");
        let run = |algorithm| {
            let request = RenderRequest {
                aa,
                ..RenderRequest::new(algorithm, camera.clone(), 200, 150)
            };
            render(&scene, &request).unwrap_or_else(|e| panic!("{algorithm} {aa}: {e}"))
        };
        for (gpu, cpu) in PAIRS {
            let (g, c) = (run(gpu), run(cpu));
            let digests = |o: &RenderOutput| o.framebuffer.sample_digest.clone();
            let differing = digests(&g)
                .iter()
                .zip(&digests(&c))
                .filter(|(a, b)| a != b)
                .count();
            println!(
                "{gpu} {aa}: {differing} of {} pixels differ from {cpu} in some sample",
                200 * 150
            );
            assert!(!digests(&g).is_empty(), "{gpu} {aa}: no sample digests");
            assert!(
                differing * 500 <= 200 * 150,
                "{gpu} {aa}: {differing} pixels differ"
            );
            assert_eq!(
                g.stats.stored_samples_per_pixel,
                c.stats.stored_samples_per_pixel
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 3 * PAIRS.len());
}

/// Counters and stage times mean what the CPU's do.
#[test]
fn gpu_kernels_report_setups_tests_tiles_and_device_times() {
    let scene = prepared("bunny");
    let camera = scene.scene.first_camera();
    let run = |algorithm| {
        render(
            &scene,
            &RenderRequest::new(algorithm, camera.clone(), 256, 192),
        )
        .unwrap_or_else(|e| panic!("{algorithm}: {e}"))
    };
    let cpu = run(AlgorithmId::ThreeDBrute);
    for (gpu, _) in PAIRS {
        let out = run(gpu);
        let s = &out.stats;
        let times = s.gpu.as_ref().expect("GPU stage times");
        assert!(times.adapter.contains("llvmpipe") || !times.adapter.is_empty());
        assert!(
            times.clock == "timestamps" || times.clock == "wall",
            "{gpu}: {}",
            times.clock
        );
        assert!(times.raster > 0.0 && times.setup > 0.0, "{gpu}: {times:?}");
        assert!(s.triangle_setups > 0 && s.edge_evaluations > 0, "{gpu}");
        assert!(s.predicted_instructions > 0, "{gpu}");
        // Every covered sample was counted once per triangle covering it.
        assert_eq!(
            s.coverage_histogram.zero, cpu.stats.coverage_histogram.zero,
            "{gpu}"
        );
        let json = serde_json::to_value(s).expect("stats as JSON");
        assert!(json["gpu"]["clock"].is_string(), "{gpu}: {json}");
        if gpu == AlgorithmId::Gpu3drBinned {
            assert!(s.counters.tiles_tested > 0, "{gpu}: no tile tests");
            assert!(
                s.counters.tiles_rejected + s.counters.tiles_accepted <= s.counters.tiles_tested
            );
        }
    }
}

/// Bad requests name their field; nothing panics or hangs.
#[test]
fn gpu_kernels_refuse_what_they_cannot_render_by_field() {
    let scene = prepared("box");
    let camera = scene.scene.first_camera();
    let field = |request: RenderRequest| {
        render(&scene, &request)
            .err()
            .map(|e| e.field)
            .unwrap_or("rendered")
    };
    let mut refused = 0;
    for (gpu, _) in PAIRS {
        let base = RenderRequest::new(gpu, camera.clone(), 32, 24);
        for aa in ["csaa:8x2", "ssaa:16", "msaa:8"] {
            let r = RenderRequest {
                aa: AaMode::parse(aa).expect("aa"),
                ..base.clone()
            };
            assert_eq!(field(r), "aa", "{gpu} {aa}");
            refused += 1;
        }
        let r = RenderRequest {
            oracles: continuum::Oracles::parse("early_z=off").expect("oracles"),
            ..base.clone()
        };
        assert_eq!(field(r), "oracles", "{gpu}");
        let mut parabolic = base.clone();
        parabolic.camera.viewport = continuum::Viewport::Parabolic;
        let e = render(&scene, &parabolic).expect_err("parabolic");
        assert_eq!(e.field, "viewport", "{gpu}");
        assert!(e.message.contains("perspective and orthographic"), "{e}");
        // Larger than the adapter's largest storage buffer (lavapipe: 128 MiB;
        // 4 samples of 4 bytes for 4096x2100 pixels is 131 MiB).
        let r = RenderRequest {
            aa: AaMode::Ssaa(4),
            ..RenderRequest::new(gpu, camera.clone(), 4096, 2100)
        };
        assert_eq!(field(r), "size", "{gpu}");
        refused += 3;
    }
    // See-through materials: the GPU draws opaque surfaces only.
    let glass = builtin_scenes()
        .into_iter()
        .find(|name| !prepared(name).triangle_opacity.is_empty())
        .expect("a built-in scene with see-through materials");
    let glass = prepared(&glass);
    let e = render(
        &glass,
        &RenderRequest::new(AlgorithmId::Gpu3dr, glass.scene.first_camera(), 32, 24),
    )
    .expect_err("see-through");
    assert_eq!(e.field, "algorithm");
    assert_eq!(refused, PAIRS.len() * 6);
}

/// A grid with a vertex on every pixel centre: every sample lies on a vertex
/// of six triangles, where f32 cannot decide any of them, so the kernels
/// leave every sample to the CPU's exact decision — several per sample,
/// far more than the room first made for them, so the render also runs
/// again with room for all. The result must be the CPU's exactly: the same
/// triangle at every pixel, and each sample inside the grid covered once.
#[test]
fn gpu_kernels_decide_exactly_where_f32_cannot() {
    const N: u32 = 256;
    // Under `exact_camera` at N×N pixels, pixel point (x, y) is world
    // point (−1 + 2x/N, 1 − 2y/N, −1), exactly.
    let at = |x: u32, y: u32| {
        let s = 2.0 / N as f32;
        glam::Vec3::new(
            -1.0 + (x as f32 + 0.5) * s,
            1.0 - (y as f32 + 0.5) * s,
            -1.0,
        )
    };
    let scene = grid_scene(N, at);
    let run = |algorithm| {
        render(
            &scene,
            &RenderRequest::new(algorithm, scene.scene.first_camera(), N, N),
        )
        .unwrap_or_else(|e| panic!("{algorithm}: {e}"))
    };
    let mut checked = 0;
    for (gpu, cpu) in &PAIRS[1..] {
        let (g, c) = (run(*gpu), run(*cpu));
        assert_eq!(
            g.framebuffer.triangle_id, c.framebuffer.triangle_id,
            "{gpu}: ids differ from {cpu}'s"
        );
        let interior = (1..N - 1).flat_map(|y| (1..N - 1).map(move |x| (y * N + x) as usize));
        let not_once: Vec<usize> = interior
            .filter(|&i| g.framebuffer.coverage_writes[i] != 1)
            .collect();
        assert!(
            not_once.is_empty(),
            "{gpu}: {} samples not covered once",
            not_once.len()
        );
        // Each sample was unsure in about six triangles: past the first
        // room of 2^16 pairs.
        let exact = g.stats.counters.edge_tests_f64;
        assert!(
            exact > 1 << 17,
            "{gpu}: only {exact} edge tests decided past f32"
        );
        checked += 1;
    }
    assert_eq!(checked, 3);
}

/// A scene whose set-up triangles would not fit the adapter's largest
/// storage buffer (lavapipe: 128 MiB, 112 bytes per triangle) is an error
/// naming `scene`, for every kernel, not a panic or a hang.
#[test]
fn gpu_kernels_refuse_a_scene_beyond_the_adapters_buffers() {
    // 820 × 820 vertices: 1,341,954 triangles, 150 MB of set-up triangles.
    const N: u32 = 820;
    let scene = grid_scene(N, |x, y| glam::Vec3::new(x as f32, y as f32, -2000.0));
    assert!(scene.triangle_count() as u64 * 112 > 128 << 20);
    let mut refused = 0;
    for (gpu, _) in PAIRS {
        let e = render(
            &scene,
            &RenderRequest::new(gpu, scene.scene.first_camera(), 64, 48),
        )
        .expect_err("beyond the buffers");
        assert_eq!(e.field, "scene", "{gpu}: {e}");
        refused += 1;
    }
    assert_eq!(refused, PAIRS.len());
}

/// A grid of `n` × `n` vertices at `at(x, y)`, two triangles per cell, seen
/// by `exact_camera`.
fn grid_scene(n: u32, at: impl Fn(u32, u32) -> glam::Vec3) -> continuum::PreparedScene {
    let positions = (0..n).flat_map(|y| (0..n).map(move |x| (x, y)));
    let positions = positions.map(|(x, y)| at(x, y)).collect();
    let mut triangles = Vec::new();
    for y in 0..n - 1 {
        for x in 0..n - 1 {
            let v = |dx: u32, dy: u32| (y + dy) * n + x + dx;
            triangles.push([v(0, 0), v(0, 1), v(1, 0)]);
            triangles.push([v(1, 0), v(0, 1), v(1, 1)]);
        }
    }
    continuum_tests::scene_from_triangles(positions, triangles, continuum_tests::exact_camera())
}
