//! The controllers a scenario may name: one table ([`CONTROLLERS`]) of names, descriptions and
//! constructors, and the scenario's `[controller]` settings they are built from
//! ([`ControllerSpec`]).

use fuzzy_sugeno::FuzzySystem;
use modal_reduce::PlantModel;
use optimal_ctl::MpcSettings;
use serde::{Deserialize, Serialize};
use sim_core::controller::{
    ComputedTorque, Controller, FuzzyController, LqrController, MpcController, MpcLimits,
    PdController,
};
use sim_core::{ControllerFactory, Prepared, ReferenceFactory, SimError};
use std::fmt;
use std::path::PathBuf;
use std::str::FromStr;
use std::sync::Arc;

/// Which controller closes the loop: the key of a row of [`CONTROLLERS`], where its name,
/// description and constructor are. Written in scenario files and on the command line by its
/// [`name`](Self::name).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub enum ControllerKind {
    /// The paper's fuzzy controller, or the `.fis` system given.
    #[default]
    Fuzzy,
    /// The fuzzy controller's linearisation at the origin ([`PdController::from_fuzzy_slope`]).
    Pd,
    /// Computed torque with the exact reduced model ([`ComputedTorque`]).
    ComputedTorque,
    /// The fuzzy controller plus gravity compensation `G*`.
    FuzzyGc,
    /// LQR about the reference, re-linearised along it ([`LqrController`]).
    Lqr,
    /// Model-predictive control: control-limited iLQR over a receding horizon, previewing the
    /// scenario's reference ([`MpcController`], [`MpcSettings::uniform`]).
    Mpc,
}

/// The controller and its sampling.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerSpec {
    /// Which controller (default fuzzy).
    #[serde(default)]
    pub kind: ControllerKind,
    /// Sampling period (s); default: the RK4 step (required with `dopri5`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub period: Option<f64>,
    /// A `.fis` file replacing the paper's fuzzy system (for fuzzy, pd and fuzzy-gc); a relative
    /// path is relative to the scenario file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fis: Option<PathBuf>,
    /// What the fuzzy controllers (fuzzy, fuzzy-gc) do with an input outside its variable's
    /// range: `"as-given"` (the default, as MATLAB's `evalfis` and Simulink's Fuzzy Logic
    /// Controller block evaluate it; bells fade far out) or `"clamp"` (evaluated at the nearest
    /// end of the range: the action saturates).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub out_of_range: Option<FuzzyInputRange>,
    /// Computed-torque stiffness per coordinate (1/s^2, default 2500 each: 50 rad/s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kp: Option<Vec<f64>>,
    /// Computed-torque damping per coordinate (1/s, default 100 each: critically damped).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kd: Option<Vec<f64>>,
    /// PD stiffness per coordinate (N m/rad); default: the fuzzy system's slope at the origin.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pd_kp: Option<Vec<f64>>,
    /// PD damping per coordinate (N m s/rad); default: the fuzzy system's slope at the origin.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pd_kd: Option<Vec<f64>>,
    /// LQR design frequency `omega` (rad/s, default 50): the weights place the poles of the
    /// straight arm without gravity at a Butterworth pair of radius `omega`
    /// ([`LqrController`](sim_core::controller::LqrController)).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lqr_frequency: Option<f64>,
    /// LQR re-linearisation period (s, default 0.01; at least the controller period).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lqr_relinearise: Option<f64>,
    /// The clearance MPC plans to keep between every link and every obstacle and between links
    /// that share no joint (m, non-negative, at most 1e3; default the `[task]`'s `clearance`,
    /// else 0). Only with `[[obstacles]]` or `[arm] radius`
    /// ([`MpcLimits`](sim_core::controller::MpcLimits)).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clearance_m: Option<f64>,
}

/// What a fuzzy controller does with an input outside its variable's range
/// ([`fuzzy_sugeno::OutOfRange`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FuzzyInputRange {
    /// Evaluated as given (MATLAB's `evalfis`, Simulink's Fuzzy Logic Controller block).
    #[default]
    AsGiven,
    /// Evaluated at the nearest end of the range.
    Clamp,
}

impl From<FuzzyInputRange> for fuzzy_sugeno::OutOfRange {
    fn from(policy: FuzzyInputRange) -> Self {
        match policy {
            FuzzyInputRange::AsGiven => Self::AsGiven,
            FuzzyInputRange::Clamp => Self::Clamp,
        }
    }
}

/// What a controller's constructor is given: the scenario's `[controller]` settings, with every
/// per-coordinate gain array already checked to have `m` entries, the model and sampling period
/// of the loop, and its reference.
#[derive(Clone, Copy)]
pub struct ControllerSetup<'a> {
    /// The scenario's `[controller]` table.
    pub spec: &'a ControllerSpec,
    /// The reduced model (planar or spatial) the controller will be sampled on (`m`
    /// coordinates).
    pub model: &'a PlantModel,
    /// The controller's sampling period (s).
    pub period: f64,
    /// The loop's reference (MPC previews a copy of it).
    pub reference: &'a ReferenceFactory,
    /// A fuzzy system given in memory (e.g. one just learned), used instead of the `.fis` file
    /// `spec.fis` names or the paper's; `None` for those.
    pub system: Option<&'a FuzzySystem>,
    /// What MPC plans within besides the `tau*` box: the loop's joint limits, its links and
    /// obstacles, and the clearance margin (empty without them).
    pub limits: &'a MpcLimits,
}

/// A row of the controller table: a controller's name, what it is, and how a scenario builds it.
#[derive(Debug, Clone, Copy)]
pub struct ControllerEntry {
    /// Its key.
    pub kind: ControllerKind,
    /// Its name in scenario files, on the command line and in outputs.
    pub name: &'static str,
    /// One line on what it is (the command line's help).
    pub description: &'static str,
    prepare: fn(&ControllerSetup<'_>) -> Result<ControllerFactory, SimError>,
}

impl ControllerSetup<'_> {
    /// The fuzzy system: the one given in memory, else the `.fis` file if given, else the
    /// paper's.
    fn fuzzy_system(&self) -> Result<FuzzySystem, SimError> {
        match self.system {
            Some(system) => Ok(system.clone()),
            None => self.spec.fuzzy_system(),
        }
    }

    /// The controller of `spec.kind` for the model, prepared for any number of runs: checks
    /// every per-coordinate gain array of `spec` to have `m` entries, the LQR's settings to be in
    /// their domain and the `fis` file to be a fuzzy system (whichever controller uses them: a
    /// sweep may run any on the scenario), then calls the kind's constructor in [`CONTROLLERS`].
    pub fn prepare(&self) -> Result<ControllerFactory, SimError> {
        let m = m(self);
        self.spec.computed_torque_gains(m)?;
        self.spec.pd_gains(m)?;
        if self.spec.lqr_frequency.is_some() || self.spec.lqr_relinearise.is_some() {
            let (frequency, relinearise) = self.spec.lqr_settings(self.period);
            LqrController::check_settings(self.period, frequency, relinearise)?;
        }
        // The fuzzy kinds read `fis` themselves; the others check it can be read and parsed.
        let reads_fis = matches!(
            self.spec.kind,
            ControllerKind::Fuzzy | ControllerKind::Pd | ControllerKind::FuzzyGc
        );
        if self.spec.fis.is_some() && !reads_fis {
            self.fuzzy_system()?;
        }
        self.spec.kind.entry().prepare(self)
    }
}

impl ControllerEntry {
    /// The controller for `setup`'s model, built once (a `.fis` file read and parsed once),
    /// as a factory of fresh copies for the runs.
    pub fn prepare(&self, setup: &ControllerSetup<'_>) -> Result<ControllerFactory, SimError> {
        (self.prepare)(setup)
    }
}

/// The controller table, in the order of the paper's comparison (the order of the main job's
/// table): row `i` is the entry of the [`ControllerKind`] whose discriminant is `i`, checked when
/// the crate compiles.
pub const CONTROLLERS: &[ControllerEntry] = &[
    ControllerEntry {
        kind: ControllerKind::Fuzzy,
        name: "fuzzy",
        description: "the paper's fuzzy controller (eqs 19-24), or the .fis system given",
        prepare: |s| {
            Ok(Prepared::controller_clones(
                FuzzyController::new(s.fuzzy_system()?, m(s))?
                    .with_out_of_range(s.spec.out_of_range.unwrap_or_default().into())?,
            ))
        },
    },
    ControllerEntry {
        kind: ControllerKind::Pd,
        name: "pd",
        description: "PD: the fuzzy controller's slope at the origin, or the pd_kp, pd_kd gains",
        prepare: |s| {
            let m = m(s);
            let slope = PdController::from_fuzzy_slope(&s.fuzzy_system()?, m)?;
            let (kp, kd) = s.spec.pd_gains(m)?;
            let kp = kp.unwrap_or_else(|| slope.kp().to_vec());
            let kd = kd.unwrap_or_else(|| slope.kd().to_vec());
            Ok(Prepared::controller_clones(PdController::new(
                slope.offset(),
                &kp,
                &kd,
            )?))
        },
    },
    ControllerEntry {
        kind: ControllerKind::ComputedTorque,
        name: "computed-torque",
        description: "computed torque with the exact reduced model, gains kp, kd",
        prepare: |s| {
            let (kp, kd) = s.spec.computed_torque_gains(m(s))?;
            Ok(Prepared::controller_clones(ComputedTorque::new(
                s.model.plant(),
                &kp,
                &kd,
            )?))
        },
    },
    ControllerEntry {
        kind: ControllerKind::FuzzyGc,
        name: "fuzzy-gc",
        description: "the fuzzy controller plus gravity compensation G*",
        prepare: |s| {
            let fuzzy = FuzzyController::new(s.fuzzy_system()?, m(s))?
                .with_out_of_range(s.spec.out_of_range.unwrap_or_default().into())?;
            Ok(Prepared::controller_clones(
                fuzzy.with_gravity_compensation(s.model.plant())?,
            ))
        },
    },
    ControllerEntry {
        kind: ControllerKind::Lqr,
        name: "lqr",
        description: "LQR about the reference (feedforward M* a_ref_dd + C* + G*), re-linearised \
                      along it every lqr_relinearise s, design frequency lqr_frequency",
        prepare: |s| {
            let (frequency, relinearise) = s.spec.lqr_settings(s.period);
            Ok(Prepared::controller_clones(LqrController::new(
                s.model.plant(),
                s.period,
                frequency,
                relinearise,
            )?))
        },
    },
    ControllerEntry {
        kind: ControllerKind::Mpc,
        name: "mpc",
        description: "model-predictive control: control-limited iLQR over a 0.3 s receding horizon, \
                      within the joint limits and the clearance margin (clearance_m)",
        prepare: |s| {
            let settings = MpcSettings::uniform(m(s));
            // The scenario's key that sets `m` (2K or 2K + 1 planar, 4K spatial).
            if m(s) > settings.max_coords() {
                return Err(SimError::setting(
                    "modal.harmonics",
                    format!(
                        "gives {} modal coordinates, more than the {} whose plan over MPC's \
                         {}-step horizon the solver holds",
                        m(s),
                        settings.max_coords(),
                        settings.horizon
                    ),
                ));
            }
            let (model, reference) = (s.model.clone(), Arc::clone(s.reference));
            let limits = s.limits.clone();
            let build = move || -> Result<Box<dyn Controller>, SimError> {
                Ok(Box::new(
                    MpcController::new(model.plant(), &settings, reference()?)?
                        .with_limits(model.plant(), &limits)?,
                ))
            };
            // Checked once here; each run builds its own (its plan is its state).
            build()?;
            Ok(Arc::new(build))
        },
    },
];

// Row `i` of the table is the kind with discriminant `i`, so `kind.entry()` is an index.
const _: () = {
    let mut i = 0;
    while i < CONTROLLERS.len() {
        assert!(CONTROLLERS[i].kind as usize == i);
        i += 1;
    }
};

/// The number of modal coordinates of a setup's model.
fn m(setup: &ControllerSetup<'_>) -> usize {
    setup.model.plant().n_coords()
}

impl ControllerKind {
    /// Every controller, in the table's order.
    pub const ALL: [ControllerKind; CONTROLLERS.len()] = {
        let mut all = [ControllerKind::Fuzzy; CONTROLLERS.len()];
        let mut i = 0;
        while i < all.len() {
            all[i] = CONTROLLERS[i].kind;
            i += 1;
        }
        all
    };

    /// Its row of [`CONTROLLERS`].
    pub fn entry(self) -> &'static ControllerEntry {
        &CONTROLLERS[self as usize]
    }

    /// The name used in scenario files and on the command line.
    pub fn name(self) -> &'static str {
        self.entry().name
    }

    /// Every controller's name, joined by `separator`.
    pub fn names(separator: &str) -> String {
        CONTROLLERS
            .iter()
            .map(|e| e.name)
            .collect::<Vec<_>>()
            .join(separator)
    }
}

impl fmt::Display for ControllerKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for ControllerKind {
    type Err = SimError;

    /// Parses a name of the table ([`CONTROLLERS`]).
    fn from_str(s: &str) -> Result<Self, SimError> {
        CONTROLLERS
            .iter()
            .find(|e| e.name == s)
            .map(|e| e.kind)
            .ok_or_else(|| {
                SimError::setting(
                    "controller",
                    format!("must be one of {}, got '{s}'", Self::names(", ")),
                )
            })
    }
}

impl Serialize for ControllerKind {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for ControllerKind {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let name = String::deserialize(deserializer)?;
        name.parse().map_err(|_| {
            serde::de::Error::custom(format!(
                "unknown controller `{name}`, expected one of {}",
                Self::names(", ")
            ))
        })
    }
}

/// The default computed-torque stiffness (1/s^2): 50 rad/s.
const DEFAULT_KP: f64 = 2500.0;
/// The default computed-torque damping (1/s): critically damped with [`DEFAULT_KP`].
const DEFAULT_KD: f64 = 100.0;

impl ControllerSpec {
    /// The LQR's design frequency and re-linearisation period for a controller sampled every
    /// `period` seconds: the keys given, else [`LqrController`]'s defaults (the
    /// re-linearisation at least every sample: a controller period above the default's 10 ms
    /// re-linearises at every sample).
    fn lqr_settings(&self, period: f64) -> (f64, f64) {
        (
            self.lqr_frequency
                .unwrap_or(LqrController::DEFAULT_FREQUENCY),
            self.lqr_relinearise
                .unwrap_or(LqrController::DEFAULT_RELINEARISE_PERIOD.max(period)),
        )
    }

    /// The fuzzy system: the `.fis` file if given, else the paper's.
    fn fuzzy_system(&self) -> Result<FuzzySystem, SimError> {
        match &self.fis {
            None => Ok(fuzzy_sugeno::paper_controller()),
            Some(path) => {
                let text =
                    crate::read_text_file(path, crate::MAX_INPUT_FILE_BYTES).map_err(|e| {
                        SimError::setting(
                            "controller.fis",
                            format!("cannot be read from {}: {e}", path.display()),
                        )
                    })?;
                FuzzySystem::from_fis(&text).map_err(|e| {
                    SimError::setting("controller.fis", format!("({}): {e}", path.display()))
                })
            }
        }
    }

    /// The PD gains `pd_kp`, `pd_kd` for `m` coordinates where given, each non-negative and
    /// finite (a negative stiffness pushes the arm away from its reference).
    fn pd_gains(&self, m: usize) -> Result<(GivenGains, GivenGains), SimError> {
        Ok((
            gains("controller.pd_kp", &self.pd_kp, m)?,
            gains("controller.pd_kd", &self.pd_kd, m)?,
        ))
    }

    /// The computed-torque gains `kp`, `kd` for `m` coordinates (defaults where not given), each
    /// non-negative and finite.
    pub(super) fn computed_torque_gains(&self, m: usize) -> Result<(Vec<f64>, Vec<f64>), SimError> {
        Ok((
            gains("controller.kp", &self.kp, m)?.unwrap_or_else(|| vec![DEFAULT_KP; m]),
            gains("controller.kd", &self.kd, m)?.unwrap_or_else(|| vec![DEFAULT_KD; m]),
        ))
    }
}

/// Per-coordinate gains a scenario gives, if it does.
type GivenGains = Option<Vec<f64>>;

/// The gains `values` of the key `name` if given: `m` entries ([`per_coordinate`]), each
/// non-negative and finite.
fn gains(name: &str, values: &Option<Vec<f64>>, m: usize) -> Result<GivenGains, SimError> {
    let values = per_coordinate(name, values.as_deref(), m)?;
    for &value in values.iter().flatten() {
        sim_core::check_non_negative(name, value)?;
    }
    Ok(values)
}

/// `values` if given, checked to have exactly `m` entries (one per modal coordinate); the
/// error names the field.
pub(super) fn per_coordinate(
    name: &str,
    values: Option<&[f64]>,
    m: usize,
) -> Result<Option<Vec<f64>>, SimError> {
    match values {
        None => Ok(None),
        Some(values) if values.len() == m => Ok(Some(values.to_vec())),
        Some(values) => Err(SimError::setting(
            name,
            format!(
                "has {} entries, the model has {m} coordinates (one entry each)",
                values.len()
            ),
        )),
    }
}
