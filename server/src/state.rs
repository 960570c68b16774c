//! Shared state: the scenes folder, prepared scenes built once and kept in a
//! memory-bounded cache, uploaded scenes, and the limits that keep one request
//! from taking the machine.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use continuum::{PreparedScene, Viewport};
use serde_json::{Value, json};
use tokio::sync::Semaphore;

use crate::error::ApiError;

/// Request limits (all configurable from `continuum serve`).
#[derive(Clone, Debug)]
pub struct Limits {
    /// Most pixels in one render.
    pub max_pixels: u64,
    /// Most samples per pixel a request may ask for (anti-aliasing modes).
    pub max_samples_per_pixel: u32,
    /// Most samples in one render (pixels × samples per pixel): what bounds a
    /// render's time once anti-aliasing multiplies its pixels.
    pub max_samples: u64,
    /// Renders running at once.
    pub max_concurrent_renders: usize,
    /// Renders that may wait for a slot; more get 503 with `Retry-After`.
    pub max_queued_renders: usize,
    /// A render not finished by then is answered with 504 and cancelled.
    pub render_timeout: Duration,
    /// Largest request body (JSON requests and `.glb` uploads), bytes.
    pub max_body_bytes: usize,
    /// Most triangles an uploaded scene may have.
    pub max_upload_triangles: usize,
    /// Memory for prepared scenes; least recently used ones are dropped beyond it.
    pub max_cache_bytes: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_pixels: 2560 * 1600,
            max_samples_per_pixel: 256,
            max_samples: 2560 * 1600 * 16,
            max_concurrent_renders: std::thread::available_parallelism().map_or(2, |n| n.get()),
            max_queued_renders: 4 * std::thread::available_parallelism().map_or(2, |n| n.get()),
            render_timeout: Duration::from_secs(60),
            max_body_bytes: 32 << 20,
            max_upload_triangles: 2_000_000,
            max_cache_bytes: 2 << 30,
        }
    }
}

/// A cached prepared scene and when it was last used.
#[derive(Debug)]
struct Cached {
    scene: Arc<PreparedScene>,
    bytes: usize,
    last_used: u64,
    /// Uploaded scenes cannot be reloaded from disk once dropped.
    uploaded: bool,
}

#[derive(Debug, Default)]
struct Cache {
    entries: HashMap<String, Cached>,
    clock: u64,
}

impl Cache {
    fn get(&mut self, name: &str) -> Option<Arc<PreparedScene>> {
        self.clock += 1;
        let clock = self.clock;
        self.entries.get_mut(name).map(|c| {
            c.last_used = clock;
            c.scene.clone()
        })
    }

    /// Inserts, then drops least recently used entries (never the new one) until
    /// the total fits `max_bytes`.
    fn insert(&mut self, name: &str, scene: Arc<PreparedScene>, uploaded: bool, max_bytes: usize) {
        self.clock += 1;
        let bytes = scene.bytes();
        self.entries.insert(
            name.to_string(),
            Cached {
                scene,
                bytes,
                last_used: self.clock,
                uploaded,
            },
        );
        while self.entries.values().map(|c| c.bytes).sum::<usize>() > max_bytes {
            let Some(oldest) = self
                .entries
                .iter()
                .filter(|(n, _)| n.as_str() != name)
                .min_by_key(|(_, c)| c.last_used)
                .map(|(n, _)| n.clone())
            else {
                break;
            };
            self.entries.remove(&oldest);
        }
    }
}

#[derive(Debug)]
pub struct AppState {
    pub scenes_dir: PathBuf,
    pub limits: Limits,
    pub(crate) renders: Arc<Semaphore>,
    pub(crate) metrics: crate::metrics::Metrics,
    /// Requests waiting for a render slot.
    pub(crate) queued: std::sync::atomic::AtomicUsize,
    cache: Mutex<Cache>,
    /// What `GET /api/scenes` says of each scene (cameras, triangles, lights),
    /// made from the loaded scene once, never by preparing it.
    catalogue: Mutex<HashMap<String, Arc<serde_json::Value>>>,
}

/// A place in the render queue, given back when dropped.
#[derive(Debug)]
pub(crate) struct QueueTicket<'a>(&'a std::sync::atomic::AtomicUsize);

impl Drop for QueueTicket<'_> {
    fn drop(&mut self) {
        self.0.fetch_sub(1, std::sync::atomic::Ordering::SeqCst);
    }
}

impl AppState {
    pub fn new(scenes_dir: PathBuf, limits: Limits) -> Arc<AppState> {
        Arc::new(AppState {
            scenes_dir,
            renders: Arc::new(Semaphore::new(limits.max_concurrent_renders.max(1))),
            limits,
            metrics: crate::metrics::Metrics::default(),
            queued: std::sync::atomic::AtomicUsize::new(0),
            cache: Mutex::new(Cache::default()),
            catalogue: Mutex::new(HashMap::new()),
        })
    }

    /// A place in the render queue, or `None` when it is full.
    pub(crate) fn queue_ticket(&self) -> Option<QueueTicket<'_>> {
        use std::sync::atomic::Ordering;
        let max = self.limits.max_queued_renders;
        self.queued
            .fetch_update(Ordering::SeqCst, Ordering::SeqCst, |n| {
                (n < max).then_some(n + 1)
            })
            .ok()
            .map(|_| QueueTicket(&self.queued))
    }

    fn cache(&self) -> Result<std::sync::MutexGuard<'_, Cache>, ApiError> {
        self.cache
            .lock()
            .map_err(|_| ApiError::internal("scene cache poisoned"))
    }

    /// How many prepared scenes are cached, and their approximate bytes.
    pub fn cache_usage(&self) -> (usize, usize) {
        self.cache.lock().map_or((0, 0), |c| {
            (c.entries.len(), c.entries.values().map(|e| e.bytes).sum())
        })
    }

    /// Names of the scenes this service serves: the scenes folder's and the
    /// uploads still cached.
    pub fn scene_names(&self) -> Result<Vec<String>, ApiError> {
        let mut names = self.builtin_names()?;
        if let Ok(cache) = self.cache.lock() {
            let mut uploads: Vec<String> = cache
                .entries
                .iter()
                .filter(|(_, c)| c.uploaded)
                .map(|(n, _)| n.clone())
                .collect();
            uploads.sort();
            names.extend(uploads);
        }
        Ok(names)
    }

    /// The scenes folder's scenes; an unreadable folder is the server's error.
    pub fn builtin_names(&self) -> Result<Vec<String>, ApiError> {
        continuum::scene::builtin_names(&self.scenes_dir)
            .map_err(|e| ApiError::internal(format!("listing the scenes: {e}")))
    }

    /// The prepared scene `name` (a scene of the scenes folder or an upload,
    /// never a path), loaded and prepared on first use. Blocking: call off the
    /// async runtime.
    pub fn prepared(&self, name: &str) -> Result<Arc<PreparedScene>, ApiError> {
        if let Some(p) = self.cache()?.get(name) {
            return Ok(p);
        }
        if !self.builtin_names()?.iter().any(|n| n == name) {
            return Err(ApiError::bad_request(
                "scene",
                format!(
                    "unknown scene '{name}'; scenes are: {}",
                    self.scene_names()?.join(", ")
                ),
            ));
        }
        let scene = continuum::scene::load_named_or_path(name, &self.scenes_dir)
            .map_err(|e| ApiError::internal(format!("scene '{name}' failed to load: {e}")))?;
        let prepared = Arc::new(PreparedScene::new(scene));
        self.cache()?
            .insert(name, prepared.clone(), false, self.limits.max_cache_bytes);
        Ok(prepared)
    }

    /// Keeps an uploaded, prepared scene under `name`.
    pub fn add_upload(&self, name: &str, scene: Arc<PreparedScene>) -> Result<(), ApiError> {
        self.remember(name, &scene.scene, scene.triangle_count());
        self.cache()?
            .insert(name, scene, true, self.limits.max_cache_bytes);
        Ok(())
    }

    /// The catalogue entry of `name`: from the cache of entries, else from the
    /// prepared scene if one is cached, else by loading (not preparing) the
    /// scene. Blocking: call off the async runtime.
    pub fn describe(&self, name: &str) -> Arc<serde_json::Value> {
        if let Some(entry) = self
            .catalogue
            .lock()
            .ok()
            .and_then(|c| c.get(name).cloned())
        {
            return entry;
        }
        if let Ok(Some(p)) = self.cache().map(|mut c| c.get(name)) {
            return self.remember(name, &p.scene, p.triangle_count());
        }
        let error = |e: String| Arc::new(serde_json::json!({ "name": name, "error": e }));
        // A name, never a path: only the scenes folder's scenes load from disk.
        match self.builtin_names() {
            Ok(names) if names.iter().any(|n| n == name) => {}
            Ok(_) => return error(format!("unknown scene '{name}'")),
            Err(e) => return error(e.error),
        }
        match continuum::scene::load_named_or_path(name, &self.scenes_dir) {
            Ok(scene) => {
                let triangles = scene.mesh.triangle_count();
                self.remember(name, &scene, triangles)
            }
            Err(e) => error(format!("scene '{name}' failed to load: {e}")),
        }
    }

    /// Keeps `scene`'s catalogue entry under `name`.
    fn remember(
        &self,
        name: &str,
        scene: &continuum::Scene,
        triangles: usize,
    ) -> Arc<serde_json::Value> {
        let entry = Arc::new(scene_entry(name, scene, triangles));
        if let Ok(mut c) = self.catalogue.lock() {
            c.insert(name.to_string(), entry.clone());
        }
        entry
    }

    /// How many prepared scenes are cached (tests check that listing prepares none).
    #[doc(hidden)]
    pub fn prepared_count(&self) -> usize {
        self.cache_usage().0
    }

    /// The render-slot semaphore, so tests can hold slots as long renders would.
    #[doc(hidden)]
    pub fn renders_for_test(&self) -> Arc<Semaphore> {
        self.renders.clone()
    }
}

/// A scene's catalogue entry.
pub(crate) fn scene_entry(name: &str, scene: &continuum::Scene, triangles: usize) -> Value {
    let cameras: Vec<Value> = scene
        .all_cameras()
        .iter()
        .map(|c| {
            json!({
                "name": c.name, "eye": c.eye.to_array(), "target": c.target.to_array(),
                "up": c.up.to_array(), "viewport": c.viewport.to_string(),
                "fov_y": match c.viewport {
                    Viewport::Perspective { fov_y_deg } => Some(fov_y_deg),
                    _ => None,
                },
                "near": c.near,
            })
        })
        .collect();
    json!({
        "name": name,
        "triangles": triangles,
        "cameras": cameras,
        "lights": scene.lights.len(),
        // What the scene calls for beyond Lambert shading.
        "effects": scene.effects(),
        "warnings": scene.warnings,
    })
}
