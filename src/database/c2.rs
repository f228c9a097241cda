//! C₂'s diagonal texels, gathered once per opened database.
//!
//! Why: correction scores every pixel's C₂ candidates, `C₂(u)` of each
//! distinct `u = S(p+Δ) − Δ`, by the four diagonal texels around them.
//! C₂ points anywhere in the atlas, so at level 0 (an atlas larger than
//! the L2 cache) each one cost two or three cache misses that waited on
//! another (`similar[u]`, then the texels it names). Here texel `u`'s
//! entry holds those four texels themselves, 32-byte aligned: `u` is near
//! `S(p)`, which neighbouring pixels share, so the entries are read in
//! the order the level is walked and come from cache, one line each.
//!
//! Derived data of the CPU path (the WGSL kernel reads `similar`): built
//! when the database's first `Synthesizer` is made ([`super::Database::c2`])
//! and shared by every later one, so that short runs (a window, a Dask
//! chunk, a getter that makes a `Synthesizer`) do not pay for it again.

use super::file::Bytes;
use super::{Database, Level, layout};
use crate::isa::prefetch;
use rayon::prelude::*;
use std::ops::Range;

/// How many entries ahead [`gather`] prefetches.
const AHEAD: usize = 16;

/// The four diagonal texels of one C₂, in the AVX2 scorer's order:
/// (−1,−1), (−1,1), (1,−1), (1,1) (the `u64` appearance texels). Files
/// keep them in this order ([`super::c2_cache`]): a change of it is a new
/// `FORMAT` there.
#[repr(C, align(32))]
#[derive(Clone, Copy, Default, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Quad(pub [u64; 4]);

impl Quad {
    /// The diagonals of the texel with index `k` in an exemplar of row
    /// stride `s` (the caller guarantees they lie in it).
    #[inline(always)]
    pub fn around(app: &[u64], k: i32, s: i32) -> Quad {
        Quad::beside(app, k - s - 1, k + s - 1)
    }

    /// The diagonals of the texel between `up` (its up-left diagonal's
    /// index) and `down` (its down-left one's); their right-hand diagonals
    /// are two texels further on.
    #[inline(always)]
    pub fn beside(app: &[u64], up: i32, down: i32) -> Quad {
        let t = |i: i32| app[i as usize];
        Quad([t(up), t(down), t(up + 2), t(down + 2)])
    }
}

/// The [`Quad`] of `C₂(u)` for every texel `u` of `level`, in texel order.
///
/// Every similarity entry is an interior coordinate (the database checks
/// them when it is opened), so its diagonals lie in its exemplar.
pub fn gather(level: &Level<'_>) -> Vec<Quad> {
    let app = level.appearance;
    let similar = level.similar;
    // The texel index and row stride of a similarity entry (the database
    // checked that every entry lies in an exemplar when it was opened).
    let at = |c: u32| {
        let (x, y) = layout::unpack(c);
        let r = &level.layout.rects[level.columns[x as usize] as usize];
        (r.index(x, y) as i32, r.width as i32)
    };
    // Entries point anywhere in the atlas: the rows of entry u + AHEAD are
    // asked for while entry u is read (this halved the build, which every
    // process that synthesizes pays: ~4 % of a 1024² `synth`'s CPU time).
    let quad = |u: usize| {
        if let Some(&c) = similar.get(u + AHEAD) {
            let (k, s) = at(c);
            prefetch(app, k - s - 1);
            prefetch(app, k + s - 1);
        }
        let (k, s) = at(similar[u]);
        Quad::around(app, k, s)
    };
    // A pixel reads entries of three exemplar rows (16 KiB apart at 512
    // texels a row), and patches jump across the table (24 MiB at the
    // embedded database's level 0): on 4 KiB pages that missed the TLB
    // often; a 2 MiB page holds 128 such rows.
    let mut out = Vec::with_capacity(similar.len());
    crate::pages::advise_huge(out.spare_capacity_mut());
    (0..similar.len())
        .into_par_iter()
        .map(quad)
        .collect_into_vec(&mut out);
    out
}

/// The tables of every level of a database: gathered in this process, or
/// read from the file that keeps them ([`super::c2_cache`]).
pub enum Tables {
    Gathered(Vec<Vec<Quad>>),
    /// The file and each level's byte range in it (checked to be 32-byte
    /// aligned when the file was read).
    Read(Bytes, Vec<Range<usize>>),
}

impl Tables {
    /// Level `i`'s table.
    pub fn level(&self, i: usize) -> &[Quad] {
        match self {
            Tables::Gathered(t) => &t[i],
            Tables::Read(b, r) => bytemuck::cast_slice(&b.as_slice()[r[i].clone()]),
        }
    }
}

/// Bytes of the tables of every level of `db` (what CPU synthesis keeps
/// besides the database: `db info` reports it).
pub fn table_bytes(db: &Database) -> usize {
    (0..db.level_count())
        .map(|i| db.level(i).similar.len() * std::mem::size_of::<Quad>())
        .sum()
}
