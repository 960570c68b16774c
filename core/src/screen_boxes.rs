//! Conservative screen boxes for the 3D family (paper §3.2–3.3, §5 "3DR
//! brute-force": the bounding box the samples are searched in).
//!
//! A 3D edge function decides coverage without projecting anything, so the box
//! only bounds the search; but it must never cut off a sample the edge
//! functions cover, or every 3D algorithm and the ray caster (which trust the
//! same box) would lose it alike. What they cover is defined exactly: the ray
//! `d(x, y) = d0 + x·dx + y·dy` (orthographic: from `o0 + x·ox + y·oy` along
//! the view axis) in real arithmetic on the view's f32 coefficients, against
//! the triangle whose vertices are the setup's f32 `p − eye`. So the box is
//! the projection of those vertices through the exact inverse of that ray
//! generator ([`ImageMap`]), padded by a certified bound on the rounding of
//! that projection — thousandths of a pixel for ordinary views, and still
//! correct for extreme zoom, where the image plane's f32 coefficients
//! themselves are off by a tenth of a pixel from the camera's nominal one.

use glam::{DMat3, DVec3, Vec3};
use rayon::prelude::*;

use crate::camera::View;
use crate::clip::{ClipPlane, clip_triangle};
use crate::edge::EPS;
use crate::ground::PixelRect;
use crate::ground::SampleSpan;
use crate::prepared::PreparedScene;
use crate::simd::{self, Lanes, abs, finite, first_lanes};

/// Non-planar viewports' screen box: the bounds of the triangle's cap of
/// directions ([`crate::camera::SphereMap::bounds_of`]), padded by a pixel.
fn sphere_rect(p: &[Vec3; 3], view: &View, span: SampleSpan) -> Option<PixelRect> {
    let map = view.sphere.as_ref()?;
    let [x0, y0, x1, y1] = map.bounds_of(&p.map(|v| view.to_camera_f64(v)));
    PixelRect::from_bounds(
        (x0 - 1.0) as f32,
        (y0 - 1.0) as f32,
        (x1 + 1.0) as f32,
        (y1 + 1.0) as f32,
        view.width,
        view.height,
        span,
    )
}

/// Triangles reaching nearer than this are clipped for their screen box:
/// slightly less than `near`, so rounding never cuts off a sample at `near`.
fn near_bound(view: &View) -> f32 {
    view.near * (1.0 - 1.0 / 1024.0)
}

/// The inverse of a planar view's ray generator, `G(q) = M⁻¹·q` with
/// `M = [dx | dy | d0]` (perspective; `q` relative to the eye) or
/// `M = [ox | oy | d_p]` (orthographic; `q` relative to the ray origin at
/// image point (0, 0)): a point `q = c·d(x, y)` (orthographic
/// `q = o(x, y) + c·d_p`) has `G(q) = (c·x, c·y, c)` (orthographic
/// `(x, y, c)`), `c` its depth along the ray. Exact in real arithmetic
/// against the f32 coefficients the edge functions use, so the projection
/// and the coverage test agree on where every point is.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ImageMap {
    /// Rows of `M⁻¹` (computed in f64, rounded once), with their absolute values.
    rows: [Vec3; 3],
    rows_abs: [Vec3; 3],
    rows64: [DVec3; 3],
    /// Orthographic: the ray origin at image point (0, 0) relative to the eye.
    origin: Option<Vec3>,
    /// The view axis: the setups' vertex depths are `(p − eye)·forward` in f32.
    forward: Vec3,
    near_bound: f32,
}

/// Where a vertex lands on the image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum ImagePoint {
    /// Certainly at depth `≥ near_bound`: its image point and a bound on the
    /// rounding of both coordinates.
    Projected { x: f32, y: f32, pad: f32 },
    /// Certainly nearer than `near_bound`.
    Nearer,
    /// Too close to `near_bound` to tell in f32: the triangle takes the
    /// clipped f64 path.
    Unsure,
}

impl ImagePoint {
    /// The point as `[x, y, pad, kind]`: a projected point's values and kind
    /// 0; NaN values and kind 1 (nearer) or 2 (unsure) for the others — so
    /// that a lane's `x` alone says whether its point was projected (a
    /// projected point's values are finite).
    fn packed(self) -> [f32; 4] {
        match self {
            ImagePoint::Projected { x, y, pad } => [x, y, pad, 0.0],
            ImagePoint::Nearer => [f32::NAN, f32::NAN, f32::NAN, 1.0],
            ImagePoint::Unsure => [f32::NAN, f32::NAN, f32::NAN, 2.0],
        }
    }

    /// The point [`ImagePoint::packed`] packed.
    #[inline(always)]
    fn unpacked([x, y, pad, kind]: [f32; 4]) -> ImagePoint {
        if kind == 0.0 {
            ImagePoint::Projected { x, y, pad }
        } else if kind == 1.0 {
            ImagePoint::Nearer
        } else {
            ImagePoint::Unsure
        }
    }
}

impl ImageMap {
    pub(crate) fn new(view: &View) -> ImageMap {
        let (columns, origin) = if view.is_orthographic() {
            ([view.ox, view.oy, view.forward], Some(view.o0))
        } else {
            ([view.dx, view.dy, view.d0], None)
        };
        let m = DMat3::from_cols(
            columns[0].as_dvec3(),
            columns[1].as_dvec3(),
            columns[2].as_dvec3(),
        );
        // Rows of the inverse: the columns of its transpose.
        let inverse = m.inverse().transpose();
        let rows64 = [inverse.x_axis, inverse.y_axis, inverse.z_axis];
        let rows = rows64.map(|r| r.as_vec3());
        ImageMap {
            rows,
            rows_abs: rows.map(Vec3::abs),
            rows64,
            origin,
            forward: view.forward,
            near_bound: near_bound(view),
        }
    }

    /// The image point of the vertex `q = p − eye` (rounded in f32 exactly as
    /// the setup rounds it), with a certified bound on its rounding error.
    /// [`ImagePoint::Nearer`] only when the setups' own depth of the vertex,
    /// `(p − eye)·forward` (in f32 or f64), is certainly below the bound too:
    /// a triangle whose vertices all are has every sample's depth (clamped
    /// into the vertices' range) below `near`.
    ///
    /// The f64 setups take `p − eye` exactly: `q` is off from it by at most
    /// `ε·|q|`, which the bound below covers as well, so the point holds for
    /// both.
    ///
    /// Each coordinate of `G(q)` is a 3-term dot product: off from the exact
    /// one by at most `γ₃·|r|·|q|` plus `ε·|r|·|q|` for the row's own rounding
    /// and `ε·|r|·|q|` for `q`'s (orthographic: one more `ε` for `q − o0`),
    /// `< 6ε·|r|·|q|`; bounded as
    /// `16ε·|r|·|q|`. Perspective divides: with `a, c` off by `α, β`,
    /// `a/c − a₀/c₀ = (α − x₀·β)/c`, and the quotient rounds by `ε·|x|`. The
    /// bound doubles that and adds `8ε·|x|` so that the box's pixel bounds,
    /// rounded again from it, still hold every sample inside.
    #[cfg_attr(
        not(test),
        expect(dead_code, reason = "the definition `points_eight` is tested against")
    )]
    #[inline]
    pub(crate) fn point(&self, q: Vec3) -> ImagePoint {
        let setup_w = q.dot(self.forward);
        let (q, q_abs) = match self.origin {
            Some(o0) => (q - o0, q.abs() + o0.abs()),
            None => (q, q.abs()),
        };
        let [ra, rb, rc] = self.rows;
        let (a, b, c) = (ra.dot(q), rb.dot(q), rc.dot(q));
        let [sa, sb, sc] = self.rows_abs.map(|r| r.dot(q_abs) * (16.0 * EPS));
        if c + sc < self.near_bound && setup_w + sc < self.near_bound {
            return ImagePoint::Nearer;
        }
        if !(c - sc >= self.near_bound && c - sc > 0.0) {
            return ImagePoint::Unsure;
        }
        let (x, y, pad) = if self.origin.is_some() {
            (a, b, sa.max(sb))
        } else {
            let (x, y) = (a / c, b / c);
            let off = |v: f32, s: f32| 2.0 * (s + (v.abs() + s / c) * sc) / c;
            (x, y, off(x, sa).max(off(y, sb)))
        };
        let pad = pad + 8.0 * EPS * x.abs().max(y.abs()) + 1.0 / (1 << 20) as f32;
        if !(x.is_finite() && y.is_finite() && pad.is_finite()) {
            return ImagePoint::Unsure;
        }
        ImagePoint::Projected { x, y, pad }
    }

    /// A conservative image box of the axis-aligned box `lo..hi` (world
    /// space): interval arithmetic on `G` over the box, widened by a bound on
    /// f32 rounding as in [`ImageMap::point`] (doubled), so it holds the image
    /// point of every vertex inside, and so the screen box of every triangle
    /// with its vertices inside. `None` unless the box lies certainly beyond
    /// `near_bound` (and in front of the eye).
    #[inline]
    fn box_bounds(&self, lo: Vec3, hi: Vec3, eye: Vec3) -> Option<ImageBox> {
        let o = eye + self.origin.unwrap_or(Vec3::ZERO);
        let (mid, half) = ((lo + hi) * 0.5 - o, (hi - lo) * 0.5);
        // Bounds every vertex's `p − eye` (and `− o0`) and their roundings.
        let magnitude = mid.abs() + half + eye.abs() + o.abs();
        let [ra, rb, rc] = self.rows;
        let reach = half + magnitude * (32.0 * EPS);
        let [ea, eb, ec] = self.rows_abs.map(|r| r.dot(reach));
        let (a, b, c) = (ra.dot(mid), rb.dot(mid), rc.dot(mid));
        let (clo, chi) = (c - ec, c + ec);
        if !(clo >= self.near_bound && clo > 0.0) {
            return None;
        }
        let mut image_box = ImageBox::EMPTY;
        if self.origin.is_some() {
            image_box.grow(a - ea, b - eb, 0.0);
            image_box.grow(a + ea, b + eb, 0.0);
        } else {
            // A quotient's extremes lie at its intervals' ends (c > 0); each
            // product with a reciprocal is off by under 3ε relative.
            for inverse in [1.0 / clo, 1.0 / chi] {
                for (x, y) in [(a - ea, b - eb), (a + ea, b + eb)] {
                    image_box.grow(x * inverse, y * inverse, 0.0);
                }
            }
        }
        image_box.pad = 8.0 * EPS * image_box.magnitude() + 1.0 / 1024.0;
        image_box.magnitude().is_finite().then_some(image_box)
    }

    /// [`ImageMap::box_bounds`] and [`ImageBox::pixels`] of eight boxes, one
    /// per lane (`lo`, `hi` per axis): the same operations in the same order
    /// (`Vec3::dot` as `(x·x' + y·y') + z·z'`, no fused multiply-add), so the
    /// same pixels wherever every image bound is finite. Returns the rects
    /// and the lanes where one is not (beyond the near bound, but unsure:
    /// the scalar `min`/`max` pass over a NaN where the lanes' do not).
    #[inline(always)]
    fn box_rects<L: Lanes>(
        &self,
        lo: &[L; 3],
        hi: &[L; 3],
        view: &View,
        span: SampleSpan,
    ) -> ([Option<PixelRect>; 8], u8) {
        let eye = view.eye;
        let o = eye + self.origin.unwrap_or(Vec3::ZERO);
        let half_of = L::splat(0.5);
        let mut mid = [L::splat(0.0); 3];
        let mut reach = [L::splat(0.0); 3];
        for a in 0..3 {
            mid[a] = (lo[a] + hi[a]) * half_of - L::splat(o[a]);
            let half = (hi[a] - lo[a]) * half_of;
            let magnitude = ((abs(mid[a]) + half) + L::splat(eye[a].abs())) + L::splat(o[a].abs());
            reach[a] = half + magnitude * L::splat(32.0 * EPS);
        }
        // Lane code: functions and loops, no closures (see `crate::simd`).
        let ([ra, rb, rc], [sa, sb, sc]) = (self.rows, self.rows_abs);
        let [ea, eb, ec] = [
            dot_lanes(sa, &reach),
            dot_lanes(sb, &reach),
            dot_lanes(sc, &reach),
        ];
        let (a, b, c) = (
            dot_lanes(ra, &mid),
            dot_lanes(rb, &mid),
            dot_lanes(rc, &mid),
        );
        let clo = c - ec;
        let beyond = clo.ge(L::splat(self.near_bound)) & clo.gt(L::splat(0.0));
        let (xs, ys) = ([a - ea, a + ea], [b - eb, b + eb]);
        let (inf, neg_inf) = (L::splat(f32::INFINITY), L::splat(f32::NEG_INFINITY));
        let mut bounds = [inf, inf, neg_inf, neg_inf];
        let mut all_finite = u8::MAX;
        if self.origin.is_some() {
            for k in 0..2 {
                all_finite &= grow_lanes(&mut bounds, xs[k], ys[k]);
            }
        } else {
            for inverse in [L::splat(1.0) / clo, L::splat(1.0) / (c + ec)] {
                for k in 0..2 {
                    all_finite &= grow_lanes(&mut bounds, xs[k] * inverse, ys[k] * inverse);
                }
            }
        }
        let [min_x, min_y, max_x, max_y] = bounds;
        let magnitude = abs(min_x).max(abs(min_y)).max(abs(max_x)).max(abs(max_y));
        let pad = L::splat(8.0 * EPS) * magnitude + L::splat(1.0 / 1024.0);
        let size = [view.width, view.height];
        let mut rects = padded_rects([min_x, min_y, max_x, max_y], pad, size, span);
        rects.some &= beyond;
        (rects.options(), beyond & !all_finite)
    }

    /// The box of the triangle `p` with vertex image points `points`: theirs
    /// when all three are projected; `None` when all three are nearer than
    /// the bound (so is every point of the triangle, which has no sample at
    /// `w ≥ near`); else the clipped f64 box.
    #[inline]
    fn image_box(&self, p: &[Vec3; 3], points: &[ImagePoint; 3], view: &View) -> Option<ImageBox> {
        if points.iter().all(|p| *p == ImagePoint::Nearer) {
            return None;
        }
        ImageBox::of(points).or_else(|| self.clipped_box(p, view))
    }

    /// The box of the part of the triangle where a sample can pass the near
    /// test, in f64, for both geometries a setup may take the triangle in:
    /// `p − eye` rounded to f32 (the f32 setups) and exact (the f64 ones),
    /// which on extreme zoom differ by pixels. Per geometry: each vertex
    /// mapped through `G`, the polygon clipped at depth `c ≥ near_bound`
    /// lowered by how far `c` and the setup's own vertex depth may differ at
    /// a vertex (both are linear over the triangle, so the vertices bound
    /// their difference everywhere: a sample lifted to `near` by the clamp to
    /// the vertices' depth range is kept too), its corners projected. Padded
    /// by 1/16 pixel plus a relative 2⁻¹⁶ (far more than f64 rounding).
    /// `None` when nothing of it is that far; the whole image when the
    /// lowered plane reaches the eye.
    fn clipped_box(&self, p: &[Vec3; 3], view: &View) -> Option<ImageBox> {
        let origin = self.origin.unwrap_or(Vec3::ZERO).as_dvec3();
        let forward = self.forward.as_dvec3();
        let [ra, rb, rc] = self.rows64;
        let rounded = p.map(|v| {
            let q = v - view.eye;
            (q.as_dvec3(), f64::from(q.dot(self.forward)))
        });
        let exact = p.map(|v| {
            let q = v.as_dvec3() - view.eye.as_dvec3();
            (q, q.dot(forward))
        });
        let mut image_box: Option<ImageBox> = None;
        for geometry in [rounded, exact] {
            let mut slack = 0.0f64;
            let g = geometry.map(|(q, setup_w)| {
                let q = q - origin;
                let g = DVec3::new(ra.dot(q), rb.dot(q), rc.dot(q));
                slack = slack.max((g.z - setup_w).abs() + 1e-9 * q.abs().max_element());
                g
            });
            let plane = f64::from(self.near_bound) - slack;
            if plane.is_nan() || plane <= 0.0 {
                return Some(ImageBox::EVERYWHERE);
            }
            let Some(poly) = clip_triangle(g, &[ClipPlane::near(plane)]) else {
                continue;
            };
            let part = image_box.get_or_insert(ImageBox::EMPTY);
            for &g in poly.as_slice() {
                let (x, y) = match self.origin {
                    Some(_) => (g.x, g.y),
                    None => (g.x / g.z, g.y / g.z),
                };
                part.grow(x as f32, y as f32, 0.0);
            }
        }
        let mut image_box = image_box?;
        image_box.pad = 1.0 / 16.0 + image_box.magnitude() / 65536.0;
        Some(image_box)
    }
}

/// The conservative screen boxes of every triangle of one view, planar
/// views' vertices projected once (not once per triangle using them).
pub(crate) struct ScreenBoxes {
    map: Option<ImageMap>,
    /// Each mesh vertex's [`ImagePoint`] as four floats ([`ImagePoint::packed`]),
    /// which a setup in lanes gathers.
    pub(crate) points: Vec<[f32; 4]>,
}

impl ScreenBoxes {
    pub(crate) fn new(scene: &PreparedScene, view: &View) -> ScreenBoxes {
        ScreenBoxes::of(&scene.scene.mesh.positions, view)
    }

    /// The boxes of triangles by BVH slot: over the slot-numbered vertices
    /// (`PreparedScene::slot_vertices` index these points).
    pub(crate) fn of_slots(scene: &PreparedScene, view: &View) -> ScreenBoxes {
        ScreenBoxes::of(&scene.slot_positions, view)
    }

    /// The boxes of triangles over mesh vertices `positions`.
    pub(crate) fn of(positions: &[Vec3], view: &View) -> ScreenBoxes {
        let map = view.sphere.is_none().then(|| ImageMap::new(view));
        let points = match &map {
            Some(map) => {
                // Eight vertices at a time ([`points_eight`]); the last
                // chunk's missing lanes repeat its last vertex and are cut.
                let eights: Vec<[[f32; 4]; 8]> = (positions.par_chunks(8))
                    .map(|p| {
                        let corners = std::array::from_fn(|l| p[l.min(p.len() - 1)]);
                        points_eight(map, corners, view.eye).map(ImagePoint::packed)
                    })
                    .collect();
                let mut points = eights.into_flattened();
                points.truncate(positions.len());
                points
            }
            None => Vec::new(),
        };
        ScreenBoxes { map, points }
    }

    /// A conservative screen box of the part at `w ≥ near` of the triangle
    /// with positions `p` at mesh vertices `vertices`: planar views, its
    /// vertices' projections through [`ImageMap`] (clipped in f64 where it
    /// reaches nearer); non-planar ones, [`sphere_rect`]. The pixels returned
    /// are those with a sample (at offsets `span`) in the box.
    #[inline]
    pub(crate) fn rect(
        &self,
        p: &[Vec3; 3],
        vertices: [u32; 3],
        view: &View,
        span: SampleSpan,
    ) -> Option<PixelRect> {
        let Some(map) = &self.map else {
            return sphere_rect(p, view, span);
        };
        let points = vertices.map(|v| ImagePoint::unpacked(self.points[v as usize]));
        map.image_box(p, &points, view)?.pixels(view, span)
    }

    /// [`ScreenBoxes::rect`] of eight triangles, the same boxes: lane `l`'s
    /// triangle has mesh vertices `vertices[k][l]` (every lane's index a
    /// vertex; lanes outside `present` get `None`). Where its three vertices
    /// are projected (the common case), their points are gathered into
    /// lanes and the box and pixels computed there ([`pixels_lanes`]); a
    /// lane with a vertex not projected, and every lane of a non-planar
    /// view, takes [`ScreenBoxes::rect`]'s own path (with its corners from
    /// `positions`).
    #[inline(always)]
    pub(crate) fn rects_lanes<L: Lanes>(
        &self,
        vertices: &[[u32; 8]; 3],
        present: u8,
        positions: &[Vec3],
        view: &View,
        span: SampleSpan,
    ) -> PixelRects {
        let mut rects = PixelRects {
            some: 0,
            first: [[0.0; 8]; 2],
            last: [[0.0; 8]; 2],
        };
        let mut projected = 0;
        if self.map.is_some() {
            let points = [
                gathered_point::<L>(&self.points, vertices[0]),
                gathered_point::<L>(&self.points, vertices[1]),
                gathered_point::<L>(&self.points, vertices[2]),
            ];
            // A point is projected where its x is finite.
            projected =
                present & finite(points[0][0]) & finite(points[1][0]) & finite(points[2][0]);
            if projected != 0 {
                rects = pixels_lanes(&points, [view.width, view.height], span);
                rects.some &= projected;
            }
        }
        let mut scalar = present & !projected;
        while scalar != 0 {
            let l = scalar.trailing_zeros() as usize;
            scalar &= scalar - 1;
            let v = [vertices[0][l], vertices[1][l], vertices[2][l]];
            let rect = self.rect(&v.map(|v| positions[v as usize]), v, view, span);
            rects.set(l, rect);
        }
        rects
    }

    /// [`ScreenBoxes::node_rect`] of the boxes of `lanes` (bit per lane; `lo`,
    /// `hi` per axis and lane): the same rects, computed eight at a time
    /// ([`node_rects_eight`]) and by `node_rect` itself in a lane whose
    /// bounds are not all finite. Lanes outside `lanes` hold anything.
    pub(crate) fn node_rects(
        &self,
        lo: &[[f32; 8]; 3],
        hi: &[[f32; 8]; 3],
        lanes: u8,
        view: &View,
        span: SampleSpan,
    ) -> [Option<PixelRect>; 8] {
        let Some(map) = &self.map else {
            return [None; 8];
        };
        let (mut rects, unsure) = node_rects_eight(map, lo, hi, view, span);
        let unsure = unsure & lanes;
        for (l, rect) in rects.iter_mut().enumerate() {
            if unsure >> l & 1 == 1 {
                let corner = |v: &[[f32; 8]; 3]| Vec3::new(v[0][l], v[1][l], v[2][l]);
                *rect = self.node_rect(corner(lo), corner(hi), view, span);
            }
        }
        rects
    }

    /// The pixels with a sample in a conservative screen box of the
    /// axis-aligned box `lo..hi` ([`ImageMap::box_bounds`]): every pixel a
    /// triangle with its vertices inside may cover. `None` on non-planar views
    /// and where the box reaches nearer than `near` (or when no pixel is in it).
    #[inline]
    pub(crate) fn node_rect(
        &self,
        lo: Vec3,
        hi: Vec3,
        view: &View,
        span: SampleSpan,
    ) -> Option<PixelRect> {
        self.map
            .as_ref()?
            .box_bounds(lo, hi, view.eye)?
            .pixels(view, span)
    }
}

simd::dispatch! {
    /// [`ImageMap::box_rects`] of eight boxes given per axis and lane.
    fn node_rects_eight<>(
        map: &ImageMap,
        lo: &[[f32; 8]; 3],
        hi: &[[f32; 8]; 3],
        view: &View,
        span: SampleSpan,
    ) -> ([Option<PixelRect>; 8], u8) => node_rects_eight_on
}

#[inline(always)]
fn node_rects_eight_on<L: Lanes>(
    map: &ImageMap,
    lo: &[[f32; 8]; 3],
    hi: &[[f32; 8]; 3],
    view: &View,
    span: SampleSpan,
) -> ([Option<PixelRect>; 8], u8) {
    let lo = [
        L::from_array(lo[0]),
        L::from_array(lo[1]),
        L::from_array(lo[2]),
    ];
    let hi = [
        L::from_array(hi[0]),
        L::from_array(hi[1]),
        L::from_array(hi[2]),
    ];
    map.box_rects::<L>(&lo, &hi, view, span)
}

/// The packed points ([`ImagePoint::packed`]) of vertices `v`, one per lane:
/// x, y and rounding bound.
#[inline(always)]
fn gathered_point<L: Lanes>(points: &[[f32; 4]], v: [u32; 8]) -> [L; 3] {
    let [x, y, bound, _] = L::gather_xyzw(points, v);
    [x, y, bound]
}

simd::dispatch! {
    /// [`ImageMap::point`] of eight vertices `p − eye`, one per lane.
    fn points_eight<>(map: &ImageMap, p: [Vec3; 8], eye: Vec3) -> [ImagePoint; 8] => points_eight_on
}

/// [`ImageMap::point`] on lanes: the same IEEE operations in the same order
/// (dot products as [`dot_lanes`], `f32::max` as [`max_f32`], no fused
/// multiply-add), so each lane's point is the scalar one bit for bit.
#[inline(always)]
fn points_eight_on<L: Lanes>(map: &ImageMap, p: [Vec3; 8], eye: Vec3) -> [ImagePoint; 8] {
    let (mut x, mut y, mut z) = ([0.0; 8], [0.0; 8], [0.0; 8]);
    for l in 0..8 {
        (x[l], y[l], z[l]) = (p[l].x, p[l].y, p[l].z);
    }
    let q = [
        L::from_array(x) - L::splat(eye.x),
        L::from_array(y) - L::splat(eye.y),
        L::from_array(z) - L::splat(eye.z),
    ];
    let setup_w = dot_lanes(map.forward, &q);
    let (q, q_abs) = match map.origin {
        Some(o0) => (
            [
                q[0] - L::splat(o0.x),
                q[1] - L::splat(o0.y),
                q[2] - L::splat(o0.z),
            ],
            [
                abs(q[0]) + L::splat(o0.x.abs()),
                abs(q[1]) + L::splat(o0.y.abs()),
                abs(q[2]) + L::splat(o0.z.abs()),
            ],
        ),
        None => (q, [abs(q[0]), abs(q[1]), abs(q[2])]),
    };
    let [ra, rb, rc] = map.rows;
    let (a, b, c) = (dot_lanes(ra, &q), dot_lanes(rb, &q), dot_lanes(rc, &q));
    let bound = L::splat(16.0 * EPS);
    let sa = dot_lanes(map.rows_abs[0], &q_abs) * bound;
    let sb = dot_lanes(map.rows_abs[1], &q_abs) * bound;
    let sc = dot_lanes(map.rows_abs[2], &q_abs) * bound;
    let near = L::splat(map.near_bound);
    let nearer = (c + sc).lt(near) & (setup_w + sc).lt(near);
    let sure = (c - sc).ge(near) & (c - sc).gt(L::splat(0.0));
    let (x, y, pad) = match map.origin {
        Some(_) => (a, b, max_f32(sa, sb)),
        None => {
            let (x, y) = (a / c, b / c);
            let two = L::splat(2.0);
            let off_x = two * (sa + (abs(x) + sa / c) * sc) / c;
            let off_y = two * (sb + (abs(y) + sb / c) * sc) / c;
            (x, y, max_f32(off_x, off_y))
        }
    };
    let pad =
        pad + L::splat(8.0 * EPS) * max_f32(abs(x), abs(y)) + L::splat(1.0 / (1 << 20) as f32);
    let projected = sure & finite(x) & finite(y) & finite(pad);
    let (x, y, pad) = (x.to_array(), y.to_array(), pad.to_array());
    std::array::from_fn(|l| {
        if nearer >> l & 1 == 1 {
            ImagePoint::Nearer
        } else if projected >> l & 1 == 1 {
            ImagePoint::Projected {
                x: x[l],
                y: y[l],
                pad: pad[l],
            }
        } else {
            ImagePoint::Unsure
        }
    })
}

/// `f32::max` per lane: the other operand where one is NaN (x86's `maxps`
/// alone gives the second one).
#[inline(always)]
fn max_f32<L: Lanes>(a: L, b: L) -> L {
    L::select(b.eq(b), a.max(b), a)
}

/// [`ImageBox::of`] and [`ImageBox::pixels`] for eight triangles, one per
/// lane: `points` holds per vertex each lane's projected vertex (x, y,
/// rounding bound). The same operations as the scalar ones, so the same
/// pixels: minima, maxima and the bound's maximum are exact in any order on
/// the finite values [`ImageMap::point`] projects, and the lanes'
/// `floor`/`ceil` are exact (`PixelRect::from_bounds`'s differ from them only
/// in the sign of a zero, which the pixel bounds do not see).
#[inline(always)]
pub(crate) fn pixels_lanes<L: Lanes>(
    points: &[[L; 3]; 3],
    [width, height]: [u32; 2],
    span: SampleSpan,
) -> PixelRects {
    let [x, y, pad] = points[0];
    let (mut min_x, mut min_y, mut max_x, mut max_y) = (x, y, x, y);
    let mut pad = L::splat(0.0).max(pad);
    for &[x, y, p] in &points[1..] {
        (min_x, min_y) = (min_x.min(x), min_y.min(y));
        (max_x, max_y) = (max_x.max(x), max_y.max(y));
        pad = pad.max(p);
    }
    padded_rects([min_x, min_y, max_x, max_y], pad, [width, height], span)
}

/// `r · v` for eight vectors `v` (per axis), as `Vec3::dot` rounds it:
/// `(x·x' + y·y') + z·z'`.
#[inline(always)]
fn dot_lanes<L: Lanes>(r: Vec3, v: &[L; 3]) -> L {
    (L::splat(r.x) * v[0] + L::splat(r.y) * v[1]) + L::splat(r.z) * v[2]
}

simd::dispatch! {
    /// [`ScreenBoxes::rects_lanes`] of the first `n` (at least one) of eight
    /// triangles with vertex records `vertices` (lanes past `n` repeat a
    /// record of the mesh): the setups that read their triangles one by one.
    pub(crate) fn rects_eight<>(
        boxes: &ScreenBoxes,
        vertices: &[[u32; 3]; 8],
        n: usize,
        positions: &[Vec3],
        view: &View,
        span: SampleSpan,
    ) -> [Option<PixelRect>; 8] => rects_eight_on
}

#[inline(always)]
fn rects_eight_on<L: Lanes>(
    boxes: &ScreenBoxes,
    vertices: &[[u32; 3]; 8],
    n: usize,
    positions: &[Vec3],
    view: &View,
    span: SampleSpan,
) -> [Option<PixelRect>; 8] {
    let lanes = std::array::from_fn(|k| vertices.map(|v| v[k]));
    (boxes.rects_lanes::<L>(&lanes, first_lanes(n), positions, view, span)).options()
}

/// Grows eight boxes `[min_x, min_y, max_x, max_y]` by a point each;
/// returns the lanes where the point is finite.
#[inline(always)]
fn grow_lanes<L: Lanes>(b: &mut [L; 4], x: L, y: L) -> u8 {
    *b = [b[0].min(x), b[1].min(y), b[2].max(x), b[3].max(y)];
    finite(x) & finite(y)
}

/// `PixelRect::from_bounds` of eight boxes `[min_x, min_y, max_x, max_y]`
/// padded by `pad`, one per lane (the same operations, so the same pixels on
/// finite bounds).
#[inline(always)]
fn padded_rects<L: Lanes>(
    [min_x, min_y, max_x, max_y]: [L; 4],
    pad: L,
    [width, height]: [u32; 2],
    span: SampleSpan,
) -> PixelRects {
    let zero = L::splat(0.0);
    let x0 = ((min_x - pad) - L::splat(span.hi[0])).ceil().max(zero);
    let y0 = ((min_y - pad) - L::splat(span.hi[1])).ceil().max(zero);
    let x1 = ((max_x + pad) - L::splat(span.lo[0])).floor();
    let y1 = ((max_y + pad) - L::splat(span.lo[1])).floor();
    let x1 = x1.min(L::splat(width as f32 - 1.0));
    let y1 = y1.min(L::splat(height as f32 - 1.0));
    PixelRects {
        some: x0.le(x1) & y0.le(y1),
        first: [x0.to_array(), y0.to_array()],
        last: [x1.to_array(), y1.to_array()],
    }
}

/// Eight pixel rects, one per lane, as lanes compute them: lane `l`'s, where
/// bit `l` of `some` is set, holds the pixels `first[0][l]..=last[0][l]` by
/// `first[1][l]..=last[1][l]` (whole numbers). Read lane by lane from the
/// whole-register stores that made it (a rect built field by field and then
/// copied whole waits for its stores to land).
#[derive(Clone, Copy, Debug)]
pub(crate) struct PixelRects {
    pub some: u8,
    first: [[f32; 8]; 2],
    last: [[f32; 8]; 2],
}

impl PixelRects {
    /// Lane `l`'s rect.
    #[inline(always)]
    pub(crate) fn get(&self, l: usize) -> Option<PixelRect> {
        (self.some >> l & 1 == 1).then(|| PixelRect {
            x0: self.first[0][l] as u32,
            y0: self.first[1][l] as u32,
            x1: self.last[0][l] as u32 + 1,
            y1: self.last[1][l] as u32 + 1,
        })
    }

    /// Every lane's pixel bounds `[x0, y0, x1, y1]` (`x1`, `y1` past the
    /// last pixel), computed in lanes as [`PixelRects::get`] computes them
    /// one by one (whole numbers below 2¹⁶: adding one and truncating are
    /// exact); meaningful only for the lanes of `some`.
    #[inline(always)]
    pub(crate) fn bounds<L: Lanes>(&self) -> [[u32; 8]; 4] {
        let one = L::splat(1.0);
        [
            L::from_array(self.first[0]).truncate(),
            L::from_array(self.first[1]).truncate(),
            (L::from_array(self.last[0]) + one).truncate(),
            (L::from_array(self.last[1]) + one).truncate(),
        ]
    }

    /// Lane `l`'s rect becomes `rect` (pixel bounds are below 2¹⁶: exact in f32).
    #[inline(always)]
    fn set(&mut self, l: usize, rect: Option<PixelRect>) {
        self.some &= !(1 << l);
        if let Some(r) = rect {
            self.some |= 1 << l;
            (self.first[0][l], self.first[1][l]) = (r.x0 as f32, r.y0 as f32);
            (self.last[0][l], self.last[1][l]) = ((r.x1 - 1) as f32, (r.y1 - 1) as f32);
        }
    }

    /// The eight rects.
    #[inline(always)]
    pub(crate) fn options(&self) -> [Option<PixelRect>; 8] {
        std::array::from_fn(|l| self.get(l))
    }
}

/// A box of image points, padded.
#[derive(Clone, Copy, Debug)]
struct ImageBox {
    min: [f32; 2],
    max: [f32; 2],
    pad: f32,
}

impl ImageBox {
    const EMPTY: ImageBox = ImageBox {
        min: [f32::INFINITY; 2],
        max: [f32::NEG_INFINITY; 2],
        pad: 0.0,
    };

    /// Every image point.
    const EVERYWHERE: ImageBox = ImageBox {
        min: [f32::NEG_INFINITY; 2],
        max: [f32::INFINITY; 2],
        pad: 0.0,
    };

    /// The box of three projected vertices, padded by the largest of their
    /// bounds; `None` unless all three are [`ImagePoint::Projected`].
    #[inline]
    fn of(points: &[ImagePoint; 3]) -> Option<ImageBox> {
        let mut image_box = ImageBox::EMPTY;
        for point in points {
            let ImagePoint::Projected { x, y, pad } = *point else {
                return None;
            };
            image_box.grow(x, y, pad);
        }
        Some(image_box)
    }

    #[inline]
    fn grow(&mut self, x: f32, y: f32, pad: f32) {
        self.min = [self.min[0].min(x), self.min[1].min(y)];
        self.max = [self.max[0].max(x), self.max[1].max(y)];
        self.pad = self.pad.max(pad);
    }

    fn magnitude(&self) -> f32 {
        let (min, max) = (self.min, self.max);
        min[0]
            .abs()
            .max(min[1].abs())
            .max(max[0].abs())
            .max(max[1].abs())
    }

    /// The pixels with a sample in the padded box.
    #[inline]
    fn pixels(self, view: &View, span: SampleSpan) -> Option<PixelRect> {
        let (min, max, pad) = (self.min, self.max, self.pad);
        PixelRect::from_bounds(
            min[0] - pad,
            min[1] - pad,
            max[0] + pad,
            max[1] + pad,
            view.width,
            view.height,
            span,
        )
    }
}

#[cfg(test)]
mod tests {
    use glam::{DVec3, Vec3};

    use super::*;
    use crate::aa::{AaMode, SamplePattern};
    use crate::camera::Camera;
    use crate::edge::{Coverage, Triangle3D64};
    use crate::viewport::Viewport;

    /// One mode of each anti-aliasing family: sample spans of each kind.
    const AA_FAMILIES: [AaMode; 3] = [
        AaMode::None,
        AaMode::Ssaa(16),
        AaMode::Csaa {
            coverage: 8,
            stored: 4,
        },
    ];

    fn view(eye: Vec3, target: Vec3, viewport: Viewport, size: (u32, u32), near: f32) -> View {
        let camera = Camera {
            name: "test".into(),
            eye,
            target,
            up: Vec3::Y,
            viewport,
            near: Some(near),
        };
        View::new(&camera, size.0, size.1, near).expect("a valid camera")
    }

    /// A point (rounded to f32) at depth `t` on the ray of image point
    /// `(x, y)`, computed in f64: within rounding of that sample's ray, where
    /// rounding decides whether the sample is covered.
    /// A camera of test case `case`: an eye near the origin or far from it,
    /// looking roughly down −z; orthographic in one case of `orthographic`,
    /// else perspective with one of `fovs`.
    fn random_look(
        rng: &mut fastrand::Rng,
        case: usize,
        orthographic: usize,
        fovs: &[f32],
    ) -> (Vec3, Vec3, Viewport) {
        let far = [0.0, 1e3, 3e5][case % 3];
        let eye =
            Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, rng.f32() - 0.5) * 4.0 + Vec3::splat(far);
        let target = eye + Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, -1.0);
        let viewport = match case % orthographic {
            0 => Viewport::Orthographic {
                height: [1e-3, 1.0, 50.0][rng.usize(0..3)],
            },
            _ => Viewport::Perspective {
                fov_y_deg: fovs[rng.usize(0..fovs.len())],
            },
        };
        (eye, target, viewport)
    }

    fn on_ray(view: &View, x: f32, y: f32, t: f64) -> Vec3 {
        let (x, y) = (f64::from(x), f64::from(y));
        let origin = view.eye.as_dvec3()
            + view.o0.as_dvec3()
            + view.ox.as_dvec3() * x
            + view.oy.as_dvec3() * y;
        (origin + view.direction_f64(x, y) * t).as_vec3()
    }

    /// Every sample the 3D edge functions cover lies in the triangle's screen
    /// box, and in the screen box of the triangle's bounding box (what
    /// occlusion culling of a BVH node reads), on views that stress the box's rounding bound:
    /// extreme zoom, 16384-pixel images, cameras far from the origin,
    /// orthographic views, triangles crossing the near plane, and vertices
    /// placed on sample rays (where rounding alone decides coverage).
    /// Coverage as the f64 setup decides it (edges and depth in f64): on
    /// such views the f32 depth of a triangle crossing the eye plane can be
    /// far off, and the box's clipping at `near` is what keeps those
    /// samples out.
    #[test]
    fn screen_boxes_hold_every_covered_sample() {
        let mut rng = fastrand::Rng::with_seed(11);
        let (mut covered, mut boxes, mut in_nodes) = (0u64, 0u64, 0u64);
        for case in 0..400 {
            let fovs = [0.05, 0.5, 10.0, 60.0, 120.0, 170.0];
            let (eye, target, viewport) = random_look(&mut rng, case, 6, &fovs);
            let size = match case % 4 {
                0 => (16384, 9),
                1 => (9, 16384),
                _ => (rng.u32(1..200), rng.u32(1..200)),
            };
            let near = [1e-3, 0.1, 1.0][rng.usize(0..3)];
            let view = view(eye, target, viewport, size, near);
            let pattern = SamplePattern::of(AA_FAMILIES[rng.usize(0..3)]);
            // Triangles: one vertex on a sample's ray, the others a few pixels
            // (or a fraction of one) away, at depths around and across `near`.
            let mut positions = Vec::new();
            for _ in 0..24 {
                let pixel = |rng: &mut fastrand::Rng, n: u32| rng.u32(0..n) as f32;
                let (px, py) = (pixel(&mut rng, view.width), pixel(&mut rng, view.height));
                let [ox, oy] = pattern.positions[rng.usize(0..pattern.positions.len())];
                let depth = |rng: &mut fastrand::Rng| {
                    let base = f64::from(near) * [0.999, 1.0, 1.001, 2.0, 100.0][rng.usize(0..5)];
                    if rng.u32(0..6) == 0 {
                        -base
                    } else {
                        base * (0.5 + rng.f64())
                    }
                };
                let spread = [0.3, 2.0, 40.0][rng.usize(0..3)];
                let mut corner = |x: f32, y: f32, rng: &mut fastrand::Rng| {
                    positions.push(on_ray(&view, x, y, depth(rng)));
                };
                corner(px + ox, py + oy, &mut rng);
                for _ in 0..2 {
                    let (dx, dy) = ((rng.f32() - 0.5) * spread, (rng.f32() - 0.5) * spread);
                    corner(px + ox + dx, py + oy + dy, &mut rng);
                }
            }
            let screen = ScreenBoxes::of(&positions, &view);
            for (k, tri) in positions.chunks_exact(3).enumerate() {
                let p: [Vec3; 3] = [tri[0], tri[1], tri[2]];
                let vertices = [3 * k as u32, 3 * k as u32 + 1, 3 * k as u32 + 2];
                let rect = screen.rect(&p, vertices, &view, pattern.span);
                boxes += u64::from(rect.is_some());
                let (lo, hi) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
                let node = screen.node_rect(lo, hi, &view, pattern.span);
                // Coverage is only meaningful where the orientation is: skip
                // triangles so nearly edge-on that f64 cannot tell (the f64
                // setup has no exact fallback; the f32 one decides exactly).
                let q = p.map(|v| v.as_dvec3() - view.eye.as_dvec3());
                let volume = (q[1] - q[0]).cross(q[2] - q[0]).dot(q[0]);
                let scale = q[0].length() * q[1].length() * q[2].length();
                if volume.is_nan() || volume.abs() <= 1e-12 * scale {
                    continue;
                }
                let f64_setup = Triangle3D64::setup(&p, &view);
                // Pixels to test: the box and two pixels around it, and around
                // each vertex's projection (so a box that is missing or too
                // small is caught), all of them on small images.
                let mut regions: Vec<[u32; 4]> = Vec::new();
                let clamp = |x0: f64, y0: f64, x1: f64, y1: f64| {
                    let w = f64::from(view.width - 1);
                    let h = f64::from(view.height - 1);
                    [
                        x0.clamp(0.0, w) as u32,
                        y0.clamp(0.0, h) as u32,
                        x1.clamp(0.0, w) as u32,
                        y1.clamp(0.0, h) as u32,
                    ]
                };
                if u64::from(view.width) * u64::from(view.height) <= 40_000 {
                    regions.push([0, 0, view.width - 1, view.height - 1]);
                } else {
                    if let Some(r) = rect {
                        regions.push(clamp(
                            f64::from(r.x0) - 2.0,
                            f64::from(r.y0) - 2.0,
                            f64::from(r.x1) + 1.0,
                            f64::from(r.y1) + 1.0,
                        ));
                    }
                    for v in p {
                        let c: DVec3 = view.to_camera_f64(v);
                        if view.is_orthographic() || c.z > 0.0 {
                            let (x, y) = view.project_f64(c);
                            regions.push(clamp(x - 3.0, y - 3.0, x + 3.0, y + 3.0));
                        }
                    }
                }
                for [x0, y0, x1, y1] in regions {
                    for py in y0..=y1 {
                        for px in x0..=x1 {
                            for &[ox, oy] in &pattern.positions {
                                let (sx, sy) = (px as f32 + ox, py as f32 + oy);
                                let hit = f64_setup
                                    .as_ref()
                                    .is_some_and(|t| t.sample(sx, sy).is_some());
                                if !hit {
                                    continue;
                                }
                                covered += 1;
                                let inside = rect.is_some_and(|r| r.contains(px, py));
                                assert!(
                                    inside,
                                    "case {case}: sample ({sx}, {sy}) of {p:?} is covered but outside {rect:?} ({view:?})"
                                );
                                if let Some(n) = node {
                                    in_nodes += 1;
                                    assert!(
                                        n.contains(px, py),
                                        "case {case}: sample ({sx}, {sy}) of {p:?} is covered but outside its box's {n:?} ({view:?})"
                                    );
                                }
                            }
                        }
                    }
                }
            }
        }
        // The test must have tested something.
        assert!(
            covered > 10_000 && boxes > 3_000 && in_nodes > 5_000,
            "{covered} covered samples, {boxes} boxes, {in_nodes} in node boxes"
        );
    }

    /// On an ordinary view the bound is thousandths of a pixel (the box of
    /// a sub-pixel triangle is not inflated to its neighbours' samples).
    #[test]
    fn the_rounding_bound_is_small_on_ordinary_views() {
        let view = view(
            Vec3::new(0.0, 1.0, 5.0),
            Vec3::ZERO,
            Viewport::Perspective { fov_y_deg: 60.0 },
            (1920, 1080),
            0.01,
        );
        let map = ImageMap::new(&view);
        let mut rng = fastrand::Rng::with_seed(5);
        for _ in 0..10_000 {
            let (x, y) = (rng.f32() * 1920.0, rng.f32() * 1080.0);
            let q = on_ray(&view, x, y, 0.1 + 10.0 * rng.f64()) - view.eye;
            let ImagePoint::Projected { x: px, y: py, pad } = map.point(q) else {
                panic!("({x}, {y}) is in front of the camera");
            };
            assert!(pad < 0.01, "pad {pad} at ({x}, {y})");
            assert!(
                (px - x).abs() < 0.01 && (py - y).abs() < 0.01,
                "({px}, {py}) for ({x}, {y})"
            );
        }
    }

    /// An image point for the lane tests: on and around pixel borders and
    /// sample offsets, off the image, and far beyond f32's integers.
    fn coordinate(rng: &mut fastrand::Rng, n: u32) -> f32 {
        let n = n as f32;
        match rng.u32(0..6) {
            0 => rng.i32(-3..n as i32 + 3) as f32,
            1 => rng.i32(-3..n as i32 + 3) as f32 + 0.5,
            2 => (rng.i32(-3..n as i32 + 3) as f32 + 0.5).next_up(),
            3 => (rng.f32() - 0.5) * [1e4, 1e8, 3e38][rng.usize(0..3)],
            _ => (rng.f32() * 1.2 - 0.1) * n,
        }
    }

    /// Eight triangles' projected vertices: x, y and rounding bound (as in
    /// [`ImagePoint::Projected`]), each per coordinate, vertex and lane.
    type LanePoints = [[[f32; 8]; 3]; 3];

    simd::dispatch! {
        /// [`pixels_lanes`] of points given per coordinate, vertex and lane.
        fn pixels_eight<>(
            points: &LanePoints,
            size: [u32; 2],
            span: SampleSpan,
        ) -> [Option<PixelRect>; 8] => pixels_eight_on
    }

    #[inline(always)]
    fn pixels_eight_on<L: Lanes>(
        [xs, ys, pads]: &LanePoints,
        size: [u32; 2],
        span: SampleSpan,
    ) -> [Option<PixelRect>; 8] {
        let lanes = |k: usize| {
            [
                L::from_array(xs[k]),
                L::from_array(ys[k]),
                L::from_array(pads[k]),
            ]
        };
        pixels_lanes(&[lanes(0), lanes(1), lanes(2)], size, span).options()
    }

    /// `pixels` (one of the lane forms of [`pixels_eight`]) gives, lane by
    /// lane, the pixels [`ImageBox::of`] and [`ImageBox::pixels`] give each
    /// lane's three points, for every sample span and image size, with
    /// bounds that round, clamp, overflow to infinity or leave the image.
    fn eight_boxes_are_the_single_ones(
        pixels: fn(&LanePoints, [u32; 2], SampleSpan) -> [Option<PixelRect>; 8],
    ) {
        let mut rng = fastrand::Rng::with_seed(21);
        let (mut checked, mut some) = (0, 0);
        for _ in 0..4_000 {
            let size = (rng.u32(1..3000), rng.u32(1..3000));
            let view = view(
                Vec3::Z,
                Vec3::ZERO,
                Viewport::Perspective { fov_y_deg: 60.0 },
                size,
                0.1,
            );
            let span = SamplePattern::of(AA_FAMILIES[rng.usize(0..3)]).span;
            let mut points: LanePoints = [[[0.0; 8]; 3]; 3];
            let [xs, ys, pads] = &mut points;
            for k in 0..3 {
                for l in 0..8 {
                    xs[k][l] = coordinate(&mut rng, size.0);
                    ys[k][l] = coordinate(&mut rng, size.1);
                    pads[k][l] = [2f32.powi(-20), 1e-3, 0.3, 1e38][rng.usize(0..4)];
                }
            }
            let lanes = pixels(&points, [size.0, size.1], span);
            for (l, lane) in lanes.into_iter().enumerate() {
                let vertex = std::array::from_fn(|k| ImagePoint::Projected {
                    x: points[0][k][l],
                    y: points[1][k][l],
                    pad: points[2][k][l],
                });
                let single = ImageBox::of(&vertex).and_then(|b| b.pixels(&view, span));
                assert_eq!(lane, single, "lane {l} of {points:?} on {size:?}");
                (checked, some) = (checked + 1, some + usize::from(single.is_some()));
            }
        }
        assert_eq!(checked, 32_000);
        assert!(some > 8_000, "{some} boxes with pixels");
    }

    #[test]
    fn portable_eight_boxes_are_the_single_ones() {
        eight_boxes_are_the_single_ones(pixels_eight_on::<simd::Portable>);
    }

    #[test]
    fn avx2_eight_boxes_are_the_single_ones() {
        #[cfg(target_arch = "x86_64")]
        assert!(
            simd::cpu_has_avx2(),
            "this test checks the AVX2 kernel, and this CPU has no AVX2"
        );
        // `pixels_eight` takes AVX2 where the CPU has it.
        eight_boxes_are_the_single_ones(pixels_eight);
    }

    /// `points` (one of the lane forms of [`points_eight`]) gives, lane by
    /// lane and bit for bit, the point [`ImageMap::point`] gives each vertex:
    /// perspective and orthographic views near and far from the origin, with
    /// vertices in view, about the near plane (nearer, unsure), behind the
    /// eye, at the eye, and so far away or non-finite that the point is not.
    fn eight_points_are_the_single_ones(points: fn(&ImageMap, [Vec3; 8], Vec3) -> [ImagePoint; 8]) {
        let bits = |p: ImagePoint| match p {
            ImagePoint::Projected { x, y, pad } => Some([x, y, pad].map(f32::to_bits)),
            ImagePoint::Nearer | ImagePoint::Unsure => None,
        };
        let mut rng = fastrand::Rng::with_seed(41);
        let mut kinds = [0; 3];
        for case in 0..3_000 {
            let (eye, target, viewport) = random_look(&mut rng, case, 4, &[0.5, 10.0, 60.0, 170.0]);
            let size = (rng.u32(1..3000), rng.u32(1..3000));
            let near = [1e-3, 0.1, 1.0][rng.usize(0..3)];
            let view = view(eye, target, viewport, size, near);
            let map = ImageMap::new(&view);
            let p: [Vec3; 8] = std::array::from_fn(|_| {
                let off = Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, rng.f32() - 0.5);
                let depth = match rng.u32(0..8) {
                    // About the near plane, where the bound decides.
                    0 => near * (0.99 + rng.f32() * 0.02),
                    // Within ulps of the bound, where `c` and the setups'
                    // own depth may round to opposite sides of it.
                    1 => map.near_bound * (1.0 + (rng.f32() - 0.5) * 1e-5),
                    2 => -rng.f32() * 5.0,
                    3 => 0.0,
                    4 => [1e20, 1e38, f32::INFINITY, f32::NAN][rng.usize(0..4)],
                    _ => rng.f32() * 100.0,
                };
                eye + (target - eye) * depth + off * depth.abs().min(1e3)
            });
            let lanes = points(&map, p, view.eye);
            for (l, lane) in lanes.into_iter().enumerate() {
                let single = map.point(p[l] - view.eye);
                let at = format!("case {case} lane {l}: {:?} on {view:?}", p[l]);
                assert_eq!(
                    std::mem::discriminant(&lane),
                    std::mem::discriminant(&single),
                    "{at}"
                );
                assert_eq!(bits(lane), bits(single), "{at}");
                kinds[match single {
                    ImagePoint::Projected { .. } => 0,
                    ImagePoint::Nearer => 1,
                    ImagePoint::Unsure => 2,
                }] += 1;
            }
        }
        assert_eq!(kinds.iter().sum::<usize>(), 24_000);
        assert!(
            kinds.iter().all(|&k| k > 1_000),
            "projected, nearer, unsure: {kinds:?}"
        );
    }

    #[test]
    fn portable_eight_points_are_the_single_ones() {
        eight_points_are_the_single_ones(points_eight_on::<simd::Portable>);
    }

    #[test]
    fn avx2_eight_points_are_the_single_ones() {
        #[cfg(target_arch = "x86_64")]
        assert!(
            simd::cpu_has_avx2(),
            "this test checks the AVX2 kernel, and this CPU has no AVX2"
        );
        // `points_eight` takes AVX2 where the CPU has it.
        eight_points_are_the_single_ones(points_eight);
    }

    /// [`ScreenBoxes::node_rects`] is [`ScreenBoxes::node_rect`] per box, on
    /// perspective and orthographic views near and far from the origin, for
    /// boxes in view, across the near plane, behind the eye, and large
    /// enough that their bounds overflow (the lanes' scalar fallback).
    #[test]
    fn node_rects_of_eight_boxes_are_their_node_rects() {
        fn lanes<L: Lanes>(v: &[[f32; 8]; 3]) -> [L; 3] {
            v.map(L::from_array)
        }
        let mut rng = fastrand::Rng::with_seed(31);
        let (mut checked, mut some, mut in_lanes, mut fallback) = (0, 0, 0, 0);
        for case in 0..2_000 {
            let (eye, target, viewport) = random_look(&mut rng, case, 4, &[0.5, 10.0, 60.0, 170.0]);
            let size = (rng.u32(1..3000), rng.u32(1..3000));
            let near = [1e-3, 0.1, 1.0][rng.usize(0..3)];
            // One case in ten: an axis-aligned orthographic view of boxes
            // 2e38 wide, whose image bounds overflow where their depth does not.
            let overflow = case % 10 == 9;
            let view = match overflow {
                true => {
                    let viewport = Viewport::Orthographic { height: 1e-3 };
                    view(Vec3::ZERO, -Vec3::Z, viewport, size, near)
                }
                false => view(eye, target, viewport, size, near),
            };
            let span = SamplePattern::of(AA_FAMILIES[rng.usize(0..3)]).span;
            let screen = ScreenBoxes::of(&[], &view);
            let (mut lo, mut hi) = ([[0.0f32; 8]; 3], [[0.0f32; 8]; 3]);
            for l in 0..8 {
                let depth = [-2.0, 0.05, 0.5, 3.0, 100.0][rng.usize(0..5)];
                let off = Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, rng.f32() - 0.5);
                let centre = eye + (target - eye) * depth + off * depth;
                let size = [1e-4, 0.1, 2.0, 1e3, 1e37][rng.usize(0..5)];
                for a in 0..3 {
                    lo[a][l] = centre[a] - rng.f32() * size;
                    hi[a][l] = centre[a] + rng.f32() * size;
                }
                if overflow {
                    [lo[0][l], hi[0][l], lo[2][l], hi[2][l]] = [-1e38, 1e38, -3.0, -2.0];
                }
            }
            // The dispatched kernel (AVX2 here) and the portable one.
            let rects = screen.node_rects(&lo, &hi, u8::MAX, &view, span);
            let map = screen.map.as_ref().expect("a planar view");
            let (lane_lo, lane_hi) = (lanes::<simd::Portable>(&lo), lanes(&hi));
            let (portable, unsure) = map.box_rects(&lane_lo, &lane_hi, &view, span);
            fallback += unsure.count_ones();
            for (l, rect) in rects.into_iter().enumerate() {
                if unsure >> l & 1 == 0 {
                    assert_eq!(portable[l], rect, "case {case} lane {l}: portable lanes");
                }
                let corner = |v: &[[f32; 8]; 3]| Vec3::new(v[0][l], v[1][l], v[2][l]);
                let single = screen.node_rect(corner(&lo), corner(&hi), &view, span);
                let at = format!("case {case} lane {l}: {lo:?}..{hi:?} on {view:?}");
                assert_eq!(rect, single, "{at}");
                checked += 1;
                some += usize::from(single.is_some());
                in_lanes += usize::from(single.is_some() && unsure >> l & 1 == 0);
            }
        }
        assert_eq!(checked, 16_000);
        assert!(in_lanes > 1_500, "{some} rects, {in_lanes} from lanes");
        assert!(fallback > 100, "{fallback} lanes took the scalar fallback");
    }

    /// [`rects_eight`] (so [`ScreenBoxes::rects_lanes`]) is
    /// [`ScreenBoxes::rect`] per triangle, on every viewport, for groups of one to eight triangles that reach
    /// nearer than `near` (the clipped path), behind the eye or not at all.
    #[test]
    fn rects_of_eight_triangles_are_their_rects() {
        let mut rng = fastrand::Rng::with_seed(23);
        let (mut checked, mut some) = (0, 0);
        for case in 0..400 {
            let eye = Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 4.0;
            let viewport = [
                Viewport::Perspective { fov_y_deg: 60.0 },
                Viewport::Orthographic { height: 3.0 },
                Viewport::Parabolic,
                Viewport::LatLong,
            ][case % 4];
            let view = view(
                eye,
                eye - Vec3::Z,
                viewport,
                (rng.u32(1..400), rng.u32(1..400)),
                0.1,
            );
            let positions: Vec<Vec3> = (0..24)
                .map(|_| {
                    eye + Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, -rng.f32() * 1.2 + 0.1) * 3.0
                })
                .collect();
            let screen = ScreenBoxes::of(&positions, &view);
            let triangles: Vec<[Vec3; 3]> = positions
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]])
                .collect();
            let n = rng.usize(1..=8);
            let corners: [&[Vec3; 3]; 8] = std::array::from_fn(|l| &triangles[l.min(n - 1)]);
            let vertices = std::array::from_fn(|l| {
                let k = 3 * l.min(n - 1) as u32;
                [k, k + 1, k + 2]
            });
            let span = SamplePattern::of(AaMode::None).span;
            let rects = rects_eight(&screen, &vertices, n, &positions, &view, span);
            for l in 0..8 {
                let single = (l < n)
                    .then(|| screen.rect(corners[l], vertices[l], &view, span))
                    .flatten();
                assert_eq!(rects[l], single, "case {case}, lane {l} of {n}");
                checked += usize::from(l < n);
                some += usize::from(single.is_some());
            }
        }
        assert!(
            checked > 1_000 && some > 500,
            "{checked} checked, {some} with pixels"
        );
    }
}
