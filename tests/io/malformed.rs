//! The malformed-input suite: every file in tests/malformed/<format>/ (made
//! by tests/make_fixtures.py) must fail to read with the specific error
//! listed, by its path under tests/malformed/, in
//! tests/malformed/expected.json — the variant, a message substring, and
//! the file (data or sidecar) the message names. Nothing may panic.

use std::collections::BTreeMap;
use std::path::PathBuf;
use terrasynth::io::{self, ReadOptions};

#[derive(serde::Deserialize)]
struct Expected {
    variant: String,
    contains: String,
    names: String,
}

fn dir() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/malformed"))
}

/// The variant name of an error, from its Debug form (`Variant(..)` or `Variant { .. }`).
fn variant(e: &io::FormatError) -> String {
    let d = format!("{e:?}");
    d.split(['(', ' ', '{'])
        .next()
        .unwrap_or_default()
        .to_string()
}

#[test]
fn every_malformed_file_fails_with_its_specific_error() {
    let manifest: BTreeMap<String, Expected> =
        serde_json::from_slice(&std::fs::read(dir().join("expected.json")).unwrap()).unwrap();
    assert!(manifest.len() >= 30, "the suite needs at least 30 files");
    let mut failures = Vec::new();
    for (name, want) in &manifest {
        let path = dir().join(name);
        let err = match io::read(&path, &ReadOptions::default()) {
            Ok(hf) => {
                failures.push(format!(
                    "{name}: read succeeded ({}x{})",
                    hf.width(),
                    hf.height()
                ));
                continue;
            }
            Err(e) => e,
        };
        let msg = err.to_string();
        let Some(kind) = err.format_error() else {
            failures.push(format!("{name}: not a format error: {msg}"));
            continue;
        };
        let got = variant(kind);
        if got != want.variant || !msg.contains(&want.contains) || !msg.contains(&want.names) {
            failures.push(format!(
                "{name}: expected {} containing {:?} naming {}, got {got}: {msg}",
                want.variant, want.contains, want.names
            ));
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

/// Every file under the directory is a case or a case's sidecar, so a
/// file cannot be added without saying what it must produce.
#[test]
fn every_file_is_listed_in_the_manifest() {
    let manifest: BTreeMap<String, serde_json::Value> =
        serde_json::from_slice(&std::fs::read(dir().join("expected.json")).unwrap()).unwrap();
    let mut names = Vec::new();
    let mut dirs = vec![dir()];
    while let Some(d) = dirs.pop() {
        for entry in std::fs::read_dir(d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                dirs.push(path);
            } else {
                // The manifest's key: the path under tests/malformed/.
                let rel = path.strip_prefix(dir()).unwrap();
                names.push(rel.to_str().unwrap().to_owned());
            }
        }
    }
    assert!(names.len() >= 30, "{} files", names.len());
    for name in names {
        let stem = name.rsplit_once('.').map_or(name.as_str(), |(s, _)| s);
        let listed = manifest.contains_key(&name)
            || name == "expected.json"
            || (name.ends_with(".json")
                && manifest
                    .keys()
                    .any(|k| k.rsplit_once('.').is_some_and(|(s, _)| s == stem)));
        assert!(listed, "{name} is not in expected.json");
    }
}
