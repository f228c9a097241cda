//! Crops of the real DEMs in ../shared/dem (never copied into the
//! repository): the exemplars of the tests that build small databases.

use std::path::Path;
use terrasynth::database::{ExemplarInput, TypeMask};

/// Where the shared DEMs are.
pub const DEM: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/dem");

/// The `w × h` window at (x, y) of DEM `name`, with the same window of its
/// type mask when `typed`; `None` when the files are absent.
pub fn exemplar(
    name: &str,
    (x, y, w, h): (usize, usize, usize, usize),
    typed: bool,
) -> Option<ExemplarInput> {
    let dir = Path::new(DEM);
    let hf = terrasynth::io::read(&dir.join(format!("{name}.png")), &Default::default()).ok()?;
    let types = if typed {
        let m = TypeMask::read(&dir.join(format!("{name}_types.png"))).ok()?;
        Some(m.crop(x, y, w, h).expect("window inside the type mask"))
    } else {
        None
    };
    Some(ExemplarInput {
        name: name.into(),
        heights: hf.crop(x, y, w, h).expect("window inside the DEM"),
        types,
    })
}

/// The stem of every shared DEM with a type mask (`<stem>.png` beside
/// `<stem>_types.png` in [`DEM`]), sorted; `None`, saying that `what` is
/// skipped, when the folder is absent.
pub fn typed_stems(what: &str) -> Option<Vec<String>> {
    let Ok(entries) = std::fs::read_dir(DEM) else {
        eprintln!("{DEM} not found: {what} skipped");
        return None;
    };
    let mut stems: Vec<String> = entries
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter_map(|n| n.strip_suffix("_types.png").map(str::to_owned))
        .collect();
    stems.sort();
    Some(stems)
}
