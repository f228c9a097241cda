//! Replays the `georef` fuzz target's seeds (fuzz/corpus/georef: an SRTM
//! tile name, then a `.prj`), every prefix of each and single-bit flips,
//! exactly as the target runs them: a CRS or a typed error, never a panic.

use terrasynth::io::{Companions, Format, ReadOptions, ground, load_bytes, wkt};

const GRID: &[u8] =
    b"ncols 3\nnrows 2\nxllcorner 1\nyllcorner 41\ndx 0.001\ndy 0.0008\n1 2 3\n4 5 6\n";

fn run(data: &[u8]) -> Option<terrasynth::Heightfield> {
    let split = data.iter().position(|&b| b == b'\n').unwrap_or(data.len());
    let name = String::from_utf8_lossy(&data[..split]);
    let _ = ground::hgt_georef(&name, 1201);
    let prj = data.get(split + 1..).unwrap_or_default();
    let _ = wkt::parse(prj);
    let companions = Companions {
        prj: Some(prj),
        ..Default::default()
    };
    load_bytes(GRID, Format::Asc, &companions, &ReadOptions::default())
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
