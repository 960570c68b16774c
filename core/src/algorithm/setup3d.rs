//! Setup of the 3D family (paper §3.2) and of homogeneous 2D rasterization: edge
//! functions with no projection and no clipping; a conservative screen box only
//! bounds the search.

use std::mem::MaybeUninit;

use glam::Vec3;
use rayon::prelude::*;

use super::tiles::{ItemBox, Setups};
use crate::camera::View;
use crate::edge::{
    CurvedTriangle, EightTriangles, HomogeneousVertex, Shared3D, Stored, Triangle3D, Triangle3D64,
};
use crate::ground::PixelRect;
use crate::ground::SampleSpan;
use crate::prepared::PreparedScene;
use crate::screen_boxes::{PixelRects, ScreenBoxes, rects_eight};
use crate::simd::{self, EightIds, Lanes, first_lanes};

/// Every drawable triangle with samples on screen, set up with 3D edge functions.
pub(crate) fn setup_3d<'a>(
    scene: &'a PreparedScene,
    view: &'a View,
    span: SampleSpan,
) -> Setups<'a, Triangle3D> {
    let shared = shared_3d(scene, view, false);
    let mesh = &scene.scene.mesh;
    if !LaneMesh::applies(view, &mesh.positions, &mesh.triangles) {
        return setup_visible(scene, view, span, shared, Triangle3D::setup_eight);
    }
    let boxes = ScreenBoxes::new(scene, view);
    let lanes = LaneMesh::new(&boxes, &mesh.positions, &mesh.triangles, view, span);
    set_up_in_lanes(&lanes, &scene.drawable, false, shared)
}

/// [`setup_slots`] of [`Triangle3D`]s: every BVH slot's triangle set up
/// with 3D edge functions, in lanes a block of slots at a time where the
/// view allows ([`setup_3d_block`]).
pub(crate) fn setup_slots_3d<'a>(
    scene: &'a PreparedScene,
    view: &'a View,
    span: SampleSpan,
) -> Setups<'a, Triangle3D> {
    let shared = slot_shared_3d(scene, view);
    let positions = &scene.slot_positions;
    if !LaneMesh::applies(view, positions, &scene.slot_vertices) {
        return setup_slots(scene, view, span, shared, Triangle3D::setup_eight);
    }
    let boxes = ScreenBoxes::of_slots(scene, view);
    let lanes = LaneMesh::new(&boxes, positions, &scene.slot_vertices, view, span);
    set_up_in_lanes(&lanes, &scene.slot_triangles, true, shared)
}

/// Triangles per block of the setup in lanes ([`setup_3d_block`]): eight
/// eights, whose lanes with a box are packed into as few setups as they fill.
const BLOCK: usize = 64;

/// The triangles `ids` set up in lanes ([`setup_3d_block`]), a block at a
/// time: `mesh`'s records by id, or (`by_slot`) the records in a row, one
/// per item (the BVH's slots, whose triangles `ids` lists). Each block
/// writes its items' boxes and records straight into their places in the
/// two arrays, not into a block on the stack then copied there (on
/// `teapots`, a million items, that copy was 64 MB and 6% of a frame's
/// samples; setup takes 0.95× the time without it).
fn set_up_in_lanes<'a>(
    mesh: &LaneMesh,
    ids: &[u32],
    by_slot: bool,
    shared: Shared3D<'a>,
) -> Setups<'a, Triangle3D> {
    let len = ids.len();
    let mut boxes: Vec<ItemBox> = Vec::with_capacity(len);
    let mut triangles: Vec<Option<Triangle3D>> = Vec::with_capacity(len);
    let spare = (
        &mut boxes.spare_capacity_mut()[..len],
        &mut triangles.spare_capacity_mut()[..len],
    );
    (ids.par_chunks(BLOCK), spare.0.par_chunks_mut(BLOCK))
        .into_par_iter()
        .zip(spare.1.par_chunks_mut(BLOCK))
        .enumerate()
        .for_each(|(block, ((ids, boxes), triangles))| {
            let run = by_slot.then_some((block * BLOCK) as u32);
            // The block writes every box again; filling them first (768
            // bytes, in cache) is what lets `set_len` below rest on this
            // function alone, not on the block's code.
            let boxes = filled(boxes, ItemBox::NONE);
            let triangles = filled(triangles, None);
            setup_3d_block(mesh, ids, run, boxes, triangles);
        });
    // SAFETY: the chunks of the first `len` spare places of each array
    // cover them, and every place of each was written (`filled`) above; a
    // panic there never reaches this line.
    unsafe {
        boxes.set_len(len);
        triangles.set_len(len);
    }
    Setups {
        boxes,
        triangles,
        shared,
    }
}

/// `places`, every one set to `value`, as values (what the unstable
/// `write_filled` of `[MaybeUninit<T>]` does).
fn filled<T: Copy>(places: &mut [MaybeUninit<T>], value: T) -> &mut [T] {
    for place in places.iter_mut() {
        place.write(value);
    }
    // SAFETY: every place was written just above, and `MaybeUninit<T>` has
    // `T`'s size and alignment, so the slice is one of `T`s.
    unsafe { &mut *(std::ptr::from_mut(places) as *mut [T]) }
}

/// What a setup in lanes ([`setup_3d_block`]) reads: the mesh's
/// positions and vertex records (`[u32; 3]` per triangle) as flat arrays
/// the lanes gather from, the vertices' projections, the view.
struct LaneMesh<'a> {
    positions: &'a [Vec3],
    records: &'a [u32],
    boxes: &'a ScreenBoxes,
    view: &'a View,
    span: SampleSpan,
}

impl<'a> LaneMesh<'a> {
    /// Whether the lanes apply: a planar view, and a mesh small enough for
    /// 32-bit lane offsets into its flat arrays.
    fn applies(view: &View, positions: &[Vec3], records: &[[u32; 3]]) -> bool {
        let fits = |n: usize| n < (i32::MAX / 4) as usize;
        view.sphere.is_none() && fits(positions.len()) && fits(records.len())
    }

    fn new(
        boxes: &'a ScreenBoxes,
        positions: &'a [Vec3],
        records: &'a [[u32; 3]],
        view: &'a View,
        span: SampleSpan,
    ) -> LaneMesh<'a> {
        debug_assert!(LaneMesh::applies(view, positions, records));
        LaneMesh {
            positions,
            records: records.as_flattened(),
            boxes,
            view,
            span,
        }
    }
}

simd::dispatch! {
    /// The screen boxes and 3D setups of the items `ids` (at most
    /// [`BLOCK`], triangle ids), each exactly as [`ScreenBoxes::rect`] and
    /// [`Triangle3D::setup_eight`] make them: the records are `ids`
    /// themselves, or (`run`) the ones in a row from `run`. Boxes come
    /// eight at a time; then only the items with one are set up, packed
    /// eight to a setup — a mesh of sub-pixel triangles (most of whose
    /// boxes hold no sample) sets up each triangle with samples once, not
    /// every eight that holds one.
    ///
    /// Item `k`'s box and setup go to `boxes[k]` and `triangles[k]`, which
    /// hold [`ItemBox::NONE`] and `None` before (one place per item).
    fn setup_3d_block<>(
        mesh: &LaneMesh,
        ids: &[u32],
        run: Option<u32>,
        boxes: &mut [ItemBox],
        triangles: &mut [Option<Triangle3D>],
    ) -> () => setup_3d_block_on
}

#[inline(always)]
fn setup_3d_block_on<L: Lanes>(
    mesh: &LaneMesh,
    ids: &[u32],
    run: Option<u32>,
    boxes: &mut [ItemBox],
    triangles: &mut [Option<Triangle3D>],
) {
    debug_assert!(!ids.is_empty() && ids.len() <= BLOCK);
    assert!(boxes.len() == ids.len() && triangles.len() == ids.len());
    // The items with a box not yet set up: their records, and where they
    // are. Every lane of an eight is written and the count steps by whether
    // it has a box, so at most fifteen wait (the lanes with a box are as
    // many as no predictor foresees: a branch per lane missed a third of
    // the time on the teapots).
    let (mut packed, mut at, mut n) = ([0u32; 16], [0usize; 16], 0);
    for (e, eight) in ids.chunks(8).enumerate() {
        // Each lane's record (past the chunk's end, its last one).
        let items = match run {
            Some(first) => {
                let last = eight.len() - 1;
                std::array::from_fn(|l| first + (e * 8 + l.min(last)) as u32)
            }
            None => *EightIds::of(eight).get(),
        };
        let rects = rects_eight_lanes::<L>(mesh, items, eight.len());
        let [x0, y0, x1, y1] = rects.bounds::<L>();
        // Lanes past the chunk's end have no box (nor a place in `boxes`).
        let mut kept = [ItemBox::NONE; 8];
        for l in 0..8 {
            let keep = rects.some >> l & 1 == 1;
            let id = eight[l.min(eight.len() - 1)];
            kept[l] = ItemBox::kept([x0[l], y0[l], x1[l], y1[l]], id, keep);
            (packed[n], at[n]) = (items[l], e * 8 + l);
            n += usize::from(keep);
        }
        boxes[e * 8..][..eight.len()].copy_from_slice(&kept[..eight.len()]);
        if n >= 8 {
            set_up_packed::<L>(mesh, &packed, &at, 8, (boxes, triangles));
            packed.copy_within(8.., 0);
            at.copy_within(8.., 0);
            n -= 8;
        }
    }
    if n > 0 {
        for l in n..8 {
            packed[l] = packed[n - 1];
        }
        set_up_packed::<L>(mesh, &packed, &at, n, (boxes, triangles));
    }
}

/// The boxes of the first `n` (at least one) of the eight triangles with
/// records `items` ([`ScreenBoxes::rects_lanes`]).
#[inline(always)]
fn rects_eight_lanes<L: Lanes>(mesh: &LaneMesh, items: [u32; 8], n: usize) -> PixelRects {
    let vertices = simd::gather_xyz_u32::<L>(mesh.records, 3, items);
    (mesh.boxes).rects_lanes::<L>(
        &vertices,
        first_lanes(n),
        mesh.positions,
        mesh.view,
        mesh.span,
    )
}

/// The first `n` (at most eight) of the triangles with records `items`
/// (the last one repeated past them up to eight), each with a box, set up
/// in lanes ([`Triangle3D::setup_lanes`]) into item `at[l]` of the
/// block's places; an item whose setup is `None` loses its box.
#[inline(always)]
fn set_up_packed<L: Lanes>(
    mesh: &LaneMesh,
    items: &[u32; 16],
    at: &[usize; 16],
    n: usize,
    (boxes, triangles): (&mut [ItemBox], &mut [Option<Triangle3D>]),
) {
    let items = *items.first_chunk::<8>().expect("16 > 8");
    let vertices = simd::gather_xyz_u32::<L>(mesh.records, 3, items);
    let flat = bytemuck::cast_slice(mesh.positions);
    let corners = [
        L::gather_xyz(flat, 3, vertices[0]),
        L::gather_xyz(flat, 3, vertices[1]),
        L::gather_xyz(flat, 3, vertices[2]),
    ];
    let corners_of = |l: usize| vertices.map(|v| mesh.positions[v[l] as usize]);
    Triangle3D::setup_lanes(
        &corners,
        first_lanes(n),
        mesh.view,
        corners_of,
        |l, set_up| match set_up {
            Some(triangle) => triangles[at[l]] = Some(triangle),
            None => boxes[at[l]] = ItemBox::NONE,
        },
    );
}

simd::dispatch! {
    /// [`Triangle3D::setup`] of the triangles with corners `corners[slots[l]]`
    /// for the lanes of `wanted`: the same setups, made eight at a time
    /// ([`Triangle3D::setup_lanes`]) — the leaf triangles a BVH node's
    /// frustum reaches (paper §3.2, Fig. 7).
    pub(crate) fn leaf_setups_3d<>(
        corners: &[[Vec3; 3]],
        slots: [u32; 8],
        wanted: u8,
        view: &View,
    ) -> [Option<Triangle3D>; 8] => leaf_setups_3d_on
}

#[inline(always)]
fn leaf_setups_3d_on<L: Lanes>(
    corners: &[[Vec3; 3]],
    slots: [u32; 8],
    wanted: u8,
    view: &View,
) -> [Option<Triangle3D>; 8] {
    // Corner `k` of slot `s`: floats `9s + 3k ..`, a row of the floats from `3k` on.
    let flat: &[f32] = bytemuck::cast_slice(corners);
    let lanes = [
        L::gather_xyz(flat, 9, slots),
        L::gather_xyz(&flat[3..], 9, slots),
        L::gather_xyz(&flat[6..], 9, slots),
    ];
    let mut out = [None; 8];
    let corners_of = |l: usize| corners[slots[l] as usize];
    Triangle3D::setup_lanes(&lanes, wanted, view, corners_of, |l, t| out[l] = t);
    out
}

/// [`leaf_setups_3d`] in f64, one at a time ([`Triangle3D64::setup`]).
pub(crate) fn leaf_setups_3d_f64(
    corners: &[[Vec3; 3]],
    slots: [u32; 8],
    wanted: u8,
    view: &View,
) -> [Option<Triangle3D64>; 8] {
    std::array::from_fn(|l| match wanted >> l & 1 {
        1 => Triangle3D64::setup(&corners[slots[l] as usize], view),
        _ => None,
    })
}

/// What the view's [`Triangle3D`]s share, set up by the 3D setup or the
/// homogeneous one.
pub(crate) fn shared_3d<'a>(
    scene: &'a PreparedScene,
    view: &'a View,
    homogeneous: bool,
) -> Shared3D<'a> {
    let mesh = &scene.scene.mesh;
    Shared3D::of_mesh(view, homogeneous, &mesh.positions, &mesh.triangles)
}

/// What the view's [`Triangle3D`]s share, set up by the 3D setup, with their
/// vertices by BVH slot: a ray caster or a BVH traversal knows its leaf
/// triangles' slots, and finds their corners in one read.
pub(crate) fn slot_shared_3d<'a>(scene: &'a PreparedScene, view: &'a View) -> Shared3D<'a> {
    Shared3D::of_corners(view, false, &scene.slot_corners)
}

/// [`setup_3d`] in f64.
pub(crate) fn setup_3d_f64<'a>(
    scene: &'a PreparedScene,
    view: &'a View,
    span: SampleSpan,
) -> Setups<'a, Triangle3D64> {
    setup_visible(scene, view, span, (), one_by_one(Triangle3D64::setup))
}

/// Every drawable triangle with samples on a non-planar viewport, set up with 3D
/// edge functions evaluated per sample direction (paper §3.5).
pub(crate) fn setup_curved<'a>(
    scene: &'a PreparedScene,
    view: &'a View,
    span: SampleSpan,
) -> Setups<'a, CurvedTriangle> {
    setup_visible(scene, view, span, (), one_by_one(CurvedTriangle::setup))
}

/// Every drawable triangle with samples on screen, set up for homogeneous 2D
/// rasterization (no clipping). Every vertex is transformed to homogeneous
/// pixel coordinates once (as a vertex shader would), not once per triangle.
pub(crate) fn setup_homogeneous<'a>(
    scene: &'a PreparedScene,
    view: &'a View,
    span: SampleSpan,
) -> Setups<'a, Triangle3D> {
    let points: Vec<HomogeneousVertex> = (scene.scene.mesh.positions.par_iter())
        .map(|&p| HomogeneousVertex::of(p, view))
        .collect();
    let setup = |t: &EightTriangles<'a>, view: &'a View| {
        Triangle3D::setup_homogeneous_eight(t, &points, view)
    };
    let shared = shared_3d(scene, view, true);
    setup_visible(scene, view, span, shared, setup)
}

/// A setup of eight triangles at a time, such as [`Triangle3D::setup_eight`].
pub(crate) trait SetupEight<'a, T>:
    Fn(&EightTriangles<'a>, &'a View) -> [Option<T>; 8] + Sync
{
}

impl<'a, T, F> SetupEight<'a, T> for F where
    F: Fn(&EightTriangles<'a>, &'a View) -> [Option<T>; 8] + Sync
{
}

/// A one-triangle setup applied lane by lane.
pub(crate) fn one_by_one<'a, T>(
    setup: impl Fn(&'a [Vec3; 3], &'a View) -> Option<T> + Sync,
) -> impl SetupEight<'a, T> {
    move |t: &EightTriangles<'a>, view: &'a View| t.each(|l| setup(t.corners[l], view))
}

/// Every BVH slot's triangle set up by `setup` with its conservative screen
/// box, in slot order (from the scene's slot-ordered copies of positions and
/// vertex indices: memory read in order), eight slots at a time. `shared`
/// finds the vertices by slot ([`slot_shared_3d`] for a [`Triangle3D`]).
pub(crate) fn setup_slots<'a, T: Stored>(
    scene: &'a PreparedScene,
    view: &'a View,
    span: SampleSpan,
    shared: T::Shared<'a>,
    setup: impl SetupEight<'a, T>,
) -> Setups<'a, T> {
    let boxes = ScreenBoxes::of_slots(scene, view);
    let positions = &scene.slot_positions;
    let chunks = (scene.slot_corners.par_chunks(8))
        .zip(scene.slot_vertices.par_chunks(8))
        .zip(scene.slot_triangles.par_chunks(8));
    let eights = chunks.map(|((p, vertices), ids)| {
        let mut eight = EightTriangles {
            corners: lanes_of(p),
            vertices: lanes_of(vertices).map(|v| *v),
            present: 0,
        };
        let rects = rects_of(&boxes, &mut eight, p.len(), positions, view, span);
        paired(|l| rects[l], lanes_of(ids), setup(&eight, view))
    });
    flattened(eights.unzip(), scene.slot_triangles.len(), shared)
}

/// Eight lanes' boxes (with the triangles' ids) and set-up triangles,
/// `None` in both where either is.
#[inline(always)]
fn paired<T>(
    rects: impl Fn(usize) -> Option<PixelRect>,
    ids: [&u32; 8],
    mut triangles: [Option<T>; 8],
) -> ([ItemBox; 8], [Option<T>; 8]) {
    let mut boxes = [ItemBox::NONE; 8];
    for l in 0..8 {
        match rects(l) {
            Some(rect) if triangles[l].is_some() => boxes[l] = ItemBox::new(rect, *ids[l]),
            _ => triangles[l] = None,
        }
    }
    (boxes, triangles)
}

/// The first `len` items of chunks of `N`, sharing `shared`.
fn flattened<'a, T: Stored, const N: usize>(
    (boxes, triangles): (Vec<[ItemBox; N]>, Vec<[Option<T>; N]>),
    len: usize,
    shared: T::Shared<'a>,
) -> Setups<'a, T> {
    let (mut boxes, mut triangles) = (boxes.into_flattened(), triangles.into_flattened());
    boxes.truncate(len);
    triangles.truncate(len);
    Setups {
        boxes,
        triangles,
        shared,
    }
}

/// Up to eight values as lanes (the last one repeated past the end).
#[inline]
fn lanes_of<T>(v: &[T]) -> [&T; 8] {
    std::array::from_fn(|l| &v[l.min(v.len() - 1)])
}

/// The screen boxes of the first `n` of `eight`'s triangles (vertices of
/// the mesh with `positions`), whose `present` mask becomes the lanes that
/// have one (the lanes to set up).
#[inline]
fn rects_of(
    boxes: &ScreenBoxes,
    eight: &mut EightTriangles,
    n: usize,
    positions: &[Vec3],
    view: &View,
    span: SampleSpan,
) -> [Option<PixelRect>; 8] {
    let rects = rects_eight(boxes, &eight.vertices, n, positions, view, span);
    eight.present = 0;
    for (l, rect) in rects.iter().enumerate() {
        eight.present |= u8::from(rect.is_some()) << l;
    }
    rects
}

/// Every drawable triangle set up by `setup` with its conservative screen
/// box: one item per triangle, in order (exactly sized, parallel collects of
/// eight at a time: no chunks to concatenate); `None` for the ones off
/// screen or edge-on.
fn setup_visible<'a, T: Stored>(
    scene: &'a PreparedScene,
    view: &'a View,
    span: SampleSpan,
    shared: T::Shared<'a>,
    setup: impl SetupEight<'a, T>,
) -> Setups<'a, T> {
    let boxes = ScreenBoxes::new(scene, view);
    let (positions, corners) = (&scene.scene.mesh.positions, &scene.scene.mesh.triangles);
    let eights = (scene.drawable.par_chunks(8).enumerate()).map(|(chunk, ids)| {
        // The slot-ordered corners are scattered in id order: the next
        // eight triangles' are on their way while these are set up.
        let next = scene.drawable.get((chunk + 1) * 8..).unwrap_or_default();
        for &id in next.iter().take(8) {
            if let Some(corners) = scene.slot_corners.get(scene.slot_of[id as usize] as usize) {
                simd::prefetch(corners);
            }
        }
        let id = lanes_of(ids).map(|&id| id as usize);
        let mut eight = EightTriangles {
            corners: id.map(|id| &scene.slot_corners[scene.slot_of[id] as usize]),
            vertices: id.map(|id| corners[id]),
            present: 0,
        };
        let rects = rects_of(&boxes, &mut eight, ids.len(), positions, view, span);
        paired(|l| rects[l], lanes_of(ids), setup(&eight, view))
    });
    flattened(eights.unzip(), scene.drawable.len(), shared)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aa::{AaMode, SamplePattern};
    use crate::{Camera, Viewport};

    type Kernel = fn(&LaneMesh, &[u32], Option<u32>, &mut [ItemBox], &mut [Option<Triangle3D>]);

    /// A camera at a random place looking about down −z with a vertical
    /// field of `fov_y_deg`.
    fn looking_down_z(rng: &mut fastrand::Rng, fov_y_deg: f32) -> Camera {
        let eye = Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 4.0;
        Camera {
            name: "test".into(),
            eye,
            target: eye - Vec3::Z + Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, 0.0),
            up: Vec3::Y,
            viewport: Viewport::Perspective { fov_y_deg },
            near: Some(0.1),
        }
    }

    /// `kernel` gives every item the box [`ScreenBoxes::rect`] gives and the
    /// set-up triangle the eight-at-a-time path gives
    /// ([`Triangle3D::setup_eight`], checked against the one-triangle form),
    /// bit for bit, whichever other items of its block have a box (which
    /// decides the lanes it is set up in): random meshes of shared vertices
    /// on screen, off it, across the near plane and behind the eye; listed
    /// and run records; full and short blocks.
    fn lanes_match_the_eight_path(kernel: Kernel) {
        let mut rng = fastrand::Rng::with_seed(31);
        let (mut checked, mut set_up, mut scalar_boxes, mut packed) = (0, 0, 0, 0);
        for case in 0..300 {
            let camera = looking_down_z(&mut rng, [20.0, 60.0, 120.0][case % 3]);
            let eye = camera.eye;
            let size = (rng.u32(1..400), rng.u32(1..400));
            let view = View::new(&camera, size.0, size.1, 0.1).expect("a valid camera");
            let scale = [3.0, 0.05, 40.0][case / 3 % 3];
            let positions: Vec<Vec3> = (0..40)
                .map(|_| {
                    let d = Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, 0.1 - rng.f32() * 1.2);
                    eye + d * scale
                })
                .collect();
            let records: Vec<[u32; 3]> = (0..2 * BLOCK)
                .map(|_| [rng.u32(0..40), rng.u32(0..40), rng.u32(0..40)])
                .collect();
            let span = SamplePattern::of([AaMode::None, AaMode::Ssaa(16)][case % 2]).span;
            let boxes = ScreenBoxes::of(&positions, &view);
            let mesh = LaneMesh::new(&boxes, &positions, &records, &view, span);
            let n = [rng.usize(1..=BLOCK), BLOCK][case % 2];
            let bound = 2 * BLOCK as u32;
            let listed: Vec<u32> = (0..n).map(|_| rng.u32(0..bound)).collect();
            let first = rng.u32(0..=BLOCK as u32);
            let run: Vec<u32> = (0..n as u32).map(|k| first + k).collect();
            for (ids, run_from, items) in [(&listed, None, &listed), (&run, Some(first), &run)] {
                let (mut got_boxes, mut got) = (vec![ItemBox::NONE; n], vec![None; n]);
                kernel(&mesh, ids, run_from, &mut got_boxes, &mut got);
                let corners: Vec<[Vec3; 3]> = (items.iter())
                    .map(|&i| records[i as usize].map(|v| positions[v as usize]))
                    .collect();
                let rects: Vec<_> = (0..n)
                    .map(|k| boxes.rect(&corners[k], records[items[k] as usize], &view, span))
                    .collect();
                let mut with_box = 0;
                for e in 0..n.div_ceil(8) {
                    let lane = |l: usize| (e * 8 + l).min(n - 1);
                    let eight = EightTriangles {
                        corners: std::array::from_fn(|l| &corners[lane(l)]),
                        vertices: std::array::from_fn(|l| records[items[lane(l)] as usize]),
                        present: (0..8).fold(0, |m, l| {
                            m | u8::from(e * 8 + l < n && rects[lane(l)].is_some()) << l
                        }),
                    };
                    with_box += eight.present.count_ones();
                    let expected = Triangle3D::setup_eight(&eight, &view);
                    for l in 0..8 {
                        let k = e * 8 + l;
                        let at = format!("case {case}, item {k} of {n}");
                        let Some(&tri) = expected.get(l).filter(|_| k < n) else {
                            continue;
                        };
                        let expected_box = match (rects[k], tri) {
                            (Some(rect), Some(_)) => ItemBox::new(rect, ids[k]),
                            _ => ItemBox::NONE,
                        };
                        assert_eq!(got_boxes[k], expected_box, "{at}");
                        let tri = tri.filter(|_| rects[k].is_some());
                        // Debug shows the sign of a zero, which `==` does not.
                        assert_eq!(format!("{:?}", got[k]), format!("{tri:?}"), "{at}");
                        checked += 1;
                        set_up += usize::from(tri.is_some());
                        let projected = (0..3).all(|v| {
                            boxes.points[records[items[k] as usize][v] as usize][0].is_finite()
                        });
                        scalar_boxes += usize::from(!projected);
                    }
                }
                // An item with a box after one without: set up in a lane
                // other than its own.
                let first_gap = rects.iter().position(Option::is_none).unwrap_or(n);
                packed += usize::from(rects[first_gap..].iter().any(Option::is_some));
                assert!(with_box as usize <= n);
            }
        }
        assert!(
            checked > 10_000 && set_up > 1_000 && scalar_boxes > 500 && packed > 100,
            "{checked} items checked, {set_up} set up, {scalar_boxes} boxed by the scalar \
             path, {packed} blocks packed"
        );
    }

    /// The leaf setups of eight slots ([`leaf_setups_3d`]) are
    /// [`Triangle3D::setup`]'s of each slot of the lanes asked for, bit for
    /// bit, and `None` in the others: slots in any order, repeated, the
    /// last slot (whose corners end the slice), on both lane sets.
    #[test]
    fn leaf_setups_are_the_one_by_one_ones() {
        type Setups = fn(&[[Vec3; 3]], [u32; 8], u8, &View) -> [Option<Triangle3D>; 8];
        let kernels: [Setups; 2] = [leaf_setups_3d_on::<simd::Portable>, leaf_setups_3d];
        let mut rng = fastrand::Rng::with_seed(7);
        let (mut checked, mut set_up, mut last) = (0, 0, 0);
        for case in 0..200 {
            let camera = looking_down_z(&mut rng, 60.0);
            let eye = camera.eye;
            let view = View::new(&camera, 320, 200, 0.1).expect("a valid camera");
            let positions: Vec<Vec3> = (0..30)
                .map(|_| eye + Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, -rng.f32()) * 3.0)
                .collect();
            let records: Vec<[u32; 3]> = (0..20)
                .map(|_| [rng.u32(0..30), rng.u32(0..30), rng.u32(0..30)])
                .collect();
            let corners: Vec<[Vec3; 3]> = (records.iter())
                .map(|r| r.map(|v| positions[v as usize]))
                .collect();
            let slots: [u32; 8] = std::array::from_fn(|_| rng.u32(0..20));
            let wanted = rng.u8(..);
            let kernel = kernels[case % 2];
            let made = kernel(&corners, slots, wanted, &view);
            for l in 0..8 {
                let slot = slots[l] as usize;
                let tri = match wanted >> l & 1 {
                    1 => Triangle3D::setup(&corners[slot], &view),
                    _ => None,
                };
                // Debug shows the sign of a zero, which `==` does not.
                let at = format!("case {case}, lane {l}, slot {slot}");
                assert_eq!(format!("{:?}", made[l]), format!("{tri:?}"), "{at}");
                checked += 1;
                set_up += usize::from(tri.is_some());
                last += usize::from(wanted >> l & 1 == 1 && slot == 19);
            }
        }
        assert!(
            checked == 1600 && set_up > 400 && last > 20,
            "{checked} lanes checked, {set_up} set up, {last} of the last slot"
        );
    }

    #[test]
    fn portable_lanes_set_up_as_eight_at_a_time() {
        lanes_match_the_eight_path(setup_3d_block_on::<simd::Portable>);
    }

    #[test]
    fn avx2_lanes_set_up_as_eight_at_a_time() {
        #[cfg(target_arch = "x86_64")]
        assert!(
            simd::cpu_has_avx2(),
            "this test checks the AVX2 kernel, and this CPU has no AVX2"
        );
        // `setup_3d_block` takes AVX2 where the CPU has it.
        lanes_match_the_eight_path(setup_3d_block);
    }
}
