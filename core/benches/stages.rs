//! Each stage of a frame on its own (`cargo bench -p continuum-core --bench
//! stages`): triangle setup, binning, per-sample coverage, the BVH traversal,
//! the resolve, shading and the frame's store, on the Stanford bunny at
//! 960×540 — so a regression in one stage shows there first. Each benchmark
//! renders whole frames and reports only its stage's time (the frame's own
//! `stats.time_ms`, measured inside the render), through criterion's
//! `iter_custom`; the frames are the real pipeline, not a model of it.

use std::time::Duration;

use continuum::{AlgorithmId, PreparedScene, RenderRequest, StageTimes, render};
use criterion::{Criterion, criterion_group, criterion_main};

/// A stage, by the algorithm whose frame shows it and how to read its time.
type Stage = (&'static str, AlgorithmId, fn(&StageTimes) -> f64);

const STAGES: [Stage; 10] = [
    ("setup/2d", AlgorithmId::TwoDBrute, |t| t.setup),
    ("setup/3d", AlgorithmId::ThreeDBrute, |t| t.setup),
    ("binning/2d", AlgorithmId::TwoDBin, |t| t.coverage),
    ("binning/3d", AlgorithmId::ThreeDBin, |t| t.coverage),
    ("coverage/2d", AlgorithmId::TwoDBrute, |t| t.coverage),
    ("coverage/3d", AlgorithmId::ThreeDBrute, |t| t.coverage),
    ("traversal/frusta", AlgorithmId::ThreeDFull, |t| t.traversal),
    ("traversal/rays", AlgorithmId::Raycast, |t| t.traversal),
    ("resolve", AlgorithmId::ThreeDBrute, |t| t.resolve),
    ("shading", AlgorithmId::ThreeDBrute, |t| t.shading),
];

fn stages(c: &mut Criterion) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/bunny.toml");
    let scene = continuum::scene::load_path(path.as_ref()).expect("the bunny scene loads");
    let scene = PreparedScene::new(scene);
    let camera = scene.scene.first_camera();
    let mut group = c.benchmark_group("stages");
    group.sample_size(20);
    let mut benched = 0;
    for (name, algorithm, stage) in STAGES {
        let request = RenderRequest::new(algorithm, camera.clone(), 960, 540);
        let first = render(&scene, &request).expect("the bench frame renders");
        assert!(
            stage(&first.stats.time_ms) > 0.0,
            "{name}: {algorithm} has this stage"
        );
        first.framebuffer.recycle();
        group.bench_function(name, |b| {
            b.iter_custom(|frames| {
                let mut spent = Duration::ZERO;
                for _ in 0..frames {
                    let out = render(&scene, &request).expect("renders");
                    spent += Duration::from_secs_f64(stage(&out.stats.time_ms) / 1e3);
                    out.framebuffer.recycle();
                }
                spent
            });
        });
        benched += 1;
    }
    group.finish();
    assert_eq!(benched, STAGES.len());
}

criterion_group!(benches, stages);
criterion_main!(benches);
