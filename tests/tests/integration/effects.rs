//! Effects run only when the scene calls for them, each counted; secondary rays
//! are watertight; and every algorithm shades the same image with effects on.

use continuum::metrics::flip_mean;
use continuum::scene::Scene;
use continuum::shade::secondary::{Rays, intersect};
use continuum::shade::texture::TextureFilter;
use continuum::{AaMode, AlgorithmId, Family, PreparedScene, RenderRequest};
use continuum_tests::{builtin_scenes, prepared, render_with};
use glam::Vec3;

const SIZE: (u32, u32) = (160, 120);

/// (effect, light) → rays, from a render's stats.
fn rays(scene: &PreparedScene, algorithm: AlgorithmId) -> Vec<(String, Option<String>, u64)> {
    let camera = scene.scene.first_camera();
    let out = render_with(scene, algorithm, &camera, SIZE.0, SIZE.1);
    out.stats
        .effects
        .iter()
        .map(|e| (e.effect.to_owned(), e.light.clone(), e.rays))
        .collect()
}

#[test]
fn a_scene_pays_only_for_the_effects_it_calls_for() {
    for name in builtin_scenes() {
        let scene = prepared(&name);
        let wants = scene.scene.effects();
        let report = rays(&scene, AlgorithmId::ThreeDBrute);
        let ran = |effect: &str| report.iter().any(|(e, _, _)| e == effect);
        for effect in ["textures", "shadows", "reflections"] {
            assert_eq!(
                ran(effect),
                wants.contains(&effect),
                "{name}: {effect} ran = {}, {report:?}",
                ran(effect)
            );
        }
        // Whatever ran did work (every effect scene shows its effect from its first camera).
        let out = render_with(
            &scene,
            AlgorithmId::ThreeDBrute,
            &scene.scene.first_camera(),
            SIZE.0,
            SIZE.1,
        );
        assert!(
            out.stats.effects.iter().all(|e| e.rays + e.lookups > 0),
            "{name}: {:?}",
            out.stats.effects
        );
    }
    assert!(
        prepared("bunny").scene.effects().is_empty(),
        "bunny calls for no effect"
    );
}

#[test]
fn turning_one_lights_shadows_off_removes_exactly_its_rays() {
    let both = prepared("shadows");
    let before = rays(&both, AlgorithmId::ThreeDBrute);
    let lamp = before
        .iter()
        .find(|(_, l, _)| l.as_deref() == Some("lamp"))
        .expect("the lamp casts shadows")
        .2;
    let mut scene: Scene = (*both.scene).clone();
    let l = scene
        .lights
        .iter()
        .position(|l| l.name == "lamp")
        .expect("a lamp");
    scene.lights[l].shadows = false;
    let after = rays(&PreparedScene::new(scene), AlgorithmId::ThreeDBrute);
    let others: Vec<_> = before
        .iter()
        .filter(|(_, l, _)| l.as_deref() != Some("lamp"))
        .cloned()
        .collect();
    assert_eq!(
        after, others,
        "the sun's rays are unchanged and the lamp's are gone"
    );
    let total = |r: &[(String, Option<String>, u64)]| r.iter().map(|x| x.2).sum::<u64>();
    assert_eq!(total(&before) - total(&after), lamp);
}

#[test]
fn every_algorithm_shades_the_same_image_with_effects() {
    for name in ["shadows", "mirror", "fig8", "checker"] {
        let scene = prepared(name);
        for camera in scene.scene.all_cameras() {
            let reference = render_with(&scene, AlgorithmId::ThreeDBrute, &camera, SIZE.0, SIZE.1);
            assert!(!reference.stats.effects.is_empty(), "{name}");
            for algorithm in AlgorithmId::CPU
                .into_iter()
                .filter(|a| a.family() == Family::ThreeD)
            {
                let out = render_with(&scene, algorithm, &camera, SIZE.0, SIZE.1);
                assert_eq!(
                    out.hashes.triangle_id, reference.hashes.triangle_id,
                    "{name}/{} {algorithm}",
                    camera.name
                );
                assert_eq!(
                    out.hashes.color, reference.hashes.color,
                    "{name}/{} {algorithm}",
                    camera.name
                );
                let counts = |o: &continuum::RenderOutput| {
                    o.stats
                        .effects
                        .iter()
                        .map(|e| (e.rays, e.lookups, e.texel_probes))
                        .collect::<Vec<_>>()
                };
                assert_eq!(
                    counts(&out),
                    counts(&reference),
                    "{name}/{} {algorithm}",
                    camera.name
                );
            }
        }
    }
}

#[test]
fn fig8_casts_one_shadow_and_one_reflection_ray_per_lit_sample() {
    let scene = prepared("fig8");
    let camera = scene.scene.first_camera();
    let out = render_with(&scene, AlgorithmId::ThreeDFull, &camera, SIZE.0, SIZE.1);
    let covered = out
        .framebuffer
        .triangle_id
        .iter()
        .filter(|&&id| id != continuum::BACKGROUND)
        .count() as u64;
    let get = |effect: &str| {
        out.stats
            .effects
            .iter()
            .find(|e| e.effect == effect)
            .map_or(0, |e| e.rays)
    };
    // Every material reflects: one reflection ray per visible sample; one
    // shadow ray per visible sample that faces the sun.
    assert_eq!(get("reflections"), covered);
    assert!(
        get("shadows") <= covered && get("shadows") > covered / 2,
        "{} of {covered}",
        get("shadows")
    );
}

#[test]
fn secondary_rays_from_inside_a_closed_mesh_hit_it_exactly_once() {
    let sphere = prepared("sphere");
    let mut rng = fastrand::Rng::with_seed(8);
    let rays = Rays::new(&sphere);
    for _ in 0..2000 {
        let origin = Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, rng.f32() - 0.5) * 0.8;
        let dir = Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, rng.f32() - 0.5);
        let hits = sphere
            .drawable
            .iter()
            .filter(|&&id| {
                intersect(
                    &sphere.triangles[id as usize],
                    origin,
                    dir,
                    0.0,
                    f32::INFINITY,
                )
                .is_some()
            })
            .count();
        assert_eq!(hits, 1, "from {origin} along {dir}");
        // The BVH walk finds that one hit, and the shadow query agrees.
        let hit = rays.closest(origin, dir, 0.0, u32::MAX).expect("a hit");
        assert!(
            intersect(
                &sphere.triangles[hit.id as usize],
                origin,
                dir,
                0.0,
                f32::INFINITY
            )
            .is_some()
        );
        assert!(rays.occluded(origin, dir, 0.0, f32::INFINITY, u32::MAX));
        assert!(!rays.occluded(origin, dir, 0.0, hit.t * 0.999, u32::MAX));
    }
}

/// A render of `scene` from `camera` with `aa` and `filter`.
fn render_filtered(
    scene: &PreparedScene,
    camera: &str,
    aa: AaMode,
    filter: TextureFilter,
) -> continuum::RenderOutput {
    let request = RenderRequest {
        algorithm: AlgorithmId::ThreeDBrute,
        oracles: None,
        camera: scene.scene.camera(camera).expect("a camera of the scene"),
        width: 192,
        height: 108,
        aa,
        precision: Default::default(),
        texture_filter: filter,
    };
    continuum::render(scene, &request).expect("renders")
}

#[test]
fn trilinear_and_anisotropic_filtering_alias_less_than_nearest() {
    // Texture aliasing on the grazing checkerboard: each filter's one sample per
    // pixel against 256 nearest-filtered samples per pixel (the texture
    // integrated over the pixel), in mean FLIP.
    let scene = prepared("checker");
    let reference = render_filtered(&scene, "grazing", AaMode::Ssaa(256), TextureFilter::Nearest);
    let error = |filter| {
        let out = render_filtered(&scene, "grazing", AaMode::None, filter);
        assert_eq!(
            out.hashes.triangle_id,
            render_filtered(&scene, "grazing", AaMode::None, TextureFilter::Nearest)
                .hashes
                .triangle_id
        );
        flip_mean(
            &reference.framebuffer.color,
            &out.framebuffer.color,
            192,
            108,
        )
    };
    let nearest = error(TextureFilter::Nearest);
    let bilinear = error(TextureFilter::Bilinear);
    let trilinear = error(TextureFilter::Trilinear);
    let anisotropic = error(TextureFilter::Anisotropic(16));
    eprintln!(
        "mean FLIP: nearest {nearest:.4}, bilinear {bilinear:.4}, trilinear {trilinear:.4}, anisotropic:16 {anisotropic:.4}"
    );
    assert!(
        trilinear < nearest,
        "trilinear {trilinear} vs nearest {nearest}"
    );
    assert!(
        anisotropic < nearest,
        "anisotropic {anisotropic} vs nearest {nearest}"
    );
    assert!(
        anisotropic < trilinear,
        "anisotropic {anisotropic} vs trilinear {trilinear}: sharper along the long axis"
    );
}

#[test]
fn a_gltf_base_colour_texture_is_decoded_and_mapped() {
    // A quad with TEXCOORD_0 and an embedded 2×1 PNG: red on the left, green
    // on the right (glTF's uv origin is the image's top-left corner).
    let mut png = Vec::new();
    image::RgbaImage::from_raw(2, 1, vec![255, 0, 0, 255, 0, 255, 0, 255])
        .expect("2×1 texels")
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .expect("PNG encoding");
    let positions: [[f32; 3]; 4] = [
        [-1.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
    ];
    let uvs: [[f32; 2]; 4] = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]];
    let indices: [u16; 6] = [0, 1, 2, 0, 2, 3];
    let mut bin: Vec<u8> = positions
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let uv_at = bin.len();
    bin.extend(uvs.iter().flatten().flat_map(|v| v.to_le_bytes()));
    let index_at = bin.len();
    bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    bin.extend([0, 0]);
    let image_at = bin.len();
    bin.extend(&png);
    let json = serde_json::json!({
        "asset": { "version": "2.0" },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "mesh": 0 }],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0, "TEXCOORD_0": 1 }, "indices": 2, "material": 0 }] }],
        "materials": [{ "pbrMetallicRoughness": { "baseColorTexture": { "index": 0 } } }],
        "textures": [{ "source": 0 }],
        "images": [{ "bufferView": 3, "mimeType": "image/png" }],
        "buffers": [{ "byteLength": bin.len() }],
        "bufferViews": [
            { "buffer": 0, "byteOffset": 0, "byteLength": uv_at },
            { "buffer": 0, "byteOffset": uv_at, "byteLength": index_at - uv_at },
            { "buffer": 0, "byteOffset": index_at, "byteLength": 12 },
            { "buffer": 0, "byteOffset": image_at, "byteLength": png.len() }
        ],
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1.0, -1.0, 0.0], "max": [1.0, 1.0, 0.0] },
            { "bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2" },
            { "bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR" }
        ]
    });
    let scene =
        continuum::scene::load_gltf_slice(&continuum_tests::glb(&json, &bin), "textured-quad")
            .expect("the glb loads");
    assert_eq!(scene.effects(), vec!["textures"]);
    let prepared = PreparedScene::new(scene);
    assert!(
        prepared.textures.iter().all(Result::is_ok),
        "{:?}",
        prepared
            .textures
            .iter()
            .filter_map(|t| t.as_ref().err())
            .collect::<Vec<_>>()
    );
    let camera = continuum::Camera {
        name: "front".into(),
        eye: Vec3::new(0.0, 0.0, 3.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        viewport: continuum::Viewport::Perspective { fov_y_deg: 60.0 },
        near: None,
    };
    let request = RenderRequest {
        algorithm: AlgorithmId::Raycast,
        oracles: None,
        camera,
        width: 64,
        height: 64,
        aa: AaMode::None,
        precision: Default::default(),
        texture_filter: TextureFilter::Nearest,
    };
    let out = continuum::render(&prepared, &request).expect("renders");
    let textures = out
        .stats
        .effects
        .iter()
        .find(|e| e.effect == "textures")
        .expect("textures ran");
    let covered = out
        .framebuffer
        .triangle_id
        .iter()
        .filter(|&&id| id != continuum::BACKGROUND)
        .count() as u64;
    assert_eq!(textures.lookups, covered, "one lookup per shaded sample");
    let pixel = |x: u32, y: u32| out.framebuffer.color[(y * 64 + x) as usize];
    let (left, right) = (pixel(20, 32), pixel(44, 32));
    assert!(left[0] > 200 && left[1] < 40, "left {left:?}");
    assert!(right[1] > 200 && right[0] < 40, "right {right:?}");
}
