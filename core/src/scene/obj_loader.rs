//! Wavefront OBJ through `tobj` (triangulated, single index); MTL diffuse colours
//! become base colours when the library file is present.

use std::path::Path;

/// How `tobj` reads every OBJ: triangles only, one index per vertex.
const OPTIONS: tobj::LoadOptions = tobj::LoadOptions {
    triangulate: true,
    single_index: true,
    ignore_points: true,
    ignore_lines: true,
};

type Loaded = (
    Vec<tobj::Model>,
    Result<Vec<tobj::Material>, tobj::LoadError>,
);

use glam::{Vec2, Vec3};

use super::validate::{PartLocation, validate_part};
use super::{Material, Mesh, Scene, SceneError};

pub fn load_obj(path: &Path) -> Result<Scene, SceneError> {
    let file = path.display().to_string();
    let loaded = tobj::load_obj(path, &OPTIONS).map_err(|e| obj_error(&file, e))?;
    let name = path
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("scene")
        .to_string();
    build(loaded, &file, name)
}

/// An OBJ from bytes in memory (no material library: there is no folder to
/// find one in); `name` names it in messages.
pub fn load_obj_slice(bytes: &[u8], name: &str) -> Result<Scene, SceneError> {
    let mut reader = std::io::BufReader::new(bytes);
    let loaded = tobj::load_obj_buf(&mut reader, &OPTIONS, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| obj_error(name, e))?;
    build(loaded, name, name.to_string())
}

fn obj_error(file: &str, e: tobj::LoadError) -> SceneError {
    match e {
        tobj::LoadError::OpenFileFailed => SceneError::Io {
            path: file.to_string(),
            message: "cannot open".into(),
        },
        other => SceneError::Obj {
            path: file.to_string(),
            message: other.to_string(),
        },
    }
}

fn build((models, materials): Loaded, file: &str, name: String) -> Result<Scene, SceneError> {
    let file = file.to_string();
    let mut scene = Scene {
        name,
        source: file.clone(),
        ..Scene::default()
    };
    match materials {
        Ok(mats) => {
            scene.materials = mats
                .iter()
                .map(|m| {
                    let d = m.diffuse.unwrap_or([0.8; 3]);
                    Material {
                        name: m.name.clone(),
                        base_color: [d[0], d[1], d[2], m.dissolve.unwrap_or(1.0)],
                        ..Material::default()
                    }
                })
                .collect();
        }
        Err(e) => scene.warnings.push(format!("materials not loaded: {e}")),
    }
    let default_material = scene.materials.len() as u32;
    scene.materials.push(Material::default());

    for (index, model) in models.iter().enumerate() {
        let m = &model.mesh;
        let location =
            PartLocation::part(&file, format!("object '{}' (#{index})", model.name), None);
        let positions: Vec<Vec3> = m
            .positions
            .chunks_exact(3)
            .map(|c| Vec3::new(c[0], c[1], c[2]))
            .collect();
        let triangles: Vec<[u32; 3]> = m
            .indices
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        if triangles.is_empty() {
            continue; // objects with only points or lines
        }
        validate_part(&positions, &triangles, &location)?;
        let normals: Vec<Vec3> = m
            .normals
            .chunks_exact(3)
            .map(|c| Vec3::new(c[0], c[1], c[2]))
            .collect();
        let uvs: Vec<Vec2> = m
            .texcoords
            .chunks_exact(2)
            .map(|c| Vec2::new(c[0], c[1]))
            .collect();
        // Vertex colours (`v x y z r g b`, linear) only when every vertex has one.
        let colors: Vec<glam::Vec4> = m
            .vertex_color
            .chunks_exact(3)
            .map(|c| glam::Vec4::new(c[0], c[1], c[2], 1.0))
            .collect();
        if let Some(v) = colors.iter().position(|c| !c.is_finite()) {
            return Err(SceneError::Invalid {
                location: location.to_string(),
                problem: format!("the colour of vertex {v} is not finite"),
            });
        }
        let material = m
            .material_id
            .filter(|&i| i < default_material as usize)
            .map_or(default_material, |i| i as u32);
        let part = Mesh {
            normals: if normals.len() == positions.len() {
                normals
            } else {
                Vec::new()
            },
            uvs: if uvs.len() == positions.len() {
                uvs
            } else {
                Vec::new()
            },
            colors: if colors.len() == positions.len() {
                colors
            } else {
                Vec::new()
            },
            material_ids: vec![material; triangles.len()],
            positions,
            triangles,
        };
        scene.mesh.append(&part, 0);
    }
    scene.validate()?;
    Ok(scene)
}
