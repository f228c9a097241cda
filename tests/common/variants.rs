//! Every way a stage runs, against one result (DESIGN §6): the scalar
//! oracle, the CPU's fast path (rayon, explicit SIMD where the stage has
//! it) at every instruction-set level this CPU has (`Isa::all`: the
//! portable copy and AVX2, for the stages that dispatch on it) and, with
//! `--features gpu` and an adapter, the WGSL kernel. Each stage test draws
//! its inputs once, asks for every variant's output here and checks them
//! all with [`assert_agree`] — one loop, whatever was built, in one run.

use std::fmt::Debug;
use terrasynth::backend::engine::Engine;
use terrasynth::backend::{Backend, BackendError, cpu::Cpu};
use terrasynth::database::Database;
use terrasynth::isa::Isa;
use terrasynth::level::atlas::AtlasLevel;
use terrasynth::level::fixed::Coord;
use terrasynth::level::state::{State, level_size, top_level};
use terrasynth::stages::correct::{CorrectParams, Guide, PRIORS, SUBPASSES, scalar};
use terrasynth::stages::fill_ssd::{fill_ssd_scalar, fill_ssd_table};
use terrasynth::stages::shade::{ShadeBuffers, ShadeParams};
use terrasynth::stages::upsample_jitter::UpsampleParams;

#[cfg(feature = "gpu")]
use terrasynth::backend::gpu::Gpu;

use super::states::{copy, pixels};

/// One variant's output: its name and values (one per pixel or entry).
pub type Run<T> = (&'static str, Vec<T>);

/// Every run equals the first (the oracle), value for value; a difference
/// names the variant, the value's index and both values.
pub fn assert_agree<T: PartialEq + Debug>(runs: &[Run<T>], what: &str) {
    let (oracle, want) = &runs[0];
    for (name, got) in &runs[1..] {
        if let Some(i) = (0..want.len().min(got.len())).find(|&i| got[i] != want[i]) {
            panic!(
                "{what}: {name} differs from {oracle} first at {i}: {:?} vs {:?}",
                got[i], want[i]
            );
        }
        assert_eq!(got.len(), want.len(), "{what}: {name}'s length");
    }
}

/// The upload of 5 values as a 2 × 3 raster was refused with
/// [`BackendError::RasterSize`] (a stage indexes rasters by pixel: a short
/// one must be a typed error, never an out-of-bounds read).
pub fn assert_mis_sized(r: Result<(), BackendError>) {
    assert!(
        matches!(
            r,
            Err(BackendError::RasterSize {
                len: 5,
                width: 2,
                height: 3,
                ..
            })
        ),
        "{r:?}"
    )
}

/// Whether a stage without a CPU fast path has anything to compare (a
/// GPU); says so when not.
pub fn gpu_or_skip(stage: &str) -> bool {
    #[cfg(feature = "gpu")]
    if super::gpu::context().is_some() {
        return true;
    }
    eprintln!("no GPU variant: stage {stage} has nothing to compare its CPU result against");
    false
}

/// The level stages' variants over one database: its atlas, and the GPU
/// bound to it where there is one.
pub struct Rig<'db> {
    pub atlas: Vec<AtlasLevel<'db>>,
    pub heights: &'db [u16],
    #[cfg(feature = "gpu")]
    pub gpu: Option<Gpu>,
}

/// The rig of `db`, built once per test binary and database.
pub fn rig(db: &'static Database) -> &'static Rig<'static> {
    use std::sync::Mutex;
    static RIGS: Mutex<Vec<(usize, &'static Rig<'static>)>> = Mutex::new(Vec::new());
    let mut rigs = RIGS.lock().unwrap_or_else(|e| e.into_inner());
    let key = db as *const Database as usize;
    if let Some(&(_, r)) = rigs.iter().find(|(k, _)| *k == key) {
        return r;
    }
    let atlas: Vec<_> = (0..db.level_count())
        .map(|i| AtlasLevel::new(db, i))
        .collect();
    #[cfg(feature = "gpu")]
    let gpu = super::gpu::context().map(|ctx| Gpu::new(ctx, &atlas, db.heights()).unwrap());
    // Leaked like the databases: borrowed for the whole run.
    let r: &'static Rig<'static> = Box::leak(Box::new(Rig {
        atlas,
        heights: db.heights(),
        #[cfg(feature = "gpu")]
        gpu,
    }));
    rigs.push((key, r));
    r
}

impl<'db> Rig<'db> {
    /// The CPU backend (the stages' fast paths) at the default level.
    pub fn cpu(&self) -> Cpu<'_, 'db> {
        Cpu::new(&self.atlas, self.heights)
    }

    /// The CPU backend at every level this CPU has, each named by it.
    fn cpus(&self) -> impl Iterator<Item = (&'static str, Cpu<'_, 'db>)> {
        Isa::all().iter().map(|&isa| {
            let cpu = Cpu { isa, ..self.cpu() };
            (isa.name(), cpu)
        })
    }

    /// Whether a GPU variant runs.
    pub fn has_gpu(&self) -> bool {
        #[cfg(feature = "gpu")]
        if self.gpu.is_some() {
            return true;
        }
        false
    }

    /// Stage `correct`, one subpass at `level` from `st` (the level above:
    /// `parent`): `scalar`, the CPU backend at each [`Isa`] (`portable`,
    /// `avx2`) and `gpu`. Without a guide through each variant's plain
    /// entry point, with one through its guided one.
    pub fn correct(
        &self,
        level: usize,
        (st, parent): (&State, Option<&State>),
        p: &CorrectParams,
        g: Option<&Guide<'_>>,
    ) -> Vec<Run<(Coord, i32)>> {
        let atlas = &self.atlas[level];
        let out = |s: &State| pixels(&s.coords(), &s.offsets());
        let oracle = copy(st);
        match g {
            None => scalar::correct(atlas, &oracle, parent, p),
            Some(g) => scalar::correct_guided(atlas, &oracle, parent, p, g),
        }
        let mut runs = vec![("scalar", out(&oracle))];
        for (name, cpu) in self.cpus() {
            let fast = copy(st);
            match g {
                None => cpu.correct(&fast, parent, level, p),
                Some(g) => {
                    let cg = cpu.upload_guide(g, st.width, st.height).unwrap();
                    cpu.correct_guided(&fast, parent, level, p, &cg);
                }
            }
            runs.push((name, out(&fast)));
        }
        #[cfg(feature = "gpu")]
        if let Some(gpu) = &self.gpu {
            let gs = gpu.upload(copy(st)).unwrap();
            let gp = parent.map(|pa| gpu.upload(copy(pa)).unwrap());
            match g {
                None => gpu.correct(&gs, gp.as_ref(), level, p),
                Some(g) => {
                    let gg = gpu.upload_guide(g, st.width, st.height).unwrap();
                    gpu.correct_guided(&gs, gp.as_ref(), level, p, &gg);
                }
            }
            let (c, v) = gpu.download(&gs).unwrap();
            runs.push(("gpu", pixels(&c, &v)));
        }
        runs
    }

    /// [`Rig::correct`] for every subpass at every height prior weight,
    /// with and without C₂, each from copies of `st`; every variant must
    /// agree.
    pub fn correct_at_every_prior(
        &self,
        level: usize,
        (st, parent): (&State, Option<&State>),
        g: Option<&Guide<'_>>,
        what: &str,
    ) {
        for &(px, py) in &SUBPASSES {
            for &prior in &PRIORS {
                for similar in [true, false] {
                    let p = CorrectParams {
                        px,
                        py,
                        prior,
                        similar,
                    };
                    let runs = self.correct(level, (st, parent), &p, g);
                    let what = format!("{what}, subpass ({px},{py}), prior {prior}, C₂ {similar}");
                    assert_agree(&runs, &what);
                }
            }
        }
    }

    /// Stage `upsample_jitter` from `parent` into a `w × h` level `level`:
    /// the CPU backend at each [`Isa`] and `gpu`.
    pub fn upsample_jitter(
        &self,
        parent: &State,
        (w, h): (usize, usize),
        level: usize,
        p: &UpsampleParams,
    ) -> Vec<Run<(Coord, i32)>> {
        let mut runs = Vec::new();
        for (name, cpu) in self.cpus() {
            let child = State::new(w, h);
            cpu.upsample_jitter(parent, &child, level, p);
            runs.push((name, pixels(&child.coords(), &child.offsets())));
        }
        #[cfg(feature = "gpu")]
        if let Some(gpu) = &self.gpu {
            let gp = gpu.upload(copy(parent)).unwrap();
            let gc = gpu.alloc(w, h).unwrap();
            gpu.upsample_jitter(&gp, &gc, level, p);
            let (c, v) = gpu.download(&gc).unwrap();
            runs.push(("gpu", pixels(&c, &v)));
        }
        runs
    }

    /// Stage `reconstruct` of a level-0 state: `cpu` and `gpu`.
    pub fn reconstruct(&self, st: &State) -> Vec<Run<i32>> {
        #[allow(unused_mut)]
        let mut runs = vec![("cpu", self.cpu().reconstruct(st).unwrap())];
        #[cfg(feature = "gpu")]
        if let Some(gpu) = &self.gpu {
            let g = gpu.upload(copy(st)).unwrap();
            runs.push(("gpu", gpu.reconstruct(&g).unwrap()));
        }
        runs
    }

    /// Stage `reduce_types` level by level from `r0` (`w × h`), with the
    /// level sizes of a synthesis (`level_size`, at least 2 × 2, so the top
    /// levels have pixels without children) one past its top, the GPU's
    /// rasters staying on the device: per level, `cpu` and `gpu`.
    pub fn reduce_types(
        &self,
        r0: &[u32],
        (w, h): (usize, usize),
        full: u32,
    ) -> Vec<Vec<Run<u32>>> {
        let cpu = self.cpu();
        let mut c = cpu.upload_types(r0, w, h).unwrap();
        let mut levels = Vec::new();
        for level in 1..=top_level(w, h) + 1 {
            let (lw, lh) = level_size(w, h, level);
            c = cpu.reduce_types(&c, lw, lh, full).unwrap();
            levels.push(vec![("cpu", c.data.clone())]);
        }
        #[cfg(feature = "gpu")]
        if let Some(gpu) = &self.gpu {
            let mut g = gpu.upload_types(r0, w, h).unwrap();
            assert_eq!(gpu.download_types(&g).unwrap(), r0, "type sets: upload");
            for (k, runs) in levels.iter_mut().enumerate() {
                let (lw, lh) = level_size(w, h, k + 1);
                g = gpu.reduce_types(&g, lw, lh, full).unwrap();
                runs.push(("gpu", gpu.download_types(&g).unwrap()));
            }
        }
        levels
    }

    /// [`Rig::reduce_types`] for stage `reduce_weights`.
    pub fn reduce_weights(&self, w0: &[u8], (w, h): (usize, usize)) -> Vec<Vec<Run<u8>>> {
        let cpu = self.cpu();
        let mut c = cpu.upload_weights(w0, w, h).unwrap();
        let mut levels = Vec::new();
        for level in 1..=top_level(w, h) + 1 {
            let (lw, lh) = level_size(w, h, level);
            c = cpu.reduce_weights(&c, lw, lh).unwrap();
            levels.push(vec![("cpu", c.data.clone())]);
        }
        #[cfg(feature = "gpu")]
        if let Some(gpu) = &self.gpu {
            let mut g = gpu.upload_weights(w0, w, h).unwrap();
            assert_eq!(gpu.download_weights(&g).unwrap(), w0, "weights: upload");
            for (k, runs) in levels.iter_mut().enumerate() {
                let (lw, lh) = level_size(w, h, k + 1);
                g = gpu.reduce_weights(&g, lw, lh).unwrap();
                runs.push(("gpu", gpu.download_weights(&g).unwrap()));
            }
        }
        levels
    }
}

/// Stage `shade`: `cpu` and `gpu` packed RGBA pixels, each through the
/// engine a preview is rendered on (`Engine::shade`).
pub fn shade(p: &ShadeParams, b: &ShadeBuffers<'_>) -> Vec<Run<u32>> {
    #[allow(unused_mut)]
    let mut runs = vec![("cpu", Engine::default().shade(p, b).unwrap())];
    #[cfg(feature = "gpu")]
    if let Some(ctx) = super::gpu::context() {
        runs.push(("gpu", Engine::Gpu(ctx).shade(p, b).unwrap()));
    }
    runs
}

/// Stage `fill_ssd`'s table of every candidate in `cells` (each
/// `user[v].len()` long) under every transform `v`: `scalar` (the oracle,
/// entry by entry), `simd` (the CPU table) and `gpu`.
pub fn fill_ssd(user: &[Vec<i32>], mask: &[Vec<i32>], cells: &[i32], count: i64) -> Vec<Run<u64>> {
    let per = user[0].len();
    let oracle = cells
        .chunks(per)
        .flat_map(|c| {
            user.iter()
                .zip(mask)
                .map(move |(u, m)| fill_ssd_scalar(u, m, c, count))
        })
        .collect();
    #[allow(unused_mut)]
    let mut runs = vec![
        ("scalar", oracle),
        ("simd", fill_ssd_table(user, mask, cells, count)),
    ];
    #[cfg(feature = "gpu")]
    if let Some(ctx) = super::gpu::context() {
        let src = ctx.upload_fill_source(cells, per).unwrap();
        runs.push(("gpu", ctx.fill_ssd(&src, user, mask, count).unwrap()));
    }
    runs
}
