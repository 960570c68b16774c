//! The scene's BVH: an obvhs CWBVH (8-wide, compressed) built once per scene over
//! the drawable triangles, and a closest-hit ray walk whose box tests are
//! conservative, so a ray never skips a node holding a triangle that the 3D edge
//! functions say it covers.
//!
//! obvhs's own node test clamps `t` to an absolute epsilon and replaces tiny
//! direction components by `±1/ε`; both can drop a node a ray grazes. Here child
//! boxes are padded (relative [`BOX_PAD`]) and zero direction components get an
//! exact slab test.

use std::time::Duration;

use glam::{UVec2, Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::node::{CwBvhNode, extract_byte64};

use crate::simd::{Lanes, Portable, abs};

/// Relative padding of every box, beyond CWBVH quantisation and rounding.
pub const BOX_PAD: f32 = 1.0 / (1 << 18) as f32;

/// A BVH over triangles. Its primitives are indices into `drawable`.
#[derive(Clone, Debug)]
pub struct SceneBvh {
    pub cwbvh: CwBvh,
}

/// Index of `node` in `bvh.nodes` (the traversal hands out references).
#[inline(always)]
fn node_index(bvh: &CwBvh, node: &CwBvhNode) -> usize {
    // Both point into the same slice, so the offset is exact.
    (node as *const CwBvhNode as usize - bvh.nodes.as_ptr() as usize)
        / std::mem::size_of::<CwBvhNode>()
}

/// The eight child boxes of a CWBVH node, decoded from its quantised bytes in
/// registers and padded, one child per lane: `lo[axis]`, `hi[axis]` (empty
/// children hold whatever their bytes decode to; callers mask them out).
///
/// The node keeps its 80 bytes (obvhs's layout, paper-independent: an origin
/// `p`, a power-of-two scale `2^e` per axis and six bytes per child); a child
/// box is `q·2^e + p` per bound — the product is exact, so this is the one
/// rounding obvhs's `child_aabb` makes — padded as [`padded`] pads, bit for
/// bit, so the lane tests cull exactly what a child-by-child test culls.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Children<L> {
    pub lo: [L; 3],
    pub hi: [L; 3],
}

/// Eight quantised bounds as lanes.
#[inline(always)]
fn byte_lanes<L: Lanes>(bytes: &[u8; 8]) -> L {
    L::from_array(bytes.map(f32::from))
}

impl<L: Lanes> Children<L> {
    /// Decodes `node`'s children (see [`Children`]).
    #[inline(always)]
    pub(crate) fn decode(node: &CwBvhNode) -> Children<L> {
        let scale = node.compute_extent();
        let bytes = [
            (&node.child_min_x, &node.child_max_x),
            (&node.child_min_y, &node.child_max_y),
            (&node.child_min_z, &node.child_max_z),
        ];
        let mut lo = [L::splat(0.0); 3];
        let mut hi = [L::splat(0.0); 3];
        for a in 0..3 {
            let (e, p) = (L::splat(scale[a]), L::splat(node.p[a]));
            lo[a] = byte_lanes::<L>(bytes[a].0) * e + p;
            hi[a] = byte_lanes::<L>(bytes[a].1) * e + p;
        }
        // `padded`, per lane: the largest magnitude of either corner.
        let mut largest = abs(lo[0]).max(abs(hi[0]));
        for a in 1..3 {
            largest = largest.max(abs(lo[a]).max(abs(hi[a])));
        }
        let pad = largest * L::splat(BOX_PAD) + L::splat(f32::MIN_POSITIVE);
        for a in 0..3 {
            lo[a] = lo[a] - pad;
            hi[a] = hi[a] + pad;
        }
        Children { lo, hi }
    }
}

/// The padded box of each drawable triangle: the BVH's primitives.
fn primitive_aabbs(triangles: &[[Vec3; 3]], drawable: &[u32]) -> Vec<Aabb> {
    drawable
        .iter()
        .map(|&id| {
            let [a, b, c] = triangles[id as usize];
            let (min, max) = padded(Vec3A::from(a.min(b).min(c)), Vec3A::from(a.max(b).max(c)));
            Aabb::new(min, max)
        })
        .collect()
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
        let aabbs = primitive_aabbs(triangles, drawable);
        let cwbvh = if aabbs.is_empty() {
            CwBvh::default()
        } else {
            obvhs::cwbvh::builder::build_cwbvh(
                &aabbs,
                BvhBuildParams::medium_build(),
                &mut Duration::default(),
            )
        };
        let mut cwbvh = cwbvh;
        // The builder reserves for the worst case; keep what the tree holds.
        cwbvh.nodes.shrink_to_fit();
        cwbvh.primitive_indices.shrink_to_fit();
        SceneBvh { cwbvh }
    }

    /// Heap bytes held: the nodes and the primitive order.
    pub fn bytes(&self) -> usize {
        self.cwbvh.nodes.capacity() * std::mem::size_of::<CwBvhNode>()
            + self.cwbvh.primitive_indices.capacity() * 4
    }

    /// Checks obvhs's structural invariants against the primitive boxes; panics on
    /// a violation (for tests).
    pub fn validate(&self, triangles: &[[Vec3; 3]], drawable: &[u32]) {
        if self.cwbvh.nodes.is_empty() {
            assert!(drawable.is_empty());
            return;
        }
        let aabbs = primitive_aabbs(triangles, drawable);
        let result = self.cwbvh.validate(&aabbs, false);
        assert_eq!(
            result.prim_count,
            drawable.len(),
            "every triangle in exactly one leaf"
        );
    }

    /// Walks the BVH along `origin + t·dir` front to back. `leaf(slot)` is called
    /// for each primitive slot (an index into `primitive_indices`, leaves hold
    /// consecutive slots) of every leaf the ray reaches and returns the current
    /// culling distance: nodes entered beyond it are skipped. Returns the number
    /// of nodes whose children were tested.
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
                let hits = ray.hits8::<Portable>(&Children::decode(node), tmax);
                child_mask(node, hits, state.oct_inv4)
            },
            {
                tmax = leaf(state.primitive_id);
            }
        );
        visited
    }

    /// [`SceneBvh::walk`] for a packet of `G` groups of up to [`PACKET`] rays
    /// each (absent lanes take no part): a node is entered when any ray may
    /// meet it before its own culling distance, so every ray reaches every
    /// node its single walk would (front to back in the first present ray's
    /// order). The groups share each node's read and decode, and are tested
    /// each on its own, by the group's [`PacketInterval`] (over one origin in
    /// perspective and spherical views, over the origins' range in
    /// orthographic ones) against its own largest culling distance: one
    /// 8-lane test per node and group. So a packet whose groups diverge (one
    /// done behind a near surface, another still open to the background)
    /// culls as its groups would alone. `leaf(slot, cull)` is called for each
    /// primitive slot of every leaf the packet reaches, updates each lane's
    /// culling distance in `cull[group]` and says whether it changed any.
    /// Returns the number of nodes whose children were tested (once per
    /// node, for the packet), and adds their indices to `entered` when given
    /// (a render's trace). The slab
    /// tests run on lanes `L` (the caller's instruction set, see
    /// [`crate::simd`]; inlined into it).
    #[inline(always)]
    pub fn walk_packet<L: Lanes, const G: usize>(
        &self,
        rays: &[PacketRays; G],
        mut entered: Option<&mut Vec<u32>>,
        mut leaf: impl FnMut(u32, &mut [[f32; PACKET]; G]) -> bool,
    ) -> u64 {
        if self.cwbvh.nodes.is_empty() {
            return 0;
        }
        // Loops, not `map` closures: this is lane code (see `crate::simd`).
        // Absent lanes never enter a node.
        let mut cull = [[f32::NEG_INFINITY; PACKET]; G];
        let mut intervals = [None; G];
        let mut first = None;
        for g in 0..G {
            // (By reference: a group's lanes are 200 bytes or more.)
            let (interval, present, direction) = match &rays[g] {
                &PacketRays::OneOrigin {
                    origin,
                    ref directions,
                    present,
                } if present != 0 => (
                    PacketInterval::of_directions::<L>(origin, directions, present),
                    present,
                    lane_vector(directions, present.trailing_zeros() as usize),
                ),
                &PacketRays::Planar {
                    ref origins,
                    ref directions,
                    present,
                } if present != 0 => (
                    PacketInterval::of_rays::<L>(origins, directions, present),
                    present,
                    lane_vector(directions, present.trailing_zeros() as usize),
                ),
                PacketRays::Rays(rays) => {
                    let slabs = rays.map(|ray| ray.map(|(origin, dir)| SlabRay::new(origin, dir)));
                    let present =
                        (0..PACKET).fold(0u16, |m, l| m | u16::from(rays[l].is_some()) << l);
                    let Some(interval) = PacketInterval::of(&slabs) else {
                        continue;
                    };
                    let first = rays[present.trailing_zeros() as usize].map(|(_, dir)| dir);
                    (interval, present, first.expect("a present ray"))
                }
                _ => continue,
            };
            for (l, c) in cull[g].iter_mut().enumerate() {
                if present >> l & 1 == 1 {
                    *c = f32::INFINITY;
                }
            }
            first = first.or(Some(direction));
            intervals[g] = Some(interval);
        }
        let Some(first) = first else {
            return 0;
        };
        // Each group's largest culling distance, renewed after each leaf
        // (−∞: a group without rays).
        let mut tmax = [f32::NEG_INFINITY; G];
        largest_per_group::<L, G>(&cull, &mut tmax);
        let mut visited = 0u64;
        let bvh = &self.cwbvh;
        let mut state = bvh.new_traversal(Vec3A::from(first));
        let mut node: &CwBvhNode;
        obvhs::traverse!(
            bvh,
            node,
            state,
            {
                visited += 1;
                if let Some(entered) = entered.as_deref_mut() {
                    entered.push(node_index(bvh, node) as u32);
                }
                let boxes = &Children::<L>::decode(node);
                let mut hits = 0;
                for g in 0..G {
                    // (A group without rays has no interval and culls at −∞.)
                    if let Some(interval) = &intervals[g]
                        && tmax[g] != f32::NEG_INFINITY
                    {
                        hits |= interval.hits::<L>(boxes, tmax[g]);
                    }
                }
                child_mask(node, hits, state.oct_inv4)
            },
            {
                // Most leaf triangles miss every ray: the culling distances
                // are renewed only when a hit moved one.
                if leaf(state.primitive_id, &mut cull) {
                    largest_per_group::<L, G>(&cull, &mut tmax);
                }
            }
        );
        visited
    }
}

/// Each group's largest culling distance (distances are never NaN: the
/// maximum is the same in any order).
#[inline(always)]
fn largest_per_group<L: Lanes, const G: usize>(cull: &[[f32; PACKET]; G], tmax: &mut [f32; G]) {
    const { assert!(PACKET == 16) };
    for g in 0..G {
        let (lo, hi) = cull[g].split_at(8);
        let (lo, hi): ([f32; 8], [f32; 8]) = (lo.try_into().expect("8"), hi.try_into().expect("8"));
        let largest = L::from_array(lo).max(L::from_array(hi)).to_array();
        tmax[g] = largest.into_iter().fold(f32::NEG_INFINITY, f32::max);
    }
}

impl SceneBvh {
    /// Node `index`'s box: the union of its children's (padded) boxes.
    pub fn node_box(&self, index: usize) -> [[f32; 3]; 2] {
        let node = &self.cwbvh.nodes[index];
        let boxes = Children::<Portable>::decode(node);
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for a in 0..3 {
            let (los, his) = (boxes.lo[a].to_array(), boxes.hi[a].to_array());
            for child in (0..8).filter(|&c| !node.is_child_empty(c)) {
                lo[a] = lo[a].min(los[child]);
                hi[a] = hi[a].max(his[child]);
            }
        }
        [lo, hi]
    }
}

/// obvhs's traversal mask for the children of `node` whose bits are set in
/// `hits` (bit `i` for child slot `i`).
#[inline(always)]
fn child_mask(node: &CwBvhNode, hits: u32, oct_inv4: u32) -> u32 {
    if hits == 0 {
        return 0;
    }
    // Every slot, hit or not, with no branch: how many children a packet
    // hits is unpredictable, and a loop over them mispredicts its exit. An
    // empty slot's bits are zero (its meta byte is), so it adds nothing.
    let (child_bits8, bit_index8) = node.get_child_and_index_bits(oct_inv4);
    let mut mask = 0;
    for child in 0..8 {
        let bits = extract_byte64(child_bits8, child) * (hits >> child & 1);
        mask |= bits << extract_byte64(bit_index8, child);
    }
    mask
}

/// The children (bit per lane) whose per-axis slab intervals `(near, far)`
/// overlap each other and `[0, tmax]`.
#[inline(always)]
fn overlapping<L: Lanes>([(nx, fx), (ny, fy), (nz, fz)]: [(L, L); 3], tmax: f32) -> u32 {
    let near = nx.max(ny).max(nz.max(L::splat(0.0)));
    let far = fx.min(fy).min(fz.min(L::splat(tmax)));
    u32::from(near.le(far))
}

/// The slab tests of a packet of rays by interval arithmetic over the packet
/// (Wald et al. style): per axis the smallest and largest reciprocal
/// direction of its rays, and the smallest and largest of their (padded)
/// origins — one origin for a perspective view's rays, a range for an
/// orthographic view's parallel rays. For a box coordinate `q` every ray's
/// slab distance is the rounded `(q − o)·inv`, which is monotonic in `o` and
/// in `inv`, so the distances at the ranges' ends bound every ray's exactly,
/// and so do the min/max combinations of them: a box is missed by every ray
/// when the packet's nearest possible entry lies beyond its farthest
/// possible exit (or beyond every ray's culling distance). Conservative
/// against each ray's own `SlabRay::hits8` bit for bit, so no ray loses a
/// node its single walk enters.
#[derive(Clone, Copy, Debug)]
pub struct PacketInterval {
    /// Per axis, the least and the greatest `SlabRay::origin_lo` of the rays.
    origin_lo: [[f32; 3]; 2],
    /// Per axis, the least and the greatest `SlabRay::origin_hi` of the rays.
    origin_hi: [[f32; 3]; 2],
    inv_min: [f32; 3],
    inv_max: [f32; 3],
    /// Every ray has the same origin (each range is one value).
    one_origin: bool,
}

/// Per axis, the least and greatest reciprocal of `directions[axis][lane]`
/// over the lanes of `present` (at least one), as [`SlabRay`] takes it
/// ([`safe_direction`]), eight lanes at a time: IEEE division, so each lane
/// rounds as the scalar one, and minima and maxima of nonzero finite values,
/// exact in any order.
#[inline(always)]
fn inverse_range<L: Lanes>(directions: &[[f32; PACKET]; 3], present: u16) -> ([f32; 3], [f32; 3]) {
    const { assert!(PACKET == 16) };
    let first = present.trailing_zeros() as usize;
    let (mut inv_min, mut inv_max) = ([0.0; 3], [0.0; 3]);
    for a in 0..3 {
        // Absent lanes repeat the first present one: no effect on min/max.
        let fill = L::splat(directions[a][first]);
        let (mut lo, mut hi) = (L::splat(f32::INFINITY), L::splat(f32::NEG_INFINITY));
        for (half, chunk) in directions[a].chunks_exact(8).enumerate() {
            let lanes = (present >> (8 * half)) as u8;
            let chunk: [f32; 8] = chunk.try_into().expect("eight lanes");
            let mut d = L::select(lanes, L::from_array(chunk), fill);
            // Components below the tiny bound (rare) as the scalar path takes them.
            if d.lt(L::splat(TINY_DIRECTION)) & d.gt(L::splat(-TINY_DIRECTION)) != 0 {
                d = L::from_array(d.to_array().map(safe_direction));
            }
            let inv = L::splat(1.0) / d;
            (lo, hi) = (lo.min(inv), hi.max(inv));
        }
        inv_min[a] = lo.to_array().into_iter().fold(f32::INFINITY, f32::min);
        inv_max[a] = hi.to_array().into_iter().fold(f32::NEG_INFINITY, f32::max);
    }
    (inv_min, inv_max)
}

/// Lane `l` of vectors in lanes, `v[axis][lane]`.
#[inline(always)]
fn lane_vector(v: &[[f32; PACKET]; 3], l: usize) -> Vec3 {
    Vec3::new(v[0][l], v[1][l], v[2][l])
}

/// The rays of a packet for [`SceneBvh::walk_packet`].
#[derive(Clone, Copy, Debug)]
pub enum PacketRays<'r> {
    /// Rays from `origin` along `directions[axis][lane]`; lanes outside
    /// `present` (bit per lane) take no part and may hold anything.
    OneOrigin {
        origin: Vec3,
        directions: [[f32; PACKET]; 3],
        present: u16,
    },
    /// Rays from `origins[axis][lane]` along `directions[axis][lane]`
    /// (an orthographic view's); lanes outside `present` as above.
    Planar {
        origins: [[f32; PACKET]; 3],
        directions: [[f32; PACKET]; 3],
        present: u16,
    },
    /// One ray per lane (`None`: absent), any origins.
    Rays(&'r [Option<(Vec3, Vec3)>; PACKET]),
}

impl PacketInterval {
    /// The interval of rays from `origin` along `directions[axis][lane]`
    /// (lanes in `present`, at least one): the same bounds as [`PacketInterval::of`]
    /// on their [`SlabRay`]s, with the reciprocals taken eight lanes at a
    /// time (IEEE division, so each lane rounds as the scalar one).
    #[inline(always)]
    pub fn of_directions<L: Lanes>(
        origin: Vec3,
        directions: &[[f32; PACKET]; 3],
        present: u16,
    ) -> PacketInterval {
        let (origin_lo, origin_hi) = padded_origin(origin);
        let (inv_min, inv_max) = inverse_range::<L>(directions, present);
        PacketInterval {
            origin_lo: [origin_lo; 2],
            origin_hi: [origin_hi; 2],
            inv_min,
            inv_max,
            one_origin: true,
        }
    }

    /// The interval of rays from `origins[axis][lane]` along
    /// `directions[axis][lane]` (lanes in `present`, at least one): the
    /// same bounds as [`PacketInterval::of`] on their [`SlabRay`]s.
    #[inline(always)]
    pub fn of_rays<L: Lanes>(
        origins: &[[f32; PACKET]; 3],
        directions: &[[f32; PACKET]; 3],
        present: u16,
    ) -> PacketInterval {
        let first = lane_vector(origins, present.trailing_zeros() as usize);
        let (lo, hi) = padded_origin(first);
        let (mut origin_lo, mut origin_hi, mut one_origin) = ([lo; 2], [hi; 2], true);
        for l in (0..PACKET).filter(|&l| present >> l & 1 == 1) {
            let origin = lane_vector(origins, l);
            let (lo, hi) = padded_origin(origin);
            one_origin &= origin == first;
            for a in 0..3 {
                origin_lo[0][a] = origin_lo[0][a].min(lo[a]);
                origin_lo[1][a] = origin_lo[1][a].max(lo[a]);
                origin_hi[0][a] = origin_hi[0][a].min(hi[a]);
                origin_hi[1][a] = origin_hi[1][a].max(hi[a]);
            }
        }
        let (inv_min, inv_max) = inverse_range::<L>(directions, present);
        PacketInterval {
            origin_lo,
            origin_hi,
            inv_min,
            inv_max,
            one_origin,
        }
    }

    /// The interval of the present rays (`None` when there is none).
    pub fn of(slabs: &[Option<SlabRay>]) -> Option<PacketInterval> {
        let mut present = slabs.iter().flatten();
        let first = present.next()?;
        let mut interval = PacketInterval {
            origin_lo: [first.origin_lo; 2],
            origin_hi: [first.origin_hi; 2],
            inv_min: first.inv,
            inv_max: first.inv,
            one_origin: true,
        };
        for slab in present {
            interval.one_origin &= slab.origin == first.origin;
            for a in 0..3 {
                let [lo, hi] = &mut interval.origin_lo;
                (lo[a], hi[a]) = (lo[a].min(slab.origin_lo[a]), hi[a].max(slab.origin_lo[a]));
                let [lo, hi] = &mut interval.origin_hi;
                (lo[a], hi[a]) = (lo[a].min(slab.origin_hi[a]), hi[a].max(slab.origin_hi[a]));
                interval.inv_min[a] = interval.inv_min[a].min(slab.inv[a]);
                interval.inv_max[a] = interval.inv_max[a].max(slab.inv[a]);
            }
        }
        Some(interval)
    }

    /// The children (bit per slot) some ray of the packet may meet before
    /// `tmax` (the largest culling distance of its rays).
    #[inline(always)]
    fn hits<L: Lanes>(&self, boxes: &Children<L>, tmax: f32) -> u32 {
        // An array, not a `map` closure: lane code must be inlined (`crate::simd`).
        let axes = [
            self.axis::<L>(boxes, 0),
            self.axis::<L>(boxes, 1),
            self.axis::<L>(boxes, 2),
        ];
        overlapping(axes, tmax)
    }

    /// Along axis `a`, per child: a lower bound of every ray's slab entry
    /// `min(ta, tb)` and an upper bound of its exit `max(ta, tb)`. (A function,
    /// not a closure: only `#[inline(always)]` code is compiled for the caller's lanes.)
    #[inline(always)]
    fn axis<L: Lanes>(&self, boxes: &Children<L>, a: usize) -> (L, L) {
        // The distances at the least origins (the largest differences) ...
        let (near, far) = self.distances(boxes, a, 0);
        if self.one_origin {
            return (near, far);
        }
        // ... and at the greatest (the smallest).
        let (near_1, far_1) = self.distances(boxes, a, 1);
        (near.min(near_1), far.max(far_1))
    }

    /// Along axis `a`, per child: the least and greatest of the box sides'
    /// differences from origin end `end` (0: least, 1: greatest) times the
    /// two reciprocal extremes.
    #[inline(always)]
    fn distances<L: Lanes>(&self, boxes: &Children<L>, a: usize, end: usize) -> (L, L) {
        let (lo, hi) = (L::splat(self.inv_min[a]), L::splat(self.inv_max[a]));
        let below = boxes.lo[a] - L::splat(self.origin_lo[end][a]);
        let above = boxes.hi[a] - L::splat(self.origin_hi[end][a]);
        let (ta_lo, ta_hi) = (below * lo, below * hi);
        let (tb_lo, tb_hi) = (above * lo, above * hi);
        (
            ta_lo.min(ta_hi).min(tb_lo.min(tb_hi)),
            ta_lo.max(ta_hi).max(tb_lo.max(tb_hi)),
        )
    }
}

/// Rays of one group of [`SceneBvh::walk_packet`]: a 4×4 pixel block.
pub const PACKET: usize = 16;

/// A ray prepared for slab tests.
#[derive(Clone, Copy, Debug)]
pub struct SlabRay {
    origin: [f32; 3],
    dir: [f32; 3],
    inv: [f32; 3],
    /// The origin moved by its own rounding pad: subtracted from lower bounds
    /// (`origin_lo`) and upper bounds (`origin_hi`), it widens every slab by more
    /// than the subtraction can round.
    origin_lo: [f32; 3],
    origin_hi: [f32; 3],
}

/// Direction components smaller than this are treated as this (with their sign):
/// the slab test then stays exact for rays parallel to a slab (an origin inside
/// gives an interval of ±10³⁰, one outside never enters) and never forms 0·∞.
const TINY_DIRECTION: f32 = 1e-30;

/// A direction component as the slab tests use it: at least
/// [`TINY_DIRECTION`] in magnitude, with its sign.
#[inline(always)]
fn safe_direction(d: f32) -> f32 {
    if d.abs() < TINY_DIRECTION {
        TINY_DIRECTION.copysign(d)
    } else {
        d
    }
}

/// The origin moved by its own rounding pad, for lower bounds and for upper
/// bounds (see [`SlabRay`]).
#[inline(always)]
fn padded_origin(origin: Vec3) -> ([f32; 3], [f32; 3]) {
    let pad = origin.abs().max_element() * BOX_PAD;
    (
        (origin + Vec3::splat(pad)).to_array(),
        (origin - Vec3::splat(pad)).to_array(),
    )
}

impl SlabRay {
    pub fn new(origin: Vec3, dir: Vec3) -> SlabRay {
        let (origin_lo, origin_hi) = padded_origin(origin);
        let d = dir.to_array();
        SlabRay {
            origin: origin.to_array(),
            dir: d,
            inv: [
                1.0 / safe_direction(d[0]),
                1.0 / safe_direction(d[1]),
                1.0 / safe_direction(d[2]),
            ],
            origin_lo,
            origin_hi,
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

    /// The children (bit per slot of `boxes`) this ray meets before `tmax`:
    /// eight slab tests side by side.
    #[inline(always)]
    fn hits8<L: Lanes>(&self, boxes: &Children<L>, tmax: f32) -> u32 {
        // An array, not a `map` closure: lane code must be inlined (`crate::simd`).
        let axes = [
            self.axis::<L>(boxes, 0),
            self.axis::<L>(boxes, 1),
            self.axis::<L>(boxes, 2),
        ];
        overlapping(axes, tmax)
    }

    /// Along axis `a`, per child: the slab entry and exit distances.
    #[inline(always)]
    fn axis<L: Lanes>(&self, boxes: &Children<L>, a: usize) -> (L, L) {
        let inv = L::splat(self.inv[a]);
        let ta = (boxes.lo[a] - L::splat(self.origin_lo[a])) * inv;
        let tb = (boxes.hi[a] - L::splat(self.origin_hi[a])) * inv;
        (ta.min(tb), ta.max(tb))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The packet's interval test never misses a child box that one of its
    /// rays' own slab test meets: random packets from one origin (nearly
    /// parallel, spread, and with direction components of both signs) and
    /// of parallel rays from spread origins (orthographic views), against
    /// random boxes and culling distances.
    #[test]
    fn the_interval_test_keeps_every_box_a_ray_meets() {
        let mut rng = fastrand::Rng::with_seed(11);
        let mut f = move |lo: f32, hi: f32| lo + rng.f32() * (hi - lo);
        let (mut met, mut kept_extra, mut parallel) = (0u32, 0u32, 0);
        for case in 0..6000 {
            let origin = Vec3::new(f(-5.0, 5.0), f(-5.0, 5.0), f(-5.0, 5.0));
            let centre = Vec3::new(f(-1.0, 1.0), f(-1.0, 1.0), f(-1.0, 1.0)).normalize_or(Vec3::X);
            // Cases 3 and 4 of 5: one direction from origins spread apart.
            let (spread, apart) = [
                (1e-4, 0.0),
                (1e-2, 0.0),
                (0.5, 0.0),
                (0.0, 0.05),
                (0.0, 2.0),
            ][case % 5];
            let mut ray = || {
                let dir = centre + Vec3::new(f(-1.0, 1.0), f(-1.0, 1.0), f(-1.0, 1.0)) * spread;
                let at = origin + Vec3::new(f(-1.0, 1.0), f(-1.0, 1.0), f(-1.0, 1.0)) * apart;
                SlabRay::new(at, dir)
            };
            let slabs: Vec<Option<SlabRay>> =
                (0..PACKET).map(|l| (l % 5 != 4).then(&mut ray)).collect();
            let tmax: Vec<f32> = (0..PACKET).map(|_| f(0.0, 20.0)).collect();
            let (mut lo, mut hi) = ([[0.0; 8]; 3], [[0.0; 8]; 3]);
            for c in 0..8 {
                for a in 0..3 {
                    let (p, q) = (f(-10.0, 10.0), f(-10.0, 10.0));
                    (lo[a][c], hi[a][c]) = (p.min(q), p.max(q));
                }
            }
            let boxes = Children {
                lo: lo.map(lanes::<Portable>),
                hi: hi.map(lanes::<Portable>),
            };
            let interval = PacketInterval::of(&slabs).expect("rays");
            assert_eq!(interval.one_origin, apart == 0.0);
            parallel += usize::from(!interval.one_origin);
            let packet = interval.hits::<Portable>(&boxes, tmax.iter().fold(0.0, |m, &t| m.max(t)));
            let rays = slabs
                .iter()
                .zip(&tmax)
                .filter_map(|(s, &t)| Some(s.as_ref()?.hits8::<Portable>(&boxes, t)))
                .fold(0, |m, h| m | h);
            assert_eq!(rays & !packet, 0, "case {case}: boxes {boxes:?}");
            met += rays.count_ones();
            kept_extra += (packet & !rays).count_ones();
        }
        assert!(met > 3000, "only {met} boxes met: the cases test little");
        assert_eq!(parallel, 2400);
        // Conservative, not everything: the test still rejects boxes.
        assert!(
            kept_extra < 6000 * 8 - met,
            "the interval test kept every box"
        );
    }

    /// A node's children decoded in lanes are obvhs's `child_aabb`s padded by
    /// [`padded`], bit for bit, on both lane types: every node of a BVH over
    /// random triangles far from the origin and near it.
    #[test]
    fn children_decode_in_lanes_as_child_by_child() {
        let mut rng = fastrand::Rng::with_seed(13);
        let mut checked = 0;
        for (offset, size) in [(0.0, 1.0), (1e4, 3.0), (-37.5, 1e-3)] {
            let triangles: Vec<[Vec3; 3]> = (0..3000)
                .map(|_| {
                    let c = Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 100.0 * size;
                    let mut corner = || c + Vec3::new(rng.f32(), rng.f32(), rng.f32()) * size;
                    [corner(), corner(), corner()].map(|p| p + Vec3::splat(offset))
                })
                .collect();
            let drawable: Vec<u32> = (0..triangles.len() as u32).collect();
            let bvh = SceneBvh::build(&triangles, &drawable);
            for node in &bvh.cwbvh.nodes {
                let decoded = Children::<Portable>::decode(node);
                #[cfg(target_arch = "x86_64")]
                let avx2 = crate::simd::cpu_has_avx2().then(|| {
                    // SAFETY: this CPU has AVX2.
                    let c = unsafe { decode_avx2(node) };
                    (c.lo.map(array), c.hi.map(array))
                });
                for child in (0..8).filter(|&c| !node.is_child_empty(c)) {
                    let aabb = node.child_aabb(child);
                    let (lo, hi) = padded(aabb.min, aabb.max);
                    for a in 0..3 {
                        assert_eq!(array(decoded.lo[a])[child].to_bits(), lo[a].to_bits());
                        assert_eq!(array(decoded.hi[a])[child].to_bits(), hi[a].to_bits());
                        #[cfg(target_arch = "x86_64")]
                        if let Some((alo, ahi)) = avx2 {
                            assert_eq!(alo[a][child].to_bits(), lo[a].to_bits());
                            assert_eq!(ahi[a][child].to_bits(), hi[a].to_bits());
                        }
                    }
                    checked += 1;
                }
            }
        }
        // Every triangle's leaf and every inner node is some node's child.
        assert!(checked > 3 * 3000 / 4, "only {checked} children checked");
    }

    fn lanes<L: Lanes>(values: [f32; 8]) -> L {
        L::from_array(values)
    }

    fn array<L: Lanes>(lanes: L) -> [f32; 8] {
        lanes.to_array()
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn decode_avx2(node: &CwBvhNode) -> Children<crate::simd::Avx2> {
        Children::decode(node)
    }

    /// The interval built from directions (and origins) eight lanes at a
    /// time is the one built from the rays' own slab rays, field for field,
    /// on both lane types: random packets with absent lanes, tiny and zero
    /// components, from one origin and (orthographic views) from several.
    #[test]
    fn the_interval_from_lanes_is_the_interval_of_the_rays() {
        let mut rng = fastrand::Rng::with_seed(12);
        let mut several = 0;
        for case in 0..3000 {
            let origin = Vec3::new(rng.f32() - 0.5, rng.f32() * 1e3, -rng.f32()) * 7.0;
            let present = (rng.u32(..) as u16) | 1 << rng.usize(0..PACKET);
            let (mut directions, mut origins) = ([[0.0; PACKET]; 3], [[0.0; PACKET]; 3]);
            for (axis, d) in directions.iter_mut().enumerate() {
                for (l, d) in d.iter_mut().enumerate() {
                    *d = match rng.u8(0..8) {
                        0 => 0.0,
                        1 => -1e-31,
                        _ => rng.f32() * 4.0 - 2.0,
                    };
                    // Every other case: origins apart (from 0 to 3 units).
                    let apart = (case % 2) as f32 * rng.f32() * 3.0;
                    origins[axis][l] = origin[axis] + apart;
                }
            }
            let slabs: Vec<Option<SlabRay>> = (0..PACKET)
                .map(|l| {
                    let (o, d) = (lane_vector(&origins, l), lane_vector(&directions, l));
                    (present >> l & 1 == 1).then(|| SlabRay::new(o, d))
                })
                .collect();
            let expected = PacketInterval::of(&slabs).expect("rays");
            several += usize::from(!expected.one_origin);
            let fields =
                |i: PacketInterval| (i.origin_lo, i.origin_hi, i.inv_min, i.inv_max, i.one_origin);
            let portable = match case % 2 {
                0 => PacketInterval::of_directions::<Portable>(origin, &directions, present),
                _ => PacketInterval::of_rays::<Portable>(&origins, &directions, present),
            };
            assert_eq!(fields(portable), fields(expected), "case {case}");
            #[cfg(target_arch = "x86_64")]
            if crate::simd::cpu_has_avx2() {
                // SAFETY: this CPU has AVX2.
                let avx2 = unsafe {
                    match case % 2 {
                        0 => of_directions_avx2(origin, &directions, present),
                        _ => of_lanes_avx2(&origins, &directions, present),
                    }
                };
                assert_eq!(fields(avx2), fields(expected), "case {case} (AVX2)");
            }
        }
        assert!(
            several > 1000,
            "only {several} packets from several origins"
        );
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn of_lanes_avx2(
        origins: &[[f32; PACKET]; 3],
        directions: &[[f32; PACKET]; 3],
        present: u16,
    ) -> PacketInterval {
        PacketInterval::of_rays::<crate::simd::Avx2>(origins, directions, present)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn of_directions_avx2(
        origin: Vec3,
        directions: &[[f32; PACKET]; 3],
        present: u16,
    ) -> PacketInterval {
        PacketInterval::of_directions::<crate::simd::Avx2>(origin, directions, present)
    }

    /// Rays from different origins (orthographic views) have an interval
    /// over the range of their padded origins; no ray, none.
    #[test]
    fn rays_from_several_origins_have_an_interval_over_their_origins() {
        let slabs = [
            Some(SlabRay::new(Vec3::new(0.0, 2.0, -1.0), Vec3::Z)),
            None,
            Some(SlabRay::new(Vec3::new(1.0, -3.0, -1.0), Vec3::Z)),
        ];
        let interval = PacketInterval::of(&slabs).expect("rays");
        assert!(!interval.one_origin);
        for slab in slabs.iter().flatten() {
            for a in 0..3 {
                let [lo, hi] = interval.origin_lo;
                assert!(lo[a] <= slab.origin_lo[a] && slab.origin_lo[a] <= hi[a]);
                let [lo, hi] = interval.origin_hi;
                assert!(lo[a] <= slab.origin_hi[a] && slab.origin_hi[a] <= hi[a]);
            }
        }
        assert!(PacketInterval::of(&slabs[..2]).expect("one ray").one_origin);
        assert!(PacketInterval::of(&[None]).is_none());
    }
}
