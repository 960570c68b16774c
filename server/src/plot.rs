//! Plots written beside comparison results, as self-contained SVG (no fonts or
//! scripts to fetch): `aa_cost.svg`, error against time per anti-aliasing mode.

use std::fmt::Write;

/// One measured configuration in the accuracy-versus-time chart.
#[derive(Clone, Debug, PartialEq)]
pub struct AaPoint {
    pub scene: String,
    pub algorithm: String,
    pub aa: String,
    pub median_ms: f64,
    pub flip_mean: f64,
}

const PANEL_W: f64 = 640.0;
const PANEL_H: f64 = 440.0;
const MARGIN_L: f64 = 70.0;
const MARGIN_R: f64 = 20.0;
const MARGIN_T: f64 = 40.0;
const MARGIN_B: f64 = 90.0;
const PALETTE: [&str; 10] = [
    "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
    "#bcbd22", "#17becf",
];

/// The points on the Pareto front (no other point is both faster and more
/// accurate), fastest first.
pub fn pareto_front(points: &[&AaPoint]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| {
        points[a]
            .median_ms
            .total_cmp(&points[b].median_ms)
            .then(points[a].flip_mean.total_cmp(&points[b].flip_mean))
    });
    let mut front = Vec::new();
    let mut best = f64::INFINITY;
    for i in order {
        if points[i].flip_mean < best {
            best = points[i].flip_mean;
            front.push(i);
        }
    }
    front
}

/// Mean FLIP against time (log scale), one panel per scene, one point per
/// algorithm and mode, the Pareto front as a dashed line.
pub fn aa_cost_svg(points: &[AaPoint]) -> String {
    let mut scenes: Vec<&str> = Vec::new();
    let mut algorithms: Vec<&str> = Vec::new();
    for p in points {
        if !scenes.contains(&p.scene.as_str()) {
            scenes.push(&p.scene);
        }
        if !algorithms.contains(&p.algorithm.as_str()) {
            algorithms.push(&p.algorithm);
        }
    }
    let width = PANEL_W * scenes.len().max(1) as f64;
    let mut svg = String::new();
    let _ = writeln!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{PANEL_H}" viewBox="0 0 {width} {PANEL_H}" font-family="sans-serif" font-size="11">"#
    );
    let _ = writeln!(svg, r#"<rect width="100%" height="100%" fill="white"/>"#);
    for (k, scene) in scenes.iter().enumerate() {
        let panel: Vec<&AaPoint> = points.iter().filter(|p| p.scene == *scene).collect();
        panel_svg(&mut svg, k as f64 * PANEL_W, scene, &panel, &algorithms);
    }
    svg.push_str("</svg>\n");
    svg
}

fn panel_svg(svg: &mut String, x0: f64, scene: &str, points: &[&AaPoint], algorithms: &[&str]) {
    let (plot_w, plot_h) = (PANEL_W - MARGIN_L - MARGIN_R, PANEL_H - MARGIN_T - MARGIN_B);
    let times = points.iter().map(|p| p.median_ms.max(1e-3));
    let (t_min, t_max) = times.fold((f64::INFINITY, 0.0f64), |(lo, hi), t| {
        (lo.min(t), hi.max(t))
    });
    let (lt0, lt1) = if t_min.is_finite() {
        let (a, b) = (t_min.log10(), t_max.log10());
        let pad = ((b - a) * 0.08).max(0.05);
        (a - pad, b + pad)
    } else {
        (0.0, 1.0)
    };
    let e_max = points.iter().map(|p| p.flip_mean).fold(0.0f64, f64::max);
    let e_top = if e_max > 0.0 { e_max * 1.12 } else { 1.0 };
    let sx = |t: f64| x0 + MARGIN_L + (t.max(1e-3).log10() - lt0) / (lt1 - lt0) * plot_w;
    let sy = |e: f64| MARGIN_T + plot_h - e / e_top * plot_h;

    let _ = writeln!(
        svg,
        r#"<text x="{}" y="22" font-size="14" font-weight="bold">{}: mean FLIP against time</text>"#,
        x0 + MARGIN_L,
        escape(scene)
    );
    // Axes, grid and ticks.
    let _ = writeln!(
        svg,
        r##"<rect x="{}" y="{MARGIN_T}" width="{plot_w}" height="{plot_h}" fill="none" stroke="#444"/>"##,
        x0 + MARGIN_L
    );
    for decade in (lt0.floor() as i32)..=(lt1.ceil() as i32) {
        for m in [1.0, 2.0, 5.0] {
            let t = m * 10f64.powi(decade);
            let lt = t.log10();
            if lt < lt0 || lt > lt1 {
                continue;
            }
            let x = sx(t);
            let _ = writeln!(
                svg,
                r##"<line x1="{x:.1}" y1="{MARGIN_T}" x2="{x:.1}" y2="{:.1}" stroke="#ddd"/><text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"##,
                MARGIN_T + plot_h,
                MARGIN_T + plot_h + 14.0,
                format_ms(t)
            );
        }
    }
    for k in 0..=4 {
        let e = e_top * f64::from(k) / 4.0;
        let y = sy(e);
        let _ = writeln!(
            svg,
            r##"<line x1="{:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#ddd"/><text x="{:.1}" y="{:.1}" text-anchor="end">{e:.4}</text>"##,
            x0 + MARGIN_L,
            x0 + MARGIN_L + plot_w,
            x0 + MARGIN_L - 4.0,
            y + 4.0
        );
    }
    let _ = writeln!(
        svg,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">median time per frame (ms, log scale)</text>"#,
        x0 + MARGIN_L + plot_w / 2.0,
        MARGIN_T + plot_h + 32.0
    );
    let _ = writeln!(
        svg,
        r#"<text transform="translate({:.1} {:.1}) rotate(-90)" text-anchor="middle">mean FLIP vs ssaa:256</text>"#,
        x0 + 16.0,
        MARGIN_T + plot_h / 2.0
    );
    // The Pareto front.
    let front = pareto_front(points);
    if front.len() > 1 {
        let path: Vec<String> = front
            .iter()
            .map(|&i| {
                format!(
                    "{:.1},{:.1}",
                    sx(points[i].median_ms),
                    sy(points[i].flip_mean)
                )
            })
            .collect();
        let _ = writeln!(
            svg,
            r##"<polyline points="{}" fill="none" stroke="#222" stroke-dasharray="5 3"/>"##,
            path.join(" ")
        );
    }
    // The points, coloured by algorithm and labelled by mode where the label
    // finds room (every point names itself in its tooltip).
    let mut placed: Vec<[f64; 4]> = Vec::new();
    for (i, p) in points.iter().enumerate() {
        let color = algorithm_color(algorithms, &p.algorithm);
        let (x, y) = (sx(p.median_ms), sy(p.flip_mean));
        let ring = if front.contains(&i) {
            r##" stroke="#000" stroke-width="1.5""##
        } else {
            ""
        };
        let _ = writeln!(
            svg,
            r#"<circle cx="{x:.1}" cy="{y:.1}" r="4" fill="{color}"{ring}><title>{} {}: {:.2} ms, FLIP {:.5}</title></circle>"#,
            escape(&p.algorithm),
            escape(&p.aa),
            p.median_ms,
            p.flip_mean,
        );
        let width = 6.5 * p.aa.len() as f64;
        let spot = [
            (6.0, -4.0),
            (6.0, 12.0),
            (-6.0 - width, -4.0),
            (-6.0 - width, 12.0),
        ]
        .into_iter()
        .map(|(dx, dy)| [x + dx, y + dy - 10.0, x + dx + width, y + dy])
        .find(|b| {
            !placed
                .iter()
                .any(|o| b[0] < o[2] && o[0] < b[2] && b[1] < o[3] && o[1] < b[3])
        });
        if let Some(b) = spot {
            placed.push(b);
            let _ = writeln!(
                svg,
                r#"<text x="{:.1}" y="{:.1}" fill="{color}">{}</text>"#,
                b[0],
                b[3],
                escape(&p.aa)
            );
        }
    }
    // Legend.
    let mut lx = x0 + MARGIN_L;
    let ly = MARGIN_T + plot_h + 56.0;
    for a in algorithms {
        if !points.iter().any(|p| p.algorithm == *a) {
            continue;
        }
        let color = algorithm_color(algorithms, a);
        let _ = writeln!(
            svg,
            r#"<circle cx="{:.1}" cy="{:.1}" r="4" fill="{color}"/><text x="{:.1}" y="{:.1}">{}</text>"#,
            lx,
            ly - 4.0,
            lx + 7.0,
            ly,
            escape(a)
        );
        lx += 14.0 + 7.0 * a.len() as f64;
    }
    let _ = writeln!(
        svg,
        r##"<text x="{:.1}" y="{:.1}" fill="#444">dashed: Pareto front (ringed points)</text>"##,
        x0 + MARGIN_L,
        ly + 18.0
    );
}

fn algorithm_color(algorithms: &[&str], a: &str) -> &'static str {
    let k = algorithms.iter().position(|x| *x == a).unwrap_or(0);
    PALETTE[k % PALETTE.len()]
}

fn format_ms(t: f64) -> String {
    if t >= 1.0 {
        format!("{t:.0}")
    } else {
        format!("{t}")
    }
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(aa: &str, ms: f64, flip: f64) -> AaPoint {
        AaPoint {
            scene: "s".into(),
            algorithm: "a".into(),
            aa: aa.into(),
            median_ms: ms,
            flip_mean: flip,
        }
    }

    #[test]
    fn the_front_keeps_only_points_nothing_beats_on_both_axes() {
        let pts = [
            point("none", 10.0, 0.1),
            point("msaa:4", 20.0, 0.05),
            point("ssaa:4", 40.0, 0.06),
            point("msaa:16", 30.0, 0.02),
        ];
        let refs: Vec<&AaPoint> = pts.iter().collect();
        assert_eq!(pareto_front(&refs), [0, 1, 3]);
        let svg = aa_cost_svg(&pts);
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        for mode in ["none", "msaa:4", "ssaa:4", "msaa:16"] {
            assert!(svg.contains(&format!(">{mode}</text>")), "{mode}");
        }
        assert_eq!(svg.matches("<polyline").count(), 1);
    }
}
