//! Peers: the tools a user would otherwise pick, run on the same scene, camera
//! and rays for comparison. They are *not* watertight and decide hits with their
//! own intersectors; comparisons report how many pixels differ, never assert it.
//!
//! - `peer-obvhs`: obvhs's CWBVH built from its `Triangle`s and walked with its
//!   own `ray_traverse` and `Triangle::intersect`, one ray per pixel, as a user of
//!   that library writes it.

use std::time::{Duration, Instant};

use glam::Vec3A;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use rayon::prelude::*;

use crate::camera::{View, pixel_center};
use crate::framebuffer::BACKGROUND;
use crate::prepared::PreparedScene;

/// A peer renderer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PeerId {
    Obvhs,
}

impl PeerId {
    pub const ALL: [PeerId; 1] = [PeerId::Obvhs];

    pub fn as_str(self) -> &'static str {
        match self {
            PeerId::Obvhs => "peer-obvhs",
        }
    }

    pub fn parse(s: &str) -> Option<PeerId> {
        PeerId::ALL.into_iter().find(|p| p.as_str() == s)
    }
}

/// The triangle ids a peer found, per pixel.
#[derive(Clone, Debug)]
pub struct PeerOutput {
    pub triangle_id: Vec<u32>,
    /// Wall time of the ray loop in milliseconds.
    pub time_ms: f64,
}

/// A peer's scene data, built once (not part of the timed loop).
#[derive(Debug)]
pub struct PreparedPeer {
    pub id: PeerId,
    triangles: Vec<Triangle>,
    bvh: CwBvh,
    /// Triangle id of each entry of `triangles`.
    ids: Vec<u32>,
    pub build_ms: f64,
}

impl PreparedPeer {
    pub fn new(id: PeerId, scene: &PreparedScene) -> PreparedPeer {
        let start = Instant::now();
        let ids = scene.drawable.clone();
        let triangles: Vec<Triangle> = ids
            .iter()
            .map(|&i| {
                let [a, b, c] = scene.triangles[i as usize];
                Triangle {
                    v0: a.into(),
                    v1: b.into(),
                    v2: c.into(),
                }
            })
            .collect();
        let bvh = if triangles.is_empty() {
            CwBvh::default()
        } else {
            obvhs::cwbvh::builder::build_cwbvh_from_tris(
                &triangles,
                obvhs::BvhBuildParams::medium_build(),
                &mut Duration::default(),
            )
        };
        PreparedPeer {
            id,
            triangles,
            bvh,
            ids,
            build_ms: start.elapsed().as_secs_f64() * 1e3,
        }
    }

    /// One closest-hit ray per pixel centre, in parallel over rows.
    pub fn render(&self, view: &View) -> PeerOutput {
        let start = Instant::now();
        let width = view.width as usize;
        let mut ids = vec![BACKGROUND; view.pixel_count()];
        if !self.triangles.is_empty() {
            ids.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
                let yc = pixel_center(y as u32);
                for (x, out) in row.iter_mut().enumerate() {
                    let dir = view.direction(pixel_center(x as u32), yc);
                    let ray = Ray::new(
                        Vec3A::from(view.eye),
                        Vec3A::from(dir),
                        view.near,
                        f32::INFINITY,
                    );
                    let mut hit = RayHit::none();
                    if self.bvh.ray_traverse(ray, &mut hit, |ray, id| {
                        self.triangles[self.bvh.primitive_indices[id] as usize].intersect(ray)
                    }) {
                        *out = self.ids
                            [self.bvh.primitive_indices[hit.primitive_id as usize] as usize];
                    }
                }
            });
        }
        PeerOutput {
            triangle_id: ids,
            time_ms: start.elapsed().as_secs_f64() * 1e3,
        }
    }
}
