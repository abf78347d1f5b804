//! What a sweep runs: its configuration, the fixed enumeration of its runs, each run's seed,
//! and the slice of runs one shard takes.

use super::error::{SettingError, StudyError};
use super::inputs::{self, InputDigest};
use super::shard::MAX_SHARDS;
use crate::{ControllerKind, NoiseSpec, Scenario};
use lane_math::Compact;
use serde::{Deserialize, Serialize};
use sim_core::{Prepared, RunNoise, SimError};

/// The SplitMix64 increment (the golden ratio in 64-bit fixed point).
const SPLITMIX_GAMMA: u64 = 0x9E37_79B9_7F4A_7C15;

/// Most runs in a sweep (noise levels x controllers x seeds), checked by
/// [`SweepConfig::validate`] before any per-run buffer exists.
pub const MAX_RUNS: usize = 10_000_000;

/// The most noise levels a sweep takes.
pub const MAX_NOISE_LEVELS: usize = 1000;

/// The most seeds (noise realisations per cell) a sweep takes.
pub const MAX_SEEDS: usize = 1_000_000;
// A shard holds one run at least, so a sweep never splits into more shards than runs.
const _: () = assert!(MAX_SHARDS <= MAX_RUNS);

/// Everything that defines a sweep's results; shards merge only when theirs are equal.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepConfig {
    /// The `hrm` version that ran the sweep.
    pub hrm_version: String,
    /// The scenario, duration override applied; its `noise` and `seed` are replaced per run.
    pub scenario: Scenario,
    /// What the sweep varies: controllers, noise levels and ratios, seeds.
    pub settings: SweepSettings,
    /// The SHA-256 of the scenario and of every file it references
    /// ([`input_digests`](super::input_digests) of `scenario`).
    pub inputs: Vec<InputDigest>,
}

/// Where run `index` sits in the sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunId {
    /// The run's index in the fixed enumeration.
    pub index: usize,
    /// Position of its noise level in [`SweepSettings::noise_levels`].
    pub level_index: usize,
    /// Its noise level (rad).
    pub noise_level: f64,
    /// Its controller.
    pub controller: ControllerKind,
    /// Which of the cell's noise realisations (0-based).
    pub seed_index: usize,
    /// The seed of its noise sources.
    pub seed: u64,
}

/// What a sweep varies and how many noise realisations it draws: the options of `hrm sweep` and
/// the keywords of `hrm.Sweep`, which [`SweepConfig::new`] checks and turns into a sweep. The
/// [`Default`] is `hrm sweep`'s.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepSettings {
    /// The controllers compared, in table order, each once.
    pub controllers: Vec<ControllerKind>,
    /// The noise levels `L`, distinct and ascending: the sensor noise standard deviation on every
    /// modal coordinate (rad).
    pub noise_levels: Vec<f64>,
    /// Sensor noise on every modal rate per unit of noise level (rad/s per rad, i.e. 1/s).
    pub rate_noise_ratio: f64,
    /// Noise on every coordinate of the reference per unit of noise level.
    pub reference_noise_ratio: f64,
    /// Noise realisations per (noise level, controller) cell, at least 1.
    pub seeds: usize,
    /// The seed every run's seed derives from ([`run_seed`]).
    pub base_seed: u64,
}

impl Default for SweepSettings {
    /// `hrm sweep`'s defaults: every controller, noise levels 0, 0.005, 0.01, 0.02, 0.05 and
    /// 0.1 rad, rate noise ratio 10, no reference noise, 10 seeds from base seed 1.
    fn default() -> Self {
        Self {
            controllers: ControllerKind::ALL.to_vec(),
            noise_levels: vec![0.0, 0.005, 0.01, 0.02, 0.05, 0.1],
            rate_noise_ratio: 10.0,
            reference_noise_ratio: 0.0,
            seeds: 10,
            base_seed: 1,
        }
    }
}

impl SweepSettings {
    /// Number of runs: noise levels x controllers x seeds (`None` on overflow).
    pub fn runs(&self) -> Option<usize> {
        self.noise_levels
            .len()
            .checked_mul(self.controllers.len())?
            .checked_mul(self.seeds)
    }

    /// Checks the settings: at least one controller and none twice, at least one noise level,
    /// all finite, non-negative, distinct and ascending, finite non-negative ratios whose products
    /// with the largest level are finite, from one seed to [`MAX_SEEDS`], and at most
    /// [`MAX_RUNS`] runs.
    pub fn check(&self) -> Result<(), SettingError> {
        if self.controllers.is_empty() {
            return Err(SettingError::new(
                "controllers",
                "must name at least one controller",
            ));
        }
        for (k, c) in self.controllers.iter().enumerate().skip(1) {
            if self.controllers[..k].contains(c) {
                return Err(SettingError::new("controllers", format!("lists {c} twice")));
            }
        }
        if self.noise_levels.is_empty() {
            return Err(SettingError::new(
                "noise_levels",
                "must hold at least one noise level",
            ));
        }
        if let Some(bad) = self
            .noise_levels
            .iter()
            .find(|l| !(l.is_finite() && l.is_sign_positive()))
        {
            return Err(SettingError::new(
                "noise_levels",
                format!("must be finite and non-negative, got {}", Compact(*bad)),
            ));
        }
        if self.noise_levels.len() > MAX_NOISE_LEVELS {
            return Err(SettingError::new(
                "noise_levels",
                format!(
                    "lists {} levels, more than the {MAX_NOISE_LEVELS} a sweep takes",
                    self.noise_levels.len()
                ),
            ));
        }
        if self.noise_levels.windows(2).any(|w| w[0] >= w[1]) {
            return Err(SettingError::new(
                "noise_levels",
                format!(
                    "must be distinct and ascending, got {:?}",
                    self.noise_levels
                ),
            ));
        }
        for (name, ratio) in [
            ("rate_noise_ratio", self.rate_noise_ratio),
            ("reference_noise_ratio", self.reference_noise_ratio),
        ] {
            if !(ratio.is_finite() && ratio >= 0.0) {
                return Err(SettingError::new(
                    name,
                    format!("must be finite and non-negative, got {}", Compact(ratio)),
                ));
            }
        }
        // A run's noise is a level, and a level times a ratio: each within the scale a run
        // resolves (`sim_core::MAX_MODAL_MAGNITUDE`), which the scenario would refuse by its
        // own keys.
        let largest = self.noise_levels[self.noise_levels.len() - 1];
        let bound = sim_core::MAX_MODAL_MAGNITUDE;
        if largest > bound {
            return Err(SettingError::new(
                "noise_levels",
                format!(
                    "must be at most {} (rad, rad/s), got {}",
                    Compact(bound),
                    Compact(largest)
                ),
            ));
        }
        for (name, ratio) in [
            ("rate_noise_ratio", self.rate_noise_ratio),
            ("reference_noise_ratio", self.reference_noise_ratio),
        ] {
            let product = largest * ratio;
            if product > bound {
                return Err(SettingError::new(
                    "noise_levels",
                    format!(
                        "{} times {name} = {} is {}, more than the {} (rad, rad/s) a run's noise \
                         may be",
                        Compact(largest),
                        Compact(ratio),
                        Compact(product),
                        Compact(bound)
                    ),
                ));
            }
        }
        if self.seeds == 0 {
            return Err(SettingError::new("seeds", "must be at least 1"));
        }
        if self.seeds > MAX_SEEDS {
            return Err(SettingError::new(
                "seeds",
                format!("must be at most {MAX_SEEDS}, got {}", self.seeds),
            ));
        }
        match self.runs() {
            Some(runs) if runs <= MAX_RUNS => Ok(()),
            _ => Err(SettingError::new(
                "seeds",
                format!(
                    "= {} with {} noise levels x {} controllers makes more than the {MAX_RUNS} \
                     runs allowed",
                    self.seeds,
                    self.noise_levels.len(),
                    self.controllers.len()
                ),
            )),
        }
    }
}

impl SweepConfig {
    /// The sweep of `scenario` (its duration applies; its noise and seed are cleared, then set
    /// per run) under `settings`, with the SHA-256 of its inputs (its `controller.fis` and
    /// `arm.urdf` made absolute against the working directory): `settings` are checked
    /// ([`SweepSettings::check`]), then the scenario ([`validate`](Self::validate): every setting
    /// JSON can hold), and every controller's simulation is built once
    /// ([`check_builds`](Self::check_builds)), so a bad setting fails here rather than in every
    /// run. The one constructor of a checked sweep: `hrm sweep` and `hrm.Sweep` call it.
    pub fn new(scenario: Scenario, settings: SweepSettings) -> Result<Self, StudyError> {
        settings.check()?;
        let mut scenario = scenario;
        scenario.noise = NoiseSpec::default();
        scenario.seed = 0;
        // A file given relative to the working directory (Python's `controller.fis = "c.fis"`)
        // is kept absolute, so that a task elsewhere (a Dask worker, an unpickled sweep) reads
        // the same file or none.
        for path in [&mut scenario.controller.fis, &mut scenario.arm.urdf]
            .into_iter()
            .flatten()
        {
            if let Ok(absolute) = std::path::absolute(&*path) {
                *path = absolute;
            }
        }
        inputs::check_json_safe(&scenario)?;
        let config = SweepConfig {
            hrm_version: super::VERSION.to_string(),
            inputs: inputs::input_digests(&scenario)?,
            scenario,
            settings,
        };
        config.validate()?;
        config.check_builds()?;
        Ok(config)
    }

    /// Builds the simulation of the first run of each controller at the largest noise level, so
    /// that a bad setting fails once here rather than in every run.
    pub fn check_builds(&self) -> Result<(), StudyError> {
        let cells = self.settings.noise_levels.len() * self.settings.controllers.len();
        for c in 0..self.settings.controllers.len() {
            let id =
                self.run_at((cells - self.settings.controllers.len() + c) * self.settings.seeds);
            self.scenario_for(&id)
                .build()
                .map_err(|source| StudyError::Build {
                    scenario: self.scenario.name.clone(),
                    controller: id.controller,
                    source: Box::new(source),
                })?;
        }
        Ok(())
    }

    /// Checks that every scenario setting survives JSON
    /// ([`check_json_safe`](super::check_json_safe)), that [`inputs`](Self::inputs) lists the
    /// scenario, with the digest of its content, and the files it references
    /// ([`check_digests`](super::check_digests)), and the [`settings`](Self::settings)
    /// ([`SweepSettings::check`]): for a configuration read back from a shard file or JSON.
    pub fn validate(&self) -> Result<(), StudyError> {
        inputs::check_json_safe(&self.scenario)?;
        inputs::check_digests(&self.scenario, &self.inputs)?;
        Ok(self.settings.check()?)
    }

    /// Number of runs: noise levels x controllers x seeds (`None` on overflow).
    pub fn runs(&self) -> Option<usize> {
        self.settings.runs()
    }

    /// Run `index` of the enumeration `index = (level_index * controllers + controller_index)
    /// * seeds + seed_index`: noise level slowest, seed fastest.
    pub fn run_at(&self, index: usize) -> RunId {
        let seed_index = index % self.settings.seeds;
        let cell = index / self.settings.seeds;
        let n_controllers = self.settings.controllers.len();
        let level_index = cell / n_controllers;
        RunId {
            index,
            level_index,
            noise_level: self.settings.noise_levels[level_index],
            controller: self.settings.controllers[cell % n_controllers],
            seed_index,
            seed: run_seed(self.settings.base_seed, seed_index),
        }
    }

    /// The scenario of run `id`: its controller, seed and noise.
    pub fn scenario_for(&self, id: &RunId) -> Scenario {
        let mut scenario = self.scenario.clone();
        scenario.controller.kind = id.controller;
        scenario.seed = id.seed;
        scenario.noise = self.noise_spec(id);
        scenario
    }

    /// The scenario with `controller`, prepared once for all of its runs
    /// ([`Scenario::prepare`]); each run then takes its [`run_noise`](Self::run_noise).
    pub fn prepare(&self, controller: ControllerKind) -> Result<Prepared, SimError> {
        let mut scenario = self.scenario.clone();
        scenario.controller.kind = controller;
        scenario.prepare()
    }

    /// Run `id`'s seed and noise: what its [`scenario_for`](Self::scenario_for) sets.
    pub fn run_noise(&self, id: &RunId) -> Result<RunNoise, SimError> {
        self.noise_spec(id)
            .run_noise(id.seed, self.scenario.n_coords())
    }

    /// Run `id`'s noise level on every coordinate, scaled by the settings' ratios on the rates
    /// and the reference.
    fn noise_spec(&self, id: &RunId) -> NoiseSpec {
        let level = id.noise_level;
        NoiseSpec::uniform(
            self.scenario.n_coords(),
            level,
            self.settings.rate_noise_ratio * level,
            self.settings.reference_noise_ratio * level,
        )
    }

    /// The name of the first field in which `other` differs, if any: a scenario's key by its
    /// path (`scenario.duration`, `scenario.controller.fis`).
    pub fn first_difference(&self, other: &Self) -> Option<String> {
        let (a, b) = (&self.settings, &other.settings);
        [
            ("hrm_version", self.hrm_version == other.hrm_version),
            ("scenario", self.scenario == other.scenario),
            ("controllers", a.controllers == b.controllers),
            ("noise_levels", a.noise_levels == b.noise_levels),
            ("rate_noise_ratio", a.rate_noise_ratio == b.rate_noise_ratio),
            (
                "reference_noise_ratio",
                a.reference_noise_ratio == b.reference_noise_ratio,
            ),
            ("seeds", a.seeds == b.seeds),
            ("base_seed", a.base_seed == b.base_seed),
            ("inputs", self.inputs == other.inputs),
        ]
        .into_iter()
        .find(|(_, equal)| !equal)
        .map(|(name, _)| match name {
            "scenario" => {
                let tree = |scenario: &Scenario| serde_json::to_value(scenario).ok();
                match (tree(&self.scenario), tree(&other.scenario)) {
                    (Some(here), Some(there)) => {
                        first_different_key(&here, &there, "scenario".to_string())
                    }
                    _ => "scenario".to_string(),
                }
            }
            name => name.to_string(),
        })
    }
}

/// The path (`scenario.reference.sine.amplitude`, `scenario.arm.lengths[3]`) of the first entry
/// where two trees differ, `path` itself where they differ as a whole.
fn first_different_key(
    here: &serde_json::Value,
    there: &serde_json::Value,
    path: String,
) -> String {
    use serde_json::Value;
    match (here, there) {
        (Value::Object(a), Value::Object(b)) => {
            let keys = a.keys().chain(b.keys().filter(|k| !a.contains_key(*k)));
            for key in keys {
                match (a.get(key), b.get(key)) {
                    (Some(x), Some(y)) if x == y => {}
                    (Some(x), Some(y)) => {
                        return first_different_key(x, y, format!("{path}.{key}"));
                    }
                    _ => return format!("{path}.{key}"),
                }
            }
            path
        }
        (Value::Array(a), Value::Array(b)) if a.len() == b.len() => a
            .iter()
            .zip(b)
            .position(|(x, y)| x != y)
            .map_or(path.clone(), |i| {
                first_different_key(&a[i], &b[i], format!("{path}[{i}]"))
            }),
        _ => path,
    }
}

/// The seed of noise realisation `seed_index`: output number `seed_index + 1` of the SplitMix64
/// generator (Steele, Lea and Flood 2014; Vigna's `splitmix64.c`) seeded with `base_seed`. It
/// depends on nothing else, so every (noise level, controller) cell sees the same noise
/// realisations (common random numbers) and no result depends on sharding or scheduling.
pub fn run_seed(base_seed: u64, seed_index: usize) -> u64 {
    let mut z = base_seed.wrapping_add(
        (seed_index as u64)
            .wrapping_add(1)
            .wrapping_mul(SPLITMIX_GAMMA),
    );
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn config(levels: usize, controllers: usize, seeds: usize) -> SweepConfig {
        let scenario = Scenario::builtin("paper-responses-step").unwrap();
        SweepConfig {
            inputs: inputs::input_digests(&scenario).unwrap(),
            hrm_version: "test".into(),
            scenario,
            settings: SweepSettings {
                controllers: ControllerKind::ALL[..controllers].to_vec(),
                noise_levels: (0..levels).map(|l| l as f64 * 1e-3).collect(),
                rate_noise_ratio: 10.0,
                reference_noise_ratio: 0.5,
                seeds,
                base_seed: 9,
            },
        }
    }

    #[test]
    fn seeds_are_the_splitmix64_reference_sequence() {
        // Vigna's splitmix64.c seeded with 1234567 (the Rosetta Code test vector).
        let expected = [
            6457827717110365317,
            3203168211198807973,
            9817491932198370423,
            4593380528125082431,
            16408922859458223821,
        ];
        for (j, e) in expected.into_iter().enumerate() {
            assert_eq!(run_seed(1234567, j), e, "output {}", j + 1);
        }
        // Seeded with 0, the first output is 0xe220a8397b1dcdaf.
        assert_eq!(run_seed(0, 0), 0xE220_A839_7B1D_CDAF);
    }

    #[test]
    fn runs_are_enumerated_level_then_controller_then_seed() {
        let c = config(3, 4, 5);
        assert_eq!(c.runs(), Some(60));
        let id = c.run_at(2 * 20 + 3 * 5 + 4);
        assert_eq!(
            (id.level_index, id.controller, id.seed_index),
            (2, ControllerKind::FuzzyGc, 4)
        );
        assert_eq!(id.noise_level, 2e-3);
        assert_eq!(id.seed, run_seed(9, 4));
        let scenario = c.scenario_for(&id);
        assert_eq!(scenario.controller.kind, ControllerKind::FuzzyGc);
        assert_eq!(scenario.seed, id.seed);
        assert_eq!(scenario.noise.sensor_a_std, Some(vec![2e-3; 2]));
        assert_eq!(scenario.noise.sensor_a_dot_std, Some(vec![2e-2; 2]));
        assert_eq!(scenario.noise.reference_std, Some(vec![1e-3; 2]));
    }

    #[test]
    fn invalid_configurations_are_refused_naming_the_setting() {
        let mut c = config(2, 2, 2);
        assert!(c.validate().is_ok());
        c.settings.noise_levels[1] = -1.0;
        let err = c.validate().unwrap_err().to_string();
        assert_eq!(err, "noise_levels must be finite and non-negative, got -1");
        c.settings.noise_levels[1] = f64::NAN;
        assert!(c.validate().unwrap_err().to_string().contains("got NaN"));
        c.settings.noise_levels = vec![-0.0, 0.01];
        let err = c.validate().unwrap_err().to_string();
        assert_eq!(err, "noise_levels must be finite and non-negative, got -0");
        c.settings.noise_levels = vec![0.01, 0.0];
        let err = c.validate().unwrap_err().to_string();
        assert!(err.starts_with("noise_levels must be distinct and ascending"));
        let mut c = config(2, 2, 0);
        assert_eq!(
            c.validate().unwrap_err().to_string(),
            "seeds must be at least 1"
        );
        c.settings.seeds = 1;
        c.settings.rate_noise_ratio = f64::INFINITY;
        let err = c.validate().unwrap_err().to_string();
        assert_eq!(
            err,
            "rate_noise_ratio must be finite and non-negative, got inf"
        );
        c.settings.rate_noise_ratio = 10.0;
        c.settings.noise_levels = vec![0.0, 1e308];
        assert_eq!(
            c.validate().unwrap_err().to_string(),
            "noise_levels must be at most 1000000 (rad, rad/s), got 1e308"
        );
        c.settings.noise_levels = vec![0.0, 1e6];
        assert_eq!(
            c.validate().unwrap_err().to_string(),
            "noise_levels 1000000 times rate_noise_ratio = 10 is 10000000, more than the 1000000 \
             (rad, rad/s) a run's noise may be"
        );
        let err = config(0, 2, 1).validate().unwrap_err().to_string();
        assert_eq!(err, "noise_levels must hold at least one noise level");
        let err = config(1, 0, 1).validate().unwrap_err().to_string();
        assert_eq!(err, "controllers must name at least one controller");
        let mut twice = config(1, 3, 1);
        twice.settings.controllers[2] = twice.settings.controllers[0];
        let err = twice.validate().unwrap_err().to_string();
        assert_eq!(
            err,
            format!("controllers lists {} twice", twice.settings.controllers[0])
        );
        let err = config(20, 1, MAX_SEEDS).validate().unwrap_err().to_string();
        assert!(err.starts_with("seeds = 1000000 with 20 noise levels x 1 controllers makes more than the 10000000 runs"), "{err}");
        // Python's `Sweep` and `hrm sweep --seeds` share the bound on seeds.
        let err = config(1, 1, MAX_SEEDS + 1)
            .validate()
            .unwrap_err()
            .to_string();
        assert_eq!(err, "seeds must be at most 1000000, got 1000001");
        // The error says which setting, for a front end to name it its own way.
        let settings = SweepSettings {
            seeds: 0,
            ..SweepSettings::default()
        };
        let err = settings.check().unwrap_err();
        assert_eq!(
            (err.setting, err.problem.as_str()),
            ("seeds", "must be at least 1")
        );
    }

    #[test]
    fn the_constructor_checks_the_settings_then_the_scenario_and_clears_its_noise() {
        let mut scenario = Scenario::builtin("paper-responses-step").unwrap();
        scenario.seed = 77;
        scenario.noise = NoiseSpec::uniform(2, 0.1, 0.0, 0.0);
        let settings = SweepSettings {
            controllers: vec![ControllerKind::Pd, ControllerKind::Fuzzy],
            noise_levels: vec![0.0, 0.01],
            seeds: 3,
            base_seed: 5,
            reference_noise_ratio: 0.5,
            ..SweepSettings::default()
        };
        let config = SweepConfig::new(scenario.clone(), settings.clone()).unwrap();
        assert_eq!(config.settings, settings);
        assert_eq!(
            (config.scenario.seed, &config.scenario.noise),
            (0, &NoiseSpec::default())
        );
        assert_eq!(
            config.inputs,
            inputs::input_digests(&config.scenario).unwrap()
        );
        let twice = SweepSettings {
            controllers: vec![ControllerKind::Pd, ControllerKind::Pd],
            ..settings.clone()
        };
        let err = SweepConfig::new(scenario.clone(), twice)
            .unwrap_err()
            .to_string();
        assert_eq!(err, "controllers lists pd twice");
        scenario.duration = 0.00015;
        let err = SweepConfig::new(scenario, settings)
            .unwrap_err()
            .to_string();
        assert!(err.contains("duration"), "{err}");
    }

    #[test]
    fn configurations_name_their_first_difference() {
        let a = config(2, 2, 2);
        assert_eq!(a.first_difference(&a.clone()), None);
        let mut b = a.clone();
        b.settings.base_seed = 10;
        assert_eq!(a.first_difference(&b).as_deref(), Some("base_seed"));
        b.scenario.duration = 0.5;
        assert_eq!(a.first_difference(&b).as_deref(), Some("scenario.duration"));
        let mut c = a.clone();
        c.scenario.controller.fis = Some("/elsewhere/tuned.fis".into());
        assert_eq!(
            a.first_difference(&c).as_deref(),
            Some("scenario.controller.fis")
        );
    }

    proptest! {
        #[test]
        fn every_run_is_enumerated_once(levels in 1usize..4, controllers in 1usize..=4, seeds in 1usize..6) {
            let c = config(levels, controllers, seeds);
            let mut seen = std::collections::HashSet::new();
            for i in 0..c.runs().unwrap() {
                let id = c.run_at(i);
                prop_assert_eq!(id.index, i);
                prop_assert!(seen.insert((id.level_index, id.controller, id.seed_index)));
            }
        }
    }
}
