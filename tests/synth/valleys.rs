//! `synth --valleys` (issue 46): the terrain synthesized again with its
//! own valley network as curve constraints drains better than without it,
//! the same bytes every run, and whole maps only.

use crate::common;
use terrasynth::eval::drainage::closed_share;

fn synth(dir: &std::path::Path, name: &str, extra: &[&str]) -> terrasynth::Heightfield {
    let out = dir.join(name);
    let mut args = vec!["synth", "--size", "384x384", "--seed", "11", "-o"];
    args.push(out.to_str().unwrap());
    args.extend(extra);
    common::run_ok(std::process::Command::new(env!("CARGO_BIN_EXE_terrasynth")).args(&args));
    terrasynth::io::read(&out, &Default::default()).unwrap()
}

#[test]
fn valleys_drain_closed_basins_deterministically() {
    let dir = tempfile::tempdir().unwrap();
    let plain = synth(dir.path(), "plain.tif", &[]);
    let a = synth(dir.path(), "a.tif", &["--valleys"]);
    let b = synth(dir.path(), "b.tif", &["--valleys"]);
    assert_eq!(a.data(), b.data(), "--valleys twice: different bytes");
    // The embedded database, seed 11: 3.1 % of the area closed without the
    // network, 1.7 % with it.
    let (before, after) = (closed_share(&plain), closed_share(&a));
    assert!(after < 0.7 * before, "closed share {before} -> {after}");
    // The network changes the terrain where it runs, not everywhere.
    let changed = (plain.data().iter().zip(a.data()))
        .filter(|(p, q)| (*p - *q).abs() > 1.0)
        .count() as f64
        / plain.len() as f64;
    assert!((0.02..0.8).contains(&changed), "{changed}");
}

#[test]
fn valleys_refuse_a_window() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_terrasynth"))
        .args([
            "synth",
            "--valleys",
            "--window",
            "0,0,64,64",
            "-o",
            "/dev/null/x.tif",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--valleys") && err.contains("--window"),
        "{err}"
    );
}
