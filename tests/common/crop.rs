//! The real crop the realism and novelty tests share, and its database.

use super::dem;
use std::sync::OnceLock;
use terrasynth::database::{self, BuildOptions, Database, ExemplarInput};
use terrasynth::progress::Silent;

/// The crop the ratio tests use: rugged enough that smoothing and noise
/// both show.
/// Wider than 256 px, so that an 8-bit coordinates map could not be exact.
pub const CROP: (&str, (usize, usize, usize, usize)) = ("pyrenees_andorra", (100, 100, 288, 272));

/// The crop and its single-exemplar database; None (with a message) when
/// the shared DEMs are absent.
pub fn crop_db() -> Option<&'static (ExemplarInput, Database)> {
    static DB: OnceLock<Option<(ExemplarInput, Database)>> = OnceLock::new();
    DB.get_or_init(|| {
        let ex = dem::exemplar(CROP.0, CROP.1, true)?;
        let (db, _) = database::build(vec![ex.clone()], &BuildOptions::default(), &Silent).unwrap();
        Some((ex, db))
    })
    .as_ref()
}
