//! The top-left rule: pixel centres exactly on edges and vertices go to exactly
//! one triangle, the Direct3D way, in every algorithm.

use continuum::{AlgorithmId, BACKGROUND, Family};
use continuum_tests::matrix::Matrix;
use continuum_tests::{exact_camera, pixel_point, scene_from_triangles};
use glam::Vec3;

/// Every algorithm, the GPU's included, through the scene's camera at 8×8.
fn every_algorithm() -> Matrix {
    Matrix {
        algorithms: AlgorithmId::ALL.to_vec(),
        size: (8, 8),
        ..Matrix::new()
    }
}

/// Direct3D's worked example: a 5×5 square from (0.5, 0.5) to (5.5, 5.5) split
/// along its diagonal covers 15 + 10 pixels, none twice.
#[test]
fn direct3d_square_split_along_its_diagonal_gives_15_and_10() {
    let positions = vec![
        pixel_point(0.5, 0.5),
        pixel_point(5.5, 0.5),
        pixel_point(5.5, 5.5),
        pixel_point(0.5, 5.5),
    ];
    // Triangle 0 is above-right of the diagonal, triangle 1 below-left.
    for winding in [[[0, 1, 2], [0, 2, 3]], [[0, 2, 1], [0, 3, 2]]] {
        let scene = scene_from_triangles(positions.clone(), winding.to_vec(), exact_camera());
        let rendered = every_algorithm().run_on("square", &scene, |cell| {
            let (algorithm, out) = (cell.request.algorithm, cell.output);
            let fb = &out.framebuffer;
            let count = |id: u32| fb.triangle_id.iter().filter(|&&t| t == id).count();
            assert_eq!(
                (count(0), count(1)),
                (15, 10),
                "{algorithm}, winding {winding:?}"
            );
            assert_eq!(
                out.stats.coverage_histogram.many, 0,
                "{algorithm}: a pixel covered twice"
            );
            // Exactly the pixels with centres in [0.5, 5.5) on both axes.
            for y in 0..8u32 {
                for x in 0..8u32 {
                    let inside = x < 5 && y < 5;
                    let id = fb.triangle_id[(y * 8 + x) as usize];
                    assert_eq!(id != BACKGROUND, inside, "{algorithm} pixel ({x},{y})");
                    if inside {
                        // On or above the diagonal goes to triangle 0 (its edge is a left edge).
                        assert_eq!(
                            id,
                            if x >= y { 0 } else { 1 },
                            "{algorithm} pixel ({x},{y})"
                        );
                    }
                }
            }
        });
        assert_eq!(rendered, AlgorithmId::ALL.len(), "winding {winding:?}");
    }
}

/// A fan of 8 triangles around a vertex that sits exactly on a pixel centre, edges
/// through pixel centres horizontally, vertically and diagonally: every pixel of
/// the fan's square is covered exactly once.
#[test]
fn fan_around_a_vertex_on_a_pixel_centre_covers_each_pixel_once() {
    let c = pixel_point(4.5, 4.5);
    let ring: Vec<Vec3> = [
        (0.5, 0.5),
        (4.5, 0.5),
        (7.5, 0.5),
        (7.5, 4.5),
        (7.5, 7.5),
        (4.5, 7.5),
        (0.5, 7.5),
        (0.5, 4.5),
    ]
    .iter()
    .map(|&(x, y)| pixel_point(x, y))
    .collect();
    let mut positions = vec![c];
    positions.extend(ring);
    let triangles: Vec<[u32; 3]> = (0..8).map(|k| [0, 1 + k, 1 + (k + 1) % 8]).collect();
    let scene = scene_from_triangles(positions, triangles, exact_camera());
    let mut three_d = 0;
    let rendered = every_algorithm().run_on("fan", &scene, |cell| {
        let (algorithm, out) = (cell.request.algorithm, cell.output);
        let fb = &out.framebuffer;
        for y in 0..8u32 {
            for x in 0..8u32 {
                // Centres in [0.5, 7.5) belong to the square (its left and top edges included).
                let expected = u32::from(x < 7 && y < 7);
                assert_eq!(
                    fb.coverage_writes[(y * 8 + x) as usize],
                    expected,
                    "{algorithm} pixel ({x},{y})"
                );
            }
        }
        // The centre vertex lies exactly on a pixel centre's ray: the 3D and
        // homogeneous families decide their edges there past f32, some
        // exactly, and count them (README: "Precision and exactness"), the
        // GPU kernels of those families through the CPU; the 2D family,
        // `gpu-2dr` and `gpu-raster` have no such path.
        let c = &out.stats.counters;
        let exact_gpu = matches!(
            algorithm,
            AlgorithmId::Gpu2drHomogeneous | AlgorithmId::Gpu3dr | AlgorithmId::Gpu3drBinned
        );
        if exact_gpu || matches!(algorithm.family(), Family::ThreeD | Family::Homogeneous) {
            three_d += 1;
            assert!(c.edge_tests_exact > 0, "{algorithm}: {c:?}");
            assert!(c.edge_tests_f64 >= c.edge_tests_exact, "{algorithm}: {c:?}");
        } else {
            assert_eq!(
                (c.edge_tests_f64, c.edge_tests_exact),
                (0, 0),
                "{algorithm}"
            );
        }
    });
    assert_eq!(rendered, AlgorithmId::ALL.len());
    assert_eq!(
        three_d, 10,
        "2dr-homogeneous, the five 3D rasterizers, raycast and three GPU kernels"
    );
}
