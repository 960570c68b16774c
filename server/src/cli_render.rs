//! `continuum render`: one image, its maps and its statistics.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use continuum::{CameraSpec, PreparedScene, RenderWords, draw_overlays, maps, render};

use crate::{CliError, scenes_dir, write_stdout};

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// A built-in scene name, or a .toml, .gltf, .glb or .obj path.
    #[arg(long)]
    scene: String,
    #[arg(long, help = crate::help::algorithms())]
    algorithm: String,
    /// A camera of the scene (by name); default: the scene's first camera.
    #[arg(long)]
    camera: Option<String>,
    /// Explicit oracle settings on top of the algorithm's, e.g.
    /// outside=on,occluded=on,split=8,binning=on,early_z=off,frustum=256,leaf=8.
    #[arg(long)]
    oracles: Option<String>,
    /// Viewport: `perspective[:FOV]`, `orthographic[:HEIGHT]`, `parabolic` or `latlong`
    /// (default: the camera's own; bare words keep its field of view or height).
    #[arg(long)]
    viewport: Option<String>,
    #[arg(long, default_value = "none", help = crate::help::aa_modes())]
    aa: String,
    /// Precision of coverage decisions: f32, f64 (3D family) or fixed (2D
    /// family: vertices snapped to 1/256 pixel, exact integer edge functions).
    #[arg(long, default_value = "f32")]
    precision: String,
    /// Texture filtering (scenes with textures): nearest, bilinear, trilinear
    /// or anisotropic:N (N in 1..=16).
    #[arg(long, default_value = "trilinear")]
    texture_filter: String,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "640x480")]
    size: String,
    /// Draw what the algorithm did over every image written:
    /// comma-separated wireframe, tiles, frusta, bvh.
    #[arg(long)]
    overlay: Option<String>,
    /// Write the colour image here (PNG).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Write edge_evals.png, depth.png and triangle_id.png into this folder.
    #[arg(long)]
    maps: Option<PathBuf>,
    /// Print one JSON document with the statistics on stdout.
    #[arg(long)]
    json: bool,
    /// Folder of built-in scenes.
    #[arg(long)]
    scenes: Option<PathBuf>,
    /// Worker threads [default: all cores].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    threads: Option<u32>,
}

impl RenderArgs {
    /// The flags' words, for the front door every front end shares.
    fn words(&self) -> RenderWords {
        RenderWords {
            scene: self.scene.clone(),
            algorithm: self.algorithm.clone(),
            camera: self.camera.clone().map(CameraSpec::Named),
            oracles: self.oracles.clone(),
            viewport: self.viewport.clone(),
            aa: Some(self.aa.clone()),
            precision: Some(self.precision.clone()),
            texture_filter: Some(self.texture_filter.clone()),
            size: Some(self.size.clone()),
            overlays: self.overlay.clone(),
        }
    }
}

pub fn run(args: &RenderArgs) -> Result<(), CliError> {
    let usage = |e: continuum::FieldError| {
        // The words' field `overlays` is the flag `--overlay`.
        let flag = if e.field == "overlays" {
            "overlay"
        } else {
            e.field
        };
        CliError::Usage(format!("--{flag}: {}", e.message))
    };
    // Every word checked before the scene is loaded.
    let settings = args.words().settings().map_err(usage)?;
    let scene =
        continuum::scene::load_named_or_path(&args.scene, &scenes_dir(args.scenes.as_ref()))
            .map_err(|e| CliError::Usage(format!("--scene: {e}")))?;
    let request = settings.request(&scene).map_err(usage)?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    let prepared = PreparedScene::new(scene);
    let (width, height) = (request.width, request.height);
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(t) = args.threads {
        pool = pool.num_threads(t as usize);
    }
    let pool = pool.build().context("building the thread pool")?;
    let out = pool
        .install(|| render(&prepared, &request))
        .map_err(usage)?;

    // Every image written gets the overlays asked for.
    let finish = |mut img| {
        draw_overlays(&mut img, settings.overlays, &out, &prepared);
        maps::png_bytes(&img)
    };
    if let Some(path) = &args.out {
        std::fs::write(path, finish(maps::color_image(&out.framebuffer)))
            .with_context(|| format!("writing {}", path.display()))?;
    }
    if let Some(dir) = &args.maps {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        let fb = &out.framebuffer;
        for (name, img) in [
            ("edge_evals.png", maps::edge_eval_image(fb)),
            ("depth.png", maps::depth_image(fb)),
            ("triangle_id.png", maps::triangle_id_image(fb)),
        ] {
            let path = dir.join(name);
            std::fs::write(&path, finish(img))
                .with_context(|| format!("writing {}", path.display()))?;
        }
    }
    let summary = out.summary(&prepared.scene.name, &request.camera.name);
    if args.json {
        let text = serde_json::to_string_pretty(&summary).context("encoding JSON")?;
        write_stdout(&(text + "\n"))?;
    } else {
        let s = &out.stats;
        write_stdout(&format!(
            "{} {} {}x{}: {:.2} ms (setup {:.2}, traversal {:.2}, coverage {:.2}, resolve {:.2}, shading {:.2}, store {:.2}); {} setups, {} edge evaluations, {} BVH nodes; coverage 0/1/many = {}/{}/{}; ids {}\n",
            summary.scene,
            summary.algorithm,
            width,
            height,
            s.time_ms.total,
            s.time_ms.setup,
            s.time_ms.traversal,
            s.time_ms.coverage,
            s.time_ms.resolve,
            s.time_ms.shading,
            s.time_ms.store,
            s.triangle_setups,
            s.edge_evaluations,
            s.bvh_nodes_visited,
            s.coverage_histogram.zero,
            s.coverage_histogram.one,
            s.coverage_histogram.many,
            summary.hashes.triangle_id
        ))?;
    }
    Ok(())
}
