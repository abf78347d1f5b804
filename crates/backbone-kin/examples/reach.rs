//! Inverse kinematics of targets along the paper's path (eq 25), and the discrete chain's tip.
//!
//! `cargo run -p backbone-kin --example reach` walks `y = 0.4 sin(5x) + 0.2`, `0.08 <= x <= 0.4`
//! with the paper's arm (10 links of 0.1 m, `alpha0 = pi/2`); `... --example reach -- X Y [ALPHA0]`
//! solves one target instead. For each target it prints the closed-form modal coordinates
//! (eqs 5-6), the chain tip reached through the modal map (eqs 7-8) and its distance to the
//! target, which is the aliasing of the discrete chain (at most `2 l |J_10(A)|`).

use backbone_kin::{
    BackboneCurve, Branch, HarmonicIk, KinError, ModalMap, inverse_kinematics, tip_position,
};
use lane_math::Classify;
use std::f64::consts::FRAC_PI_2;

const LINKS: usize = 10;
const LINK_LENGTH: f64 = 0.1;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|arg| arg.parse::<f64>())
        .collect::<Result<_, _>>()?;
    let (targets, alpha0) = match args[..] {
        [] => (
            (0..=8)
                .map(|i| 0.08 + 0.04 * f64::from(i))
                .map(|x| [x, 0.4 * (5.0 * x).sin() + 0.2])
                .collect(),
            FRAC_PI_2,
        ),
        [x, y] => (vec![[x, y]], FRAC_PI_2),
        [x, y, alpha0] => (vec![[x, y]], alpha0),
        _ => return Err("usage: reach [X Y [ALPHA0]]".into()),
    };
    let length = LINKS as f64 * LINK_LENGTH;
    let map = ModalMap::paper_fixed_alpha0(LINKS, alpha0)?;
    let mut theta = [0.0; LINKS];
    println!("arm: {LINKS} links of {LINK_LENGTH} m, alpha0 = {alpha0:.4} rad");
    println!(
        "{:>8} {:>8} | {:>9} {:>9} | {:>9} {:>9} {:>10}",
        "x", "y", "a1", "a2", "chain x", "chain y", "chain err"
    );
    for target in targets {
        match inverse_kinematics(length, target, alpha0, Branch::Positive) {
            Ok(a) => {
                map.joint_angles(&a, &mut theta)?;
                let tip = tip_position(&[LINK_LENGTH; LINKS], &theta)?;
                let error = (tip[0] - target[0]).hypot(tip[1] - target[1]);
                println!(
                    "{:8.4} {:8.4} | {:9.5} {:9.5} | {:9.5} {:9.5} {:10.2e}",
                    target[0], target[1], a[0], a[1], tip[0], tip[1], error
                );
            }
            Err(error) if error.is_unreachable() => {
                println!(
                    "{:8.4} {:8.4} | two-mode curve: {error}",
                    target[0], target[1]
                );
                two_harmonics(length, target, alpha0)?;
            }
            Err(error) => return Err(error.into()),
        }
    }
    Ok(())
}

/// Beyond the paper: tries the numerical inverse kinematics with two harmonics.
fn two_harmonics(length: f64, target: [f64; 2], alpha0: f64) -> Result<(), KinError> {
    let mut ik = HarmonicIk::new(length, 2, alpha0)?;
    let mut a = [0.3, 0.3, 0.1, 0.1];
    match ik.solve(target, &mut a) {
        Ok(report) => {
            let tip = BackboneCurve::new(length, &a, alpha0)?.end_point();
            println!(
                "{:>17} | K = 2 reaches it: a = [{:.4}, {:.4}, {:.4}, {:.4}], end point ({:.5}, {:.5}) after {} iterations",
                "", a[0], a[1], a[2], a[3], tip[0], tip[1], report.iterations
            );
            Ok(())
        }
        Err(error) => {
            println!("{:>17} | K = 2: {error}", "");
            Ok(())
        }
    }
}
