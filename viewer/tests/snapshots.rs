//! egui_kittest snapshots of the viewer's main views, rendered with wgpu on the
//! CPU (lavapipe): colour, the heat map with its legend and the pixel loupe, the
//! timings panel after several algorithms, and the compare view.
//! `UPDATE_SNAPSHOTS=1 cargo test -p continuum-viewer --test snapshots` accepts
//! new images (`tests/snapshots/*.png`); a failure leaves `*.new.png` and
//! `*.diff.png` beside them.
//!
//! Times are the one thing that differs between runs, so each test pins them
//! (`pin_times`) before its snapshot; everything else on screen is computed.

use continuum::{AlgorithmId, Precision, PreparedScene, render};
use continuum_viewer::config::CameraChoice;
use continuum_viewer::images::ViewKind;
use continuum_viewer::{Config, Method, ViewerApp};
use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT as _, Queryable as _};

const WINDOW: egui::Vec2 = egui::vec2(1280.0, 800.0);

fn config(algorithm: &str) -> Config {
    let mut c = Config::from_words(&continuum::RenderWords {
        scene: "bunny".into(),
        size: Some("320x240".into()),
        ..continuum::RenderWords::new(algorithm)
    })
    .expect("valid words");
    c.threads = 2;
    c
}

fn harness(config: Config) -> Harness<'static, ViewerApp> {
    let app = ViewerApp::new(
        &egui::Context::default(),
        &continuum::scene::default_scenes_dir(),
        config,
    );
    Harness::builder()
        .with_size(WINDOW)
        // Frames 1/60 s apart, as on a screen (a double click needs two within 0.3 s).
        .with_step_dt(1.0 / 60.0)
        .wgpu()
        .build_ui_state(|ui, app: &mut ViewerApp| app.show(ui), app)
}

/// Renders what the app asks for, blocking, pins its times, then lets the UI
/// settle.
fn settle(h: &mut Harness<'_, ViewerApp>) {
    h.state_mut().wait_for_render();
    assert!(h.state().error().is_none(), "{:?}", h.state().error());
    pin_times(h.state_mut());
    h.run();
}

/// Fixed stage times and history totals, so bars, labels and plots are the same
/// on every run (a plot also remembers its axes from earlier frames, so times
/// are pinned before any frame shows them).
fn pin_times(app: &mut ViewerApp) {
    for (i, stats) in app.shown_stats_mut().into_iter().enumerate() {
        let k = 1.0 + i as f64;
        stats.time_ms.setup = 2.0 * k;
        stats.time_ms.traversal = 3.0 * k;
        stats.time_ms.coverage = 5.0 * k;
        stats.time_ms.resolve = 0.5 * k;
        stats.time_ms.shading = 1.0 * k;
        stats.time_ms.store = 0.5 * k;
        stats.time_ms.total = 12.0 * k;
    }
    let history = app.history_mut();
    let labels: Vec<String> = history.frames().iter().map(|(l, _)| l.clone()).collect();
    let mut order: Vec<&str> = Vec::new();
    *history = Default::default();
    for (n, label) in labels.iter().enumerate() {
        let line = order.iter().position(|l| l == label).unwrap_or_else(|| {
            order.push(label);
            order.len() - 1
        });
        history.push(label.clone(), 10.0 + 6.0 * line as f64 + (n % 4) as f64);
    }
}

#[test]
fn colour_view() {
    let mut h = harness(config("3dr-brute"));
    settle(&mut h);
    let out = h.state().shown_output().expect("a frame on screen");
    assert_eq!((out.view.width, out.view.height), (320, 240));
    h.snapshot("colour");
}

#[test]
fn heat_map_with_legend_and_pixel_loupe() {
    let mut h = harness(config("3dr-full"));
    h.state_mut().view = ViewKind::EdgeEvals;
    settle(&mut h);
    // Hover the middle of the central panel: the image is centred there.
    h.hover_at(image_centre());
    h.run();
    h.get_by_label_contains("edge evaluations per pixel: min");
    h.get_by_label("coverage writes");
    h.snapshot("heat_map");
}

#[test]
fn timings_after_three_algorithms() {
    let algorithms = [
        AlgorithmId::TwoDBrute,
        AlgorithmId::ThreeDBrute,
        AlgorithmId::Raycast,
    ];
    let mut h = harness(config("2dr-brute"));
    for a in algorithms {
        h.state_mut().config.method.algorithm = a;
        settle(&mut h);
    }
    // One history line per algorithm, and the counters of the last.
    assert_eq!(h.state_mut().history_mut().series().len(), 3);
    h.get_by_label("BVH nodes visited");
    h.snapshot("timings");
}

#[test]
fn compare_view_counts_differing_pixels() {
    let a = config("3dr-brute");
    let b = Method {
        algorithm: AlgorithmId::TwoDBrute,
        precision: Precision::Fixed,
        ..Method::default()
    };
    let mut h = harness(a.clone());
    h.state_mut().compare = Some(b.clone());
    settle(&mut h);

    // The label's count is the number of pixels whose triangle ids differ,
    // counted here again from the core's own renders.
    let node = h.get_by_label_contains("pixels differ in triangle id");
    let label = node
        .accesskit_node()
        .label()
        .or_else(|| node.value())
        .unwrap_or_default();
    let shown: u64 = label
        .split_whitespace()
        .nth(3)
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no count in {label:?}"));
    let scene =
        continuum::scene::load_named_or_path("bunny", &continuum::scene::default_scenes_dir())
            .expect("bunny loads");
    let prepared = PreparedScene::new(scene);
    let ids = |m: &Method| {
        let request = a.request(&prepared, m).expect("a valid request");
        render(&prepared, &request)
            .expect("renders")
            .framebuffer
            .triangle_id
    };
    let (ia, ib) = (ids(&a.method), ids(&b));
    let differ = ia.iter().zip(&ib).filter(|(p, q)| p != q).count() as u64;
    assert_eq!(shown, differ, "{label}");
    assert!(differ > 0 && differ < 320 * 240 / 100, "{label}");
    h.snapshot("compare");
}

/// The centre of the central panel, where the image sits.
fn image_centre() -> egui::Pos2 {
    egui::pos2(250.0 + (WINDOW.x - 250.0 - 330.0) / 2.0, 300.0)
}

#[test]
fn dragging_the_image_orbits_and_double_click_resets() {
    let mut h = harness(config("3dr-brute"));
    settle(&mut h);
    let before = h
        .state()
        .shown_output()
        .expect("a frame")
        .hashes()
        .triangle_id
        .clone();

    let start = image_centre();
    h.hover_at(start);
    h.step();
    h.drag_at(start);
    h.step();
    for step in 1..=5 {
        h.hover_at(start + egui::vec2(12.0 * step as f32, 0.0));
        h.step();
    }
    h.drop_at(start + egui::vec2(60.0, 0.0));
    h.step();
    let CameraChoice::Moved(camera) = h.state().config.camera.clone() else {
        panic!(
            "the drag did not move the camera: {:?}",
            h.state().config.camera
        )
    };
    settle(&mut h);
    let out = h.state().shown_output().expect("a frame");
    assert_eq!(
        out.view.eye, camera.eye,
        "the shown frame uses the moved camera"
    );
    assert_ne!(
        out.hashes().triangle_id,
        before,
        "orbiting changes the image"
    );

    // A double click is the Reset button: the scene's camera again.
    let pos = image_centre();
    h.hover_at(pos);
    h.step();
    for pressed in [true, false, true, false] {
        h.event(egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: Default::default(),
        });
        h.step();
    }
    assert_eq!(h.state().config.camera, CameraChoice::Named(None));
    settle(&mut h);
    assert_eq!(
        h.state()
            .shown_output()
            .expect("a frame")
            .hashes()
            .triangle_id,
        before
    );
}
