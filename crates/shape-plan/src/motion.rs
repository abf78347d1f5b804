//! A straight motion in modal space checked at a bounded resolution (`docs/theory.md`, "Shape
//! planning").
//!
//! Every point of every link's axis moves at most `Lambda |a - b|` between the shapes `a` and
//! `b` ([`Arm::lipschitz`]), so a clearance to an obstacle changes at most that much and a
//! clearance between two links at most twice that. A check point whose smallest clearance to
//! the obstacles is `d_o` and to itself `d_s` therefore proves every shape within
//! `r = min((d_o - c) / Lambda, (d_s - c) / (2 Lambda))` of it keeps `c`; the next check point
//! is placed `r` further along the segment. Every check point must keep `c + epsilon`, so the
//! steps are at least `epsilon / (2 Lambda)` and a segment of length `D` needs at most
//! `2 Lambda D / epsilon + 2` checks; far from obstacles the steps are long.

use crate::arm::Arm;
use crate::data::PlanData;
use crate::error::PlanError;
use crate::options::PlanOptions;
use clearance::{ClearanceModel, distances};
use lane_math::check_len;

/// What checking a segment found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentCheck {
    /// Whether every check point keeps `c + epsilon` (so every shape of the segment keeps `c`).
    pub clear: bool,
    /// The smallest clearance at the check points visited (up to the first that failed), m.
    pub clearance: f64,
    /// Check points visited.
    pub checks: usize,
}

/// Checks the straight segment from `from` to `to` in modal coordinates with the steps of the
/// module docs, both ends included, stopping at the first check point closer than
/// `c + epsilon`. Allocation-free.
///
/// Errors: options that [`PlanOptions::validate`] refuses; [`PlanError::TooMany`] when the
/// segment needs more than `max_checks` points; sizes that disagree (the clearance data of
/// `data` made for another model included); non-finite coordinates.
pub fn check_segment<A: Arm>(
    arm: &A,
    clearance: &ClearanceModel,
    options: &PlanOptions,
    data: &mut PlanData,
    from: &[f64],
    to: &[f64],
) -> Result<SegmentCheck, PlanError> {
    options.validate()?;
    let m = arm.n_coords();
    check_len("segment start", from.len(), m)?;
    check_len("segment end", to.len(), m)?;
    let length = from
        .iter()
        .zip(to)
        .map(|(x, y)| (y - x) * (y - x))
        .sum::<f64>()
        .sqrt();
    lane_math::check_finite("segment length", length)?;
    let (lipschitz, c, needed) = (arm.lipschitz(), options.clearance, options.needed());
    let mut smallest = f64::INFINITY;
    let (mut s, mut checks) = (0.0_f64, 0);
    loop {
        if checks == options.max_checks {
            return Err(PlanError::TooMany {
                name: "check points of one path segment (max checks)",
                got: checks + 1,
                max: options.max_checks,
            });
        }
        for ((p, x), y) in data.point.iter_mut().zip(from).zip(to) {
            *p = x + s * (y - x);
        }
        arm.place(clearance, &mut data.trial, &mut data.scratch, &data.point)?;
        let (obstacles, itself) = distances(clearance, &mut data.trial);
        checks += 1;
        smallest = smallest.min(obstacles.min(itself));
        if smallest < needed {
            return Ok(SegmentCheck {
                clear: false,
                clearance: smallest,
                checks,
            });
        }
        if s >= 1.0 {
            break;
        }
        // The ball of shapes this check point proves clear, as a fraction of the segment.
        let radius = ((obstacles - c) / lipschitz).min(0.5 * (itself - c) / lipschitz);
        s = if length > 0.0 {
            (s + radius / length).min(1.0)
        } else {
            1.0
        };
    }
    Ok(SegmentCheck {
        clear: true,
        clearance: smallest,
        checks,
    })
}
