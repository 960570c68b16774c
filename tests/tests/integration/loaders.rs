//! Scene loading: every format, and errors that name the file, mesh, primitive and
//! index at fault.

use std::path::PathBuf;

use continuum::PreparedScene;
use continuum::scene::{SceneError, load_path};
use continuum_tests::{builtin_scenes, glb, prepared, triangle_glb, triangle_gltf};

fn temp_file(name: &str, bytes: &[u8]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("continuum-loaders-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join(name);
    std::fs::write(&path, bytes).expect("write temp file");
    path
}

fn load_err(name: &str, bytes: &[u8]) -> String {
    let path = temp_file(name, bytes);
    match load_path(&path) {
        Ok(_) => panic!("{name} loaded"),
        Err(e) => e.to_string(),
    }
}

const QUAD: [[f32; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 1.0, 0.0],
    [0.0, 1.0, 0.0],
];

#[test]
fn a_valid_glb_loads() {
    let path = temp_file("quad.glb", &triangle_glb(&QUAD, &[0, 1, 2, 0, 2, 3], 4));
    let scene = load_path(&path).expect("loads");
    assert_eq!(scene.mesh.triangle_count(), 2);
    assert_eq!(scene.name, "quad");
}

#[test]
fn malformed_gltf_is_a_clear_error() {
    let msg = load_err(
        "broken.glb",
        b"glTF\x02\x00\x00\x00garbage that is not a glb",
    );
    assert!(
        msg.contains("broken.glb") && msg.contains("not a valid glTF"),
        "{msg}"
    );
    let msg = load_err("broken.gltf", b"{ \"asset\": ");
    assert!(
        msg.contains("broken.gltf") && msg.contains("not a valid glTF"),
        "{msg}"
    );
}

#[test]
fn nan_vertex_is_named() {
    let mut positions = QUAD;
    positions[2][1] = f32::NAN;
    let msg = load_err("nan.glb", &triangle_glb(&positions, &[0, 1, 2, 0, 2, 3], 4));
    for part in [
        "nan.glb",
        "mesh 'part' (#0)",
        "primitive 0",
        "vertex 2",
        "non-finite",
    ] {
        assert!(msg.contains(part), "'{part}' missing from: {msg}");
    }
}

#[test]
fn out_of_range_index_is_named() {
    let msg = load_err("range.glb", &triangle_glb(&QUAD, &[0, 1, 2, 0, 2, 9], 4));
    for part in [
        "range.glb",
        "mesh 'part' (#0)",
        "primitive 0",
        "index 5",
        "is 9",
        "out of range for 4 vertices",
    ] {
        assert!(msg.contains(part), "'{part}' missing from: {msg}");
    }
}

#[test]
fn non_triangle_modes_are_refused_and_strips_are_assembled() {
    let msg = load_err("lines.glb", &triangle_glb(&QUAD, &[0, 1, 2, 3], 1));
    assert!(
        msg.contains("lines.glb") && msg.contains("Lines") && msg.contains("TRIANGLES"),
        "{msg}"
    );
    let strip = temp_file("strip.glb", &triangle_glb(&QUAD, &[0, 1, 3, 2], 5));
    assert_eq!(
        load_path(&strip)
            .expect("strip loads")
            .mesh
            .triangle_count(),
        2
    );
    let fan = temp_file("fan.glb", &triangle_glb(&QUAD, &[0, 1, 2, 3], 6));
    assert_eq!(load_path(&fan).expect("fan loads").mesh.triangle_count(), 2);
}

#[test]
fn empty_mesh_is_an_error() {
    let msg = load_err("empty.glb", &triangle_glb(&QUAD, &[], 4));
    assert!(
        msg.contains("empty.glb") && msg.contains("primitive 0") && msg.contains("empty"),
        "{msg}"
    );
}

#[test]
fn obj_loads_and_its_errors_are_named() {
    let path = temp_file(
        "quad.obj",
        b"o quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n",
    );
    let scene = load_path(&path).expect("obj loads");
    assert_eq!(scene.mesh.triangle_count(), 2);
    let msg = load_err("nan.obj", b"o bad\nv 0 0 0\nv 1 nan 0\nv 1 1 0\nf 1 2 3\n");
    assert!(
        msg.contains("nan.obj") && msg.contains("object 'bad'") && msg.contains("vertex 1"),
        "{msg}"
    );
}

#[test]
fn scene_file_errors_name_the_key() {
    let msg = load_err(
        "typo.toml",
        b"[[mesh]]\ngenerator = \"grid\"\nparams = { size = [1.0, 1.0], divisons = [2, 2] }\n",
    );
    assert!(
        msg.contains("typo.toml") && msg.contains("divisons"),
        "{msg}"
    );
    let msg = load_err(
        "key.toml",
        b"[[mesh]]\ngenerator = \"sphere\"\ncolour = 3\n",
    );
    assert!(msg.contains("key.toml") && msg.contains("colour"), "{msg}");
    let msg = load_err("cam.toml", b"[[mesh]]\ngenerator = \"sphere\"\n[[camera]]\nname = \"c\"\neye = [0, 0, 0]\ntarget = [0, 0, 0]\n");
    assert!(
        msg.contains("camera 'c'") && msg.contains("target"),
        "{msg}"
    );
    let msg = load_err("gen.toml", b"[[mesh]]\ngenerator = \"cube\"\n");
    assert!(
        msg.contains("unknown generator 'cube'") && msg.contains("teapots"),
        "{msg}"
    );
}

#[test]
fn unknown_scene_lists_the_builtins() {
    let err =
        continuum::scene::load_named_or_path("nope", &continuum_tests::scenes_dir()).unwrap_err();
    assert!(matches!(err, SceneError::UnknownScene { .. }));
    assert!(err.to_string().contains("bunny"), "{err}");
}

#[test]
fn builtin_scenes_load_with_cameras_and_a_valid_bvh() {
    let names = builtin_scenes();
    for required in [
        "teapots",
        "bunny",
        "box",
        "orientation",
        "grid",
        "sphere",
        "soup",
    ] {
        assert!(
            names.iter().any(|n| n == required),
            "built-in scene {required} missing from {names:?}"
        );
    }
    for name in &names {
        let p = prepared(name);
        assert!(p.scene.cameras.len() >= 2, "{name}");
        continuum::internal::validate_bvh(&p);
    }
    assert!(prepared("teapots").triangle_count() >= 1_000_000);
    assert_eq!(prepared("bunny").triangle_count(), 69_451);
    assert_eq!(prepared("orientation").triangle_count(), 524);
}

#[test]
fn gltf_node_transforms_are_applied() {
    // The Box sample's root node rotates +z into −y... its bounds stay the unit cube.
    let b = prepared("box").bounds;
    assert!(
        (b.min.x + 0.5).abs() < 1e-6 && (b.max.y - 0.5).abs() < 1e-6,
        "{b:?}"
    );
    // OrientationTest places arrows 5 units out along each axis.
    let o = prepared("orientation").bounds;
    assert!(
        o.max.x > 5.0 && o.min.x < -5.0 && o.max.z > 5.0 && o.min.z < -5.0,
        "{o:?}"
    );
}

#[test]
fn degenerate_triangles_load_but_are_never_drawn() {
    use continuum::AlgorithmId;
    use glam::Vec3;
    let camera = continuum::Camera {
        name: "c".into(),
        eye: Vec3::new(0.0, 0.0, 3.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        viewport: continuum::Viewport::Perspective { fov_y_deg: 60.0 },
        near: None,
    };
    let positions = vec![
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.5, 0.5, 0.5),
    ];
    // Triangle 0 repeats a vertex, 1 is collinear, 2 is real.
    let triangles = vec![[0, 0, 2], [0, 1, 1], [0, 1, 2]];
    let scene: PreparedScene =
        continuum_tests::scene_from_triangles(positions, triangles, camera.clone());
    assert_eq!(scene.drawable, vec![2]);
    let every_algorithm = continuum_tests::matrix::Matrix {
        algorithms: AlgorithmId::ALL.to_vec(),
        size: (64, 64),
        ..continuum_tests::matrix::Matrix::new()
    };
    let rendered = every_algorithm.run_on("degenerate", &scene, |cell| {
        let ids = &cell.output.framebuffer.triangle_id;
        let label = cell.label();
        assert!(
            ids.iter().all(|&t| t == 2 || t == continuum::BACKGROUND),
            "{label}"
        );
        assert!(ids.contains(&2), "{label}");
    });
    assert_eq!(rendered, AlgorithmId::ALL.len());
}

#[test]
fn every_index_width_loads() {
    for component in [5121, 5123, 5125] {
        let (json, bin) = triangle_gltf(&QUAD, &[0, 1, 2, 0, 2, 3], component, 4);
        let path = temp_file(&format!("width{component}.glb"), &glb(&json, &bin));
        let scene = load_path(&path).unwrap_or_else(|e| panic!("component type {component}: {e}"));
        assert_eq!(scene.mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    }
}

#[test]
fn gltf_cameras_lights_materials_and_transforms_load() {
    let (mut json, bin) = triangle_gltf(&QUAD, &[0, 1, 2, 0, 2, 3], 5123, 4);
    json["scenes"][0]["nodes"] = serde_json::json!([0, 1, 3]);
    json["nodes"] = serde_json::json!([
        { "mesh": 0, "translation": [10.0, 0.0, 0.0], "children": [2] },
        { "camera": 0, "name": "cam", "translation": [0.5, 0.5, 4.0] },
        { "extensions": { "KHR_lights_punctual": { "light": 0 } }, "translation": [0.0, 3.0, 0.0] },
        { "camera": 1, "translation": [0.0, 0.0, 9.0] }
    ]);
    json["cameras"] = serde_json::json!([
        { "name": "shot", "type": "perspective", "perspective": { "yfov": 0.5, "znear": 0.05, "aspectRatio": 1.5 } },
        { "name": "flat", "type": "orthographic", "orthographic": { "xmag": 2.0, "ymag": 1.5, "znear": 0.0, "zfar": 100.0 } }
    ]);
    json["extensionsUsed"] = serde_json::json!(["KHR_lights_punctual"]);
    json["extensions"] = serde_json::json!({ "KHR_lights_punctual": { "lights": [{ "type": "point", "color": [1.0, 0.5, 0.25], "intensity": 7.0 }] } });
    json["materials"] = serde_json::json!([{ "name": "paint", "pbrMetallicRoughness": { "baseColorFactor": [0.1, 0.2, 0.3, 1.0] } }]);
    json["meshes"][0]["primitives"][0]["material"] = serde_json::json!(0);
    let path = temp_file("rich.glb", &glb(&json, &bin));
    let scene = load_path(&path).expect("loads");
    // The mesh node's translation moved the quad.
    assert_eq!(scene.mesh.positions[0], glam::Vec3::new(10.0, 0.0, 0.0));
    let camera = scene.camera("shot").expect("the glTF camera by name");
    assert_eq!(camera.eye, glam::Vec3::new(0.5, 0.5, 4.0));
    let continuum::Viewport::Perspective { fov_y_deg } = camera.viewport else {
        panic!("a perspective camera, got {}", camera.viewport);
    };
    assert!((fov_y_deg - 0.5f32.to_degrees()).abs() < 1e-4);
    // Orthographic: ymag is half the height; znear = 0 leaves the scene's default.
    let flat = scene.camera("flat").expect("the orthographic camera");
    assert_eq!(
        flat.viewport,
        continuum::Viewport::Orthographic { height: 3.0 }
    );
    assert_eq!(
        (flat.eye, flat.near),
        (glam::Vec3::new(0.0, 0.0, 9.0), None)
    );
    assert_eq!(camera.near, Some(0.05));
    assert_eq!(scene.lights.len(), 1);
    // The light's node is a child of the mesh node: it inherits the translation.
    assert_eq!(
        scene.lights[0].kind,
        continuum::scene::LightKind::Point {
            position: glam::Vec3::new(10.0, 3.0, 0.0)
        }
    );
    assert_eq!(scene.lights[0].color, [1.0, 0.5, 0.25]);
    assert_eq!(scene.materials[0].base_color, [0.1, 0.2, 0.3, 1.0]);
    assert!(scene.mesh.material_ids.iter().all(|&m| m == 0));
}

#[test]
fn scene_file_cameras_may_name_a_viewport() {
    let toml = |viewport: &str| {
        format!(
            "[[mesh]]\ngenerator = \"sphere\"\n\n\
             [[camera]]\nname = \"pano\"\neye = [0, 0, 0.1]\ntarget = [0, 0, -1]\nviewport = \"{viewport}\"\n\n\
             [[camera]]\nname = \"plain\"\neye = [0, 0, 5]\ntarget = [0, 0, 0]\nfov_y = 35\n"
        )
    };
    let path = temp_file("viewports.toml", toml("latlong").as_bytes());
    let scene = load_path(&path).expect("loads");
    let camera = |name: &str| scene.camera(name).expect("camera").viewport;
    assert_eq!(camera("pano"), continuum::Viewport::LatLong);
    assert_eq!(
        camera("plain"),
        continuum::Viewport::Perspective { fov_y_deg: 35.0 }
    );
    let path = temp_file("ortho.toml", toml("orthographic:4").as_bytes());
    assert_eq!(
        load_path(&path)
            .expect("loads")
            .camera("pano")
            .expect("camera")
            .viewport,
        continuum::Viewport::Orthographic { height: 4.0 }
    );
    let msg = load_err("fisheye.toml", toml("fisheye").as_bytes());
    assert!(
        msg.contains("camera 'pano'") && msg.contains("viewport") && msg.contains("latlong"),
        "{msg}"
    );
}

mod untrusted {
    //! The fuzz targets' entry (`continuum_tests::untrusted::exercise`) on
    //! random bytes and on mutations of valid files: errors, never panics.

    use continuum_tests::untrusted::{Format, exercise};
    use proptest::prelude::*;

    /// The fuzz targets' seeds: `fuzz/seeds/obj`, `fuzz/seeds/toml`, and the
    /// small glTF samples of `scenes/assets`.
    fn seeds(format: Format) -> Vec<Vec<u8>> {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let (dir, ext) = match format {
            Format::Glb => (root.join("scenes/assets"), "glb"),
            Format::Obj => (root.join("fuzz/seeds/obj"), "obj"),
            Format::SceneToml => (root.join("fuzz/seeds/toml"), "toml"),
        };
        let sub = ext;
        let mut out: Vec<Vec<u8>> = std::fs::read_dir(dir)
            .expect("seed folder exists")
            .flatten()
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|x| x == ext))
            .filter(|p| std::fs::metadata(p).is_ok_and(|m| m.len() < 100_000))
            .map(|p| std::fs::read(p).expect("seed"))
            .collect();
        out.sort();
        assert!(!out.is_empty(), "no seeds for {sub}");
        out
    }

    #[test]
    fn every_seed_loads_and_renders() {
        for format in [Format::Glb, Format::Obj, Format::SceneToml] {
            for seed in seeds(format) {
                exercise(format, &seed).unwrap_or_else(|e| panic!("{format:?} seed: {e}"));
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 256, failure_persistence: None, ..ProptestConfig::default() })]

        #[test]
        fn mutated_files_never_panic(
            format in prop::sample::select(vec![Format::Glb, Format::Obj, Format::SceneToml]),
            which in any::<prop::sample::Index>(),
            edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..4),
            cut in prop::option::weighted(0.2, any::<prop::sample::Index>()),
        ) {
            let seeds = seeds(format);
            let mut data = seeds[which.index(seeds.len())].clone();
            for (at, byte) in edits {
                let i = at.index(data.len());
                data[i] = byte;
            }
            if let Some(cut) = cut {
                data.truncate(cut.index(data.len() + 1).max(1));
            }
            let _ = exercise(format, &data);
        }

        #[test]
        fn random_bytes_never_panic(
            format in prop::sample::select(vec![Format::Glb, Format::Obj, Format::SceneToml]),
            data in prop::collection::vec(any::<u8>(), 0..512),
        ) {
            let _ = exercise(format, &data);
        }
    }
}

/// Found by fuzzing: one byte of Box.glb's JSON changed so a primitive names
/// an accessor that does not exist; the gltf crate's validation indexed out of
/// bounds. Now an error naming the file.
#[test]
fn a_glb_naming_a_missing_accessor_is_an_error_not_a_panic() {
    let mut data =
        std::fs::read(continuum_tests::scenes_dir().join("assets/Box.glb")).expect("Box.glb");
    data[341] = b'#';
    let e = continuum::scene::load_gltf_slice(&data, "mutated.glb").expect_err("malformed");
    assert!(e.to_string().contains("mutated.glb"), "{e}");
}

/// Found by fuzzing: a vertex coordinate of 9.4e21 made the BVH builder
/// (obvhs) index out of bounds. Coordinates beyond ±1e18 are refused at load,
/// naming the vertex.
#[test]
fn a_vertex_beyond_the_coordinate_range_is_refused_with_its_index() {
    let mut data =
        std::fs::read(continuum_tests::scenes_dir().join("assets/Box.glb")).expect("Box.glb");
    data[1323] = 100;
    let e = continuum::scene::load_gltf_slice(&data, "far.glb").expect_err("out of range");
    assert!(
        e.to_string().contains("beyond ±1e18") && e.to_string().contains("vertex"),
        "{e}"
    );
    let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2e18, 0.0]];
    let glb = continuum_tests::triangle_glb(&positions, &[0, 1, 2], 4);
    let e = continuum::scene::load_gltf_slice(&glb, "far.glb").expect_err("out of range");
    assert!(e.to_string().contains("vertex 2"), "{e}");
}
