//! Per-dispatch GPU timestamps, where the adapter has timestamp queries.
//!
//! One [`super::Context`] is shared by every synthesizer of a process (the
//! editor's sessions, parallel tests), so the timed dispatches of several
//! syntheses interleave in one query set. Each timed dispatch is labelled
//! with the thread that recorded it — a synthesis records all its
//! dispatches from the thread that drives it — and a read takes only the
//! calling thread's times, leaving the others' for their own reads.

use super::Context;
use crate::backend::{BackendError, StageTime};
use crate::stages::Stage;
use std::thread::ThreadId;
use std::time::Duration;

/// Query-pair slots between two moments when no timed dispatch is
/// outstanding (a 4096² synthesis makes ~120); later dispatches go untimed
/// and their synthesis reports its times missing.
pub(super) const MAX_TIMED: u32 = 2048;

/// What each query pair timed, and for whom.
#[derive(Debug, Default)]
pub(super) struct Labels {
    /// Outstanding timed dispatches: thread, query-pair slot (none when the
    /// slots had run out), stage and level.
    entries: Vec<(ThreadId, Option<u32>, Stage, usize)>,
    /// The next free slot; back to 0 once no entry is outstanding.
    next: u32,
}

impl Labels {
    /// Labels a dispatch recorded by `thread`; its query-pair slot, or
    /// `None` when all [`MAX_TIMED`] are taken.
    pub(super) fn push(&mut self, thread: ThreadId, stage: Stage, level: usize) -> Option<u32> {
        let slot = (self.next < MAX_TIMED).then_some(self.next);
        self.next += slot.is_some() as u32;
        self.entries.push((thread, slot, stage, level));
        slot
    }

    /// Takes `thread`'s labels in recording order: `(slot, stage, level)`,
    /// or `None` when one of them went untimed.
    pub(super) fn take(&mut self, thread: ThreadId) -> Option<Vec<(u32, Stage, usize)>> {
        let mut mine = Vec::new();
        let mut complete = true;
        self.entries.retain(|&(t, slot, stage, level)| {
            if t != thread {
                return true;
            }
            match slot {
                Some(s) => mine.push((s, stage, level)),
                None => complete = false,
            }
            false
        });
        if self.entries.is_empty() {
            self.next = 0;
        }
        complete.then_some(mine)
    }
}

impl Context {
    /// Reads and forgets the timestamps this thread recorded since its last
    /// call (`None`: no timestamp queries, or some dispatch went untimed).
    pub(super) fn stage_times(&self) -> Result<Option<Vec<StageTime>>, BackendError> {
        let Some(queries) = &self.queries else {
            return Ok(None);
        };
        let mut rec = self.recorder();
        let Some(taken) = rec.labels.take(std::thread::current().id()) else {
            return Ok(None);
        };
        let (Some(first), Some(last)) = (taken.first(), taken.last()) else {
            return Ok(Some(Vec::new()));
        };
        // Slots are handed out in recording order, so this thread's lie in
        // first..=last; every slot up to `last` was recorded before this
        // lock was taken, so the resolve below comes after all of them.
        let (first, n) = (first.0, 2 * (last.0 - first.0 + 1));
        let resolved = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamps"),
            size: n as u64 * 8,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        rec.encoder(&self.device).resolve_query_set(
            queries,
            2 * first..2 * first + n,
            &resolved,
            0,
        );
        drop(rec);
        let ticks: Vec<u64> = self.read(&resolved)?;
        let period_ns = self.queue.get_timestamp_period() as f64;
        Ok(Some(stage_times(&taken, first, &ticks, period_ns)))
    }
}

/// The stage times of query pairs `taken`, from the resolved ticks of
/// slots `first..` (`ticks[2k], ticks[2k + 1]` = begin and end of slot
/// `first + k`) and the queue's timestamp period.
pub(super) fn stage_times(
    taken: &[(u32, Stage, usize)],
    first: u32,
    ticks: &[u64],
    period_ns: f64,
) -> Vec<StageTime> {
    taken
        .iter()
        .map(|&(slot, stage, level)| {
            let k = 2 * (slot - first) as usize;
            // Host-side conversion of tick counts (floats are fine here, DESIGN §6 rule 5).
            let ns = ticks[k + 1].saturating_sub(ticks[k]) as f64 * period_ns;
            StageTime {
                stage,
                level,
                time: Duration::from_nanos(ns as u64),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn other_thread() -> ThreadId {
        std::thread::spawn(|| std::thread::current().id())
            .join()
            .unwrap()
    }

    #[test]
    fn each_thread_takes_only_its_own_times() {
        let (a, b) = (std::thread::current().id(), other_thread());
        let mut l = Labels::default();
        assert_eq!(l.push(a, Stage::UpsampleJitter, 7), Some(0));
        assert_eq!(l.push(b, Stage::Correct, 3), Some(1));
        assert_eq!(l.push(a, Stage::Correct, 7), Some(2));
        assert_eq!(
            l.take(a),
            Some(vec![(0, Stage::UpsampleJitter, 7), (2, Stage::Correct, 7)])
        );
        // b's dispatch is still outstanding: its slot stays taken.
        assert_eq!(l.push(a, Stage::Reconstruct, 0), Some(3));
        assert_eq!(l.take(b), Some(vec![(1, Stage::Correct, 3)]));
        assert_eq!(l.take(a), Some(vec![(3, Stage::Reconstruct, 0)]));
        // Nothing outstanding: the slots are free again.
        assert_eq!(l.push(b, Stage::Correct, 0), Some(0));
    }

    #[test]
    fn running_out_of_slots_loses_only_the_overflowing_threads_times() {
        let (a, b) = (std::thread::current().id(), other_thread());
        let mut l = Labels::default();
        assert_eq!(l.push(b, Stage::Correct, 1), Some(0));
        for _ in 1..MAX_TIMED {
            assert!(l.push(a, Stage::Correct, 0).is_some());
        }
        assert_eq!(l.push(a, Stage::Correct, 0), None);
        assert_eq!(l.take(a), None);
        assert_eq!(l.take(b), Some(vec![(0, Stage::Correct, 1)]));
        assert_eq!(l.push(a, Stage::Correct, 0), Some(0));
    }

    #[test]
    fn times_come_from_each_slots_own_pair() {
        let taken = [(5, Stage::Correct, 2), (7, Stage::Reconstruct, 0)];
        // Slots 5, 6, 7 resolved from slot 5: begin/end ticks per slot.
        let ticks = [100, 150, 0, 0, 1000, 1400];
        let t = stage_times(&taken, 5, &ticks, 2.0);
        assert_eq!(t[0].time, Duration::from_nanos(100));
        assert_eq!((t[1].stage, t[1].level), (Stage::Reconstruct, 0));
        assert_eq!(t[1].time, Duration::from_nanos(800));
    }
}
