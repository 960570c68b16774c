//! continuum: one renderer for the road between rasterization and ray casting.
//!
//! It follows "3D Rasterization: A Bridge between Rasterization and Ray Casting"
//! (Davidovič et al., GI 2012). Coverage is decided by edge functions — projected
//! 2D ones, or the paper's 3D (Plücker) ones — and the algorithms differ only in
//! how they enumerate triangles and samples. Every front end calls [`render()`]:
//!
//! ```no_run
//! use continuum::{render, AlgorithmId, PreparedScene, RenderRequest};
//! let scene = continuum::scene::load_path("scenes/bunny.toml".as_ref()).unwrap();
//! let prepared = PreparedScene::new(scene);
//! let camera = prepared.scene.first_camera();
//! let out = render(&prepared, &RenderRequest { algorithm: AlgorithmId::ThreeDBrute, oracles: None, camera, width: 640, height: 480, aa: Default::default(), precision: Default::default(), texture_filter: Default::default() }).unwrap();
//! println!("{}", out.hashes.triangle_id);
//! ```

pub mod aa;
pub mod algorithm;
pub mod binning;
pub mod bvh;
pub mod camera;
pub mod clip;
pub mod edge;
pub mod framebuffer;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod hardcases;
pub mod maps;
pub mod mesa;
pub mod metrics;
pub mod peer;
pub mod precision;
pub mod prepared;
pub mod render;
pub mod request;
pub mod scene;
pub mod shade;
pub mod simd;
pub mod stats;
pub mod traversal;
pub mod viewport;

pub use aa::AaMode;
pub use algorithm::{AlgorithmId, Family, Pipeline};
pub use camera::{Camera, View};
pub use framebuffer::{BACKGROUND, Framebuffer};
pub use precision::Precision;
pub use prepared::PreparedScene;
pub use render::{
    RenderError, RenderOutput, RenderRequest, render, render_cancellable, unavailable,
};
pub use scene::{Scene, SceneError};
pub use stats::{Hashes, Stats};
pub use viewport::Viewport;
