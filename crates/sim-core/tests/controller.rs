//! Controllers against independent facts: the hand-computed slope of the paper's fuzzy system,
//! and the reduced forward dynamics for computed torque and gravity compensation.

use backbone_kin::ModalMap;
use fuzzy_sugeno::{Evaluator, paper_controller};
use manip_dyn::ChainModel;
use modal_reduce::{ReducedData, ReducedModel, forward_dynamics};
use proptest::prelude::*;
use sim_core::SimError;
use sim_core::controller::{ComputedTorque, Controller, FuzzyController, ModalState, PdController};
use sim_core::reference::ReferenceSample;

fn paper_model() -> ReducedModel {
    ReducedModel::new(
        ChainModel::uniform(10, 0.1, 0.1, 9.81).unwrap(),
        ModalMap::paper_fixed_alpha0(10, std::f64::consts::FRAC_PI_2).unwrap(),
    )
    .unwrap()
}

fn accelerations(model: &ReducedModel, state: &ModalState, tau: [f64; 2]) -> [f64; 2] {
    let mut data = ReducedData::new(model);
    let mut a_ddot = [0.0; 2];
    forward_dynamics(model, &mut data, &state.a, &state.a_dot, &tau, &mut a_ddot).unwrap();
    a_ddot
}

#[test]
fn pd_gains_are_the_paper_fuzzy_slope() {
    // By hand: at the origin each bell is 1/2 with slope -+1/r, so d tau1/d da1 =
    // (1/2r)(-(VP + P) + (N + VN)) = -180/0.3 and d tau1/d a1_dot = (1/2)(-(VP + N) + (P + VN)).
    let pd = PdController::from_fuzzy_slope(&paper_controller()).unwrap();
    let expected = [[-600.0, 0.0, -20.0, 0.0], [0.0, -300.0, 0.0, -10.0]];
    for (row, expected_row) in pd.gains().iter().zip(expected) {
        for (gain, value) in row.iter().zip(expected_row) {
            assert!((gain - value).abs() < 1e-6, "K = {:?}", pd.gains());
        }
    }
    assert_eq!(pd.offset(), [0.0, 0.0]);
}

proptest! {
    #[test]
    fn pd_agrees_with_fuzzy_to_second_order_near_the_origin(
        direction in prop::array::uniform4(-1.0f64..1.0),
        scale in 1e-4f64..1e-2,
    ) {
        let mut fuzzy = FuzzyController::new(paper_controller()).unwrap();
        let mut pd = PdController::from_fuzzy_slope(&paper_controller()).unwrap();
        let x = direction.map(|d| d * scale);
        let measured = ModalState { a: [x[0] + 0.3, x[1] - 0.2], a_dot: [x[2], x[3]] };
        let reference = ReferenceSample { a: [0.3, -0.2], ..ReferenceSample::default() };
        let f = fuzzy.control(0.0, &measured, &reference).unwrap();
        let p = pd.control(0.0, &measured, &reference).unwrap();
        // The paper's surface is odd, so the remainder is cubic; 1e6 bounds its coefficient
        // (third derivative of the bells ~ 1/r^3 with r = 0.3, times 100 N m).
        for i in 0..2 {
            prop_assert!((f[i] - p[i]).abs() < 1e6 * scale.powi(3) + 1e-9, "{f:?} vs {p:?}");
        }
    }

    #[test]
    fn computed_torque_imposes_the_error_dynamics(
        a in prop::array::uniform2(-1.0f64..1.0),
        a_dot in prop::array::uniform2(-2.0f64..2.0),
        reference_a in prop::array::uniform2(-1.0f64..1.0),
        reference_rates in prop::array::uniform4(-2.0f64..2.0),
    ) {
        let model = paper_model();
        let (kp, kd) = ([400.0, 900.0], [40.0, 60.0]);
        let mut controller = ComputedTorque::new(model.clone(), kp, kd).unwrap();
        let measured = ModalState { a, a_dot };
        let reference = ReferenceSample {
            a: reference_a,
            a_dot: [reference_rates[0], reference_rates[1]],
            a_ddot: [reference_rates[2], reference_rates[3]],
        };
        let tau = controller.control(0.0, &measured, &reference).unwrap();
        let a_ddot = accelerations(&model, &measured, tau);
        for i in 0..2 {
            let expected = reference.a_ddot[i] - kp[i] * (a[i] - reference.a[i]) - kd[i] * (a_dot[i] - reference.a_dot[i]);
            prop_assert!((a_ddot[i] - expected).abs() < 1e-9 * (1.0 + expected.abs()), "{a_ddot:?}");
        }
    }

    #[test]
    fn gravity_compensation_adds_exactly_g_star(
        a in prop::array::uniform2(-1.0f64..1.0),
        da in prop::array::uniform2(-0.5f64..0.5),
    ) {
        let model = paper_model();
        let mut fuzzy = FuzzyController::new(paper_controller()).unwrap();
        let mut fuzzy_gc = FuzzyController::new(paper_controller()).unwrap()
            .with_gravity_compensation(model.clone()).unwrap();
        let measured = ModalState { a, a_dot: [0.0; 2] };
        let reference = ReferenceSample { a: [a[0] + da[0], a[1] + da[1]], ..ReferenceSample::default() };
        let plain = fuzzy.control(0.0, &measured, &reference).unwrap();
        let compensated = fuzzy_gc.control(0.0, &measured, &reference).unwrap();
        // At rest, the difference G* alone holds the arm still.
        let a_ddot = accelerations(&model, &measured, [compensated[0] - plain[0], compensated[1] - plain[1]]);
        prop_assert!(a_ddot[0].abs() < 1e-9 && a_ddot[1].abs() < 1e-9, "{a_ddot:?}");
    }
}

#[test]
fn fuzzy_controller_is_the_fuzzy_system() {
    let mut controller = FuzzyController::new(paper_controller()).unwrap();
    let mut evaluator = Evaluator::new(paper_controller());
    let measured = ModalState {
        a: [0.25, -0.1],
        a_dot: [0.3, -0.7],
    };
    let reference = ReferenceSample {
        a: [0.1, 0.05],
        ..ReferenceSample::default()
    };
    let mut expected = [0.0; 2];
    evaluator
        .eval(&[0.15, -0.15, 0.3, -0.7], &mut expected)
        .unwrap();
    assert_eq!(
        controller.control(0.0, &measured, &reference).unwrap(),
        expected
    );
}

#[test]
fn controllers_refuse_wrong_shapes_and_gains() {
    let three_coords = ReducedModel::new(
        ChainModel::uniform(10, 0.1, 0.1, 9.81).unwrap(),
        ModalMap::paper(10).unwrap(),
    )
    .unwrap();
    assert!(matches!(
        ComputedTorque::new(three_coords.clone(), [1.0; 2], [1.0; 2]),
        Err(SimError::InvalidSetting { .. })
    ));
    let fuzzy = FuzzyController::new(paper_controller()).unwrap();
    assert!(fuzzy.with_gravity_compensation(three_coords).is_err());
    assert!(ComputedTorque::new(paper_model(), [-1.0, 1.0], [1.0; 2]).is_err());
    assert!(ComputedTorque::new(paper_model(), [1.0, 1.0], [f64::NAN, 1.0]).is_err());
    assert!(PdController::new([0.0, f64::INFINITY], [[0.0; 4]; 2]).is_err());
    let two_inputs = fuzzy_sugeno::FuzzySystem::builder("small")
        .input(
            "e",
            [-1.0, 1.0],
            [("N", fuzzy_sugeno::MembershipFn::bell(1.0, 2.0, -1.0))],
        )
        .input(
            "v",
            [-1.0, 1.0],
            [("N", fuzzy_sugeno::MembershipFn::bell(1.0, 2.0, -1.0))],
        )
        .output(
            "u",
            [-1.0, 1.0],
            [("A", fuzzy_sugeno::OutputFn::Constant(1.0))],
        )
        .rule(["N", "N"], ["A"])
        .build()
        .unwrap();
    let err = FuzzyController::new(two_inputs.clone()).unwrap_err();
    assert!(err.to_string().contains("4 inputs"), "{err}");
    assert!(PdController::from_fuzzy_slope(&two_inputs).is_err());
}
