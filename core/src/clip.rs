//! Sutherland–Hodgman clipping for the 2D paths, in camera space `(x, y, w)`.
//!
//! Triangles are clipped against the near plane `w = near` (so the 2D family drops
//! exactly what the 3D family rejects per sample) and against a guard band of
//! [`GUARD_BAND`]× the screen, which keeps projected coordinates small enough for
//! f32 to place edges to ~1e-4 pixel. New vertices are always interpolated from the
//! inside endpoint towards the outside one, so two triangles that share an edge get
//! bit-identical clipped vertices on it (no cracks along a clip line).
//!
//! Everything is in f64, the camera-space vertices and the polygons between the
//! planes: a triangle 10¹³ pixels across that crosses the eye plane leaves
//! vertices at `w = near` with `x` and `y` near 10¹³, and rounding those to f32
//! would turn their directions `x/w` by far more than the screen.

use glam::DVec3;

use crate::camera::View;

/// Guard band half-extent in units of the screen half-extent (2 = screen plus
/// half a screen on every side).
pub const GUARD_BAND: f32 = 2.0;

/// Most vertices a triangle can have after five clip planes.
pub const MAX_CLIPPED: usize = 8;

/// A convex polygon of at most [`MAX_CLIPPED`] camera-space vertices, no heap.
#[derive(Clone, Copy, Debug)]
pub struct ClipPolygon {
    pub vertices: [DVec3; MAX_CLIPPED],
    pub len: usize,
}

impl ClipPolygon {
    pub fn as_slice(&self) -> &[DVec3] {
        &self.vertices[..self.len]
    }
}

/// A clip plane as a signed distance on camera-space points (`≥ 0` is kept).
#[derive(Clone, Copy, Debug)]
pub struct ClipPlane {
    /// `distance(v) = v.x·k.x + v.y·k.y + v.z·k.z − offset`.
    pub k: DVec3,
    pub offset: f64,
    /// The coordinate a new vertex is solved for, so that it lies on the plane
    /// exactly (`k[axis] ≠ 0`): `z` for the near plane, `x` or `y` for the sides.
    pub axis: usize,
}

impl ClipPlane {
    /// The near plane `w = near`.
    pub fn near(near: f64) -> ClipPlane {
        ClipPlane {
            k: DVec3::Z,
            offset: near,
            axis: 2,
        }
    }

    #[inline]
    fn distance(&self, v: DVec3) -> f64 {
        v.dot(self.k) - self.offset
    }

    /// Whether `v` is on this plane's kept side (`distance ≥ 0`, the test
    /// [`clip_triangle`] makes).
    #[inline]
    pub(crate) fn keeps(&self, v: DVec3) -> bool {
        self.distance(v) >= 0.0
    }

    /// The point where the segment from `vin` (inside, distance `din`) to
    /// `vout` (outside, `dout`) crosses the plane, with its `axis` coordinate
    /// solved from the others so the point is on the plane.
    fn crossing(&self, vin: DVec3, din: f64, vout: DVec3, dout: f64) -> DVec3 {
        let t = din / (din - dout);
        let mut v = (vin + (vout - vin) * t).to_array();
        let k = self.k.to_array();
        let rest: f64 = (0..3)
            .filter(|&j| j != self.axis)
            .map(|j| k[j] * v[j])
            .sum();
        v[self.axis] = (self.offset - rest) / k[self.axis];
        DVec3::from(v)
    }
}

/// Half-extent in pixels of the guard band of `--precision fixed`: coordinates
/// stay within 2¹⁴ pixels of the image centre, inside the 16.8 fixed-point range
/// (±2¹⁵), so clipping hardly ever moves an edge before snapping.
pub const FIXED_GUARD_PIXELS: f32 = 16384.0;

/// The guard band of `--precision fixed`, in units of the screen half-extents
/// (`x` and `y`): [`FIXED_GUARD_PIXELS`] from the image centre, at least [`GUARD_BAND`].
pub fn fixed_guard_band(view: &View) -> [f32; 2] {
    let g = |pixels: u32| (FIXED_GUARD_PIXELS / (pixels as f32 * 0.5)).max(GUARD_BAND);
    [g(view.width), g(view.height)]
}

/// The five planes of the 2D pipeline: near, then the guard band's left, right,
/// bottom and top: perspective `x/w ∈ [−G·half_x, G·half_x]`, orthographic
/// `x ∈ [−G·half_x, G·half_x]`, likewise `y`, with `guard = [G_x, G_y]` in units
/// of the half-extents ([`GUARD_BAND`] for f32, [`fixed_guard_band`] for fixed point).
pub fn pipeline_planes(view: &View, guard: [f32; 2]) -> [ClipPlane; 5] {
    planes_for(
        f64::from(view.near),
        f64::from(guard[0]) * f64::from(view.half_x),
        f64::from(guard[1]) * f64::from(view.half_y),
        view.is_orthographic(),
    )
}

/// The near plane and the guard band's four planes at `x = ±gx`, `y = ±gy`
/// (perspective: on `x/w`, `y/w`).
fn planes_for(near: f64, gx: f64, gy: f64, orthographic: bool) -> [ClipPlane; 5] {
    let side = |k: DVec3, g: f64| {
        let axis = if k.x != 0.0 { 0 } else { 1 };
        if orthographic {
            ClipPlane {
                k,
                offset: -g,
                axis,
            }
        } else {
            ClipPlane {
                k: DVec3::new(k.x, k.y, g),
                offset: 0.0,
                axis,
            }
        }
    };
    [
        ClipPlane::near(near),
        side(DVec3::X, gx),
        side(-DVec3::X, gx),
        side(DVec3::Y, gy),
        side(-DVec3::Y, gy),
    ]
}

/// Clips triangle `tri` (camera space) against `planes`. Returns `None` when
/// nothing is left, the polygon otherwise (the triangle itself when no plane cuts it).
pub fn clip_triangle(tri: [DVec3; 3], planes: &[ClipPlane]) -> Option<ClipPolygon> {
    let mut poly = ClipPolygon {
        vertices: [DVec3::ZERO; MAX_CLIPPED],
        len: 3,
    };
    poly.vertices[..3].copy_from_slice(&tri);
    for plane in planes {
        let n = poly.len;
        let dist: [f64; MAX_CLIPPED] = std::array::from_fn(|i| {
            if i < n {
                plane.distance(poly.vertices[i])
            } else {
                0.0
            }
        });
        if dist[..n].iter().all(|&d| d >= 0.0) {
            continue;
        }
        // Copied only when the plane cuts (most triangles are inside every plane).
        let src = poly;
        poly.len = 0;
        for i in 0..n {
            let j = (i + 1) % n;
            let (vi, vj) = (src.vertices[i], src.vertices[j]);
            let (di, dj) = (dist[i], dist[j]);
            let inside_i = di >= 0.0;
            if inside_i {
                push(&mut poly, vi);
            }
            if inside_i != (dj >= 0.0) {
                // Canonical direction: from the inside endpoint to the outside one.
                let (vin, din, vout, dout) = if inside_i {
                    (vi, di, vj, dj)
                } else {
                    (vj, dj, vi, di)
                };
                push(&mut poly, plane.crossing(vin, din, vout, dout));
            }
        }
        if poly.len < 3 {
            return None;
        }
    }
    Some(poly)
}

#[inline]
fn push(poly: &mut ClipPolygon, v: DVec3) {
    // A convex polygon gains at most one vertex per plane; MAX_CLIPPED covers five.
    if poly.len < MAX_CLIPPED {
        poly.vertices[poly.len] = v;
        poly.len += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn untouched_triangle_is_returned_as_is() {
        let planes = planes_for(0.1, 2.0, 2.0, false);
        let tri = [
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(0.1, 0.0, 1.0),
            DVec3::new(0.0, 0.1, 1.0),
        ];
        let p = clip_triangle(tri, &planes).expect("visible");
        assert_eq!(p.as_slice(), &tri);
    }

    #[test]
    fn near_plane_cuts_a_triangle_through_the_eye_plane() {
        let planes = planes_for(0.5, 2.0, 2.0, false);
        let tri = [
            DVec3::new(0.0, 0.0, -1.0),
            DVec3::new(0.2, 0.0, 2.0),
            DVec3::new(-0.2, 0.1, 2.0),
        ];
        let p = clip_triangle(tri, &planes).expect("partly visible");
        assert_eq!(p.len, 4);
        assert!(p.as_slice().iter().all(|v| v.z >= 0.5 - 1e-6));
    }

    #[test]
    fn shared_edge_clips_to_identical_vertices_in_both_orders() {
        let planes = planes_for(0.5, 2.0, 2.0, false);
        let (a, b) = (DVec3::new(0.1, 0.3, -0.7), DVec3::new(0.3, -0.2, 3.1));
        let t1 = clip_triangle([a, b, DVec3::new(0.5, 0.5, 2.0)], &planes).expect("visible");
        let t2 = clip_triangle([b, a, DVec3::new(-0.5, 0.5, 2.0)], &planes).expect("visible");
        let on_plane = |p: &ClipPolygon| {
            p.as_slice()
                .iter()
                .copied()
                .filter(|v| v.z < 0.5 + 1e-3)
                .collect::<Vec<_>>()
        };
        let shared1: Vec<DVec3> = on_plane(&t1);
        let shared2: Vec<DVec3> = on_plane(&t2);
        assert!(
            shared1.iter().any(|v| shared2.contains(v)),
            "{shared1:?} vs {shared2:?}"
        );
    }

    #[test]
    fn triangle_behind_the_eye_vanishes() {
        let planes = planes_for(0.1, 2.0, 2.0, false);
        let tri = [
            DVec3::new(0.0, 0.0, -1.0),
            DVec3::new(1.0, 0.0, -1.0),
            DVec3::new(0.0, 1.0, -2.0),
        ];
        assert!(clip_triangle(tri, &planes).is_none());
    }
}
