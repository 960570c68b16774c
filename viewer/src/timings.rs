//! The timings panel: per-stage times of the last frame as bars, every frame's
//! total in a history plot with one line per algorithm, and the counters.

use continuum::Stats;
use eframe::egui::{self, Color32, RichText};
use egui_plot::{Bar, BarChart, Legend, Line, Plot, Points};

/// Totals of past frames in render order, labelled by algorithm (and by the
/// method's anti-aliasing and precision when not the defaults).
#[derive(Clone, Debug, Default)]
pub struct History {
    frames: Vec<(String, f64)>,
}

impl History {
    /// Frames kept; the oldest go first.
    const CAPACITY: usize = 1000;

    pub fn push(&mut self, label: String, total_ms: f64) {
        if self.frames.len() == Self::CAPACITY {
            self.frames.remove(0);
        }
        self.frames.push((label, total_ms));
    }

    /// Every frame kept, oldest first: (label, total ms).
    pub fn frames(&self) -> &[(String, f64)] {
        &self.frames
    }

    pub fn len(&self) -> usize {
        self.frames.len()
    }

    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// Per label, its frames as (frame number, ms), labels in order of first appearance.
    pub fn series(&self) -> Vec<(&str, Vec<[f64; 2]>)> {
        let mut out: Vec<(&str, Vec<[f64; 2]>)> = Vec::new();
        for (n, (label, ms)) in self.frames.iter().enumerate() {
            let point = [n as f64, *ms];
            match out.iter_mut().find(|(l, _)| l == label) {
                Some((_, points)) => points.push(point),
                None => out.push((label, vec![point])),
            }
        }
        out
    }
}

/// The stages of `StageTimes` with their colours, in pipeline order.
const STAGES: [(&str, Color32); 6] = [
    ("setup", Color32::from_rgb(0x4e, 0x79, 0xa7)),
    ("traversal", Color32::from_rgb(0xf2, 0x8e, 0x2b)),
    ("coverage", Color32::from_rgb(0xe1, 0x57, 0x59)),
    ("resolve", Color32::from_rgb(0xed, 0xc9, 0x48)),
    ("shading", Color32::from_rgb(0x59, 0xa1, 0x4f)),
    ("store", Color32::from_rgb(0x9c, 0x75, 0x5f)),
];

/// Colours of the history's lines, in order of first appearance (Tableau 10).
const SERIES: [Color32; 10] = [
    Color32::from_rgb(0x4e, 0x79, 0xa7),
    Color32::from_rgb(0xf2, 0x8e, 0x2b),
    Color32::from_rgb(0xe1, 0x57, 0x59),
    Color32::from_rgb(0x76, 0xb7, 0xb2),
    Color32::from_rgb(0x59, 0xa1, 0x4f),
    Color32::from_rgb(0xed, 0xc9, 0x48),
    Color32::from_rgb(0xb0, 0x7a, 0xa1),
    Color32::from_rgb(0xff, 0x9d, 0xa7),
    Color32::from_rgb(0x9c, 0x75, 0x5f),
    Color32::from_rgb(0xba, 0xb0, 0xac),
];

fn stage_ms(stats: &Stats) -> [f64; 6] {
    let t = &stats.time_ms;
    [
        t.setup,
        t.traversal,
        t.coverage,
        t.resolve,
        t.shading,
        t.store,
    ]
}

/// Horizontal bars of each stage's time for each labelled render (A, and B in
/// the compare view).
pub fn stage_bars(ui: &mut egui::Ui, renders: &[(&str, &Stats)]) {
    for (label, stats) in renders {
        ui.label(RichText::new(format!("{label}: {:.1} ms total", stats.time_ms.total)).strong());
        ui.horizontal_wrapped(|ui| {
            ui.spacing_mut().item_spacing.x = 4.0;
            for ((name, color), ms) in STAGES.iter().zip(stage_ms(stats)) {
                let (swatch, _) =
                    ui.allocate_exact_size(egui::vec2(10.0, 10.0), egui::Sense::hover());
                ui.painter().rect_filled(swatch, 2.0, *color);
                ui.small(format!("{name} {ms:.1}"));
            }
        });
    }
    let rows = renders.len().max(1);
    let charts: Vec<BarChart> = STAGES
        .iter()
        .enumerate()
        .map(|(s, (name, color))| {
            let bars = renders
                .iter()
                .enumerate()
                .map(|(r, (label, stats))| {
                    Bar::new((rows - 1 - r) as f64, stage_ms(stats)[s])
                        .name(format!("{label} {name}"))
                        .fill(*color)
                        .width(0.7)
                })
                .collect();
            BarChart::new(*name, bars).color(*color).horizontal()
        })
        .collect();
    // Stack the stages along each bar.
    let mut stacked: Vec<BarChart> = Vec::with_capacity(charts.len());
    for chart in charts {
        let refs: Vec<&BarChart> = stacked.iter().collect();
        let chart = chart.stack_on(&refs);
        stacked.push(chart);
    }
    Plot::new("stage_bars")
        .height(40.0 + 28.0 * rows as f32)
        .show_y(false)
        .allow_drag(false)
        .allow_zoom(false)
        .allow_scroll(false)
        .include_x(0.0)
        .include_y(-0.5)
        .include_y(rows as f64 - 0.5)
        .x_axis_label("ms")
        .y_axis_formatter(|_, _| String::new())
        .show(ui, |plot| {
            for chart in stacked {
                plot.bar_chart(chart);
            }
        });
}

/// Every frame's total time, one line per algorithm.
pub fn history_plot(ui: &mut egui::Ui, history: &History) {
    Plot::new("history")
        .height(160.0)
        .legend(Legend::default())
        .include_y(0.0)
        .include_x(0.0)
        .include_x(history.len().max(2) as f64 - 1.0)
        .x_axis_label("frame")
        .y_axis_label("ms")
        .allow_scroll(false)
        .show(ui, |plot| {
            for (i, (label, points)) in history.series().into_iter().enumerate() {
                let color = SERIES[i % SERIES.len()];
                // Markers too: a single frame is a point, not yet a line.
                plot.points(
                    Points::new(label.to_owned(), points.clone())
                        .radius(2.5)
                        .color(color),
                );
                plot.line(Line::new(label.to_owned(), points).color(color));
            }
        });
}

/// The counters of each labelled render, one column per render.
pub fn counters_table(ui: &mut egui::Ui, renders: &[(&str, &Stats)]) {
    let rows: [Row<Stats, u64>; 18] = [
        ("triangle setups", |s| s.triangle_setups),
        ("edge evaluations", |s| s.edge_evaluations),
        ("max per pixel", |s| u64::from(s.max_edge_evals_per_pixel)),
        ("predicted instructions", |s| s.predicted_instructions),
        ("BVH nodes visited", |s| s.bvh_nodes_visited),
        ("frusta created", |s| s.counters.frusta_created),
        ("frusta split", |s| s.counters.frusta_split),
        ("nodes culled outside", |s| s.counters.nodes_culled_outside),
        ("nodes culled occluded", |s| {
            s.counters.nodes_culled_occluded
        }),
        ("tiles tested", |s| s.counters.tiles_tested),
        ("tiles accepted", |s| s.counters.tiles_accepted),
        ("tiles rejected", |s| s.counters.tiles_rejected),
        ("early-z rejects", |s| s.counters.early_z_rejects),
        ("spans", |s| s.counters.spans),
        ("edge steps", |s| s.counters.edge_steps),
        ("samples shaded", |s| s.shading_samples),
        ("pixels with 1 coverage write", |s| s.coverage_histogram.one),
        ("pixels with 2+ writes", |s| s.coverage_histogram.many),
    ];
    egui::Grid::new("counters")
        .striped(true)
        .num_columns(1 + renders.len())
        .show(ui, |ui| {
            ui.label("");
            for (label, _) in renders {
                ui.label(RichText::new(*label).strong());
            }
            ui.end_row();
            for (name, value) in rows {
                ui.label(name);
                for (_, stats) in renders {
                    ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                        ui.monospace(thousands(value(stats)));
                    });
                }
                ui.end_row();
            }
        });
}

/// The effects each render ran (texture lookups, shadow rays per light,
/// reflection rays, blended fragments) and their worker time; nothing when
/// the scene calls for none.
pub fn effects_table(ui: &mut egui::Ui, renders: &[(&str, &Stats)]) {
    if renders.iter().all(|(_, s)| s.effects.is_empty()) {
        ui.label("none: the scene calls for no effect");
        return;
    }
    egui::Grid::new("effects")
        .striped(true)
        .num_columns(3)
        .show(ui, |ui| {
            for (label, stats) in renders {
                for e in &stats.effects {
                    let name = match &e.light {
                        Some(light) => format!("{label} {} ({light})", e.effect),
                        None => format!("{label} {}", e.effect),
                    };
                    ui.label(name);
                    // What the effect counts: rays, texture lookups or blended
                    // fragments (short words: the panel is narrow).
                    ui.monospace(match e.effect {
                        "textures" => format!("{} lookups", thousands(e.lookups)),
                        "transparency" => format!("{} blends", thousands(e.fragments)),
                        _ => format!("{} rays", thousands(e.rays)),
                    });
                    ui.monospace(format!("{:.1} ms", e.worker_ms));
                    ui.end_row();
                }
            }
        });
}

/// `1234567` as `1 234 567` (thin groups read at a glance in a table).
pub fn thousands(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::with_capacity(digits.len() + digits.len() / 3);
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(' ');
        }
        out.push(c);
    }
    out
}

/// A table row: its name and how to read its value.
pub(crate) type Row<T, V> = (&'static str, fn(&T) -> V);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn history_groups_frames_by_label_in_order() {
        let mut h = History::default();
        h.push("raycast".into(), 5.0);
        h.push("3dr-brute".into(), 2.0);
        h.push("raycast".into(), 4.0);
        let series = h.series();
        assert_eq!(series[0], ("raycast", vec![[0.0, 5.0], [2.0, 4.0]]));
        assert_eq!(series[1], ("3dr-brute", vec![[1.0, 2.0]]));
    }

    #[test]
    fn history_drops_the_oldest_beyond_capacity() {
        let mut h = History::default();
        for i in 0..=History::CAPACITY {
            h.push("a".into(), i as f64);
        }
        assert_eq!(h.len(), History::CAPACITY);
        assert_eq!(h.series()[0].1[0], [0.0, 1.0]);
    }

    #[test]
    fn thousands_groups_digits() {
        assert_eq!(thousands(0), "0");
        assert_eq!(thousands(999), "999");
        assert_eq!(thousands(1000), "1 000");
        assert_eq!(thousands(1_234_567), "1 234 567");
    }
}
