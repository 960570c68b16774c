//! The one test matrix: scenes × cameras × viewports × anti-aliasing modes ×
//! precisions × algorithms, each cell rendered once if the renderer's
//! capability check ([`continuum::check`]) says the algorithm serves it. A
//! test states its matrix, gets every rendered cell, and learns how many
//! there were (and a matrix that renders nothing fails), so no test passes
//! by checking nothing.

use std::collections::HashMap;

use continuum::{
    AaMode, AlgorithmId, Camera, Oracles, Precision, PreparedScene, RenderOutput, RenderRequest,
    Viewport, render,
};

use crate::{builtin_scenes, prepared};

/// Which cameras of each scene a matrix renders through.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cameras {
    /// The scene's first camera.
    First,
    /// Every camera the scene names.
    All,
    /// Every camera the scene names and the framing `default` one.
    AllAndDefault,
    /// The scene's camera of this name.
    Named(&'static str),
}

/// Which viewport a cell looks through.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ViewportChoice {
    /// The camera's own.
    Own,
    /// This one.
    Is(Viewport),
    /// Orthographic, framing what the camera shows at its target
    /// ([`orthographic_for`]).
    Orthographic,
}

/// An orthographic view that frames what a perspective camera frames at its
/// target (a 60° field of view standing in for other cameras').
pub fn orthographic_for(camera: &Camera) -> Viewport {
    let fov = match camera.viewport {
        Viewport::Perspective { fov_y_deg } => fov_y_deg,
        _ => 60.0,
    };
    let distance = (camera.target - camera.eye).length();
    Viewport::Orthographic {
        height: 2.0 * distance * (fov.to_radians() * 0.5).tan(),
    }
}

/// A matrix of renders; [`Matrix::new`] is every built-in scene's first
/// camera, its own viewport, no anti-aliasing, f32, every CPU algorithm with
/// its own oracle settings, at 64×48.
#[derive(Clone, Debug)]
pub struct Matrix {
    pub scenes: Vec<String>,
    pub cameras: Cameras,
    pub viewports: Vec<ViewportChoice>,
    pub aa: Vec<AaMode>,
    pub precisions: Vec<Precision>,
    pub algorithms: Vec<AlgorithmId>,
    /// Oracle settings each algorithm is rendered with (cells whose settings
    /// the algorithm does not take are left out).
    pub oracles: Vec<Oracles>,
    pub size: (u32, u32),
}

/// One rendered cell.
#[derive(Debug)]
pub struct Cell<'a> {
    pub scene: &'a str,
    pub prepared: &'a PreparedScene,
    pub request: &'a RenderRequest,
    pub output: &'a RenderOutput,
}

impl Cell<'_> {
    /// The cell without its algorithm and oracles, plus the algorithm's
    /// family: the key under which renders must agree bit for bit.
    pub fn family_key(&self) -> String {
        let r = self.request;
        format!(
            "{} {} {} {} {} {:?}",
            self.scene,
            r.camera.name,
            r.camera.viewport,
            r.aa,
            r.precision,
            r.algorithm.family()
        )
    }

    /// Names the cell in failure messages.
    pub fn label(&self) -> String {
        let r = self.request;
        format!(
            "{}/{} {} {} {} {} {}",
            self.scene, r.camera.name, r.camera.viewport, r.aa, r.precision, r.algorithm, r.oracles
        )
    }
}

impl Default for Matrix {
    fn default() -> Matrix {
        Matrix::new()
    }
}

impl Matrix {
    pub fn new() -> Matrix {
        Matrix {
            scenes: builtin_scenes(),
            cameras: Cameras::First,
            viewports: vec![ViewportChoice::Own],
            aa: vec![AaMode::None],
            precisions: vec![Precision::F32],
            algorithms: AlgorithmId::CPU.to_vec(),
            oracles: vec![Oracles::default()],
            size: (64, 48),
        }
    }

    /// Renders every cell an algorithm serves, in order (scene, camera,
    /// viewport, mode, precision, algorithm, oracles), handing each to `check`;
    /// returns how many were rendered and fails when none was. Cells the
    /// capability check refuses (an algorithm that does not serve the
    /// viewport or precision, `gpu-raster` on see-through materials) are
    /// left out; an algorithm this machine cannot run is a failure.
    pub fn run(&self, mut check: impl FnMut(&Cell)) -> usize {
        let rendered: usize = self
            .scenes
            .iter()
            .map(|name| self.render_scene(name, &prepared(name), &mut check))
            .sum();
        assert!(rendered > 0, "the matrix rendered nothing: {self:?}");
        rendered
    }

    /// [`Matrix::run`] on one scene a test built itself (named `name` in
    /// messages) instead of [`Matrix::scenes`].
    pub fn run_on(&self, name: &str, scene: &PreparedScene, mut check: impl FnMut(&Cell)) -> usize {
        let rendered = self.render_scene(name, scene, &mut check);
        assert!(
            rendered > 0,
            "the matrix rendered nothing of {name}: {self:?}"
        );
        rendered
    }

    fn render_scene(
        &self,
        name: &str,
        scene: &PreparedScene,
        check: &mut impl FnMut(&Cell),
    ) -> usize {
        let mut rendered = 0;
        let cameras: Vec<Camera> = match self.cameras {
            Cameras::First => vec![scene.scene.first_camera()],
            Cameras::All => scene.scene.cameras.clone(),
            Cameras::AllAndDefault => scene.scene.all_cameras(),
            Cameras::Named(camera) => vec![
                scene
                    .scene
                    .camera(camera)
                    .unwrap_or_else(|e| panic!("{name}: {e}")),
            ],
        };
        for camera in &cameras {
            for choice in &self.viewports {
                let viewport = match *choice {
                    ViewportChoice::Own => camera.viewport,
                    ViewportChoice::Is(v) => v,
                    ViewportChoice::Orthographic => orthographic_for(camera),
                };
                let camera = Camera {
                    viewport,
                    ..camera.clone()
                };
                for &aa in &self.aa {
                    for &precision in &self.precisions {
                        for (&algorithm, &oracles) in self
                            .algorithms
                            .iter()
                            .flat_map(|a| self.oracles.iter().map(move |o| (a, o)))
                        {
                            let (w, h) = self.size;
                            let request = RenderRequest {
                                aa,
                                precision,
                                oracles,
                                ..RenderRequest::new(algorithm, camera.clone(), w, h)
                            };
                            // A test needs what it names: an algorithm this
                            // machine cannot run fails loudly, never skips.
                            if let Some(why) = continuum::unavailable(algorithm) {
                                panic!("{algorithm} cannot run here: {why}");
                            }
                            if continuum::check(&request, Some(scene)).is_err() {
                                continue;
                            }
                            let output = render(scene, &request).unwrap_or_else(|e| {
                                panic!("{name}/{} {algorithm}: {e}", camera.name)
                            });
                            rendered += 1;
                            check(&Cell {
                                scene: name,
                                prepared: scene,
                                request: &request,
                                output: &output,
                            });
                        }
                    }
                }
            }
        }
        rendered
    }

    /// [`Matrix::run`], handing each cell to `check` with the first render
    /// of its [`Cell::family_key`] (the one the family must agree with;
    /// `None` for that first render itself).
    pub fn run_against_first(&self, mut check: impl FnMut(&Cell, Option<&RenderOutput>)) -> usize {
        let mut first: HashMap<String, RenderOutput> = HashMap::new();
        self.run(|cell| {
            let key = cell.family_key();
            check(cell, first.get(&key));
            first.entry(key).or_insert_with(|| cell.output.clone());
        })
    }

    /// Runs the matrix and asserts that within each family every algorithm
    /// renders what the first one did (every buffer hash and the samples'
    /// digest); returns how many renders were compared with a first one.
    pub fn assert_families_agree(&self) -> usize {
        let mut compared = 0;
        self.run_against_first(|cell, first| {
            if let Some(first) = first {
                let label = cell.label();
                assert_eq!(
                    cell.output.hashes(),
                    first.hashes(),
                    "{label} differs from {}",
                    first.algorithm
                );
                compared += 1;
            }
        });
        compared
    }
}
