//! Shared helpers for continuum's integration tests: built-in scenes loaded and
//! prepared once per test process, renders, and buffer comparisons.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

use continuum::{AlgorithmId, Camera, PreparedScene, RenderOutput, RenderRequest, render};

/// The repository's `scenes/` folder.
pub fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes")
}

/// Every built-in scene name.
pub fn builtin_scenes() -> Vec<String> {
    continuum::scene::builtin_names(&scenes_dir())
}

/// A built-in scene, loaded and prepared once per process.
pub fn prepared(name: &str) -> Arc<PreparedScene> {
    static CACHE: OnceLock<Mutex<HashMap<String, Arc<PreparedScene>>>> = OnceLock::new();
    let cache = CACHE.get_or_init(Default::default);
    if let Some(p) = cache.lock().expect("cache lock").get(name) {
        return p.clone();
    }
    let scene = continuum::scene::load_named_or_path(name, &scenes_dir())
        .unwrap_or_else(|e| panic!("built-in scene {name}: {e}"));
    let p = Arc::new(PreparedScene::new(scene));
    cache
        .lock()
        .expect("cache lock")
        .insert(name.to_string(), p.clone());
    p
}

/// Renders with `algorithm` from `camera` at `width × height`, panicking on error.
pub fn render_with(
    scene: &PreparedScene,
    algorithm: AlgorithmId,
    camera: &Camera,
    width: u32,
    height: u32,
) -> RenderOutput {
    render(
        scene,
        &RenderRequest {
            algorithm,
            camera: camera.clone(),
            width,
            height,
        },
    )
    .unwrap_or_else(|e| panic!("{algorithm}: {e}"))
}

/// Pixels where two triangle-id buffers differ, as `(x, y, a, b)`.
pub fn id_differences(a: &RenderOutput, b: &RenderOutput) -> Vec<(u32, u32, u32, u32)> {
    let w = a.framebuffer.width;
    a.framebuffer
        .triangle_id
        .iter()
        .zip(&b.framebuffer.triangle_id)
        .enumerate()
        .filter(|(_, (x, y))| x != y)
        .map(|(i, (x, y))| (i as u32 % w, i as u32 / w, *x, *y))
        .collect()
}

/// Why a pixel differs between the 2D and the 3D family.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Explanation {
    /// The pixel centre lies within 1e-3 pixel of an edge of one of the two triangles.
    Edge,
    /// Within 1e-3 pixel of where one of the triangles crosses the near plane (the
    /// edge the 2D family's clipping makes).
    NearPlane,
    /// Both triangles are there and their depths differ by less than 1e-5 relative.
    DepthTie,
}

/// Tally of [`explain_2d_3d`].
#[derive(Clone, Debug, Default)]
pub struct DifferenceReport {
    pub covered: u64,
    pub edge: u64,
    pub near_plane: u64,
    pub depth_tie: u64,
    /// `(x, y, id_2d, id_3d)` of pixels nothing explains.
    pub unexplained: Vec<(u32, u32, u32, u32)>,
}

impl DifferenceReport {
    pub fn explained(&self) -> u64 {
        self.edge + self.near_plane + self.depth_tie
    }
}

/// Exact-ish (f64) geometry of one triangle at one pixel.
struct PixelGeometry {
    /// Distance in pixels from the pixel centre to the nearest of the three edge lines.
    edge_distance: f64,
    /// Distance in pixels to the line where the triangle's plane meets `w = near`.
    near_distance: f64,
    /// View-axis distance of the triangle's plane along the pixel's ray.
    w: f64,
}

fn pixel_geometry(
    scene: &PreparedScene,
    view: &continuum::View,
    id: u32,
    x: f64,
    y: f64,
) -> PixelGeometry {
    let p = scene.triangles[id as usize].map(|v| v.as_dvec3());
    let e = view.eye.as_dvec3();
    let (dx, dy) = (view.dx.as_dvec3(), view.dy.as_dvec3());
    let d = view.direction_f64(x, y);
    let mut edge_distance = f64::INFINITY;
    for i in 0..3 {
        let (a, b) = (p[(i + 1) % 3], p[(i + 2) % 3]);
        let n = (e - (a + b) * 0.5).cross(a - b);
        let gradient = (n.dot(dx).powi(2) + n.dot(dy).powi(2)).sqrt();
        edge_distance = edge_distance.min(n.dot(d).abs() / gradient);
    }
    let normal = (p[1] - p[0]).cross(p[2] - p[0]);
    let volume = normal.dot(p[0] - e);
    let w = volume / normal.dot(d);
    // f(x, y) = N·d / D − 1/near vanishes where the plane meets w = near.
    let f = normal.dot(d) / volume - 1.0 / f64::from(view.near);
    let grad = (normal.dot(dx).powi(2) + normal.dot(dy).powi(2)).sqrt() / volume.abs();
    PixelGeometry {
        edge_distance,
        near_distance: f.abs() / grad,
        w,
    }
}

/// Explains, in f64, every pixel where the 2D and 3D renders pick different
/// triangles (see [`Explanation`]).
pub fn explain_2d_3d(
    scene: &PreparedScene,
    two_d: &RenderOutput,
    three_d: &RenderOutput,
) -> DifferenceReport {
    let view = &three_d.view;
    let mut report = DifferenceReport {
        covered: three_d
            .framebuffer
            .triangle_id
            .iter()
            .filter(|&&id| id != continuum::BACKGROUND)
            .count() as u64,
        ..DifferenceReport::default()
    };
    for (x, y, a, b) in id_differences(two_d, three_d) {
        let (xc, yc) = (f64::from(x) + 0.5, f64::from(y) + 0.5);
        let geo: Vec<PixelGeometry> = [a, b]
            .into_iter()
            .filter(|&id| id != continuum::BACKGROUND)
            .map(|id| pixel_geometry(scene, view, id, xc, yc))
            .collect();
        if std::env::var_os("CONTINUUM_DEBUG_DIFF").is_some() {
            let d: Vec<f64> = geo.iter().map(|g| g.edge_distance).collect();
            eprintln!("diff ({x},{y}) {a} vs {b}: edge distances {d:?}");
        }
        let explanation = if geo.iter().any(|g| g.edge_distance < 1e-3) {
            Some(Explanation::Edge)
        } else if geo.iter().any(|g| g.near_distance < 1e-3) {
            Some(Explanation::NearPlane)
        } else if geo.len() == 2
            && (geo[0].w - geo[1].w).abs() < 1e-5 * geo[0].w.abs().max(geo[1].w.abs())
        {
            Some(Explanation::DepthTie)
        } else {
            None
        };
        match explanation {
            Some(Explanation::Edge) => report.edge += 1,
            Some(Explanation::NearPlane) => report.near_plane += 1,
            Some(Explanation::DepthTie) => report.depth_tie += 1,
            None => report.unexplained.push((x, y, a, b)),
        }
    }
    report
}
