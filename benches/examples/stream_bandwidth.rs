//! The memory bandwidth one core gets, STREAM-style, beside `reduced_fd/1000000` (issue 34):
//! arrays of 2^25 `f64` (256 MiB each: on the benchmark machine a triad's speed stops falling from
//! 128 MiB working sets up, although `lscpu` reports the host's shared 480 MiB L3), each kernel
//! timed 7 times, the fastest kept. Prints `stream/<kernel> <GB/s> GB/s` for
//!
//! - `read`: `sum += a[i]` (8 bytes a value read),
//! - `copy`: `b[i] = a[i]` (16 bytes a value: one read, one written),
//! - `triad`: `a[i] = b[i] + s c[i]` (24 bytes a value),
//!
//! counting the bytes the program asks for (a write that misses the cache also reads its line
//! first, which STREAM does not count either). On the shared 2-core machine the figures move
//! with the other users' load: run it next to the benchmark it explains.
//!
//! ```sh
//! cargo run --release -p hrm-benches --example stream_bandwidth
//! ```

use std::hint::black_box;
use std::time::Instant;

/// Values an array.
const LEN: usize = 1 << 25;
/// Timed repetitions of each kernel.
const REPEATS: usize = 7;

/// The fastest of [`REPEATS`] runs of `kernel`, in seconds.
fn fastest(mut kernel: impl FnMut()) -> f64 {
    (0..REPEATS)
        .map(|_| {
            let start = Instant::now();
            kernel();
            start.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let mut a: Vec<f64> = (0..LEN).map(|i| i as f64 * 1e-6).collect();
    let mut b = vec![1.0; LEN];
    let c = vec![2.0; LEN];
    let gb_s =
        |bytes_per_value: usize, seconds: f64| (bytes_per_value * LEN) as f64 / seconds / 1e9;
    let read = fastest(|| {
        // Four partial sums, so that the additions' latency does not bound the loop.
        let mut sums = [0.0; 4];
        for chunk in black_box(&a).chunks_exact(4) {
            for (s, &x) in sums.iter_mut().zip(chunk) {
                *s += x;
            }
        }
        black_box(sums);
    });
    println!("stream/read {:.2} GB/s", gb_s(8, read));
    let copy = fastest(|| {
        b.copy_from_slice(black_box(&a));
        black_box(&mut b);
    });
    println!("stream/copy {:.2} GB/s", gb_s(16, copy));
    let triad = fastest(|| {
        let s = black_box(3.0);
        for ((x, &y), &z) in a.iter_mut().zip(black_box(&b)).zip(black_box(&c)) {
            *x = y + s * z;
        }
        black_box(&mut a);
    });
    println!("stream/triad {:.2} GB/s", gb_s(24, triad));
}
