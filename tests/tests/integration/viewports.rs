//! Viewports (paper §3.3, §3.5): orthographic, parabolic and latitude–longitude
//! rendering agree across every algorithm that serves them, curved edges lose no
//! sample to binning, closed meshes stay watertight on curved viewports, and the
//! golden images of `teapots` hold.

use continuum::{
    AlgorithmId, Camera, Family, Oracles, RenderOutput, RenderRequest, Viewport, render,
};
use continuum_tests::golden::assert_golden;
use continuum_tests::matrix::{Cameras, Matrix, ViewportChoice, orthographic_for};
use continuum_tests::{explain_2d_3d, id_differences, prepared, render_with};
use glam::Vec3;

const W: u32 = 192;
const H: u32 = 96;

fn with_viewport(camera: &Camera, viewport: Viewport) -> Camera {
    Camera {
        viewport,
        ..camera.clone()
    }
}

fn assert_identical(what: &str, a: &RenderOutput, b: &RenderOutput) {
    let diff = id_differences(a, b);
    assert!(
        diff.is_empty(),
        "{what}: {} and {} differ at {} pixels, first {:?}",
        a.algorithm,
        b.algorithm,
        diff.len(),
        &diff[..diff.len().min(8)]
    );
    assert_eq!(a.framebuffer.depth, b.framebuffer.depth, "{what}: depth");
}

/// On every built-in scene, camera and viewport, every 3D algorithm that serves
/// the viewport — with binning on and off — and the ray caster give the same
/// triangle ids and depths bit for bit.
#[test]
fn three_d_family_and_raycast_agree_on_every_viewport() {
    let three_d: Vec<AlgorithmId> = AlgorithmId::CPU
        .into_iter()
        .filter(|a| a.family() == Family::ThreeD)
        .collect();
    // Binning without early-z: every curved block test is exercised.
    let binning_only = Oracles::parse("early_z=off").expect("valid words");
    let mut compared = 0;
    Matrix {
        cameras: Cameras::All,
        viewports: vec![
            ViewportChoice::Orthographic,
            ViewportChoice::Is(Viewport::Parabolic),
            ViewportChoice::Is(Viewport::LatLong),
        ],
        algorithms: three_d,
        oracles: vec![Oracles::default(), binning_only],
        size: (W, H),
        ..Matrix::new()
    }
    .run_against_first(|cell, first| {
        let Some(reference) = first else {
            let drawn = cell.output.framebuffer.triangle_id.iter();
            let covered = drawn.filter(|&&id| id != continuum::BACKGROUND).count();
            assert!(covered > 0, "{}: nothing drawn", cell.label());
            return;
        };
        assert_identical(&cell.label(), reference, cell.output);
        if cell.request.algorithm == AlgorithmId::ThreeDBin && cell.request.oracles == binning_only
        {
            assert_eq!(
                cell.output.framebuffer.coverage_writes,
                reference.framebuffer.coverage_writes,
                "{}: binning lost or added a covered sample",
                cell.label()
            );
        }
        compared += 1;
    });
    assert!(compared >= 7 * 2 * 9, "only {compared} comparisons");
}

/// Both 2D families serve orthographic views: 2dr-brute and 2dr-bin bit for bit,
/// and against 3dr-brute every differing pixel explained in f64.
#[test]
fn two_d_families_serve_orthographic_views() {
    let (mut covered, mut differing, mut explained) = (0, 0, 0);
    let mut three: Option<RenderOutput> = None;
    let mut two: Option<RenderOutput> = None;
    let rendered = Matrix {
        cameras: Cameras::All,
        viewports: vec![ViewportChoice::Orthographic],
        algorithms: vec![
            AlgorithmId::ThreeDBrute,
            AlgorithmId::TwoDBrute,
            AlgorithmId::TwoDBin,
            AlgorithmId::TwoDHomogeneous,
        ],
        size: (W, H),
        ..Matrix::new()
    }
    .run(|cell| {
        let out = cell.output;
        match cell.request.algorithm {
            AlgorithmId::ThreeDBrute => three = Some(out.clone()),
            AlgorithmId::TwoDBin => {
                let two = two.as_ref().expect("2dr-brute renders before 2dr-bin");
                assert_identical(&cell.label(), two, out);
            }
            _ => {
                let three = three.as_ref().expect("3dr-brute renders first");
                let r = explain_2d_3d(cell.prepared, out, three);
                assert!(
                    r.unexplained.is_empty(),
                    "{}: unexplained differences {:?}",
                    cell.label(),
                    &r.unexplained[..r.unexplained.len().min(10)]
                );
                covered += r.covered;
                differing += r.explained();
                explained += 1;
                if cell.request.algorithm == AlgorithmId::TwoDBrute {
                    two = Some(out.clone());
                }
            }
        }
    });
    // 12 scenes, two cameras or more each, four algorithms.
    assert!(rendered >= 12 * 2 * 4, "only {rendered} renders");
    assert_eq!(
        explained * 2,
        rendered,
        "two 2D renders explained per camera"
    );
    println!("orthographic, 2D families vs 3D: {differing} of {covered} covered pixels differ");
    assert!(
        differing * 10_000 <= covered,
        "{differing} differing pixels is more than 0.01% of {covered}"
    );
}

/// The §3.5 double-incremental scheme decides every sample as direct evaluation does.
#[test]
fn incremental_evaluation_decides_like_direct_evaluation() {
    let incremental = Oracles::parse("incremental=on").expect("valid words");
    let mut direct: Option<RenderOutput> = None;
    let mut compared = 0;
    Matrix {
        cameras: Cameras::All,
        viewports: vec![ViewportChoice::Is(Viewport::Parabolic)],
        algorithms: vec![AlgorithmId::ThreeDBrute, AlgorithmId::ThreeDBin],
        oracles: vec![Oracles::default(), incremental],
        size: (128, 128),
        ..Matrix::new()
    }
    .run(|cell| {
        if cell.request.oracles != incremental {
            direct = Some(cell.output.clone());
            return;
        }
        let direct = direct.as_ref().expect("the direct render comes first");
        assert_eq!(direct.algorithm, cell.request.algorithm);
        assert_identical(&cell.label(), direct, cell.output);
        assert_eq!(
            direct.framebuffer.coverage_writes,
            cell.output.framebuffer.coverage_writes,
            "{}: coverage decisions differ",
            cell.label()
        );
        compared += 1;
    });
    assert!(compared >= 12 * 2 * 2, "only {compared} comparisons");
    let scene = prepared("box");
    let camera = with_viewport(&scene.scene.first_camera(), Viewport::LatLong);
    let e = render(
        &scene,
        &RenderRequest {
            oracles: continuum::Oracles::parse("incremental=on").expect("valid words"),
            ..RenderRequest::new(AlgorithmId::ThreeDBrute, camera, 64, 32)
        },
    )
    .unwrap_err();
    assert_eq!(e.field, "oracles", "{e}");
}

/// Inside the closed sphere the latitude–longitude view covers every pixel
/// exactly once, and the parabolic view every pixel of its disc (and none
/// outside it).
#[test]
fn closed_sphere_from_inside_covers_every_sample_once() {
    let scene = prepared("sphere");
    let inside = scene
        .scene
        .camera("inside")
        .expect("sphere has an inside camera");
    for (viewport, w, h) in [
        (Viewport::LatLong, 256, 128),
        (Viewport::Parabolic, 160, 128),
    ] {
        let camera = with_viewport(&inside, viewport);
        for algorithm in [
            AlgorithmId::ThreeDBrute,
            AlgorithmId::ThreeDBin,
            AlgorithmId::Raycast,
        ] {
            let out = render_with(&scene, algorithm, &camera, w, h);
            let fb = &out.framebuffer;
            let mut in_viewport = 0;
            for y in 0..h {
                for x in 0..w {
                    let i = (y * w + x) as usize;
                    let has_ray = out.view.ray(x as f32 + 0.5, y as f32 + 0.5).is_some();
                    in_viewport += usize::from(has_ray);
                    assert_eq!(
                        fb.coverage_writes[i],
                        u32::from(has_ray),
                        "{viewport} {algorithm}: pixel ({x}, {y}) written {} times",
                        fb.coverage_writes[i]
                    );
                }
            }
            // The parabolic disc of radius 64 holds about π·64² pixels.
            if viewport == Viewport::Parabolic {
                assert!((12_800..13_000).contains(&in_viewport), "{in_viewport}");
            }
        }
    }
}

#[test]
fn unsupported_pairings_are_errors_listing_the_supported_ones() {
    let scene = prepared("box");
    for viewport in [Viewport::Parabolic, Viewport::LatLong] {
        let camera = with_viewport(&scene.scene.first_camera(), viewport);
        for algorithm in AlgorithmId::CPU {
            let result = render(
                &scene,
                &RenderRequest::new(algorithm, camera.clone(), 32, 16),
            );
            let served = matches!(
                algorithm,
                AlgorithmId::ThreeDBrute | AlgorithmId::ThreeDBin | AlgorithmId::Raycast
            );
            match result {
                Ok(_) => assert!(served, "{algorithm} rendered {viewport}"),
                Err(e) => {
                    assert!(!served, "{algorithm} {viewport}: {e}");
                    assert_eq!(e.field, "viewport");
                    assert!(e.message.contains("3dr-brute, 3dr-bin, raycast"), "{e}");
                }
            }
        }
    }
}

/// The golden images: `teapots` in all four viewports, exactly. Regenerate with
/// `UPDATE_GOLDEN=1 cargo test -p continuum-tests golden`.
#[test]
fn golden_teapots_in_every_viewport() {
    let scene = prepared("teapots");
    let overview = scene.scene.camera("overview").expect("overview camera");
    let among = Camera {
        name: "among".into(),
        eye: Vec3::new(0.0, 1.8, 0.0),
        target: Vec3::new(0.0, 1.8, -1.0),
        up: Vec3::Y,
        viewport: Viewport::LatLong,
        near: Some(0.01),
    };
    let above = Camera {
        name: "above".into(),
        eye: Vec3::new(0.0, 14.0, 0.0),
        target: Vec3::new(0.0, 0.0, 0.0),
        up: Vec3::NEG_Z,
        viewport: Viewport::Parabolic,
        near: Some(0.01),
    };
    let cases = [
        ("perspective", overview.clone(), 480, 320),
        (
            "orthographic",
            with_viewport(&overview, orthographic_for(&overview)),
            480,
            320,
        ),
        ("parabolic", above, 320, 320),
        ("latlong", among, 640, 320),
    ];
    for (kind, camera, w, h) in cases {
        let out = render_with(&scene, AlgorithmId::ThreeDBin, &camera, w, h);
        let raycast = render_with(&scene, AlgorithmId::Raycast, &camera, w, h);
        assert_identical(kind, &out, &raycast);
        assert_golden(
            &format!("viewports/teapots_{kind}"),
            &continuum::maps::color_image(&out.framebuffer),
        );
    }
}
