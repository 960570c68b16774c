//! Shared state: the scenes folder, prepared scenes built once and cached, and the
//! limits that keep one request from taking the machine.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use continuum::PreparedScene;
use tokio::sync::Semaphore;

use crate::error::ApiError;

/// Request limits (all configurable).
#[derive(Clone, Debug)]
pub struct Limits {
    /// Most pixels in one render.
    pub max_pixels: u64,
    /// Renders running at once; more get 503.
    pub max_concurrent_renders: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_pixels: 2560 * 1600,
            max_concurrent_renders: std::thread::available_parallelism().map_or(2, |n| n.get()),
        }
    }
}

#[derive(Debug)]
pub struct AppState {
    pub scenes_dir: PathBuf,
    pub limits: Limits,
    pub(crate) renders: Arc<Semaphore>,
    pub(crate) metrics: crate::metrics::Metrics,
    cache: Mutex<HashMap<String, Arc<PreparedScene>>>,
}

impl AppState {
    pub fn new(scenes_dir: PathBuf, limits: Limits) -> Arc<AppState> {
        Arc::new(AppState {
            scenes_dir,
            renders: Arc::new(Semaphore::new(limits.max_concurrent_renders.max(1))),
            limits,
            metrics: crate::metrics::Metrics::default(),
            cache: Mutex::new(HashMap::new()),
        })
    }

    /// How many prepared scenes are cached.
    pub fn cached_scenes(&self) -> usize {
        self.cache.lock().map_or(0, |c| c.len())
    }

    /// Names of the scenes this service serves.
    pub fn scene_names(&self) -> Vec<String> {
        continuum::scene::builtin_names(&self.scenes_dir)
    }

    /// The prepared scene `name` (a scene of the scenes folder, never a path),
    /// loaded and prepared on first use. Blocking: call off the async runtime.
    pub fn prepared(&self, name: &str) -> Result<Arc<PreparedScene>, ApiError> {
        if let Some(p) = self
            .cache
            .lock()
            .map_err(|_| ApiError::internal("scene cache poisoned"))?
            .get(name)
        {
            return Ok(p.clone());
        }
        if !self.scene_names().iter().any(|n| n == name) {
            return Err(ApiError::bad_request(
                "scene",
                format!(
                    "unknown scene '{name}'; scenes are: {}",
                    self.scene_names().join(", ")
                ),
            ));
        }
        let scene = continuum::scene::load_named_or_path(name, &self.scenes_dir)
            .map_err(|e| ApiError::internal(format!("scene '{name}' failed to load: {e}")))?;
        let prepared = Arc::new(PreparedScene::new(scene));
        self.cache
            .lock()
            .map_err(|_| ApiError::internal("scene cache poisoned"))?
            .insert(name.to_string(), prepared.clone());
        Ok(prepared)
    }
}

impl AppState {
    /// The render-slot semaphore, so tests can hold slots as long renders would.
    #[doc(hidden)]
    pub fn renders_for_test(&self) -> Arc<Semaphore> {
        self.renders.clone()
    }
}
