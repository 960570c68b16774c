//! Anti-aliased and thick lines: a polyline stroked to a width, with butt,
//! square or round caps and bevel, miter or round joins (Saarland lecture,
//! "Thick Lines": "Real solution: draw 2D area … allows for anti-aliasing
//! and fractional width", and "Handling Start and End Points": joins,
//! caps, "avoid overdraw when lines join").
//!
//! The stroke is the union of convex pieces — each segment's rectangle, the
//! caps, the join wedges or discs — and each pixel is drawn once, with the
//! share of its anti-aliasing positions ([`super::sample_positions`]) inside that union: the same
//! positions the triangle rasterizers test for the same `--aa` mode, and no
//! pixel covered twice where segments meet.

use super::{Plot, finite};
use crate::ground::FieldError;

/// How a stroke ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cap {
    /// At the end point, square to the line.
    Butt,
    /// Half the width beyond the end point, square.
    Square,
    /// A half disc of the stroke's width around the end point.
    Round,
}

/// How a stroke turns a corner.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Join {
    /// The outer corners joined by a straight line.
    Bevel,
    /// The outer edges extended to where they meet (a bevel beyond the limit).
    Miter,
    /// A disc of the stroke's width around the corner.
    Round,
}

/// A stroke's shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stroke {
    /// Width in pixels (> 0).
    pub width: f64,
    pub cap: Cap,
    pub join: Join,
    /// Longest miter, as a multiple of the width, before it is bevelled (SVG's 4).
    pub miter_limit: f64,
}

impl Stroke {
    /// `width` pixels wide, butt caps and bevel joins.
    pub fn new(width: f64) -> Stroke {
        Stroke {
            width,
            cap: Cap::Butt,
            join: Join::Bevel,
            miter_limit: 4.0,
        }
    }
}

/// One convex piece of a stroke.
#[derive(Clone, Debug)]
enum Piece {
    /// A convex polygon, counter-clockwise in a y-down image (inside: every
    /// edge's cross product ≥ 0).
    Convex(Vec<[f64; 2]>),
    Disc {
        centre: [f64; 2],
        radius: f64,
    },
}

impl Piece {
    fn convex(mut points: Vec<[f64; 2]>) -> Piece {
        let n = points.len();
        let area: f64 = (0..n).map(|k| cross(points[k], points[(k + 1) % n])).sum();
        if area < 0.0 {
            points.reverse();
        }
        Piece::Convex(points)
    }

    fn contains(&self, p: [f64; 2]) -> bool {
        match self {
            Piece::Convex(v) => (0..v.len()).all(|k| {
                let (a, b) = (v[k], v[(k + 1) % v.len()]);
                cross(sub(b, a), sub(p, a)) >= 0.0
            }),
            Piece::Disc { centre, radius } => {
                let d = sub(p, *centre);
                d[0] * d[0] + d[1] * d[1] <= radius * radius
            }
        }
    }

    /// The piece's extent in x between the lines `y0` and `y1`, if it reaches them.
    fn x_range(&self, y0: f64, y1: f64) -> Option<[f64; 2]> {
        match self {
            Piece::Convex(v) => {
                let mut range: Option<[f64; 2]> = None;
                let mut add = |x: f64| {
                    let r = range.get_or_insert([x, x]);
                    *r = [r[0].min(x), r[1].max(x)];
                };
                for k in 0..v.len() {
                    let (a, b) = (v[k], v[(k + 1) % v.len()]);
                    if (y0..=y1).contains(&a[1]) {
                        add(a[0]);
                    }
                    for y in [y0, y1] {
                        if (a[1] - y) * (b[1] - y) < 0.0 {
                            add(a[0] + (y - a[1]) / (b[1] - a[1]) * (b[0] - a[0]));
                        }
                    }
                }
                range
            }
            Piece::Disc { centre, radius } => {
                let nearest = centre[1].clamp(y0, y1);
                let dy = nearest - centre[1];
                let half = (radius * radius - dy * dy).sqrt();
                (half >= 0.0).then(|| [centre[0] - half, centre[0] + half])
            }
        }
    }
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

fn along(p: [f64; 2], d: [f64; 2], s: f64) -> [f64; 2] {
    [p[0] + d[0] * s, p[1] + d[1] * s]
}

/// The convex pieces of the stroke of `points` (consecutive duplicates
/// removed; at least two points).
fn pieces(points: &[[f64; 2]], style: &Stroke) -> Vec<Piece> {
    let h = style.width / 2.0;
    let unit = |a: [f64; 2], b: [f64; 2]| {
        let d = sub(b, a);
        let len = d[0].hypot(d[1]);
        [d[0] / len, d[1] / len]
    };
    let normal = |d: [f64; 2]| [-d[1], d[0]];
    let mut out = Vec::new();
    for w in points.windows(2) {
        let n = normal(unit(w[0], w[1]));
        out.push(Piece::convex(vec![
            along(w[0], n, h),
            along(w[1], n, h),
            along(w[1], n, -h),
            along(w[0], n, -h),
        ]));
    }
    let last = points.len() - 1;
    for (end, inward) in [(points[0], points[1]), (points[last], points[last - 1])] {
        let d = unit(inward, end);
        let n = normal(d);
        match style.cap {
            Cap::Butt => {}
            Cap::Square => out.push(Piece::convex(vec![
                along(end, n, h),
                along(along(end, n, h), d, h),
                along(along(end, n, -h), d, h),
                along(end, n, -h),
            ])),
            Cap::Round => out.push(Piece::Disc {
                centre: end,
                radius: h,
            }),
        }
    }
    for w in points.windows(3) {
        let (d1, d2) = (unit(w[0], w[1]), unit(w[1], w[2]));
        let turn = cross(d1, d2);
        let p = w[1];
        if style.join == Join::Round {
            out.push(Piece::Disc {
                centre: p,
                radius: h,
            });
            continue;
        }
        if turn == 0.0 {
            continue; // straight on (or straight back): the rectangles meet
        }
        // The outer side, away from the turn.
        let s = -turn.signum() * h;
        let (n1, n2) = (normal(d1), normal(d2));
        let (o1, o2) = (along(p, n1, s), along(p, n2, s));
        let cos = n1[0] * n2[0] + n1[1] * n2[1];
        // Miter length over width: 1 / cos(θ/2) = √(2 / (1 + cos θ)).
        let miter = style.join == Join::Miter
            && cos > -1.0
            && (2.0 / (1.0 + cos)).sqrt() <= style.miter_limit;
        if miter {
            let bisector = [n1[0] + n2[0], n1[1] + n2[1]];
            let tip = along(p, bisector, s / (1.0 + cos));
            out.push(Piece::convex(vec![p, o1, tip, o2]));
        } else {
            out.push(Piece::convex(vec![p, o1, o2]));
        }
    }
    out
}

/// Strokes the polyline `points` with `style`: each pixel of the image the
/// stroke reaches once, with the share of the sample `positions` (within
/// a pixel, [`super::sample_positions`]) inside it.
/// Fewer than two distinct points draw nothing; a width that is not a
/// positive number is an error naming `width`, a point that is not finite
/// one naming `stroke`.
pub fn stroke(
    points: &[[f64; 2]],
    style: &Stroke,
    positions: &[[f32; 2]],
    size: [u32; 2],
    plot: &mut impl Plot,
) -> Result<(), FieldError> {
    finite("stroke", points)?;
    if !(style.width > 0.0 && style.width <= super::MAX_COORDINATE) {
        return Err(FieldError::new(
            "width",
            format!("{} is not a positive number of pixels", style.width),
        ));
    }
    if style.miter_limit.is_nan() || style.miter_limit < 1.0 {
        return Err(FieldError::new(
            "miter_limit",
            format!("{} is not at least 1", style.miter_limit),
        ));
    }
    let mut distinct = points.to_vec();
    distinct.dedup();
    if distinct.len() < 2 {
        return Ok(());
    }
    let pieces = pieces(&distinct, style);
    if positions.is_empty() {
        return Err(FieldError::new("aa", "no sample positions"));
    }
    let share = 1.0 / positions.len() as f32;
    let (width, height) = (f64::from(size[0]), f64::from(size[1]));
    // Rows the stroke reaches: the pieces' extents, within the image.
    let reach = distinct
        .iter()
        .fold([f64::INFINITY, f64::NEG_INFINITY], |r, p| {
            [r[0].min(p[1]), r[1].max(p[1])]
        });
    let pad = style.width * style.miter_limit;
    let first = (reach[0] - pad).floor().max(0.0) as u32;
    let end = (reach[1] + pad).ceil().min(height).max(0.0) as u32;
    let mut spans: Vec<([f64; 2], usize)> = Vec::new();
    for y in first..end {
        let (y0, y1) = (f64::from(y), f64::from(y + 1));
        spans.clear();
        spans.extend(
            pieces
                .iter()
                .enumerate()
                .filter_map(|(k, p)| Some((p.x_range(y0, y1)?, k))),
        );
        spans.sort_by(|a, b| a.0[0].total_cmp(&b.0[0]));
        // Pixels in the merged spans, each once, tested against the pieces
        // whose span reaches it.
        let mut next = 0.0f64;
        for &([lo, hi], _) in &spans {
            let from = lo.floor().max(next).max(0.0);
            let to = hi.floor().min(width - 1.0);
            let mut x = from;
            while x <= to {
                let inside = positions
                    .iter()
                    .filter(|[ox, oy]| {
                        let p = [x + f64::from(*ox), y0 + f64::from(*oy)];
                        (spans.iter())
                            .any(|&([a, b], k)| a <= x + 1.0 && b >= x && pieces[k].contains(p))
                    })
                    .count();
                if inside > 0 {
                    plot.plot(x as u32, y, inside as f32 * share);
                }
                x += 1.0;
            }
            next = next.max(to + 1.0);
        }
    }
    Ok(())
}

/// An anti-aliased line from `a` to `b`, `width` pixels wide, butt ends: a
/// pixel's coverage is the share of the sample `positions` within the line's
/// rectangle (so `--aa none` draws the pixels whose centres it holds).
pub fn aa_line(
    a: [f64; 2],
    b: [f64; 2],
    width: f64,
    positions: &[[f32; 2]],
    size: [u32; 2],
    plot: &mut impl Plot,
) -> Result<(), FieldError> {
    stroke(&[a, b], &Stroke::new(width), positions, size, plot)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aa::AaMode;
    use crate::draw::sample_positions;
    use std::collections::HashMap;

    const SIZE: [u32; 2] = [64, 48];

    fn coverage(
        points: &[[f64; 2]],
        style: &Stroke,
        pattern: &[[f32; 2]],
    ) -> HashMap<(u32, u32), f32> {
        let mut out = HashMap::new();
        stroke(points, style, pattern, SIZE, &mut |x, y, c| {
            assert!(out.insert((x, y), c).is_none(), "({x}, {y}) drawn twice");
        })
        .unwrap();
        out
    }

    /// Brute force over every pixel of the image: the share of positions
    /// for which `inside` holds.
    fn brute(pattern: &[[f32; 2]], inside: impl Fn([f64; 2]) -> bool) -> HashMap<(u32, u32), f32> {
        let mut out = HashMap::new();
        for y in 0..SIZE[1] {
            for x in 0..SIZE[0] {
                let n = (pattern.iter())
                    .filter(|[ox, oy]| {
                        inside([f64::from(x) + f64::from(*ox), f64::from(y) + f64::from(*oy)])
                    })
                    .count();
                if n > 0 {
                    out.insert((x, y), n as f32 / pattern.len() as f32);
                }
            }
        }
        out
    }

    fn distance_to_segment(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
        let (d, v) = (sub(b, a), sub(p, a));
        let t = ((v[0] * d[0] + v[1] * d[1]) / (d[0] * d[0] + d[1] * d[1])).clamp(0.0, 1.0);
        let q = along(a, d, t);
        (p[0] - q[0]).hypot(p[1] - q[1])
    }

    fn patterns() -> Vec<Vec<[f32; 2]>> {
        ["none", "msaa:4", "ssaa:16", "csaa:8x2"]
            .map(|m| sample_positions(AaMode::parse(m).unwrap()))
            .to_vec()
    }

    fn random_polyline(rng: &mut fastrand::Rng, n: usize) -> Vec<[f64; 2]> {
        (0..n)
            .map(|_| [rng.f64() * 70.0 - 3.0, rng.f64() * 54.0 - 3.0])
            .collect()
    }

    /// Anti-aliased lines: each pixel's coverage is the share of the mode's
    /// positions inside the line's rectangle, as a brute force finds it.
    #[test]
    fn aa_lines_cover_the_pattern_positions_in_their_rectangle() {
        let mut rng = fastrand::Rng::with_seed(31);
        let mut pixels = 0;
        for pattern in patterns() {
            for _ in 0..40 {
                let (a, b) = (
                    random_polyline(&mut rng, 1)[0],
                    random_polyline(&mut rng, 1)[0],
                );
                let width = 0.5 + rng.f64() * 3.0;
                let mut got = HashMap::new();
                aa_line(a, b, width, &pattern, SIZE, &mut |x, y, c| {
                    assert!(got.insert((x, y), c).is_none());
                })
                .unwrap();
                let len = (b[0] - a[0]).hypot(b[1] - a[1]);
                let d = [(b[0] - a[0]) / len, (b[1] - a[1]) / len];
                let want = brute(&pattern, |p| {
                    let v = sub(p, a);
                    let t = v[0] * d[0] + v[1] * d[1];
                    (0.0..=len).contains(&t) && cross(d, v).abs() <= width / 2.0
                });
                assert_eq!(got, want, "{a:?} → {b:?} width {width}");
                pixels += got.len();
            }
        }
        assert!(pixels > 10_000, "{pixels}");
    }

    /// Round caps and round joins: exactly the samples within half the width
    /// of the polyline (a brute-force distance test), each pixel once.
    #[test]
    fn round_strokes_are_the_points_near_the_polyline() {
        let mut rng = fastrand::Rng::with_seed(32);
        let style = Stroke {
            cap: Cap::Round,
            join: Join::Round,
            ..Stroke::new(0.0)
        };
        let mut pixels = 0;
        for pattern in patterns() {
            for _ in 0..25 {
                let n = 2 + rng.usize(0..5);
                let line = random_polyline(&mut rng, n);
                let style = Stroke {
                    width: 1.0 + rng.f64() * 6.0,
                    ..style
                };
                let got = coverage(&line, &style, &pattern);
                let want = brute(&pattern, |p| {
                    line.windows(2)
                        .any(|w| distance_to_segment(p, w[0], w[1]) <= style.width / 2.0)
                });
                assert_eq!(got, want, "{line:?} width {}", style.width);
                pixels += got.len();
            }
        }
        assert!(pixels > 10_000, "{pixels}");
    }

    /// Joins nest (bevel within round within an unlimited miter) and so do
    /// caps (butt within round within square), pixel by pixel; no pixel is
    /// drawn twice at a join (asserted by `coverage`).
    #[test]
    fn joins_and_caps_nest() {
        let mut rng = fastrand::Rng::with_seed(33);
        let pattern = sample_positions(AaMode::parse("ssaa:16").unwrap());
        let mut strictly = [0; 2];
        for _ in 0..60 {
            let n = 3 + rng.usize(0..3);
            let line = random_polyline(&mut rng, n);
            let width = 2.0 + rng.f64() * 5.0;
            let of = |cap, join| {
                coverage(
                    &line,
                    &Stroke {
                        width,
                        cap,
                        join,
                        miter_limit: 1e9,
                    },
                    &pattern,
                )
            };
            let at = |m: &HashMap<(u32, u32), f32>, k| m.get(k).copied().unwrap_or(0.0);
            let joins = [Join::Bevel, Join::Round, Join::Miter].map(|j| of(Cap::Butt, j));
            let caps = [Cap::Butt, Cap::Round, Cap::Square].map(|c| of(c, Join::Bevel));
            for (k, nested) in [joins, caps].iter().enumerate() {
                for (p, _) in nested[2].iter() {
                    assert!(
                        at(&nested[0], p) <= at(&nested[1], p)
                            && at(&nested[1], p) <= at(&nested[2], p),
                        "{line:?} {p:?}"
                    );
                }
                assert!(nested[0].keys().all(|p| nested[2].contains_key(p)));
                let sum = |m: &HashMap<_, f32>| m.values().sum::<f32>();
                strictly[k] += usize::from(sum(&nested[0]) < sum(&nested[2]));
            }
        }
        assert!(strictly.iter().all(|&n| n > 30), "{strictly:?}");
    }

    #[test]
    fn bad_and_degenerate_strokes() {
        let pattern = sample_positions(AaMode::None);
        let mut n = 0;
        let mut plot = |_, _, _| n += 1;
        let e = stroke(
            &[[0.0, 0.0], [f64::NAN, 2.0]],
            &Stroke::new(1.0),
            &pattern,
            SIZE,
            &mut plot,
        );
        assert_eq!(e.unwrap_err().field, "stroke");
        for w in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let e = stroke(
                &[[0.0, 0.0], [5.0, 2.0]],
                &Stroke::new(w),
                &pattern,
                SIZE,
                &mut plot,
            );
            assert_eq!(e.unwrap_err().field, "width");
        }
        stroke(
            &[[3.0, 3.0], [3.0, 3.0]],
            &Stroke::new(2.0),
            &pattern,
            SIZE,
            &mut plot,
        )
        .unwrap();
        stroke(&[], &Stroke::new(2.0), &pattern, SIZE, &mut plot).unwrap();
        stroke(
            &[[-1e15, -1e15], [-1e15 + 5.0, -1e15]],
            &Stroke::new(2.0),
            &pattern,
            SIZE,
            &mut plot,
        )
        .unwrap();
        assert_eq!(n, 0);
        // Across the whole image from far outside: the row, once per pixel.
        let mut row = 0;
        aa_line(
            [-1e15, 10.5],
            [1e15, 10.5],
            1.0,
            &pattern,
            SIZE,
            &mut |_, y, _| {
                assert_eq!(y, 10);
                row += 1;
            },
        )
        .unwrap();
        assert_eq!(row, 64);
    }
}
