//! Stage `correct` on the GPU (`kernels/correct.wgsl`), with the control
//! inputs it reads uploaded once per pass.

use super::{Gpu, GpuState, groups};
use crate::backend::{BackendError, check_guide};
use crate::stages::Stage;
use crate::stages::correct::{
    CORRECT_ALLOWED, CORRECT_COHERENCE, CORRECT_TARGETS, CorrectParams, CorrectUniform, Guide,
    GuideCell,
};

/// The control inputs of `correct` for one pass of one level on the device
/// ([`crate::backend::Backend::upload_guide`]): which controls are on, and one
/// [`GuideCell`] per pixel when any is.
pub struct GpuGuide {
    pub(super) level: u32,
    pub(super) origin: [u32; 2],
    pub(super) window: Option<[usize; 4]>,
    pub(super) flags: u32,
    pub(super) cells: Option<wgpu::Buffer>,
}

impl Gpu {
    pub(super) fn make_guide(
        &self,
        g: &Guide<'_>,
        width: usize,
        height: usize,
    ) -> Result<GpuGuide, BackendError> {
        check_guide(g, width, height)?;
        let mut flags = 0;
        for (on, flag) in [
            (g.targets.is_some(), CORRECT_TARGETS),
            (g.allowed.is_some(), CORRECT_ALLOWED),
            (g.coherence.is_some(), CORRECT_COHERENCE),
        ] {
            if on {
                flags |= flag;
            }
        }
        let cells = (flags != 0)
            .then(|| {
                let cells: Vec<GuideCell> = (0..width * height)
                    .map(|i| {
                        let mut c = GuideCell::default();
                        if let Some(t) = g.targets {
                            c.blend_target = [t[i].height, t[i].tol];
                        }
                        if let Some(a) = g.allowed {
                            c.allowed = a[i];
                        }
                        if let Some(co) = g.coherence {
                            c.weight = co.weights[i] as u32;
                            c.prev_s = bytemuck::cast(co.coords[i].pack());
                            c.prev_v = co.offsets[i];
                        }
                        c
                    })
                    .collect();
                self.ctx
                    .storage("control inputs", bytemuck::cast_slice(&cells))
            })
            .transpose()?;
        Ok(GpuGuide {
            level: g.level,
            origin: g.origin,
            window: g.window,
            flags,
            cells,
        })
    }

    /// One subpass of stage `correct`, with the control inputs `g` (`None`:
    /// no controls, the whole level).
    pub(super) fn dispatch_correct(
        &self,
        st: &GpuState,
        parent: Option<&GpuState>,
        level: usize,
        p: &CorrectParams,
        g: Option<&GpuGuide>,
    ) {
        let none = GpuGuide {
            level: level as u32,
            origin: [0, 0],
            window: None,
            flags: 0,
            cells: None,
        };
        let g = g.unwrap_or(&none);
        let [x0, y0, x1, y1] = g.window.unwrap_or([0, 0, st.width, st.height]);
        let mut u = CorrectUniform {
            width: st.width as u32,
            height: st.height as u32,
            px: p.px,
            py: p.py,
            level: g.level,
            type_count: self.levels[level].type_count,
            prior: p.prior,
            similar: p.similar as u32,
            x0: x0 as u32,
            y0: y0 as u32,
            x1: x1.min(st.width) as u32,
            y1: y1.min(st.height) as u32,
            parent_width: parent.map_or(0, |pa| pa.width as u32),
            parent_height: parent.map_or(0, |pa| pa.height as u32),
            has_parent: parent.is_some() as u32,
            origin_x: g.origin[0],
            origin_y: g.origin[1],
            ..Default::default()
        };
        u.flags = g.flags;
        let l = &self.levels[level];
        // Pixels of the parity class per axis: ⌈(n − parity) / 2⌉.
        let class = |n: usize, parity: u32| (n - parity as usize).div_ceil(2);
        self.ctx.dispatch(
            Stage::Correct,
            Some(level),
            bytemuck::bytes_of(&u),
            &[
                &st.s,
                &st.v,
                &l.columns,
                &l.appearance,
                &l.similar,
                &l.type_data,
                g.cells.as_ref().unwrap_or(&self.placeholder),
                parent.map_or(&self.placeholder, |pa| &pa.v),
            ],
            (
                groups(class(st.width, p.px)),
                groups(class(st.height, p.py)),
            ),
        );
    }
}
