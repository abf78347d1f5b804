//! What a closed-loop run records: time series at the recording rate, and summary metrics over
//! every controller sample.

use crate::error::SimError;
use lane_math::{OutOfMemory, try_reserve};
use serde::Serialize;

/// Time series of a run, one entry per recorded controller sample (the state at the sample
/// time and the torques held from it). The modal series hold [`n_coords`](Self::n_coords)
/// numbers per sample, row-major (`a[k * m + i]` is coordinate `i` at sample `k`); read a row
/// with the `*_at` accessors.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Record {
    /// Joints of the arm (the row length of [`joint_torques`](Self::joint_torques)).
    pub n_joints: usize,
    /// Modal coordinates `m` (the row length of the modal series).
    pub n_coords: usize,
    /// Sample times (s).
    pub t: Vec<f64>,
    /// Modal coordinates (rad).
    pub a: Vec<f64>,
    /// Modal rates (rad/s).
    pub a_dot: Vec<f64>,
    /// The reference without reference noise (rad).
    pub a_ref: Vec<f64>,
    /// The reference rates (rad/s).
    pub a_ref_dot: Vec<f64>,
    /// The reference as the controller received it, reference noise included (rad).
    pub a_cmd: Vec<f64>,
    /// Modal torques `tau*` held from this sample to the next (N m), after the actuator limits.
    pub tau_star: Vec<f64>,
    /// Whether the actuator limit clamped the controller's `tau_i*` at this sample, per
    /// coordinate (row-major like the modal series; all `false` without limits).
    pub clamped: Vec<bool>,
    /// Tip of the discrete chain, `x` and `y` (m).
    pub tip: Vec<[f64; 2]>,
    /// The reference tip, `x` and `y`: the backbone curve's end point at `a_ref` (eqs 3-4) for a
    /// planar arm, the chain's tip at `a_ref` for a spatial one; for a Cartesian path reference
    /// it is the path point (m).
    pub tip_ref: Vec<[f64; 2]>,
    /// The `z` of [`tip`](Self::tip) (zero for a planar arm) (m).
    pub tip_z: Vec<f64>,
    /// The `z` of [`tip_ref`](Self::tip_ref) (m).
    pub tip_ref_z: Vec<f64>,
    /// Joint torques `tau = M J a_dd + C + G` (eq 13) at the sample, `n_joints` per sample,
    /// row-major (N m).
    pub joint_torques: Vec<f64>,
    /// The chain's points at the sample, [`n_points`](Self::n_points) per sample: the base, then
    /// the distal end of every link (the last is the tip), `[x, y, z]` with `z = 0` for a planar
    /// arm (m). The clearance is measured from exactly these points (`links.csv`).
    pub joint_points: Vec<[f64; 3]>,
    /// Points per sample in [`joint_points`](Self::joint_points): the links plus one.
    pub n_points: usize,
}

impl Record {
    /// Number of recorded samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether nothing was recorded.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// The joint torques of sample `k` (N m).
    ///
    /// # Panics
    /// If `k >= len()`, like slice indexing.
    pub fn joint_torques_at(&self, k: usize) -> &[f64] {
        &self.joint_torques[k * self.n_joints..(k + 1) * self.n_joints]
    }

    /// The chain's points at sample `k`, base to tip (m).
    ///
    /// # Panics
    /// If `k >= len()`, like slice indexing.
    pub fn joint_points_at(&self, k: usize) -> &[[f64; 3]] {
        &self.joint_points[k * self.n_points..(k + 1) * self.n_points]
    }

    /// Row `k` of a modal series (`m` numbers).
    fn row<'a>(&self, series: &'a [f64], k: usize) -> &'a [f64] {
        &series[k * self.n_coords..(k + 1) * self.n_coords]
    }

    /// The modal coordinates at sample `k` (rad). Panics if `k >= len()`, like the others.
    pub fn a_at(&self, k: usize) -> &[f64] {
        self.row(&self.a, k)
    }

    /// The modal rates at sample `k` (rad/s).
    pub fn a_dot_at(&self, k: usize) -> &[f64] {
        self.row(&self.a_dot, k)
    }

    /// The noise-free reference at sample `k` (rad).
    pub fn a_ref_at(&self, k: usize) -> &[f64] {
        self.row(&self.a_ref, k)
    }

    /// The reference rates at sample `k` (rad/s).
    pub fn a_ref_dot_at(&self, k: usize) -> &[f64] {
        self.row(&self.a_ref_dot, k)
    }

    /// The reference the controller received at sample `k` (rad).
    pub fn a_cmd_at(&self, k: usize) -> &[f64] {
        self.row(&self.a_cmd, k)
    }

    /// The modal torques held from sample `k` (N m).
    pub fn tau_star_at(&self, k: usize) -> &[f64] {
        self.row(&self.tau_star, k)
    }

    /// Which coordinates' torques the actuator limits clamped at sample `k`.
    pub fn clamped_at(&self, k: usize) -> &[bool] {
        &self.clamped[k * self.n_coords..(k + 1) * self.n_coords]
    }
}

/// One recorded sample, before it is pushed.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Sample<'a> {
    pub t: f64,
    pub a: &'a [f64],
    pub a_dot: &'a [f64],
    pub a_ref: &'a [f64],
    pub a_ref_dot: &'a [f64],
    pub a_cmd: &'a [f64],
    pub tau_star: &'a [f64],
    pub clamped: &'a [bool],
    pub tip: [f64; 3],
    pub tip_ref: [f64; 3],
}

impl Record {
    /// The values one recorded sample holds: `t`, seven modal series of `n_coords` (the
    /// clamping flags counted as one value each), two tips of three coordinates, a torque per
    /// joint and three coordinates per chain point.
    pub(crate) fn values_per_sample(n_coords: usize, n_joints: usize, n_points: usize) -> usize {
        7 + 7 * n_coords + n_joints + 3 * n_points
    }

    /// An empty record of runs with these sizes.
    pub(crate) fn empty(n_coords: usize, n_joints: usize, n_points: usize) -> Self {
        Self {
            n_joints,
            n_coords,
            t: Vec::new(),
            a: Vec::new(),
            a_dot: Vec::new(),
            a_ref: Vec::new(),
            a_ref_dot: Vec::new(),
            a_cmd: Vec::new(),
            tau_star: Vec::new(),
            clamped: Vec::new(),
            tip: Vec::new(),
            tip_ref: Vec::new(),
            tip_z: Vec::new(),
            tip_ref_z: Vec::new(),
            joint_torques: Vec::new(),
            joint_points: Vec::new(),
            n_points,
        }
    }

    /// Room for `samples` more samples, or [`OutOfMemory`] when the system refuses it.
    pub(crate) fn reserve(&mut self, samples: usize) -> Result<(), OutOfMemory> {
        const WHAT: &str = "the run's record";
        let per = |count: usize| samples.saturating_mul(count);
        for series in [&mut self.t, &mut self.tip_z, &mut self.tip_ref_z] {
            try_reserve(series, samples, WHAT)?;
        }
        for series in [
            &mut self.a,
            &mut self.a_dot,
            &mut self.a_ref,
            &mut self.a_ref_dot,
            &mut self.a_cmd,
            &mut self.tau_star,
        ] {
            try_reserve(series, per(self.n_coords), WHAT)?;
        }
        try_reserve(&mut self.clamped, per(self.n_coords), WHAT)?;
        try_reserve(&mut self.tip, samples, WHAT)?;
        try_reserve(&mut self.tip_ref, samples, WHAT)?;
        try_reserve(&mut self.joint_torques, per(self.n_joints), WHAT)?;
        try_reserve(&mut self.joint_points, per(self.n_points), WHAT)
    }

    pub(crate) fn push(&mut self, s: &Sample<'_>, joint_torques: &[f64], points: &[[f64; 3]]) {
        self.t.push(s.t);
        self.a.extend_from_slice(s.a);
        self.a_dot.extend_from_slice(s.a_dot);
        self.a_ref.extend_from_slice(s.a_ref);
        self.a_ref_dot.extend_from_slice(s.a_ref_dot);
        self.a_cmd.extend_from_slice(s.a_cmd);
        self.tau_star.extend_from_slice(s.tau_star);
        self.clamped.extend_from_slice(s.clamped);
        self.tip.push([s.tip[0], s.tip[1]]);
        self.tip_ref.push([s.tip_ref[0], s.tip_ref[1]]);
        self.tip_z.push(s.tip[2]);
        self.tip_ref_z.push(s.tip_ref[2]);
        self.joint_torques.extend_from_slice(joint_torques);
        self.joint_points.extend_from_slice(points);
    }
}

/// A joint whose torque exceeded its limit during a run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TorqueLimitExceeded {
    /// 0-based joint index.
    pub joint: usize,
    /// The limit (N m).
    pub limit_nm: f64,
    /// First controller sample time at which `|tau| > limit` (s).
    pub first_time_s: f64,
    /// Largest `|tau|` over the run (N m).
    pub peak_nm: f64,
    /// Number of controller samples (recorded or not) over the limit.
    pub samples_over: usize,
}

/// Summary metrics of a run.
///
/// The torque peaks, the torque limit checks and the clamped fractions cover every controller
/// sample, recorded or not, so a torque spike between two recorded samples is never missed. The
/// tracking errors (`tip_error_rms_m`, `tip_error_max_m`, `modal_error_rms_rad`,
/// `modal_error_max_rad`) are the statistics of the [`Record`]'s time series, taken over the
/// recorded samples (every `record_period`, plus the last and a runaway sample): record every
/// controller sample to take them over all (the runaway check itself sees every sample). The
/// control effort integrates the held torques over every controller period. Serialises to the
/// fields of
/// `summary.json`; the key of every physical quantity ends in its unit (`_m`, `_rad`, `_nm`, `_s`,
/// `_n2m2s`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// Controller samples taken (including the one at the final time).
    pub controller_samples: usize,
    /// Recorded samples (the ones the tracking errors are taken over).
    pub recorded_samples: usize,
    /// Accepted integrator steps.
    pub steps: usize,
    /// Rejected integrator steps (adaptive integration only).
    pub rejected_steps: usize,
    /// Simulated time (s): the final sample time, or the last good one of a failed run.
    pub simulated_s: f64,
    /// Root mean square of the distance between the chain's tip and the reference tip over the
    /// recorded samples (m).
    pub tip_error_rms_m: f64,
    /// Largest such distance over the recorded samples (m).
    pub tip_error_max_m: f64,
    /// Root mean square of `a_i - a_i_ref` per coordinate over the recorded samples (rad),
    /// against the noise-free reference.
    pub modal_error_rms_rad: Vec<f64>,
    /// Largest `|a_i - a_i_ref|` per coordinate over the recorded samples (rad).
    pub modal_error_max_rad: Vec<f64>,
    /// Largest `|tau_i*|` per coordinate over every controller sample (N m).
    pub peak_modal_torques_nm: Vec<f64>,
    /// Largest `|tau_j|` over all joints and every controller sample (N m).
    pub peak_joint_torque_nm: f64,
    /// Largest `|tau_j|` of each joint over every controller sample (N m).
    pub peak_joint_torques_nm: Vec<f64>,
    /// Control effort `integral of |tau*|^2 dt` under the zero-order hold (N^2 m^2 s).
    pub control_effort_n2m2s: f64,
    /// Per coordinate, the fraction of controller samples (from 0 to 1) at which the actuator
    /// limit `limits.tau_star` clamped the controller's output (zeros without limits).
    pub tau_star_clamped_fraction: Vec<f64>,
    /// Joints whose torque limit was exceeded (empty without limits or violations). The limits
    /// are enforced at every controller sample, so with them an entry means a joint torque the
    /// projection could not keep within them (rounding), never a controller left unchecked.
    pub torque_limit_exceeded: Vec<TorqueLimitExceeded>,
    /// The fraction of controller samples (from 0 to 1) at which the enforced joint limits
    /// (`limits.joint_torque_nm`, `limits.joint_angle_rad`) moved the controller's `tau*`;
    /// absent without them.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub torque_projection_share: Option<f64>,
    /// The smallest clearance between a link's capsule and an obstacle over every controller
    /// sample (m; negative in contact); absent without obstacles.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_clearance_m: Option<f64>,
    /// The smallest clearance between two links that share no joint over every controller
    /// sample (m; negative where they cross); absent without `arm.radius` or obstacles, or for
    /// an arm of fewer than three links.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_self_clearance_m: Option<f64>,
}

/// Running sums behind a [`Summary`].
#[derive(Debug, Clone)]
pub(crate) struct Metrics {
    controller_samples: usize,
    samples: usize,
    last_t: f64,
    tip_sq: f64,
    tip_max: f64,
    modal_sq: Vec<f64>,
    modal_max: Vec<f64>,
    peak_tau_star: Vec<f64>,
    peak_joint: Vec<f64>,
    effort: f64,
    clamped: Vec<usize>,
    limits: Option<Vec<f64>>,
    exceeded: Vec<Option<TorqueLimitExceeded>>,
    /// Controller samples at which the joint limits acted, when they are enforced.
    projected: Option<usize>,
    min_clearance: Option<f64>,
    min_self_clearance: Option<f64>,
}

impl Metrics {
    /// Sums for `n_coords` coordinates and `n_joints` joints, checking the joint torques against
    /// `limits`; `projecting` when the loop enforces joint limits.
    pub(crate) fn new(
        n_coords: usize,
        n_joints: usize,
        limits: Option<Vec<f64>>,
        projecting: bool,
    ) -> Self {
        Self {
            controller_samples: 0,
            samples: 0,
            last_t: 0.0,
            tip_sq: 0.0,
            tip_max: 0.0,
            modal_sq: vec![0.0; n_coords],
            modal_max: vec![0.0; n_coords],
            peak_tau_star: vec![0.0; n_coords],
            peak_joint: vec![0.0; n_joints],
            effort: 0.0,
            clamped: vec![0; n_coords],
            limits,
            exceeded: vec![None; n_joints],
            projected: projecting.then_some(0),
            min_clearance: None,
            min_self_clearance: None,
        }
    }

    /// Counts a controller sample at which the joint limits moved `tau*`.
    pub(crate) fn add_projection(&mut self, acted: bool) {
        if let Some(count) = &mut self.projected {
            *count += usize::from(acted);
        }
    }

    /// Counts a controller sample's smallest clearances to the obstacles and to the arm itself
    /// (`None` for a kind of pair the model does not have).
    pub(crate) fn add_clearance(&mut self, to_obstacles: Option<f64>, to_itself: Option<f64>) {
        let lower = |least: &mut Option<f64>, value: Option<f64>| {
            if let Some(v) = value {
                *least = Some(least.map_or(v, |l| l.min(v)));
            }
        };
        lower(&mut self.min_clearance, to_obstacles);
        lower(&mut self.min_self_clearance, to_itself);
    }

    /// Counts the controller sample at `t` whose torque `tau_star` (with its clamping flags and
    /// the joint torques at the sample) is held for `hold` seconds: its clamping, effort, torque peaks and limit checks, which therefore
    /// cover every controller sample whether it is recorded or not. Refuses an effort that
    /// overflows ([`SimError::EffortOverflow`]), which a summary could not report.
    pub(crate) fn add_control(
        &mut self,
        t: f64,
        tau_star: &[f64],
        clamped: &[bool],
        joint_torques: &[f64],
        hold: f64,
    ) -> Result<(), SimError> {
        self.controller_samples += 1;
        for (count, &c) in self.clamped.iter_mut().zip(clamped) {
            *count += usize::from(c);
        }
        self.last_t = t;
        let mut square = 0.0;
        for tau in tau_star {
            square += tau * tau;
        }
        let effort = self.effort + square * hold;
        if !effort.is_finite() {
            return Err(SimError::EffortOverflow {
                t,
                tau_star: tau_star.to_vec(),
            });
        }
        self.effort = effort;
        for (peak, tau) in self.peak_tau_star.iter_mut().zip(tau_star) {
            *peak = peak.max(tau.abs());
        }
        for (j, &tau) in joint_torques.iter().enumerate() {
            self.peak_joint[j] = self.peak_joint[j].max(tau.abs());
            if let Some(limits) = &self.limits
                && tau.abs() > limits[j]
            {
                let entry = self.exceeded[j].get_or_insert(TorqueLimitExceeded {
                    joint: j,
                    limit_nm: limits[j],
                    first_time_s: t,
                    peak_nm: 0.0,
                    samples_over: 0,
                });
                entry.samples_over += 1;
            }
        }
        Ok(())
    }

    /// Adds recorded sample `s` (already counted by [`add_control`](Self::add_control)) to the
    /// tracking errors, which are taken over the recorded samples.
    pub(crate) fn add_recorded(&mut self, s: &Sample<'_>) {
        self.samples += 1;
        // In the plane `z` is zero and `hypot(d, 0) = |d|` exactly: the planar distance's bits.
        let tip_error = (s.tip[0] - s.tip_ref[0])
            .hypot(s.tip[1] - s.tip_ref[1])
            .hypot(s.tip[2] - s.tip_ref[2]);
        self.tip_sq += tip_error * tip_error;
        self.tip_max = self.tip_max.max(tip_error);
        for i in 0..self.modal_sq.len() {
            let e = s.a[i] - s.a_ref[i];
            self.modal_sq[i] += e * e;
            self.modal_max[i] = self.modal_max[i].max(e.abs());
        }
    }

    pub(crate) fn summary(&self, steps: usize, rejected_steps: usize) -> Summary {
        let n = self.samples.max(1) as f64;
        let torque_limit_exceeded = self
            .exceeded
            .iter()
            .flatten()
            .map(|e| TorqueLimitExceeded {
                peak_nm: self.peak_joint[e.joint],
                ..e.clone()
            })
            .collect();
        Summary {
            controller_samples: self.controller_samples,
            recorded_samples: self.samples,
            steps,
            rejected_steps,
            simulated_s: self.last_t,
            tip_error_rms_m: (self.tip_sq / n).sqrt(),
            tip_error_max_m: self.tip_max,
            modal_error_rms_rad: self.modal_sq.iter().map(|s| (s / n).sqrt()).collect(),
            modal_error_max_rad: self.modal_max.clone(),
            peak_modal_torques_nm: self.peak_tau_star.clone(),
            peak_joint_torque_nm: self.peak_joint.iter().copied().fold(0.0, f64::max),
            peak_joint_torques_nm: self.peak_joint.clone(),
            control_effort_n2m2s: self.effort,
            tau_star_clamped_fraction: self
                .clamped
                .iter()
                .map(|&c| c as f64 / self.controller_samples.max(1) as f64)
                .collect(),
            torque_limit_exceeded,
            torque_projection_share: self
                .projected
                .map(|count| count as f64 / self.controller_samples.max(1) as f64),
            min_clearance_m: self.min_clearance,
            min_self_clearance_m: self.min_self_clearance,
        }
    }
}
