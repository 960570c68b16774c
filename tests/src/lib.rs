//! Shared helpers for continuum's integration tests: built-in scenes loaded and
//! prepared once per test process, renders, and buffer comparisons.

pub mod golden;
pub mod matrix;
pub mod untrusted;

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

use continuum::{AlgorithmId, Camera, Oracles, PreparedScene, RenderOutput, RenderRequest, render};

/// The repository's `scenes/` folder.
pub fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes")
}

/// Every built-in scene name.
pub fn builtin_scenes() -> Vec<String> {
    let names = continuum::scene::builtin_names(&scenes_dir()).expect("the scenes folder lists");
    assert!(
        names.len() >= 12,
        "only {} built-in scenes: {names:?}",
        names.len()
    );
    names
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
    render_with_oracles(scene, algorithm, None, camera, width, height)
}

/// As [`render_with`], with explicit oracle settings.
pub fn render_with_oracles(
    scene: &PreparedScene,
    algorithm: AlgorithmId,
    oracles: Option<&str>,
    camera: &Camera,
    width: u32,
    height: u32,
) -> RenderOutput {
    render(
        scene,
        &RenderRequest {
            oracles: oracles
                .map(|text| Oracles::parse(text).unwrap_or_else(|e| panic!("{text}: {e}")))
                .unwrap_or_default(),
            ..RenderRequest::new(algorithm, camera.clone(), width, height)
        },
    )
    .unwrap_or_else(|e| panic!("{algorithm} {oracles:?}: {e}"))
}

/// As [`render_with`], with an anti-aliasing mode.
pub fn render_aa(
    scene: &PreparedScene,
    algorithm: AlgorithmId,
    camera: &Camera,
    size: (u32, u32),
    aa: continuum::AaMode,
) -> RenderOutput {
    render_full(scene, algorithm, camera, size, aa, Default::default())
}

/// Renders at `precision` (one sample per pixel), panicking on error.
pub fn render_precise(
    scene: &PreparedScene,
    algorithm: AlgorithmId,
    camera: &Camera,
    size: (u32, u32),
    precision: continuum::Precision,
) -> RenderOutput {
    render_full(
        scene,
        algorithm,
        camera,
        size,
        continuum::AaMode::None,
        precision,
    )
}

/// Renders with an anti-aliasing mode and a precision, panicking on error.
pub fn render_full(
    scene: &PreparedScene,
    algorithm: AlgorithmId,
    camera: &Camera,
    (width, height): (u32, u32),
    aa: continuum::AaMode,
    precision: continuum::Precision,
) -> RenderOutput {
    render(
        scene,
        &RenderRequest {
            aa,
            precision,
            ..RenderRequest::new(algorithm, camera.clone(), width, height)
        },
    )
    .unwrap_or_else(|e| panic!("{algorithm} {aa} {precision}: {e}"))
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
    let p = scene.triangle(id).map(|v| v.as_dvec3());
    if view.is_orthographic() {
        return pixel_geometry_orthographic(view, p, x, y);
    }
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

/// [`pixel_geometry`] for parallel rays `o(x, y) + t·d_p`: edge functions
/// `(d_p × (a − b))·(m − o)` and `w = N·(p0 − o) / (N·d_p)`.
fn pixel_geometry_orthographic(
    view: &continuum::View,
    p: [glam::DVec3; 3],
    x: f64,
    y: f64,
) -> PixelGeometry {
    let (ox, oy) = (view.ox.as_dvec3(), view.oy.as_dvec3());
    let o = view.eye.as_dvec3() + view.o0.as_dvec3() + ox * x + oy * y;
    let dp = view.forward.as_dvec3();
    let gradient_of = |k: glam::DVec3| (k.dot(ox).powi(2) + k.dot(oy).powi(2)).sqrt();
    let mut edge_distance = f64::INFINITY;
    for i in 0..3 {
        let (a, b) = (p[(i + 1) % 3], p[(i + 2) % 3]);
        let n = dp.cross(a - b);
        edge_distance = edge_distance.min(n.dot((a + b) * 0.5 - o).abs() / gradient_of(n));
    }
    let normal = (p[1] - p[0]).cross(p[2] - p[0]);
    let w = normal.dot(p[0] - o) / normal.dot(dp);
    let grad = gradient_of(normal) / normal.dot(dp).abs();
    PixelGeometry {
        edge_distance,
        near_distance: (w - f64::from(view.near)).abs() / grad,
        w,
    }
}

/// The f64 view-axis depths of triangles `a` and `b` at the centre of
/// pixel `(x, y)` of `view`.
pub fn depths_at(
    scene: &PreparedScene,
    view: &continuum::View,
    (x, y): (u32, u32),
    [a, b]: [u32; 2],
) -> [f64; 2] {
    let (xc, yc) = (f64::from(x) + 0.5, f64::from(y) + 0.5);
    [a, b].map(|id| pixel_geometry(scene, view, id, xc, yc).w)
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

/// A camera at the origin looking down −z with a 90° field of view: at 8×8 pixels
/// the sample generator is exact in binary (`d0 = (−1, 1, −1)`, `dx = (¼, 0, 0)`,
/// `dy = (0, −¼, 0)`), so pixel point `(x, y)` is world point `(−1 + x/4, 1 − y/4, −1)`
/// and edges through pixel centres evaluate to exactly zero.
pub fn exact_camera() -> Camera {
    Camera {
        name: "exact".into(),
        eye: glam::Vec3::ZERO,
        target: glam::Vec3::NEG_Z,
        up: glam::Vec3::Y,
        viewport: continuum::Viewport::Perspective { fov_y_deg: 90.0 },
        near: Some(0.01),
    }
}

/// World point of pixel point `(x, y)` under [`exact_camera`] at 8×8 pixels.
pub fn pixel_point(x: f32, y: f32) -> glam::Vec3 {
    glam::Vec3::new(-1.0 + x / 4.0, 1.0 - y / 4.0, -1.0)
}

/// A scene made in code: `triangles` over `positions`, one default material, one camera.
pub fn scene_from_triangles(
    positions: Vec<glam::Vec3>,
    triangles: Vec<[u32; 3]>,
    camera: Camera,
) -> PreparedScene {
    let n = triangles.len();
    let scene = continuum::Scene {
        name: "test".into(),
        source: "test".into(),
        mesh: continuum::scene::Mesh {
            positions,
            triangles,
            material_ids: vec![0; n],
            ..Default::default()
        },
        materials: vec![continuum::scene::Material::default()],
        cameras: vec![camera],
        ..Default::default()
    };
    scene.validate().expect("test scene is valid");
    PreparedScene::new(scene)
}

/// A binary glTF (`.glb`) from a JSON document and one binary buffer.
pub fn glb(json: &serde_json::Value, bin: &[u8]) -> Vec<u8> {
    let mut j = serde_json::to_vec(json).expect("json");
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    let total = 12 + 8 + j.len() + if b.is_empty() { 0 } else { 8 + b.len() };
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    if !b.is_empty() {
        out.extend_from_slice(&(b.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&b);
    }
    out
}

/// A one-mesh `.glb` with the given positions and u16 indices (mode 4 unless `mode`).
pub fn triangle_glb(positions: &[[f32; 3]], indices: &[u16], mode: u32) -> Vec<u8> {
    let indices: Vec<u32> = indices.iter().map(|&i| u32::from(i)).collect();
    let (json, bin) = triangle_gltf(positions, &indices, 5123, mode);
    glb(&json, &bin)
}

/// The JSON and binary buffer of a one-mesh glTF: positions, then indices stored
/// with `component_type` (5121 u8, 5123 u16, 5125 u32), primitive `mode`.
pub fn triangle_gltf(
    positions: &[[f32; 3]],
    indices: &[u32],
    component_type: u32,
    mode: u32,
) -> (serde_json::Value, Vec<u8>) {
    let mut bin: Vec<u8> = positions
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let pos_len = bin.len();
    for &i in indices {
        match component_type {
            5121 => bin.push(i as u8),
            5123 => bin.extend((i as u16).to_le_bytes()),
            _ => bin.extend(i.to_le_bytes()),
        }
    }
    let index_len = bin.len() - pos_len;
    let finite: Vec<[f32; 3]> = positions
        .iter()
        .copied()
        .filter(|p| p.iter().all(|v| v.is_finite()))
        .collect();
    let min: Vec<f32> = (0..3)
        .map(|k| finite.iter().map(|p| p[k]).fold(f32::INFINITY, f32::min))
        .collect();
    let max: Vec<f32> = (0..3)
        .map(|k| {
            finite
                .iter()
                .map(|p| p[k])
                .fold(f32::NEG_INFINITY, f32::max)
        })
        .collect();
    let json = serde_json::json!({
        "asset": { "version": "2.0" },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "mesh": 0 }],
        "meshes": [{ "name": "part", "primitives": [{ "attributes": { "POSITION": 0 }, "indices": 1, "mode": mode }] }],
        "buffers": [{ "byteLength": bin.len() }],
        "bufferViews": [
            { "buffer": 0, "byteOffset": 0, "byteLength": pos_len },
            { "buffer": 0, "byteOffset": pos_len, "byteLength": index_len }
        ],
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "count": positions.len(), "type": "VEC3", "min": min, "max": max },
            { "bufferView": 1, "componentType": component_type, "count": indices.len(), "type": "SCALAR" }
        ]
    });
    (json, bin)
}
