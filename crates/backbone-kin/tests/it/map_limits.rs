//! A modal map of up to `MAX_LINKS` links is built, and its `J` (links x coordinates entries) is
//! bounded by `MAX_MAP_ENTRIES` before anything is allocated.

use backbone_kin::{BaseAngle, KinError, MAX_HARMONICS, MAX_LINKS, MAX_MAP_ENTRIES, ModalMap};

#[test]
fn a_map_of_max_links_is_built() {
    let map = ModalMap::uniform(MAX_LINKS, 1, BaseAngle::Free).unwrap();
    assert_eq!((map.n_joints(), map.n_coords()), (MAX_LINKS, 3));
    // theta_1 + ... + theta_n is the tip's inclination alpha(l - L_n / 2).
    let mut theta = vec![0.0; MAX_LINKS];
    map.joint_angles(&[0.4, -0.2, 1.0], &mut theta).unwrap();
    let tip: f64 = theta.iter().sum();
    let s = 1.0 - 0.5 / MAX_LINKS as f64;
    let (sin, one_minus_cos) = backbone_kin::harmonic_basis(1, s, 1.0);
    assert!((tip - (1.0 + 0.4 * sin - 0.2 * one_minus_cos)).abs() < 1e-9);
}

#[test]
fn the_jacobian_is_bounded_before_it_is_allocated() {
    // 17 harmonics and alpha0 on 10^6 links: 35 million entries.
    let err = ModalMap::uniform(MAX_LINKS, 17, BaseAngle::Free).unwrap_err();
    assert_eq!(
        err,
        KinError::TooMany {
            what: "modal Jacobian entries (links x coordinates)",
            got: 35 * MAX_LINKS,
            max: MAX_MAP_ENTRIES,
        }
    );
    assert_eq!(
        err.to_string(),
        "at most 33554432 modal Jacobian entries (links x coordinates) are supported, got 35000000"
    );
    // Every harmonic up to MAX_HARMONICS fits on 4096 links.
    const { assert!(4096 * (2 * MAX_HARMONICS + 1) <= MAX_MAP_ENTRIES) };
}
