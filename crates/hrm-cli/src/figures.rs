//! The paper's figures (section 5) as SVG files, one function per figure: modal responses
//! (Figure 9), backbone configurations over the tracked path (Figure 10), the tracking residual
//! (Figure 11), and the fuzzy controller's membership functions and control surfaces.

use crate::figure_parts::{self, snapshot_samples};
use crate::fis_cmd;
use crate::plot::{self, Labels};
use sim_core::{Record, Run};
use sim_study::{ControllerKind, Scenario};
use std::path::{Path, PathBuf};

/// Figure 9: every modal coordinate `a_i(t)` (named `names`) of every run against the
/// reference, one panel each.
pub fn modal_responses(
    path: &Path,
    scenario: &str,
    names: &[String],
    runs: &[(ControllerKind, &Run)],
) -> Result<(), String> {
    // No more panels than the runs have coordinates.
    let n_coords = runs.first().map_or(0, |(_, run)| run.record.n_coords);
    let rows = names
        .iter()
        .take(n_coords)
        .enumerate()
        .map(|(i, name)| {
            let series = figure_parts::against_reference(
                path,
                runs,
                |r, k| r.a_at(k)[i],
                |r, k| r.a_ref_at(k)[i],
            )?;
            Ok((format!("{name} (rad)"), series))
        })
        .collect::<Result<Vec<_>, String>>()?;
    figure_parts::over_time(path, &format!("Modal coordinates, {scenario}"), &rows)
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
    let arms: Vec<(usize, Vec<[f64; 3]>)> = configurations(scenario, record, every_s)?
        .into_iter()
        .map(|c| (c.k, c.joints.iter().map(|p| [p[0], p[1], 0.0]).collect()))
        .collect();
    let curves = figure_parts::backbone_curves(record, &arms, |p| (p[0], p[1]));
    let title = figure_parts::backbone_title(every_s, &scenario.name, controller);
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
    let series = figure_parts::run_series(runs, |r, k| 1e3 * tip_error(r, k));
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
    let (tip, reference) = (
        figure_parts::tip(record, k),
        figure_parts::tip_ref(record, k),
    );
    (tip[0] - reference[0])
        .hypot(tip[1] - reference[1])
        .hypot(tip[2] - reference[2])
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
}
