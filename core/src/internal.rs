//! Kernels for benches and tests, and nothing else: not part of the API, no
//! stability promised. Everything here is safe to call on any CPU.

use crate::edge::Coverage;
pub use crate::edge::{Shared3D, Triangle3D};
use crate::prepared::PreparedScene;
pub use crate::shade::secondary::{Rays, intersect};
pub use crate::simd::{Isa, cpu_has_avx2};
use crate::simd::{Lanes, Portable};

/// Set-up triangles by id (`None`: not set up) and what their view shares.
pub type SetUp<'a> = (&'a [Option<Triangle3D>], &'a Shared3D<'a>);

/// Covered samples of every triangle over every row of a `width × height`
/// image, through the 8-lane coverage kernel ([`Triangle3D`]'s `sample_run`)
/// on the lanes `isa` names; `None` when this CPU has no such lanes.
pub fn covered_samples(triangles: SetUp, width: u32, height: u32, isa: Isa) -> Option<u64> {
    match isa {
        Isa::Portable => Some(covered_rows::<Portable>(triangles, width, height)),
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 if cpu_has_avx2() => {
            // SAFETY: this CPU has AVX2 (checked just now).
            Some(unsafe { covered_rows_avx2(triangles, width, height) })
        }
        Isa::Avx2 => None,
    }
}

/// Checks the scene's BVH against its triangles (every drawable triangle in
/// exactly one leaf, every box holding its children); panics on a fault.
pub fn validate_bvh(scene: &PreparedScene) {
    let triangles: Vec<_> = (0..scene.triangle_count() as u32)
        .map(|id| scene.triangle(id))
        .collect();
    scene.bvh.validate(&triangles, &scene.drawable);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn covered_rows_avx2(triangles: SetUp, width: u32, height: u32) -> u64 {
    covered_rows::<crate::simd::Avx2>(triangles, width, height)
}

#[inline(always)]
fn covered_rows<L: Lanes>((triangles, shared): SetUp, width: u32, height: u32) -> u64 {
    let mut covered = 0u64;
    for (id, t) in triangles.iter().enumerate() {
        let Some(t) = t else { continue };
        let t = t.bind(shared, id as u32, id as u32);
        for y in 0..height {
            t.sample_run::<L>(0.5, y as f32 + 0.5, width, |_, w| {
                covered += u64::from(w > 0.0);
            });
        }
    }
    covered
}
