//! The reduced model's memory grows as `O(n m)`: a model and its workspace take a few hundred
//! bytes a link (measured with a counting allocator), a chain of `MAX_LINKS` links reduces, and
//! the faer path, which forms the `n x n` mass matrix, refuses chains beyond `MAX_DENSE_LINKS`
//! before allocating it. The same for the spatial arm's reduced-only path.

use backbone_kin::ModalMap;
use manip_dyn::{ChainModel, DynError, MAX_DENSE_LINKS, MAX_LINKS};
use modal_reduce::spatial::{
    SpatialReducedBatchData, SpatialReducedData, SpatialReducedModel, spatial_forward_dynamics,
    spatial_forward_dynamics_batch,
};
use modal_reduce::{
    ReduceError, ReducedData, ReducedModel, forward_dynamics, forward_dynamics_by_projection,
    potential_energy, reduced_terms_by_projection,
};

use test_support::alloc::memory_during as bytes_of;

/// The paper's arm stretched to `n` links: total length 1 m and mass 1 kg.
fn stretched(n: usize) -> ReducedModel {
    let length = 1.0 / n as f64;
    ReducedModel::new(
        ChainModel::uniform(n, length, length, 9.81).unwrap(),
        ModalMap::paper(n).unwrap(),
    )
    .unwrap()
}

#[test]
fn a_model_and_its_workspace_take_a_few_hundred_bytes_a_link() {
    let n = 100_000;
    let ((model, data), held, peak) = bytes_of(|| {
        let model = stretched(n);
        let data = ReducedData::new(&model);
        (model, data)
    });
    let (per_link, peak_per_link) = (held / n, peak / n);
    println!("{per_link} bytes a link held, {peak_per_link} at the peak (m = 3)");
    assert!(per_link <= 512, "{per_link} bytes a link");
    assert!(
        peak_per_link <= 768,
        "{peak_per_link} bytes a link at the peak"
    );
    assert_eq!(data.mass_matrix().nrows(), model.n_coords());
}

#[test]
fn a_chain_of_max_links_reduces() {
    let model = stretched(MAX_LINKS);
    let mut data = ReducedData::new(&model);
    let (a, a_dot) = ([0.8, -0.5, 0.7], [1.2, -0.7, 0.4]);
    let mut a_ddot = [0.0; 3];
    forward_dynamics(
        &model,
        &mut data,
        &a,
        &a_dot,
        &[0.3, -0.2, 0.1],
        &mut a_ddot,
    )
    .unwrap();
    assert!(a_ddot.iter().all(|x| x.is_finite()));
    // Holding still against gravity takes tau* = G*, also at a million links.
    let g_star = data.gravity().to_vec();
    forward_dynamics(&model, &mut data, &a, &[0.0; 3], &g_star, &mut a_ddot).unwrap();
    assert!(a_ddot.iter().all(|x| x.abs() < 1e-9), "{a_ddot:?}");
    // The recursive full-chain algorithms run at this size too.
    assert!(potential_energy(&model, &mut data, &a).unwrap().is_finite());
}

#[test]
fn the_faer_path_allocates_on_first_use_and_stops_at_the_dense_limit() {
    let model = stretched(64);
    let mut data = ReducedData::new(&model);
    let (a, a_dot) = ([0.3, 0.2, 1.0], [0.1, -0.2, 0.3]);
    let (_, held, _) =
        bytes_of(|| reduced_terms_by_projection(&model, &mut data, &a, &a_dot).unwrap());
    assert!(
        held >= 8 * 64 * 64,
        "the first call allocates M: {held} bytes"
    );

    let n = MAX_DENSE_LINKS + 1;
    let model = stretched(n);
    let (mut data, held, _) = bytes_of(|| ReducedData::new(&model));
    assert!(held < n * 1024, "{held} bytes for {n} links");
    let mut a_ddot = [0.0; 3];
    let (result, held, peak) = bytes_of(|| {
        forward_dynamics_by_projection(&model, &mut data, &a, &a_dot, &[0.0; 3], &mut a_ddot)
    });
    assert_eq!(
        result,
        Err(ReduceError::Dyn(DynError::TooManyLinks {
            what: "the projection J^T M J",
            got: n,
            max: MAX_DENSE_LINKS,
        }))
    );
    assert_eq!((held, peak), (0, 0));
    assert_eq!(
        result.unwrap_err().to_string(),
        format!("chain dynamics: the projection J^T M J may have at most 4096 links, got {n}")
    );
    // The default path is unaffected.
    forward_dynamics(&model, &mut data, &a, &a_dot, &[0.0; 3], &mut a_ddot).unwrap();
}

/// The spatial arm stretched to `n` links (total length 1 m and mass 1 kg, `m = 4`), under
/// gravity along `-z`.
fn spatial_stretched(n: usize) -> SpatialReducedModel {
    let length = 1.0 / n as f64;
    SpatialReducedModel::uniform_rods(n, 1, length, length, [0.0, 0.0, -9.81]).unwrap()
}

/// The spatial reduced-only path is `O(n m)` in memory: a model, its workspace and a batch's
/// workspace take the same few hundred bytes a link at `10^4` and `10^5` links (nothing grows
/// with `n^2`), forward dynamics alone and in a batch allocates nothing at `10^5` links, and
/// holding the arm still against gravity (`tau* = G*`) gives zero acceleration there too.
#[test]
fn a_spatial_arm_takes_a_few_hundred_bytes_a_link() {
    let bytes_per_link = |n: usize| {
        let ((model, data, batch), held, peak) = bytes_of(|| {
            let model = spatial_stretched(n);
            let data = SpatialReducedData::new(&model);
            let batch = SpatialReducedBatchData::new(&model);
            (model, data, batch)
        });
        (model, data, batch, held / n, peak / n)
    };
    let (.., small, _) = bytes_per_link(10_000);
    let (model, mut data, mut batch, per_link, peak_per_link) = bytes_per_link(100_000);
    println!("{per_link} bytes a link held, {peak_per_link} at the peak (spatial, m = 4)");
    assert!(per_link <= 1024, "{per_link} bytes a link");
    assert!(
        peak_per_link <= 1536,
        "{peak_per_link} bytes a link at the peak"
    );
    assert!(
        per_link.abs_diff(small) <= 8,
        "{small} bytes a link at 10^4 links, {per_link} at 10^5"
    );
    let (a, a_dot) = ([0.8, -0.5, 0.7, 0.3], [1.2, -0.7, 0.4, -0.2]);
    let mut a_ddot = [0.0; 4];
    let (result, held, peak) = bytes_of(|| {
        spatial_forward_dynamics(
            &model,
            &mut data,
            &a,
            &a_dot,
            &[0.3, -0.2, 0.1, 0.0],
            &mut a_ddot,
        )
    });
    result.unwrap();
    assert_eq!((held, peak), (0, 0), "one state");
    assert!(a_ddot.iter().all(|x| x.is_finite()));
    let g_star = data.gravity().to_vec();
    let states = 9;
    let (a, g_star) = (a.repeat(states), g_star.repeat(states));
    let (a_dot, mut out) = (vec![0.0; 4 * states], vec![1.0; 4 * states]);
    let (result, held, peak) = bytes_of(|| {
        spatial_forward_dynamics_batch(&model, &mut batch, &a, &a_dot, &g_star, &mut out)
    });
    result.unwrap();
    assert_eq!((held, peak), (0, 0), "a batch");
    assert!(out.iter().all(|x| x.abs() < 1e-9), "{out:?}");
}
