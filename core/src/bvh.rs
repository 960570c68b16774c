//! The scene's BVH: an obvhs CWBVH (8-wide, compressed) built once per scene over
//! the drawable triangles, and a closest-hit ray walk whose box tests are
//! conservative, so a ray never skips a node holding a triangle that the 3D edge
//! functions say it covers.
//!
//! obvhs's own node test clamps `t` to an absolute epsilon and replaces tiny
//! direction components by `±1/ε`; both can drop a node a ray grazes. Here child
//! boxes are padded (relative [`BOX_PAD`]) and zero direction components get an
//! exact slab test.

use std::time::{Duration, Instant};

use glam::{UVec2, Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::node::{CwBvhNode, extract_byte64};
use wide::f32x8;

/// Relative padding of every box, beyond CWBVH quantisation and rounding.
pub const BOX_PAD: f32 = 1.0 / (1 << 18) as f32;

/// A BVH over triangles. Its primitives are indices into `drawable`.
#[derive(Clone, Debug)]
pub struct SceneBvh {
    pub cwbvh: CwBvh,
    /// Build wall time in milliseconds.
    pub build_ms: f64,
}

/// Pads a box by [`BOX_PAD`] of its largest coordinate magnitude (plus a tiny
/// absolute amount for boxes at the origin).
#[inline]
pub fn padded(min: Vec3A, max: Vec3A) -> (Vec3A, Vec3A) {
    let pad = min.abs().max(max.abs()).max_element() * BOX_PAD + f32::MIN_POSITIVE;
    (min - Vec3A::splat(pad), max + Vec3A::splat(pad))
}

impl SceneBvh {
    /// Builds over `triangles[id]` for every `id` in `drawable`.
    pub fn build(triangles: &[[Vec3; 3]], drawable: &[u32]) -> SceneBvh {
        let start = Instant::now();
        let aabbs: Vec<Aabb> = drawable
            .iter()
            .map(|&id| {
                let [a, b, c] = triangles[id as usize];
                let (min, max) = padded(Vec3A::from(a.min(b).min(c)), Vec3A::from(a.max(b).max(c)));
                Aabb::new(min, max)
            })
            .collect();
        let cwbvh = if aabbs.is_empty() {
            CwBvh::default()
        } else {
            obvhs::cwbvh::builder::build_cwbvh(
                &aabbs,
                BvhBuildParams::medium_build(),
                &mut Duration::default(),
            )
        };
        SceneBvh {
            cwbvh,
            build_ms: start.elapsed().as_secs_f64() * 1e3,
        }
    }

    /// Checks obvhs's structural invariants against the primitive boxes; panics on
    /// a violation (for tests).
    pub fn validate(&self, triangles: &[[Vec3; 3]], drawable: &[u32]) {
        if self.cwbvh.nodes.is_empty() {
            assert!(drawable.is_empty());
            return;
        }
        let aabbs: Vec<Aabb> = drawable
            .iter()
            .map(|&id| {
                let [a, b, c] = triangles[id as usize];
                let (min, max) = padded(Vec3A::from(a.min(b).min(c)), Vec3A::from(a.max(b).max(c)));
                Aabb::new(min, max)
            })
            .collect();
        let result = self.cwbvh.validate(&aabbs, false);
        assert_eq!(
            result.prim_count,
            drawable.len(),
            "every triangle in exactly one leaf"
        );
    }

    /// Walks the BVH along `origin + t·dir` front to back. `leaf(k)` is called for
    /// each primitive `k` (an index into `drawable`) of every leaf the ray reaches
    /// and returns the current culling distance: nodes entered beyond it are
    /// skipped. Returns the number of nodes whose children were tested.
    #[inline]
    pub fn walk(&self, origin: Vec3, dir: Vec3, mut leaf: impl FnMut(u32) -> f32) -> u64 {
        if self.cwbvh.nodes.is_empty() {
            return 0;
        }
        let ray = SlabRay::new(origin, dir);
        let mut tmax = f32::INFINITY;
        let mut visited = 0u64;
        let bvh = &self.cwbvh;
        let mut state = bvh.new_traversal(Vec3A::from(dir));
        let mut node: &CwBvhNode;
        obvhs::traverse!(
            bvh,
            node,
            state,
            {
                visited += 1;
                ray.child_hitmask(node, tmax, state.oct_inv4)
            },
            {
                tmax = leaf(bvh.primitive_indices[state.primitive_id as usize]);
            }
        );
        visited
    }
}

/// A ray prepared for slab tests.
#[derive(Clone, Copy, Debug)]
pub struct SlabRay {
    origin: [f32; 3],
    dir: [f32; 3],
    inv: [f32; 3],
}

/// Direction components smaller than this are treated as this (with their sign):
/// the slab test then stays exact for rays parallel to a slab (an origin inside
/// gives an interval of ±10³⁰, one outside never enters) and never forms 0·∞.
const TINY_DIRECTION: f32 = 1e-30;

impl SlabRay {
    pub fn new(origin: Vec3, dir: Vec3) -> SlabRay {
        let safe = dir.to_array().map(|d| {
            if d.abs() < TINY_DIRECTION {
                TINY_DIRECTION.copysign(d)
            } else {
                d
            }
        });
        SlabRay {
            origin: origin.to_array(),
            dir: dir.to_array(),
            inv: safe.map(|d| 1.0 / d),
        }
    }

    /// Does the ray meet the box `[lo, hi]` at some `t ∈ [0, tmax]`?
    #[inline(always)]
    pub fn hits(&self, lo: Vec3A, hi: Vec3A, tmax: f32) -> bool {
        let (lo, hi) = (lo.to_array(), hi.to_array());
        let mut t0 = 0.0f32;
        let mut t1 = tmax;
        for a in 0..3 {
            if self.dir[a].abs() < TINY_DIRECTION {
                // Parallel to the slab: inside it or never.
                if self.origin[a] < lo[a] || self.origin[a] > hi[a] {
                    return false;
                }
                continue;
            }
            let ta = (lo[a] - self.origin[a]) * self.inv[a];
            let tb = (hi[a] - self.origin[a]) * self.inv[a];
            t0 = t0.max(ta.min(tb));
            t1 = t1.min(ta.max(tb));
        }
        t0 <= t1
    }

    /// obvhs's hit mask for the children of `node` this ray meets before `tmax`:
    /// the eight child boxes are decoded and slab-tested side by side (8 lanes).
    #[inline(always)]
    fn child_hitmask(&self, node: &CwBvhNode, tmax: f32, oct_inv4: u32) -> u32 {
        let extent = node.compute_extent();
        let p = Vec3A::from(node.p);
        // One pad for the node: BOX_PAD of its largest coordinate magnitude.
        let far = p + extent * 255.0;
        let pad = f32x8::splat(p.abs().max(far.abs()).max_element() * BOX_PAD + f32::MIN_POSITIVE);
        let lanes = |q: [u8; 8]| f32x8::from(q.map(f32::from));
        let axis = |qlo: [u8; 8], qhi: [u8; 8], a: usize| {
            let (e, base) = (f32x8::splat(extent[a]), f32x8::splat(p[a]));
            let (o, inv) = (f32x8::splat(self.origin[a]), f32x8::splat(self.inv[a]));
            let lo = lanes(qlo) * e + base - pad;
            let hi = lanes(qhi) * e + base + pad;
            let (ta, tb) = ((lo - o) * inv, (hi - o) * inv);
            (ta.fast_min(tb), ta.fast_max(tb))
        };
        let (nx, fx) = axis(node.child_min_x, node.child_max_x, 0);
        let (ny, fy) = axis(node.child_min_y, node.child_max_y, 1);
        let (nz, fz) = axis(node.child_min_z, node.child_max_z, 2);
        let near = nx.fast_max(ny).fast_max(nz.fast_max(f32x8::ZERO));
        let far = fx.fast_min(fy).fast_min(fz.fast_min(f32x8::splat(tmax)));
        let mut hits = near.simd_le(far).to_bitmask();
        if hits == 0 {
            return 0;
        }
        let (child_bits8, bit_index8) = node.get_child_and_index_bits(oct_inv4);
        let mut mask = 0;
        while hits != 0 {
            let child = hits.trailing_zeros() as usize;
            hits &= hits - 1;
            if !node.is_child_empty(child) {
                mask |= extract_byte64(child_bits8, child) << extract_byte64(bit_index8, child);
            }
        }
        mask
    }
}
