//! The frame's counters are what its per-pixel planes hold: the edge
//! evaluations `Stats` reports (counted tile by tile in the resolve) are the
//! sum and the maximum of the framebuffer's `edge_evals`.

use continuum::{AaMode, AlgorithmId};
use continuum_tests::builtin_scenes;
use continuum_tests::matrix::Matrix;

#[test]
fn the_reported_edge_evaluations_are_the_frames_per_pixel_counts() {
    let matrix = Matrix {
        aa: vec![
            AaMode::None,
            AaMode::Msaa(4),
            AaMode::Csaa {
                coverage: 8,
                stored: 2,
            },
        ],
        algorithms: AlgorithmId::ALL.to_vec(),
        size: (97, 61),
        ..Matrix::new()
    };
    let mut counted = 0u64;
    let rendered = matrix.run(|cell| {
        let (stats, fb) = (&cell.output.stats, &cell.output.framebuffer);
        let sum: u64 = fb.edge_evals.iter().map(|&e| u64::from(e)).sum();
        let max = fb.edge_evals.iter().copied().max().unwrap_or(0);
        assert_eq!(stats.edge_evaluations, sum, "{}", cell.label());
        assert_eq!(stats.max_edge_evals_per_pixel, max, "{}", cell.label());
        counted += sum;
    });
    // Every built-in scene, three AA modes, and at least the ten CPU
    // algorithms (the GPU's where the capability check lets them run).
    assert!(
        rendered >= builtin_scenes().len() * 3 * 10,
        "only {rendered} cells rendered"
    );
    assert!(counted > 0, "no cell evaluated an edge");
}
