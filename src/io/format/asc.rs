//! ESRI ASCII grids (`.asc`, read/write).
//!
//! Header: one `keyword value` pair per line, keywords in any order and any
//! case: `ncols`, `nrows`, `cellsize` or both `dx` and `dy` (GDAL writes
//! those for non-square cells), `xllcorner` | `xllcenter` and `yllcorner` |
//! `yllcenter` (optional, both or neither), `NODATA_value` (optional, a
//! number or `nan`, as GDAL writes for float grids). Values follow, rows
//! north to south, separated by any whitespace (rows may wrap across
//! lines). Samples equal to `NODATA_value`, or spelled `nan`, become NaN.
//! Errors name the line.
//!
//! The grid's placement becomes a [`Georef`] without CRS; a `.prj` beside
//! the file gives the CRS (read by [`crate::io::load`]). Without a `.prj` the
//! units are taken to be metres; cells of degrees without a `.prj` are
//! refused with a hint ([`crate::io::place::ground`]), and `dx` ≠ `dy` is resampled
//! to square cells there.
//!
//! Writing uses Rust's shortest round-trip float formatting, so every f32
//! reads back bit-exact; `NODATA_value` is written only when there is
//! nodata, with a value that no sample has. A georeferenced heightfield is
//! written in its own map units (`dx`/`dy` when its cells are not square in
//! them, as for a geographic grid), and [`crate::io::write`] puts its CRS in
//! a `.prj`.

use crate::georef::{Georef, PixelIs};
use crate::heightfield::Heightfield;
use crate::io::{Encoded, FormatError};
use crate::size::check_dims;
use std::fmt::Write as _;

const KEYWORDS: &str =
    "ncols, nrows, xllcorner|xllcenter, yllcorner|yllcenter, cellsize or dx and dy, NODATA_value";

#[derive(Default)]
struct Header {
    ncols: Option<usize>,
    nrows: Option<usize>,
    xll: Option<(f64, bool)>,
    yll: Option<(f64, bool)>,
    cellsize: Option<f64>,
    dx: Option<f64>,
    dy: Option<f64>,
    nodata: Option<f64>,
}

pub(in crate::io) fn decode(bytes: &[u8]) -> Result<Heightfield, FormatError> {
    let syntax = |line: usize, message: String| FormatError::Syntax { line, message };
    let mut header = Header::default();
    let mut offset = 0;
    let mut line_no = 0;
    // Header lines start with a keyword (a letter); the first line that
    // does not is the first row of values.
    while offset < bytes.len() {
        let end = bytes[offset..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |p| offset + p + 1);
        let line = &bytes[offset..end];
        let first = line
            .split(|b| b.is_ascii_whitespace())
            .find(|t| !t.is_empty());
        if first.is_some_and(|t| !is_keyword_like(t)) {
            break;
        }
        line_no += 1;
        offset = end;
        if first.is_none() {
            continue;
        }
        let text = std::str::from_utf8(line)
            .map_err(|_| syntax(line_no, "header line is not UTF-8 text".into()))?;
        let mut tokens = text.split_ascii_whitespace();
        let (Some(key), Some(value), None) = (tokens.next(), tokens.next(), tokens.next()) else {
            return Err(syntax(
                line_no,
                format!("expected `keyword value`, found {:?}", text.trim()),
            ));
        };
        parse_keyword(&mut header, key, value).map_err(|m| syntax(line_no, m))?;
    }

    let first_data_line = line_no + 1;
    let missing = |what: &str| {
        syntax(
            first_data_line,
            format!("header has no {what} before the values (keywords: {KEYWORDS})"),
        )
    };
    let w = header.ncols.ok_or_else(|| missing("ncols"))?;
    let h = header.nrows.ok_or_else(|| missing("nrows"))?;
    let (cx, cy) = match (header.cellsize, header.dx, header.dy) {
        (Some(c), None, None) => (c, c),
        (None, Some(x), Some(y)) => (x, y),
        (None, None, None) => return Err(missing("cellsize (or dx and dy)")),
        (Some(_), _, _) => return Err(missing("cellsize or dx/dy (both are given)")),
        (None, _, _) => return Err(missing("dx and dy (one is given without the other)")),
    };
    check_dims(w, h)?;
    // Every value takes at least one digit and one separator (the last
    // needs no separator): refuse before allocating.
    let remaining = bytes.len() - offset;
    if (w as u64) * (h as u64) * 2 > remaining as u64 + 1 {
        return Err(FormatError::not_justified(w, h, bytes.len()));
    }
    let georef = match (header.xll, header.yll) {
        (None, None) if cx == cy => None,
        // Non-square cells still need their geometry to be resampled.
        (None, None) => Some((0.0, false, 0.0, false)),
        (Some((x, xc)), Some((y, yc))) => Some((x, xc, y, yc)),
        _ => {
            return Err(missing(
                "xllcorner and yllcorner (one is given without the other)",
            ));
        }
    }
    .map(|(x, xc, y, yc)| {
        let x = if xc { x - cx / 2.0 } else { x };
        let y = if yc { y - cy / 2.0 } else { y };
        Georef {
            crs: None,
            origin_x: x,
            origin_y: y + h as f64 * cy,
            pixel_x: cx,
            pixel_y: cy,
            pixel_is: PixelIs::Area,
        }
    });
    if georef.as_ref().is_some_and(|g| !g.is_valid()) {
        return Err(syntax(
            first_data_line,
            "the corner and cell size place the grid beyond finite coordinates".into(),
        ));
    }
    let cell = cy;

    let n = w * h;
    let nodata = header.nodata.map(|v| v as f32);
    let mut data = Vec::with_capacity(n);
    for line in bytes[offset..].split(|&b| b == b'\n') {
        line_no += 1;
        for token in line
            .split(|b| b.is_ascii_whitespace())
            .filter(|t| !t.is_empty())
        {
            let v = std::str::from_utf8(token)
                .ok()
                .and_then(|t| t.parse::<f32>().ok())
                .ok_or_else(|| {
                    syntax(
                        line_no,
                        format!("invalid number {:?}", String::from_utf8_lossy(token)),
                    )
                })?;
            if data.len() == n {
                return Err(syntax(
                    line_no,
                    format!("more values than ncols x nrows = {w} x {h} = {n}"),
                ));
            }
            data.push(if v.is_nan() || Some(v) == nodata {
                f32::NAN
            } else {
                v
            });
        }
    }
    if data.len() < n {
        // `split` yields one empty piece after a final newline.
        let last = if bytes.ends_with(b"\n") {
            line_no - 1
        } else {
            line_no
        };
        return Err(syntax(
            last,
            format!(
                "the grid ends early: expected ncols x nrows = {n} values, found {}",
                data.len()
            ),
        ));
    }
    let mut hf = Heightfield::from_vec(w, h, cell, data)?;
    hf.set_georef(georef);
    Ok(hf)
}

/// Header lines start with a word; `nan` and `inf` are values, not words.
fn is_keyword_like(token: &[u8]) -> bool {
    token[0].is_ascii_alphabetic()
        && std::str::from_utf8(token).map_or(true, |t| t.parse::<f32>().is_err())
}

fn parse_keyword(header: &mut Header, key: &str, value: &str) -> Result<(), String> {
    let number = || -> Result<f64, String> {
        value
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("{key} is {value:?}: expected a finite number"))
    };
    let count = || -> Result<usize, String> {
        value
            .parse::<usize>()
            .ok()
            .filter(|&v| v >= 1)
            .ok_or_else(|| format!("{key} is {value:?}: expected a whole number >= 1"))
    };
    let k = key.to_ascii_lowercase();
    let already = match k.as_str() {
        "ncols" => header.ncols.replace(count()?).is_some(),
        "nrows" => header.nrows.replace(count()?).is_some(),
        "xllcorner" | "xllcenter" => header.xll.replace((number()?, k == "xllcenter")).is_some(),
        "yllcorner" | "yllcenter" => header.yll.replace((number()?, k == "yllcenter")).is_some(),
        "cellsize" | "dx" | "dy" => {
            let c = number()?;
            if c <= 0.0 {
                return Err(format!("{key} is {value}: expected a value > 0"));
            }
            match k.as_str() {
                "dx" => header.dx.replace(c),
                "dy" => header.dy.replace(c),
                _ => header.cellsize.replace(c),
            }
            .is_some()
        }
        // GDAL writes `nan` for float grids whose nodata is NaN.
        "nodata_value" if value.eq_ignore_ascii_case("nan") => {
            header.nodata.replace(f64::NAN).is_some()
        }
        "nodata_value" => header.nodata.replace(number()?).is_some(),
        _ => {
            return Err(format!(
                "unknown header keyword {key:?} (expected {KEYWORDS})"
            ));
        }
    };
    if already {
        return Err(format!("{key} is given twice"));
    }
    Ok(())
}

pub(in crate::io) fn encode(hf: &Heightfield) -> Result<Encoded, FormatError> {
    let (w, h) = (hf.width(), hf.height());
    let local = Georef::local(h, hf.cell_size());
    let g = hf.georef().unwrap_or(&local);
    let mut s = String::with_capacity(hf.len() * 9 + 200);
    // Writing to a String cannot fail.
    let _ = write!(
        s,
        "ncols {w}\nnrows {h}\nxllcorner {}\nyllcorner {}\n",
        g.origin_x,
        g.origin_y - h as f64 * g.pixel_y
    );
    if g.pixel_x == g.pixel_y {
        let _ = writeln!(s, "cellsize {}", g.pixel_x);
    } else {
        let _ = write!(s, "dx {}\ndy {}\n", g.pixel_x, g.pixel_y);
    }
    let nodata = match hf.stats() {
        _ if hf.nodata_count() == 0 => None,
        None => Some(-9999.0),
        // -9999 by convention; below or above every sample if that is taken.
        Some(st) => Some(
            [-9999.0f32, (st.min - 1.0).floor(), (st.max + 1.0).ceil()]
                .into_iter()
                .find(|n| n.is_finite() && !hf.data().contains(n))
                .ok_or_else(|| {
                    FormatError::Unwritable(
                        "no finite value is free to mark nodata in ESRI ASCII".into(),
                    )
                })?,
        ),
    };
    if let Some(n) = nodata {
        let _ = writeln!(s, "NODATA_value {n}");
    }
    for y in 0..h {
        for (x, &v) in hf.row(y).iter().enumerate() {
            if x > 0 {
                s.push(' ');
            }
            let _ = write!(s, "{}", if v.is_nan() { nodata.unwrap_or(v) } else { v });
        }
        s.push('\n');
    }
    Ok(Encoded {
        bytes: s.into_bytes(),
        sidecar: None,
    })
}
