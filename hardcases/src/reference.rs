//! The f64 reference a hard case's renders are checked against.
//!
//! For every pixel centre and every drawable triangle it computes, in f64 and
//! relative to the ray origin, the three edge functions of paper §3.2 and their
//! gradients in pixels, hence the signed distance in pixels from the centre to
//! each edge, and the distance to where the triangle crosses the near plane.
//! A pixel's answer is *unambiguous* where nothing that could change it lies
//! within a radius of the centre:
//! - the visible triangle: the nearest covering one is inside all its edges and
//!   the near plane by more than the radius, nothing nearer comes that close,
//!   and the next depth differs by more than 10⁻⁶ (relative);
//! - the number of covering triangles: no *count-changing* edge (one not shared
//!   with exactly one other triangle facing the same way, so crossing it does
//!   not hand the sample from one triangle to the next) and no near-plane
//!   crossing within the radius. Shared edges and vertices inside a surface are
//!   exactly where a tie rule decides, and the count there must still be exact.
//!
//! Elsewhere only a bound is checked: no more triangles than come within the
//! radius.

use std::collections::HashMap;

use glam::DVec3;
use rayon::prelude::*;

use continuum::{BACKGROUND, PreparedScene, View};

/// Radius in pixels for renders that decide coverage on the pixel's own
/// coordinates (f32, f64).
pub const FLOAT_RADIUS: f64 = 1e-3;

/// Radius for renders that snap vertices to 1/256 pixel (`--precision fixed`,
/// `gpu-raster`): snapping moves an edge by up to 1/512·√2 pixel.
pub const SNAPPED_RADIUS: f64 = 1.0 / 128.0;

/// Depths closer than this (relative) are a tie the reference does not decide.
const DEPTH_TIE: f64 = 1e-6;

/// Direction, in radians from the image x axis, of the point where a
/// constant count is read (no lattice edge runs through the centre at it).
const PROBE_ANGLE: f64 = 0.3;

/// What the reference says about one pixel for one radius.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Expected {
    /// The visible triangle ([`BACKGROUND`] for none), where unambiguous.
    pub visible: Option<u32>,
    /// How many triangles cover the centre, where unambiguous.
    pub count: Option<u32>,
    /// The most triangles that come within the radius of the centre.
    pub max_count: u32,
}

/// The reference for every pixel of one view, at both radii.
#[derive(Clone, Debug)]
pub struct Reference {
    pub width: u32,
    pub height: u32,
    /// Per pixel, for [`FLOAT_RADIUS`].
    pub float: Vec<Expected>,
    /// Per pixel, for [`SNAPPED_RADIUS`].
    pub snapped: Vec<Expected>,
}

/// A drawable triangle for the reference: positions relative to the eye, and
/// per edge whether crossing it can change how many triangles cover a sample.
struct RefTriangle {
    id: u32,
    p: [DVec3; 3],
    count_changing: [bool; 3],
    /// Edge `i`'s function as `c_i + n_i·d + w_i·o` of the ray's direction
    /// `d` and origin `o` (eye-relative): perspective and non-planar views
    /// `n_i = p_{i+1} × p_{i+2}`; orthographic ones `c_i = det[p_{i+1},
    /// p_{i+2}, d_p]`, `w_i = (p_{i+1} − p_{i+2}) × d_p`.
    c: [f64; 3],
    n: [DVec3; 3],
    w: [DVec3; 3],
    /// The geometric normal.
    normal: DVec3,
}

/// One pixel's view of one triangle.
#[derive(Clone, Copy, Debug)]
struct Seen {
    id: u32,
    /// Signed distances in pixels to the three edges (inside positive).
    edge: [f64; 3],
    /// Signed distance in pixels from the near plane (in front positive), or
    /// `-∞` when the plane is behind the eye or seen edge-on.
    near: f64,
    depth: f64,
    count_changing: [bool; 3],
    /// Is the probe point (`r/2` from the centre) covered?
    probe: [bool; 2],
}

impl Reference {
    pub fn compute(scene: &PreparedScene, view: &View) -> Reference {
        let tris = reference_triangles(scene, view);
        let (w, h) = (view.width, view.height);
        let pixels: Vec<(Expected, Expected)> = (0..w * h)
            .into_par_iter()
            .map(|i| {
                let (x, y) = (f64::from(i % w) + 0.5, f64::from(i / w) + 0.5);
                let Some(ray) = PixelRay::at(view, x, y) else {
                    let none = Expected {
                        visible: Some(BACKGROUND),
                        count: Some(0),
                        max_count: 0,
                    };
                    return (none, none);
                };
                let seen: Vec<Seen> = tris.iter().filter_map(|t| ray.see(t, view)).collect();
                (
                    expected(&seen, FLOAT_RADIUS, 0),
                    expected(&seen, SNAPPED_RADIUS, 1),
                )
            })
            .collect();
        let (float, snapped) = pixels.into_iter().unzip();
        Reference {
            width: w,
            height: h,
            float,
            snapped,
        }
    }
}

/// The drawable triangles relative to the eye, with their count-changing edges:
/// an edge is count-preserving when exactly two triangles share it (by vertex
/// position) and the eye sees both from the same side.
fn reference_triangles(scene: &PreparedScene, view: &View) -> Vec<RefTriangle> {
    let eye = view.eye.as_dvec3();
    type EdgeKey = ([u32; 3], [u32; 3]);
    let edge_key = |a: glam::Vec3, b: glam::Vec3| -> EdgeKey {
        let (a, b) = (
            a.to_array().map(f32::to_bits),
            b.to_array().map(f32::to_bits),
        );
        if a <= b { (a, b) } else { (b, a) }
    };
    // 1. Per triangle: eye-relative positions, which way it faces the eye
    //    (orthographic: the view axis), and its edges' keys.
    let mut faces: HashMap<EdgeKey, Vec<bool>> = HashMap::new();
    let mut tris = Vec::with_capacity(scene.drawable.len());
    let mut keys = Vec::with_capacity(scene.drawable.len());
    for &id in &scene.drawable {
        let world = scene.triangle(id);
        let p = world.map(|v| v.as_dvec3() - eye);
        let normal = (p[1] - p[0]).cross(p[2] - p[0]);
        let facing = if view.is_orthographic() {
            normal.dot(view.forward.as_dvec3()) > 0.0
        } else {
            normal.dot(p[0]) > 0.0
        };
        let k = [0, 1, 2].map(|i| edge_key(world[(i + 1) % 3], world[(i + 2) % 3]));
        for key in k {
            faces.entry(key).or_default().push(facing);
        }
        keys.push(k);
        let mut t = RefTriangle {
            id,
            p,
            count_changing: [true; 3],
            c: [0.0; 3],
            n: [DVec3::ZERO; 3],
            w: [DVec3::ZERO; 3],
            normal,
        };
        let dp = view.forward.as_dvec3();
        for i in 0..3 {
            let (a, b) = (p[(i + 1) % 3], p[(i + 2) % 3]);
            if view.is_orthographic() {
                t.c[i] = a.cross(b).dot(dp);
                t.w[i] = (a - b).cross(dp);
            } else {
                t.n[i] = a.cross(b);
            }
        }
        tris.push(t);
    }
    // 2. An edge shared by exactly two triangles facing the same way hands a
    //    sample from one to the other.
    for (t, k) in tris.iter_mut().zip(&keys) {
        t.count_changing = k.map(|key| !matches!(faces[&key][..], [a, b] if a == b));
    }
    tris
}

/// The exact ray through a pixel centre, relative to the eye, with its
/// derivatives along the image axes.
struct PixelRay {
    /// Ray origin (perspective and non-planar views: the eye, zero).
    o: DVec3,
    d: DVec3,
    /// `∂o/∂x`, `∂o/∂y` (orthographic) and `∂d/∂x`, `∂d/∂y` (the others).
    ox: DVec3,
    oy: DVec3,
    dx: DVec3,
    dy: DVec3,
    /// The stored depth is the ray parameter times `|d|` (non-planar views)
    /// or the parameter itself (planar).
    euclidean: bool,
}

impl PixelRay {
    fn at(view: &View, x: f64, y: f64) -> Option<PixelRay> {
        let zero = DVec3::ZERO;
        match &view.sphere {
            Some(map) => {
                let d = view.camera_to_world(map.direction(x, y)?);
                let (ddx, ddy) = map.derivatives(x, y);
                Some(PixelRay {
                    o: zero,
                    d,
                    ox: zero,
                    oy: zero,
                    dx: view.camera_to_world(ddx),
                    dy: view.camera_to_world(ddy),
                    euclidean: true,
                })
            }
            None if view.is_orthographic() => {
                let (ox, oy) = (view.ox.as_dvec3(), view.oy.as_dvec3());
                Some(PixelRay {
                    o: view.o0.as_dvec3() + ox * x + oy * y,
                    d: view.forward.as_dvec3(),
                    ox,
                    oy,
                    dx: zero,
                    dy: zero,
                    euclidean: false,
                })
            }
            None => Some(PixelRay {
                o: zero,
                d: view.direction_f64(x, y),
                ox: zero,
                oy: zero,
                dx: view.dx.as_dvec3(),
                dy: view.dy.as_dvec3(),
                euclidean: false,
            }),
        }
    }

    /// Edge `i` of `t`: its value and gradient in pixels at the centre.
    #[inline]
    fn edge(&self, t: &RefTriangle, i: usize) -> (f64, [f64; 2]) {
        let (n, w) = (t.n[i], t.w[i]);
        let v = t.c[i] + n.dot(self.d) + w.dot(self.o);
        (
            v,
            [
                n.dot(self.dx) + w.dot(self.ox),
                n.dot(self.dy) + w.dot(self.oy),
            ],
        )
    }

    /// Depth of the triangle's plane along the ray at an offset `(u, v)` pixels
    /// from the centre (first order in the ray, exact in the plane).
    fn depth_at(&self, p0: DVec3, normal: DVec3, u: f64, v: f64) -> Option<f64> {
        let o = self.o + self.ox * u + self.oy * v;
        let d = self.d + self.dx * u + self.dy * v;
        let t = normal.dot(p0 - o) / normal.dot(d);
        let depth = if self.euclidean { t * d.length() } else { t };
        (t > 0.0 && depth.is_finite()).then_some(depth)
    }

    fn see(&self, t: &RefTriangle, view: &View) -> Option<Seen> {
        let p = t.p;
        let values = [0, 1, 2].map(|i| self.edge(t, i));
        let sum: f64 = values.iter().map(|v| v.0).sum();
        if sum == 0.0 || !sum.is_finite() {
            return None;
        }
        let s = sum.signum();
        let edge = values.map(|(v, [gx, gy])| s * v / (gx * gx + gy * gy).sqrt());
        // Far outside some edge: not seen at all.
        if edge.iter().any(|&e| e < -4.0 * SNAPPED_RADIUS) {
            return None;
        }
        let normal = t.normal;
        let depth = self.depth_at(p[0], normal, 0.0, 0.0)?;
        let near = f64::from(view.near);
        // Distance to the near-plane crossing from the depth's gradient.
        let step = 1e-3;
        let gx = self
            .depth_at(p[0], normal, step, 0.0)
            .map_or(f64::INFINITY, |d| (d - depth) / step);
        let gy = self
            .depth_at(p[0], normal, 0.0, step)
            .map_or(f64::INFINITY, |d| (d - depth) / step);
        let near_distance = (depth - near) / (gx * gx + gy * gy).sqrt();
        // The probe points r/2 from the centre, per radius.
        let probe = [FLOAT_RADIUS, SNAPPED_RADIUS].map(|r| {
            let (sin, cos) = PROBE_ANGLE.sin_cos();
            let (u, v) = (0.5 * r * cos, 0.5 * r * sin);
            let inside = values
                .iter()
                .all(|&(value, [gx, gy])| s * (value + gx * u + gy * v) > 0.0);
            inside && self.depth_at(p[0], normal, u, v).is_some_and(|d| d >= near)
        });
        Some(Seen {
            id: t.id,
            edge,
            near: near_distance,
            depth,
            count_changing: t.count_changing,
            probe,
        })
    }
}

/// The unambiguous answers at radius `r` (`slot` selects the probe point).
fn expected(seen: &[Seen], r: f64, slot: usize) -> Expected {
    let inside = |s: &Seen| s.edge.iter().all(|&e| e > r) && s.near > r;
    let within = |s: &Seen| s.edge.iter().all(|&e| e > -r) && s.near > -r;
    let candidates: Vec<&Seen> = seen.iter().filter(|s| within(s)).collect();
    // 1. The count: constant over the disc unless a count-changing edge or the
    //    near plane passes through it; then read at the probe point.
    let changes = candidates
        .iter()
        .any(|s| s.near.abs() <= r || (0..3).any(|i| s.edge[i].abs() <= r && s.count_changing[i]));
    let count = (!changes).then(|| candidates.iter().filter(|s| s.probe[slot]).count() as u32);
    // 2. The visible triangle: the nearest candidate, robustly inside, with
    //    every other candidate clearly behind it.
    let nearest = candidates
        .iter()
        .min_by(|a, b| a.depth.total_cmp(&b.depth).then(a.id.cmp(&b.id)));
    let visible = match nearest {
        None => Some(BACKGROUND),
        Some(n) if inside(n) => {
            let clear = candidates
                .iter()
                .filter(|s| s.id != n.id)
                .all(|s| s.depth - n.depth > DEPTH_TIE * n.depth.abs());
            clear.then_some(n.id)
        }
        Some(_) => None,
    };
    Expected {
        visible,
        count,
        max_count: candidates.len() as u32,
    }
}
