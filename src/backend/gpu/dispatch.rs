//! Recording and submitting one compute dispatch.

use super::Context;
use super::timing::MAX_TIMED;
use crate::backend::Stage;
use wgpu::util::DeviceExt;

impl Context {
    /// Records and submits one dispatch: `uniform` at binding 0, `buffers`
    /// at bindings 1.., `groups` workgroups; timed as `label` (a synthesis
    /// stage and its level) when given and the device has timestamps.
    pub(super) fn dispatch(
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
}
