//! The spatial chains (`manip_dyn::spatial`): `planar` (the planar chain as a spatial one gives
//! the planar algorithms' results), `properties` (each algorithm against a second one over
//! random spatial chains), and `sample` for the random chains.

mod planar;
mod properties;
pub mod sample;
