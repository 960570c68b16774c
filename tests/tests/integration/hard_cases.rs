//! The hard-case suite (`tests/hard_cases/`): every case through every
//! algorithm, precision and viewport, at the origin and at offsets up to 10⁷,
//! holds every invariant — and the checks do catch a broken render.

use continuum::{AlgorithmId, BACKGROUND, PreparedScene, RenderRequest, View, render};
use continuum_hardcases::{self as hardcases, Check, HardCase, Violations, reference::Reference};
use std::path::Path;

fn cases_dir() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("hard_cases")
}

#[test]
fn every_hard_case_holds_every_invariant_in_every_algorithm() {
    let cases = hardcases::load_cases(&cases_dir()).expect("hard cases load");
    assert!(cases.len() >= 10, "{} cases", cases.len());
    let report = hardcases::run_suite(&cases).expect("suite runs");
    let failing: Vec<&Check> = report
        .checks
        .iter()
        .filter(|c| c.violations.total() > 0 && !hardcases::beyond_limit(c))
        .collect();
    assert!(
        failing.is_empty(),
        "{} renders break invariants; first: {:#?}",
        failing.len(),
        &failing[..failing.len().min(5)]
    );
    // Every case ran every algorithm, at every offset.
    for case in &cases {
        for algorithm in AlgorithmId::ALL {
            assert!(
                report
                    .checks
                    .iter()
                    .any(|c| c.case == case.name && c.algorithm == algorithm),
                "{}: {algorithm} never ran",
                case.name
            );
        }
        let offsets = report
            .checks
            .iter()
            .filter(|c| c.case == case.name)
            .map(|c| c.offset)
            .fold(0.0f64, f64::max);
        assert_eq!(offsets, 1e7, "{}", case.name);
    }
    // Our own CPU renders hold at every precision and offset of the suite;
    // only the GPU (its driver, and the compute kernels' f32 without an
    // exact fallback) has documented limits.
    for summary in &report.cases {
        assert!(summary.f64_holds, "{}", summary.name);
        assert_eq!(summary.f32_first_violation, None, "{}", summary.name);
    }
    assert!(
        report
            .checks
            .iter()
            .filter(|c| c.limit.is_some())
            .all(|c| c.algorithm.family() == continuum::Family::Gpu)
    );
}

/// The checks are not vacuous: a render with one pixel covered twice, one
/// hole, one wrong triangle and one non-finite depth is caught four times.
#[test]
fn the_checks_catch_double_coverage_holes_wrong_triangles_and_bad_depth() {
    let case = HardCase::load(&cases_dir().join("shared-edges-axis.toml")).expect("case loads");
    let scene = PreparedScene::new(case.scene(0.0).expect("scene"));
    let camera = scene.scene.cameras[0].clone();
    let view = View::new(&camera, 64, 64, scene.default_near).expect("view");
    let reference = Reference::compute(&scene, &view);
    let mut out = render(
        &scene,
        &RenderRequest::new(AlgorithmId::ThreeDBrute, camera, 64, 64),
    )
    .expect("renders");
    let check = |out: &continuum::RenderOutput| {
        let mut c = Check {
            case: case.name.clone(),
            camera: "exact".into(),
            viewport: "perspective:90".into(),
            offset: 0.0,
            algorithm: AlgorithmId::ThreeDBrute,
            precision: Default::default(),
            violations: Violations::default(),
            example: None,
            limit: None,
        };
        hardcases::check_render(&scene, &reference, out, &mut c);
        c.violations
    };
    assert_eq!(check(&out).total(), 0);
    // Pixels robustly inside one triangle (the reference knows which).
    let robust: Vec<usize> = (0..64 * 64)
        .filter(|&i| {
            let e = reference.float[i];
            e.count == Some(1) && e.visible.is_some_and(|v| v != BACKGROUND)
        })
        .collect();
    assert!(robust.len() > 100);
    let fb = &mut out.framebuffer;
    fb.coverage_writes[robust[0]] = 2;
    fb.coverage_writes[robust[1]] = 0;
    fb.triangle_id[robust[1]] = BACKGROUND;
    fb.depth[robust[1]] = f32::INFINITY;
    fb.triangle_id[robust[2]] ^= 1;
    fb.depth[robust[3]] = f32::NAN;
    let v = check(&out);
    assert_eq!((v.coverage, v.visible, v.depth), (2, 2, 1), "{v:?}");
}

#[test]
fn a_bad_case_file_is_an_error_naming_the_key() {
    let dir = std::env::temp_dir().join(format!("continuum-hardcases-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let bad = [
        ("typo.toml", "descripton = \"x\"\n[scene]\n", "descripton"),
        (
            "size.toml",
            "description = \"x\"\nsize = [0, 4]\n[[scene.mesh]]\ngenerator = \"fan\"\nparams = { count = 3 }\n",
            "size",
        ),
        (
            "param.toml",
            "description = \"x\"\n[[scene.mesh]]\ngenerator = \"fan\"\nparams = { count = 2 }\n",
            "count",
        ),
    ];
    for (name, text, key) in bad {
        let path = dir.join(name);
        std::fs::write(&path, text).expect("write case");
        let e = HardCase::load(&path).expect_err(name).to_string();
        assert!(e.contains(key), "{name}: {e}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

mod random {
    //! Property tests: random welded meshes (jittered grids, radially
    //! jittered icospheres) seen by random cameras through every viewport hold
    //! every invariant of the suite in every algorithm.

    use continuum::scene::procedural::{GridParams, SphereParams};
    use continuum::{Camera, Viewport};
    use continuum_hardcases::{self as hardcases, ViewCase};
    use glam::{Quat, Vec3};
    use proptest::prelude::*;

    /// A welded mesh from `seed`: a grid with its inner vertices moved within
    /// their cells, or an icosphere with every vertex moved along its radius
    /// (both stay partitions: no triangle folds over).
    fn mesh(seed: u64, sphere: bool) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let mut rng = fastrand::Rng::with_seed(seed);
        let mut mesh = if sphere {
            SphereParams {
                radius: 1.0,
                center: [0.0; 3],
                subdivisions: rng.u32(0..=2),
            }
            .generate()
            .expect("sphere")
        } else {
            let n = [rng.u32(1..=6), rng.u32(1..=6)];
            GridParams {
                size: [2.0, 2.0],
                divisions: n,
                plane: None,
            }
            .generate()
            .expect("grid")
        };
        let cell = 2.0 / 6.0;
        for p in &mut mesh.positions {
            if sphere {
                *p *= 0.9 + 0.2 * rng.f32();
            } else if p.x.abs() < 0.999 && p.z.abs() < 0.999 {
                p.x += (rng.f32() - 0.5) * 0.5 * cell;
                p.z += (rng.f32() - 0.5) * 0.5 * cell;
            }
        }
        let turn = Quat::from_euler(
            glam::EulerRot::XYZ,
            rng.f32() * 6.3,
            rng.f32() * 6.3,
            rng.f32() * 6.3,
        );
        let at = Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, rng.f32() - 0.5);
        let positions = mesh.positions.iter().map(|&p| turn * p + at).collect();
        (positions, mesh.triangles)
    }

    fn camera(seed: u64, viewport: usize) -> Camera {
        let mut rng = fastrand::Rng::with_seed(seed ^ 0x5eed);
        let mut point = |s: f32| Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, rng.f32() - 0.5) * s;
        let (eye, target) = (point(6.0), point(1.0));
        let viewport = match viewport {
            0 => Viewport::Perspective {
                fov_y_deg: 30.0 + 90.0 * rng.f32(),
            },
            1 => Viewport::Orthographic {
                height: 1.0 + 3.0 * rng.f32(),
            },
            2 => Viewport::Parabolic,
            _ => Viewport::LatLong,
        };
        Camera {
            name: "random".into(),
            eye,
            target: if (target - eye).length() < 0.1 {
                eye + Vec3::X
            } else {
                target
            },
            up: if rng.bool() { Vec3::Y } else { Vec3::Z },
            viewport,
            near: Some(0.01),
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, failure_persistence: None, ..ProptestConfig::default() })]

        #[test]
        fn random_welded_meshes_hold_every_invariant(
            seed in any::<u64>(),
            sphere in any::<bool>(),
            viewport in 0usize..4,
        ) {
            let (positions, triangles) = mesh(seed, sphere);
            let cam = camera(seed, viewport);
            prop_assume!(cam.validate().is_ok());
            let scene = continuum_tests::scene_from_triangles(positions, triangles, cam.clone());
            let limits = Default::default();
            let case = ViewCase { case: "random", offset: 0.0, limits: &limits };
            let checks = hardcases::check_view(&scene, &cam, (32, 32), &case);
            prop_assert!(!checks.is_empty());
            for c in &checks {
                prop_assert_eq!(c.violations.total(), 0, "{} {} {}: {:?} {:?}", c.algorithm, c.precision, c.viewport, c.violations, c.example);
            }
        }
    }
}
