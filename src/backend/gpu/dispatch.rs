//! Recording compute dispatches, and submitting them in batches.
//!
//! Every stage call records one compute pass into a shared command encoder;
//! the encoder is submitted every [`BATCH`] passes and before anything
//! reads the device back ([`Context::flush`]). Submitting each pass on its
//! own cost a queue submission per pass (~100 per 1024² synthesis), host
//! time the GPU spent idle. Passes in one encoder run in recording order
//! and wgpu places the barriers between them, so a subpass still sees the
//! previous one's writes; nothing is uploaded with `Queue::write_buffer`
//! (which would overtake passes still waiting in the encoder): uploads make
//! new buffers.

use super::Context;
use super::timing::Labels;
use crate::stages::Stage;
use std::sync::MutexGuard;
use wgpu::util::DeviceExt;

/// Passes recorded before the encoder is submitted: enough to amortise a
/// submission, few enough that the GPU starts while the host records on.
const BATCH: u32 = 16;

/// The passes recorded and not yet submitted, and the timestamp labels.
#[derive(Default)]
pub(super) struct Recorder {
    encoder: Option<wgpu::CommandEncoder>,
    passes: u32,
    pub(super) labels: Labels,
}

impl Recorder {
    /// The open encoder (a new one when the last was submitted).
    pub(super) fn encoder(&mut self, device: &wgpu::Device) -> &mut wgpu::CommandEncoder {
        self.encoder
            .get_or_insert_with(|| device.create_command_encoder(&Default::default()))
    }

    fn submit(&mut self, queue: &wgpu::Queue) {
        if let Some(enc) = self.encoder.take() {
            queue.submit([enc.finish()]);
        }
        self.passes = 0;
    }
}

impl Context {
    pub(super) fn recorder(&self) -> MutexGuard<'_, Recorder> {
        // A panic while recording leaves nothing half-written that a later
        // pass could misread: the poisoned recorder is still usable.
        self.recorder.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Submits every pass recorded so far.
    pub(super) fn flush(&self) {
        self.recorder().submit(&self.queue);
    }

    /// Records one dispatch of `stage`'s kernel: `uniform` at binding 0,
    /// `buffers` at bindings 1.., `groups` workgroups; timed as the stage
    /// at level `timed` when given (the synthesis stages) and the device
    /// has timestamps.
    pub(super) fn dispatch(
        &self,
        stage: Stage,
        timed: Option<usize>,
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
        let pipeline = self.pipeline(stage);
        let bind = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(0),
            entries: &entries,
        });
        let mut rec = self.recorder();
        let slot = self.queries.as_ref().zip(timed).and_then(|(q, level)| {
            let k = rec.labels.push(std::thread::current().id(), stage, level)?;
            Some(wgpu::ComputePassTimestampWrites {
                query_set: q,
                beginning_of_pass_write_index: Some(2 * k),
                end_of_pass_write_index: Some(2 * k + 1),
            })
        });
        {
            let mut pass =
                rec.encoder(&self.device)
                    .begin_compute_pass(&wgpu::ComputePassDescriptor {
                        label: None,
                        timestamp_writes: slot,
                    });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups(groups.0, groups.1, 1);
        }
        rec.passes += 1;
        if rec.passes >= BATCH {
            rec.submit(&self.queue);
        }
    }
}
