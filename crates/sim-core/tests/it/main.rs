//! The integration tests of sim-core, one binary: a module per `src` module it tests (`ode`,
//! `reference`, `controller`, `mpc_limits` for the rows MPC plans within), `energy` for the
//! closed loop's conservation of energy and `hooks` for the loop's hooks. The closed loop built
//! from scenarios is tested in `sim-study`.

mod controller;
mod energy;
mod hooks;
mod limits;
mod mpc_limits;
mod ode;
mod reference;
