//! `eval --plot`: one picture of a comparison that a person reads at a
//! glance — a histogram panel per distribution descriptor (synthesis red,
//! reference black, the reference's halves blue and cyan: where red leaves
//! the bundle of black and blue, the synthesis is unlike the real terrain),
//! the radially averaged power spectra on log–log axes with the fit band
//! marked, a table of the scalar descriptors, and the realism ratio.

use super::compare::{Comparison, Reference};
use super::{DESCRIPTORS, Descriptors, Kind, Sample, Spectrum, Value};
use crate::render::font::{ADVANCE, GLYPH_HEIGHT, draw_text, text_width};
use crate::render::overlay::Canvas;
use image::{Rgba, RgbaImage};

const PANEL_W: u32 = 360;
const PANEL_H: u32 = 240;
const COLUMNS: u32 = 4;
const HEADER_H: u32 = 40;
/// Text scale: font pixels to image pixels.
const TEXT: u32 = 2;
/// Histogram bins over the shown range.
const BINS: usize = 60;

const WHITE: Rgba<u8> = Rgba([255, 255, 255, 255]);
const BLACK: Rgba<u8> = Rgba([0, 0, 0, 255]);
const GREY: Rgba<u8> = Rgba([150, 150, 150, 255]);
const SYNTH: Rgba<u8> = Rgba([214, 39, 40, 255]);
const LEFT: Rgba<u8> = Rgba([31, 119, 180, 255]);
const RIGHT: Rgba<u8> = Rgba([23, 190, 207, 255]);

/// The curves of one panel, drawn back to front: halves, reference, synthesis.
fn styles() -> [(Rgba<u8>, f64); 4] {
    [(LEFT, 1.5), (RIGHT, 1.5), (BLACK, 2.5), (SYNTH, 2.0)]
}

/// The picture of `cmp`, a comparison of `synth` with `reference`, under a
/// `title` (e.g. the file names).
pub fn plot(
    reference: &Reference,
    synth: &Descriptors,
    cmp: &Comparison,
    title: &str,
) -> RgbaImage {
    let rows = 2;
    let mut img = RgbaImage::from_pixel(COLUMNS * PANEL_W, HEADER_H + rows * PANEL_H, WHITE);
    let max_chars = (img.width() / (ADVANCE * TEXT)) as usize - 2;
    let title: String = title.chars().take(max_chars).collect();
    draw_text(&mut img, 12, 12, &title, TEXT, BLACK);
    let terrains = [&reference.left, &reference.right, &reference.whole, synth];
    let mut slot = 0;
    for (i, info) in DESCRIPTORS.iter().enumerate() {
        if info.kind != Kind::Distribution {
            continue;
        }
        let samples: Vec<&Sample> = terrains
            .iter()
            .map(|t| match &t.values[i] {
                Value::Distribution(s) => s,
                Value::Scalar(_) => unreachable!("kinds are fixed per descriptor"),
            })
            .collect();
        let heading = format!("{} R {:.2}", info.id, cmp.descriptors[i].ratio);
        if i == super::id::DRAINAGE {
            exceedance(&mut img, origin(slot), &heading, &samples);
        } else {
            histogram(&mut img, origin(slot), &heading, info.unit, &samples);
        }
        slot += 1;
    }
    let spectra: Vec<&Spectrum> = terrains.iter().map(|t| &t.spectrum).collect();
    spectrum_panel(&mut img, origin(slot), &spectra, cmp);
    scalar_panel(&mut img, origin(slot + 1), cmp);
    legend_panel(&mut img, origin(slot + 2), cmp);
    img
}

/// Top-left corner of panel `slot`.
fn origin(slot: u32) -> (u32, u32) {
    (
        (slot % COLUMNS) * PANEL_W,
        HEADER_H + (slot / COLUMNS) * PANEL_H,
    )
}

/// The plotting area of a panel: (x0, y0, width, height).
fn area((px, py): (u32, u32)) -> (f64, f64, f64, f64) {
    (
        px as f64 + 12.0,
        py as f64 + 34.0,
        PANEL_W as f64 - 24.0,
        PANEL_H as f64 - 70.0,
    )
}

/// The panel's frame, heading, and three labels under the axis.
fn frame(img: &mut RgbaImage, at: (u32, u32), heading: &str, below: [&str; 3]) {
    let (x0, y0, w, h) = area(at);
    let mut c = Canvas::new(img, 1.0, 1.0);
    c.polygon(
        &[(x0, y0), (x0 + w, y0), (x0 + w, y0 + h), (x0, y0 + h)],
        None,
        Some((GREY, 1.0)),
    );
    draw_text(img, x0 as i64, at.1 as i64 + 10, heading, TEXT, BLACK);
    let ty = (y0 + h) as i64 + 8;
    let (left, mid, right) = (below[0], below[1], below[2]);
    draw_text(img, x0 as i64, ty, left, TEXT, BLACK);
    let mw = text_width(mid, TEXT) as f64;
    draw_text(img, (x0 + (w - mw) / 2.0) as i64, ty, mid, TEXT, GREY);
    let rw = text_width(right, TEXT) as f64;
    draw_text(img, (x0 + w - rw) as i64, ty, right, TEXT, BLACK);
}

/// Short number for axis labels.
fn short(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if a >= 1000.0 {
        format!("{v:.0}")
    } else if a >= 1.0 {
        format!("{v:.1}")
    } else if a >= 0.01 {
        format!("{v:.3}")
    } else {
        format!("{v:.1e}")
    }
}

/// Density histograms of the samples over the synthesis's and reference's
/// 0.5–99.5 % range, as lines through the bin centres. The height is the
/// square root of the density, so that a large flat area (sea, a plain)
/// does not flatten the rest of the distribution into the axis.
fn histogram(img: &mut RgbaImage, at: (u32, u32), heading: &str, unit: &str, s: &[&Sample]) {
    let lo = s[2].quantile(0.005).min(s[3].quantile(0.005));
    let mut hi = s[2].quantile(0.995).max(s[3].quantile(0.995));
    if hi <= lo || hi.is_nan() {
        hi = lo + 1.0;
    }
    let (lo_s, hi_s) = (short(lo), short(hi));
    let mid = format!("{unit}, sqrt");
    frame(img, at, heading, [&lo_s, &mid, &hi_s]);
    let (x0, y0, w, h) = area(at);
    let step = (hi - lo) / BINS as f64;
    let densities: Vec<Vec<f64>> = s
        .iter()
        .map(|sample| {
            let v = sample.values();
            let edge = |k: usize| {
                let e = (lo + k as f64 * step) as f32;
                v.partition_point(|&x| x < e)
            };
            (0..BINS)
                .map(|k| ((edge(k + 1) - edge(k)) as f64 / v.len().max(1) as f64).sqrt())
                .collect()
        })
        .collect();
    let top = densities.iter().flatten().fold(0.0f64, |a, &b| a.max(b)) * 1.1;
    let mut c = Canvas::new(img, 1.0, 1.0);
    for (d, (colour, width)) in densities.iter().zip(styles()) {
        let pts: Vec<(f64, f64)> = d
            .iter()
            .enumerate()
            .map(|(k, &v)| {
                let x = x0 + (k as f64 + 0.5) / BINS as f64 * w;
                (x, y0 + h - v / top.max(f64::MIN_POSITIVE) * h)
            })
            .collect();
        c.polyline(&pts, width, colour);
    }
}

/// Drainage areas, whose histogram is a comb of small integers, as the
/// usual exceedance plot instead: log₁₀ P(A ≥ a) against log₁₀ a (a
/// channel network is close to a straight line here).
fn exceedance(img: &mut RgbaImage, at: (u32, u32), heading: &str, s: &[&Sample]) {
    let hi = s
        .iter()
        .filter_map(|x| x.values().last())
        .fold(0.0f64, |a, &b| a.max(b as f64))
        .max(1.0);
    let n_max = s.iter().map(|x| x.len()).max().unwrap_or(1).max(2) as f64;
    let bottom = -n_max.log10();
    let right = format!("1e{hi:.1}");
    frame(img, at, heading, ["1", "P(A>=a)", &right]);
    let (x0, y0, w, h) = area(at);
    let mut c = Canvas::new(img, 1.0, 1.0);
    const STEPS: usize = 120;
    for (sample, (colour, width)) in s.iter().zip(styles()) {
        let v = sample.values();
        let pts: Vec<(f64, f64)> = (0..=STEPS)
            .filter_map(|k| {
                let a = hi * k as f64 / STEPS as f64;
                let above = v.len() - v.partition_point(|&x| (x as f64) < a);
                (above > 0).then(|| {
                    let p = (above as f64 / v.len() as f64).log10();
                    (x0 + a / hi * w, y0 + p / bottom * h)
                })
            })
            .collect();
        c.polyline(&pts, width, colour);
    }
}

/// Log–log power spectra, with the fit band as two grey verticals.
fn spectrum_panel(img: &mut RgbaImage, at: (u32, u32), s: &[&Spectrum], cmp: &Comparison) {
    let beta = &cmp.descriptors[super::id::BETA];
    let heading = format!(
        "beta R {:.2} ({:.2} v {:.2})",
        beta.ratio, beta.synth, beta.reference
    );
    let f_lo = s
        .iter()
        .filter_map(|x| x.freq.first())
        .fold(f64::INFINITY, |a, &b| a.min(b));
    let (lx0, lx1) = (f_lo.log10(), (0.5f64 * 2f64.sqrt()).log10());
    let logs: Vec<f64> = s
        .iter()
        .flat_map(|x| x.power.iter().filter(|&&p| p > 0.0).map(|p| p.log10()))
        .collect();
    let ly0 = logs.iter().fold(f64::INFINITY, |a, &b| a.min(b));
    let ly1 = logs.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b));
    let long = format!("{:.0}", 1.0 / f_lo);
    frame(img, at, &heading, [&long, "wavelength cells", "1.4"]);
    if lx1 <= lx0 || ly1 <= ly0 || ly0.is_nan() || ly1.is_nan() {
        return;
    }
    let (x0, y0, w, h) = area(at);
    let px = |lf: f64| x0 + (lf - lx0) / (lx1 - lx0) * w;
    let mut c = Canvas::new(img, 1.0, 1.0);
    let band = s[2].band;
    for f in [band.0, band.1] {
        let x = px(f.log10());
        c.polyline(&[(x, y0), (x, y0 + h)], 1.0, GREY);
    }
    for (sp, (colour, width)) in s.iter().zip(styles()) {
        let pts: Vec<(f64, f64)> = sp
            .freq
            .iter()
            .zip(&sp.power)
            .filter(|&(_, &p)| p > 0.0)
            .map(|(&f, &p)| (px(f.log10()), y0 + h - (p.log10() - ly0) / (ly1 - ly0) * h))
            .collect();
        c.polyline(&pts, width, colour);
    }
}

/// The scalar descriptors and the extras as a small table.
fn scalar_panel(img: &mut RgbaImage, at: (u32, u32), cmp: &Comparison) {
    let mut lines = vec![format!("{:<8}{:>6}{:>7}{:>7}", "", "synth", "ref", "R")];
    for (info, d) in DESCRIPTORS.iter().zip(&cmp.descriptors) {
        if info.kind != Kind::Scalar {
            continue;
        }
        let (s, r) = if info.id == "pits" {
            (d.synth * 100.0, d.reference * 100.0)
        } else {
            (d.synth, d.reference)
        };
        let name = if info.id == "pits" { "pits %" } else { info.id };
        let name: String = name.chars().take(7).collect();
        lines.push(format!("{name:<8}{s:>6.2}{r:>7.2}{:>7.2}", d.ratio));
    }
    lines.push(String::new());
    lines.push(format!(
        "slope {:.1} / {:.1} deg",
        cmp.median_slope.synth, cmp.median_slope.reference
    ));
    lines.push(format!("relief kept {:.0} %", cmp.relief.ratio * 100.0));
    lines.push(format!("pits x {:.2}", cmp.pits.ratio));
    lines.push(format!(
        "closed {:.1} / {:.1} %",
        cmp.closed.synth * 100.0,
        cmp.closed.reference * 100.0
    ));
    let line_h = ((GLYPH_HEIGHT + 4) * TEXT) as i64;
    for (k, l) in lines.iter().enumerate() {
        draw_text(
            img,
            at.0 as i64 + 12,
            at.1 as i64 + 10 + k as i64 * line_h,
            l,
            TEXT,
            BLACK,
        );
    }
}

/// Which colour is which, and the realism ratio.
fn legend_panel(img: &mut RgbaImage, at: (u32, u32), cmp: &Comparison) {
    let (x, mut y) = (at.0 as i64 + 12, at.1 as i64 + 10);
    let ratio = format!("ratio {:.2}", cmp.ratio);
    draw_text(img, x, y, &ratio, 4, BLACK);
    y += (GLYPH_HEIGHT * 4) as i64 + 8;
    draw_text(img, x, y, "1 = as unlike as", TEXT, GREY);
    y += (GLYPH_HEIGHT * TEXT) as i64 + 6;
    draw_text(img, x, y, "the real halves", TEXT, GREY);
    y += (GLYPH_HEIGHT * TEXT) as i64 + 14;
    let names = ["left half", "right half", "reference", "synthesis"];
    for (name, (colour, width)) in names.iter().zip(styles()) {
        let mid = (y + (GLYPH_HEIGHT * TEXT) as i64 / 2) as f64;
        Canvas::new(img, 1.0, 1.0).polyline(
            &[(x as f64, mid), (x as f64 + 40.0, mid)],
            width + 1.0,
            colour,
        );
        draw_text(img, x + 52, y, name, TEXT, BLACK);
        y += (GLYPH_HEIGHT * TEXT) as i64 + 10;
    }
}
