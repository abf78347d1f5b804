//! The modal Jacobian (eqs 7-11) against the printed formula of eq 9 (with its minus sign
//! restored) and against finite differences of joint angles computed independently from the
//! curve's inclination at the link midpoints ("Jacobian consistency").

use backbone_kin::{BackboneCurve, BaseAngle, ModalMap};
use proptest::prelude::*;
use std::f64::consts::PI;

#[test]
fn eq9_corrected_entries() {
    for n in 1..=50usize {
        let map = ModalMap::paper(n).unwrap();
        assert_eq!((map.n_joints(), map.n_coords(), map.harmonics()), (n, 3, 1));
        let nf = n as f64;
        for i in 1..=n {
            let fi = i as f64;
            let expected = if i == 1 {
                [(PI / nf).sin(), 1.0 - (PI / nf).cos(), 1.0]
            } else {
                let (upper, lower) = (PI / nf * (2.0 * fi - 1.0), PI / nf * (2.0 * fi - 3.0));
                [upper.sin() - lower.sin(), -(upper.cos() - lower.cos()), 0.0]
            };
            for (j, &e) in expected.iter().enumerate() {
                assert!(
                    (map.entry(i - 1, j) - e).abs() < 1e-14,
                    "n={n} J({i},{}) = {} vs {e}",
                    j + 1,
                    map.entry(i - 1, j)
                );
            }
        }
    }
    // The printed eq 9 (without the minus) is wrong: it disagrees with the corrected entries.
    let map = ModalMap::paper(10).unwrap();
    let printed = (PI / 10.0 * 3.0).cos() - (PI / 10.0).cos();
    assert!((map.entry(1, 1) - printed).abs() > 0.1);
    assert!((map.entry(1, 1) + printed).abs() < 1e-15);
}

#[test]
fn fixed_alpha0_drops_the_third_column_into_the_offset() {
    let free = ModalMap::paper(8).unwrap();
    let fixed = ModalMap::paper_fixed_alpha0(8, 0.7).unwrap();
    assert_eq!(
        (fixed.n_coords(), fixed.base_angle()),
        (2, BaseAngle::Fixed(0.7))
    );
    let (mut theta_free, mut theta_fixed) = ([0.0; 8], [0.0; 8]);
    free.joint_angles(&[0.4, -0.2, 0.7], &mut theta_free)
        .unwrap();
    fixed.joint_angles(&[0.4, -0.2], &mut theta_fixed).unwrap();
    assert_eq!(theta_free, theta_fixed);
    let mut rates = [0.0; 8];
    fixed.joint_rates(&[0.4, -0.2], &mut rates).unwrap();
    assert!((theta_fixed[0] - rates[0] - 0.7).abs() < 1e-15);
    assert_eq!(&theta_fixed[1..], &rates[1..]);
}

/// Joint angles from the curve directly (eq 7): link `i` takes `alpha` at its midpoint, and
/// `theta_i = phi_i - phi_{i-1}`. `coords` are `(a_1..a_2K[, alpha0])`.
fn joint_angles_from_curve(
    lengths: &[f64],
    harmonics: usize,
    base: BaseAngle,
    coords: &[f64],
) -> Vec<f64> {
    let alpha0 = match base {
        BaseAngle::Free => coords[2 * harmonics],
        BaseAngle::Fixed(alpha0) => alpha0,
    };
    let total: f64 = lengths.iter().sum();
    let curve = BackboneCurve::new(total, &coords[..2 * harmonics], alpha0).unwrap();
    let mut start = 0.0;
    let mut previous = 0.0;
    lengths
        .iter()
        .map(|&length| {
            let phi = curve.inclination(start + length / 2.0).unwrap();
            start += length;
            let theta = phi - previous;
            previous = phi;
            theta
        })
        .collect()
}

proptest! {
    /// Jacobian consistency: `J` equals central differences of the curve-derived joint angles,
    /// and `J a + theta_0` equals them, for random `K`, link lengths and base handling.
    #[test]
    fn jacobian_consistency(
        lengths in prop::collection::vec(0.05f64..2.0, 1..20),
        harmonics in 1usize..=4,
        fixed in prop::option::of(-PI..PI),
        seed in prop::collection::vec(-1.5f64..1.5, 9),
    ) {
        let base = fixed.map_or(BaseAngle::Free, BaseAngle::Fixed);
        let map = ModalMap::new(&lengths, harmonics, base).unwrap();
        let m = 2 * harmonics + usize::from(base == BaseAngle::Free);
        prop_assert_eq!((map.n_joints(), map.n_coords()), (lengths.len(), m));
        let coords = &seed[..m];
        let mut theta = vec![0.0; lengths.len()];
        map.joint_angles(coords, &mut theta).unwrap();
        let direct = joint_angles_from_curve(&lengths, harmonics, base, coords);
        for (t, d) in theta.iter().zip(&direct) {
            prop_assert!((t - d).abs() <= 1e-12, "{t} vs {d}");
        }
        let h = 1e-3;
        for j in 0..m {
            let shifted = |delta: f64| {
                let mut c = coords.to_vec();
                c[j] += delta;
                joint_angles_from_curve(&lengths, harmonics, base, &c)
            };
            let (plus, minus) = (shifted(h), shifted(-h));
            for i in 0..lengths.len() {
                let fd = (plus[i] - minus[i]) / (2.0 * h);
                prop_assert!((fd - map.entry(i, j)).abs() <= 1e-9, "J({i},{j}) = {} vs {fd}", map.entry(i, j));
            }
        }
    }
}
