//! One real window: `continuum-viewer --screenshot` on `teapots` under an X
//! server (the `DISPLAY` given, else an Xvfb this test starts) must save a PNG
//! of the whole window that contains the rendered image — the core's own
//! render of the same request, found pixel for pixel — not a blank window.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use continuum::{AlgorithmId, PreparedScene, RenderRequest, maps, render};

const SIZE: (u32, u32) = (320, 240);

/// An Xvfb server for the test's lifetime.
struct Xvfb {
    child: Child,
    display: String,
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn start_xvfb() -> Xvfb {
    for n in 90..130 {
        if Path::new(&format!("/tmp/.X11-unix/X{n}")).exists()
            || Path::new(&format!("/tmp/.X{n}-lock")).exists()
        {
            continue;
        }
        let display = format!(":{n}");
        let child = Command::new("Xvfb")
            .args([
                display.as_str(),
                "-screen",
                "0",
                "1280x800x24",
                "-nolisten",
                "tcp",
            ])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap_or_else(|e| {
                panic!("this test needs Xvfb (Debian package xvfb) or a DISPLAY: {e}")
            });
        let mut server = Xvfb { child, display };
        let deadline = Instant::now() + Duration::from_secs(20);
        while Instant::now() < deadline {
            if Path::new(&format!("/tmp/.X11-unix/X{n}")).exists() {
                return server;
            }
            if let Ok(Some(_)) = server.child.try_wait() {
                break;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
    }
    panic!("no Xvfb display could be started on :90..:129");
}

/// The core's render of the request the viewer is given below.
fn reference() -> image::RgbaImage {
    let scene =
        continuum::scene::load_named_or_path("teapots", &continuum::scene::default_scenes_dir())
            .expect("teapots loads");
    let prepared = PreparedScene::new(scene);
    let request = RenderRequest::new(
        AlgorithmId::ThreeDBrute,
        prepared.scene.first_camera(),
        SIZE.0,
        SIZE.1,
    );
    maps::color_image(&render(&prepared, &request).expect("renders").framebuffer)
}

fn close(a: &image::Rgba<u8>, b: &image::Rgba<u8>) -> bool {
    // Dithering and sRGB round trips move a channel by a step or two.
    a.0.iter()
        .zip(&b.0)
        .take(3)
        .all(|(p, q)| p.abs_diff(*q) <= 3)
}

/// Where `needle` sits in `haystack`, with the share of its pixels that match there.
fn find(haystack: &image::RgbaImage, needle: &image::RgbaImage) -> Option<((u32, u32), f64)> {
    let (w, h) = needle.dimensions();
    if haystack.width() < w || haystack.height() < h {
        return None;
    }
    // Probe pixels on a grid first; then every pixel where all probes match.
    let probes: Vec<(u32, u32)> = (0..8)
        .flat_map(|i| (0..8).map(move |j| ((2 * i + 1) * w / 16, (2 * j + 1) * h / 16)))
        .collect();
    let mut best: Option<((u32, u32), f64)> = None;
    for oy in 0..=haystack.height() - h {
        for ox in 0..=haystack.width() - w {
            let hits = probes
                .iter()
                .all(|&(x, y)| close(haystack.get_pixel(ox + x, oy + y), needle.get_pixel(x, y)));
            if !hits {
                continue;
            }
            let matching = needle
                .enumerate_pixels()
                .filter(|(x, y, p)| close(haystack.get_pixel(ox + x, oy + y), p))
                .count();
            let share = matching as f64 / f64::from(w * h);
            if best.is_none_or(|(_, s)| share > s) {
                best = Some(((ox, oy), share));
            }
        }
    }
    best
}

#[test]
fn screenshot_of_a_real_window_shows_the_render() {
    let xvfb = std::env::var("DISPLAY").is_err().then(start_xvfb);
    let out = std::env::temp_dir().join(format!(
        "continuum-viewer-window-{}.png",
        std::process::id()
    ));
    let mut command = Command::new(env!("CARGO_BIN_EXE_continuum-viewer"));
    command.args([
        "--scene",
        "teapots",
        "--algorithm",
        "3dr-brute",
        "--size",
        "320x240",
        "--threads",
        "2",
        "--screenshot",
    ]);
    command.arg(&out);
    if let Some(x) = &xvfb {
        command.env("DISPLAY", &x.display);
    }
    let status = run_with_timeout(command, Duration::from_secs(300));
    assert!(status, "continuum-viewer --screenshot failed");
    let shot = image::open(&out)
        .expect("the screenshot is a PNG")
        .to_rgba8();
    let _ = std::fs::remove_file(&out);
    assert!(
        shot.width() >= 1000 && shot.height() >= 600,
        "{:?}",
        shot.dimensions()
    );

    let reference = reference();
    // The reference is not a flat picture (a blank window would match a flat one).
    let distinct: std::collections::HashSet<[u8; 4]> = reference.pixels().map(|p| p.0).collect();
    assert!(distinct.len() > 100, "{} colours", distinct.len());
    // The viewer shows the image at a whole multiple of its size when it fits.
    let found = (1..=4)
        .filter_map(|k| {
            let scaled = image::imageops::resize(
                &reference,
                SIZE.0 * k,
                SIZE.1 * k,
                image::imageops::FilterType::Nearest,
            );
            find(&shot, &scaled).map(|(at, share)| (k, at, share))
        })
        .max_by(|a, b| a.2.total_cmp(&b.2));
    let (k, (x, y), share) = found.unwrap_or_else(|| {
        let kept: PathBuf = std::env::temp_dir().join("continuum-viewer-window-actual.png");
        let _ = shot.save(&kept);
        panic!("the render is not in the window (kept {})", kept.display())
    });
    assert!(
        share > 0.99,
        "only {:.1}% of the render (×{k}) matches at ({x}, {y})",
        100.0 * share
    );
}

fn run_with_timeout(mut command: Command, limit: Duration) -> bool {
    let mut child = command.spawn().expect("the viewer binary starts");
    let deadline = Instant::now() + limit;
    loop {
        if let Some(status) = child.try_wait().expect("waiting for the viewer") {
            return status.success();
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            panic!("continuum-viewer --screenshot did not exit within {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}
