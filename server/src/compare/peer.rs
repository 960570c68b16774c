//! Peers: the tools a user would otherwise pick, run on the same scene, camera
//! and rays for comparison. They are *not* watertight and decide hits with their
//! own intersectors; comparisons report how many pixels differ, never assert it.
//!
//! - `peer-obvhs`: obvhs's CWBVH built from its `Triangle`s and walked with its
//!   own `ray_traverse` and `Triangle::intersect`, one ray per pixel.
//! - `peer-embree`, `peer-embree-stream` (cargo feature `embree`): Embree 3 with
//!   one `rtcIntersect1` per pixel, or each image row as one coherent stream
//!   (`rtcIntersect1M`), both with a coherent intersect context.

use std::time::{Duration, Instant};

use glam::Vec3A;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use rayon::prelude::*;

use continuum::{BACKGROUND, PreparedScene, View, pixel_center};

/// A peer renderer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PeerId {
    Obvhs,
    EmbreeSingle,
    EmbreeStream,
}

impl PeerId {
    pub const ALL: [PeerId; 3] = [PeerId::Obvhs, PeerId::EmbreeSingle, PeerId::EmbreeStream];

    pub fn as_str(self) -> &'static str {
        match self {
            PeerId::Obvhs => "peer-obvhs",
            PeerId::EmbreeSingle => "peer-embree",
            PeerId::EmbreeStream => "peer-embree-stream",
        }
    }

    pub fn parse(s: &str) -> Option<PeerId> {
        PeerId::ALL.into_iter().find(|p| p.as_str() == s)
    }

    /// Whether this build can run the peer.
    pub fn available(self) -> bool {
        match self {
            PeerId::Obvhs => true,
            PeerId::EmbreeSingle | PeerId::EmbreeStream => cfg!(feature = "embree"),
        }
    }
}

/// What a peer run measured: its build time, the wall time of each timed
/// repetition (after one warm-up), and the triangle ids it found.
#[derive(Clone, Debug)]
pub struct PeerRun {
    pub build_ms: f64,
    pub times_ms: Vec<f64>,
    pub triangle_id: Vec<u32>,
}

/// Builds the peer's own acceleration structure from `scene` (timed apart), then
/// casts one closest-hit ray per pixel centre `1 + repeat` times.
pub fn run_peer(
    peer: PeerId,
    scene: &PreparedScene,
    view: &View,
    repeat: u32,
) -> Result<PeerRun, String> {
    match peer {
        PeerId::Obvhs => Ok(run_obvhs(scene, view, repeat)),
        #[cfg(feature = "embree")]
        PeerId::EmbreeSingle | PeerId::EmbreeStream => Ok(embree_peer::run(
            scene,
            view,
            repeat,
            peer == PeerId::EmbreeStream,
        )),
        #[cfg(not(feature = "embree"))]
        PeerId::EmbreeSingle | PeerId::EmbreeStream => Err(format!(
            "{} needs continuum built with the `embree` feature (and Debian's libembree-dev)",
            peer.as_str()
        )),
    }
}

/// Times `1 + repeat` runs of `f`, keeping the last result.
fn timed(repeat: u32, mut f: impl FnMut() -> Vec<u32>) -> (Vec<f64>, Vec<u32>) {
    let mut ids = f();
    let mut times = Vec::new();
    for _ in 0..repeat {
        let start = Instant::now();
        ids = f();
        times.push(start.elapsed().as_secs_f64() * 1e3);
    }
    (times, ids)
}

fn run_obvhs(scene: &PreparedScene, view: &View, repeat: u32) -> PeerRun {
    let start = Instant::now();
    let triangles: Vec<Triangle> = scene
        .drawable
        .iter()
        .map(|&i| {
            let [a, b, c] = scene.triangle(i);
            Triangle {
                v0: a.into(),
                v1: b.into(),
                v2: c.into(),
            }
        })
        .collect();
    let bvh = (!triangles.is_empty()).then(|| {
        obvhs::cwbvh::builder::build_cwbvh_from_tris(
            &triangles,
            obvhs::BvhBuildParams::medium_build(),
            &mut Duration::default(),
        )
    });
    let build_ms = start.elapsed().as_secs_f64() * 1e3;
    let (times_ms, triangle_id) = timed(repeat, || {
        let mut ids = vec![BACKGROUND; view.pixel_count()];
        if let Some(bvh) = &bvh {
            ids.par_chunks_mut(view.width as usize)
                .enumerate()
                .for_each(|(y, row)| {
                    let yc = pixel_center(y as u32);
                    for (x, out) in row.iter_mut().enumerate() {
                        // Every viewport's ray (none outside the parabolic disc).
                        let Some((origin, dir)) = view.ray(pixel_center(x as u32), yc) else {
                            continue;
                        };
                        let ray =
                            Ray::new(Vec3A::from(origin), Vec3A::from(dir), 0.0, f32::INFINITY);
                        let mut hit = RayHit::none();
                        if bvh.ray_traverse(ray, &mut hit, |ray, id| {
                            triangles[bvh.primitive_indices[id] as usize].intersect(ray)
                        }) {
                            *out = scene.drawable
                                [bvh.primitive_indices[hit.primitive_id as usize] as usize];
                        }
                    }
                });
        }
        ids
    });
    PeerRun {
        build_ms,
        times_ms,
        triangle_id,
    }
}

#[cfg(feature = "embree")]
mod embree_peer {
    use std::time::Instant;

    use cgmath::{Vector3, Vector4};
    use embree::{Device, Geometry, IntersectContext, Ray, RayHit, Scene, TriangleMesh};
    use rayon::prelude::*;

    use super::{PeerRun, timed};
    use continuum::{BACKGROUND, PreparedScene, View, pixel_center};

    pub fn run(scene: &PreparedScene, view: &View, repeat: u32, stream: bool) -> PeerRun {
        let start = Instant::now();
        let device = Device::new();
        let n = scene.drawable.len();
        let mut mesh = TriangleMesh::unanimated(&device, n, 3 * n);
        {
            let mut vertices = mesh.vertex_buffer.map();
            for (k, &id) in scene.drawable.iter().enumerate() {
                for (j, p) in scene.triangle(id).iter().enumerate() {
                    vertices[3 * k + j] = Vector4::new(p.x, p.y, p.z, 0.0);
                }
            }
        }
        {
            let mut indices = mesh.index_buffer.map();
            for k in 0..n {
                let base = 3 * k as u32;
                indices[k] = Vector3::new(base, base + 1, base + 2);
            }
        }
        let mut geometry = Geometry::Triangle(mesh);
        geometry.commit();
        let mut embree_scene = Scene::new(&device);
        embree_scene.attach_geometry(geometry);
        let committed = embree_scene.commit();
        let build_ms = start.elapsed().as_secs_f64() * 1e3;

        // Every viewport's ray; where it casts none (outside the parabolic
        // disc), an empty segment that hits nothing.
        let ray_at = |x: usize, y: usize| {
            let v = |p: glam::Vec3| Vector3::new(p.x, p.y, p.z);
            match view.ray(pixel_center(x as u32), pixel_center(y as u32)) {
                Some((o, d)) => RayHit::new(Ray::new(v(o), v(d))),
                None => RayHit::new(Ray::segment(v(view.eye), v(view.forward), 0.0, 0.0)),
            }
        };
        let id_of = |hit: &RayHit| {
            if hit.hit.geomID == u32::MAX {
                BACKGROUND
            } else {
                scene.drawable[hit.hit.primID as usize]
            }
        };
        let width = view.width as usize;
        let (times_ms, triangle_id) = timed(repeat, || {
            let mut ids = vec![BACKGROUND; view.pixel_count()];
            ids.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
                let mut ctx = IntersectContext::coherent();
                if stream {
                    let mut rays: Vec<RayHit> = (0..width).map(|x| ray_at(x, y)).collect();
                    committed.intersect_stream_aos(&mut ctx, &mut rays);
                    for (out, hit) in row.iter_mut().zip(&rays) {
                        *out = id_of(hit);
                    }
                } else {
                    for (x, out) in row.iter_mut().enumerate() {
                        let mut hit = ray_at(x, y);
                        committed.intersect(&mut ctx, &mut hit);
                        *out = id_of(&hit);
                    }
                }
            });
            ids
        });
        PeerRun {
            build_ms,
            times_ms,
            triangle_id,
        }
    }
}
