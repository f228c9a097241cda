//! The embedded default database: four 512² crops of real SRTM DEMs in
//! `data/exemplars/`, a folder each (a coast, a plain, high mountains,
//! rolling hills; sources and credits in `data/CREDITS.md`) with their type masks (sea, flat, hills,
//! mountains), compiled into the binary so that `terrasynth synth` works on
//! a fresh machine with no files. They are real terrain rather than the
//! crate's own procedural styles (`terrasynth generate`) because the first
//! command a user runs should make terrain out of real terrain, and the
//! types the editor paints should be real landscape kinds.
//!
//! Analysing them takes seconds, so the database is built on first use and
//! cached in the user's cache directory under a name that hashes the
//! embedded bytes, the crate version and [`cache::BUILD_REVISION`]: a new binary
//! never reuses a stale cache. A cache that fails to load is rebuilt; a
//! cache that cannot be written only costs a rebuild next time.

use super::{BuildOptions, Database, DbError, ExemplarInput, build, cache};
use crate::io::{self, Format, ReadOptions, TypeMask};
use crate::progress::Progress;
use std::path::{Path, PathBuf};

struct Embedded {
    name: &'static str,
    dem: &'static [u8],
    sidecar: &'static [u8],
    mask: &'static [u8],
    names: &'static [u8],
}

/// The bytes of `data/exemplars/<$name>/<$name><$suffix>`, compiled in.
macro_rules! exemplar_file {
    ($name:literal, $suffix:literal) => {
        include_bytes!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/data/exemplars/",
            $name,
            "/",
            $name,
            $suffix
        ))
    };
}

/// One exemplar's four files: heights, sidecar, type mask, type names.
macro_rules! embed {
    ($name:literal) => {
        Embedded {
            name: $name,
            dem: exemplar_file!($name, ".png"),
            sidecar: exemplar_file!($name, ".json"),
            mask: exemplar_file!($name, "_types.png"),
            names: exemplar_file!($name, "_types.json"),
        }
    };
}

/// In alphabetical order, which puts the coast first: the database numbers
/// types by first appearance, so the editor's palette reads sea, flat,
/// hills, mountains (the masks' own indices).
const EMBEDDED: [Embedded; 4] = [
    embed!("catalan_coast_hills"),
    embed!("north_german_plain"),
    embed!("pyrenees_andorra"),
    embed!("thuringia_hills"),
];

/// Names of the embedded exemplars, in database order.
pub fn names() -> Vec<&'static str> {
    EMBEDDED.iter().map(|e| e.name).collect()
}

/// The embedded exemplars, decoded.
pub fn inputs() -> Vec<ExemplarInput> {
    EMBEDDED
        .iter()
        .map(|e| ExemplarInput {
            name: e.name.to_string(),
            heights: io::decode(
                e.dem,
                Format::Png16,
                Some(e.sidecar),
                &ReadOptions::default(),
            )
            .expect("embedded exemplars are valid (tested)"),
            types: Some(
                TypeMask::decode(e.mask, Some(e.names)).expect("embedded masks are valid (tested)"),
            ),
        })
        .collect()
}

/// Builds the default database in memory.
pub fn build_default(progress: &dyn Progress) -> Result<Database, DbError> {
    Ok(build(inputs(), &BuildOptions::default(), progress)?.0)
}

/// Where the default database is cached in `dir`.
pub fn cache_path(dir: &Path) -> PathBuf {
    let key = cache::key(
        EMBEDDED
            .iter()
            .flat_map(|e| [e.dem, e.sidecar, e.mask, e.names]),
    );
    dir.join(format!("default-{key:08x}.tsdb"))
}

/// `$TERRASYNTH_CACHE_DIR`, else `$XDG_CACHE_HOME/terrasynth`, else
/// `~/.cache/terrasynth`, else the system temporary directory.
pub fn cache_dir() -> PathBuf {
    let env = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    env("TERRASYNTH_CACHE_DIR")
        .or_else(|| env("XDG_CACHE_HOME").map(|p| p.join("terrasynth")))
        .or_else(|| env("HOME").map(|p| p.join(".cache").join("terrasynth")))
        .unwrap_or_else(|| std::env::temp_dir().join("terrasynth"))
}

/// Loads the default database cached in `dir` (normally [`cache_dir`]),
/// building and caching it if needed. Returns the database and whether it
/// was just built. C₂'s tables ([`Database::c2`]) are kept beside it.
pub fn load_or_build(dir: &Path, progress: &dyn Progress) -> Result<(Database, bool), DbError> {
    let path = cache_path(dir);
    let (mut db, built) = cache::load_or_build(&path, || build_default(progress))?;
    db.keep_c2_at(path.with_extension("c2"));
    Ok((db, built))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::database::c2::{self, Quad};
    use crate::database::c2_cache;

    #[test]
    fn embedded_exemplars_decode_with_types() {
        let inputs = inputs();
        assert_eq!(
            names(),
            [
                "catalan_coast_hills",
                "north_german_plain",
                "pyrenees_andorra",
                "thuringia_hills"
            ]
        );
        for e in &inputs {
            let m = e.types.as_ref().unwrap();
            assert_eq!((m.width, m.height), (e.heights.width(), e.heights.height()));
            assert_eq!((m.width, m.height), (512, 512), "{}", e.name);
            let named: Vec<&str> = (0..4).map(|i| m.names[&i].as_str()).collect();
            assert_eq!(named, ["sea", "flat", "hills", "mountains"], "{}", e.name);
            assert_eq!(e.heights.nodata_count(), 0);
            // SRTM3 resampled to square cells of about 3 arc-seconds.
            assert!((92.0..93.0).contains(&e.heights.cell_size()), "{}", e.name);
        }
    }

    #[test]
    fn cache_is_used_and_a_corrupt_cache_is_rebuilt() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("cache");
        let silent = &crate::progress::Silent;
        let (a, built) = load_or_build(&dir, silent).unwrap();
        assert!(built && cache_path(&dir).exists());
        assert_eq!(a.type_names(), ["sea", "flat", "hills", "mountains"]);
        let (b, built) = load_or_build(&dir, silent).unwrap();
        assert!(!built);
        assert!(a.file_bytes() == b.file_bytes());
        std::fs::write(cache_path(&dir), b"junk").unwrap();
        let (c, built) = load_or_build(&dir, silent).unwrap();
        assert!(built && c.file_bytes() == a.file_bytes());
        // C₂'s tables: the first use gathers them and keeps them beside
        // the database.
        let c2_path = cache_path(&dir).with_extension("c2");
        assert!(!c2_path.exists());
        let gathered: Vec<Vec<Quad>> = (0..a.level_count())
            .map(|i| c2::gather(&a.level(i)))
            .collect();
        assert_eq!(a.c2(0), gathered[0].as_slice());
        let kept = std::fs::read(&c2_path).unwrap();
        // A process that finds them uses the file as it is: here a valid
        // file whose level-0 entries were changed (a gathering would undo it).
        let mut changed = gathered.clone();
        changed[0][7].0[2] ^= 1;
        let views: Vec<&[Quad]> = changed.iter().map(|t| t.as_slice()).collect();
        std::fs::write(&c2_path, c2_cache::encode(a.fingerprint(), &views)).unwrap();
        let (d, _) = load_or_build(&dir, silent).unwrap();
        for (i, t) in changed.iter().enumerate() {
            assert_eq!(d.c2(i), t.as_slice(), "level {i}");
        }
        // A damaged file is refused: the tables are gathered and kept again.
        let mut damaged = kept.clone();
        damaged[kept.len() / 2] ^= 0x40;
        std::fs::write(&c2_path, &damaged).unwrap();
        let (e, _) = load_or_build(&dir, silent).unwrap();
        for (i, t) in gathered.iter().enumerate() {
            assert_eq!(e.c2(i), t.as_slice(), "level {i}");
        }
        assert!(std::fs::read(&c2_path).unwrap() == kept);
    }
}
