//! Viewports (paper §3.3, §3.5): orthographic, parabolic and latitude–longitude
//! rendering agree across every algorithm that serves them, curved edges lose no
//! sample to binning, closed meshes stay watertight on curved viewports, and the
//! golden images of `teapots` hold.

use continuum::{AlgorithmId, Camera, Family, RenderOutput, RenderRequest, Viewport, render};
use continuum_tests::golden::assert_golden;
use continuum_tests::{
    builtin_scenes, explain_2d_3d, id_differences, prepared, render_with, render_with_oracles,
    serves,
};
use glam::Vec3;

const W: u32 = 192;
const H: u32 = 96;

/// An orthographic view that frames what the perspective camera frames at its target.
fn orthographic_for(camera: &Camera) -> Viewport {
    let fov = match camera.viewport {
        Viewport::Perspective { fov_y_deg } => fov_y_deg,
        _ => 60.0,
    };
    let distance = (camera.target - camera.eye).length();
    Viewport::Orthographic {
        height: 2.0 * distance * (fov.to_radians() * 0.5).tan(),
    }
}

fn with_viewport(camera: &Camera, viewport: Viewport) -> Camera {
    Camera {
        viewport,
        ..camera.clone()
    }
}

/// The three viewports beyond the pinhole, for `camera`.
fn other_viewports(camera: &Camera) -> [Viewport; 3] {
    [
        orthographic_for(camera),
        Viewport::Parabolic,
        Viewport::LatLong,
    ]
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
    let mut compared = 0;
    for name in builtin_scenes() {
        let scene = prepared(&name);
        for camera in &scene.scene.cameras {
            for viewport in other_viewports(camera) {
                let camera = with_viewport(camera, viewport);
                let what = format!("{name}/{} {viewport}", camera.name);
                let reference = render_with(&scene, AlgorithmId::ThreeDBrute, &camera, W, H);
                let covered = reference
                    .framebuffer
                    .triangle_id
                    .iter()
                    .filter(|&&id| id != continuum::BACKGROUND)
                    .count();
                assert!(covered > 0, "{what}: nothing drawn");
                let served = AlgorithmId::CPU
                    .into_iter()
                    .filter(|&a| a.family() == Family::ThreeD && serves(a, viewport));
                for algorithm in served.skip(1) {
                    let out = render_with(&scene, algorithm, &camera, W, H);
                    assert_identical(&what, &reference, &out);
                    compared += 1;
                }
                // Binning without early-z: every curved block test is exercised.
                let binned = render_with_oracles(
                    &scene,
                    AlgorithmId::ThreeDBin,
                    Some("early_z=off"),
                    &camera,
                    W,
                    H,
                );
                assert_identical(&format!("{what} binning only"), &reference, &binned);
                assert_eq!(
                    binned.framebuffer.coverage_writes, reference.framebuffer.coverage_writes,
                    "{what}: binning lost or added a covered sample"
                );
                compared += 1;
            }
        }
    }
    assert!(compared >= 7 * 2 * 9, "only {compared} comparisons");
}

/// Both 2D families serve orthographic views: 2dr-brute and 2dr-bin bit for bit,
/// and against 3dr-brute every differing pixel explained in f64.
#[test]
fn two_d_families_serve_orthographic_views() {
    let (mut covered, mut differing) = (0, 0);
    for name in builtin_scenes() {
        let scene = prepared(&name);
        for camera in &scene.scene.cameras {
            let camera = with_viewport(camera, orthographic_for(camera));
            let what = format!("{name}/{} {}", camera.name, camera.viewport);
            let three = render_with(&scene, AlgorithmId::ThreeDBrute, &camera, W, H);
            let two = render_with(&scene, AlgorithmId::TwoDBrute, &camera, W, H);
            let binned = render_with(&scene, AlgorithmId::TwoDBin, &camera, W, H);
            assert_identical(&what, &two, &binned);
            for other in [
                two,
                render_with(&scene, AlgorithmId::TwoDHomogeneous, &camera, W, H),
            ] {
                let r = explain_2d_3d(&scene, &other, &three);
                assert!(
                    r.unexplained.is_empty(),
                    "{what} {}: unexplained differences {:?}",
                    other.algorithm,
                    &r.unexplained[..r.unexplained.len().min(10)]
                );
                covered += r.covered;
                differing += r.explained();
            }
        }
    }
    println!("orthographic, 2D families vs 3D: {differing} of {covered} covered pixels differ");
    assert!(
        differing * 10_000 <= covered,
        "{differing} differing pixels is more than 0.01% of {covered}"
    );
}

/// The §3.5 double-incremental scheme decides every sample as direct evaluation does.
#[test]
fn incremental_evaluation_decides_like_direct_evaluation() {
    for name in builtin_scenes() {
        let scene = prepared(&name);
        for camera in &scene.scene.cameras {
            let camera = with_viewport(camera, Viewport::Parabolic);
            for algorithm in [AlgorithmId::ThreeDBrute, AlgorithmId::ThreeDBin] {
                let what = format!("{name}/{} {algorithm}", camera.name);
                let direct = render_with(&scene, algorithm, &camera, 128, 128);
                let incremental = render_with_oracles(
                    &scene,
                    algorithm,
                    Some("incremental=on"),
                    &camera,
                    128,
                    128,
                );
                assert_identical(&what, &direct, &incremental);
                assert_eq!(
                    direct.framebuffer.coverage_writes, incremental.framebuffer.coverage_writes,
                    "{what}: coverage decisions differ"
                );
            }
        }
    }
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
