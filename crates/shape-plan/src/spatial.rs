//! The spatial modal arm: a universal-joint chain on `SpatialModalMap` (`docs/theory.md`, section
//! 8), placed from its base pose.

use crate::arm::{Arm, ArmScratch};
use crate::error::PlanError;
use backbone_kin::vec3::{add, column, cross, dot, mat_mul, rot_y, rot_z, scale, sub};
use backbone_kin::{BasePose, SpatialIk, SpatialModalMap};
use clearance::{ClearanceData, ClearanceModel, Pair, place};
use lane_math::check_len;

/// A universal-joint chain of the given links (joint angles `theta = J a`, interleaved
/// `[z_1, y_1, z_2, ...]`) leaving `base`.
#[derive(Debug, Clone, PartialEq)]
pub struct SpatialArm {
    map: SpatialModalMap,
    base: BasePose,
    lipschitz: f64,
}

impl SpatialArm {
    /// The arm of these links (base first), `harmonics` harmonics per bending plane, at `base`.
    pub fn new(link_lengths: &[f64], harmonics: usize, base: BasePose) -> Result<Self, PlanError> {
        base.validate()?;
        let map = SpatialModalMap::new(link_lengths, harmonics)?;
        // Frame k turns at |omega_k| <= sum of |theta_dot_j| over the joints up to link k, and a
        // point of link i is base + sum_{k < i} L_k R_k e_x + t L_i R_i e_x, so
        // |dx| <= sum_k L_k sum_{j <= 2k + 1} |J_j . da|.
        let (mut lipschitz, mut rates) = (0.0, 0.0);
        for (k, &length) in link_lengths.iter().enumerate() {
            for j in [2 * k, 2 * k + 1] {
                rates += map.row(j).iter().map(|x| x * x).sum::<f64>().sqrt();
            }
            lipschitz += length * rates;
        }
        Ok(Self {
            map,
            base,
            lipschitz,
        })
    }

    /// The modal map.
    pub fn map(&self) -> &SpatialModalMap {
        &self.map
    }

    /// The base pose.
    pub fn base_pose(&self) -> &BasePose {
        &self.base
    }
}

impl Arm for SpatialArm {
    fn dimension(&self) -> usize {
        3
    }

    fn n_links(&self) -> usize {
        self.map.n_links()
    }

    fn n_joints(&self) -> usize {
        self.map.n_joints()
    }

    fn n_coords(&self) -> usize {
        self.map.n_coords()
    }

    fn length(&self) -> f64 {
        self.map.link_lengths().iter().sum()
    }

    fn base(&self) -> [f64; 3] {
        self.base.xyz
    }

    /// The walk of `backbone_kin::spatial_joint_positions`, keeping each joint's axis:
    /// `R_i = R_{i-1} Rz(z_i) Ry(y_i)`, the `z` joint about `R_{i-1} e_z`, the `y` joint about
    /// `R_{i-1} Rz(z_i) e_y`, both at the link's proximal end.
    fn place(
        &self,
        clearance: &ClearanceModel,
        data: &mut ClearanceData,
        scratch: &mut ArmScratch,
        a: &[f64],
    ) -> Result<(), PlanError> {
        self.map.joint_angles(a, &mut scratch.theta)?;
        let mut rotation = self.base.rotation();
        scratch.points[0] = self.base.xyz;
        for (i, &length) in self.map.link_lengths().iter().enumerate() {
            let (z, y) = (scratch.theta[2 * i], scratch.theta[2 * i + 1]);
            scratch.axes[2 * i] = column(&rotation, 2);
            let after_z = mat_mul(rotation, rot_z(z));
            scratch.axes[2 * i + 1] = column(&after_z, 1);
            rotation = mat_mul(after_z, rot_y(y));
            scratch.points[i + 1] = add(scratch.points[i], scale(column(&rotation, 0), length));
            scratch.link_axes[i] = scratch.axes[2 * i];
        }
        place(clearance, data, &scratch.points, &scratch.link_axes)?;
        Ok(())
    }

    /// With `W_il = sum J_jl u_j` and `U_il = sum J_jl (u_j x o_j)` over the joints `j` of links
    /// up to `i` (`u_j` the axis, `o_j` the point), the envelope theorem's
    /// `d d / d theta_j = u_j . ((c - o_j) x n)` gives `d d / d a_l = W_il . (c x n) - U_il . n`
    /// for link `i` against an obstacle and `(U_kl - U_il) . n - (W_kl - W_il) . (c_k x n)` for
    /// links `i < k`; the tip moves by `d tip / d a_l = W_{n-1,l} x tip - U_{n-1,l}`.
    fn gradients(
        &self,
        clearance: &ClearanceModel,
        data: &mut ClearanceData,
        scratch: &mut ArmScratch,
        gradients: &mut [f64],
        tip_jacobian: &mut [f64],
    ) -> Result<(), PlanError> {
        let (n, m) = (self.n_links(), self.n_coords());
        check_len("tip Jacobian", tip_jacobian.len(), 3 * m)?;
        check_len(
            "pair gradients",
            gradients.len(),
            clearance.pairs().len() * m,
        )?;
        check_len("prefix sums", scratch.prefix.len(), 2 * n * m)?;
        for i in 0..n {
            for l in 0..m {
                let (mut w, mut u) = if i == 0 {
                    ([0.0; 3], [0.0; 3])
                } else {
                    let k = 2 * ((i - 1) * m + l);
                    (scratch.prefix[k], scratch.prefix[k + 1])
                };
                for j in [2 * i, 2 * i + 1] {
                    let (entry, axis) = (self.map.row(j)[l], scratch.axes[j]);
                    w = add(w, scale(axis, entry));
                    u = add(u, scale(cross(axis, scratch.points[i]), entry));
                }
                let k = 2 * (i * m + l);
                scratch.prefix[k] = w;
                scratch.prefix[k + 1] = u;
            }
        }
        let prefix = &scratch.prefix;
        let at = |i: usize, l: usize| (prefix[2 * (i * m + l)], prefix[2 * (i * m + l) + 1]);
        let tip = scratch.points[n];
        for l in 0..m {
            let (w, u) = at(n - 1, l);
            let column = sub(cross(w, tip), u);
            for (d, value) in column.into_iter().enumerate() {
                tip_jacobian[d * m + l] = value;
            }
        }
        for ((pair, closest), row) in clearance
            .pairs()
            .iter()
            .zip(data.closest())
            .zip(gradients.chunks_exact_mut(m.max(1)))
        {
            let normal = closest.normal;
            match *pair {
                Pair::Obstacle { link, .. } => {
                    let arm = cross(closest.point, normal);
                    for (l, g) in row.iter_mut().enumerate() {
                        let (w, u) = at(link, l);
                        *g = dot(w, arm) - dot(u, normal);
                    }
                }
                Pair::Links { link, other } => {
                    let arm = cross(closest.other, normal);
                    for (l, g) in row.iter_mut().enumerate() {
                        let ((w_lo, u_lo), (w_hi, u_hi)) = (at(link, l), at(other, l));
                        *g = dot(sub(u_hi, u_lo), normal) - dot(sub(w_hi, w_lo), arm);
                    }
                }
            }
        }
        Ok(())
    }

    fn lipschitz(&self) -> f64 {
        self.lipschitz
    }

    fn free_space_starts(&self, target: [f64; 3], _initial: &[f64]) -> Vec<Vec<f64>> {
        let Ok(mut ik) = SpatialIk::new(self.map.clone(), self.base) else {
            return Vec::new();
        };
        let (m, k2) = (self.map.n_coords(), self.map.n_coords() / 2);
        let mut starts = Vec::new();
        // Bent guesses in both planes (the straight arm is singular for targets on its axis).
        for (z, y) in [(0.5, 0.5), (-0.5, 0.5), (0.5, -0.5), (-0.5, -0.5)] {
            let mut a = vec![0.0; m];
            a[0] = z;
            a[k2] = y;
            if ik.solve(target, &mut a).is_ok() {
                starts.push(a);
            }
        }
        starts
    }
}
