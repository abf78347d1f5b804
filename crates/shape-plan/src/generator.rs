//! Seeded narrow-passage problems, solvable by construction (`docs/theory.md`, "Shape
//! planning").
//!
//! A witness goal shape `a*` is drawn at random (every modal coordinate uniform in `[-A, A]`,
//! redrawn until its own links keep the margin); its tip is the target. Obstacles (circles of
//! the plane for the planar arm, spheres for the spatial one) are then placed beside the
//! witness's body: at a random point of a random link, along a random direction perpendicular
//! to the link (the link's normal on a random side in the plane), so that the obstacle's surface
//! is `c + gap` from the link's capsule. A candidate is kept only if the straight motion from the initial shape to
//! `a*` keeps `c + gap` at every check point ([`check_segment`] with slack `gap` less a thousandth, so every
//! shape of it keeps `c`). The witness and its motion then solve the problem, while the
//! obstacles leave the goal shape only `gap` of room beyond the margin.

use crate::arm::{Arm, ArmScratch};
use crate::data::PlanData;
use crate::error::PlanError;
use crate::motion::check_segment;
use crate::options::PlanOptions;
use crate::planar::PlanarArm;
use crate::spatial::SpatialArm;
use backbone_kin::{BaseAngle, BasePose};
use clearance::{ClearanceModel, Obstacle, distances};
use lane_math::check_finite;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The most obstacles a generated problem may ask for.
pub const MAX_PASSAGE_OBSTACLES: usize = 1024;

/// What a narrow-passage problem is made of.
#[derive(Debug, Clone, PartialEq)]
pub struct PassageSpec {
    /// The arm's link lengths, base first.
    pub link_lengths: Vec<f64>,
    /// Harmonics `K` of the modal family.
    pub harmonics: usize,
    /// The fixed base angle `alpha0`.
    pub alpha0: f64,
    /// The links' radius, m.
    pub radius: f64,
    /// The margin `c`, m.
    pub clearance: f64,
    /// The room (m) beyond the margin between the witness and each obstacle, and the slack of
    /// the witness motion's checks; positive.
    pub gap: f64,
    /// Obstacles wanted; fewer are placed if candidates keep failing (at most 50 tries each).
    pub obstacles: usize,
    /// The obstacles' radius, m; positive.
    pub obstacle_radius: f64,
    /// The amplitude `A` of the witness's coordinates, rad; positive.
    pub amplitude: f64,
    /// The seed: the same seed gives the same problem.
    pub seed: u64,
}

/// A generated problem and its witness.
#[derive(Debug, Clone)]
pub struct NarrowPassage<A: Arm> {
    /// The arm.
    pub arm: A,
    /// The links' radius and the obstacles.
    pub clearance_model: ClearanceModel,
    /// The initial shape (the straight arm, all coordinates zero).
    pub initial: Vec<f64>,
    /// The target, the witness's tip (`arm.dimension()` entries).
    pub target: Vec<f64>,
    /// The witness goal shape.
    pub witness: Vec<f64>,
}

/// Generates the planar problem of `spec` (module docs): the arm leaves the origin at
/// `alpha0`, the obstacles are circles.
///
/// Errors: input errors for the spec's numbers; [`PlanError::NoCollisionFreeShape`] when 1000
/// witnesses drawn all collide with themselves (an amplitude far too large for the arm).
pub fn narrow_passage(spec: &PassageSpec) -> Result<NarrowPassage<PlanarArm>, PlanError> {
    let arm = PlanarArm::new(
        &spec.link_lengths,
        spec.harmonics,
        BaseAngle::Fixed(spec.alpha0),
    )?;
    generate(arm, spec, |rng, axis| {
        let side = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
        [-axis[1] * side, axis[0] * side, 0.0]
    })
}

/// Generates the spatial problem of `spec` (module docs) for the universal-joint arm at the
/// default base pose (the straight arm along `x`; `alpha0` is not used), the obstacles spheres.
///
/// Errors: as [`narrow_passage`].
pub fn spatial_narrow_passage(spec: &PassageSpec) -> Result<NarrowPassage<SpatialArm>, PlanError> {
    let arm = SpatialArm::new(&spec.link_lengths, spec.harmonics, BasePose::default())?;
    generate(arm, spec, |rng, axis| {
        // A uniform direction, its part along the link removed (redrawn if nearly parallel).
        loop {
            let v: [f64; 3] = std::array::from_fn(|_| rng.random_range(-1.0..=1.0));
            let along = v[0] * axis[0] + v[1] * axis[1] + v[2] * axis[2];
            let w: [f64; 3] = std::array::from_fn(|d| v[d] - along * axis[d]);
            let norm = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
            if norm > 0.1 {
                return w.map(|x| x / norm);
            }
        }
    })
}

/// The construction of the module docs for any arm; `perpendicular` draws a unit direction
/// perpendicular to a link's unit axis.
fn generate<A: Arm>(
    arm: A,
    spec: &PassageSpec,
    perpendicular: impl Fn(&mut ChaCha8Rng, [f64; 3]) -> [f64; 3],
) -> Result<NarrowPassage<A>, PlanError> {
    for (name, value) in [
        ("gap", spec.gap),
        ("obstacle radius", spec.obstacle_radius),
        ("amplitude", spec.amplitude),
    ] {
        check_finite(name, value)?;
        if value <= 0.0 {
            return Err(PlanError::OutOfRange {
                name,
                bound: "positive",
                value,
            });
        }
    }
    if spec.obstacles > MAX_PASSAGE_OBSTACLES {
        return Err(PlanError::TooMany {
            name: "obstacles",
            got: spec.obstacles,
            max: MAX_PASSAGE_OBSTACLES,
        });
    }
    let options = PlanOptions {
        clearance: spec.clearance,
        // A thousandth below the gap, so that rounding cannot refuse the witness.
        check_slack: spec.gap * (1.0 - 1e-3),
        ..PlanOptions::default()
    };
    options.validate()?;
    let n = arm.n_links();
    let m = arm.n_coords();
    let mut rng = ChaCha8Rng::seed_from_u64(spec.seed);
    let initial = vec![0.0; m];
    let mut model = ClearanceModel::new(n, spec.radius, Vec::new())?;
    let mut data = PlanData::new(&arm, &model)?;
    let mut scratch = ArmScratch::new(&arm);
    // The witness: a shape that keeps the margin from itself.
    let mut witness = vec![0.0; m];
    let mut found = false;
    let mut best = f64::NEG_INFINITY;
    for _ in 0..1000 {
        for x in &mut witness {
            *x = rng.random_range(-spec.amplitude..=spec.amplitude);
        }
        arm.place(&model, &mut data.current, &mut scratch, &witness)?;
        let (_, itself) = distances(&model, &mut data.current);
        best = best.max(itself);
        if itself >= options.needed()
            && check_segment(&arm, &model, &options, &mut data, &initial, &witness)?.clear
        {
            found = true;
            break;
        }
    }
    if !found {
        return Err(PlanError::NoCollisionFreeShape {
            best_clearance: best,
            needed: options.needed(),
            tip_error: 0.0,
            starts: 1000,
        });
    }
    arm.place(&model, &mut data.current, &mut scratch, &witness)?;
    let points = data.current.points().to_vec();
    let target = points[n][..arm.dimension()].to_vec();
    let mut obstacles = Vec::with_capacity(spec.obstacles);
    let offset = spec.radius + spec.clearance + spec.gap + spec.obstacle_radius;
    for _ in 0..spec.obstacles {
        for _ in 0..50 {
            let link = rng.random_range(0..n);
            let t = rng.random_range(0.0..=1.0);
            let (a, b) = (points[link], points[link + 1]);
            let delta: [f64; 3] = std::array::from_fn(|d| b[d] - a[d]);
            let length = (delta[0] * delta[0] + delta[1] * delta[1] + delta[2] * delta[2]).sqrt();
            let normal = perpendicular(&mut rng, delta.map(|x| x / length));
            let center: [f64; 3] =
                std::array::from_fn(|d| a[d] + t * delta[d] + offset * normal[d]);
            let mut candidate = obstacles.clone();
            candidate.push(Obstacle::sphere(center, spec.obstacle_radius)?);
            let trial = ClearanceModel::new(n, spec.radius, candidate.clone())?;
            let mut trial_data = PlanData::new(&arm, &trial)?;
            if check_segment(&arm, &trial, &options, &mut trial_data, &initial, &witness)?.clear {
                obstacles = candidate;
                model = trial;
                break;
            }
        }
    }
    Ok(NarrowPassage {
        arm,
        clearance_model: model,
        initial,
        target,
        witness,
    })
}
