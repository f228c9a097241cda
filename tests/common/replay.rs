//! Which reader each fuzz corpus, malformed file or regression case feeds,
//! shared by the replay and allocation tests.

use std::path::{Path, PathBuf};
use terrasynth::Heightfield;
use terrasynth::io::{self, Format, FormatError, ReadOptions};

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The fuzz targets and the format each decodes (`sidecar` is special).
pub const TARGETS: [(&str, Option<Format>); 9] = [
    ("png", Some(Format::Png16)),
    ("exr", Some(Format::Exr)),
    ("tiff", Some(Format::Tiff)),
    ("hgt", Some(Format::Hgt)),
    ("asc", Some(Format::Asc)),
    ("r16", Some(Format::R16)),
    ("r32", Some(Format::R32)),
    ("ter", Some(Format::Ter)),
    ("sidecar", None),
];

/// Runs one input exactly as its fuzz target does.
pub fn run_target(format: Option<Format>, data: &[u8]) -> Option<Result<Heightfield, FormatError>> {
    match format {
        Some(f) => Some(io::decode(data, f, None, &ReadOptions::default())),
        None => {
            // fuzz/fuzz_targets/companions/sidecar.rs: first byte = sidecar length.
            let (&split, rest) = data.split_first()?;
            let (json, raw) = rest.split_at((split as usize).min(rest.len()));
            io::Sidecar::parse(json).ok()?;
            Some(io::decode(
                raw,
                Format::R16,
                Some(json),
                &ReadOptions::default(),
            ))
        }
    }
}

/// Every (file, target format) to replay: the fuzz corpus, the committed
/// crash regressions (tests/regressions/<target>/), and tests/malformed/<format>/
/// with the format its extension names.
pub fn cases() -> Vec<(PathBuf, Option<Format>)> {
    let mut out = Vec::new();
    for (target, format) in TARGETS {
        for dir in [
            root().join("fuzz/corpus").join(target),
            root().join("tests/regressions").join(target),
        ] {
            out.extend(files(&dir).into_iter().map(|p| (p, format)));
        }
    }
    for p in files(&root().join("tests/malformed")) {
        if let Some(f) =
            Format::from_path(&p).filter(|_| p.extension().is_some_and(|e| e != "json"))
        {
            out.push((p, Some(f)));
        }
    }
    out
}

/// The files under `dir`, its subfolders' too (tests/malformed has one
/// per format), sorted; none where `dir` is missing.
fn files(dir: &Path) -> Vec<PathBuf> {
    let mut v = Vec::new();
    let mut dirs = vec![dir.to_path_buf()];
    while let Some(d) = dirs.pop() {
        let Ok(rd) = std::fs::read_dir(&d) else {
            continue;
        };
        for p in rd.map(|e| e.unwrap().path()) {
            if p.is_dir() {
                dirs.push(p);
            } else if p.is_file() {
                v.push(p);
            }
        }
    }
    v.sort();
    v
}
