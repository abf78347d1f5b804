//! What the planar and the spatial figures of runs share: a record thinned to a drawable number
//! of points, the samples drawn as arm snapshots, the curves of a backbone figure, one series per
//! run (with or without the reference), and panels stacked over time.

use crate::plot::{self, Panel, Series, Style};
use sim_core::{Record, Run};
use sim_study::ControllerKind;
use std::path::Path;

/// At most this many points per curve: enough for a smooth line, small enough for a light SVG.
const MAX_POINTS: usize = 1500;

/// `point(record, k)` at no more than [`MAX_POINTS`] evenly strided samples, the last included.
pub fn thin(record: &Record, point: impl Fn(&Record, usize) -> (f64, f64)) -> Vec<(f64, f64)> {
    let n = record.len();
    let stride = n.div_ceil(MAX_POINTS).max(1);
    let mut points: Vec<_> = (0..n).step_by(stride).map(|k| point(record, k)).collect();
    if n > 0 && !(n - 1).is_multiple_of(stride) {
        points.push(point(record, n - 1));
    }
    points
}

/// The samples of `record` drawn every `every_s` seconds: the first, then the first at or after
/// each multiple, and the last.
pub fn snapshot_samples(record: &Record, every_s: f64) -> Result<Vec<usize>, String> {
    if !(every_s.is_finite() && every_s > 0.0) {
        return Err(format!(
            "the interval between configurations must be positive, got {every_s}"
        ));
    }
    let mut picked = Vec::new();
    let mut next = f64::NEG_INFINITY;
    for (k, &t) in record.t.iter().enumerate() {
        if t >= next || k + 1 == record.len() {
            picked.push(k);
            next = ((t / every_s + 1e-9).floor() + 1.0) * every_s;
        }
    }
    Ok(picked)
}

/// The tip at sample `k` of `record`, `[x, y, z]` (`z = 0` in the plane).
pub fn tip(record: &Record, k: usize) -> [f64; 3] {
    [record.tip[k][0], record.tip[k][1], record.tip_z[k]]
}

/// The reference tip at sample `k` of `record`, `[x, y, z]` (`z = 0` in the plane).
pub fn tip_ref(record: &Record, k: usize) -> [f64; 3] {
    [
        record.tip_ref[k][0],
        record.tip_ref[k][1],
        record.tip_ref_z[k],
    ]
}

/// The title of a backbone figure: the arm of `scenario` with `controller` every `every_s` s.
pub fn backbone_title(every_s: f64, scenario: &str, controller: ControllerKind) -> String {
    format!(
        "Backbone every {every_s} s, {scenario} with {}",
        controller.name()
    )
}

/// The curves of one view of a backbone figure, every point through `project`: the arm at each
/// snapshot `(k, joints)` of `record` (light to dark blue with time, dots at the joints, the
/// first and the last labelled with their time), then the reference path (red) and the tip's
/// path (green).
pub fn backbone_curves(
    record: &Record,
    arms: &[(usize, Vec<[f64; 3]>)],
    project: impl Fn([f64; 3]) -> (f64, f64),
) -> Vec<(Series, Style)> {
    let last = arms.len().saturating_sub(1).max(1) as f64;
    let mut curves: Vec<(Series, Style)> = arms
        .iter()
        .enumerate()
        .map(|(i, (k, joints))| {
            let shade = |light: f64, dark: f64| (light + (dark - light) * i as f64 / last) as u8;
            let label = if i == 0 || i + 1 == arms.len() {
                format!("arm at t = {:.1} s", record.t[*k])
            } else {
                String::new()
            };
            let series = Series {
                label,
                points: joints.iter().map(|&p| project(p)).collect(),
            };
            let style = Style {
                colour: (shade(170.0, 10.0), shade(200.0, 40.0), shade(240.0, 140.0)),
                width: 2,
                dots: true,
            };
            (series, style)
        })
        .collect();
    let path = |label: &str, point: fn(&Record, usize) -> [f64; 3], colour, width| {
        let series = Series {
            label: label.into(),
            points: thin(record, |r, k| project(point(r, k))),
        };
        let style = Style {
            colour,
            width,
            dots: false,
        };
        (series, style)
    };
    curves.push(path("reference path", tip_ref, (220, 30, 30), 3));
    curves.push(path("tip", tip, (20, 150, 60), 1));
    curves
}

/// One series per run, labelled with its controller's name: `value(record, k)` over time.
pub fn run_series(
    runs: &[(ControllerKind, &Run)],
    value: impl Fn(&Record, usize) -> f64,
) -> Vec<Series> {
    runs.iter()
        .map(|(kind, run)| Series {
            label: kind.name().into(),
            points: thin(&run.record, |r, k| (r.t[k], value(r, k))),
        })
        .collect()
}

/// Every run's `value(record, k)` over time, then the first run's `reference(record, k)`, last
/// so that it is drawn on top of a controller that tracks it exactly. No runs is an error
/// naming `path`, the figure's file.
pub fn against_reference(
    path: &Path,
    runs: &[(ControllerKind, &Run)],
    value: impl Fn(&Record, usize) -> f64,
    reference: impl Fn(&Record, usize) -> f64,
) -> Result<Vec<Series>, String> {
    let (_, first) = runs
        .first()
        .ok_or_else(|| format!("{}: no runs to plot", path.display()))?;
    let mut series = run_series(runs, value);
    series.push(Series {
        label: "reference".into(),
        points: thin(&first.record, |r, k| (r.t[k], reference(r, k))),
    });
    Ok(series)
}

/// Writes one panel per `(vertical axis label, curves)` row, stacked over the shared axis
/// `t (s)` under `title`, to the SVG file `path`.
pub fn over_time(path: &Path, title: &str, rows: &[(String, Vec<Series>)]) -> Result<(), String> {
    let panels: Vec<Panel<'_>> = rows
        .iter()
        .map(|(y, series)| Panel {
            y,
            series,
            y_range: None,
        })
        .collect();
    plot::stacked_line_charts(path, title, "t (s)", &panels)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thinning_keeps_the_ends_and_bounds_the_count() {
        let record = Record {
            t: (0..4000).map(|k| k as f64).collect(),
            ..Record::default()
        };
        let points = thin(&record, |r, k| (r.t[k], 0.0));
        assert!(points.len() <= MAX_POINTS + 1);
        assert_eq!(points[0].0, 0.0);
        assert_eq!(points.last().unwrap().0, 3999.0);
        let short = Record {
            t: vec![0.0, 1.0],
            ..Record::default()
        };
        assert_eq!(thin(&short, |r, k| (r.t[k], 0.0)).len(), 2);
    }
}
