//! Overlays and the trace behind them: the trace records exactly what the
//! counters count, recording it changes no pixel, and each overlay draws
//! over the image only where it has something to show.

use continuum::{
    AlgorithmId, BlockOutcome, FrustumEvent, NodeOutcome, Overlays, RenderRequest, draw_overlays,
    maps, render,
};
use continuum_tests::prepared;

fn request(scene: &continuum::PreparedScene, algorithm: AlgorithmId, trace: bool) -> RenderRequest {
    RenderRequest {
        trace,
        ..RenderRequest::new(algorithm, scene.scene.first_camera(), 160, 120)
    }
}

/// Every algorithm, traced and not: the same hashes and counters; the trace
/// only when asked; its records as many as the counters say.
#[test]
fn the_trace_records_what_the_counters_count_and_changes_nothing() {
    let mut checked = 0;
    for name in ["teapots", "box", "bunny"] {
        let scene = prepared(name);
        for algorithm in AlgorithmId::CPU {
            let plain = render(&scene, &request(&scene, algorithm, false)).unwrap();
            let traced = render(&scene, &request(&scene, algorithm, true)).unwrap();
            let label = format!("{name} {algorithm}");
            assert!(plain.trace.is_none(), "{label}: a trace nobody asked for");
            assert_eq!(plain.hashes(), traced.hashes(), "{label}");
            assert_eq!(plain.stats.counters, traced.stats.counters, "{label}");
            let trace = traced.trace.as_ref().expect("a trace");
            let c = &traced.stats.counters;
            let blocks = |o| trace.blocks.iter().filter(|b| b.1 == o).count() as u64;
            assert_eq!(blocks(BlockOutcome::Accepted), c.tiles_accepted, "{label}");
            assert_eq!(blocks(BlockOutcome::Rejected), c.tiles_rejected, "{label}");
            assert_eq!(blocks(BlockOutcome::Refined), c.tiles_refined, "{label}");
            let frusta = |e| trace.frusta.iter().filter(|f| f.1 == e).count() as u64;
            assert_eq!(frusta(FrustumEvent::Created), c.frusta_created, "{label}");
            assert_eq!(frusta(FrustumEvent::Split), c.frusta_split, "{label}");
            let nodes = |o| trace.nodes.iter().filter(|n| n.1 == o).count() as u64;
            assert_eq!(
                nodes(NodeOutcome::Outside),
                c.nodes_culled_outside,
                "{label}"
            );
            assert_eq!(
                nodes(NodeOutcome::Occluded),
                c.nodes_culled_occluded,
                "{label}"
            );
            let frusta_algorithms = [
                AlgorithmId::ThreeDFrustumCull,
                AlgorithmId::ThreeDFrustumSplit,
                AlgorithmId::ThreeDFull,
            ];
            if frusta_algorithms.contains(&algorithm) {
                assert_eq!(
                    trace.nodes.len() as u64,
                    traced.stats.bvh_nodes_visited,
                    "{label}"
                );
                assert!(frusta(FrustumEvent::Rasterized) > 0, "{label}");
            }
            if algorithm == AlgorithmId::Raycast {
                // The nodes its packets entered, each tile's once.
                let entered = trace.nodes.iter().all(|n| n.1 == NodeOutcome::Entered);
                assert!(entered && !trace.nodes.is_empty(), "{label}");
                assert!(trace.nodes.len() as u64 <= traced.stats.bvh_nodes_visited);
            }
            // Every pixel lies in exactly one work item.
            let area: u64 = trace
                .tiles
                .iter()
                .map(|r| u64::from(r.width() * r.height()))
                .sum();
            assert_eq!(area, 160 * 120, "{label}: work items");
            checked += 1;
        }
    }
    assert_eq!(checked, 3 * AlgorithmId::CPU.len());
}

/// Each overlay changes the image where it has records (and the frusta
/// overlay of a render without frusta changes nothing).
#[test]
fn overlays_draw_what_was_recorded() {
    let scene = prepared("teapots");
    let out = render(
        &scene,
        &request(&scene, AlgorithmId::ThreeDFrustumSplit, true),
    )
    .unwrap();
    let base = maps::color_image(&out.framebuffer);
    let mut drawn = 0;
    for name in Overlays::NAMES {
        let overlays = Overlays::parse(name).unwrap();
        let mut img = base.clone();
        draw_overlays(&mut img, overlays, &out, &scene);
        let changed = img
            .pixels()
            .zip(base.pixels())
            .filter(|(a, b)| a != b)
            .count();
        assert!(changed > 500, "{name} changed only {changed} pixels");
        drawn += 1;
    }
    assert_eq!(drawn, 4);
    let brute = render(&scene, &request(&scene, AlgorithmId::ThreeDBrute, true)).unwrap();
    let mut img = maps::color_image(&brute.framebuffer);
    let before = img.clone();
    draw_overlays(
        &mut img,
        Overlays::parse("frusta,bvh").unwrap(),
        &brute,
        &scene,
    );
    assert_eq!(img, before, "3dr-brute makes no frusta and visits no nodes");
    let e = Overlays::parse("frusta,holes").unwrap_err();
    assert_eq!(e.field, "overlays");
}
