//! `hrm fis`: check, evaluate and plot Takagi-Sugeno systems stored as MATLAB `.fis` files.
//!
//! - `hrm fis check FILE`: Wang's completeness, consistency and continuity; exits non-zero if
//!   one of them fails.
//! - `hrm fis eval FILE x1 x2 ...`: prints `name = value` for every output.
//! - `hrm fis surface FILE --out DIR`: SVGs of every input's membership functions and of every
//!   output over every pair of inputs (others at a reference value), like MATLAB's `plotmf` and
//!   `gensurf`.
//! - `hrm fis train ...` and `hrm fis export ...`: see `fis_train` and `fis_export`.
//!
//! A FILE whose name ends in `.fcl` is read as IEC 61131-7 FCL, any other as MATLAB `.fis`.

use crate::plot::{self, Grid, Labels, Series};
use clap::{Args, Subcommand, ValueEnum};
use fuzzy_sugeno::{
    AnalysisOptions, EvalOptions, Evaluator, FuzzySystem, InputVariable, OutOfRange,
};
use std::path::{Path, PathBuf};

/// The arguments of `hrm fis`.
#[derive(Debug, Args)]
pub struct FisArgs {
    #[command(subcommand)]
    command: FisCommand,
}

#[derive(Debug, Subcommand)]
enum FisCommand {
    /// Check the rule base for completeness, consistency and continuity (Wang); fails if one does not hold.
    Check {
        /// The `.fis` file.
        file: PathBuf,
        /// Completeness: the degree to which every antecedent of some rule must hold everywhere.
        #[arg(long, default_value_t = 0.5)]
        coverage: f64,
        /// Completeness: evenly spaced samples per input (set landmarks are added).
        #[arg(long, default_value_t = 21)]
        samples: usize,
        /// Continuity: the largest allowed jump between neighbouring rules, as a fraction of the output range.
        #[arg(long, default_value_t = 1.0)]
        max_jump: f64,
    },
    /// Evaluate the system at one input vector and print its outputs.
    Eval {
        /// The `.fis` file.
        file: PathBuf,
        /// One value per input, in the file's order.
        #[arg(required = true, allow_negative_numbers = true)]
        inputs: Vec<f64>,
        /// What to do with an input outside its range.
        #[arg(long, value_enum, default_value_t = RangePolicy::Clamp)]
        out_of_range: RangePolicy,
    },
    /// Learn a system from a CSV of samples (genfis, then ANFIS) and write it as a .fis file.
    Train(crate::fis_train::TrainArgs),
    /// Write the system as C99 source and header, or as IEC 61131-7 FCL.
    Export(crate::fis_export::ExportArgs),
    /// Write SVG plots of the membership functions and control surfaces.
    Surface {
        /// The `.fis` file.
        file: PathBuf,
        /// The directory to write into (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// Samples per axis of each surface.
        #[arg(long, default_value_t = 41)]
        resolution: usize,
        /// Values of the inputs not on a surface's axes, comma-separated (default: the middle of each range).
        #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
        reference: Option<Vec<f64>>,
    },
}

/// The out-of-range policies, as command-line values.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub(crate) enum RangePolicy {
    /// Evaluate at the nearest end of the range.
    Clamp,
    /// Evaluate the membership functions at the value as given.
    AsGiven,
    /// Refuse.
    Error,
}

/// Runs `hrm fis ...`.
pub fn run(args: FisArgs) -> Result<(), String> {
    match args.command {
        FisCommand::Check {
            file,
            coverage,
            samples,
            max_jump,
        } => {
            let options = AnalysisOptions {
                coverage,
                samples_per_input: samples,
                max_relative_jump: max_jump,
                ..Default::default()
            };
            let (report, passed) = check(&read_system(&file)?, &options)?;
            print!("{report}");
            if passed {
                Ok(())
            } else {
                Err(format!("{}: the rule base fails the check", file.display()))
            }
        }
        FisCommand::Eval {
            file,
            inputs,
            out_of_range,
        } => {
            for (name, value) in eval(read_system(&file)?, &inputs, out_of_range)? {
                println!("{name} = {value}");
            }
            Ok(())
        }
        FisCommand::Train(args) => crate::fis_train::run(args),
        FisCommand::Export(args) => crate::fis_export::run(args),
        FisCommand::Surface {
            file,
            out,
            resolution,
            reference,
        } => {
            for path in surface(&read_system(&file)?, &out, resolution, reference.as_deref())? {
                println!("{}", path.display());
            }
            Ok(())
        }
    }
}

/// Parses the text of a `.fis` file.
fn load_system(text: &str) -> Result<FuzzySystem, String> {
    FuzzySystem::from_fis(text).map_err(|e| e.to_string())
}

/// Reads a `.fis` file, or an FCL file if the name ends in `.fcl`.
pub(crate) fn read_system(path: &Path) -> Result<FuzzySystem, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let is_fcl = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("fcl"));
    let system = if is_fcl {
        FuzzySystem::from_fcl(&text).map_err(|e| e.to_string())
    } else {
        load_system(&text)
    };
    system.map_err(|e| format!("{}: {e}", path.display()))
}

/// The analysis report and whether it passed.
fn check(system: &FuzzySystem, options: &AnalysisOptions) -> Result<(String, bool), String> {
    let report = system.analyze(options).map_err(|e| e.to_string())?;
    Ok((report.to_string(), report.passed()))
}

/// Each output's name and value at `inputs`.
fn eval(
    system: FuzzySystem,
    inputs: &[f64],
    policy: RangePolicy,
) -> Result<Vec<(String, f64)>, String> {
    let out_of_range = match policy {
        RangePolicy::Clamp => OutOfRange::Clamp,
        RangePolicy::AsGiven => OutOfRange::AsGiven,
        RangePolicy::Error => OutOfRange::Error,
    };
    let options = EvalOptions {
        out_of_range,
        ..EvalOptions::default()
    };
    let mut evaluator = Evaluator::with_options(system, options).map_err(|e| e.to_string())?;
    let mut outputs = vec![0.0; evaluator.system().outputs().len()];
    evaluator
        .eval(inputs, &mut outputs)
        .map_err(|e| e.to_string())?;
    let names = evaluator.system().outputs().iter().map(|o| o.name.clone());
    Ok(names.zip(outputs).collect())
}

/// Writes the plots into `dir` and returns their paths: `mf_<input>.svg` for every input, then
/// `surface_<output>_<x>_<y>.svg` for every output and pair of inputs (or `curve_<output>_<x>.svg`
/// for a single-input system).
fn surface(
    system: &FuzzySystem,
    dir: &Path,
    resolution: usize,
    reference: Option<&[f64]>,
) -> Result<Vec<PathBuf>, String> {
    let inputs = system.inputs();
    if resolution < 2 {
        return Err(format!("--resolution must be at least 2, got {resolution}"));
    }
    let reference: Vec<f64> = match reference {
        None => inputs
            .iter()
            .map(|v| 0.5 * (v.range[0] + v.range[1]))
            .collect(),
        Some(values) if values.len() != inputs.len() => {
            return Err(format!(
                "--reference has {} values for {} inputs",
                values.len(),
                inputs.len()
            ));
        }
        Some(values) => values.to_vec(),
    };
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut written = Vec::new();
    for input in inputs {
        written.push(membership_chart(input, dir)?);
    }
    if inputs.len() == 1 {
        written.extend(output_curves(system, dir)?);
        return Ok(written);
    }
    for i in 0..inputs.len() {
        for j in i + 1..inputs.len() {
            for output in 0..system.outputs().len() {
                written.push(surface_chart(
                    system,
                    [i, j],
                    output,
                    &reference,
                    resolution,
                    dir,
                )?);
            }
        }
    }
    Ok(written)
}

/// `n >= 2` evenly spaced samples of `range`, both ends included.
fn samples(range: [f64; 2], n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| range[0] + (range[1] - range[0]) * k as f64 / (n - 1) as f64)
        .collect()
}

/// Samples of a membership function or single-input curve.
const CURVE_SAMPLES: usize = 201;

/// Writes the membership functions of `input` (like MATLAB's `plotmf`) to `dir/mf_<input>.svg`
/// and returns that path.
pub fn membership_chart(input: &InputVariable, dir: &Path) -> Result<PathBuf, String> {
    let xs = samples(input.range, CURVE_SAMPLES);
    let series = input
        .sets
        .iter()
        .map(|set| {
            let points = xs
                .iter()
                .map(|&x| set.membership.degree(x).map(|mu| (x, mu)))
                .collect::<Result<_, _>>();
            points
                .map(|points| Series {
                    label: set.name.clone(),
                    points,
                })
                .map_err(|e| e.to_string())
        })
        .collect::<Result<Vec<_>, String>>()?;
    let path = dir.join(format!("mf_{}.svg", file_name(&input.name)));
    let title = format!("Membership functions of {}", input.name);
    plot::line_chart(
        &path,
        &Labels {
            title: &title,
            x: &input.name,
            y: "degree of membership",
        },
        &series,
        Some(0.0..1.05),
    )?;
    Ok(path)
}

/// Writes every output of a single-input system over its input to
/// `dir/curve_<output>_<input>.svg` and returns the paths.
fn output_curves(system: &FuzzySystem, dir: &Path) -> Result<Vec<PathBuf>, String> {
    let (input, outputs) = (&system.inputs()[0], system.outputs());
    let mut evaluator = Evaluator::new(system.clone());
    let mut y = vec![0.0; outputs.len()];
    let xs = samples(input.range, CURVE_SAMPLES);
    let mut curves = vec![Vec::with_capacity(xs.len()); outputs.len()];
    for &x in &xs {
        evaluator.eval(&[x], &mut y).map_err(|e| e.to_string())?;
        for (curve, &value) in curves.iter_mut().zip(&y) {
            curve.push((x, value));
        }
    }
    let mut written = Vec::new();
    for (output, points) in outputs.iter().zip(curves) {
        let path = dir.join(format!(
            "curve_{}_{}.svg",
            file_name(&output.name),
            file_name(&input.name)
        ));
        let title = format!("{} = f({})", output.name, input.name);
        let series = [Series {
            label: output.name.clone(),
            points,
        }];
        plot::line_chart(
            &path,
            &Labels {
                title: &title,
                x: &input.name,
                y: &output.name,
            },
            &series,
            None,
        )?;
        written.push(path);
    }
    Ok(written)
}

/// Writes output `output` of `system` over the inputs `[i, j]` on a `resolution` x `resolution`
/// grid, the other inputs at `reference` (like MATLAB's `gensurf`), as a heat map
/// `dir/surface_<output>_<x>_<y>.svg`, and returns its path.
pub fn surface_chart(
    system: &FuzzySystem,
    [i, j]: [usize; 2],
    output: usize,
    reference: &[f64],
    resolution: usize,
    dir: &Path,
) -> Result<PathBuf, String> {
    let (inputs, outputs) = (system.inputs(), system.outputs());
    if i == j
        || i.max(j) >= inputs.len()
        || output >= outputs.len()
        || reference.len() != inputs.len()
        || resolution < 2
    {
        return Err(format!(
            "a surface needs two distinct inputs and one output of the system ({} inputs, {} outputs), one reference value per input and at least 2 samples per axis (got inputs {i}, {j}, output {output}, {} reference values, resolution {resolution})",
            inputs.len(),
            outputs.len(),
            reference.len()
        ));
    }
    let mut evaluator = Evaluator::new(system.clone());
    let mut point = reference.to_vec();
    let mut y = vec![0.0; outputs.len()];
    let (xs, ys) = (
        samples(inputs[i].range, resolution),
        samples(inputs[j].range, resolution),
    );
    let mut z = Vec::with_capacity(xs.len() * ys.len());
    for &yv in &ys {
        for &xv in &xs {
            point[i] = xv;
            point[j] = yv;
            evaluator.eval(&point, &mut y).map_err(|e| e.to_string())?;
            z.push(y[output]);
        }
    }
    let (xn, yn, zn) = (&inputs[i].name, &inputs[j].name, &outputs[output].name);
    let path = dir.join(format!(
        "surface_{}_{}_{}.svg",
        file_name(zn),
        file_name(xn),
        file_name(yn)
    ));
    let title = format!("{zn} = f({xn}, {yn})");
    let grid = Grid { x: xs, y: ys, z };
    plot::heatmap(
        &path,
        &Labels {
            title: &title,
            x: xn,
            y: yn,
        },
        zn,
        &grid,
    )?;
    Ok(path)
}

/// A name made safe for a file name.
fn file_name(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use fuzzy_sugeno::{PaperController, paper_controller};

    const PAPER_FIS: &str = include_str!("../../fuzzy-sugeno/data/paper.fis");

    fn temp_dir(tag: &str) -> PathBuf {
        std::env::temp_dir().join(format!("hrm-fis-{tag}-{}", std::process::id()))
    }

    #[test]
    fn load_system_reads_the_shipped_paper_file_and_reports_line_numbers() {
        assert_eq!(load_system(PAPER_FIS).unwrap(), paper_controller());
        let broken = PAPER_FIS.replace("NumMFs=4", "NumMFs=x");
        assert_eq!(
            load_system(&broken).unwrap_err(),
            "line 45: expected NumMFs=<integer >= 1>, found NumMFs=x"
        );
    }

    #[test]
    fn check_passes_the_paper_and_fails_narrow_bells() {
        let (report, passed) = check(&paper_controller(), &AnalysisOptions::default()).unwrap();
        assert!(passed, "{report}");
        assert!(report.contains("completeness: pass") && report.contains("continuity: pass"));
        let narrow = PaperController {
            width_fraction: 0.5,
            ..PaperController::default()
        }
        .build()
        .unwrap();
        let (report, passed) = check(&narrow, &AnalysisOptions::default()).unwrap();
        assert!(!passed && report.contains("completeness: FAIL"), "{report}");
    }

    #[test]
    fn eval_prints_named_outputs_and_refuses_bad_input() {
        let outputs = eval(
            paper_controller(),
            &[0.3, 0.0, 0.0, 0.0],
            RangePolicy::Clamp,
        )
        .unwrap();
        assert_eq!(outputs[0].0, "tau1");
        assert!((outputs[0].1 + 80.0).abs() < 1e-12);
        assert_eq!(
            eval(paper_controller(), &[0.1], RangePolicy::Clamp).unwrap_err(),
            "expected 4 inputs, got 1"
        );
        assert_eq!(
            eval(
                paper_controller(),
                &[0.5, 0.0, 0.0, 0.0],
                RangePolicy::Error
            )
            .unwrap_err(),
            "input 0 ('da1') = 0.5 lies outside its range [-0.3, 0.3]"
        );
    }

    #[test]
    fn surface_writes_every_membership_plot_and_every_pair() {
        let dir = temp_dir("surface");
        let written = surface(&paper_controller(), &dir, 9, None).unwrap();
        // 4 inputs, then 2 outputs x 6 pairs of inputs.
        assert_eq!(written.len(), 4 + 2 * 6);
        assert!(written.contains(&dir.join("mf_da1.svg")));
        assert!(written.contains(&dir.join("surface_tau1_da1_a1_dot.svg")));
        for path in &written {
            assert!(std::fs::read_to_string(path).unwrap().starts_with("<svg"));
        }
        assert_eq!(
            surface(&paper_controller(), &dir, 9, Some(&[0.0])).unwrap_err(),
            "--reference has 1 values for 4 inputs"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_single_input_system_gets_curves() {
        let text = "[System]\nName='one'\nType='sugeno'\nNumInputs=1\nNumOutputs=1\nNumRules=2\nAndMethod='prod'\n\
            OrMethod='probor'\nImpMethod='prod'\nAggMethod='sum'\nDefuzzMethod='wtaver'\n[Input1]\nName='x y'\n\
            Range=[0 1]\nNumMFs=2\nMF1='lo':'trimf',[-1 0 1]\nMF2='hi':'trimf',[0 1 2]\n[Output1]\nName='u'\n\
            Range=[0 1]\nNumMFs=2\nMF1='a':'constant',[0]\nMF2='b':'constant',[1]\n[Rules]\n1, 1 (1) : 1\n2, 2 (1) : 1\n";
        let dir = temp_dir("curve");
        let written = surface(&load_system(text).unwrap(), &dir, 5, None).unwrap();
        assert_eq!(
            written,
            [dir.join("mf_x_y.svg"), dir.join("curve_u_x_y.svg")]
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
