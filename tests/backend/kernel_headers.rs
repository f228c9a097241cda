//! Every `kernels/*.wgsl` kernel names its CPU mirror, and every file and
//! Rust item its comments cite exists (issue 42: after the stages moved,
//! 7 of 9 headers named their mirror by the old path, and `fill_ssd.wgsl`
//! a function that no longer existed — a reader following them got lost).
//!
//! The rules, from the comments (`//` lines) of each kernel:
//! - a stage kernel (every file but `common.wgsl`) names
//!   `src/stages/<stem>.rs`, the mirror it is checked against;
//! - every `src/…` path exists;
//! - every Rust path `m::item` names an item that is defined (fn, const,
//!   static, struct, enum, type, mod, field or variant) in a file of module
//!   `m` (`…/m.rs` or `…/m/mod.rs`, and the files of `m/`), or, where `m`
//!   is a type (`Type::item`), in a file that defines the type.

use std::fs;
use std::path::{Path, PathBuf};

use crate::common::rust_files;

/// The `//` comment text of a WGSL file.
fn comments(wgsl: &str) -> String {
    wgsl.lines()
        .filter_map(|l| l.split_once("//").map(|(_, c)| c))
        .collect::<Vec<_>>()
        .join("\n")
}

fn is_ident_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// Rust paths `a::b(::c…)` in `text` (words joined by `::`).
fn rust_paths(text: &str) -> Vec<Vec<String>> {
    let chars: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        if !is_ident_char(chars[i]) || (i > 0 && is_ident_char(chars[i - 1])) {
            i += 1;
            continue;
        }
        let mut segs = Vec::new();
        let mut j = i;
        loop {
            let s = j;
            while j < chars.len() && is_ident_char(chars[j]) {
                j += 1;
            }
            segs.push(chars[s..j].iter().collect::<String>());
            if chars.get(j) == Some(&':')
                && chars.get(j + 1) == Some(&':')
                && chars.get(j + 2).is_some_and(|&c| is_ident_char(c))
            {
                j += 2;
            } else {
                break;
            }
        }
        if segs.len() > 1 {
            out.push(segs);
        }
        i = j.max(i + 1);
    }
    out
}

/// `src/…` paths in `text` (a trailing `.` or `,` is punctuation).
fn src_paths(text: &str) -> Vec<String> {
    text.split(|c: char| c.is_whitespace() || "()`,;".contains(c))
        .filter(|w| w.starts_with("src/"))
        .map(|w| w.trim_end_matches('.').to_string())
        .collect()
}

/// Whether `src` defines `item` (as an item, a field or a variant).
fn defines(src: &str, item: &str) -> bool {
    let kw = ["fn", "const", "static", "struct", "enum", "type", "mod"];
    src.lines().any(|l| {
        let l = l.trim_start().trim_start_matches("pub(crate) ");
        let l = l
            .trim_start_matches("pub(super) ")
            .trim_start_matches("pub ");
        let l = l
            .trim_start_matches("unsafe ")
            .trim_start_matches("const fn ");
        let rest = |after: &str| {
            after
                .strip_prefix(item)
                .is_some_and(|r| !r.starts_with(is_ident_char))
        };
        kw.iter().any(|k| l.strip_prefix(k).and_then(|r| r.strip_prefix(' ')).is_some_and(rest))
            || l.strip_prefix("fn ").is_some_and(rest)
            // A field `item: T` or a variant `Item,` / `Item {` / `Item(`.
            || rest(l) && {
                let r = &l[item.len()..];
                r.starts_with(':') && !r.starts_with("::")
                    || r.starts_with(',')
                    || r.starts_with(" {")
                    || r.starts_with('(')
                    || r.starts_with(" =")
            }
    })
}

#[test]
fn kernel_headers_point_at_what_exists() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    rust_files(&root.join("src"), &mut files);
    let sources: Vec<(PathBuf, String)> = files
        .into_iter()
        .map(|p| {
            let s = fs::read_to_string(&p).unwrap();
            (p, s)
        })
        .collect();
    // The files of module `m`: `m.rs`, `m/mod.rs` and everything under `m/`.
    let of_module = |m: &str| -> Vec<&(PathBuf, String)> {
        sources
            .iter()
            .filter(|(p, _)| {
                p.file_stem().is_some_and(|s| s == m) || p.components().any(|c| c.as_os_str() == m)
            })
            .collect()
    };
    let mut kernels: Vec<PathBuf> = fs::read_dir(root.join("kernels"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "wgsl"))
        .collect();
    kernels.sort();
    assert!(kernels.len() >= 9, "{} kernels", kernels.len());
    let mut wrong = Vec::new();
    for k in &kernels {
        let stem = k.file_stem().unwrap().to_str().unwrap();
        let text = comments(&fs::read_to_string(k).unwrap());
        let mirror = format!("src/stages/{stem}.rs");
        if stem != "common" && !text.contains(&mirror) {
            wrong.push(format!("{stem}.wgsl does not name its mirror {mirror}"));
        }
        for p in src_paths(&text) {
            if !root.join(&p).exists() {
                wrong.push(format!("{stem}.wgsl cites {p}, which does not exist"));
            }
        }
        for path in rust_paths(&text) {
            let (m, item) = (&path[path.len() - 2], &path[path.len() - 1]);
            // Primitive types' methods are the standard library's.
            if ["i32", "u32", "u64", "i64"].contains(&m.as_str()) {
                continue;
            }
            let found = if m.starts_with(char::is_uppercase) {
                sources.iter().any(|(_, s)| {
                    (defines(s, m) || s.contains(&format!("impl {m} "))) && defines(s, item)
                })
            } else {
                of_module(m).iter().any(|(_, s)| defines(s, item))
            };
            if !found {
                wrong.push(format!(
                    "{stem}.wgsl cites {}, which no file of `{m}` defines",
                    path.join("::")
                ));
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// The checker itself: a stale path and a renamed item are caught.
#[test]
fn the_checker_sees_stale_paths_and_items() {
    let text = comments("// mirror of src/synth/stages/correct.rs (`fixed::FRAC_BITS`)\nfn x() {}");
    assert_eq!(src_paths(&text), ["src/synth/stages/correct.rs"]);
    assert_eq!(
        rust_paths(&text),
        [vec!["fixed".to_string(), "FRAC_BITS".to_string()]]
    );
    assert!(defines("pub const FRAC_BITS: u32 = 8;", "FRAC_BITS"));
    assert!(!defines("pub const FRAC_BITS_X: u32 = 8;", "FRAC_BITS"));
    assert!(defines("    pub prior: u32,", "prior"));
    assert!(!defines("    let x = prior::y;", "prior"));
}
