//! `terrasynth mesh`'s files read by the reference clients (issue 44):
//! the Khronos glTF-Validator (npm `gltf-validator`, run by node) must
//! report no error and no warning on a regular, an adaptive, an LOD and a
//! tiled mesh; trimesh (PyPI) must load the OBJ with the vertex count and
//! bounds we wrote.
//!
//! The validator is found by node's `require` (set `NODE_PATH` to the
//! `node_modules` it is installed in), trimesh by `TERRASYNTH_PYTHON`
//! (default `python3`). Absent, the tests skip with a message;
//! `TERRASYNTH_REQUIRE_GLTF_VALIDATOR` / `TERRASYNTH_REQUIRE_TRIMESH`
//! (set by `.ci/run`) turn the skip into a failure.

use std::path::Path;
use std::process::Command;
use terrasynth::Heightfield;

use crate::common::{run_ok, terrasynth};

/// Validates each file given, printing one JSON line per file with the
/// validator's counts and its messages.
const VALIDATE_JS: &str = r#"
const v = require('gltf-validator'); const fs = require('fs'); const path = require('path');
(async () => {
  for (const f of process.argv.slice(1)) {
    const dir = path.dirname(f);
    const opts = { uri: f, externalResourceFunction: (u) =>
      new Promise((ok, no) => fs.readFile(path.join(dir, decodeURIComponent(u)), (e, d) => e ? no(e) : ok(new Uint8Array(d)))) };
    const r = f.endsWith('.glb') ? await v.validateBytes(new Uint8Array(fs.readFileSync(f)), opts)
                                 : await v.validateString(fs.readFileSync(f, 'utf8'), opts);
    console.log(JSON.stringify({ file: path.basename(f), version: v.version(), ...r.issues }));
  }
})().catch((e) => { console.error(e); process.exit(1); });
"#;

/// Whether `program args` (a probe of a client) succeeds; panics when it
/// does not under the `require` variable.
fn available(program: &str, args: &[&str], require: &str, what: &str) -> bool {
    let ok = Command::new(program)
        .args(args)
        .output()
        .is_ok_and(|o| o.status.success());
    if !ok {
        assert!(
            std::env::var_os(require).is_none_or(|v| v.is_empty()),
            "{require} is set but {what} cannot run"
        );
        eprintln!("{what} not found: skipped ({require} makes this a failure)");
    }
    ok
}

/// A 16-bit PNG heightfield (with sidecar) of 65 × 49 samples of 30 m.
fn input(dir: &Path) -> (String, Heightfield) {
    let hf = Heightfield::from_fn(65, 49, 30.0, |x, y| {
        let (x, y) = (x as f32, y as f32);
        300.0 + 80.0 * (x * 0.17).sin() * (y * 0.11).cos() + 2.0 * y
    })
    .unwrap();
    let p = dir.join("in.png");
    terrasynth::io::write(&hf, &p, &Default::default()).unwrap();
    let hf = terrasynth::io::read(&p, &Default::default()).unwrap();
    (p.to_string_lossy().into_owned(), hf)
}

#[test]
fn gltf_validator_finds_no_error_or_warning() {
    if !available(
        "node",
        &["-e", "require('gltf-validator')"],
        "TERRASYNTH_REQUIRE_GLTF_VALIDATOR",
        "node with gltf-validator (npm install gltf-validator; NODE_PATH=…/node_modules)",
    ) {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (inp, _) = input(dir.path());
    let cases: [(&str, &[&str]); 4] = [
        ("regular.glb", &["--normals", "--uv"]),
        ("adaptive.gltf", &["--max-error", "1", "--normals"]),
        ("lod.glb", &["--max-error", "0.5", "--lods", "4", "--uv"]),
        (
            "tiled.gltf",
            &[
                "--max-error",
                "1",
                "--tile",
                "16",
                "--skirt",
                "10",
                "--lods",
                "2",
                "--normals",
                "--uv",
            ],
        ),
    ];
    let mut files = vec![];
    for (name, args) in cases {
        let out = dir.path().join(name).to_string_lossy().into_owned();
        let mut a = vec!["mesh", &inp, "-o", &out];
        a.extend_from_slice(args);
        terrasynth(&a);
        files.push(out);
    }
    let out = Command::new("node")
        .arg("-e")
        .arg(VALIDATE_JS)
        .args(&files)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let reports: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(reports.len(), 4, "{text}");
    for r in &reports {
        eprintln!(
            "glTF-Validator {}: {}: {} errors, {} warnings, {} infos, {} hints",
            r["version"], r["file"], r["numErrors"], r["numWarnings"], r["numInfos"], r["numHints"]
        );
        assert_eq!(
            (r["numErrors"].as_u64(), r["numWarnings"].as_u64()),
            (Some(0), Some(0)),
            "{r}"
        );
    }
}

#[test]
fn trimesh_loads_the_obj_with_our_vertices_and_bounds() {
    let python = std::env::var("TERRASYNTH_PYTHON").unwrap_or_else(|_| "python3".into());
    if !available(
        &python,
        &["-c", "import trimesh"],
        "TERRASYNTH_REQUIRE_TRIMESH",
        "python with trimesh (pip install trimesh; TERRASYNTH_PYTHON=…/python)",
    ) {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (inp, hf) = input(dir.path());
    let obj = dir.path().join("t.obj").to_string_lossy().into_owned();
    terrasynth(&["mesh", &inp, "-o", &obj, "--normals", "--uv"]);
    let script = "import sys, json, trimesh\n\
        m = trimesh.load(sys.argv[1], force='mesh', process=False)\n\
        print(json.dumps({'vertices': len(m.vertices), 'faces': len(m.faces), 'bounds': m.bounds.tolist()}))";
    let out = run_ok(Command::new(&python).args(["-c", script, &obj]));
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    eprintln!("trimesh: {r}");
    let s = hf.stats().unwrap();
    assert_eq!(r["vertices"], 65 * 49);
    assert_eq!(r["faces"], 2 * 64 * 48);
    let want = [[0.0, s.min, 0.0], [64.0 * 30.0, s.max, 48.0 * 30.0]];
    // trimesh reads the text as f64; as f32 it is what we wrote.
    let got: [[f64; 3]; 2] = serde_json::from_value(r["bounds"].clone()).unwrap();
    assert_eq!(got.map(|p| p.map(|v| v as f32)), want);
}

#[test]
fn the_cli_names_the_file_it_refuses() {
    let dir = tempfile::tempdir().unwrap();
    let mut hf = Heightfield::new(8, 8, 10.0).unwrap();
    hf.set(2, 5, f32::NAN);
    let p = dir.path().join("holes.exr");
    terrasynth::io::write(&hf, &p, &Default::default()).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_terrasynth"))
        .args(["mesh", p.to_str().unwrap(), "-o"])
        .arg(dir.path().join("m.glb"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("holes.exr") && err.contains("nodata"),
        "{err}"
    );
    assert!(!dir.path().join("m.glb").exists());
}
