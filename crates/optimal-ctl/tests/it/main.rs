//! The integration tests of optimal-ctl, one binary: linearisation and LQR against finite
//! differences and closed forms (`optimal`); the polytope projection and the linearly
//! constrained QP against enumeration of active sets (`qp`); iLQR under linear control
//! constraints against the condensed QP of the whole horizon (`constrained_ilqr`); rollouts that
//! linearise on their way against separate linearisations (`rollouts`).

mod chain_mpc;
mod constrained_ilqr;
mod optimal;
mod qp;
mod rollouts;
