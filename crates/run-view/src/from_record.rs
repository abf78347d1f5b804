//! A planar closed-loop run of `sim-core` as a [`RunView`]: the arm's points from the recorded
//! modal coordinates through the scenario's modal map (eq 8) and the chain's forward kinematics,
//! and the series a reader checks first.

use crate::error::ViewError;
use crate::view::{RunView, Series};
use sim_core::Record;
use sim_study::{Scenario, TorqueLimit};

/// The run `record` of `scenario` under the controller named `label`: every sample's joint
/// positions (`theta = J a + theta_0`, eq 8, then the chain from the base at the origin), the
/// reference tip, the joint torques (eq 13) against the scenario's joint torque limits, and the
/// series tip error (mm), modal coordinates with their references (rad) and `tau*` (N m) (the
/// viewer adds the panel of the joint torques itself, from the torques that colour the links). `stopped` is why a run stopped early.
pub fn from_record(
    scenario: &Scenario,
    label: &str,
    record: &Record,
    stopped: Option<&str>,
) -> Result<RunView, ViewError> {
    let model = scenario.model()?;
    let lengths: Vec<f64> = model.chain().link_lengths().collect();
    let n = lengths.len();
    let (m, samples) = (record.n_coords, record.len());
    if record.n_joints != n || record.a.len() != samples * m || record.tip.len() != samples {
        return Err(ViewError::RecordMismatch {
            scenario: scenario.name.clone(),
            joints: record.n_joints,
            samples,
        });
    }
    let mut theta = vec![0.0; n];
    let mut points = vec![[0.0; 2]; n + 1];
    let mut joints = Vec::with_capacity(samples);
    for k in 0..samples {
        model.map().joint_angles(record.a_at(k), &mut theta)?;
        backbone_kin::joint_positions(&lengths, &theta, &mut points)?;
        joints.push(points.iter().flatten().copied().collect());
    }
    let names = scenario.coordinate_names();
    let tip_error = (0..samples)
        .map(|k| {
            let (tip, reference) = (record.tip[k], record.tip_ref[k]);
            1e3 * (tip[0] - reference[0]).hypot(tip[1] - reference[1])
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
    let joint_torque: Vec<Vec<f64>> = (0..samples)
        .map(|k| record.joint_torques_at(k).to_vec())
        .collect();
    let series = vec![
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
    let torque_limit = match &scenario.limits.joint_torque_nm {
        Some(TorqueLimit::All(limit)) => vec![*limit; n],
        Some(TorqueLimit::PerJoint(limits)) => limits.clone(),
        None => Vec::new(),
    };
    let view = RunView {
        label: label.to_owned(),
        dims: 2,
        t: record.t.clone(),
        joints,
        tip_ref: record.tip_ref.iter().map(|p| p.to_vec()).collect(),
        joint_torque: if record.joint_torques.len() == samples * n {
            joint_torque
        } else {
            Vec::new()
        },
        torque_limit,
        series,
        obstacles: Vec::new(),
        channels: Vec::new(),
        stopped: stopped.map(str::to_owned),
    };
    view.check()?;
    Ok(view)
}
