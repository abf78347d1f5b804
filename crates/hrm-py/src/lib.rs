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
//! - [`fuzzy`]: `hrm.fuzzy.System`, `hrm.fuzzy.paper_controller` (`fuzzy-sugeno`).
//!
//! The tests are Python (`tests/`, run by `cargo xtask test`); `docs/python.md` is the guide.
#![deny(missing_docs)]

mod arm;
mod array;
mod errors;
mod fuzzy;
mod reduced;

use pyo3::prelude::*;

/// The extension module: classes, functions and exceptions of `hrm` and `hrm.fuzzy`.
#[pymodule]
fn _hrm(module: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = module.py();
    module.add_class::<arm::Arm>()?;
    module.add_class::<reduced::ReducedModel>()?;
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
