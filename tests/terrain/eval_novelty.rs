//! Novelty (`terrasynth::eval::novelty`, issue 46) on real terrain, and
//! the `eval` command end to end through the binary (`synth --coords` →
//! `eval`, the protocol on a one-DEM folder).

use crate::common::crop::crop_db;
use crate::common::dem;
use terrasynth::database::{self, BuildOptions};
use terrasynth::eval::{self, novelty};
use terrasynth::io::CoordsMap;
use terrasynth::progress::Silent;
use terrasynth::synth::{Params, Synthesizer};

/// Novelty on real terrain (issue 46): a jitter-free synthesis is a copy of
/// its exemplar (a toroidal shift of it: only the windows across the wrap
/// are not), while one half of a DEM against the other scores like the
/// DEM's own top and bottom halves — real terrain is not a copy of itself.
#[test]
fn novelty_sees_copies_and_not_real_terrain() {
    let Some(ex) = dem::exemplar("pyrenees_andorra", (0, 0, 888, 888), false) else {
        return;
    };
    let p = novelty::Params::default();
    let hf = ex.heights.clone();
    let (db, _) = database::build(vec![ex], &BuildOptions::default(), &Silent).unwrap();
    let copy = Synthesizer::new(
        &db,
        Params {
            jitter: 0.0,
            ..Params::default()
        },
    )
    .unwrap()
    .synthesize(888, 888, 11)
    .unwrap();
    let c = novelty::copies(&copy, &[&hf], &p).unwrap();
    let (west, east) = (
        hf.crop(0, 0, 444, 888).unwrap(),
        hf.crop(444, 0, 444, 888).unwrap(),
    );
    let other = novelty::copies(&east, &[&west], &p).unwrap();
    let base = novelty::halves(&hf, &p).unwrap();
    eprintln!(
        "copy share: jitter-free {:.2}, east half against west {:.2}, top against bottom {:.2}",
        c.share, other.share, base.share
    );
    // Measured: 0.88, 0.00 and 0.00.
    assert!(c.share >= 0.8, "a shifted copy: {}", c.share);
    assert!(
        other.share <= base.share + 0.1,
        "real terrain against its neighbour: {} (halves {})",
        other.share,
        base.share
    );
    assert!(other.median_ncc < 0.9 && c.median_ncc > 0.99);
}

fn cli(args: &[&std::ffi::OsStr]) -> std::process::Output {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_terrasynth"))
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "terrasynth {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// `synth --coords` → `eval --coords --db --json --plot`, `eval --help`,
/// and the protocol on a one-DEM folder, end to end through the binary.
#[test]
fn cli_synth_coords_eval_and_suite() {
    let Some((ex, db)) = crop_db() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let p = |n: &str| tmp.path().join(n).into_os_string();
    let reference = tmp.path().join("dem.png");
    terrasynth::io::write(&ex.heights, &reference, &Default::default()).unwrap();
    db.save(std::path::Path::new(&p("db.tsdb"))).unwrap();
    cli(&[
        "synth".as_ref(),
        "--db".as_ref(),
        &p("db.tsdb"),
        "--size".as_ref(),
        "160x128".as_ref(),
        "-o".as_ref(),
        &p("out.png"),
        "--coords".as_ref(),
        &p("c.png"),
        "--coords-preview".as_ref(),
        &p("cp.png"),
    ]);
    let map = CoordsMap::read(std::path::Path::new(&p("c.png"))).unwrap();
    assert_eq!((map.width, map.height), (160, 128));
    let out = cli(&[
        "eval".as_ref(),
        &p("out.png"),
        reference.as_os_str(),
        "--json".as_ref(),
        "--plot".as_ref(),
        &p("plot.png"),
        "--coords".as_ref(),
        &p("c.png"),
        "--db".as_ref(),
        &p("db.tsdb"),
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["ratio"].as_f64().unwrap() > 0.0);
    assert_eq!(
        v["descriptors"].as_array().unwrap().len(),
        eval::DESCRIPTORS.len()
    );
    let used: f64 = v["type_usage"]["types"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["used"].as_f64().unwrap())
        .sum();
    assert!((used - 1.0).abs() < 1e-9, "shares sum to 1: {used}");
    let plot = image::open(tmp.path().join("plot.png")).unwrap();
    assert_eq!((plot.width(), plot.height()), (1440, 520));
    // Novelty against the database's exemplar (the crop): the synthesis's
    // windows against it, the crop's halves, the synthesis against itself.
    let n = &v["novelty"];
    for k in ["copies", "repetition"] {
        let share = n[k]["share"].as_f64().unwrap();
        assert!((0.0..=1.0).contains(&share), "{k}: {share}");
        assert_eq!(
            n[k]["scored"].as_u64().unwrap() + n[k]["flat"].as_u64().unwrap(),
            4,
            "{k}: 2 x 2 windows"
        );
    }
    assert_eq!(n["baselines"].as_array().unwrap().len(), 1);
    // The crop against itself is all copies; novelty alone needs no
    // reference; the copy map is drawn.
    let out = cli(&[
        "eval".as_ref(),
        reference.as_os_str(),
        "--exemplars".as_ref(),
        reference.as_os_str(),
        "--json".as_ref(),
        "--copy-map".as_ref(),
        &p("copies.png"),
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v.get("ratio").is_none(), "no reference, no realism");
    assert_eq!(v["novelty"]["copies"]["share"].as_f64(), Some(1.0));
    let map = image::open(tmp.path().join("copies.png")).unwrap();
    assert!(
        map.width() >= 288 && map.height() > 272,
        "the preview under a caption"
    );
    let help = cli(&["eval".as_ref(), "--help".as_ref()]);
    // clap wraps long lines: compare with whitespace collapsed.
    let words = |s: &str| s.split_whitespace().collect::<Vec<_>>().join(" ");
    let help = words(&String::from_utf8_lossy(&help.stdout));
    for d in &eval::DESCRIPTORS {
        assert!(help.contains(&words(d.doc)), "--help documents {}", d.id);
    }
    // The protocol on a folder holding the crop and its type mask.
    let suite = tmp.path().join("suite");
    std::fs::create_dir(&suite).unwrap();
    terrasynth::io::write(&ex.heights, &suite.join("crop.png"), &Default::default()).unwrap();
    let types = ex.types.as_ref().unwrap();
    types
        .write(&suite.join("crop_types.png"), "crop.png", "test")
        .unwrap();
    let out = cli(&[
        "eval".as_ref(),
        "--suite".as_ref(),
        suite.as_os_str(),
        "--seeds".as_ref(),
        "1,2".as_ref(),
        "--typed-size".as_ref(),
        "96x96".as_ref(),
        "--cache-dir".as_ref(),
        &p("cache"),
        "--out-dir".as_ref(),
        &p("outs"),
        "--json".as_ref(),
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let dem = &v["dems"][0];
    assert_eq!(dem["name"], "crop");
    assert_eq!(dem["seeds"].as_array().unwrap().len(), 2);
    assert!(dem["median"]["ratio"].as_f64().unwrap() > 0.0);
    assert!(dem["baseline"].as_f64().unwrap() > 0.0);
    // Passes per level, finest first, down to the start level; `--passes`
    // (2) at least on every one.
    let passes = dem["level_passes"].as_array().unwrap();
    assert!(passes.len() >= 2, "{passes:?}");
    assert!(
        passes.iter().all(|p| p.as_u64().unwrap() >= 2),
        "{passes:?}"
    );
    assert!(dem["copy_baseline"].as_f64().is_some());
    assert!(dem["median"]["copy_share"].as_f64().is_some());
    assert!(dem["targets"]["copies"].as_bool().is_some());
    assert_eq!(
        v["typed"]["median"].as_array().unwrap().len(),
        types.present().len()
    );
    for f in [
        "crop_s1_side.png",
        "crop_s1_plot.png",
        "crop_s1_copies.png",
        "crop_s2.png",
        "typed_s2_coords.png",
        "report.json",
    ] {
        assert!(tmp.path().join("outs").join(f).exists(), "{f} written");
    }
    // A second run finds both databases in the cache.
    let again = std::process::Command::new(env!("CARGO_BIN_EXE_terrasynth"))
        .args([
            "eval".as_ref(),
            "--suite".as_ref(),
            suite.as_os_str(),
            "--seeds".as_ref(),
            "1".as_ref(),
            "--typed-size".as_ref(),
            "96x96".as_ref(),
            "--cache-dir".as_ref(),
            &p("cache"),
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&again.stderr);
    assert_eq!(err.matches("from cache").count(), 2, "{err}");
}
