//! Prometheus text metrics: requests by route and status, render time
//! histograms by algorithm, renders in flight, prepared scenes cached.

use std::collections::BTreeMap;
use std::fmt::Write;
use std::sync::Mutex;

/// Upper bounds of the render-time buckets, seconds.
const BUCKETS: [f64; 11] = [
    0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1.0, 2.5, 5.0, 10.0,
];

#[derive(Debug, Default)]
struct Histogram {
    counts: [u64; BUCKETS.len()],
    count: u64,
    sum: f64,
}

/// The service's counters.
#[derive(Debug, Default)]
pub struct Metrics {
    requests: Mutex<BTreeMap<(String, u16), u64>>,
    renders: Mutex<BTreeMap<String, Histogram>>,
}

impl Metrics {
    pub fn count_request(&self, route: &str, status: u16) {
        if let Ok(mut m) = self.requests.lock() {
            *m.entry((route.to_string(), status)).or_default() += 1;
        }
    }

    pub fn observe_render(&self, algorithm: &str, seconds: f64) {
        if let Ok(mut m) = self.renders.lock() {
            let h = m.entry(algorithm.to_string()).or_default();
            for (c, &b) in h.counts.iter_mut().zip(&BUCKETS) {
                if seconds <= b {
                    *c += 1;
                }
            }
            h.count += 1;
            h.sum += seconds;
        }
    }

    pub(crate) fn render_text(
        &self,
        in_flight: usize,
        queued: usize,
        cached: usize,
        cached_bytes: usize,
    ) -> String {
        let mut out = String::new();
        out.push_str("# HELP continuum_requests_total HTTP requests by route and status.\n");
        out.push_str("# TYPE continuum_requests_total counter\n");
        if let Ok(m) = self.requests.lock() {
            for ((route, status), n) in m.iter() {
                let _ = writeln!(
                    out,
                    "continuum_requests_total{{route=\"{route}\",status=\"{status}\"}} {n}"
                );
            }
        }
        out.push_str("# HELP continuum_render_seconds Render wall time by algorithm.\n");
        out.push_str("# TYPE continuum_render_seconds histogram\n");
        if let Ok(m) = self.renders.lock() {
            for (algorithm, h) in m.iter() {
                for (c, b) in h.counts.iter().zip(BUCKETS) {
                    let _ = writeln!(
                        out,
                        "continuum_render_seconds_bucket{{algorithm=\"{algorithm}\",le=\"{b}\"}} {c}"
                    );
                }
                let _ = writeln!(
                    out,
                    "continuum_render_seconds_bucket{{algorithm=\"{algorithm}\",le=\"+Inf\"}} {}",
                    h.count
                );
                let _ = writeln!(
                    out,
                    "continuum_render_seconds_sum{{algorithm=\"{algorithm}\"}} {}",
                    h.sum
                );
                let _ = writeln!(
                    out,
                    "continuum_render_seconds_count{{algorithm=\"{algorithm}\"}} {}",
                    h.count
                );
            }
        }
        out.push_str("# HELP continuum_renders_in_flight Renders running now.\n# TYPE continuum_renders_in_flight gauge\n");
        let _ = writeln!(out, "continuum_renders_in_flight {in_flight}");
        out.push_str("# HELP continuum_render_queue_depth Renders waiting for a slot.\n# TYPE continuum_render_queue_depth gauge\n");
        let _ = writeln!(out, "continuum_render_queue_depth {queued}");
        out.push_str("# HELP continuum_scene_cache_size Prepared scenes held in memory.\n# TYPE continuum_scene_cache_size gauge\n");
        let _ = writeln!(out, "continuum_scene_cache_size {cached}");
        out.push_str("# HELP continuum_scene_cache_bytes Approximate memory of the cached scenes.\n# TYPE continuum_scene_cache_bytes gauge\n");
        let _ = writeln!(out, "continuum_scene_cache_bytes {cached_bytes}");
        out
    }
}
