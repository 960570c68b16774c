//! Effects run only when the scene calls for them, each counted; secondary rays
//! are watertight; and every algorithm shades the same image with effects on.

use continuum::TextureFilter;
use continuum::internal::{Rays, intersect};
use continuum::metrics::flip_mean;
use continuum::scene::Scene;
use continuum::{AaMode, AlgorithmId, Family, PreparedScene, RenderRequest};
use continuum_tests::matrix::{Cameras, Matrix};
use continuum_tests::{builtin_scenes, prepared, render_with};
use glam::Vec3;

const SIZE: (u32, u32) = (160, 120);

/// The built-in scenes made to show an effect.
const EFFECT_SCENES: [&str; 5] = ["shadows", "mirror", "fig8", "checker", "pane"];

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
        for effect in ["textures", "shadows", "reflections", "transparency"] {
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
            out.stats
                .effects
                .iter()
                .all(|e| e.rays + e.lookups + e.fragments > 0),
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
    let counts = |o: &continuum::RenderOutput| {
        o.stats
            .effects
            .iter()
            .map(|e| (e.rays, e.lookups, e.texel_probes, e.fragments))
            .collect::<Vec<_>>()
    };
    let mut reference: Option<continuum::RenderOutput> = None;
    let three_d = AlgorithmId::CPU
        .into_iter()
        .filter(|a| a.family() == Family::ThreeD);
    let rendered = Matrix {
        scenes: EFFECT_SCENES.map(String::from).to_vec(),
        cameras: Cameras::AllAndDefault,
        algorithms: three_d.collect(),
        size: SIZE,
        ..Matrix::new()
    }
    .run(|cell| {
        let out = cell.output;
        if cell.request.algorithm == AlgorithmId::ThreeDBrute {
            assert!(!out.stats.effects.is_empty(), "{}", cell.label());
            reference = Some(out.clone());
            return;
        }
        let reference = reference.as_ref().expect("3dr-brute renders first");
        assert_eq!(
            out.hashes().triangle_id,
            reference.hashes().triangle_id,
            "{}",
            cell.label()
        );
        assert_eq!(
            out.hashes().color,
            reference.hashes().color,
            "{}",
            cell.label()
        );
        assert_eq!(counts(out), counts(reference), "{}", cell.label());
    });
    // Five scenes, three cameras or more each (theirs and the default), six 3D algorithms.
    assert!(rendered >= 5 * 3 * 6, "only {rendered} renders");
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
                intersect(&sphere.triangle(id), origin, dir, 0.0, f32::INFINITY).is_some()
            })
            .count();
        assert_eq!(hits, 1, "from {origin} along {dir}");
        // The BVH walk finds that one hit, and the shadow query agrees.
        let hit = rays.closest(origin, dir, 0.0, u32::MAX).expect("a hit");
        assert!(intersect(&sphere.triangle(hit.id), origin, dir, 0.0, f32::INFINITY).is_some());
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
        aa,
        texture_filter: filter,
        ..RenderRequest::new(
            AlgorithmId::ThreeDBrute,
            scene.scene.camera(camera).expect("a camera of the scene"),
            192,
            108,
        )
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
            out.hashes().triangle_id,
            render_filtered(&scene, "grazing", AaMode::None, TextureFilter::Nearest)
                .hashes()
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

/// A 2×1 PNG: red on the left, green on the right.
fn red_green_png() -> Vec<u8> {
    let mut png = Vec::new();
    image::RgbaImage::from_raw(2, 1, vec![255, 0, 0, 255, 0, 255, 0, 255])
        .expect("2×1 texels")
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .expect("PNG encoding");
    png
}

/// The corners of a 2×2 quad at z = 0, counter-clockwise from the lower left.
const QUAD: [[f32; 3]; 4] = [
    [-1.0, -1.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, 1.0, 0.0],
    [-1.0, 1.0, 0.0],
];

/// A camera 3 units in front of [`QUAD`], which then spans pixels ≈ 13.5..50.5 of 64.
fn quad_camera() -> continuum::Camera {
    continuum::Camera {
        name: "front".into(),
        eye: Vec3::new(0.0, 0.0, 3.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        viewport: continuum::Viewport::Perspective { fov_y_deg: 60.0 },
        near: None,
    }
}

#[test]
fn a_gltf_base_colour_texture_is_decoded_and_mapped() {
    // A quad with TEXCOORD_0 and an embedded 2×1 PNG: red on the left, green
    // on the right (glTF's uv origin is the image's top-left corner).
    let png = red_green_png();
    let positions = QUAD;
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
    let camera = quad_camera();
    let request = RenderRequest {
        texture_filter: TextureFilter::Nearest,
        ..RenderRequest::new(AlgorithmId::Raycast, camera, 64, 64)
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

/// Indices of the scene's see-through materials.
fn glass_materials(scene: &Scene) -> Vec<usize> {
    (0..scene.materials.len())
        .filter(|&m| scene.materials[m].opacity < 1.0)
        .collect()
}

#[test]
fn a_tessellated_pane_blends_exactly_once_per_layer_in_every_algorithm() {
    // A pixel blends a pane exactly when that pane, made opaque, is what the
    // pixel shows. Where the panes' triangles meet, a pixel must blend each
    // pane exactly once: no seam of zero, no double blend of two.
    let pane = prepared("pane");
    let glass = glass_materials(&pane.scene);
    assert_eq!(glass.len(), 2, "the pane scene has two panes");
    for camera in pane.scene.all_cameras() {
        for algorithm in AlgorithmId::CPU {
            let out = render_with(&pane, algorithm, &camera, SIZE.0, SIZE.1);
            let mut expected = vec![0u32; out.framebuffer.blended.len()];
            for &m in &glass {
                let mut solid: Scene = (*pane.scene).clone();
                solid.materials[m].opacity = 1.0;
                let solid = render_with(
                    &PreparedScene::new(solid),
                    algorithm,
                    &camera,
                    SIZE.0,
                    SIZE.1,
                );
                for (e, &id) in expected.iter_mut().zip(&solid.framebuffer.triangle_id) {
                    if id != continuum::BACKGROUND
                        && pane.scene.mesh.material_ids[id as usize] as usize == m
                    {
                        *e += 1;
                    }
                }
            }
            assert!(
                expected.contains(&2),
                "the panes overlap from {}",
                camera.name
            );
            let wrong: Vec<_> = (0..expected.len())
                .filter(|&i| out.framebuffer.blended[i] != expected[i])
                .map(|i| {
                    (
                        i as u32 % SIZE.0,
                        i as u32 / SIZE.0,
                        out.framebuffer.blended[i],
                        expected[i],
                    )
                })
                .collect();
            assert!(
                wrong.is_empty(),
                "{algorithm} from {}: (x, y, blended, panes) {:?}",
                camera.name,
                &wrong[..wrong.len().min(10)]
            );
            let fragments: u64 = out.framebuffer.blended.iter().map(|&b| u64::from(b)).sum();
            let reported = out
                .stats
                .effects
                .iter()
                .find(|e| e.effect == "transparency");
            assert_eq!(
                reported.map(|e| e.fragments),
                Some(fragments),
                "{algorithm}"
            );
        }
    }
}

#[test]
fn blending_does_not_depend_on_drawing_order() {
    // The same panes drawn in the other order (their meshes swapped in the
    // scene, so the rasterizers meet their triangles the other way round).
    let pane = prepared("pane");
    let mut swapped: Scene = (*pane.scene).clone();
    let glass = glass_materials(&swapped);
    for m in swapped.mesh.material_ids.iter_mut() {
        if *m as usize == glass[0] {
            *m = glass[1] as u32;
        } else if *m as usize == glass[1] {
            *m = glass[0] as u32;
        }
    }
    swapped.materials.swap(glass[0], glass[1]);
    let swapped = PreparedScene::new(swapped);
    let camera = pane.scene.first_camera();
    let a = render_with(&pane, AlgorithmId::ThreeDBrute, &camera, SIZE.0, SIZE.1);
    let b = render_with(&swapped, AlgorithmId::ThreeDBrute, &camera, SIZE.0, SIZE.1);
    // Swapping the materials' slots leaves every triangle its material: the image is unchanged.
    assert_eq!(a.framebuffer.color, b.framebuffer.color);
    // Reversing the triangle order of the whole mesh changes every id and
    // the drawing order, and still gives the same colours.
    let mut reversed: Scene = (*pane.scene).clone();
    reversed.mesh.triangles.reverse();
    reversed.mesh.material_ids.reverse();
    let reversed = PreparedScene::new(reversed);
    for algorithm in [
        AlgorithmId::TwoDBrute,
        AlgorithmId::ThreeDBrute,
        AlgorithmId::ThreeDFull,
        AlgorithmId::Raycast,
    ] {
        let a = render_with(&pane, algorithm, &camera, SIZE.0, SIZE.1);
        let r = render_with(&reversed, algorithm, &camera, SIZE.0, SIZE.1);
        assert_eq!(a.framebuffer.blended, r.framebuffer.blended, "{algorithm}");
        let differ = a
            .framebuffer
            .color
            .iter()
            .zip(&r.framebuffer.color)
            .filter(|(x, y)| x != y)
            .count();
        assert_eq!(differ, 0, "{algorithm}: {differ} pixels differ");
    }
}

#[test]
fn transparency_agrees_across_the_3d_family_with_anti_aliasing() {
    let modes = [
        AaMode::Ssaa(4),
        AaMode::Msaa(4),
        AaMode::Csaa {
            coverage: 8,
            stored: 4,
        },
    ];
    let mut reference: Option<continuum::RenderOutput> = None;
    let rendered = Matrix {
        scenes: vec!["pane".into()],
        aa: modes.to_vec(),
        algorithms: AlgorithmId::CPU
            .into_iter()
            .filter(|a| a.family() == Family::ThreeD)
            .collect(),
        size: SIZE,
        ..Matrix::new()
    }
    .run(|cell| {
        let out = cell.output;
        if cell.request.algorithm == AlgorithmId::ThreeDBrute {
            reference = Some(out.clone());
            return;
        }
        let reference = reference.as_ref().expect("3dr-brute renders first");
        assert_eq!(
            out.hashes().color,
            reference.hashes().color,
            "{}",
            cell.label()
        );
        let blended = &out.framebuffer.blended;
        assert_eq!(blended, &reference.framebuffer.blended, "{}", cell.label());
    });
    assert_eq!(rendered, modes.len() * 6, "three modes, six 3D algorithms");
}

#[test]
fn shadow_rays_pass_glass_dimmed_by_its_opacity() {
    // Three stacked unit quads along -z: glass of opacity 0.25 and 0.5, then
    // an opaque one.
    let quad = |z: f32| {
        [
            [[-1.0, -1.0, z], [1.0, -1.0, z], [1.0, 1.0, z]],
            [[-1.0, -1.0, z], [1.0, 1.0, z], [-1.0, 1.0, z]],
        ]
    };
    let positions: Vec<Vec3> = [-1.0, -2.0, -3.0]
        .into_iter()
        .flat_map(quad)
        .flatten()
        .map(Vec3::from)
        .collect();
    let triangles = (0..6).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
    let scene = continuum_tests::scene_from_triangles(
        positions,
        triangles,
        continuum_tests::exact_camera(),
    );
    let mut scene: Scene = (*scene.scene).clone();
    scene.materials = vec![
        continuum::scene::Material {
            opacity: 0.25,
            ..Default::default()
        },
        continuum::scene::Material {
            opacity: 0.5,
            ..Default::default()
        },
        continuum::scene::Material::default(),
    ];
    scene.mesh.material_ids = vec![0, 0, 1, 1, 2, 2];
    let scene = PreparedScene::new(scene);
    let rays = Rays::new(&scene);
    let (origin, dir) = (Vec3::new(0.1, 0.2, 0.0), Vec3::new(0.05, -0.02, -1.0));
    let through = |t_max: f32| rays.transmittance(origin, dir, 0.0, t_max, u32::MAX);
    assert_eq!(through(0.5), 1.0);
    assert_eq!(through(1.5), 0.75);
    assert_eq!(through(2.5), 0.75 * 0.5);
    assert_eq!(through(10.0), 0.0);
    // Mirrors show opaque surfaces only.
    let hit = rays
        .closest(origin, dir, 0.0, u32::MAX)
        .expect("the opaque quad");
    assert_eq!(scene.scene.mesh.material_ids[hit.id as usize], 2);
}

#[test]
fn gpu_raster_refuses_see_through_scenes_naming_the_field() {
    let pane = prepared("pane");
    let err = continuum::render(
        &pane,
        &RenderRequest::new(AlgorithmId::GpuRaster, pane.scene.first_camera(), 32, 24),
    )
    .expect_err("gpu-raster draws opaque surfaces only");
    assert_eq!(err.field, "algorithm", "{err}");
}

#[test]
fn gltf_uv_sets_sampler_wrap_modes_and_vertex_colours_are_honoured() {
    // A quad whose texture reads TEXCOORD_1 (u from 0 to 2) through a sampler
    // that clamps u; TEXCOORD_0 is all zeros, a trap. COLOR_0 halves red.
    let png = red_green_png();
    let positions = QUAD;
    let uv1: [[f32; 2]; 4] = [[0.0, 1.0], [2.0, 1.0], [2.0, 0.0], [0.0, 0.0]];
    let colors: [[f32; 4]; 4] = [[0.5, 1.0, 1.0, 1.0]; 4];
    let indices: [u16; 6] = [0, 1, 2, 0, 2, 3];
    let floats = |v: &[f32]| v.iter().flat_map(|f| f.to_le_bytes()).collect::<Vec<u8>>();
    let mut bin = floats(positions.as_flattened());
    let mut views = vec![(0, bin.len())];
    for part in [
        floats(&[0.0; 8]),
        floats(uv1.as_flattened()),
        floats(colors.as_flattened()),
    ] {
        views.push((bin.len(), part.len()));
        bin.extend(part);
    }
    views.push((bin.len(), 12));
    bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    bin.extend([0, 0]);
    views.push((bin.len(), png.len()));
    bin.extend(&png);
    let json = serde_json::json!({
        "asset": { "version": "2.0" },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "mesh": 0 }],
        "meshes": [{ "primitives": [{
            "attributes": { "POSITION": 0, "TEXCOORD_0": 1, "TEXCOORD_1": 2, "COLOR_0": 3 },
            "indices": 4, "material": 0 }] }],
        "materials": [{ "pbrMetallicRoughness": { "baseColorTexture": { "index": 0, "texCoord": 1 } } }],
        "samplers": [{ "wrapS": 33071 }],
        "textures": [{ "source": 0, "sampler": 0 }],
        "images": [{ "bufferView": 5, "mimeType": "image/png" }],
        "buffers": [{ "byteLength": bin.len() }],
        "bufferViews": views.iter().map(|&(o, l)| serde_json::json!({ "buffer": 0, "byteOffset": o, "byteLength": l })).collect::<Vec<_>>(),
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1.0, -1.0, 0.0], "max": [1.0, 1.0, 0.0] },
            { "bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2" },
            { "bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2" },
            { "bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC4" },
            { "bufferView": 4, "componentType": 5123, "count": 6, "type": "SCALAR" }
        ]
    });
    let scene = continuum::scene::load_gltf_slice(&continuum_tests::glb(&json, &bin), "uv-sets")
        .expect("the glb loads");
    assert_eq!(
        scene.mesh.uvs[1],
        glam::Vec2::new(2.0, 1.0),
        "TEXCOORD_1 was read"
    );
    assert_eq!(scene.mesh.colors.len(), 4);
    let texture = scene.materials[0]
        .base_color_texture
        .clone()
        .expect("a texture");
    use continuum::scene::Wrap;
    assert_eq!(
        (texture.tex_coord, texture.wrap),
        (1, [Wrap::ClampToEdge, Wrap::Repeat])
    );
    let camera = quad_camera();
    let render = |scene: &Scene| {
        let request = RenderRequest {
            texture_filter: TextureFilter::Nearest,
            ..RenderRequest::new(AlgorithmId::ThreeDFull, camera.clone(), 64, 64)
        };
        continuum::render(&PreparedScene::new(scene.clone()), &request).expect("renders")
    };
    let out = render(&scene);
    let pixel = |o: &continuum::RenderOutput, x: u32| o.framebuffer.color[(32 * 64 + x) as usize];
    // u = 0.25: red; u = 0.75: green; u = 1.5: clamped to the last texel, green
    // (repeat would be red again).
    let (red, green, clamped) = (pixel(&out, 18), pixel(&out, 27), pixel(&out, 41));
    assert!(red[0] > 100 && red[1] < 40, "u 0.25: {red:?}");
    assert!(green[1] > 200 && green[0] < 40, "u 0.75: {green:?}");
    assert!(clamped[1] > 200 && clamped[0] < 40, "u 1.5: {clamped:?}");
    // COLOR_0 halves red in linear light.
    let mut white = scene.clone();
    white.mesh.colors.clear();
    let full = pixel(&render(&white), 18);
    let ratio = continuum::decode_srgb(red[0]) / continuum::decode_srgb(full[0]);
    assert!((ratio - 0.5).abs() < 0.01, "{ratio}: {red:?} vs {full:?}");
}

#[test]
fn the_2d_family_shades_like_the_3d_family_with_effects() {
    // The families may pick different triangles only where the foundation's
    // bound allows (a pixel centre on an edge, the near plane, a depth tie);
    // wherever they pick the same triangle and blend the same fragments, the
    // colour is bitwise the same: shading reads the triangle and the ray, not
    // the family's depth.
    let mut three: Option<continuum::RenderOutput> = None;
    let rendered = Matrix {
        scenes: EFFECT_SCENES.map(String::from).to_vec(),
        cameras: Cameras::AllAndDefault,
        algorithms: vec![
            AlgorithmId::ThreeDBrute,
            AlgorithmId::TwoDBrute,
            AlgorithmId::TwoDBin,
        ],
        size: SIZE,
        ..Matrix::new()
    }
    .run(|cell| {
        if cell.request.algorithm == AlgorithmId::ThreeDBrute {
            three = Some(cell.output.clone());
            return;
        }
        let three = three.as_ref().expect("3dr-brute renders first");
        let two = cell.output;
        let report = continuum_tests::explain_2d_3d(cell.prepared, two, three);
        let at = cell.label();
        assert!(
            report.unexplained.is_empty(),
            "{at}: {:?}",
            report.unexplained
        );
        let (a, b) = (&two.framebuffer, &three.framebuffer);
        assert_eq!(a.blended, b.blended, "{at}: fragments blended");
        let differ: Vec<usize> = (0..a.color.len())
            .filter(|&i| a.triangle_id[i] == b.triangle_id[i] && a.color[i] != b.color[i])
            .collect();
        assert!(
            differ.is_empty(),
            "{at}: same triangle, other colour at {differ:?}"
        );
    });
    // Five scenes, three cameras or more each, three algorithms.
    assert!(rendered >= 5 * 3 * 3, "only {rendered} renders");
}
