//! Replays every fuzz seed, every crash the fuzzers ever found
//! (tests/regressions/<target>/) and every malformed file through the
//! readers: each must return a heightfield or a typed error, never panic.

#[path = "../common/replay.rs"]
mod replay;

#[test]
fn every_corpus_and_regression_input_decodes_or_fails_cleanly() {
    let cases = replay::cases();
    assert!(
        cases.len() >= 60,
        "corpus, regressions and malformed files: {}",
        cases.len()
    );
    let mut per_target = std::collections::BTreeMap::new();
    for (path, format) in &cases {
        let data = std::fs::read(path).unwrap();
        let outcome =
            std::panic::catch_unwind(|| replay::run_target(*format, &data).map(|r| r.map(|_| ())));
        match outcome {
            Ok(Some(Err(e))) => assert!(!e.to_string().is_empty(), "{}", path.display()),
            Ok(_) => {}
            Err(_) => panic!("{} panicked the {format:?} reader", path.display()),
        }
        *per_target
            .entry(format.map_or("sidecar", |f| f.name()))
            .or_insert(0) += 1;
    }
    // Every target has seeds.
    for (target, format) in replay::TARGETS {
        let key = format.map_or("sidecar", |f| f.name());
        assert!(
            per_target.get(key).copied().unwrap_or(0) > 0,
            "no inputs for {target}"
        );
    }
}

/// The seeds that are valid files decode: the corpus exercises the readers
/// past their header checks.
#[test]
fn valid_seeds_decode() {
    for (target, format) in replay::TARGETS {
        let ok = replay::cases()
            .iter()
            .filter(|(p, f)| *f == format && p.starts_with(replay::root().join("fuzz/corpus")))
            .filter(|(p, f)| {
                matches!(
                    replay::run_target(*f, &std::fs::read(p).unwrap()),
                    Some(Ok(_))
                )
            })
            .count();
        // hgt seeds are small (a valid tile is 2.8 MB); the others include valid files.
        assert!(target == "hgt" || ok > 0, "no valid seed for {target}");
    }
}
