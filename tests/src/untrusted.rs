//! Untrusted scene input, as the fuzz targets (`fuzz/`) and the property test
//! `loaders::untrusted` feed it: any bytes must load or fail with an error,
//! never panic or hang; what loads must prepare and render.

use continuum::{AlgorithmId, PreparedScene, RenderRequest, render};

/// Which loader reads the bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Glb,
    Obj,
    SceneToml,
}

/// Scenes above this many triangles are loaded but not prepared (a fuzz run
/// should find crashes, not spend its time building big BVHs).
const MAX_PREPARED_TRIANGLES: usize = 100_000;

/// Loads `data` as `format`; if it loads, prepares it and renders 16×16 with
/// a 2D, a 3D and the ray-casting algorithm from its first camera. Returns
/// the loader's error, if any.
pub fn exercise(format: Format, data: &[u8]) -> Result<(), String> {
    let scene = match format {
        Format::Glb => continuum::scene::load_gltf_slice(data, "fuzz.glb"),
        Format::Obj => continuum::scene::load_obj_slice(data, "fuzz.obj"),
        Format::SceneToml => {
            let text = std::str::from_utf8(data).map_err(|e| e.to_string())?;
            // No folder: referenced files fail to load.
            let dir = std::path::Path::new("/nonexistent-continuum-fuzz");
            continuum::scene::load_scene_file_str(text, "fuzz.toml", dir)
        }
    }
    .map_err(|e| e.to_string())?;
    if scene.mesh.triangle_count() > MAX_PREPARED_TRIANGLES {
        return Ok(());
    }
    let camera = scene.first_camera();
    let prepared = PreparedScene::new(scene);
    for algorithm in [
        AlgorithmId::TwoDBrute,
        AlgorithmId::ThreeDBin,
        AlgorithmId::Raycast,
    ] {
        let request = RenderRequest::new(algorithm, camera.clone(), 16, 16);
        // A camera the scene names may not serve every algorithm (a
        // non-planar viewport with a 2D one): an error, not a crash.
        let _ = render(&prepared, &request);
    }
    Ok(())
}
