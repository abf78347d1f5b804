//! The paper's figures (section 5) as SVG files, one function per figure: modal responses
//! (Figure 9), backbone configurations over the tracked path (Figure 10), the tracking residual
//! (Figure 11), and the fuzzy controller's membership functions and control surfaces.

use crate::fis_cmd;
use crate::plot::{self, Labels, Panel, Series, Style};
use sim_core::{Record, Run};
use sim_study::{ControllerKind, Scenario};
use std::path::{Path, PathBuf};

/// At most this many points per curve: enough for a smooth line, small enough for a light SVG.
const MAX_POINTS: usize = 1500;

/// Figure 9: every modal coordinate `a_i(t)` (named `names`) of every run against the
/// reference, one panel each.
pub fn modal_responses(
    path: &Path,
    scenario: &str,
    names: &[String],
    runs: &[(ControllerKind, &Run)],
) -> Result<(), String> {
    let first = runs
        .first()
        .ok_or_else(|| format!("{}: no runs to plot", path.display()))?;
    let coordinate = |i: usize| {
        let reference = Series {
            label: "reference".into(),
            points: thin(&first.1.record, |r, k| (r.t[k], r.a_ref_at(k)[i])),
        };
        let controllers = runs.iter().map(|(kind, run)| Series {
            label: kind.name().into(),
            points: thin(&run.record, |r, k| (r.t[k], r.a_at(k)[i])),
        });
        // The reference last, so that it is drawn on top of a controller that tracks it exactly.
        controllers
            .chain(std::iter::once(reference))
            .collect::<Vec<_>>()
    };
    let series: Vec<Vec<Series>> = (0..first.1.record.n_coords).map(coordinate).collect();
    let labels: Vec<String> = names.iter().map(|name| format!("{name} (rad)")).collect();
    let panels: Vec<Panel> = series
        .iter()
        .zip(&labels)
        .map(|(series, y)| Panel {
            y,
            series,
            y_range: None,
        })
        .collect();
    plot::stacked_line_charts(
        path,
        &format!("Modal coordinates, {scenario}"),
        "t (s)",
        &panels,
    )
}

/// One drawn arm configuration: sample `k` of a record, with every joint position from the base
/// (the origin) to the tip.
pub struct Configuration {
    /// The record's sample index.
    pub k: usize,
    /// `n + 1` joint positions (m), base first, tip last.
    pub joints: Vec<[f64; 2]>,
}

/// The arm's joint positions every `every_s` seconds of `record` (the first sample, then the
/// first sample at or after each multiple, and the last sample), from the recorded `a(t)`
/// through the scenario's modal map (eq 8, with its `alpha0`) and link lengths.
pub fn configurations(
    scenario: &Scenario,
    record: &Record,
    every_s: f64,
) -> Result<Vec<Configuration>, String> {
    let picked = snapshot_samples(record, every_s)?;
    let model = scenario.model().map_err(|e| e.to_string())?;
    let lengths: Vec<f64> = model.chain().link_lengths().collect();
    let mut theta = vec![0.0; lengths.len()];
    picked
        .into_iter()
        .map(|k| {
            model
                .map()
                .joint_angles(record.a_at(k), &mut theta)
                .map_err(|e| e.to_string())?;
            let mut joints = vec![[0.0; 2]; lengths.len() + 1];
            backbone_kin::joint_positions(&lengths, &theta, &mut joints)
                .map_err(|e| e.to_string())?;
            Ok(Configuration { k, joints })
        })
        .collect()
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

/// Figure 10: the arm's configurations every `every_s` seconds (light to dark with time, joints
/// as dots) over the reference path and the tip's actual path, base at the origin, equal scales.
pub fn backbone_over_path(
    path: &Path,
    scenario: &Scenario,
    controller: ControllerKind,
    run: &Run,
    every_s: f64,
) -> Result<(), String> {
    let record = &run.record;
    let configurations = configurations(scenario, record, every_s)?;
    let last = configurations.len().saturating_sub(1).max(1) as f64;
    let mut curves: Vec<(Series, Style)> = configurations
        .iter()
        .enumerate()
        .map(|(i, c)| {
            // From light to dark blue as time goes on.
            let shade = |light: f64, dark: f64| (light + (dark - light) * i as f64 / last) as u8;
            let label = if i == 0 || i + 1 == configurations.len() {
                format!("arm at t = {:.1} s", record.t[c.k])
            } else {
                String::new()
            };
            let series = Series {
                label,
                points: c.joints.iter().map(|p| (p[0], p[1])).collect(),
            };
            let style = Style {
                colour: (shade(170.0, 10.0), shade(200.0, 40.0), shade(240.0, 140.0)),
                width: 2,
                dots: true,
            };
            (series, style)
        })
        .collect();
    curves.push((
        Series {
            label: "reference path".into(),
            points: thin(record, |r, k| (r.tip_ref[k][0], r.tip_ref[k][1])),
        },
        Style {
            colour: (220, 30, 30),
            width: 3,
            dots: false,
        },
    ));
    curves.push((
        Series {
            label: "tip".into(),
            points: thin(record, |r, k| (r.tip[k][0], r.tip[k][1])),
        },
        Style {
            colour: (20, 150, 60),
            width: 1,
            dots: false,
        },
    ));
    let title = format!(
        "Backbone every {every_s} s, {} with {}",
        scenario.name,
        controller.name()
    );
    plot::xy_chart(
        path,
        &Labels {
            title: &title,
            x: "x (m)",
            y: "y (m)",
        },
        &curves,
    )
}

/// Figure 11: the tracking residual, the distance from the tip to the reference tip (mm), of
/// every run over time.
pub fn tracking_residual(
    path: &Path,
    scenario: &str,
    runs: &[(ControllerKind, &Run)],
) -> Result<(), String> {
    let series: Vec<Series> = runs
        .iter()
        .map(|(kind, run)| Series {
            label: kind.name().into(),
            points: thin(&run.record, |r, k| (r.t[k], 1e3 * tip_error(r, k))),
        })
        .collect();
    let title = format!("Tracking residual, {scenario}");
    plot::line_chart(
        path,
        &Labels {
            title: &title,
            x: "t (s)",
            y: "|tip - reference| (mm)",
        },
        &series,
        None,
    )
}

/// The paper's fuzzy controller (eqs 22-24, Table 1): the membership functions of every input,
/// then `tau1` over `(da1, a1_dot)` and `tau2` over `(da2, a2_dot)` with the other inputs at zero,
/// written into `dir`; returns the paths.
pub fn fuzzy_controller(dir: &Path, resolution: usize) -> Result<Vec<PathBuf>, String> {
    let system = fuzzy_sugeno::paper_controller();
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let names = fis_cmd::PlotNames::new(&system);
    let mut written = system
        .inputs()
        .iter()
        .zip(&names.inputs)
        .map(|(input, name)| fis_cmd::membership_chart(input, name, dir))
        .collect::<Result<Vec<_>, _>>()?;
    let zero = vec![0.0; system.inputs().len()];
    // Inputs: da1, da2, a1_dot, a2_dot; outputs: tau1, tau2.
    for (pair, output) in [([0, 2], 0), ([1, 3], 1)] {
        written.push(fis_cmd::surface_chart(
            &system, pair, output, &zero, resolution, &names, dir,
        )?);
    }
    Ok(written)
}

/// The distance from the tip to the reference tip at sample `k` (m), in space (`z = 0` in the
/// plane, where `hypot(d, 0) = |d|`).
fn tip_error(record: &Record, k: usize) -> f64 {
    let (tip, reference) = (record.tip[k], record.tip_ref[k]);
    (tip[0] - reference[0])
        .hypot(tip[1] - reference[1])
        .hypot(record.tip_z[k] - record.tip_ref_z[k])
}

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

#[cfg(test)]
mod tests {
    use super::*;

    /// A shortened shipped scenario run with `kind`.
    fn short_run(name: &str, duration: f64, kind: ControllerKind) -> (Scenario, Run) {
        let mut scenario = Scenario::builtin(name).unwrap();
        scenario.duration = duration;
        scenario.controller.kind = kind;
        let run = scenario.build().unwrap().run().unwrap();
        (scenario, run)
    }

    fn temp_dir(tag: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("hrm-figures-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// Coloured polylines: curves and their legend entries (axes and ticks are black).
    fn coloured_lines(svg: &str) -> usize {
        svg.matches("<polyline").count().saturating_sub(
            svg.matches("<polyline fill=\"none\" opacity=\"1\" stroke=\"#000000\"")
                .count(),
        )
    }

    /// Whether `svg` has a text element reading exactly `label`.
    fn has_text(svg: &str, label: &str) -> bool {
        svg.lines().any(|line| line.trim() == label)
    }

    fn svg(path: &Path) -> String {
        let text = std::fs::read_to_string(path).unwrap();
        assert!(text.starts_with("<svg") && text.trim_end().ends_with("</svg>"));
        text
    }

    #[test]
    fn backbone_joints_end_at_the_recorded_tip_and_start_at_the_base() {
        let (scenario, run) = short_run("paper-tracking", 0.25, ControllerKind::Fuzzy);
        let record = &run.record;
        let picked = configurations(&scenario, record, 0.1).unwrap();
        let times: Vec<f64> = picked.iter().map(|c| record.t[c.k]).collect();
        // Samples at 0, 0.1, 0.2 s and the last one.
        assert_eq!(times.len(), 4, "{times:?}");
        for (t, expected) in times.iter().zip([0.0, 0.1, 0.2]) {
            assert!((t - expected).abs() < 1e-9, "{times:?}");
        }
        assert_eq!(picked.last().unwrap().k, record.len() - 1);
        for c in &picked {
            assert_eq!(c.joints.len(), 11);
            assert_eq!(c.joints[0], [0.0, 0.0]);
            let tip = c.joints[10];
            for axis in 0..2 {
                assert!(
                    (tip[axis] - record.tip[c.k][axis]).abs() <= 1e-12,
                    "t = {}: {tip:?} vs {:?}",
                    record.t[c.k],
                    record.tip[c.k]
                );
            }
            // Every link keeps its length (0.1 m).
            for w in c.joints.windows(2) {
                let length = (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]);
                assert!((length - 0.1).abs() < 1e-12);
            }
        }
        // At rest at the path's first point, the tip is on y = 0.4 sin(5x) + 0.2.
        let start = picked[0].joints[10];
        assert!((start[1] - (0.4 * (5.0 * start[0]).sin() + 0.2)).abs() < 1e-6);
        assert!(configurations(&scenario, record, 0.0).is_err());
    }

    #[test]
    fn each_figure_is_an_svg_with_its_curves() {
        let dir = temp_dir("each");
        let kinds = [ControllerKind::Fuzzy, ControllerKind::ComputedTorque];
        let tracking: Vec<_> = kinds
            .iter()
            .map(|&kind| short_run("paper-tracking", 0.2, kind))
            .collect();
        let runs: Vec<_> = kinds
            .iter()
            .copied()
            .zip(tracking.iter().map(|(_, r)| r))
            .collect();
        let (step_scenario, step) = short_run("paper-responses-step", 0.2, ControllerKind::Pd);

        let fig9 = dir.join("fig9.svg");
        let names = ["a1".to_string(), "a2".to_string()];
        modal_responses(
            &fig9,
            "paper-responses-step",
            &names,
            &[(ControllerKind::Pd, &step)],
        )
        .unwrap();
        let text = svg(&fig9);
        // Two panels, each with the reference and one controller, and their legends.
        assert_eq!(coloured_lines(&text), 2 * 2 + 2 * 2);
        assert!(
            ["a1 (rad)", "a2 (rad)", "pd", "reference"]
                .iter()
                .all(|label| has_text(&text, label))
        );

        let fig10 = dir.join("fig10.svg");
        backbone_over_path(
            &fig10,
            &tracking[0].0,
            ControllerKind::Fuzzy,
            runs[0].1,
            0.1,
        )
        .unwrap();
        let text = svg(&fig10);
        let arms = configurations(&tracking[0].0, &runs[0].1.record, 0.1)
            .unwrap()
            .len();
        // One polyline per arm, the path and the tip, plus 4 legend entries; a dot per joint.
        assert_eq!(coloured_lines(&text), arms + 2 + 4);
        assert!(text.matches("<circle").count() >= arms * 11);
        assert!(has_text(&text, "reference path") && has_text(&text, "tip"));

        let fig11 = dir.join("fig11.svg");
        tracking_residual(&fig11, "paper-tracking", &runs).unwrap();
        let text = svg(&fig11);
        assert_eq!(coloured_lines(&text), 2 * 2);
        assert!(has_text(&text, "computed-torque") && has_text(&text, "|tip - reference| (mm)"));

        let fuzzy = fuzzy_controller(&dir.join("fuzzy"), 11).unwrap();
        let names: Vec<_> = fuzzy
            .iter()
            .map(|p| p.file_name().unwrap().to_str().unwrap().to_owned())
            .collect();
        assert_eq!(
            names,
            [
                "mf_da1.svg",
                "mf_da2.svg",
                "mf_a1_dot.svg",
                "mf_a2_dot.svg",
                "surface_tau1_da1_a1_dot.svg",
                "surface_tau2_da2_a2_dot.svg"
            ]
        );
        assert_eq!(coloured_lines(&svg(&fuzzy[0])), 2 * 2);
        assert!(svg(&fuzzy[4]).matches("<rect").count() >= 11 * 11);

        // Unwritable destinations are errors naming the path.
        let blocked = dir.join("fig9.svg").join("inside-a-file.svg");
        let err =
            modal_responses(&blocked, "s", &names, &[(ControllerKind::Pd, &step)]).unwrap_err();
        assert!(err.contains("inside-a-file.svg"), "{err}");
        let err = fuzzy_controller(&blocked, 11).unwrap_err();
        assert!(err.contains("inside-a-file.svg"), "{err}");
        assert!(modal_responses(&fig9, "s", &names, &[]).is_err());
        drop(step_scenario);
        std::fs::remove_dir_all(&dir).unwrap();
    }

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
