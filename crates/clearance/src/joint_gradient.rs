//! The gradient of one pair's clearance with respect to the joint angles.

use crate::data::ClearanceData;
use crate::error::ClearanceError;
use crate::model::{ClearanceModel, Pair};
use crate::vector::{cross, dot, sub};
use lane_math::check_len;

/// Writes `d d / d theta` of pair `pair` (after [`distances`](crate::distances)) into `gradient`
/// (`n` entries). Allocation-free.
///
/// Turning joint `j` (axis `w_j` through `p_j`) moves every point `x` distal to it with velocity
/// `w_j x (x - p_j)`, and the clearance changes along the normal `n` at the closest point `c`
/// (envelope theorem), so `d d / d theta_j = w_j . ((c - p_j) x n)` for `j <= i` when `c` lies on
/// link `i`. For two links `i < k` the joints up to `i` move both closest points rigidly (no
/// change: `c_i - c_k` is parallel to `n`) and those in `(i, k]` move `c_k` alone:
/// `d d / d theta_j = -w_j . ((c_k - p_j) x n)`.
pub fn joint_gradient(
    model: &ClearanceModel,
    data: &ClearanceData,
    pair: usize,
    gradient: &mut [f64],
) -> Result<(), ClearanceError> {
    data.check_model(model)?;
    check_len("joint gradient", gradient.len(), model.n_links())?;
    let Some(&which) = model.pairs().get(pair) else {
        return Err(ClearanceError::OutOfRange {
            name: "pair index",
            bound: "less than the model's number of pairs",
            value: pair as f64,
        });
    };
    let closest = &data.closest[pair];
    let normal = closest.normal;
    gradient.fill(0.0);
    let (point, first, last, sign) = match which {
        Pair::Obstacle { link, .. } => (closest.point, 0, link, 1.0),
        Pair::Links { link, other } => (closest.other, link + 1, other, -1.0),
    };
    for ((g, p), w) in gradient[first..=last]
        .iter_mut()
        .zip(&data.points[first..=last])
        .zip(&data.axes[first..=last])
    {
        *g = sign * dot(*w, cross(sub(point, *p), normal));
    }
    Ok(())
}
