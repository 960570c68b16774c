//! The continuum as wgpu compute pipelines (paper §5 and its future work):
//! `gpu-2dr`, `gpu-2dr-homogeneous`, `gpu-3dr` (a setup kernel, then one
//! thread per triangle over its bounding box) and `gpu-3dr-binned` (setup →
//! bin → prefix sum → one workgroup per tile). The kernels are in
//! `compute.wgsl`, `brute.wgsl`, `binned.wgsl`; this module dispatches them,
//! times them and reads back per sample the triangle id and depth, per sample
//! the coverage writes and per pixel the edge evaluations, which the CPU then
//! resolves and shades as it does every algorithm's samples.
//!
//! Visibility needs no depth attachment: one 64-bit atomic per sample holds
//! `(w bits << 32) | id` (`visibility64.wgsl`, where the adapter offers
//! `SHADER_INT64_ATOMIC_MIN_MAX`), or two 32-bit passes (`visibility32.wgsl`).
//! Both keep the complement with `atomicMax`, so a buffer the driver zeroes
//! is an empty one.

use std::collections::HashMap;
use std::sync::OnceLock;
use std::time::Instant;

use wgpu::util::DeviceExt;

use super::{Gpu, GpuError, GpuMesh, UNCAPTURED};
use crate::aa::SamplePattern;
use crate::camera::View;
use crate::clip::GUARD_BAND;
use crate::pipeline::ComputeKind;
use crate::stats::GpuTimes;

/// How the brute-force kernels keep the nearest sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum GpuAtomics {
    /// One 64-bit `atomicMin` per sample where the adapter has it, else
    /// [`GpuAtomics::TwoPass`].
    Auto,
    /// Two passes of 32-bit atomics (depth, then the smallest id at it).
    TwoPass,
}

/// The words of one set-up triangle on the GPU (`Tri` in `compute.wgsl`).
pub(crate) type TriWords = [u32; 28];

/// What a compute render read back, layer-major per stored sample.
#[derive(Debug, Default)]
pub(crate) struct ComputeSamples {
    pub triangle_id: Vec<u32>,
    pub depth: Vec<f32>,
    pub coverage_writes: Vec<u32>,
    /// Per pixel.
    pub edge_evals: Vec<u32>,
    /// Triangles (2D: pieces) set up with a box on screen.
    pub setups: u64,
    /// Triangles the CPU set up (2D: clipped; 3D and homogeneous: of
    /// unsure orientation).
    pub on_cpu: u64,
    /// (triangle id, layer-major sample index) pairs whose coverage f32 was
    /// not sure of: the CPU decides them exactly and merges the covered
    /// ones (their depth and id are not in `triangle_id`, `depth`,
    /// `coverage_writes`; their edge evaluations are in `edge_evals`).
    pub unsure: Vec<[u32; 2]>,
    /// Binned: tile tests, tiles accepted whole, tiles rejected.
    pub tiles: [u64; 3],
    /// Host milliseconds from submit to a finished device poll: setup
    /// (with the CPU's clipping), binning, raster.
    pub wall: [f64; 3],
    pub times: GpuTimes,
}

/// Side of the binned pipeline's tiles in pixels (`TILE` in compute.wgsl).
const TILE: u32 = 8;
/// Boxes of more pixels are rasterized by workgroups (`BIG_AREA`).
const BIG_AREA: u32 = 4096;
/// Side of the image chunks a big triangle's workgroups take (`CHUNK`).
const CHUNK: u32 = 64;
/// Tile-list entries per `raster_binned` dispatch (`SEGMENT` in binned.wgsl).
const SEGMENT: u32 = 16_384;
/// Words of the counters buffer.
const COUNTERS: u64 = 16;
/// Room first made for the samples left to the CPU's exact decision, in
/// (id, sample) pairs: a few per thousand samples near edges at most on
/// the built-in scenes; a render that finds more runs again with room for
/// all.
const UNSURE_ROOM: u32 = 1 << 16;

/// `box_chunks` of compute.wgsl: the chunks of `CHUNK²` pixels or of 8×8
/// tiles a box `[x0, y0, x1, y1)` spans, whichever is more.
fn box_chunks([x0, y0, x1, y1]: [u32; 4]) -> u32 {
    let pixels = (x1 - x0).div_ceil(CHUNK) * (y1 - y0).div_ceil(CHUNK);
    let tiles = |lo: u32, hi: u32| (hi - 1) / TILE - lo / TILE + 1;
    pixels.max(tiles(x0, x1).div_ceil(8) * tiles(y0, y1).div_ceil(8))
}

/// Bindings of the shader modules: compute.wgsl's eight, then the raster's.
const SHARED_BINDINGS: u32 = 8;

/// The three modules: brute force with 64-bit or 32-bit visibility, binned.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Module {
    Brute64,
    Brute32,
    Binned,
}

impl Module {
    fn source(self) -> String {
        let common = include_str!("compute.wgsl");
        match self {
            Module::Brute64 => [
                common,
                include_str!("brute.wgsl"),
                include_str!("visibility64.wgsl"),
            ]
            .concat(),
            Module::Brute32 => [
                common,
                include_str!("brute.wgsl"),
                include_str!("visibility32.wgsl"),
            ]
            .concat(),
            Module::Binned => [common, include_str!("binned.wgsl")].concat(),
        }
    }

    fn bindings(self) -> u32 {
        SHARED_BINDINGS
            + match self {
                Module::Brute64 => 3,
                Module::Brute32 => 4,
                Module::Binned => 8,
            }
    }

    fn entry_points(self) -> &'static [&'static str] {
        match self {
            Module::Brute64 | Module::Brute32 => &[
                "setup_2d",
                "setup_homogeneous",
                "setup_3d",
                "raster_brute",
                "raster_big",
            ],
            Module::Binned => &["setup_3d", "bin", "bin_big", "scan", "raster_binned"],
        }
    }
}

/// A module's pipelines, by entry point, and their one bind group layout.
#[derive(Debug)]
pub(crate) struct Kernels {
    layout: wgpu::BindGroupLayout,
    pipelines: HashMap<&'static str, wgpu::ComputePipeline>,
}

/// The kernels of each module, compiled on first use.
#[derive(Debug, Default)]
pub(crate) struct ComputeCache {
    modules: [OnceLock<Result<Kernels, GpuError>>; 3],
}

/// The params uniform (`Params` in compute.wgsl): 272 bytes.
/// `flags`: the depth test off, the first big triangle, the list segment.
fn params(
    view: &View,
    pattern: &SamplePattern,
    count: u32,
    tiles: [u32; 2],
    pass: u32,
    flags: [u32; 4],
) -> Vec<u8> {
    let mut floats: Vec<f32> = Vec::with_capacity(48);
    for v in [
        view.eye,
        view.right,
        view.up,
        view.forward,
        view.d0,
        view.dx,
        view.dy,
        view.o0,
        view.ox,
        view.oy,
    ] {
        floats.extend([v.x, v.y, v.z, 0.0]);
    }
    floats.extend([view.half_x, view.half_y, view.near, GUARD_BAND]);
    let span = pattern.span;
    floats.extend([span.lo[0], span.lo[1], span.hi[0], span.hi[1]]);
    for s in 0..4 {
        let [x, y] = pattern.positions.get(s).copied().unwrap_or([0.5, 0.5]);
        floats.extend([x, y]);
    }
    let mut bytes: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
    let words = [
        view.width,
        view.height,
        count,
        pattern.stored as u32,
        u32::from(view.is_orthographic()),
        pass,
        tiles[0],
        tiles[1],
        flags[0],
        flags[1],
        flags[2],
        flags[3],
    ];
    bytes.extend(words.iter().flat_map(|w| w.to_le_bytes()));
    bytes
}

/// Workgroups of 64 threads for `n` items, as a 2D grid within the
/// dispatch limit (`thread_index` in compute.wgsl undoes it).
fn groups_for(n: u32) -> (u32, u32) {
    let groups = n.div_ceil(64).max(1);
    let x = groups.min(65_535);
    (x, groups.div_ceil(x))
}

/// Timestamps around each pass where the adapter has them (host wall time
/// per submission otherwise, kept by the caller).
struct Clock {
    queries: Option<wgpu::QuerySet>,
    /// Per pass its stage: 0 setup, 1 binning, 2 raster.
    passes: Vec<usize>,
}

/// Passes a render times with timestamps (more: host wall time instead).
const MAX_PASSES: u32 = 256;

impl Clock {
    fn new(gpu: &Gpu) -> Clock {
        let queries = gpu.timestamps.then(|| {
            gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("stage times"),
                ty: wgpu::QueryType::Timestamp,
                count: MAX_PASSES * 2,
            })
        });
        Clock {
            queries,
            passes: Vec::new(),
        }
    }

    /// One compute pass of `stage` dispatching `pipeline` with `bind`.
    fn pass(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        stage: usize,
        pipeline: &wgpu::ComputePipeline,
        bind: &wgpu::BindGroup,
        groups: (u32, u32),
    ) {
        let index = self.passes.len() as u32;
        self.passes.push(stage);
        let timestamp_writes = match &self.queries {
            Some(set) if index < MAX_PASSES => Some(wgpu::ComputePassTimestampWrites {
                query_set: set,
                beginning_of_pass_write_index: Some(2 * index),
                end_of_pass_write_index: Some(2 * index + 1),
            }),
            _ => None,
        };
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: None,
            timestamp_writes,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, bind, &[]);
        pass.dispatch_workgroups(groups.0, groups.1, 1);
    }

    /// Resolves the timestamps into a buffer (with the last submission), when
    /// every pass has them.
    fn resolve(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
    ) -> Option<(wgpu::Buffer, u32)> {
        let set = self.queries.as_ref()?;
        let count = self.passes.len() as u32 * 2;
        if count > MAX_PASSES * 2 {
            return None;
        }
        let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamps"),
            size: u64::from(count) * 8,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        encoder.resolve_query_set(set, 0..count, &buffer, 0);
        Some((buffer, count))
    }

    /// Milliseconds per stage from the resolved timestamps.
    fn stages(
        &self,
        gpu: &Gpu,
        resolved: Option<(wgpu::Buffer, u32)>,
    ) -> Result<Option<[f64; 3]>, GpuError> {
        let Some((buffer, count)) = resolved else {
            return Ok(None);
        };
        let r = gpu.read(&[(&buffer, u64::from(count) * 8)])?;
        let ticks: Vec<u64> = r[0]
            .chunks_exact(8)
            .map(|c| u64::from_le_bytes(c.try_into().expect("8 bytes")))
            .collect();
        let period = f64::from(gpu.queue.get_timestamp_period()) * 1e-6;
        let mut stage = [0.0; 3];
        for (k, &s) in self.passes.iter().enumerate() {
            stage[s] += ticks[2 * k + 1].saturating_sub(ticks[2 * k]) as f64 * period;
        }
        Ok(Some(stage))
    }
}

impl Gpu {
    /// The kernels of `module`, compiled once per process.
    fn kernels(&self, module: Module) -> Result<&Kernels, GpuError> {
        let slot = match module {
            Module::Brute64 => 0,
            Module::Brute32 => 1,
            Module::Binned => 2,
        };
        self.compute.modules[slot]
            .get_or_init(|| self.compile(module))
            .as_ref()
            .map_err(Clone::clone)
    }

    fn compile(&self, module: Module) -> Result<Kernels, GpuError> {
        let device = &self.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("continuum compute"),
            source: wgpu::ShaderSource::Wgsl(module.source().into()),
        });
        let entries: Vec<wgpu::BindGroupLayoutEntry> = (0..module.bindings())
            .map(|binding| wgpu::BindGroupLayoutEntry {
                binding,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty: match binding {
                        0 => wgpu::BufferBindingType::Uniform,
                        1..=3 => wgpu::BufferBindingType::Storage { read_only: true },
                        _ => wgpu::BufferBindingType::Storage { read_only: false },
                    },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            })
            .collect();
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("compute"),
            entries: &entries,
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("compute"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipelines = module
            .entry_points()
            .iter()
            .map(|&entry| {
                let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(entry),
                    layout: Some(&pipeline_layout),
                    module: &shader,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    cache: None,
                });
                (entry, pipeline)
            })
            .collect();
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(GpuError::Failed(format!(
                "the adapter {} refused the compute kernels: {e}",
                self.adapter
            )));
        }
        Ok(Kernels { layout, pipelines })
    }

    /// A storage buffer holding `bytes` (at least 16 bytes).
    pub(super) fn storage(&self, label: &str, bytes: &[u8]) -> wgpu::Buffer {
        let mut contents = bytes.to_vec();
        contents.resize(bytes.len().max(16), 0);
        self.device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: &contents,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
            })
    }

    /// A zeroed storage buffer of `size` bytes (at least 16), or an error
    /// naming `field` when it is beyond the adapter's limits.
    fn zeroed(
        &self,
        label: &str,
        size: u64,
        field: &'static str,
    ) -> Result<wgpu::Buffer, GpuError> {
        let limits = self.device.limits();
        let max = limits
            .max_buffer_size
            .min(limits.max_storage_buffer_binding_size);
        if size > max {
            return Err(GpuError::BufferTooLarge {
                what: label.to_string(),
                bytes: size,
                max,
                field,
            });
        }
        Ok(self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: size.max(16),
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        }))
    }

    /// Submits `encoder`, waits for the device and reports an error raised
    /// in the meantime.
    fn finish(&self, encoder: wgpu::CommandEncoder) -> Result<(), GpuError> {
        self.queue.submit([encoder.finish()]);
        self.wait()
    }

    /// Waits for the device and reports an error raised in the meantime.
    fn wait(&self) -> Result<(), GpuError> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Failed(e.to_string()))?;
        if let Some(e) = UNCAPTURED.lock().unwrap_or_else(|p| p.into_inner()).take() {
            return Err(GpuError::Failed(e));
        }
        Ok(())
    }

    /// Copies the first `bytes` of each buffer to host memory and reads them.
    fn read(&self, buffers: &[(&wgpu::Buffer, u64)]) -> Result<Vec<Vec<u8>>, GpuError> {
        let mut encoder = self.device.create_command_encoder(&Default::default());
        let staging: Vec<wgpu::Buffer> = buffers
            .iter()
            .map(|&(buffer, bytes)| {
                let size = bytes.next_multiple_of(4).max(4);
                let s = self.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("readback"),
                    size,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                encoder.copy_buffer_to_buffer(buffer, 0, &s, 0, size);
                s
            })
            .collect();
        self.queue.submit([encoder.finish()]);
        for s in &staging {
            s.map_async(wgpu::MapMode::Read, .., |_| {});
        }
        self.wait()?;
        staging
            .iter()
            .zip(buffers)
            .map(|(s, &(_, bytes))| {
                let mapped = s
                    .get_mapped_range(..)
                    .map_err(|e| GpuError::Failed(e.to_string()))?;
                Ok(mapped[..bytes as usize].to_vec())
            })
            .collect()
    }

    /// Renders `view` of `mesh` with the compute pipeline `kind`: setup,
    /// (binning,) raster, read-back. `cpu_setup` sets up, on the CPU, the
    /// triangles the setup kernel listed: for 2D the pieces of those that
    /// cross the near plane or the guard band (as `2dr-brute` clips them),
    /// for 3D and homogeneous those whose orientation f32 cannot be sure of
    /// (with the exact sign, as the CPU's setups take it).
    pub(crate) fn compute(
        &self,
        mesh: &GpuMesh,
        kind: ComputeKind,
        view: &View,
        pattern: &SamplePattern,
        (atomics, depth_test): (GpuAtomics, bool),
        cpu_setup: &dyn Fn(&[u32]) -> Vec<TriWords>,
    ) -> Result<ComputeSamples, GpuError> {
        self.fits(view)?;
        let _one_at_a_time = self.lock.lock().unwrap_or_else(|e| e.into_inner());
        let mut room = UNSURE_ROOM;
        loop {
            let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
            let result = self.compute_scoped(
                mesh,
                kind,
                view,
                pattern,
                (atomics, depth_test, room),
                cpu_setup,
            );
            if let Some(e) = pollster::block_on(scope.pop()) {
                return Err(GpuError::Failed(e.to_string()));
            }
            match result? {
                Ok(samples) => return Ok(samples),
                // More unsure samples than room: again, with room for all.
                Err(needed) => room = needed,
            }
        }
    }

    fn compute_scoped(
        &self,
        mesh: &GpuMesh,
        kind: ComputeKind,
        view: &View,
        pattern: &SamplePattern,
        (atomics, depth_test, room): (GpuAtomics, bool, u32),
        cpu_setup: &dyn Fn(&[u32]) -> Vec<TriWords>,
    ) -> Result<Result<ComputeSamples, u32>, GpuError> {
        let module = match kind {
            ComputeKind::ThreeDBinned => Module::Binned,
            _ if atomics == GpuAtomics::Auto && self.int64_atomics => Module::Brute64,
            _ => Module::Brute32,
        };
        let kernels = self.kernels(module)?;
        let n = mesh.triangles;
        let pixels = u64::from(view.width) * u64::from(view.height);
        let samples = pixels * pattern.stored as u64;
        let tiles = [view.width.div_ceil(TILE), view.height.div_ceil(TILE)];
        // 1. Buffers: the set-up triangles, counters, the lists of what the
        //    CPU finishes and of big triangles, the module's own.
        let mut tris = self.zeroed("triangles", u64::from(n) * 112, "scene")?;
        let counters = self.zeroed("counters", 4 * COUNTERS, "scene")?;
        let setup_list = self.zeroed("triangles for the CPU", u64::from(n) * 4, "scene")?;
        let unsure_list = self.zeroed("samples for the CPU", u64::from(room) * 8, "size")?;
        let mut big = self.zeroed("big triangles", u64::from(n) * 4, "scene")?;
        let mut own: Vec<wgpu::Buffer> = match module {
            Module::Brute64 => vec![
                self.zeroed("edge evaluations", pixels * 4, "size")?,
                self.zeroed("coverage writes", samples * 4, "size")?,
                self.zeroed("visible", samples * 8, "size")?,
            ],
            Module::Brute32 => vec![
                self.zeroed("edge evaluations", pixels * 4, "size")?,
                self.zeroed("coverage writes", samples * 4, "size")?,
                self.zeroed("nearest", samples * 4, "size")?,
                self.zeroed("ids", samples * 4, "size")?,
            ],
            Module::Binned => {
                let t = u64::from(tiles[0]) * u64::from(tiles[1]);
                vec![
                    self.zeroed("tile counts", t * 4, "size")?,
                    self.zeroed("tile offsets", (t + 1) * 4, "size")?,
                    self.zeroed("tile cursor", t * 4, "size")?,
                    // The list, made once its length is known (below).
                    self.zeroed("tile list", 4, "size")?,
                    self.zeroed("depth", samples * 4, "size")?,
                    self.zeroed("ids", samples * 4, "size")?,
                    self.zeroed("coverage writes", samples * 4, "size")?,
                    self.zeroed("edge evaluations", pixels * 4, "size")?,
                ]
            }
        };
        let mut dispatch = Dispatcher {
            gpu: self,
            kernels,
            clock: Clock::new(self),
            wall: [0.0; 3],
            params: Params {
                view,
                pattern,
                depth_test,
                tiles,
                room,
            },
        };
        let mut out = ComputeSamples::default();

        // 2. Setup; what the CPU sets up joins the triangles.
        let setup = match kind {
            ComputeKind::TwoD => "setup_2d",
            ComputeKind::Homogeneous => "setup_homogeneous",
            ComputeKind::ThreeD | ComputeKind::ThreeDBinned => "setup_3d",
        };
        let shared = Shared {
            mesh,
            counters: &counters,
            cpu_list: &setup_list,
        };
        let mut encoder = self.device.create_command_encoder(&Default::default());
        let bind = dispatch.bind(&shared, &tris, &big, &own, [n, 0, 0, 0]);
        dispatch.pass(&mut encoder, 0, setup, &bind, groups_for(n));
        dispatch.submit(0, encoder)?;
        let mut count = self.counters(&counters)?;
        let mut records = n;
        out.setups = u64::from(count[0]);
        if count[1] > 0 {
            let listed = self.read(&[(&setup_list, u64::from(count[1]) * 4)])?;
            let ids = words(&listed[0]);
            out.on_cpu = ids.len() as u64;
            let start = Instant::now();
            let pieces = cpu_setup(&ids);
            dispatch.wall[0] += start.elapsed().as_secs_f64() * 1e3;
            out.setups += pieces.len() as u64;
            if !pieces.is_empty() {
                // The pieces after the triangles, the big ones on the big list.
                let m = pieces.len() as u32;
                let all = self.zeroed("triangles and pieces", u64::from(n + m) * 112, "scene")?;
                let longer = self.zeroed("big triangles", u64::from(n + m) * 4, "scene")?;
                let mut encoder = self.device.create_command_encoder(&Default::default());
                encoder.copy_buffer_to_buffer(&tris, 0, &all, 0, u64::from(n) * 112);
                encoder.copy_buffer_to_buffer(&big, 0, &longer, 0, u64::from(n) * 4);
                self.queue.submit([encoder.finish()]);
                let bytes: Vec<u8> = pieces
                    .iter()
                    .flatten()
                    .flat_map(|w| w.to_le_bytes())
                    .collect();
                self.queue.write_buffer(&all, u64::from(n) * 112, &bytes);
                let mut big_pieces: Vec<u8> = Vec::new();
                for (j, p) in pieces.iter().enumerate() {
                    let [x0, y0, x1, y1] =
                        [p[25] & 0xffff, p[25] >> 16, p[26] & 0xffff, p[26] >> 16];
                    if (x1 - x0) * (y1 - y0) > BIG_AREA {
                        big_pieces.extend((n + j as u32).to_le_bytes());
                        count[8] = count[8].max(box_chunks([x0, y0, x1, y1]));
                    }
                }
                self.queue
                    .write_buffer(&longer, u64::from(count[6]) * 4, &big_pieces);
                count[6] += big_pieces.len() as u32 / 4;
                (tris, big, records) = (all, longer, n + m);
            }
        }
        let (big_count, chunks) = (count[6], count[8]);
        // From here on the kernels list unsure samples for the CPU.
        let shared = Shared {
            cpu_list: &unsure_list,
            ..shared
        };

        // 3. Binning (sort-middle only): count, prefix sum, then the lists.
        let mut encoder = self.device.create_command_encoder(&Default::default());
        if module == Module::Binned {
            let bins = |dispatch: &mut Dispatcher,
                        encoder: &mut wgpu::CommandEncoder,
                        own: &[wgpu::Buffer],
                        pass| {
                let bind = dispatch.bind(&shared, &tris, &big, own, [records, pass, 0, 0]);
                dispatch.pass(encoder, 1, "bin", &bind, groups_for(records));
                let buffers = (&tris, &big, own);
                dispatch.big_passes(
                    encoder,
                    1,
                    "bin_big",
                    &shared,
                    buffers,
                    (big_count, chunks, pass),
                );
                bind
            };
            let bind = bins(&mut dispatch, &mut encoder, &own, 0);
            dispatch.pass(&mut encoder, 1, "scan", &bind, (1, 1));
            dispatch.submit(1, encoder)?;
            let count = self.counters(&counters)?;
            own[3] = self.zeroed("tile list", u64::from(count[5]) * 4, "size")?;
            encoder = self.device.create_command_encoder(&Default::default());
            bins(&mut dispatch, &mut encoder, &own, 1);
            // 4. Raster: a workgroup per tile, the lists in segments.
            for segment in 0..count[7].div_ceil(SEGMENT).max(1) {
                let bind = dispatch.bind(&shared, &tris, &big, &own, [records, 0, 0, segment]);
                dispatch.pass(
                    &mut encoder,
                    2,
                    "raster_binned",
                    &bind,
                    (tiles[0], tiles[1]),
                );
            }
        } else {
            // 4. Raster: a thread per small triangle, workgroups per big one;
            //    the 32-bit fallback twice.
            let passes = if module == Module::Brute32 { 2 } else { 1 };
            for pass in 0..passes {
                let bind = dispatch.bind(&shared, &tris, &big, &own, [records, pass, 0, 0]);
                dispatch.pass(&mut encoder, 2, "raster_brute", &bind, groups_for(records));
                dispatch.big_passes(
                    &mut encoder,
                    2,
                    "raster_big",
                    &shared,
                    (&tris, &big, &own),
                    (big_count, chunks, pass),
                );
            }
        }
        let resolved = dispatch.clock.resolve(self, &mut encoder);
        dispatch.submit(2, encoder)?;

        // 5. Read back: the counters first (the unsure samples may not have
        //    fit), then the samples.
        let start = Instant::now();
        let c = self.counters(&counters)?;
        if c[9] > room {
            return Ok(Err(c[9]));
        }
        out.tiles = [c[2], c[3], c[4]].map(u64::from);
        if c[9] > 0 {
            let listed = self.read(&[(&unsure_list, u64::from(c[9]) * 8)])?;
            out.unsure = (words(&listed[0]).chunks_exact(2))
                .map(|p| [p[0], p[1]])
                .collect();
        }
        let (ids, depth, writes, evals) = match module {
            Module::Brute64 => {
                let r = self.read(&[
                    (&own[0], pixels * 4),
                    (&own[1], samples * 4),
                    (&own[2], samples * 8),
                ])?;
                let (ids, depth) = r[2]
                    .chunks_exact(8)
                    .map(|c| {
                        let key = !u64::from_le_bytes(c.try_into().expect("8 bytes"));
                        // An empty sample's key is all ones: its id reads as none
                        // either way round.
                        let (hi, lo) = ((key >> 32) as u32, key as u32);
                        if depth_test {
                            visible(lo, hi)
                        } else {
                            visible(hi, lo)
                        }
                    })
                    .unzip();
                (ids, depth, words(&r[1]), words(&r[0]))
            }
            Module::Brute32 => {
                let r = self.read(&[
                    (&own[0], pixels * 4),
                    (&own[1], samples * 4),
                    (&own[2], samples * 4),
                    (&own[3], samples * 4),
                ])?;
                let (ids, depth) = words(&r[3])
                    .into_iter()
                    .zip(words(&r[2]))
                    .map(|(id, w)| visible(!id, !w))
                    .unzip();
                (ids, depth, words(&r[1]), words(&r[0]))
            }
            Module::Binned => {
                let r = self.read(&[
                    (&own[4], samples * 4),
                    (&own[5], samples * 4),
                    (&own[6], samples * 4),
                    (&own[7], pixels * 4),
                ])?;
                let (ids, depth) = words(&r[1])
                    .into_iter()
                    .zip(words(&r[0]))
                    .map(|(id, w)| visible(id, w))
                    .unzip();
                (ids, depth, words(&r[2]), words(&r[3]))
            }
        };
        (
            out.triangle_id,
            out.depth,
            out.coverage_writes,
            out.edge_evals,
        ) = (ids, depth, writes, evals);
        let readback = start.elapsed().as_secs_f64() * 1e3;
        let wall = dispatch.wall;
        out.wall = wall;
        let mut times = GpuTimes {
            adapter: self.adapter.clone(),
            clock: "wall".into(),
            setup: wall[0],
            binning: wall[1],
            raster: wall[2],
            readback,
            atomics: match module {
                Module::Brute64 => "64-bit",
                Module::Brute32 => "32-bit two-pass",
                Module::Binned => "none (registers)",
            }
            .into(),
        };
        if let Some(stages) = dispatch.clock.stages(self, resolved)? {
            times.clock = "timestamps".into();
            (times.setup, times.binning, times.raster) = (stages[0], stages[1], stages[2]);
        }
        out.times = times;
        Ok(Ok(out))
    }

    /// The counters (`counters` in compute.wgsl).
    fn counters(&self, counters: &wgpu::Buffer) -> Result<Vec<u32>, GpuError> {
        Ok(words(&self.read(&[(counters, 4 * COUNTERS)])?[0]))
    }
}

/// What every dispatch of one render binds first: the mesh and the shared
/// counters and lists.
struct Shared<'a> {
    mesh: &'a GpuMesh,
    counters: &'a wgpu::Buffer,
    /// What the CPU finishes (`cpu_list` in compute.wgsl).
    cpu_list: &'a wgpu::Buffer,
}

/// What the params uniform says besides a dispatch's own words.
struct Params<'a> {
    view: &'a View,
    pattern: &'a SamplePattern,
    depth_test: bool,
    tiles: [u32; 2],
    /// Room in the unsure samples' list, in pairs.
    room: u32,
}

/// Records the passes of one render: bind groups, timed passes, submissions.
struct Dispatcher<'a> {
    gpu: &'a Gpu,
    kernels: &'a Kernels,
    clock: Clock,
    /// Host milliseconds per stage (without timestamps).
    wall: [f64; 3],
    params: Params<'a>,
}

impl Dispatcher<'_> {
    /// A bind group over `tris`, `big` and the module's buffers, with a params
    /// uniform whose per-dispatch words are `[count, pass, first big,
    /// segment]`.
    fn bind(
        &self,
        shared: &Shared,
        tris: &wgpu::Buffer,
        big: &wgpu::Buffer,
        own: &[wgpu::Buffer],
        [count, pass, first, segment]: [u32; 4],
    ) -> wgpu::BindGroup {
        let p = &self.params;
        let params = self
            .gpu
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("params"),
                contents: &params(
                    p.view,
                    p.pattern,
                    count,
                    p.tiles,
                    pass,
                    [u32::from(!p.depth_test), first, segment, p.room],
                ),
                usage: wgpu::BufferUsages::UNIFORM,
            });
        let buffers = [
            &params,
            &shared.mesh.drawable,
            &shared.mesh.corners,
            &shared.mesh.positions_packed,
            tris,
            shared.counters,
            shared.cpu_list,
            big,
        ];
        let entries: Vec<wgpu::BindGroupEntry> = (buffers.into_iter().chain(own))
            .enumerate()
            .map(|(i, b)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource: b.as_entire_binding(),
            })
            .collect();
        self.gpu
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout: &self.kernels.layout,
                entries: &entries,
            })
    }

    /// One timed pass of `entry` over `groups`.
    fn pass(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        stage: usize,
        entry: &str,
        bind: &wgpu::BindGroup,
        groups: (u32, u32),
    ) {
        let pipeline = &self.kernels.pipelines[entry];
        self.clock.pass(encoder, stage, pipeline, bind, groups);
    }

    /// `entry` over every big triangle: a workgroup per chunk of its box
    /// (`chunks`: the most any box spans) and big triangle, in dispatches
    /// of at most 65,535 triangles.
    fn big_passes(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        stage: usize,
        entry: &str,
        shared: &Shared,
        (tris, big, own): (&wgpu::Buffer, &wgpu::Buffer, &[wgpu::Buffer]),
        (count, chunks, pass): (u32, u32, u32),
    ) {
        for first in (0..count).step_by(65_535) {
            let bind = self.bind(shared, tris, big, own, [count, pass, first, 0]);
            let rows = (count - first).min(65_535);
            self.pass(encoder, stage, entry, &bind, (chunks, rows));
        }
    }

    /// Submits `encoder` and waits, the host time going to `stage`.
    fn submit(&mut self, stage: usize, encoder: wgpu::CommandEncoder) -> Result<(), GpuError> {
        let start = Instant::now();
        let r = self.gpu.finish(encoder);
        self.wall[stage] += start.elapsed().as_secs_f64() * 1e3;
        r
    }
}

/// Little-endian u32 words.
fn words(bytes: &[u8]) -> Vec<u32> {
    bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes(c.try_into().expect("4 bytes")))
        .collect()
}

/// A sample's id and depth from the kernels' id and w bits: `u32::MAX`
/// (none) is the background at `+∞`.
fn visible(id: u32, w_bits: u32) -> (u32, f32) {
    if id == u32::MAX {
        (crate::framebuffer::BACKGROUND, f32::INFINITY)
    } else {
        (id, f32::from_bits(w_bits))
    }
}
