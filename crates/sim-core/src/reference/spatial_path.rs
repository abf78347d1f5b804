//! A tip path in space for a spatial modal arm (a helix, or a circle), followed through the
//! numerical continuation of the chain's inverse kinematics with minimum-norm modal rates
//! (`docs/theory.md`, "Tip paths in space").

use super::continuation::{RateScratch, ResolveError, TipFamily, TipMotion, resolve};
use super::{Reference, ReferenceSample};
use crate::error::{SimError, check_positive};
use backbone_kin::vec3::{cross, dot, sub};
use backbone_kin::{BasePose, Branch, KinError, SpatialIk, SpatialModalMap, inverse_kinematics};
use lane_math::{Compact, check_all_finite};

/// Intervals of the continuation's time grid.
const GRID_INTERVALS: usize = 2000;
/// The most links times modal coordinates (`n m`) of an arm whose path is resolved: the
/// continuation's inverse kinematics costs about `n m` a node at 2001 nodes (about 12 s at the
/// bound on a 3.6 GHz core: 8,192 links at `K = 1`, 512 at `K = 16`).
pub const MAX_SPATIAL_PATH_WORK: usize = 1 << 15;
/// `J J^T` counts as singular below this ratio of its determinant to the cube of its trace.
const SINGULAR_RATIO: f64 = 1e-12;

/// The largest magnitude of a helix's coordinates and pitch (m): a path a million metres out is
/// already beyond any arm, and the helix's arithmetic stays far from overflow.
pub const MAX_HELIX_EXTENT_M: f64 = 1e6;

/// Refuses a value that is not finite or beyond [`MAX_HELIX_EXTENT_M`], naming `name[k]`.
fn check_extent(name: &str, values: &[f64]) -> Result<(), SimError> {
    check_all_finite(name, values)?;
    match values.iter().position(|x| x.abs() > MAX_HELIX_EXTENT_M) {
        Some(k) => Err(SimError::setting(
            if values.len() == 1 {
                name.to_string()
            } else {
                format!("{name}[{k}]")
            },
            format!(
                "must be at most {} m in magnitude, got {}",
                Compact(MAX_HELIX_EXTENT_M),
                Compact(values[k])
            ),
        )),
        None => Ok(()),
    }
}

/// A helix in space: from `start`, turning right-handedly about the line through `center` along
/// `axis` for `turns` turns and rising `pitch` metres per turn along `axis`; `pitch = 0` is a
/// circle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Helix {
    /// A point on the axis (m).
    pub center: [f64; 3],
    /// The axis direction (not zero; normalised when the path is built).
    pub axis: [f64; 3],
    /// The first point (m), off the axis.
    pub start: [f64; 3],
    /// Rise per turn along the axis (m).
    pub pitch: f64,
    /// Number of turns, positive.
    pub turns: f64,
}

/// The helix in its own frame: `p(phi) = foot + cos(phi) u + sin(phi) v + rise phi w`.
#[derive(Debug, Clone, Copy)]
struct HelixFrame {
    foot: [f64; 3],
    u: [f64; 3],
    v: [f64; 3],
    w: [f64; 3],
    rise: f64,
    sweep: f64,
}

impl Helix {
    fn frame(&self) -> Result<HelixFrame, SimError> {
        check_extent("reference.helix.center", &self.center)?;
        check_all_finite("reference.helix.axis", &self.axis)?;
        check_extent("reference.helix.start", &self.start)?;
        check_extent("reference.helix.pitch", &[self.pitch])?;
        check_positive("reference.helix.turns", self.turns)?;
        if self.turns > 1e3 {
            return Err(SimError::setting(
                "reference.helix.turns",
                format!("must be at most 1000, got {}", self.turns),
            ));
        }
        // Scaled by its largest component first, any finite non-zero axis has a unit direction
        // (`[1e308, 1e308, 0]` as well as `[1e-310, 0, 0]`).
        let largest = self.axis.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
        if largest == 0.0 {
            return Err(SimError::setting(
                "reference.helix.axis",
                "must be a non-zero direction",
            ));
        }
        let scaled = self.axis.map(|x| x / largest);
        let norm = dot(scaled, scaled).sqrt();
        let w = scaled.map(|x| x / norm);
        let offset = sub(self.start, self.center);
        let along = dot(offset, w);
        let u: [f64; 3] = std::array::from_fn(|d| offset[d] - along * w[d]);
        let radius = dot(u, u).sqrt();
        if radius <= 1e-9 * (1.0 + dot(offset, offset).sqrt()) {
            return Err(SimError::setting(
                "reference.helix.start",
                "must lie off the axis (the helix's radius is its distance from the axis)",
            ));
        }
        Ok(HelixFrame {
            foot: std::array::from_fn(|d| self.center[d] + along * w[d]),
            u,
            v: cross(w, u),
            w,
            rise: self.pitch / std::f64::consts::TAU,
            sweep: std::f64::consts::TAU * self.turns,
        })
    }
}

/// The chain's tip as a [`TipFamily`] in three dimensions: the inverse kinematics and the
/// `3 x 4K` tip Jacobian of [`SpatialIk`].
#[derive(Debug, Clone)]
struct ChainTip {
    ik: SpatialIk,
    jacobian: Vec<f64>,
    scratch: RateScratch,
}

impl TipFamily<3> for ChainTip {
    fn scratch(&mut self) -> &mut RateScratch {
        &mut self.scratch
    }

    fn unreachable(t: f64, point: [f64; 3], source: KinError) -> SimError {
        SimError::UnreachableInSpace { t, point, source }
    }

    fn singular(what: &'static str, t: f64, point: [f64; 3]) -> SimError {
        SimError::SingularPointInSpace { what, t, point }
    }

    fn jacobian_at(&mut self, a: &[f64]) -> Result<[f64; 3], KinError> {
        self.ik.tip_jacobian(a, &mut self.jacobian)
    }

    /// `J^T (J J^T)^{-1} v` with the `3 x 3` Gram matrix inverted through its cofactors.
    fn pseudo_inverse(&self, v: [f64; 3], out: &mut [f64]) -> Result<(), ResolveError> {
        let m = out.len();
        let row = |d: usize| &self.jacobian[d * m..(d + 1) * m];
        let dot_rows =
            |p: usize, q: usize| row(p).iter().zip(row(q)).map(|(x, y)| x * y).sum::<f64>();
        let g = [
            [dot_rows(0, 0), dot_rows(0, 1), dot_rows(0, 2)],
            [dot_rows(0, 1), dot_rows(1, 1), dot_rows(1, 2)],
            [dot_rows(0, 2), dot_rows(1, 2), dot_rows(2, 2)],
        ];
        let cof = |i: usize, j: usize| {
            let (r0, r1) = ((i + 1) % 3, (i + 2) % 3);
            let (c0, c1) = ((j + 1) % 3, (j + 2) % 3);
            g[r0][c0] * g[r1][c1] - g[r0][c1] * g[r1][c0]
        };
        let det = g[0][0] * cof(0, 0) + g[0][1] * cof(0, 1) + g[0][2] * cof(0, 2);
        let trace = g[0][0] + g[1][1] + g[2][2];
        if !(det > SINGULAR_RATIO * trace * trace * trace && det.is_finite()) {
            return Err(ResolveError::Singular);
        }
        // (G^-1)_{ij} = cof(j, i) / det; G is symmetric.
        let y: [f64; 3] =
            std::array::from_fn(|i| (0..3).map(|j| cof(i, j) * v[j]).sum::<f64>() / det);
        for (k, o) in out.iter_mut().enumerate() {
            *o = (0..3).map(|d| self.jacobian[d * m + k] * y[d]).sum();
        }
        Ok(())
    }

    fn solve(&mut self, target: [f64; 3], a: &mut [f64]) -> Result<(), KinError> {
        self.ik.solve(target, a).map(|_| ())
    }
}

/// A tip path in space traversed at constant speed in `travel_time` seconds by the chain's tip
/// of a spatial modal arm, then held at its end point (before `t = 0` it holds its start).
///
/// The modal reference is the numerical continuation of the chain's inverse kinematics
/// ([`SpatialIk`]) with the minimum-norm modal rate `a_dot = J^+ p_dot` (`J = d tip / d a`,
/// `3 x 4K`) and its time derivative, as the planar [`CartesianPath`](super::CartesianPath)
/// resolves the planar families: the positions are solved on a grid of 2000 intervals, each node
/// warm-started from a second-order prediction off the previous one, and any time `t` is solved
/// from its grid node, so a sample depends on `t` alone. The start is solved from a guess that
/// bends the in-plane family alone: the planar closed form (eqs 5-6, `K = 1`, on `branch`) of the
/// start point's projection onto the base's `x-y` plane, the out-of-plane coordinates zero.
///
/// ```
/// use backbone_kin::{BasePose, Branch, SpatialModalMap};
/// use sim_core::reference::{Helix, Reference, ReferenceSample, SpatialPath};
/// // A circle of radius 0.15 m about the x axis, out of the arm's x-y plane, on the 1 m arm.
/// let circle = Helix { center: [0.8, 0.0, 0.0], axis: [1.0, 0.0, 0.0], start: [0.8, 0.15, 0.0], pitch: 0.0, turns: 1.0 };
/// let map = SpatialModalMap::new(&[0.1; 10], 1)?;
/// let mut path = SpatialPath::new(circle, 4.0, map.clone(), BasePose::default(), Branch::Positive)?;
/// let mut quarter = ReferenceSample::zeros(4);
/// path.sample(1.0, &mut quarter)?;
/// let mut theta = [0.0; 20];
/// map.joint_angles(&quarter.a, &mut theta)?;
/// let tip = backbone_kin::spatial_tip_position(map.link_lengths(), &BasePose::default(), &theta)?;
/// assert!((tip[2] - 0.15).abs() < 1e-9 && tip[1].abs() < 1e-9);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct SpatialPath {
    frame: HelixFrame,
    travel_time: f64,
    family: Box<ChainTip>,
    /// Node `k` at `t = k * step`.
    nodes: Vec<ReferenceSample>,
    step: f64,
}

impl SpatialPath {
    /// The path `helix` traversed in `travel_time` s by the tip of the chain of `map` leaving
    /// `base`; `branch` chooses the start's in-plane guess.
    ///
    /// Checks the helix and the work (links times modal coordinates at most
    /// [`MAX_SPATIAL_PATH_WORK`]), then resolves the whole path: every point must be reachable
    /// ([`SimError::UnreachableInSpace`] names the first that is not) and away from the
    /// singular points of the inverse kinematics ([`SimError::SingularPointInSpace`]).
    pub fn new(
        helix: Helix,
        travel_time: f64,
        map: SpatialModalMap,
        base: BasePose,
        branch: Branch,
    ) -> Result<Self, SimError> {
        super::check_travel_time("reference.travel_time", travel_time)?;
        let frame = helix.frame()?;
        let m = map.n_coords();
        let n = map.link_lengths().len();
        if n.saturating_mul(m) > MAX_SPATIAL_PATH_WORK {
            return Err(SimError::setting(
                "arm.links",
                format!(
                    "x modal coordinates must be at most {MAX_SPATIAL_PATH_WORK} for a path \
                     reference (its inverse kinematics is resolved at {} nodes, each costing \
                     about links x coordinates), got {n} x {m}: fewer links or harmonics",
                    GRID_INTERVALS + 1
                ),
            ));
        }
        let length: f64 = map.link_lengths().iter().sum();
        let rotation = base.rotation();
        let ik = SpatialIk::new(map, base)?;
        let step = travel_time / GRID_INTERVALS as f64;
        let mut path = Self {
            frame,
            travel_time,
            family: Box::new(ChainTip {
                ik,
                jacobian: vec![0.0; 3 * m],
                scratch: RateScratch::new(m),
            }),
            nodes: Vec::with_capacity(GRID_INTERVALS + 1),
            step,
        };
        // The start's guess: the planar closed form of the start's projection on the base's
        // x-y plane (in the base frame), in the a_z family.
        let start = path.tip_motion(0.0).p;
        let local: [f64; 3] = std::array::from_fn(|c| {
            (0..3)
                .map(|r| rotation[r][c] * (start[r] - base.xyz[r]))
                .sum()
        });
        let mut first = ReferenceSample::zeros(m);
        if let Ok([a1, a2]) = inverse_kinematics(length, [local[0], local[1]], 0.0, branch) {
            first.a[0] = a1;
            first.a[1] = a2;
        }
        let motion = path.tip_motion(0.0);
        resolve(&mut *path.family, 0.0, motion, None, &mut first)?;
        path.nodes.push(first);
        for k in 1..=GRID_INTERVALS {
            let t = k as f64 * step;
            let mut node = ReferenceSample::zeros(m);
            let motion = path.tip_motion(t);
            let previous = Some((&path.nodes[k - 1], step));
            resolve(&mut *path.family, t, motion, previous, &mut node)?;
            path.nodes.push(node);
        }
        Ok(path)
    }

    /// The desired tip position at time `t` (m).
    pub fn point(&self, t: f64) -> [f64; 3] {
        self.tip_motion(t).p
    }

    /// The time the tip takes along the path (s).
    pub fn travel_time(&self) -> f64 {
        self.travel_time
    }

    /// The tip's position, velocity and acceleration at `t`.
    fn tip_motion(&self, t: f64) -> TipMotion<3> {
        let HelixFrame {
            foot,
            u,
            v,
            w,
            rise,
            sweep,
        } = self.frame;
        let moving = (0.0..self.travel_time).contains(&t);
        let phi = sweep * (t / self.travel_time).clamp(0.0, 1.0);
        let rate = if moving {
            sweep / self.travel_time
        } else {
            0.0
        };
        let (sin, cos) = phi.sin_cos();
        TipMotion {
            p: std::array::from_fn(|d| foot[d] + cos * u[d] + sin * v[d] + rise * phi * w[d]),
            v: std::array::from_fn(|d| rate * (-sin * u[d] + cos * v[d] + rise * w[d])),
            acc: std::array::from_fn(|d| -rate * rate * (cos * u[d] + sin * v[d])),
        }
    }
}

impl Reference for SpatialPath {
    fn n_coords(&self) -> usize {
        self.nodes[0].n_coords()
    }

    /// The solution from the grid node at or before `t` (see the type's docs).
    fn sample(&mut self, t: f64, out: &mut ReferenceSample) -> Result<(), SimError> {
        let motion = self.tip_motion(t);
        let k = ((t / self.step).floor().max(0.0) as usize).min(self.nodes.len() - 1);
        let node = &self.nodes[k];
        let dt = t.clamp(0.0, self.travel_time) - k as f64 * self.step;
        out.a.copy_from_slice(&node.a);
        let previous = (dt > 0.0).then_some((node, dt));
        resolve(&mut *self.family, t, motion, previous, out)
    }
}
