//! The planar modal arm: `K` harmonics, `alpha0` fixed or free, base at the origin.

use crate::arm::{Arm, ArmScratch};
use crate::error::PlanError;
use backbone_kin::{BaseAngle, Branch, ChainIk, ModalMap};
use clearance::{ClearanceData, ClearanceModel, modal_gradients, place_planar};
use lane_math::check_len;

/// A planar chain of the given links, base at the origin, joint angles
/// `theta = J a + theta_0` from the `K`-harmonic [`ModalMap`] of these links (eqs 7-11).
#[derive(Debug, Clone, PartialEq)]
pub struct PlanarArm {
    link_lengths: Vec<f64>,
    map: ModalMap,
    lipschitz: f64,
}

impl PlanarArm {
    /// The arm of these links (base first) on the `harmonics`-harmonic family with `base`.
    pub fn new(link_lengths: &[f64], harmonics: usize, base: BaseAngle) -> Result<Self, PlanError> {
        let map = ModalMap::new(link_lengths, harmonics, base)?;
        // Link k points along phi_k = theta_1 + ... + theta_k = Phi_k . a (+ alpha0), Phi_k the
        // prefix sum of J's rows (eq 7), and a point of link i is
        // sum_{k < i} L_k u(phi_k) + t L_i u(phi_i), u the unit vector of an angle, so
        // |dx| <= sum_{k <= i} L_k |dphi_k| <= (sum_k L_k |Phi_k|) |da|.
        let m = map.n_coords();
        let mut inclination = vec![0.0; m];
        let mut lipschitz = 0.0;
        for (k, &length) in link_lengths.iter().enumerate() {
            for (phi, j) in inclination.iter_mut().zip(map.row(k)) {
                *phi += j;
            }
            lipschitz += length * inclination.iter().map(|x| x * x).sum::<f64>().sqrt();
        }
        Ok(Self {
            link_lengths: link_lengths.to_vec(),
            map,
            lipschitz,
        })
    }

    /// The modal map.
    pub fn map(&self) -> &ModalMap {
        &self.map
    }

    /// The link lengths, base first.
    pub fn link_lengths(&self) -> &[f64] {
        &self.link_lengths
    }
}

impl Arm for PlanarArm {
    fn dimension(&self) -> usize {
        2
    }

    fn n_links(&self) -> usize {
        self.link_lengths.len()
    }

    fn n_joints(&self) -> usize {
        self.link_lengths.len()
    }

    fn n_coords(&self) -> usize {
        self.map.n_coords()
    }

    fn length(&self) -> f64 {
        self.link_lengths.iter().sum()
    }

    fn base(&self) -> [f64; 3] {
        [0.0; 3]
    }

    fn place(
        &self,
        clearance: &ClearanceModel,
        data: &mut ClearanceData,
        scratch: &mut ArmScratch,
        a: &[f64],
    ) -> Result<(), PlanError> {
        self.map.joint_angles(a, &mut scratch.theta)?;
        place_planar(clearance, data, &self.link_lengths, &scratch.theta)?;
        Ok(())
    }

    fn gradients(
        &self,
        clearance: &ClearanceModel,
        data: &mut ClearanceData,
        _scratch: &mut ArmScratch,
        gradients: &mut [f64],
        tip_jacobian: &mut [f64],
    ) -> Result<(), PlanError> {
        let m = self.map.n_coords();
        check_len("tip Jacobian", tip_jacobian.len(), 3 * m)?;
        check_len(
            "pair gradients",
            gradients.len(),
            clearance.pairs().len() * m,
        )?;
        modal_gradients(clearance, data, &self.map)?;
        for (k, row) in gradients.chunks_exact_mut(m.max(1)).enumerate() {
            row.copy_from_slice(data.modal_gradient(k));
        }
        // d tip / d theta_j = z x (tip - p_j), then d tip / d a = sum_j (d tip / d theta_j) J_j.
        let points = data.points();
        let tip = points[self.link_lengths.len()];
        tip_jacobian.fill(0.0);
        for (j, p) in points[..self.link_lengths.len()].iter().enumerate() {
            let velocity = [p[1] - tip[1], tip[0] - p[0]];
            for (l, &entry) in self.map.row(j).iter().enumerate() {
                tip_jacobian[l] += entry * velocity[0];
                tip_jacobian[m + l] += entry * velocity[1];
            }
        }
        Ok(())
    }

    fn lipschitz(&self) -> f64 {
        self.lipschitz
    }

    fn free_space_starts(&self, target: [f64; 3], initial: &[f64]) -> Vec<Vec<f64>> {
        let m = self.map.n_coords();
        let (alpha0, modes) = match self.map.base_angle() {
            BaseAngle::Fixed(alpha0) => (alpha0, m),
            BaseAngle::Free => (initial.get(m - 1).copied().unwrap_or(0.0), m - 1),
        };
        let Ok(mut ik) = ChainIk::new(&self.link_lengths, self.map.harmonics(), alpha0) else {
            return Vec::new();
        };
        let mut starts = Vec::new();
        for branch in [Branch::Positive, Branch::Negative] {
            let mut a = vec![0.0; m];
            if ik
                .solve_from_closed_form([target[0], target[1]], branch, &mut a[..modes])
                .is_ok()
            {
                if modes < m {
                    a[m - 1] = alpha0;
                }
                starts.push(a);
            }
        }
        starts
    }
}
