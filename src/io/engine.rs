//! Heightmaps ready for game engines, with the numbers to type into their
//! import dialogs.
//!
//! **Unity** (Manual, "Working with Heightmaps", Terrain Settings → Import
//! Raw): a headerless 16-bit RAW, square, of 2ⁿ + 1 samples per side (33 …
//! 4097, the Heightmap Resolution choices); Byte Order *Windows* = little
//! endian; Unity puts the file's first row at the terrain's z = 0 (its
//! south edge), so a north-up image arrives mirrored unless *Flip
//! Vertically* is ticked. We write the rows south to north, so *Flip
//! Vertically* stays **off**; the whole 0 … 65535 range maps onto the
//! terrain's Height, so Terrain Size Y = the relief and the terrain's
//! position Y = the lowest point.
//!
//! **Unreal** (Landscape Technical Guide, "Recommended Landscape Sizes" and
//! "Calculating Heightmap Z Scale"): a 16-bit greyscale PNG or little-endian
//! RAW (`.r16`) of a recommended size (127, 253, 505, 1009, 2017, 4033 or
//! 8129 per side for square landscapes), rows as seen from above with
//! north up; a sample v lies at (v − 32768) / 128 × Z scale centimetres
//! above the Landscape's location, so Z scale 100 spans −256 … +256 m.
//! Our mapping puts the lowest point at 0 and the highest at 65535, hence
//! Z scale = relief (m) × 100 × 128 / 65535 and location Z = height of
//! v = 32768; X/Y scale = the cell size in centimetres.
//!
//! In both, a grid of another size is resampled (tent filter, as
//! [`crate::resample`]) to the smallest allowed size that holds it (or the
//! largest allowed), keeping its ground extent: the printed Terrain Size /
//! scale already accounts for the new spacing, so nothing is stretched.

use super::FormatError;
use crate::heightfield::Heightfield;

/// An engine preset.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Engine {
    Unity,
    Unreal,
}

/// Unity's Heightmap Resolution choices (2ⁿ + 1).
pub const UNITY_SIZES: [usize; 8] = [33, 65, 129, 257, 513, 1025, 2049, 4097];
/// Unreal's recommended square landscape sizes (one component per section
/// up to 2×2 sections of 255 quads), from the Landscape Technical Guide.
pub const UNREAL_SIZES: [usize; 7] = [127, 253, 505, 1009, 2017, 4033, 8129];

/// A heightmap laid out for an engine, and how to import it.
#[derive(Debug, Clone)]
pub struct Prepared {
    /// Resampled to the engine's size (rows north to south, as always).
    pub heightfield: Heightfield,
    /// Whether the file's rows must run south to north
    /// ([`super::WriteOptions::south_up`]).
    pub south_up: bool,
    /// The import settings, one `setting: value` per line.
    pub settings: Vec<String>,
    /// Notices (resampling).
    pub notes: Vec<String>,
}

impl Engine {
    pub fn name(self) -> &'static str {
        match self {
            Engine::Unity => "unity",
            Engine::Unreal => "unreal",
        }
    }

    pub fn sizes(self) -> &'static [usize] {
        match self {
            Engine::Unity => &UNITY_SIZES,
            Engine::Unreal => &UNREAL_SIZES,
        }
    }

    /// The smallest allowed side that holds `n` samples, else the largest.
    pub fn side_for(self, n: usize) -> usize {
        let s = self.sizes();
        s.iter()
            .copied()
            .find(|&v| v >= n)
            .unwrap_or(s[s.len() - 1])
    }

    /// Whether `ext` (lower case, no dot) is a file type the engine imports.
    pub fn accepts(self, ext: &str) -> bool {
        match self {
            Engine::Unity => matches!(ext, "raw" | "r16"),
            Engine::Unreal => matches!(ext, "png" | "r16" | "raw"),
        }
    }
}

/// Unreal's Z scale and location Z (cm) for heights `lo … hi` metres mapped
/// onto the codes 0 … 65535: code v lies (v − 32768) / 128 × Z scale cm
/// above the location (module docs).
pub fn unreal_z(lo: f64, hi: f64) -> (f64, f64) {
    let relief = hi - lo;
    let mid = lo + relief * 32768.0 / 65535.0;
    (relief * 100.0 * 128.0 / 65535.0, mid * 100.0)
}

/// Resamples and orders `hf` for `engine` and works out the import settings.
pub fn prepare(hf: &Heightfield, engine: Engine) -> Result<Prepared, FormatError> {
    let stats = hf.stats().ok_or_else(|| {
        FormatError::Unwritable("every sample is nodata: nothing to export".into())
    })?;
    FormatError::check_no_nodata(hf, super::Format::R16)?;
    let (w, h) = (hf.width(), hf.height());
    let side = engine.side_for(w.max(h));
    let mut notes = Vec::new();
    // Ground extent (cell areas): kept, whatever the sample count.
    let (ext_x, ext_z) = (w as f64 * hf.cell_size(), h as f64 * hf.cell_size());
    let out = if (w, h) == (side, side) {
        hf.clone()
    } else {
        notes.push(format!(
            "{} needs a square heightmap of {}: resampled {w}x{h} -> {side}x{side} (tent filter), same ground extent {:.1} x {:.1} m",
            engine.name(),
            engine
                .sizes()
                .iter()
                .map(|s| s.to_string())
                .collect::<Vec<_>>()
                .join(", "),
            ext_x,
            ext_z
        ));
        // Square samples over a non-square extent: the engine's Y/Z size
        // (Unity Terrain Size Z, Unreal Y scale) restores the extent.
        let mut r = crate::resample::resample(hf, side, side)?;
        r.set_cell_size(ext_x / side as f64)?;
        r
    };
    let (min, max) = (stats.min as f64, stats.max as f64);
    let relief = max - min;
    // Engines place samples on vertices: N of them span N − 1 cells.
    let span = (side - 1) as f64 * out.cell_size();
    let settings = match engine {
        Engine::Unity => {
            vec![
                "Terrain Settings > Import Raw".to_string(),
                "Depth: Bit 16".to_string(),
                format!("Resolution: {side}"),
                "Byte Order: Windows".to_string(),
                "Flip Vertically: off (rows are written south to north)".to_string(),
                format!(
                    "Terrain Size: X = {span:.3}, Y = {relief:.3}, Z = {:.3} (metres)",
                    span * ext_z / ext_x
                ),
                format!("Terrain position Y: {min:.3} (the lowest point)"),
            ]
        }
        Engine::Unreal => {
            let (z_scale, location_z) = unreal_z(min, max);
            vec![
                "Landscape > Manage > Import from File".to_string(),
                format!("Heightmap resolution: {side} x {side}"),
                format!(
                    "Scale: X = {:.3}, Y = {:.3}, Z = {z_scale:.4} (Z = relief {relief:.3} m x 100 x 128 / 65535)",
                    out.cell_size() * 100.0,
                    out.cell_size() * 100.0 * ext_z / ext_x
                ),
                format!("Location Z: {location_z:.1} cm (height of sample 32768)"),
            ]
        }
    };
    Ok(Prepared {
        heightfield: out,
        south_up: engine == Engine::Unity,
        settings,
        notes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unity_flips_rows_and_pads_to_2n_plus_1() {
        let hf = Heightfield::from_fn(33, 33, 10.0, |_, y| y as f32).unwrap();
        let p = prepare(&hf, Engine::Unity).unwrap();
        assert!(p.south_up && p.notes.is_empty());
        // Row 0 of the file is the south edge (our last row), and the
        // sidecar says so, so terrasynth reads it back north-up.
        let opts = super::super::WriteOptions {
            south_up: true,
            ..Default::default()
        };
        let enc = super::super::encode(&p.heightfield, super::super::Format::R16, &opts).unwrap();
        assert_eq!(&enc.bytes[..2], &65535u16.to_le_bytes());
        let back = super::super::decode(
            &enc.bytes,
            super::super::Format::R16,
            enc.sidecar.as_deref(),
            &Default::default(),
        )
        .unwrap();
        assert_eq!(back.get(0, 0), 0.0);
        assert_eq!(back.get(0, 32), 32.0);
        assert!(p.settings.iter().any(|s| s == "Resolution: 33"));
        assert!(
            p.settings
                .iter()
                .any(|s| s.contains("X = 320.000, Y = 32.000, Z = 320.000"))
        );
        let big = Heightfield::from_fn(782, 700, 92.68, |x, _| x as f32).unwrap();
        let p = prepare(&big, Engine::Unity).unwrap();
        assert_eq!(p.heightfield.width(), 1025);
        assert!(p.notes[0].contains("782x700 -> 1025x1025"), "{:?}", p.notes);
    }

    #[test]
    fn unreal_z_scale_maps_the_relief_onto_the_16_bit_range() {
        let hf = Heightfield::from_fn(1009, 1009, 1.0, |x, _| 100.0 + x as f32 * 0.5).unwrap();
        let p = prepare(&hf, Engine::Unreal).unwrap();
        // Relief 504 m: Z scale 504 x 12800 / 65535 = 98.44 (100 spans 512 m).
        assert!(
            p.settings
                .iter()
                .any(|s| s.contains("X = 100.000, Y = 100.000, Z = 98.4390")),
            "{:?}",
            p.settings
        );
        assert_eq!(p.heightfield.get(5, 0), hf.get(5, 0), "north stays up");
        assert_eq!(Engine::Unreal.side_for(1010), 2017);
        assert_eq!(Engine::Unreal.side_for(9000), 8129);
    }
}
