//! Polygons by direct scan conversion (Saarland lecture, "Reminder:
//! Polygons", "Inside-Outside Tests"): convex, concave, with holes (further
//! contours) and self-intersecting, filled by the even-odd or the non-zero
//! winding rule.
//!
//! An **edge table** holds every non-horizontal edge under the first pixel
//! row whose centre it reaches; an **active edge list** carries the edges
//! crossing the current row's centre line, sorted by where they cross it.
//! Walking that list from left to right, each edge changes the winding
//! number by its direction (+1 downwards, −1 upwards), and the pixels whose
//! centres lie where the rule says "inside" are filled — from a crossing
//! `x_a` (inclusive) to the next `x_b` (exclusive), and rows from an edge's
//! upper end (inclusive) to its lower end (exclusive): the top-left rule, so
//! polygons sharing an edge give each pixel centre on it to exactly one of
//! them. Each crossing is computed from the edge's endpoints in a canonical
//! order (upper first), so a shared edge crosses a row at the same `x` bit
//! for bit in both polygons.

use super::{Plot, finite};
use crate::ground::FieldError;

/// Which points a self-overlapping outline encloses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FillRule {
    /// Inside where a ray to infinity crosses the outline an odd number of times.
    EvenOdd,
    /// Inside where the outline winds around the point a non-zero number of times.
    NonZero,
}

impl FillRule {
    fn inside(self, winding: i32) -> bool {
        match self {
            FillRule::EvenOdd => winding % 2 != 0,
            FillRule::NonZero => winding != 0,
        }
    }
}

/// One edge, upper endpoint first, with its direction.
#[derive(Clone, Copy, Debug)]
struct Edge {
    upper: [f64; 2],
    lower: [f64; 2],
    /// +1 where the outline runs downwards (increasing y), −1 upwards.
    winding: i32,
    /// Rows whose centre lines it crosses: `first..end`.
    first: i64,
    end: i64,
}

impl Edge {
    /// Where the edge crosses the horizontal line `y` (a row's centre).
    #[inline]
    fn x_at(&self, y: f64) -> f64 {
        let ([x0, y0], [x1, y1]) = (self.upper, self.lower);
        x0 + (y - y0) / (y1 - y0) * (x1 - x0)
    }
}

/// Fills the polygon bounded by `contours` (each closed from its last point
/// to its first; holes are contours of their own) by `rule`, each pixel
/// inside the image once. Degenerate outlines draw nothing; a point that is
/// not finite is an error naming `polygon`.
pub fn fill_polygon(
    contours: &[Vec<[f64; 2]>],
    rule: FillRule,
    size: [u32; 2],
    plot: &mut impl Plot,
) -> Result<(), FieldError> {
    for c in contours {
        finite("polygon", c)?;
    }
    let (width, height) = (i64::from(size[0]), i64::from(size[1]));
    // The edge table, by first row (clamped to the image).
    let mut table: Vec<Edge> = contours
        .iter()
        .flat_map(|c| (0..c.len()).map(move |k| (c[k], c[(k + 1) % c.len()])))
        .filter_map(|(a, b)| {
            let down = (a[1], a[0]) < (b[1], b[0]);
            let (upper, lower) = if down { (a, b) } else { (b, a) };
            // Rows j with upper.y <= j + 0.5 < lower.y.
            let first = ((upper[1] - 0.5).ceil().max(-1.0) as i64).max(0);
            let end = ((lower[1] - 0.5).ceil().min(height as f64) as i64).min(height);
            (upper[1] != lower[1] && first < end).then_some(Edge {
                upper,
                lower,
                winding: if down { 1 } else { -1 },
                first,
                end,
            })
        })
        .collect();
    table.sort_by_key(|e| std::cmp::Reverse(e.first));
    let mut active: Vec<Edge> = Vec::new();
    let mut crossings: Vec<(f64, i32)> = Vec::new();
    let Some(start) = table.last().map(|e| e.first) else {
        return Ok(());
    };
    for row in start..height {
        active.retain(|e| e.end > row);
        while table.last().is_some_and(|e| e.first == row) {
            active.extend(table.pop());
        }
        if active.is_empty() {
            if table.is_empty() {
                break;
            }
            continue;
        }
        let y = row as f64 + 0.5;
        crossings.clear();
        crossings.extend(active.iter().map(|e| (e.x_at(y), e.winding)));
        crossings.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut winding = 0;
        for pair in crossings.windows(2) {
            winding += pair[0].1;
            if !rule.inside(winding) {
                continue;
            }
            // Pixel centres i + 0.5 in [x_a, x_b).
            let lo = (pair[0].0 - 0.5).ceil().max(0.0);
            let hi = (pair[1].0 - 0.5).ceil().min(width as f64);
            for x in lo as i64..hi as i64 {
                plot.plot(x as u32, row as u32, 1.0);
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fill(contours: &[Vec<[f64; 2]>], rule: FillRule, size: [u32; 2], counts: &mut [u32]) {
        fill_polygon(contours, rule, size, &mut |x, y, _| {
            counts[(y * size[0] + x) as usize] += 1;
        })
        .unwrap();
    }

    /// Brute force: the winding number of the outline around `p`, by signed
    /// crossings of the ray to the right (half-open in y, as the fill).
    fn winding(contours: &[Vec<[f64; 2]>], p: [f64; 2]) -> i32 {
        let mut w = 0;
        for c in contours {
            for k in 0..c.len() {
                let (a, b) = (c[k], c[(k + 1) % c.len()]);
                let down = (a[1], a[0]) < (b[1], b[0]);
                let (u, l) = if down { (a, b) } else { (b, a) };
                if u[1] <= p[1] && p[1] < l[1] {
                    let x = u[0] + (p[1] - u[1]) / (l[1] - u[1]) * (l[0] - u[0]);
                    if x > p[0] {
                        w += if down { 1 } else { -1 };
                    }
                }
            }
        }
        w
    }

    /// A square cut into random polygons: a jittered grid's quads, some
    /// pairs merged into concave hexagons, some quads with a triangular
    /// hole that a polygon of its own fills. Every pixel exactly once,
    /// under both rules (every polygon is simple, so they agree).
    #[test]
    fn a_partition_covers_every_pixel_once() {
        let mut rng = fastrand::Rng::with_seed(21);
        let (n, cell) = (8usize, 16.0f64);
        let size = [(n as f64 * cell) as u32; 2];
        let (mut holes, mut merged) = (0, 0);
        for round in 0..20 {
            let grid: Vec<Vec<[f64; 2]>> = (0..=n)
                .map(|j| {
                    (0..=n)
                        .map(|i| {
                            let mut jitter = |k: usize| {
                                if k == 0 || k == n {
                                    0.0
                                } else {
                                    (rng.f64() - 0.5) * cell * 0.3
                                }
                            };
                            [i as f64 * cell + jitter(i), j as f64 * cell + jitter(j)]
                        })
                        .collect()
                })
                .collect();
            let mut polygons: Vec<Vec<Vec<[f64; 2]>>> = Vec::new();
            for j in 0..n {
                let mut i = 0;
                while i < n {
                    let merge = i + 1 < n && rng.bool();
                    merged += usize::from(merge);
                    let right = if merge { i + 2 } else { i + 1 };
                    let mut outline = vec![grid[j][i]];
                    outline.extend((i + 1..=right).map(|k| grid[j][k]));
                    outline.extend((i..=right).rev().map(|k| grid[j + 1][k]));
                    if !merge && rng.u8(0..4) == 0 {
                        // A triangular hole wound against the outline (so a
                        // hole under both rules), filled by a polygon of its own.
                        let corners = [
                            grid[j][i],
                            grid[j][i + 1],
                            grid[j + 1][i],
                            grid[j + 1][i + 1],
                        ];
                        let c = [0, 1].map(|a| corners.iter().map(|p| p[a]).sum::<f64>() / 4.0);
                        let hole = vec![
                            [c[0] - 2.5, c[1] - 1.7],
                            [c[0] + 0.3, c[1] + 2.9],
                            [c[0] + 2.6, c[1] - 2.1],
                        ];
                        holes += 1;
                        polygons.push(vec![outline, hole.clone()]);
                        polygons.push(vec![hole.into_iter().rev().collect()]);
                    } else {
                        polygons.push(vec![outline]);
                    }
                    i = right;
                }
            }
            for rule in [FillRule::EvenOdd, FillRule::NonZero] {
                let mut counts = vec![0; (size[0] * size[1]) as usize];
                for p in &polygons {
                    fill(p, rule, size, &mut counts);
                }
                if let Some(k) = counts.iter().position(|&c| c != 1) {
                    panic!(
                        "round {round} {rule:?}: pixel {k} covered {} times",
                        counts[k]
                    );
                }
            }
        }
        assert!(holes > 50 && merged > 200, "{holes} holes, {merged} merged");
    }

    fn star(centre: [f64; 2], radius: f64, points: usize, step: usize) -> Vec<[f64; 2]> {
        (0..points)
            .map(|k| {
                let a = std::f64::consts::TAU * (k * step % points) as f64 / points as f64 + 0.1;
                [centre[0] + radius * a.cos(), centre[1] + radius * a.sin()]
            })
            .collect()
    }

    /// Self-intersecting stars and holes of both orientations: each rule
    /// fills exactly where the brute-force winding number says, so the
    /// rules differ exactly where it is even and not zero.
    #[test]
    fn even_odd_and_non_zero_follow_the_winding_number() {
        let shapes: Vec<Vec<Vec<[f64; 2]>>> = vec![
            vec![star([40.0, 40.0], 35.0, 5, 2)],
            vec![star([40.0, 40.0], 35.0, 7, 3)],
            vec![star([40.0, 40.0], 35.0, 7, 2)],
            // A square with a hole wound the same way (non-zero keeps it
            // filled) and one wound the other way (a hole under both).
            vec![
                vec![[5.0, 5.0], [75.0, 5.0], [75.0, 75.0], [5.0, 75.0]],
                vec![[20.0, 20.0], [40.0, 20.0], [40.0, 40.0], [20.0, 40.0]],
                vec![[50.0, 60.0], [60.0, 60.0], [60.0, 50.0], [50.0, 50.0]],
            ],
        ];
        let size = [80u32, 80];
        let mut differ = 0;
        for (s, shape) in shapes.iter().enumerate() {
            for rule in [FillRule::EvenOdd, FillRule::NonZero] {
                let mut counts = vec![0; 6400];
                fill(shape, rule, size, &mut counts);
                for y in 0..80 {
                    for x in 0..80 {
                        let w = winding(shape, [x as f64 + 0.5, y as f64 + 0.5]);
                        let k = y * 80 + x;
                        assert_eq!(
                            counts[k],
                            u32::from(rule.inside(w)),
                            "shape {s} {rule:?} ({x}, {y}) winding {w}"
                        );
                        differ += usize::from(rule == FillRule::NonZero && w != 0 && w % 2 == 0);
                    }
                }
            }
        }
        assert!(differ > 500, "the rules differ at only {differ} pixels");
    }

    #[test]
    fn bad_and_degenerate_polygons() {
        let mut n = 0;
        let mut plot = |_, _, _| n += 1;
        let size = [16, 16];
        let e = fill_polygon(
            &[vec![[0.0, 0.0], [f64::NAN, 1.0], [3.0, 3.0]]],
            FillRule::NonZero,
            size,
            &mut plot,
        );
        assert_eq!(e.unwrap_err().field, "polygon");
        for degenerate in [
            vec![],
            vec![[1.0, 1.0]],
            vec![[1.0, 1.0], [9.0, 9.0]],
            vec![[0.0, 0.0], [4.0, 4.0], [8.0, 8.0]],
        ] {
            fill_polygon(&[degenerate], FillRule::NonZero, size, &mut plot).unwrap();
        }
        // Far outside: clipped, bounded by the image.
        fill_polygon(
            &[vec![[-1e15, -1e15], [1e15, -1e15], [0.0, 1e15]]],
            FillRule::EvenOdd,
            size,
            &mut plot,
        )
        .unwrap();
        assert_eq!(n, 256);
    }
}
