//! The reduced model's memory grows as `O(n m)`: a model and its workspace take a few hundred
//! bytes a link (measured with a counting allocator), a chain of `MAX_LINKS` links reduces, and
//! the faer path, which forms the `n x n` mass matrix, refuses chains beyond `MAX_DENSE_LINKS`
//! before allocating it.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use backbone_kin::ModalMap;
use manip_dyn::{ChainModel, DynError, MAX_DENSE_LINKS, MAX_LINKS};
use modal_reduce::{
    ReduceError, ReducedData, ReducedModel, forward_dynamics, forward_dynamics_faer,
    potential_energy, reduced_terms_faer,
};

/// Counts the bytes the current thread holds (the test harness runs others in parallel).
struct Counting;

thread_local! {
    static LIVE: Cell<isize> = const { Cell::new(0) };
    static PEAK: Cell<isize> = const { Cell::new(0) };
}

fn grow(bytes: usize) {
    LIVE.with(|live| {
        live.set(live.get() + bytes as isize);
        PEAK.with(|peak| peak.set(peak.get().max(live.get())));
    });
}

fn shrink(bytes: usize) {
    LIVE.with(|live| live.set(live.get() - bytes as isize));
}

// SAFETY: forwards to the system allocator; the counters are plain thread-local cells.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        grow(layout.size());
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        grow(layout.size());
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        shrink(layout.size());
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        shrink(layout.size());
        grow(new_size);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Bytes held after `f` and the peak while it ran, above what was held before.
fn bytes_of<T>(f: impl FnOnce() -> T) -> (T, usize, usize) {
    let before = LIVE.with(Cell::get);
    PEAK.with(|peak| peak.set(before));
    let value = f();
    let held = LIVE.with(Cell::get) - before;
    let peak = PEAK.with(Cell::get) - before;
    (value, held.max(0) as usize, peak.max(0) as usize)
}

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
    let (_, held, _) = bytes_of(|| reduced_terms_faer(&model, &mut data, &a, &a_dot).unwrap());
    assert!(
        held >= 8 * 64 * 64,
        "the first call allocates M: {held} bytes"
    );

    let n = MAX_DENSE_LINKS + 1;
    let model = stretched(n);
    let (mut data, held, _) = bytes_of(|| ReducedData::new(&model));
    assert!(held < n * 1024, "{held} bytes for {n} links");
    let mut a_ddot = [0.0; 3];
    let (result, held, peak) =
        bytes_of(|| forward_dynamics_faer(&model, &mut data, &a, &a_dot, &[0.0; 3], &mut a_ddot));
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
