//! `continuum-viewer`: the desktop viewer. The flags are `continuum render`'s
//! for scene, camera, algorithm, viewport, aa, precision and size; with
//! `--screenshot PATH` it renders the first frame, saves the whole window as PNG
//! and exits.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::PoisonError;

use clap::Parser;
use continuum_viewer::images::ViewKind;
use continuum_viewer::{Config, ViewerApp};
use eframe::egui;

#[derive(Parser, Debug)]
#[command(
    name = "continuum-viewer",
    version,
    about = "The continuum desktop viewer"
)]
struct Args {
    /// A built-in scene name, or a .toml, .gltf, .glb or .obj path.
    #[arg(long, default_value = "bunny")]
    scene: String,
    /// A camera of the scene (by name); default: the scene's first camera.
    #[arg(long)]
    camera: Option<String>,
    #[arg(long, default_value = "3dr-brute", help = format!("Algorithm id: {}", continuum::AlgorithmId::ALL.map(|a| a.as_str()).join(", ")))]
    algorithm: String,
    /// Explicit oracle settings on top of the algorithm's, e.g. outside=on,split=8.
    #[arg(long)]
    oracles: Option<String>,
    /// Viewport: `perspective[:FOV]`, `orthographic[:HEIGHT]`, `parabolic` or `latlong`.
    #[arg(long)]
    viewport: Option<String>,
    #[arg(long, default_value = "none", help = format!("Anti-aliasing mode: {}", continuum::AaMode::all().iter().map(ToString::to_string).collect::<Vec<_>>().join(", ")))]
    aa: String,
    /// Precision of coverage decisions: f32, f64 or fixed.
    #[arg(long, default_value = "f32")]
    precision: String,
    /// Texture filtering: nearest, bilinear, trilinear or anisotropic:N.
    #[arg(long, default_value = "trilinear")]
    texture_filter: String,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "640x480")]
    size: String,
    /// Draw what the algorithm did over the image: comma-separated
    /// wireframe, tiles, frusta, bvh.
    #[arg(long)]
    overlay: Option<String>,
    /// Render threads (default: every core).
    #[arg(long)]
    threads: Option<usize>,
    /// Folder of built-in scenes.
    #[arg(long)]
    scenes: Option<PathBuf>,
    /// The view to open on: colour, edge-evals, depth or ids.
    #[arg(long, default_value = "colour")]
    view: String,
    /// Window size in points, WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x800")]
    window: String,
    /// Render the first frame, save a screenshot of the whole window here (PNG), exit.
    #[arg(long)]
    screenshot: Option<PathBuf>,
    /// GPU adapter for the GPU algorithms, a case-insensitive part of its
    /// name (CONTINUUM_ADAPTER otherwise).
    #[arg(long)]
    adapter: Option<String>,
}

/// mimalloc reuses the frame-sized buffers every render allocates (see the server's).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// `mi_option_purge_delay` of mimalloc's `mi_option_t` (`mimalloc.h`).
const MI_OPTION_PURGE_DELAY: libmimalloc_sys::mi_option_t = 15;

fn main() -> ExitCode {
    if let Some(dir) = continuum::mesa::private_runtime_dir() {
        // SAFETY: the first statement of `main`, before any thread exists, so
        // nothing reads the environment while it changes.
        unsafe { std::env::set_var("XDG_RUNTIME_DIR", dir) };
    }
    // Freed pages stay with the process for the next frame (see the
    // server's `keep_freed_memory`).
    // SAFETY: `mi_option_set` stores an integer option (no pointers, any
    // value is valid); called at the start of `main`, before any thread.
    unsafe { libmimalloc_sys::mi_option_set(MI_OPTION_PURGE_DELAY, -1) };
    let args = Args::parse();
    if let Some(name) = &args.adapter {
        continuum::choose_gpu_adapter(name);
    }
    let usage = |message: String| {
        eprintln!("error: {message}");
        ExitCode::from(2)
    };
    let words = continuum::RenderWords {
        scene: args.scene.clone(),
        algorithm: args.algorithm.clone(),
        camera: args.camera.clone().map(continuum::CameraSpec::Named),
        oracles: args.oracles.clone(),
        viewport: args.viewport.clone(),
        aa: Some(args.aa.clone()),
        precision: Some(args.precision.clone()),
        texture_filter: Some(args.texture_filter.clone()),
        size: Some(args.size.clone()),
        overlays: args.overlay.clone(),
    };
    let mut config = match Config::from_words(&words) {
        Ok(c) => c,
        Err(e) if e.field == "overlays" => return usage(format!("--overlay: {}", e.message)),
        Err(e) => return usage(format!("--{e}")),
    };
    if let Some(t) = args.threads {
        if t == 0 {
            return usage("--threads: must be at least 1".into());
        }
        config.threads = t;
    }
    let view = match ViewKind::parse(&args.view) {
        Ok(v) => v,
        Err(e) => return usage(format!("--view: {e}")),
    };
    let window = match continuum::parse_size(&args.window) {
        Ok((w, h)) => [w as f32, h as f32],
        Err(e) => return usage(format!("--window: {}", e.message)),
    };
    let scenes_dir = args
        .scenes
        .clone()
        .unwrap_or_else(continuum::scene::default_scenes_dir);

    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("continuum")
            .with_inner_size(window)
            .with_drag_and_drop(true),
        renderer: eframe::Renderer::Wgpu,
        ..Default::default()
    };
    let result = std::sync::Arc::new(std::sync::Mutex::new(None));
    let slot = std::sync::Arc::clone(&result);
    let screenshot = args.screenshot.clone();
    let run = eframe::run_native(
        "continuum",
        options,
        Box::new(move |cc| {
            let mut app = ViewerApp::new(&cc.egui_ctx, &scenes_dir, config);
            app.view = view;
            if let Some(path) = screenshot {
                *slot.lock().unwrap_or_else(PoisonError::into_inner) =
                    Some(app.screenshot_to(path));
            }
            Ok(Box::new(app))
        }),
    );
    if let Err(e) = run {
        eprintln!("error: the window could not run: {e}");
        return ExitCode::FAILURE;
    }
    let Some(shot) = result.lock().unwrap_or_else(PoisonError::into_inner).take() else {
        return ExitCode::SUCCESS;
    };
    let outcome = shot.lock().unwrap_or_else(PoisonError::into_inner).take();
    match outcome {
        Some(Ok(())) => ExitCode::SUCCESS,
        Some(Err(message)) => usage(message),
        None => {
            eprintln!("error: --screenshot: the window closed before the first frame was captured");
            ExitCode::FAILURE
        }
    }
}
