//! Follow-the-leader deployment of a planar arm with a base insertion axis into a channel
//! (`docs/theory.md`, "Follow-the-leader deployment").
//!
//! The channel is a centreline polyline `P_0, ..., P_M` and a radius; the insertion axis is the
//! line through the entry `P_0` along the first segment's direction `d`. The tip's path is
//! `Gamma(sigma)`: `P_0 + sigma d` behind the entry (`sigma <= 0`, the guide the arm comes
//! from) and the centreline at arc length `sigma` beyond it. At tip progress `tau` the tip is
//! `Gamma(tau)` and every joint lies on `Gamma` too: from the tip backwards, joint `k` is the first
//! point of `Gamma` behind joint `k + 1` at the chord distance `L_k`. The base joint lands on the
//! axis at `sigma_0 <= 0`, which fixes the prismatic insertion `q = sigma_0 + l` (`q = 0`: fully
//! retracted, tip at the entry). This is the discrete chain's exact follow-the-leader shape:
//! the body occupies the path its tip traced.
//!
//! The revolute joints follow the constant modal map of the whole chain, `theta = J a + theta_0`
//! (eq 8, `alpha0` the axis's angle, `K` harmonics): the deployed length changes only `q`, and the
//! modal coordinates at each step are the least-squares fit `a = argmin |J a + theta_0 -
//! theta_FTL|`, exact when `2K = n`. The metrics are those of the chain the fit realises.

use crate::channel::Channel;
use crate::deploy_metrics::{
    DeployMetrics, DeployTracker, MAX_DEPLOY_METRIC_WORK, deploy_metric_work,
};
use crate::error::PlanError;
use crate::polyline::dist;
use backbone_kin::{BaseAngle, ModalMap, joint_positions};
use lane_math::check_finite;
use optimal_ctl::LinearQp;

/// The most deployment steps [`follow_the_leader`] accepts.
pub const MAX_DEPLOY_STEPS: usize = 10_000;
/// The most the centreline may be longer than the shortest link, as a ratio (bounds the
/// backward search of each joint).
pub const MAX_LENGTH_RATIO: f64 = 1e6;

/// One step of a deployment.
#[derive(Debug, Clone, PartialEq)]
pub struct DeployFrame {
    /// The tip's progress `tau` along the centreline, m.
    pub progress: f64,
    /// The prismatic insertion `q` (the base joint at `sigma_0 = q - l` on the axis), m.
    pub insertion: f64,
    /// The exact follow-the-leader joint angles (`theta_1` from the `x` axis).
    pub theta: Vec<f64>,
    /// The modal coordinates fitted to them.
    pub modal: Vec<f64>,
    /// The joint points of the chain the modal coordinates realise, base first.
    pub points: Vec<[f64; 2]>,
}

/// A deployment: its steps and metrics.
#[derive(Debug, Clone, PartialEq)]
pub struct Deployment {
    /// The steps, tip progress from `0` to the deployed length.
    pub frames: Vec<DeployFrame>,
    /// The metrics over all steps.
    pub metrics: DeployMetrics,
}

/// Deploys the planar chain of `link_lengths` (links of radius `link_radius`) into `channel`
/// by follow-the-leader (module docs) in `steps` equal steps of tip progress up to `depth`
/// (at most the centreline's length), fitting `harmonics` harmonics at each step.
///
/// Errors: input errors for sizes and numbers (including a centreline longer than
/// [`MAX_LENGTH_RATIO`] shortest links, a channel no wider than the links, more than
/// [`MAX_DEPLOY_METRIC_WORK`] to measure); [`PlanError::OutOfRange`] when `depth` exceeds
/// the centreline or would pull the base past the entry (the arm is shorter than the depth);
/// [`PlanError::DeployFoldsOnItself`] when a shape's links that share no joint overlap (the
/// centreline turns back on itself within a few links).
pub fn follow_the_leader(
    channel: &Channel,
    link_lengths: &[f64],
    link_radius: f64,
    harmonics: usize,
    depth: f64,
    steps: usize,
) -> Result<Deployment, PlanError> {
    check_finite("deploy depth", depth)?;
    if !(0.0..=channel.length()).contains(&depth) {
        return Err(PlanError::OutOfRange {
            name: "deploy depth",
            bound: "within [0, the centreline's length]",
            value: depth,
        });
    }
    if steps == 0 || steps > MAX_DEPLOY_STEPS {
        return Err(PlanError::TooMany {
            name: "deploy steps (at least 1)",
            got: steps,
            max: MAX_DEPLOY_STEPS,
        });
    }
    // Not `>=`-negated: a NaN radius is the tracker's to refuse, by name.
    if link_radius >= channel.radius() {
        return Err(PlanError::OutOfRange {
            name: "deploy radius (the arm must fit in the channel)",
            bound: "larger than the arm's link radius",
            value: channel.radius(),
        });
    }
    let work = deploy_metric_work(link_lengths.len(), steps + 1);
    if work > MAX_DEPLOY_METRIC_WORK {
        return Err(PlanError::OutOfRange {
            name: "deploy work (steps x links: the metrics of every shape)",
            bound: "at most 2e9 (MAX_DEPLOY_METRIC_WORK: fewer links or steps)",
            value: work,
        });
    }
    let axis = channel.axis();
    let alpha0 = axis[1].atan2(axis[0]);
    // The map checks the link lengths (each positive and finite) before their ratio is taken.
    let map = ModalMap::new(link_lengths, harmonics, BaseAngle::Fixed(alpha0))?;
    let shortest = link_lengths.iter().copied().fold(f64::INFINITY, f64::min);
    if channel.length() + link_lengths.iter().sum::<f64>() > MAX_LENGTH_RATIO * shortest {
        return Err(PlanError::OutOfRange {
            name: "deploy centerline length over the shortest link",
            bound: "at most 1e6",
            value: channel.length() / shortest,
        });
    }
    let (n, m) = (link_lengths.len(), map.n_coords());
    let length: f64 = link_lengths.iter().sum();
    // The normal equations of the fit, J^T J (constant), through LinearQp without constraints.
    let mut normal = vec![0.0; m * m];
    for i in 0..m {
        for j in 0..m {
            normal[i * m + j] = (0..n).map(|k| map.entry(k, i) * map.entry(k, j)).sum();
        }
    }
    let mut qp = LinearQp::new(m, 0);
    let mut linear = vec![0.0; m];
    let mut frames = Vec::with_capacity(steps + 1);
    let mut sigma = vec![0.0; n + 1];
    let mut joints = vec![[0.0; 2]; n + 1];
    let mut tracker = DeployTracker::new(channel, link_lengths, link_radius)?;
    for step in 0..=steps {
        let tau = depth * step as f64 / steps as f64;
        // Joints on Gamma, from the tip back.
        sigma[n] = tau;
        joints[n] = channel.point_at(tau);
        for k in (0..n).rev() {
            sigma[k] = chord_back(channel, sigma[k + 1], joints[k + 1], link_lengths[k]);
            joints[k] = channel.point_at(sigma[k]);
        }
        let base_sigma = sigma[0];
        if base_sigma > 1e-12 * length {
            let reached = depth * step.saturating_sub(1) as f64 / steps as f64;
            return Err(PlanError::ArmTooShort {
                depth,
                reach: reach(channel, link_lengths, reached, tau),
            });
        }
        let mut theta = vec![0.0; n];
        // Absolute link angles, each within half a turn of the previous one (the first of the
        // axis's angle), and theta_k their differences (theta_1 from the x axis).
        let (mut previous, mut reference) = (0.0, alpha0);
        for k in 0..n {
            let (a, b) = (joints[k], joints[k + 1]);
            let phi = unwrap(reference, (b[1] - a[1]).atan2(b[0] - a[0]));
            theta[k] = phi - previous;
            (previous, reference) = (phi, phi);
        }
        // The fit: J^T J a = J^T (theta - theta_0).
        for (l, q) in linear.iter_mut().enumerate() {
            *q = -(0..n)
                .map(|k| map.entry(k, l) * (theta[k] - map.offset()[k]))
                .sum::<f64>();
        }
        let mut modal = vec![0.0; m];
        qp.solve(&normal, &linear, &[], &[], &mut modal)
            .map_err(|_| PlanError::OutOfRange {
                name: "harmonics (the fit needs at least 2K links)",
                bound: "at most half the links",
                value: harmonics as f64,
            })?;
        let mut fitted = vec![0.0; n];
        map.joint_angles(&modal, &mut fitted)?;
        let mut points = vec![[0.0; 2]; n + 1];
        joint_positions(link_lengths, &fitted, &mut points)?;
        for p in &mut points {
            p[0] += joints[0][0];
            p[1] += joints[0][1];
        }
        // The deployed length is the arm's length past the entry, the insertion, as a dynamic
        // run measures it.
        let sample = tracker.add(&points, base_sigma + length);
        if sample.self_clearance < 0.0 {
            return Err(PlanError::DeployFoldsOnItself {
                progress: tau,
                clearance: sample.self_clearance,
            });
        }
        frames.push(DeployFrame {
            progress: tau,
            insertion: base_sigma + length,
            theta,
            modal,
            points,
        });
    }
    Ok(Deployment {
        frames,
        metrics: tracker.metrics(),
    })
}

/// The largest `sigma < from` (searched backwards in steps of a tenth of the chord, then
/// bisected) with `|Gamma(sigma) - joint| = chord`: behind the entry `Gamma` is a straight ray,
/// so such a point exists.
fn chord_back(channel: &Channel, from: f64, joint: [f64; 2], chord: f64) -> f64 {
    let step = 0.1 * chord;
    let (mut hi, mut lo) = (from, from - step);
    while dist(channel.point_at(lo), joint) < chord {
        hi = lo;
        lo -= step;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid == lo || mid == hi {
            break;
        }
        if dist(channel.point_at(mid), joint) < chord {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The most tip progress (m) at which the chain of `link_lengths`, its joints on the centreline
/// from the tip back, keeps its base at the entry: bisected between `within` (a progress that
/// keeps it) and `beyond` (one that does not).
fn reach(channel: &Channel, link_lengths: &[f64], within: f64, beyond: f64) -> f64 {
    let base_at = |tau: f64| {
        let (mut sigma, mut joint) = (tau, channel.point_at(tau));
        for &chord in link_lengths.iter().rev() {
            sigma = chord_back(channel, sigma, joint, chord);
            joint = channel.point_at(sigma);
        }
        sigma
    };
    let (mut lo, mut hi) = (within, beyond);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if mid == lo || mid == hi {
            break;
        }
        if base_at(mid) > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    lo
}

/// `angle` moved by whole turns to within `pi` of `previous`.
fn unwrap(previous: f64, angle: f64) -> f64 {
    let turns = ((angle - previous) / std::f64::consts::TAU).round();
    angle - turns * std::f64::consts::TAU
}
