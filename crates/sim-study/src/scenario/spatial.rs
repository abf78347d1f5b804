//! Scenarios on a spatial modal arm (`[arm] kind = "spatial"`): the arm's reduced model, its
//! tip path in space, and which of the planar keys it refuses.

use super::arm::{ArmKind, Gravity, Inertias};
use super::schema::{Alpha0, ArmSpec, BranchSpec, HelixSpec, ReferenceSpec, Scenario};
use backbone_kin::{BasePose, Branch, SpatialModalMap};
use lane_math::check_all_finite;
use manip_dyn::{ChainModel, DynError};
use modal_reduce::spatial::{SpatialLinkInertia, SpatialReducedModel};
use modal_reduce::{PlantModel, ReduceError};
use sim_core::reference::{Helix, SpatialPath};
use sim_core::{Prepared, ReferenceFactory, SimError};

/// Gravity of a spatial arm without `arm.gravity`: 9.81 m/s^2 along `-z`.
const DEFAULT_GRAVITY: [f64; 3] = [0.0, 0.0, -9.81];

impl Scenario {
    /// The modal arm of the scenario, planar ([`model`](Self::model)) or spatial
    /// ([`spatial_model`](Self::spatial_model)), as the loop takes it.
    pub fn plant(&self) -> Result<PlantModel, SimError> {
        match self.arm.kind {
            ArmKind::Planar => self.model().map(PlantModel::Planar),
            ArmKind::Spatial => self.spatial_model().map(PlantModel::Spatial),
        }
    }

    /// The reduced model of a spatial arm (`[arm] kind = "spatial"`) with `modal.harmonics = K`
    /// harmonics per bending plane (`m = 4K`). Refuses a planar arm, `alpha0` (the base pose
    /// `arm.base` holds a spatial arm's base angles), a family with no harmonic or more than
    /// `n / 2` (two coordinates per plane and harmonic: more would leave the reduced mass
    /// matrix singular), or one whose dynamics take more than
    /// [`MAX_LOOP_WORK`](sim_core::MAX_LOOP_WORK) per evaluation; the arm's own errors are
    /// [`ArmSpec::to_spatial`]'s.
    pub fn spatial_model(&self) -> Result<SpatialReducedModel, SimError> {
        if self.arm.kind != ArmKind::Spatial {
            return Err(SimError::setting(
                "arm.kind",
                "is \"planar\": the planar arm's model is Scenario::model",
            ));
        }
        if self.alpha0.is_some() {
            return Err(SimError::setting(
                "alpha0",
                "is not used with a spatial arm: its base angles are arm.base.rpy",
            ));
        }
        self.arm.to_spatial(self.modal.harmonics)
    }

    /// The reference of a spatial scenario for `model`: the modal kinds as for a planar arm
    /// (`m = 4K` entries per array), or a path of kind `path` with a `helix`.
    pub(super) fn spatial_reference(
        &self,
        model: &SpatialReducedModel,
    ) -> Result<ReferenceFactory, SimError> {
        let ReferenceSpec::Path {
            travel_time,
            branch,
            sine,
            points,
            helix,
        } = &self.reference
        else {
            return self.reference.build(
                0.0,
                self.modal.harmonics,
                Alpha0::Fixed(0.0),
                model.n_coords(),
            );
        };
        let helix = match (sine, points, helix) {
            (None, None, Some(helix)) => helix,
            _ => {
                return Err(SimError::setting(
                    "reference",
                    "of kind \"path\" on a spatial arm needs a `helix` (and no `sine` or \
                     `points`, which are paths in the plane)",
                ));
            }
        };
        let branch = match branch {
            BranchSpec::Positive => Branch::Positive,
            BranchSpec::Negative => Branch::Negative,
        };
        Ok(Prepared::reference_clones(SpatialPath::new(
            helix.helix(),
            *travel_time,
            model.map().clone(),
            *model.base(),
            branch,
        )?))
    }
}

impl HelixSpec {
    /// The helix of `sim-core`.
    fn helix(&self) -> Helix {
        Helix {
            center: self.center,
            axis: self.axis,
            start: self.start,
            pitch: self.pitch,
            turns: self.turns,
        }
    }
}

impl ArmSpec {
    /// The spatial arm with `harmonics` harmonics per plane: `links` links of `link_length` and
    /// `link_mass` (the paper's 10 of 0.1 m and 0.1 kg by default), per-link `lengths` and
    /// `masses` overriding, slender rods (`Ixx = 0`, `Iyy = Izz = m L^2 / 12`) unless `inertias` gives each
    /// link's `[Ixx, Iyy, Izz]`, universal joints, leaving `base` under `gravity` (default
    /// `[0, 0, -9.81]`; a number `g` is `[0, 0, -g]`). The number of links is checked against
    /// [`backbone_kin::MAX_LINKS`] before any per-link array is allocated.
    ///
    /// # Errors
    /// [`SimError::InvalidSetting`] naming the field: lists of different lengths, no link or too many, a non-positive or non-finite length or
    /// mass (`arm.lengths[3]`), an inertia that is negative, not finite or breaks the triangle
    /// inequality (`arm.inertias[3]`), a non-finite base pose or gravity, a URDF, and harmonics
    /// out of range (`modal.harmonics`); a model whose reduced dynamics exceed the work a
    /// closed-loop run's evaluation may take (`sim_core::check_loop_work`).
    pub fn to_spatial(&self, harmonics: usize) -> Result<SpatialReducedModel, SimError> {
        let model = self.spatial_model(harmonics)?;
        sim_core::check_loop_work(2 * model.n_links(), model.n_coords())?;
        Ok(model)
    }

    /// [`to_spatial`](Self::to_spatial) without the bound of a closed-loop run's work: the
    /// model to evaluate (`hrm eval`, Python's `SpatialArm`), whose callers bound their own.
    ///
    /// # Errors
    /// As [`to_spatial`](Self::to_spatial), but for the run's work.
    pub fn spatial_model(&self, harmonics: usize) -> Result<SpatialReducedModel, SimError> {
        if self.urdf.is_some() {
            return Err(SimError::setting(
                "arm.urdf",
                "is not used with a spatial modal arm (a URDF chain runs in the joint-space \
                 loop)",
            ));
        }
        let inertias = match &self.inertias {
            None => None,
            Some(Inertias::Principal(values)) => Some(values),
            Some(Inertias::PerLink(_)) => {
                return Err(SimError::setting(
                    "arm.inertias",
                    "of a spatial arm gives [Ixx, Iyy, Izz] per link (kg m^2, about the centre \
                     of mass in the link frame), not one number per link",
                ));
            }
        };
        let n = self.link_count(inertias.map(Vec::len))?;
        let k = harmonics;
        if k == 0 {
            return Err(SimError::setting("modal.harmonics", "must be at least 1"));
        }
        if n < 2 {
            return Err(SimError::setting(
                "arm.links",
                format!(
                    "must be at least 2 for a spatial arm (one harmonic takes 2 coordinates per \
                     bending plane, which must not outnumber the links), got {n}"
                ),
            ));
        }
        if k > n / 2 {
            return Err(SimError::setting(
                "modal.harmonics",
                format!(
                    "= {k} gives {} coordinates per bending plane, more than the arm's {n} \
                     links: the reduced mass matrix would be singular (at most {} harmonics)",
                    2 * k,
                    n / 2
                ),
            ));
        }
        let gravity = self.gravity.unwrap_or(Gravity::Vector(DEFAULT_GRAVITY));
        gravity.check()?;
        let gravity = gravity.spatial();
        // The links checked as a planar arm's beams, and their sums (total mass, mass x length^2,
        // mass x |g| x length) finite as a planar chain's: a length whose square under- or
        // overflows leaves no curve to resolve and no mass matrix.
        let beams = self.links(n, None)?;
        let lengths: Vec<f64> = beams.iter().map(|link| link.length).collect();
        let masses: Vec<f64> = beams.iter().map(|link| link.mass).collect();
        let g = gravity.iter().map(|g| g * g).sum::<f64>().sqrt();
        ChainModel::new(beams, g)
            .map_err(|e| SimError::setting("arm", format!("is invalid: {e}")))?;
        let links: Vec<SpatialLinkInertia> = match inertias {
            Some(values) => masses
                .iter()
                .zip(values)
                .map(|(&mass, &principal)| SpatialLinkInertia { mass, principal })
                .collect(),
            None => masses
                .iter()
                .zip(&lengths)
                .map(|(&mass, &length)| SpatialLinkInertia::rod(mass, length))
                .collect(),
        };
        let base: BasePose = self.base.unwrap_or_default().into();
        check_all_finite("arm.base.xyz", &base.xyz)?;
        check_all_finite("arm.base.rpy", &base.rpy)?;
        base.validate()
            .map_err(|e| SimError::setting("arm.base.xyz", format!("is invalid: {e}")))?;
        let map = SpatialModalMap::new(&lengths, k)
            .map_err(|e| SimError::setting("arm", format!("is invalid: {e}")))?;
        // Lengths and masses are checked above (a rod's `m L^2 / 12` is the beam's): a link the
        // model refuses has a bad inertia of the user's.
        SpatialReducedModel::new(map, base, links, gravity).map_err(|e| match e {
            ReduceError::Dyn(DynError::InvalidLink { index, .. }) if inertias.is_some() => {
                SimError::setting(format!("arm.inertias[{index}]"), format!("is invalid: {e}"))
            }
            e => SimError::setting("arm", format!("is invalid: {e}")),
        })
    }
}
