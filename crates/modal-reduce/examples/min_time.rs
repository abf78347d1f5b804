//! The fastest time of `forward_dynamics` (the 10- and 1000-link arms of `reduced_fd/10` and
//! `/1000`, same states) and of `forward_dynamics_batch` (the 1024 states of
//! `reduced_fd_batch/10`), as the minimum over 2000-3000 short blocks of calls.
//!
//! On a loaded machine a block that ran without being preempted shows the cost of the code
//! itself, so two builds timed one after the other compare fairly where Criterion's medians swing
//! by tens of percent. Run with `cargo run --release -p modal-reduce --example min_time`.

use backbone_kin::ModalMap;
use manip_dyn::ChainModel;
use modal_reduce::{
    ReducedBatchData, ReducedData, ReducedModel, forward_dynamics, forward_dynamics_batch,
};
use std::hint::black_box;
use std::time::Instant;

const A: [f64; 3] = [0.4, -0.3, 1.2];
const A_DOT: [f64; 3] = [0.5, 0.2, -0.1];
const TAU_STAR: [f64; 3] = [1.0, -0.5, 0.2];
/// States of the batch.
const BATCH: usize = 1024;

/// The paper's arm scaled to `n` links of total length 1 m and mass 1 kg.
fn model(n: usize) -> Result<ReducedModel, Box<dyn std::error::Error>> {
    let link = 1.0 / n as f64;
    Ok(ReducedModel::new(
        ChainModel::uniform(n, link, link, 9.81)?,
        ModalMap::paper(n)?,
    )?)
}

/// The fastest and the 10th-percentile time of one call, in nanoseconds, over `blocks` blocks
/// of `calls` calls of `f`.
fn time(mut f: impl FnMut(), calls: usize, blocks: usize) -> (f64, f64) {
    let mut per_call: Vec<f64> = (0..blocks)
        .map(|_| {
            let start = Instant::now();
            for _ in 0..calls {
                f();
            }
            start.elapsed().as_secs_f64() * 1e9 / calls as f64
        })
        .collect();
    per_call.sort_by(f64::total_cmp);
    (per_call[0], per_call[blocks / 10])
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    for (n, calls) in [(10, 2000), (1000, 20)] {
        let model = model(n)?;
        let mut data = ReducedData::new(&model);
        let mut a_ddot = [0.0; 3];
        let mut call = || {
            forward_dynamics(
                &model,
                &mut data,
                black_box(&A),
                black_box(&A_DOT),
                black_box(&TAU_STAR),
                &mut a_ddot,
            )
            .expect("a valid state");
            black_box(a_ddot);
        };
        let (fastest, p10) = time(&mut call, calls, 2000);
        println!("reduced_fd/{n}: fastest {fastest:.1} ns, 10th percentile {p10:.1} ns");
    }
    let model = model(10)?;
    let mut data = ReducedBatchData::new(&model);
    // The states of `reduced_fd_batch/10`.
    let spread = |base: [f64; 3], i: usize| base.map(|x| x * (1.0 + 0.1 * (i as f64).sin()));
    let batch = |base| {
        (0..BATCH)
            .flat_map(|i| spread(base, i))
            .collect::<Vec<f64>>()
    };
    let (a, a_dot, tau_star) = (batch(A), batch(A_DOT), batch(TAU_STAR));
    let mut a_ddot = vec![0.0; 3 * BATCH];
    let call = || {
        forward_dynamics_batch(
            &model,
            &mut data,
            black_box(&a),
            black_box(&a_dot),
            black_box(&tau_star),
            &mut a_ddot,
        )
        .expect("valid states");
        black_box(&a_ddot);
    };
    let (fastest, p10) = time(call, 1, 3000);
    let states = BATCH as f64;
    println!(
        "reduced_fd_batch/10: fastest {:.2} ns a state, 10th percentile {:.2} ns",
        fastest / states,
        p10 / states
    );
    Ok(())
}
