//! The CPU backend: the rayon + SIMD stages of `stages`, state in
//! host memory. The reference every other backend is checked against.

use super::{Backend, BackendError, Raster};
use crate::isa::Isa;
use crate::level::atlas::AtlasLevel;
use crate::level::fixed::Coord;
use crate::level::state::State;
use crate::stages::correct::{self, CorrectParams};
use crate::stages::reconstruct;
use crate::stages::reduce_types::reduce_types;
use crate::stages::reduce_weights::reduce_weights;
use crate::stages::upsample_jitter::{self, Step, UpsampleParams};

/// Stages on the host, over one database's atlas levels.
pub struct Cpu<'a, 'db> {
    pub atlas: &'a [AtlasLevel<'db>],
    /// Level-0 heights (`Database::heights`).
    pub heights: &'a [u16],
    /// The instruction-set level the run-time-dispatched stages run at: a
    /// value, so that tests run every level in one process.
    pub isa: Isa,
}

impl<'a, 'db> Cpu<'a, 'db> {
    /// The CPU backend at the default level ([`Isa::default`]).
    pub fn new(atlas: &'a [AtlasLevel<'db>], heights: &'a [u16]) -> Cpu<'a, 'db> {
        Cpu {
            atlas,
            heights,
            isa: Isa::default(),
        }
    }
}

impl Backend for Cpu<'_, '_> {
    type State = State;
    type Types = Raster<u32>;
    type Weights = Raster<u8>;
    type Guide<'g> = correct::Guide<'g>;

    fn name(&self) -> &'static str {
        "cpu"
    }

    fn upload(&self, st: State) -> Result<State, BackendError> {
        Ok(st)
    }

    fn host_state(&self, st: State) -> Option<State> {
        Some(st)
    }

    fn alloc(&self, width: usize, height: usize) -> Result<State, BackendError> {
        Ok(State::new(width, height))
    }

    fn crop(&self, st: &State, rect: [usize; 4]) -> Result<State, BackendError> {
        Ok(st.crop(rect))
    }

    fn upsample_jitter(&self, parent: &State, child: &State, level: usize, p: &UpsampleParams) {
        let whole = [0, 0, child.width, child.height];
        self.upsample_jitter_rect(parent, child, level, p, whole);
    }

    fn upsample_jitter_rect(
        &self,
        parent: &State,
        child: &State,
        level: usize,
        p: &UpsampleParams,
        rect: [usize; 4],
    ) {
        let atlas = matches!(p.step, Step::Pyramid).then(|| &self.atlas[level]);
        upsample_jitter::upsample_jitter_rect(parent, child, atlas, p, rect, self.isa);
    }

    fn correct(&self, st: &State, parent: Option<&State>, level: usize, p: &CorrectParams) {
        correct::correct(&self.atlas[level], st, parent, p, self.isa);
    }

    fn upload_guide<'g>(
        &self,
        g: &correct::Guide<'g>,
        width: usize,
        height: usize,
    ) -> Result<correct::Guide<'g>, BackendError> {
        super::check_guide(g, width, height)?;
        Ok(*g)
    }

    fn correct_guided(
        &self,
        st: &State,
        parent: Option<&State>,
        level: usize,
        p: &CorrectParams,
        g: &correct::Guide<'_>,
    ) {
        correct::correct_guided(&self.atlas[level], st, parent, p, g, self.isa);
    }

    fn reconstruct(&self, st: &State) -> Result<Vec<i32>, BackendError> {
        Ok(reconstruct::reconstruct(&self.atlas[0], self.heights, st))
    }

    fn reconstruct_rect(
        &self,
        st: &State,
        prev: Vec<i32>,
        rect: [usize; 4],
    ) -> Result<Vec<i32>, BackendError> {
        let mut out = prev;
        reconstruct::reconstruct_rect(&self.atlas[0], self.heights, st, &mut out, rect);
        Ok(out)
    }

    fn download(&self, st: &State) -> Result<(Vec<Coord>, Vec<i32>), BackendError> {
        Ok((st.coords(), st.offsets()))
    }

    fn upload_types(&self, data: &[u32], w: usize, h: usize) -> Result<Raster<u32>, BackendError> {
        Raster::new("type sets", data, w, h)
    }

    fn upload_weights(&self, data: &[u8], w: usize, h: usize) -> Result<Raster<u8>, BackendError> {
        Raster::new("coherence weights", data, w, h)
    }

    fn reduce_types(
        &self,
        child: &Raster<u32>,
        width: usize,
        height: usize,
        full: u32,
    ) -> Result<Raster<u32>, BackendError> {
        let data = reduce_types(&child.data, child.width, child.height, width, height, full);
        Ok(Raster {
            width,
            height,
            data,
        })
    }

    fn reduce_weights(
        &self,
        child: &Raster<u8>,
        width: usize,
        height: usize,
    ) -> Result<Raster<u8>, BackendError> {
        let data = reduce_weights(&child.data, child.width, child.height, width, height);
        Ok(Raster {
            width,
            height,
            data,
        })
    }

    fn download_types(&self, r: &Raster<u32>) -> Result<Vec<u32>, BackendError> {
        Ok(r.data.clone())
    }

    fn download_weights(&self, r: &Raster<u8>) -> Result<Vec<u8>, BackendError> {
        Ok(r.data.clone())
    }

    fn finish(&self) -> Result<(), BackendError> {
        Ok(())
    }
}
