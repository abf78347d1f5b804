//! A closed-loop run of `sim-core` (a planar or a spatial arm) as a [`RunView`]: the arm's points
//! from the recorded modal coordinates through the scenario's modal map (eq 8) and the chain's
//! forward kinematics, and the series a reader checks first.

use crate::error::ViewError;
use crate::view::{Obstacle, RunView, Series};
use clearance::{ClearanceData, ClearanceModel};
use modal_reduce::PlantModel;
use sim_core::Record;
use sim_study::{Scenario, TorqueLimit, Workspace};

/// The run `record` of `scenario` under the controller named `label`: every sample's joint
/// positions (`theta = J a + theta_0`, eq 8, then the chain from the base at the origin; for a
/// spatial arm the universal-joint chain from its base pose, in 3-D), the reference tip, the
/// joint torques (eq 13; a spatial link's the magnitude of its universal joint's two) against
/// the scenario's joint torque limits (a spatial arm's against the run's peak), and the
/// series tip error (mm), modal coordinates with their references (rad) and `tau*` (N m) (the
/// viewer adds the panel of the joint torques itself, from the torques that colour the links).
/// A scenario with obstacles (or an arm radius) also gets its obstacles drawn and the series
/// clearance (mm): the smallest clearance of the links' capsules to the obstacles and to the arm
/// itself at every sample, measured by `clearance::distances` from the drawn joint points.
/// A box turned by `rpy` is not drawn (the page draws axis-aligned boxes); its clearance is
/// still measured. `stopped` is why a run stopped early.
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
    let mut theta = vec![0.0; n_joints];
    let mut joints = Vec::with_capacity(samples);
    match &plant {
        PlantModel::Planar(model) => {
            let lengths: Vec<f64> = model.chain().link_lengths().collect();
            let mut points = vec![[0.0; 2]; n + 1];
            for k in 0..samples {
                model.map().joint_angles(record.a_at(k), &mut theta)?;
                backbone_kin::joint_positions(&lengths, &theta, &mut points)?;
                joints.push(points.iter().flatten().copied().collect());
            }
        }
        PlantModel::Spatial(model) => {
            let map = model.map();
            let mut points = vec![[0.0; 3]; n + 1];
            for k in 0..samples {
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
    let names = scenario.coordinate_names();
    // In the plane z is zero and `hypot(d, 0) = |d|`.
    let tip_error = (0..samples)
        .map(|k| {
            let (tip, reference) = (record.tip[k], record.tip_ref[k]);
            1e3 * (tip[0] - reference[0])
                .hypot(tip[1] - reference[1])
                .hypot(record.tip_z[k] - record.tip_ref_z[k])
        })
        .collect();
    let modal = |series: fn(&Record, usize) -> &[f64], i: usize| -> Vec<f64> {
        (0..samples).map(|k| series(record, k)[i]).collect()
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
    // A link's torque: its joint's, or the magnitude of its universal joint's two.
    let joint_torque: Vec<Vec<f64>> = (0..samples)
        .map(|k| match dims {
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
            names: names.iter().map(|n| format!("tau*_{}", &n[1..])).collect(),
            values: (0..m).map(|i| modal(Record::tau_star_at, i)).collect(),
        },
    ];
    let workspace = if dims == 2 {
        Workspace::Planar
    } else {
        Workspace::Spatial
    };
    let model = scenario.clearance_model(n, workspace)?;
    if let Some(model) = &model {
        series.push(clearance_series(model, &joints, dims, m)?);
    }
    // A spatial arm's links are coloured against the run's peak torque.
    let torque_limit = match (&scenario.limits.joint_torque_nm, dims) {
        (Some(TorqueLimit::All(limit)), 2) => vec![*limit; n],
        (Some(TorqueLimit::PerJoint(limits)), 2) => limits.clone(),
        _ => Vec::new(),
    };
    let view = RunView {
        label: label.to_owned(),
        dims,
        t: record.t.clone(),
        joints,
        tip_ref: record
            .tip_ref
            .iter()
            .zip(&record.tip_ref_z)
            .map(|(p, &z)| {
                if dims == 2 {
                    p.to_vec()
                } else {
                    vec![p[0], p[1], z]
                }
            })
            .collect(),
        joint_torque: if record.joint_torques.len() == samples * n_joints {
            joint_torque
        } else {
            Vec::new()
        },
        torque_limit,
        series,
        obstacles: model
            .iter()
            .flat_map(ClearanceModel::obstacles)
            .filter_map(|o| drawn(o, dims))
            .collect(),
        channels: Vec::new(),
        stopped: stopped.map(str::to_owned),
    };
    view.check()?;
    Ok(view)
}

/// The smallest clearance (mm) of the links to the obstacles and to the arm itself at every
/// sample (`joints`: a sample's points, `dims` numbers each; a curve each when the model has
/// such pairs).
fn clearance_series(
    model: &ClearanceModel,
    joints: &[Vec<f64>],
    dims: usize,
    n_coords: usize,
) -> Result<Series, ViewError> {
    let mut data = ClearanceData::new(model, n_coords)?;
    // The distances use the joint points only; the axes serve the gradients, unused here.
    let axes = vec![[0.0, 0.0, 1.0]; model.n_links()];
    let mut points = vec![[0.0; 3]; model.n_links() + 1];
    let (mut to_obstacles, mut to_itself) = (Vec::new(), Vec::new());
    for sample in joints {
        for (point, coords) in points.iter_mut().zip(sample.chunks_exact(dims)) {
            point[..dims].copy_from_slice(coords);
        }
        clearance::place(model, &mut data, &points, &axes)?;
        let (obstacle, itself) = clearance::distances(model, &mut data);
        to_obstacles.push(1e3 * obstacle);
        to_itself.push(1e3 * itself);
    }
    let mut series = Series {
        title: "clearance".into(),
        unit: "mm".into(),
        names: Vec::new(),
        values: Vec::new(),
    };
    for (name, values) in [("to obstacles", to_obstacles), ("to itself", to_itself)] {
        if values.iter().all(|v| v.is_finite()) {
            series.names.push(name.into());
            series.values.push(values);
        }
    }
    Ok(series)
}

/// A measured obstacle as the page draws it, in the arm's `dims` coordinates; `None` for a
/// turned box.
fn drawn(obstacle: &clearance::Obstacle, dims: usize) -> Option<Obstacle> {
    let point = |p: &[f64; 3]| p[..dims].to_vec();
    Some(match obstacle {
        clearance::Obstacle::Sphere { center, radius } if dims == 2 => Obstacle::Circle {
            centre: point(center),
            radius: *radius,
        },
        clearance::Obstacle::Sphere { center, radius } => Obstacle::Sphere {
            centre: point(center),
            radius: *radius,
        },
        clearance::Obstacle::Capsule { from, to, radius } => Obstacle::Capsule {
            a: point(from),
            b: point(to),
            radius: *radius,
        },
        clearance::Obstacle::Box {
            center,
            half_extents,
            axes,
        } => {
            let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
            if *axes != identity {
                return None;
            }
            Obstacle::Box {
                centre: point(center),
                half: point(half_extents),
            }
        }
    })
}
