//! `docs/ARCHITECTURE.md` stays true (issue 42): its folder tree names
//! every folder of the repository and no folder that is gone, its module
//! floors hold (every top-level module on one line, importing only from
//! its own line or those above), and the stage rule it states — no stage
//! imports another stage — holds in `src/stages/`; its table of stages
//! is the `stages!` table's (`stages::Stage::ALL`). A moved or added
//! folder or module, an import up the floors, or a stage reaching into
//! another, fails here until the map says so.

use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

mod common;
use common::rust_files;
use terrasynth::stages::Stage;

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

/// The stems of the stages: the names of the `stages!` table's lines.
fn stages() -> Vec<String> {
    Stage::ALL.iter().map(|s| s.name().to_owned()).collect()
}

/// The map's table of stages has one row per line of the `stages!` table,
/// in its order; every file a row names exists; every `src/stages/<x>.rs`
/// (mod.rs and common.rs aside), `kernels/<x>.wgsl` (common.wgsl aside)
/// and `tests/stages/<x>.rs` (the target's main.rs aside) is a stage's.
#[test]
fn the_stage_table_matches_the_stages() {
    let doc = architecture();
    let rows: Vec<&str> = doc.lines().filter(|l| l.starts_with("| `")).collect();
    let named: Vec<&str> = rows.iter().filter_map(|r| r.split('`').nth(1)).collect();
    assert_eq!(named, stages(), "ARCHITECTURE.md's table of stages");
    for row in &rows {
        // Backticked paths, less patterns (`{a,b}`, `<x>`) and bench ids.
        for path in row.split('`').skip(1).step_by(2) {
            let file = path.ends_with(".rs") || path.ends_with(".wgsl");
            if file && path.contains('/') && !path.contains(['{', '<']) && !path.starts_with('.') {
                let p = root().join(path);
                assert!(p.is_file(), "ARCHITECTURE.md names {path}, which is gone");
            }
        }
    }
    let stems = |dir: &str, ext: &str| -> Vec<String> {
        fs::read_dir(root().join(dir))
            .unwrap()
            .filter_map(|e| {
                let name = e.unwrap().file_name().to_string_lossy().into_owned();
                name.strip_suffix(ext).map(str::to_owned)
            })
            .collect()
    };
    let known = stages();
    for (dir, ext, aside) in [
        ("src/stages", ".rs", &["mod", "common"][..]),
        ("kernels", ".wgsl", &["common"][..]),
        ("tests/stages", ".rs", &["main"][..]),
    ] {
        for stem in stems(dir, ext) {
            assert!(
                known.contains(&stem) || aside.contains(&stem.as_str()),
                "{dir}/{stem}{ext} is no line of the stages! table (src/stages/mod.rs)"
            );
        }
    }
}

/// Every test target of a folder (`tests/<target>/main.rs`) declares each
/// `.rs` file beside its main.rs as a module: Cargo compiles only what
/// main.rs declares, so a file left out would never run, silently.
#[test]
fn every_test_file_of_a_target_folder_is_a_module_of_it() {
    let mut targets = 0;
    for entry in fs::read_dir(root().join("tests")).unwrap() {
        let dir = entry.unwrap().path();
        let Ok(main) = fs::read_to_string(dir.join("main.rs")) else {
            continue;
        };
        targets += 1;
        for file in fs::read_dir(&dir).unwrap() {
            let name = file.unwrap().file_name().to_string_lossy().into_owned();
            if let Some(stem) = name.strip_suffix(".rs").filter(|s| *s != "main") {
                assert!(
                    main.lines().any(|l| l.trim() == format!("mod {stem};")),
                    "{}/{name} is no module of its main.rs, so it never runs",
                    dir.display()
                );
            }
        }
    }
    assert!(targets >= 8, "{targets} test targets in folders");
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

/// The map's module floors: line number → its modules (the bold
/// `**`name`**` of each numbered item of "Module floors").
fn floors() -> Vec<(usize, String)> {
    let doc = architecture();
    let section = doc
        .split("## Module floors")
        .nth(1)
        .and_then(|s| s.split("\n## ").next())
        .expect("a \"Module floors\" section");
    let mut out = Vec::new();
    let mut line = 0;
    for text in section.lines() {
        if let Some((n, _)) = text.split_once(". ")
            && let Ok(n) = n.parse::<usize>()
        {
            line = n;
        }
        for bold in text.split("**`").skip(1) {
            if let Some((name, _)) = bold.split_once("`**") {
                out.push((line, name.to_owned()));
            }
        }
    }
    out
}

/// The crate's top-level modules a source text names as `crate::<module>`
/// (also inside `use crate::{a, b::c}` groups); comments skipped.
fn crate_modules(text: &str) -> BTreeSet<String> {
    let code: String = text
        .lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n");
    let ident = |s: &str| -> String {
        s.trim_start()
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect()
    };
    let mut out = BTreeSet::new();
    for rest in code.split("crate::").skip(1) {
        if let Some(group) = rest.strip_prefix('{') {
            // Top-level entries of the group: split at commas of depth 0.
            let (mut depth, mut start) = (0, 0);
            for (i, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => {
                        out.insert(ident(&group[start..i]));
                        break;
                    }
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        out.insert(ident(&group[start..i]));
                        start = i + 1;
                    }
                    _ => {}
                }
            }
        } else {
            out.insert(ident(rest));
        }
    }
    out.remove("");
    out
}

#[test]
fn every_module_imports_only_from_its_floor_or_below() {
    let floors = floors();
    let floor = |m: &str| floors.iter().find(|(_, n)| n == m).map(|(l, _)| *l);
    assert!(floors.len() >= 25, "{floors:?}");
    let src = root().join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut broken = Vec::new();
    for f in files {
        let rel = f.strip_prefix(&src).unwrap();
        let top = rel.iter().next().unwrap().to_string_lossy();
        let top = top.trim_end_matches(".rs");
        if top == "lib" || top == "bin" {
            continue;
        }
        let own = floor(top).unwrap_or_else(|| panic!("src/{top} is on no line of the floors"));
        for m in crate_modules(&fs::read_to_string(&f).unwrap()) {
            match floor(&m) {
                Some(l) if l > own => broken.push(format!(
                    "src/{} (line {own}) imports `{m}` (line {l})",
                    rel.display()
                )),
                // Items of lib.rs itself (`crate::Heightfield`) are no module.
                _ => {}
            }
        }
    }
    assert!(broken.is_empty(), "{broken:#?}");
}
