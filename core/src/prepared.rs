//! `Scene` → `PreparedScene`: everything a render needs that does not depend on
//! the camera, built once (and cached by the server): per-triangle positions and
//! face normals, the list of drawable (non-degenerate) triangles, and the BVH.

use std::sync::Arc;

use glam::Vec3;
use rayon::prelude::*;

use crate::bvh::SceneBvh;
use crate::effects::EffectPlan;
use crate::ground::Bounds;
use crate::scene::Scene;
use crate::texture::MipChain;

/// A scene ready to render from any camera.
#[derive(Debug)]
pub struct PreparedScene {
    pub scene: Arc<Scene>,
    /// Unit geometric normal per triangle id (zero for degenerate triangles).
    pub(crate) face_normals: Vec<Vec3>,
    /// Ids of the triangles that are drawn: all but the degenerate ones (two equal
    /// vertices, or an f32 cross product of exactly zero).
    pub drawable: Vec<u32>,
    pub(crate) bvh: SceneBvh,
    /// Triangle id of each BVH primitive slot: `drawable[primitive_indices[slot]]`,
    /// so per-slot data sits in the order leaves read it.
    pub(crate) slot_triangles: Vec<u32>,
    /// Per slot: its triangle's positions, so a per-view setup in slot
    /// order reads memory in order instead of gathering from the mesh.
    pub(crate) slot_corners: Vec<[Vec3; 3]>,
    /// Per slot: its triangle's vertex indices into
    /// [`PreparedScene::slot_positions`] (not the mesh's).
    pub(crate) slot_vertices: Vec<[u32; 3]>,
    /// The drawable triangles' vertex positions numbered in the order the
    /// slots first use them: a setup in slot order that gathers its
    /// vertices (and their projections, `ScreenBoxes::of_slots`) finds
    /// them near the last slot's, where the mesh's numbering scatters them
    /// (a 1080p `raycast` setup of `teapots` 24 → 19 ms).
    pub(crate) slot_positions: Vec<Vec3>,
    /// Per triangle id: its BVH slot ([`NO_SLOT`] for a degenerate triangle),
    /// so that [`PreparedScene::triangle`] reads the slot-ordered corners
    /// instead of a second copy in id order.
    pub(crate) slot_of: Vec<u32>,
    pub bounds: Bounds,
    /// Near distance for cameras that give none: 1e-3 of the bounding radius.
    pub default_near: f32,
    /// Decoded textures with their mip chains, one per `scene.images` entry
    /// (or why it could not be decoded); empty when no material is textured.
    pub textures: Vec<Result<MipChain, String>>,
    /// Opacity per triangle id, from its material; empty when every material
    /// is opaque (the effect plan runs no transparency then).
    pub triangle_opacity: Vec<f32>,
    /// What the GPU keeps of this scene (its drawable triangles uploaded by
    /// the first `gpu-raster` render), typed by the floor above that owns it.
    #[cfg(feature = "gpu")]
    pub(crate) gpu_cache: std::sync::OnceLock<Box<dyn std::any::Any + Send + Sync>>,
}

impl PreparedScene {
    pub fn new(scene: Scene) -> PreparedScene {
        Self::from_arc(Arc::new(scene))
    }

    pub fn from_arc(scene: Arc<Scene>) -> PreparedScene {
        let mesh = &scene.mesh;
        let triangles: Vec<[Vec3; 3]> = (0..mesh.triangle_count())
            .into_par_iter()
            .map(|t| mesh.triangle_positions(t))
            .collect();
        let raw_normals: Vec<Vec3> = triangles
            .par_iter()
            .map(|[a, b, c]| (*b - *a).cross(*c - *a))
            .collect();
        let drawable: Vec<u32> = raw_normals
            .iter()
            .enumerate()
            .filter(|(_, n)| **n != Vec3::ZERO && n.is_finite())
            .map(|(i, _)| i as u32)
            .collect();
        let face_normals = raw_normals.iter().map(|n| n.normalize_or_zero()).collect();
        let bvh = SceneBvh::build(&triangles, &drawable);
        let slot_triangles: Vec<u32> = bvh
            .cwbvh
            .primitive_indices
            .iter()
            .map(|&k| drawable[k as usize])
            .collect();
        let slot_corners = slot_triangles
            .par_iter()
            .map(|&id| triangles[id as usize])
            .collect();
        let (slot_vertices, slot_positions) =
            renumbered(&slot_triangles, &mesh.triangles, &mesh.positions);
        let mut slot_of = vec![NO_SLOT; triangles.len()];
        for (slot, &id) in slot_triangles.iter().enumerate() {
            slot_of[id as usize] = slot as u32;
        }
        drop(triangles);
        let bounds = scene.bounds();
        let radius = if bounds.is_empty() {
            1.0
        } else {
            bounds.radius().max(1e-6)
        };
        // Mip chains and per-triangle opacity only when the effect plan runs
        // textures and transparency.
        let plan = EffectPlan::of(&scene);
        let textures = if plan.textures {
            scene
                .images
                .par_iter()
                .map(|i| MipChain::load(&i.source))
                .collect()
        } else {
            Vec::new()
        };
        let triangle_opacity = if plan.transparency {
            mesh.material_ids
                .iter()
                .map(|&m| scene.materials[m as usize].opacity)
                .collect()
        } else {
            Vec::new()
        };
        PreparedScene {
            textures,
            triangle_opacity,
            face_normals,
            drawable,
            bvh,
            slot_triangles,
            slot_corners,
            slot_vertices,
            slot_positions,
            slot_of,
            bounds,
            default_near: radius * 1e-3,
            scene,
            #[cfg(feature = "gpu")]
            gpu_cache: std::sync::OnceLock::new(),
        }
    }

    /// Heap bytes this prepared scene holds, its mesh included: every
    /// buffer's allocated capacity (the GPU's copy, held by the driver, is
    /// not counted). What `stats.scene_bytes_per_triangle` reports and the
    /// service's scene cache bounds.
    pub fn bytes(&self) -> usize {
        fn held<T>(v: &Vec<T>) -> usize {
            v.capacity() * std::mem::size_of::<T>()
        }
        let mesh = &self.scene.mesh;
        let textures: usize = (self.textures.iter().flatten())
            .map(|t| t.texel_count() * 16)
            .sum();
        held(&mesh.positions)
            + held(&mesh.normals)
            + held(&mesh.uvs)
            + held(&mesh.colors)
            + held(&mesh.triangles)
            + held(&mesh.material_ids)
            + held(&self.face_normals)
            + held(&self.drawable)
            + held(&self.slot_triangles)
            + held(&self.slot_corners)
            + held(&self.slot_vertices)
            + held(&self.slot_positions)
            + held(&self.slot_of)
            + held(&self.triangle_opacity)
            + self.bvh.bytes()
            + textures
    }

    /// Whether triangle `id` is see-through (its material's opacity below 1).
    #[inline(always)]
    pub fn is_transparent(&self, id: u32) -> bool {
        is_see_through(&self.triangle_opacity, id)
    }

    /// Triangle count, degenerate ones included.
    pub fn triangle_count(&self) -> usize {
        self.scene.mesh.triangle_count()
    }

    /// The vertex positions of triangle `id` (any id, degenerate ones too),
    /// read from the slot-ordered copies where the BVH holds it: triangles
    /// side by side on screen are side by side there, whatever the mesh's
    /// own order.
    #[inline(always)]
    pub fn triangle(&self, id: u32) -> [Vec3; 3] {
        match self.slot_of[id as usize] {
            NO_SLOT => self.scene.mesh.triangle_positions(id as usize),
            slot => self.slot_corners[slot as usize],
        }
    }
}

/// The vertex indices of triangles `ids` (`triangles` of the mesh) with
/// their vertices numbered in the order they are first used there, and the
/// positions in that order.
fn renumbered(
    ids: &[u32],
    triangles: &[[u32; 3]],
    positions: &[Vec3],
) -> (Vec<[u32; 3]>, Vec<Vec3>) {
    const UNSEEN: u32 = u32::MAX;
    let mut number = vec![UNSEEN; positions.len()];
    let mut order = Vec::new();
    let vertices = ids
        .iter()
        .map(|&id| {
            triangles[id as usize].map(|v| {
                let n = &mut number[v as usize];
                if *n == UNSEEN {
                    *n = order.len() as u32;
                    order.push(positions[v as usize]);
                }
                *n
            })
        })
        .collect();
    (vertices, order)
}

/// [`PreparedScene::slot_of`] of a triangle the BVH does not hold.
const NO_SLOT: u32 = u32::MAX;

/// Whether triangle `id` is see-through under the per-triangle `opacity`
/// (empty: every triangle opaque).
#[inline(always)]
pub(crate) fn is_see_through(opacity: &[f32], id: u32) -> bool {
    !opacity.is_empty() && opacity[id as usize] < 1.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Renumbered vertices spell the same corners, are numbered in the
    /// order of first use (each new one the next number), and only the
    /// vertices used are kept.
    #[test]
    fn vertices_are_renumbered_in_order_of_first_use() {
        let positions: Vec<Vec3> = (0..6).map(|i| Vec3::splat(i as f32)).collect();
        let triangles = [[0, 1, 2], [2, 3, 4], [4, 1, 0]];
        // Vertex 5 is used by no listed triangle.
        let ids = [2, 0, 1];
        let (vertices, order) = renumbered(&ids, &triangles, &positions);
        assert_eq!(vertices, vec![[0, 1, 2], [2, 1, 3], [3, 4, 0]]);
        assert_eq!(order.len(), 5);
        for (k, &id) in ids.iter().enumerate() {
            let corners = vertices[k].map(|v| order[v as usize]);
            assert_eq!(
                corners,
                triangles[id as usize].map(|v| positions[v as usize])
            );
        }
    }

    /// A built-in scene's slots find their corners through the renumbered
    /// vertices, slot by slot.
    #[test]
    fn slot_vertices_spell_the_slot_corners() {
        let path = format!("{}/../scenes/sphere.toml", env!("CARGO_MANIFEST_DIR"));
        let scene = crate::scene::load_path(path.as_ref()).expect("built-in scene loads");
        let prepared = PreparedScene::new(scene);
        let mut checked = 0;
        for (slot, corners) in prepared.slot_corners.iter().enumerate() {
            let renumbered =
                prepared.slot_vertices[slot].map(|v| prepared.slot_positions[v as usize]);
            assert_eq!(&renumbered, corners, "slot {slot}");
            checked += 1;
        }
        assert_eq!(checked, prepared.drawable.len());
        assert!(prepared.slot_positions.len() <= prepared.scene.mesh.positions.len());
    }
}
