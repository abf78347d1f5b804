//! The reduced terms of a two-link arm against the textbook closed form of the double pendulum,
//! projected by hand: an answer that shares nothing with either implementation.

use backbone_kin::{BaseAngle, ModalMap};
use manip_dyn::{ChainModel, Link};
use modal_reduce::{ReducedData, ReducedModel, reduced_terms, reduced_terms_faer};

struct Pendulum {
    m: [f64; 2],
    l1: f64,
    r: [f64; 2],
    inertia: [f64; 2],
    g: f64,
}

impl Pendulum {
    /// `(M, C, G)` of the double pendulum in relative joint angles.
    fn terms(&self, q: [f64; 2], v: [f64; 2]) -> ([[f64; 2]; 2], [f64; 2], [f64; 2]) {
        let Pendulum {
            m,
            l1,
            r,
            inertia,
            g,
        } = *self;
        let c2 = q[1].cos();
        let m22 = inertia[1] + m[1] * r[1] * r[1];
        let m12 = m22 + m[1] * l1 * r[1] * c2;
        let m11 = inertia[0] + m[0] * r[0] * r[0] + m22 + m[1] * (l1 * l1 + 2.0 * l1 * r[1] * c2);
        let h = m[1] * l1 * r[1] * q[1].sin();
        let coriolis = [-h * (2.0 * v[0] * v[1] + v[1] * v[1]), h * v[0] * v[0]];
        let tip = m[1] * r[1] * g * (q[0] + q[1]).cos();
        let gravity = [(m[0] * r[0] + m[1] * l1) * g * q[0].cos() + tip, tip];
        ([[m11, m12], [m12, m22]], coriolis, gravity)
    }
}

#[test]
fn two_link_arm_matches_the_double_pendulum() {
    let p = Pendulum {
        m: [0.7, 0.3],
        l1: 0.4,
        r: [0.15, 0.2],
        inertia: [0.01, 0.004],
        g: 9.81,
    };
    let links = vec![
        Link::new(p.l1, p.m[0], p.r[0], p.inertia[0]).unwrap(),
        Link::new(0.3, p.m[1], p.r[1], p.inertia[1]).unwrap(),
    ];
    for base in [BaseAngle::Fixed(0.7), BaseAngle::Fixed(-2.0)] {
        let map = ModalMap::new(&[p.l1, 0.3], 1, base).unwrap();
        let model = ReducedModel::new(ChainModel::new(links.clone(), p.g).unwrap(), map).unwrap();
        let mut data = ReducedData::new(&model);
        for (a, a_dot) in [([0.3, -0.4], [1.0, 0.5]), ([-1.2, 0.9], [-0.3, 2.0])] {
            let map = model.map();
            let theta =
                [0, 1].map(|i| map.offset()[i] + map.entry(i, 0) * a[0] + map.entry(i, 1) * a[1]);
            let theta_dot = [0, 1].map(|i| map.entry(i, 0) * a_dot[0] + map.entry(i, 1) * a_dot[1]);
            let (mass, coriolis, gravity) = p.terms(theta, theta_dot);
            let j = |i: usize, k: usize| map.entry(i, k);
            for compute in [reduced_terms, reduced_terms_faer] {
                compute(&model, &mut data, &a, &a_dot).unwrap();
                for r in 0..2 {
                    for c in 0..2 {
                        let expected: f64 = (0..2)
                            .map(|i| (0..2).map(|k| j(i, r) * mass[i][k] * j(k, c)).sum::<f64>())
                            .sum();
                        assert!(
                            (data.mass_matrix()[(r, c)] - expected).abs() < 1e-15,
                            "M*[{r}][{c}]"
                        );
                    }
                    let c_star: f64 = (0..2).map(|i| j(i, r) * coriolis[i]).sum();
                    let g_star: f64 = (0..2).map(|i| j(i, r) * gravity[i]).sum();
                    assert!((data.coriolis()[r] - c_star).abs() < 1e-14, "C*[{r}]");
                    assert!((data.gravity()[r] - g_star).abs() < 1e-14, "G*[{r}]");
                }
            }
        }
    }
}
