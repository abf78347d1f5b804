//! ABA's pivot test is relative to the rounding of the articulated inertia itself, so a long,
//! well-conditioned chain is accepted at any length up to `MAX_LINKS`; a chain whose pivot is
//! lost to rounding is still refused (`bad_input.rs`).

use manip_dyn::{ChainData, ChainModel, aba, gravity, rnea};

/// Straight chains of equal links, held out horizontally and released from rest, with and
/// without joint torques: the accelerations ABA finds give back the torques through RNEA (an
/// independent algorithm), to a tolerance relative to the torques involved.
#[test]
fn a_straight_chain_of_many_equal_links_is_accepted() {
    for (n, bent) in [(100_000, 0.0), (100_000, 1e-3), (4097, 0.0)] {
        let link = 1.0 / n as f64;
        let arm = ChainModel::uniform(n, link, link, 9.81).unwrap();
        let mut data = ChainData::recursive(&arm);
        let mut q = vec![bent; n];
        q[0] = 0.3;
        let v = vec![0.0; n];
        let mut tau = vec![0.0; n];
        gravity(&arm, &mut data, &q, &mut tau).unwrap();
        // Half the static torque: the chain falls, but not freely.
        tau.iter_mut().for_each(|t| *t *= 0.5);
        let mut qdd = vec![0.0; n];
        aba(&arm, &mut data, &q, &v, &tau, &mut qdd).unwrap();
        let mut back = vec![0.0; n];
        rnea(&arm, &mut data, &q, &v, &qdd, &mut back).unwrap();
        let scale = 2.0 * tau.iter().fold(0.0f64, |m, t| m.max(t.abs()));
        let worst = back
            .iter()
            .zip(&tau)
            .fold(0.0f64, |m, (b, t)| m.max((b - t).abs()));
        assert!(
            worst <= 1e-9 * scale,
            "n = {n}, bent {bent}: residual {worst:e} of {scale:e}"
        );
    }
}
