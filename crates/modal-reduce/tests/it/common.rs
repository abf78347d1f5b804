//! Random arms, maps and states for the property tests, and brute-force reference formulas that
//! share no code with the crate.

use backbone_kin::{BaseAngle, ModalMap};
use manip_dyn::{ChainModel, Link};
use modal_reduce::{ReduceError, ReducedModel};
use proptest::prelude::*;

pub use test_support::config::expensive;
pub use test_support::numeric::{max_abs, relative_difference, ridders};

/// A random link: length 0.02-0.5 m, mass 0.01-2 kg, centre of mass anywhere along the link,
/// inertia from 0.2 to 2 times the uniform-beam value.
fn link() -> impl Strategy<Value = Link> {
    (0.02..0.5f64, 0.01..2.0f64, 0.0..1.0f64, 0.2..2.0f64)
        .prop_map(|(l, m, c, k)| Link::new(l, m, c * l, k * m * l * l / 12.0).expect("valid link"))
}

/// A random reduced model with `links` links: 1-2 harmonics, `alpha0` free or fixed, the map built
/// for the actual link lengths, gravity 0-20 m/s^2.
pub fn model(links: std::ops::RangeInclusive<usize>) -> impl Strategy<Value = ReducedModel> {
    model_with_harmonics(links, 2)
}

/// [`model`] with 1 to `max_harmonics` harmonics.
pub fn model_with_harmonics(
    links: std::ops::RangeInclusive<usize>,
    max_harmonics: usize,
) -> impl Strategy<Value = ReducedModel> {
    (
        prop::collection::vec(link(), links),
        1usize..=max_harmonics,
        prop::option::of(-3.0..3.0f64),
        0.0..20.0f64,
    )
        .prop_filter_map("rank-deficient map", |(links, harmonics, fixed, g)| {
            let lengths: Vec<f64> = links.iter().map(|l| l.length).collect();
            let base = fixed.map_or(BaseAngle::Free, BaseAngle::Fixed);
            let map = ModalMap::new(&lengths, harmonics, base).ok()?;
            let chain = ChainModel::new(links, g).ok()?;
            match ReducedModel::new(chain, map) {
                Ok(model) => Some(model),
                Err(ReduceError::RankDeficient { .. }) => None,
                Err(e) => panic!("unexpected error {e}"),
            }
        })
}

/// A random model (`links` links) with a random state `(a, a_dot)` of matching size.
pub fn model_and_state(
    links: std::ops::RangeInclusive<usize>,
) -> impl Strategy<Value = (ReducedModel, Vec<f64>, Vec<f64>)> {
    model(links).prop_flat_map(|model| {
        let m = model.n_coords();
        (
            Just(model),
            prop::collection::vec(-1.5..1.5f64, m),
            prop::collection::vec(-2.0..2.0f64, m),
        )
    })
}

/// `theta = J a + theta_0`, by the entries of the map.
pub fn joint_angles(map: &ModalMap, a: &[f64]) -> Vec<f64> {
    (0..map.n_joints())
        .map(|i| {
            map.offset()[i]
                + (0..map.n_coords())
                    .map(|j| map.entry(i, j) * a[j])
                    .sum::<f64>()
        })
        .collect()
}

/// `J v` without the offset.
pub fn joint_rates(map: &ModalMap, v: &[f64]) -> Vec<f64> {
    (0..map.n_joints())
        .map(|i| {
            (0..map.n_coords())
                .map(|j| map.entry(i, j) * v[j])
                .sum::<f64>()
        })
        .collect()
}

/// Kinetic and potential energy of the chain, straight from the definitions: absolute angles as
/// running sums, centre-of-mass velocities as sums over the links below.
pub fn brute_energy(chain: &ChainModel, theta: &[f64], theta_dot: &[f64]) -> (f64, f64) {
    let mut angle = 0.0;
    let mut rate = 0.0;
    let mut joint = [0.0f64; 2];
    let mut joint_velocity = [0.0f64; 2];
    let (mut kinetic, mut potential) = (0.0, 0.0);
    for (link, (&q, &v)) in chain.links().iter().zip(theta.iter().zip(theta_dot)) {
        angle += q;
        rate += v;
        let (s, c) = angle.sin_cos();
        let com_y = joint[1] + link.com * s;
        let com_velocity = [
            joint_velocity[0] - link.com * s * rate,
            joint_velocity[1] + link.com * c * rate,
        ];
        kinetic += 0.5 * link.mass * (com_velocity[0].powi(2) + com_velocity[1].powi(2))
            + 0.5 * link.inertia * rate * rate;
        potential += link.mass * chain.gravity() * com_y;
        joint = [joint[0] + link.length * c, joint[1] + link.length * s];
        joint_velocity = [
            joint_velocity[0] - link.length * s * rate,
            joint_velocity[1] + link.length * c * rate,
        ];
    }
    (kinetic, potential)
}

/// The `m x m` matrix of a `MatRef` as a row-major vector.
pub fn to_vec(mat: faer::MatRef<'_, f64>) -> Vec<f64> {
    let mut out = Vec::with_capacity(mat.nrows() * mat.ncols());
    for i in 0..mat.nrows() {
        for j in 0..mat.ncols() {
            out.push(mat[(i, j)]);
        }
    }
    out
}

/// The paper's arm: 10 equal links of 0.1 m and 0.1 kg, `g = 9.81`, the paper's map
/// `(a1, a2, alpha0)`.
pub fn paper_arm() -> ReducedModel {
    ReducedModel::new(
        ChainModel::uniform(10, 0.1, 0.1, 9.81).unwrap(),
        ModalMap::paper(10).unwrap(),
    )
    .unwrap()
}
