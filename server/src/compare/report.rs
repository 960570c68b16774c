//! `report.html`: one self-contained page (inline SVG plots and base64
//! thumbnails, no scripts or fonts to fetch) from a comparison's rows: the
//! paper's Fig. 9 (time and predicted instructions relative to `2dr-brute`, per
//! scene), the edge-evaluation maps side by side (Fig. 1 right), accuracy
//! against time for anti-aliasing, the peers, agreement, every row, and the
//! machine and command that produced them.

use std::fmt::Write;
use std::path::Path;

use base64::Engine;
use serde_json::Value;

use super::Row;

const COLORS: [&str; 2] = ["#1f77b4", "#ff7f0e"];

/// The report for `rows` (thumbnails read relative to `maps_root`), with the
/// anti-aliasing chart when there is one; `doc` holds the machine, command,
/// sweep and shards.
pub fn report_html(doc: &Value, rows: &[Row], maps_root: &Path, aa_svg: Option<&str>) -> String {
    let mut h = String::new();
    let _ = write!(
        h,
        r#"<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>continuum comparison</title>
<style>
body {{ font-family: sans-serif; margin: 24px; color: #222; max-width: 1400px; }}
h1 {{ font-size: 22px; }} h2 {{ font-size: 18px; margin-top: 32px; border-bottom: 1px solid #ccc; }}
h3 {{ font-size: 15px; }}
table {{ border-collapse: collapse; font-size: 12px; }}
td, th {{ border: 1px solid #ddd; padding: 3px 6px; text-align: right; }}
th {{ background: #f4f4f4; }} td.l, th.l {{ text-align: left; }}
.bad {{ background: #fdd; }} .good {{ background: #dfd; }}
.maps {{ display: flex; flex-wrap: wrap; gap: 10px; }}
.maps figure {{ margin: 0; font-size: 11px; text-align: center; }}
.maps img {{ image-rendering: pixelated; border: 1px solid #ccc; }}
pre {{ background: #f7f7f7; padding: 8px; font-size: 11px; overflow-x: auto; }}
</style></head><body>
<h1>continuum comparison</h1>
<p>{} rows over {} scenes. Times are medians over repeats; ratios are to <code>2dr-brute</code> of the same scene, viewport and mode (the paper's Fig. 9).</p>
"#,
        rows.len(),
        distinct(rows.iter().map(|r| r.scene.as_str())).len()
    );
    if let Some(list) = doc["not_run"].as_array().filter(|l| !l.is_empty()) {
        h.push_str("<p><strong>Not run on this machine:</strong></p>\n<ul>\n");
        for n in list {
            let _ = writeln!(
                h,
                "<li><code>{}</code>: {}</li>",
                escape(n["algorithm"].as_str().unwrap_or("")),
                escape(n["reason"].as_str().unwrap_or(""))
            );
        }
        h.push_str("</ul>\n");
    }
    fig9(&mut h, rows);
    stages(&mut h, rows);
    threads(&mut h, rows);
    edge_maps(&mut h, rows, maps_root);
    if let Some(svg) = aa_svg {
        let _ = write!(
            h,
            "<h2 id=\"aa\">Anti-aliasing: accuracy against time</h2>\n<p>Mean FLIP against a <code>ssaa:256</code> reference, time on a log scale; dashed: the Pareto front.</p>\n{svg}\n"
        );
    }
    sect5(&mut h, rows);
    traversal(&mut h, rows);
    peers(&mut h, rows);
    agreement(&mut h, rows);
    all_rows(&mut h, rows);
    let _ = write!(
        h,
        "<h2 id=\"machine\">Machine, command, versions</h2>\n<pre>{}</pre>\n</body></html>\n",
        escape(&serde_json::to_string_pretty(&meta_without_rows(doc)).unwrap_or_default())
    );
    h
}

fn meta_without_rows(doc: &Value) -> Value {
    let mut meta = doc.clone();
    if let Some(map) = meta.as_object_mut() {
        map.remove("rows");
    }
    meta
}

fn distinct<'a>(items: impl Iterator<Item = &'a str>) -> Vec<&'a str> {
    let mut out: Vec<&str> = Vec::new();
    for i in items {
        if !out.contains(&i) {
            out.push(i);
        }
    }
    out
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("–".into(), |x| format!("{x:.digits$}"))
}

/// Rows of one group (scene, viewport, camera, mode and precision), in order.
fn groups(rows: &[Row]) -> Vec<Vec<&Row>> {
    let mut out: Vec<Vec<&Row>> = Vec::new();
    for r in rows {
        match out.iter_mut().find(|g| {
            let f = g[0];
            (
                &f.scene,
                &f.viewport,
                &f.camera,
                &f.aa,
                f.precision,
                f.threads,
                f.depth_test,
            ) == (
                &r.scene,
                &r.viewport,
                &r.camera,
                &r.aa,
                r.precision,
                r.threads,
                r.depth_test,
            )
        }) {
            Some(g) => g.push(r),
            None => out.push(vec![r]),
        }
    }
    out
}

/// Fig. 9: per scene, each algorithm's time (measured) and predicted
/// instructions relative to 2dr-brute, as horizontal bars around 1.
fn fig9(h: &mut String, rows: &[Row]) {
    let _ = writeln!(
        h,
        "<h2 id=\"fig9\">Time relative to 2dr-brute (paper Fig. 9)</h2>\n<p><span style=\"color:{}\">■</span> measured time ratio, <span style=\"color:{}\">■</span> predicted-instruction ratio from the paper's Fig. 10 costs. Below 1 is faster than 2dr-brute.</p>",
        COLORS[0], COLORS[1]
    );
    for group in groups(rows) {
        let bars: Vec<&&Row> = group
            .iter()
            .filter(|r| r.ratio_to_2dr_brute.is_some())
            .collect();
        if bars.is_empty() {
            continue;
        }
        let f = group[0];
        let _ = writeln!(
            h,
            "<h3>{} — {} {} {} {}×{}</h3>",
            escape(&f.scene),
            escape(&f.viewport),
            escape(&f.aa),
            f.precision,
            f.width,
            f.height
        );
        let max = bars
            .iter()
            .flat_map(|r| [r.ratio_to_2dr_brute, r.predicted_ratio])
            .flatten()
            .fold(1.0f64, f64::max)
            .min(20.0);
        let label_w = label_width(bars.iter().map(|r| r.algorithm.as_str()));
        let (plot_w, row_h) = (520.0, 26.0);
        let height = bars.len() as f64 * row_h + 30.0;
        let x = |v: f64| label_w + plot_w * (v.min(max) / max);
        let _ = writeln!(
            h,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{}" height="{height}" font-family="sans-serif" font-size="11">"#,
            label_w + plot_w + 120.0
        );
        for (k, r) in bars.iter().enumerate() {
            let y = 10.0 + k as f64 * row_h;
            let _ = writeln!(
                h,
                r#"<text x="{}" y="{}" text-anchor="end">{}</text>"#,
                label_w - 6.0,
                y + 14.0,
                escape(&r.algorithm)
            );
            for (j, v) in [r.ratio_to_2dr_brute, r.predicted_ratio]
                .into_iter()
                .enumerate()
            {
                let Some(v) = v else { continue };
                let yy = y + j as f64 * 10.0 + 2.0;
                let _ = writeln!(
                    h,
                    r#"<rect x="{label_w}" y="{yy}" width="{:.1}" height="9" fill="{}"><title>{}: {v:.3}</title></rect><text x="{:.1}" y="{:.1}">{v:.2}</text>"#,
                    (x(v) - label_w).max(0.5),
                    COLORS[j],
                    if j == 0 {
                        "time ratio"
                    } else {
                        "predicted ratio"
                    },
                    x(v) + 3.0,
                    yy + 8.0
                );
            }
        }
        let one = x(1.0);
        let _ = writeln!(
            h,
            r##"<line x1="{one:.1}" y1="4" x2="{one:.1}" y2="{:.1}" stroke="#444" stroke-dasharray="3,3"/><text x="{one:.1}" y="{:.1}" text-anchor="middle">1</text></svg>"##,
            height - 16.0,
            height - 4.0
        );
    }
}

/// The stages of a render, in the order they run, and their colours.
const STAGES: [(&str, &str); 6] = [
    ("setup", "#4e79a7"),
    ("traversal", "#59a14f"),
    ("coverage", "#76b7b2"),
    ("resolve", "#edc948"),
    ("shading", "#e15759"),
    ("store", "#9c755f"),
];

/// Fig. 9 split by stage: per group, each of continuum's algorithms as one
/// bar of its median stage times (ms), so a reader sees where its time goes;
/// the frame around the algorithm (resolve, shading, store) as a share.
fn stages(h: &mut String, rows: &[Row]) {
    let legend: String = STAGES
        .iter()
        .map(|(name, color)| format!("<span style=\"color:{color}\">■</span> {name} "))
        .collect();
    let _ = writeln!(
        h,
        "<h2 id=\"stages\">Where the time goes (Fig. 9 by stage)</h2>\n<p>Median milliseconds of each stage over the timed rounds; the rest of a bar to its total (view and shader setup) is left blank. {legend}</p>"
    );
    for group in groups(rows) {
        let bars: Vec<(&Row, continuum::StageTimes)> = group
            .iter()
            .filter_map(|r| Some((*r, r.stage_ms?)))
            .collect();
        if bars.is_empty() {
            continue;
        }
        let f = group[0];
        let _ = writeln!(
            h,
            "<h3>{} — {} {} {} {}×{}, threads: {}</h3>",
            escape(&f.scene),
            escape(&f.viewport),
            escape(&f.aa),
            f.precision,
            f.width,
            f.height,
            f.threads
        );
        let max = bars
            .iter()
            .map(|(_, t)| t.total)
            .fold(f64::MIN_POSITIVE, f64::max);
        let label_w = label_width(bars.iter().map(|(r, _)| r.algorithm.as_str()));
        let (plot_w, row_h) = (620.0, 18.0);
        let height = bars.len() as f64 * row_h + 12.0;
        let _ = writeln!(
            h,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{}" height="{height}" font-family="sans-serif" font-size="11">"#,
            label_w + plot_w + 150.0
        );
        for (k, (r, t)) in bars.iter().enumerate() {
            let y = 6.0 + k as f64 * row_h;
            let _ = writeln!(
                h,
                r#"<text x="{}" y="{}" text-anchor="end">{}</text>"#,
                label_w - 6.0,
                y + 11.0,
                escape(&r.algorithm)
            );
            let values = [
                t.setup,
                t.traversal,
                t.coverage,
                t.resolve,
                t.shading,
                t.store,
            ];
            let mut x = label_w;
            for ((name, color), ms) in STAGES.iter().zip(values) {
                let w = plot_w * ms.max(0.0) / max;
                let _ = writeln!(
                    h,
                    r#"<rect x="{x:.1}" y="{y}" width="{w:.1}" height="13" fill="{color}"><title>{name}: {ms:.2} ms</title></rect>"#
                );
                x += w;
            }
            let _ = writeln!(
                h,
                r#"<text x="{:.1}" y="{}">{:.1} ms, frame {:.0}%</text>"#,
                label_w + plot_w * t.total / max + 4.0,
                y + 11.0,
                t.total,
                100.0 * super::frame_share(t)
            );
        }
        h.push_str("</svg>\n");
    }
}

/// With several thread counts: each row's time and its speed-up over the
/// run's smallest count.
fn threads(h: &mut String, rows: &[Row]) {
    if rows.iter().all(|r| r.speedup.is_none()) {
        return;
    }
    h.push_str("<h2 id=\"threads\">Threads</h2>\n<p>Speed-up: the median time at the run's smallest thread count over the median at this count (same scene, viewport, mode, precision and algorithm).</p>\n<table><tr><th class=\"l\">scene</th><th class=\"l\">algorithm</th><th class=\"l\">aa</th><th>threads</th><th>median ms</th><th>speed-up</th></tr>\n");
    for r in rows.iter().filter(|r| r.speedup.is_some()) {
        let _ = writeln!(
            h,
            "<tr><td class=\"l\">{}</td><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{}</td><td>{:.2}</td><td>{}</td></tr>",
            escape(&r.scene),
            escape(&r.algorithm),
            escape(&r.aa),
            r.threads,
            r.median_ms,
            opt(r.speedup, 2)
        );
    }
    h.push_str("</table>\n");
}

/// Fig. 1 right: every algorithm's edge evaluations per pixel, side by side.
fn edge_maps(h: &mut String, rows: &[Row], maps_root: &Path) {
    let _ = writeln!(
        h,
        "<h2 id=\"maps\">Edge evaluations per pixel (paper Fig. 1 right)</h2>\n<p>Inferno scale, logarithmic: a pixel with n evaluations sits at ln(1+n)/ln(1+max), black = none; max is per image.</p>"
    );
    for group in groups(rows) {
        let with_maps: Vec<&&Row> = group.iter().filter(|r| r.map.is_some()).collect();
        if with_maps.is_empty() {
            continue;
        }
        let f = group[0];
        let _ = writeln!(
            h,
            "<h3>{} — {} {} {}</h3>\n<div class=\"maps\">",
            escape(&f.scene),
            escape(&f.viewport),
            escape(&f.aa),
            f.precision
        );
        for r in with_maps {
            let Some(map) = &r.map else { continue };
            let Ok(bytes) = std::fs::read(maps_root.join(map)) else {
                continue;
            };
            let data = base64::engine::general_purpose::STANDARD.encode(bytes);
            let _ = writeln!(
                h,
                r#"<figure><img alt="{0}" src="data:image/png;base64,{data}"><figcaption>{0}: max {1}, {2} evaluations</figcaption></figure>"#,
                escape(&r.algorithm),
                r.stats["max_edge_evals_per_pixel"],
                r.stats["edge_evaluations"]
            );
        }
        h.push_str("</div>\n");
    }
}

/// The peers beside the ray caster and the fastest of continuum's own.
/// The algorithms of the paper's §5 GPU comparison, in table order; the
/// ratios are to `gpu-3dr`'s frame rate.
const SECT5: [&str; 5] = [
    "gpu-2dr",
    "gpu-2dr-homogeneous",
    "gpu-3dr",
    "gpu-3dr-binned",
    "gpu-raster",
];

pub const SECT5_TITLE: &str = "GPU shaders side by side (paper section 5): frames per second, and in brackets each over gpu-3dr's";

/// The §5 table as text cells, a header and one line per scene, viewport,
/// aa and depth-test setting: the triangles gpu-3dr set up, then per algorithm its
/// fps (median) and its fps over `gpu-3dr`'s. `None` without a `gpu-3dr` row.
pub fn sect5_rows(rows: &[Row]) -> Option<Vec<Vec<String>>> {
    if !rows.iter().any(|r| r.algorithm == "gpu-3dr") {
        return None;
    }
    let mut out = vec![
        ["scene", "set up", "size", "aa", "depth test"]
            .iter()
            .map(|s| format!("{s:>12}"))
            .chain(SECT5.iter().map(|a| format!("{a:>22}")))
            .collect(),
    ];
    for group in groups(rows) {
        let fps = |name: &str| {
            group
                .iter()
                .find(|r| r.algorithm == name)
                .map(|r| 1e3 / r.median_ms)
        };
        let Some(base) = fps("gpu-3dr") else { continue };
        let r = group[0];
        let triangles = r.stats["triangle_setups"].as_u64().unwrap_or(0);
        let mut line: Vec<String> = [
            r.scene.clone(),
            triangles.to_string(),
            format!("{}x{}", r.width, r.height),
            r.aa.clone(),
            (if r.depth_test { "on" } else { "off" }).to_string(),
        ]
        .iter()
        .map(|s| format!("{s:>12}"))
        .collect();
        for name in SECT5 {
            line.push(match fps(name) {
                Some(f) => format!("{:>22}", format!("{f:.2} ({:.3})", f / base)),
                None => format!("{:>22}", "–"),
            });
        }
        out.push(line);
    }
    Some(out)
}

/// The paper's §5 table: the GPU algorithms' frame rates side by side.
fn sect5(h: &mut String, rows: &[Row]) {
    let Some(table) = sect5_rows(rows) else {
        return;
    };
    let _ = write!(
        h,
        "<h2 id=\"sect5\">GPU shaders side by side (paper §5)</h2>\n<p>Frames per second (median) of the compute kernels and the hardware pipeline, each in brackets over <code>gpu-3dr</code>'s; the paper (ATI HD5870, 1920×1200, depth test off) measured 3DR 465 = homogeneous 465 &gt; 2DR 464 fps on 262,144 triangles and 2559 / 2558 / 2503 on 144. <em>Set up</em>: the triangles <code>gpu-3dr</code> set up (those with samples on screen). Adapter, driver and timing clock per row in <code>results.json</code> (<code>stats.gpu</code>) and below.</p>\n<table>"
    );
    for (k, line) in table.iter().enumerate() {
        let cell = if k == 0 { "th" } else { "td" };
        h.push_str("<tr>");
        for (i, c) in line.iter().enumerate() {
            let class = if i == 0 { " class=\"l\"" } else { "" };
            let _ = write!(h, "<{cell}{class}>{}</{cell}>", escape(c.trim()));
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</table>\n");
}

fn peers(h: &mut String, rows: &[Row]) {
    let peer = |r: &Row| r.algorithm.starts_with("peer-") || r.algorithm == "gpu-raster";
    if !rows.iter().any(peer) {
        return;
    }
    h.push_str("<h2 id=\"peers\">Peers</h2>\n<p>peer-obvhs (obvhs's own traversal and triangle test), peer-embree (one rtcIntersect1 per ray), peer-embree-stream (coherent row streams), gpu-raster (the GPU's pipeline through wgpu; lavapipe without a GPU) beside raycast and 3dr-full. Peers are not watertight: their pixels differing from 3dr-brute are reported, not asserted. Peers find the visible triangle and shade nothing; <em>visibility</em> is continuum's render without its resolve and shading stages, timed the same way.</p>\n<table><tr><th class=\"l\">scene</th><th class=\"l\">algorithm</th><th>median ms</th><th>× 2dr-brute</th><th>Mrays/s</th><th>visibility ms</th><th>visibility Mrays/s</th><th>pixels ≠ 3dr-brute</th></tr>\n");
    for group in groups(rows) {
        if !group.iter().any(|r| peer(r)) {
            continue;
        }
        for r in group
            .iter()
            .filter(|r| peer(r) || r.algorithm == "raycast" || r.algorithm == "3dr-full")
        {
            let _ = writeln!(
                h,
                "<tr><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{:.2}</td><td>{}</td><td>{:.2}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                escape(&r.scene),
                escape(&r.algorithm),
                r.median_ms,
                opt(r.ratio_to_2dr_brute, 2),
                r.rays_per_second / 1e6,
                opt(r.visibility_ms, 2),
                opt(
                    r.visibility_ms
                        .map(|ms| f64::from(r.width) * f64::from(r.height) / ms / 1e3),
                    2
                ),
                r.pixels_differing_from_3dr_brute
                    .map_or("–".into(), |d| d.to_string())
            );
        }
    }
    h.push_str("</table>\n");
}

/// The counters that explain a BVH algorithm's time: per row, the nodes its
/// frusta (or ray packets) visited, those culled as outside and as occluded
/// (paper Fig. 6a), the frusta split (Fig. 6b, c) and the leaf triangles set up.
fn traversal(h: &mut String, rows: &[Row]) {
    let count = |r: &Row, k: &str| r.stats.get(k).and_then(Value::as_u64).unwrap_or(0);
    let walks = |r: &&Row| count(r, "bvh_nodes_visited") > 0;
    if !rows.iter().any(|r| walks(&r)) {
        return;
    }
    h.push_str("<h2 id=\"traversal\">BVH traversal</h2>\n<p>Per row: the nodes visited (a culled node counts once, its subtree not at all), those culled as outside the frustum and as occluded behind the hierarchical w-buffer (<em>culled</em> share of the visits in brackets), the frusta split, the leaf triangles set up, and the setups reused (a leaf triangle reached again by another frustum of the same work item while the worker's leaf cache held it). <code>raycast</code> counts the nodes its packets entered.</p>\n<table><tr><th class=\"l\">scene</th><th class=\"l\">algorithm</th><th class=\"l\">viewport</th><th class=\"l\">aa</th><th>median ms</th><th>nodes visited</th><th>outside</th><th>occluded</th><th>frusta split</th><th>setups</th><th>reused</th></tr>\n");
    for r in rows.iter().filter(walks) {
        let visited = count(r, "bvh_nodes_visited");
        let share = |n: u64| format!("{n} ({:.0}%)", 100.0 * n as f64 / visited as f64);
        let _ = writeln!(
            h,
            "<tr><td class=\"l\">{}</td><td class=\"l\">{}</td><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{:.2}</td><td>{visited}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            escape(&r.scene),
            escape(&r.algorithm),
            escape(&r.viewport),
            escape(&r.aa),
            r.median_ms,
            share(count(r, "nodes_culled_outside")),
            share(count(r, "nodes_culled_occluded")),
            count(r, "frusta_split"),
            count(r, "triangle_setups"),
            count(r, "leaf_setups_reused"),
        );
    }
    h.push_str("</table>\n");
}

/// Does every algorithm agree with its family (continuum's own: bit for bit)?
fn agreement(h: &mut String, rows: &[Row]) {
    let algorithms = distinct(rows.iter().map(|r| r.algorithm.as_str()));
    h.push_str("<h2 id=\"agreement\">Agreement</h2>\n<p>✓: the triangle ids (per sample with anti-aliasing) equal the family's first member's bit for bit; for peers and the GPU, equal 3dr-brute's (with no depth test, which only the compute kernels offer, gpu-3dr's). A ✗ on one of continuum's own algorithms is a bug.</p>\n<table><tr><th class=\"l\">scene / viewport / aa / precision</th>");
    for a in &algorithms {
        let _ = write!(h, "<th>{}</th>", escape(a));
    }
    h.push_str("</tr>\n");
    for group in groups(rows) {
        let f = group[0];
        let _ = write!(
            h,
            "<tr><td class=\"l\">{} / {} / {} / {}{}</td>",
            escape(&f.scene),
            escape(&f.viewport),
            escape(&f.aa),
            f.precision,
            if f.depth_test { "" } else { " / no depth test" }
        );
        for a in &algorithms {
            match group.iter().find(|r| r.algorithm == *a) {
                None => h.push_str("<td></td>"),
                Some(r) if r.agrees => h.push_str("<td class=\"good\">✓</td>"),
                Some(r) => {
                    let _ = write!(
                        h,
                        "<td class=\"bad\">✗{}</td>",
                        r.pixels_differing_from_3dr_brute
                            .map_or(String::new(), |d| format!(" {d} px"))
                    );
                }
            }
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</table>\n");
}

fn all_rows(h: &mut String, rows: &[Row]) {
    h.push_str("<h2 id=\"rows\">Every row</h2>\n<table><tr><th class=\"l\">scene</th><th class=\"l\">algorithm</th><th class=\"l\">viewport</th><th class=\"l\">aa</th><th class=\"l\">prec.</th><th>median ms</th><th>min</th><th>max</th><th>× 2dr-brute</th><th>predicted</th><th>× aa none</th><th>× f32</th><th>setups</th><th>edge evals</th><th>PSNR</th><th>FLIP</th></tr>\n");
    for r in rows {
        let stat = |k: &str| {
            r.stats
                .get(k)
                .and_then(Value::as_u64)
                .map_or("–".into(), |v| v.to_string())
        };
        let _ = writeln!(
            h,
            "<tr><td class=\"l\">{}</td><td class=\"l\">{}</td><td class=\"l\">{}</td><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{:.2}</td><td>{:.2}</td><td>{:.2}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            escape(&r.scene),
            escape(&r.algorithm),
            escape(&r.viewport),
            escape(&r.aa),
            r.precision,
            r.median_ms,
            r.min_ms,
            r.max_ms,
            opt(r.ratio_to_2dr_brute, 2),
            opt(r.predicted_ratio, 2),
            opt(r.ratio_to_aa_none, 2),
            opt(r.ratio_to_f32, 2),
            stat("triangle_setups"),
            stat("edge_evaluations"),
            opt(r.psnr, 2),
            opt(r.flip_mean, 4)
        );
    }
    h.push_str("</table>\n");
}

/// The width of an SVG chart's label column, in pixels: room for its longest
/// label at 11 px sans-serif (`--oracles` rows' labels are long), 170 at least.
fn label_width<'a>(labels: impl Iterator<Item = &'a str>) -> f64 {
    let longest = labels.map(|l| l.chars().count()).max().unwrap_or(0);
    (longest as f64 * 6.5 + 12.0).max(170.0)
}
