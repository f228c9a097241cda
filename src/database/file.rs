//! The `.tsdb` file: a versioned, checksummed, little-endian container that
//! is used in place once read into memory ([`Bytes`]).
//!
//! ```text
//! 0   magic   "TSDB\r\n\x1a\n"           (8 bytes; catches text-mode mangling)
//! 8   version u32                         (FORMAT_VERSION)
//! 12  count   u32                         (number of sections, ≤ MAX_SECTIONS)
//! 16  length  u64                         (total file length)
//! 24  crc     u32                         (CRC-32 of the header with this field zeroed)
//! 28  zero    u32
//! 32  table   count × 40 bytes: kind u32, level u32, offset u64, length u64,
//!                                crc u32 (of the section), zero u32, zero u64
//! ..  zero padding to 64, then each section at a 64-byte boundary, zero
//!     padding between sections and after the last one up to `length`.
//! ```
//!
//! Every byte is covered: header and table by the header CRC, sections by
//! their CRCs, padding by a must-be-zero check. A flipped or missing byte is
//! therefore always refused — never undefined data — and after the CRCs the
//! contents are validated too (every similarity entry and seed must be an
//! interior coordinate, every type id in range), because a well-formed file
//! can still come from a buggy or hostile writer.

use super::error::DbError;
use std::ops::Range;
use std::path::Path;

pub const MAGIC: &[u8; 8] = b"TSDB\r\n\x1a\n";
pub const FORMAT_VERSION: u32 = 1;
const HEADER: usize = 32;
const ENTRY: usize = 40;
const ALIGN: usize = 64;
const MAX_SECTIONS: u32 = 1024;

/// What a section holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
#[repr(u32)]
pub enum Kind {
    /// JSON metadata ([`super::Meta`]).
    Meta = 1,
    /// E⁰: u16 height units per level-0 texel.
    Heights = 2,
    /// A^i: packed u64 appearance texels.
    Appearance = 3,
    /// C₂^i: packed u32 coordinates.
    Similar = 4,
    /// T^i: u8 type ids.
    Types = 5,
    /// Per-type seed coordinates, u32.
    Seeds = 6,
}

impl Kind {
    fn from_u32(v: u32) -> Option<Kind> {
        Some(match v {
            1 => Kind::Meta,
            2 => Kind::Heights,
            3 => Kind::Appearance,
            4 => Kind::Similar,
            5 => Kind::Types,
            6 => Kind::Seeds,
            _ => return None,
        })
    }
}

/// A section to write.
pub struct Section<'a> {
    pub kind: Kind,
    pub level: u32,
    pub bytes: &'a [u8],
}

/// A section found in a file: where its bytes are.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Found {
    pub kind: Kind,
    pub level: u32,
    pub range: Range<usize>,
}

fn align(n: usize) -> usize {
    n.div_ceil(ALIGN) * ALIGN
}

/// Serializes sections (in the given order) into one [`Bytes`] buffer, laid
/// out in memory exactly as a file read back by [`Bytes::read`].
pub fn encode(sections: &[Section<'_>]) -> Bytes {
    let table_end = HEADER + ENTRY * sections.len();
    let mut offsets = Vec::with_capacity(sections.len());
    let mut pos = align(table_end);
    for s in sections {
        offsets.push(pos);
        pos = align(pos + s.bytes.len());
    }
    let total = pos;
    let mut out = Bytes::zeroed(total);
    let buf = out.as_mut_slice();
    buf[..8].copy_from_slice(MAGIC);
    buf[8..12].copy_from_slice(&FORMAT_VERSION.to_le_bytes());
    buf[12..16].copy_from_slice(&(sections.len() as u32).to_le_bytes());
    buf[16..24].copy_from_slice(&(total as u64).to_le_bytes());
    for (i, (s, &off)) in sections.iter().zip(&offsets).enumerate() {
        let e = HEADER + ENTRY * i;
        buf[e..e + 4].copy_from_slice(&(s.kind as u32).to_le_bytes());
        buf[e + 4..e + 8].copy_from_slice(&s.level.to_le_bytes());
        buf[e + 8..e + 16].copy_from_slice(&(off as u64).to_le_bytes());
        buf[e + 16..e + 24].copy_from_slice(&(s.bytes.len() as u64).to_le_bytes());
        buf[e + 24..e + 28].copy_from_slice(&crc32fast::hash(s.bytes).to_le_bytes());
        buf[off..off + s.bytes.len()].copy_from_slice(s.bytes);
    }
    let crc = crc32fast::hash(&buf[..table_end]);
    buf[24..28].copy_from_slice(&crc.to_le_bytes());
    out
}

pub(super) fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().expect("4 bytes"))
}
pub(super) fn u64_at(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().expect("8 bytes"))
}

/// The header's CRC-32 of a checked file (it covers every section's CRC).
pub(super) fn header_crc(bytes: &[u8]) -> u32 {
    u32_at(bytes, 24)
}

/// Checks the container (magic, version, lengths, checksums, padding) and
/// returns where the sections are. Contents are checked by the caller.
pub fn decode(bytes: &[u8], path: &Path) -> Result<Vec<Found>, DbError> {
    let fail = |message: String| DbError::File {
        path: path.to_path_buf(),
        message,
    };
    if bytes.len() < HEADER {
        return Err(fail(format!(
            "truncated: {} bytes, a database header alone is {HEADER}",
            bytes.len()
        )));
    }
    if &bytes[..8] != MAGIC {
        return Err(fail("not a terrasynth database (bad magic)".into()));
    }
    let version = u32_at(bytes, 8);
    if version != FORMAT_VERSION {
        return Err(fail(format!(
            "database format version {version} is not supported (this build reads version {FORMAT_VERSION}); rebuild it with `terrasynth db build`"
        )));
    }
    let count = u32_at(bytes, 12);
    if count > MAX_SECTIONS {
        return Err(fail(format!(
            "corrupt header: {count} sections (at most {MAX_SECTIONS})"
        )));
    }
    let declared = u64_at(bytes, 16);
    if declared != bytes.len() as u64 {
        return Err(fail(format!(
            "truncated or extended: header says {declared} bytes, the file has {}",
            bytes.len()
        )));
    }
    let table_end = HEADER + ENTRY * count as usize;
    if table_end > bytes.len() {
        return Err(fail(
            "truncated: the section table runs past the end".into(),
        ));
    }
    let mut header = bytes[..table_end].to_vec();
    header[24..28].fill(0);
    if crc32fast::hash(&header) != u32_at(bytes, 24) || u32_at(bytes, 28) != 0 {
        return Err(fail("corrupt header: checksum mismatch".into()));
    }
    let mut found = Vec::with_capacity(count as usize);
    let mut cursor = table_end;
    for i in 0..count as usize {
        let e = HEADER + ENTRY * i;
        let kind = Kind::from_u32(u32_at(bytes, e))
            .ok_or_else(|| fail(format!("section {i}: unknown kind {}", u32_at(bytes, e))))?;
        let level = u32_at(bytes, e + 4);
        let off = u64_at(bytes, e + 8);
        let len = u64_at(bytes, e + 16);
        if u32_at(bytes, e + 28) != 0 || u64_at(bytes, e + 32) != 0 {
            return Err(fail(format!("section {i}: reserved fields are not zero")));
        }
        let end = off
            .checked_add(len)
            .filter(|&end| end <= bytes.len() as u64);
        let (off, end) = match end {
            Some(end) if off as usize % ALIGN == 0 && off as usize >= cursor => {
                (off as usize, end as usize)
            }
            _ => {
                return Err(fail(format!(
                    "section {i} ({kind:?}) lies outside the file or overlaps another"
                )));
            }
        };
        if bytes[cursor..off].iter().any(|&b| b != 0) {
            return Err(fail(format!("corrupt padding before section {i}")));
        }
        found.push(Found {
            kind,
            level,
            range: off..end,
        });
        cursor = end;
    }
    if bytes[cursor..].iter().any(|&b| b != 0) {
        return Err(fail("corrupt padding after the last section".into()));
    }
    use rayon::prelude::*;
    let bad = (0..found.len()).into_par_iter().find_first(|&i| {
        let f = &found[i];
        crc32fast::hash(&bytes[f.range.clone()]) != u32_at(bytes, HEADER + ENTRY * i + 24)
    });
    if let Some(i) = bad {
        return Err(fail(format!(
            "section {i} ({:?}, level {}) is corrupt: checksum mismatch",
            found[i].kind, found[i].level
        )));
    }
    Ok(found)
}

/// The bytes a database (or a file of C₂ tables, [`super::c2_cache`])
/// lives in: one buffer of 64-byte lines, so that every section (each on
/// a 64-byte boundary) is aligned for the arrays cast from it, C₂'s
/// 32-byte quads included.
///
/// Why a file is read into it rather than memory-mapped: the correction
/// reads texels all over the atlas (each patch is a jump elsewhere), and
/// a file mapping comes in 4 KiB pages, which missed the TLB; this buffer
/// is advised huge pages ([`crate::pages`]): the 1024² `bench` ran 10 %
/// faster read than mapped on a database of the embedded exemplars (0.90×,
/// per-round median of 30 interleaved rounds), 7 % on the embedded one
/// (0.93×, 10 rounds). The copy costs a read of the file, which the
/// mapping paid too (it was populated up front, and every checksum reads
/// every byte).
pub struct Bytes {
    lines: Vec<Line>,
    len: usize,
}

/// 64 bytes, 64-byte aligned: [`Bytes`]' unit.
#[repr(C, align(64))]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Line([u8; 64]);

impl Bytes {
    /// `len` zero bytes, on huge pages where the OS gives them.
    fn zeroed(len: usize) -> Bytes {
        let mut lines = Vec::with_capacity(len.div_ceil(64));
        // Advised before the first write, which faults the pages in.
        crate::pages::advise_huge(lines.spare_capacity_mut());
        lines.resize(len.div_ceil(64), Line([0; 64]));
        Bytes { lines, len }
    }

    /// A copy of `bytes` (an embedded image, a fuzzer's input).
    pub fn copied(bytes: &[u8]) -> Bytes {
        let mut out = Bytes::zeroed(bytes.len());
        out.as_mut_slice().copy_from_slice(bytes);
        out
    }

    pub fn as_slice(&self) -> &[u8] {
        &bytemuck::cast_slice(&self.lines)[..self.len]
    }

    fn as_mut_slice(&mut self) -> &mut [u8] {
        &mut bytemuck::cast_slice_mut(&mut self.lines)[..self.len]
    }

    /// Reads a whole file, refused up front when it is empty or larger
    /// than the memory the system can give.
    pub fn read(path: &Path) -> Result<Bytes, DbError> {
        let os = |source| DbError::Os {
            path: path.to_path_buf(),
            source,
        };
        let mut file = std::fs::File::open(path).map_err(os)?;
        let len = file.metadata().map_err(os)?.len();
        if len == 0 {
            return Err(DbError::File {
                path: path.to_path_buf(),
                message: "truncated: the file is empty".into(),
            });
        }
        let what = format!("database file {}", path.display());
        crate::io::check_memory(&what, len)?;
        let len = usize::try_from(len).map_err(|_| DbError::File {
            path: path.to_path_buf(),
            message: format!("{len} bytes do not fit this machine's address space"),
        })?;
        let mut out = Bytes::zeroed(len);
        std::io::Read::read_exact(&mut file, out.as_mut_slice()).map_err(os)?;
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_reads_back_as_encoded_and_64_byte_aligned() {
        let b = vec![7u8; 300];
        let encoded = encode(&[Section {
            kind: Kind::Types,
            level: 2,
            bytes: &b,
        }]);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.tsdb");
        std::fs::write(&path, encoded.as_slice()).unwrap();
        let read = Bytes::read(&path).unwrap();
        assert_eq!(read.as_slice(), encoded.as_slice());
        assert_eq!(read.as_slice().as_ptr() as usize % 64, 0);
        let found = decode(read.as_slice(), &path).unwrap();
        assert_eq!(&read.as_slice()[found[0].range.clone()], &b[..]);
        // An empty file is refused with its path; a missing one too.
        std::fs::write(&path, b"").unwrap();
        let e = Bytes::read(&path).err().unwrap().to_string();
        assert!(e.contains("x.tsdb") && e.contains("empty"), "{e}");
        assert!(Bytes::read(&dir.path().join("none.tsdb")).is_err());
    }

    #[test]
    fn round_trip_and_every_byte_is_checked() {
        let a = [1u8, 2, 3];
        let b = vec![7u8; 100];
        let encoded = encode(&[
            Section {
                kind: Kind::Meta,
                level: 0,
                bytes: &a,
            },
            Section {
                kind: Kind::Types,
                level: 3,
                bytes: &b,
            },
        ]);
        let bytes = encoded.as_slice();
        let p = Path::new("x.tsdb");
        let found = decode(bytes, p).unwrap();
        assert_eq!(found.len(), 2);
        assert_eq!(&bytes[found[0].range.clone()], &a);
        assert_eq!((found[1].kind, found[1].level), (Kind::Types, 3));
        assert_eq!(&bytes[found[1].range.clone()], &b[..]);
        for i in 0..bytes.len() {
            let mut c = bytes.to_vec();
            c[i] ^= 0x10;
            assert!(decode(&c, p).is_err(), "flip at byte {i} went unnoticed");
        }
        for n in 0..bytes.len() {
            assert!(
                decode(&bytes[..n], p).is_err(),
                "truncation to {n} went unnoticed"
            );
        }
    }
}
