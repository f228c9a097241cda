//! The procedural styles of `terrasynth generate`: eroded alpine ridges,
//! canyons and mesas, rolling hills (`tests/inputs/procedural.rs` pins their
//! output at the defaults by golden hashes).
//!
//! Noise alone does not look like terrain: real landscapes are organised by
//! their drainage, every valley leading into a larger one. So each style is
//! *evolved*: a warped fBm pattern of tectonic uplift raises the
//! land while stream-power incision ([`fluvial_erode`]) cuts the drainage
//! network, thermal erosion keeps hillslopes at their talus angle and soil
//! creep rounds them, coarse to fine over 4–5 resolution levels (fresh noise
//! at each) so that valleys branch at every scale. The styles then differ
//! in their rates and in the finishing: scree and rock ribs for the alpine
//! style, bias + terracing + cliff erosion for the canyons, creep for the
//! hills.
//!
//! Sizes are in cells of [`CELL_SIZE_M`] metres; a larger `size` shows more
//! of the same landscape (feature sizes are fixed in metres). Everything is
//! deterministic (see the module [`super`]), so `generate` recreates the
//! same files byte for byte.

use super::error::ProceduralError;
use super::fbm::{Fractal, Shape};
use super::fluvial::{FluvialParams, Routing, fluvial_erode};
use super::grid::upsample2;
use super::noise::pcg;
use super::remap;
use super::thermal::{ThermalParams, thermal_erode};
use super::types::TypeClassification;
use super::warp::Warp;
use crate::heightfield::Heightfield;
use crate::progress::Progress;
use crate::size::check_dims;
use serde::Deserialize;
use std::collections::BTreeMap;

/// Cell size of the generated terrain, in metres (a typical DEM posting).
pub const CELL_SIZE_M: f64 = 30.0;
/// Side `generate` makes by default (the golden hashes' size).
pub const DEFAULT_SIZE: usize = 512;
/// Seed `generate` uses by default (the golden hashes' seed).
pub const DEFAULT_SEED: u32 = 2015;
/// Smallest accepted side (the coarsest level of the hills is 1/16 of it).
pub const MIN_SIZE: usize = 32;

/// A procedural terrain style.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Style {
    Alpine,
    Canyon,
    Hills,
}

impl Style {
    pub const ALL: [Style; 3] = [Style::Alpine, Style::Canyon, Style::Hills];

    /// The name used on the command line and in `data/styles.json`.
    pub fn name(self) -> &'static str {
        match self {
            Style::Alpine => "alpine",
            Style::Canyon => "canyon",
            Style::Hills => "hills",
        }
    }

    pub fn from_name(name: &str) -> Result<Style, ProceduralError> {
        Self::ALL
            .into_iter()
            .find(|s| s.name() == name)
            .ok_or_else(|| ProceduralError::UnknownStyle {
                name: name.to_string(),
                known: Self::ALL.map(|s| s.name()).join(", "),
            })
    }

    /// One line for `generate --list`.
    pub fn description(self) -> &'static str {
        match self {
            Style::Alpine => {
                "eroded alpine ridges: sharp crests, deep branching valleys, scree slopes (about 500-2800 m)"
            }
            Style::Canyon => {
                "canyons and mesas: plateau benches, terraced cliff bands, talus and canyon floors (1200-2100 m)"
            }
            Style::Hills => {
                "rolling hills: rounded hills, soft slopes, a branching valley network (about 200-800 m)"
            }
        }
    }

    /// The `method` text of the type mask's JSON: how it was made.
    pub fn types_method(self, size: usize, seed: u32) -> String {
        format!(
            "derived from the terrain made by `terrasynth generate --style {} --size {size} --seed {seed}`: \
             cliff where slope >= 1, plateau where slope < 0.1 and not in a valley, valley floor and ridge \
             by topographic position (height above the mean of a ~1.2 km window, in units of the local \
             relief), slope otherwise; majority-filtered into regions",
            self.name()
        )
    }

    /// Generates the style's terrain (`size`² cells of [`CELL_SIZE_M`]) and
    /// its type mask. Deterministic for a seed, at any thread count.
    pub fn generate(
        self,
        size: usize,
        seed: u32,
        progress: &dyn Progress,
    ) -> Result<(Heightfield, TypeClassification), ProceduralError> {
        check_dims(size, size)?;
        if size < MIN_SIZE {
            return Err(ProceduralError::Param {
                name: "size",
                value: size as f64,
                allowed: "at least 32 cells",
            });
        }
        let recipe = Recipe::of(self);
        progress.start(self.name(), recipe.work());
        let mut hf = evolve(&recipe, size, seed, progress)?;
        match self {
            // Ridged detail noise on every level, then the finishing talus
            // at ~35° with strong variation (scree aprons between rock
            // ribs), then rock ribs and gullies on the steep ground.
            Style::Alpine => {
                recipe.finish(&mut hf, seed, progress)?;
                roughen(&mut hf, 15.0, 400.0, sub_seed(seed, 5));
                remap::map(&mut hf, |h| h + 500.0);
            }
            // A deeply incised drainage network, range-mapped into mesas
            // and cliff bands, whose cliffs the finishing erosion with
            // strongly varying talus breaks into buttresses above talus
            // aprons.
            Style::Canyon => {
                terrace_canyons(&mut hf, seed);
                recipe.finish(&mut hf, seed, progress)?;
            }
            // Weak uplift, a coarse start (480 m cells: valleys a few km
            // apart), gentle talus and soil creep on the finer levels for
            // rounded crests.
            Style::Hills => {
                recipe.finish(&mut hf, seed, progress)?;
                remap::map(&mut hf, |h| h + 200.0);
            }
        }
        progress.finish();
        let mask = TypeClassification::classify(&hf);
        Ok((hf, mask))
    }
}

/// Forwards only `advance`, so that the stages of a style fill one bar.
struct Inner<'a>(&'a dyn Progress);

impl Progress for Inner<'_> {
    fn start(&self, _stage: &str, _total: u64) {}
    fn advance(&self, n: u64) {
        self.0.advance(n);
    }
    fn finish(&self) {}
}

/// Distinct seeds for the parts of one style.
fn sub_seed(seed: u32, part: u32) -> u32 {
    pcg(seed ^ pcg(part))
}

/// The styles' recipes. They are numbers only, so they live in
/// `data/styles.json` (one object per [`Style::name`], fields as in
/// [`Recipe`]) where the three can be compared and tuned side by side.
const RECIPES: &str = include_str!("../../data/styles.json");

/// A landscape-evolution recipe: tectonic uplift against fluvial incision,
/// thermal erosion and soil creep, from coarse to fine (see [`evolve`]),
/// then a finishing thermal pass.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Recipe {
    /// Seed namespace of the style, so styles do not share layouts.
    part: u32,
    /// Number of levels (at most 6); the coarsest has cells of
    /// `30 m · 2^(levels−1)`.
    levels: usize,
    /// Uplift per fluvial step in metres, where the uplift pattern is highest.
    uplift_m: f64,
    /// Uplift where the pattern is lowest, as a fraction of `uplift_m`.
    uplift_min: f64,
    /// Feature size of the uplift pattern, metres.
    pattern_m: f64,
    erodibility: f64,
    talus: f64,
    talus_variation: f64,
    /// Per level (index 0 = finest): rounds of (fluvial steps, thermal
    /// iterations), creep iterations after the rounds, and the amplitude in
    /// metres of fresh detail noise added when the level is entered.
    rounds: [u32; 6],
    fluvial_steps: [u32; 6],
    thermal_steps: u32,
    creep: [u32; 6],
    detail_m: [f64; 6],
    ridged_detail: bool,
    finish: Finish,
}

/// The thermal erosion that finishes a style (scree, soil or cliff walls,
/// each at its own talus).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Finish {
    talus: f64,
    variation: f64,
    iterations: u32,
}

impl Recipe {
    fn of(style: Style) -> Recipe {
        let mut all: BTreeMap<String, Recipe> =
            serde_json::from_str(RECIPES).expect("data/styles.json parses (see the tests)");
        all.remove(style.name())
            .expect("data/styles.json has every style (see the tests)")
    }

    /// Progress units: every fluvial, thermal and creep iteration.
    fn work(&self) -> u64 {
        (0..self.levels)
            .map(|l| {
                self.rounds[l] as u64 * (self.fluvial_steps[l] + self.thermal_steps) as u64
                    + self.creep[l] as u64
            })
            .sum::<u64>()
            + self.finish.iterations as u64
    }

    /// Runs the finishing thermal erosion on `hf`.
    fn finish(
        &self,
        hf: &mut Heightfield,
        seed: u32,
        progress: &dyn Progress,
    ) -> Result<(), ProceduralError> {
        let params = ThermalParams {
            talus: self.finish.talus,
            rate: 0.5,
            variation: self.finish.variation,
            seed: sub_seed(seed, 4),
        };
        thermal_erode(hf, &params, self.finish.iterations, &Inner(progress))
    }
}

/// Evolves a landscape: on the coarsest level, a nearly flat surface (with
/// a margin around the map, so that the map's edges are not base level and
/// rivers cross them at any height) rises under a warped-noise uplift
/// pattern while the stream-power law cuts it down along the drainage
/// ([`fluvial_erode`]) and thermal erosion keeps hillslopes at the talus
/// angle. Each finer level upsamples, adds fresh noise at its own scale and
/// continues the evolution, so tributaries appear at every scale. The
/// drainage is dendritic because it is organised, not drawn.
fn evolve(
    r: &Recipe,
    size: usize,
    seed: u32,
    progress: &dyn Progress,
) -> Result<Heightfield, ProceduralError> {
    let seed = sub_seed(seed, r.part);
    let n = size.div_ceil(1 << (r.levels - 1));
    let margin = n / 8 + 1;
    let warp = Warp::new(
        Fractal {
            octaves: 3,
            ..Fractal::new(sub_seed(seed, 1), 1.0 / (0.65 * r.pattern_m))
        },
        0.1 * r.pattern_m,
    );
    let pattern = Fractal {
        h: 1.0,
        octaves: 4,
        ..Fractal::new(sub_seed(seed, 2), 1.0 / r.pattern_m)
    };
    let amp = pattern.amplitude_sum();
    let uplift_at = |xm: f64, ym: f64| {
        let (u, v) = warp.apply(xm, ym);
        let t = (0.5 + 0.8 * pattern.sample(u, v) / amp).clamp(0.0, 1.0);
        r.uplift_m * (r.uplift_min + (1.0 - r.uplift_min) * t)
    };
    let talus = ThermalParams {
        talus: r.talus,
        rate: 0.5,
        variation: r.talus_variation,
        seed: sub_seed(seed, 3),
    };
    let inner = Inner(progress);
    let mut hf: Option<Heightfield> = None;
    for level in (0..r.levels).rev() {
        let cell = CELL_SIZE_M * (1 << level) as f64;
        let pad = if hf.is_none() { margin } else { 0 };
        let at = |i: usize| (i as f64 + 0.5 - pad as f64) * cell;
        let detail = Fractal {
            octaves: 2,
            h: 1.0,
            shape: if r.ridged_detail {
                Shape::Ridged
            } else {
                Shape::Plain
            },
            ..Fractal::new(sub_seed(seed, 10 + level as u32), 1.0 / (4.0 * cell))
        };
        // ridged values lie in [0, 1] with mean ≈ ¾: centre them
        let centre = if r.ridged_detail {
            0.75 * detail.amplitude_sum()
        } else {
            0.0
        };
        let noise = |x: usize, y: usize| r.detail_m[level] * (detail.sample(at(x), at(y)) - centre);
        let mut cur = match hf.take() {
            None => {
                Heightfield::from_fn(n + 2 * pad, n + 2 * pad, cell, |x, y| noise(x, y) as f32)?
            }
            Some(prev) => {
                let up = upsample2(&prev);
                let w = up.width();
                let mut d = up.into_vec();
                super::grid::sweep_add(&mut d, w, noise);
                Heightfield::from_vec(w, w, cell, d)?
            }
        };
        let w = cur.width();
        let uplift = Heightfield::from_fn(w, w, cell, |x, y| uplift_at(at(x), at(y)) as f32)?;
        for round in 0..r.rounds[level] {
            let rivers = FluvialParams {
                erodibility: r.erodibility,
                epsilon: 0.01,
                routing: Routing::Random(sub_seed(seed, 1000 * level as u32 + round + 100)),
            };
            fluvial_erode(
                &mut cur,
                &rivers,
                Some(&uplift),
                r.fluvial_steps[level],
                &inner,
            )?;
            thermal_erode(&mut cur, &talus, r.thermal_steps, &inner)?;
        }
        super::creep::creep(&mut cur, 0.5, r.creep[level], &inner)?;
        if pad > 0 {
            cur = cur.crop(pad, pad, n, n)?;
        }
        hf = Some(cur);
    }
    Ok(hf.expect("at least one level").crop(0, 0, size, size)?)
}

/// Adds ridged noise scaled by the local slope (rock ribs and gullies on
/// steep ground, nothing on flats). `amplitude_m` is the displacement at
/// slope 1; features are about `feature_m` across.
fn roughen(hf: &mut Heightfield, amplitude_m: f64, feature_m: f64, seed: u32) {
    let fine = Fractal {
        h: 1.0,
        octaves: 3,
        shape: Shape::Ridged,
        ..Fractal::new(seed, 1.0 / feature_m)
    };
    let centre = 0.75 * fine.amplitude_sum();
    let cell = hf.cell_size();
    let src = hf.clone();
    let w = hf.width();
    super::grid::sweep_add(hf.data_mut(), w, |x, y| {
        let (xi, yi) = (x as isize, y as isize);
        let gx = (src.get_clamped(xi + 1, yi) - src.get_clamped(xi - 1, yi)) as f64 / (2.0 * cell);
        let gy = (src.get_clamped(xi, yi + 1) - src.get_clamped(xi, yi - 1)) as f64 / (2.0 * cell);
        let slope = (gx * gx + gy * gy).sqrt();
        let (xm, ym) = ((x as f64 + 0.5) * cell, (y as f64 + 0.5) * cell);
        amplitude_m * slope * (fine.sample(xm, ym) - centre)
    });
}

/// The canyon style's range mapping: bias lifts most of the land onto the
/// plateau (the seed's "canyon" effect), terracing turns the valley sides
/// into treads and cliff bands; then metre-scale unevenness of the rock.
fn terrace_canyons(hf: &mut Heightfield, seed: u32) {
    const FLOOR_M: f64 = 1200.0;
    const DEPTH_M: f64 = 900.0;
    const STEPS: u32 = 5;
    /// Heights above `1/LIFT` of the range become one flat top: the highest
    /// ground ends in flat mesas instead of smooth summits.
    const LIFT: f64 = 1.08;
    const RISER: f64 = 0.2;
    /// Share of the unterraced surface kept, so treads are not dead flat.
    const TREAD_SLOPE: f64 = 0.1;
    remap::normalize(hf);
    remap::map(hf, |t| {
        let b = (remap::bias(0.65, t) * LIFT).min(1.0);
        let t = remap::terrace(b, STEPS, RISER) * (1.0 - TREAD_SLOPE) + b * TREAD_SLOPE;
        FLOOR_M + DEPTH_M * t
    });
    // metre-scale unevenness of the rock surfaces
    let texture = Fractal {
        h: 0.8,
        octaves: 4,
        ..Fractal::new(sub_seed(seed, 6), 1.0 / 600.0)
    };
    let w = hf.width();
    super::grid::sweep_add(hf.data_mut(), w, |x, y| {
        let (xm, ym) = (
            (x as f64 + 0.5) * CELL_SIZE_M,
            (y as f64 + 0.5) * CELL_SIZE_M,
        );
        6.0 * texture.sample(xm, ym)
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `data/styles.json` gives every style a recipe that [`evolve`] can
    /// index (at most 6 levels).
    #[test]
    fn every_style_has_a_recipe() {
        for style in Style::ALL {
            let r = Recipe::of(style);
            assert!((1..=6).contains(&r.levels), "{}", style.name());
        }
    }
}
