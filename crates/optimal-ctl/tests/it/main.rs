//! The integration tests of optimal-ctl, one binary: linearisation and LQR against finite
//! differences and closed forms (`optimal`); the polytope projection and the linearly
//! constrained QP against enumeration of active sets (`qp`).

mod optimal;
mod qp;
