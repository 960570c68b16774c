//! The frame's counters are what its per-pixel planes hold: the edge
//! evaluations `Stats` reports (counted tile by tile in the resolve) are the
//! sum and the maximum of the framebuffer's `edge_evals`.

use continuum::{AaMode, AlgorithmId, RenderRequest, StageTimes, Stats, render};
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

/// A render without counter planes (`RenderRequest::counter_planes` off, as
/// `compare` times) is the render with them, less those planes: the same
/// colours, depths, ids, sample digests and counters in `Stats`, every
/// algorithm, with and without anti-aliasing; its counter planes are empty.
#[test]
fn a_frame_without_counter_planes_is_the_same_frame() {
    let matrix = Matrix {
        aa: vec![AaMode::None, AaMode::Msaa(4)],
        algorithms: AlgorithmId::ALL.to_vec(),
        size: (97, 61),
        ..Matrix::new()
    };
    let rendered = matrix.run(|cell| {
        let label = cell.label();
        let request = RenderRequest {
            counter_planes: false,
            ..cell.request.clone()
        };
        let out = render(cell.prepared, &request).unwrap_or_else(|e| panic!("{label}: {e}"));
        let (with, without) = (&cell.output.framebuffer, &out.framebuffer);
        assert!(
            without.edge_evals.is_empty() && without.coverage_writes.is_empty(),
            "{label}"
        );
        assert_eq!(with.color, without.color, "{label}: colour");
        assert_eq!(with.depth, without.depth, "{label}: depth");
        assert_eq!(with.triangle_id, without.triangle_id, "{label}: ids");
        assert_eq!(
            with.sample_digest, without.sample_digest,
            "{label}: samples"
        );
        assert_eq!(with.blended, without.blended, "{label}: blended");
        // Everything but the times.
        let counters = |s: &Stats| {
            let mut s = s.clone();
            s.time_ms = StageTimes::default();
            s.gpu = None;
            s.effects.iter_mut().for_each(|e| e.worker_ms = 0.0);
            s
        };
        assert_eq!(
            counters(&cell.output.stats),
            counters(&out.stats),
            "{label}: stats"
        );
        // And the next render that asks for them, in this frame's memory
        // (the pool's), has them again.
        out.framebuffer.recycle();
        let again = render(cell.prepared, cell.request).unwrap_or_else(|e| panic!("{label}: {e}"));
        assert_eq!(again.framebuffer, *with, "{label}: the next frame");
    });
    assert!(
        rendered >= builtin_scenes().len() * 2 * 10,
        "only {rendered} cells rendered"
    );
}
