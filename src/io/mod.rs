//! Heightfields in and out of the formats terrain people exchange.
//!
//! Two layers:
//! - [`decode`] / [`encode`] work on bytes and return a [`FormatError`]; they
//!   never touch the file system, so the fuzz targets call them directly.
//! - [`read`] / [`write()`] add paths: sidecar lookup, format choice by
//!   extension, and atomic output (temporary file, then rename — a failed
//!   write never leaves a partial file behind). Their [`IoError`] names the file.
//!
//! Every reader checks declared sizes against [`crate::size::check_dims`]
//! and against what the file's length can justify *before* allocating
//! (see `guard/limits.rs`).
//!
//! | format | ext | read | write | samples | nodata | metadata kept | round-trip precision |
//! |---|---|---|---|---|---|---|---|
//! | png16 | .png + .json | yes | yes | u16 | code 0 (sidecar `nodata_value`) | cell size, metre mapping | (max−min)/65535/2 |
//! | png8 | .png + .json | yes | — | u8 | sidecar `nodata_value` | cell size, metre mapping | — |
//! | exr | .exr | yes | yes | f32 (f16 read) | NaN | cell size (`cellSizeMetres`) | exact |
//! | tiff | .tif .tiff | yes | yes | (u)int8/16/32, f32, f64, any band read; f32 written | `GDAL_NODATA`, NaN | cell size, georeference, CRS, scale/offset (read) | exact |
//! | hgt | .hgt | yes | — | i16 BE, 1201² / 3601² | −32768 | georeference from the tile name | — |
//! | asc | .asc + .prj | yes | yes | decimal text | `NODATA_value` (number or nan) | cell size (`dx`/`dy` read), georeference, CRS (.prj) | exact |
//! | r16 | .r16 .raw + .json | yes | yes | u16 LE | refused | size, cell size, metre mapping, georeference | (max−min)/65535/2 |
//! | r32 | .r32 + .json | yes | yes | f32 LE | NaN | size, cell size | exact |
//! | ter | .ter | yes | yes | i16 LE | refused | cell size (f32) | ≈ (max−min+cell)/131070 |
//!
//! After decoding, [`ground::square_cells`] brings georeferenced grids whose
//! true spacings differ (geographic DEMs, ESRI `dx` ≠ `dy`) to square metric
//! cells, so nothing is ever stretched; [`load`] reports what it did.

pub mod engine;
mod error;
mod format;
mod guard;
pub mod maps;
pub mod place;

pub use error::{FormatError, IoError};
pub use format::exr::CELL_SIZE_ATTRIBUTE as EXR_CELL_SIZE_ATTRIBUTE;
pub use format::hgt::ARC_SECOND_M;
pub use format::sidecar::{DEFAULT_CELL_SIZE_M, HeightMapping, Sidecar};
pub use format::tiff::METRES_PER_DEGREE;
pub use guard::atomic::{remove_orphans, write_atomic};
pub use guard::memory::{available_memory, check_memory};
pub use maps::coords_map::CoordsMap;
pub use maps::type_mask::TypeMask;
pub use place::ground::GridReport;

use crate::heightfield::Heightfield;
use format::{asc, exr, hgt, png, raw, ter, tiff};
use place::{ground, wkt};
use std::path::{Path, PathBuf};

/// A heightfield file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Format {
    /// 16-bit greyscale PNG; metres via a JSON sidecar (`<stem>.json`).
    Png16,
    /// 8-bit greyscale PNG (read only); metres via the sidecar or the default mapping.
    Png8,
    /// OpenEXR, one 32-bit float channel (`Y` or the only one); NaN = nodata.
    Exr,
    /// GeoTIFF / TIFF: int16, uint16, float32 read; float32 written.
    Tiff,
    /// SRTM `.hgt` tile, 1201² or 3601² big-endian i16 (read only).
    Hgt,
    /// ESRI ASCII grid.
    Asc,
    /// Headerless little-endian u16 (Unity / Unreal); metres via the sidecar.
    R16,
    /// Headerless little-endian f32 metres.
    R32,
    /// Terragen terrain file.
    Ter,
}

impl Format {
    /// Every format, in the order `--help` lists them.
    pub const ALL: &'static [Format] = &[
        Format::Png16,
        Format::Png8,
        Format::Exr,
        Format::Tiff,
        Format::Hgt,
        Format::Asc,
        Format::R16,
        Format::R32,
        Format::Ter,
    ];

    /// The name used on the command line (`--format`).
    pub fn name(self) -> &'static str {
        match self {
            Format::Png16 => "png16",
            Format::Png8 => "png8",
            Format::Exr => "exr",
            Format::Tiff => "tiff",
            Format::Hgt => "hgt",
            Format::Asc => "asc",
            Format::R16 => "r16",
            Format::R32 => "r32",
            Format::Ter => "ter",
        }
    }

    pub fn from_name(name: &str) -> Option<Format> {
        Self::ALL.iter().copied().find(|f| f.name() == name)
    }

    /// The format a path's extension implies. `.png` means 16-bit on output;
    /// on input the PNG's own bit depth decides between [`Format::Png16`] and
    /// [`Format::Png8`]. `.raw` means R16, the Unity / Unreal convention.
    pub fn from_path(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "png" => Format::Png16,
            "exr" => Format::Exr,
            "tif" | "tiff" => Format::Tiff,
            "hgt" => Format::Hgt,
            "asc" => Format::Asc,
            "r16" | "raw" => Format::R16,
            "r32" => Format::R32,
            "ter" => Format::Ter,
            _ => return None,
        })
    }

    pub fn can_write(self) -> bool {
        !matches!(self, Format::Png8 | Format::Hgt)
    }

    /// Formats whose JSON sidecar (`<stem>.json`) gives metres, size or cell
    /// size: the integer formats, and the headerless raw ones.
    pub fn uses_sidecar(self) -> bool {
        matches!(
            self,
            Format::Png16 | Format::Png8 | Format::R16 | Format::R32
        )
    }

    /// Comma-separated names, for error messages.
    pub fn list() -> String {
        Self::ALL
            .iter()
            .map(|f| f.name())
            .collect::<Vec<_>>()
            .join(", ")
    }
}

impl std::fmt::Display for Format {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// How to read a file. The defaults suit every self-describing format.
#[derive(Debug, Clone, Default)]
pub struct ReadOptions {
    /// Overrides the format implied by the extension.
    pub format: Option<Format>,
    /// Dimensions of headerless raw files (R16/R32) when no sidecar gives them.
    pub size: Option<(usize, usize)>,
    /// The cell size in metres: a georeferenced grid is resampled to it
    /// (see [`ground`]), any other grid's cell size is overridden.
    pub cell_size: Option<f64>,
    /// Band of a multi-band GeoTIFF, 1-based (as GDAL's `-b`).
    pub band: Option<usize>,
}

/// How to write a file.
#[derive(Debug, Clone, Default)]
pub struct WriteOptions {
    /// Overrides the format implied by the extension.
    pub format: Option<Format>,
    /// Height range mapped onto the integer range of quantized formats
    /// (PNG16, R16); by default the data's own min..max, so no precision is wasted.
    pub height_range: Option<(f64, f64)>,
    /// Files the command read (inputs, scene files): no output, sidecar or
    /// `.prj` may replace one of them.
    pub inputs: Vec<PathBuf>,
    /// PNG16 / R16: store rows south to north (Unity's order, see
    /// [`engine`]); the sidecar records it so terrasynth reads them back.
    pub south_up: bool,
}

/// Decodes a heightfield from bytes. `sidecar` is the JSON sidecar's bytes for
/// formats that use one.
pub fn decode(
    bytes: &[u8],
    format: Format,
    sidecar: Option<&[u8]>,
    opts: &ReadOptions,
) -> Result<Heightfield, FormatError> {
    let companions = Companions {
        sidecar,
        ..Default::default()
    };
    load_bytes(bytes, format, &companions, opts).map(|l| l.heightfield)
}

/// The files beside a data file that complete it.
#[derive(Debug, Clone, Copy, Default)]
pub struct Companions<'a> {
    /// The JSON sidecar (`<stem>.json`), for formats that use one.
    pub sidecar: Option<&'a [u8]>,
    /// The ESRI `.prj` (WKT), for formats without a CRS of their own.
    pub prj: Option<&'a [u8]>,
    /// The data file's name (SRTM tiles are placed by it).
    pub file_name: Option<&'a str>,
}

/// A heightfield as read, with what the reader had to decide.
#[derive(Debug, Clone)]
pub struct Loaded {
    pub heightfield: Heightfield,
    /// The cell size is the documented default (nothing in the file gave one).
    pub cell_size_default: bool,
    /// Spacings as read and notices (resampling, dropped placement, the
    /// EXR channel read, a normalised 0..1 range).
    pub grid: GridReport,
}

/// Decodes bytes with their companion files, then brings the grid to
/// square metric cells ([`ground::square_cells`]).
pub fn load_bytes(
    bytes: &[u8],
    format: Format,
    companions: &Companions,
    opts: &ReadOptions,
) -> Result<Loaded, FormatError> {
    let sidecar = companions.sidecar.map(Sidecar::parse).transpose()?;
    let sc = sidecar.as_ref();
    let mut notes = Vec::new();
    let mut hf = match format {
        Format::Png16 | Format::Png8 => png::decode(bytes, sc)?,
        Format::Exr => {
            let (hf, note) = exr::decode(bytes)?;
            notes.extend(note.map(str::to_string));
            hf
        }
        Format::Tiff => tiff::decode(bytes, opts.band)?,
        Format::Hgt => hgt::decode(bytes)?,
        Format::Asc => asc::decode(bytes)?,
        Format::R16 | Format::R32 => raw::decode(format, bytes, sc, opts.size)?,
        Format::Ter => ter::decode(bytes)?,
    };
    if format != Format::Tiff && opts.band.is_some_and(|b| b != 1) {
        return Err(FormatError::Metadata(format!(
            "--band {} needs a multi-band GeoTIFF; {format} files have one band",
            opts.band.unwrap_or(1)
        )));
    }
    if let Some(g) = sc.and_then(|s| s.georef.clone()) {
        hf.set_georef(Some(g));
    }
    if format == Format::Hgt
        && let Some(g) = companions
            .file_name
            .and_then(|n| ground::hgt_georef(n, hf.width()))
    {
        hf.set_georef(Some(g));
    }
    if let Some(prj) = companions.prj {
        let crs = wkt::parse(prj).map_err(FormatError::Prj)?;
        if let Some(g) = hf.georef().cloned()
            && g.crs.is_none()
        {
            hf.set_georef(Some(crate::georef::Georef {
                crs: Some(crs),
                ..g
            }));
        }
    }
    let cell_size_default = opts.cell_size.is_none()
        && hf.georef().is_none()
        && match format {
            Format::Png16 | Format::Png8 | Format::R16 | Format::R32 => {
                sc.is_none_or(|s| s.cell_size_m.is_none())
            }
            Format::Exr => !exr::has_cell_size(bytes),
            Format::Tiff => hf.cell_size() == DEFAULT_CELL_SIZE_M,
            Format::Hgt | Format::Asc | Format::Ter => false,
        };
    notes.extend(normalised_note(&hf));
    let (heightfield, mut grid) = ground::square_cells(hf, opts.cell_size)?;
    grid.notes.splice(0..0, notes);
    Ok(Loaded {
        heightfield,
        cell_size_default,
        grid,
    })
}

/// A notice when every height lies within 0 … 1: heights normalised to that
/// range (Gaea's "Raw" EXR, many image exports) are read as metres — a
/// terrain under a metre high, which no exemplar resembles.
fn normalised_note(hf: &Heightfield) -> Option<String> {
    let s = hf.stats()?;
    (s.min >= 0.0 && s.max <= 1.0 && s.max > s.min).then(|| {
        format!(
            "heights span only {:.3} .. {:.3}: a normalised 0..1 range? They are read as metres (a relief under 1 m); rescale them to metres first (e.g. gdal_translate -scale 0 1 LOW HIGH in out.tif, or a float export in metres)",
            s.min, s.max
        )
    })
}

/// What [`encode`] produces: the file's bytes and, for formats that need one,
/// the sidecar's.
#[derive(Debug, Clone)]
pub struct Encoded {
    pub bytes: Vec<u8>,
    pub sidecar: Option<Vec<u8>>,
}

/// Encodes a heightfield. Formats that cannot represent nodata refuse a
/// heightfield that has any (fill it first, see [`crate::nodata`]).
pub fn encode(
    hf: &Heightfield,
    format: Format,
    opts: &WriteOptions,
) -> Result<Encoded, FormatError> {
    match format {
        Format::Png16 => png::encode16(hf, opts.height_range, opts.south_up),
        Format::Exr => exr::encode(hf),
        Format::Tiff => tiff::encode(hf),
        Format::Asc => asc::encode(hf),
        Format::R16 => raw::encode16(hf, opts.height_range, opts.south_up),
        Format::R32 => raw::encode32(hf),
        Format::Ter => ter::encode(hf),
        Format::Png8 | Format::Hgt => Err(FormatError::Unwritable(format!(
            "{format} is read-only; write png16, exr, tiff, asc, r16, r32 or ter instead"
        ))),
    }
}

/// The sidecar path of a data file: the same stem with `.json`.
pub fn sidecar_path(path: &Path) -> PathBuf {
    path.with_extension("json")
}

/// Resolves the format of an input file: explicit, else by extension, with
/// PNG bit depth sniffed from the header.
fn input_format(path: &Path, bytes: &[u8], opts: &ReadOptions) -> Result<Format, IoError> {
    let format = match opts.format {
        Some(f) => f,
        None => Format::from_path(path).ok_or_else(|| IoError::unknown_format(path))?,
    };
    // For PNG, the file's own bit depth decides between the two readers.
    Ok(match format {
        Format::Png16 | Format::Png8 => png::sniff_depth(bytes).unwrap_or(format),
        other => other,
    })
}

/// Reads a companion file, `None` when it does not exist.
fn companion(path: &Path) -> Result<Option<Vec<u8>>, IoError> {
    match std::fs::read(path) {
        Ok(b) => Ok(Some(b)),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(IoError::os(path, e)),
    }
}

/// The `.prj` path of a data file.
pub fn prj_path(path: &Path) -> PathBuf {
    path.with_extension("prj")
}

/// Reads a heightfield file (and its sidecar when the format uses one).
pub fn read(path: &Path, opts: &ReadOptions) -> Result<Heightfield, IoError> {
    load(path, opts).map(|l| l.heightfield)
}

/// Reads a heightfield file with its companions (sidecar, `.prj`), and says
/// what the reader decided ([`Loaded`]).
pub fn load(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let bytes = std::fs::read(path).map_err(|e| IoError::os(path, e))?;
    let format = input_format(path, &bytes, opts)?;
    let sidecar_bytes = if format.uses_sidecar() {
        companion(&sidecar_path(path))?
    } else {
        None
    };
    let prj = if format == Format::Asc {
        companion(&prj_path(path))?
    } else {
        None
    };
    let name = path.file_name().and_then(|n| n.to_str());
    let companions = Companions {
        sidecar: sidecar_bytes.as_deref(),
        prj: prj.as_deref(),
        file_name: name,
    };
    load_bytes(&bytes, format, &companions, opts).map_err(|kind| {
        // A sidecar or .prj problem is reported against that file.
        let p = match kind {
            FormatError::InvalidSidecar(_) => sidecar_path(path),
            FormatError::Prj(_) => prj_path(path),
            _ => path.to_path_buf(),
        };
        IoError::Format { path: p, kind }
    })
}

/// Writes a heightfield atomically (and its sidecar when the format has one).
pub fn write(hf: &Heightfield, path: &Path, opts: &WriteOptions) -> Result<(), IoError> {
    write_noted(hf, path, opts).map(|_| ())
}

/// [`write()`], returning one-line notices for the user (a CRS that the
/// format cannot carry).
///
/// Every file it would write — the data file, its sidecar, its `.prj` — is
/// first checked against [`WriteOptions::inputs`]: an output that would
/// replace an input is refused before anything is written.
pub fn write_noted(
    hf: &Heightfield,
    path: &Path,
    opts: &WriteOptions,
) -> Result<Vec<String>, IoError> {
    let format = match opts.format {
        Some(f) => f,
        None => Format::from_path(path).ok_or_else(|| IoError::unknown_format(path))?,
    };
    let enc = encode(hf, format, opts).map_err(|kind| IoError::Format {
        path: path.to_path_buf(),
        kind,
    })?;
    let mut notes = Vec::new();
    let prj = match (format, hf.georef().and_then(|g| g.crs.as_ref())) {
        (Format::Asc, Some(crs)) if !hf.georef().is_some_and(|g| g.is_local()) => {
            match crs.wkt.clone().or_else(|| crs.epsg.and_then(wkt::for_epsg)) {
                Some(w) => Some(w),
                None => {
                    notes.push(format!(
                        "{} has no .prj: the CRS {} has no WKT here (write a GeoTIFF to keep it)",
                        path.display(),
                        crs.label()
                    ));
                    None
                }
            }
        }
        _ => None,
    };
    // A CRS known only by its WKT: GDAL does not rebuild one from GeoKeys
    // alone, so it also goes into GDAL's PAM sidecar (`<file>.aux.xml`),
    // which GDAL and QGIS read with the TIFF.
    let pam = match (format, hf.georef().and_then(|g| g.crs.as_ref())) {
        (Format::Tiff, Some(c)) if c.epsg.is_none() && c.wkt.is_some() => Some(format!(
            "<PAMDataset>\n  <SRS>{}</SRS>\n</PAMDataset>\n",
            xml_escape(c.wkt.as_deref().unwrap_or_default())
        )),
        _ => None,
    };
    let mut targets = vec![path.to_path_buf()];
    if pam.is_some() {
        targets.push(pam_path(path));
    }
    if enc.sidecar.is_some() {
        targets.push(sidecar_path(path));
    }
    if prj.is_some() {
        targets.push(prj_path(path));
    }
    for t in &targets {
        if let Some(input) = opts.inputs.iter().find(|i| same_file(i, t)) {
            return Err(IoError::WouldOverwrite {
                path: t.clone(),
                input: input.clone(),
            });
        }
    }
    // The sidecar goes first: a reader that finds the data file then always
    // finds the mapping that belongs to it.
    if let Some(sc) = &enc.sidecar {
        write_atomic(&sidecar_path(path), sc)?;
    }
    if let Some(w) = &prj {
        write_atomic(&prj_path(path), w.as_bytes())?;
    }
    if let Some(x) = &pam {
        write_atomic(&pam_path(path), x.as_bytes())?;
    }
    write_atomic(path, &enc.bytes)?;
    Ok(notes)
}

/// GDAL's PAM sidecar of a data file (`<file>.aux.xml`).
pub fn pam_path(path: &Path) -> PathBuf {
    let mut name = path.as_os_str().to_owned();
    name.push(".aux.xml");
    PathBuf::from(name)
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Whether two paths name the same file (or would: an output that does not
/// exist yet is compared by its absolute path).
pub fn same_file(a: &Path, b: &Path) -> bool {
    let abs = |p: &Path| {
        std::fs::canonicalize(p).unwrap_or_else(|_| {
            let parent = p
                .parent()
                .filter(|d| !d.as_os_str().is_empty())
                .unwrap_or(Path::new("."));
            std::fs::canonicalize(parent)
                .map(|d| d.join(p.file_name().unwrap_or_default()))
                .unwrap_or_else(|_| p.to_path_buf())
        })
    };
    abs(a) == abs(b)
}
