//! `continuum compare`: the benchmark. Every algorithm and peer on every scene,
//! in one process, timed as medians over repeats and reported as ratios to
//! `2dr-brute` (the paper's Fig. 9 form), with the counters that explain them.
//! Writes `results.json` and `results.csv` into `--out`. With `--aa`, every
//! mode is measured too: its time against `none`, its shading and coverage
//! samples, and its error (PSNR, FLIP) against a `ssaa:256` reference, plotted
//! as `aa_cost.svg`.

use std::collections::HashMap;
use std::io::Write;
use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use continuum::metrics::{self, ImageError};
use continuum::peer::{PeerId, run_peer};
use continuum::request::{parse_algorithm, parse_size};
use continuum::{
    AaMode, AlgorithmId, Framebuffer, Precision, PreparedScene, RenderRequest, View, render,
};
use serde::Serialize;
use serde_json::{Value, json};

use crate::plot::{AaPoint, aa_cost_svg};
use crate::{CliError, scenes_dir, write_stdout};

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// Scenes: built-in names or paths, comma-separated [default: every built-in scene].
    #[arg(long, value_delimiter = ',')]
    scenes: Vec<String>,
    /// Algorithm ids and peers (peer-obvhs; peer-embree and peer-embree-stream with
    /// the `embree` feature), comma-separated [default: all that are built in].
    #[arg(long, value_delimiter = ',')]
    algorithms: Vec<String>,
    /// Camera name; default: each scene's first camera.
    #[arg(long)]
    camera: Option<String>,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x720", value_parser = |s: &str| parse_size(s).map_err(|e| e.message))]
    size: (u32, u32),
    /// Timed runs per scene and algorithm (after one warm-up run).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=1000))]
    repeat: u32,
    /// Worker threads [default: all cores].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    threads: Option<u32>,
    /// Anti-aliasing modes, comma-separated (none, ssaa:N, msaa:N, csaa:CxS);
    /// each is measured against a ssaa:256 reference and plotted in aa_cost.svg
    /// [default: none, without a reference].
    #[arg(long, value_delimiter = ',', value_parser = |s: &str| continuum::AaMode::parse(s).map_err(|e| e.message))]
    aa: Vec<AaMode>,
    /// Precisions, comma-separated (f32, f64 for the 3D family, fixed for the 2D
    /// family); each algorithm runs at every one it computes in, and rows
    /// report their time against f32 [default: f32].
    #[arg(long, value_delimiter = ',', value_parser = |s: &str| Precision::parse(s).map_err(|e| e.message))]
    precision: Vec<Precision>,
    /// Folder for results.json and results.csv.
    #[arg(long)]
    out: PathBuf,
    /// Also print results.json on stdout.
    #[arg(long)]
    json: bool,
    /// Folder of built-in scenes.
    #[arg(long = "scenes-dir")]
    scenes_dir: Option<PathBuf>,
}

/// What one row measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Entry {
    Algorithm(AlgorithmId),
    Peer(PeerId),
}

impl Entry {
    fn name(self) -> &'static str {
        match self {
            Entry::Algorithm(a) => a.as_str(),
            Entry::Peer(p) => p.as_str(),
        }
    }
}

fn parse_entries(names: &[String]) -> Result<Vec<Entry>, CliError> {
    if names.is_empty() {
        let mut all: Vec<Entry> = AlgorithmId::ALL.into_iter().map(Entry::Algorithm).collect();
        all.extend(
            PeerId::ALL
                .into_iter()
                .filter(|p| p.available())
                .map(Entry::Peer),
        );
        return Ok(all);
    }
    names
        .iter()
        .map(|n| match PeerId::parse(n) {
            Some(p) if !p.available() => Err(CliError::Usage(format!(
                "--algorithms: {n} needs continuum built with --features embree (and Debian's libembree-dev)"
            ))),
            Some(p) => Ok(Entry::Peer(p)),
            None => parse_algorithm(n).map(Entry::Algorithm).map_err(|e| {
                CliError::Usage(format!(
                    "--algorithms: {}; peers are: {}",
                    e.message,
                    PeerId::ALL.map(|p| p.as_str()).join(", ")
                ))
            }),
        })
        .collect()
}

/// One measured row of results.json.
#[derive(Debug, Serialize)]
struct Row {
    scene: String,
    algorithm: String,
    viewport: String,
    aa: String,
    precision: Precision,
    width: u32,
    height: u32,
    threads: usize,
    median_ms: f64,
    min_ms: f64,
    max_ms: f64,
    ratio_to_2dr_brute: Option<f64>,
    predicted_ratio: Option<f64>,
    rays_per_second: f64,
    stats: Value,
    hashes: Value,
    /// Does the triangle-id buffer equal its family's reference (for peers: 3dr-brute)?
    agrees: bool,
    /// Pixels whose triangle id differs from 3dr-brute's (peers are not watertight).
    pixels_differing_from_3dr_brute: Option<u64>,
    /// Time against the same algorithm without anti-aliasing (when measured).
    ratio_to_aa_none: Option<f64>,
    /// Time against the same algorithm and mode at f32 (when measured).
    ratio_to_f32: Option<f64>,
    /// Shading evaluations and coverage samples of the render.
    shading_samples: u64,
    coverage_samples: u64,
    /// Error against the ssaa:256 reference (with `--aa`).
    psnr: Option<f64>,
    psnr_edges: Option<f64>,
    flip_mean: Option<f64>,
}

impl Row {
    /// A row from timed repetitions (median, min, max, rays per second); the
    /// relations to other rows are filled in later.
    fn timed(
        scene: &str,
        algorithm: &str,
        (width, height): (u32, u32),
        threads: usize,
        times: Vec<f64>,
    ) -> Row {
        let (median_ms, min_ms, max_ms) = median(times);
        Row {
            scene: scene.to_string(),
            algorithm: algorithm.to_string(),
            viewport: String::new(),
            aa: String::new(),
            precision: Precision::F32,
            width,
            height,
            threads,
            median_ms,
            min_ms,
            max_ms,
            ratio_to_2dr_brute: None,
            predicted_ratio: None,
            rays_per_second: f64::from(width) * f64::from(height) / (median_ms / 1e3),
            stats: Value::Null,
            hashes: Value::Null,
            agrees: false,
            pixels_differing_from_3dr_brute: None,
            ratio_to_aa_none: None,
            ratio_to_f32: None,
            shading_samples: 0,
            coverage_samples: 0,
            psnr: None,
            psnr_edges: None,
            flip_mean: None,
        }
    }

    fn with(mut self, viewport: &str, aa: &str, stats: Value) -> Row {
        self.viewport = viewport.to_string();
        self.aa = aa.to_string();
        self.stats = stats;
        self
    }

    fn hashes(mut self, hashes: Value) -> Row {
        self.hashes = hashes;
        self
    }

    fn error(&mut self, e: ImageError) {
        self.psnr = e.psnr;
        self.psnr_edges = e.psnr_edges;
        self.flip_mean = Some(e.flip_mean);
    }
}

fn median(mut v: Vec<f64>) -> (f64, f64, f64) {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    let m = if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    };
    (m, v[0], v[n - 1])
}

pub fn run(args: &CompareArgs) -> Result<(), CliError> {
    let entries = parse_entries(&args.algorithms)?;
    let dir = scenes_dir(args.scenes_dir.as_ref());
    let scene_args = if args.scenes.is_empty() {
        continuum::scene::builtin_names(&dir)
    } else {
        args.scenes.clone()
    };
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let threads = args
        .threads
        .map_or_else(rayon::current_num_threads, |t| t as usize);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .context("building the thread pool")?;
    let (width, height) = args.size;

    let modes = if args.aa.is_empty() {
        vec![AaMode::None]
    } else {
        args.aa.clone()
    };
    // f32 first: the other precisions' rows relate to its times.
    let precisions: Vec<Precision> = if args.precision.is_empty() {
        vec![Precision::F32]
    } else {
        Precision::ALL
            .into_iter()
            .filter(|p| args.precision.contains(p))
            .collect()
    };
    let total_steps = (scene_args.len() * modes.len() * precisions.len() * entries.len()) as u64;
    let progress = indicatif::ProgressBar::new(total_steps).with_style(
        indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} {msg} [{elapsed}]")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );

    let mut rows = Vec::new();
    for scene_arg in &scene_args {
        let scene = continuum::scene::load_named_or_path(scene_arg, &dir)
            .map_err(|e| CliError::Usage(format!("--scenes: {e}")))?;
        let camera = match &args.camera {
            Some(name) => scene
                .camera(name)
                .map_err(|e| CliError::Usage(format!("--camera: {e}")))?,
            None => scene.first_camera(),
        };
        progress.set_message(format!("{}: preparing", scene.name));
        let prepared = pool.install(|| PreparedScene::new(scene));
        let scene_name = prepared.scene.name.clone();
        let view = View::new(&camera, width, height, prepared.default_near)
            .map_err(|e| CliError::Usage(format!("--camera: {e}")))?;
        let reference = if args.aa.is_empty() {
            None
        } else {
            progress.set_message(format!(
                "{scene_name}: {} reference",
                continuum::aa::REFERENCE
            ));
            Some(pool.install(|| Reference::render(&prepared, &camera, args.size))?)
        };
        let first_row = rows.len();
        for &mode in &modes {
            let mut f32_base = None;
            for &precision in &precisions {
                let mut group: Vec<(Row, Vec<u64>)> = Vec::new();
                for &entry in &entries {
                    progress
                        .set_message(format!("{scene_name} {mode} {precision}: {}", entry.name()));
                    let measured = match entry {
                        Entry::Algorithm(a) if precision.serves(a.family()) => {
                            Some(measure_algorithm(
                                &pool,
                                &prepared,
                                &camera,
                                (a, mode, precision),
                                args,
                                threads,
                                &scene_name,
                            )?)
                        }
                        // Peers render one sample per pixel in their own precision.
                        Entry::Peer(p) if mode == AaMode::None && precision == Precision::F32 => {
                            Some(measure_peer(
                                &pool,
                                &prepared,
                                &view,
                                p,
                                args.repeat,
                                threads,
                                &scene_name,
                            )?)
                        }
                        _ => None,
                    };
                    if let Some(Measured { mut row, keys, fb }) = measured {
                        if let (Some(r), Some(fb)) = (&reference, &fb) {
                            row.error(r.error_of(fb));
                        }
                        group.push((row, keys));
                    }
                    progress.inc(1);
                }
                // Ratios to 2dr-brute at f32, whatever this group's precision
                // (f32 comes first).
                if precision == Precision::F32 {
                    f32_base = brute_base(&group);
                }
                fill_relations(&mut group, f32_base);
                rows.extend(group.into_iter().map(|(r, _)| r));
            }
        }
        fill_aa_ratios(&mut rows[first_row..]);
        fill_precision_ratios(&mut rows[first_row..]);
    }
    progress.finish_and_clear();

    let doc = json!({
        "machine": machine(threads),
        "command": std::env::args().collect::<Vec<_>>().join(" "),
        "rows": rows,
    });
    let text = serde_json::to_string_pretty(&doc).context("encoding results")?;
    std::fs::write(args.out.join("results.json"), &text).context("writing results.json")?;
    write_csv(&args.out.join("results.csv"), &rows)?;
    if !args.aa.is_empty() {
        let path = args.out.join("aa_cost.svg");
        let points: Vec<AaPoint> = rows
            .iter()
            .filter_map(|r| {
                Some(AaPoint {
                    scene: r.scene.clone(),
                    algorithm: r.algorithm.clone(),
                    aa: r.aa.clone(),
                    median_ms: r.median_ms,
                    flip_mean: r.flip_mean?,
                })
            })
            .collect();
        std::fs::write(&path, aa_cost_svg(&points))
            .with_context(|| format!("writing {}", path.display()))?;
    }
    if args.json {
        write_stdout(&(text + "\n"))?;
    } else {
        write_stdout(&table_text(&rows))?;
    }
    Ok(())
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
        camera: &continuum::Camera,
        (width, height): (u32, u32),
    ) -> Result<Reference, CliError> {
        let request = |aa| RenderRequest {
            algorithm: AlgorithmId::ThreeDBin,
            oracles: None,
            camera: camera.clone(),
            width,
            height,
            aa,
            precision: Precision::F32,
        };
        let run = |aa| {
            render(prepared, &request(aa))
                .map(|o| o.framebuffer.color)
                .map_err(|e| CliError::Usage(format!("--{e}")))
        };
        let color = run(continuum::aa::REFERENCE)?;
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

/// Each row's time against the same scene, algorithm and precision without
/// anti-aliasing.
fn fill_aa_ratios(rows: &mut [Row]) {
    let none: HashMap<(String, Precision), f64> = rows
        .iter()
        .filter(|r| r.aa == "none")
        .map(|r| ((r.algorithm.clone(), r.precision), r.median_ms))
        .collect();
    for r in rows {
        r.ratio_to_aa_none = none
            .get(&(r.algorithm.clone(), r.precision))
            .map(|base| r.median_ms / base);
    }
}

/// Each row's time against the same scene, algorithm and mode at f32.
fn fill_precision_ratios(rows: &mut [Row]) {
    let single: HashMap<(String, String), f64> = rows
        .iter()
        .filter(|r| r.precision == Precision::F32)
        .map(|r| ((r.algorithm.clone(), r.aa.clone()), r.median_ms))
        .collect();
    for r in rows {
        r.ratio_to_f32 = single
            .get(&(r.algorithm.clone(), r.aa.clone()))
            .map(|base| r.median_ms / base);
    }
}

/// One measured row, the key that decides agreement (per pixel: the triangle
/// id, or the digest of every sample's id under anti-aliasing) and, for our
/// own algorithms, the framebuffer.
struct Measured {
    row: Row,
    keys: Vec<u64>,
    fb: Option<Framebuffer>,
}

fn measure_algorithm(
    pool: &rayon::ThreadPool,
    prepared: &PreparedScene,
    camera: &continuum::Camera,
    (algorithm, aa, precision): (AlgorithmId, AaMode, Precision),
    args: &CompareArgs,
    threads: usize,
    scene: &str,
) -> Result<Measured, CliError> {
    let request = RenderRequest {
        algorithm,
        oracles: None,
        camera: camera.clone(),
        width: args.size.0,
        height: args.size.1,
        aa,
        precision,
    };
    let mut out = pool
        .install(|| render(prepared, &request))
        .map_err(|e| CliError::Usage(format!("--{e}")))?;
    let mut times = Vec::new();
    for _ in 0..args.repeat {
        out = pool
            .install(|| render(prepared, &request))
            .map_err(|e| CliError::Usage(format!("--{e}")))?;
        times.push(out.stats.time_ms.total);
    }
    let mut row = Row::timed(
        scene,
        algorithm.as_str(),
        (args.size.0, args.size.1),
        threads,
        times,
    )
    .with(
        &out.viewport,
        &out.aa,
        serde_json::to_value(&out.stats).unwrap_or(Value::Null),
    )
    .hashes(serde_json::to_value(&out.hashes).unwrap_or(Value::Null));
    row.precision = precision;
    row.shading_samples = out.stats.shading_samples;
    row.coverage_samples = out.stats.coverage_samples;
    let fb = out.framebuffer;
    let keys = if fb.sample_digest.is_empty() {
        fb.triangle_id.iter().map(|&t| u64::from(t)).collect()
    } else {
        fb.sample_digest.clone()
    };
    Ok(Measured {
        row,
        keys,
        fb: Some(fb),
    })
}

fn measure_peer(
    pool: &rayon::ThreadPool,
    prepared: &PreparedScene,
    view: &View,
    peer: PeerId,
    repeat: u32,
    threads: usize,
    scene: &str,
) -> Result<Measured, CliError> {
    let run = pool
        .install(|| run_peer(peer, prepared, view, repeat))
        .map_err(|e| CliError::Usage(format!("--algorithms: {e}")))?;
    let mut row = Row::timed(
        scene,
        peer.as_str(),
        (view.width, view.height),
        threads,
        run.times_ms,
    )
    .with(
        "perspective",
        "none",
        json!({ "bvh_build_ms": run.build_ms }),
    );
    row.coverage_samples = u64::from(view.width) * u64::from(view.height);
    Ok(Measured {
        row,
        keys: run.triangle_id.iter().map(|&t| u64::from(t)).collect(),
        fb: None,
    })
}

/// 2dr-brute's median time and predicted instructions in `rows`, if measured.
fn brute_base(rows: &[(Row, Vec<u64>)]) -> Option<(f64, Option<f64>)> {
    rows.iter()
        .find(|(r, _)| r.algorithm == "2dr-brute")
        .map(|(r, _)| (r.median_ms, r.stats["predicted_instructions"].as_f64()))
}

/// Ratios to `base` (2dr-brute's time and predicted instructions), family
/// agreement and peer differences within one scene, anti-aliasing mode and
/// precision.
fn fill_relations(rows: &mut [(Row, Vec<u64>)], base: Option<(f64, Option<f64>)>) {
    let find =
        |rows: &[(Row, Vec<u64>)], name: &str| rows.iter().position(|(r, _)| r.algorithm == name);
    let three_d = find(rows, "3dr-brute").map(|i| rows[i].1.clone());
    // The first member of each family present is its reference.
    let mut family_reference: HashMap<String, usize> = HashMap::new();
    for i in 0..rows.len() {
        let name = rows[i].0.algorithm.clone();
        if let Some((base_ms, base_instr)) = base {
            rows[i].0.ratio_to_2dr_brute = Some(rows[i].0.median_ms / base_ms);
            if let (Some(bi), Some(pi)) = (
                base_instr,
                rows[i].0.stats["predicted_instructions"].as_f64(),
            ) {
                rows[i].0.predicted_ratio = Some(pi / bi);
            }
        }
        // Our own algorithms agree within their family; peers (and the GPU's
        // rasterizer) report how many pixels differ from 3dr-brute.
        match AlgorithmId::CPU.into_iter().find(|a| a.as_str() == name) {
            Some(a) => {
                let family = format!("{:?}", a.family());
                let reference = *family_reference.entry(family).or_insert(i);
                rows[i].0.agrees = rows[i].1 == rows[reference].1;
            }
            None => {
                if let Some(ids) = &three_d {
                    let differing =
                        ids.iter().zip(&rows[i].1).filter(|(a, b)| a != b).count() as u64;
                    rows[i].0.pixels_differing_from_3dr_brute = Some(differing);
                    rows[i].0.agrees = differing == 0;
                }
            }
        }
    }
}

fn machine(threads: usize) -> Value {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into());
    json!({
        "cpu": cpu,
        "logical_cores": std::thread::available_parallelism().map_or(0, |n| n.get()),
        "threads": threads,
        "os": std::env::consts::OS,
        "arch": std::env::consts::ARCH,
        "continuum_version": env!("CARGO_PKG_VERSION"),
    })
}

fn write_csv(path: &std::path::Path, rows: &[Row]) -> Result<(), CliError> {
    let mut f =
        std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?;
    let mut text = String::from(
        "scene,algorithm,aa,precision,width,height,threads,median_ms,min_ms,max_ms,ratio_to_2dr_brute,predicted_ratio,rays_per_second,triangle_setups,edge_evaluations,bvh_nodes_visited,agrees,pixels_differing_from_3dr_brute,triangle_id_hash,ratio_to_aa_none,ratio_to_f32,shading_samples,coverage_samples,psnr,psnr_edges,flip_mean\n",
    );
    let opt = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:.4}"));
    for r in rows {
        let stat = |k: &str| {
            r.stats
                .get(k)
                .and_then(Value::as_u64)
                .map_or(String::new(), |v| v.to_string())
        };
        text.push_str(&format!(
            "{},{},{},{},{},{},{},{:.3},{:.3},{:.3},{},{},{:.0},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            r.scene,
            r.algorithm,
            r.aa,
            r.precision,
            r.width,
            r.height,
            r.threads,
            r.median_ms,
            r.min_ms,
            r.max_ms,
            opt(r.ratio_to_2dr_brute),
            opt(r.predicted_ratio),
            r.rays_per_second,
            stat("triangle_setups"),
            stat("edge_evaluations"),
            stat("bvh_nodes_visited"),
            r.agrees,
            r.pixels_differing_from_3dr_brute
                .map_or(String::new(), |v| v.to_string()),
            r.hashes
                .get("triangle_id")
                .and_then(Value::as_str)
                .unwrap_or(""),
            opt(r.ratio_to_aa_none),
            opt(r.ratio_to_f32),
            r.shading_samples,
            r.coverage_samples,
            opt(r.psnr),
            opt(r.psnr_edges),
            r.flip_mean.map_or(String::new(), |v| format!("{v:.6}")),
        ));
    }
    f.write_all(text.as_bytes())
        .context("writing results.csv")?;
    Ok(())
}

/// The rows as a table for the terminal.
fn table_text(rows: &[Row]) -> String {
    use std::fmt::Write;
    let mut out = String::new();
    writeln!(
        out,
        "{:<12} {:<18} {:<10} {:<5} {:>10} {:>8} {:>9} {:>7} {:>7} {:>9} {:>9} {:>7} {:>7}",
        "scene",
        "algorithm",
        "aa",
        "prec",
        "median ms",
        "ratio",
        "predicted",
        "x none",
        "x f32",
        "PSNR dB",
        "edges dB",
        "FLIP",
        "agrees"
    )
    .ok();
    for r in rows {
        let opt = |v: Option<f64>| v.map_or("-".to_string(), |x| format!("{x:.2}"));
        writeln!(
            out,
            "{:<12} {:<18} {:<10} {:<5} {:>10.2} {:>8} {:>9} {:>7} {:>7} {:>9} {:>9} {:>7} {:>7}",
            r.scene,
            r.algorithm,
            r.aa,
            r.precision,
            r.median_ms,
            opt(r.ratio_to_2dr_brute),
            opt(r.predicted_ratio),
            opt(r.ratio_to_aa_none),
            opt(r.ratio_to_f32),
            opt(r.psnr),
            opt(r.psnr_edges),
            r.flip_mean.map_or("-".to_string(), |v| format!("{v:.4}")),
            match r.pixels_differing_from_3dr_brute {
                Some(d) => format!("{d} px"),
                None => r.agrees.to_string(),
            }
        )
        .ok();
    }
    out
}
