//! Lines one pixel wide: the DDA and the integer Bresenham algorithm in all
//! eight octants (Saarland lecture, "Lines: DDA", "Lines: Bresenham",
//! "Lines: Integer Bresenham", "Lines: Arbitrary Directions").
//!
//! The lecture's goal: along the driving axis (the longer of the two), one
//! pixel per column (or row), the one whose centre is closest to the line.

use super::{Plot, finite};
use crate::ground::FieldError;

/// Largest pixel index magnitude [`bresenham`] takes (its arithmetic is exact in `i64`).
pub const MAX_INDEX: i64 = 1 << 40;

/// The integer Bresenham line from pixel `p0` to pixel `p1` (both drawn): on
/// the driving axis every index from `p0`'s to `p1`'s, across it the index
/// nearest the line through the two centres, a tie (the line exactly between
/// two centres) going to the one nearer `p0`. Only adds and compares per
/// pixel: the decision variable `D = 2i·|dv| + n − 1 − 2n·j` stays in
/// `0..2n`, stepping by `2|dv|` and, when it reaches `2n`, moving across.
/// Clipped to the image by starting at the first column inside it, with
/// the decision variable computed there. A zero-length line draws nothing.
pub fn bresenham(
    p0: [i64; 2],
    p1: [i64; 2],
    size: [u32; 2],
    plot: &mut impl Plot,
) -> Result<(), FieldError> {
    if let Some(c) = p0.iter().chain(&p1).find(|c| c.abs() > MAX_INDEX) {
        return Err(FieldError::new(
            "line",
            format!("pixel index {c} is beyond ±2⁴⁰"),
        ));
    }
    let (dx, dy) = (p1[0] - p0[0], p1[1] - p0[1]);
    if dx == 0 && dy == 0 {
        return Ok(());
    }
    // Driving axis u, the other v; `axis` 0 when x drives.
    let axis = usize::from(dy.abs() > dx.abs());
    let (u0, v0) = (p0[axis], p0[1 - axis]);
    let (du, dv) = ([dx, dy][axis], [dx, dy][1 - axis]);
    let (su, sv, n, m) = (du.signum(), dv.signum(), du.abs(), dv.abs());
    let (u_len, v_len) = (i64::from(size[axis]), i64::from(size[1 - axis]));
    // Steps i (0..=n) whose u lies inside the image.
    let (mut first, last) = {
        let (a, b) = ((0 - u0) * su, (u_len - 1 - u0) * su);
        (a.min(b).max(0), a.max(b).min(n))
    };
    if first > last {
        return Ok(());
    }
    // j at step `first`, exactly: floor((2·i·m + n − 1) / (2n)).
    let num = 2 * i128::from(first) * i128::from(m) + i128::from(n) - 1;
    let mut j = (num / (2 * i128::from(n))) as i64;
    let mut d = (num - 2 * i128::from(n) * i128::from(j)) as i64;
    while first <= last {
        let (u, v) = (u0 + su * first, v0 + sv * j);
        if (0..v_len).contains(&v) {
            let mut p = [0u32; 2];
            p[axis] = u as u32;
            p[1 - axis] = v as u32;
            plot.plot(p[0], p[1], 1.0);
        }
        first += 1;
        d += 2 * m;
        if d >= 2 * n {
            d -= 2 * n;
            j += 1;
        }
    }
    Ok(())
}

/// The DDA from image point `a` to `b`: along the driving axis every pixel
/// whose centre lies between the two points' (both ends included), across
/// it the pixel holding the line's point there, that point stepped by the
/// slope from pixel to pixel (`y_{i+1} = y_i + m`, in f64: the error the
/// lecture warns of accumulates, and a point exactly between two pixels goes
/// to the lower-right one). A line shorter than a pixel centre's spacing
/// on its driving axis may draw nothing.
pub fn dda(
    a: [f64; 2],
    b: [f64; 2],
    size: [u32; 2],
    plot: &mut impl Plot,
) -> Result<(), FieldError> {
    finite("line", &[a, b])?;
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    if dx == 0.0 && dy == 0.0 {
        return Ok(());
    }
    let axis = usize::from(dy.abs() > dx.abs());
    let (mut p, mut q) = (a, b);
    if p[axis] > q[axis] {
        std::mem::swap(&mut p, &mut q);
    }
    let slope = (q[1 - axis] - p[1 - axis]) / (q[axis] - p[axis]);
    let (u_len, v_len) = (f64::from(size[axis]), f64::from(size[1 - axis]));
    // Pixel centres c + 0.5 in [p, q], within the image.
    let first = (p[axis] - 0.5).ceil().max(0.0);
    let last = (q[axis] - 0.5).floor().min(u_len - 1.0);
    if first > last {
        return Ok(());
    }
    let mut v = p[1 - axis] + slope * (first + 0.5 - p[axis]);
    let mut u = first;
    while u <= last {
        let row = v.floor();
        if (0.0..v_len).contains(&row) {
            let mut at = [0u32; 2];
            at[axis] = u as u32;
            at[1 - axis] = row as u32;
            plot.plot(at[0], at[1], 1.0);
        }
        v += slope;
        u += 1.0;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pixels_bresenham(p0: [i64; 2], p1: [i64; 2], size: [u32; 2]) -> Vec<[u32; 2]> {
        let mut out = Vec::new();
        bresenham(p0, p1, size, &mut |x, y, _| out.push([x, y])).unwrap();
        out
    }

    /// The lecture's definition, by exact rationals: per index on the
    /// driving axis, the nearest index across it, ties toward `p0`.
    fn definition(p0: [i64; 2], p1: [i64; 2]) -> Vec<[i64; 2]> {
        let (dx, dy) = (p1[0] - p0[0], p1[1] - p0[1]);
        let axis = usize::from(dy.abs() > dx.abs());
        let (du, dv) = ([dx, dy][axis], [dx, dy][1 - axis]);
        let n = du.abs();
        (0..=n)
            .map(|i| {
                // v offset = i·dv/n, nearest integer, ties toward 0.
                let (num, den) = (i * dv.abs(), n);
                let (q, r) = (num / den, num % den);
                let j = if 2 * r > den { q + 1 } else { q };
                let mut p = [0; 2];
                p[axis] = p0[axis] + du.signum() * i;
                p[1 - axis] = p0[1 - axis] + dv.signum() * j;
                p
            })
            .collect()
    }

    #[test]
    fn bresenham_is_the_nearest_pixel_per_column_in_every_octant() {
        let mut rng = fastrand::Rng::with_seed(11);
        let mut octants = [0usize; 8];
        for _ in 0..5000 {
            let p0 = [rng.i64(0..200), rng.i64(0..200)];
            let p1 = [rng.i64(0..200), rng.i64(0..200)];
            if p0 == p1 {
                continue;
            }
            let (dx, dy) = (p1[0] - p0[0], p1[1] - p0[1]);
            octants[usize::from(dx < 0) * 4
                + usize::from(dy < 0) * 2
                + usize::from(dy.abs() > dx.abs())] += 1;
            let want: Vec<[u32; 2]> = definition(p0, p1)
                .into_iter()
                .map(|p| [p[0] as u32, p[1] as u32])
                .collect();
            assert_eq!(
                pixels_bresenham(p0, p1, [200, 200]),
                want,
                "{p0:?} → {p1:?}"
            );
        }
        assert!(octants.iter().all(|&n| n > 400), "octants {octants:?}");
    }

    /// Clipping: the pixels inside a small image are exactly those of the
    /// unclipped line that fall inside it, for lines from far outside.
    #[test]
    fn clipped_lines_keep_the_unclipped_pixels() {
        let mut rng = fastrand::Rng::with_seed(12);
        let mut drawn = 0;
        for _ in 0..3000 {
            let p0 = [rng.i64(-300..340), rng.i64(-300..340)];
            let p1 = [rng.i64(-300..340), rng.i64(-300..340)];
            if p0 == p1 {
                continue;
            }
            let want: Vec<[u32; 2]> = definition(p0, p1)
                .into_iter()
                .filter(|p| (0..40).contains(&p[0]) && (0..30).contains(&p[1]))
                .map(|p| [p[0] as u32, p[1] as u32])
                .collect();
            let got = pixels_bresenham(p0, p1, [40, 30]);
            assert_eq!(got, want, "{p0:?} → {p1:?}");
            drawn += got.len();
        }
        assert!(drawn > 1000, "{drawn}");
        // Far outside: bounded work, nothing drawn.
        assert!(pixels_bresenham([-MAX_INDEX, 5], [MAX_INDEX, 7], [0, 0]).is_empty());
        assert_eq!(
            pixels_bresenham([-MAX_INDEX, 5], [MAX_INDEX, 5], [40, 30]).len(),
            40
        );
        assert!(bresenham([MAX_INDEX + 1, 0], [0, 0], [4, 4], &mut |_, _, _| {}).is_err());
    }

    /// The DDA on pixel centres draws Bresenham's pixels wherever no column
    /// is a tie (ties round the other way: toward larger indices).
    #[test]
    fn dda_agrees_with_bresenham_off_ties() {
        let mut rng = fastrand::Rng::with_seed(13);
        let mut compared = 0;
        for _ in 0..3000 {
            let p0 = [rng.i64(0..120), rng.i64(0..120)];
            let p1 = [rng.i64(0..120), rng.i64(0..120)];
            let (dx, dy) = (p1[0] - p0[0], p1[1] - p0[1]);
            let n = dx.abs().max(dy.abs());
            let m = dx.abs().min(dy.abs());
            if n == 0 || (0..=n).any(|i| 2 * (i * m % n) == n) {
                continue;
            }
            let centre = |p: [i64; 2]| [p[0] as f64 + 0.5, p[1] as f64 + 0.5];
            let mut got = Vec::new();
            dda(centre(p0), centre(p1), [120, 120], &mut |x, y, _| {
                got.push([x, y]);
            })
            .unwrap();
            let mut want = pixels_bresenham(p0, p1, [120, 120]);
            got.sort_unstable();
            want.sort_unstable();
            assert_eq!(got, want, "{p0:?} → {p1:?}");
            compared += 1;
        }
        assert!(compared > 1000, "{compared}");
    }

    #[test]
    fn bad_and_degenerate_lines() {
        let mut n = 0;
        assert!(pixels_bresenham([3, 3], [3, 3], [8, 8]).is_empty());
        dda([2.0, 2.0], [2.0, 2.0], [8, 8], &mut |_, _, _| n += 1).unwrap();
        let e = dda([f64::NAN, 0.0], [1.0, 1.0], [8, 8], &mut |_, _, _| n += 1).unwrap_err();
        assert_eq!(e.field, "line");
        assert!(dda([1e17, 0.0], [1.0, 1.0], [8, 8], &mut |_, _, _| n += 1).is_err());
        dda([-1e15, 3.5], [1e15, 3.5], [8, 8], &mut |_, _, _| n += 1).unwrap();
        assert_eq!(n, 8);
    }
}
