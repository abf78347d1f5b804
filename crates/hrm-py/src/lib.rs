//! `import hrm`: Python bindings of the hrm crates (PyO3, numpy).
//!
//! The extension module `hrm._hrm`; the Python package `hrm` (in `python/hrm/`) re-exports it,
//! with `hrm.fuzzy` as a submodule, type stubs and `py.typed`. One module per concept:
//!
//! - [`errors`]: the exceptions `InvalidInput`, `Unreachable`, `NumericalError` and the mapping
//!   of every library error onto them;
//! - [`array`]: numpy inputs (one state or a batch, any real dtype, any layout) and the batch
//!   driver (GIL released, rayon);
//! - [`arm`]: `hrm.Arm` (`manip-dyn`);
//! - [`reduced`]: `hrm.ReducedModel` (`backbone-kin`, `modal-reduce`);
//! - [`fuzzy`]: `hrm.fuzzy.System`, `hrm.fuzzy.paper_controller` (`fuzzy-sugeno`);
//! - [`scenario`]: `hrm.Scenario`, `hrm.Settings`, `hrm.ReferenceSample`, `hrm.Run`: closed-loop
//!   runs with built-in or Python controllers (`sim-core`);
//! - [`sweep`]: `hrm.Sweep`: Monte Carlo sweeps, whole or shard by shard (`sim_core::study`).
//!
//! The tests are Python (`tests/`, run by `cargo xtask test`); `docs/python.md` is the guide.
#![deny(missing_docs)]

mod arm;
mod array;
mod errors;
mod fuzzy;
mod reduced;
mod scenario;
mod sweep;

use pyo3::prelude::*;

/// The extension module: classes, functions and exceptions of `hrm` and `hrm.fuzzy`.
#[pymodule]
fn _hrm(module: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = module.py();
    module.add_class::<arm::Arm>()?;
    module.add_class::<reduced::ReducedModel>()?;
    module.add_class::<scenario::Scenario>()?;
    module.add_class::<scenario::Settings>()?;
    module.add_class::<scenario::ReferenceSample>()?;
    module.add_class::<scenario::Run>()?;
    module.add_class::<sweep::Sweep>()?;
    module.add("InvalidInput", py.get_type::<errors::InvalidInput>())?;
    module.add("Unreachable", py.get_type::<errors::Unreachable>())?;
    module.add("NumericalError", py.get_type::<errors::NumericalError>())?;
    module.add("__version__", env!("CARGO_PKG_VERSION"))?;
    let fuzzy = PyModule::new(py, "fuzzy")?;
    fuzzy.add_class::<fuzzy::System>()?;
    fuzzy.add_function(wrap_pyfunction!(fuzzy::paper_controller, &fuzzy)?)?;
    module.add_submodule(&fuzzy)?;
    Ok(())
}
