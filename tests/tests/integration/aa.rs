//! Anti-aliasing: every sample of a pattern is decided like a pixel centre, so
//! coverage follows the geometry exactly, closed meshes are covered once per
//! sample, algorithms agree per sample, and shading runs as often as each mode
//! promises.

use continuum::{AaMode, AlgorithmId, Viewport};
use continuum_tests::matrix::{Matrix, ViewportChoice};
use continuum_tests::{exact_camera, pixel_point, prepared, render_aa, scene_from_triangles};
use glam::{DVec2, Vec3};

fn world(p: DVec2) -> Vec3 {
    pixel_point(p.x as f32, p.y as f32)
}

/// Area of the unit pixel `[x, x+1] × [y, y+1]` where `n·(p − c) ≥ t`
/// (Sutherland–Hodgman against one half-plane, then the shoelace formula).
fn analytic_area(pixel: DVec2, n: DVec2, c: DVec2, t: f64) -> f64 {
    let square = [
        pixel,
        pixel + DVec2::X,
        pixel + DVec2::ONE,
        pixel + DVec2::Y,
    ];
    let f = |p: DVec2| n.dot(p - c) - t;
    let mut poly = Vec::new();
    for k in 0..4 {
        let (a, b) = (square[k], square[(k + 1) % 4]);
        let (fa, fb) = (f(a), f(b));
        if fa >= 0.0 {
            poly.push(a);
        }
        if (fa >= 0.0) != (fb >= 0.0) {
            poly.push(a + (b - a) * (fa / (fa - fb)));
        }
    }
    let mut area = 0.0;
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        area += a.x * b.y - b.x * a.y;
    }
    area.abs() * 0.5
}

/// A straight edge across pixel (3, 3) at many angles and offsets: the covered
/// count is exactly the number of pattern positions on the inner side (every
/// sample goes through the edge function), and the covered fraction is within
/// the pattern's documented bound of the analytic area (1/N for axis-aligned
/// edges; (2k − 1)/N for k×k stratified patterns at any angle). The mean
/// absolute error per mode is printed (`--nocapture`).
#[test]
fn edge_coverage_matches_the_pattern_and_the_analytic_area() {
    let modes: Vec<AaMode> = AaMode::all()
        .into_iter()
        .filter(|m| matches!(m, AaMode::Msaa(_) | AaMode::Ssaa(_)))
        .collect();
    let pixel = DVec2::new(3.0, 3.0);
    let c = pixel + DVec2::splat(0.5);
    let mut errors = vec![(0.0f64, 0u32, 0.0f64); modes.len()];
    for step in 0..48 {
        let angle = f64::from(step) * std::f64::consts::TAU / 48.0;
        let axis_aligned = step % 12 == 0;
        let n = DVec2::new(angle.cos(), angle.sin());
        let u = DVec2::new(-n.y, n.x);
        for k in -6..=6 {
            // An irrational-looking shift keeps sample positions off the line.
            let t = f64::from(k) * 0.1 + 0.013_7;
            let on_line = c + n * t;
            let positions = vec![
                world(on_line + u * 50.0),
                world(on_line - u * 50.0),
                world(on_line + n * 50.0),
            ];
            let scene = scene_from_triangles(positions, vec![[0, 1, 2]], exact_camera());
            let area = analytic_area(pixel, n, c, t);
            for (m, &mode) in modes.iter().enumerate() {
                let pattern = mode.pattern();
                let side = |q: &[f32; 2]| {
                    n.dot(pixel + DVec2::new(f64::from(q[0]), f64::from(q[1])) - c) - t
                };
                if pattern.positions.iter().any(|q| side(q).abs() < 1e-4) {
                    continue;
                }
                let expected = pattern.positions.iter().filter(|q| side(q) > 0.0).count() as u32;
                let out = render_aa(
                    &scene,
                    AlgorithmId::ThreeDBrute,
                    &exact_camera(),
                    (8, 8),
                    mode,
                );
                let covered = out.framebuffer.coverage_writes[3 * 8 + 3];
                assert_eq!(covered, expected, "{mode}: angle step {step}, offset {t}");
                let fraction = f64::from(covered) / pattern.positions.len() as f64;
                let error = (fraction - area).abs();
                let bound = pattern.edge_error_bound(axis_aligned);
                assert!(
                    error <= bound + 1e-12,
                    "{mode}: edge at angle step {step}, offset {t}: {fraction} vs area {area}, bound {bound}"
                );
                errors[m].0 += error;
                errors[m].1 += 1;
                errors[m].2 = errors[m].2.max(error);
            }
        }
    }
    println!("mode        mean |covered − area|   max");
    for (mode, (sum, count, max)) in modes.iter().zip(&errors) {
        assert!(*count > 400, "{mode}: only {count} edges tested");
        println!(
            "{:<10} {:>12.5} {:>12.5}",
            mode.to_string(),
            sum / f64::from(*count),
            max
        );
    }
    // The stratified patterns are the ones the bound says.
    let grids: Vec<Option<usize>> = modes
        .iter()
        .map(|m| m.pattern().stratified_grid())
        .collect();
    let expected: Vec<Option<usize>> = modes
        .iter()
        .map(|m| match m {
            AaMode::Ssaa(4) | AaMode::Msaa(4) => Some(2),
            AaMode::Ssaa(64) => Some(8),
            AaMode::Ssaa(256) => Some(16),
            _ => None,
        })
        .collect();
    assert_eq!(grids, expected);
    // More samples, closer to the area: the mean error falls with N.
    let mean = |m: AaMode| {
        let k = modes.iter().position(|&x| x == m).unwrap_or(0);
        errors[k].0 / f64::from(errors[k].1)
    };
    assert!(mean(AaMode::Msaa(16)) < mean(AaMode::Msaa(4)));
    assert!(mean(AaMode::Ssaa(256)) < mean(AaMode::Ssaa(16)));
    assert!(
        mean(AaMode::Ssaa(256)) < 0.01,
        "{}",
        mean(AaMode::Ssaa(256))
    );
}

/// Inside a closed box, and on a grid filling the screen, every stored sample of
/// every mode gets exactly one coverage write, in every algorithm.
#[test]
fn closed_geometry_is_covered_once_per_sample() {
    for (scene, camera) in [("box", "inside"), ("grid", "fill")] {
        let prepared = prepared(scene);
        let camera = prepared.scene.camera(camera).expect("camera exists");
        for mode in [
            AaMode::Msaa(4),
            AaMode::Csaa {
                coverage: 8,
                stored: 2,
            },
            AaMode::Ssaa(16),
        ] {
            for algorithm in AlgorithmId::CPU {
                let (w, h) = (67, 43);
                let out = render_aa(&prepared, algorithm, &camera, (w, h), mode);
                let hist = out.stats.coverage_histogram;
                let samples = u64::from(w * h) * u64::from(mode.stored_samples());
                assert_eq!(
                    (hist.zero, hist.one, hist.many),
                    (0, samples, 0),
                    "{scene} {mode} {algorithm}"
                );
            }
        }
    }
}

/// Every algorithm of a family stores the same triangle at every sample (and,
/// under CSAA, the same coverage masks) and resolves the same colours, on every
/// built-in scene and on a non-planar viewport.
#[test]
fn algorithms_agree_per_sample() {
    let modes = [
        AaMode::Msaa(4),
        AaMode::Csaa {
            coverage: 16,
            stored: 4,
        },
        AaMode::Ssaa(16),
    ];
    let every_scene = Matrix {
        aa: modes.to_vec(),
        ..Matrix::new()
    };
    let compared = every_scene.assert_families_agree();
    // 12 scenes × 3 modes, 5 3D comparisons and 1 2D one each.
    assert!(compared >= 12 * 3 * 6, "only {compared} comparisons");
    let parabolic = Matrix {
        scenes: vec!["teapots".into()],
        viewports: vec![ViewportChoice::Is(Viewport::Parabolic)],
        ..every_scene
    };
    // 3dr-brute, 3dr-bin and raycast serve the parabolic viewport.
    let compared = parabolic.assert_families_agree();
    assert_eq!(compared, 3 * 2, "parabolic comparisons");
}

/// MSAA shades once per pixel per triangle it shows, SSAA once per covered
/// sample, CSAA once per triangle held by a stored sample: counted against an
/// exact model of two triangles splitting a square along its diagonal.
#[test]
fn shading_runs_once_per_pixel_and_triangle_or_once_per_sample() {
    // A square from (0.513, 0.529) to (5.513, 5.329), split along a diagonal;
    // the odd offsets keep every sample off the edges.
    let (a, b) = (DVec2::new(0.513, 0.529), DVec2::new(5.513, 5.329));
    let corners = [a, DVec2::new(b.x, a.y), b, DVec2::new(a.x, b.y)];
    let scene = scene_from_triangles(
        corners.iter().map(|&p| world(p)).collect(),
        vec![[0, 1, 2], [0, 2, 3]],
        exact_camera(),
    );
    // 0: above-right of the diagonal, 1: below-left, None: outside.
    let which = |p: DVec2| -> Option<u32> {
        if p.x <= a.x || p.x >= b.x || p.y <= a.y || p.y >= b.y {
            return None;
        }
        let d = b - a;
        let cross = d.x * (p.y - a.y) - d.y * (p.x - a.x);
        assert!(cross.abs() > 1e-4, "sample too close to the diagonal");
        Some(u32::from(cross > 0.0))
    };
    for mode in [
        AaMode::Msaa(4),
        AaMode::Msaa(16),
        AaMode::Ssaa(16),
        AaMode::Csaa {
            coverage: 16,
            stored: 4,
        },
    ] {
        let pattern = mode.pattern();
        let mut expected = 0u64;
        for y in 0..8 {
            for x in 0..8 {
                let seen: Vec<Option<u32>> = pattern.positions[..pattern.stored]
                    .iter()
                    .map(|q| {
                        which(DVec2::new(
                            f64::from(x) + f64::from(q[0]),
                            f64::from(y) + f64::from(q[1]),
                        ))
                    })
                    .collect();
                expected += if pattern.shade_per_sample {
                    seen.iter().flatten().count() as u64
                } else {
                    u64::from(seen.contains(&Some(0))) + u64::from(seen.contains(&Some(1)))
                };
            }
        }
        assert!(expected > 20, "{mode}: a test that shades nothing");
        for algorithm in AlgorithmId::CPU {
            let out = render_aa(&scene, algorithm, &exact_camera(), (8, 8), mode);
            assert_eq!(out.stats.shading_samples, expected, "{mode} {algorithm}");
        }
    }
}
