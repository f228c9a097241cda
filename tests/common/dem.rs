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
