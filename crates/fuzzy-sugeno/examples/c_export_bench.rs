//! Times one evaluation of the paper's controller exported as C (compiled by the system `cc`
//! with `-O2`) against the Rust evaluator, on the same 1024 input vectors, in one session.
//!
//! ```sh
//! cargo run --release -p fuzzy-sugeno --example c_export_bench
//! ```
//!
//! Each figure is the median of 5 runs of 10^7 evaluations; run it on a quiet machine, or read
//! the ratio rather than the absolute numbers.

use fuzzy_sugeno::{EvalOptions, Evaluator, paper_controller};
use std::fmt::Write as _;
use std::hint::black_box;
use std::process::Command;
use std::time::Instant;

const POINTS: usize = 1024;
const EVALUATIONS: usize = 10_000_000;
const RUNS: usize = 5;

/// Deterministic inputs over the controller's ranges and a little beyond.
fn points() -> Vec<[f64; 4]> {
    (0..POINTS)
        .map(|k| {
            let t = k as f64;
            [
                0.35 * (0.37 * t).sin(),
                0.35 * (0.11 * t).cos(),
                1.2 * (0.23 * t).sin(),
                1.2 * (0.05 * t).cos(),
            ]
        })
        .collect()
}

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::temp_dir().join(format!("fuzzy-c-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let c = paper_controller().to_c("paper", &EvalOptions::default())?;
    std::fs::write(dir.join(&c.header_name), &c.header)?;
    std::fs::write(dir.join(&c.source_name), &c.source)?;
    let mut table = String::new();
    for p in points() {
        let _ = writeln!(
            table,
            "    {{{:e}, {:e}, {:e}, {:e}}},",
            p[0], p[1], p[2], p[3]
        );
    }
    let harness = format!(
        "#define _POSIX_C_SOURCE 199309L\n#include <stdio.h>\n#include <time.h>\n#include \"paper.h\"\n\
         static const double points[{POINTS}][4] = {{\n{table}}};\n\
         int main(void)\n{{\n    double out[2], sum = 0.0;\n    struct timespec a, b;\n    long k;\n    int run;\n    \
         for (run = 0; run < {RUNS}; ++run) {{\n        clock_gettime(CLOCK_MONOTONIC, &a);\n        \
         for (k = 0; k < {EVALUATIONS}L; ++k) {{\n            if (paper_eval(points[k % {POINTS}], out) != 0) {{\n                return 1;\n            }}\n            \
         sum += out[0] + out[1];\n        }}\n        clock_gettime(CLOCK_MONOTONIC, &b);\n        \
         printf(\"%.3f\\n\", ((b.tv_sec - a.tv_sec) * 1e9 + (b.tv_nsec - a.tv_nsec)) / {EVALUATIONS}.0);\n    }}\n    \
         fprintf(stderr, \"checksum %g\\n\", sum);\n    return 0;\n}}\n"
    );
    std::fs::write(dir.join("bench.c"), harness)?;
    let binary = dir.join("bench");
    let status = Command::new("cc")
        .args(["-std=c99", "-O2", "-o"])
        .arg(&binary)
        .arg(dir.join("bench.c"))
        .arg(dir.join(&c.source_name))
        .arg("-lm")
        .status()?;
    if !status.success() {
        return Err("cc failed".into());
    }
    let output = Command::new(&binary).output()?;
    if !output.status.success() {
        return Err("the C harness failed".into());
    }
    let c_ns = median(
        String::from_utf8(output.stdout)?
            .lines()
            .map(str::parse)
            .collect::<Result<_, _>>()?,
    );
    let points = points();
    let mut evaluator = Evaluator::new(paper_controller());
    let mut out = [0.0; 2];
    let mut sum = 0.0;
    let rust_ns = median(
        (0..RUNS)
            .map(|_| {
                let started = Instant::now();
                for k in 0..EVALUATIONS {
                    evaluator
                        .eval(black_box(&points[k % POINTS]), &mut out)
                        .expect("finite inputs");
                    sum += out[0] + out[1];
                }
                started.elapsed().as_nanos() as f64 / EVALUATIONS as f64
            })
            .collect(),
    );
    black_box(sum);
    println!("paper controller, one evaluation (median of {RUNS} x 10^7):");
    println!("  C (cc -O2):      {c_ns:.1} ns");
    println!("  Rust evaluator:  {rust_ns:.1} ns");
    println!("  C / Rust:        {:.2}", c_ns / rust_ns);
    let _ = std::fs::remove_dir_all(&dir);
    Ok(())
}
