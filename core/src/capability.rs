//! Floor 9: the one answer to "can this request be rendered here?" —
//! algorithm × viewport × precision × anti-aliasing × oracles × the scene's
//! effects × this machine — with the field at fault. `render` asks
//! it first; the service asks it before queueing a render, the viewer before
//! starting one, and `/api/algorithms` builds its listing from it.

use crate::aa::AaMode;
use crate::ground::{AlgorithmId, FieldError, MAX_DIMENSION};
use crate::pipeline::Pipeline;
use crate::precision::Precision;
use crate::prepared::PreparedScene;
use crate::request::RenderRequest;
use crate::viewport::Viewport;

/// Whether `request` can be rendered here, or the first field that stops it:
/// `size`, `camera`, `oracles`, `viewport`, `precision`, `aa`, then
/// `algorithm` (what this machine cannot run, or — with `scene` — what the
/// scene's materials rule out). Without a scene, the scene's part is left to
/// the render.
pub fn check(request: &RenderRequest, scene: Option<&PreparedScene>) -> Result<(), FieldError> {
    pipeline_for(request, scene).map(|_| ())
}

/// [`check`], answering with the pipeline that renders the request.
pub(crate) fn pipeline_for(
    request: &RenderRequest,
    scene: Option<&PreparedScene>,
) -> Result<Pipeline, FieldError> {
    let (width, height) = (request.width, request.height);
    if width == 0 || height == 0 || width > MAX_DIMENSION || height > MAX_DIMENSION {
        return Err(FieldError::new(
            "size",
            format!(
                "{width}x{height} is out of range: width and height must be in 1..={MAX_DIMENSION}"
            ),
        ));
    }
    request.camera.validate()?;
    let algorithm = request.algorithm;
    let pipeline = algorithm.pipeline().with_oracles(&request.oracles)?;
    let viewport = request.camera.viewport;
    if !pipeline.serves(&viewport) {
        return Err(viewport_unsupported(viewport, algorithm));
    }
    if !request.precision.serves(algorithm.family()) {
        return Err(precision_unsupported(request.precision, algorithm));
    }
    if pipeline.samples().is_some_and(|s| s.incremental) {
        if viewport != Viewport::Parabolic {
            return Err(FieldError::new(
                "oracles",
                format!(
                    "incremental: the double-incremental scheme serves the parabolic viewport only, not {}",
                    viewport.kind()
                ),
            ));
        }
        if request.aa != AaMode::None {
            return Err(FieldError::new(
                "oracles",
                format!(
                    "incremental: the double-incremental scheme steps along rows of pixel centres; not with aa {}",
                    request.aa
                ),
            ));
        }
    }
    if pipeline == Pipeline::Gpu && request.aa != AaMode::None {
        return Err(FieldError::new(
            "aa",
            format!(
                "gpu-raster renders one sample per pixel; not aa {}",
                request.aa
            ),
        ));
    }
    if matches!(pipeline, Pipeline::Compute(_)) && !COMPUTE_AA.contains(&request.aa) {
        return Err(FieldError::new(
            "aa",
            format!(
                "{algorithm} renders aa none, msaa:2, msaa:4 and ssaa:4 (at most four stored samples, no coverage-only ones); not aa {}",
                request.aa
            ),
        ));
    }
    if !request.depth_test && !matches!(pipeline, Pipeline::Compute(_)) {
        return Err(FieldError::new(
            "depth_test",
            format!(
                "{algorithm} always keeps the nearest sample; the depth test can be off for gpu-2dr, gpu-2dr-homogeneous, gpu-3dr and gpu-3dr-binned (the paper's section 5 experiment)"
            ),
        ));
    }
    if let Some(why) = unavailable(algorithm) {
        return Err(FieldError::new("algorithm", why));
    }
    let on_gpu = matches!(pipeline, Pipeline::Gpu | Pipeline::Compute(_));
    if on_gpu && scene.is_some_and(|s| !s.triangle_opacity.is_empty()) {
        return Err(FieldError::new(
            "algorithm",
            format!(
                "{algorithm} draws opaque surfaces only; this scene has see-through materials (opacity < 1)"
            ),
        ));
    }
    Ok(pipeline)
}

/// The anti-aliasing modes the compute kernels render: at most four stored
/// samples, each also a coverage sample.
const COMPUTE_AA: [AaMode; 4] = [
    AaMode::None,
    AaMode::Msaa(2),
    AaMode::Msaa(4),
    AaMode::Ssaa(4),
];

/// Why this process cannot run `algorithm` on this machine, or `None` when it
/// can: `gpu-raster` needs the `gpu` feature and a device that renders its
/// formats (opened on first ask). Front ends list, grey out or skip what this
/// names; [`check`] refuses it with the same message.
pub fn unavailable(algorithm: AlgorithmId) -> Option<String> {
    match algorithm.pipeline() {
        Pipeline::Gpu | Pipeline::Compute(_) => gpu_unavailable(),
        _ => None,
    }
}

/// The GPU adapter `gpu-raster` renders on (for a report's machine facts),
/// or `None` when it cannot run.
pub fn gpu_adapter() -> Option<String> {
    #[cfg(feature = "gpu")]
    return crate::gpu::gpu().ok().map(|g| g.adapter.clone());
    #[cfg(not(feature = "gpu"))]
    None
}

/// Chooses the GPU adapter by a (case-insensitive) part of its name, for
/// every GPU algorithm of this process (`--adapter`; `CONTINUUM_ADAPTER`
/// otherwise). Only a choice made before the first GPU render counts:
/// returns whether this one did.
pub fn choose_gpu_adapter(name: &str) -> bool {
    #[cfg(feature = "gpu")]
    return crate::gpu::choose_adapter(name);
    #[cfg(not(feature = "gpu"))]
    {
        let _ = name;
        false
    }
}

/// Makes the GPU compute kernels keep visibility with two passes of 32-bit
/// atomics even where 64-bit `atomicMin` exists (`CONTINUUM_GPU_ATOMICS=two-pass`
/// does the same): the fallback, testable on any adapter.
pub fn force_gpu_two_pass(on: bool) {
    #[cfg(feature = "gpu")]
    crate::gpu::set_atomics(if on {
        crate::gpu::GpuAtomics::TwoPass
    } else {
        crate::gpu::GpuAtomics::Auto
    });
    #[cfg(not(feature = "gpu"))]
    let _ = on;
}

#[cfg(feature = "gpu")]
fn gpu_unavailable() -> Option<String> {
    crate::gpu::gpu().err().map(|e| e.to_string())
}

#[cfg(not(feature = "gpu"))]
fn gpu_unavailable() -> Option<String> {
    Some(crate::algorithm::NO_GPU_FEATURE.into())
}

/// The error for an algorithm `viewport` does not serve, listing those that do.
fn viewport_unsupported(viewport: Viewport, algorithm: AlgorithmId) -> FieldError {
    let served: Vec<&str> = AlgorithmId::ALL
        .into_iter()
        .filter(|a| a.pipeline().serves(&viewport))
        .map(AlgorithmId::as_str)
        .collect();
    FieldError::new(
        "viewport",
        format!(
            "{algorithm} cannot render the {kind} viewport (it needs straight edges); \
             {kind} is served by {}; perspective and orthographic by every algorithm",
            served.join(", "),
            kind = viewport.kind(),
        ),
    )
}

/// The error for an algorithm `precision` does not serve, listing those it does.
fn precision_unsupported(precision: Precision, algorithm: AlgorithmId) -> FieldError {
    let served: Vec<&str> = AlgorithmId::ALL
        .into_iter()
        .filter(|a| precision.serves(a.family()))
        .map(AlgorithmId::as_str)
        .collect();
    FieldError::new(
        "precision",
        format!(
            "{algorithm} does not compute in {precision}; {precision} serves {}",
            served.join(", ")
        ),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;
    use crate::ground::Bounds;
    use crate::pipeline::Oracles;

    fn request(algorithm: AlgorithmId, viewport: Viewport) -> RenderRequest {
        let mut camera = Camera::framing(&Bounds::EMPTY);
        camera.viewport = viewport;
        RenderRequest::new(algorithm, camera, 32, 32)
    }

    fn field(r: &RenderRequest) -> Option<&'static str> {
        check(r, None).err().map(|e| e.field)
    }

    #[test]
    fn each_refusal_names_its_field() {
        let ok = request(AlgorithmId::ThreeDBrute, Viewport::Parabolic);
        assert_eq!(field(&ok), None);
        let mut r = ok.clone();
        r.width = 0;
        assert_eq!(field(&r), Some("size"));
        let mut r = ok.clone();
        r.camera.up = r.camera.target - r.camera.eye;
        assert_eq!(field(&r), Some("camera"));
        assert_eq!(
            field(&request(AlgorithmId::TwoDBin, Viewport::LatLong)),
            Some("viewport")
        );
        let mut r = ok.clone();
        r.precision = Precision::Fixed;
        assert_eq!(field(&r), Some("precision"));
        let e = check(&r, None).unwrap_err();
        assert!(e.message.contains("2dr-brute, 2dr-bin"), "{e}");
        let mut r = ok.clone();
        r.oracles = Oracles::parse("split=8").unwrap();
        assert_eq!(field(&r), Some("oracles"));
        let mut r = request(AlgorithmId::ThreeDBrute, Viewport::LatLong);
        r.oracles = Oracles::parse("incremental=on").unwrap();
        assert_eq!(field(&r), Some("oracles"));
        let mut r = ok;
        r.oracles = Oracles::parse("incremental=on").unwrap();
        r.aa = AaMode::Msaa(4);
        assert_eq!(field(&r), Some("oracles"));
    }

    #[test]
    fn the_viewport_error_lists_what_serves_it() {
        let e = check(&request(AlgorithmId::TwoDBrute, Viewport::Parabolic), None).unwrap_err();
        assert!(e.message.contains("3dr-brute, 3dr-bin, raycast"), "{e}");
    }
}
