//! C₂'s tables ([`super::c2`]) kept on disk across processes, for the
//! databases that live in the cache directory.
//!
//! Why: every process that synthesizes on the CPU gathered the tables
//! anew: for the embedded database 33 MB written into fresh memory,
//! ~20 ms of a ~0.4 s `synth --size 1024x1024` (about half of it the
//! kernel zeroing the pages), paid again by every Dask worker and every
//! short `synth`. Read from a file the OS already holds in its page
//! cache, they cost a copy and one checksum pass (into huge pages, like
//! the database: [`super::file::Bytes`]). The embedded database keeps them
//! beside its own cached file ([`super::default`]); a database the user
//! names is left as it is (its tables are gathered per process, as
//! before), so that nothing is written beside the user's files.
//!
//! Layout, little-endian:
//!
//! ```text
//! 0   magic "TSC2"
//! 4   FORMAT u32
//! 8   the database's fingerprint: its header CRC u32, its length u64 (at 12)
//! 20  level count n u32
//! 24  CRC-32 of the tables u32
//! 28  zero u32
//! 32  per level its entry count u64, then zeros up to a multiple of 32
//! …   each level's entries in level order, 32 bytes each (a `Quad`)
//! ```
//!
//! A file that fails any check — another database, another layout, a
//! count that is not the level's, a wrong length or checksum — is
//! refused, and the tables are gathered (and the file rewritten) instead.

use super::Database;
use super::c2::{Quad, Tables};
use super::file::{self, Bytes};
use std::ops::Range;
use std::path::Path;

const MAGIC: &[u8; 4] = b"TSC2";
/// Bump when the layout or the meaning of an entry changes.
const FORMAT: u32 = 1;
const ENTRY: usize = std::mem::size_of::<Quad>();

/// Which database a file's tables belong to: the CRC-32 of its header
/// (which covers every section's CRC) and its length.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Fingerprint {
    pub crc: u32,
    pub len: u64,
}

/// Bytes before the first entry, for `n` levels.
fn header_len(n: usize) -> usize {
    (32 + 8 * n).next_multiple_of(ENTRY)
}

/// The file holding `tables` of the database `db`.
pub fn encode(db: Fingerprint, tables: &[&[Quad]]) -> Vec<u8> {
    let head = header_len(tables.len());
    let total = head + tables.iter().map(|t| t.len() * ENTRY).sum::<usize>();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&FORMAT.to_le_bytes());
    out.extend_from_slice(&db.crc.to_le_bytes());
    out.extend_from_slice(&db.len.to_le_bytes());
    out.extend_from_slice(&(tables.len() as u32).to_le_bytes());
    out.extend_from_slice(&[0; 8]); // the CRC, below; zero
    for t in tables {
        out.extend_from_slice(&(t.len() as u64).to_le_bytes());
    }
    out.resize(head, 0);
    let mut crc = crc32fast::Hasher::new();
    for t in tables {
        let bytes: &[u8] = bytemuck::cast_slice(t);
        crc.update(bytes);
        out.extend_from_slice(bytes);
    }
    out[24..28].copy_from_slice(&crc.finalize().to_le_bytes());
    out
}

/// The byte ranges of each level's entries in `bytes`, if they are the
/// tables of database `db` with `counts` entries per level; else why not.
pub fn decode(
    bytes: &[u8],
    db: Fingerprint,
    counts: &[usize],
) -> Result<Vec<Range<usize>>, String> {
    let u32_at = |i: usize| file::u32_at(bytes, i);
    let u64_at = |i: usize| file::u64_at(bytes, i);
    if bytes.len() < 32 || &bytes[..4] != MAGIC {
        return Err("not a C2 table file".into());
    }
    if u32_at(4) != FORMAT {
        return Err(format!("format {} (this build reads {FORMAT})", u32_at(4)));
    }
    let theirs = Fingerprint {
        crc: u32_at(8),
        len: u64_at(12),
    };
    if theirs != db {
        return Err("the tables of another database".into());
    }
    let n = counts.len();
    if u32_at(20) as usize != n {
        return Err(format!("{} levels, expected {n}", u32_at(20)));
    }
    if u32_at(28) != 0 {
        return Err("nonzero reserved field".into());
    }
    let head = header_len(n);
    if bytes.len() < head {
        return Err("truncated header".into());
    }
    let mut ranges = Vec::with_capacity(n);
    let mut at = head;
    for (i, &count) in counts.iter().enumerate() {
        if u64_at(32 + 8 * i) != count as u64 {
            return Err(format!(
                "level {i}: {} entries, expected {count}",
                u64_at(32 + 8 * i)
            ));
        }
        ranges.push(at..at + count * ENTRY);
        at += count * ENTRY;
    }
    if bytes[32 + 8 * n..head].iter().any(|&b| b != 0) {
        return Err("nonzero header padding".into());
    }
    if bytes.len() != at {
        return Err(format!("{} bytes, expected {at}", bytes.len()));
    }
    if crc32fast::hash(&bytes[head..]) != u32_at(24) {
        return Err("checksum mismatch".into());
    }
    Ok(ranges)
}

/// The tables of `db` kept at `path`; `None` if the file is missing or
/// refused.
pub(super) fn load(path: &Path, db: &Database) -> Option<Tables> {
    let bytes = Bytes::read(path).ok()?;
    let counts: Vec<usize> = (0..db.level_count())
        .map(|i| db.level(i).similar.len())
        .collect();
    let ranges = decode(bytes.as_slice(), db.fingerprint(), &counts).ok()?;
    // `Bytes` starts on 64 bytes, and every range on a multiple of 32
    // bytes from it; checked anyway, since `Tables::level` casts.
    let aligned = ranges
        .iter()
        .all(|r| bytemuck::try_cast_slice::<u8, Quad>(&bytes.as_slice()[r.clone()]).is_ok());
    aligned.then_some(Tables::Read(bytes, ranges))
}

/// Keeps `tables` of `db` at `path` (atomically). A file that cannot be
/// written only means gathering them again next time.
pub(super) fn save(path: &Path, db: &Database, tables: &[Vec<Quad>]) {
    let views: Vec<&[Quad]> = tables.iter().map(|t| t.as_slice()).collect();
    let _ = crate::io::write_atomic(path, &encode(db.fingerprint(), &views));
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tables() -> Vec<Vec<Quad>> {
        let q = |k: u64| Quad([k, k * 3 + 1, !k, k << 40]);
        vec![(0..5).map(q).collect(), vec![], (7..9).map(q).collect()]
    }

    const DB: Fingerprint = Fingerprint {
        crc: 0xDEAD_BEEF,
        len: 123_456,
    };

    #[test]
    fn tables_decode_to_where_they_were_written() {
        let t = tables();
        let views: Vec<&[Quad]> = t.iter().map(|v| v.as_slice()).collect();
        let bytes = encode(DB, &views);
        assert_eq!(bytes.len() % ENTRY, 0);
        let ranges = decode(&bytes, DB, &[5, 0, 2]).unwrap();
        for (r, v) in ranges.iter().zip(&t) {
            assert_eq!(&bytes[r.clone()], bytemuck::cast_slice::<Quad, u8>(v));
        }
    }

    #[test]
    fn another_database_layout_or_damage_is_refused() {
        let t = tables();
        let views: Vec<&[Quad]> = t.iter().map(|v| v.as_slice()).collect();
        let bytes = encode(DB, &views);
        let other = Fingerprint { len: 1, ..DB };
        assert!(decode(&bytes, other, &[5, 0, 2]).is_err());
        assert!(decode(&bytes, DB, &[5, 0, 3]).is_err());
        assert!(decode(&bytes, DB, &[5, 0]).is_err());
        // Every truncation, and a flipped bit anywhere.
        for len in 0..bytes.len() {
            assert!(
                decode(&bytes[..len], DB, &[5, 0, 2]).is_err(),
                "{len} bytes"
            );
        }
        for i in 0..bytes.len() {
            let mut b = bytes.clone();
            b[i] ^= 0x10;
            assert!(decode(&b, DB, &[5, 0, 2]).is_err(), "bit flipped at {i}");
        }
    }
}
