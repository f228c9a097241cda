//! The databases the stage and control tests run on: the embedded default
//! one, and small ones built from two crops of the shared DEMs — one set-up
//! for every test binary instead of a copy in each.

use std::sync::{Mutex, OnceLock};
use terrasynth::Heightfield;
use terrasynth::database::{self, BuildOptions, Database, default};
use terrasynth::io::{self, Format};
use terrasynth::procedural::Style;
use terrasynth::procedural::styles::{DEFAULT_SEED, DEFAULT_SIZE};
use terrasynth::progress::Silent;

use super::dem::{self, DEM};

/// A 320² crop of the Pyrenees DEM (alpine relief, 92.6 m cells) with its
/// type mask, 5 levels, and its lowest and highest heights (m); `None` when
/// the shared DEMs are absent. The scene, session and sculpt tests' terrain.
pub fn pyrenees_crop() -> Option<&'static (Database, f64, f64)> {
    static DB: OnceLock<Option<(Database, f64, f64)>> = OnceLock::new();
    DB.get_or_init(|| {
        let input = dem::exemplar("pyrenees_andorra", (300, 250, 320, 320), true)?;
        let s = input.heights.stats().unwrap();
        let opts = BuildOptions {
            levels: 5,
            ..Default::default()
        };
        let (db, _) = database::build(vec![input], &opts, &Silent).unwrap();
        Some((db, s.min as f64, s.max as f64))
    })
    .as_ref()
}

/// The embedded default database, built once per test binary.
pub fn default_db() -> &'static Database {
    static DB: OnceLock<Database> = OnceLock::new();
    DB.get_or_init(|| default::build_default(&Silent).unwrap())
}

/// A coast: the top-left 256² of the procedural hills (`generate --style
/// hills` at its defaults, pinned by `tests/inputs/procedural.rs`) flooded to its
/// 30th height percentile, so that 30 % of it is one flat sea (the
/// `correct` stage's flat-candidate prior acts there), and that sea level
/// in metres. Flooded valleys, not a real coast: a real coast's open sea is
/// one body whose texels see only sea and stay flat with or without the
/// prior (on the embedded Catalan coast the sea share was 19 % with it and
/// 14 % without), where the narrow flooded valleys meet land everywhere.
pub fn coast_db() -> &'static (Database, f32) {
    static DB: OnceLock<(Database, f32)> = OnceLock::new();
    DB.get_or_init(|| {
        let mut heights = hills().crop(0, 0, 256, 256).unwrap();
        let mut sorted = heights.data().to_vec();
        sorted.sort_by(f32::total_cmp);
        let sea = sorted[sorted.len() * 3 / 10];
        for v in heights.data_mut() {
            *v = v.max(sea);
        }
        let input = database::ExemplarInput {
            name: "coast".into(),
            heights,
            types: None,
        };
        let (db, _) = database::build(vec![input], &BuildOptions::default(), &Silent).unwrap();
        (db, sea)
    })
}

/// The procedural hills (`generate --style hills` at its defaults, pinned
/// by `tests/inputs/procedural.rs`) as `generate` writes them: 16-bit PNG heights.
fn hills() -> &'static Heightfield {
    static HILLS: OnceLock<Heightfield> = OnceLock::new();
    HILLS.get_or_init(|| {
        let (hills, _) = Style::Hills
            .generate(DEFAULT_SIZE, DEFAULT_SEED, &Silent)
            .unwrap();
        let png = io::encode(&hills, Format::Png16, &Default::default()).unwrap();
        io::decode(
            &png.bytes,
            Format::Png16,
            png.sidecar.as_deref(),
            &Default::default(),
        )
        .unwrap()
    })
}

/// The `(x, y, width, height)` crops of the procedural hills in
/// [`unequal_db`]: interiors in the ratio of about 5 : 2 : 1 at level 2,
/// so that an exemplar's share of uniform draws (⅓ each) is far from its
/// share of the area.
pub const UNEQUAL_CROPS: [(usize, usize, usize, usize); 3] =
    [(0, 0, 256, 256), (256, 0, 192, 128), (256, 256, 96, 160)];

/// Three crops of the procedural hills of unequal sizes ([`UNEQUAL_CROPS`]),
/// untyped, four levels: for what must follow each exemplar's area.
pub fn unequal_db() -> &'static Database {
    static DB: OnceLock<Database> = OnceLock::new();
    DB.get_or_init(|| {
        let inputs = UNEQUAL_CROPS
            .iter()
            .enumerate()
            .map(|(k, &(x, y, w, h))| database::ExemplarInput {
                name: format!("hills{k}"),
                heights: hills().crop(x, y, w, h).unwrap(),
                types: None,
            })
            .collect();
        let opts = BuildOptions {
            levels: 4,
            ..Default::default()
        };
        database::build(inputs, &opts, &Silent).unwrap().0
    })
}

/// Two `side²` crops of shared DEMs, `(name, x, y)` at their top-left
/// corners, with their type masks when `typed` (so the database has types
/// and seeds); four levels, like every small test database.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TwoDems {
    pub crops: [(&'static str, usize, usize); 2],
    pub side: usize,
    pub typed: bool,
}

/// 192² crops of the Pyrenees and the Franconian Jura, untyped: the real
/// states of the stage cross-checks.
pub const PYRENEES_JURA: TwoDems = TwoDems {
    crops: [
        ("pyrenees_andorra", 300, 200),
        ("franconian_jura", 200, 300),
    ],
    side: 192,
    typed: false,
};

/// 160² crops of the Riviera coast and the Pyrenees with their types: the
/// real guides of the guided `correct` checks.
pub const RIVIERA_PYRENEES: TwoDems = TwoDems {
    crops: [("riviera_coast", 100, 150), ("pyrenees_andorra", 300, 200)],
    side: 160,
    typed: true,
};

/// 256² crops of the Pyrenees and the Catalan coast hills with their
/// types: the user-control tests.
pub const PYRENEES_CATALAN: TwoDems = TwoDems {
    crops: [
        ("pyrenees_andorra", 300, 200),
        ("catalan_coast_hills", 300, 300),
    ],
    side: 256,
    typed: true,
};

/// The syntheses whose real level states every level stage is checked on:
/// `(database, size, seed)` — 256×192 of the default database (seed 3),
/// 160² of the flooded [`coast_db`] (seed 2) and, where ../shared/dem is present (else saying that `what` is
/// skipped), 200×256 of [`PYRENEES_JURA`] (seed 11).
pub fn real_syntheses(what: &str) -> Vec<(&'static Database, (usize, usize), u32)> {
    let mut out = vec![
        (default_db(), (256, 192), 3),
        (&coast_db().0, (160, 160), 2),
    ];
    out.extend(two_dems(PYRENEES_JURA, what).map(|db| (db, (200, 256), 11)));
    out
}

/// The database of `spec`, built once per test binary, or `None` (saying
/// that `what` is skipped) when ../shared/dem is absent.
pub fn two_dems(spec: TwoDems, what: &str) -> Option<&'static Database> {
    static BUILT: Mutex<Vec<(TwoDems, Option<&'static Database>)>> = Mutex::new(Vec::new());
    let mut built = BUILT.lock().unwrap_or_else(|e| e.into_inner());
    let db = match built.iter().find(|(s, _)| *s == spec) {
        Some(&(_, db)) => db,
        None => {
            // Leaked: the tests borrow it for the whole run, as from a static.
            let db = build(spec).map(|db| &*Box::leak(Box::new(db)));
            built.push((spec, db));
            db
        }
    };
    if db.is_none() {
        eprintln!("{DEM} not found: {what} skipped");
    }
    db
}

fn build(spec: TwoDems) -> Option<Database> {
    let mut inputs = Vec::new();
    for (name, x, y) in spec.crops {
        inputs.push(dem::exemplar(
            name,
            (x, y, spec.side, spec.side),
            spec.typed,
        )?);
    }
    let opts = BuildOptions {
        levels: 4,
        ..Default::default()
    };
    Some(database::build(inputs, &opts, &Silent).unwrap().0)
}

/// Relief (max − min) of a database's first exemplar, metres: the scale of
/// the control tests' tolerances.
pub fn start_relief(db: &Database) -> f64 {
    let e = &db.meta().exemplars[0];
    e.max_m - e.min_m
}
