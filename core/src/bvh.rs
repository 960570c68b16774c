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

impl SlabRay {
    pub fn new(origin: Vec3, dir: Vec3) -> SlabRay {
        SlabRay {
            origin: origin.to_array(),
            dir: dir.to_array(),
            inv: (Vec3::ONE / dir).to_array(),
        }
    }

    /// Does the ray meet the box `[lo, hi]` at some `t ∈ [0, tmax]`?
    #[inline(always)]
    pub fn hits(&self, lo: Vec3A, hi: Vec3A, tmax: f32) -> bool {
        let (lo, hi) = (lo.to_array(), hi.to_array());
        let mut t0 = 0.0f32;
        let mut t1 = tmax;
        for a in 0..3 {
            if self.dir[a].abs() < 1e-30 {
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

    /// obvhs's hit mask for the children of `node` this ray meets before `tmax`.
    #[inline(always)]
    fn child_hitmask(&self, node: &CwBvhNode, tmax: f32, oct_inv4: u32) -> u32 {
        let (child_bits8, bit_index8) = node.get_child_and_index_bits(oct_inv4);
        let extent = node.compute_extent();
        let p = Vec3A::from(node.p);
        let mut mask = 0;
        for child in 0..8 {
            if node.is_child_empty(child) {
                continue;
            }
            let local = node.local_child_aabb(child);
            let (lo, hi) = padded(local.min * extent + p, local.max * extent + p);
            if self.hits(lo, hi, tmax) {
                mask |= extract_byte64(child_bits8, child) << extract_byte64(bit_index8, child);
            }
        }
        mask
    }
}
