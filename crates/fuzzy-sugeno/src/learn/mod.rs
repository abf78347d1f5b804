//! Fuzzy systems learned from data: `genfis` (grid partition or subtractive clustering) builds a
//! first- or zero-order Sugeno system from samples, and ANFIS (Jang 1993) tunes it with the
//! hybrid rule, least squares for the consequents and gradient descent for the premises.
//!
//! Data are [`TrainingData`]: rows of inputs followed by one or more outputs. Each learned
//! system has a single output, picked by index, so a several-output data set (for example
//! recorded controller inputs and torques) is learned as one system per output, and
//! [`merge_outputs`] joins those into one multi-output system that evaluates each output exactly
//! as its own system does.
//!
//! ```
//! use fuzzy_sugeno::learn::{anfis, genfis_grid, AnfisOptions, GridPartition, TrainingData};
//! use fuzzy_sugeno::Evaluator;
//!
//! // y = x1 * x2 on a 9 x 9 grid of [-1, 1]^2.
//! let mut values = Vec::new();
//! for i in 0..9 {
//!     for j in 0..9 {
//!         let (x1, x2) = (-1.0 + 0.25 * i as f64, -1.0 + 0.25 * j as f64);
//!         values.extend([x1, x2, x1 * x2]);
//!     }
//! }
//! let data = TrainingData::new(2, 1, values)?;
//! let initial = genfis_grid(&data, 0, &GridPartition::default())?;
//! let trained = anfis(initial, &data, None, 0, &AnfisOptions { epochs: 20, ..Default::default() })?;
//! let mut evaluator = Evaluator::new(trained.system.clone());
//! let mut y = [0.0];
//! evaluator.eval(&[0.5, -0.5], &mut y)?;
//! assert!((y[0] + 0.25).abs() < 1e-2, "{}", y[0]);
//! assert!(trained.history.last().unwrap().training_rmse < trained.history[0].training_rmse);
//! # Ok::<(), fuzzy_sugeno::FuzzyError>(())
//! ```

mod anfis;
mod data;
mod genfis;
mod merge;
mod premise;

pub use anfis::{Anfis, AnfisOptions, EpochReport, Trained, anfis};
pub use data::{MAX_INPUTS, MAX_MAGNITUDE, MAX_ROWS, TrainingData};
pub use genfis::{
    ConsequentOrder, GridPartition, MAX_CLUSTER_ROWS, MAX_RULES, MAX_SETS_PER_INPUT,
    MIN_INPUT_RANGE, SetShape, SubtractiveClustering, genfis_cluster, genfis_grid,
    genfis_grid_over,
};
pub use merge::merge_outputs;
