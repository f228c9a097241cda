//! Crops of the real DEMs in ../shared/dem (never copied into the
//! repository): the exemplars of the tests that build small databases.
//! Every test that reads that folder goes through [`dir`], so that one
//! switch, [`REQUIRE_DEM`], turns every "absent, skipped" into a failure.

use std::path::Path;
use terrasynth::database::ExemplarInput;
use terrasynth::io::TypeMask;

/// Where the shared DEMs are.
pub const DEM: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/dem");

/// Set (non-empty) where the shared DEMs are known to be present — `.ci/run`
/// checks the folder first — so that no test there can pass by skipping.
pub const REQUIRE_DEM: &str = "TERRASYNTH_REQUIRE_DEM";

/// The shared DEMs' folder; `None`, saying that `what` is skipped, when it
/// is absent. Panics when it is absent under [`REQUIRE_DEM`].
pub fn dir(what: &str) -> Option<&'static Path> {
    let dir = Path::new(DEM);
    if dir.is_dir() {
        return Some(dir);
    }
    assert!(
        std::env::var_os(REQUIRE_DEM).is_none_or(|v| v.is_empty()),
        "{REQUIRE_DEM} is set but {DEM} is absent: {what} cannot run"
    );
    eprintln!("{DEM} not found: {what} skipped");
    None
}

/// The `w × h` window at (x, y) of DEM `name`, with the same window of its
/// type mask when `typed`; `None` when the shared DEMs are absent (a file
/// missing from a present folder is a failure, not a skip).
pub fn exemplar(
    name: &str,
    (x, y, w, h): (usize, usize, usize, usize),
    typed: bool,
) -> Option<ExemplarInput> {
    let dir = dir(&format!("the tests on a crop of {name}"))?;
    let hf = terrasynth::io::read(&dir.join(format!("{name}.png")), &Default::default())
        .unwrap_or_else(|e| panic!("{name}.png in {DEM}: {e}"));
    let types = typed.then(|| {
        let m = TypeMask::read(&dir.join(format!("{name}_types.png")))
            .unwrap_or_else(|e| panic!("{name}_types.png in {DEM}: {e}"));
        m.crop(x, y, w, h).expect("window inside the type mask")
    });
    Some(ExemplarInput {
        name: name.into(),
        heights: hf.crop(x, y, w, h).expect("window inside the DEM"),
        types,
    })
}

/// The heights of DEM `name`, whole; `None`, saying that `what` is
/// skipped, when the shared DEMs are absent.
pub fn heights(name: &str, what: &str) -> Option<terrasynth::Heightfield> {
    let dir = dir(what)?;
    let hf = terrasynth::io::read(&dir.join(format!("{name}.png")), &Default::default())
        .unwrap_or_else(|e| panic!("{name}.png in {DEM}: {e}"));
    Some(hf)
}

/// The stem of every shared DEM with a type mask (`<stem>.png` beside
/// `<stem>_types.png` in [`DEM`]), sorted; `None`, saying that `what` is
/// skipped, when the folder is absent.
pub fn typed_stems(what: &str) -> Option<Vec<String>> {
    let entries = std::fs::read_dir(dir(what)?).unwrap();
    let mut stems: Vec<String> = entries
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter_map(|n| n.strip_suffix("_types.png").map(str::to_owned))
        .collect();
    stems.sort();
    Some(stems)
}
