//! The report of a whole sweep: a text table and an SVG plot of the tip error against the noise
//! level (its `summary.json` is `sim_study::summary_json::sweep`'s).

use crate::plot::{Labels, Series, line_chart};
use sim_study::study::{Cell, Stats, SweepConfig};
use std::fmt::Write as _;
use std::path::Path;

/// Failed runs listed under the table; the rest are counted.
const LISTED_FAILURES: usize = 20;

/// The table: per cell, completed runs and the statistics of the tip and modal errors.
pub fn table(config: &SweepConfig, cells: &[Cell]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "sweep of {}: {} noise levels x {} controllers x {} seeds = {} runs, base seed {}, {} s each",
        // The user's text: a newline or U+202E in it must not break or reverse the table.
        crate::console::escape_field(&config.scenario.name),
        config.settings.noise_levels.len(),
        config.settings.controllers.len(),
        config.settings.seeds,
        cells.iter().map(|c| c.runs).sum::<usize>(),
        config.settings.base_seed,
        config.scenario.duration,
    );
    let names = config.scenario.coordinate_names();
    let rates: Vec<String> = names.iter().map(|n| format!("{n}_dot")).collect();
    let _ = writeln!(
        s,
        "noise level L: sensor noise std L rad on ({}), {} L rad/s on ({}), {} L rad on the reference",
        names.join(", "),
        config.settings.rate_noise_ratio,
        rates.join(", "),
        config.settings.reference_noise_ratio
    );
    let _ = write!(
        s,
        "{:>10} {:<16} {:>7} | {:^49} | {:^29}",
        "", "", "", "tip error RMS (mm)", "tip error max (mm)"
    );
    for name in &names {
        let _ = write!(s, " | {:^19}", format!("{name} error RMS (rad)"));
    }
    s.push('\n');
    let _ = write!(
        s,
        "{:>10} {:<16} {:>7} | {:>9} {:>9} {:>9} {:>9} {:>9} | {:>9} {:>9} {:>9}",
        "L (rad)",
        "controller",
        "ok/runs",
        "mean",
        "std",
        "min",
        "median",
        "max",
        "mean",
        "std",
        "max"
    );
    for _ in &names {
        let _ = write!(s, " | {:>9} {:>9}", "mean", "std");
    }
    s.push('\n');
    for c in cells {
        let _ = write!(
            s,
            "{:>10} {:<16} {:>7}",
            format!("{:.3e}", c.noise_level),
            c.controller.name(),
            format!("{}/{}", c.runs - c.failed, c.runs)
        );
        let cols = |s: &mut String,
                    stats: &Option<Stats>,
                    pick: &[fn(&Stats) -> f64],
                    fmt: fn(f64) -> String| {
            s.push_str(" |");
            for f in pick {
                let text = stats.as_ref().map_or("-".to_string(), |st| fmt(f(st)));
                let _ = write!(s, " {text:>9}");
            }
        };
        // Millimetres to four decimals; a value of a kilometre or more (a hand-edited shard's
        // 1e300 printed 300 digits) in scientific notation.
        let mm = |v: f64| {
            if v.abs() < 1e6 {
                format!("{v:.4}")
            } else {
                format!("{v:.3e}")
            }
        };
        let rad = |v: f64| format!("{v:.3e}");
        cols(
            &mut s,
            &c.tip_error_rms_mm,
            &[|t| t.mean, |t| t.std, |t| t.min, |t| t.median, |t| t.max],
            mm,
        );
        cols(
            &mut s,
            &c.tip_error_max_mm,
            &[|t| t.mean, |t| t.std, |t| t.max],
            mm,
        );
        for stats in &c.modal_error_rms_rad {
            cols(&mut s, stats, &[|t| t.mean, |t| t.std], rad);
        }
        s.push('\n');
    }
    let stopped: usize = cells.iter().map(|c| c.failed).sum();
    let failures: Vec<_> = cells
        .iter()
        .flat_map(|c| c.failures.iter().map(move |f| (c, f)))
        .take(LISTED_FAILURES)
        .collect();
    if stopped > 0 {
        let _ = writeln!(s, "{stopped} runs stopped before the end:");
        for (c, f) in &failures {
            let _ = writeln!(
                s,
                "  run {} ({}, L = {:.3e} rad, seed {}): {}",
                f.index,
                c.controller.name(),
                c.noise_level,
                f.seed,
                f.error
            );
        }
        if stopped > failures.len() {
            let _ = writeln!(
                s,
                "  ... and {} more (see summary.json and runs.json)",
                stopped - failures.len()
            );
        }
    }
    s
}

/// The plot: mean tip error RMS against the noise level per controller, with the band
/// mean ± one standard deviation drawn as a closed outline. `Ok(false)` when no cell has a
/// completed run (nothing to draw, no file written).
pub fn plot(path: &Path, config: &SweepConfig, cells: &[Cell]) -> Result<bool, String> {
    let mut means = Vec::new();
    let mut bands = Vec::new();
    for &controller in &config.settings.controllers {
        let stats: Vec<(f64, Stats)> = cells
            .iter()
            .filter(|c| c.controller == controller)
            .filter_map(|c| c.tip_error_rms_mm.map(|s| (c.noise_level, s)))
            .collect();
        if stats.is_empty() {
            continue;
        }
        means.push(Series {
            label: format!("{controller}: mean"),
            points: stats.iter().map(|(l, s)| (*l, s.mean)).collect(),
        });
        let upper = stats.iter().map(|(l, s)| (*l, s.mean + s.std));
        let lower = stats.iter().rev().map(|(l, s)| (*l, s.mean - s.std));
        let mut outline: Vec<(f64, f64)> = upper.chain(lower).collect();
        outline.push(outline[0]);
        bands.push(Series {
            label: format!("{controller}: mean ± std"),
            points: outline,
        });
    }
    if means.is_empty() {
        return Ok(false);
    }
    means.extend(bands);
    let title = format!(
        "{}: tip error RMS vs noise level ({} seeds)",
        config.scenario.name, config.settings.seeds
    );
    let labels = Labels {
        title: &title,
        x: "noise level: sensor noise std on the modal coordinates (rad)",
        y: "tip error RMS (mm)",
    };
    line_chart(path, &labels, &means, None)?;
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;
    use sim_study::Scenario;
    use sim_study::study::SweepSettings;

    #[test]
    fn a_huge_tip_error_is_written_in_scientific_notation() {
        // A hand-edited shard's 1e300 mm printed three hundred digits in one cell.
        let config = SweepConfig::new(
            Scenario::builtin("paper-tracking").unwrap(),
            SweepSettings::default(),
        )
        .unwrap();
        let huge = Stats::of(&[1e300]);
        let cell = Cell {
            noise_level: 0.0,
            controller: sim_study::ControllerKind::Pd,
            runs: 1,
            failed: 0,
            tip_error_rms_mm: huge,
            tip_error_max_mm: Stats::of(&[4.25]),
            modal_error_rms_rad: vec![Stats::of(&[1e-3]); 2],
            peak_joint_torque_nm: None,
            failures: Vec::new(),
        };
        let text = table(&config, &[cell]);
        assert!(
            text.contains("1.000e300") && text.contains("4.2500"),
            "{text}"
        );
        assert!(text.lines().all(|line| line.len() < 300), "{text}");
    }
}
