//! The viewer application: controls on the left, the image (or A | B |
//! difference) in the middle, the pixel inspector and timings on the right.
//! Every frame: take the worker's newest result, draw, and submit the
//! configuration again if the user changed it.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, PoisonError};

use continuum::TextureFilter;
use continuum::{AaMode, AlgorithmId, Overlays, Precision, RenderOutput, Stats, Viewport};
use eframe::egui::{self, Color32, ColorImage, TextureHandle, TextureOptions};

use continuum::FieldError;

use crate::config::{CameraChoice, Config, Method, SceneSource, has_scene_extension};
use crate::image_view::{self, Gesture};
use crate::images::{self, Difference, ViewKind};
use crate::orbit;
use crate::timings::{self, History, Row};
use crate::worker::{Activity, Job, Outcome, RenderWorker};

/// The resolutions offered beside the width and height fields.
const PRESETS: [(u32, u32); 5] = [
    (320, 240),
    (640, 480),
    (1280, 720),
    (1920, 1080),
    (512, 512),
];

/// Which render of the compare view an image belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Side {
    A,
    B,
}

/// A finished render on screen, with the images made from it so far.
struct Shown {
    outcome: Outcome,
    images: HashMap<(Side, ViewKind), (ColorImage, TextureHandle)>,
    difference: Option<(Difference, TextureHandle)>,
}

impl Shown {
    /// Gives the frames' memory back for the next renders of their size.
    fn recycle(self) {
        if let Ok(rendered) = self.outcome.result {
            rendered.a.framebuffer.recycle();
            if let Some(Ok(b)) = rendered.b {
                b.framebuffer.recycle();
            }
        }
    }

    fn output(&self, side: Side) -> Option<&RenderOutput> {
        let rendered = self.outcome.result.as_ref().ok()?;
        match side {
            Side::A => Some(&rendered.a),
            Side::B => rendered.b.as_ref()?.as_ref().ok(),
        }
    }

    /// The image of `kind` for `side`, made and uploaded on first use.
    fn image(
        &mut self,
        ctx: &egui::Context,
        side: Side,
        kind: ViewKind,
    ) -> Option<&(ColorImage, TextureHandle)> {
        if !self.images.contains_key(&(side, kind)) {
            // The overlays the job asked for, drawn over every view of it.
            let out = self.output(side)?;
            let rendered = self.outcome.result.as_ref().ok()?;
            let mut rgba = kind.rgba(&out.framebuffer);
            let overlays = self.outcome.job.config.overlays;
            continuum::draw_overlays(&mut rgba, overlays, out, &rendered.scene);
            let image = images::to_color_image(&rgba);
            let texture = ctx.load_texture(
                format!("{side:?}-{}", kind.label()),
                image.clone(),
                TextureOptions::NEAREST,
            );
            self.images.insert((side, kind), (image, texture));
        }
        self.images.get(&(side, kind))
    }

    fn difference(&mut self, ctx: &egui::Context) -> Option<&(Difference, TextureHandle)> {
        if self.difference.is_none() {
            let d = images::difference(
                &self.output(Side::A)?.framebuffer,
                &self.output(Side::B)?.framebuffer,
            )?;
            let texture = ctx.load_texture("difference", d.image.clone(), TextureOptions::NEAREST);
            self.difference = Some((d, texture));
        }
        self.difference.as_ref()
    }
}

/// `--screenshot`: wait for the first frame, capture the window, save it, close.
#[derive(Debug)]
struct Screenshot {
    path: PathBuf,
    requested: bool,
    image: Arc<Mutex<Option<Arc<ColorImage>>>>,
    /// What happened, for `main`'s exit status.
    result: Arc<Mutex<Option<Result<(), String>>>>,
}

/// The viewer's state: what to render, what is shown, and the worker.
pub struct ViewerApp {
    worker: RenderWorker,
    builtins: Vec<String>,
    /// What the controls describe now.
    pub config: Config,
    /// The compare view's B (its method; everything else is A's).
    pub compare: Option<Method>,
    pub view: ViewKind,
    submitted: Option<Job>,
    shown: Option<Shown>,
    /// Why the newest job failed (the last good image stays on screen).
    error: Option<FieldError>,
    history: History,
    scene_path: String,
    /// A scenes folder the user opened: its scene and model files.
    folder: Option<(PathBuf, Vec<PathBuf>)>,
    hovered: Option<(u32, u32)>,
    screenshot: Option<Screenshot>,
}

impl std::fmt::Debug for ViewerApp {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ViewerApp")
            .field("config", &self.config)
            .field("compare", &self.compare)
            .field("view", &self.view)
            .finish_non_exhaustive()
    }
}

impl ViewerApp {
    /// A viewer of `config`, with built-in scenes from `scenes_dir`; results
    /// wake `ctx`.
    pub fn new(ctx: &egui::Context, scenes_dir: &Path, config: Config) -> ViewerApp {
        let wake = ctx.clone();
        ViewerApp {
            worker: RenderWorker::start(scenes_dir.to_owned(), move || wake.request_repaint()),
            builtins: continuum::scene::builtin_names(scenes_dir).unwrap_or_default(),
            config,
            compare: None,
            view: ViewKind::Color,
            submitted: None,
            shown: None,
            error: None,
            history: History::default(),
            scene_path: String::new(),
            folder: None,
            hovered: None,
            screenshot: None,
        }
    }

    /// Capture the window to `path` (PNG) once the first frame is on screen,
    /// then close; the returned slot holds the outcome.
    pub fn screenshot_to(&mut self, path: PathBuf) -> Arc<Mutex<Option<Result<(), String>>>> {
        let result = Arc::new(Mutex::new(None));
        self.screenshot = Some(Screenshot {
            path,
            requested: false,
            image: Arc::new(Mutex::new(None)),
            result: Arc::clone(&result),
        });
        result
    }

    /// Submits the current configuration if it changed since the last submission.
    pub fn submit_if_changed(&mut self) {
        let job = Job {
            config: self.config.clone(),
            compare: self.compare.clone(),
        };
        if self.submitted.as_ref() != Some(&job) {
            self.worker.submit(job.clone());
            self.submitted = Some(job);
        }
    }

    /// Blocks until the worker has finished everything submitted and takes its
    /// newest result (for tests; the UI itself never blocks).
    pub fn wait_for_render(&mut self) {
        self.submit_if_changed();
        if let Some(outcome) = self.worker.wait() {
            self.accept(outcome);
        }
    }

    /// The error of the newest job, if it failed.
    pub fn error(&self) -> Option<&FieldError> {
        self.error.as_ref()
    }

    /// The statistics of the renders on screen (A, then B), mutable so tests can
    /// pin the one thing that varies from run to run: time.
    pub fn shown_stats_mut(&mut self) -> Vec<&mut Stats> {
        let Some(Ok(rendered)) = self.shown.as_mut().map(|s| s.outcome.result.as_mut()) else {
            return Vec::new();
        };
        let mut out = vec![&mut rendered.a.stats];
        if let Some(Ok(b)) = rendered.b.as_mut() {
            out.push(&mut b.stats);
        }
        out
    }

    /// Past frames' totals (mutable for the same reason).
    pub fn history_mut(&mut self) -> &mut History {
        &mut self.history
    }

    /// The colour image on screen (A), if any.
    pub fn shown_output(&self) -> Option<&RenderOutput> {
        self.shown.as_ref()?.output(Side::A)
    }

    fn accept(&mut self, outcome: Outcome) {
        match &outcome.result {
            Ok(rendered) => {
                self.error = None;
                let outputs = [
                    Some(&rendered.a),
                    rendered.b.as_ref().and_then(|b| b.as_ref().ok()),
                ];
                for out in outputs.into_iter().flatten() {
                    self.history
                        .push(history_label(out), out.stats.time_ms.total);
                }
                // The frames shown until now serve the worker's next renders.
                if let Some(old) = self.shown.take() {
                    old.recycle();
                }
                self.shown = Some(Shown {
                    outcome,
                    images: HashMap::new(),
                    difference: None,
                });
            }
            Err(e) => self.error = Some(e.clone()),
        }
    }

    /// One frame of the whole window.
    pub fn show(&mut self, ui: &mut egui::Ui) {
        if let Some(outcome) = self.worker.poll() {
            self.accept(outcome);
        }
        self.take_dropped_files(ui.ctx());

        egui::Panel::top("status").show(ui, |ui| self.status_bar(ui));
        egui::Panel::left("controls")
            .resizable(false)
            .exact_size(250.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| self.controls(ui));
            });
        egui::Panel::right("inspector")
            .resizable(false)
            .exact_size(330.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| self.inspector(ui));
            });
        egui::CentralPanel::default().show(ui, |ui| self.images(ui));

        self.submit_if_changed();
        if self.worker.activity().0 != Activity::Idle {
            ui.ctx()
                .request_repaint_after(std::time::Duration::from_millis(100));
        }
        self.advance_screenshot(ui.ctx());
    }

    fn take_dropped_files(&mut self, ctx: &egui::Context) {
        let dropped = ctx.input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_path_buf())
                .next()
        });
        if let Some(path) = dropped {
            self.open_scene(SceneSource::Path(path));
        }
    }

    fn open_scene(&mut self, scene: SceneSource) {
        if scene != self.config.scene {
            self.config.scene = scene;
            self.config.camera = CameraChoice::Named(None);
        }
    }

    fn status_bar(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.strong("continuum");
            ui.separator();
            for kind in ViewKind::ALL {
                ui.selectable_value(&mut self.view, kind, kind.label());
            }
            ui.separator();
            match self.worker.activity() {
                (Activity::Idle, _) => {
                    if let Some(shown) = &self.shown {
                        ui.label(format!("ready: {}", job_label(&shown.outcome.job)));
                    }
                }
                (Activity::Loading(scene), elapsed) => {
                    ui.spinner();
                    ui.label(format!("loading {scene} … {}", seconds(elapsed)));
                }
                (Activity::Rendering, elapsed) => {
                    ui.spinner();
                    ui.label(format!("rendering … {}", seconds(elapsed)));
                }
            }
            if let Some(e) = &self.error {
                ui.colored_label(
                    Color32::from_rgb(255, 110, 100),
                    format!("{}: {}", e.field, e.message),
                );
            }
        });
    }

    fn controls(&mut self, ui: &mut egui::Ui) {
        let heading = ui.heading("Scene");
        let current = self.config.scene.label();
        let mut picked = None;
        egui::ComboBox::from_id_salt("scene")
            .selected_text(&current)
            .width(200.0)
            .show_ui(ui, |ui| {
                for name in &self.builtins {
                    if ui.selectable_label(current == *name, name).clicked() {
                        picked = Some(SceneSource::Builtin(name.clone()));
                    }
                }
                if let Some((dir, files)) = &self.folder {
                    ui.separator();
                    ui.label(dir.display().to_string());
                    for file in files {
                        let source = SceneSource::Path(file.clone());
                        let chosen = self.config.scene == source;
                        if ui.selectable_label(chosen, source.label()).clicked() {
                            picked = Some(source);
                        }
                    }
                }
            })
            .response
            .labelled_by(heading.id);
        ui.horizontal(|ui| {
            let field = ui.add(
                egui::TextEdit::singleline(&mut self.scene_path)
                    .hint_text("a scene file or folder")
                    .desired_width(160.0),
            );
            let enter = field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
            let path = self.scene_path.trim();
            if (ui.button("Open").clicked() || enter) && !path.is_empty() {
                if Path::new(path).is_dir() {
                    let files = scene_files(Path::new(path));
                    picked = files.first().cloned().map(SceneSource::Path);
                    self.folder = Some((PathBuf::from(path), files));
                } else {
                    picked = Some(SceneSource::parse(path));
                }
            }
        });
        ui.small(".gltf .glb .obj .toml, or drop a file on the window");
        if let Some(scene) = picked {
            self.open_scene(scene);
        }
        if let Some(rendered) = self.shown_scene() {
            ui.small(format!(
                "{} triangles, {} cameras",
                timings::thousands(rendered.0 as u64),
                rendered.1.len()
            ));
        }

        ui.add_space(6.0);
        let heading = ui.heading("Camera");
        self.camera_controls(ui, heading.id);

        ui.add_space(6.0);
        ui.heading("Method");
        method_controls(ui, "a", &mut self.config.method);

        ui.add_space(6.0);
        ui.heading("Image");
        size_controls(ui, &mut self.config);
        ui.horizontal(|ui| {
            let label = ui.label("threads");
            ui.add(egui::DragValue::new(&mut self.config.threads).range(1..=64))
                .labelled_by(label.id);
        });
        overlay_controls(ui, &mut self.config.overlays);

        ui.add_space(6.0);
        let mut comparing = self.compare.is_some();
        if ui.checkbox(&mut comparing, "Compare A | B").changed() {
            self.compare = comparing.then(|| Method {
                algorithm: AlgorithmId::Raycast,
                ..self.config.method.clone()
            });
        }
        if let Some(b) = &mut self.compare {
            ui.label("B (scene, camera and size as A)");
            method_controls(ui, "b", b);
        }
    }

    /// The triangle count and camera names of the scene on screen, when it is
    /// the configured scene.
    fn shown_scene(&self) -> Option<(usize, Vec<String>)> {
        let shown = self.shown.as_ref()?;
        if shown.outcome.job.config.scene != self.config.scene {
            return None;
        }
        let scene = &shown.outcome.result.as_ref().ok()?.scene.scene;
        Some((scene.mesh.triangle_count(), scene.camera_names()))
    }

    fn camera_controls(&mut self, ui: &mut egui::Ui, heading: egui::Id) {
        let names = self.shown_scene().map(|s| s.1).unwrap_or_default();
        let selected = match &self.config.camera {
            CameraChoice::Named(Some(name)) => name.clone(),
            CameraChoice::Named(None) => names.first().cloned().unwrap_or_else(|| "first".into()),
            CameraChoice::Moved(_) => "moved".into(),
        };
        ui.horizontal(|ui| {
            egui::ComboBox::from_id_salt("camera")
                .selected_text(&selected)
                .width(130.0)
                .show_ui(ui, |ui| {
                    for name in &names {
                        if ui.selectable_label(selected == *name, name).clicked() {
                            self.config.camera = CameraChoice::Named(Some(name.clone()));
                        }
                    }
                })
                .response
                .labelled_by(heading);
            if ui
                .button("Reset")
                .on_hover_text("the scene camera, unmoved")
                .clicked()
            {
                self.reset_camera();
            }
        });
        ui.small("drag: orbit · right drag: pan · wheel: zoom · double click: reset");
        ui.horizontal(|ui| {
            let viewport = ui.label("viewport");
            let label = if self.config.viewport.is_empty() {
                "camera's own".to_owned()
            } else {
                self.config.viewport.clone()
            };
            egui::ComboBox::from_id_salt("viewport")
                .selected_text(label)
                .show_ui(ui, |ui| {
                    ui.selectable_value(&mut self.config.viewport, String::new(), "camera's own");
                    for kind in Viewport::KINDS {
                        let word = kind.kind().to_owned();
                        ui.selectable_value(&mut self.config.viewport, word.clone(), word);
                    }
                })
                .response
                .labelled_by(viewport.id);
        });
    }

    fn reset_camera(&mut self) {
        self.config.camera = match &self.config.camera {
            CameraChoice::Moved(_) => CameraChoice::Named(None),
            named => named.clone(),
        };
    }

    /// Applies a mouse gesture to the camera the shown frame was rendered with.
    fn apply_gesture(&mut self, gesture: &Gesture) {
        self.hovered = gesture.hovered;
        if gesture.reset {
            self.reset_camera();
            return;
        }
        if !gesture.moves() {
            return;
        }
        let Some(shown) = &self.shown else { return };
        let Ok(rendered) = &shown.outcome.result else {
            return;
        };
        let mut camera = match &self.config.camera {
            CameraChoice::Moved(camera) => camera.clone(),
            CameraChoice::Named(_) if shown.outcome.job.config.scene == self.config.scene => {
                rendered.camera.clone()
            }
            CameraChoice::Named(_) => return,
        };
        orbit::orbit(&mut camera, gesture.orbit.x, gesture.orbit.y);
        orbit::pan(&mut camera, gesture.pan.x, gesture.pan.y);
        orbit::zoom(&mut camera, gesture.zoom);
        camera.name = "moved".into();
        self.config.camera = CameraChoice::Moved(camera);
    }

    fn images(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        let view = self.view;
        let Some(shown) = &mut self.shown else {
            ui.centered_and_justified(|ui| {
                ui.spinner();
            });
            return;
        };
        let size = shown.output(Side::A).map(|o| [o.view.width, o.view.height]);
        let Some(size) = size else { return };
        let comparing = shown.outcome.job.compare.is_some();
        let mut gesture = Gesture::default();
        if !comparing {
            let available = ui.available_size()
                - egui::vec2(
                    0.0,
                    if view == ViewKind::EdgeEvals {
                        60.0
                    } else {
                        0.0
                    },
                );
            if let Some((_, texture)) = shown.image(&ctx, Side::A, view) {
                ui.vertical_centered(|ui| gesture = image_view::show(ui, texture, size, available));
            }
        } else {
            let width = (ui.available_width() - 16.0) / 3.0;
            let available = egui::vec2(width, ui.available_height() - 90.0);
            ui.horizontal_top(|ui| {
                for (side, title) in [(Side::A, "A"), (Side::B, "B")] {
                    ui.vertical(|ui| {
                        ui.strong(format!("{title}: {}", side_label(shown, side)));
                        match shown.image(&ctx, side, view) {
                            Some((_, texture)) => {
                                gesture =
                                    gesture.merge(image_view::show(ui, texture, size, available));
                            }
                            None => {
                                let why = match shown
                                    .outcome
                                    .result
                                    .as_ref()
                                    .ok()
                                    .and_then(|r| r.b.as_ref())
                                {
                                    Some(Err(e)) => format!("{}: {}", e.field, e.message),
                                    _ => "not rendered".into(),
                                };
                                ui.colored_label(Color32::from_rgb(255, 110, 100), why);
                            }
                        }
                    });
                }
                ui.vertical(|ui| match shown.difference(&ctx) {
                    Some((d, texture)) => {
                        ui.strong(format!(
                            "A − B: {} pixels differ in triangle id, {} in colour",
                            d.ids_differ, d.colours_differ
                        ));
                        gesture = gesture.merge(image_view::show(ui, texture, size, available));
                    }
                    None => {
                        ui.strong("A − B");
                    }
                });
            });
            ui.small("difference: magenta = another triangle, yellow = same triangle, other colour, dim = equal");
        }
        if view == ViewKind::EdgeEvals
            && let Some(out) = shown.output(Side::A)
        {
            let evals = &out.framebuffer.edge_evals;
            let min = evals.iter().copied().min().unwrap_or(0);
            let max = evals.iter().copied().max().unwrap_or(0);
            ui.add_space(4.0);
            ui.vertical_centered(|ui| {
                image_view::heat_legend(ui, min, max, 360.0_f32.min(ui.available_width()));
            });
        }
        self.apply_gesture(&gesture);
    }

    fn inspector(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        let view = self.view;
        let hovered = self.hovered;
        let history = &self.history;
        let Some(shown) = &mut self.shown else { return };

        ui.heading("Pixel");
        match hovered {
            Some(p) => {
                if let Some((image, _)) = shown.image(&ctx, Side::A, view) {
                    let image = image.clone();
                    image_view::loupe(ui, &image, p, 150.0);
                }
                pixel_table(ui, shown, p);
            }
            None => {
                ui.label("hover the image to see a pixel's values");
            }
        }

        ui.add_space(6.0);
        ui.heading("Timings");
        let mut renders: Vec<(&str, &Stats)> = Vec::new();
        if let Some(a) = shown.output(Side::A) {
            renders.push(("A", &a.stats));
        }
        if let Some(b) = shown.output(Side::B) {
            renders.push(("B", &b.stats));
        }
        if renders.is_empty() {
            return;
        }
        timings::stage_bars(ui, &renders);
        ui.label("history (total ms per frame)");
        timings::history_plot(ui, history);
        ui.add_space(6.0);
        ui.heading("Effects");
        timings::effects_table(ui, &renders);
        ui.add_space(6.0);
        ui.heading("Counters");
        timings::counters_table(ui, &renders);
    }

    fn advance_screenshot(&mut self, ctx: &egui::Context) {
        let Some(shot) = &mut self.screenshot else {
            return;
        };
        ctx.request_repaint();
        let finish = |shot: &Screenshot, result: Result<(), String>| {
            *shot.result.lock().unwrap_or_else(PoisonError::into_inner) = Some(result);
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        };
        if shot
            .result
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .is_some()
        {
            return;
        }
        if let Some(e) = &self.error {
            finish(shot, Err(format!("--{}: {}", e.field, e.message)));
            return;
        }
        // Capture once the first frame has been drawn (its textures are up).
        if self.shown.is_some() && !shot.requested {
            shot.requested = true;
            let slot = Arc::clone(&shot.image);
            ctx.request_screenshot(move |image| {
                *slot.lock().unwrap_or_else(PoisonError::into_inner) = Some(image);
            });
            return;
        }
        let image = shot
            .image
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .take();
        if let Some(image) = image {
            finish(shot, save_png(&image, &shot.path));
        }
    }
}

impl eframe::App for ViewerApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.show(ui);
    }
}

fn method_controls(ui: &mut egui::Ui, id: &str, method: &mut Method) {
    egui::Grid::new(("method", id))
        .num_columns(2)
        .show(ui, |ui| {
            let label = ui.label("algorithm");
            egui::ComboBox::from_id_salt(("algorithm", id))
                .selected_text(method.algorithm.as_str())
                .show_ui(ui, |ui| {
                    for a in AlgorithmId::ALL {
                        // What this machine cannot run stays listed, greyed out, with why.
                        let why = continuum::unavailable(a);
                        ui.add_enabled_ui(why.is_none(), |ui| {
                            ui.selectable_value(&mut method.algorithm, a, a.as_str())
                        })
                        .inner
                        .on_hover_text(a.description())
                        .on_disabled_hover_text(why.unwrap_or_default());
                    }
                })
                .response
                .labelled_by(label.id);
            ui.end_row();
            let label = ui.label("oracles");
            ui.add(
                egui::TextEdit::singleline(&mut method.oracles)
                    .hint_text(
                        (method.algorithm.oracles_example()).unwrap_or("none for this algorithm"),
                    )
                    .desired_width(140.0),
            )
            .labelled_by(label.id)
            .on_hover_text(
                "explicit oracle settings on top of the algorithm's (the CLI's --oracles)",
            );
            ui.end_row();
            let label = ui.label("aa");
            egui::ComboBox::from_id_salt(("aa", id))
                .selected_text(method.aa.to_string())
                .show_ui(ui, |ui| {
                    for mode in AaMode::all() {
                        ui.selectable_value(&mut method.aa, mode, mode.to_string());
                    }
                })
                .response
                .labelled_by(label.id);
            ui.end_row();
            let label = ui.label("precision");
            egui::ComboBox::from_id_salt(("precision", id))
                .selected_text(method.precision.as_str())
                .show_ui(ui, |ui| {
                    for p in Precision::ALL {
                        ui.selectable_value(&mut method.precision, p, p.as_str());
                    }
                })
                .response
                .labelled_by(label.id);
            ui.end_row();
            let label = ui.label("textures");
            egui::ComboBox::from_id_salt(("texture filter", id))
                .selected_text(method.texture_filter.to_string())
                .show_ui(ui, |ui| {
                    for f in [
                        TextureFilter::Nearest,
                        TextureFilter::Bilinear,
                        TextureFilter::Trilinear,
                        TextureFilter::Anisotropic(4),
                        TextureFilter::Anisotropic(16),
                    ] {
                        ui.selectable_value(&mut method.texture_filter, f, f.to_string());
                    }
                })
                .response
                .labelled_by(label.id);
            ui.end_row();
        });
}

fn size_controls(ui: &mut egui::Ui, config: &mut Config) {
    let max = continuum::MAX_DIMENSION;
    ui.horizontal(|ui| {
        let width = ui.label("size");
        ui.add(egui::DragValue::new(&mut config.width).range(1..=max))
            .labelled_by(width.id);
        let by = ui.label("×");
        ui.add(egui::DragValue::new(&mut config.height).range(1..=max))
            .labelled_by(by.id);
        egui::ComboBox::from_id_salt("size presets")
            .selected_text("presets")
            .show_ui(ui, |ui| {
                for (w, h) in PRESETS {
                    if ui
                        .selectable_label(
                            (config.width, config.height) == (w, h),
                            format!("{w}×{h}"),
                        )
                        .clicked()
                    {
                        (config.width, config.height) = (w, h);
                    }
                }
            })
            .response
            .labelled_by(width.id);
    });
}

fn pixel_table(ui: &mut egui::Ui, shown: &Shown, (x, y): (u32, u32)) {
    let sides: Vec<(&str, images::PixelProbe)> = [(Side::A, "A"), (Side::B, "B")]
        .into_iter()
        .filter_map(|(side, label)| {
            Some((
                label,
                images::probe(&shown.output(side)?.framebuffer, x, y)?,
            ))
        })
        .collect();
    egui::Grid::new("pixel")
        .striped(true)
        .num_columns(1 + sides.len())
        .show(ui, |ui| {
            ui.label(format!("({x}, {y})"));
            for (label, _) in &sides {
                ui.strong(*label);
            }
            ui.end_row();
            let rows: [Row<images::PixelProbe, String>; 5] = [
                ("triangle id", |p| {
                    p.triangle_id
                        .map_or_else(|| "background".into(), |id| id.to_string())
                }),
                ("depth", |p| {
                    p.depth.map_or_else(|| "none".into(), |d| format!("{d:.6}"))
                }),
                ("edge evaluations", |p| p.edge_evals.to_string()),
                ("coverage writes", |p| p.coverage_writes.to_string()),
                ("colour", |p| {
                    format!("{:02x}{:02x}{:02x}", p.color[0], p.color[1], p.color[2])
                }),
            ];
            for (name, value) in rows {
                ui.label(name);
                for (_, p) in &sides {
                    ui.monospace(value(p));
                }
                ui.end_row();
            }
        });
}

/// The label of a render in the history: its algorithm, with any method
/// setting that is not the default.
fn history_label(out: &RenderOutput) -> String {
    let mut label = out.algorithm.as_str().to_owned();
    if out.aa != AaMode::None.to_string() {
        label += &format!(" {}", out.aa);
    }
    if out.precision != Precision::F32 {
        label += &format!(" {}", out.precision.as_str());
    }
    label
}

fn method_label(m: &Method) -> String {
    let mut label = format!("{} {} {}", m.algorithm.as_str(), m.aa, m.precision.as_str());
    if !m.oracles.trim().is_empty() {
        label += &format!(" +{}", m.oracles.trim());
    }
    label
}

fn job_label(job: &Job) -> String {
    let c = &job.config;
    format!(
        "{} {}×{} {}",
        c.scene.label(),
        c.width,
        c.height,
        method_label(&c.method)
    )
}

fn side_label(shown: &Shown, side: Side) -> String {
    match side {
        Side::A => method_label(&shown.outcome.job.config.method),
        Side::B => shown
            .outcome
            .job
            .compare
            .as_ref()
            .map(method_label)
            .unwrap_or_default(),
    }
}

fn seconds(elapsed: Option<std::time::Duration>) -> String {
    elapsed.map_or_else(String::new, |d| format!("{:.1} s", d.as_secs_f64()))
}

/// The scene and model files of a folder, sorted.
pub fn scene_files(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.is_file() && has_scene_extension(p))
        .collect();
    files.sort();
    files
}

/// Writes a screenshot as PNG.
pub fn save_png(image: &ColorImage, path: &Path) -> Result<(), String> {
    let [w, h] = image.size;
    let bytes: Vec<u8> = image.pixels.iter().flat_map(|c| c.to_array()).collect();
    let rgba = image::RgbaImage::from_raw(w as u32, h as u32, bytes)
        .ok_or_else(|| "screenshot: pixel count does not match its size".to_owned())?;
    rgba.save(path)
        .map_err(|e| format!("--screenshot: writing {}: {e}", path.display()))
}

/// The overlays, one toggle each: what the algorithm did, drawn over the image.
fn overlay_controls(ui: &mut egui::Ui, overlays: &mut Overlays) {
    ui.horizontal_wrapped(|ui| {
        ui.label("overlays");
        for (flag, name, hint) in [
            (&mut overlays.wireframe, "wireframe", "the triangles' edges"),
            (
                &mut overlays.tiles,
                "tiles",
                "the tile grid; blocks binning accepted (green), refined (yellow), rejected (red)",
            ),
            (
                &mut overlays.frusta,
                "frusta",
                "frusta rasterized (green), split (orange), culled (red)",
            ),
            (
                &mut overlays.bvh,
                "bvh",
                "the projected boxes of the BVH nodes the traversal or the ray packets entered",
            ),
        ] {
            ui.checkbox(flag, name).on_hover_text(hint);
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scenes_folder_lists_its_scene_and_model_files() {
        let dir = continuum::scene::default_scenes_dir();
        let files = scene_files(&dir);
        let names: Vec<String> = files
            .iter()
            .map(|f| SceneSource::Path(f.clone()).label())
            .collect();
        assert!(names.contains(&"bunny.toml".to_owned()), "{names:?}");
        assert!(names.windows(2).all(|w| w[0] <= w[1]), "sorted: {names:?}");
        assert!(files.iter().all(|f| has_scene_extension(f)));
        // The assets folder holds models (glb) and their licences (not listed).
        let assets = scene_files(&dir.join("assets"));
        assert!(!assets.is_empty() && assets.iter().all(|f| has_scene_extension(f)));
    }
}
