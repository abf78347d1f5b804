//! Host package for the workspace's Criterion benchmarks (`benches/benches/*.rs`).
//!
//! A virtual workspace root cannot own benches, so they live in this unpublished package.
//! Run them with `cargo xtask bench`, which also writes `target/bench-summary.json`.
//!
//! It also holds the arms several benches, examples and harnesses share.

use modal_reduce::spatial::SpatialReducedModel;

/// The spatial modal arm of the speed comparison with Pinocchio (`reduced_fd_spatial/<n>`):
/// `n` universal-joint links of 0.1 m and 0.1 kg as slender rods, `K = 1` harmonic per plane
/// (`m = 4`), the identity base pose, gravity 9.81 m/s^2 along `-z`. `examples/spatial_urdf.rs`
/// writes its URDF export for `benches/pinocchio/spatial.cpp`.
///
/// # Panics
/// If `n` is below 2 (the map of one harmonic per plane needs two links) or above
/// `backbone_kin::MAX_LINKS`.
pub fn spatial_arm(n: usize) -> SpatialReducedModel {
    SpatialReducedModel::uniform_rods(n, 1, 0.1, 0.1, [0.0, 0.0, -9.81])
        .expect("a uniform arm of 2 to MAX_LINKS links")
}

/// The moving state of the comparison, `[a, a_dot, tau*]` (`m = 4` values each).
pub fn spatial_state() -> [Vec<f64>; 3] {
    [
        vec![0.4, -0.2, 0.3, 0.1],
        vec![0.5, 0.3, -0.2, 0.4],
        vec![0.01, -0.02, 0.015, 0.005],
    ]
}
