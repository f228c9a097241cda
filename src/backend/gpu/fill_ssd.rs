//! Stage `fill_ssd` on the GPU (`kernels/fill_ssd.wgsl`): round one of the
//! patch engine's hole filling, the mirror of
//! [`crate::stages::fill_ssd::fill_ssd_table`]. A source's candidate cells are
//! uploaded once ([`FillSource`]) and stay on the device for every window
//! of a synthesis; per window only the user's permuted cells go up and one
//! `(s, s2)` pair per candidate and transform comes back. The kernel sums
//! in integers (s2 in two u32 words); the host ends with
//! [`dc_ssd`] like the CPU, so the table is the same
//! bytes.

use super::Context;
use crate::backend::BackendError;
use crate::stages::Stage;
use crate::stages::fill_ssd::{FillSsdUniform, dc_ssd};

/// One source's candidate cells on the device.
pub struct FillSource {
    cells: usize,
    candidates: usize,
    buf: wgpu::Buffer,
}

impl FillSource {
    /// The number of candidates.
    pub fn candidates(&self) -> usize {
        self.candidates
    }
}

impl Context {
    /// Uploads a source's candidate cells: `cells` per candidate,
    /// contiguous (`PreparedSource::fill_cells`).
    pub fn upload_fill_source(
        &self,
        data: &[i32],
        cells: usize,
    ) -> Result<FillSource, BackendError> {
        if cells == 0 || data.len() % cells != 0 {
            return Err(BackendError::RasterSize {
                what: "fill candidate cells",
                len: data.len(),
                width: cells,
                height: data.len() / cells.max(1),
            });
        }
        // A binding needs a buffer: one zero cell row for a source without
        // candidates (the kernel reads none of it then).
        let zeros = vec![0i32; cells];
        let bytes = if data.is_empty() { &zeros[..] } else { data };
        Ok(FillSource {
            cells,
            candidates: data.len() / cells,
            buf: self.storage("fill candidate cells", bytemuck::cast_slice(bytes))?,
        })
    }

    /// The round-one table of one window against `src`: entry
    /// `k · transforms + v` is candidate k's DC-corrected SSD under
    /// transform v (`user[v]`, `mask[v]`, each `cells` long) over `count`
    /// valid cells.
    pub fn fill_ssd(
        &self,
        src: &FillSource,
        user: &[Vec<i32>],
        mask: &[Vec<i32>],
        count: i64,
    ) -> Result<Vec<u64>, BackendError> {
        let transforms = user.len();
        if mask.len() != transforms || user.iter().chain(mask).any(|v| v.len() != src.cells) {
            return Err(BackendError::RasterSize {
                what: "fill user cells",
                len: user.iter().chain(mask).map(Vec::len).sum(),
                width: src.cells,
                height: 2 * transforms,
            });
        }
        if transforms == 0 || src.candidates == 0 {
            return Ok(Vec::new());
        }
        // One invocation per candidate along x: at most 65535 workgroups.
        let most = 65535 * super::kernels::WORKGROUP as usize;
        if src.candidates > most {
            return Err(BackendError::Gpu(format!(
                "{} fill candidates in one source: at most {most} per dispatch",
                src.candidates
            )));
        }
        let words: Vec<i32> = user.iter().chain(mask).flatten().copied().collect();
        let user_buf = self.storage("fill user cells", bytemuck::cast_slice(&words))?;
        let n = (src.candidates * transforms) as u64;
        let out = self.storage_empty("fill sums", n * 16)?;
        let u = FillSsdUniform {
            cells: src.cells as u32,
            candidates: src.candidates as u32,
            transforms: transforms as u32,
            pad0: 0,
        };
        self.dispatch(
            Stage::FillSsd,
            None,
            bytemuck::bytes_of(&u),
            &[&user_buf, &src.buf, &out],
            (super::groups(src.candidates), super::groups(transforms)),
        );
        let sums: Vec<[u32; 4]> = self.read(&out)?;
        Ok(sums
            .iter()
            .map(|&[s, lo, hi, _]| {
                let s2 = ((hi as u64) << 32 | lo as u64) as i64;
                dc_ssd(s as i32 as i64, s2, count)
            })
            .collect())
    }
}
