//! The device and its compiled kernels: adapter choice, device creation and
//! one compute pipeline per stage of the table (`stages::Stage::ALL`).

use super::dispatch::Recorder;
use super::timing::MAX_TIMED;
use crate::backend::BackendError;
use crate::backend::kernels;
use crate::stages::Stage;
use std::sync::{Arc, Mutex};

/// A device with the kernels compiled: create once, share (`Arc`) between
/// synthesizers — compiling the shaders is the slow part on lavapipe.
pub struct Context {
    pub(super) device: wgpu::Device,
    pub(super) queue: wgpu::Queue,
    pub(super) info: wgpu::AdapterInfo,
    pub(super) limits: wgpu::Limits,
    /// Each stage's kernel, at its index in [`Stage::ALL`].
    pipelines: [wgpu::ComputePipeline; Stage::ALL.len()],
    /// Timestamp queries (two per timed dispatch), where the adapter has them.
    pub(super) queries: Option<wgpu::QuerySet>,
    /// Passes recorded and not yet submitted, and what the queries time.
    pub(super) recorder: Mutex<Recorder>,
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
        let pipeline = |s: Stage| {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(s.name()),
                source: wgpu::ShaderSource::Wgsl(kernels::module_source(s).into()),
            });
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(s.name()),
                layout: None,
                module: &module,
                entry_point: Some(kernels::ENTRY_POINT),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let pipelines = Stage::ALL.map(pipeline);
        if let Some(e) = scope.pop().await {
            return Err(BackendError::Gpu(e.to_string()));
        }
        let queries = features.contains(wgpu::Features::TIMESTAMP_QUERY).then(|| {
            device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("stage timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2 * MAX_TIMED,
            })
        });
        Ok(Arc::new(Context {
            queries,
            recorder: Mutex::default(),
            info: adapter.get_info(),
            device,
            queue,
            limits,
            pipelines,
        }))
    }

    /// `stage`'s compiled kernel.
    pub(super) fn pipeline(&self, stage: Stage) -> &wgpu::ComputePipeline {
        &self.pipelines[stage as usize]
    }

    /// Whether stage times come from GPU timestamp queries (else wall clock).
    pub fn has_timestamps(&self) -> bool {
        self.queries.is_some()
    }

    /// The adapter, e.g. "llvmpipe (LLVM 15.0.6, 256 bits) (Vulkan)".
    pub fn adapter_name(&self) -> String {
        format!("{} ({:?})", self.info.name, self.info.backend)
    }

    /// Submits what is recorded and waits until the device is idle.
    pub(super) fn wait(&self) -> Result<(), BackendError> {
        self.flush();
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| BackendError::Gpu(e.to_string()))
    }
}
