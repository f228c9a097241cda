//! Databases cached on disk: a build takes seconds to minutes, and the same
//! exemplars are analysed again and again (the embedded default database,
//! the realism protocol's per-DEM databases).
//!
//! A cache file's name carries a CRC-32 of everything the database depends
//! on — the exemplars' names, sizes, cell sizes and height bits, their type
//! masks, the build options, the crate version, [`FORMAT_VERSION`] and
//! [`BUILD_REVISION`] — so a changed input or a new binary never reuses a
//! stale file. A file that fails to load (damaged, truncated) is rebuilt;
//! one that cannot be written only costs a rebuild next time. Files are
//! written atomically, so concurrent users never see half a database.

use super::{BuildOptions, Database, DbError, ExemplarInput, build, file::FORMAT_VERSION};
use crate::progress::Progress;
use std::path::{Path, PathBuf};

/// Bump when the build algorithm changes its output (PatchMatch, PCA…).
pub const BUILD_REVISION: u32 = 1;

/// A CRC-32 over length-prefixed parts, then the crate version,
/// [`FORMAT_VERSION`] and [`BUILD_REVISION`].
pub fn key<'a>(parts: impl IntoIterator<Item = &'a [u8]>) -> u32 {
    let mut h = crc32fast::Hasher::new();
    for part in parts {
        h.update(&(part.len() as u64).to_le_bytes());
        h.update(part);
    }
    h.update(env!("CARGO_PKG_VERSION").as_bytes());
    h.update(&FORMAT_VERSION.to_le_bytes());
    h.update(&BUILD_REVISION.to_le_bytes());
    h.finalize()
}

/// Where the database of `inputs` built with `opts` is cached in `dir`.
pub fn path_for(dir: &Path, inputs: &[ExemplarInput], opts: &BuildOptions) -> PathBuf {
    let mut parts: Vec<Vec<u8>> = vec![
        format!(
            "levels {} cell {:?} fill {} patchmatch {}",
            opts.levels, opts.cell_size, opts.fill_nodata, opts.patchmatch_iterations
        )
        .into_bytes(),
    ];
    for e in inputs {
        let hf = &e.heights;
        parts.push(
            format!(
                "{} {}x{} cell {:016x}",
                e.name,
                hf.width(),
                hf.height(),
                hf.cell_size().to_bits()
            )
            .into_bytes(),
        );
        parts.push(bytemuck::cast_slice(hf.data()).to_vec());
        match &e.types {
            Some(m) => {
                parts.push(m.indices.clone());
                parts.push(format!("{:?}", m.names).into_bytes());
            }
            None => parts.push(b"untyped".to_vec()),
        }
    }
    dir.join(format!(
        "db-{:08x}.tsdb",
        key(parts.iter().map(|p| p.as_slice()))
    ))
}

/// Loads the database cached at `path`, or makes it with `build` and caches
/// it there. Returns the database and whether it was just built.
pub fn load_or_build(
    path: &Path,
    build: impl FnOnce() -> Result<Database, DbError>,
) -> Result<(Database, bool), DbError> {
    if let Ok(db) = Database::load(path) {
        return Ok((db, false));
    }
    let db = build()?;
    if path
        .parent()
        .is_none_or(|d| std::fs::create_dir_all(d).is_ok())
    {
        // A cache we cannot write only means building again next time.
        let _ = db.save(path);
    }
    Ok((db, true))
}

/// The database of `inputs` built with `opts`, from the cache in `dir` or
/// built (with progress) and cached. Returns whether it was built; the
/// build's warnings are only seen when it is.
pub fn cached_build(
    dir: &Path,
    inputs: Vec<ExemplarInput>,
    opts: &BuildOptions,
    progress: &dyn Progress,
) -> Result<(Database, bool), DbError> {
    let path = path_for(dir, &inputs, opts);
    load_or_build(&path, || Ok(build(inputs, opts, progress)?.0))
}
