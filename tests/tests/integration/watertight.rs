//! Watertightness: on a plane filling the screen and inside a closed sphere every
//! pixel gets exactly one coverage write, in every algorithm.

use continuum::AlgorithmId;
use continuum_tests::matrix::{Cameras, Matrix};

fn assert_every_pixel_covered_once(scene: &str, camera: &'static str) {
    for (w, h) in [(640, 480), (333, 201)] {
        let rendered = Matrix {
            scenes: vec![scene.into()],
            cameras: Cameras::Named(camera),
            algorithms: AlgorithmId::ALL.to_vec(),
            size: (w, h),
            ..Matrix::new()
        }
        .run(|cell| {
            let hist = cell.output.stats.coverage_histogram;
            assert_eq!(
                (hist.zero, hist.many),
                (0, 0),
                "{} at {w}x{h}: {hist:?}",
                cell.label()
            );
            assert_eq!(hist.one, u64::from(w * h), "{}", cell.label());
        });
        assert_eq!(
            rendered,
            AlgorithmId::ALL.len(),
            "{scene}/{camera} at {w}x{h}"
        );
    }
}

#[test]
fn grid_filling_the_screen_is_covered_exactly_once() {
    assert_every_pixel_covered_once("grid", "fill");
}

#[test]
fn closed_sphere_seen_from_inside_is_covered_exactly_once() {
    assert_every_pixel_covered_once("sphere", "inside");
}

#[test]
fn closed_box_seen_from_inside_is_covered_exactly_once() {
    assert_every_pixel_covered_once("box", "inside");
}
