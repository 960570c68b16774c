//! GPU paths through wgpu (feature `gpu`): `gpu-raster`, the hardware pipeline
//! as the reference from outside and a peer in `compare`. On machines without a
//! GPU it runs on Mesa's lavapipe (Vulkan on the CPU, Debian package
//! `mesa-vulkan-drivers`).
//!
//! One draw renders every drawable triangle (in id order, so with the depth
//! test `Greater` on a reversed depth an exact depth tie keeps the smaller id)
//! into a triangle-id target (`R32Uint`), a view-axis distance target
//! (`R32Float`) and a depth-stencil buffer whose stencil counts every fragment,
//! passing the depth test or not: the same `coverage_writes` the CPU
//! algorithms count. The samples are then resolved and shaded by the CPU code
//! every algorithm shares, so equal ids and depths give equal colours.
//!
//! Coverage follows the Vulkan rasterization rules as the driver implements
//! them (lavapipe: vertices snapped to 1/256 pixel, top-left rule); the
//! conformance tests compare it with `--precision fixed`.

mod compute;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::Instant;

use crate::camera::View;
use crate::prepared::PreparedScene;
use crate::stats::Stats;

pub use compute::GpuAtomics;
pub(crate) use compute::{ComputeSamples, TriWords};

/// Why the GPU path cannot render.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum GpuError {
    #[error(
        "no Vulkan device: the GPU algorithms need a GPU or Mesa's lavapipe (Debian: apt-get install mesa-vulkan-drivers libvulkan1): {0}"
    )]
    NoDevice(String),
    #[error("{width}x{height} exceeds the GPU's largest render target of {max}x{max}")]
    TooLarge { width: u32, height: u32, max: u32 },
    #[error("the scene's {vertices} vertices exceed the GPU's largest buffer")]
    SceneTooLarge { vertices: u64 },
    #[error("the {what} buffer needs {bytes} bytes; the GPU's largest storage buffer holds {max}")]
    BufferTooLarge {
        what: String,
        bytes: u64,
        max: u64,
        /// The request field that sized it (`size` or `scene`).
        field: &'static str,
    },
    #[error("GPU failure: {0}")]
    Failed(String),
}

impl GpuError {
    /// The request field at fault.
    pub(crate) fn field(&self) -> &'static str {
        match self {
            GpuError::TooLarge { .. } => "size",
            GpuError::SceneTooLarge { .. } => "scene",
            GpuError::BufferTooLarge { field, .. } => field,
            GpuError::NoDevice(_) | GpuError::Failed(_) => "algorithm",
        }
    }
}

/// The adapter to open, by name (a case-insensitive part of it), set before
/// the first render (`--adapter`); `CONTINUUM_ADAPTER` otherwise.
static ADAPTER_CHOICE: OnceLock<String> = OnceLock::new();

/// Forces the compute kernels' 32-bit two-pass visibility
/// (`continuum::force_gpu_two_pass`; `CONTINUUM_GPU_ATOMICS=two-pass`).
static FORCE_TWO_PASS: AtomicBool = AtomicBool::new(false);

/// Chooses the adapter by name; only the first choice, made before the GPU
/// is opened, counts. Returns whether it was taken.
pub fn choose_adapter(name: &str) -> bool {
    ADAPTER_CHOICE.set(name.to_string()).is_ok() && GPU_OPENED.get().is_none()
}

/// Chooses how the compute kernels keep the nearest sample.
pub fn set_atomics(atomics: GpuAtomics) {
    FORCE_TWO_PASS.store(atomics == GpuAtomics::TwoPass, Ordering::Relaxed);
}

/// The visibility the compute kernels use now.
pub(crate) fn atomics() -> GpuAtomics {
    let env = std::env::var("CONTINUUM_GPU_ATOMICS").is_ok_and(|v| v == "two-pass");
    if env || FORCE_TWO_PASS.load(Ordering::Relaxed) {
        GpuAtomics::TwoPass
    } else {
        GpuAtomics::Auto
    }
}

/// Set once the GPU has been opened (the adapter can no longer change).
static GPU_OPENED: OnceLock<()> = OnceLock::new();

/// The device, its queue and the pipeline, made once per process.
#[derive(Debug)]
pub struct Gpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    depth_format: wgpu::TextureFormat,
    /// Adapter name, driver and backend, for reports.
    pub adapter: String,
    max_dimension: u32,
    /// One render at a time: lavapipe uses every core already.
    lock: Mutex<()>,
    /// The compute kernels, compiled on first use.
    compute: compute::ComputeCache,
    /// The device has 64-bit atomicMin/Max on storage buffers.
    int64_atomics: bool,
    /// The device has timestamp queries around passes.
    timestamps: bool,
}

/// Per-scene vertex data on the device: three vertices per drawable triangle
/// (positions, and the triangle id on each), in id order, for the hardware
/// pipeline; the indexed mesh and the drawable ids for the compute kernels.
#[derive(Debug)]
pub(crate) struct GpuMesh {
    positions: wgpu::Buffer,
    ids: wgpu::Buffer,
    vertices: u32,
    /// Per mesh vertex three f32 coordinates.
    positions_packed: wgpu::Buffer,
    /// Per triangle its three vertex indices.
    corners: wgpu::Buffer,
    /// The drawable triangles' ids.
    drawable: wgpu::Buffer,
    /// How many triangles are drawable.
    triangles: u32,
}

/// The process's GPU, opened on first use.
pub fn gpu() -> Result<&'static Gpu, GpuError> {
    static GPU: OnceLock<Result<Gpu, GpuError>> = OnceLock::new();
    GPU.get_or_init(|| {
        let _ = GPU_OPENED.set(());
        Gpu::open()
    })
    .as_ref()
    .map_err(Clone::clone)
}

/// The adapter `name` names (a case-insensitive part of its name), or an
/// error listing the adapters there are.
fn adapter_named(instance: &wgpu::Instance, name: &str) -> Result<wgpu::Adapter, GpuError> {
    let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::PRIMARY));
    let names: Vec<String> = adapters.iter().map(|a| a.get_info().name).collect();
    let wanted = name.to_lowercase();
    adapters
        .into_iter()
        .find(|a| a.get_info().name.to_lowercase().contains(&wanted))
        .ok_or_else(|| {
            GpuError::NoDevice(format!(
                "no adapter named '{name}' (adapter / CONTINUUM_ADAPTER); adapters here: {}",
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            ))
        })
}

/// A device error raised outside an error scope, kept for the next draw to
/// report instead of wgpu's default handler, which panics.
static UNCAPTURED: Mutex<Option<String>> = Mutex::new(None);

const ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
const W_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// The camera uniform: see `raster.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
struct CameraUniform {
    eye: [f32; 4],
    right: [f32; 4],
    up: [f32; 4],
    forward: [f32; 4],
    params: [f32; 4],
    mode: [u32; 4],
}

impl CameraUniform {
    fn bytes(&self) -> Vec<u8> {
        let floats = [self.eye, self.right, self.up, self.forward, self.params];
        let mut out: Vec<u8> = floats
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        out.extend(self.mode.iter().flat_map(|v| v.to_le_bytes()));
        out
    }
}

impl Gpu {
    fn open() -> Result<Gpu, GpuError> {
        // 1. An adapter: Vulkan (or another primary backend; `WGPU_BACKEND`
        //    overrides), never a backend that may lack the formats we render to
        //    unless asked for by name, and then checked before use.
        let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle();
        descriptor.backends = wgpu::Backends::PRIMARY;
        let instance = wgpu::Instance::new(descriptor.with_env());
        let choice = ADAPTER_CHOICE
            .get()
            .cloned()
            .or_else(|| std::env::var("CONTINUUM_ADAPTER").ok())
            .filter(|n| !n.is_empty());
        let adapter = match choice {
            Some(name) => adapter_named(&instance, &name)?,
            None => pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                ..Default::default()
            }))
            .map_err(|e| GpuError::NoDevice(e.to_string()))?,
        };
        let info = adapter.get_info();
        let adapter_name = format!("{} ({}, {:?})", info.name, info.driver, info.backend);
        let depth_format = if adapter
            .features()
            .contains(wgpu::Features::DEPTH32FLOAT_STENCIL8)
        {
            wgpu::TextureFormat::Depth32FloatStencil8
        } else {
            wgpu::TextureFormat::Depth24PlusStencil8
        };
        for format in [ID_FORMAT, W_FORMAT, depth_format] {
            let usages = adapter.get_texture_format_features(format).allowed_usages;
            if !usages
                .contains(wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC)
            {
                // A refused adapter is kept, not dropped: on Mesa's EGL, wgpu's
                // teardown and glvnd's thread-state destructor at process exit
                // can free the same state twice (an abort in about one run in
                // twenty; gfx-rs/wgpu#4285). `gpu()` opens once per process, so
                // this keeps one instance at most.
                std::mem::forget(adapter);
                std::mem::forget(instance);
                return Err(GpuError::NoDevice(format!(
                    "the adapter {adapter_name} cannot render to {format:?}"
                )));
            }
        }
        let limits = adapter.limits();
        // Optional features the compute kernels use where the adapter has them.
        let int64 = wgpu::Features::SHADER_INT64 | wgpu::Features::SHADER_INT64_ATOMIC_MIN_MAX;
        let optional = int64 | wgpu::Features::TIMESTAMP_QUERY;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("continuum"),
            required_features: (adapter.features() & optional)
                | if depth_format == wgpu::TextureFormat::Depth32FloatStencil8 {
                    wgpu::Features::DEPTH32FLOAT_STENCIL8
                } else {
                    wgpu::Features::empty()
                },
            required_limits: limits.clone(),
            ..Default::default()
        }))
        .map_err(|e| GpuError::NoDevice(e.to_string()))?;
        // 2. The pipeline, its validation errors caught (a driver that refuses
        //    it is "no device", not a panic); later errors outside a scope are
        //    kept for the draw to report.
        device.on_uncaptured_error(Arc::new(|e: wgpu::Error| {
            *UNCAPTURED.lock().unwrap_or_else(|p| p.into_inner()) = Some(e.to_string());
        }));
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("raster.wgsl"),
            source: wgpu::ShaderSource::Wgsl(include_str!("raster.wgsl").into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("camera"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("raster"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        // Every fragment increments the stencil, whether it passes the depth test or not.
        let count = wgpu::StencilFaceState {
            compare: wgpu::CompareFunction::Always,
            fail_op: wgpu::StencilOperation::IncrementClamp,
            depth_fail_op: wgpu::StencilOperation::IncrementClamp,
            pass_op: wgpu::StencilOperation::IncrementClamp,
        };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("raster"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &shader,
                entry_point: Some("vs"),
                compilation_options: Default::default(),
                buffers: &[
                    Some(wgpu::VertexBufferLayout {
                        array_stride: 12,
                        step_mode: wgpu::VertexStepMode::Vertex,
                        attributes: &[wgpu::VertexAttribute {
                            format: wgpu::VertexFormat::Float32x3,
                            offset: 0,
                            shader_location: 0,
                        }],
                    }),
                    Some(wgpu::VertexBufferLayout {
                        array_stride: 4,
                        step_mode: wgpu::VertexStepMode::Vertex,
                        attributes: &[wgpu::VertexAttribute {
                            format: wgpu::VertexFormat::Uint32,
                            offset: 0,
                            shader_location: 1,
                        }],
                    }),
                ],
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: depth_format,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Greater),
                stencil: wgpu::StencilState {
                    front: count,
                    back: count,
                    read_mask: 0xff,
                    write_mask: 0xff,
                },
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &shader,
                entry_point: Some("fs"),
                compilation_options: Default::default(),
                targets: &[Some(ID_FORMAT.into()), Some(W_FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(GpuError::NoDevice(format!(
                "the adapter {adapter_name} refused the pipeline: {e}"
            )));
        }
        Ok(Gpu {
            pipeline,
            layout,
            depth_format,
            adapter: adapter_name,
            max_dimension: limits.max_texture_dimension_2d,
            lock: Mutex::new(()),
            compute: Default::default(),
            int64_atomics: device.features().contains(int64),
            timestamps: device.features().contains(wgpu::Features::TIMESTAMP_QUERY),
            device,
            queue,
        })
    }

    /// The scene's mesh on the device, uploaded on the first render of the
    /// prepared scene.
    pub(crate) fn mesh<'s>(&self, scene: &'s PreparedScene) -> Result<&'s GpuMesh, GpuError> {
        scene
            .gpu_cache
            .get_or_init(|| Box::new(self.upload(scene)))
            .downcast_ref::<Result<GpuMesh, GpuError>>()
            .ok_or_else(|| GpuError::Failed("the scene's GPU cache holds another type".into()))?
            .as_ref()
            .map_err(Clone::clone)
    }

    /// Uploads a scene's drawable triangles.
    pub(crate) fn upload(&self, scene: &PreparedScene) -> Result<GpuMesh, GpuError> {
        let vertices = scene.drawable.len() as u64 * 3;
        let max = self.device.limits().max_buffer_size;
        if vertices * 12 > max || vertices > u64::from(u32::MAX) {
            return Err(GpuError::SceneTooLarge { vertices });
        }
        let mut positions = Vec::with_capacity(vertices as usize * 12);
        let mut ids = Vec::with_capacity(vertices as usize * 4);
        for &id in &scene.drawable {
            for p in &scene.triangle(id) {
                positions.extend(p.to_array().iter().flat_map(|v| v.to_le_bytes()));
                ids.extend(id.to_le_bytes());
            }
        }
        let buffer = |label, bytes: &[u8]| {
            let b = self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: (bytes.len() as u64).max(16),
                usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            self.queue.write_buffer(&b, 0, bytes);
            b
        };
        let mesh = &scene.scene.mesh;
        let storage_max = self.device.limits().max_storage_buffer_binding_size;
        if mesh.positions.len() as u64 * 12 > storage_max
            || mesh.triangles.len() as u64 * 12 > storage_max
        {
            return Err(GpuError::SceneTooLarge { vertices });
        }
        let packed: Vec<u8> = (mesh.positions.iter())
            .flat_map(|p| p.to_array())
            .flat_map(f32::to_le_bytes)
            .collect();
        let corners: Vec<u8> = (mesh.triangles.iter())
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let drawable: Vec<u8> = scene
            .drawable
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        Ok(GpuMesh {
            positions: buffer("positions", &positions),
            ids: buffer("ids", &ids),
            vertices: vertices as u32,
            positions_packed: self.storage("mesh positions", &packed),
            corners: self.storage("mesh triangles", &corners),
            drawable: self.storage("drawable", &drawable),
            triangles: scene.drawable.len() as u32,
        })
    }

    /// Whether the view fits the adapter's largest image.
    fn fits(&self, view: &View) -> Result<(), GpuError> {
        let (width, height) = (view.width, view.height);
        if width > self.max_dimension || height > self.max_dimension {
            return Err(GpuError::TooLarge {
                width,
                height,
                max: self.max_dimension,
            });
        }
        Ok(())
    }

    /// Renders `view` of `mesh`: per pixel the triangle id (`u32::MAX` for
    /// none), the view-axis distance (`+∞` for none) and the fragment count.
    pub(crate) fn draw(&self, mesh: &GpuMesh, view: &View, far: f32) -> Result<Samples, GpuError> {
        self.fits(view)?;
        let (width, height) = (view.width, view.height);
        let _one_at_a_time = self.lock.lock().unwrap_or_else(|e| e.into_inner());
        let device = &self.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        // 1. Targets and the camera.
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let target = |label, format| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            })
        };
        let ids = target("ids", ID_FORMAT);
        let ws = target("w", W_FORMAT);
        let depth = target("depth", self.depth_format);
        let camera = camera_uniform(view, far);
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("camera"),
            size: 96,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        self.queue.write_buffer(&uniform, 0, &camera.bytes());
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("camera"),
            layout: &self.layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: uniform.as_entire_binding(),
            }],
        });
        // 2. The draw.
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let id_view = ids.create_view(&Default::default());
            let w_view = ws.create_view(&Default::default());
            let depth_view = depth.create_view(&Default::default());
            let clear = |c: f64| wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color {
                    r: c,
                    g: 0.0,
                    b: 0.0,
                    a: 0.0,
                }),
                store: wgpu::StoreOp::Store,
            };
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("raster"),
                color_attachments: &[
                    Some(wgpu::RenderPassColorAttachment {
                        view: &id_view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: clear(f64::from(u32::MAX)),
                    }),
                    Some(wgpu::RenderPassColorAttachment {
                        view: &w_view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: clear(f64::INFINITY),
                    }),
                ],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(0.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(0),
                        store: wgpu::StoreOp::Store,
                    }),
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.set_vertex_buffer(0, mesh.positions.slice(..));
            pass.set_vertex_buffer(1, mesh.ids.slice(..));
            pass.draw(0..mesh.vertices, 0..1);
        }
        // 3. Read back.
        let readback =
            |texture: &wgpu::Texture, aspect, texel: u32, encoder: &mut wgpu::CommandEncoder| {
                let row = (width * texel).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
                let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("readback"),
                    size: u64::from(row) * u64::from(height),
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                encoder.copy_texture_to_buffer(
                    wgpu::TexelCopyTextureInfo {
                        texture,
                        mip_level: 0,
                        origin: wgpu::Origin3d::ZERO,
                        aspect,
                    },
                    wgpu::TexelCopyBufferInfo {
                        buffer: &buffer,
                        layout: wgpu::TexelCopyBufferLayout {
                            offset: 0,
                            bytes_per_row: Some(row),
                            rows_per_image: Some(height),
                        },
                    },
                    size,
                );
                (buffer, row)
            };
        let id_buffer = readback(&ids, wgpu::TextureAspect::All, 4, &mut encoder);
        let w_buffer = readback(&ws, wgpu::TextureAspect::All, 4, &mut encoder);
        let count_buffer = readback(&depth, wgpu::TextureAspect::StencilOnly, 1, &mut encoder);
        self.queue.submit([encoder.finish()]);
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(GpuError::Failed(e.to_string()));
        }
        if let Some(e) = UNCAPTURED.lock().unwrap_or_else(|p| p.into_inner()).take() {
            return Err(GpuError::Failed(e));
        }
        for (b, _) in [&id_buffer, &w_buffer, &count_buffer] {
            b.map_async(wgpu::MapMode::Read, .., |_| {});
        }
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Failed(e.to_string()))?;
        // Each plane decoded in one pass over its padded rows.
        fn plane<T, const N: usize>(
            (buffer, row): &(wgpu::Buffer, u32),
            (width, height): (u32, u32),
            decode: fn([u8; N]) -> T,
        ) -> Result<Vec<T>, GpuError> {
            let mapped = buffer
                .get_mapped_range(..)
                .map_err(|e| GpuError::Failed(e.to_string()))?;
            let mut out = Vec::with_capacity(width as usize * height as usize);
            for r in mapped.chunks(*row as usize) {
                let texels = r[..width as usize * N].as_chunks::<N>().0;
                out.extend(texels.iter().map(|&t| decode(t)));
            }
            Ok(out)
        }
        let size = (width, height);
        Ok(Samples {
            triangle_id: plane(&id_buffer, size, u32::from_le_bytes)?,
            depth: plane(&w_buffer, size, f32::from_le_bytes)?,
            fragments: plane(&count_buffer, size, |[count]: [u8; 1]| u32::from(count))?,
        })
    }
}

/// What the GPU drew, per pixel, row-major.
#[derive(Clone, Debug)]
pub(crate) struct Samples {
    pub triangle_id: Vec<u32>,
    pub depth: Vec<f32>,
    /// Fragments per pixel (the stencil count: at most 255).
    pub fragments: Vec<u32>,
}

/// The camera of `view` for the shader; `far` bounds orthographic depth.
fn camera_uniform(view: &View, far: f32) -> CameraUniform {
    let v4 = |v: glam::Vec3| [v.x, v.y, v.z, 0.0];
    CameraUniform {
        eye: v4(view.eye),
        right: v4(view.right),
        up: v4(view.up),
        forward: v4(view.forward),
        params: [view.half_x, view.half_y, view.near, far],
        mode: [u32::from(view.is_orthographic()), 0, 0, 0],
    }
}

/// `gpu-raster`'s draw: `view` of `scene` through the GPU's pipeline, read
/// back (planar viewports, one sample per pixel); the caller resolves and
/// shades it as every algorithm's samples are.
pub(crate) fn draw_gpu_raster(
    scene: &PreparedScene,
    view: &View,
    stats: &mut Stats,
) -> Result<Samples, GpuError> {
    let gpu = gpu()?;
    // 1. Setup: the scene's vertices on the device (once per prepared scene).
    let start = Instant::now();
    let mesh = gpu.mesh(scene)?;
    stats.triangle_setups = scene.drawable.len() as u64;
    stats.time_ms.setup = start.elapsed().as_secs_f64() * 1e3;
    // 2. The draw and its read-back.
    let start = Instant::now();
    let far = orthographic_far(scene, view);
    let samples = gpu.draw(mesh, view, far)?;
    stats.time_ms.coverage = start.elapsed().as_secs_f64() * 1e3;
    Ok(samples)
}

/// The far distance for an orthographic view's depth range: beyond the scene's
/// farthest point along the view axis.
fn orthographic_far(scene: &PreparedScene, view: &View) -> f32 {
    let b = &scene.bounds;
    let mut far = view.near * 2.0;
    if !b.is_empty() {
        for i in 0..8 {
            let corner = glam::Vec3::new(
                if i & 1 == 0 { b.min.x } else { b.max.x },
                if i & 2 == 0 { b.min.y } else { b.max.y },
                if i & 4 == 0 { b.min.z } else { b.max.z },
            );
            far = far.max((corner - view.eye).dot(view.forward) * 1.01 + view.near);
        }
    }
    far
}
