//! [`Backend`] for [`Gpu`]: each method hands over to the stage's own
//! module, except the two reductions, which are one shared dispatch
//! (`rasters`) with the stage's parameter block.

use super::{Gpu, GpuGuide, GpuRaster, GpuState};
use crate::backend::{Backend, BackendError, StageTime};
use crate::level::fixed::Coord;
use crate::level::state::State;
use crate::stages::Stage;
use crate::stages::correct::{CorrectParams, Guide};
use crate::stages::reduce_types::ReduceTypesUniform;
use crate::stages::reduce_weights::ReduceWeightsUniform;
use crate::stages::upsample_jitter::UpsampleParams;

impl Backend for Gpu {
    type State = GpuState;
    type Types = GpuRaster;
    type Weights = GpuRaster;
    type Guide<'g> = GpuGuide;

    fn name(&self) -> &'static str {
        "gpu"
    }

    fn upload(&self, st: State) -> Result<GpuState, BackendError> {
        self.upload_state(st)
    }

    fn alloc(&self, width: usize, height: usize) -> Result<GpuState, BackendError> {
        self.alloc_state(width, height)
    }

    fn crop(&self, st: &GpuState, rect: [usize; 4]) -> Result<GpuState, BackendError> {
        self.crop_state(st, rect)
    }

    fn upsample_jitter(
        &self,
        parent: &GpuState,
        child: &GpuState,
        level: usize,
        p: &UpsampleParams,
    ) {
        self.dispatch_upsample_jitter(parent, child, level, p)
    }

    fn correct(&self, st: &GpuState, parent: Option<&GpuState>, level: usize, p: &CorrectParams) {
        self.dispatch_correct(st, parent, level, p, None)
    }

    fn upload_guide(
        &self,
        g: &Guide<'_>,
        width: usize,
        height: usize,
    ) -> Result<GpuGuide, BackendError> {
        self.make_guide(g, width, height)
    }

    fn correct_guided(
        &self,
        st: &GpuState,
        parent: Option<&GpuState>,
        level: usize,
        p: &CorrectParams,
        g: &GpuGuide,
    ) {
        self.dispatch_correct(st, parent, level, p, Some(g))
    }

    fn reconstruct(&self, st: &GpuState) -> Result<Vec<i32>, BackendError> {
        self.dispatch_reconstruct(st, <[i32]>::to_vec)
    }

    fn reconstruct_with<R>(
        &self,
        st: &GpuState,
        f: impl FnOnce(&[i32]) -> R,
    ) -> Result<R, BackendError> {
        self.dispatch_reconstruct(st, f)
    }

    fn download(&self, st: &GpuState) -> Result<(Vec<Coord>, Vec<i32>), BackendError> {
        self.download_state(st)
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
        self.upload_weight_raster(data, width, height)
    }

    fn reduce_types(
        &self,
        child: &GpuRaster,
        width: usize,
        height: usize,
        full: u32,
    ) -> Result<GpuRaster, BackendError> {
        let u = ReduceTypesUniform::new(width, height, (child.width, child.height), full);
        self.reduce("type sets", Stage::ReduceTypes, &u, child, width, height)
    }

    fn reduce_weights(
        &self,
        child: &GpuRaster,
        width: usize,
        height: usize,
    ) -> Result<GpuRaster, BackendError> {
        let u = ReduceWeightsUniform::new(width, height, (child.width, child.height));
        self.reduce(
            "coherence weights",
            Stage::ReduceWeights,
            &u,
            child,
            width,
            height,
        )
    }

    fn download_types(&self, r: &GpuRaster) -> Result<Vec<u32>, BackendError> {
        self.download_type_raster(r)
    }

    fn download_weights(&self, r: &GpuRaster) -> Result<Vec<u8>, BackendError> {
        self.download_weight_raster(r)
    }

    fn finish(&self) -> Result<(), BackendError> {
        self.ctx.wait()
    }

    fn has_device_clock(&self) -> bool {
        self.ctx.queries.is_some()
    }

    fn device_times(&self) -> Result<Option<Vec<StageTime>>, BackendError> {
        self.ctx.stage_times()
    }
}
