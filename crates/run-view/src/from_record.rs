//! A closed-loop run of `sim-core` (a planar or a spatial arm) as a [`RunView`]: the arm's points
//! from the recorded modal coordinates through the scenario's modal map (eq 8) and the chain's
//! forward kinematics, the scenario's obstacles, and the series a reader checks first.

use crate::decimate::strided;
use crate::error::ViewError;
use crate::view::{MAX_POINTS, MAX_SAMPLES, Obstacle, RunView, Series};
use clearance::{ClearanceData, ClearanceModel};
use modal_reduce::PlantModel;
use sim_core::Record;
use sim_study::{Scenario, TorqueLimit};

/// The run `record` of `scenario` under the controller named `label`: every sample's joint
/// positions (`theta = J a + theta_0`, eq 8, then the chain from the base at the origin; for a
/// spatial arm the universal-joint chain from its base pose, in 3-D), the reference tip, the
/// joint torques (eq 13; a spatial link's the magnitude of its universal joint's two) against
/// the scenario's joint torque limits (a spatial arm's against the run's peak), and the
/// series tip error (mm), modal coordinates with their references (rad) and `tau*` (N m) (the
/// viewer adds the panel of the joint torques itself, from the torques that colour the links).
/// A scenario with `[[obstacles]]` or `[arm] radius` also gets its obstacles drawn and a
/// clearance series (mm): at every recorded sample the smallest clearance of a link's capsule
/// to an obstacle and between links that share no joint, measured by `clearance::distances`
/// from the drawn joint points (the loop's own minima over every controller sample are in the
/// run's summary). A record of more than [`MAX_SAMPLES`] samples is drawn at evenly strided
/// samples ([`strided`](crate::strided), the first and the last included). `stopped` is why a
/// run stopped early.
pub fn from_record(
    scenario: &Scenario,
    label: &str,
    record: &Record,
    stopped: Option<&str>,
) -> Result<RunView, ViewError> {
    let plant = scenario.plant()?;
    // Links, joints and the arm's dimensions.
    let (n, n_joints, dims) = match &plant {
        PlantModel::Planar(model) => (model.n_links(), model.n_links(), 2),
        PlantModel::Spatial(model) => (model.n_links(), 2 * model.n_links(), 3),
    };
    if n + 1 > MAX_POINTS {
        return Err(ViewError::TooManyLinks {
            scenario: scenario.name.clone(),
            links: n,
            max: MAX_POINTS - 1,
        });
    }
    let (m, samples) = (record.n_coords, record.len());
    if record.n_joints != n_joints
        || record.a.len() != samples * m
        || record.tip.len() != samples
        || record.tip_z.len() != samples
    {
        return Err(ViewError::RecordMismatch {
            scenario: scenario.name.clone(),
            joints: record.n_joints,
            samples,
        });
    }
    // A run longer than the viewer holds is drawn at evenly strided samples, the last included.
    let picked = strided(samples, MAX_SAMPLES - 1);
    let mut theta = vec![0.0; n_joints];
    let mut joints: Vec<Vec<f64>> = Vec::with_capacity(picked.len());
    match &plant {
        PlantModel::Planar(model) => {
            let lengths: Vec<f64> = model.chain().link_lengths().collect();
            let mut points = vec![[0.0; 2]; n + 1];
            for &k in &picked {
                model.map().joint_angles(record.a_at(k), &mut theta)?;
                backbone_kin::joint_positions(&lengths, &theta, &mut points)?;
                joints.push(points.iter().flatten().copied().collect());
            }
        }
        PlantModel::Spatial(model) => {
            let map = model.map();
            let mut points = vec![[0.0; 3]; n + 1];
            for &k in &picked {
                map.joint_angles(record.a_at(k), &mut theta)?;
                backbone_kin::spatial_joint_positions(
                    map.link_lengths(),
                    model.base(),
                    &theta,
                    &mut points,
                )?;
                joints.push(points.iter().flatten().copied().collect());
            }
        }
    }
    // The arm drawn is the scenario's: its tip must be the recorded one (the chain's, computed
    // by the same kinematics), or the folder's scenario is not the run's (a changed link length).
    let length: f64 = match &plant {
        PlantModel::Planar(model) => model.chain().link_lengths().sum(),
        PlantModel::Spatial(model) => model.map().link_lengths().iter().sum(),
    };
    for (&k, points) in picked.iter().zip(&joints) {
        let drawn = &points[points.len() - dims..];
        let recorded = [record.tip[k][0], record.tip[k][1], record.tip_z[k]];
        let distance = (0..dims)
            .map(|i| (drawn[i] - recorded[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        if distance.is_nan() || distance > 1e-9 * (1.0 + length) {
            return Err(ViewError::TipMismatch {
                scenario: scenario.name.clone(),
                t: record.t[k],
                distance,
            });
        }
    }
    let (obstacles, clearance) = match scenario.clearance_model(n, scenario.workspace())? {
        Some(model) => (
            model.obstacles().iter().map(|o| drawn(o, dims)).collect(),
            clearance_series(&model, &joints, dims, m)?,
        ),
        None => (Vec::new(), None),
    };
    let names = scenario.coordinate_names();
    // In the plane z is zero and `hypot(d, 0) = |d|`.
    let tip_error = picked
        .iter()
        .map(|&k| {
            let (tip, reference) = (record.tip[k], record.tip_ref[k]);
            1e3 * (tip[0] - reference[0])
                .hypot(tip[1] - reference[1])
                .hypot(record.tip_z[k] - record.tip_ref_z[k])
        })
        .collect();
    let modal = |series: fn(&Record, usize) -> &[f64], i: usize| -> Vec<f64> {
        picked.iter().map(|&k| series(record, k)[i]).collect()
    };
    let mut coordinates = Series {
        title: "modal coordinates".into(),
        unit: "rad".into(),
        names: Vec::new(),
        values: Vec::new(),
    };
    for (i, name) in names.iter().enumerate() {
        coordinates
            .names
            .extend([name.clone(), format!("{name} ref")]);
        coordinates
            .values
            .extend([modal(Record::a_at, i), modal(Record::a_ref_at, i)]);
    }
    // A link's torque: its joint's, or the magnitude of its universal joint's two (none when
    // the record has no joint torques for every sample).
    let has_torques = record.joint_torques.len() == samples * n_joints;
    let joint_torque: Vec<Vec<f64>> = picked
        .iter()
        .filter(|_| has_torques)
        .map(|&k| match dims {
            2 => record.joint_torques_at(k).to_vec(),
            _ => record
                .joint_torques_at(k)
                .chunks_exact(2)
                .map(|pair| pair[0].hypot(pair[1]))
                .collect(),
        })
        .collect();
    let mut series = vec![
        Series {
            title: "tip error".into(),
            unit: "mm".into(),
            names: vec!["|tip - reference|".into()],
            values: vec![tip_error],
        },
        coordinates,
        Series {
            title: "modal torques tau*".into(),
            unit: "N m".into(),
            names: names.iter().map(|n| modal_torque_name(n)).collect(),
            values: (0..m).map(|i| modal(Record::tau_star_at, i)).collect(),
        },
    ];
    series.extend(clearance);
    // A spatial arm's links are coloured against the run's peak torque.
    let torque_limit = match (&scenario.limits.joint_torque_nm, dims) {
        (Some(TorqueLimit::All(limit)), 2) => vec![*limit; n],
        (Some(TorqueLimit::PerJoint(limits)), 2) => limits.clone(),
        _ => Vec::new(),
    };
    let view = RunView {
        label: label.to_owned(),
        dims,
        t: picked.iter().map(|&k| record.t[k]).collect(),
        joints,
        tip_ref: picked
            .iter()
            .map(|&k| (record.tip_ref[k], record.tip_ref_z[k]))
            .map(|(p, z)| {
                if dims == 2 {
                    p.to_vec()
                } else {
                    vec![p[0], p[1], z]
                }
            })
            .collect(),
        joint_torque,
        torque_limit,
        series,
        obstacles,
        channels: Vec::new(),
        stopped: stopped.map(str::to_owned),
    };
    view.check()?;
    Ok(view)
}

/// The curve name of the modal torque that drives coordinate `coordinate`: `tau*_1` for `a1`,
/// `tau*_z1` for `az1`, `tau*_alpha0` for a free base angle `alpha0`.
fn modal_torque_name(coordinate: &str) -> String {
    let index = match coordinate.strip_prefix('a') {
        Some(rest) if rest.starts_with(|c: char| c.is_ascii_digit() || c == 'y' || c == 'z') => {
            rest
        }
        _ => coordinate,
    };
    format!("tau*_{index}")
}

/// The clearance series (mm) of the drawn samples `joints` (each `n + 1` points of `dims`
/// coordinates): the smallest clearance to an obstacle, and between links when the arm has
/// a pair that shares no joint (`clearance::distances`); `None` when the arm has neither.
fn clearance_series(
    model: &ClearanceModel,
    joints: &[Vec<f64>],
    dims: usize,
    n_coords: usize,
) -> Result<Option<Series>, ViewError> {
    let mut data = ClearanceData::new(model, n_coords)?;
    let mut points = vec![[0.0; 3]; model.n_links() + 1];
    // The distances read the joint points only; the axes are placeholders of unit length.
    let axes = vec![[0.0, 0.0, 1.0]; model.n_links()];
    let (mut to_obstacles, mut to_itself) = (Vec::new(), Vec::new());
    for row in joints {
        for (point, drawn) in points.iter_mut().zip(row.chunks_exact(dims)) {
            point[..dims].copy_from_slice(drawn);
        }
        clearance::place(model, &mut data, &points, &axes)?;
        let (near_obstacle, near_self) = clearance::distances(model, &mut data);
        to_obstacles.push(1e3 * near_obstacle);
        to_itself.push(1e3 * near_self);
    }
    let (mut names, mut values) = (Vec::new(), Vec::new());
    if model.n_obstacle_pairs() > 0 {
        names.push("to the obstacles".into());
        values.push(to_obstacles);
    }
    if model.pairs().len() > model.n_obstacle_pairs() {
        names.push("between links".into());
        values.push(to_itself);
    }
    Ok((!names.is_empty()).then(|| Series {
        title: "clearance".into(),
        unit: "mm".into(),
        names,
        values,
    }))
}

/// How the viewer draws `obstacle` in `dims` coordinates: a sphere of a planar arm as a
/// circle, a box as the axis-aligned box that bounds it (exactly the box when it is not
/// turned; an infinite half-extent along `z` of a planar box is dropped with `z`).
fn drawn(obstacle: &clearance::Obstacle, dims: usize) -> Obstacle {
    let cut = |p: [f64; 3]| p[..dims].to_vec();
    match *obstacle {
        clearance::Obstacle::Sphere { center, radius } if dims == 2 => Obstacle::Circle {
            centre: cut(center),
            radius,
        },
        clearance::Obstacle::Sphere { center, radius } => Obstacle::Sphere {
            centre: cut(center),
            radius,
        },
        clearance::Obstacle::Capsule { from, to, radius } => Obstacle::Capsule {
            a: cut(from),
            b: cut(to),
            radius,
        },
        clearance::Obstacle::Box {
            center,
            half_extents,
            axes,
        } => {
            // Half the extent of the turned box along world axis `i`: sum_k |R_ik| h_k.
            let half: Vec<f64> = (0..dims)
                .map(|i| {
                    (0..3)
                        .map(|k| axes[k][i].abs() * half_extents[k])
                        .filter(|h| !h.is_nan())
                        .sum()
                })
                .collect();
            Obstacle::Box {
                centre: cut(center),
                half,
            }
        }
    }
}
