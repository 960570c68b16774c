//! Setup of the 3D family (paper §3.2) and of homogeneous 2D rasterization: edge
//! functions with no projection and no clipping; a conservative screen box only
//! bounds the search.

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
/// with 3D edge functions, eight slots at a time in lanes where the view
/// allows ([`setup_3d_eight`]).
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

/// The triangles `ids` set up in lanes ([`setup_3d_eight`]), eight at a
/// time: `mesh`'s records by id, or (`by_slot`) the records in a row, one
/// per item (the BVH's slots, whose triangles `ids` lists).
fn set_up_in_lanes<'a>(
    mesh: &LaneMesh,
    ids: &[u32],
    by_slot: bool,
    shared: Shared3D<'a>,
) -> Setups<'a, Triangle3D> {
    let eights = ids.par_chunks(8).enumerate().map(|(chunk, eight)| {
        let (rects, triangles) = match by_slot {
            true => setup_3d_eight(mesh, Records::Run((chunk * 8) as u32), eight.len()),
            false => {
                let listed = EightIds::of(eight);
                setup_3d_eight(mesh, Records::Listed(listed.get()), eight.len())
            }
        };
        paired(|l| rects.get(l), lanes_of(eight), triangles)
    });
    flattened(eights.unzip(), ids.len(), shared)
}

/// What a perspective setup in lanes ([`setup_3d_eight`]) reads: the mesh's
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
    /// Whether the lanes apply: a planar perspective view, and a mesh small
    /// enough for 32-bit lane offsets into its flat arrays.
    fn applies(view: &View, positions: &[Vec3], records: &[[u32; 3]]) -> bool {
        let fits = |n: usize| n < (i32::MAX / 4) as usize;
        view.sphere.is_none()
            && !view.is_orthographic()
            && fits(positions.len())
            && fits(records.len())
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

/// Which vertex records eight lanes set up.
#[derive(Clone, Copy, Debug)]
enum Records<'a> {
    /// These (lanes past the chunk's end repeat its last one).
    Listed(&'a [u32; 8]),
    /// Eight in a row from this one.
    Run(u32),
}

simd::dispatch! {
    /// The screen boxes and 3D setups of the first `n` (at least one) of
    /// eight triangles with vertex records `records`, each exactly as
    /// [`ScreenBoxes::rect`] and [`Triangle3D::setup_eight`] make them:
    /// vertex indices, projected points and corners gathered straight into
    /// lanes, with no per-lane copies between the steps.
    fn setup_3d_eight<>(
        mesh: &LaneMesh,
        records: Records,
        n: usize,
    ) -> (PixelRects, [Option<Triangle3D>; 8]) => setup_3d_eight_on
}

#[inline(always)]
fn setup_3d_eight_on<L: Lanes>(
    mesh: &LaneMesh,
    records: Records,
    n: usize,
) -> (PixelRects, [Option<Triangle3D>; 8]) {
    let items = match records {
        Records::Listed(items) => *items,
        // Past the end, the last record (`n ≥ 1`).
        Records::Run(first) => std::array::from_fn(|l| first + (l as u32).min(n as u32 - 1)),
    };
    let vertices = simd::gather_xyz_u32::<L>(mesh.records, 3, items);
    let (view, span) = (mesh.view, mesh.span);
    let rects =
        (mesh.boxes).rects_lanes::<L>(&vertices, first_lanes(n), mesh.positions, view, span);
    let present = rects.some;
    // Off-screen triangles come in runs (the mesh's order is spatial):
    // eight at once with no box skip the setup.
    if present == 0 {
        return (rects, [None; 8]);
    }
    let flat = bytemuck::cast_slice(mesh.positions);
    let corners = [
        L::gather_xyz(flat, 3, vertices[0]),
        L::gather_xyz(flat, 3, vertices[1]),
        L::gather_xyz(flat, 3, vertices[2]),
    ];
    let corners_of = |l: usize| vertices.map(|v| mesh.positions[v[l] as usize]);
    (
        rects,
        Triangle3D::setup_lanes(&corners, present, view, corners_of),
    )
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

/// The first `len` items of chunks of eight, sharing `shared`.
fn flattened<'a, T: Stored>(
    (boxes, triangles): (Vec<[ItemBox; 8]>, Vec<[Option<T>; 8]>),
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

    type Kernel = fn(&LaneMesh, Records, usize) -> (PixelRects, [Option<Triangle3D>; 8]);

    /// `kernel` gives every lane the box [`ScreenBoxes::rect`] gives and the
    /// set-up triangle the eight-at-a-time path gives
    /// ([`Triangle3D::setup_eight`], checked against the one-triangle form),
    /// bit for bit: random meshes of shared vertices on screen, off it,
    /// across the near plane and behind the eye; listed and run records;
    /// full and short chunks.
    fn lanes_match_the_eight_path(kernel: Kernel) {
        let mut rng = fastrand::Rng::with_seed(31);
        let (mut checked, mut set_up, mut scalar_boxes) = (0, 0, 0);
        for case in 0..600 {
            let eye = Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 4.0;
            let camera = Camera {
                name: "test".into(),
                eye,
                target: eye - Vec3::Z + Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, 0.0),
                up: Vec3::Y,
                viewport: Viewport::Perspective {
                    fov_y_deg: [20.0, 60.0, 120.0][case % 3],
                },
                near: Some(0.1),
            };
            let size = (rng.u32(1..400), rng.u32(1..400));
            let view = View::new(&camera, size.0, size.1, 0.1).expect("a valid camera");
            let scale = [3.0, 0.05, 40.0][case / 3 % 3];
            let positions: Vec<Vec3> = (0..40)
                .map(|_| {
                    let d = Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, 0.1 - rng.f32() * 1.2);
                    eye + d * scale
                })
                .collect();
            let records: Vec<[u32; 3]> = (0..64)
                .map(|_| [rng.u32(0..40), rng.u32(0..40), rng.u32(0..40)])
                .collect();
            let span = SamplePattern::of([AaMode::None, AaMode::Ssaa(16)][case % 2]).span;
            let boxes = ScreenBoxes::of(&positions, &view);
            let mesh = LaneMesh::new(&boxes, &positions, &records, &view, span);
            let n = rng.usize(1..=8);
            let mut listed: [u32; 8] = std::array::from_fn(|_| rng.u32(0..64));
            for l in n..8 {
                listed[l] = listed[n - 1];
            }
            let first = rng.u32(0..=56);
            let run = std::array::from_fn(|l| first + l.min(n - 1) as u32);
            for (records_of, items) in [
                (Records::Listed(&listed), listed),
                (Records::Run(first), run),
            ] {
                let (rects, triangles) = kernel(&mesh, records_of, n);
                let corners: [[Vec3; 3]; 8] =
                    items.map(|i| records[i as usize].map(|v| positions[v as usize]));
                let vertices = items.map(|i| records[i as usize]);
                let expected_rects: [_; 8] = std::array::from_fn(|l| {
                    (l < n)
                        .then(|| boxes.rect(&corners[l], vertices[l], &view, span))
                        .flatten()
                });
                let eight = EightTriangles {
                    corners: std::array::from_fn(|l| &corners[l]),
                    vertices,
                    present: (0..8).fold(0, |m, l| m | u8::from(expected_rects[l].is_some()) << l),
                };
                let expected = Triangle3D::setup_eight(&eight, &view);
                for l in 0..8 {
                    let at = format!("case {case}, lane {l} of {n}");
                    assert_eq!(rects.get(l), expected_rects[l], "{at}");
                    // Debug shows the sign of a zero, which `==` does not.
                    assert_eq!(
                        format!("{:?}", triangles[l]),
                        format!("{:?}", expected[l]),
                        "{at}"
                    );
                    checked += usize::from(l < n);
                    set_up += usize::from(l < n && triangles[l].is_some());
                    let projected =
                        (0..3).all(|k| boxes.points[vertices[l][k] as usize][0].is_finite());
                    scalar_boxes += usize::from(l < n && !projected);
                }
            }
        }
        assert!(
            checked > 4_000 && set_up > 1_000 && scalar_boxes > 500,
            "{checked} lanes checked, {set_up} set up, {scalar_boxes} boxed by the scalar path"
        );
    }

    #[test]
    fn portable_lanes_set_up_as_eight_at_a_time() {
        lanes_match_the_eight_path(setup_3d_eight_on::<simd::Portable>);
    }

    #[test]
    fn avx2_lanes_set_up_as_eight_at_a_time() {
        #[cfg(target_arch = "x86_64")]
        assert!(
            simd::cpu_has_avx2(),
            "this test checks the AVX2 kernel, and this CPU has no AVX2"
        );
        // `setup_3d_eight` takes AVX2 where the CPU has it.
        lanes_match_the_eight_path(setup_3d_eight);
    }
}
