//! A disk cache of source features (seed 004 §5.4 pre-processes every
//! source once and keeps the result on disk): PPA on a whole DEM is most of
//! the cost of preparing it, and the same DEMs are used again and again.
//!
//! One file per prepared source, `patch-<key>.tsps` in the cache directory
//! ([`crate::database::default::cache_dir`], shared with the default
//! database). The key is a 64-bit FNV-1a hash of everything the features
//! depend on: the DEM's size, cell size and height bits, the preparation
//! parameters and the relief scale, the crate version, [`FORMAT`], and the
//! text of every module the preparation runs (`CODE`), so any edit to
//! that code (or a new release) makes old entries unreachable instead of
//! stale. The file repeats the key and carries a CRC-32 of its payload;
//! an entry that is missing, truncated, corrupted or of another key is
//! rebuilt and rewritten (written to a temporary name, then renamed, so a
//! concurrent reader never sees half a file). A cache that cannot be
//! written only costs a rebuild next time.

use crate::patch::input::control_point::{ACROSS, ALONG, Cp};
use crate::patch::place::candidates::{FeatureNode, Features, FillCand, PreparedSource};
use crate::patch::{Params, PatchError};
use std::path::{Path, PathBuf};

/// Bump when the file layout changes.
pub const FORMAT: u32 = 1;

const MAGIC: &[u8; 8] = b"TSPSRC\r\n";

/// The source text of the code that computes [`Features`]: part of the
/// key, so that a changed algorithm never reads an old entry.
const CODE: [&str; 11] = [
    include_str!("../place/candidates.rs"),
    include_str!("ppa.rs"),
    include_str!("graph.rs"),
    include_str!("control_point.rs"),
    include_str!("../place/costs.rs"),
    include_str!("cache.rs"),
    include_str!("../../nodata.rs"),
    include_str!("../../poisson/mod.rs"),
    include_str!("../../poisson/cascadic.rs"),
    include_str!("../../poisson/pcg.rs"),
    include_str!("../../poisson/multigrid.rs"),
];

/// FNV-1a, 64-bit: stable across platforms and Rust versions (unlike
/// `std`'s hasher), which a key stored on disk needs.
struct Fnv(u64);

impl Fnv {
    fn new() -> Fnv {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
    fn bytes(&mut self, b: &[u8]) {
        for &x in b {
            self.0 = (self.0 ^ x as u64).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    fn u64(&mut self, v: u64) {
        self.bytes(&v.to_le_bytes());
    }
}

/// The cache key of one source prepared with `params` at relief `scale`.
pub fn key(hf: &crate::Heightfield, params: &Params, scale: f32) -> u64 {
    let mut h = Fnv::new();
    h.bytes(MAGIC);
    h.u64(FORMAT as u64);
    h.bytes(env!("CARGO_PKG_VERSION").as_bytes());
    for c in CODE {
        h.u64(c.len() as u64);
        h.bytes(c.as_bytes());
    }
    h.u64(hf.width() as u64);
    h.u64(hf.height() as u64);
    h.u64(hf.cell_size().to_bits());
    let mut buf = Vec::with_capacity(hf.data().len() * 4);
    for v in hf.data() {
        buf.extend_from_slice(&v.to_bits().to_le_bytes());
    }
    h.bytes(&buf);
    h.u64(params.patch as u64);
    h.u64(params.source_dip.to_bits() as u64);
    h.u64(params.source_min_prominence.to_bits() as u64);
    h.u64(params.max_source_nodes as u64);
    h.u64(scale.to_bits() as u64);
    h.0
}

/// The file of key `key` in `dir`.
pub fn path(dir: &Path, key: u64) -> PathBuf {
    dir.join(format!("patch-{key:016x}.tsps"))
}

/// Whether a source came from the cache.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// Read from the cache.
    Hit,
    /// Computed (no usable entry) and written.
    Built,
}

/// [`PreparedSource::prepare`] through the cache in `dir`.
pub fn prepare(
    dir: &Path,
    name: &str,
    hf: &crate::Heightfield,
    params: &Params,
    scale: f32,
) -> Result<(PreparedSource, Outcome), PatchError> {
    let k = key(hf, params, scale);
    let file = path(dir, k);
    let usable = |f: &Features| {
        let n = params.patch;
        let fits = |c: &FillCand| {
            let (x, y) = (c.x as usize, c.y as usize);
            x % crate::patch::place::candidates::COARSE == 0
                && y % crate::patch::place::candidates::COARSE == 0
                && x + n <= hf.width()
                && y + n <= hf.height()
        };
        let node_ok = |v: &FeatureNode| (1..=8).contains(&v.cps.len());
        f.fill.iter().all(fits) && f.ridges.iter().chain(&f.valleys).all(node_ok)
    };
    let cached = std::fs::read(&file).ok().and_then(|b| decode(&b, k));
    if let Some(f) = cached.filter(usable) {
        return Ok((
            PreparedSource::build(name, hf, params, scale, Some(f))?,
            Outcome::Hit,
        ));
    }
    let src = PreparedSource::prepare(name, hf, params, scale)?;
    // A cache we cannot write only means preparing again next time.
    let _ = write(dir, &file, &encode(&src.features(), k));
    Ok((src, Outcome::Built))
}

fn write(dir: &Path, file: &Path, bytes: &[u8]) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let tmp = file.with_extension(format!("tsps.tmp{}", std::process::id()));
    std::fs::write(&tmp, bytes)?;
    std::fs::rename(&tmp, file).inspect_err(|_| {
        let _ = std::fs::remove_file(&tmp);
    })
}

/// `MAGIC, key u64, payload length u64, CRC-32 u32, payload` (little endian).
pub fn encode(f: &Features, key: u64) -> Vec<u8> {
    let mut p = Vec::new();
    for nodes in [&f.ridges, &f.valleys] {
        p.extend_from_slice(&(nodes.len() as u32).to_le_bytes());
        for n in nodes {
            for v in [n.centre[0], n.centre[1], n.prominence] {
                p.extend_from_slice(&v.to_bits().to_le_bytes());
            }
            p.push(n.cps.len() as u8);
            for c in &n.cps {
                for v in c.pos {
                    p.extend_from_slice(&v.to_bits().to_le_bytes());
                }
                p.extend_from_slice(&c.angle.to_le_bytes());
                for v in c.along.iter().chain(&c.across) {
                    p.extend_from_slice(&v.to_le_bytes());
                }
            }
        }
    }
    p.extend_from_slice(&(f.fill.len() as u32).to_le_bytes());
    for c in &f.fill {
        for v in [c.x, c.y, c.noise[0], c.noise[1], c.noise[2]] {
            p.extend_from_slice(&v.to_le_bytes());
        }
    }
    let mut out = Vec::with_capacity(p.len() + 28);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&key.to_le_bytes());
    out.extend_from_slice(&(p.len() as u64).to_le_bytes());
    out.extend_from_slice(&crc32fast::hash(&p).to_le_bytes());
    out.extend_from_slice(&p);
    out
}

/// Reads [`encode`]'s bytes back; `None` for anything but an intact entry
/// of key `key`.
pub fn decode(b: &[u8], key: u64) -> Option<Features> {
    let mut r = Reader(b);
    if r.take(8)? != MAGIC || r.u64()? != key {
        return None;
    }
    let len = r.u64()?;
    let crc = r.u32()?;
    let payload = r.take(usize::try_from(len).ok()?)?;
    if !r.0.is_empty() || crc32fast::hash(payload) != crc {
        return None;
    }
    let mut r = Reader(payload);
    let mut nodes = || -> Option<Vec<FeatureNode>> {
        let count = r.u32()? as usize;
        let mut out = Vec::with_capacity(count.min(1 << 16));
        for _ in 0..count {
            let centre = [r.f32()?, r.f32()?];
            let prominence = r.f32()?;
            let d = r.take(1)?[0] as usize;
            let mut cps = Vec::with_capacity(d);
            for _ in 0..d {
                let pos = [r.f32()?, r.f32()?];
                let angle = r.u16()?;
                let mut along = [0i16; ALONG];
                let mut across = [0i16; ACROSS];
                for v in along.iter_mut().chain(across.iter_mut()) {
                    *v = r.u16()? as i16;
                }
                cps.push(Cp {
                    pos,
                    angle,
                    along,
                    across,
                });
            }
            out.push(FeatureNode {
                centre,
                cps,
                prominence,
            });
        }
        Some(out)
    };
    let ridges = nodes()?;
    let valleys = nodes()?;
    let count = r.u32()? as usize;
    let mut fill = Vec::with_capacity(count.min(1 << 20));
    for _ in 0..count {
        fill.push(FillCand {
            x: r.u32()?,
            y: r.u32()?,
            noise: [r.u32()?, r.u32()?, r.u32()?],
        });
    }
    r.0.is_empty().then_some(Features {
        ridges,
        valleys,
        fill,
    })
}

struct Reader<'a>(&'a [u8]);

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        if self.0.len() < n {
            return None;
        }
        let (a, b) = self.0.split_at(n);
        self.0 = b;
        Some(a)
    }
    fn u16(&mut self) -> Option<u16> {
        Some(u16::from_le_bytes(self.take(2)?.try_into().ok()?))
    }
    fn u32(&mut self) -> Option<u32> {
        Some(u32::from_le_bytes(self.take(4)?.try_into().ok()?))
    }
    fn u64(&mut self) -> Option<u64> {
        Some(u64::from_le_bytes(self.take(8)?.try_into().ok()?))
    }
    fn f32(&mut self) -> Option<f32> {
        Some(f32::from_bits(self.u32()?))
    }
}
