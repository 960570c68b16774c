//! Secondary rays (shadow and reflection rays) through the scene's BVH, decided
//! by the same signed-volume test as primary coverage (paper §3.1): for a ray
//! `o + t·d` and a triangle, `V_i = ((p_{i+1} − o) × (p_{i+2} − o)) · d`. Two
//! triangles sharing an edge compute its two cross products from the same
//! operands in swapped order, which negates them exactly, so no ray slips
//! through a shared edge or hits it twice. A ray exactly on an edge (`V_i = 0`)
//! belongs to the triangle whose edge vector `n_i` is lexicographically
//! positive — its neighbour holds `−n_i`, so exactly one of them owns it (the
//! §3.4 idea with the edge vector's components in place of screen derivatives).

use glam::Vec3;

use crate::prepared::PreparedScene;

/// A ray's hit: the triangle, the ray parameter and the barycentrics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub id: u32,
    pub t: f32,
    /// `λ_i = V_i / ΣV` (paper §3.2): the weight of vertex `i`.
    pub lambda: [f32; 3],
}

/// Whether `n` owns a tie on its edge: its first non-zero component is positive.
#[inline]
fn owns_edge_tie(n: Vec3) -> bool {
    n.x > 0.0 || (n.x == 0.0 && (n.y > 0.0 || (n.y == 0.0 && n.z > 0.0)))
}

/// The barycentrics `λ_i = V_i / ΣV` (paper §3.2) of where the ray
/// `origin + t·dir` meets the plane of `p` — perspective-correct by
/// construction, from the same signed volumes that decide coverage.
#[inline]
pub fn barycentrics(p: &[Vec3; 3], origin: Vec3, dir: Vec3) -> [f32; 3] {
    let (_, v) = signed_volumes(p, origin, dir);
    let total = v[0] + v[1] + v[2];
    if total == 0.0 || !total.is_finite() {
        return [1.0 / 3.0; 3];
    }
    [v[0] / total, v[1] / total, v[2] / total]
}

/// The edge vectors `n_i = (p_{i+1} − o) × (p_{i+2} − o)` of `p` seen from
/// `origin`, and the signed volumes `V_i = n_i · dir` (paper §3.1).
#[inline]
fn signed_volumes(p: &[Vec3; 3], origin: Vec3, dir: Vec3) -> ([Vec3; 3], [f32; 3]) {
    let q = [p[0] - origin, p[1] - origin, p[2] - origin];
    let n = [q[1].cross(q[2]), q[2].cross(q[0]), q[0].cross(q[1])];
    (n, [n[0].dot(dir), n[1].dot(dir), n[2].dot(dir)])
}

/// The ray `origin + t·dir` against triangle `p`, for `t` in `(t_min, t_max)`.
#[inline]
pub fn intersect(
    p: &[Vec3; 3],
    origin: Vec3,
    dir: Vec3,
    t_min: f32,
    t_max: f32,
) -> Option<(f32, [f32; 3])> {
    let (n, v) = signed_volumes(p, origin, dir);
    // All three the same sign (zeros decided by the tie rule, oriented by
    // that sign); NaN compares false and misses.
    let sign = if v.iter().all(|&x| x >= 0.0) {
        1.0
    } else if v.iter().all(|&x| x <= 0.0) {
        -1.0
    } else {
        return None;
    };
    let inside = (0..3).all(|i| {
        let s = v[i] * sign;
        s > 0.0 || (s == 0.0 && owns_edge_tie(n[i] * sign))
    });
    if !inside {
        return None;
    }
    let total = v[0] + v[1] + v[2];
    if total == 0.0 {
        return None;
    }
    let lambda = [v[0] / total, v[1] / total, v[2] / total];
    let t = plane_distance(p, origin, dir)?;
    (t > t_min && t < t_max).then_some((t, lambda))
}

/// Where the ray `origin + t·dir` meets the plane through `p`: `t = N·(p_0 − o) / N·d`
/// with `N = (p_1 − p_0) × (p_2 − p_0)`; `None` when the ray runs along it.
#[inline]
pub fn plane_distance(p: &[Vec3; 3], origin: Vec3, dir: Vec3) -> Option<f32> {
    let normal = (p[1] - p[0]).cross(p[2] - p[0]);
    let denom = normal.dot(dir);
    let t = normal.dot(p[0] - origin) / denom;
    (denom != 0.0 && t.is_finite()).then_some(t)
}

/// Queries of one prepared scene.
#[derive(Clone, Copy, Debug)]
pub struct Rays<'a> {
    scene: &'a PreparedScene,
}

impl<'a> Rays<'a> {
    pub fn new(scene: &'a PreparedScene) -> Rays<'a> {
        Rays { scene }
    }

    /// The nearest opaque hit along `origin + t·dir` with `t > t_min`,
    /// ignoring triangle `skip` (the surface the ray leaves) and see-through
    /// triangles (a mirror shows opaque surfaces only). Ties in `t` go to the
    /// smaller id, as everywhere.
    pub fn closest(&self, origin: Vec3, dir: Vec3, t_min: f32, skip: u32) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let scene = self.scene;
        scene.bvh.walk(origin, dir, |slot| {
            let id = scene.slot_triangles[slot as usize];
            let t_max = best.map_or(f32::INFINITY, |h| h.t);
            if id != skip
                && !scene.is_transparent(id)
                && let Some((t, lambda)) = intersect(
                    &scene.slot_corners[slot as usize],
                    origin,
                    dir,
                    t_min,
                    t_max.next_up(),
                )
                && best.is_none_or(|b| t < b.t || (t == b.t && id < b.id))
            {
                best = Some(Hit { id, t, lambda });
            }
            best.map_or(f32::INFINITY, |h| h.t)
        });
        best
    }

    /// Whether anything lies on `origin + t·dir` for `t` in `(t_min, t_max)`,
    /// ignoring triangle `skip`; stops at the first hit.
    pub fn occluded(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32, skip: u32) -> bool {
        self.transmittance(origin, dir, t_min, t_max, skip) == 0.0
    }

    /// The share of light that passes along `origin + t·dir` for `t` in
    /// `(t_min, t_max)`, ignoring triangle `skip`: 0 at the first opaque hit
    /// (the walk ends there), else the product of `1 − opacity` over the
    /// see-through triangles met (1 when nothing is met).
    pub fn transmittance(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32, skip: u32) -> f32 {
        let mut passed = 1.0f32;
        let scene = self.scene;
        scene.bvh.walk(origin, dir, |slot| {
            let id = scene.slot_triangles[slot as usize];
            if passed > 0.0
                && id != skip
                && intersect(
                    &scene.slot_corners[slot as usize],
                    origin,
                    dir,
                    t_min,
                    t_max,
                )
                .is_some()
            {
                passed *= scene
                    .triangle_opacity
                    .get(id as usize)
                    .map_or(0.0, |o| 1.0 - o);
            }
            // Nothing passes an opaque hit: the walk ends.
            if passed > 0.0 {
                t_max
            } else {
                f32::NEG_INFINITY
            }
        });
        passed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ray_through_a_shared_edge_hits_exactly_one_triangle() {
        // A quad of two triangles; rays through points on the diagonal, and
        // through its end vertices.
        let (a, b, c, d) = (
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        );
        let first = [a, b, c];
        let second = [a, c, d];
        let origin = Vec3::new(0.3, 0.2, 2.0);
        for k in 0..=64 {
            let s = k as f32 / 64.0;
            let target = a + (c - a) * s;
            let dir = target - origin;
            let hits = [&first, &second]
                .iter()
                .filter(|t| intersect(t, origin, dir, 0.0, f32::INFINITY).is_some())
                .count();
            if 0 < k && k < 64 {
                assert_eq!(hits, 1, "s = {s}");
            } else {
                assert!(hits <= 1, "s = {s}: {hits} hits");
            }
        }
    }

    #[test]
    fn barycentrics_and_distance() {
        let p = [
            Vec3::new(0.0, 0.0, -2.0),
            Vec3::new(1.0, 0.0, -2.0),
            Vec3::new(0.0, 1.0, -2.0),
        ];
        let (t, l) = intersect(
            &p,
            Vec3::ZERO,
            Vec3::new(0.1, 0.15, -1.0),
            0.0,
            f32::INFINITY,
        )
        .expect("a hit");
        assert!((t - 2.0).abs() < 1e-6, "{t}");
        // The hit (0.2, 0.3, -2) = 0.5 p0 + 0.2 p1 + 0.3 p2.
        let expect = [0.5, 0.2, 0.3];
        for i in 0..3 {
            assert!((l[i] - expect[i]).abs() < 1e-6, "{l:?}");
        }
        // From behind, and beyond t_max: the same triangle, no hit.
        assert!(
            intersect(
                &p,
                Vec3::ZERO,
                Vec3::new(0.1, 0.15, 1.0),
                0.0,
                f32::INFINITY
            )
            .is_none()
        );
        assert!(intersect(&p, Vec3::ZERO, Vec3::new(0.1, 0.15, -1.0), 0.0, 1.5).is_none());
        assert_eq!(
            barycentrics(&p, Vec3::ZERO, Vec3::new(0.1, 0.15, -1.0)).map(|x| (x * 1e5).round()),
            expect.map(|x| (x * 1e5f32).round())
        );
    }
}
