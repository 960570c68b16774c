//! The per-sample coverage kernel on its two instruction sets: 3D edge
//! functions (paper §3.2) over every row of a 256×192 image for random
//! triangles, through `sample_run` on the portable lanes and on AVX2
//! (`cargo bench -p continuum-core --bench coverage`), reached through
//! `continuum::internal::covered_samples`, which checks the CPU itself. Both
//! count the same covered samples; the bench asserts it before timing.

use std::hint::black_box;

use continuum::internal::{Isa, Shared3D, Triangle3D, covered_samples};
use continuum::{Camera, View, Viewport};
use criterion::{Criterion, criterion_group, criterion_main};
use glam::Vec3;

const WIDTH: u32 = 256;
const HEIGHT: u32 = 192;

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
    let set_up: Vec<Option<Triangle3D>> = vertices
        .iter()
        .map(|p| Triangle3D::setup(p, &view))
        .collect();
    let shared = Shared3D::of_corners(&view, false, &vertices);
    let triangles = (set_up.as_slice(), &shared);

    let mut group = c.benchmark_group("coverage/sample_run");
    let portable = covered_samples(triangles, WIDTH, HEIGHT, Isa::Portable);
    group.bench_function("portable", |b| {
        b.iter(|| covered_samples(black_box(triangles), WIDTH, HEIGHT, Isa::Portable));
    });
    if let Some(avx2) = covered_samples(triangles, WIDTH, HEIGHT, Isa::Avx2) {
        assert_eq!(
            portable,
            Some(avx2),
            "the two instruction sets cover different samples"
        );
        group.bench_function("avx2", |b| {
            b.iter(|| covered_samples(black_box(triangles), WIDTH, HEIGHT, Isa::Avx2));
        });
    }
    group.finish();
}

criterion_group!(benches, coverage);
criterion_main!(benches);
