//! Sample positions of the anti-aliasing modes.
//!
//! - `msaa:N`, `ssaa:4`, `ssaa:16` and the coverage positions of `csaa:CxS` use
//!   the standard sample locations of Direct3D 11 and Vulkan ("standard sample
//!   locations", multiples of 1/16): rotated grids that are also N-rooks patterns
//!   (every row and every column of an N×N grid over the pixel holds one sample).
//! - `ssaa:64` and `ssaa:256` use multi-jittered patterns (Chiu, Shirley and
//!   Wang 1994) with a fixed seed: stratified over √N×√N cells *and* N-rooks,
//!   with positions at the centres of the N×N sub-cells (multiples of 1/2N, exact
//!   in `f32`).
//! - `csaa:CxS` stores S of its C positions: for each position of the standard
//!   S-sample pattern the nearest one, so its stored samples lie about where
//!   `msaa:S` samples; they come first in the pattern.
//!
//! Because every pattern is N-rooks, the covered fraction of a pixel crossed by
//! an axis-aligned edge differs from the covered area by at most 1/N.

use super::AaMode;
use crate::ground::SampleSpan;

/// Direct3D 11 / Vulkan standard sample locations, in 1/16 pixel from the
/// pixel centre (`y` down).
const STANDARD_2: [[i8; 2]; 2] = [[4, 4], [-4, -4]];
const STANDARD_4: [[i8; 2]; 4] = [[-2, -6], [6, -2], [-6, 2], [2, 6]];
const STANDARD_8: [[i8; 2]; 8] = [
    [1, -3],
    [-1, 3],
    [5, 1],
    [-3, -5],
    [-5, 5],
    [-7, -1],
    [3, 7],
    [7, -7],
];
const STANDARD_16: [[i8; 2]; 16] = [
    [1, 1],
    [-1, -3],
    [-3, 2],
    [4, -1],
    [-5, -2],
    [2, 5],
    [5, 3],
    [3, -5],
    [-2, 6],
    [0, -7],
    [-4, -6],
    [-6, 4],
    [-8, 0],
    [7, -4],
    [6, 7],
    [-7, -8],
];

/// The seed of the multi-jittered patterns (fixed: every run and every
/// algorithm samples the same positions).
const JITTER_SEED: u64 = 0x3d_7a57_e415;

/// Where in a pixel the samples of a mode lie.
#[derive(Clone, Debug, PartialEq)]
pub struct SamplePattern {
    /// Coverage positions as offsets from the pixel's top-left corner, in
    /// `[0, 1)²`; the first [`SamplePattern::stored`] also keep depth and id.
    pub positions: Vec<[f32; 2]>,
    /// How many positions store depth and triangle id (`S`).
    pub stored: usize,
    /// Shade every stored sample (SSAA, none) or once per pixel per triangle.
    pub shade_per_sample: bool,
    /// The smallest box holding every position.
    pub span: SampleSpan,
    /// CSAA: per coverage position, the stored positions nearest first
    /// (empty when every position is stored).
    pub nearest: Vec<Vec<u8>>,
}

impl SamplePattern {
    /// The pattern of `mode`.
    pub fn of(mode: AaMode) -> SamplePattern {
        let (positions, stored) = match mode {
            AaMode::None => (vec![[0.5, 0.5]], 1),
            AaMode::Msaa(n) | AaMode::Ssaa(n) if n <= 16 => (standard(n), n as usize),
            AaMode::Msaa(n) | AaMode::Ssaa(n) => (multi_jittered(n), n as usize),
            AaMode::Csaa { coverage, stored } => (
                stored_first(standard(coverage), stored as usize),
                stored as usize,
            ),
        };
        let mut span = SampleSpan {
            lo: [f32::INFINITY; 2],
            hi: [f32::NEG_INFINITY; 2],
        };
        for p in &positions {
            span.lo = [span.lo[0].min(p[0]), span.lo[1].min(p[1])];
            span.hi = [span.hi[0].max(p[0]), span.hi[1].max(p[1])];
        }
        let distance = |a: [f32; 2], b: [f32; 2]| (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2);
        // CSAA: per coverage position, the stored ones nearest first.
        let nearest: Vec<Vec<u8>> = if stored < positions.len() {
            positions
                .iter()
                .map(|&p| {
                    let mut order: Vec<u8> = (0..stored as u8).collect();
                    order.sort_by(|&a, &b| {
                        let (a, b) = (positions[a as usize], positions[b as usize]);
                        distance(p, a).total_cmp(&distance(p, b))
                    });
                    order
                })
                .collect()
        } else {
            Vec::new()
        };
        SamplePattern {
            positions,
            stored,
            shade_per_sample: mode.shades_per_sample(),
            span,
            nearest,
        }
    }

    /// Coverage positions per pixel (`C`).
    pub fn coverage(&self) -> usize {
        self.positions.len()
    }

    /// Are there coverage positions that store nothing (CSAA)?
    pub fn has_coverage_only(&self) -> bool {
        self.positions.len() > self.stored
    }

    /// `k` when the positions are stratified over a k×k grid (one in each
    /// cell): the 2×2 rotated grid of 4 and the multi-jittered 64 and 256.
    pub fn stratified_grid(&self) -> Option<usize> {
        let n = self.positions.len();
        let k = (n as f64).sqrt().round() as usize;
        if k * k != n || k < 2 {
            return None;
        }
        let mut seen = vec![false; n];
        for q in &self.positions {
            let cell = (q[1] * k as f32) as usize * k + (q[0] * k as f32) as usize;
            if cell >= n || std::mem::replace(&mut seen[cell], true) {
                return None;
            }
        }
        Some(k)
    }

    /// How far the covered fraction of a pixel crossed by one straight edge can
    /// be from the covered area. Axis-aligned edges: 1/N (every pattern is
    /// N-rooks: each of the N columns and rows holds one position). Any other
    /// edge: (2k − 1)/N for patterns stratified over a k×k grid (the edge
    /// crosses at most 2k − 1 cells, each off by at most its area 1/N); no
    /// bound below 1 otherwise.
    pub fn edge_error_bound(&self, axis_aligned: bool) -> f64 {
        let n = self.positions.len() as f64;
        match (axis_aligned, self.stratified_grid()) {
            (true, _) => 1.0 / n,
            (false, Some(k)) => (2 * k - 1) as f64 / n,
            (false, None) => 1.0,
        }
    }
}

/// The standard locations for `n` samples (`n` in 1, 2, 4, 8, 16).
fn standard(n: u32) -> Vec<[f32; 2]> {
    let table: &[[i8; 2]] = match n {
        2 => &STANDARD_2,
        4 => &STANDARD_4,
        8 => &STANDARD_8,
        16 => &STANDARD_16,
        _ => &[[0, 0]],
    };
    table
        .iter()
        .map(|&[x, y]| [0.5 + f32::from(x) / 16.0, 0.5 + f32::from(y) / 16.0])
        .collect()
}

/// Multi-jittered positions for `n = k²` samples: sample `(i, j)` lies in cell
/// `(i, j)` of the k×k grid, at sub-column `π_i(j)` and sub-row `ρ_j(i)` of it,
/// where every `π_i` and `ρ_j` is a permutation — so each of the n columns and n
/// rows of the n×n grid holds exactly one sample.
fn multi_jittered(n: u32) -> Vec<[f32; 2]> {
    let k = (n as f64).sqrt() as usize;
    debug_assert_eq!(k * k, n as usize);
    let mut rng = fastrand::Rng::with_seed(JITTER_SEED ^ u64::from(n));
    let mut permutation = || {
        let mut p: Vec<usize> = (0..k).collect();
        rng.shuffle(&mut p);
        p
    };
    let columns: Vec<Vec<usize>> = (0..k).map(|_| permutation()).collect();
    let rows: Vec<Vec<usize>> = (0..k).map(|_| permutation()).collect();
    let n = n as f32;
    let mut out = Vec::with_capacity(k * k);
    for j in 0..k {
        for i in 0..k {
            let sub_x = i * k + columns[i][j];
            let sub_y = j * k + rows[j][i];
            out.push([(sub_x as f32 + 0.5) / n, (sub_y as f32 + 0.5) / n]);
        }
    }
    out
}

/// Reorders `positions` so that the `stored` ones come first: for each
/// position of the standard `stored`-sample pattern in turn, the nearest one
/// not yet taken — so `csaa:CxS` stores about where `msaa:S` samples.
fn stored_first(mut positions: Vec<[f32; 2]>, stored: usize) -> Vec<[f32; 2]> {
    let distance = |a: [f32; 2], b: [f32; 2]| (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2);
    for (chosen, target) in standard(stored as u32).into_iter().enumerate() {
        // The first nearest keeps the choice deterministic.
        let mut best = chosen;
        for k in chosen + 1..positions.len() {
            if distance(positions[k], target) < distance(positions[best], target) {
                best = k;
            }
        }
        positions[chosen..=best].rotate_right(1);
    }
    positions
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each of the n columns and n rows of the n×n grid over the pixel holds one
    /// position.
    fn is_n_rooks(p: &[[f32; 2]]) -> bool {
        let n = p.len();
        (0..2).all(|axis| {
            let mut seen = vec![false; n];
            p.iter().all(|q| {
                let cell = (q[axis] * n as f32).floor() as usize;
                cell < n && !std::mem::replace(&mut seen[cell], true)
            })
        })
    }

    #[test]
    fn every_pattern_is_n_rooks_inside_the_pixel_and_without_repeats() {
        for mode in AaMode::all() {
            let p = mode.pattern();
            assert_eq!(p.coverage(), mode.coverage_samples() as usize, "{mode}");
            assert_eq!(p.stored, mode.stored_samples() as usize, "{mode}");
            assert!(is_n_rooks(&p.positions), "{mode}: {:?}", p.positions);
            for q in &p.positions {
                assert!(
                    (0.0..1.0).contains(&q[0]) && (0.0..1.0).contains(&q[1]),
                    "{mode}"
                );
            }
        }
    }

    #[test]
    fn multi_jittered_patterns_are_stratified() {
        assert_eq!(AaMode::Ssaa(64).pattern().stratified_grid(), Some(8));
        assert_eq!(AaMode::Ssaa(256).pattern().stratified_grid(), Some(16));
    }

    #[test]
    fn csaa_stores_spread_positions_first() {
        let p = AaMode::Csaa {
            coverage: 16,
            stored: 4,
        }
        .pattern();
        let mut sorted = p.positions.clone();
        sorted.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
        let mut standard16 = standard(16);
        standard16.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
        assert_eq!(sorted, standard16, "the same positions, reordered");
        // The stored four lie in four different quadrants.
        let quadrant = |q: [f32; 2]| (q[0] >= 0.5) as usize + 2 * (q[1] >= 0.5) as usize;
        let mut quadrants: Vec<usize> = p.positions[..4].iter().map(|&q| quadrant(q)).collect();
        quadrants.sort_unstable();
        assert_eq!(quadrants, [0, 1, 2, 3], "{:?}", &p.positions[..4]);
    }
}
