//! The `continuum` binary as a user runs it.

use std::path::PathBuf;
use std::process::{Command, Output};

fn continuum(args: &[&str]) -> Output {
    continuum_with(args, &[])
}

fn continuum_with(args: &[&str], env: &[(&str, &str)]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_continuum"))
        .args(args)
        .env("CONTINUUM_SCENES", scenes())
        .envs(env.iter().copied())
        .output()
        .expect("run continuum")
}

fn scenes() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes")
}

fn out_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("continuum-cli-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

#[test]
fn render_json_has_the_documented_keys() {
    let out = continuum(&[
        "render",
        "--scene",
        "box",
        "--algorithm",
        "3dr-brute",
        "--size",
        "64x48",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value =
        serde_json::from_slice(&out.stdout).expect("stdout is one JSON document");
    for key in [
        "scene",
        "algorithm",
        "viewport",
        "aa",
        "width",
        "height",
        "stats",
        "hashes",
    ] {
        assert!(doc.get(key).is_some(), "missing {key}: {doc}");
    }
    assert_eq!(doc["scene"], "box");
    assert_eq!(doc["algorithm"], "3dr-brute");
    assert_eq!(
        (doc["width"].as_u64(), doc["height"].as_u64()),
        (Some(64), Some(48))
    );
    let stats = &doc["stats"];
    for key in ["setup", "traversal", "coverage", "shading", "total"] {
        assert!(stats["time_ms"][key].is_number(), "time_ms.{key}: {stats}");
    }
    for key in ["triangle_setups", "edge_evaluations", "bvh_nodes_visited"] {
        assert!(stats[key].is_u64(), "{key}: {stats}");
    }
    let h = &stats["coverage_histogram"];
    let total: u64 = ["zero", "one", "many"]
        .iter()
        .map(|k| h[k].as_u64().expect("count"))
        .sum();
    assert_eq!(total, 64 * 48);
    for key in ["triangle_id", "color"] {
        let hex = doc["hashes"][key].as_str().expect("hex string");
        assert!(
            hex.len() == 16 && hex.chars().all(|c| c.is_ascii_hexdigit()),
            "{hex}"
        );
    }
}

/// The AVX2 coverage kernels (this machine's) and the portable ones
/// (`CONTINUUM_SIMD=portable`) give bitwise the same buffers and the same
/// counts, for the rasterizers, the frustum traversal and the ray caster, with
/// and without anti-aliasing, effects included.
#[test]
fn the_avx2_and_portable_kernels_render_the_same_buffers() {
    #[cfg(target_arch = "x86_64")]
    assert!(
        continuum::internal::cpu_has_avx2(),
        "this test compares the AVX2 kernels with the portable ones, and this CPU has no AVX2"
    );
    let render = |scene: &str, algorithm: &str, aa: &str, simd: &str| {
        let args = [
            "render",
            "--scene",
            scene,
            "--algorithm",
            algorithm,
            "--aa",
            aa,
            "--size",
            "96x72",
            "--json",
        ];
        let out = continuum_with(&args, &[("CONTINUUM_SIMD", simd)]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let doc: serde_json::Value =
            serde_json::from_slice(&out.stdout).expect("one JSON document");
        let counts = [
            "edge_evaluations",
            "triangle_setups",
            "bvh_nodes_visited",
            "coverage_histogram",
        ]
        .map(|k| doc["stats"][k].clone());
        (doc["hashes"].clone(), counts)
    };
    for scene in ["bunny", "pane"] {
        for algorithm in [
            "2dr-homogeneous",
            "3dr-brute",
            "3dr-bin",
            "3dr-full",
            "raycast",
        ] {
            for aa in ["none", "csaa:8x4"] {
                let avx2 = render(scene, algorithm, aa, "avx2");
                let portable = render(scene, algorithm, aa, "portable");
                assert_eq!(avx2, portable, "{scene} {algorithm} {aa}");
            }
        }
    }
}

#[test]
fn render_takes_every_viewport() {
    // The orthographic rays start inside the sphere too: the image is 1 × 0.5 units.
    for viewport in ["perspective:40", "orthographic:0.5", "parabolic", "latlong"] {
        let out = continuum(&[
            "render",
            "--scene",
            "sphere",
            "--camera",
            "inside",
            "--algorithm",
            "3dr-bin",
            "--viewport",
            viewport,
            "--size",
            "64x32",
            "--json",
        ]);
        assert!(
            out.status.success(),
            "{viewport}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let doc: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
        assert_eq!(doc["viewport"], viewport);
        // Inside the closed sphere every sample with a ray is covered once.
        assert!(doc["stats"]["coverage_histogram"]["one"].as_u64() > Some(700));
        assert_eq!(doc["stats"]["coverage_histogram"]["many"], 0, "{viewport}");
    }
}

#[test]
fn render_writes_the_image_and_maps() {
    let dir = out_dir("maps");
    let png = dir.join("bunny.png");
    let maps = dir.join("maps");
    let out = continuum(&[
        "render",
        "--scene",
        "bunny",
        "--algorithm",
        "raycast",
        "--camera",
        "front",
        "--size",
        "96x72",
        "--out",
        png.to_str().expect("utf-8"),
        "--maps",
        maps.to_str().expect("utf-8"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for file in [
        png,
        maps.join("edge_evals.png"),
        maps.join("depth.png"),
        maps.join("triangle_id.png"),
    ] {
        let bytes = std::fs::read(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        assert_eq!(&bytes[1..4], b"PNG", "{}", file.display());
    }
}

#[test]
fn scenes_load_by_path_too() {
    let glb = scenes().join("assets/Box.glb");
    let out = continuum(&[
        "render",
        "--scene",
        glb.to_str().expect("utf-8"),
        "--algorithm",
        "2dr-brute",
        "--size",
        "32x32",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn bad_arguments_exit_2_naming_the_argument() {
    let cases: &[(&[&str], &str)] = &[
        (
            &["render", "--scene", "box", "--algorithm", "zbuffer"],
            "--algorithm",
        ),
        (
            &[
                "render",
                "--scene",
                "box",
                "--algorithm",
                "raycast",
                "--size",
                "0x10",
            ],
            "--size",
        ),
        (
            &["render", "--scene", "nosuch", "--algorithm", "raycast"],
            "--scene",
        ),
        (
            &[
                "render",
                "--scene",
                "box",
                "--algorithm",
                "raycast",
                "--camera",
                "nosuch",
            ],
            "--camera",
        ),
        (
            &[
                "render",
                "--scene",
                "/nonexistent/x.glb",
                "--algorithm",
                "raycast",
            ],
            "--scene",
        ),
        (&["render", "--algorithm", "raycast"], "--scene"),
        (
            &[
                "render",
                "--scene",
                "box",
                "--algorithm",
                "raycast",
                "--overlay",
                "frusta,heat",
            ],
            "--overlay",
        ),
        (
            &[
                "render",
                "--scene",
                "box",
                "--algorithm",
                "raycast",
                "--viewport",
                "fisheye",
            ],
            "--viewport",
        ),
        (
            &[
                "render",
                "--scene",
                "box",
                "--algorithm",
                "2dr-bin",
                "--viewport",
                "parabolic",
            ],
            "--viewport",
        ),
        (
            &[
                "render",
                "--scene",
                "box",
                "--algorithm",
                "raycast",
                "--aa",
                "msaa:3",
            ],
            "--aa",
        ),
    ];
    for (args, named) in cases {
        let out = continuum(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(
            stderr.contains(named),
            "{args:?} should name {named}: {stderr}"
        );
    }
}

/// The `results.json` a compare run wrote into `dir`.
fn results_json(dir: &std::path::Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(dir.join("results.json")).expect("results.json"))
        .expect("JSON")
}

#[test]
fn compare_writes_results_with_the_documented_keys() {
    let dir = out_dir("compare");
    let out = continuum(&[
        "compare",
        "--scenes",
        "box,sphere",
        "--algorithms",
        "2dr-brute,3dr-brute,3dr-full,raycast,peer-obvhs",
        "--size",
        "64x48",
        "--repeat",
        "2",
        "--threads",
        "2",
        "--out",
        dir.to_str().expect("utf-8"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc = results_json(&dir);
    assert!(doc["machine"].is_object() && doc["command"].is_string());
    let rows = doc["rows"].as_array().expect("rows");
    assert_eq!(rows.len(), 10);
    for row in rows {
        for key in [
            "scene",
            "algorithm",
            "viewport",
            "aa",
            "width",
            "height",
            "threads",
            "median_ms",
            "min_ms",
            "max_ms",
            "ratio_to_2dr_brute",
            "predicted_ratio",
            "rays_per_second",
            "stats",
            "hashes",
            "agrees",
            "scene_triangles",
        ] {
            assert!(row.get(key).is_some(), "missing {key}: {row}");
        }
        // The built-in box has 12 triangles, the sphere 20,480 (README).
        let triangles = match row["scene"].as_str() {
            Some("box") => 12,
            Some("sphere") => 20_480,
            _ => panic!("a scene of the run: {row}"),
        };
        assert_eq!(row["scene_triangles"], triangles, "{row}");
        if row["algorithm"] != "peer-obvhs" {
            assert_eq!(row["agrees"], true, "{row}");
        }
        // Visibility alone: the whole render for a peer (it shades nothing),
        // no more than the whole render for ours.
        let (visibility, median) = (row["visibility_ms"].as_f64(), row["median_ms"].as_f64());
        let (visibility, median) = (
            visibility.expect("visibility_ms"),
            median.expect("median_ms"),
        );
        if row["algorithm"] == "peer-obvhs" {
            assert_eq!(visibility, median, "{row}");
        } else {
            assert!(visibility > 0.0 && visibility <= median, "{row}");
            // The stages are disjoint spans of the render: together no more
            // than its total; each row carries their medians.
            let t = &row["stats"]["time_ms"];
            let stages = [
                "setup",
                "traversal",
                "coverage",
                "resolve",
                "shading",
                "store",
            ];
            let sum: f64 = stages.iter().map(|s| t[s].as_f64().expect(s)).sum();
            let total = t["total"].as_f64().expect("total");
            assert!(sum > 0.0 && sum <= total * (1.0 + 1e-9), "{row}");
            assert!(row["stage_ms"]["shading"].as_f64().expect("stage_ms") > 0.0);
        }
    }
    let csv = std::fs::read_to_string(dir.join("results.csv")).expect("results.csv");
    assert_eq!(csv.lines().count(), 11);
    let header = csv.lines().next().expect("a header");
    assert!(header.ends_with(",scene_triangles"), "{header}");
    assert!(
        csv.lines()
            .skip(1)
            .all(|l| l.ends_with(",12") || l.ends_with(",20480")),
        "{csv}"
    );
}

#[test]
fn compare_measures_anti_aliasing_against_the_reference() {
    let dir = out_dir("compare-aa");
    let out = continuum(&[
        "compare",
        "--scenes",
        "box",
        "--algorithms",
        "3dr-bin,raycast,peer-obvhs",
        "--aa",
        "none,msaa:4,csaa:8x2",
        "--size",
        "48x32",
        "--repeat",
        "1",
        "--out",
        dir.to_str().expect("utf-8"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc = results_json(&dir);
    let rows = doc["rows"].as_array().expect("rows");
    // The peer renders one sample per pixel: measured for `none` only.
    assert_eq!(rows.len(), 2 * 3 + 1);
    for row in rows {
        let aa = row["aa"].as_str().expect("aa");
        assert!(
            row["coverage_samples"].as_u64().expect("count") >= 48 * 32,
            "{row}"
        );
        // Peers give triangle ids, not images: no error to measure.
        if row["algorithm"] != "peer-obvhs" {
            assert!(row["flip_mean"].as_f64().is_some(), "{row}");
            assert!(row["psnr"].as_f64().is_some(), "{row}");
            assert_eq!(row["agrees"], true, "{row}");
            assert!(row["ratio_to_aa_none"].as_f64().is_some(), "{row}");
            assert!(row["shading_samples"].as_u64().expect("count") > 0, "{row}");
        }
        if aa == "msaa:4" {
            assert_eq!(row["stats"]["samples_per_pixel"], 4, "{row}");
        }
    }
    // Anti-aliasing brings the image closer to the reference.
    let flip = |aa: &str| {
        rows.iter()
            .find(|r| r["algorithm"] == "3dr-bin" && r["aa"] == aa)
            .and_then(|r| r["flip_mean"].as_f64())
            .expect("row")
    };
    assert!(
        flip("msaa:4") < flip("none"),
        "{} {}",
        flip("msaa:4"),
        flip("none")
    );
    let svg = std::fs::read_to_string(dir.join("aa_cost.svg")).expect("aa_cost.svg");
    assert!(svg.contains("<svg") && svg.contains("msaa:4"), "{svg}");
    // One point per row with an image error, each named in its tooltip.
    let measured: Vec<(f64, f64)> = rows
        .iter()
        .filter_map(|r| Some((r["median_ms"].as_f64()?, r["flip_mean"].as_f64()?)))
        .collect();
    assert_eq!(measured.len(), 2 * 3);
    assert_eq!(svg.matches("</title></circle>").count(), measured.len());
    // The Pareto front is drawn as a line when it holds more than one point:
    // when some point is more accurate than the fastest. At 48x32 and one
    // repeat which point is fastest is the machine's noise, so the test
    // derives the expectation from the measured times, not a fixed answer.
    let fastest = measured
        .iter()
        .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)))
        .expect("a point");
    let front_is_a_line = measured.iter().any(|p| p.1 < fastest.1);
    assert_eq!(svg.contains("<polyline"), front_is_a_line, "{svg}");
    let bad = continuum(&["compare", "--aa", "msaa:3", "--out", "/tmp/never"]);
    assert_eq!(bad.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&bad.stderr);
    assert!(
        stderr.contains("--aa") && stderr.contains("valid modes"),
        "{stderr}"
    );
}

/// `--threads 1,2`: every cell at each count, each row with its speed-up
/// over one thread, the report with the stage stacks and the thread table.
#[test]
fn compare_measures_each_thread_count() {
    let dir = out_dir("compare-threads");
    let out = continuum(&[
        "compare",
        "--scenes",
        "box",
        "--algorithms",
        "2dr-brute,3dr-full",
        "--size",
        "48x32",
        "--repeat",
        "1",
        "--threads",
        "2,1",
        "--out",
        dir.to_str().expect("utf-8"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc = results_json(&dir);
    let rows = doc["rows"].as_array().expect("rows");
    let threads: Vec<u64> = rows
        .iter()
        .map(|r| r["threads"].as_u64().expect("threads"))
        .collect();
    assert_eq!(threads, [1, 1, 2, 2], "each count in turn, smallest first");
    for row in rows {
        let speedup = row["speedup"].as_f64().expect("speedup");
        assert!(speedup > 0.0, "{row}");
        if row["threads"] == 1 {
            assert_eq!(speedup, 1.0, "{row}");
        }
        assert!(row["ratio_to_2dr_brute"].as_f64().is_some(), "{row}");
    }
    assert_eq!(doc["machine"]["threads"], serde_json::json!([1, 2]));
    let html = std::fs::read_to_string(dir.join("report.html")).expect("report.html");
    assert!(html.contains("id=\"stages\"") && html.contains("id=\"threads\""));
    // 3dr-full walks the BVH: its counters in the report and the CSV.
    assert!(html.contains("id=\"traversal\""));
    let csv = std::fs::read_to_string(dir.join("results.csv")).expect("results.csv");
    let mut lines = csv.lines().map(|l| l.split(',').collect::<Vec<_>>());
    let header = lines.next().expect("a header");
    let column = |name: &str| header.iter().position(|h| *h == name).expect(name);
    let (visited, outside) = (column("bvh_nodes_visited"), column("nodes_culled_outside"));
    let reused = column("leaf_setups_reused");
    let full: Vec<_> = lines.filter(|l| l[1] == "3dr-full").collect();
    assert_eq!(full.len(), 2, "{csv}");
    for l in full {
        let n = |i: usize| l[i].parse::<u64>().expect("a count");
        assert!(n(visited) > 0 && n(outside) <= n(visited), "{l:?}");
        // The box's faces span many of the 8x8 frusta: set up once each.
        assert!(n(reused) > 0, "{l:?}");
    }
    let bad = continuum(&["compare", "--threads", "0,2", "--out", "/tmp/never"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--threads"));
}

/// `--oracles` adds, for each setting, a row beside every algorithm it
/// changes (and none beside those it does not), renders the same image, and
/// the table ends with the fastest setting of each algorithm.
#[test]
fn compare_measures_oracle_settings_beside_the_algorithms_own() {
    let dir = out_dir("compare-oracles");
    // The box: triangles large enough for tiles and early-z to matter.
    let out = continuum(&[
        "compare",
        "--scenes",
        "box",
        "--algorithms",
        "2dr-brute,3dr-bin,3dr-full",
        "--oracles",
        "frustum=64,split=16;early_z=off",
        "--size",
        "128x96",
        "--repeat",
        "1",
        "--threads",
        "2",
        "--out",
        dir.to_str().expect("utf-8"),
    ]);
    let stdout = succeeded(&out);
    let doc = results_json(&dir);
    let rows = doc["rows"].as_array().expect("rows");
    let names: Vec<&str> = rows
        .iter()
        .map(|r| r["algorithm"].as_str().expect("algorithm"))
        .collect();
    // 2dr-brute takes no traversal keys and has early-z off already: no rows.
    assert_eq!(
        names,
        [
            "2dr-brute",
            "3dr-bin",
            "3dr-full",
            "3dr-full[split=16,frustum=64]",
            "3dr-bin[early_z=off]",
            "3dr-full[early_z=off]",
        ]
    );
    // Every row of the 3D family (all but 2dr-brute) renders 3dr-bin's ids.
    let hash = |r: &serde_json::Value| r["hashes"]["triangle_id"].clone();
    for row in rows {
        if row["algorithm"] != "2dr-brute" {
            assert_eq!(hash(row), hash(&rows[1]), "{row}");
        }
        assert_eq!(row["agrees"], true, "{row}");
        let tuned = row["algorithm"].as_str().expect("algorithm").contains('[');
        assert_eq!(row.get("oracles").is_some(), tuned, "{row}");
    }
    // The settings change the work done: each tuned row against its own.
    let counters = |i: usize| {
        [
            "edge_evaluations",
            "tiles_tested",
            "early_z_rejects",
            "bvh_nodes_visited",
            "frusta_split",
        ]
        .map(|k| rows[i]["stats"][k].as_u64().expect(k))
    };
    for (own, tuned) in [(2, 3), (1, 4), (2, 5)] {
        assert_ne!(
            counters(own),
            counters(tuned),
            "{} and {}",
            names[own],
            names[tuned]
        );
    }
    let best: Vec<&str> = stdout
        .lines()
        .skip_while(|l| !l.starts_with("fastest oracles"))
        .skip(1)
        .take_while(|l| !l.is_empty())
        .collect();
    assert_eq!(best.len(), 2, "{stdout}");
    assert!(best[0].contains(": 3dr-bin -> 3dr-bin") && best[1].contains(": 3dr-full -> 3dr-full"));
    let csv = std::fs::read_to_string(dir.join("results.csv")).expect("results.csv");
    assert_eq!(csv.lines().count(), 7, "{csv}");
    assert!(
        csv.contains("\nbox,\"3dr-full[split=16,frustum=64]\","),
        "{csv}"
    );

    for (oracles, algorithms, says) in [
        ("split=16", "2dr-brute", "changes none"),
        ("bogus=1", "3dr-full", "unknown oracle"),
        (
            "final_depth=on,occluded=off",
            "3dr-full",
            "needs occluded=on",
        ),
    ] {
        let bad = continuum(&[
            "compare",
            "--algorithms",
            algorithms,
            "--oracles",
            oracles,
            "--out",
            "/tmp/never",
        ]);
        assert_eq!(bad.status.code(), Some(2));
        let stderr = String::from_utf8_lossy(&bad.stderr);
        assert!(
            stderr.contains("--oracles") && stderr.contains(says),
            "{stderr}"
        );
    }
}

#[test]
fn compare_refuses_unknown_algorithms() {
    let out = continuum(&["compare", "--algorithms", "zbuffer", "--out", "/tmp/never"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--algorithms"));
}

/// With the `embree` feature, Embree 3 runs beside us (single rays and streams).
#[cfg(feature = "embree")]
#[test]
fn compare_runs_the_embree_peers() {
    let dir = out_dir("embree");
    let out = continuum(&[
        "compare",
        "--scenes",
        "sphere",
        "--algorithms",
        "3dr-brute,peer-embree,peer-embree-stream",
        "--size",
        "64x48",
        "--repeat",
        "1",
        "--out",
        dir.to_str().expect("utf-8"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc = results_json(&dir);
    for row in &doc["rows"].as_array().expect("rows")[1..] {
        // Embree is not watertight, but on a closed sphere it should miss very little.
        let differing = row["pixels_differing_from_3dr_brute"]
            .as_u64()
            .expect("count");
        assert!(differing < 64 * 48 / 100, "{row}");
        assert!(row["rays_per_second"].as_f64().expect("rate") > 0.0);
    }
}

#[cfg(not(feature = "embree"))]
#[test]
fn embree_peers_need_the_feature() {
    let out = continuum(&[
        "compare",
        "--algorithms",
        "peer-embree",
        "--out",
        "/tmp/never",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("embree"));
}

fn hard_cases() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/hard_cases")
}

#[test]
fn hardcases_prints_the_table_and_exits_by_the_invariants() {
    let dir = hard_cases();
    let dir = dir.to_str().expect("utf-8 path");
    // One case through everything: the table, and success.
    let out = continuum(&["hardcases", "--cases", dir, "--only", "fans"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        table.contains("fans") && table.contains("gpu-raster"),
        "{table}"
    );
    // The JSON report: a table row per case and a checked render per variant.
    let out = continuum(&[
        "hardcases",
        "--cases",
        dir,
        "--only",
        "degenerate",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert_eq!(doc["passed"], true);
    assert_eq!(doc["table"][0]["case"], "degenerate");
    assert!(doc["checks"].as_array().is_some_and(|c| c.len() > 100));
    // An unknown case is a usage error naming the flag.
    let out = continuum(&["hardcases", "--cases", dir, "--only", "nosuch"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--only"));
    // A case that breaks an invariant exits with status 1: huge-triangles
    // without its documented limit (the GPU driver clips in f32).
    let bad = out_dir("hardcases");
    let text = std::fs::read_to_string(hard_cases().join("huge-triangles.toml")).expect("case");
    let (head, rest) = text.split_once("[limits]").expect("the case has limits");
    let rest = rest.split_once("\n\n").expect("limits table ends").1;
    std::fs::write(bad.join("huge.toml"), format!("{head}{rest}")).expect("write case");
    let out = continuum(&["hardcases", "--cases", bad.to_str().expect("utf-8")]);
    assert_eq!(
        out.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    std::fs::remove_dir_all(&bad).ok();
}

/// A row of results.json without what timing decides (times, their ratios,
/// rays per second, stage times), as text, for comparing runs.
fn untimed(row: &serde_json::Value) -> String {
    let mut row = row.clone();
    let map = row.as_object_mut().expect("row is an object");
    for key in [
        "median_ms",
        "min_ms",
        "max_ms",
        "visibility_ms",
        "rays_per_second",
        "ratio_to_2dr_brute",
        "ratio_to_aa_none",
        "ratio_to_f32",
        "stage_ms",
        "speedup",
    ] {
        map.remove(key);
    }
    if let Some(stats) = map.get_mut("stats").and_then(|s| s.as_object_mut()) {
        stats.remove("time_ms");
        stats.remove("bvh_build_ms");
    }
    row.to_string()
}

fn rows_of(dir: &std::path::Path) -> Vec<String> {
    let mut rows: Vec<String> = results_json(dir)["rows"]
        .as_array()
        .expect("rows")
        .iter()
        .map(untimed)
        .collect();
    rows.sort();
    rows
}

#[test]
fn sharded_sweeps_merge_into_the_unsharded_results_and_report() {
    let base = out_dir("sweep");
    let sweep = base.join("sweep.toml");
    std::fs::write(
        &sweep,
        "scenes = [\"box\", \"sphere\"]\nalgorithms = [\"2dr-brute\", \"2dr-bin\", \"3dr-brute\", \"raycast\", \"peer-obvhs\"]\n\
         viewports = [\"camera\", \"orthographic\"]\naa = [\"none\", \"msaa:4\"]\nprecision = [\"f32\", \"f64\"]\n\
         size = \"48x32\"\nrepeat = 1\nthreads = 2\n",
    )
    .expect("sweep file");
    let run = |args: &[&str]| {
        let out = continuum(args);
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    let s = sweep.to_str().expect("utf-8");
    let whole = base.join("whole");
    run(&[
        "compare",
        "--sweep",
        s,
        "--out",
        whole.to_str().expect("utf-8"),
    ]);
    let mut parts = Vec::new();
    for i in 0..3 {
        let dir = base.join(format!("shard-{i}"));
        let shard = format!("{i}/3");
        run(&[
            "compare",
            "--sweep",
            s,
            "--shard",
            &shard,
            "--out",
            dir.to_str().expect("utf-8"),
        ]);
        parts.push(dir);
    }
    // Shards are disjoint and none is empty.
    let counts: Vec<usize> = parts.iter().map(|d| rows_of(d).len()).collect();
    assert!(counts.iter().all(|&n| n > 0), "{counts:?}");
    let merged = base.join("merged");
    let mut args = vec!["compare", "merge", "--out", merged.to_str().expect("utf-8")];
    args.extend(parts.iter().map(|p| p.to_str().expect("utf-8")));
    run(&args);
    assert_eq!(counts.iter().sum::<usize>(), rows_of(&whole).len());
    assert_eq!(rows_of(&merged), rows_of(&whole));
    // The report names every scene and algorithm, and embeds its maps.
    let html = std::fs::read_to_string(merged.join("report.html")).expect("report.html");
    for name in [
        "box",
        "sphere",
        "2dr-brute",
        "2dr-bin",
        "3dr-brute",
        "raycast",
        "peer-obvhs",
    ] {
        assert!(html.contains(name), "report lacks {name}");
    }
    assert!(html.contains("data:image/png;base64,") && html.contains("<svg"));
    // Self-contained: nothing to fetch but the SVG namespace name.
    assert!(!html.contains("src=\"http") && !html.contains("href=\"http"));
    // A merge missing a shard says which.
    let out = continuum(&[
        "compare",
        "merge",
        "--out",
        base.join("partial").to_str().expect("utf-8"),
        parts[0].to_str().expect("utf-8"),
        parts[2].to_str().expect("utf-8"),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("[1]"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::remove_dir_all(&base).ok();
}

#[test]
fn a_bad_sweep_file_is_an_error_naming_the_key() {
    let base = out_dir("bad-sweep");
    for (text, key) in [
        (
            "scenes = [\"box\"]\nalgoritms = [\"raycast\"]\n",
            "algoritms",
        ),
        ("scenes = [\"box\"]\naa = [\"msaa:3\"]\n", "aa"),
        ("scenes = [\"box\"]\nprecision = [\"f16\"]\n", "precision"),
        (
            "scenes = [\"box\"]\nviewports = [\"fisheye\"]\n",
            "viewports",
        ),
        ("scenes = [\"box\"]\nsize = \"0x4\"\n", "size"),
        ("scenes = [\"box\"]\nrepeat = 0\n", "repeat"),
    ] {
        let path = base.join("sweep.toml");
        std::fs::write(&path, text).expect("sweep file");
        let out = continuum(&[
            "compare",
            "--sweep",
            path.to_str().expect("utf-8"),
            "--out",
            base.to_str().expect("utf-8"),
        ]);
        assert_eq!(out.status.code(), Some(2), "{text}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains(key) && err.contains("--sweep"),
            "{text}: {err}"
        );
    }
    let out = continuum(&[
        "compare",
        "--sweep",
        "/nonexistent/sweep.toml",
        "--out",
        "/tmp/never",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let out = continuum(&[
        "compare",
        "--scenes",
        "box",
        "--shard",
        "3/3",
        "--out",
        "/tmp/never",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--shard"));
    std::fs::remove_dir_all(&base).ok();
}

/// No Vulkan driver for the process: the loader finds no ICD.
const WITHOUT_VULKAN: [(&str, &str); 2] = [
    ("VK_ICD_FILENAMES", "/nonexistent/icd.json"),
    ("VK_DRIVER_FILES", "/nonexistent/icd.json"),
];

/// The standard output of a run that must succeed (its stderr otherwise).
fn succeeded(out: &Output) -> String {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn no_panic(out: &Output) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(!stderr.contains("panicked"), "a panic: {stderr}");
    stderr
}

#[test]
fn the_gl_backend_forced_is_a_named_error_not_a_panic() {
    // wgpu's OpenGL backend (switched on in workspace builds by the viewer's
    // test renderer) cannot render gpu-raster's formats on Mesa: refused by name.
    for env in [&[("WGPU_BACKEND", "gl")][..], &WITHOUT_VULKAN[..]] {
        let out = continuum_with(
            &[
                "render",
                "--scene",
                "box",
                "--algorithm",
                "gpu-raster",
                "--size",
                "16x16",
            ],
            env,
        );
        let stderr = no_panic(&out);
        assert_eq!(out.status.code(), Some(2), "{env:?}: {stderr}");
        assert!(
            stderr.contains("--algorithm") && stderr.contains("no Vulkan device"),
            "{env:?}: {stderr}"
        );
    }
}

#[test]
fn compare_without_vulkan_leaves_gpu_raster_out_unless_named() {
    let dir = out_dir("no-vulkan");
    let args = [
        "compare", "--scenes", "box", "--size", "16x16", "--repeat", "1", "--out",
    ];
    let out = continuum_with(
        &[&args[..], &[dir.to_str().expect("utf-8")]].concat(),
        &WITHOUT_VULKAN,
    );
    let stderr = no_panic(&out);
    assert!(out.status.success(), "{stderr}");
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.contains("not run: gpu-raster"), "{table}");
    let doc = results_json(&dir);
    assert_eq!(
        doc["not_run"][0]["algorithm"], "gpu-raster",
        "{}",
        doc["not_run"]
    );
    let rows = doc["rows"].as_array().expect("rows");
    assert!(rows.iter().all(|r| r["algorithm"] != "gpu-raster"));
    assert_eq!(
        rows.iter()
            .filter(|r| !r["algorithm"]
                .as_str()
                .is_some_and(|a| a.starts_with("peer-")))
            .count(),
        continuum::AlgorithmId::ALL.len() - continuum::AlgorithmId::GPU.len()
    );
    let not_run: Vec<&str> = doc["not_run"]
        .as_array()
        .expect("not_run")
        .iter()
        .filter_map(|n| n["algorithm"].as_str())
        .collect();
    assert_eq!(
        not_run,
        continuum::AlgorithmId::GPU.map(|a| a.as_str()),
        "every GPU algorithm is left out"
    );
    let report = std::fs::read_to_string(dir.join("report.html")).expect("report");
    assert!(report.contains("Not run on this machine") && report.contains("gpu-raster"));
    std::fs::remove_dir_all(&dir).ok();
    // Named, it fails before writing anything.
    let named = out_dir("no-vulkan-named").join("results");
    let out = continuum_with(
        &[
            &args[..],
            &[named.to_str().expect("utf-8"), "--algorithms", "gpu-raster"],
        ]
        .concat(),
        &WITHOUT_VULKAN,
    );
    let stderr = no_panic(&out);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("gpu-raster") && stderr.contains("cannot run"),
        "{stderr}"
    );
    assert!(!named.exists(), "a failed compare left {}", named.display());
    // hardcases likewise, and says so.
    let cases = hard_cases();
    let out = continuum_with(
        &[
            "hardcases",
            "--cases",
            cases.to_str().expect("utf-8"),
            "--only",
            "fans",
        ],
        &WITHOUT_VULKAN,
    );
    let stderr = no_panic(&out);
    assert!(out.status.success(), "{stderr}");
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        table.contains("not run on this machine: gpu-raster"),
        "{table}"
    );
}

/// The `continuum` command lines of README.md's code blocks (continuation
/// lines joined), as words.
fn readme_commands() -> Vec<Vec<String>> {
    let readme =
        std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../README.md"))
            .expect("README.md");
    let mut commands = Vec::new();
    let mut in_code = false;
    let mut joined = String::new();
    for line in readme.lines() {
        if line.trim_start().starts_with("```") {
            in_code = !in_code;
            continue;
        }
        if !in_code {
            continue;
        }
        let line = line.split(" #").next().unwrap_or("").trim_end();
        joined.push_str(line.trim_end_matches('\\'));
        joined.push(' ');
        if line.ends_with('\\') {
            continue;
        }
        let words = shell_words(&joined);
        joined.clear();
        let start = if words.starts_with(&[
            "cargo".into(),
            "run".into(),
            "--release".into(),
            "--".into(),
        ]) {
            4
        } else if words.first().is_some_and(|w| w == "continuum") {
            1
        } else {
            continue;
        };
        commands.push(words[start..].to_vec());
    }
    commands
}

/// Splits a command line into words: whitespace outside quotes separates.
fn shell_words(line: &str) -> Vec<String> {
    let mut words = Vec::new();
    let mut word = String::new();
    let mut quote = None;
    let mut any = false;
    for c in line.chars() {
        match (quote, c) {
            (None, '\'' | '"') => {
                quote = Some(c);
                any = true;
            }
            (Some(q), c) if c == q => quote = None,
            (None, c) if c.is_whitespace() => {
                if any {
                    words.push(std::mem::take(&mut word));
                    any = false;
                }
            }
            (_, c) => {
                word.push(c);
                any = true;
            }
        }
    }
    if any {
        words.push(word);
    }
    words
}

#[test]
fn the_readme_command_lines_use_flags_the_cli_has() {
    let commands = readme_commands();
    assert!(
        commands.len() >= 6,
        "found only {} command lines in README.md",
        commands.len()
    );
    let mut checked = 0;
    for words in &commands {
        // The subcommand path (`compare merge`), then its flags.
        let path: Vec<&str> = words
            .iter()
            .map(String::as_str)
            .take_while(|w| !w.starts_with('-'))
            .filter(|w| ["serve", "render", "compare", "merge", "hardcases"].contains(w))
            .collect();
        let out = continuum(&[&path[..], &["--help"]].concat());
        assert!(out.status.success(), "{path:?} --help");
        let help = String::from_utf8_lossy(&out.stdout);
        for flag in words.iter().filter(|w| w.starts_with("--")) {
            let flag = flag.split('=').next().unwrap_or(flag);
            assert!(
                help.contains(&format!("{flag} ")) || help.contains(&format!("{flag}\n")),
                "README: `continuum {}` uses {flag}, which `{} --help` does not list",
                words.join(" "),
                path.join(" ")
            );
            checked += 1;
        }
    }
    assert!(checked >= 20, "only {checked} flags checked");
}

#[test]
fn help_lists_every_value_and_marks_required_flags() {
    let out = continuum(&["render", "--help"]);
    let help = String::from_utf8_lossy(&out.stdout);
    for a in continuum::AlgorithmId::ALL {
        assert!(help.contains(a.as_str()), "render --help omits {a}: {help}");
    }
    for m in continuum::AaMode::all() {
        assert!(help.contains(&m.to_string()), "render --help omits aa {m}");
    }
    assert!(
        help.contains("--scene <SCENE>") && !help.contains("[SCENE]"),
        "{help}"
    );
    let out = continuum(&["compare", "--help"]);
    let help = String::from_utf8_lossy(&out.stdout);
    assert!(help.contains("--out <OUT>"), "{help}");
    assert!(
        help.contains("gpu-raster") && help.contains("peer-obvhs"),
        "{help}"
    );
    // Required: the usage line names it outside brackets.
    let usage = help
        .lines()
        .find(|l| l.starts_with("Usage:"))
        .expect("usage line");
    assert!(
        usage.contains("--out <OUT>") && !usage.contains("[--out"),
        "{usage}"
    );
}

/// The paper's §5 experiment (`docker/gpu-sect5.toml`) at a small size: the
/// compute kernels side by side with the depth test off and on, every one
/// agreeing with its reference (`3dr-brute` with the depth test, `gpu-3dr`
/// without), and the §5 table printed and in the report.
#[test]
fn the_section_5_sweep_sets_the_gpu_kernels_side_by_side_in_agreement() {
    let base = out_dir("sect5");
    let repo = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let paper =
        std::fs::read_to_string(repo.join("docker/gpu-sect5.toml")).expect("gpu-sect5.toml");
    let sweep: toml::Table = toml::from_str(&paper).expect("gpu-sect5.toml parses");
    let scenes: Vec<String> = sweep["scenes"]
        .as_array()
        .expect("scenes")
        .iter()
        .map(|s| {
            repo.join(s.as_str().expect("scene path"))
                .display()
                .to_string()
        })
        .collect();
    let algorithms = &sweep["algorithms"];
    let small = format!(
        "scenes = {scenes:?}\nalgorithms = {algorithms}\nsize = \"160x100\"\nrepeat = 1\ndepth_test = [false, true]\n"
    );
    let file = base.join("sect5.toml");
    std::fs::write(&file, small).expect("sweep file");
    let dir = base.join("out");
    let out = continuum(&[
        "compare",
        "--sweep",
        file.to_str().expect("utf-8"),
        "--out",
        dir.to_str().expect("utf-8"),
    ]);
    let stdout = succeeded(&out);
    let results = results_json(&dir);
    let rows = results["rows"].as_array().expect("rows");
    let kernels = [
        "gpu-2dr",
        "gpu-2dr-homogeneous",
        "gpu-3dr",
        "gpu-3dr-binned",
    ];
    let mut checked = 0;
    for r in rows {
        let algorithm = r["algorithm"].as_str().expect("algorithm");
        if kernels.contains(&algorithm) {
            assert_eq!(
                r["agrees"], true,
                "{algorithm} depth_test {}: {r}",
                r["depth_test"]
            );
            checked += 1;
        }
    }
    // Two scenes, the depth test off and on; gpu-raster (on only) and
    // 3dr-brute (on only) beside the four kernels.
    assert_eq!(checked, 2 * 2 * kernels.len(), "kernel rows");
    assert_eq!(rows.len(), 2 * (kernels.len() * 2 + 2), "rows");
    let title = stdout
        .find("GPU shaders side by side")
        .expect("the section 5 table");
    // One line per scene and depth test setting.
    let table = stdout[title..].lines().filter(|l| l.contains("160x100"));
    assert_eq!(table.count(), 4, "{stdout}");
    let html = std::fs::read_to_string(dir.join("report.html")).expect("report.html");
    assert!(
        html.contains("id=\"sect5\""),
        "report lacks the section 5 table"
    );
    std::fs::remove_dir_all(&base).ok();
}
