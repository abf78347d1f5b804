//! What the in-loop MPC plans within besides the `tau*` box: the joint-torque polytope, joint
//! angle limits and clearance, as the rows `G u_k <= g` of every node of its horizon
//! ([`StepConstraints`], `docs/theory.md`, "MPC within limits and clearance").

use crate::error::SimError;
use clearance::{ClearanceData, ClearanceError, ClearanceModel, Pair};
use lane_math::dense::{cholesky, cholesky_solve};
use modal_reduce::{Plant, PlantData};
use optimal_ctl::{JointTorqueLimits, OptimalError, StepConstraints};

/// A clearance pair gets a row at a node when its clearance predicted for the next node is
/// within this distance of the margin (m).
pub const CLEARANCE_ACTIVATION_M: f64 = 0.02;

/// A pair's barrier is evaluated at a node when its clearance predicted for the next node is
/// within this distance beyond [`CLEARANCE_ACTIVATION_M`] of the margin (m).
pub const CLEARANCE_LOOKAHEAD_M: f64 = 0.05;

/// The time constant `T` (s) of the clearance barrier `psi = d + T d_dot >= c`: a pair's
/// clearance `d` approaches the margin `c` no faster than `(d - c) / T`, so the arm slows down
/// towards an obstacle instead of arriving at the margin at full speed, and the torque that
/// keeps the barrier acts through the next rate (`h T M*^-1`) as well as the next position
/// (`h^2 M*^-1`).
pub const CLEARANCE_APPROACH_S: f64 = 0.05;

/// At most this many clearance rows a node: the pairs with the least slack (the arm's few
/// modal coordinates leave no room for more independent ones).
pub const MAX_CLEARANCE_ROWS: usize = 16;

/// A joint gets its two angle rows at a node when its angle at the node, or its predicted
/// `theta + T theta_dot` at the next, is within this angle of its limit (rad).
pub const ANGLE_ACTIVATION_RAD: f64 = 0.1;

/// The most a clearance margin may be (m): far beyond any arm of `manip_dyn`'s link limits.
pub const MAX_CLEARANCE_MARGIN_M: f64 = 1e3;

/// What [`MpcController`](super::MpcController) plans within besides the `tau*` box (each
/// optional; with none of them it plans within the box alone, exactly as without limits).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MpcLimits {
    /// Joint torque limits (N m, one per joint, positive): every node's joint torques within
    /// them (exact rows, [`JointTorqueLimits`]).
    pub joint_torque_limits: Option<Vec<f64>>,
    /// Joint angle limits (rad, one per joint, positive): every node keeps
    /// `|theta_j + T theta_dot_j| <= limit_j` at the next node, `T` =
    /// [`joint_angle_approach_s`](Self::joint_angle_approach_s), so no joint passes its limit
    /// and each slows down towards it as the loop's projection makes it.
    pub joint_angle_limits: Option<Vec<f64>>,
    /// `T` of the angle rows (s, positive and at most 1e3; the loop's rule uses
    /// [`JOINT_ANGLE_APPROACH_S`](crate::JOINT_ANGLE_APPROACH_S) or its controller period).
    pub joint_angle_approach_s: f64,
    /// The links and obstacles: every node keeps each pair's linearised clearance at the next
    /// node at least [`clearance_margin_m`](Self::clearance_margin_m) (planar or spatial arms).
    pub clearance: Option<ClearanceModel>,
    /// The clearance the plans keep (m, non-negative, at most [`MAX_CLEARANCE_MARGIN_M`]).
    pub clearance_margin_m: f64,
}

impl MpcLimits {
    /// Whether there is nothing beyond the `tau*` box to plan within.
    pub fn is_empty(&self) -> bool {
        self.joint_torque_limits.is_none()
            && self.joint_angle_limits.is_none()
            && self.clearance.is_none()
    }
}

/// The joint angle rows' constants: `theta = J a + theta_0`.
#[derive(Debug, Clone)]
struct AngleRows {
    limits: Vec<f64>,
    /// `J` (`n x m`, row-major) and `theta_0` (`n`).
    jacobian: Vec<f64>,
    offset: Vec<f64>,
    approach: f64,
}

/// The clearance rows' model and working memory.
#[derive(Debug, Clone)]
struct ClearanceRows {
    model: ClearanceModel,
    data: ClearanceData,
    margin: f64,
    placement: Placement,
    /// The joints' gradient of one pair's clearance (`n` planar, `2n` spatial), and the modal
    /// map's `J^T` (`m x joints`, row-major).
    joint_gradient: Vec<f64>,
    jacobian_t: Vec<f64>,
    /// Per pair: the modal gradient of its clearance (`m`, filled for the candidates).
    gradients: Vec<f64>,
    /// Room for every pair as a candidate: each one's slack at the next node and its index.
    candidates: Vec<(f64, usize)>,
    /// The pairs of the rows written last, in row order (the first `n_rows`).
    pairs: Vec<usize>,
    n_rows: usize,
}

/// How the chain is placed for its clearance, by family.
#[derive(Debug, Clone)]
enum Placement {
    /// The planar chain: its link lengths and joint angles; a pair's joint gradient from
    /// `clearance::joint_gradient`.
    Planar {
        link_lengths: Vec<f64>,
        theta: Vec<f64>,
    },
    /// The spatial universal-joint chain: its `2n` joint angles, its `n + 1` points and each
    /// link's two joint axes (`z`, then `y`) in the world frame, walked as
    /// `backbone_kin::spatial_joint_positions` walks them; a pair's joint gradient from
    /// [`spatial_joint_gradient`].
    Spatial {
        theta: Vec<f64>,
        points: Vec<[f64; 3]>,
        axes: Vec<[[f64; 3]; 2]>,
        /// The `z` axes, for `clearance::place` (which distances do not use).
        place_axes: Vec<[f64; 3]>,
    },
}

/// The working memory of the rows of [`MpcLimits`] for one arm and MPC step, sized once;
/// [`bind`](Self::bind) hands them to a solve with the arm. Allocation-free per use.
///
/// At node `k` with state `x = (a, a_dot)` and control `u`, the semi-implicit Euler step's
/// `B = dF/du = [h^2 M*^-1; h M*^-1]` at `x` (from `M*` there, not the nominal `B` a forward pass
/// hands in), the next state at `u` is `F(x, u)` and at any `u'` it is `F(x, u) + B (u' - u)`
/// (exact: `a_ddot` is affine in `tau*`, eq 15), so:
///
/// - joint torques: `|A(x) u' + b(x)| <= L` ([`JointTorqueLimits`], exact);
/// - joint angles: with `s_j(u') = theta_j(a_{k+1}) + T theta_dot_j(a_dot_{k+1})`, exactly
///   `s_j(u) + J_j (B_a + T B_v) (u' - u)`, the rows `+-s_j(u') <= L_j` for every joint within
///   [`ANGLE_ACTIVATION_RAD`] of its limit at `a` or in `s_j(u)` (with semi-implicit Euler,
///   `s_j <= L_j` at every node keeps `theta_j <= L_j` at every node);
/// - clearance: with `psi(u') = d(a_{k+1}) + T g . a_dot_{k+1}`, `g = grad_a d` at the
///   predicted next coordinates `a_{k+1}(u)` and `T` = [`CLEARANCE_APPROACH_S`], exactly
///   `psi(u) + g (B_a + T B_v) (u' - u) >= min(d(a), c)` (the modal gradient: the pair's joint
///   gradient through `J^T`, eq 14; `d(a)` to first order back from `a_{k+1}`), for every pair
///   (link-obstacle and link-link) with `d(a_{k+1}(u))` or `psi(u)` within
///   [`CLEARANCE_ACTIVATION_M`] of the margin `c` (the barrier evaluated for the pairs within
///   [`CLEARANCE_LOOKAHEAD_M`] more), the [`MAX_CLEARANCE_ROWS`] with the least slack: a pair
///   approaches the margin no faster than `(d - c) / T`, and one already inside the margin may
///   not approach at all.
///
/// The solve's gain takes in the joint rows' state dependence (their state Jacobian by forward
/// differences, [`StepConstraints::state_jacobian`]) when there are no clearance rows.
#[derive(Debug, Clone)]
pub struct MpcConstraints {
    m: usize,
    step: f64,
    torque: Option<JointTorqueLimits>,
    angle: Option<AngleRows>,
    clearance: Option<ClearanceRows>,
    data: PlantData,
    /// `M*`'s factor and inverse at `x`, the step's `B` (`m x m` each, row-major: position
    /// rows, rate rows), the acceleration at `(x, u)`, the next state `(a, a_dot)` at `u`, and
    /// a row's scratch.
    factor: Vec<f64>,
    inverse: Vec<f64>,
    b_a: Vec<f64>,
    b_v: Vec<f64>,
    a_ddot: Vec<f64>,
    next: Vec<f64>,
    row: Vec<f64>,
}

impl MpcConstraints {
    /// The rows of `limits` for `model` and an MPC of step `step` (s), or `None` when `limits`
    /// is empty.
    ///
    /// # Errors
    /// [`SimError::InvalidSetting`] naming the limit: lengths other than the joints, limits
    /// that are not positive and finite, an approach time or margin out of its domain, or a
    /// clearance model of another number of links (or too many pairs).
    pub fn new<'p>(
        model: impl Into<Plant<'p>>,
        limits: &MpcLimits,
        step: f64,
    ) -> Result<Option<Self>, SimError> {
        if limits.is_empty() {
            return Ok(None);
        }
        let plant = model.into();
        let m = plant.n_coords();
        let torque = match &limits.joint_torque_limits {
            None => None,
            Some(l) => Some(JointTorqueLimits::new(plant, l).map_err(|e| {
                SimError::setting(
                    "limits.joint_torque_nm",
                    format!("cannot be planned within: {e}"),
                )
            })?),
        };
        let angle = match &limits.joint_angle_limits {
            None => None,
            Some(l) => Some(angle_rows(plant, l, limits.joint_angle_approach_s)?),
        };
        let clearance = match &limits.clearance {
            None => None,
            Some(model) => Some(clearance_rows(plant, model, limits.clearance_margin_m)?),
        };
        Ok(Some(Self {
            m,
            step,
            torque,
            angle,
            clearance,
            data: PlantData::new(plant),
            factor: vec![0.0; m * m],
            inverse: vec![0.0; m * m],
            b_a: vec![0.0; m * m],
            b_v: vec![0.0; m * m],
            a_ddot: vec![0.0; m],
            next: vec![0.0; 2 * m],
            row: vec![0.0; m],
        }))
    }

    /// The most rows a node may have: `2n` per kind of joint limit, and
    /// [`MAX_CLEARANCE_ROWS`] (or the number of pairs, if fewer).
    pub fn max_rows(&self) -> usize {
        self.torque.as_ref().map_or(0, JointTorqueLimits::max_rows)
            + self.angle.as_ref().map_or(0, |a| 2 * a.limits.len())
            + self
                .clearance
                .as_ref()
                .map_or(0, |c| c.model.pairs().len().min(MAX_CLEARANCE_ROWS))
    }

    /// The clearance pairs (indices into [`ClearanceModel::pairs`]) of the rows written last,
    /// in row order after the joint rows.
    pub fn clearance_pairs(&self) -> &[usize] {
        self.clearance
            .as_ref()
            .map_or(&[], |c| &c.pairs[..c.n_rows])
    }

    /// The rows with `plant` (the arm they were made for), as [`StepConstraints`].
    pub fn bind<'a>(&'a mut self, plant: Plant<'a>) -> BoundConstraints<'a> {
        BoundConstraints {
            constraints: self,
            plant,
        }
    }

    /// Writes the rows of node `(x, u)` (see [`StepConstraints::rows`]; `B` is computed at `x`).
    fn rows(
        &mut self,
        plant: Plant<'_>,
        (x, u): (&[f64], &[f64]),
        rows: &mut [f64],
        bounds: &mut [f64],
    ) -> Result<usize, OptimalError> {
        let (m, h) = (self.m, self.step);
        let mut count = match &mut self.torque {
            Some(torque) => torque.rows(plant, x, rows, bounds)?,
            None => 0,
        };
        if self.angle.is_none() && self.clearance.is_none() {
            return Ok(count);
        }
        // M*^-1 at x: the exact B = [h^2 M*^-1; h M*^-1] of the step at this state (the `b`
        // handed in is the nominal state's in a forward pass), and the next state at u
        // (semi-implicit Euler, as the plan's dynamics).
        let (a, a_dot) = (&x[..m], &x[m..2 * m]);
        plant.terms(&mut self.data, a, a_dot)?;
        let mass = self.data.mass_matrix();
        for i in 0..m {
            for j in 0..m {
                self.factor[i * m + j] = mass[(i, j)];
                self.inverse[i * m + j] = if i == j { 1.0 } else { 0.0 };
            }
        }
        if !cholesky(&mut self.factor, m) {
            return Err(OptimalError::NotPositiveDefinite("M*"));
        }
        cholesky_solve(&self.factor, m, &mut self.inverse, m);
        let (coriolis, gravity) = (self.data.coriolis(), self.data.gravity());
        for i in 0..m {
            self.a_ddot[i] = (0..m)
                .map(|j| self.inverse[i * m + j] * (u[j] - coriolis[j] - gravity[j]))
                .sum();
        }
        for (i, inverse) in self.inverse.iter().enumerate() {
            self.b_a[i] = h * h * inverse;
            self.b_v[i] = h * inverse;
        }
        let (next_a, next_v) = self.next.split_at_mut(m);
        for i in 0..m {
            next_v[i] = a_dot[i] + h * self.a_ddot[i];
            next_a[i] = a[i] + h * next_v[i];
        }
        let (b_a, b_v) = (&self.b_a[..], &self.b_v[..]);
        if let Some(angle) = &self.angle {
            for (j, &limit) in angle.limits.iter().enumerate() {
                let jac = &angle.jacobian[j * m..(j + 1) * m];
                let now = dot(jac, a) + angle.offset[j];
                let s = dot(jac, next_a) + angle.offset[j] + angle.approach * dot(jac, next_v);
                if now.abs().max(s.abs()) < limit - ANGLE_ACTIVATION_RAD {
                    continue;
                }
                // d s / d u' = J_j (B_a + T B_v).
                for (i, g) in self.row[..m].iter_mut().enumerate() {
                    *g = (0..m)
                        .map(|l| jac[l] * (b_a[l * m + i] + angle.approach * b_v[l * m + i]))
                        .sum();
                }
                let gu = dot(&self.row[..m], u);
                for sign in [1.0, -1.0] {
                    for (r, g) in rows[count * m..(count + 1) * m]
                        .iter_mut()
                        .zip(&self.row[..m])
                    {
                        *r = sign * g;
                    }
                    bounds[count] = limit - sign * (s - gu);
                    count += 1;
                }
            }
        }
        if let Some(c) = &mut self.clearance {
            let (rows, bounds) = (&mut rows[count * m..], &mut bounds[count..]);
            let (next_a, next_v) = self.next.split_at(m);
            count += c.rows(plant, (a, next_a, next_v, u), (b_a, b_v), rows, bounds)?;
        }
        Ok(count)
    }
}

impl ClearanceRows {
    /// Writes the clearance rows at the node `a` whose next coordinates and rates at `u` are
    /// `next_a`, `next_v`, with `b_a = d a_{k+1} / d u`, `b_v = d a_dot_{k+1} / d u`; returns
    /// their number.
    fn rows(
        &mut self,
        plant: Plant<'_>,
        (a, next_a, next_v, u): (&[f64], &[f64], &[f64], &[f64]),
        (b_a, b_v): (&[f64], &[f64]),
        rows: &mut [f64],
        bounds: &mut [f64],
    ) -> Result<usize, OptimalError> {
        let m = a.len();
        let approach = CLEARANCE_APPROACH_S;
        // Every pair's clearance at the predicted next coordinates.
        self.place(plant, next_a)?;
        clearance::distances(&self.model, &mut self.data);
        let reach = self.margin + CLEARANCE_ACTIVATION_M;
        let mut n_candidates = 0;
        for (p, &next) in self.data.distances().iter().enumerate() {
            if next < reach + CLEARANCE_LOOKAHEAD_M {
                self.candidates[n_candidates] = (next, p);
                n_candidates += 1;
            }
        }
        // Their modal gradients there, the barrier psi = d + T d_dot at the next node and its
        // slack over the floor min(d(a), c), d(a) to first order back from the next
        // coordinates; a pair neither near the margin nor approaching it fast is dropped.
        let mut kept = 0;
        for c in 0..n_candidates {
            let (next, p) = self.candidates[c];
            self.gradient(m, p)?;
            let gradient = &self.gradients[p * m..(p + 1) * m];
            let now = next - dot_difference(gradient, next_a, a);
            let psi = next + approach * dot(gradient, next_v);
            if next.min(psi) >= reach {
                continue;
            }
            self.candidates[kept] = (psi - now.min(self.margin), p);
            kept += 1;
        }
        n_candidates = kept;
        if n_candidates > MAX_CLEARANCE_ROWS {
            self.candidates[..n_candidates]
                .select_nth_unstable_by(MAX_CLEARANCE_ROWS - 1, |x, y| x.0.total_cmp(&y.0));
            n_candidates = MAX_CLEARANCE_ROWS;
        }
        for (r, &(slack, p)) in self.candidates[..n_candidates].iter().enumerate() {
            // psi(u') ~ psi(u) + c . (u' - u) >= floor, c = grad d . (B_a + T B_v):
            // -c . u' <= slack - c . u.
            let gradient = &self.gradients[p * m..(p + 1) * m];
            let row = &mut rows[r * m..(r + 1) * m];
            for (i, value) in row.iter_mut().enumerate() {
                *value = -(0..m)
                    .map(|l| gradient[l] * (b_a[l * m + i] + approach * b_v[l * m + i]))
                    .sum::<f64>();
            }
            bounds[r] = slack + dot(row, u);
            self.pairs[r] = p;
        }
        self.n_rows = n_candidates;
        Ok(n_candidates)
    }

    /// Places the chain at the coordinates `a`.
    fn place(&mut self, plant: Plant<'_>, a: &[f64]) -> Result<(), OptimalError> {
        let kinematics = |e: backbone_kin::KinError| OptimalError::Dynamics(e.into());
        match (&mut self.placement, plant) {
            (
                Placement::Planar {
                    link_lengths,
                    theta,
                },
                Plant::Planar(model),
            ) => {
                model.map().joint_angles(a, theta).map_err(kinematics)?;
                clearance::place_planar(&self.model, &mut self.data, link_lengths, theta)
                    .map_err(clearance_failure)?;
            }
            (
                Placement::Spatial {
                    theta,
                    points,
                    axes,
                    place_axes,
                    ..
                },
                Plant::Spatial(model),
            ) => {
                let map = model.map();
                map.joint_angles(a, theta).map_err(kinematics)?;
                walk_spatial(map.link_lengths(), model.base(), theta, points, axes);
                for (place, axis) in place_axes.iter_mut().zip(axes.iter()) {
                    *place = axis[0];
                }
                clearance::place(&self.model, &mut self.data, points, place_axes)
                    .map_err(clearance_failure)?;
            }
            _ => unreachable!("the clearance rows are built for the arm's own family"),
        }
        Ok(())
    }

    /// The modal gradient `d d / d a = J^T d d / d theta` of pair `p`'s clearance (after the
    /// distances) into `gradients`: the pair's joint gradient through eq 14's `J^T`, `O(n m)`,
    /// for the few pairs near the margin alone.
    fn gradient(&mut self, m: usize, p: usize) -> Result<(), OptimalError> {
        match &self.placement {
            Placement::Planar { .. } => {
                clearance::joint_gradient(&self.model, &self.data, p, &mut self.joint_gradient)
                    .map_err(clearance_failure)?;
            }
            Placement::Spatial { points, axes, .. } => spatial_joint_gradient(
                self.model.pairs()[p],
                &self.data.closest()[p],
                (points, axes),
                &mut self.joint_gradient,
            ),
        }
        let joints = self.joint_gradient.len();
        for (out, column) in self.gradients[p * m..(p + 1) * m]
            .iter_mut()
            .zip(self.jacobian_t.chunks_exact(joints))
        {
            *out = dot(column, &self.joint_gradient);
        }
        Ok(())
    }
}

/// The rows of [`MpcConstraints`] bound to their arm: [`StepConstraints`] for
/// [`Mpc::solve_constrained`](optimal_ctl::Mpc::solve_constrained).
#[derive(Debug)]
pub struct BoundConstraints<'a> {
    constraints: &'a mut MpcConstraints,
    plant: Plant<'a>,
}

impl StepConstraints for BoundConstraints<'_> {
    fn max_rows(&self) -> usize {
        self.constraints.max_rows()
    }

    fn rows(
        &mut self,
        _k: usize,
        x: &[f64],
        u: &[f64],
        _b: &[f64],
        rows: &mut [f64],
        bounds: &mut [f64],
    ) -> Result<usize, OptimalError> {
        self.constraints.rows(self.plant, (x, u), rows, bounds)
    }

    /// The joint rows' state Jacobian goes into the gain; with clearance rows (a distance and
    /// its gradient per pair near the margin, each evaluation) it does not.
    fn state_jacobian(&self) -> bool {
        self.constraints.clearance.is_none()
    }

    /// The rows are those of `(x, u)` (`B` from `x`, not the `b` handed in).
    fn rows_of_state_and_control(&self) -> bool {
        true
    }
}

/// The angle rows of `plant` under `limits` with approach time `approach`.
fn angle_rows(plant: Plant<'_>, limits: &[f64], approach: f64) -> Result<AngleRows, SimError> {
    const FIELD: &str = "limits.joint_angle_rad";
    let (n, m) = (plant.n_joints(), plant.n_coords());
    if limits.len() != n {
        return Err(SimError::setting(
            FIELD,
            format!("has {} entries, the arm has {n} joints", limits.len()),
        ));
    }
    if let Some(l) = limits.iter().find(|l| !(l.is_finite() && **l > 0.0)) {
        return Err(SimError::setting(
            FIELD,
            format!("must be positive and finite, got {l}"),
        ));
    }
    if !(approach.is_finite() && approach > 0.0 && approach <= 1e3) {
        return Err(SimError::setting(
            "joint_angle_approach_s",
            format!("must be positive and at most 1e3 s, got {approach}"),
        ));
    }
    let jacobian = joint_jacobian(plant)?;
    let mut offset = vec![0.0; n];
    let zero = vec![0.0; m];
    match plant {
        Plant::Planar(model) => model.map().joint_angles(&zero, &mut offset)?,
        Plant::Spatial(model) => model.map().joint_angles(&zero, &mut offset)?,
    }
    Ok(AngleRows {
        limits: limits.to_vec(),
        jacobian,
        offset,
        approach,
    })
}

/// The modal map's `J = d theta / d a` (`joints x m`, row-major; `theta = J a + theta_0`): row
/// `j` is `J^T e_j`, eq 14's projection of a unit joint torque.
pub(crate) fn joint_jacobian(plant: Plant<'_>) -> Result<Vec<f64>, SimError> {
    let (n, m) = (plant.n_joints(), plant.n_coords());
    let mut jacobian = vec![0.0; n * m];
    let mut unit = vec![0.0; n];
    for (j, row) in jacobian.chunks_exact_mut(m).enumerate() {
        unit.fill(0.0);
        unit[j] = 1.0;
        plant.project_torques(&unit, row).map_err(SimError::Model)?;
    }
    Ok(jacobian)
}

/// The transpose of `a` (row-major, `columns` columns).
fn transpose(a: &[f64], columns: usize) -> Vec<f64> {
    let rows = a.len().checked_div(columns).unwrap_or(0);
    (0..columns)
        .flat_map(|c| (0..rows).map(move |r| a[r * columns + c]))
        .collect()
}

/// The clearance rows of `plant` among `model` with `margin`.
fn clearance_rows(
    plant: Plant<'_>,
    model: &ClearanceModel,
    margin: f64,
) -> Result<ClearanceRows, SimError> {
    if !(margin.is_finite() && (0.0..=MAX_CLEARANCE_MARGIN_M).contains(&margin)) {
        return Err(SimError::setting(
            "controller.clearance_m",
            format!("must be non-negative and at most 1e3 m, got {margin}"),
        ));
    }
    let (n, m) = (plant.n_links(), plant.n_coords());
    if model.n_links() != n {
        return Err(SimError::setting(
            "obstacles",
            format!(
                "are measured for {} links, the arm has {n}",
                model.n_links()
            ),
        ));
    }
    let pairs = model.pairs().len();
    if pairs.saturating_mul(m) > clearance::MAX_GRADIENT_ENTRIES {
        return Err(SimError::setting(
            "obstacles",
            format!(
                "cannot be measured: {pairs} pairs x {m} coordinates exceed {} gradient entries",
                clearance::MAX_GRADIENT_ENTRIES
            ),
        ));
    }
    // No modal gradients in the data: each candidate's comes from its joint gradient.
    let data = ClearanceData::new(model, 0)
        .map_err(|e| SimError::setting("obstacles", format!("cannot be measured: {e}")))?;
    let placement = match plant {
        Plant::Planar(planar) => Placement::Planar {
            link_lengths: planar.chain().link_lengths().collect(),
            theta: vec![0.0; n],
        },
        Plant::Spatial(_) => Placement::Spatial {
            theta: vec![0.0; 2 * n],
            points: vec![[0.0; 3]; n + 1],
            axes: vec![[[0.0; 3]; 2]; n],
            place_axes: vec![[0.0; 3]; n],
        },
    };
    Ok(ClearanceRows {
        model: model.clone(),
        data,
        margin,
        placement,
        joint_gradient: vec![0.0; plant.n_joints()],
        jacobian_t: transpose(&joint_jacobian(plant)?, m),
        gradients: vec![0.0; pairs * m],
        candidates: vec![(0.0, 0); pairs],
        pairs: vec![0; pairs.min(MAX_CLEARANCE_ROWS)],
        n_rows: 0,
    })
}

/// A clearance evaluation the kinematics refused at a planned state, as the dynamics' error.
fn clearance_failure(e: ClearanceError) -> OptimalError {
    match e {
        ClearanceError::Kinematics(e) => OptimalError::Dynamics(e.into()),
        ClearanceError::Dimension {
            name,
            expected,
            found,
        } => OptimalError::Dimension {
            name,
            expected,
            found,
        },
        _ => OptimalError::InvalidSetting {
            name: "planned state",
            requirement: "a placement of the chain with finite clearances",
            value: f64::NAN,
        },
    }
}

fn dot(x: &[f64], y: &[f64]) -> f64 {
    x.iter().zip(y).map(|(a, b)| a * b).sum()
}

/// `g . (x - y)`.
fn dot_difference(g: &[f64], x: &[f64], y: &[f64]) -> f64 {
    g.iter()
        .zip(x.iter().zip(y))
        .map(|(g, (x, y))| g * (x - y))
        .sum()
}

/// The universal-joint chain's points (`n + 1`) and each link's joint axes (`z`, then `y`) in the
/// world frame at the joint angles `theta` (`2n`): `R_i = R_{i-1} Rz(z_i) Ry(y_i)` from the base's
/// rotation, `p_i = p_{i-1} + L_i R_i e_x` (`backbone_kin::spatial_joint_positions`), the `z`
/// axis the parent frame's third column, the `y` axis the second after turning about it.
fn walk_spatial(
    link_lengths: &[f64],
    base: &backbone_kin::BasePose,
    theta: &[f64],
    points: &mut [[f64; 3]],
    axes: &mut [[[f64; 3]; 2]],
) {
    use backbone_kin::vec3::{column, mat_mul, rot_y, rot_z};
    let mut rotation = base.rotation();
    points[0] = base.xyz;
    for (i, (&length, angles)) in link_lengths.iter().zip(theta.chunks_exact(2)).enumerate() {
        let z_axis = column(&rotation, 2);
        let after_z = mat_mul(rotation, rot_z(angles[0]));
        axes[i] = [z_axis, column(&after_z, 1)];
        rotation = mat_mul(after_z, rot_y(angles[1]));
        let x_axis = column(&rotation, 0);
        let start = points[i];
        points[i + 1] = std::array::from_fn(|d| start[d] + length * x_axis[d]);
    }
}

/// `d d / d theta` of one pair of the spatial chain (`2n`, interleaved `z`, `y` per link) from
/// its closest points and normal: turning a joint (axis `w` through `p`) moves the closest point
/// `c` it carries with velocity `w x (c - p)`, so `d d / d theta = w . ((c - p) x n)` for the
/// joints of links up to the link against an obstacle, and `-w . ((c_k - p) x n)` for the joints
/// of links `i + 1..=k` of two links `i < k` ([`clearance::joint_gradient`]'s rule, two axes a
/// joint point).
fn spatial_joint_gradient(
    pair: Pair,
    closest: &clearance::Closest,
    (points, axes): (&[[f64; 3]], &[[[f64; 3]; 2]]),
    out: &mut [f64],
) {
    use backbone_kin::vec3::{cross, dot as dot3, sub};
    out.fill(0.0);
    let (point, first, last, sign) = match pair {
        Pair::Obstacle { link, .. } => (closest.point, 0, link, 1.0),
        Pair::Links { link, other } => (closest.other, link + 1, other, -1.0),
    };
    for j in first..=last {
        let arm = cross(sub(point, points[j]), closest.normal);
        out[2 * j] = sign * dot3(axes[j][0], arm);
        out[2 * j + 1] = sign * dot3(axes[j][1], arm);
    }
}
