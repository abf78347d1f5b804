//! Placing the chain: its joint points and axes in world coordinates.

use crate::data::ClearanceData;
use crate::error::ClearanceError;
use crate::model::ClearanceModel;
use crate::obstacle::MAX_OBSTACLE_EXTENT;
use crate::vector::{V3, dot};
use lane_math::{check_finite, check_len};

/// Places a planar chain (base at the origin, every axis along `z`) with joint angles `theta`
/// through `backbone_kin::joint_positions`. Allocation-free.
pub fn place_planar(
    model: &ClearanceModel,
    data: &mut ClearanceData,
    link_lengths: &[f64],
    theta: &[f64],
) -> Result<(), ClearanceError> {
    data.check_model(model)?;
    check_len("link lengths", link_lengths.len(), model.n_links())?;
    backbone_kin::joint_positions(link_lengths, theta, &mut data.planar)?;
    for (point, planar) in data.points.iter_mut().zip(&data.planar) {
        if !within_extent(planar[0]) || !within_extent(planar[1]) {
            return check_extents(planar);
        }
        *point = [planar[0], planar[1], 0.0];
    }
    data.axes.fill([0.0, 0.0, 1.0]);
    data.turns_about_z = true;
    Ok(())
}

/// Places any serial chain of revolute joints: `points` the `n + 1` joint points from the base
/// to the tip (joint `i` at `points[i]`, link `i` to `points[i + 1]`) and `axes` the `n` unit
/// joint axes in world coordinates. Allocation-free.
pub fn place(
    model: &ClearanceModel,
    data: &mut ClearanceData,
    points: &[V3],
    axes: &[V3],
) -> Result<(), ClearanceError> {
    data.check_model(model)?;
    check_len("joint points", points.len(), model.n_links() + 1)?;
    check_len("joint axes", axes.len(), model.n_links())?;
    check_extents(points.iter().flatten())?;
    for axis in axes {
        let length = dot(*axis, *axis).sqrt();
        if (length - 1.0).abs() > 1e-9 || length.is_nan() {
            return Err(ClearanceError::OutOfRange {
                name: "joint axis length",
                bound: "1 (a unit vector)",
                value: length,
            });
        }
    }
    data.points.copy_from_slice(points);
    data.axes.copy_from_slice(axes);
    data.turns_about_z = false;
    Ok(())
}

/// Refuses the first joint point coordinate of `coordinates` that is not finite or beyond
/// [`MAX_OBSTACLE_EXTENT`] in magnitude, where the closest points' products would lose the links'
/// scale: one comparison a coordinate (NaN fails it too), the error's kind found after.
fn check_extents<'a>(coordinates: impl IntoIterator<Item = &'a f64>) -> Result<(), ClearanceError> {
    match coordinates.into_iter().find(|x| !within_extent(**x)) {
        None => Ok(()),
        Some(&x) => {
            check_finite("joint point", x)?;
            Err(ClearanceError::OutOfRange {
                name: "joint point coordinate",
                bound: "at most 1e15 m in magnitude (MAX_OBSTACLE_EXTENT)",
                value: x,
            })
        }
    }
}

/// Whether `x` is a number within [`MAX_OBSTACLE_EXTENT`] in magnitude (false for NaN).
#[inline]
fn within_extent(x: f64) -> bool {
    x.abs() <= MAX_OBSTACLE_EXTENT
}
