//! The spatial chains (`manip_dyn::spatial`): `planar` (the planar chain as a spatial one gives
//! the planar algorithms' results), `massless` (chains with massless links), `properties` (each algorithm against a second one over
//! random spatial chains), `eigen` (principal moments and the inertia check on rotated
//! inertias), and `sample` for the random chains.

mod eigen;
mod massless;
mod planar;
mod properties;
pub mod sample;
