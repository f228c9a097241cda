//! Water on a tiled world (`terrasynth tiles --water`): the same rasters
//! as [`super::compute`] on the whole world — filled surface, water depth,
//! accumulation, river orders — bit for bit, computed tile by tile so that
//! memory holds a few tiles' arrays and the rings (perimeter cells) of all
//! of them, never the whole world at full resolution.
//!
//! ```text
//! pass 1   each tile: heights → joins of its ring's labels (spill::joins)
//! solve    the spill graph → filled level of every ring cell (spill::solve)
//! pass 2   each tile: refill with its ring at those levels; classes, flats
//!          and lake bodies reaching the ring (joined across tiles)
//! settle   flat sweeps: tiles pass ring distances until none changes
//! pass 3   each tile: flat gradient, D8 (ring-padded) → direction codes
//! settle   flow: tiles pass accumulation and orders until none changes
//! pass 4   each tile: lakes (global area and depth), rasters → the sink
//! ```
//!
//! Each tile reads its one-cell halo from its neighbours' rings (`ring`),
//! so every per-cell rule is the whole-world one evaluated on the same
//! numbers. The passes keep each tile's heights, levels and directions in
//! a scratch folder between them (removed at the end).

mod flats;
pub mod flow;
pub mod ring;
mod spill;
mod unions;

pub use ring::{Core, Layout};

use super::d8::{self, CLOCKWISE, Edges, OUTLET};
use super::{Params, WaterError, fill, threshold_cells};
use crate::io::IoError;
use flow::{NO_RECEIVER, SEA_BIT};
use rayon::prelude::*;
use ring::{Pad, Rings, ring_cells};
use std::path::{Path, PathBuf};
use unions::{Components, NONE, Unions};

/// Bytes per core cell a tile's pass holds at its peak (heights, levels,
/// the padded surface and its classes, the sweeps, components, receivers).
pub const BYTES_PER_CELL: u64 = 64;

/// Bytes per ring cell of the whole world held throughout: the rings'
/// published values (about 40 bytes) and, while it is solved, the spill
/// graph's adjacency.
pub const BYTES_PER_RING_CELL: u64 = 256;

/// One tile's water, its core's cells row-major.
#[derive(Debug, Clone)]
pub struct TileWater {
    pub core: Core,
    /// The water surface ([`super::Water::filled`]).
    pub filled: Vec<f32>,
    /// Water depth of lakes and sea, 0 elsewhere.
    pub depth: Vec<f32>,
    /// Upstream area in cells.
    pub accumulation: Vec<u64>,
    /// Strahler order of river cells (on land), 0 elsewhere.
    pub rivers: Vec<u8>,
}

/// What a tiled run did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Report {
    pub tiles: usize,
    /// Rounds the flat sweeps and the flow took to settle.
    pub flat_rounds: usize,
    pub flow_rounds: usize,
    pub lakes: usize,
    pub lake_cells: u64,
}

/// Where heights come from and water goes: `heights` gives a core's
/// heights (row-major, no NaN), `sink` takes each tile's water.
pub struct Io<'a> {
    pub heights: &'a (dyn Fn(Core) -> Result<Vec<f32>, WaterError> + Sync),
    pub sink: &'a (dyn Fn(TileWater) -> Result<(), WaterError> + Sync),
    /// A folder for the passes' scratch files (created, then emptied).
    pub scratch: &'a Path,
}

struct Scratch(PathBuf);

impl Scratch {
    fn path(&self, t: usize, what: &str) -> PathBuf {
        self.0.join(format!("{t}.{what}"))
    }

    fn save<T: bytemuck::Pod>(&self, t: usize, what: &str, v: &[T]) -> Result<(), WaterError> {
        let p = self.path(t, what);
        std::fs::write(&p, bytemuck::cast_slice(v)).map_err(|e| IoError::os(&p, e).into())
    }

    fn load<T: bytemuck::Pod>(&self, t: usize, what: &str) -> Result<Vec<T>, WaterError> {
        let p = self.path(t, what);
        let bytes = std::fs::read(&p).map_err(|e| IoError::os(&p, e))?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }
}

/// Runs `run` on every tile, then on every tile beside a ring cell whose
/// published value changed (`publish` returns the changed cells' ring
/// indices), until none changes: a Jacobi iteration over tiles. Returns
/// the rounds.
fn settle<S: Sync, O: Send>(
    layout: &Layout,
    state: &mut S,
    run: impl Fn(&S, usize) -> Result<O, WaterError> + Sync,
    publish: impl Fn(&mut S, usize, O) -> Vec<usize>,
) -> Result<usize, WaterError> {
    let (ww, wh) = layout.world;
    let mut todo: Vec<usize> = (0..layout.count()).collect();
    let mut rounds = 0;
    while !todo.is_empty() {
        rounds += 1;
        let out: Vec<O> = todo
            .par_iter()
            .map(|&t| run(state, t))
            .collect::<Result<_, WaterError>>()?;
        let mut next = vec![false; layout.count()];
        for (&t, o) in todo.iter().zip(out) {
            let c = layout.core(t);
            let cells = ring_cells(c.w, c.h);
            for r in publish(state, t, o) {
                let (gx, gy) = (c.x0 + cells[r].0, c.y0 + cells[r].1);
                for &(dx, dy, _) in &CLOCKWISE {
                    if let Some(k) = crate::procedural::grid::neighbour(gx, gy, dx, dy, ww, wh)
                        && layout.tile_of(k % ww, k / ww) != t
                    {
                        next[layout.tile_of(k % ww, k / ww)] = true;
                    }
                }
            }
        }
        todo = (0..layout.count()).filter(|&t| next[t]).collect();
    }
    Ok(rounds)
}

/// Replaces tile `t`'s ring values with `v` and `w`, returning the ring
/// indices where either changed.
fn replace<T: Copy + PartialEq, U: Copy + PartialEq>(
    (a, b): (&mut Rings<T>, &mut Rings<U>),
    t: usize,
    (v, w): (&[T], &[U]),
) -> Vec<usize> {
    let (ra, rb) = (a.tile_mut(t), b.tile_mut(t));
    let changed = (0..v.len())
        .filter(|&r| ra[r] != v[r] || rb[r] != w[r])
        .collect();
    ra.copy_from_slice(v);
    rb.copy_from_slice(w);
    changed
}

/// Values of a core array on its ring.
fn on_ring<T: Copy>(v: &[T], w: usize, h: usize) -> Vec<T> {
    ring_cells(w, h)
        .into_iter()
        .map(|(x, y)| v[y * w + x])
        .collect()
}

/// Values of a padded array on its core's ring.
fn on_padded_ring<T: Copy>(v: &[T], pad: &Pad) -> Vec<T> {
    let (w, h) = (pad.core.w, pad.core.h);
    ring_cells(w, h)
        .into_iter()
        .map(|(x, y)| v[pad.at(x, y)])
        .collect()
}

/// For every ring cell of every tile and each neighbour on a later tile's
/// ring: (this ring cell's node, the neighbour's node).
fn seams(layout: &Layout, rings: &Rings<f32>) -> Vec<(usize, usize)> {
    let (ww, wh) = layout.world;
    let mut v = Vec::new();
    for t in 0..layout.count() {
        let c = layout.core(t);
        for (r, (x, y)) in ring_cells(c.w, c.h).into_iter().enumerate() {
            let (gx, gy) = (c.x0 + x, c.y0 + y);
            for &(dx, dy, _) in &CLOCKWISE {
                if let Some(k) = crate::procedural::grid::neighbour(gx, gy, dx, dy, ww, wh)
                    && layout.tile_of(k % ww, k / ww) > t
                {
                    v.push((rings.node(t, r), rings.node_at(layout, k % ww, k / ww)));
                }
            }
        }
    }
    v
}

/// What pass 2 learns of a tile's ring.
struct Ring2 {
    class: Vec<u8>,
    flat: Vec<u32>,
    flats: usize,
    body: Vec<u32>,
    /// Cells and deepest water of each open body.
    bodies: Vec<(u64, f32)>,
}

/// Lake bodies of a tile: raised cells (not sea) at one level.
fn bodies(pad: &Pad, f: &[f32], z: &[f32], sea: &[bool]) -> Components {
    let w = pad.core.w;
    let raised = |p: usize| {
        let (x, y) = pad.to_core(p).expect("members are core cells");
        f[p] > z[y * w + x] && !sea[p]
    };
    Components::label(pad, raised, |a, b| f[a] == f[b])
}

/// Cells and deepest water of each body.
fn body_sizes(b: &Components, pad: &Pad, f: &[f32], z: &[f32]) -> Vec<(u64, f32)> {
    let mut s = vec![(0u64, f32::NEG_INFINITY); b.count];
    for (i, &c) in b.id.iter().enumerate().filter(|p| *p.1 != NONE) {
        let p = pad.at(i % pad.core.w, i / pad.core.w);
        let e = &mut s[c as usize];
        e.0 += 1;
        e.1 = e.1.max(f[p] - z[i]);
    }
    s
}

/// Computes the water of the world `layout` cuts into tiles of
/// `cell_size`-metre cells; see the module docs.
pub fn compute(
    layout: &Layout,
    cell_size: f64,
    params: &Params,
    io: &Io<'_>,
) -> Result<Report, WaterError> {
    params.check()?;
    let scratch = Scratch(io.scratch.to_path_buf());
    std::fs::create_dir_all(&scratch.0).map_err(|e| IoError::os(&scratch.0, e))?;
    let result = run(layout, cell_size, params, io, &scratch);
    for t in 0..layout.count() {
        for what in ["z", "f", "dir"] {
            let _ = std::fs::remove_file(scratch.path(t, what));
        }
    }
    let _ = std::fs::remove_dir(&scratch.0);
    result
}

fn run(
    layout: &Layout,
    cell_size: f64,
    params: &Params,
    io: &Io<'_>,
    scratch: &Scratch,
) -> Result<Report, WaterError> {
    let n = layout.count();
    let pad = |t: usize| Pad {
        core: layout.core(t),
    };
    // Pass 1: the joins of each tile's ring labels.
    let pass1: Vec<(Vec<f32>, Vec<spill::Join>)> = (0..n)
        .into_par_iter()
        .map(|t| {
            let c = layout.core(t);
            let z = (io.heights)(c)?;
            assert_eq!(z.len(), c.w * c.h, "heights of a {}x{} core", c.w, c.h);
            if let Some(i) = z.iter().position(|v| v.is_nan()) {
                return Err(WaterError::Nodata {
                    count: z.iter().filter(|v| v.is_nan()).count(),
                    x: c.x0 + i % c.w,
                    y: c.y0 + i / c.w,
                });
            }
            scratch.save(t, "z", &z)?;
            Ok((on_ring(&z, c.w, c.h), spill::joins(&z, c.w, c.h)))
        })
        .collect::<Result<_, WaterError>>()?;
    let mut ring_z = Rings::new(layout, 0.0f32);
    let mut joins = Vec::with_capacity(n);
    for (t, (rz, j)) in pass1.into_iter().enumerate() {
        ring_z.tile_mut(t).copy_from_slice(&rz);
        joins.push(j);
    }
    let level = spill::solve(layout, &ring_z, &joins);
    drop(joins);
    let sea_of = |f: f32| params.sea_level.is_some_and(|l| f <= l);
    let sea_level = |f: f32| match params.sea_level {
        Some(l) if f <= l => l,
        _ => f,
    };
    let mut ring_f = level.clone();
    ring_f.values.iter_mut().for_each(|f| *f = sea_level(*f));
    let mut ring_sea = Rings::new(layout, false);
    for (s, &f) in ring_sea.values.iter_mut().zip(&level.values) {
        *s = sea_of(f);
    }
    // Pass 2: refill; classes, flats and bodies on the ring.
    let ring_class0 = Rings::new(layout, 0u8);
    let pass2: Vec<Ring2> = (0..n)
        .into_par_iter()
        .map(|t| {
            let p = pad(t);
            let (w, h) = (p.core.w, p.core.h);
            let z: Vec<f32> = scratch.load(t, "z")?;
            let mut seeded = z.clone();
            for ((x, y), &l) in ring_cells(w, h).into_iter().zip(level.tile(t)) {
                seeded[y * w + x] = l;
            }
            let mut f = fill::priority_flood(&seeded, w, h, None);
            drop(seeded);
            let sea: Vec<bool> = f.iter().map(|&v| sea_of(v)).collect();
            f.iter_mut().for_each(|v| *v = sea_level(*v));
            scratch.save(t, "f", &f)?;
            // The ring's classes come from the core's: the halo's classes
            // are not known yet and are not needed for them.
            let s = flats::Surface::new(layout, p, (&f, &sea), (&ring_f, &ring_sea, &ring_class0));
            let b = bodies(&p, &s.f, &z, &s.sea);
            let sizes = body_sizes(&b, &p, &s.f, &z);
            let mut open = vec![(0, 0.0); b.open_count];
            for (c, &o) in b.open.iter().enumerate().filter(|x| *x.1 != NONE) {
                open[o as usize] = sizes[c];
            }
            let fl = s.flats();
            Ok(Ring2 {
                class: on_padded_ring(&s.class, &p),
                flat: fl.ring(w, h),
                flats: fl.open_count,
                body: b.ring(w, h),
                bodies: open,
            })
        })
        .collect::<Result<_, WaterError>>()?;
    let mut ring_class = Rings::new(layout, 0u8);
    let mut ring_flat = Rings::new(layout, NONE);
    let mut ring_body = Rings::new(layout, NONE);
    let (mut flat_base, mut body_base) = (vec![0usize; n + 1], vec![0usize; n + 1]);
    for (t, r) in pass2.iter().enumerate() {
        ring_class.tile_mut(t).copy_from_slice(&r.class);
        ring_flat.tile_mut(t).copy_from_slice(&r.flat);
        ring_body.tile_mut(t).copy_from_slice(&r.body);
        flat_base[t + 1] = flat_base[t] + r.flats;
        body_base[t + 1] = body_base[t] + r.bodies.len();
    }
    // Global ids of open flats and bodies, and their unions across tiles.
    let seams = seams(layout, &ring_z);
    let mut flat_sets = Unions::new(flat_base[n]);
    let mut body_sets = Unions::new(body_base[n]);
    let node_tile: Vec<usize> = {
        let mut v = Vec::with_capacity(ring_z.values.len());
        for t in 0..n {
            v.extend(std::iter::repeat_n(t, ring_z.tile(t).len()));
        }
        v
    };
    for &(a, b) in &seams {
        let (ta, tb) = (node_tile[a], node_tile[b]);
        let (fa, fb) = (ring_flat.values[a], ring_flat.values[b]);
        if fa != NONE && fb != NONE {
            flat_sets.union(flat_base[ta] + fa as usize, flat_base[tb] + fb as usize);
        }
        let (ba, bb) = (ring_body.values[a], ring_body.values[b]);
        if ba != NONE && bb != NONE && ring_f.values[a] == ring_f.values[b] {
            body_sets.union(body_base[ta] + ba as usize, body_base[tb] + bb as usize);
        }
    }
    drop(seams);
    let body_root: Vec<usize> = (0..body_base[n]).map(|i| body_sets.find(i)).collect();
    let mut body_size = vec![(0u64, f32::NEG_INFINITY); body_base[n]];
    for (t, r) in pass2.iter().enumerate() {
        for (o, &(cells, deepest)) in r.bodies.iter().enumerate() {
            let root = body_root[body_base[t] + o];
            body_size[root].0 += cells;
            body_size[root].1 = body_size[root].1.max(deepest);
        }
    }
    drop(pass2);
    let cell_area = cell_size * cell_size;
    let t = params.lakes;
    let is_lake = |(cells, deepest): (u64, f32)| {
        !((deepest as f64) < t.min_depth_m || cells as f64 * cell_area / 1e6 < t.min_area_km2)
    };
    let surface = |t: usize| -> Result<(flats::Surface, Vec<f32>), WaterError> {
        let f: Vec<f32> = scratch.load(t, "f")?;
        let sea: Vec<bool> = f
            .iter()
            .map(|&v| params.sea_level.is_some_and(|l| v <= l))
            .collect();
        let s = flats::Surface::new(
            layout,
            pad(t),
            (&f, &sea),
            (&ring_f, &ring_sea, &ring_class),
        );
        Ok((s, f))
    };
    // The flat sweeps, settled across tiles.
    struct Sweeps {
        tl: Rings<u32>,
        hi: Rings<u32>,
        tops: Vec<Vec<u32>>,
    }
    let mut sw = Sweeps {
        tl: Rings::new(layout, 0),
        hi: Rings::new(layout, 0),
        tops: vec![Vec::new(); n],
    };
    let flat_rounds = settle(
        layout,
        &mut sw,
        |sw, t| {
            let (s, _) = surface(t)?;
            let (tl, hi) = s.sweeps(layout, &sw.tl, &sw.hi);
            let fl = s.flats();
            let tops = flats::tops(&fl, &hi, &s.pad);
            let mut open = vec![0u32; fl.open_count];
            for (c, &o) in fl.open.iter().enumerate().filter(|x| *x.1 != NONE) {
                open[o as usize] = tops[c];
            }
            Ok((
                on_padded_ring(&tl, &s.pad),
                on_padded_ring(&hi, &s.pad),
                open,
            ))
        },
        |sw, t, (tl, hi, open)| {
            sw.tops[t] = open;
            replace((&mut sw.tl, &mut sw.hi), t, (&tl, &hi))
        },
    )?;
    let mut flat_top = vec![0u32; flat_base[n]];
    for (t, tops) in sw.tops.iter().enumerate() {
        for (o, &top) in tops.iter().enumerate() {
            let root = flat_sets.find(flat_base[t] + o);
            flat_top[root] = flat_top[root].max(top);
        }
    }
    let flat_root: Vec<usize> = (0..flat_base[n]).map(|i| flat_sets.find(i)).collect();
    let global_top = |t: usize, open: u32| flat_top[flat_root[flat_base[t] + open as usize]];
    // Pass 3: gradient and D8 directions.
    let pass3: Vec<Vec<u8>> = (0..n)
        .into_par_iter()
        .map(|t| {
            let (s, _) = surface(t)?;
            let p = s.pad;
            let (tl, hi) = s.sweeps(layout, &sw.tl, &sw.hi);
            let fl = s.flats();
            let tops = flats::tops(&fl, &hi, &p);
            let mut grad = vec![0u32; p.cells()];
            for (i, &c) in fl.id.iter().enumerate() {
                let q = p.at(i % p.core.w, i / p.core.w);
                let top = match c {
                    NONE => 0,
                    c if fl.open[c as usize] != NONE => global_top(t, fl.open[c as usize]),
                    c => tops[c as usize],
                };
                grad[q] = flats::gradient(tl[q], c != NONE, hi[q], top);
            }
            for (q, gx, gy) in p.halo(layout) {
                let node = sw.tl.node_at(layout, gx, gy);
                let open = ring_flat.values[node];
                let top = if open == NONE {
                    0
                } else {
                    global_top(layout.tile_of(gx, gy), open)
                };
                grad[q] =
                    flats::gradient(sw.tl.values[node], open != NONE, sw.hi.values[node], top);
            }
            let surface = d8::Surface {
                heights: &s.f,
                width: p.pw(),
                height: p.core.h + 2,
                gradient: Some(&grad),
                sinks: Some(&s.sea),
            };
            let receivers = d8::receivers(&surface, Edges::Inside);
            let offsets = p.offsets();
            let mut dirs = vec![0u8; p.core.w * p.core.h];
            for (i, d) in dirs.iter_mut().enumerate() {
                let q = p.at(i % p.core.w, i / p.core.w);
                let r = receivers[q];
                *d = if r == OUTLET {
                    NO_RECEIVER
                } else {
                    offsets
                        .iter()
                        .position(|&o| q.wrapping_add_signed(o) == r as usize)
                        .expect("a receiver is a neighbour") as u8
                } | if s.sea[q] { SEA_BIT } else { 0 };
            }
            scratch.save(t, "dir", &dirs)?;
            Ok(on_ring(&dirs, p.core.w, p.core.h))
        })
        .collect::<Result<_, WaterError>>()?;
    drop(sw);
    let mut ring_dir = Rings::new(layout, NO_RECEIVER);
    for (t, d) in pass3.into_iter().enumerate() {
        ring_dir.tile_mut(t).copy_from_slice(&d);
    }
    // Flow, settled across tiles.
    let threshold = threshold_cells(params.river_area_km2, cell_size) as u64;
    let mut fl = (Rings::new(layout, 0u64), Rings::new(layout, 0u8));
    let route = |fl: &(Rings<u64>, Rings<u8>), t: usize| -> Result<flow::Flow, WaterError> {
        let dirs: Vec<u8> = scratch.load(t, "dir")?;
        Ok(flow::route(
            layout,
            &pad(t),
            &dirs,
            (&ring_dir, &fl.0, &fl.1),
            threshold,
        ))
    };
    let flow_rounds = settle(
        layout,
        &mut fl,
        |fl, t| {
            let f = route(fl, t)?;
            let c = layout.core(t);
            Ok((on_ring(&f.acc, c.w, c.h), on_ring(&f.order, c.w, c.h)))
        },
        |fl, t, (acc, order)| replace((&mut fl.0, &mut fl.1), t, (&acc, &order)),
    )?;
    // Pass 4: lakes and the rasters.
    let counts: Vec<(usize, u64)> = (0..n)
        .into_par_iter()
        .map(|t| {
            let p = pad(t);
            let c = p.core;
            let z: Vec<f32> = scratch.load(t, "z")?;
            let (s, f) = surface(t)?;
            let b = bodies(&p, &s.f, &z, &s.sea);
            let sizes = body_sizes(&b, &p, &s.f, &z);
            let lake: Vec<bool> = (0..b.count)
                .map(|k| match b.open[k] {
                    NONE => is_lake(sizes[k]),
                    o => is_lake(body_size[body_root[body_base[t] + o as usize]]),
                })
                .collect();
            let flow = route(&fl, t)?;
            let mut depth = vec![0.0f32; c.w * c.h];
            let mut rivers = flow.order;
            let mut lakes = (0usize, 0u64);
            for (i, d) in depth.iter_mut().enumerate() {
                let k = b.id[i];
                let in_lake = k != NONE && lake[k as usize];
                if in_lake || s.sea[p.at(i % c.w, i / c.w)] {
                    *d = f[i] - z[i];
                    rivers[i] = 0;
                }
                lakes.1 += in_lake as u64;
            }
            lakes.0 = (0..b.count)
                .filter(|&k| b.open[k] == NONE && lake[k])
                .count();
            (io.sink)(TileWater {
                core: c,
                filled: f,
                depth,
                accumulation: flow.acc,
                rivers,
            })?;
            Ok(lakes)
        })
        .collect::<Result<_, WaterError>>()?;
    let open_lakes = (0..body_base[n])
        .filter(|&i| body_root[i] == i && is_lake(body_size[i]))
        .count();
    Ok(Report {
        tiles: n,
        flat_rounds,
        flow_rounds,
        lakes: open_lakes + counts.iter().map(|c| c.0).sum::<usize>(),
        lake_cells: counts.iter().map(|c| c.1).sum(),
    })
}
