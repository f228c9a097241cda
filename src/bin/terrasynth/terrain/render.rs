//! `terrasynth render`: a PNG preview of a heightfield.

use crate::{CliResult, args::Input};
use std::path::PathBuf;
use terrasynth::io::TypeMask;
use terrasynth::render::{self, Contours, Grid, RenderOptions, Sea, TypeOverlay};

/// What the picture shows, printed after the options.
const ABOUT_THE_MAP: &str = "\
The map: a shaded relief lit from the north-west, coloured by elevation
(greens low, then tans and browns, rock grey and snow high; blue water
below sea level when the heights cross 0 m), brown contour lines with a
thicker index line every fifth, and hatched grey where data is missing.
Optional: a white grid, red where heights leave --range, and terrain types
in colour (the legend is printed). A line on stderr says which contour
interval was used. Inputs larger than --max-size are averaged down;
smaller ones are enlarged.

Examples:
  terrasynth render alps.png -o alps-preview.png
  terrasynth render alps.png -o check.png --range 400:3200 --grid-m 1000
  terrasynth render dem.png -o types.png --types dem_types.png";

#[derive(clap::Args)]
#[command(after_help = ABOUT_THE_MAP)]
pub struct Args {
    /// Input heightfield (any readable format).
    input: PathBuf,
    /// Output PNG.
    #[arg(short, long, value_name = "PNG")]
    output: PathBuf,
    /// Contour interval in metres [default: a round interval giving 10-20 lines].
    #[arg(long, value_name = "M", conflicts_with = "no_contours")]
    contour: Option<f64>,
    /// Draw no contour lines.
    #[arg(long)]
    no_contours: bool,
    /// Grid line every CELLS input cells.
    #[arg(long, value_name = "CELLS", conflicts_with = "grid_m")]
    grid: Option<f64>,
    /// Grid line every METRES metres.
    #[arg(long = "grid-m", value_name = "METRES")]
    grid_m: Option<f64>,
    /// Paint heights outside MIN:MAX metres red (e.g. the exemplars' range).
    #[arg(long, value_name = "MIN:MAX", allow_hyphen_values = true, value_parser = parse_range)]
    range: Option<(f64, f64)>,
    /// Colour terrain types from an 8-bit index PNG of the input's size
    /// (255 = no type); type names are read from MASK.json when present.
    #[arg(long, value_name = "MASK.png")]
    types: Option<PathBuf>,
    /// Vertical exaggeration of the shading.
    #[arg(long, value_name = "X", default_value_t = 1.0)]
    exaggeration: f64,
    /// Longest side of the preview in pixels; larger inputs are averaged down.
    #[arg(long, value_name = "PX", default_value_t = 2048)]
    max_size: usize,
    /// Smaller inputs are enlarged by a whole factor toward this size (at most --max-size).
    #[arg(long, value_name = "PX", default_value_t = 512)]
    min_size: usize,
    /// Show water below this level [default: 0 m, if the heights cross it].
    #[arg(
        long,
        value_name = "M",
        allow_hyphen_values = true,
        conflicts_with = "no_sea"
    )]
    sea_level: Option<f64>,
    /// Show no water; colour every height as land.
    #[arg(long)]
    no_sea: bool,
    /// Heights LO:HI in metres the land colours run over [default: from the data].
    #[arg(long, value_name = "LO:HI", allow_hyphen_values = true, value_parser = parse_range)]
    tint_range: Option<(f64, f64)>,
    #[command(flatten)]
    read: Input,
}

pub fn run(a: Args) -> CliResult {
    let hf = a.read.read(&a.input)?;
    let types = a.types.as_deref().map(TypeMask::read).transpose()?;
    let legend: Vec<String> = types
        .as_ref()
        .map(|m| {
            m.present()
                .into_iter()
                .map(|i| {
                    let [r, g, b] = render::types::type_colour(i);
                    let name = m.names.get(&i).map_or("", String::as_str);
                    format!("{i} {name} #{r:02x}{g:02x}{b:02x}")
                })
                .collect()
        })
        .unwrap_or_default();
    let opts = RenderOptions {
        max_size: a.max_size,
        min_size: a.min_size,
        exaggeration: a.exaggeration,
        contours: match (a.no_contours, a.contour) {
            (true, _) => Contours::Off,
            (false, Some(m)) => Contours::Every(m),
            (false, None) => Contours::Auto,
        },
        grid: match (a.grid, a.grid_m) {
            (Some(c), _) => Grid::Cells(c),
            (None, Some(m)) => Grid::Metres(m),
            (None, None) => Grid::Off,
        },
        range: a.range,
        sea: match (a.no_sea, a.sea_level) {
            (true, _) => Sea::Off,
            (false, Some(s)) => Sea::Level(s),
            (false, None) => Sea::Auto,
        },
        tint_range: a.tint_range,
        types: types.map(TypeOverlay::new),
        ..RenderOptions::default()
    };
    let preview = render::render(&hf, &opts)?;
    render::write_png(&a.output, &preview.image)?;

    let i = &preview.info;
    let mut notes = Vec::new();
    if let Some((lo, hi)) = i.height_range_m {
        notes.push(format!("heights {lo:.1}..{hi:.1} m"));
    }
    match i.contour_interval_m {
        Some(c) => notes.push(format!(
            "contours every {} m, index every {} m",
            fmt_m(c),
            fmt_m(c * render::contours::INDEX_EVERY as f64)
        )),
        None => notes.push("no contours".into()),
    }
    if let Some(s) = i.sea_level_m {
        notes.push(format!("water below {} m", fmt_m(s)));
    }
    if !legend.is_empty() {
        notes.push(format!("types: {}", legend.join(", ")));
    }
    eprintln!(
        "wrote {} ({} x {} px from {} x {} cells); {}",
        a.output.display(),
        i.width,
        i.height,
        hf.width(),
        hf.height(),
        notes.join("; ")
    );
    Ok(())
}

/// Metres without trailing zeros (`20`, `2.5`, `0.005`).
fn fmt_m(v: f64) -> String {
    let s = format!("{v:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Parses `MIN:MAX` metres, MIN <= MAX, both finite.
fn parse_range(s: &str) -> Result<(f64, f64), String> {
    let err = || {
        format!("invalid range {s:?}: expected MIN:MAX in metres with MIN <= MAX, e.g. -10:2500")
    };
    let (a, b) = s.split_once(':').ok_or_else(err)?;
    let a: f64 = a.trim().parse().map_err(|_| err())?;
    let b: f64 = b.trim().parse().map_err(|_| err())?;
    if a.is_finite() && b.is_finite() && a <= b {
        Ok((a, b))
    } else {
        Err(err())
    }
}
