//! The figures of a spatial arm's runs as SVG files, one function per figure: the backbone in
//! space at snapshots (two orthogonal projections and an oblique view), the tip's coordinates
//! against the reference, and per-coordinate modal errors and efforts.

use crate::figure_parts::{self, snapshot_samples, tip, tip_ref};
use crate::plot::{self, Labels, Panel, Series, Style};
use clearance::Obstacle;
use sim_core::Run;
use sim_study::{ControllerKind, Scenario, Workspace};
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
/// light to dark with time), with the reference path, the tip's path and the scenario's
/// obstacles ([`obstacle_outlines`]), in three views side by side: from above, from the side
/// and oblique, each with equal scales.
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
    let obstacles = scenario
        .obstacles(Workspace::Spatial)
        .map_err(|e| e.to_string())?;
    let views: Vec<(Labels<'_>, Vec<(Series, Style)>)> = VIEWS
        .iter()
        .map(|view| {
            let mut curves = figure_parts::backbone_curves(record, &arms, view.project);
            curves.extend(obstacle_outlines(&obstacles, view.project));
            let labels = Labels {
                title: view.title,
                x: view.x,
                y: view.y,
            };
            (labels, curves)
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

/// Points on each outline circle of [`obstacle_outlines`].
const OUTLINE_POINTS: usize = 48;
/// The outlines' colour (grey).
const OUTLINE_COLOUR: (u8, u8, u8) = (110, 110, 110);

/// The outlines of `obstacles` in the view that projects by `project` (an orthographic
/// projection onto two orthonormal directions, so that lengths across the view are kept): a
/// sphere as the circle of its radius about its projected centre, a capsule as the circles
/// about its two ends joined by the two lines tangent to both (its silhouette), a box as its
/// twelve edges. The first curve is labelled `obstacles`, the others are not.
fn obstacle_outlines(
    obstacles: &[Obstacle],
    project: fn([f64; 3]) -> (f64, f64),
) -> Vec<(Series, Style)> {
    let circle = |(x, y): (f64, f64), r: f64| -> Vec<(f64, f64)> {
        (0..=OUTLINE_POINTS)
            .map(|k| {
                let phi = std::f64::consts::TAU * k as f64 / OUTLINE_POINTS as f64;
                (x + r * phi.cos(), y + r * phi.sin())
            })
            .collect()
    };
    let mut outlines: Vec<Vec<(f64, f64)>> = Vec::new();
    for obstacle in obstacles {
        match *obstacle {
            Obstacle::Sphere { center, radius } => outlines.push(circle(project(center), radius)),
            Obstacle::Capsule { from, to, radius } => {
                let (a, b) = (project(from), project(to));
                outlines.push(circle(a, radius));
                outlines.push(circle(b, radius));
                let (dx, dy) = (b.0 - a.0, b.1 - a.1);
                let length = dx.hypot(dy);
                if length > 0.0 {
                    let (nx, ny) = (-dy / length * radius, dx / length * radius);
                    for side in [1.0, -1.0] {
                        outlines.push(vec![
                            (a.0 + side * nx, a.1 + side * ny),
                            (b.0 + side * nx, b.1 + side * ny),
                        ]);
                    }
                }
            }
            Obstacle::Box {
                center,
                half_extents,
                axes,
            } => {
                let corner = |signs: [f64; 3]| {
                    project(std::array::from_fn(|d| {
                        center[d]
                            + (0..3)
                                .map(|k| signs[k] * half_extents[k] * axes[k][d])
                                .sum::<f64>()
                    }))
                };
                // Each edge joins two corners that differ in the sign along one axis.
                for along in 0..3 {
                    for (u, v) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
                        let signs = |end: f64| {
                            let mut s = [0.0; 3];
                            s[along] = end;
                            s[(along + 1) % 3] = u;
                            s[(along + 2) % 3] = v;
                            s
                        };
                        outlines.push(vec![corner(signs(-1.0)), corner(signs(1.0))]);
                    }
                }
            }
        }
    }
    outlines
        .into_iter()
        .enumerate()
        .map(|(i, points)| {
            let label = if i == 0 { "obstacles" } else { "" };
            let series = Series {
                label: label.into(),
                points,
            };
            let style = Style {
                colour: OUTLINE_COLOUR,
                width: 1,
                dots: false,
            };
            (series, style)
        })
        .collect()
}

/// The clearance over time of every run among the scenario's obstacles: one panel for the
/// smallest clearance of a link's capsule to an obstacle and one for that between links (mm,
/// at every recorded sample, as `run_view::from_record` measures it from the drawn joints),
/// with the task's margin when the scenario has a `[task]`.
pub fn clearance_over_time(
    path: &Path,
    scenario: &Scenario,
    runs: &[(ControllerKind, &Run)],
) -> Result<(), String> {
    let mut panels: Vec<(String, Vec<Series>)> = Vec::new();
    for &(kind, run) in runs {
        let view = run_view::from_record(scenario, kind.name(), &run.record, None)
            .map_err(|e| e.to_string())?;
        let Some(clearance) = view.series.iter().find(|s| s.title == "clearance") else {
            return Err(format!(
                "{}: {} measures no clearance",
                path.display(),
                scenario.name
            ));
        };
        let picked = run_view::strided(view.t.len(), MAX_CLEARANCE_POINTS);
        for (name, values) in clearance.names.iter().zip(&clearance.values) {
            let y = format!("clearance {name} ({})", clearance.unit);
            let at = match panels.iter().position(|(label, _)| *label == y) {
                Some(at) => at,
                None => {
                    panels.push((y, Vec::new()));
                    panels.len() - 1
                }
            };
            panels[at].1.push(Series {
                label: kind.name().into(),
                points: picked.iter().map(|&k| (view.t[k], values[k])).collect(),
            });
        }
    }
    if let Some(sim_study::TaskSpec::Reach { clearance, .. }) = &scenario.task {
        let end = runs
            .iter()
            .filter_map(|(_, run)| run.record.t.last().copied())
            .fold(0.0, f64::max);
        for (_, series) in &mut panels {
            series.push(Series {
                label: "task margin".into(),
                points: vec![(0.0, 1e3 * clearance), (end, 1e3 * clearance)],
            });
        }
    }
    let panels: Vec<Panel<'_>> = panels
        .iter()
        .map(|(y, series)| Panel {
            y,
            series,
            y_range: None,
        })
        .collect();
    plot::stacked_line_charts(
        path,
        &format!("Clearance, {}", scenario.name),
        "t (s)",
        &panels,
    )
}

/// The most samples of a clearance curve drawn.
const MAX_CLEARANCE_POINTS: usize = 1500;

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
    fn obstacle_outlines_are_the_silhouettes_of_the_obstacles() {
        let sphere = Obstacle::sphere([0.3, -0.1, 0.2], 0.05).unwrap();
        let capsule = Obstacle::capsule([0.1, 0.0, 0.0], [0.1, 0.3, 0.4], 0.02).unwrap();
        let turned =
            Obstacle::cuboid([0.5, 0.2, -0.1], [0.04, 0.02, 0.03], [0.0, 0.0, 0.4]).unwrap();
        for view in &VIEWS {
            // A sphere: every point of its outline is its radius from the projected centre.
            let outlines = obstacle_outlines(std::slice::from_ref(&sphere), view.project);
            assert_eq!(outlines.len(), 1);
            assert_eq!(outlines[0].0.label, "obstacles");
            let c = (view.project)([0.3, -0.1, 0.2]);
            for &(x, y) in &outlines[0].0.points {
                assert!(((x - c.0).hypot(y - c.1) - 0.05).abs() < 1e-12);
            }
            // A capsule: two end circles and two lines, each the radius from the projected axis.
            let outlines = obstacle_outlines(std::slice::from_ref(&capsule), view.project);
            assert_eq!(outlines.len(), 4);
            let (a, b) = (
                (view.project)([0.1, 0.0, 0.0]),
                (view.project)([0.1, 0.3, 0.4]),
            );
            for (series, _) in &outlines[2..] {
                assert!(series.label.is_empty());
                for &(x, y) in &series.points {
                    let cross = (b.0 - a.0) * (y - a.1) - (b.1 - a.1) * (x - a.0);
                    let distance = cross.abs() / (b.0 - a.0).hypot(b.1 - a.1);
                    assert!((distance - 0.02).abs() < 1e-12);
                }
            }
        }
        // A box turned about z seen from above: its twelve edges end on the four corners of the
        // rectangle turned by its yaw, each edge joining corners of the box.
        let outlines = obstacle_outlines(std::slice::from_ref(&turned), VIEWS[0].project);
        assert_eq!(outlines.len(), 12);
        let (sin, cos) = 0.4f64.sin_cos();
        let corners: Vec<(f64, f64)> = [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)]
            .iter()
            .map(|&(u, v)| {
                let (x, y) = (u * 0.04, v * 0.02);
                (0.5 + cos * x - sin * y, 0.2 + sin * x + cos * y)
            })
            .collect();
        for (series, _) in &outlines {
            assert_eq!(series.points.len(), 2);
            for &(x, y) in &series.points {
                assert!(
                    corners
                        .iter()
                        .any(|c| (c.0 - x).abs() < 1e-12 && (c.1 - y).abs() < 1e-12),
                    "({x}, {y})"
                );
            }
        }
    }

    #[test]
    fn spatial_clutter_draws_its_obstacles_and_its_clearance() {
        let dir = std::env::temp_dir().join(format!("hrm-spatial-clutter-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut scenario = Scenario::builtin("spatial-clutter").unwrap();
        scenario.duration = 0.3;
        let outcome = run_one(&scenario, ControllerKind::ComputedTorque);
        let run = outcome.result.as_ref().unwrap();
        let file = dir.join("backbone.svg");
        backbone_in_space(&file, &scenario, ControllerKind::ComputedTorque, run, 0.1).unwrap();
        assert!(
            std::fs::read_to_string(&file)
                .unwrap()
                .contains("obstacles")
        );
        let file = dir.join("clearance.svg");
        let runs = [(ControllerKind::ComputedTorque, run)];
        clearance_over_time(&file, &scenario, &runs).unwrap();
        let svg = std::fs::read_to_string(&file).unwrap();
        for text in [
            "clearance to the obstacles (mm)",
            "clearance between links (mm)",
            "task margin",
        ] {
            assert!(svg.contains(text), "{text}");
        }
        // A scenario without obstacles has no clearance to draw: refused, not an empty figure.
        let mut short = Scenario::builtin("spatial-tracking").unwrap();
        short.duration = 0.05;
        let outcome = run_one(&short, ControllerKind::ComputedTorque);
        let runs = [(
            ControllerKind::ComputedTorque,
            outcome.result.as_ref().unwrap(),
        )];
        assert!(clearance_over_time(&file, &short, &runs).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
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
