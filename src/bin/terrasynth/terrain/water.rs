//! `terrasynth water`: filled surface, lakes, flow and rivers beside a
//! heightfield (see `terrasynth::water`).

use crate::{CliResult, args::Input};
use std::path::{Path, PathBuf};
use terrasynth::io::{self, WriteOptions, write_atomic};
use terrasynth::water::{self, Params, Routing, Thresholds};

const ABOUT_THE_FILES: &str = "\
Files written to --out-dir, in the input's grid and georeference (GeoTIFF,
float32):
  filled.tif      the water surface: depressions filled to their spill level
                  (priority-flood), the sea at sea level, elsewhere the ground
  lakes.tif       water depth in metres: lakes (filled - ground, where deep and
                  wide enough) and the sea; 0 on land
  flow.tif        flow accumulation on the filled surface, in cells
                  (upstream area = value x cell area): D8, or with
                  --routing mfd shared among lower neighbours by slope
                  (rivers and their orders follow D8 either way)
  rivers.tif      Strahler order of river cells, 0 elsewhere
  rivers.geojson  river segments as LineStrings (strahler, upstream_area_km2,
                  length_m, end), in the input's CRS, or in terrasynth's local
                  grid in metres when the input has no georeference

Examples:
  terrasynth water dem.tif --out-dir water/
  terrasynth water coast.png --out-dir water/ --sea-level 0 --json
  terrasynth water world.png --out-dir water/ --river-area 20 --preview water.png
  terrasynth water dem.tif --out-dir water/ --routing mfd";

#[derive(clap::Args)]
#[command(after_help = ABOUT_THE_FILES)]
pub struct Args {
    /// The heightfield.
    input: PathBuf,
    /// Folder for filled.tif, lakes.tif, flow.tif, rivers.tif and
    /// rivers.geojson (created if missing).
    #[arg(long)]
    out_dir: PathBuf,
    #[command(flatten)]
    params: Knobs,
    /// How flow.tif's accumulation is routed: d8 (all to the steepest
    /// neighbour) or mfd (shared among lower neighbours by slope, as
    /// pysheds' routing='mfd'). Rivers follow D8 either way.
    #[arg(long, value_enum, default_value_t = RoutingArg::D8)]
    routing: RoutingArg,
    /// Print the summary (lakes, sea, river length by order) as JSON.
    #[arg(long)]
    json: bool,
    /// Also write a picture: hillshade, lakes and sea in blue, rivers by
    /// Strahler order.
    #[arg(long, value_name = "PNG")]
    preview: Option<PathBuf>,
    /// Longest side of the preview in pixels.
    #[arg(long, value_name = "PX", default_value_t = 2048)]
    preview_size: usize,
    #[command(flatten)]
    read: Input,
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum RoutingArg {
    D8,
    Mfd,
}

/// Refuses to replace the input (or its companions' data file).
fn guard(path: &Path, input: &Path) -> Result<(), String> {
    if io::same_file(path, input) {
        Err(format!(
            "{}: refusing to overwrite the input",
            path.display()
        ))
    } else {
        Ok(())
    }
}

/// The water parameters `water` and `tiles --water` share.
#[derive(clap::Args)]
pub struct Knobs {
    /// Cells joined to the border at or below this height (metres) are sea:
    /// rivers end there. Default: no sea.
    #[arg(long, value_name = "M", allow_hyphen_values = true)]
    sea_level: Option<f32>,
    /// Upstream area from which a flow line is a river, km² [default: 5].
    #[arg(long, value_name = "KM2")]
    river_area: Option<f64>,
    /// A filled depression is a lake only this deep (metres, its deepest
    /// cell) [default: 2] ...
    #[arg(long, value_name = "M")]
    lake_min_depth: Option<f64>,
    /// ... and this large (km²) [default: 0.1]; smaller ones are still
    /// filled for flow.
    #[arg(long, value_name = "KM2")]
    lake_min_area: Option<f64>,
}

impl Knobs {
    pub fn params(&self) -> Params {
        let d = Params::default();
        Params {
            sea_level: self.sea_level,
            lakes: Thresholds {
                min_depth_m: self.lake_min_depth.unwrap_or(d.lakes.min_depth_m),
                min_area_km2: self.lake_min_area.unwrap_or(d.lakes.min_area_km2),
            },
            river_area_km2: self.river_area.unwrap_or(d.river_area_km2),
        }
    }

    /// Whether any was given.
    pub fn any(&self) -> bool {
        self.sea_level.is_some()
            || self.river_area.is_some()
            || self.lake_min_depth.is_some()
            || self.lake_min_area.is_some()
    }
}

pub fn run(a: Args) -> CliResult {
    let hf = a.read.read(&a.input)?;
    let params = a.params.params();
    let name = a.input.display().to_string();
    let routing = match a.routing {
        RoutingArg::D8 => Routing::D8,
        RoutingArg::Mfd => Routing::Mfd,
    };
    let w = water::compute_with(&hf, &params, routing).map_err(|e| format!("{name}: {e}"))?;
    std::fs::create_dir_all(&a.out_dir)
        .map_err(|e| format!("cannot create {}: {e}", a.out_dir.display()))?;
    let opts = WriteOptions {
        inputs: vec![a.input.clone()],
        ..Default::default()
    };
    let rasters: [(&str, Vec<f32>); 4] = [
        ("filled.tif", w.filled.clone()),
        ("lakes.tif", w.bodies.depth.clone()),
        ("flow.tif", w.flow()),
        (
            "rivers.tif",
            w.rivers.order.iter().map(|&o| o as f32).collect(),
        ),
    ];
    for (file, values) in rasters {
        io::write(&w.raster(&hf, values), &a.out_dir.join(file), &opts)?;
    }
    let geojson = a.out_dir.join("rivers.geojson");
    guard(&geojson, &a.input)?;
    write_atomic(&geojson, &w.rivers_geojson(hf.georef()))?;
    if let Some(p) = &a.preview {
        guard(p, &a.input)?;
        let img = w.preview(&hf, a.preview_size)?;
        terrasynth::render::write_png(p, &img)?;
    }
    let s = w.summary();
    if a.json {
        println!("{}", serde_json::to_string_pretty(&s)?);
    } else {
        if let Some(sea) = &s.sea {
            println!("sea: {:.2} km², {:.3e} m³", sea.area_km2, sea.volume_m3);
        }
        println!(
            "lakes: {} ({:.2} km², {:.3e} m³; {} shallower than {} m or smaller than {} km² left out)",
            s.lakes.count,
            s.lakes.area_km2,
            s.lakes.volume_m3,
            s.lakes.below_thresholds,
            s.lakes.min_depth_m,
            s.lakes.min_area_km2
        );
        let by_order: Vec<String> = s
            .rivers
            .length_km_by_order
            .iter()
            .map(|(o, km)| format!("order {o}: {km:.1} km"))
            .collect();
        println!(
            "rivers (from {} km²): {} segments; {}",
            s.rivers.min_area_km2,
            s.rivers.segments,
            by_order.join(", ")
        );
    }
    eprintln!(
        "wrote filled.tif, lakes.tif, flow.tif, rivers.tif and rivers.geojson ({} x {}) to {} in {:.2} s",
        w.width,
        w.height,
        a.out_dir.display(),
        w.timings.total().as_secs_f64()
    );
    Ok(())
}
