//! The continuum's one algorithm (paper Fig. 7): a recursive traversal of frusta
//! over screen regions through the BVH, steered by oracles.
//!
//! ```text
//! traverse(frustum F, node N):
//!   if is_occluded(F, N) or is_outside(F, N): return        // Fig. 6a
//!   if split_frustum(F, N): for Fi in split(F): traverse(Fi, N)  // Fig. 6b, c
//!   else if N is a leaf: rasterize(N, binning)               // Fig. 6d
//!   else: for child C of N, front to back: traverse(F, C)
//! ```
//! Every test is conservative — a node is culled only when none of its triangles
//! can win a sample of the frustum — so every setting of the oracles renders the
//! same image as `3dr-brute`.

use glam::{Vec3, Vec3A};
use obvhs::cwbvh::node::CwBvhNode;

use crate::binning::raster_triangle;
use crate::bvh::{Children, SlabRay, padded};
use crate::camera::View;
use crate::edge::Stored;
use crate::framebuffer::TileBuffer;
use crate::ground::PixelRect;
use crate::pipeline::TraversalOracles;
use crate::prepared::PreparedScene;
use crate::screen_boxes::{ScreenBoxes, rects_eight};
use crate::simd::{self, Lanes};
use crate::stats::RasterCounters;
use crate::trace::{FrustumEvent, NodeOutcome};

/// Sets up leaf triangles' edge functions for a view (f32 or f64): lane
/// `l`'s, for the lanes of the `u8`, is the triangle with the corners at BVH
/// slot `slots[l]` of the slice (`None` where it is seen edge-on, and in the
/// other lanes); the results may borrow the corners and the view.
pub(crate) type Setup<'a, T> = fn(&'a [[Vec3; 3]], [u32; 8], u8, &'a View) -> [Option<T>; 8];

/// A leaf triangle as the frusta of one work item met it: its screen box
/// (`None`: no sample on screen), whether its setup was made once a frustum
/// needed it (the setup itself is in [`LeafCache::setups`]), and whether a
/// frustum has rasterized it since.
#[derive(Clone, Copy, Debug)]
struct Leaf {
    rect: Option<PixelRect>,
    set_up: bool,
    used: bool,
}

impl Leaf {
    /// A triangle just reached, with screen box `rect`: not set up, not used.
    fn new(rect: Option<PixelRect>) -> Leaf {
        Leaf {
            rect,
            set_up: false,
            used: false,
        }
    }
}

/// A [`LeafCache`] entry that holds no triangle.
const NO_LEAF: u32 = u32::MAX;

/// The leaf triangles the frusta of one work item reached last, by BVH
/// slot: a triangle's box is made and its setup done once while it stays
/// here, however many of the Fig. 7 frusta reach it (a 256² frustum split
/// down to 8² reaches a leaf from every sub-frustum its box overlaps, one
/// after the other). Direct-mapped on the slot's low bits — a leaf's
/// triangles and its neighbours' have consecutive slots, so they do not
/// evict each other — and small enough to stay in cache beside the tile
/// (a map of every triangle reached cost more than the setups it saved on
/// a million small triangles). Kept by the worker, emptied per work item:
/// only the slots, apart from the entries (4 bytes an entry to clear, not a
/// set-up triangle's 64).
#[derive(Debug)]
pub(crate) struct LeafCache<T> {
    /// Per entry, the BVH slot it holds ([`NO_LEAF`]: none).
    slots: Vec<u32>,
    leaves: Vec<Leaf>,
    /// Per entry, its triangle's setup (`None`: seen edge-on), read only
    /// where its [`Leaf`] says it was made. Apart from the entries' boxes
    /// and flags: an `Option<Option<Triangle3D>>` beside them took 192 bytes
    /// an entry (a cache-line-aligned setup and a second line for the
    /// flags), these 64 and 24.
    setups: Vec<Option<T>>,
}

/// Entries of a [`LeafCache`] (a power of two).
const LEAF_CACHE: usize = 1024;

impl<T: Copy> Default for LeafCache<T> {
    fn default() -> Self {
        LeafCache {
            slots: vec![NO_LEAF; LEAF_CACHE],
            leaves: vec![Leaf::new(None); LEAF_CACHE],
            setups: vec![None; LEAF_CACHE],
        }
    }
}

/// Per-frustum traversal state and counters.
pub(crate) struct Traversal<'a, 't, T: Stored> {
    pub scene: &'a PreparedScene,
    pub view: &'a View,
    pub oracles: TraversalOracles,
    pub tile: &'t mut TileBuffer<'a>,
    pub setup: Setup<'a, T>,
    /// What the view's set-up triangles share (their vertices by BVH slot).
    pub shared: &'t T::Shared<'a>,
    /// The leaf triangles' screen boxes.
    pub boxes: &'t ScreenBoxes,
    /// The leaf triangles this work item set up last.
    leaves: &'t mut LeafCache<T>,
    pub counters: RasterCounters,
    pub nodes_visited: u64,
    pub setups: u64,
}

/// A node of the CWBVH: an inner node (index) or a leaf (primitive range,
/// and the inner node whose child it is).
#[derive(Clone, Copy, Debug)]
enum NodeRef {
    Inner(u32),
    Leaf { start: u32, count: u32, parent: u32 },
}

/// A box with its nearest view-axis distance, and where its screen rect
/// comes from when occlusion culling needs it.
#[derive(Clone, Copy, Debug)]
struct NodeBox<'s> {
    lo: Vec3A,
    hi: Vec3A,
    min_w: f32,
    rect: RectOf<'s>,
}

/// Where a node's screen rect ([`ScreenBoxes::node_rect`]) comes from.
#[derive(Clone, Copy, Debug)]
enum RectOf<'s> {
    /// Made from the box when read (the root).
    Own,
    /// Child `c` of a node: every child's made together in lanes when the
    /// first is read ([`ScreenBoxes::node_rects`]), then read by the others
    /// and by the frusta its own frustum splits into.
    Sibling(&'s SiblingRects<'s>, usize),
}

/// A node's children's boxes (per axis, a lane per child slot), and their
/// screen rects once one was needed.
#[derive(Debug)]
struct SiblingRects<'s> {
    lo: &'s [[f32; 8]; 3],
    hi: &'s [[f32; 8]; 3],
    /// Bit per child slot that holds a child.
    present: u8,
    rects: std::cell::OnceCell<[Option<PixelRect>; 8]>,
}

/// `n·(corner − eye)` for each box of `boxes`, `corner` its corner furthest
/// along `n` (`furthest`) or against it, in [`dot`]'s order.
#[inline(always)]
fn along<L: Lanes>(boxes: &Children<L>, eye: Vec3A, n: Vec3A, furthest: bool) -> L {
    let mut d = [L::splat(0.0); 3];
    for a in 0..3 {
        let corner = if (n[a] >= 0.0) == furthest {
            boxes.hi[a]
        } else {
            boxes.lo[a]
        };
        d[a] = (corner - L::splat(eye[a])) * L::splat(n[a]);
    }
    (d[0] + d[1]) + d[2]
}

/// `(d.x·n.x + d.y·n.y) + d.z·n.z`: glam's order, written out so that the
/// lane tests ([`ChildTests`]) round as the single-box ones.
#[inline(always)]
fn dot(d: Vec3A, n: Vec3A) -> f32 {
    (d.x * n.x + d.y * n.y) + d.z * n.z
}

/// A CWBVH node's eight children against a frustum, one child per lane: their
/// boxes decoded in registers ([`Children`]), each box's nearest view-axis
/// distance, and which boxes lie wholly outside a side plane or nearer than
/// `near` — the same tests, rounded the same way, as [`NodeBox`] and
/// `Traversal::is_outside` make for one box.
#[derive(Debug)]
struct ChildTests {
    /// Per axis, the child boxes' bounds, a lane per child slot.
    lo: [[f32; 8]; 3],
    hi: [[f32; 8]; 3],
    min_w: [f32; 8],
    /// Bit per child slot (empty slots included: the caller skips them).
    outside: u8,
}

simd::dispatch! {
    /// [`ChildTests`] of `node` against `frustum`, in the lanes of this CPU.
    fn child_tests<>(node: &CwBvhNode, frustum: &Frustum, v: &View) -> ChildTests
        => child_tests_on
}

#[inline(always)]
fn child_tests_on<L: Lanes>(node: &CwBvhNode, frustum: &Frustum, v: &View) -> ChildTests {
    let boxes = Children::<L>::decode(node);
    let eye = Vec3A::from(v.eye);
    let fw = Vec3A::from(v.forward);
    let mut outside = along(&boxes, eye, fw, true).lt(L::splat(v.near));
    for &(n, offset) in &frustum.planes {
        outside |= along(&boxes, eye, n, true).lt(L::splat(offset));
    }
    // (No closure around a lane operation: it would be compiled without the
    // lanes' instruction set.)
    let [lo, hi] = [boxes.lo, boxes.hi];
    ChildTests {
        lo: [lo[0].to_array(), lo[1].to_array(), lo[2].to_array()],
        hi: [hi[0].to_array(), hi[1].to_array(), hi[2].to_array()],
        min_w: along(&boxes, eye, fw, false).to_array(),
        outside,
    }
}

/// A frustum: its pixels, the four side planes through their borders, and
/// its centre ray — computed once when the frustum is made, not at every node
/// it meets — and the hierarchical w-buffer's depths over its pixels, read
/// again only when the buffer has changed (a 256² frustum spans 1,024 cells,
/// and meets many nodes between two leaves).
#[derive(Clone, Debug)]
struct Frustum {
    rect: PixelRect,
    /// [`Hiz::depths`](crate::hiz::Hiz::depths) of `rect` and the
    /// [`Hiz::version`](crate::hiz::Hiz::version) it was read at.
    depths: std::cell::Cell<Option<(u64, f32, f32)>>,
    /// Each side plane as `n·(p − eye) ≥ offset` (through the eye under
    /// perspective, parallel to the view axis under orthographic projection).
    planes: [(Vec3A, f32); 4],
    /// The ray through the rect's centre (for `split_frustum`).
    centre: SlabRay,
}

impl Frustum {
    fn new(rect: PixelRect, v: &View) -> Frustum {
        let (fw, right, up) = (v.forward, v.right, v.up);
        // Image x of a camera-space point is (x/w / half_x + 1)·W/2 (orthographic:
        // x instead of x/w); border lines at the rect's pixel edges (half a pixel
        // beyond its outermost samples).
        let kx = |x: u32| (2.0 * x as f32 / v.width as f32 - 1.0) * v.half_x;
        let ky = |y: u32| (1.0 - 2.0 * y as f32 / v.height as f32) * v.half_y;
        let (left, right_border) = (kx(rect.x0), kx(rect.x1));
        let (top, bottom) = (ky(rect.y0), ky(rect.y1));
        let planes = if v.is_orthographic() {
            [
                (right, left),
                (-right, -right_border),
                (-up, -top),
                (up, bottom),
            ]
        } else {
            [
                (right - fw * left, 0.0),
                (fw * right_border - right, 0.0),
                (fw * top - up, 0.0),
                (up - fw * bottom, 0.0),
            ]
        };
        let (cx, cy) = (
            (rect.x0 + rect.x1) as f32 * 0.5,
            (rect.y0 + rect.y1) as f32 * 0.5,
        );
        Frustum {
            rect,
            depths: std::cell::Cell::new(None),
            planes: planes.map(|(n, offset)| (Vec3A::from(n), offset)),
            centre: SlabRay::new(v.origin(cx, cy), v.direction(cx, cy)),
        }
    }
}

/// A child's place in the visiting order as one integer: its nearest
/// distance `w` in [`f32::total_cmp`]'s order (the sign bit flipped on
/// positive values, every bit on negative ones), then its slot — ordered
/// as a stable sort of the children by distance orders them, with no
/// comparison closure in the sort.
#[inline]
fn visiting_key(w: f32, slot: u8) -> u64 {
    let bits = w.to_bits();
    let ordered = if bits >> 31 == 1 {
        !bits
    } else {
        bits | 1 << 31
    };
    u64::from(ordered) << 8 | u64::from(slot)
}

/// The slot of a [`visiting_key`].
#[inline]
fn visited_slot(key: u64) -> usize {
    (key & 0xff) as usize
}

/// Sorts a node's (at most eight, distinct) visiting keys in place, by
/// insertion. (`sort_unstable` gives the same order with as many
/// instructions, but 6% more mispredicted branches on the dragon's
/// `3dr-full`: callgrind, `scripts/instructions.py`.)
#[inline]
fn sort_keys(keys: &mut [u64]) {
    for i in 1..keys.len() {
        let key = keys[i];
        let mut j = i;
        while j > 0 && keys[j - 1] > key {
            keys[j] = keys[j - 1];
            j -= 1;
        }
        keys[j] = key;
    }
}

impl<'a, 't, T: Stored + Copy> Traversal<'a, 't, T> {
    /// A traversal of the frustum over `tile`'s pixels, leaf triangles set up
    /// by `setup` over their `boxes`, once each in `leaves` (emptied first).
    pub fn new(
        scene: &'a PreparedScene,
        view: &'a View,
        oracles: TraversalOracles,
        tile: &'t mut TileBuffer<'a>,
        (setup, shared, boxes): (Setup<'a, T>, &'t T::Shared<'a>, &'t ScreenBoxes),
        leaves: &'t mut LeafCache<T>,
    ) -> Self {
        leaves.slots.fill(NO_LEAF);
        Traversal {
            scene,
            view,
            oracles,
            tile,
            setup,
            shared,
            boxes,
            leaves,
            counters: RasterCounters::default(),
            nodes_visited: 0,
            setups: 0,
        }
    }

    /// Traverses the whole tile from the BVH root.
    pub fn run(&mut self) {
        let bvh = &self.scene.bvh.cwbvh;
        if bvh.nodes.is_empty() {
            return;
        }
        let root = self.node_box(bvh.total_aabb.min, bvh.total_aabb.max);
        if self.oracles.final_depth {
            // The oracle: an uncounted traversal renders the tile first, so
            // that the counted one's occlusion tests read the depths it ends
            // with (the same winners are written again: the image is the same).
            let trace = self.tile.trace.take();
            let f = Frustum::new(self.tile.rect(), self.view);
            self.traverse(&f, NodeRef::Inner(0), root);
            self.tile.trace = trace;
            self.tile.restart_counts();
            self.leaves.slots.fill(NO_LEAF);
            (self.counters, self.nodes_visited, self.setups) = (RasterCounters::default(), 0, 0);
        }
        let f = Frustum::new(self.tile.rect(), self.view);
        self.counters.frusta_created += 1;
        self.tile
            .record(|t| t.frusta.push((f.rect, FrustumEvent::Created)));
        self.traverse(&f, NodeRef::Inner(0), root);
    }

    fn node_box(&self, min: Vec3A, max: Vec3A) -> NodeBox<'static> {
        let (lo, hi) = padded(min, max);
        // Nearest w over the box: the corner furthest against the view axis.
        let f = Vec3A::from(self.view.forward);
        let corner = Vec3A::select(f.cmpge(Vec3A::ZERO), lo, hi);
        NodeBox {
            lo,
            hi,
            min_w: dot(corner - Vec3A::from(self.view.eye), f),
            rect: RectOf::Own,
        }
    }

    /// Fig. 7: `node` met by `frustum`, tested against it first.
    fn traverse(&mut self, frustum: &Frustum, node: NodeRef, b: NodeBox) {
        let outside = self.oracles.outside && self.is_outside(frustum, &b);
        self.visit(frustum, node, b, outside);
    }

    /// Fig. 7 for a node whose `is_outside` answer is known (`outside`, false
    /// when that oracle is off).
    fn visit(&mut self, frustum: &Frustum, node: NodeRef, b: NodeBox, outside: bool) {
        self.nodes_visited += 1;
        let f = frustum.rect;
        // 1. is_outside / is_occluded (Fig. 6a).
        let node_box = |outcome| ([b.lo.to_array(), b.hi.to_array()], outcome);
        if outside {
            self.counters.nodes_culled_outside += 1;
            self.tile
                .record(|t| t.nodes.push(node_box(NodeOutcome::Outside)));
            return;
        }
        if self.oracles.occluded && self.is_occluded(frustum, &b) {
            self.counters.nodes_culled_occluded += 1;
            self.tile
                .record(|t| t.nodes.push(node_box(NodeOutcome::Occluded)));
            return;
        }
        self.tile
            .record(|t| t.nodes.push(node_box(NodeOutcome::Entered)));
        // 2. split_frustum (Fig. 6b, c).
        if let Some(min) = self.oracles.split
            && self.should_split(frustum, &b, min)
        {
            self.counters.frusta_split += 1;
            self.tile
                .record(|t| t.frusta.push((f, FrustumEvent::Split)));
            // The first halves take the middle pixel of an odd side.
            let (mx, my) = ((f.x0 + f.x1).div_ceil(2), (f.y0 + f.y1).div_ceil(2));
            for q in [
                PixelRect::new(f.x0, f.y0, mx, my),
                PixelRect::new(mx, f.y0, f.x1, my),
                PixelRect::new(f.x0, my, mx, f.y1),
                PixelRect::new(mx, my, f.x1, f.y1),
            ] {
                if !q.is_empty() {
                    self.counters.frusta_created += 1;
                    self.tile
                        .record(|t| t.frusta.push((q, FrustumEvent::Created)));
                    self.traverse(&Frustum::new(q, self.view), node, b);
                }
            }
            return;
        }
        match node {
            // 3. generate_samples at leaves (Fig. 6d).
            NodeRef::Leaf {
                start,
                count,
                parent,
            } => self.rasterize_leaf(f, start, count, parent),
            // 4. Children, nearest first.
            NodeRef::Inner(index) => self.visit_children(frustum, index),
        }
    }

    /// The children of inner node `index`, nearest first: decoded and tested
    /// against the frustum's planes eight at a time ([`ChildTests`]), then
    /// visited one by one.
    fn visit_children(&mut self, frustum: &Frustum, index: u32) {
        let n = &self.scene.bvh.cwbvh.nodes[index as usize];
        let tests = child_tests(n, frustum, self.view);
        let outside = if self.oracles.outside {
            tests.outside
        } else {
            0
        };
        let ChildTests { lo, hi, min_w, .. } = tests;
        // Sorted by distance, ties in slot order ([`visiting_key`]), each
        // child's box and reference made when it is visited.
        let mut order = [0u64; 8];
        let (mut len, mut present) = (0, 0u8);
        for (c, &w) in min_w.iter().enumerate() {
            if !n.is_child_empty(c) {
                order[len] = visiting_key(w, c as u8);
                len += 1;
                present |= 1 << c;
            }
        }
        let siblings = SiblingRects {
            lo: &lo,
            hi: &hi,
            present,
            rects: std::cell::OnceCell::new(),
        };
        sort_keys(&mut order[..len]);
        // What the children inside the frustum will read first is on its way
        // while the nearest is visited: an inner child's node, a leaf's
        // vertex indices and corners (each a likely miss on a large scene).
        let scene = self.scene;
        for &key in &order[..len] {
            let c = visited_slot(key);
            if outside >> c & 1 == 1 {
                continue;
            }
            if n.is_leaf(c) {
                let (start, count) = n.child_primitives(c);
                let slots = start as usize..(start + count) as usize;
                if let (Some(v), Some(p)) = (
                    scene.slot_vertices.get(slots.clone()),
                    scene.slot_corners.get(slots),
                ) {
                    simd::prefetch_short(v);
                    simd::prefetch_short(p);
                }
            } else if let Some(child) = scene.bvh.cwbvh.nodes.get(n.child_node_index(c) as usize) {
                simd::prefetch(child);
            }
        }
        for &key in &order[..len] {
            let c = visited_slot(key);
            let min_w = min_w[c];
            let r = if n.is_leaf(c) {
                let (start, count) = n.child_primitives(c);
                NodeRef::Leaf {
                    start,
                    count,
                    parent: index,
                }
            } else {
                NodeRef::Inner(n.child_node_index(c))
            };
            let b = NodeBox {
                lo: Vec3A::new(lo[0][c], lo[1][c], lo[2][c]),
                hi: Vec3A::new(hi[0][c], hi[1][c], hi[2][c]),
                min_w,
                rect: RectOf::Sibling(&siblings, c),
            };
            self.visit(frustum, r, b, outside >> c & 1 == 1);
        }
    }

    /// Is the box wholly outside one of the frustum's side planes, or nearer
    /// than `near`?
    fn is_outside(&self, f: &Frustum, b: &NodeBox) -> bool {
        let v = self.view;
        let eye = Vec3A::from(v.eye);
        for &(n, offset) in &f.planes {
            // The corner furthest along n.
            let corner = Vec3A::select(n.cmpge(Vec3A::ZERO), b.hi, b.lo);
            if dot(corner - eye, n) < offset {
                return true;
            }
        }
        // Wholly nearer than near: the farthest corner along the view axis.
        let fw = Vec3A::from(v.forward);
        let far = Vec3A::select(fw.cmpge(Vec3A::ZERO), b.hi, b.lo);
        dot(far - eye, fw) < v.near
    }

    /// Is the box behind what the hierarchical w-buffer holds: over the whole
    /// frustum, or over the pixels its screen box reaches in it when some
    /// other pixels of the frustum are still empty ([`crate::hiz`])? Under
    /// the `final_depth` oracle the second test reads every stored sample
    /// of those pixels instead of their cells (a cell's farthest depth
    /// covers all of its pixels, and can rise as more of them fill).
    fn is_occluded(&self, f: &Frustum, b: &NodeBox) -> bool {
        let hiz = &self.tile.hiz;
        let (farthest, nearest) = match f.depths.get() {
            Some((version, farthest, nearest)) if version == hiz.version() => (farthest, nearest),
            _ => {
                let (farthest, nearest) = hiz.depths(f.rect);
                f.depths.set(Some((hiz.version(), farthest, nearest)));
                (farthest, nearest)
            }
        };
        if b.min_w > farthest {
            return true;
        }
        let exact = self.oracles.final_depth;
        if b.min_w <= nearest && !exact {
            // Not behind any cell's held depths: no need to project the box.
            return false;
        }
        let (view, span) = (self.view, self.tile.pattern.span);
        let rect = match b.rect {
            RectOf::Own => (self.boxes).node_rect(b.lo.into(), b.hi.into(), view, span),
            RectOf::Sibling(siblings, c) => siblings.rects.get_or_init(|| {
                let (lo, hi) = (siblings.lo, siblings.hi);
                (self.boxes).node_rects(lo, hi, siblings.present, view, span)
            })[c],
        };
        rect.and_then(|r| r.intersect(f.rect))
            .is_some_and(|r| match exact {
                true => self.tile.all_nearer(r, b.min_w),
                false => self.tile.hiz.hides(r, b.min_w),
            })
    }

    /// Split when the frustum is still larger than `min` and the node is not a
    /// good fit: its box misses the frustum's centre ray, or it is small against
    /// the frustum (paper §5, "3DR frustum split").
    fn should_split(&self, frustum: &Frustum, b: &NodeBox, min: u32) -> bool {
        let f = frustum.rect;
        let (w, h) = (f.width(), f.height());
        if w.max(h) <= min {
            return false;
        }
        let v = self.view;
        if !frustum.centre.hits(b.lo, b.hi, f32::INFINITY) {
            return true;
        }
        // Projected size of the box in pixels (perspective: at its nearest distance).
        let image_height = if v.is_orthographic() {
            2.0 * v.half_y
        } else {
            2.0 * v.half_y * b.min_w.max(v.near)
        };
        let pixels_per_unit = v.height as f32 / image_height;
        let extent = (b.hi - b.lo).length() * pixels_per_unit;
        extent < w.max(h) as f32 * 0.5
    }

    /// The boxes and setups of the triangles of `node`'s leaf children that
    /// the leaf cache does not hold, made eight at a time ([`rects_eight`],
    /// `setup`) when the first of them is rasterized: a leaf holds at most
    /// three triangles, a node's leaves up to 24, so a batch fills its lanes
    /// where a leaf's would not. Setups only for the triangles whose box
    /// meets the frustum (`f`); a sibling leaf that a later frustum reaches
    /// sets up what it lacks then.
    fn prepare_leaves(&mut self, f: PixelRect, node: &CwBvhNode) {
        let (mut slots, mut len) = ([0u32; 24], 0);
        for c in 0..8 {
            if !node.is_child_empty(c) && node.is_leaf(c) {
                let (start, count) = node.child_primitives(c);
                for slot in start..start + count {
                    slots[len] = slot;
                    len += 1;
                }
            }
        }
        for eight in slots[..len].chunks(8) {
            self.prepare_eight(f, eight);
        }
    }

    /// [`Traversal::prepare_leaves`] of one to eight slots.
    fn prepare_eight(&mut self, f: PixelRect, eight: &[u32]) {
        let scene = self.scene;
        let (view, span) = (self.view, self.tile.pattern.span);
        // Lanes past the eight's end repeat its last slot.
        let slots: [u32; 8] = std::array::from_fn(|l| eight[l.min(eight.len() - 1)]);
        let entry = |l: usize| slots[l] as usize % LEAF_CACHE;
        let mut missing = 0u8;
        for (l, &slot) in eight.iter().enumerate() {
            if self.leaves.slots[entry(l)] != slot {
                missing |= 1 << l;
            }
        }
        if missing != 0 {
            let vertices = slots.map(|slot| scene.slot_vertices[slot as usize]);
            let (boxes, positions) = (self.boxes, &scene.slot_positions);
            let rects = rects_eight(boxes, &vertices, eight.len(), positions, view, span);
            for l in (0..8).filter(|l| missing >> l & 1 == 1) {
                self.leaves.slots[entry(l)] = slots[l];
                self.leaves.leaves[entry(l)] = Leaf::new(rects[l]);
            }
        }
        let mut wanted = 0u8;
        for l in 0..eight.len() {
            let leaf = &self.leaves.leaves[entry(l)];
            if !leaf.set_up && leaf.rect.is_some_and(|r| r.intersect(f).is_some()) {
                wanted |= 1 << l;
            }
        }
        if wanted != 0 {
            let made = (self.setup)(&scene.slot_corners, slots, wanted, view);
            for l in (0..8).filter(|l| wanted >> l & 1 == 1) {
                self.leaves.setups[entry(l)] = made[l];
                self.leaves.leaves[entry(l)].set_up = true;
            }
            self.setups += u64::from(wanted.count_ones());
        }
    }

    /// Rasterizes the leaf's triangles over the frustum, set up with the
    /// leaves of its `parent` node ([`Traversal::prepare_leaves`]) when the
    /// leaf cache does not hold its first, else one by one where the cache
    /// lacks them.
    fn rasterize_leaf(&mut self, f: PixelRect, start: u32, count: u32, parent: u32) {
        let scene = self.scene;
        if self.leaves.slots[start as usize % LEAF_CACHE] != start {
            self.prepare_leaves(f, &scene.bvh.cwbvh.nodes[parent as usize]);
        }
        self.tile
            .record(|t| t.frusta.push((f, FrustumEvent::Rasterized)));
        let (view, boxes, span) = (self.view, self.boxes, self.tile.pattern.span);
        let shared = self.shared;
        for slot in start..start + count {
            let entry = slot as usize % LEAF_CACHE;
            let leaf = &mut self.leaves.leaves[entry];
            if std::mem::replace(&mut self.leaves.slots[entry], slot) != slot {
                let p = &scene.slot_corners[slot as usize];
                *leaf = Leaf::new(boxes.rect(p, scene.slot_vertices[slot as usize], view, span));
            }
            let Some(clip) = leaf.rect.and_then(|rect| rect.intersect(f)) else {
                continue;
            };
            if !leaf.set_up {
                self.setups += 1;
                self.leaves.setups[entry] =
                    (self.setup)(&scene.slot_corners, [slot; 8], 1, view)[0];
                leaf.set_up = true;
            } else if leaf.used {
                self.counters.leaf_setups_reused += 1;
            }
            leaf.used = true;
            // By reference: a setup is a cache line.
            let Some(tri) = &self.leaves.setups[entry] else {
                continue;
            };
            let id = scene.slot_triangles[slot as usize];
            raster_triangle(
                self.tile,
                &tri.bind(shared, slot, id),
                id,
                clip,
                self.oracles.samples,
                &mut self.counters,
            );
        }
        if self.oracles.occluded && !self.oracles.samples.early_z {
            // Occlusion culling reads the hierarchical w-buffer: keep it current.
            self.tile.update_hiz(f);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Viewport;

    /// The visiting keys sort a node's children as a stable sort by
    /// [`f32::total_cmp`] of their distances does: random distances with
    /// ties, both zeros, negative values, infinities and NaNs, one to eight
    /// children in any slots.
    #[test]
    fn visiting_keys_order_children_as_a_stable_sort_by_distance() {
        let mut rng = fastrand::Rng::with_seed(5);
        let special = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            -f32::NAN,
        ];
        let (mut checked, mut ties) = (0, 0);
        for _ in 0..5000 {
            let len = rng.usize(1..=8);
            let mut slots: Vec<u8> = (0..8).collect();
            rng.shuffle(&mut slots);
            slots.truncate(len);
            slots.sort_unstable();
            let children: Vec<(f32, u8)> = (slots.iter())
                .map(|&c| match rng.u32(0..3) {
                    0 => (special[rng.usize(..special.len())], c),
                    1 => (rng.u32(0..3) as f32, c),
                    _ => ((rng.f32() - 0.5) * 100.0, c),
                })
                .collect();
            let mut expected = children.clone();
            expected.sort_by(|a, b| a.0.total_cmp(&b.0));
            let mut keys: Vec<u64> = (children.iter())
                .map(|&(w, c)| visiting_key(w, c))
                .collect();
            sort_keys(&mut keys);
            let got: Vec<usize> = keys.iter().map(|&k| visited_slot(k)).collect();
            let want: Vec<usize> = expected.iter().map(|&(_, c)| usize::from(c)).collect();
            assert_eq!(got, want, "{children:?}");
            checked += 1;
            ties +=
                usize::from((1..len).any(|i| expected[i - 1].0.total_cmp(&expected[i].0).is_eq()));
        }
        assert_eq!(checked, 5000);
        assert!(ties > 500, "{ties} sets with equal distances");
    }

    /// The dispatched child tests (AVX2 where the CPU has it) are the
    /// portable lanes' bit for bit, at every inner node of the soup's BVH
    /// against frusta of random rects, under perspective and orthographic
    /// views.
    #[test]
    fn both_lane_sets_test_children_alike() {
        #[cfg(target_arch = "x86_64")]
        assert!(
            simd::cpu_has_avx2(),
            "this test checks the AVX2 kernel, and this CPU has no AVX2"
        );
        let path = format!("{}/../scenes/soup.toml", env!("CARGO_MANIFEST_DIR"));
        let scene = crate::scene::load_path(path.as_ref()).expect("built-in scene loads");
        let scene = PreparedScene::new(scene);
        let camera = scene.scene.first_camera();
        let orthographic = crate::Camera {
            viewport: Viewport::Orthographic {
                height: scene.bounds.radius(),
            },
            ..camera.clone()
        };
        let nodes = &scene.bvh.cwbvh.nodes;
        let mut rng = fastrand::Rng::with_seed(9);
        let (mut compared, mut outside) = (0, 0);
        for camera in [&camera, &orthographic] {
            let view = View::new(camera, 320, 240, scene.default_near).expect("a valid camera");
            for _ in 0..20 {
                let (x0, y0) = (rng.u32(0..320), rng.u32(0..240));
                let rect = PixelRect::new(x0, y0, rng.u32(x0 + 1..=320), rng.u32(y0 + 1..=240));
                let frustum = Frustum::new(rect, &view);
                for node in nodes {
                    let portable = child_tests_on::<simd::Portable>(node, &frustum, &view);
                    let dispatched = child_tests(node, &frustum, &view);
                    // Debug shows the sign of a zero, which `==` does not.
                    assert_eq!(
                        format!("{dispatched:?}"),
                        format!("{portable:?}"),
                        "{rect:?}"
                    );
                    outside += portable.outside.count_ones();
                    compared += 1;
                }
            }
        }
        assert!(nodes.len() > 100, "{} nodes", nodes.len());
        assert_eq!(compared, 40 * nodes.len());
        assert!(outside > 1000, "{outside} children outside");
    }
}
