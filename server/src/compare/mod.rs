//! `continuum compare`: the benchmark. Every algorithm and peer on every scene,
//! viewport, anti-aliasing mode and precision of a sweep, in one process,
//! timed as medians over repeats and reported as ratios to `2dr-brute` (the
//! paper's Fig. 9 form), with the counters that explain them. Writes
//! `results.json`, `results.csv`, `report.html` (and `aa_cost.svg` with
//! anti-aliasing) into `--out`. A sweep can run in disjoint shards
//! (`--shard I/N`) and be merged (`continuum compare merge`).

mod measure;
pub mod peer;
mod report;
pub mod sweep;

use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::{Args, Subcommand};
use continuum::Precision;
use continuum::metrics::ImageError;
use serde::{Deserialize, Serialize};
use serde_json::{Value, json};

use crate::plot::{AaPoint, aa_cost_svg};
use crate::{CliError, scenes_dir, write_stdout};
use measure::{LoadedScene, measure_cell};
use sweep::{Shard, Sweep, SweepFile, read_sweep_file};

#[derive(Args, Debug)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct CompareArgs {
    #[command(subcommand)]
    command: Option<CompareCommand>,
    /// A sweep file describing the matrix (scenes, algorithms, viewports, aa,
    /// precision, size, repeat, threads, camera); instead of those flags.
    #[arg(long, conflicts_with_all = ["scenes", "algorithms", "camera", "viewports", "aa", "precision", "size", "repeat", "threads", "oracles"])]
    sweep: Option<PathBuf>,
    /// Run only part I of N (0-based: 0/4 … 3/4) of the sweep's cells.
    #[arg(long, value_parser = Shard::parse)]
    shard: Option<Shard>,
    /// Scenes: built-in names or paths, comma-separated [default: every built-in scene].
    #[arg(long, value_delimiter = ',')]
    scenes: Vec<String>,
    #[arg(long, value_delimiter = ',', help = crate::help::algorithms_and_peers())]
    algorithms: Vec<String>,
    /// Camera name; default: each scene's first camera.
    #[arg(long)]
    camera: Option<String>,
    /// Viewports, comma-separated: `camera` (the camera's own), `perspective[:FOV]`,
    /// `orthographic[:HEIGHT]`, `parabolic`, `latlong` [default: camera].
    #[arg(long, value_delimiter = ',')]
    viewports: Vec<String>,
    /// Image size, WIDTHxHEIGHT [default: 1280x720].
    #[arg(long)]
    size: Option<String>,
    /// Timed runs per scene and algorithm, after one warm-up run [default: 3].
    #[arg(long)]
    repeat: Option<u32>,
    /// Worker threads, comma-separated: each count measures every cell, and
    /// rows report their speed-up over the smallest [default: all cores].
    #[arg(long, value_delimiter = ',')]
    threads: Vec<u32>,
    /// Anti-aliasing modes, comma-separated (none, ssaa:4|16|64|256,
    /// msaa:2|4|8|16, csaa:CxS with C in 4, 8, 16 and S in 1, 2, 4, 8 below C);
    /// each is measured against a ssaa:256 reference and plotted in aa_cost.svg
    /// [default: none, without a reference].
    #[arg(long, value_delimiter = ',')]
    aa: Vec<String>,
    /// Precisions, comma-separated (f32, f64 for the 3D family, fixed for the 2D
    /// family); each algorithm runs at every one it computes in, and rows
    /// report their time against f32 [default: f32].
    #[arg(long, value_delimiter = ',')]
    precision: Vec<String>,
    /// Oracle settings, semicolon-separated, each in `render --oracles` words
    /// (e.g. `frustum=128,split=16;split=off`): every algorithm a setting
    /// changes gets a row `ALGORITHM[SETTING]` beside its own, and the table
    /// ends with the fastest setting per scene, cell and algorithm.
    #[arg(long, value_delimiter = ';')]
    oracles: Vec<String>,
    /// Folder for results.json, results.csv and report.html (required).
    #[arg(long, required = true)]
    out: Option<PathBuf>,
    /// Also print results.json on stdout.
    #[arg(long)]
    json: bool,
    /// Folder of built-in scenes.
    #[arg(long = "scenes-dir")]
    scenes_dir: Option<PathBuf>,
}

#[derive(Subcommand, Debug)]
enum CompareCommand {
    /// Merge the outputs of shard runs into one results.json and report.html.
    Merge(MergeArgs),
}

#[derive(Args, Debug)]
struct MergeArgs {
    /// Folders written by `continuum compare --shard I/N --out DIR`.
    #[arg(required = true)]
    shards: Vec<PathBuf>,
    /// Folder for the merged results.json, results.csv and report.html.
    #[arg(long)]
    out: PathBuf,
}

/// One measured row of results.json.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Row {
    pub scene: String,
    /// The scene's triangles (0 in results written before it was recorded).
    #[serde(default)]
    pub scene_triangles: u64,
    pub algorithm: String,
    #[serde(default)]
    pub camera: String,
    pub viewport: String,
    pub aa: String,
    pub precision: Precision,
    /// Off in the paper's §5 GPU experiment (the sweep's `depth_test`).
    #[serde(default = "depth_test_on")]
    pub depth_test: bool,
    pub width: u32,
    pub height: u32,
    pub threads: usize,
    pub median_ms: f64,
    pub min_ms: f64,
    pub max_ms: f64,
    pub ratio_to_2dr_brute: Option<f64>,
    pub predicted_ratio: Option<f64>,
    pub rays_per_second: f64,
    /// The median render without its resolve and shading stages: finding what each sample
    /// sees (setup, traversal, binning, coverage) — what the peers, which
    /// shade nothing, are timed doing.
    #[serde(default)]
    pub visibility_ms: Option<f64>,
    /// Each stage's median time over the timed rounds (continuum's own
    /// algorithms): where the frame's time goes.
    #[serde(default)]
    pub stage_ms: Option<continuum::StageTimes>,
    /// With several thread counts in the run: the time at the smallest count
    /// over this row's (same scene, cell and algorithm).
    #[serde(default)]
    pub speedup: Option<f64>,
    pub stats: Value,
    pub hashes: Value,
    /// Does the triangle-id buffer equal its family's reference (for peers and
    /// the GPU: 3dr-brute's)?
    pub agrees: bool,
    /// Pixels whose triangle id differs from 3dr-brute's (peers and the GPU).
    pub pixels_differing_from_3dr_brute: Option<u64>,
    /// Time against the same algorithm without anti-aliasing (when measured).
    pub ratio_to_aa_none: Option<f64>,
    /// Time against the same algorithm and mode at f32 (when measured).
    pub ratio_to_f32: Option<f64>,
    /// Shading evaluations and coverage samples of the render.
    pub shading_samples: u64,
    pub coverage_samples: u64,
    /// Error against the ssaa:256 reference (with anti-aliasing modes).
    pub psnr: Option<f64>,
    pub psnr_edges: Option<f64>,
    pub flip_mean: Option<f64>,
    /// The sweep cell (scene, viewport, mode, precision) the row belongs to.
    #[serde(default)]
    pub cell: usize,
    /// The edge-evaluation thumbnail, relative to the output folder.
    #[serde(default)]
    pub map: Option<String>,
    /// The oracle settings on top of the algorithm's own (`--oracles` rows,
    /// whose `algorithm` reads `ID[SETTING]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub oracles: Option<String>,
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
            scene_triangles: 0,
            algorithm: algorithm.to_string(),
            camera: String::new(),
            viewport: String::new(),
            aa: String::new(),
            precision: Precision::F32,
            depth_test: true,
            width,
            height,
            threads,
            median_ms,
            min_ms,
            max_ms,
            ratio_to_2dr_brute: None,
            predicted_ratio: None,
            rays_per_second: f64::from(width) * f64::from(height) / (median_ms / 1e3),
            visibility_ms: None,
            stage_ms: None,
            speedup: None,
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
            cell: 0,
            map: None,
            oracles: None,
        }
    }

    fn with(mut self, viewport: &str, aa: &str, stats: Value) -> Row {
        self.viewport = viewport.to_string();
        self.aa = aa.to_string();
        self.stats = stats;
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
    if let Some(CompareCommand::Merge(m)) = &args.command {
        return merge(m);
    }
    let out = args
        .out
        .clone()
        .ok_or_else(|| CliError::Usage("--out: the folder for the results is required".into()))?;
    let dir = scenes_dir(args.scenes_dir.as_ref());
    let file = match &args.sweep {
        Some(path) => read_sweep_file(path)?,
        None => sweep_from_flags(args),
    };
    let sweep = Sweep::new(file, || {
        continuum::scene::builtin_names(&dir)
            .map_err(|e| CliError::Usage(format!("scenes-dir: {e}")))
    })
    .map_err(|e| match e {
        CliError::Usage(m) if args.sweep.is_none() => CliError::Usage(format!("--{m}")),
        CliError::Usage(m) => CliError::Usage(format!("--sweep: {m}")),
        other => other,
    })?;
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    let threads = match sweep.threads.as_slice() {
        [] => vec![rayon::current_num_threads()],
        counts => counts.to_vec(),
    };
    let pools = (threads.iter())
        .map(|&t| rayon::ThreadPoolBuilder::new().num_threads(t).build())
        .collect::<Result<Vec<_>, _>>()
        .context("building the thread pools")?;
    let widest = pools.last().context("one thread pool at least")?;

    // 1. The cells this run measures.
    let cells: Vec<sweep::Cell> = sweep
        .cells()
        .into_iter()
        .filter(|c| args.shard.is_none_or(|s| s.takes(c)))
        .collect();
    let steps = (cells.len() * sweep.entries.len() * pools.len()) as u64;
    let progress = indicatif::ProgressBar::new(steps).with_style(
        indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} {msg} [{elapsed}]")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    // 2. Scene by scene (each loaded and prepared once), cell by cell.
    let mut rows = Vec::new();
    let mut loaded: Option<(String, LoadedScene)> = None;
    for cell in &cells {
        if loaded.as_ref().is_none_or(|(name, _)| *name != cell.scene) {
            progress.set_message(format!("{}: preparing", cell.scene));
            loaded = Some((
                cell.scene.clone(),
                LoadedScene::load(&cell.scene, &sweep, &dir, widest)?,
            ));
        }
        let Some((_, scene)) = &mut loaded else {
            continue;
        };
        for pool in &pools {
            rows.extend(measure_cell(cell, scene, &sweep, pool, &out, &progress)?);
        }
    }
    progress.finish_and_clear();
    relate(&mut rows);

    // 3. The outputs.
    let meta = json!({
        "machine": machine(&threads),
        "command": std::env::args().collect::<Vec<_>>().join(" "),
        "sweep": sweep.file,
        "shard": args.shard,
        "not_run": sweep.not_run,
    });
    let text = write_outputs(&out, meta, &rows, &out)?;
    if args.json {
        write_stdout(&(text + "\n"))?;
    } else {
        let mut text = table_text(&rows);
        for n in &sweep.not_run {
            text.push_str(&format!("not run: {} ({})\n", n.algorithm, n.reason));
        }
        write_stdout(&text)?;
    }
    Ok(())
}

/// The sweep the matrix flags describe.
fn sweep_from_flags(args: &CompareArgs) -> SweepFile {
    let list = |v: &Vec<String>| (!v.is_empty()).then(|| v.clone());
    SweepFile {
        scenes: args.scenes.clone(),
        algorithms: list(&args.algorithms),
        viewports: list(&args.viewports),
        aa: list(&args.aa),
        precision: list(&args.precision),
        size: args.size.clone(),
        repeat: args.repeat,
        threads: match args.threads.as_slice() {
            [] => None,
            [one] => Some(sweep::Threads::One(*one)),
            many => Some(sweep::Threads::Each(many.to_vec())),
        },
        camera: args.camera.clone(),
        depth_test: None,
        oracles: list(&args.oracles),
    }
}

/// The relations between rows of different cells, from their medians alone
/// (so a merge of shards computes them as an unsharded run does): the ratio
/// to `2dr-brute` of the same scene, viewport and mode at f32 (time and
/// predicted instructions), to the same algorithm without anti-aliasing, and
/// to the same algorithm at f32.
pub fn relate(rows: &mut [Row]) {
    let key = |r: &Row| {
        (
            r.scene.clone(),
            r.viewport.clone(),
            r.camera.clone(),
            r.threads,
            r.depth_test,
        )
    };
    let brute: HashMap<_, (f64, Option<f64>)> = rows
        .iter()
        .filter(|r| r.algorithm == "2dr-brute" && r.precision == Precision::F32)
        .map(|r| {
            let k = (key(r), r.aa.clone());
            (k, (r.median_ms, r.stats["predicted_instructions"].as_f64()))
        })
        .collect();
    let none: HashMap<_, f64> = rows
        .iter()
        .filter(|r| r.aa == "none")
        .map(|r| ((key(r), r.algorithm.clone(), r.precision), r.median_ms))
        .collect();
    let single: HashMap<_, f64> = rows
        .iter()
        .filter(|r| r.precision == Precision::F32)
        .map(|r| ((key(r), r.algorithm.clone(), r.aa.clone()), r.median_ms))
        .collect();
    // The same measurement at the run's smallest thread count.
    let same = |r: &Row| {
        let (scene, camera) = (r.scene.clone(), r.camera.clone());
        let what = (r.algorithm.clone(), r.aa.clone(), r.precision);
        (scene, r.viewport.clone(), camera, r.depth_test, what)
    };
    let mut fewest: HashMap<_, (usize, f64)> = HashMap::new();
    for r in rows.iter() {
        let entry = fewest.entry(same(r)).or_insert((r.threads, r.median_ms));
        if r.threads < entry.0 {
            *entry = (r.threads, r.median_ms);
        }
    }
    let several = rows.iter().any(|r| r.threads != rows[0].threads);
    for r in rows.iter_mut() {
        r.speedup = several
            .then(|| fewest.get(&same(r)))
            .flatten()
            .map(|(_, ms)| ms / r.median_ms);
        let base = brute.get(&(key(r), r.aa.clone()));
        r.ratio_to_2dr_brute = base.map(|(ms, _)| r.median_ms / ms);
        r.predicted_ratio = base.and_then(|(_, instructions)| {
            let ours = r.stats["predicted_instructions"].as_f64()?;
            let base = (*instructions)?;
            (ours > 0.0 && base > 0.0).then(|| ours / base)
        });
        r.ratio_to_aa_none = none
            .get(&(key(r), r.algorithm.clone(), r.precision))
            .map(|ms| r.median_ms / ms);
        r.ratio_to_f32 = single
            .get(&(key(r), r.algorithm.clone(), r.aa.clone()))
            .map(|ms| r.median_ms / ms);
    }
}

/// Writes results.json (`meta` plus the rows), results.csv, aa_cost.svg
/// (when rows carry image errors) and report.html into `out`; thumbnails are
/// read from `maps_root`. Returns the results.json text.
fn write_outputs(
    out: &Path,
    meta: Value,
    rows: &[Row],
    maps_root: &Path,
) -> Result<String, CliError> {
    let mut doc = meta;
    doc["rows"] = serde_json::to_value(rows).context("encoding results")?;
    let text = serde_json::to_string_pretty(&doc).context("encoding results")?;
    std::fs::write(out.join("results.json"), &text).context("writing results.json")?;
    write_csv(&out.join("results.csv"), rows)?;
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
    let aa_svg = (!points.is_empty()).then(|| aa_cost_svg(&points));
    if let Some(svg) = &aa_svg {
        let path = out.join("aa_cost.svg");
        std::fs::write(&path, svg).with_context(|| format!("writing {}", path.display()))?;
    }
    let html = report::report_html(&doc, rows, maps_root, aa_svg.as_deref());
    std::fs::write(out.join("report.html"), html).context("writing report.html")?;
    Ok(text)
}

/// `continuum compare merge`: the shards' rows together, their relations
/// computed again, their thumbnails copied, one report.
fn merge(args: &MergeArgs) -> Result<(), CliError> {
    let mut rows: Vec<Row> = Vec::new();
    let mut shards = Vec::new();
    let mut sweep: Option<Value> = None;
    let mut seen: Vec<Value> = Vec::new();
    let mut not_run: Vec<Value> = Vec::new();
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    for dir in &args.shards {
        let path = dir.join("results.json");
        let text = std::fs::read_to_string(&path)
            .map_err(|e| CliError::Usage(format!("{}: {e}", path.display())))?;
        let doc: Value = serde_json::from_str(&text)
            .map_err(|e| CliError::Usage(format!("{}: {e}", path.display())))?;
        let this_sweep = doc.get("sweep").cloned().unwrap_or(Value::Null);
        match &sweep {
            None => sweep = Some(this_sweep),
            Some(s) if *s != this_sweep => {
                return Err(CliError::Usage(format!(
                    "{}: a shard of another sweep ({this_sweep} against {s})",
                    path.display()
                )));
            }
            Some(_) => {}
        }
        let shard = doc.get("shard").cloned().unwrap_or(Value::Null);
        if !shard.is_null() && seen.contains(&shard) {
            return Err(CliError::Usage(format!(
                "{}: shard {shard} given twice",
                path.display()
            )));
        }
        seen.push(shard.clone());
        let part: Vec<Row> = serde_json::from_value(doc["rows"].clone())
            .map_err(|e| CliError::Usage(format!("{}: rows: {e}", path.display())))?;
        for row in &part {
            if let Some(map) = &row.map {
                let (from, to) = (dir.join(map), args.out.join(map));
                if let Some(parent) = to.parent() {
                    std::fs::create_dir_all(parent)
                        .with_context(|| format!("creating {}", parent.display()))?;
                }
                if from != to {
                    std::fs::copy(&from, &to)
                        .with_context(|| format!("copying {}", from.display()))?;
                }
            }
        }
        rows.extend(part);
        for n in doc["not_run"].as_array().into_iter().flatten() {
            if !not_run.contains(n) {
                not_run.push(n.clone());
            }
        }
        shards.push(json!({ "dir": dir.display().to_string(), "machine": doc["machine"], "command": doc["command"], "shard": shard }));
    }
    // Every part of the sweep must be there.
    if let Some(count) = seen.iter().find_map(|s| s["count"].as_u64()) {
        let missing: Vec<u64> = (0..count)
            .filter(|i| !seen.iter().any(|s| s["index"].as_u64() == Some(*i)))
            .collect();
        if !missing.is_empty() {
            return Err(CliError::Usage(format!(
                "shards {missing:?} of {count} are missing"
            )));
        }
    }
    rows.sort_by_key(|r| r.cell);
    relate(&mut rows);
    let meta = json!({
        "machine": shards.first().map_or(Value::Null, |s| s["machine"].clone()),
        "command": std::env::args().collect::<Vec<_>>().join(" "),
        "sweep": sweep.unwrap_or(Value::Null),
        "shards": shards,
        "not_run": not_run,
    });
    write_outputs(&args.out, meta, &rows, &args.out)?;
    write_stdout(&table_text(&rows))?;
    Ok(())
}

/// The machine a run measured on: CPU, cores, threads, OS, the GPU adapter
/// (when built with it and one opens), the SIMD kernels and continuum's version.
fn machine(threads: &[usize]) -> Value {
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
        "threads": match threads {
            [one] => json!(one),
            many => json!(many),
        },
        "os": std::env::consts::OS,
        "arch": std::env::consts::ARCH,
        "continuum_version": env!("CARGO_PKG_VERSION"),
        "gpu": gpu_adapter(),
        "lp_num_threads": std::env::var("LP_NUM_THREADS").ok(),
        // The coverage kernels' instruction set (`CONTINUUM_SIMD=portable` forces the portable one).
        "simd": match continuum::isa() {
            continuum::Isa::Avx2 => "avx2",
            continuum::Isa::Portable => "portable",
        },
    })
}

/// A CSV field as RFC 4180 writes it: quoted when it holds a comma, a quote
/// or a line break (an `--oracles` row's label, a scene path).
fn csv_field(text: &str) -> std::borrow::Cow<'_, str> {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\"")).into()
    } else {
        text.into()
    }
}

fn write_csv(path: &std::path::Path, rows: &[Row]) -> Result<(), CliError> {
    let mut f =
        std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?;
    let mut text = String::from(
        "scene,algorithm,camera,viewport,aa,precision,width,height,threads,median_ms,min_ms,max_ms,ratio_to_2dr_brute,predicted_ratio,rays_per_second,triangle_setups,edge_evaluations,bvh_nodes_visited,agrees,pixels_differing_from_3dr_brute,triangle_id_hash,ratio_to_aa_none,ratio_to_f32,shading_samples,coverage_samples,psnr,psnr_edges,flip_mean,visibility_ms,setup_ms,traversal_ms,coverage_ms,resolve_ms,shading_ms,store_ms,speedup,scene_bytes_per_triangle,spans,edge_steps,nodes_culled_outside,nodes_culled_occluded,frusta_split,leaf_setups_reused,scene_triangles\n",
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
            "{},{},{},{},{},{},{},{},{},{:.3},{:.3},{:.3},{},{},{:.0},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            csv_field(&r.scene),
            csv_field(&r.algorithm),
            csv_field(&r.camera),
            r.viewport,
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
            opt(r.visibility_ms),
            r.stage_ms.map_or(",,,,,".to_string(), |t| {
                [t.setup, t.traversal, t.coverage, t.resolve, t.shading, t.store]
                    .map(|ms| format!("{ms:.4}"))
                    .join(",")
            }),
            opt(r.speedup),
            opt(r.stats.get("scene_bytes_per_triangle").and_then(Value::as_f64)),
            stat("spans"),
            stat("edge_steps"),
            stat("nodes_culled_outside"),
            stat("nodes_culled_occluded"),
            stat("frusta_split"),
            stat("leaf_setups_reused"),
            r.scene_triangles,
        ));
    }
    f.write_all(text.as_bytes())
        .context("writing results.csv")?;
    Ok(())
}

/// The rows as a table for the terminal.
fn depth_test_on() -> bool {
    true
}

fn table_text(rows: &[Row]) -> String {
    use std::fmt::Write;
    let mut out = String::new();
    // `--oracles` rows' labels are longer than the ids.
    let width = rows.iter().map(|r| r.algorithm.len()).fold(18, usize::max);
    writeln!(
        out,
        "{:<16} {:<width$} {:<16} {:<10} {:<5} {:>3} {:>10} {:>8} {:>9} {:>7} {:>7} {:>6} {:>7} {:>7} {:>9} {:>9} {:>7} {:>7}",
        "scene",
        "algorithm",
        "viewport",
        "aa",
        "prec",
        "thr",
        "median ms",
        "ratio",
        "predicted",
        "frame%",
        "speedup",
        "B/tri",
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
        let aa = if r.depth_test {
            r.aa.clone()
        } else {
            format!("{} no-z", r.aa)
        };
        writeln!(
            out,
            "{:<16} {:<width$} {:<16} {:<10} {:<5} {:>3} {:>10.2} {:>8} {:>9} {:>7} {:>7} {:>6} {:>7} {:>7} {:>9} {:>9} {:>7} {:>7}",
            r.scene,
            r.algorithm,
            r.viewport,
            aa,
            r.precision,
            r.threads,
            r.median_ms,
            opt(r.ratio_to_2dr_brute),
            opt(r.predicted_ratio),
            r.stage_ms
                .map_or("-".to_string(), |t| format!("{:.1}", 100.0 * frame_share(&t))),
            opt(r.speedup),
            (r.stats.get("scene_bytes_per_triangle").and_then(Value::as_f64))
                .map_or("-".to_string(), |b| format!("{b:.0}")),
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
    let best = fastest_oracles(rows);
    if !best.is_empty() {
        writeln!(out, "\nfastest oracles (scene, viewport, aa, precision, threads: algorithm -> fastest row, median ms, x own setting)").ok();
        for b in best {
            writeln!(
                out,
                "{} {} {} {} {}: {} -> {} {:.2} ms x{:.3}",
                b.own.scene,
                b.own.viewport,
                b.own.aa,
                b.own.precision,
                b.own.threads,
                b.own.algorithm,
                b.fastest.algorithm,
                b.fastest.median_ms,
                b.fastest.median_ms / b.own.median_ms
            )
            .ok();
        }
    }
    if let Some(table) = report::sect5_rows(rows) {
        writeln!(out, "\n{}", report::SECT5_TITLE).ok();
        for line in table {
            writeln!(out, "{}", line.join("  ")).ok();
        }
    }
    out
}

/// An algorithm's row at its own oracle settings and the fastest of it and
/// its `--oracles` rows in the same cell and thread count.
pub struct FastestOracles<'r> {
    pub own: &'r Row,
    pub fastest: &'r Row,
}

/// For every row that has `--oracles` rows beside it: the fastest setting.
pub fn fastest_oracles(rows: &[Row]) -> Vec<FastestOracles<'_>> {
    let own_rows = rows.iter().filter(|r| r.oracles.is_none());
    own_rows
        .filter_map(|own| {
            let prefix = format!("{}[", own.algorithm);
            let mut tuned = rows
                .iter()
                .filter(|r| {
                    r.oracles.is_some()
                        && r.algorithm.starts_with(&prefix)
                        && (&r.scene, r.cell, r.threads) == (&own.scene, own.cell, own.threads)
                })
                .peekable();
            tuned.peek()?;
            let fastest = tuned.fold(own, |f, r| if r.median_ms < f.median_ms { r } else { f });
            Some(FastestOracles { own, fastest })
        })
        .collect()
}

/// The share of a render's time spent on the frame around its algorithm:
/// resolve, shading and store over the total.
pub fn frame_share(t: &continuum::StageTimes) -> f64 {
    if t.total <= 0.0 {
        return 0.0;
    }
    (t.resolve + t.shading + t.store) / t.total
}

#[cfg(feature = "gpu")]
fn gpu_adapter() -> Option<String> {
    continuum::gpu_adapter()
}

#[cfg(not(feature = "gpu"))]
fn gpu_adapter() -> Option<String> {
    None
}
