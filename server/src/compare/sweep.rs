//! What a comparison run covers: the sweep (scenes × viewports × anti-aliasing
//! modes × precisions × algorithms), from flags or a sweep file, cut into
//! cells — one scene, viewport, mode and precision with every algorithm that
//! serves it — and into disjoint shards of cells.
//!
//! A sweep file (`continuum compare --sweep sweep.toml`):
//! ```toml
//! scenes = ["teapots", "bunny", "../shared/scenes/dragon/dragon_vrip_res2.glb"]
//! algorithms = ["2dr-brute", "3dr-full", "raycast", "gpu-raster", "peer-obvhs"]  # default: all
//! viewports = ["camera", "orthographic", "parabolic"]   # default: the camera's own
//! aa = ["none", "msaa:4"]                              # default: none
//! precision = ["f32", "f64"]                           # default: f32
//! size = "1280x720"
//! repeat = 3
//! threads = [1, 2]                                     # or one count; default: all cores
//! camera = "front"                                     # default: each scene's first
//! oracles = ["frustum=128,split=16", "split=off"]      # extra rows; default: none
//! ```
//!
//! Each `oracles` setting (the words of `render --oracles`) adds a row for
//! every algorithm of the sweep it changes, labelled `ALGORITHM[SETTING]`
//! (e.g. `3dr-full[frustum=128,split=16]`), timed in the same rounds as the
//! algorithms' own settings; the printed table ends with the fastest setting
//! of each scene, cell and algorithm.
//! Unknown keys and bad values are errors naming the key.

use std::path::Path;

use super::peer::PeerId;
use continuum::{AaMode, AlgorithmId, Oracles, Precision, Viewport};
use continuum::{parse_algorithm, parse_size};
use serde::{Deserialize, Serialize};

use crate::CliError;

/// The sweep file's keys; every one optional but `scenes`.
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SweepFile {
    pub scenes: Vec<String>,
    pub algorithms: Option<Vec<String>>,
    pub viewports: Option<Vec<String>>,
    pub aa: Option<Vec<String>>,
    pub precision: Option<Vec<String>>,
    pub size: Option<String>,
    pub repeat: Option<u32>,
    pub threads: Option<Threads>,
    pub camera: Option<String>,
    /// Depth test on, off or both (`[false, true]`): off is the paper's §5
    /// GPU experiment, rendered by the GPU compute algorithms only.
    #[serde(default)]
    pub depth_test: Option<Vec<bool>>,
    /// Oracle settings, each measured as extra rows of every algorithm it changes.
    #[serde(default)]
    pub oracles: Option<Vec<String>>,
}

/// The sweep file's `threads`: one count or a list of counts, each measured.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(untagged)]
pub enum Threads {
    One(u32),
    Each(Vec<u32>),
}

/// What one row measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Entry {
    Algorithm(AlgorithmId),
    /// An algorithm with oracle settings on top of its own.
    Tuned(AlgorithmId, Oracles),
    Peer(PeerId),
}

impl Entry {
    /// The row's label: the id, or `ID[SETTING]` for a tuned algorithm.
    pub fn name(self) -> String {
        match self {
            Entry::Algorithm(a) => a.as_str().into(),
            Entry::Tuned(a, o) => format!("{a}[{o}]"),
            Entry::Peer(p) => p.as_str().into(),
        }
    }

    /// A continuum algorithm and the oracle settings it runs with (none for a peer).
    pub fn algorithm(self) -> Option<(AlgorithmId, Oracles)> {
        match self {
            Entry::Algorithm(a) => Some((a, Oracles::default())),
            Entry::Tuned(a, o) => Some((a, o)),
            Entry::Peer(_) => None,
        }
    }
}

/// The algorithms that take the traversal keys of the oracles.
const BVH_TRAVERSALS: [AlgorithmId; 3] = [
    AlgorithmId::ThreeDFrustumCull,
    AlgorithmId::ThreeDFrustumSplit,
    AlgorithmId::ThreeDFull,
];

/// The tuned entries: each setting of `settings` for every algorithm of
/// `entries` whose pipeline it changes. A setting that is not valid oracle
/// words, or that changes none of them, is an error naming `oracles`.
fn tuned_entries(entries: &[Entry], settings: &[String]) -> Result<Vec<Entry>, CliError> {
    let bad = |m: String| CliError::Usage(format!("oracles: {m}"));
    if settings.is_empty() {
        return Err(bad("an empty list".into()));
    }
    let mut tuned = Vec::new();
    for text in settings {
        let oracles = Oracles::parse(text).map_err(|e| bad(e.message))?;
        let before = tuned.len();
        // Why a BVH algorithm of the sweep refused the setting, if one did.
        let mut refused = None;
        for entry in entries {
            let Entry::Algorithm(a) = *entry else {
                continue;
            };
            let own = a.pipeline();
            match own.with_oracles(&oracles) {
                Ok(p) if p != own => tuned.push(Entry::Tuned(a, oracles)),
                Err(e) if BVH_TRAVERSALS.contains(&a) => {
                    refused.get_or_insert(format!("{a}: {}", e.message));
                }
                _ => {}
            }
        }
        if tuned.len() == before {
            let why = refused.unwrap_or_else(|| {
                let names = BVH_TRAVERSALS.map(|a| a.as_str()).join(", ");
                format!("the traversal keys need one of {names}")
            });
            return Err(bad(format!(
                "'{text}' changes none of the sweep's algorithms ({why})"
            )));
        }
    }
    Ok(tuned)
}

/// A viewport as a sweep names it: the camera's own, or one in the CLI's words
/// (bare `orthographic` frames what the camera's field of view shows at its
/// target).
#[derive(Clone, Debug, PartialEq)]
pub enum ViewportChoice {
    Camera,
    Named(String),
}

impl ViewportChoice {
    /// The camera's viewport under this choice.
    pub fn apply(&self, camera: &continuum::Camera) -> Result<Viewport, CliError> {
        match self {
            ViewportChoice::Camera => Ok(camera.viewport),
            ViewportChoice::Named(text) if text.trim() == "orthographic" => {
                Ok(Viewport::Orthographic {
                    height: camera.framing_height(),
                })
            }
            ViewportChoice::Named(text) => Viewport::parse(text, camera.viewport)
                .map_err(|e| CliError::Usage(format!("viewports: {}", e.message))),
        }
    }
}

/// A checked sweep.
#[derive(Clone, Debug)]
pub struct Sweep {
    pub scenes: Vec<String>,
    pub entries: Vec<Entry>,
    /// Algorithms left out because this machine cannot run them.
    pub not_run: Vec<NotRun>,
    pub viewports: Vec<ViewportChoice>,
    pub aa: Vec<AaMode>,
    /// f32 first: the other precisions' rows relate to its times.
    pub precisions: Vec<Precision>,
    pub size: (u32, u32),
    pub repeat: u32,
    /// Worker-thread counts, each measured over every cell, smallest first
    /// (empty: one run on all cores).
    pub threads: Vec<usize>,
    pub camera: Option<String>,
    /// Depth test settings, each measured (on only, unless the file says).
    pub depth_tests: Vec<bool>,
    /// Is any mode not `none` (then every scene gets an `ssaa:256` reference)?
    pub with_reference: bool,
    /// The file's text form (for results.json).
    pub file: SweepFile,
}

/// Parses a sweep file; errors name the file and the key.
pub fn read_sweep_file(path: &Path) -> Result<SweepFile, CliError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| CliError::Usage(format!("--sweep: {}: {e}", path.display())))?;
    toml::from_str(&text).map_err(|e| CliError::Usage(format!("--sweep: {}: {e}", path.display())))
}

impl Sweep {
    /// Checks every key of `file`; `builtin` lists the scenes when it names none.
    pub fn new(
        file: SweepFile,
        builtin: impl FnOnce() -> Result<Vec<String>, CliError>,
    ) -> Result<Sweep, CliError> {
        let bad = |key: &str, m: String| CliError::Usage(format!("{key}: {m}"));
        let scenes = if file.scenes.is_empty() {
            builtin()?
        } else {
            file.scenes.clone()
        };
        let (mut entries, not_run) = parse_entries(file.algorithms.as_deref().unwrap_or_default())?;
        if let Some(settings) = &file.oracles {
            let tuned = tuned_entries(&entries, settings)?;
            entries.extend(tuned);
        }
        let viewports = match &file.viewports {
            None => vec![ViewportChoice::Camera],
            Some(list) if list.is_empty() => return Err(bad("viewports", "is empty".into())),
            Some(list) => list
                .iter()
                .map(|v| {
                    if v == "camera" {
                        return Ok(ViewportChoice::Camera);
                    }
                    // The words now; bare `orthographic` is framed per camera.
                    Viewport::parse(v, Viewport::Orthographic { height: 1.0 })
                        .map_err(|e| bad("viewports", e.message))?;
                    Ok(ViewportChoice::Named(v.clone()))
                })
                .collect::<Result<_, CliError>>()?,
        };
        let aa = match &file.aa {
            None => vec![AaMode::None],
            Some(list) => list
                .iter()
                .map(|s| AaMode::parse(s).map_err(|e| bad("aa", e.message)))
                .collect::<Result<Vec<_>, _>>()?,
        };
        let precisions: Vec<Precision> = match &file.precision {
            None => vec![Precision::F32],
            Some(list) => {
                let parsed = list
                    .iter()
                    .map(|s| Precision::parse(s).map_err(|e| bad("precision", e.message)))
                    .collect::<Result<Vec<_>, _>>()?;
                Precision::ALL
                    .into_iter()
                    .filter(|p| parsed.contains(p))
                    .collect()
            }
        };
        if aa.is_empty() || precisions.is_empty() {
            return Err(bad("aa/precision", "an empty list".into()));
        }
        let size = match &file.size {
            None => (1280, 720),
            Some(s) => parse_size(s).map_err(|e| bad("size", e.message))?,
        };
        let repeat = file.repeat.unwrap_or(3);
        if !(1..=1000).contains(&repeat) {
            return Err(bad("repeat", format!("{repeat} is not in 1..=1000")));
        }
        let mut threads = match &file.threads {
            None => Vec::new(),
            Some(Threads::One(t)) => vec![*t],
            Some(Threads::Each(list)) if list.is_empty() => {
                return Err(bad("threads", "an empty list".into()));
            }
            Some(Threads::Each(list)) => list.clone(),
        };
        if let Some(t) = threads.iter().find(|t| !(1..=1024).contains(*t)) {
            return Err(bad("threads", format!("{t} is not in 1..=1024")));
        }
        threads.sort_unstable();
        threads.dedup();
        let depth_tests = match &file.depth_test {
            None => vec![true],
            Some(list) if list.is_empty() => return Err(bad("depth_test", "an empty list".into())),
            Some(list) => list.clone(),
        };
        Ok(Sweep {
            depth_tests,
            scenes,
            entries,
            not_run,
            viewports,
            with_reference: aa.iter().any(|&m| m != AaMode::None),
            aa,
            precisions,
            size,
            repeat,
            threads: threads.into_iter().map(|t| t as usize).collect(),
            camera: file.camera.clone(),
            file,
        })
    }

    /// Every cell in plan order: scene, viewport, mode, precision, depth test.
    pub fn cells(&self) -> Vec<Cell> {
        let mut cells = Vec::new();
        for scene in &self.scenes {
            for viewport in &self.viewports {
                for &aa in &self.aa {
                    for &precision in &self.precisions {
                        for &depth_test in &self.depth_tests {
                            cells.push(Cell {
                                index: cells.len(),
                                scene: scene.clone(),
                                viewport: viewport.clone(),
                                aa,
                                precision,
                                depth_test,
                            });
                        }
                    }
                }
            }
        }
        cells
    }
}

/// One scene, viewport, anti-aliasing mode and precision: its algorithms run
/// together (their agreement is decided within the cell).
#[derive(Clone, Debug, PartialEq)]
pub struct Cell {
    pub index: usize,
    pub scene: String,
    pub viewport: ViewportChoice,
    pub aa: AaMode,
    pub precision: Precision,
    pub depth_test: bool,
}

/// `I/N`: part `I` (0-based, as Kubernetes' `JOB_COMPLETION_INDEX`) of `N`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Shard {
    pub index: u32,
    pub count: u32,
}

impl Shard {
    pub fn parse(s: &str) -> Result<Shard, String> {
        let bad = || format!("'{s}' is not I/N with 0 <= I < N, e.g. 0/4");
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count): (u32, u32) = (
            i.trim().parse().map_err(|_| bad())?,
            n.trim().parse().map_err(|_| bad())?,
        );
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }

    /// Does this shard run `cell`? Cells are dealt round-robin, so shards get
    /// a mix of scenes and modes.
    pub fn takes(self, cell: &Cell) -> bool {
        cell.index % self.count as usize == self.index as usize
    }
}

/// An algorithm this machine cannot run, left out of a sweep that did not name it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NotRun {
    pub algorithm: String,
    pub reason: String,
}

/// Algorithm ids and peers; empty means every algorithm this machine can run
/// (the others come back as [`NotRun`]) and every peer this binary was built
/// with. A named algorithm that cannot run here is an error.
pub fn parse_entries(names: &[String]) -> Result<(Vec<Entry>, Vec<NotRun>), CliError> {
    if names.is_empty() {
        let mut all = Vec::new();
        let mut not_run = Vec::new();
        for a in AlgorithmId::ALL {
            match continuum::unavailable(a) {
                None => all.push(Entry::Algorithm(a)),
                Some(reason) => not_run.push(NotRun {
                    algorithm: a.as_str().into(),
                    reason,
                }),
            }
        }
        all.extend(
            PeerId::ALL
                .into_iter()
                .filter(|p| p.available())
                .map(Entry::Peer),
        );
        return Ok((all, not_run));
    }
    let entries = names
        .iter()
        .map(|n| match PeerId::parse(n) {
            Some(p) if !p.available() => Err(CliError::Usage(format!(
                "algorithms: {n} needs continuum built with --features embree (and Debian's libembree-dev)"
            ))),
            Some(p) => Ok(Entry::Peer(p)),
            None => {
                let a = parse_algorithm(n).map_err(|e| {
                    CliError::Usage(format!(
                        "algorithms: {}; peers are: {}",
                        e.message,
                        PeerId::ALL.map(|p| p.as_str()).join(", ")
                    ))
                })?;
                match continuum::unavailable(a) {
                    Some(reason) => Err(CliError::Usage(format!(
                        "algorithms: {n} cannot run on this machine: {reason}"
                    ))),
                    None => Ok(Entry::Algorithm(a)),
                }
            }
        })
        .collect::<Result<_, _>>()?;
    Ok((entries, Vec::new()))
}
