//! Device buffers: storage buffers checked against the device's limits,
//! and the copy back to the host.

use super::Context;
use crate::backend::BackendError;
use std::sync::mpsc;
use wgpu::util::DeviceExt;

impl Context {
    /// Largest storage buffer the device binds.
    pub(super) fn max_buffer(&self) -> u64 {
        self.limits
            .max_storage_buffer_binding_size
            .min(self.limits.max_buffer_size)
    }

    pub(super) fn check_size(&self, what: &'static str, bytes: u64) -> Result<(), BackendError> {
        let limit = self.max_buffer();
        if bytes == 0 || bytes > limit {
            return Err(BackendError::TooLarge { what, bytes, limit });
        }
        Ok(())
    }

    /// A storage buffer holding `bytes` (padded to whole u32 words).
    pub(super) fn storage(
        &self,
        what: &'static str,
        bytes: &[u8],
    ) -> Result<wgpu::Buffer, BackendError> {
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
    pub(super) fn storage_empty(
        &self,
        what: &'static str,
        bytes: u64,
    ) -> Result<wgpu::Buffer, BackendError> {
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

    /// Copies a device buffer back to the host (waits for queued work).
    /// Copies `buffer` back to the host as `T`s, after every pass recorded
    /// so far (one copy on the host: mapped bytes straight into the `Vec`).
    pub(super) fn read<T: bytemuck::Pod>(
        &self,
        buffer: &wgpu::Buffer,
    ) -> Result<Vec<T>, BackendError> {
        let size = buffer.size();
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        self.recorder()
            .encoder(&self.device)
            .copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
        // Submitted before mapping: a buffer waiting to be mapped may not be
        // used by a later submission.
        self.flush();
        let (tx, rx) = mpsc::channel();
        staging.slice(..).map_async(wgpu::MapMode::Read, move |r| {
            // The receiver outlives the poll below; a send cannot fail.
            let _ = tx.send(r);
        });
        self.wait()?;
        rx.recv()
            .map_err(|e| BackendError::Gpu(e.to_string()))?
            .map_err(|e| BackendError::Gpu(e.to_string()))?;
        let data = bytemuck::pod_collect_to_vec(
            &staging
                .slice(..)
                .get_mapped_range()
                .map_err(|e| BackendError::Gpu(e.to_string()))?,
        );
        Ok(data)
    }
}
