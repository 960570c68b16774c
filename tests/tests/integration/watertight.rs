//! Watertightness: on a plane filling the screen and inside a closed sphere every
//! pixel gets exactly one coverage write, in every algorithm.

use continuum::AlgorithmId;
use continuum_tests::{prepared, render_with};

fn assert_every_pixel_covered_once(scene: &str, camera: &str) {
    let prepared = prepared(scene);
    let camera = prepared.scene.camera(camera).expect("camera exists");
    for algorithm in AlgorithmId::ALL {
        for (w, h) in [(640, 480), (333, 201)] {
            let out = render_with(&prepared, algorithm, &camera, w, h);
            let hist = out.stats.coverage_histogram;
            assert_eq!(
                (hist.zero, hist.many),
                (0, 0),
                "{scene}/{} with {algorithm} at {w}x{h}: {hist:?}",
                camera.name
            );
            assert_eq!(hist.one, u64::from(w * h));
        }
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
