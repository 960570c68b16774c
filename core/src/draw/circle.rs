//! The midpoint (Bresenham) circle with eight-way symmetry, and the disc it
//! bounds (Saarland lecture, "Bresenham: Circle").
//!
//! One octant is walked, from `(0, R)` while `x ≤ y`, by the sign of the
//! decision variable `F(x + 1, y − ½) = (x + 1)² + (y − ½)² − R²` (kept as
//! `4F`, in integers), updated by adds only; the other seven octants are its
//! mirror images. `4F` is never zero (an odd square is never a multiple of
//! four), so in each column of the octant the pixel drawn is the one nearest
//! the circle: `y = round(√(R² − x²))`.

use super::Plot;
use super::line::MAX_INDEX;
use crate::ground::FieldError;

/// Largest radius drawn (the work grows with the radius, not the image).
pub const MAX_RADIUS: i64 = 1 << 20;

/// The octant from `(0, R)` to the diagonal: `(x, y)` offsets, `x ≤ y`.
fn octant(radius: i64) -> Vec<(i64, i64)> {
    let (mut x, mut y) = (0, radius);
    let mut d = 5 - 4 * radius;
    let mut points = Vec::new();
    while x <= y {
        points.push((x, y));
        if d < 0 {
            d += 4 * (2 * x + 3);
        } else {
            d += 4 * (2 * (x - y) + 5);
            y -= 1;
        }
        x += 1;
    }
    points
}

fn check(centre: [i64; 2], radius: i64) -> Result<bool, FieldError> {
    if let Some(c) = centre.iter().find(|c| c.abs() > MAX_INDEX) {
        return Err(FieldError::new(
            "centre",
            format!("pixel index {c} is beyond ±2⁴⁰"),
        ));
    }
    if !(0..=MAX_RADIUS).contains(&radius) {
        return Err(FieldError::new(
            "radius",
            format!("{radius} is not in 0..=2²⁰"),
        ));
    }
    Ok(radius > 0)
}

/// Plots `(centre + offset)` when inside the image.
fn put(size: [u32; 2], centre: [i64; 2], (dx, dy): (i64, i64), plot: &mut impl Plot) {
    let (x, y) = (centre[0] + dx, centre[1] + dy);
    if (0..i64::from(size[0])).contains(&x) && (0..i64::from(size[1])).contains(&y) {
        plot.plot(x as u32, y as u32, 1.0);
    }
}

/// The circle of `radius` pixels around pixel `centre`: each pixel once (the
/// mirror images that coincide, on the axes and diagonals, drawn once).
/// Radius 0 draws nothing.
pub fn midpoint_circle(
    centre: [i64; 2],
    radius: i64,
    size: [u32; 2],
    plot: &mut impl Plot,
) -> Result<(), FieldError> {
    if !check(centre, radius)? || off_image(centre, radius, size) {
        return Ok(());
    }
    let mut points: Vec<(i64, i64)> = octant(radius)
        .into_iter()
        .flat_map(|(x, y)| {
            [
                (x, y),
                (y, x),
                (-x, y),
                (-y, x),
                (x, -y),
                (y, -x),
                (-x, -y),
                (-y, -x),
            ]
        })
        .collect();
    points.sort_unstable_by_key(|&(x, y)| (y, x));
    points.dedup();
    for p in points {
        put(size, centre, p, plot);
    }
    Ok(())
}

/// The disc the midpoint circle bounds: in each row, every pixel from its
/// leftmost to its rightmost circle pixel. Radius 0 draws nothing.
pub fn midpoint_disc(
    centre: [i64; 2],
    radius: i64,
    size: [u32; 2],
    plot: &mut impl Plot,
) -> Result<(), FieldError> {
    if !check(centre, radius)? || off_image(centre, radius, size) {
        return Ok(());
    }
    // Half-width of each row offset 0..=R.
    let mut half = vec![0i64; radius as usize + 1];
    for (x, y) in octant(radius) {
        half[y as usize] = half[y as usize].max(x);
        half[x as usize] = half[x as usize].max(y);
    }
    let (w, h) = (i64::from(size[0]), i64::from(size[1]));
    for dy in -radius..=radius {
        let y = centre[1] + dy;
        if !(0..h).contains(&y) {
            continue;
        }
        let hw = half[dy.unsigned_abs() as usize];
        for x in (centre[0] - hw).max(0)..=(centre[0] + hw).min(w - 1) {
            plot.plot(x as u32, y as u32, 1.0);
        }
    }
    Ok(())
}

/// The circle's box misses the image.
fn off_image(c: [i64; 2], r: i64, size: [u32; 2]) -> bool {
    c[0] + r < 0 || c[1] + r < 0 || c[0] - r >= i64::from(size[0]) || c[1] - r >= i64::from(size[1])
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashSet;

    fn offsets(radius: i64, disc: bool) -> Vec<(i64, i64)> {
        let size = [2 * radius as u32 + 3; 2];
        let c = [radius + 1; 2];
        let mut out = Vec::new();
        let mut plot = |x: u32, y: u32, _| out.push((i64::from(x) - c[0], i64::from(y) - c[1]));
        if disc {
            midpoint_disc(c, radius, size, &mut plot).unwrap();
        } else {
            midpoint_circle(c, radius, size, &mut plot).unwrap();
        }
        out
    }

    /// Brute force: `(a, b)` with `|a| ≤ |b|` is on the circle when `|b|` is
    /// the integer nearest `√(R² − a²)`: `(2|b| − 1)² < 4(R² − a²) < (2|b| + 1)²`.
    fn on_circle(r: i64, (a, b): (i64, i64)) -> bool {
        let (a, b) = (a.abs().min(b.abs()), a.abs().max(b.abs()));
        let s = 4 * (r * r - a * a);
        a <= b && (2 * b - 1).pow(2) < s && s < (2 * b + 1).pow(2)
    }

    #[test]
    fn circles_are_eight_way_symmetric_and_the_nearest_pixels() {
        let mut checked = 0;
        for r in 1..=120 {
            let got = offsets(r, false);
            let set: HashSet<_> = got.iter().copied().collect();
            assert_eq!(set.len(), got.len(), "r {r}: a pixel drawn twice");
            for &(x, y) in &got {
                for m in [(y, x), (-x, y), (x, -y), (-y, -x)] {
                    assert!(
                        set.contains(&m),
                        "r {r}: ({x}, {y}) without its mirror {m:?}"
                    );
                }
            }
            let brute: HashSet<_> = (-r - 1..=r + 1)
                .flat_map(|a| (-r - 1..=r + 1).map(move |b| (a, b)))
                .filter(|&p| on_circle(r, p))
                .collect();
            assert_eq!(set, brute, "r {r}");
            checked += 1;
        }
        assert_eq!(checked, 120);
    }

    #[test]
    fn discs_fill_between_their_circle_once_per_pixel() {
        for r in 1..=60 {
            let disc = offsets(r, true);
            let set: HashSet<_> = disc.iter().copied().collect();
            assert_eq!(set.len(), disc.len(), "r {r}: a pixel drawn twice");
            let circle = offsets(r, false);
            for b in -r..=r {
                let row: Vec<i64> = circle.iter().filter(|p| p.1 == b).map(|p| p.0).collect();
                let (lo, hi) = (*row.iter().min().unwrap(), *row.iter().max().unwrap());
                let filled: Vec<i64> = disc.iter().filter(|p| p.1 == b).map(|p| p.0).collect();
                assert_eq!(filled, (lo..=hi).collect::<Vec<_>>(), "r {r} row {b}");
            }
            let area = std::f64::consts::PI * (r as f64 + 0.5).powi(2);
            assert!((disc.len() as f64 - area).abs() < 2.0 * std::f64::consts::PI * r as f64);
        }
    }

    #[test]
    fn bad_and_far_circles() {
        let mut n = 0;
        let mut plot = |_, _, _| n += 1;
        assert_eq!(
            midpoint_circle([0, 0], -1, [8, 8], &mut plot)
                .unwrap_err()
                .field,
            "radius"
        );
        assert_eq!(
            midpoint_disc([0, 0], 1 << 21, [8, 8], &mut plot)
                .unwrap_err()
                .field,
            "radius"
        );
        assert_eq!(
            midpoint_circle([1 << 41, 0], 1, [8, 8], &mut plot)
                .unwrap_err()
                .field,
            "centre"
        );
        midpoint_circle([3, 3], 0, [8, 8], &mut plot).unwrap();
        midpoint_disc([1 << 30, 3], 5, [8, 8], &mut plot).unwrap();
        assert_eq!(n, 0);
    }
}
