//! The per-sample coverage kernel on its two instruction sets: 3D edge
//! functions (paper §3.2) over every row of a 256×192 image for random
//! triangles, through [`Coverage::sample_run`] on the portable lanes and on
//! AVX2 (`cargo bench -p continuum-core --bench coverage`). Both count the
//! same covered samples; the bench asserts it before timing.

use std::hint::black_box;

use continuum::View;
use continuum::camera::{Camera, Viewport};
use continuum::edge::{Coverage, Triangle3D};
use continuum::simd::{self, Lanes, Portable};
use criterion::{Criterion, criterion_group, criterion_main};
use glam::Vec3;

const WIDTH: u32 = 256;
const HEIGHT: u32 = 192;

/// Covered samples of every triangle over the whole image, row by row.
#[inline(always)]
fn covered<L: Lanes>(triangles: &[Triangle3D]) -> u64 {
    let mut covered = 0u64;
    for t in triangles {
        for y in 0..HEIGHT {
            t.sample_run::<L>(0.5, y as f32 + 0.5, WIDTH, |_, w| {
                covered += u64::from(w > 0.0);
            });
        }
    }
    covered
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn covered_avx2(triangles: &[Triangle3D]) -> u64 {
    covered::<simd::Avx2>(triangles)
}

fn coverage(c: &mut Criterion) {
    let camera = Camera {
        name: "bench".into(),
        eye: Vec3::new(0.3, -0.2, 4.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        viewport: Viewport::Perspective { fov_y_deg: 60.0 },
        near: Some(0.05),
    };
    let view = View::new(&camera, WIDTH, HEIGHT, 0.01).expect("the bench camera is valid");
    // Triangles a few to a few dozen pixels across, in front of the eye.
    let mut rng = fastrand::Rng::with_seed(3);
    let vertices: Vec<[Vec3; 3]> = (0..400)
        .map(|_| {
            let centre = Vec3::new(
                rng.f32() * 4.0 - 2.0,
                rng.f32() * 3.0 - 1.5,
                rng.f32() - 0.5,
            );
            let size = 0.02 + rng.f32() * 0.3;
            let mut corner = || centre + (Vec3::new(rng.f32(), rng.f32(), rng.f32()) - 0.5) * size;
            [corner(), corner(), corner()]
        })
        .collect();
    let triangles: Vec<Triangle3D> = vertices
        .iter()
        .filter_map(|p| Triangle3D::setup(p, &view))
        .collect();

    let mut group = c.benchmark_group("coverage/sample_run");
    let portable = covered::<Portable>(&triangles);
    group.bench_function("portable", |b| {
        b.iter(|| covered::<Portable>(black_box(&triangles)));
    });
    #[cfg(target_arch = "x86_64")]
    if simd::cpu_has_avx2() {
        // SAFETY: the CPU has AVX2 (checked just now).
        let avx2 = unsafe { covered_avx2(&triangles) };
        assert_eq!(
            portable, avx2,
            "the two instruction sets cover different samples"
        );
        group.bench_function("avx2", |b| {
            // SAFETY: as above.
            b.iter(|| unsafe { covered_avx2(black_box(&triangles)) });
        });
    }
    group.finish();
}

criterion_group!(benches, coverage);
criterion_main!(benches);
