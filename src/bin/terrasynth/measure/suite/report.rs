//! The protocol's table for a person (`--json` prints the report itself).

use super::SuiteReport;
use super::dem::{TARGET_COPY_POINTS, TARGET_PITS, TARGET_RATIO, TARGET_RELIEF, TARGET_SLOPE};
use crate::measure::eval::print_type_usage;
use terrasynth::eval::DESCRIPTORS;

fn mark(ok: bool) -> &'static str {
    if ok { "✓" } else { "✗" }
}

pub(super) fn print_report(r: &SuiteReport) {
    println!(
        "realism protocol: {} DEMs, seeds {:?}, jitter {}, {} passes, {}-px pieces; medians over seeds",
        r.dems.len(),
        r.seeds,
        r.jitter,
        r.passes,
        r.piece_size
    );
    println!(
        "{:<26} {:>9} {:>7} {:>6} {:>5}  {:>20}  {:>7}  {:>22}  {:>17}  {:>15} {:>7}  targets",
        "DEM",
        "size",
        "cell m",
        "ratio",
        "real",
        "median slope real→synth",
        "relief",
        "pits real→synth",
        "closed real→syn",
        "copies real→syn",
        "repeats",
    );
    for d in &r.dems {
        let m = &d.median;
        let t = &d.targets;
        println!(
            "{:<26} {:>9} {:>7.1} {:>6.2} {:>5.2}  {:>6.1}° → {:>5.1}° ({:>3.0} %)  {:>6.0} %  {:>5.2} % → {:>5.2} % ({:>4.2}×)  {:>17}  {:>15} {:>7}  {}{}{}{}{}",
            d.name,
            format!("{}x{}", d.width, d.height),
            d.cell_size_m,
            m.ratio,
            d.baseline,
            m.median_slope_real,
            m.median_slope_synth,
            m.slope_ratio * 100.0,
            m.relief_kept * 100.0,
            m.pits_real * 100.0,
            m.pits_synth * 100.0,
            m.pits_ratio,
            format!(
                "{:.1} % → {:.1} %",
                m.closed_real * 100.0,
                m.closed_synth * 100.0
            ),
            match (d.copy_baseline, m.copy_share) {
                (Some(b), Some(c)) => format!("{:.0} % → {:.0} %", b * 100.0, c * 100.0),
                _ => "-".into(),
            },
            m.repetition
                .map(|r| format!("{:.0} %", r * 100.0))
                .unwrap_or_else(|| "-".into()),
            mark(t.ratio),
            mark(t.slope),
            mark(t.relief),
            mark(t.pits),
            t.copies.map(mark).unwrap_or("")
        );
    }
    println!(
        "real: the DEM's top half against its bottom half, in the same units (real terrain against itself)"
    );
    println!(
        "closed: share of the area more than {} m below its spill level (water with no valley out), the DEM → the synthesis; not a target",
        terrasynth::eval::drainage::CLOSED_DEPTH_M
    );
    println!(
        "copies: share of 64-px windows matching the DEM at NCC ≥ 0.95 in any orientation, its halves → the synthesis; repeats: windows with a near-duplicate elsewhere in the synthesis"
    );
    println!(
        "targets (issues 14, 46): ratio ≤ {TARGET_RATIO}, median slope within {:.0} %, relief ≥ {:.0} %, pits ≤ {TARGET_PITS}×, copies ≤ the halves' + {:.0} points",
        TARGET_SLOPE * 100.0,
        TARGET_RELIEF * 100.0,
        TARGET_COPY_POINTS * 100.0
    );
    println!();
    print!("{:<26}", "descriptor ratios");
    for d in &DESCRIPTORS {
        print!(" {:>11}", d.id);
    }
    println!();
    for d in &r.dems {
        print!("{:<26}", d.name);
        for info in &DESCRIPTORS {
            print!(" {:>11.2}", d.median.descriptors[info.id]);
        }
        println!();
    }
    if let Some(t) = &r.typed {
        println!();
        println!(
            "type usage: typed database of {} DEMs, {}x{}, median over seeds",
            t.exemplars.len(),
            t.size[0],
            t.size[1]
        );
        println!(
            "  {:<24} {:>8} {:>10} {:>8}",
            "type", "output", "exemplars", "points"
        );
        for (name, used, ex) in &t.median {
            println!(
                "  {:<24} {:>7.1}% {:>9.1}% {:>+8.1}",
                name,
                used * 100.0,
                ex * 100.0,
                (used - ex) * 100.0
            );
        }
        if let Some((seed, u)) = t.seeds.first() {
            println!("seed {seed} in detail:");
            print_type_usage(u);
        }
    }
    println!();
    println!("wall time {:.1} s on {} threads", r.wall_s, r.threads);
}
