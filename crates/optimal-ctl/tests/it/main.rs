//! The integration tests of optimal-ctl, one binary: linearisation and LQR against finite
//! differences and closed forms (`optimal`).

mod optimal;
