//! The compute kernels' visibility without 64-bit atomics: two passes of
//! 32-bit atomics (nearest depth, then the smallest id at it) must give
//! exactly what one 64-bit atomicMin on (depth bits << 32 | id) gives.
//! A test binary of its own: the fallback is forced for the whole process.

use continuum::{AlgorithmId, RenderRequest, render};
use continuum_tests::{builtin_scenes, prepared};

#[test]
fn two_pass_visibility_equals_the_64_bit_atomic() {
    let brute = [
        AlgorithmId::Gpu2dr,
        AlgorithmId::Gpu2drHomogeneous,
        AlgorithmId::Gpu3dr,
    ];
    let mut compared = 0;
    for name in builtin_scenes() {
        let scene = prepared(&name);
        if !scene.triangle_opacity.is_empty() {
            continue;
        }
        for camera in &scene.scene.cameras {
            for algorithm in brute {
                let request = RenderRequest::new(algorithm, camera.clone(), 128, 96);
                let run = |two_pass: bool| {
                    continuum::force_gpu_two_pass(two_pass);
                    render(&scene, &request).unwrap_or_else(|e| panic!("{algorithm}: {e}"))
                };
                let (one, two) = (run(false), run(true));
                let atomics = |o: &continuum::RenderOutput| {
                    o.stats.gpu.as_ref().expect("GPU times").atomics.clone()
                };
                // Lavapipe (CI) has shaderBufferInt64Atomics: the first is the 64-bit path.
                assert_eq!(
                    atomics(&one),
                    "64-bit",
                    "{name}/{} {algorithm}",
                    camera.name
                );
                assert_eq!(atomics(&two), "32-bit two-pass");
                let label = format!("{name}/{} {algorithm}", camera.name);
                assert_eq!(
                    one.framebuffer.triangle_id, two.framebuffer.triangle_id,
                    "{label}"
                );
                assert_eq!(one.framebuffer.depth, two.framebuffer.depth, "{label}");
                assert_eq!(
                    one.framebuffer.coverage_writes, two.framebuffer.coverage_writes,
                    "{label}"
                );
                assert_eq!(one.hashes(), two.hashes(), "{label}");
                compared += 1;
            }
        }
    }
    continuum::force_gpu_two_pass(false);
    assert!(compared >= 10 * 2 * 3, "only {compared} compared");
}
