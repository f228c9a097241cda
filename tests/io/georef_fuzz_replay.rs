//! Replays the `georef` fuzz target's seeds (fuzz/corpus/georef: an SRTM
//! tile name, then a `.prj`), every prefix of each and single-bit flips,
//! exactly as the target runs them: a CRS or a typed error, never a panic.

fn run(data: &[u8]) -> Option<terrasynth::Heightfield> {
    terrasynth::io::place::ground::fuzz_georef(data)
        .ok()
        .map(|l| l.heightfield)
}

#[test]
fn georef_seeds_prefixes_and_flips_never_panic() {
    let dir = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/fuzz/corpus/georef"));
    let mut seeds: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| std::fs::read(e.unwrap().path()).unwrap())
        .collect();
    seeds.sort();
    assert!(seeds.len() >= 4, "seeds in {}", dir.display());
    let mut placed = 0;
    for seed in &seeds {
        // A valid .prj places the grid in its CRS; the grid is resampled to square cells.
        if let Some(hf) = run(seed)
            && hf.georef().is_some_and(|g| g.crs.is_some())
        {
            placed += 1;
        }
        for cut in 0..seed.len() {
            run(&seed[..cut]);
        }
        for i in (0..seed.len() * 8).step_by(7) {
            let mut m = seed.clone();
            m[i / 8] ^= 1 << (i % 8);
            run(&m);
        }
    }
    assert!(placed >= 3, "valid seeds must parse: {placed}");
}
