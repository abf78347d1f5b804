//! The integration tests of sim-core, one binary: a module per `src` module it tests (`ode`,
//! `reference`, `controller`) and `energy` for the closed loop's conservation of energy. The
//! closed loop built from scenarios is tested in `sim-study`.

mod controller;
mod energy;
mod ode;
mod reference;
