//! After construction, the inverse-kinematics solvers and the per-step maps allocate nothing
//! (checked with the binary's counting allocator, which counts this test's thread only).

use backbone_kin::{BaseAngle, Branch, ChainIk, HarmonicIk, ModalMap, tip_position};
use test_support::alloc::{allocations_during, is_counting};
use test_support::sample::tapered_lengths;

#[test]
fn solvers_and_maps_do_not_allocate() {
    assert!(is_counting());
    let lengths = tapered_lengths();
    let alpha0 = std::f64::consts::FRAC_PI_2;
    let mut chain_ik = ChainIk::new(&lengths, 2, alpha0).unwrap();
    let mut harmonic_ik = HarmonicIk::new(1.0, 2, alpha0).unwrap();
    let map = ModalMap::new(&lengths, 2, BaseAngle::Fixed(alpha0)).unwrap();
    let (mut a, mut b, mut theta) = ([0.0; 4], [0.0; 4], vec![0.0; 20]);
    let count = allocations_during(|| {
        for target in [[0.3, 0.5], [-0.2, 0.6], [0.1, 0.9]] {
            chain_ik
                .solve_from_closed_form(target, Branch::Positive, &mut a)
                .unwrap();
            b.copy_from_slice(&a);
            harmonic_ik.solve(target, &mut b).unwrap();
            map.joint_angles(&a, &mut theta).unwrap();
            let tip = tip_position(&lengths, &theta).unwrap();
            assert!((tip[0] - target[0]).hypot(tip[1] - target[1]) < 1e-13);
        }
    });
    assert_eq!(count, 0);
}
