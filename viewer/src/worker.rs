//! The render worker: one thread that loads scenes and calls `continuum::render`,
//! so the UI never blocks. Jobs carry a generation number; a job still waiting
//! when a newer one arrives is dropped unrendered (the newer supersedes it), and
//! results reach the UI in submission order.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, Sender, channel};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use continuum::{Camera, PreparedScene, RenderOutput, render};

use continuum::FieldError;

use crate::config::{Config, Method, SceneSource};

/// What the UI asks for: a configuration, and optionally a second method to
/// render beside it (the compare view's B).
#[derive(Clone, Debug, PartialEq)]
pub struct Job {
    pub config: Config,
    pub compare: Option<Method>,
}

/// One finished job.
#[derive(Debug)]
pub struct Outcome {
    pub generation: u64,
    pub job: Job,
    pub result: Result<Rendered, FieldError>,
    /// Wall time of the whole job, scene loading included.
    pub wall: Duration,
}

/// The images of a finished job and the scene they came from.
#[derive(Debug)]
pub struct Rendered {
    pub scene: Arc<PreparedScene>,
    /// The camera the render looked through (the configuration's, resolved).
    pub camera: Camera,
    pub a: RenderOutput,
    /// The compare view's B, or why it could not be rendered.
    pub b: Option<Result<RenderOutput, FieldError>>,
}

/// What the worker is doing, for the UI's spinner.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Activity {
    Idle,
    Loading(String),
    Rendering,
}

#[derive(Debug)]
struct Slot {
    pending: Option<(u64, Job)>,
    activity: Activity,
    started: Option<Instant>,
    /// Jobs run to the end (superseded ones never start).
    finished: u64,
    quit: bool,
}

type Shared = Arc<(Mutex<Slot>, Condvar)>;

fn lock(shared: &Shared) -> MutexGuard<'_, Slot> {
    shared.0.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Handle to the worker thread; dropping it stops the thread after its current job.
pub struct RenderWorker {
    shared: Shared,
    results: Receiver<Outcome>,
    next_generation: u64,
    thread: Option<JoinHandle<()>>,
}

impl std::fmt::Debug for RenderWorker {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RenderWorker")
            .field("next_generation", &self.next_generation)
            .finish_non_exhaustive()
    }
}

impl RenderWorker {
    /// Starts the worker; `wake` is called whenever a result is ready (the UI's
    /// repaint request).
    pub fn start(scenes_dir: PathBuf, wake: impl Fn() + Send + 'static) -> RenderWorker {
        let shared: Shared = Arc::new((
            Mutex::new(Slot {
                pending: None,
                activity: Activity::Idle,
                started: None,
                finished: 0,
                quit: false,
            }),
            Condvar::new(),
        ));
        let (send, results) = channel();
        let thread = {
            let shared = Arc::clone(&shared);
            std::thread::Builder::new()
                .name("continuum-render".into())
                .spawn(move || work(&shared, &send, &scenes_dir, &wake))
                .expect("spawning the render thread")
        };
        RenderWorker {
            shared,
            results,
            next_generation: 1,
            thread: Some(thread),
        }
    }

    /// Queues `job`, replacing any job that has not started; returns its generation.
    pub fn submit(&mut self, job: Job) -> u64 {
        let generation = self.next_generation;
        self.next_generation += 1;
        lock(&self.shared).pending = Some((generation, job));
        self.shared.1.notify_all();
        generation
    }

    /// The newest finished job, if any finished since the last call.
    pub fn poll(&self) -> Option<Outcome> {
        self.results.try_iter().last()
    }

    /// What the worker is doing and since when.
    pub fn activity(&self) -> (Activity, Option<Duration>) {
        let slot = lock(&self.shared);
        (slot.activity.clone(), slot.started.map(|t| t.elapsed()))
    }

    /// How many jobs ran to the end.
    pub fn finished(&self) -> u64 {
        lock(&self.shared).finished
    }

    /// Blocks until every submitted job has finished, and returns the newest
    /// outcome (for tests and `--screenshot`).
    pub fn wait(&self) -> Option<Outcome> {
        // The worker takes a job and leaves idle under one lock, and sends its
        // outcome before going idle again: idle with nothing pending means sent.
        drop(
            self.shared
                .1
                .wait_while(lock(&self.shared), |s| {
                    s.pending.is_some() || s.activity != Activity::Idle
                })
                .unwrap_or_else(PoisonError::into_inner),
        );
        self.poll()
    }
}

impl Drop for RenderWorker {
    fn drop(&mut self) {
        lock(&self.shared).quit = true;
        self.shared.1.notify_all();
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The worker's loop: take the newest job, render it, send it, repeat.
fn work(shared: &Shared, send: &Sender<Outcome>, scenes_dir: &Path, wake: &dyn Fn()) {
    let mut scenes = SceneCache::default();
    let mut pools: HashMap<usize, rayon::ThreadPool> = HashMap::new();
    loop {
        let (generation, job) = {
            let mut slot = shared
                .1
                .wait_while(lock(shared), |s| s.pending.is_none() && !s.quit)
                .unwrap_or_else(PoisonError::into_inner);
            if slot.quit {
                return;
            }
            let taken = slot.pending.take().expect("woken with a pending job");
            slot.activity = Activity::Loading(taken.1.config.scene.label());
            slot.started = Some(Instant::now());
            taken
        };
        let started = Instant::now();
        let result = run_job(&job, &mut scenes, &mut pools, scenes_dir, || {
            lock(shared).activity = Activity::Rendering;
        });
        let outcome = Outcome {
            generation,
            job,
            result,
            wall: started.elapsed(),
        };
        // Send before going idle, so `wait` always finds the outcome.
        let _ = send.send(outcome);
        {
            let mut slot = lock(shared);
            slot.activity = Activity::Idle;
            slot.started = None;
            slot.finished += 1;
        }
        shared.1.notify_all();
        wake();
    }
}

fn run_job(
    job: &Job,
    scenes: &mut SceneCache,
    pools: &mut HashMap<usize, rayon::ThreadPool>,
    scenes_dir: &Path,
    rendering: impl FnOnce(),
) -> Result<Rendered, FieldError> {
    let config = &job.config;
    let scene = scenes.get(&config.scene, scenes_dir)?;
    rendering();
    let threads = config.threads.clamp(1, 256);
    let pool = match pools.entry(threads) {
        std::collections::hash_map::Entry::Occupied(e) => e.into_mut(),
        std::collections::hash_map::Entry::Vacant(e) => e.insert(
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .map_err(|e| FieldError {
                    field: "threads",
                    message: format!("cannot start {threads} render threads: {e}"),
                })?,
        ),
    };
    let render_method = |method: &Method| -> Result<(RenderOutput, Camera), FieldError> {
        let request = config.request(&scene, method)?;
        let out = pool.install(|| render(&scene, &request))?;
        Ok((out, request.camera))
    };
    // The camera A looked through (B's is the same: only the method differs).
    let (a, camera) = render_method(&config.method)?;
    let b = job
        .compare
        .as_ref()
        .map(|method| render_method(method).map(|(out, _)| out));
    Ok(Rendered {
        camera,
        scene,
        a,
        b,
    })
}

/// Prepared scenes by source; keeps the two most recent (a 1M-triangle scene
/// and its BVH take a few hundred MB).
#[derive(Default)]
struct SceneCache {
    entries: Vec<(SceneSource, Arc<PreparedScene>)>,
}

impl SceneCache {
    const CAPACITY: usize = 2;

    fn get(
        &mut self,
        source: &SceneSource,
        scenes_dir: &Path,
    ) -> Result<Arc<PreparedScene>, FieldError> {
        if let Some(i) = self.entries.iter().position(|(s, _)| s == source) {
            let entry = self.entries.remove(i);
            let scene = Arc::clone(&entry.1);
            self.entries.push(entry);
            return Ok(scene);
        }
        let scene =
            continuum::scene::load_named_or_path(&source.as_arg(), scenes_dir).map_err(|e| {
                FieldError {
                    field: "scene",
                    message: e.to_string(),
                }
            })?;
        let prepared = Arc::new(PreparedScene::new(scene));
        if self.entries.len() == Self::CAPACITY {
            self.entries.remove(0);
        }
        self.entries.push((source.clone(), Arc::clone(&prepared)));
        Ok(prepared)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::CameraChoice;

    fn job(algorithm: &str, size: &str) -> Job {
        Job {
            config: Config::from_words(&continuum::RenderWords {
                scene: "bunny".into(),
                size: Some(size.into()),
                ..continuum::RenderWords::new(algorithm)
            })
            .expect("valid words"),
            compare: None,
        }
    }

    fn worker() -> RenderWorker {
        RenderWorker::start(continuum::scene::default_scenes_dir(), || {})
    }

    #[test]
    fn a_newer_job_supersedes_one_still_waiting() {
        let mut w = worker();
        // The first job keeps the worker busy (loading the scene) while four
        // more arrive; only the newest of those waits, so at most two run.
        w.submit(job("3dr-brute", "160x120"));
        for a in ["2dr-brute", "raycast", "3dr-bin", "3dr-full"] {
            w.submit(job(a, "160x120"));
        }
        let last = w.wait().expect("an outcome");
        assert_eq!(last.generation, 5);
        assert_eq!(last.job.config.method.algorithm.as_str(), "3dr-full");
        assert!(w.finished() <= 2, "{} jobs ran", w.finished());
        let rendered = last.result.expect("renders");
        assert_eq!((rendered.a.view.width, rendered.a.view.height), (160, 120));
        assert_eq!(w.activity().0, Activity::Idle);
    }

    #[test]
    fn failures_name_their_field_and_the_worker_goes_on() {
        let mut w = worker();
        let mut missing = job("3dr-brute", "32x24");
        missing.config.scene = SceneSource::Builtin("no-such-scene".into());
        w.submit(missing);
        assert_eq!(
            w.wait()
                .expect("an outcome")
                .result
                .expect_err("no scene")
                .field,
            "scene"
        );

        let mut curved = job("2dr-brute", "32x24");
        curved.config.viewport = "latlong".into();
        w.submit(curved);
        assert_eq!(
            w.wait()
                .expect("an outcome")
                .result
                .expect_err("2D on latlong")
                .field,
            "viewport"
        );

        let mut camera = job("3dr-brute", "32x24");
        camera.config.camera = CameraChoice::Named(Some("no-such-camera".into()));
        w.submit(camera);
        assert_eq!(
            w.wait()
                .expect("an outcome")
                .result
                .expect_err("unknown camera")
                .field,
            "camera"
        );

        let mut b = job("3dr-brute", "32x24");
        b.compare = Some(Method {
            algorithm: continuum::AlgorithmId::GpuRaster,
            aa: continuum::AaMode::Msaa(4),
            ..Method::default()
        });
        w.submit(b);
        let rendered = w.wait().expect("outcome").result.expect("A renders");
        assert_eq!(
            rendered
                .b
                .expect("B asked")
                .expect_err("gpu-raster has no msaa")
                .field,
            "aa"
        );
    }
}
