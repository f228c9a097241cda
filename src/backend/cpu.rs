//! The CPU backend: the rayon + SIMD stages of `synth::stages`, state in
//! host memory. The reference every other backend is checked against.

use super::{Backend, BackendError};
use crate::synth::atlas::AtlasLevel;
use crate::synth::fixed::Coord;
use crate::synth::stages::correct::{self, CorrectParams};
use crate::synth::stages::reconstruct;
use crate::synth::stages::upsample_jitter::{self, Step, UpsampleParams};
use crate::synth::state::State;

/// Stages on the host, over one database's atlas levels.
pub struct Cpu<'a, 'db> {
    pub atlas: &'a [AtlasLevel<'db>],
    /// Level-0 heights (`Database::heights`).
    pub heights: &'a [u16],
}

impl Backend for Cpu<'_, '_> {
    type State = State;

    fn name(&self) -> &'static str {
        "cpu"
    }

    fn upload(&self, st: State) -> Result<State, BackendError> {
        Ok(st)
    }

    fn alloc(&self, width: usize, height: usize) -> Result<State, BackendError> {
        Ok(State::new(width, height))
    }

    fn upsample_jitter(&self, parent: &State, child: &State, level: usize, p: &UpsampleParams) {
        let atlas = matches!(p.step, Step::Pyramid).then(|| &self.atlas[level]);
        upsample_jitter::upsample_jitter(parent, child, atlas, p);
    }

    fn correct(&self, st: &State, level: usize, p: &CorrectParams) {
        correct::correct(&self.atlas[level], st, p);
    }

    fn reconstruct(&self, st: &State) -> Result<Vec<i32>, BackendError> {
        Ok(reconstruct::reconstruct(&self.atlas[0], self.heights, st))
    }

    fn download(&self, st: &State) -> Result<(Vec<Coord>, Vec<i32>), BackendError> {
        Ok((st.coords(), st.offsets()))
    }

    fn finish(&self) -> Result<(), BackendError> {
        Ok(())
    }
}
