//! The hard-case suite: named cases (`tests/hard_cases/NAME.toml`) that stress
//! the numerics of coverage — pixel centres exactly on shared edges and
//! vertices, fans, slivers, sub-pixel and huge triangles, triangles through the
//! eye plane, degenerate input, closed meshes — each rendered by every
//! algorithm at every precision it computes in, through every viewport that
//! serves it, at the origin and far from it (offsets 10³ … 10⁷ with the camera
//! alongside), and checked against an f64 reference ([`mod@reference`]).
//!
//! A case file:
//! ```toml
//! description = "What the case stresses"
//! size = [64, 48]                  # image size (default 64x48)
//! offsets = true                   # also far from the origin (default true)
//! viewports = ["perspective", "orthographic:40", "parabolic", "latlong"]   # default: these four
//! [limits]                         # documented limits: violations of these
//! gpu-raster = "why"               # algorithms (`ID` or `ID@PRECISION`) are reported, not failed
//! [scene]                          # a scene, as in scenes/*.toml
//! [[scene.mesh]]
//! generator = "fan"
//! params = { count = 8, radius = 6.0 }
//! [[scene.camera]]
//! name = "front"
//! eye = [0, 0, 20]
//! target = [0, 0, 0]
//! ```
//!
//! Invariants of every render (a [`Check`] counts the pixels that break each):
//! - `error`: it renders (no error, no panic);
//! - `depth`: covered pixels have a finite positive depth, others none;
//! - `degenerate`: no degenerate triangle is drawn;
//! - `visible`: where the reference is unambiguous, the visible triangle is its;
//! - `coverage`: coverage writes equal the reference's count where that is
//!   unambiguous, and never exceed the most triangles the reference finds
//!   around the pixel — so every sample of a partitioned or closed surface is
//!   covered exactly once, and nothing outside the geometry is. Algorithms
//!   that cull hidden work (early-z, occlusion, the ray caster) are checked
//!   where at most one triangle covers the pixel;
//! - `agreement`: the algorithms of a family at one precision give the same
//!   triangle ids bit for bit.

pub mod reference;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

use glam::{DVec3, Vec3};
use serde::{Deserialize, Serialize};

use continuum::scene::{LightKind, SceneFile};
use continuum::{
    AlgorithmId, BACKGROUND, Bounds, Camera, Family, Precision, PreparedScene, RenderOutput,
    RenderRequest, Scene, SceneError, View, Viewport, render,
};
use reference::{Expected, Reference};

/// Distances from the origin every case is also rendered at, along
/// [`OFFSET_DIRECTION`] (geometry, cameras and lights move together).
pub const OFFSETS: [f64; 6] = [0.0, 1e3, 1e4, 1e5, 1e6, 1e7];

/// The direction of the offsets (unnormalised: every coordinate grows).
pub const OFFSET_DIRECTION: [f64; 3] = [1.0, 0.75, -0.5];

/// The largest offset at which f32 renders are held to every invariant;
/// beyond it their violations are reported, not failed.
pub const F32_OFFSET_LIMIT: f64 = 1e7;

/// Is `check` beyond the documented limits: its case names a limit of its
/// algorithm, or it is an f32 render of continuum's own beyond
/// [`F32_OFFSET_LIMIT`]?
pub fn beyond_limit(check: &Check) -> bool {
    check.limit.is_some()
        || (check.precision == Precision::F32
            && !snaps_vertices(check.algorithm, check.precision)
            && check.offset > F32_OFFSET_LIMIT)
}

/// A variant's name in tables and `[limits]`: the id, with `@precision` unless f32.
pub fn variant_name(algorithm: AlgorithmId, precision: Precision) -> String {
    if precision == Precision::F32 {
        algorithm.to_string()
    } else {
        format!("{algorithm}@{precision}")
    }
}

/// Every (algorithm, precision) pair there is, in table order.
pub fn variants_of_all() -> Vec<(AlgorithmId, Precision)> {
    AlgorithmId::ALL
        .into_iter()
        .flat_map(|a| {
            Precision::ALL
                .into_iter()
                .filter(move |p| p.serves(a.family()))
                .map(move |p| (a, p))
        })
        .collect()
}

/// A hard-case file (see the module documentation).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HardCaseFile {
    pub description: String,
    #[serde(default = "default_size")]
    pub size: [u32; 2],
    #[serde(default = "default_offsets")]
    pub offsets: bool,
    pub viewports: Option<Vec<String>>,
    /// Documented limits: algorithm (`ID` or `ID@PRECISION`) → why it cannot
    /// hold this case's invariants.
    #[serde(default)]
    pub limits: std::collections::BTreeMap<String, String>,
    pub scene: SceneFile,
}

fn default_size() -> [u32; 2] {
    [64, 48]
}
fn default_offsets() -> bool {
    true
}

/// A named hard case, loaded.
#[derive(Clone, Debug)]
pub struct HardCase {
    pub name: String,
    pub path: PathBuf,
    pub file: HardCaseFile,
}

impl HardCase {
    /// Loads one case file; errors name the file and the key.
    pub fn load(path: &Path) -> Result<HardCase, SceneError> {
        let text = std::fs::read_to_string(path).map_err(|e| SceneError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        let file: HardCaseFile = toml::from_str(&text).map_err(|e| SceneError::SceneFile {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        let [w, h] = file.size;
        if !(1..=1024).contains(&w) || !(1..=1024).contains(&h) {
            return Err(SceneError::SceneFile {
                path: path.display().to_string(),
                message: format!("size: {w}x{h} is out of range 1..=1024"),
            });
        }
        let name = path
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("case")
            .to_string();
        if let Some(bad) = file.limits.keys().find(|k| {
            !variants_of_all()
                .iter()
                .any(|(a, p)| variant_name(*a, *p) == **k || a.as_str() == *k)
        }) {
            return Err(SceneError::SceneFile {
                path: path.display().to_string(),
                message: format!("limits: '{bad}' is not an algorithm (ID or ID@PRECISION)"),
            });
        }
        let case = HardCase {
            name,
            path: path.to_path_buf(),
            file,
        };
        // The scene must build, and the viewports parse.
        case.scene(0.0)?;
        Ok(case)
    }

    /// The case's scene moved `offset` along [`OFFSET_DIRECTION`].
    pub fn scene(&self, offset: f64) -> Result<Scene, SceneError> {
        let source = self.path.display().to_string();
        let dir = self.path.parent().unwrap_or(Path::new("."));
        let mut scene = self.file.scene.build(&source, self.name.clone(), dir)?;
        for c in &scene.cameras {
            self.viewports(c).map_err(|e| SceneError::SceneFile {
                path: source.clone(),
                message: format!("viewports: {e}"),
            })?;
        }
        if offset != 0.0 {
            translate(&mut scene, DVec3::from(OFFSET_DIRECTION) * offset);
        }
        Ok(scene)
    }

    /// The viewports `camera` is rendered with: the case's list, or the four
    /// kinds (orthographic framing what the camera's field of view shows at
    /// its target).
    pub fn viewports(&self, camera: &Camera) -> Result<Vec<Viewport>, String> {
        match &self.file.viewports {
            Some(list) => list
                .iter()
                .map(|v| Viewport::parse(v, camera.viewport).map_err(|e| e.message))
                .collect(),
            None => {
                let height = camera.framing_height();
                let perspective = match camera.viewport {
                    p @ Viewport::Perspective { .. } => p,
                    _ => Viewport::Perspective { fov_y_deg: 60.0 },
                };
                Ok(vec![
                    perspective,
                    Viewport::Orthographic { height },
                    Viewport::Parabolic,
                    Viewport::LatLong,
                ])
            }
        }
    }

    /// The offsets this case runs at.
    pub fn offsets(&self) -> &'static [f64] {
        if self.file.offsets {
            &OFFSETS
        } else {
            &OFFSETS[..1]
        }
    }
}

/// Moves geometry, cameras and lights by `by` (each coordinate rounded once to f32).
fn translate(scene: &mut Scene, by: DVec3) {
    let shift = |p: Vec3| (p.as_dvec3() + by).as_vec3();
    for p in &mut scene.mesh.positions {
        *p = shift(*p);
    }
    for c in &mut scene.cameras {
        c.eye = shift(c.eye);
        c.target = shift(c.target);
    }
    for l in &mut scene.lights {
        match &mut l.kind {
            LightKind::Point { position } | LightKind::Spot { position, .. } => {
                *position = shift(*position);
            }
            LightKind::Directional { .. } => {}
        }
    }
}

/// Every `*.toml` case in `dir`, sorted by name.
pub fn load_cases(dir: &Path) -> Result<Vec<HardCase>, SceneError> {
    let entries = std::fs::read_dir(dir).map_err(|e| SceneError::Io {
        path: dir.display().to_string(),
        message: e.to_string(),
    })?;
    let mut paths: Vec<PathBuf> = entries
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().and_then(|x| x.to_str()) == Some("toml"))
        .collect();
    paths.sort();
    paths.iter().map(|p| HardCase::load(p)).collect()
}

/// The folder of hard cases: `$CONTINUUM_HARD_CASES`, else `tests/hard_cases`
/// beside the executable (or up to three levels up), else the repository's.
pub fn default_cases_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("CONTINUUM_HARD_CASES") {
        return PathBuf::from(dir);
    }
    if let Ok(exe) = std::env::current_exe() {
        for up in exe.ancestors().skip(1).take(4) {
            let candidate = up.join("tests/hard_cases");
            if candidate.is_dir() {
                return candidate;
            }
        }
    }
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/hard_cases")
}

/// Pixels that break each invariant in one render (see the module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Violations {
    pub error: u64,
    pub depth: u64,
    pub degenerate: u64,
    pub visible: u64,
    pub coverage: u64,
    pub agreement: u64,
}

impl Violations {
    pub fn total(&self) -> u64 {
        self.error + self.depth + self.degenerate + self.visible + self.coverage + self.agreement
    }
}

/// One render of a case, checked.
#[derive(Clone, Debug, Serialize)]
pub struct Check {
    pub case: String,
    pub camera: String,
    pub viewport: String,
    pub offset: f64,
    pub algorithm: AlgorithmId,
    pub precision: Precision,
    pub violations: Violations,
    /// The first violation, described.
    pub example: Option<String>,
    /// The case's documented limit for this algorithm, if it has one.
    pub limit: Option<String>,
}

/// Every (algorithm, precision) that serves `viewport` and that this machine
/// can run ([`continuum::check`] says so; the suite reports the others as not
/// run): every algorithm at f32, the 3D family also at f64, the 2D family also
/// in fixed point.
pub fn variants(viewport: &Viewport) -> Vec<(AlgorithmId, Precision)> {
    let camera = Camera {
        viewport: *viewport,
        ..Camera::framing(&Bounds::EMPTY)
    };
    variants_of_all()
        .into_iter()
        .filter(|&(algorithm, precision)| {
            let request = RenderRequest {
                precision,
                ..RenderRequest::new(algorithm, camera.clone(), 1, 1)
            };
            continuum::check(&request, None).is_ok()
        })
        .collect()
}

/// The algorithms this machine cannot run, with why.
pub fn not_run() -> Vec<(AlgorithmId, String)> {
    AlgorithmId::ALL
        .into_iter()
        .filter_map(|a| Some((a, continuum::unavailable(a)?)))
        .collect()
}

/// Algorithms whose coverage writes count every covering triangle (no culling
/// of hidden work).
fn counts_every_fragment(a: AlgorithmId) -> bool {
    matches!(
        a,
        AlgorithmId::TwoDBrute
            | AlgorithmId::TwoDScanline
            | AlgorithmId::TwoDHomogeneous
            | AlgorithmId::ThreeDBrute
            | AlgorithmId::ThreeDFrustumCull
            | AlgorithmId::GpuRaster
            | AlgorithmId::Gpu2dr
            | AlgorithmId::Gpu2drHomogeneous
            | AlgorithmId::Gpu3dr
            | AlgorithmId::Gpu3drBinned
    )
}

/// Renders do their own vertex snapping: checked against the wider reference.
fn snaps_vertices(a: AlgorithmId, p: Precision) -> bool {
    p == Precision::Fixed || a == AlgorithmId::GpuRaster
}

/// Runs one case at every offset, camera, viewport, algorithm and precision.
pub fn run_case(case: &HardCase) -> Result<Vec<Check>, SceneError> {
    let [width, height] = case.file.size;
    let mut checks = Vec::new();
    for &offset in case.offsets() {
        let scene = PreparedScene::new(case.scene(offset)?);
        for camera in &scene.scene.cameras {
            for viewport in case.viewports(camera).unwrap_or_default() {
                let camera = Camera {
                    viewport,
                    ..camera.clone()
                };
                let view = ViewCase {
                    case: &case.name,
                    offset,
                    limits: &case.file.limits,
                };
                checks.extend(check_view(&scene, &camera, (width, height), &view));
            }
        }
    }
    Ok(checks)
}

/// What a checked view belongs to: its case, offset and documented limits.
#[derive(Clone, Copy, Debug)]
pub struct ViewCase<'a> {
    pub case: &'a str,
    pub offset: f64,
    pub limits: &'a std::collections::BTreeMap<String, String>,
}

/// Renders `camera`'s view of `scene` at `width × height` with every
/// (algorithm, precision) that serves its viewport and checks each against the
/// f64 reference and the others of its family; nothing for a camera the view
/// cannot be built from.
pub fn check_view(
    scene: &PreparedScene,
    camera: &Camera,
    (width, height): (u32, u32),
    case: &ViewCase,
) -> Vec<Check> {
    let Ok(view) = View::new(camera, width, height, scene.default_near) else {
        return Vec::new();
    };
    let reference = Reference::compute(scene, &view);
    let mut renders: Vec<(Check, Option<RenderOutput>)> = Vec::new();
    for (algorithm, precision) in variants(&camera.viewport) {
        let mut check = Check {
            case: case.case.to_string(),
            camera: camera.name.clone(),
            viewport: camera.viewport.to_string(),
            offset: case.offset,
            algorithm,
            precision,
            violations: Violations::default(),
            example: None,
            limit: case
                .limits
                .get(&variant_name(algorithm, precision))
                .or_else(|| case.limits.get(algorithm.as_str()))
                .cloned(),
        };
        let request = RenderRequest {
            precision,
            ..RenderRequest::new(algorithm, camera.clone(), width, height)
        };
        let out = match catch_unwind(AssertUnwindSafe(|| render(scene, &request))) {
            Ok(Ok(out)) => {
                check_render(scene, &reference, &out, &mut check);
                Some(out)
            }
            Ok(Err(e)) => {
                check.violations.error = 1;
                check.example = Some(format!("error: {e}"));
                None
            }
            Err(_) => {
                check.violations.error = 1;
                check.example = Some("panic".into());
                None
            }
        };
        renders.push((check, out));
    }
    check_agreement(&mut renders);
    renders.into_iter().map(|(c, _)| c).collect()
}

/// Notes one violation of `kind` at pixel `(x, y)`.
fn violate(
    check: &mut Check,
    kind: fn(&mut Violations) -> &mut u64,
    what: impl FnOnce() -> String,
) {
    *kind(&mut check.violations) += 1;
    if check.example.is_none() {
        check.example = Some(what());
    }
}

/// The per-pixel invariants of one render of `scene` against `reference`
/// (the view's), counted into `check` (whose algorithm and precision say
/// which reference radius and counting rule apply).
pub fn check_render(
    scene: &PreparedScene,
    reference: &Reference,
    out: &RenderOutput,
    check: &mut Check,
) {
    let fb = &out.framebuffer;
    let expected: &[Expected] = if snaps_vertices(check.algorithm, check.precision) {
        &reference.snapped
    } else {
        &reference.float
    };
    let complete = counts_every_fragment(check.algorithm);
    for (i, e) in expected.iter().enumerate() {
        let (x, y) = (i as u32 % fb.width, i as u32 / fb.width);
        let (id, depth, writes) = (fb.triangle_id[i], fb.depth[i], fb.coverage_writes[i]);
        let depth_ok = if id == BACKGROUND {
            depth == f32::INFINITY
        } else {
            depth.is_finite() && depth > 0.0
        };
        if !depth_ok {
            violate(
                check,
                |v| &mut v.depth,
                || format!("pixel ({x}, {y}): triangle {id} at depth {depth}"),
            );
        }
        if id != BACKGROUND && scene.drawable.binary_search(&id).is_err() {
            violate(
                check,
                |v| &mut v.degenerate,
                || format!("pixel ({x}, {y}): degenerate triangle {id} drawn"),
            );
        }
        if let Some(v) = e.visible
            && v != id
        {
            violate(
                check,
                |v| &mut v.visible,
                || {
                    format!(
                        "pixel ({x}, {y}): triangle {} visible, the reference sees {}",
                        show(id),
                        show(v)
                    )
                },
            );
        }
        if complete || e.max_count <= 1 {
            let bad = match e.count {
                Some(c) => writes != c,
                None => writes > e.max_count,
            };
            if bad {
                violate(
                    check,
                    |v| &mut v.coverage,
                    || {
                        format!(
                            "pixel ({x}, {y}): {writes} coverage writes, the reference counts {} (at most {})",
                            e.count.map_or("-".to_string(), |c| c.to_string()),
                            e.max_count
                        )
                    },
                );
            }
        }
    }
}

fn show(id: u32) -> String {
    if id == BACKGROUND {
        "none".into()
    } else {
        id.to_string()
    }
}

/// Family agreement: every render of a family at one precision against the
/// first (the CPU families; the GPU is its own).
fn check_agreement(renders: &mut [(Check, Option<RenderOutput>)]) {
    for i in 0..renders.len() {
        let (a, p) = (renders[i].0.algorithm, renders[i].0.precision);
        if a.family() == Family::Gpu {
            continue;
        }
        let Some(first) = (0..i).find(|&j| {
            let c = &renders[j].0;
            c.algorithm.family() == a.family() && c.precision == p
        }) else {
            continue;
        };
        let (Some(reference), Some(out)) = (&renders[first].1, &renders[i].1) else {
            continue;
        };
        let (ids, ours) = (
            &reference.framebuffer.triangle_id,
            &out.framebuffer.triangle_id,
        );
        let differing: Vec<usize> = (0..ids.len()).filter(|&k| ids[k] != ours[k]).collect();
        if let Some(&k) = differing.first() {
            let w = out.framebuffer.width as usize;
            let what = format!(
                "pixel ({}, {}): triangle {} where {} shows {}",
                k % w,
                k / w,
                show(ours[k]),
                reference.algorithm,
                show(ids[k])
            );
            let check = &mut renders[i].0;
            check.violations.agreement += differing.len() as u64;
            check.example.get_or_insert(what);
        }
    }
}

/// What the suite found for one case.
#[derive(Clone, Debug, Serialize)]
pub struct CaseSummary {
    pub name: String,
    pub description: String,
    pub triangles: usize,
    /// The smallest offset at which any of continuum's own f32 renders on the
    /// CPU breaks an invariant.
    pub f32_first_violation: Option<f64>,
    /// Do all f64 renders hold at every offset?
    pub f64_holds: bool,
    /// The smallest offset at which a fixed-point or GPU render breaks one.
    pub snapped_first_violation: Option<f64>,
}

/// The whole suite's result.
#[derive(Clone, Debug, Serialize)]
pub struct SuiteReport {
    pub cases: Vec<CaseSummary>,
    pub checks: Vec<Check>,
    /// Algorithms left out because this machine cannot run them, with why.
    pub not_run: Vec<(AlgorithmId, String)>,
}

/// Runs every case.
pub fn run_suite(cases: &[HardCase]) -> Result<SuiteReport, SceneError> {
    let mut summaries = Vec::new();
    let mut all = Vec::new();
    for case in cases {
        let checks = run_case(case)?;
        let first = |pick: &dyn Fn(&Check) -> bool| {
            checks
                .iter()
                .filter(|c| pick(c) && c.violations.total() > 0)
                .map(|c| c.offset)
                .min_by(f64::total_cmp)
        };
        let snapped = |c: &Check| snaps_vertices(c.algorithm, c.precision);
        summaries.push(CaseSummary {
            name: case.name.clone(),
            description: case.file.description.clone(),
            triangles: case.scene(0.0)?.mesh.triangle_count(),
            // continuum's own f32 on the CPU; the GPU's kernels (f32 without
            // an exact fallback) are held to their cases' documented limits.
            f32_first_violation: first(&|c| {
                c.precision == Precision::F32 && !snapped(c) && c.algorithm.family() != Family::Gpu
            }),
            f64_holds: first(&|c| c.precision == Precision::F64).is_none(),
            snapped_first_violation: first(&snapped),
        });
        all.extend(checks);
    }
    Ok(SuiteReport {
        cases: summaries,
        checks: all,
        not_run: not_run(),
    })
}
