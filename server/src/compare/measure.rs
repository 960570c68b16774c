//! Measuring the cells of a sweep: every algorithm and peer of a cell timed
//! over repeats (continuum's CPU algorithms interleaved, round by round;
//! `gpu-raster` and each peer in one block), with the relations
//! only the cell's own buffers can decide — family agreement, pixels a peer
//! differs by, error against the `ssaa:256` reference — and an
//! edge-evaluation thumbnail per render for the report.

use std::collections::HashMap;
use std::path::Path;

use super::peer::run_peer;
use anyhow::Context;
use continuum::metrics::{self, ImageError};
use continuum::{
    AaMode, AlgorithmId, Camera, Family, Framebuffer, Oracles, Precision, PreparedScene,
    RenderRequest, StageTimes, View, maps, render,
};
use serde_json::{Value, json};

use super::Row;
use super::sweep::{Cell, Entry, Sweep};
use crate::CliError;

/// Largest side of the edge-evaluation thumbnails the report shows.
const THUMBNAIL: u32 = 320;

/// A scene loaded and prepared once for all its cells, and its AA references
/// per viewport.
pub struct LoadedScene {
    pub prepared: PreparedScene,
    pub camera: Camera,
    references: HashMap<String, Reference>,
}

impl LoadedScene {
    /// How many triangles the scene has.
    pub fn triangles(&self) -> u64 {
        self.prepared.scene.mesh.triangles.len() as u64
    }

    pub fn load(
        arg: &str,
        sweep: &Sweep,
        scenes_dir: &Path,
        pool: &rayon::ThreadPool,
    ) -> Result<LoadedScene, CliError> {
        let scene = continuum::scene::load_named_or_path(arg, scenes_dir)
            .map_err(|e| CliError::Usage(format!("scenes: {e}")))?;
        let camera = match &sweep.camera {
            Some(name) => scene
                .camera(name)
                .map_err(|e| CliError::Usage(format!("camera: {e}")))?,
            None => scene.first_camera(),
        };
        Ok(LoadedScene {
            prepared: pool.install(|| PreparedScene::new(scene)),
            camera,
            references: HashMap::new(),
        })
    }
}

/// Measures every entry of `cell` that serves it; the rows carry the in-cell
/// relations. Thumbnails go to `out/maps/`.
pub fn measure_cell(
    cell: &Cell,
    scene: &mut LoadedScene,
    sweep: &Sweep,
    pool: &rayon::ThreadPool,
    out: &Path,
    progress: &indicatif::ProgressBar,
) -> Result<Vec<Row>, CliError> {
    let mut camera = scene.camera.clone();
    camera.viewport = cell.viewport.apply(&camera)?;
    let (width, height) = sweep.size;
    let threads = pool.current_num_threads();
    let name = scene.prepared.scene.name.clone();
    // With anti-aliasing in the sweep every mode, `none` too, is measured
    // against the scene's reference.
    let reference = if !sweep.with_reference {
        None
    } else {
        let key = camera.viewport.to_string();
        if !scene.references.contains_key(&key) {
            progress.set_message(format!(
                "{name} {key}: {} reference",
                continuum::AaMode::REFERENCE
            ));
            let r = pool.install(|| Reference::render(&scene.prepared, &camera, sweep.size))?;
            scene.references.insert(key.clone(), r);
        }
        scene.references.get(&key)
    };
    // 1. What serves this cell, in the sweep's order.
    let serving: Vec<Entry> = sweep
        .entries
        .iter()
        .copied()
        .filter(|&entry| match entry.algorithm() {
            Some(a) => continuum::check(
                &algorithm_request(a, &camera, cell, sweep),
                Some(&scene.prepared),
            )
            .is_ok(),
            // Peers cast one ray per pixel in their own precision.
            None => cell.aa == AaMode::None && cell.precision == Precision::F32 && cell.depth_test,
        })
        .collect();
    // 2. continuum's CPU algorithms, timed interleaved: one warm-up render
    //    each, then `repeat` rounds of one render per algorithm, so slow drift
    //    of the machine reaches every algorithm of the cell alike and the
    //    ratios between them stay fair. (The GPU algorithms are timed each in
    //    a block of its own like the peers: lavapipe's threads outlive its
    //    frames and would slow whichever render came next.)
    let algorithms: Vec<(AlgorithmId, Oracles)> = serving
        .iter()
        .filter_map(|e| e.algorithm())
        .filter(|(a, _)| a.family() != Family::Gpu)
        .collect();
    progress.set_message(format!(
        "{name} {} {} {}: {} algorithms over {} rounds",
        camera.viewport,
        cell.aa,
        cell.precision,
        algorithms.len(),
        sweep.repeat
    ));
    let requests: Vec<RenderRequest> = algorithms
        .iter()
        .map(|&a| algorithm_request(a, &camera, cell, sweep))
        .collect();
    let timed = time_interleaved(pool, scene, &requests, sweep.repeat)?;
    let mut timed = timed.into_iter();
    // 3. The rows in the sweep's order; peers timed each in its own block.
    let mut measured: Vec<Measured> = Vec::new();
    for entry in serving {
        progress.set_message(format!(
            "{name} {} {} {}: {}",
            camera.viewport,
            cell.aa,
            cell.precision,
            entry.name()
        ));
        let mut m = match entry {
            Entry::Algorithm(a) if a.family() == Family::Gpu => {
                let request = algorithm_request((a, Oracles::default()), &camera, cell, sweep);
                let (out, times) = time_interleaved(pool, scene, &[request], sweep.repeat)?
                    .pop()
                    .with_context(|| format!("one timed render for {a}"))?;
                algorithm_row(scene, (a, cell), sweep, threads, out, times)
            }
            Entry::Algorithm(a) | Entry::Tuned(a, _) => {
                let (out, times) = timed.next().context("one timed render per algorithm")?;
                let mut m = algorithm_row(scene, (a, cell), sweep, threads, out, times);
                if let Entry::Tuned(_, oracles) = entry {
                    m.row.algorithm = entry.name();
                    m.row.oracles = Some(oracles.to_string());
                }
                m
            }
            Entry::Peer(p) => {
                let view = View::new(&camera, width, height, scene.prepared.default_near)
                    .map_err(|e| CliError::Usage(format!("camera: {e}")))?;
                let run = pool
                    .install(|| run_peer(p, &scene.prepared, &view, sweep.repeat))
                    .map_err(|e| CliError::Usage(format!("algorithms: {e}")))?;
                let mut row = Row::timed(&name, p.as_str(), sweep.size, threads, run.times_ms)
                    .with(
                        &camera.viewport.to_string(),
                        "none",
                        json!({ "bvh_build_ms": run.build_ms }),
                    );
                row.coverage_samples = u64::from(width) * u64::from(height);
                row.scene_triangles = scene.triangles();
                // Peers find the visible triangle and shade nothing.
                row.visibility_ms = Some(row.median_ms);
                Measured {
                    row,
                    algorithm: None,
                    keys: run.triangle_id.iter().map(|&t| u64::from(t)).collect(),
                    fb: None,
                }
            }
        };
        m.row.cell = cell.index;
        m.row.camera = camera.name.clone();
        if let (Some(r), Some(fb)) = (reference, &m.fb) {
            m.row.error(r.error_of(fb));
        }
        if let Some(fb) = &m.fb {
            m.row.map = Some(write_thumbnail(out, &m.row, fb)?);
        }
        measured.push(m);
        progress.inc(1);
    }
    relate_in_cell(&mut measured);
    Ok(measured.into_iter().map(|m| m.row).collect())
}

/// One measured row, the key that decides agreement (per pixel: the triangle
/// id, or the digest of every sample's id under anti-aliasing) and, for
/// continuum's own algorithms, the framebuffer.
struct Measured {
    row: Row,
    /// The continuum algorithm rendered (`None`: a peer).
    algorithm: Option<AlgorithmId>,
    keys: Vec<u64>,
    fb: Option<Framebuffer>,
}

/// The request that renders `algorithm` in `cell`.
fn algorithm_request(
    (algorithm, oracles): (AlgorithmId, Oracles),
    camera: &Camera,
    cell: &Cell,
    sweep: &Sweep,
) -> RenderRequest {
    RenderRequest {
        oracles,
        aa: cell.aa,
        precision: cell.precision,
        depth_test: cell.depth_test,
        ..RenderRequest::new(algorithm, camera.clone(), sweep.size.0, sweep.size.1)
    }
}

/// Times `requests` interleaved: one warm-up render each (the GPU uploads
/// the scene then), then `repeat` rounds of one render per request. Returns
/// each request's warm-up output, carrying the stats of its last round, and
/// its round times. The timed rounds write no counter planes
/// ([`RenderRequest::counter_planes`]: a renderer writes no diagnostic planes
/// unasked; their totals in the stats are the same): the warm-up's frame,
/// with them, is the one the row's maps and hashes are made from.
fn time_interleaved(
    pool: &rayon::ThreadPool,
    scene: &LoadedScene,
    requests: &[RenderRequest],
    repeat: u32,
) -> Result<Vec<(continuum::RenderOutput, Times)>, CliError> {
    let render_one = |request: &RenderRequest| {
        pool.install(|| render(&scene.prepared, request))
            .map_err(|e| CliError::Usage(format!("{e}")))
    };
    let mut timed = requests
        .iter()
        .map(|r| Ok((render_one(r)?, Times::default())))
        .collect::<Result<Vec<_>, CliError>>()?;
    let rounds: Vec<RenderRequest> = (requests.iter())
        .map(|r| RenderRequest {
            counter_planes: false,
            ..r.clone()
        })
        .collect();
    for _ in 0..repeat {
        for (request, (out, times)) in rounds.iter().zip(&mut timed) {
            let round = render_one(request)?;
            let t = round.stats.time_ms;
            times.total.push(t.total);
            times.visibility.push(t.total - t.resolve - t.shading);
            times.stages.push(t);
            out.stats = round.stats;
            // This frame's memory serves the next render, as in the service
            // and the viewer.
            round.framebuffer.recycle();
        }
    }
    Ok(timed)
}

/// The times of an algorithm's rounds (ms): whole renders, and the same
/// renders without their shading stage.
#[derive(Debug, Default)]
struct Times {
    total: Vec<f64>,
    visibility: Vec<f64>,
    stages: Vec<StageTimes>,
}

/// Each stage's median over the rounds.
fn median_stages(rounds: &[StageTimes]) -> StageTimes {
    let m = |stage: fn(&StageTimes) -> f64| super::median(rounds.iter().map(stage).collect()).0;
    StageTimes {
        setup: m(|t| t.setup),
        traversal: m(|t| t.traversal),
        coverage: m(|t| t.coverage),
        resolve: m(|t| t.resolve),
        shading: m(|t| t.shading),
        store: m(|t| t.store),
        total: m(|t| t.total),
    }
}

/// The row of an algorithm from its last render and the times of its rounds.
fn algorithm_row(
    scene: &LoadedScene,
    (algorithm, cell): (AlgorithmId, &Cell),
    sweep: &Sweep,
    threads: usize,
    out: continuum::RenderOutput,
    times: Times,
) -> Measured {
    let mut row = Row::timed(
        &scene.prepared.scene.name,
        algorithm.as_str(),
        sweep.size,
        threads,
        times.total,
    )
    .with(
        &out.viewport,
        &out.aa,
        serde_json::to_value(&out.stats).unwrap_or(Value::Null),
    );
    row.scene_triangles = scene.triangles();
    row.hashes = serde_json::to_value(out.hashes()).unwrap_or(Value::Null);
    row.visibility_ms = Some(super::median(times.visibility).0);
    row.stage_ms = Some(median_stages(&times.stages));
    row.precision = cell.precision;
    row.depth_test = cell.depth_test;
    row.shading_samples = out.stats.shading_samples;
    row.coverage_samples = out.stats.coverage_samples;
    let fb = out.framebuffer;
    let keys = if fb.sample_digest.is_empty() {
        fb.triangle_id.iter().map(|&t| u64::from(t)).collect()
    } else {
        fb.sample_digest.clone()
    };
    Measured {
        row,
        algorithm: Some(algorithm),
        keys,
        fb: Some(fb),
    }
}

/// Family agreement (the first member of each family in the cell is its
/// reference) and, for the peers and the GPU, the pixels differing from
/// `3dr-brute`. A cell without `3dr-brute` (the depth test off, which only
/// the compute kernels offer) holds the GPU rows to `gpu-3dr`'s ids
/// instead: agreement only, no pixel count.
fn relate_in_cell(rows: &mut [Measured]) {
    let position = |a: AlgorithmId| rows.iter().position(|m| m.row.algorithm == a.as_str());
    let three_d = position(AlgorithmId::ThreeDBrute);
    let reference = three_d.or(position(AlgorithmId::Gpu3dr));
    let mut family_reference: HashMap<String, usize> = HashMap::new();
    for i in 0..rows.len() {
        // `--oracles` rows too: each belongs to its algorithm's family.
        let cpu = rows[i].algorithm.filter(|a| AlgorithmId::CPU.contains(a));
        match cpu {
            Some(a) => {
                let family = format!("{:?}", a.family());
                let reference = *family_reference.entry(family).or_insert(i);
                rows[i].row.agrees = rows[i].keys == rows[reference].keys;
            }
            None => {
                if let Some(j) = reference {
                    let differing = rows[j]
                        .keys
                        .iter()
                        .zip(&rows[i].keys)
                        .filter(|(a, b)| a != b)
                        .count() as u64;
                    if three_d.is_some() {
                        rows[i].row.pixels_differing_from_3dr_brute = Some(differing);
                    }
                    rows[i].row.agrees = differing == 0;
                }
            }
        }
    }
}

/// The render's edge-evaluation map, scaled to at most [`THUMBNAIL`] pixels a
/// side, as `maps/SCENE/CELL-ALGORITHM.png` under `out`; returns that path.
fn write_thumbnail(out: &Path, row: &Row, fb: &Framebuffer) -> Result<String, CliError> {
    let image = maps::edge_eval_image(fb);
    let (w, h) = (image.width(), image.height());
    let scale = (f64::from(THUMBNAIL) / f64::from(w.max(h))).min(1.0);
    let thumb = image::imageops::thumbnail(
        &image,
        ((f64::from(w) * scale) as u32).max(1),
        ((f64::from(h) * scale) as u32).max(1),
    );
    let rel = format!(
        "maps/{}/{}-{}.png",
        sanitize(&row.scene),
        row.cell,
        sanitize(&row.algorithm)
    );
    let path = out.join(&rel);
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    std::fs::write(&path, maps::png_bytes(&thumb))
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(rel)
}

/// A name safe as a file name.
fn sanitize(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// The reference of a scene: `ssaa:256` by `3dr-bin`, and the pixels where the
/// image without anti-aliasing differs from it (where anti-aliasing matters).
struct Reference {
    color: Vec<[u8; 4]>,
    edges: Vec<bool>,
    width: u32,
    height: u32,
}

impl Reference {
    fn render(
        prepared: &PreparedScene,
        camera: &Camera,
        (width, height): (u32, u32),
    ) -> Result<Reference, CliError> {
        let request = |aa| RenderRequest {
            aa,
            ..RenderRequest::new(AlgorithmId::ThreeDBin, camera.clone(), width, height)
        };
        let run = |aa| {
            render(prepared, &request(aa))
                .map(|o| o.framebuffer.color)
                .map_err(|e| CliError::Usage(format!("{e}")))
        };
        let color = run(continuum::AaMode::REFERENCE)?;
        let edges = metrics::differing_pixels(&run(AaMode::None)?, &color);
        Ok(Reference {
            color,
            edges,
            width,
            height,
        })
    }

    fn error_of(&self, fb: &Framebuffer) -> ImageError {
        metrics::compare(&self.color, &fb.color, &self.edges, self.width, self.height)
    }
}
