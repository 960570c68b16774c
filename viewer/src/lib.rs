//! continuum-viewer: the desktop viewer of the continuum renderer. It renders
//! in-process through `continuum::render` on a worker thread and shows the
//! images, the per-pixel edge-evaluation maps, the timings and counters, and two
//! configurations side by side with their difference.

pub mod app;
pub mod config;
pub mod image_view;
pub mod images;
pub mod orbit;
pub mod timings;
pub mod worker;

pub use app::ViewerApp;
pub use config::{Config, Method, SceneSource};
