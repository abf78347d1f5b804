//! The projection path: form the full chain's `M`, `C` and `G` and project them onto the modal
//! coordinates with faer (eq 14), `O(n^2 m)`. The reference against which the default
//! [`reduced_terms`](crate::reduced_terms) is tested, and the method of the paper.

use faer::linalg::matmul::matmul;
use faer::{Accum, MatMut, Par};
use manip_dyn::{DynError, MAX_DENSE_LINKS};

use crate::data::{Projection, ReducedData};
use crate::error::{ReduceError, check_finite_result};
use crate::model::ReducedModel;
use crate::torques::project;
use lane_math::check_values;

/// Computes `M* = J^T M J`, `C* = J^T C(theta, J a_dot)` and `G* = J^T G(theta)` at
/// `theta = J a + theta_0` (eq 14) into `data`, by forming the full `n x n` mass matrix with
/// `manip_dyn::mass_matrix` and multiplying with faer (sequential). The first call on a `data`
/// allocates the `n x n` and `n x m` matrices; later calls allocate nothing. Refuses chains of
/// more than [`MAX_DENSE_LINKS`] links with [`DynError::TooManyLinks`].
///
/// Gives the same terms as [`reduced_terms`](crate::reduced_terms) up to rounding, at
/// `O(n^2 m)` instead of `O(n m^2)` cost.
pub fn reduced_terms_by_projection(
    model: &ReducedModel,
    data: &mut ReducedData,
    a: &[f64],
    a_dot: &[f64],
) -> Result<(), ReduceError> {
    data.check_model(model)?;
    let m = model.n_coords();
    check_values("a", a, m)?;
    check_values("a_dot", a_dot, m)?;
    let (chain, map) = (model.chain(), model.map());
    let n = model.n_links();
    if n > MAX_DENSE_LINKS {
        return Err(ReduceError::Dyn(DynError::TooManyLinks {
            what: "the projection J^T M J",
            got: n,
            max: MAX_DENSE_LINKS,
        }));
    }
    map.joint_angles(a, &mut data.theta)?;
    map.joint_rates(a_dot, &mut data.theta_dot)?;
    check_finite_result("theta = J a + theta_0", &data.theta)?;
    check_finite_result("theta_dot = J a_dot", &data.theta_dot)?;
    let Projection {
        joint_mass,
        mass_times_jacobian,
    } = data.projection.get_or_insert_with(|| Projection::new(n, m));

    manip_dyn::mass_matrix(chain, &mut data.chain, &data.theta, joint_mass.as_mut())?;
    matmul(
        mass_times_jacobian.as_mut(),
        Accum::Replace,
        joint_mass.as_ref(),
        model.jacobian(),
        1.0,
        Par::Seq,
    );
    matmul(
        MatMut::from_row_major_slice_mut(&mut data.mass, m, m),
        Accum::Replace,
        model.jacobian().transpose(),
        mass_times_jacobian.as_ref(),
        1.0,
        Par::Seq,
    );
    // J^T (M J) is symmetric up to rounding: make it exactly so.
    for j in 0..m {
        for k in 0..j {
            let mean = 0.5 * (data.mass[j * m + k] + data.mass[k * m + j]);
            data.mass[j * m + k] = mean;
            data.mass[k * m + j] = mean;
        }
    }

    manip_dyn::coriolis(
        chain,
        &mut data.chain,
        &data.theta,
        &data.theta_dot,
        &mut data.joint_torque,
    )?;
    project(map, &data.joint_torque, &mut data.coriolis);
    manip_dyn::gravity(chain, &mut data.chain, &data.theta, &mut data.joint_torque)?;
    project(map, &data.joint_torque, &mut data.gravity);
    Ok(())
}
