//! Progress reporting without a UI dependency: long library work (erosion,
//! database builds, synthesis) reports through this trait, and the CLI maps it
//! onto a terminal progress bar that hides itself when output is piped.

/// Receives progress of long-running work. Implementations must be cheap:
/// `advance` is called from worker threads.
pub trait Progress: Sync {
    /// A new stage begins with `total` units of work.
    fn start(&self, stage: &str, total: u64);
    /// `n` more units are done.
    fn advance(&self, n: u64);
    /// The current stage is over.
    fn finish(&self);
}

/// Reports nothing.
#[derive(Debug, Default, Clone, Copy)]
pub struct Silent;

impl Progress for Silent {
    fn start(&self, _stage: &str, _total: u64) {}
    fn advance(&self, _n: u64) {}
    fn finish(&self) {}
}
