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
//!
//! The patch engine's data-parallel cost stage lives in [`fill_ssd`].

pub mod fill_ssd;

use super::kernels::{
    self, CorrectUniform, GuideCell, Kernel, ReconstructUniform, ReduceTypesUniform,
    ReduceWeightsUniform, UpsampleUniform,
};
use super::{Backend, BackendError, Stage, StageTime, check_guide, check_raster};
use crate::render::shade::{ShadeBuffers, ShadeParams};
use crate::synth::atlas::AtlasLevel;
use crate::synth::fixed::Coord;
use crate::synth::stages::correct::{CorrectParams, Guide};
use crate::synth::stages::upsample_jitter::{Step, UpsampleParams};
use crate::synth::state::State;
use std::sync::mpsc;
use std::sync::{Arc, Mutex};
use std::time::Duration;
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
    reduce_types: wgpu::ComputePipeline,
    reduce_weights: wgpu::ComputePipeline,
    reconstruct: wgpu::ComputePipeline,
    shade: wgpu::ComputePipeline,
    fill_ssd: wgpu::ComputePipeline,
    /// Timestamp queries, where the adapter has them.
    profile: Option<Mutex<Profile>>,
}

/// Most timed dispatches between two reads of the times (a 4096² synthesis
/// makes ~120); later ones go untimed and the times are reported missing.
const MAX_TIMED: u32 = 2048;

/// Begin/end timestamps of each dispatch since the last read.
struct Profile {
    queries: wgpu::QuerySet,
    /// What each pair of queries timed, in order.
    labels: Vec<(Stage, usize)>,
    /// More dispatches than [`MAX_TIMED`] since the last read.
    overflow: bool,
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
        let features = adapter.features() & wgpu::Features::TIMESTAMP_QUERY;
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("terrasynth"),
                required_features: features,
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
        let reduce_types = pipeline(kernels::REDUCE_TYPES);
        let reduce_weights = pipeline(kernels::REDUCE_WEIGHTS);
        let reconstruct = pipeline(kernels::RECONSTRUCT);
        let shade = pipeline(kernels::SHADE);
        let fill_ssd = pipeline(kernels::FILL_SSD);
        if let Some(e) = scope.pop().await {
            return Err(BackendError::Gpu(e.to_string()));
        }
        let profile = features.contains(wgpu::Features::TIMESTAMP_QUERY).then(|| {
            Mutex::new(Profile {
                queries: device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("stage timestamps"),
                    ty: wgpu::QueryType::Timestamp,
                    count: 2 * MAX_TIMED,
                }),
                labels: Vec::new(),
                overflow: false,
            })
        });
        Ok(Arc::new(Context {
            profile,
            info: adapter.get_info(),
            device,
            queue,
            limits,
            upsample_jitter,
            correct,
            reduce_types,
            reduce_weights,
            reconstruct,
            shade,
            fill_ssd,
        }))
    }

    /// Whether stage times come from GPU timestamp queries (else wall clock).
    pub fn has_timestamps(&self) -> bool {
        self.profile.is_some()
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
    /// at bindings 1.., `groups` workgroups; timed as `label` (a synthesis
    /// stage and its level) when given and the device has timestamps.
    fn dispatch(
        &self,
        label: Option<(Stage, usize)>,
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
        let mut profile = self
            .profile
            .as_ref()
            .map(|p| p.lock().expect("profile lock"));
        let timestamp_writes = profile.as_mut().zip(label).and_then(|(p, label)| {
            let k = p.labels.len() as u32;
            if k == MAX_TIMED {
                p.overflow = true;
                return None;
            }
            p.labels.push(label);
            Some(wgpu::ComputePassTimestampWrites {
                query_set: &p.queries,
                beginning_of_pass_write_index: Some(2 * k),
                end_of_pass_write_index: Some(2 * k + 1),
            })
        });
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: None,
                timestamp_writes,
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

    /// Stage `shade` (the preview renderer's): the same packed RGBA pixels
    /// as `render::shade::shade`, row-major. Checks the parameters first,
    /// exactly like the CPU stage.
    pub fn shade(&self, p: &ShadeParams, b: &ShadeBuffers<'_>) -> Result<Vec<u32>, BackendError> {
        p.validate(b)?;
        let n = p.width as u64 * p.height as u64;
        // Type buffers may be empty when the overlay is off: bind a word.
        let some = |v: &[u32]| -> Vec<u32> { if v.is_empty() { vec![0] } else { v.to_vec() } };
        let heights = self.storage("shade heights", bytemuck::cast_slice(b.heights))?;
        let types = self.storage("shade types", bytemuck::cast_slice(&some(b.types)))?;
        let tint = self.storage("tint", bytemuck::cast_slice(b.tint))?;
        let colours = self.storage("type colours", bytemuck::cast_slice(&some(b.type_colours)))?;
        let out = self.storage_empty("preview", n * 4)?;
        self.dispatch(
            None,
            &self.shade,
            bytemuck::bytes_of(p),
            &[&heights, &types, &tint, &colours, &out],
            (groups(p.width as usize), groups(p.height as usize)),
        );
        Ok(bytemuck::pod_collect_to_vec(&self.read(&out)?))
    }

    /// Reads and forgets the timestamps recorded since the last call.
    fn stage_times(&self) -> Result<Option<Vec<StageTime>>, BackendError> {
        let Some(profile) = &self.profile else {
            return Ok(None);
        };
        let mut p = profile.lock().expect("profile lock");
        let labels = std::mem::take(&mut p.labels);
        if std::mem::take(&mut p.overflow) {
            return Ok(None);
        }
        if labels.is_empty() {
            return Ok(Some(Vec::new()));
        }
        let n = 2 * labels.len() as u32;
        let resolved = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamps"),
            size: n as u64 * 8,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let mut enc = self.device.create_command_encoder(&Default::default());
        enc.resolve_query_set(&p.queries, 0..n, &resolved, 0);
        self.queue.submit([enc.finish()]);
        drop(p);
        let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(&self.read(&resolved)?);
        // Host-side conversion of tick counts (floats are fine here, DESIGN §6 rule 5).
        let period_ns = self.queue.get_timestamp_period() as f64;
        Ok(Some(
            labels
                .into_iter()
                .zip(ticks.chunks_exact(2))
                .map(|((stage, level), t)| StageTime {
                    stage,
                    level,
                    time: Duration::from_nanos(
                        (t[1].saturating_sub(t[0]) as f64 * period_ns) as u64,
                    ),
                })
                .collect(),
        ))
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
    /// Seed counts, seeds and texel types in one buffer (see
    /// `kernels/correct.wgsl`'s `type_data`).
    type_data: wgpu::Buffer,
    type_count: u32,
}

/// The control inputs of `correct` for one pass of one level on the device
/// ([`Backend::upload_guide`]): which controls are on, and one
/// [`GuideCell`] per pixel when any is.
pub struct GpuGuide {
    level: u32,
    window: Option<[usize; 4]>,
    flags: u32,
    cells: Option<wgpu::Buffer>,
}

/// The GPU backend bound to one database: its atlas levels and level-0
/// heights uploaded once.
pub struct Gpu {
    ctx: Arc<Context>,
    levels: Vec<Level>,
    heights: wgpu::Buffer,
    /// Bound where a control is off (the kernel never reads it then).
    placeholder: wgpu::Buffer,
}

/// A level's type tables as `correct.wgsl` reads them: seed counts, seeds,
/// then the texel types packed four per word (little-endian, like the
/// bytes); one zero word at least (a binding needs a buffer).
fn type_data(seed_counts: &[u32], seeds: &[u32], types: &[u8]) -> Vec<u32> {
    let mut d = Vec::with_capacity(seed_counts.len() + seeds.len() + types.len() / 4 + 1);
    d.extend_from_slice(seed_counts);
    d.extend_from_slice(seeds);
    d.extend(types.chunks(4).map(|c| {
        let mut w = [0u8; 4];
        w[..c.len()].copy_from_slice(c);
        u32::from_le_bytes(w)
    }));
    if d.is_empty() {
        d.push(0);
    }
    d
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
                    type_data: ctx.storage(
                        "type tables",
                        bytemuck::cast_slice(&type_data(
                            &a.seed_counts,
                            a.level.seeds,
                            a.level.types,
                        )),
                    )?,
                    type_count: a.seed_counts.len() as u32,
                })
            })
            .collect::<Result<_, BackendError>>()?;
        let heights = ctx.storage("heights", bytemuck::cast_slice(heights))?;
        let placeholder = ctx.storage("placeholder", bytemuck::bytes_of(&GuideCell::default()))?;
        Ok(Gpu {
            ctx,
            levels,
            heights,
            placeholder,
        })
    }

    pub fn context(&self) -> &Arc<Context> {
        &self.ctx
    }
}

/// One level's control raster on the device, one u32 per pixel: type sets
/// as they are, coherence weights widened from u8 (see
/// `kernels/reduce_weights.wgsl`).
pub struct GpuRaster {
    pub width: usize,
    pub height: usize,
    buf: wgpu::Buffer,
}

impl Gpu {
    fn upload_raster(
        &self,
        what: &'static str,
        data: &[u32],
        width: usize,
        height: usize,
    ) -> Result<GpuRaster, BackendError> {
        check_raster(what, data.len(), width, height)?;
        Ok(GpuRaster {
            width,
            height,
            buf: self.ctx.storage(what, bytemuck::cast_slice(data))?,
        })
    }

    /// One dispatch of a reduction from `child` into a new `width × height`
    /// raster.
    fn reduce(
        &self,
        what: &'static str,
        pipeline: &wgpu::ComputePipeline,
        uniform: &[u8],
        child: &GpuRaster,
        width: usize,
        height: usize,
    ) -> Result<GpuRaster, BackendError> {
        let bytes = (width as u64)
            .checked_mul(height as u64)
            .and_then(|n| n.checked_mul(4))
            .unwrap_or(u64::MAX);
        let buf = self.ctx.storage_empty(what, bytes)?;
        self.ctx.dispatch(
            None,
            pipeline,
            uniform,
            &[&child.buf, &buf],
            (groups(width), groups(height)),
        );
        Ok(GpuRaster { width, height, buf })
    }
}

impl Backend for Gpu {
    type State = GpuState;
    type Types = GpuRaster;
    type Weights = GpuRaster;
    type Guide<'g> = GpuGuide;

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
            Some((Stage::UpsampleJitter, level)),
            &self.ctx.upsample_jitter,
            bytemuck::bytes_of(&u),
            &[&parent.s, &parent.v, &child.s, &child.v, columns],
            (groups(child.width), groups(child.height)),
        );
    }

    fn correct(&self, st: &GpuState, parent: Option<&GpuState>, level: usize, p: &CorrectParams) {
        let none = GpuGuide {
            level: level as u32,
            window: None,
            flags: 0,
            cells: None,
        };
        self.correct_guided(st, parent, level, p, &none);
    }

    fn upload_guide(
        &self,
        g: &Guide<'_>,
        width: usize,
        height: usize,
    ) -> Result<GpuGuide, BackendError> {
        check_guide(g, width, height)?;
        let mut flags = 0;
        for (on, flag) in [
            (g.targets.is_some(), kernels::CORRECT_TARGETS),
            (g.allowed.is_some(), kernels::CORRECT_ALLOWED),
            (g.coherence.is_some(), kernels::CORRECT_COHERENCE),
        ] {
            if on {
                flags |= flag;
            }
        }
        let cells = (flags != 0)
            .then(|| {
                let cells: Vec<GuideCell> = (0..width * height)
                    .map(|i| {
                        let mut c = GuideCell::default();
                        if let Some(t) = g.targets {
                            c.blend_target = [t[i].height, t[i].tol];
                        }
                        if let Some(a) = g.allowed {
                            c.allowed = a[i];
                        }
                        if let Some(co) = g.coherence {
                            c.weight = co.weights[i] as u32;
                            c.prev_s = bytemuck::cast(co.coords[i].pack());
                            c.prev_v = co.offsets[i];
                        }
                        c
                    })
                    .collect();
                self.ctx
                    .storage("control inputs", bytemuck::cast_slice(&cells))
            })
            .transpose()?;
        Ok(GpuGuide {
            level: g.level,
            window: g.window,
            flags,
            cells,
        })
    }

    fn correct_guided(
        &self,
        st: &GpuState,
        parent: Option<&GpuState>,
        level: usize,
        p: &CorrectParams,
        g: &GpuGuide,
    ) {
        let [x0, y0, x1, y1] = g.window.unwrap_or([0, 0, st.width, st.height]);
        let mut u = CorrectUniform {
            width: st.width as u32,
            height: st.height as u32,
            px: p.px,
            py: p.py,
            level: g.level,
            type_count: self.levels[level].type_count,
            prior: p.prior,
            x0: x0 as u32,
            y0: y0 as u32,
            x1: x1.min(st.width) as u32,
            y1: y1.min(st.height) as u32,
            parent_width: parent.map_or(0, |pa| pa.width as u32),
            parent_height: parent.map_or(0, |pa| pa.height as u32),
            has_parent: parent.is_some() as u32,
            ..Default::default()
        };
        u.flags = g.flags;
        let l = &self.levels[level];
        // Pixels of the parity class per axis: ⌈(n − parity) / 2⌉.
        let class = |n: usize, parity: u32| (n - parity as usize).div_ceil(2);
        self.ctx.dispatch(
            Some((Stage::Correct, level)),
            &self.ctx.correct,
            bytemuck::bytes_of(&u),
            &[
                &st.s,
                &st.v,
                &l.columns,
                &l.appearance,
                &l.similar,
                &l.type_data,
                g.cells.as_ref().unwrap_or(&self.placeholder),
                parent.map_or(&self.placeholder, |pa| &pa.v),
            ],
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
            Some((Stage::Reconstruct, 0)),
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

    fn upload_types(
        &self,
        data: &[u32],
        width: usize,
        height: usize,
    ) -> Result<GpuRaster, BackendError> {
        self.upload_raster("type sets", data, width, height)
    }

    fn upload_weights(
        &self,
        data: &[u8],
        width: usize,
        height: usize,
    ) -> Result<GpuRaster, BackendError> {
        let wide: Vec<u32> = data.iter().map(|&w| w as u32).collect();
        self.upload_raster("coherence weights", &wide, width, height)
    }

    fn reduce_types(
        &self,
        child: &GpuRaster,
        width: usize,
        height: usize,
        full: u32,
    ) -> Result<GpuRaster, BackendError> {
        let u = ReduceTypesUniform {
            width: width as u32,
            height: height as u32,
            child_width: child.width as u32,
            child_height: child.height as u32,
            full,
            ..Default::default()
        };
        let p = &self.ctx.reduce_types;
        self.reduce("type sets", p, bytemuck::bytes_of(&u), child, width, height)
    }

    fn reduce_weights(
        &self,
        child: &GpuRaster,
        width: usize,
        height: usize,
    ) -> Result<GpuRaster, BackendError> {
        let u = ReduceWeightsUniform {
            width: width as u32,
            height: height as u32,
            child_width: child.width as u32,
            child_height: child.height as u32,
        };
        let p = &self.ctx.reduce_weights;
        self.reduce(
            "coherence weights",
            p,
            bytemuck::bytes_of(&u),
            child,
            width,
            height,
        )
    }

    fn download_types(&self, r: &GpuRaster) -> Result<Vec<u32>, BackendError> {
        Ok(bytemuck::pod_collect_to_vec(&self.ctx.read(&r.buf)?))
    }

    fn download_weights(&self, r: &GpuRaster) -> Result<Vec<u8>, BackendError> {
        let wide: Vec<u32> = bytemuck::pod_collect_to_vec(&self.ctx.read(&r.buf)?);
        // Every stored weight is ≤ 255 (an uploaded u8 or a reduction's ≤ 4).
        Ok(wide.into_iter().map(|w| w as u8).collect())
    }

    fn finish(&self) -> Result<(), BackendError> {
        self.ctx.wait()
    }

    fn has_device_clock(&self) -> bool {
        self.ctx.profile.is_some()
    }

    fn device_times(&self) -> Result<Option<Vec<StageTime>>, BackendError> {
        self.ctx.stage_times()
    }
}
