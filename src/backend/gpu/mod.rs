//! The wgpu backend (`--features gpu`): each stage is one compute dispatch
//! of its WGSL kernel (`kernels/<stage>.wgsl`), each level's state two
//! storage buffers that stay on the device from the coarse start to the
//! reconstructed heights.
//!
//! Vulkan only: on the GL backend signed `%` and division by zero came out
//! wrong here (DESIGN §6), and the kernels rely on both being right. Without
//! a hardware adapter wgpu falls back to Mesa's lavapipe (software Vulkan,
//! Debian package `mesa-vulkan-drivers`), which is how CI checks this path.
//!
//! Each stage call records one command buffer and submits it; the queue
//! runs them in order, and wgpu orders storage-buffer accesses across
//! submissions, so one subpass sees the previous one's writes.

use super::kernels::{self, CorrectUniform, Kernel, ReconstructUniform, UpsampleUniform};
use super::{Backend, BackendError};
use crate::synth::atlas::AtlasLevel;
use crate::synth::fixed::Coord;
use crate::synth::stages::correct::CorrectParams;
use crate::synth::stages::upsample_jitter::{Step, UpsampleParams};
use crate::synth::state::State;
use std::sync::Arc;
use std::sync::mpsc;
use wgpu::util::DeviceExt;

/// A device with the kernels compiled: create once, share (`Arc`) between
/// synthesizers — compiling the shaders is the slow part on lavapipe.
pub struct Context {
    device: wgpu::Device,
    queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    limits: wgpu::Limits,
    upsample_jitter: wgpu::ComputePipeline,
    correct: wgpu::ComputePipeline,
    reconstruct: wgpu::ComputePipeline,
}

impl Context {
    /// The first Vulkan adapter (a hardware one preferred, else the software
    /// fallback), with every limit it offers.
    pub fn new() -> Result<Arc<Context>, BackendError> {
        pollster::block_on(Self::new_async())
    }

    async fn new_async() -> Result<Arc<Context>, BackendError> {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = wgpu::Backends::VULKAN;
        let instance = wgpu::Instance::new(desc);
        let options = |fallback| wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: fallback,
            ..Default::default()
        };
        let adapter = match instance.request_adapter(&options(false)).await {
            Ok(a) => a,
            Err(_) => instance
                .request_adapter(&options(true))
                .await
                .map_err(|e| BackendError::NoAdapter(e.to_string()))?,
        };
        let limits = adapter.limits();
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("terrasynth"),
                required_limits: limits.clone(),
                ..Default::default()
            })
            .await
            .map_err(|e| BackendError::Device(e.to_string()))?;
        let pipeline = |k: Kernel| {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(k.name),
                source: wgpu::ShaderSource::Wgsl(k.module_source().into()),
            });
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(k.name),
                layout: None,
                module: &module,
                entry_point: Some("main"),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let upsample_jitter = pipeline(kernels::UPSAMPLE_JITTER);
        let correct = pipeline(kernels::CORRECT);
        let reconstruct = pipeline(kernels::RECONSTRUCT);
        if let Some(e) = scope.pop().await {
            return Err(BackendError::Gpu(e.to_string()));
        }
        Ok(Arc::new(Context {
            info: adapter.get_info(),
            device,
            queue,
            limits,
            upsample_jitter,
            correct,
            reconstruct,
        }))
    }

    /// The adapter, e.g. "llvmpipe (LLVM 15.0.6, 256 bits) (Vulkan)".
    pub fn adapter_name(&self) -> String {
        format!("{} ({:?})", self.info.name, self.info.backend)
    }

    /// Largest storage buffer the device binds.
    fn max_buffer(&self) -> u64 {
        self.limits
            .max_storage_buffer_binding_size
            .min(self.limits.max_buffer_size)
    }

    fn check_size(&self, what: &'static str, bytes: u64) -> Result<(), BackendError> {
        let limit = self.max_buffer();
        if bytes == 0 || bytes > limit {
            return Err(BackendError::TooLarge { what, bytes, limit });
        }
        Ok(())
    }

    /// A storage buffer holding `bytes` (padded to whole u32 words).
    fn storage(&self, what: &'static str, bytes: &[u8]) -> Result<wgpu::Buffer, BackendError> {
        let mut padded;
        let mut contents = bytes;
        if bytes.len() % 4 != 0 {
            padded = bytes.to_vec();
            padded.resize(bytes.len().next_multiple_of(4), 0);
            contents = &padded;
        }
        self.check_size(what, contents.len() as u64)?;
        Ok(self
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(what),
                contents,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
            }))
    }

    /// An uninitialised storage buffer of `bytes`.
    fn storage_empty(&self, what: &'static str, bytes: u64) -> Result<wgpu::Buffer, BackendError> {
        self.check_size(what, bytes)?;
        Ok(self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(what),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        }))
    }

    /// Records and submits one dispatch: `uniform` at binding 0, `buffers`
    /// at bindings 1.., `groups` workgroups.
    fn dispatch(
        &self,
        pipeline: &wgpu::ComputePipeline,
        uniform: &[u8],
        buffers: &[&wgpu::Buffer],
        groups: (u32, u32),
    ) {
        if groups.0 == 0 || groups.1 == 0 {
            return;
        }
        let params = self
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("params"),
                contents: uniform,
                usage: wgpu::BufferUsages::UNIFORM,
            });
        let mut entries = vec![wgpu::BindGroupEntry {
            binding: 0,
            resource: params.as_entire_binding(),
        }];
        entries.extend(buffers.iter().zip(1..).map(|(b, i)| wgpu::BindGroupEntry {
            binding: i,
            resource: b.as_entire_binding(),
        }));
        let bind = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(0),
            entries: &entries,
        });
        let mut enc = self.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: None,
                timestamp_writes: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups(groups.0, groups.1, 1);
        }
        self.queue.submit([enc.finish()]);
    }

    /// Copies a device buffer back to the host (waits for queued work).
    fn read(&self, buffer: &wgpu::Buffer) -> Result<Vec<u8>, BackendError> {
        let size = buffer.size();
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = self.device.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
        self.queue.submit([enc.finish()]);
        let (tx, rx) = mpsc::channel();
        staging.slice(..).map_async(wgpu::MapMode::Read, move |r| {
            // The receiver outlives the poll below; a send cannot fail.
            let _ = tx.send(r);
        });
        self.wait()?;
        rx.recv()
            .map_err(|e| BackendError::Gpu(e.to_string()))?
            .map_err(|e| BackendError::Gpu(e.to_string()))?;
        let data = staging
            .slice(..)
            .get_mapped_range()
            .map_err(|e| BackendError::Gpu(e.to_string()))?
            .to_vec();
        Ok(data)
    }

    fn wait(&self) -> Result<(), BackendError> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| BackendError::Gpu(e.to_string()))
    }
}

/// Workgroups covering `n` invocations.
fn groups(n: usize) -> u32 {
    (n as u32).div_ceil(kernels::WORKGROUP)
}

/// One database level on the device.
struct Level {
    columns: wgpu::Buffer,
    appearance: wgpu::Buffer,
    similar: wgpu::Buffer,
}

/// The GPU backend bound to one database: its atlas levels and level-0
/// heights uploaded once.
pub struct Gpu {
    ctx: Arc<Context>,
    levels: Vec<Level>,
    heights: wgpu::Buffer,
}

/// One level's state on the device: S as `vec2<i32>` (the bytes of
/// `Coord::pack`), V as `i32`.
pub struct GpuState {
    pub width: usize,
    pub height: usize,
    s: wgpu::Buffer,
    v: wgpu::Buffer,
}

impl Gpu {
    /// Uploads `atlas` (every level of one database) and its level-0
    /// `heights`.
    pub fn new(
        ctx: Arc<Context>,
        atlas: &[AtlasLevel<'_>],
        heights: &[u16],
    ) -> Result<Gpu, BackendError> {
        let levels = atlas
            .iter()
            .map(|a| {
                Ok(Level {
                    columns: ctx.storage("atlas columns", bytemuck::cast_slice(&a.columns))?,
                    appearance: ctx
                        .storage("appearance", bytemuck::cast_slice(a.level.appearance))?,
                    similar: ctx.storage("similarity", bytemuck::cast_slice(a.level.similar))?,
                })
            })
            .collect::<Result<_, BackendError>>()?;
        let heights = ctx.storage("heights", bytemuck::cast_slice(heights))?;
        Ok(Gpu {
            ctx,
            levels,
            heights,
        })
    }

    pub fn context(&self) -> &Arc<Context> {
        &self.ctx
    }
}

impl Backend for Gpu {
    type State = GpuState;

    fn name(&self) -> &'static str {
        "gpu"
    }

    fn upload(&self, st: State) -> Result<GpuState, BackendError> {
        let s: Vec<u64> = st.coords().into_iter().map(Coord::pack).collect();
        Ok(GpuState {
            width: st.width,
            height: st.height,
            s: self.ctx.storage("state S", bytemuck::cast_slice(&s))?,
            v: self
                .ctx
                .storage("state V", bytemuck::cast_slice(&st.offsets()))?,
        })
    }

    fn alloc(&self, width: usize, height: usize) -> Result<GpuState, BackendError> {
        let n = (width * height) as u64;
        Ok(GpuState {
            width,
            height,
            s: self.ctx.storage_empty("state S", n * 8)?,
            v: self.ctx.storage_empty("state V", n * 4)?,
        })
    }

    fn upsample_jitter(
        &self,
        parent: &GpuState,
        child: &GpuState,
        level: usize,
        p: &UpsampleParams,
    ) {
        let mut u = UpsampleUniform {
            child_width: child.width as u32,
            child_height: child.height as u32,
            parent_width: parent.width as u32,
            seed: p.seed,
            level: p.level,
            jitter: p.jitter,
            ..Default::default()
        };
        match p.step {
            Step::Pyramid => u.step = kernels::STEP_PYRAMID,
            Step::Virtual { shift } => {
                u.step = kernels::STEP_VIRTUAL;
                u.shift = shift;
            }
            Step::Wrap {
                min_x,
                max_x,
                min_y,
                max_y,
            } => {
                u.step = kernels::STEP_WRAP;
                (u.min_x, u.max_x, u.min_y, u.max_y) = (min_x, max_x, min_y, max_y);
            }
        }
        // Only the pyramid step reads the columns; the others get the
        // coarsest level's so that the binding is valid.
        let columns = &self.levels[level.min(self.levels.len() - 1)].columns;
        self.ctx.dispatch(
            &self.ctx.upsample_jitter,
            bytemuck::bytes_of(&u),
            &[&parent.s, &parent.v, &child.s, &child.v, columns],
            (groups(child.width), groups(child.height)),
        );
    }

    fn correct(&self, st: &GpuState, level: usize, p: &CorrectParams) {
        let u = CorrectUniform {
            width: st.width as u32,
            height: st.height as u32,
            px: p.px,
            py: p.py,
        };
        let l = &self.levels[level];
        // Pixels of the parity class per axis: ⌈(n − parity) / 2⌉.
        let class = |n: usize, parity: u32| (n - parity as usize).div_ceil(2);
        self.ctx.dispatch(
            &self.ctx.correct,
            bytemuck::bytes_of(&u),
            &[&st.s, &st.v, &l.columns, &l.appearance, &l.similar],
            (
                groups(class(st.width, p.px)),
                groups(class(st.height, p.py)),
            ),
        );
    }

    fn reconstruct(&self, st: &GpuState) -> Result<Vec<i32>, BackendError> {
        let u = ReconstructUniform {
            width: st.width as u32,
            height: st.height as u32,
            ..Default::default()
        };
        let out = self
            .ctx
            .storage_empty("heights out", (st.width * st.height * 4) as u64)?;
        self.ctx.dispatch(
            &self.ctx.reconstruct,
            bytemuck::bytes_of(&u),
            &[&st.s, &st.v, &self.levels[0].columns, &self.heights, &out],
            (groups(st.width), groups(st.height)),
        );
        Ok(bytemuck::pod_collect_to_vec(&self.ctx.read(&out)?))
    }

    fn download(&self, st: &GpuState) -> Result<(Vec<Coord>, Vec<i32>), BackendError> {
        let s: Vec<u64> = bytemuck::pod_collect_to_vec(&self.ctx.read(&st.s)?);
        let v: Vec<i32> = bytemuck::pod_collect_to_vec(&self.ctx.read(&st.v)?);
        Ok((s.into_iter().map(Coord::unpack).collect(), v))
    }

    fn finish(&self) -> Result<(), BackendError> {
        self.ctx.wait()
    }
}
