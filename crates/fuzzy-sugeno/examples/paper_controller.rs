//! The paper's fuzzy controller: evaluate it, look at its rules' firing strengths, check its rule
//! base, and print it as a MATLAB `.fis` file.
//!
//! `cargo run -p fuzzy-sugeno --example paper_controller` prints a tour;
//! `cargo run -p fuzzy-sugeno --example paper_controller -- fis` prints only the `.fis` text
//! (this is how `data/paper.fis` is made).

use fuzzy_sugeno::{AnalysisOptions, Evaluator, FuzzyError, paper_controller};

fn main() -> Result<(), FuzzyError> {
    let system = paper_controller();
    if std::env::args().nth(1).as_deref() == Some("fis") {
        print!("{}", system.to_fis());
        return Ok(());
    }
    let mut controller = Evaluator::new(system.clone());
    let mut tau = [0.0; 2];
    println!(
        "{:>6} {:>6} {:>7} {:>7} -> {:>9} {:>9}",
        "da1", "da2", "a1_dot", "a2_dot", "tau1*", "tau2*"
    );
    for x in [
        [0.0, 0.0, 0.0, 0.0],
        [0.3, 0.0, 0.0, 0.0],
        [0.15, -0.1, -0.5, 0.2],
        [-0.2, 0.1, 0.8, -1.0],
    ] {
        controller.eval(&x, &mut tau)?;
        println!(
            "{:>6} {:>6} {:>7} {:>7} -> {:>9.4} {:>9.4}",
            x[0], x[1], x[2], x[3], tau[0], tau[1]
        );
    }
    let strengths = controller.fire(&[0.15, -0.1, -0.5, 0.2])?;
    let strongest = (0..strengths.len())
        .max_by(|&a, &b| strengths[a].total_cmp(&strengths[b]))
        .unwrap_or(0);
    println!(
        "\nat (0.15, -0.1, -0.5, 0.2) rule {} fires strongest, at {:.4}",
        strongest + 1,
        strengths[strongest]
    );
    println!("\n{}", system.analyze(&AnalysisOptions::default())?);
    Ok(())
}
