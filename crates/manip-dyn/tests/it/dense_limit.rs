//! Chains of up to `MAX_LINKS` links run the `O(n)` algorithms in `O(n)` memory; the `n x n`
//! algorithms refuse chains beyond `MAX_DENSE_LINKS` with a message naming themselves, and no
//! workspace allocates `n x n` memory for such a chain.

use faer::Mat;
use manip_dyn::{
    ChainData, ChainModel, DerivativeData, DynError, MAX_DENSE_LINKS, aba, aba_derivatives,
    coriolis_matrix, forward_dynamics, mass_matrix, rnea, rnea_derivatives,
};

use test_support::alloc::bytes_allocated_during as bytes_of;

#[test]
fn dense_algorithms_refuse_chains_beyond_their_limit() {
    let n = MAX_DENSE_LINKS + 1;
    let arm = ChainModel::uniform(n, 1e-3, 1e-3, 9.81).unwrap();
    // Neither workspace holds n x n memory (8 n^2 bytes would be 134 MB).
    let (mut data, bytes) = bytes_of(|| ChainData::new(&arm));
    assert!(bytes < 1024 * n, "ChainData: {bytes} bytes");
    let (mut derivatives, bytes) = bytes_of(|| DerivativeData::new(&arm));
    assert!(bytes < 1024, "DerivativeData: {bytes} bytes");
    assert_eq!(derivatives.d_q().nrows(), 0);

    let (q, v, tau) = (vec![0.1; n], vec![0.2; n], vec![0.0; n]);
    let mut out = vec![0.0; n];
    let mut matrix = Mat::<f64>::zeros(2, 2);
    let refused = |what| DynError::TooManyLinks {
        what,
        got: n,
        max: MAX_DENSE_LINKS,
    };
    assert_eq!(
        forward_dynamics(&arm, &mut data, &q, &v, &tau, &mut out),
        Err(refused("Cholesky forward dynamics"))
    );
    assert_eq!(
        mass_matrix(&arm, &mut data, &q, matrix.as_mut()),
        Err(refused("the mass matrix"))
    );
    assert_eq!(
        coriolis_matrix(&arm, &mut data, &q, &v, matrix.as_mut()),
        Err(refused("the Coriolis matrix"))
    );
    assert_eq!(
        rnea_derivatives(&arm, &mut data, &mut derivatives, &q, &v, &tau),
        Err(refused("the RNEA derivatives"))
    );
    let err = aba_derivatives(&arm, &mut data, &mut derivatives, &q, &v, &tau).unwrap_err();
    assert_eq!(err, refused("the ABA derivatives"));
    assert_eq!(
        err.to_string(),
        format!("the ABA derivatives may have at most 4096 links, got {n}")
    );
    // The recursive algorithms run, and agree with each other: RNEA undoes ABA.
    aba(&arm, &mut data, &q, &v, &tau, &mut out).unwrap();
    let mut torque = vec![0.0; n];
    rnea(&arm, &mut data, &q, &v, &out, &mut torque).unwrap();
    assert!(torque.iter().all(|t| t.abs() < 1e-6), "{:e}", torque[0]);
}

#[test]
fn a_recursive_workspace_allocates_the_cholesky_factor_on_first_use() {
    let n = 12;
    let arm = ChainModel::uniform(n, 0.1, 0.1, 9.81).unwrap();
    let (mut data, bytes) = bytes_of(|| ChainData::recursive(&arm));
    assert!(bytes < 8 * n * n + 1024 * n, "{bytes} bytes");
    let q: Vec<f64> = (0..n).map(|i| 0.3 * (i as f64).sin()).collect();
    let v: Vec<f64> = (0..n).map(|i| 0.5 * (i as f64).cos()).collect();
    let tau = vec![0.05; n];
    let (mut by_cholesky, mut by_aba) = (vec![0.0; n], vec![0.0; n]);
    let (result, bytes) =
        bytes_of(|| forward_dynamics(&arm, &mut data, &q, &v, &tau, &mut by_cholesky));
    result.unwrap();
    assert!(
        bytes >= 8 * n * n,
        "the first call allocates the factor: {bytes} bytes"
    );
    aba(&arm, &mut data, &q, &v, &tau, &mut by_aba).unwrap();
    for (x, y) in by_cholesky.iter().zip(&by_aba) {
        assert!((x - y).abs() < 1e-9 * y.abs().max(1.0), "{x} vs {y}");
    }
    // Later calls reuse it.
    let (result, bytes) =
        bytes_of(|| forward_dynamics(&arm, &mut data, &q, &v, &tau, &mut by_cholesky));
    result.unwrap();
    assert_eq!(bytes, 0);
}
