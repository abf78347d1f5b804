//! The figures of a spatial arm's runs as SVG files, one function per figure: the backbone in
//! space at snapshots (two orthogonal projections and an oblique view), the tip's coordinates
//! against the reference, and per-coordinate modal errors and efforts.

use crate::figure_parts::{self, snapshot_samples, tip, tip_ref};
use crate::plot::{self, Labels, Series, Style};
use sim_core::Run;
use sim_study::{ControllerKind, Scenario};
use std::path::Path;

/// Azimuth of the oblique view's camera about `z` from the `x` axis (degrees).
const OBLIQUE_AZIMUTH_DEG: f64 = -50.0;
/// Elevation of the oblique view's camera above the `x-y` plane (degrees).
const OBLIQUE_ELEVATION_DEG: f64 = 25.0;

/// A view of the scene: its title, axis labels and the projection of a point onto its plane.
struct View {
    title: &'static str,
    x: &'static str,
    y: &'static str,
    project: fn([f64; 3]) -> (f64, f64),
}

/// The top view (`x-y`), the side view (`x-z`), and the oblique view: the orthographic
/// projection onto the camera's right and up directions for a camera at
/// [`OBLIQUE_AZIMUTH_DEG`] and [`OBLIQUE_ELEVATION_DEG`].
const VIEWS: [View; 3] = [
    View {
        title: "top view (x-y)",
        x: "x (m)",
        y: "y (m)",
        project: |p| (p[0], p[1]),
    },
    View {
        title: "side view (x-z)",
        x: "x (m)",
        y: "z (m)",
        project: |p| (p[0], p[2]),
    },
    View {
        title: "oblique view",
        x: "right (m)",
        y: "up (m)",
        project: oblique,
    },
];

/// The oblique view's coordinates of `p`: along the camera's right `(-sin az, cos az, 0)` and up
/// `(-sin el cos az, -sin el sin az, cos el)`.
fn oblique(p: [f64; 3]) -> (f64, f64) {
    let (sa, ca) = OBLIQUE_AZIMUTH_DEG.to_radians().sin_cos();
    let (se, ce) = OBLIQUE_ELEVATION_DEG.to_radians().sin_cos();
    (
        -sa * p[0] + ca * p[1],
        -se * ca * p[0] - se * sa * p[1] + ce * p[2],
    )
}

/// The backbone in space every `every_s` seconds of the run (the chain's joints from the
/// recorded `a(t)` through the modal map and the universal-joint chain's forward kinematics,
/// light to dark with time), with the reference path and the tip's path, in three views side by
/// side: from above, from the side and oblique, each with equal scales.
pub fn backbone_in_space(
    path: &Path,
    scenario: &Scenario,
    controller: ControllerKind,
    run: &Run,
    every_s: f64,
) -> Result<(), String> {
    let record = &run.record;
    let model = scenario.spatial_model().map_err(|e| e.to_string())?;
    let map = model.map();
    let mut theta = vec![0.0; map.n_joints()];
    let picked = snapshot_samples(record, every_s)?;
    let arms = picked
        .iter()
        .map(|&k| {
            map.joint_angles(record.a_at(k), &mut theta)
                .map_err(|e| e.to_string())?;
            let mut joints = vec![[0.0; 3]; model.n_links() + 1];
            backbone_kin::spatial_joint_positions(
                map.link_lengths(),
                model.base(),
                &theta,
                &mut joints,
            )
            .map_err(|e| e.to_string())?;
            Ok((k, joints))
        })
        .collect::<Result<Vec<_>, String>>()?;
    let views: Vec<(Labels<'_>, Vec<(Series, Style)>)> = VIEWS
        .iter()
        .map(|view| {
            let labels = Labels {
                title: view.title,
                x: view.x,
                y: view.y,
            };
            (
                labels,
                figure_parts::backbone_curves(record, &arms, view.project),
            )
        })
        .collect();
    let title = figure_parts::backbone_title(every_s, &scenario.name, controller);
    plot::xy_views(path, &title, &views)
}

/// The tip's `x`, `y` and `z` over time for every run against the reference, one panel each.
pub fn tip_paths(
    path: &Path,
    scenario: &str,
    runs: &[(ControllerKind, &Run)],
) -> Result<(), String> {
    let rows = ["tip x (m)", "tip y (m)", "tip z (m)"]
        .into_iter()
        .enumerate()
        .map(|(d, y)| {
            let series = figure_parts::against_reference(
                path,
                runs,
                |r, k| tip(r, k)[d],
                |r, k| tip_ref(r, k)[d],
            )?;
            Ok((y.to_owned(), series))
        })
        .collect::<Result<Vec<_>, String>>()?;
    figure_parts::over_time(
        path,
        &format!("Tip against the reference, {scenario}"),
        &rows,
    )
}

/// What [`per_coordinate`] draws of coordinate `i` at sample `k`.
#[derive(Debug, Clone, Copy)]
pub enum CoordinateSeries {
    /// The modal error `a_i - a_i_ref` (mrad).
    Error,
    /// The modal force `tau_i*` (N m).
    Effort,
}

/// Per modal coordinate (named `names`), one panel of every run's error or effort over time.
pub fn per_coordinate(
    path: &Path,
    scenario: &str,
    names: &[String],
    runs: &[(ControllerKind, &Run)],
    what: CoordinateSeries,
) -> Result<(), String> {
    let rows: Vec<(String, Vec<Series>)> = names
        .iter()
        .enumerate()
        .map(|(i, name)| match what {
            CoordinateSeries::Error => (
                format!("{name} - ref (mrad)"),
                figure_parts::run_series(runs, |r, k| 1e3 * (r.a_at(k)[i] - r.a_ref_at(k)[i])),
            ),
            CoordinateSeries::Effort => (
                format!("tau*_{name} (N m)"),
                figure_parts::run_series(runs, |r, k| r.tau_star_at(k)[i]),
            ),
        })
        .collect();
    let title = match what {
        CoordinateSeries::Error => format!("Modal errors, {scenario}"),
        CoordinateSeries::Effort => format!("Modal forces tau*, {scenario}"),
    };
    figure_parts::over_time(path, &title, &rows)
}

#[cfg(test)]
mod tests {
    use super::*;
    use sim_study::study::run_one;

    #[test]
    fn the_oblique_view_is_an_orthographic_projection() {
        // The camera's right and up are orthonormal and orthogonal to its direction.
        let (sa, ca) = OBLIQUE_AZIMUTH_DEG.to_radians().sin_cos();
        let (se, ce) = OBLIQUE_ELEVATION_DEG.to_radians().sin_cos();
        let towards = [ce * ca, ce * sa, se];
        let (right, up) = (oblique(towards), oblique([0.0, 0.0, 1.0]));
        assert!(right.0.abs() < 1e-15 && right.1.abs() < 1e-15);
        assert!(up.0.abs() < 1e-15 && (up.1 - ce).abs() < 1e-15);
        let (x, y) = oblique([1.0, 2.0, 3.0]);
        let (ex, ey) = (oblique([1.0, 0.0, 0.0]), oblique([0.0, 1.0, 0.0]));
        let ez = oblique([0.0, 0.0, 1.0]);
        assert!((x - (ex.0 + 2.0 * ey.0 + 3.0 * ez.0)).abs() < 1e-15);
        assert!((y - (ex.1 + 2.0 * ey.1 + 3.0 * ez.1)).abs() < 1e-15);
    }

    #[test]
    fn the_spatial_figures_are_svgs_with_their_curves() {
        let dir = std::env::temp_dir().join(format!("hrm-spatial-figures-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut scenario = Scenario::builtin("spatial-tracking").unwrap();
        scenario.duration = 0.3;
        let outcome = run_one(&scenario, ControllerKind::ComputedTorque);
        let run = outcome.result.as_ref().unwrap();
        let runs = [(ControllerKind::ComputedTorque, run)];
        let file = dir.join("backbone.svg");
        backbone_in_space(&file, &scenario, ControllerKind::ComputedTorque, run, 0.1).unwrap();
        let svg = std::fs::read_to_string(&file).unwrap();
        for text in [
            "top view (x-y)",
            "side view (x-z)",
            "oblique view",
            "reference path",
        ] {
            assert!(svg.contains(text), "{text}");
        }
        tip_paths(&dir.join("tip.svg"), &scenario.name, &runs).unwrap();
        let names = scenario.coordinate_names();
        for what in [CoordinateSeries::Error, CoordinateSeries::Effort] {
            let file = dir.join(format!("{what:?}.svg"));
            per_coordinate(&file, &scenario.name, &names, &runs, what).unwrap();
            let svg = std::fs::read_to_string(&file).unwrap();
            assert!(names.iter().all(|n| svg.contains(n.as_str())), "{what:?}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
