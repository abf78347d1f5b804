//! `Plant` dispatches onto each family's own functions: the same bits as calling them directly,
//! and a workspace of the other family is refused.

use backbone_kin::ModalMap;
use lane_math::Classify;
use manip_dyn::ChainModel;
use modal_reduce::spatial::{
    SpatialReducedData, SpatialReducedDerivatives, SpatialReducedModel, spatial_reduced_derivatives,
};
use modal_reduce::{
    Plant, PlantData, PlantDerivatives, ReduceError, ReducedData, ReducedDerivatives, ReducedModel,
    forward_dynamics, joint_torques, reduced_derivatives,
};

#[test]
fn the_planar_plant_computes_the_planar_bits() {
    let model = ReducedModel::new(
        ChainModel::uniform(10, 0.1, 0.1, 9.81).unwrap(),
        ModalMap::paper(10).unwrap(),
    )
    .unwrap();
    let plant = Plant::from(&model);
    let (a, a_dot, tau) = ([0.4, -0.3, 1.2], [0.5, 0.2, -0.1], [1.0, -0.5, 0.2]);
    let (mut data, mut direct) = (PlantData::new(plant), ReducedData::new(&model));
    let (mut x, mut y) = ([0.0; 3], [0.0; 3]);
    plant
        .forward_dynamics(&mut data, &a, &a_dot, &tau, &mut x)
        .unwrap();
    forward_dynamics(&model, &mut direct, &a, &a_dot, &tau, &mut y).unwrap();
    assert_eq!(x.map(f64::to_bits), y.map(f64::to_bits));
    assert_eq!(data.coriolis(), direct.coriolis());
    let (mut t, mut u) = ([0.0; 10], [0.0; 10]);
    plant
        .joint_torques(&mut data, &a, &a_dot, &x, &mut t)
        .unwrap();
    joint_torques(&model, &mut direct, &a, &a_dot, &y, &mut u).unwrap();
    assert_eq!(t, u);
    let mut derivatives = PlantDerivatives::new(plant);
    let mut reference = ReducedDerivatives::new(&model);
    plant
        .derivatives(&mut data, &mut derivatives, &a, &a_dot, &tau)
        .unwrap();
    reduced_derivatives(&model, &mut direct, &mut reference, &a, &a_dot, &tau).unwrap();
    assert_eq!(derivatives.d_a(), reference.d_a());
    assert_eq!(derivatives.d_a_dot(), reference.d_a_dot());
    assert_eq!(plant.n_joints(), 10);
}

#[test]
fn the_spatial_plant_computes_the_spatial_bits() {
    let model = SpatialReducedModel::uniform_rods(10, 1, 0.1, 0.1, [0.0, 0.0, -9.81]).unwrap();
    let plant = Plant::from(&model);
    let (a, a_dot, tau) = (
        [0.4, -0.3, 0.2, 0.1],
        [0.5, 0.2, -0.1, 0.3],
        [0.1, -0.5, 0.2, 0.0],
    );
    let mut data = PlantData::new(plant);
    let mut derivatives = PlantDerivatives::new(plant);
    plant
        .derivatives(&mut data, &mut derivatives, &a, &a_dot, &tau)
        .unwrap();
    let mut direct = SpatialReducedData::new(&model);
    let mut reference = SpatialReducedDerivatives::new(&model);
    spatial_reduced_derivatives(&model, &mut direct, &mut reference, &a, &a_dot, &tau).unwrap();
    assert_eq!(derivatives.d_a(), reference.d_a());
    assert_eq!(derivatives.a_ddot(), reference.a_ddot());
    assert_eq!(data.mass_matrix()[(1, 2)], direct.mass_matrix()[6]);
    assert_eq!((plant.n_joints(), plant.n_coords()), (20, 4));
    // A planar workspace is refused, naming both families.
    let planar = ReducedModel::new(
        ChainModel::uniform(10, 0.1, 0.1, 9.81).unwrap(),
        ModalMap::paper(10).unwrap(),
    )
    .unwrap();
    let mut wrong = PlantData::new(Plant::from(&planar));
    let error = plant.terms(&mut wrong, &a, &a_dot).unwrap_err();
    assert!(matches!(
        error,
        ReduceError::WrongFamily {
            built: "planar",
            given: "spatial"
        }
    ));
    assert!(error.is_invalid_input());
}
