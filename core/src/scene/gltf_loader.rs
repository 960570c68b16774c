//! glTF 2.0 (`.gltf`, `.glb`) through the `gltf` crate: every mesh and primitive of
//! the default scene with node transforms applied, any index width, base colour
//! factor and texture references (with their sampler's wrap modes and uv set),
//! vertex colours, cameras and KHR_lights_punctual lights.

use std::path::Path;
use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3, Vec4};
use gltf::mesh::Mode;

use super::validate::{PartLocation, validate_part};
use super::{
    ImageRef, ImageSource, Light, LightKind, Material, Mesh, Scene, SceneError, TextureRef, Wrap,
};
use crate::camera::{Camera, Viewport};

/// Loads a `.gltf` or `.glb` file; external buffers resolve next to it.
pub fn load_gltf(path: &Path) -> Result<Scene, SceneError> {
    let bytes = std::fs::read(path).map_err(|e| SceneError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    let base = path.parent().unwrap_or(Path::new("."));
    let name = path
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("scene")
        .to_string();
    load(&bytes, &path.display().to_string(), name, Some(base))
}

/// Loads a glTF document held in memory (e.g. an uploaded `.glb`). External
/// buffer and image files are refused: nothing outside `bytes` is read.
pub fn load_gltf_slice(bytes: &[u8], name: &str) -> Result<Scene, SceneError> {
    load(bytes, name, name.to_string(), None)
}

fn load(bytes: &[u8], file: &str, name: String, base: Option<&Path>) -> Result<Scene, SceneError> {
    let gltf_err = |e: gltf::Error| SceneError::Gltf {
        path: file.to_string(),
        message: e.to_string(),
    };
    let gltf = guarded(file, || gltf::Gltf::from_slice(bytes))?.map_err(gltf_err)?;
    read_document(&gltf, file, name, base)
}

/// Runs one call into the gltf crate, which validates and reads accessors
/// with unchecked indexing on some malformed inputs (found by fuzzing:
/// `fuzz/`): its panic becomes an error naming `location`. Only the
/// third-party call is guarded, so a panic of continuum's own code still
/// surfaces (and fails the loaders' property test).
fn guarded<T>(location: &str, call: impl FnOnce() -> T) -> Result<T, SceneError> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(call)).map_err(|_| SceneError::Gltf {
        path: location.to_string(),
        message: "malformed accessor or buffer data".into(),
    })
}

fn read_document(
    gltf: &gltf::Gltf,
    file: &str,
    name: String,
    base: Option<&Path>,
) -> Result<Scene, SceneError> {
    let gltf_err = |e: gltf::Error| SceneError::Gltf {
        path: file.to_string(),
        message: e.to_string(),
    };
    if base.is_none()
        && let Some(b) = gltf.document.buffers().find(
            |b| matches!(b.source(), gltf::buffer::Source::Uri(uri) if !uri.starts_with("data:")),
        )
    {
        return Err(SceneError::Gltf {
            path: file.to_string(),
            message: format!(
                "buffer {} refers to an external file; only self-contained .glb files are accepted here",
                b.index()
            ),
        });
    }
    let buffers = guarded(file, || {
        gltf::import_buffers(&gltf.document, base, gltf.blob.clone())
    })?
    .map_err(gltf_err)?;
    let doc = &gltf.document;

    let mut scene = Scene {
        name,
        source: file.to_string(),
        ..Scene::default()
    };

    // 1. Materials, in document order; a default one is appended on demand.
    scene.materials = doc.materials().map(|m| convert_material(&m)).collect();
    let mut default_material: Option<u32> = None;

    // 2. Images (references only; decoding belongs to the texture effect).
    scene.images = doc
        .images()
        .map(|img| ImageRef {
            name: img.name().map(str::to_string),
            source: match img.source() {
                gltf::image::Source::View { view, mime_type } => {
                    let data = &buffers[view.buffer().index()];
                    let start = view.offset();
                    let end = (start + view.length()).min(data.len());
                    ImageSource::Embedded {
                        mime_type: mime_type.to_string(),
                        bytes: Arc::from(&data[start.min(end)..end]),
                    }
                }
                gltf::image::Source::Uri { uri, .. } => match base {
                    Some(base) if !uri.starts_with("data:") => ImageSource::File(base.join(uri)),
                    _ => ImageSource::DataUri(uri.to_string()),
                },
            },
        })
        .collect();

    // 3. Walk the node hierarchy of the default scene (or every scene's roots).
    let roots: Vec<gltf::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(s) => s.nodes().collect(),
        None => Vec::new(),
    };
    let mut stack: Vec<(gltf::Node, Mat4)> =
        roots.into_iter().map(|n| (n, Mat4::IDENTITY)).collect();
    while let Some((node, parent)) = stack.pop() {
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if !world.is_finite() {
            return Err(SceneError::Invalid {
                location: file.to_string(),
                problem: format!("node {} has a non-finite transform", node.index()),
            });
        }
        if let Some(mesh) = node.mesh() {
            for prim in mesh.primitives() {
                let location = PartLocation::part(
                    file,
                    format!("mesh '{}' (#{})", mesh.name().unwrap_or(""), mesh.index()),
                    Some(format!("primitive {}", prim.index())),
                );
                let mut part = read_primitive(&prim, &buffers, &location)?;
                part.transform(world);
                validate_part(&part.positions, &part.triangles, &location)?;
                let material = match prim.material().index() {
                    Some(i) => i as u32,
                    None => *default_material.get_or_insert_with(|| {
                        scene.materials.push(Material::default());
                        (scene.materials.len() - 1) as u32
                    }),
                };
                part.material_ids = vec![material; part.triangles.len()];
                scene.mesh.append(&part, 0);
            }
        }
        if let Some(cam) = node.camera() {
            let name = cam
                .name()
                .map(str::to_string)
                .unwrap_or_else(|| format!("camera{}", cam.index()));
            let (viewport, near) = match cam.projection() {
                gltf::camera::Projection::Perspective(p) => (
                    Viewport::Perspective {
                        fov_y_deg: p.yfov().to_degrees(),
                    },
                    p.znear(),
                ),
                // ymag is half the view's height.
                gltf::camera::Projection::Orthographic(o) => (
                    Viewport::Orthographic {
                        height: 2.0 * o.ymag(),
                    },
                    o.znear(),
                ),
            };
            let eye = world.transform_point3(Vec3::ZERO);
            let forward = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
            let up = world.transform_vector3(Vec3::Y).normalize_or_zero();
            let camera = Camera {
                name,
                eye,
                target: eye + forward,
                up,
                viewport,
                // glTF allows znear = 0 for orthographic cameras; ours must be positive.
                near: (near > 0.0).then_some(near),
            };
            match camera.validate() {
                Ok(()) => scene.cameras.push(camera),
                Err(e) => scene
                    .warnings
                    .push(format!("camera '{}' skipped: {e}", camera.name)),
            }
        }
        if let Some(light) = node.light() {
            let position = world.transform_point3(Vec3::ZERO);
            let direction = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
            let kind = match light.kind() {
                gltf::khr_lights_punctual::Kind::Directional => {
                    LightKind::Directional { direction }
                }
                gltf::khr_lights_punctual::Kind::Point => LightKind::Point { position },
                gltf::khr_lights_punctual::Kind::Spot {
                    inner_cone_angle,
                    outer_cone_angle,
                } => LightKind::Spot {
                    position,
                    direction,
                    inner_cone: inner_cone_angle,
                    outer_cone: outer_cone_angle,
                },
            };
            scene.lights.push(Light {
                name: light
                    .name()
                    .map(str::to_string)
                    .unwrap_or_else(|| format!("light{}", light.index())),
                kind,
                color: light.color(),
                intensity: light.intensity(),
                shadows: true,
            });
        }
        for child in node.children() {
            stack.push((child, world));
        }
    }

    if scene.materials.is_empty() {
        scene.materials.push(Material::default());
    }
    scene.validate()?;
    Ok(scene)
}

fn convert_material(m: &gltf::Material) -> Material {
    let pbr = m.pbr_metallic_roughness();
    let base_color = pbr.base_color_factor();
    let blend = m.alpha_mode() == gltf::material::AlphaMode::Blend;
    Material {
        name: m
            .name()
            .map(str::to_string)
            .unwrap_or_else(|| format!("material{}", m.index().unwrap_or(0))),
        base_color,
        base_color_texture: pbr.base_color_texture().map(|info| {
            let sampler = info.texture().sampler();
            TextureRef {
                image: info.texture().source().index(),
                tex_coord: info.tex_coord(),
                wrap: [sampler.wrap_s(), sampler.wrap_t()].map(|w| match w {
                    gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
                    gltf::texture::WrappingMode::ClampToEdge => Wrap::ClampToEdge,
                    gltf::texture::WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
                }),
            }
        }),
        emissive: m.emissive_factor(),
        opacity: if blend { base_color[3] } else { 1.0 },
        reflectivity: 0.0,
        double_sided: m.double_sided(),
    }
}

/// Reads one primitive into a mesh part (object space), assembling triangles from
/// its mode. Points and lines are refused.
fn read_primitive(
    prim: &gltf::Primitive,
    buffers: &[gltf::buffer::Data],
    location: &PartLocation,
) -> Result<Mesh, SceneError> {
    // The gltf reader underflows on zero-length accessors: refuse them first.
    let empty = |a: Option<gltf::Accessor>| a.is_some_and(|a| a.count() == 0);
    if empty(prim.get(&gltf::Semantic::Positions)) || empty(prim.indices()) {
        return Err(SceneError::Empty {
            location: location.to_string(),
        });
    }
    // The texture coordinate set the material's base-colour texture names.
    let uv_set = prim
        .material()
        .pbr_metallic_roughness()
        .base_color_texture()
        .map_or(0, |info| info.tex_coord());
    let (positions, normals, uvs, colors, indices) = guarded(&location.to_string(), || {
        let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
        let positions: Option<Vec<Vec3>> =
            reader.read_positions().map(|p| p.map(Vec3::from).collect());
        let normals: Vec<Vec3> = reader
            .read_normals()
            .map(|n| n.map(Vec3::from).collect())
            .unwrap_or_default();
        let uvs: Vec<Vec2> = reader
            .read_tex_coords(uv_set)
            .map(|t| t.into_f32().map(Vec2::from).collect())
            .unwrap_or_default();
        let colors: Vec<Vec4> = reader
            .read_colors(0)
            .map(|c| c.into_rgba_f32().map(Vec4::from).collect())
            .unwrap_or_default();
        let indices: Option<Vec<u32>> = reader.read_indices().map(|i| i.into_u32().collect());
        (positions, normals, uvs, colors, indices)
    })?;
    let positions = positions.ok_or_else(|| SceneError::Invalid {
        location: location.to_string(),
        problem: "has no POSITION attribute".into(),
    })?;
    if let Some(v) = colors.iter().position(|c| !c.is_finite()) {
        return Err(SceneError::Invalid {
            location: location.to_string(),
            problem: format!("COLOR_0 of vertex {v} is not finite"),
        });
    }
    let indices = indices.unwrap_or_else(|| (0..positions.len() as u32).collect());
    let triangles = assemble_triangles(prim.mode(), &indices, location)?;
    validate_part(&positions, &triangles, location)?;
    let normals = if normals.len() == positions.len() {
        normals
    } else {
        Vec::new()
    };
    let uvs = if uvs.len() == positions.len() {
        uvs
    } else {
        Vec::new()
    };
    let colors = if colors.len() == positions.len() {
        colors
    } else {
        Vec::new()
    };
    let mut part = Mesh {
        positions,
        normals,
        uvs,
        colors,
        material_ids: Vec::new(),
        triangles,
    };
    keep_used_vertices(&mut part);
    Ok(part)
}

/// Drops the vertices no triangle of `part` uses, keeping the others in
/// order. glTF primitives often index ranges of one accessor that many
/// primitives share (Sponza: 1.36 million vertices read for 66 thousand
/// triangles); each part keeps only its own, so every vertex is transformed
/// once per view and stored once. Positions, and so every image, are unchanged.
fn keep_used_vertices(part: &mut Mesh) {
    let mut used = vec![false; part.positions.len()];
    for &v in part.triangles.iter().flatten() {
        used[v as usize] = true;
    }
    if used.iter().all(|&u| u) {
        return;
    }
    let mut index = vec![0u32; used.len()];
    let mut next = 0;
    for (new, &u) in index.iter_mut().zip(&used) {
        *new = next;
        next += u32::from(u);
    }
    for t in &mut part.triangles {
        *t = t.map(|v| index[v as usize]);
    }
    fn retain_used<T>(values: &mut Vec<T>, used: &[bool]) {
        if values.len() == used.len() {
            let mut k = 0;
            values.retain(|_| {
                k += 1;
                used[k - 1]
            });
            values.shrink_to_fit();
        }
    }
    retain_used(&mut part.positions, &used);
    retain_used(&mut part.normals, &used);
    retain_used(&mut part.uvs, &used);
    retain_used(&mut part.colors, &used);
}

fn assemble_triangles(
    mode: Mode,
    idx: &[u32],
    location: &PartLocation,
) -> Result<Vec<[u32; 3]>, SceneError> {
    match mode {
        Mode::Triangles => {
            if !idx.len().is_multiple_of(3) {
                return Err(SceneError::Invalid {
                    location: location.to_string(),
                    problem: format!(
                        "{} indices is not a multiple of 3 for mode TRIANGLES",
                        idx.len()
                    ),
                });
            }
            Ok(idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
        }
        // Strips alternate winding so every triangle keeps the strip's orientation.
        Mode::TriangleStrip => Ok((0..idx.len().saturating_sub(2))
            .map(|i| {
                if i % 2 == 0 {
                    [idx[i], idx[i + 1], idx[i + 2]]
                } else {
                    [idx[i + 1], idx[i], idx[i + 2]]
                }
            })
            .collect()),
        Mode::TriangleFan => Ok((1..idx.len().saturating_sub(1))
            .map(|i| [idx[0], idx[i], idx[i + 1]])
            .collect()),
        other => Err(SceneError::Unsupported {
            location: location.to_string(),
            what: format!(
                "primitive mode {other:?}: only TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN can be rendered"
            ),
        }),
    }
}

#[cfg(test)]
mod tests {
    use glam::{Vec2, Vec3};

    use super::{Mesh, keep_used_vertices};

    /// A part indexing two of a shared accessor's five vertices keeps those
    /// two (and their attributes) in order, and its triangles name the same
    /// positions as before.
    #[test]
    fn a_part_keeps_only_the_vertices_it_uses() {
        let positions: Vec<Vec3> = (0..5).map(|i| Vec3::splat(i as f32)).collect();
        let mut part = Mesh {
            positions: positions.clone(),
            normals: vec![Vec3::Z; 5],
            uvs: (0..5).map(|i| Vec2::splat(i as f32)).collect(),
            colors: Vec::new(),
            material_ids: Vec::new(),
            triangles: vec![[3, 1, 3], [1, 3, 1]],
        };
        let before: Vec<[Vec3; 3]> = (0..2).map(|t| part.triangle_positions(t)).collect();
        keep_used_vertices(&mut part);
        assert_eq!(part.positions, [positions[1], positions[3]]);
        assert_eq!(part.normals.len(), 2);
        assert_eq!(part.uvs, [Vec2::splat(1.0), Vec2::splat(3.0)]);
        assert_eq!(part.triangles, [[1, 0, 1], [0, 1, 0]]);
        let after: Vec<[Vec3; 3]> = (0..2).map(|t| part.triangle_positions(t)).collect();
        assert_eq!(before, after);
    }
}
