//! Overlays: what an algorithm did, drawn over any of its images with the
//! 2D primitives of [`crate::draw`] — the triangles' edges (`wireframe`),
//! the tile grid and binning's block decisions (`tiles`), the frusta of the
//! Fig. 7 traversal (`frusta`), the projected boxes of the BVH nodes it met
//! (`bvh`) — and, on parabolic and latlong views, the image's boundary.
//! Everything but the wireframe comes from the render's own [`Trace`].

use std::collections::HashMap;

use glam::{DVec3, Vec3};
use image::RgbaImage;

use crate::aa::AaMode;
use crate::camera::View;
use crate::draw::{self, Plot};
use crate::ground::PixelRect;
use crate::prepared::PreparedScene;
use crate::render::RenderOutput;
use crate::trace::{BlockOutcome, FrustumEvent, NodeOutcome, Overlays, Trace};
use crate::viewport::SphereMap;

/// The colours, with their meaning (the web page's and the viewer's legends).
pub const LEGEND: [(&str, [u8; 4]); 10] = [
    ("triangle edge", WIRE),
    ("tile", GRID),
    ("block accepted", ACCEPTED),
    ("block refined", REFINED),
    ("block rejected", REJECTED),
    ("frustum split", SPLIT),
    ("frustum rasterized", RASTERIZED),
    ("frustum culled", CULLED),
    ("BVH node entered", NODE),
    ("image boundary", BOUNDARY),
];

const WIRE: [u8; 4] = [80, 220, 255, 200];
const GRID: [u8; 4] = [255, 255, 255, 110];
const ACCEPTED: [u8; 4] = [60, 230, 90, 200];
const REFINED: [u8; 4] = [250, 200, 40, 170];
const REJECTED: [u8; 4] = [240, 60, 60, 140];
const SPLIT: [u8; 4] = [255, 150, 30, 150];
const RASTERIZED: [u8; 4] = [60, 230, 90, 230];
const CULLED: [u8; 4] = [240, 60, 60, 200];
const NODE: [u8; 4] = [200, 120, 255, 120];
const BOUNDARY: [u8; 4] = [255, 255, 255, 230];

/// Blends colour `c` at `coverage × alpha` over the image's pixels.
struct Painter<'i> {
    image: &'i mut RgbaImage,
    color: [u8; 4],
}

impl Plot for Painter<'_> {
    fn plot(&mut self, x: u32, y: u32, coverage: f32) {
        let a = coverage * f32::from(self.color[3]) / 255.0;
        let p = self.image.get_pixel_mut(x, y);
        for k in 0..3 {
            let (under, over) = (f32::from(p.0[k]), f32::from(self.color[k]));
            p.0[k] = (under + (over - under) * a).round() as u8;
        }
    }
}

/// Draws `overlays` over `image` (one of `output`'s images, at its size):
/// what `output`'s trace recorded, and the wireframe of `scene` as
/// `output`'s view sees it. Overlays whose records the algorithm does not
/// make (frusta without a BVH traversal, say) draw nothing.
pub fn draw_overlays(
    image: &mut RgbaImage,
    overlays: Overlays,
    output: &RenderOutput,
    scene: &PreparedScene,
) {
    let view = &output.view;
    let size = [view.width, view.height];
    assert_eq!(image.dimensions(), (size[0], size[1]), "overlay image size");
    let empty = Trace::default();
    let trace = output.trace.as_ref().unwrap_or(&empty);
    let mut pen = Pen {
        painter: Painter { image, color: WIRE },
        size,
        positions: draw::sample_positions(AaMode::Ssaa(16)),
    };
    if overlays.wireframe {
        pen.painter.color = WIRE;
        wireframe(&mut pen, scene, view);
    }
    if overlays.tiles {
        pen.painter.color = GRID;
        for &r in &trace.tiles {
            pen.rect(r);
        }
        let order = [
            (BlockOutcome::Rejected, REJECTED),
            (BlockOutcome::Refined, REFINED),
            (BlockOutcome::Accepted, ACCEPTED),
        ];
        pen.ranked_rects(&trace.blocks, &order);
    }
    if overlays.frusta {
        // A frustum never split nor rasterized was culled at every node it met.
        let order = [
            (FrustumEvent::Created, CULLED),
            (FrustumEvent::Split, SPLIT),
            (FrustumEvent::Rasterized, RASTERIZED),
        ];
        pen.ranked_rects(&trace.frusta, &order);
    }
    if overlays.bvh {
        pen.painter.color = NODE;
        let mut seen = std::collections::HashSet::new();
        for ([lo, hi], outcome) in &trace.nodes {
            let key = (lo.map(f32::to_bits), hi.map(f32::to_bits));
            if *outcome == NodeOutcome::Entered
                && seen.insert(key)
                && let Some(r) = projected_box(view, Vec3::from(*lo), Vec3::from(*hi))
            {
                pen.box_outline(r);
            }
        }
    }
    if !overlays.is_empty()
        && let Some(SphereMap::Parabolic { cx, cy, radius }) = view.sphere
    {
        pen.painter.color = BOUNDARY;
        pen.circle([cx, cy], radius);
    }
}

/// The primitives at one colour, anti-aliased with sixteen samples a pixel.
struct Pen<'i> {
    painter: Painter<'i>,
    size: [u32; 2],
    positions: Vec<[f32; 2]>,
}

impl Pen<'_> {
    /// Each rectangle of `records` once, in the colour of its strongest
    /// record (`order`: weakest first), the strongest drawn last, on top,
    /// and within a rank larger rectangles before the smaller inside them.
    fn ranked_rects<O: Copy + Eq>(&mut self, records: &[(PixelRect, O)], order: &[(O, [u8; 4])]) {
        let rank = |o: O| order.iter().position(|(p, _)| *p == o).unwrap_or(0);
        let mut best: HashMap<PixelRect, usize> = HashMap::new();
        for &(r, o) in records {
            let e = best.entry(r).or_insert(0);
            *e = (*e).max(rank(o));
        }
        let mut rects: Vec<(PixelRect, usize)> = best.into_iter().collect();
        rects.sort_by_key(|&(r, k)| (k, std::cmp::Reverse(r.width() * r.height()), r.y0, r.x0));
        for (r, k) in rects {
            self.painter.color = order[k].1;
            self.rect(r);
        }
    }

    fn line(&mut self, a: [f64; 2], b: [f64; 2]) {
        // Points come from finite renders; a line that is still bad is skipped.
        let _ = draw::aa_line(a, b, 1.0, &self.positions, self.size, &mut self.painter);
    }

    /// A rectangle's outline, one pixel inside its border.
    fn rect(&mut self, r: PixelRect) {
        let [x0, y0] = [r.x0, r.y0].map(|v| f64::from(v) + 0.5);
        let [x1, y1] = [r.x1, r.y1].map(|v| f64::from(v) - 0.5);
        self.box_outline([x0, y0, x1, y1]);
    }

    /// The outline of a box in image coordinates `[x0, y0, x1, y1]`: one
    /// closed stroke, so its corners are drawn once.
    fn box_outline(&mut self, [x0, y0, x1, y1]: [f64; 4]) {
        let outline = [[x0, y0], [x1, y0], [x1, y1], [x0, y1], [x0, y0]];
        let style = draw::Stroke {
            join: draw::Join::Miter,
            ..draw::Stroke::new(1.0)
        };
        let _ = draw::stroke(
            &outline,
            &style,
            &self.positions,
            self.size,
            &mut self.painter,
        );
    }

    fn circle(&mut self, c: [f64; 2], r: f64) {
        let points: Vec<[f64; 2]> = (0..=256)
            .map(|k| {
                let a = std::f64::consts::TAU * f64::from(k) / 256.0;
                [c[0] + (r - 0.5) * a.cos(), c[1] + (r - 0.5) * a.sin()]
            })
            .collect();
        let _ = draw::stroke(
            &points,
            &draw::Stroke::new(1.5),
            &self.positions,
            self.size,
            &mut self.painter,
        );
    }
}

/// Every drawable triangle's edges as the view sees them, each edge of the
/// mesh once: planar views clip an edge at the near plane and project it;
/// parabolic and latlong views draw it as sixteen pieces through the sphere
/// map (latlong pieces that cross the seam are left out).
fn wireframe(pen: &mut Pen, scene: &PreparedScene, view: &View) {
    let mesh = &scene.scene.mesh;
    let mut drawn = std::collections::HashSet::new();
    for &id in &scene.drawable {
        let v = mesh.triangles[id as usize];
        for k in 0..3 {
            let (a, b) = (v[k], v[(k + 1) % 3]);
            if drawn.insert((a.min(b), a.max(b))) {
                edge(
                    pen,
                    view,
                    mesh.positions[a as usize],
                    mesh.positions[b as usize],
                );
            }
        }
    }
}

fn edge(pen: &mut Pen, view: &View, a: Vec3, b: Vec3) {
    let (ca, cb) = (view.to_camera_f64(a), view.to_camera_f64(b));
    match view.sphere {
        None => {
            let near = f64::from(view.near);
            let (mut p, mut q) = (ca, cb);
            if !view.is_orthographic() {
                if p.z < near && q.z < near {
                    return;
                }
                // Clip the part nearer than `near`.
                if p.z < near || q.z < near {
                    let t = (near - p.z) / (q.z - p.z);
                    let cut = p + (q - p) * t;
                    if p.z < near {
                        p = cut;
                    } else {
                        q = cut;
                    }
                }
            }
            let (pa, pb) = (view.project_f64(p), view.project_f64(q));
            pen.line([pa.0, pa.1], [pb.0, pb.1]);
        }
        Some(map) => {
            let point = |t: f64| {
                let c: DVec3 = ca + (cb - ca) * t;
                let (x, y) = map.image_point(c);
                [x, y]
            };
            for k in 0..16 {
                let (p, q) = (point(f64::from(k) / 16.0), point(f64::from(k + 1) / 16.0));
                if (p[0] - q[0]).abs() < f64::from(view.width) * 0.5 {
                    pen.line(p, q);
                }
            }
        }
    }
}

/// The image box of a world box under a planar view: its corners in front
/// of the near plane projected (a box reaching behind the eye: the whole
/// image); `None` for parabolic and latlong views or a box wholly behind.
fn projected_box(view: &View, lo: Vec3, hi: Vec3) -> Option<[f64; 4]> {
    if view.sphere.is_some() {
        return None;
    }
    let near = f64::from(view.near);
    let mut b = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    let mut behind = 0;
    for k in 0..8 {
        let p = Vec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        );
        let c = view.to_camera_f64(p);
        if !view.is_orthographic() && c.z < near {
            behind += 1;
            continue;
        }
        let (x, y) = view.project_f64(c);
        b = [b[0].min(x), b[1].min(y), b[2].max(x), b[3].max(y)];
    }
    match behind {
        8 => None,
        0 => Some(b),
        _ => Some([0.0, 0.0, f64::from(view.width), f64::from(view.height)]),
    }
}
