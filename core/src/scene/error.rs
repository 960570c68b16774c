//! Scene loading errors. Every message names the file and, where there is one,
//! the mesh, primitive and index at fault.

use thiserror::Error;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum SceneError {
    #[error("{path}: cannot read: {message}")]
    Io { path: String, message: String },

    #[error("{path}: unsupported scene format (expected .gltf, .glb, .obj or .toml)")]
    UnsupportedFormat { path: String },

    #[error("{path}: not a valid glTF 2.0 file: {message}")]
    Gltf { path: String, message: String },

    #[error("{path}: not a valid OBJ file: {message}")]
    Obj { path: String, message: String },

    #[error("{path}: invalid scene file: {message}")]
    SceneFile { path: String, message: String },

    #[error("{location}: {problem}")]
    Invalid { location: String, problem: String },

    #[error("{location}: unsupported {what}")]
    Unsupported { location: String, what: String },

    #[error("{location}: the mesh is empty (no triangles)")]
    Empty { location: String },

    #[error("unknown scene '{name}'; built-in scenes are: {}", available.join(", "))]
    UnknownScene {
        name: String,
        available: Vec<String>,
    },

    #[error("scene '{scene}' has no camera '{camera}'; cameras are: {}", available.join(", "))]
    UnknownCamera {
        scene: String,
        camera: String,
        available: Vec<String>,
    },
}
