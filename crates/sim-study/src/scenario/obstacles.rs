//! From `[[obstacles]]` and `[arm] radius` to the obstacles and the clearance model the loop
//! evaluates, every field checked and named (`obstacles[2].radius`) when it fails.

use super::schema::{ObstacleSpec, Scenario};
use clearance::{ClearanceModel, Obstacle};
use sim_core::SimError;

/// The most obstacles a scenario may hold. With the paper's 10 links every controller sample
/// measures `10 x 1024` link-obstacle pairs at most, a few hundred microseconds.
pub const MAX_SCENARIO_OBSTACLES: usize = 1024;

/// The largest magnitude of a scenario obstacle's coordinates, radius and half-extents, and of
/// `arm.radius` (m): the scale a run resolves, as for a deployment's centreline. Beyond it the
/// rounding of the closest points reaches the arm's millimetres (a capsule 1e14 m long read
/// 3.6 mm farther than it was); the library's own bound, `clearance::MAX_OBSTACLE_EXTENT`, only
/// keeps the distances finite.
pub const MAX_SCENARIO_EXTENT: f64 = 1e6;

/// Where an arm moves, which decides how its obstacles are given.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Workspace {
    /// The plane `z = 0`: points `[x, y]`, circles, capsules and rectangles (boxes with
    /// `half_extents = [hx, hy]`, turned about `z` only).
    Planar,
    /// Space: points `[x, y, z]`, spheres, capsules and boxes turned by any `rpy`.
    Spatial,
}

impl Workspace {
    /// The coordinates of a point: 2 or 3.
    pub(super) fn dims(self) -> usize {
        match self {
            Self::Planar => 2,
            Self::Spatial => 3,
        }
    }

    /// How a message names a point of the workspace.
    pub(super) fn point_words(self) -> &'static str {
        match self {
            Self::Planar => "a point [x, y] of the arm's plane",
            Self::Spatial => "a point [x, y, z]",
        }
    }
}

impl Scenario {
    /// Where the scenario's modal arm moves: in the plane for `[arm] kind = "planar"`, in space
    /// for `"spatial"` (a URDF arm runs in joint space without clearance).
    pub fn workspace(&self) -> Workspace {
        match self.arm.kind {
            crate::ArmKind::Planar => Workspace::Planar,
            crate::ArmKind::Spatial => Workspace::Spatial,
        }
    }

    /// The scenario's obstacles for an arm in `workspace`, in file order, each checked: points
    /// of the workspace's dimension, finite; radii finite and non-negative; half-extents
    /// positive (finite); `rpy` three finite angles (`[0, 0, yaw]` in the plane); a `circle` in
    /// the plane only, a `sphere` in space only; at most [`MAX_SCENARIO_OBSTACLES`]. A planar
    /// obstacle lies in `z = 0` (a rectangle is a box of infinite height).
    ///
    /// ```
    /// let mut scenario = sim_study::Scenario::builtin("paper-tracking")?;
    /// scenario.obstacles.push(sim_study::ObstacleSpec::Circle { center: vec![0.3], radius: 0.05 });
    /// let error = scenario.obstacles(sim_study::Workspace::Planar).unwrap_err();
    /// assert_eq!(
    ///     error.to_string(),
    ///     "obstacles[0].center must be a point [x, y] of the arm's plane, got 1 number"
    /// );
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn obstacles(&self, workspace: Workspace) -> Result<Vec<Obstacle>, SimError> {
        if self.obstacles.len() > MAX_SCENARIO_OBSTACLES {
            return Err(SimError::setting(
                "obstacles",
                format!(
                    "holds {} obstacles, more than the {MAX_SCENARIO_OBSTACLES} a scenario may",
                    self.obstacles.len()
                ),
            ));
        }
        self.obstacles
            .iter()
            .enumerate()
            .map(|(i, spec)| spec.obstacle(i, workspace))
            .collect()
    }

    /// The arm's `n_links` capsules of radius `arm.radius` (default 0) among the scenario's
    /// obstacles ([`obstacles`](Self::obstacles)), or `None` when the scenario gives neither
    /// obstacles nor `arm.radius`: then the loop measures no clearance and runs exactly as
    /// without this feature.
    pub fn clearance_model(
        &self,
        n_links: usize,
        workspace: Workspace,
    ) -> Result<Option<ClearanceModel>, SimError> {
        if self.obstacles.is_empty() && self.arm.radius.is_none() {
            return Ok(None);
        }
        let radius = self.arm.radius.unwrap_or(0.0);
        if !(0.0..=MAX_SCENARIO_EXTENT).contains(&radius) {
            return Err(SimError::setting(
                "arm.radius",
                format!(
                    "must be non-negative and at most {MAX_SCENARIO_EXTENT:e} (m, as an \
                     obstacle's extent), got {}",
                    lane_math::Compact(radius)
                ),
            ));
        }
        let obstacles = self.obstacles(workspace)?;
        ClearanceModel::new(n_links, radius, obstacles)
            .map(Some)
            .map_err(|e| SimError::setting("obstacles", format!("cannot be measured: {e}")))
    }
}

impl ObstacleSpec {
    /// Obstacle `index` of the scenario (its position in the file, for the messages) for an arm
    /// in `workspace`.
    pub fn obstacle(&self, index: usize, workspace: Workspace) -> Result<Obstacle, SimError> {
        let field = |name: &str| format!("obstacles[{index}].{name}");
        let point = |name: &str, values: &[f64]| -> Result<[f64; 3], SimError> {
            if values.len() != workspace.dims() {
                let words = match (name, workspace) {
                    ("half_extents", Workspace::Planar) => "[hx, hy]",
                    ("half_extents", Workspace::Spatial) => "[hx, hy, hz]",
                    _ => workspace.point_words(),
                };
                return Err(SimError::setting(
                    field(name),
                    format!("must be {words}, got {}", numbers(values.len())),
                ));
            }
            if let Some(v) = values
                .iter()
                .find(|v| !v.is_finite() || v.abs() > MAX_SCENARIO_EXTENT)
            {
                return Err(SimError::setting(
                    field(name),
                    format!(
                        "must be finite and at most 1e6 in magnitude (m, the scale a run \
                         resolves), got {}",
                        lane_math::Compact(*v)
                    ),
                ));
            }
            Ok([values[0], values[1], values.get(2).copied().unwrap_or(0.0)])
        };
        let radius = |r: f64| {
            if (0.0..=MAX_SCENARIO_EXTENT).contains(&r) {
                Ok(r)
            } else {
                Err(SimError::setting(
                    field("radius"),
                    format!(
                        "must be non-negative, finite and at most 1e6 (m), got {}",
                        lane_math::Compact(r)
                    ),
                ))
            }
        };
        // The constructors check nothing the lines above have not; a refusal names the obstacle.
        let built = |o: Result<Obstacle, clearance::ClearanceError>| {
            o.map_err(|e| {
                SimError::setting(format!("obstacles[{index}]"), format!("is invalid: {e}"))
            })
        };
        match (self, workspace) {
            (ObstacleSpec::Circle { center, radius: r }, Workspace::Planar)
            | (ObstacleSpec::Sphere { center, radius: r }, Workspace::Spatial) => {
                built(Obstacle::sphere(point("center", center)?, radius(*r)?))
            }
            (ObstacleSpec::Sphere { .. }, Workspace::Planar) => Err(SimError::setting(
                field("kind"),
                "is \"sphere\", which needs a spatial arm: a planar arm's round obstacles are \
                 \"circle\"",
            )),
            (ObstacleSpec::Circle { .. }, Workspace::Spatial) => Err(SimError::setting(
                field("kind"),
                "is \"circle\", which lies in a plane: a spatial arm's round obstacles are \
                 \"sphere\"",
            )),
            (
                ObstacleSpec::Capsule {
                    from,
                    to,
                    radius: r,
                },
                _,
            ) => built(Obstacle::capsule(
                point("from", from)?,
                point("to", to)?,
                radius(*r)?,
            )),
            (
                ObstacleSpec::Box {
                    center,
                    half_extents,
                    rpy,
                },
                _,
            ) => {
                let center = point("center", center)?;
                let mut half = point("half_extents", half_extents)?;
                if let Some(h) = half_extents.iter().find(|h| **h <= 0.0) {
                    return Err(SimError::setting(
                        field("half_extents"),
                        format!("must be positive (m), got {h}"),
                    ));
                }
                let rpy = match rpy.as_deref() {
                    None => [0.0; 3],
                    Some(angles) => {
                        let angles: [f64; 3] = angles.try_into().map_err(|_| {
                            SimError::setting(
                                field("rpy"),
                                format!(
                                    "must be three angles [roll, pitch, yaw] (rad), got {}",
                                    numbers(angles.len())
                                ),
                            )
                        })?;
                        if let Some(v) = angles.iter().find(|v| !v.is_finite()) {
                            return Err(SimError::setting(
                                field("rpy"),
                                format!("must be finite (rad), got {v}"),
                            ));
                        }
                        angles
                    }
                };
                if workspace == Workspace::Planar {
                    if rpy[0] != 0.0 || rpy[1] != 0.0 {
                        return Err(SimError::setting(
                            field("rpy"),
                            format!(
                                "must be [0, 0, yaw] for a planar arm (a rectangle turns about z \
                                 only), got roll {} and pitch {}",
                                rpy[0], rpy[1]
                            ),
                        ));
                    }
                    half[2] = f64::INFINITY;
                }
                built(Obstacle::cuboid(center, half, rpy))
            }
        }
    }
}

/// "1 number", "3 numbers".
pub(super) fn numbers(n: usize) -> String {
    format!("{n} number{}", if n == 1 { "" } else { "s" })
}
