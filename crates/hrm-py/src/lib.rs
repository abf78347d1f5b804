#![doc = include_str!("../README.md")]

mod args;
mod arm;
mod array;
mod chain;
mod errors;
mod fuzzy;
mod pool;
mod reduced;
mod scenario;
mod spatial;
mod sweep;
mod value;

use pyo3::prelude::*;

/// The extension module: classes, functions and exceptions of `hrm` and `hrm.fuzzy`.
#[pymodule]
fn _hrm(module: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = module.py();
    module.add_class::<arm::Arm>()?;
    module.add_class::<chain::Chain>()?;
    module.add_class::<reduced::ReducedModel>()?;
    module.add_class::<spatial::SpatialArm>()?;
    module.add_class::<scenario::Scenario>()?;
    module.add_class::<scenario::Settings>()?;
    module.add_class::<scenario::ReferenceSample>()?;
    module.add_class::<scenario::Run>()?;
    module.add_class::<sweep::Sweep>()?;
    module.add_function(wrap_pyfunction!(scenario::view_html, module)?)?;
    module.add("InvalidInput", py.get_type::<errors::InvalidInput>())?;
    module.add("Unreachable", py.get_type::<errors::Unreachable>())?;
    module.add("NumericalError", py.get_type::<errors::NumericalError>())?;
    module.add("__version__", env!("CARGO_PKG_VERSION"))?;
    let fuzzy = PyModule::new(py, "fuzzy")?;
    fuzzy.add_class::<fuzzy::System>()?;
    let paper_controller = wrap_pyfunction!(fuzzy::paper_controller, &fuzzy)?;
    // Pickled by reference where users import it (`hrm.fuzzy`), not as the extension's
    // submodule `fuzzy`, which no import finds, so that a Dask worker can unpickle it.
    paper_controller.setattr("__module__", "hrm.fuzzy")?;
    fuzzy.add_function(paper_controller)?;
    module.add_submodule(&fuzzy)?;
    Ok(())
}
