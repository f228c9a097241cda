//! Per-dispatch GPU timestamps, where the adapter has timestamp queries.

use super::Context;
use crate::backend::{BackendError, Stage, StageTime};
use std::time::Duration;

/// Most timed dispatches between two reads of the times (a 4096² synthesis
/// makes ~120); later ones go untimed and the times are reported missing.
pub(super) const MAX_TIMED: u32 = 2048;

/// Begin/end timestamps of each dispatch since the last read.
pub(super) struct Profile {
    pub(super) queries: wgpu::QuerySet,
    /// What each pair of queries timed, in order.
    pub(super) labels: Vec<(Stage, usize)>,
    /// More dispatches than [`MAX_TIMED`] since the last read.
    pub(super) overflow: bool,
}

impl Context {
    /// Reads and forgets the timestamps recorded since the last call.
    pub(super) fn stage_times(&self) -> Result<Option<Vec<StageTime>>, BackendError> {
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
}
