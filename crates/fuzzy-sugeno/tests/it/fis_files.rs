//! `.fis` round trips over random systems, and the shipped `data/paper.fis`.

use crate::common::{Rng, random_point, random_system};
use fuzzy_sugeno::{Evaluator, FuzzySystem, paper_controller};
use proptest::prelude::*;

const PAPER_FIS: &str = include_str!("../../data/paper.fis");

proptest! {
    #[test]
    fn writing_then_reading_gives_the_identical_system(seed in any::<u64>(), zero_order in any::<bool>()) {
        let system = random_system(seed, zero_order);
        let text = system.to_fis();
        let (read, notes) = FuzzySystem::from_fis_with_notes(&text).map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        prop_assert_eq!(&read, &system);
        // What the crate writes is read back with nothing ignored.
        prop_assert!(notes.is_empty(), "{:?}", notes);
        prop_assert_eq!(read.to_fis(), text);
        // Bit-identical parameters give bit-identical outputs.
        let (mut a, mut b) = (Evaluator::new(system.clone()), Evaluator::new(read));
        let mut rng = Rng::new(seed);
        let (mut ya, mut yb) = (vec![0.0; system.outputs().len()], vec![0.0; system.outputs().len()]);
        let x = random_point(&system, &mut rng);
        a.eval(&x, &mut ya).unwrap();
        b.eval(&x, &mut yb).unwrap();
        prop_assert_eq!(ya, yb);
    }
}

#[test]
fn the_shipped_paper_file_is_the_preset() {
    let loaded = FuzzySystem::from_fis(PAPER_FIS).unwrap();
    assert_eq!(loaded, paper_controller());
    assert_eq!(
        PAPER_FIS,
        paper_controller().to_fis(),
        "regenerate with `cargo run -p fuzzy-sugeno --example paper_controller -- fis > crates/fuzzy-sugeno/data/paper.fis`"
    );
    let (mut from_file, mut preset) = (Evaluator::new(loaded), Evaluator::new(paper_controller()));
    let mut rng = Rng::new(22);
    let (mut a, mut b) = ([0.0; 2], [0.0; 2]);
    for _ in 0..1000 {
        let x = random_point(from_file.system(), &mut rng);
        from_file.eval(&x, &mut a).unwrap();
        preset.eval(&x, &mut b).unwrap();
        assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits), "at {x:?}");
    }
}

#[test]
fn a_matlab_mamdani_file_is_refused() {
    let mamdani = "[System]\nName='tipper'\nType='mamdani'\nVersion=2.0\nNumInputs=1\nNumOutputs=1\nNumRules=1\n\
        AndMethod='min'\nOrMethod='max'\nImpMethod='min'\nAggMethod='max'\nDefuzzMethod='centroid'\n\n\
        [Input1]\nName='service'\nRange=[0 10]\nNumMFs=1\nMF1='poor':'gaussmf',[1.5 0]\n\n\
        [Output1]\nName='tip'\nRange=[0 30]\nNumMFs=1\nMF1='cheap':'trimf',[0 5 10]\n\n[Rules]\n1, 1 (1) : 1\n";
    let error = FuzzySystem::from_fis(mamdani).unwrap_err().to_string();
    assert!(
        error.starts_with("line 3: Mamdani systems are not supported"),
        "{error}"
    );
}

/// A file of 20,000 inputs (one set each, one rule over all of them) loads and evaluates, as
/// .fis and as FCL: the readers index sections and names, so their work grows with the file (a
/// scan per section made 10^5 inputs a minute's load).
#[test]
fn a_file_of_many_inputs_loads_and_evaluates() {
    let n = 20_000;
    let mut text = format!(
        "[System]\nName='wide'\nType='sugeno'\nNumInputs={n}\nNumOutputs=1\nNumRules=1\n\
         AndMethod='prod'\nOrMethod='probor'\nDefuzzMethod='wtaver'\n"
    );
    for i in 0..n {
        text += &format!(
            "[Input{}]\nName='x{i}'\nRange=[0 1]\nNumMFs=1\nMF1='a':'trimf',[0 0.5 1]\n",
            i + 1
        );
    }
    text += "[Output1]\nName='y'\nRange=[0 1]\nNumMFs=1\nMF1='c':'constant',[0.5]\n[Rules]\n";
    text += &"1 ".repeat(n);
    text += ", 1 (1) : 1\n";
    let system = FuzzySystem::from_fis(&text).unwrap();
    // The same system through FCL, whose reader indexes its variables likewise.
    assert_eq!(
        FuzzySystem::from_fcl(&system.to_fcl().unwrap()).unwrap(),
        system
    );
    let mut evaluator = Evaluator::new(system);
    let mut out = [0.0];
    evaluator.eval(&vec![0.5; n], &mut out).unwrap();
    assert_eq!(out, [0.5]);
    // A name used twice among them is still caught, with its first line.
    let twice = text.replacen("Name='x19999'", "Name='x3'", 1);
    let message = FuzzySystem::from_fis(&twice).unwrap_err().to_string();
    assert!(
        message.contains("variable name 'x3' is already used at line"),
        "{message}"
    );
}
