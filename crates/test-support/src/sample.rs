//! Sample arms (as Pinocchio's `buildSampleModel*`) and random-arm strategies. Everything that
//! builds a `ChainModel` needs the feature `arms`; the reduced models need `reduced`.

#[cfg(feature = "arms")]
use manip_dyn::{ChainModel, Link};
#[cfg(feature = "arms")]
use proptest::collection::vec;
#[cfg(feature = "arms")]
use proptest::prelude::*;

/// Gravity of the sample arms, m/s^2.
pub const GRAVITY: f64 = 9.81;

#[cfg(feature = "arms")]
/// The paper's arm with `n` links: each 0.1 m long and 0.1 kg (uniform beams), gravity 9.81.
/// `n = 10` is the paper's 1 m arm.
pub fn uniform_chain(n: usize) -> ChainModel {
    ChainModel::uniform(n, 0.1, 0.1, GRAVITY).expect("the sample arm is valid")
}

/// Twenty tapered links, from 7.5 cm at the base down to 2.5 cm at the tip (1 m in all): a chain
/// whose links the equal-link formulas do not describe.
pub fn tapered_lengths() -> Vec<f64> {
    (0..20)
        .map(|i| 0.075 - 0.05 * f64::from(i) / 19.0)
        .collect()
}

/// The paper's reduced model on [`uniform_chain`]`(n)`: coordinates `(a1, a2, alpha0)`, the base
/// angle free ([`backbone_kin::ModalMap::paper`]).
#[cfg(feature = "reduced")]
pub fn paper_reduced(n: usize) -> modal_reduce::ReducedModel {
    let map = backbone_kin::ModalMap::paper(n).expect("the paper's map is valid");
    modal_reduce::ReducedModel::new(uniform_chain(n), map).expect("the paper's model is valid")
}

#[cfg(feature = "arms")]
/// A random link: length 0.05-1 m, mass 0.05-2 kg, centre of mass anywhere from behind the joint
/// to beyond the far end, inertia 1-30 % of `m L^2`.
pub fn link() -> impl Strategy<Value = Link> {
    (0.05..1.0f64, 0.05..2.0f64, -0.2..1.2f64, 0.01..0.3f64).prop_map(|(length, mass, c, k)| {
        Link::new(length, mass, c * length, k * mass * length * length).unwrap()
    })
}

#[cfg(feature = "arms")]
/// Number of links: small chains often, up to `max`.
pub fn links(max: usize) -> impl Strategy<Value = usize> {
    prop_oneof![1..=max.min(6), 1..=max]
}

#[cfg(feature = "arms")]
/// A random chain of `n` links ([`link`]) with gravity 0-20 m/s^2.
pub fn chain(n: usize) -> impl Strategy<Value = ChainModel> {
    (vec(link(), n), 0.0..20.0f64).prop_map(|(links, g)| ChainModel::new(links, g).unwrap())
}

#[cfg(feature = "arms")]
/// A random vector of `n` entries in `[-r, r]`.
pub fn values(n: usize, r: f64) -> impl Strategy<Value = Vec<f64>> {
    vec(-r..=r, n)
}

#[cfg(feature = "arms")]
/// A chain of at most `max` links and a state: angles, rates, accelerations (or torques).
pub fn arm_and_state(
    max: usize,
) -> impl Strategy<Value = (ChainModel, Vec<f64>, Vec<f64>, Vec<f64>)> {
    links(max).prop_flat_map(|n| {
        (
            chain(n),
            values(n, std::f64::consts::PI),
            values(n, 2.0),
            values(n, 5.0),
        )
    })
}
