//! Any point of the continuum renders the same image: random oracle settings and
//! tile sizes against the family's brute-force reference.

use continuum::{AaMode, AlgorithmId, Oracles, Precision, Viewport};
use continuum_tests::matrix::{Cameras, Matrix, ViewportChoice};
use continuum_tests::{id_differences, prepared, render_with, render_with_oracles};
use proptest::prelude::*;

const W: u32 = 200;
const H: u32 = 150;

fn on(b: bool) -> &'static str {
    if b { "on" } else { "off" }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn bvh_traversal_oracles_never_change_the_image(
        scene in prop::sample::select(vec!["bunny", "soup", "sphere", "orientation"]),
        camera in 0usize..2,
        outside in any::<bool>(),
        occluded in any::<bool>(),
        final_depth in any::<bool>(),
        binning in any::<bool>(),
        early_z in any::<bool>(),
        split in prop::sample::select(vec!["off", "8", "16", "64"]),
        frustum in prop::sample::select(vec![64u32, 128, 256]),
        leaf in prop::sample::select(vec![4u32, 8, 16, 32]),
    ) {
        let p = prepared(scene);
        let camera = &p.scene.cameras[camera];
        let oracles = format!(
            "outside={},occluded={},final_depth={},binning={},early_z={},split={split},frustum={frustum},leaf={leaf}",
            on(outside), on(occluded), on(occluded && final_depth), on(binning), on(early_z)
        );
        let reference = render_with(&p, AlgorithmId::ThreeDBrute, camera, W, H);
        let out = render_with_oracles(&p, AlgorithmId::ThreeDFull, Some(&oracles), camera, W, H);
        let diff = id_differences(&reference, &out);
        prop_assert!(diff.is_empty(), "{scene}/{}: {oracles}: {} pixels differ, first {:?}", camera.name, diff.len(), &diff[..diff.len().min(5)]);
        prop_assert_eq!(&reference.framebuffer.depth, &out.framebuffer.depth);
    }

    #[test]
    fn binning_oracles_never_change_the_image(
        scene in prop::sample::select(vec!["bunny", "soup", "grid", "box"]),
        camera in 0usize..2,
        two_d in any::<bool>(),
        binning in any::<bool>(),
        early_z in any::<bool>(),
        leaf in prop::sample::select(vec![4u32, 8, 16, 32, 64]),
    ) {
        let p = prepared(scene);
        let camera = &p.scene.cameras[camera];
        let (brute, binned) = if two_d {
            (AlgorithmId::TwoDBrute, AlgorithmId::TwoDBin)
        } else {
            (AlgorithmId::ThreeDBrute, AlgorithmId::ThreeDBin)
        };
        let oracles = format!("binning={},early_z={},leaf={leaf}", on(binning), on(early_z));
        let reference = render_with(&p, brute, camera, W, H);
        let out = render_with_oracles(&p, binned, Some(&oracles), camera, W, H);
        let diff = id_differences(&reference, &out);
        prop_assert!(diff.is_empty(), "{scene}/{} {binned}: {oracles}: {} pixels differ", camera.name, diff.len());
    }
}

#[test]
fn bad_oracles_are_errors_naming_the_field() {
    let p = prepared("box");
    let cases = [
        (AlgorithmId::ThreeDFull, "split=7"),
        (AlgorithmId::ThreeDFull, "speed=fast"),
        (AlgorithmId::ThreeDFull, "outside=maybe"),
        (AlgorithmId::ThreeDBin, "split=8"),
        (AlgorithmId::Raycast, "binning=on"),
        (AlgorithmId::Raycast, "packet=32"),
        (AlgorithmId::Raycast, "packet=8,split=8"),
        (AlgorithmId::ThreeDFull, "packet=8"),
        (AlgorithmId::ThreeDFull, "binning"),
        (AlgorithmId::ThreeDFull, "occluded=off,final_depth=on"),
        (AlgorithmId::ThreeDBin, "final_depth=on"),
        (AlgorithmId::Raycast, "final_depth=on"),
    ];
    for (algorithm, text) in cases {
        // The words through the front door, then the render.
        let words = continuum::RenderWords {
            oracles: Some(text.into()),
            size: Some("8x8".into()),
            ..continuum::RenderWords::new(algorithm.as_str())
        };
        let err = words
            .request(&p.scene)
            .and_then(|request| continuum::render(&p, &request).map(|_| ()))
            .expect_err(text);
        assert_eq!(err.field, "oracles", "{text}: {err}");
    }
}

/// Occlusion culling culls on a scene of small triangles with background
/// between them (`teapots`, where nearly every 8×8 frustum along a silhouette
/// keeps an empty pixel, so a farthest depth over all its samples stays
/// infinite): the mask of covered pixels lets the nodes behind a teapot's
/// front go. With a plain hierarchical w-buffer this render culled 61 nodes
/// and set up as many triangles as without occlusion culling; now both drop
/// (15% of the node visits and a third of the setups), and the image stays.
#[test]
fn occlusion_culling_culls_behind_partly_covered_frusta() {
    let p = prepared("teapots");
    let camera = p.scene.first_camera();
    let frustum_split = AlgorithmId::ThreeDFrustumSplit;
    let render = |oracles| render_with_oracles(&p, frustum_split, Some(oracles), &camera, 320, 180);
    let (off, on) = (render("occluded=off"), render("occluded=on"));
    assert!(id_differences(&off, &on).is_empty());
    let (a, b) = (&off.stats, &on.stats);
    assert_eq!(a.counters.nodes_culled_occluded, 0);
    assert!(
        b.counters.nodes_culled_occluded > 10_000,
        "{} culled as occluded",
        b.counters.nodes_culled_occluded
    );
    assert!(
        b.bvh_nodes_visited * 10 < a.bvh_nodes_visited * 9,
        "node visits {} with occlusion culling, {} without",
        b.bvh_nodes_visited,
        a.bvh_nodes_visited
    );
    assert!(
        b.triangle_setups * 4 < a.triangle_setups * 3,
        "triangle setups {} with occlusion culling, {} without",
        b.triangle_setups,
        a.triangle_setups
    );
}

/// The `final_depth` oracle (occlusion tests that read the depths each tile
/// ends with, sample by sample) renders the same image and counts only its
/// second traversal: fewer node visits, setups and edge tests than occlusion
/// culling makes as it goes on `teapots` — a node the w-buffer hides at some
/// moment lies behind every final depth over its box — and the per-pixel
/// counts sum to the totals.
#[test]
fn the_final_depth_oracle_bounds_occlusion_culling() {
    let p = prepared("teapots");
    let camera = p.scene.first_camera();
    let mut checked = 0;
    for algorithm in [AlgorithmId::ThreeDFrustumSplit, AlgorithmId::ThreeDFull] {
        let render = |oracles| render_with_oracles(&p, algorithm, Some(oracles), &camera, 320, 180);
        let (going, known) = (render("occluded=on"), render("final_depth=on"));
        assert!(id_differences(&going, &known).is_empty(), "{algorithm}");
        let (fa, fb) = (&going.framebuffer, &known.framebuffer);
        assert_eq!(
            (&fa.depth, &fa.color),
            (&fb.depth, &fb.color),
            "{algorithm}"
        );
        let (a, b) = (&going.stats, &known.stats);
        assert!(
            b.bvh_nodes_visited < a.bvh_nodes_visited,
            "{algorithm}: node visits {} with the final depths, {} as it goes",
            b.bvh_nodes_visited,
            a.bvh_nodes_visited
        );
        // Measured: 0.80 of the setups (3dr-frustum-split) since a leaf's first
        // rasterization sets up the triangles of its node's other leaves
        // with it, some of which occlusion culling then spares (0.70 when
        // each leaf set up its own; reading the depths per sample as they
        // come, with no first traversal, set up 0.76 of those).
        assert!(
            b.triangle_setups * 100 < a.triangle_setups * 85,
            "{algorithm}: triangle setups {} with the final depths, {} as it goes",
            b.triangle_setups,
            a.triangle_setups
        );
        assert!(b.edge_evaluations <= a.edge_evaluations, "{algorithm}");
        let sum: u64 = fb.edge_evals.iter().map(|&e| u64::from(e)).sum();
        assert_eq!(sum, b.edge_evaluations, "{algorithm}");
        checked += 1;
    }
    assert_eq!(checked, 2);
}

/// Every packet size of the ray caster (one, four or sixteen 4×4 groups of
/// rays walking the BVH together) renders what `3dr-brute` renders, every
/// buffer hash alike: every built-in scene and camera, planar and curved
/// viewports, CSAA (coverage-only positions), f32 and f64, at a size no
/// packet divides (packets cut by the image's edges).
#[test]
fn raycast_packet_sizes_never_change_the_image() {
    let mut oracles = vec![Oracles::default()];
    for text in ["packet=4", "packet=8", "packet=16"] {
        oracles.push(Oracles::parse(text).expect("valid words"));
    }
    let compared = Matrix {
        cameras: Cameras::All,
        viewports: vec![
            ViewportChoice::Own,
            ViewportChoice::Orthographic,
            ViewportChoice::Is(Viewport::Parabolic),
        ],
        aa: vec![
            AaMode::None,
            AaMode::Csaa {
                coverage: 8,
                stored: 2,
            },
        ],
        precisions: vec![Precision::F32, Precision::F64],
        algorithms: vec![AlgorithmId::ThreeDBrute, AlgorithmId::Raycast],
        oracles,
        size: (70, 45),
        ..Matrix::new()
    }
    .assert_families_agree();
    // Scenes × cameras × 3 viewports × 2 modes × 2 precisions, four
    // settings each (the ray caster serves every cell 3dr-brute does).
    assert!(
        compared >= 12 * 3 * 2 * 2 * 4,
        "only {compared} ray-cast cells compared"
    );
}
