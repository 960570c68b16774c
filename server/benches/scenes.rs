//! `GET /api/scenes` against a cold cache: the catalogue (every built-in scene
//! loaded and described, none prepared — what the listing does) beside
//! preparing every scene (what it did before: a BVH for each, `teapots`'s
//! million triangles included).
//!
//! `cargo bench -p continuum-server --bench scenes`

use std::path::PathBuf;

use continuum_server::{AppState, Limits};
use criterion::{Criterion, criterion_group, criterion_main};

fn scenes_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes")
}

fn listing(c: &mut Criterion) {
    let names = continuum::scene::builtin_names(&scenes_dir()).expect("the scenes folder lists");
    assert!(names.len() >= 12, "built-in scenes: {names:?}");
    let mut group = c.benchmark_group("api_scenes_cold");
    group.sample_size(10);
    group.bench_function("catalogue (the listing)", |b| {
        b.iter(|| {
            let state = AppState::new(scenes_dir(), Limits::default());
            let listed: usize = names
                .iter()
                .map(|n| state.describe(n)["triangles"].as_u64().unwrap_or(0) as usize)
                .sum();
            assert_eq!(state.prepared_count(), 0);
            listed
        });
    });
    group.bench_function("prepare every scene (the listing before)", |b| {
        b.iter(|| {
            let state = AppState::new(scenes_dir(), Limits::default());
            names
                .iter()
                .map(|n| state.prepared(n).map_or(0, |p| p.triangle_count()))
                .sum::<usize>()
        });
    });
    group.finish();
}

criterion_group!(benches, listing);
criterion_main!(benches);
