//! `docs/ARCHITECTURE.md` stays true (issue 42): its folder tree names
//! every folder of the repository and no folder that is gone, and the
//! stage rule it states — no stage imports another stage — holds in
//! `src/stages/`. A moved or added folder, or a stage reaching into
//! another, fails here until the map says so.

use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

/// The repository root (the crate's manifest folder).
fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn architecture() -> String {
    fs::read_to_string(root().join("docs/ARCHITECTURE.md")).unwrap()
}

/// The folders the map's tree lists (the first word of each line of its
/// `text` block), e.g. `src/stages/correct/`.
fn listed() -> Vec<String> {
    let doc = architecture();
    let tree = doc
        .split("```text\n")
        .nth(1)
        .and_then(|t| t.split("```").next())
        .expect("a ```text block with the folder tree");
    tree.lines()
        .filter_map(|l| l.split_whitespace().next())
        .map(str::to_owned)
        .collect()
}

/// Folders that are build output or caches, never part of the map.
fn skipped(name: &str) -> bool {
    matches!(name, "target" | "node_modules" | "__pycache__")
        || (name.starts_with('.') && name != ".ci")
        || name.ends_with(".egg-info")
}

/// Every folder under `dir` (relative to the root, with a trailing `/`).
fn folders(dir: &Path, out: &mut BTreeSet<String>) {
    for entry in fs::read_dir(root().join(dir)).unwrap() {
        let entry = entry.unwrap();
        let name = entry.file_name().to_string_lossy().into_owned();
        if entry.file_type().unwrap().is_dir() && !skipped(&name) {
            let rel = dir.join(&name);
            out.insert(format!("{}/", rel.display()));
            folders(&rel, out);
        }
    }
}

#[test]
fn the_folder_tree_names_every_folder_and_no_gone_one() {
    let listed = listed();
    assert!(listed.len() > 40, "{} folders listed", listed.len());
    // `fuzz/corpus/<format>/` stands for one folder per fuzz target.
    let wildcard = |l: &str| l.contains('<');
    for l in listed.iter().filter(|l| !wildcard(l)) {
        assert!(l.ends_with('/'), "{l}: a folder ends with /");
        assert!(
            root().join(l).is_dir(),
            "ARCHITECTURE.md lists {l}, which is gone"
        );
    }
    let mut present = BTreeSet::new();
    folders(Path::new(""), &mut present);
    let unlisted: Vec<&String> = present
        .iter()
        .filter(|f| !listed.contains(f))
        .filter(|f| {
            !listed.iter().filter(|l| wildcard(l)).any(|l| {
                let parent = &l[..l.find('<').unwrap()];
                f.strip_prefix(parent)
                    .is_some_and(|rest| rest.matches('/').count() <= 1)
            })
        })
        .collect();
    assert!(
        unlisted.is_empty(),
        "folders missing from ARCHITECTURE.md's tree: {unlisted:?}"
    );
}

/// The stems of the stages (`src/stages/<x>.rs`, mod.rs and common.rs
/// aside).
fn stages() -> Vec<String> {
    let mut out: Vec<String> = fs::read_dir(root().join("src/stages"))
        .unwrap()
        .filter_map(|e| {
            let name = e.unwrap().file_name().to_string_lossy().into_owned();
            name.strip_suffix(".rs").map(str::to_owned)
        })
        .filter(|s| s != "mod" && s != "common")
        .collect();
    out.sort();
    out
}

/// Every `.rs` file of stage `stem`: its file and its folder's.
fn stage_files(stem: &str, out: &mut Vec<PathBuf>) {
    out.push(root().join(format!("src/stages/{stem}.rs")));
    let mut dirs = vec![root().join(format!("src/stages/{stem}"))];
    while let Some(dir) = dirs.pop() {
        let Ok(entries) = fs::read_dir(&dir) else {
            continue;
        };
        for e in entries {
            let p = e.unwrap().path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
}

#[test]
fn no_stage_imports_another_stage() {
    let stages = stages();
    assert!(stages.len() >= 8, "{stages:?}");
    let doc = architecture();
    assert!(
        doc.contains("A stage imports no other stage"),
        "the rule this test checks is stated in ARCHITECTURE.md"
    );
    for stem in &stages {
        let mut files = Vec::new();
        stage_files(stem, &mut files);
        for file in files {
            // Code, not comments: a doc may point at another stage.
            let text: String = fs::read_to_string(&file)
                .unwrap()
                .lines()
                .filter(|l| !l.trim_start().starts_with("//"))
                .collect::<Vec<_>>()
                .join("\n");
            for other in stages.iter().filter(|o| *o != stem) {
                // The one exception the map states: reconstruct runs
                // repair_extrema fused with it on the CPU.
                if stem == "reconstruct" && other == "repair_extrema" {
                    continue;
                }
                for path in [
                    format!("stages::{other}"),
                    format!("super::{other}"),
                    format!("super::super::{other}"),
                ] {
                    assert!(
                        !text.contains(&path),
                        "{} reaches into stage {other} ({path}): share it through stages::common",
                        file.display()
                    );
                }
            }
        }
    }
}
