//! Golden images, compared exactly (see `continuum_tests::golden`): every
//! anti-aliasing mode, every scene with effects beyond Lambert shading, and
//! the edge-evaluation heat map. The viewport goldens live in `viewports.rs`.
//! Regenerate with `UPDATE_GOLDEN=1 cargo test -p continuum-tests golden`.

use continuum::{AaMode, AlgorithmId, maps};
use continuum_tests::golden::assert_golden;
use continuum_tests::matrix::Matrix;

/// `soup` (20,000 random triangles: edges everywhere) under every mode the
/// renderer accepts, through `3dr-bin`.
#[test]
fn golden_every_aa_mode() {
    let modes = AaMode::all();
    let rendered = Matrix {
        scenes: vec!["soup".into()],
        aa: modes.clone(),
        algorithms: vec![AlgorithmId::ThreeDBin],
        ..Matrix::new()
    }
    .run(|cell| {
        let mode = cell.request.aa.to_string().replace(':', "");
        assert_golden(
            &format!("aa/soup_{mode}"),
            &maps::color_image(&cell.output.framebuffer),
        );
    });
    assert_eq!(rendered, modes.len());
    assert!(rendered >= 18, "only {rendered} modes");
}

/// Every built-in scene whose materials or lights call for effects
/// (textures, shadows, reflections, transparency), through `3dr-bin`.
#[test]
fn golden_every_effect_scene() {
    let scenes: Vec<String> = continuum_tests::builtin_scenes()
        .into_iter()
        .filter(|name| !continuum_tests::prepared(name).scene.effects().is_empty())
        .collect();
    assert!(scenes.len() >= 5, "effect scenes: {scenes:?}");
    let rendered = Matrix {
        scenes: scenes.clone(),
        algorithms: vec![AlgorithmId::ThreeDBin],
        size: (128, 96),
        ..Matrix::new()
    }
    .run(|cell| {
        assert_golden(
            &format!("effects/{}", cell.scene),
            &maps::color_image(&cell.output.framebuffer),
        );
    });
    assert_eq!(rendered, scenes.len());
}

/// The heat map of edge evaluations per pixel (the paper's Fig. 1 maps) of
/// `bunny` for a brute-force, a binned and a frustum-traversal algorithm.
#[test]
fn golden_heat_maps() {
    let algorithms = [
        AlgorithmId::ThreeDBrute,
        AlgorithmId::ThreeDBin,
        AlgorithmId::ThreeDFull,
    ];
    let rendered = Matrix {
        scenes: vec!["bunny".into()],
        algorithms: algorithms.to_vec(),
        size: (128, 96),
        ..Matrix::new()
    }
    .run(|cell| {
        assert_golden(
            &format!("heat/bunny_{}", cell.request.algorithm),
            &maps::edge_eval_image(&cell.output.framebuffer),
        );
    });
    assert_eq!(rendered, algorithms.len());
}
