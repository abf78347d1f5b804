//! `hrm fis`: check, evaluate and plot Takagi-Sugeno systems stored as MATLAB `.fis` files.
//!
//! - `hrm fis check FILE`: what the reader accepted but ignored (unused methods, extension
//!   keys, extra parameters; skipped for an FCL file, whose reader keeps no such notes), then Wang's completeness, consistency and continuity; exits
//!   non-zero if one of them fails.
//! - `hrm fis eval FILE x1 x2 ...`: prints `name = value` for every output.
//! - `hrm fis surface FILE --out DIR`: SVGs of every input's membership functions and of every
//!   output over every pair of inputs (others at a reference value), like MATLAB's `plotmf` and
//!   `gensurf`.
//! - `hrm fis train ...`, `hrm fis export ...` and `hrm fis imitate ...`: see `fis_train`,
//!   `fis_export` and `fis_imitate`.
//!
//! A FILE whose name ends in `.fcl` is read as IEC 61131-7 FCL, any other as MATLAB `.fis`.

use crate::args;
use crate::console;
use crate::fis_input::{RangePolicy, read_system, read_system_with_notes};
use crate::output_dir::OutputDir;
use crate::plot::{self, Grid, Labels, Series};
use clap::{Args, Subcommand};
use fuzzy_sugeno::{
    AnalysisOptions, EvalOptions, Evaluator, FisNote, FuzzyError, FuzzySystem, InputVariable,
    MAX_SAMPLES_PER_INPUT, NoRuleFired,
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
    /// List what the file says that was accepted but ignored, then check the rule base for completeness, consistency and continuity (Wang); fails if one does not hold.
    Check {
        /// The `.fis` file.
        file: PathBuf,
        /// Completeness: the degree to which every antecedent of some rule must hold everywhere.
        #[arg(long, default_value_t = 0.5, allow_negative_numbers = true)]
        coverage: f64,
        /// Completeness: evenly spaced samples per input (set landmarks are added; thinned so the grid stays within a million points).
        #[arg(long, default_value_t = 21, allow_negative_numbers = true)]
        samples: i128,
        /// Continuity: the largest allowed jump between neighbouring rules, as a fraction of the output range.
        #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
        max_jump: f64,
    },
    /// Evaluate the system at one input vector and print its outputs.
    Eval {
        /// The `.fis` file.
        file: PathBuf,
        /// One value per input, in the file's order.
        #[arg(required = true, allow_negative_numbers = true)]
        inputs: Vec<f64>,
        /// What to do with an input outside its range (as-given: MATLAB's evalfis, with a
        /// warning on standard error).
        #[arg(long, value_enum, default_value_t = RangePolicy::AsGiven)]
        out_of_range: RangePolicy,
    },
    /// Learn a system from a CSV of samples (genfis, then ANFIS) and write it as a .fis file.
    Train(crate::fis_train::TrainArgs),
    /// Write the system as C99 source and header, or as IEC 61131-7 FCL.
    Export(crate::fis_export::ExportArgs),
    /// Learn a fuzzy controller from a teacher controller run on training scenarios (ANFIS) and write it as a .fis file.
    Imitate(crate::fis_imitate::ImitateArgs),
    /// Write SVG plots of the membership functions and control surfaces.
    Surface {
        /// The `.fis` file.
        file: PathBuf,
        /// The directory to write (created, or replaced whole if hrm wrote it).
        #[arg(long)]
        out: PathBuf,
        /// Samples per axis of each surface (2 to 600).
        #[arg(long, default_value_t = 41, allow_negative_numbers = true)]
        resolution: i128,
        /// Values of the inputs not on a surface's axes, comma-separated (default: the middle of each range; a value outside its range is drawn as given, with a warning).
        #[arg(
            long,
            value_delimiter = ',',
            action = clap::ArgAction::Set,
            allow_hyphen_values = true
        )]
        reference: Option<Vec<f64>>,
    },
}

/// Warns on standard error, as MATLAB's `evalfis` does, when `evaluator` has evaluated an input
/// of the row `inputs` outside its range as given, naming every such input: once per process (a
/// `hrm eval` session answers many requests). Inputs are numbered from 1, as in the library's
/// errors and the `.fis` file; `clamp` is how the caller asks for the other policy
/// (`--out-of-range clamp`, or a request's `"out_of_range": "clamp"`).
pub(crate) fn warn_outside_range(evaluator: &Evaluator, inputs: &[f64], clamp: &str) {
    static WARNED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);
    if evaluator.first_outside_range().is_none()
        || WARNED.swap(true, std::sync::atomic::Ordering::Relaxed)
    {
        return;
    }
    let line = format!(
        "warning: {}; evaluated as given, as MATLAB's evalfis does ({clamp} evaluates at the \
         nearest end)",
        outside_ranges(evaluator.system(), inputs).join(", ")
    );
    console::to_stderr(&console::error_line(&line));
}

/// Each value of `values` (one per input of `system`) outside its input's range, described:
/// "input 1 ('da1') = 5 is outside its range [-0.3, 0.3]".
fn outside_ranges(system: &FuzzySystem, values: &[f64]) -> Vec<String> {
    system
        .inputs()
        .iter()
        .zip(values)
        .enumerate()
        .filter(|(_, (input, value))| **value < input.range[0] || **value > input.range[1])
        .map(|(i, (input, value))| {
            format!(
                "input {} ('{}') = {value} is outside its range [{}, {}]",
                i + 1,
                input.name,
                input.range[0],
                input.range[1]
            )
        })
        .collect()
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
            // Their domains are the library's (`check` names them as options).
            let options = AnalysisOptions {
                coverage,
                samples_per_input: args::count("--samples", samples, 2, MAX_SAMPLES_PER_INPUT)?,
                max_relative_jump: max_jump,
                ..Default::default()
            };
            let (system, notes) = read_system_with_notes(&file)?;
            // The options are checked (with the system's inputs) before anything is printed.
            let (report, passed) = check(&system, &options)?;
            if let Some(notes) = notes {
                console::print(&ignored_report(&file, &notes))?;
            }
            console::print(&report)?;
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
            let lines: String = eval(read_system(&file)?, &inputs, out_of_range)?
                .into_iter()
                .map(|(name, value)| format!("{name} = {}\n", lane_math::Compact(value)))
                .collect();
            console::print(&lines)
        }
        FisCommand::Train(args) => crate::fis_train::run(args),
        FisCommand::Export(args) => crate::fis_export::run(args),
        FisCommand::Imitate(args) => crate::fis_imitate::run(args),
        FisCommand::Surface {
            file,
            out,
            resolution,
            reference,
        } => {
            let resolution = args::count("--resolution", resolution, 2, MAX_RESOLUTION)?;
            let system = read_system(&file)?;
            crate::output_dir::refuse_inputs_inside(&out, &[("FIS file", &file)])?;
            let staging = OutputDir::create(&out, "fis surface")?;
            let written = surface(&system, staging.path(), resolution, reference.as_deref())
                .map_err(|e| staging.named(e))?;
            staging.commit()?;
            let lines: String = written
                .iter()
                .filter_map(|path| path.file_name())
                .map(|name| format!("{}\n", out.join(name).display()))
                .collect();
            console::print(&lines)
        }
    }
}

/// Parses the text of a `.fis` file.
#[cfg(test)]
fn load_system(text: &str) -> Result<FuzzySystem, String> {
    FuzzySystem::from_fis(text).map_err(|e| e.to_string())
}

/// The lines of `file` that were accepted but are neither kept nor used, one per line, so that
/// nothing is dropped silently.
fn ignored_report(file: &Path, notes: &[FisNote]) -> String {
    if notes.is_empty() {
        return format!("{}: nothing ignored\n", file.display());
    }
    let mut report = format!("{}: accepted but ignored:\n", file.display());
    for note in notes {
        report.push_str(&format!("  {note}\n"));
    }
    report
}

/// Largest `--resolution`: a heat map cell per pixel of the 660-pixel-wide map.
const MAX_RESOLUTION: usize = 600;
/// Most SVG files `fis surface` writes (membership charts and surfaces).
const MAX_PLOTS: usize = 1000;
/// Most bytes of SVG `fis surface` writes, estimated before drawing (1 GiB).
const MAX_SVG_BYTES: f64 = (1u64 << 30) as f64;
/// Bytes of SVG per heat map cell (a filled rectangle), measured.
const SVG_BYTES_PER_CELL: f64 = 90.0;
/// Most rule evaluations the surfaces of `fis surface` may take (about half a minute: 2.8 ns a
/// rule of 8 inputs, measured).
const MAX_SURFACE_WORK: f64 = 1e10;

/// The analysis report and whether it passed; a note says when the even samples were thinned
/// to keep the grid within [`AnalysisOptions::max_grid_points`] and
/// [`AnalysisOptions::max_work`].
fn check(system: &FuzzySystem, options: &AnalysisOptions) -> Result<(String, bool), String> {
    let report = system.analyze(options).map_err(|e| match e {
        // The command line has no option for the grid's limit: say what the system needs.
        FuzzyError::AnalysisGrid {
            max_grid_points,
            axes,
        } => format!(
            "the completeness grid of this system needs {} points ({} along its inputs, each \
             with 2 even samples, its sets' landmarks and the midpoints between them), more \
             than the {max_grid_points} `hrm fis check` evaluates: check a system with fewer \
             inputs or sets",
            lane_math::Compact(axes.iter().map(|&n| n as f64).product()),
            axes.iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(" x ")
        ),
        // The options by their CLI names (the library names its fields).
        FuzzyError::AnalysisOption {
            name: name @ ("coverage" | "max_relative_jump"),
            requirement,
            value,
        } => format!(
            "--{} must {requirement}, got {}",
            if name == "coverage" {
                "coverage"
            } else {
                "max-jump"
            },
            lane_math::Compact(value)
        ),
        e => e.to_string(),
    })?;
    let mut text = report.to_string();
    let grid = &report.completeness.grid;
    if grid.iter().any(|&n| n < options.samples_per_input) {
        let asked = (options.samples_per_input as f64).powi(grid.len() as i32);
        let points: usize = grid.iter().product();
        text.push_str(&format!(
            "note: --samples {} per input would make a grid of {asked:e} points, more than the \
             check evaluates (at most {} points and {:e} rule evaluations): the even samples were \
             thinned to a grid of {points} points\n",
            options.samples_per_input, options.max_grid_points, options.max_work as f64
        ));
    }
    text.push_str(OUT_OF_RANGE_NOTE);
    Ok((text, report.passed()))
}

/// What `hrm fis check` says about the two ways of evaluating an input outside its range.
const OUT_OF_RANGE_NOTE: &str = "inputs outside their ranges: `hrm fis eval`, `hrm eval` and a \
scenario's fuzzy controller evaluate them as given by default, as MATLAB's evalfis and \
Simulink's Fuzzy Logic Controller block do (with a warning on standard error): sets that decay on \
both sides (bells, Gaussians) then fade, so a large error weakens the controller's action, and \
far out every output tends to a mean of the rules' conclusions; `--out-of-range clamp` (a \
scenario's `[controller] out_of_range = \"clamp\"`) evaluates them at the nearest end of the \
range instead, so a large error acts like the edge of the range and the action saturates\n";

/// Each output's name and value at `inputs`.
fn eval(
    system: FuzzySystem,
    inputs: &[f64],
    policy: RangePolicy,
) -> Result<Vec<(String, f64)>, String> {
    let options = EvalOptions {
        out_of_range: policy.policy(),
        ..EvalOptions::default()
    };
    // Evaluated where no rule may fire, to say so as MATLAB's evalfis does; then, only there,
    // again under the default (the middle of the output's range).
    let strict = EvalOptions {
        no_rule_fired: NoRuleFired::Error,
        ..options.clone()
    };
    let mut evaluator = Evaluator::with_options(system, strict).map_err(|e| e.to_string())?;
    let mut outputs = vec![0.0; evaluator.system().outputs().len()];
    match evaluator.eval(inputs, &mut outputs) {
        Ok(()) => {}
        Err(FuzzyError::NoRuleFired { index, name }) => {
            console::to_stderr(&console::error_line(&format!(
                "warning: no rule fired for output {} ('{name}') at these inputs: its value is \
                 the middle of its range, as MATLAB's evalfis gives",
                index + 1
            )));
            evaluator = Evaluator::with_options(evaluator.system().clone(), options)
                .map_err(|e| e.to_string())?;
            evaluator
                .eval(inputs, &mut outputs)
                .map_err(|e| e.to_string())?;
        }
        Err(other) => return Err(other.to_string()),
    }
    warn_outside_range(&evaluator, inputs, "--out-of-range clamp");
    let names = evaluator.system().outputs().iter().map(|o| o.name.clone());
    Ok(names.zip(outputs).collect())
}

/// Writes the plots into `dir` and returns their paths: `mf_<input>.svg` for every input that
/// has membership functions (a `NumMFs=0` input has none to draw), then
/// `surface_<output>_<x>_<y>.svg` for every output and pair of inputs (or `curve_<output>_<x>.svg`
/// for a single-input system).
fn surface(
    system: &FuzzySystem,
    dir: &Path,
    resolution: usize,
    reference: Option<&[f64]>,
) -> Result<Vec<PathBuf>, String> {
    let inputs = system.inputs();
    let (n_in, n_out) = (inputs.len(), system.outputs().len());
    if !(2..=MAX_RESOLUTION).contains(&resolution) {
        return Err(format!(
            "--resolution must be at least 2 and at most {MAX_RESOLUTION}, got {resolution}"
        ));
    }
    // Membership charts, then one surface per output and pair of inputs (curves for one input).
    let surfaces = if n_in == 1 {
        0.0
    } else {
        n_out as f64 * (n_in as f64 * (n_in as f64 - 1.0) / 2.0)
    };
    let plots = n_in as f64 + if n_in == 1 { n_out as f64 } else { surfaces };
    if plots > MAX_PLOTS as f64 {
        return Err(format!(
            "the system's {n_in} inputs and {n_out} outputs need {plots} plots, more than the \
             {MAX_PLOTS} fis surface writes"
        ));
    }
    let bytes = surfaces * (resolution * resolution) as f64 * SVG_BYTES_PER_CELL;
    if bytes > MAX_SVG_BYTES {
        return Err(format!(
            "--resolution {resolution} would write {surfaces} surfaces of {resolution} x \
             {resolution} cells, about {:.1} GB of SVG, more than the {:.1} GB limit: lower \
             --resolution",
            bytes / 1e9,
            MAX_SVG_BYTES / 1e9
        ));
    }
    let rules = system.rules().len();
    let work = surfaces * (resolution * resolution) as f64 * rules as f64;
    if work > MAX_SURFACE_WORK {
        return Err(format!(
            "--resolution {resolution} would evaluate the system's {rules} rules at {surfaces} \
             surfaces of {resolution} x {resolution} points, {work:.2e} rule evaluations, more \
             than the {MAX_SURFACE_WORK:e} fis surface may take (about half a minute): lower \
             --resolution"
        ));
    }
    let names = PlotNames::new(system);
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
        Some(values) => {
            if let Some((k, v)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                return Err(format!(
                    "--reference value {} (input '{}') must be finite, got {v}",
                    k + 1,
                    inputs[k].name
                ));
            }
            let outside = outside_ranges(system, values);
            if !outside.is_empty() {
                console::to_stderr(&console::error_line(&format!(
                    "warning: --reference: {}; the surfaces hold it there, evaluated as given",
                    outside.join(", ")
                )));
            }
            values.to_vec()
        }
    };
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut written = Vec::new();
    for (input, name) in inputs
        .iter()
        .zip(&names.inputs)
        .filter(|(input, _)| !input.sets.is_empty())
    {
        written.push(membership_chart(input, name, dir)?);
    }
    if inputs.len() == 1 {
        written.extend(output_curves(system, &names, dir)?);
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
                    &names,
                    dir,
                )?);
            }
        }
    }
    Ok(written)
}

/// `n >= 2` evenly spaced samples of `range`, both ends included; `lo (1 - t) + hi t` stays
/// finite for ranges near `±f64::MAX`, whose width overflows.
fn samples(range: [f64; 2], n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let t = k as f64 / (n - 1) as f64;
            range[0] * (1.0 - t) + range[1] * t
        })
        .collect()
}

/// The names that stand for a system's inputs and outputs in file names. A variable's name
/// with every character but ASCII letters, digits, `-` and `_` replaced by `_` (at most 64),
/// unless two of the files would then share a name (also ignoring case, for case-insensitive
/// file systems) or a name is empty: then every variable is named by its position (`in1`,
/// `out2`). No file name can leave the output folder or overwrite another.
pub struct PlotNames {
    /// One per input.
    pub inputs: Vec<String>,
    /// One per output.
    pub outputs: Vec<String>,
}

impl PlotNames {
    /// The names for `system`.
    pub fn new(system: &FuzzySystem) -> Self {
        let readable = PlotNames {
            inputs: system.inputs().iter().map(|v| file_name(&v.name)).collect(),
            outputs: system
                .outputs()
                .iter()
                .map(|v| file_name(&v.name))
                .collect(),
        };
        let files = readable.files();
        let mut lowered: Vec<String> = files.iter().map(|f| f.to_ascii_lowercase()).collect();
        lowered.sort();
        lowered.dedup();
        let empty = readable
            .inputs
            .iter()
            .chain(&readable.outputs)
            .any(String::is_empty);
        if lowered.len() == files.len() && !empty {
            return readable;
        }
        PlotNames {
            inputs: (1..=readable.inputs.len())
                .map(|k| format!("in{k}"))
                .collect(),
            outputs: (1..=readable.outputs.len())
                .map(|k| format!("out{k}"))
                .collect(),
        }
    }

    /// Every file name `fis surface` writes with these names.
    fn files(&self) -> Vec<String> {
        let mut files: Vec<String> = self.inputs.iter().map(|x| format!("mf_{x}.svg")).collect();
        for out in &self.outputs {
            if let [x] = self.inputs.as_slice() {
                files.push(format!("curve_{out}_{x}.svg"));
            }
            for (i, x) in self.inputs.iter().enumerate() {
                for y in &self.inputs[i + 1..] {
                    files.push(format!("surface_{out}_{x}_{y}.svg"));
                }
            }
        }
        files
    }
}

/// Samples of a membership function or single-input curve.
const CURVE_SAMPLES: usize = 201;

/// Writes the membership functions of `input` (like MATLAB's `plotmf`) to `dir/mf_<name>.svg`
/// (`name` from [`PlotNames`]) and returns that path.
pub fn membership_chart(input: &InputVariable, name: &str, dir: &Path) -> Result<PathBuf, String> {
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
    let path = dir.join(format!("mf_{name}.svg"));
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
fn output_curves(
    system: &FuzzySystem,
    names: &PlotNames,
    dir: &Path,
) -> Result<Vec<PathBuf>, String> {
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
    for ((output, points), name) in outputs.iter().zip(curves).zip(&names.outputs) {
        let path = dir.join(format!("curve_{name}_{}.svg", names.inputs[0]));
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
/// `dir/surface_<output>_<x>_<y>.svg` (names from [`PlotNames`]), and returns its path.
pub fn surface_chart(
    system: &FuzzySystem,
    [i, j]: [usize; 2],
    output: usize,
    reference: &[f64],
    resolution: usize,
    names: &PlotNames,
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
        names.outputs[output], names.inputs[i], names.inputs[j]
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

/// A name made safe for a file name (see [`PlotNames`]).
fn file_name(name: &str) -> String {
    name.chars()
        .take(64)
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
    fn check_lists_what_was_accepted_but_ignored() {
        let file = Path::new("dimmer.fis");
        let text = include_str!("../../fuzzy-sugeno/data/interop/fuzzylite_export.fis");
        let (_, notes) = FuzzySystem::from_fis_with_notes(text).unwrap();
        let report = ignored_report(file, &notes);
        assert!(
            report.starts_with("dimmer.fis: accepted but ignored:\n  line 4: Version=6.0"),
            "{report}"
        );
        assert!(
            report.contains("\n  line 8: AndMethod='' is not used by any rule"),
            "{report}"
        );
        assert!(
            report.contains("\n  line 16: `Enabled=1` in [Input1] is not a MATLAB key"),
            "{report}"
        );
        assert_eq!(report.lines().count(), 1 + notes.len());
        assert_eq!(ignored_report(file, &[]), "dimmer.fis: nothing ignored\n");
    }

    #[test]
    fn check_passes_the_paper_and_fails_narrow_bells() {
        let (report, passed) = check(&paper_controller(), &AnalysisOptions::default()).unwrap();
        assert!(passed, "{report}");
        assert!(report.contains("completeness: pass") && report.contains("continuity: pass"));
        assert!(report.ends_with(OUT_OF_RANGE_NOTE), "{report}");
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
            "input 1 ('da1') = 0.5 lies outside its range [-0.3, 0.3]"
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
        assert_eq!(
            surface(
                &paper_controller(),
                &dir,
                9,
                Some(&[f64::NAN, 0.0, 0.0, 0.0])
            )
            .unwrap_err(),
            "--reference value 1 (input 'da1') must be finite, got NaN"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A two-input, one-output system with the given names and constant outputs `lo`, `hi`
    /// (the output's range, unless its width leaves double precision: then `[-1, 1]`).
    fn two_inputs(x: &str, y: &str, u: &str, [lo, hi]: [f64; 2]) -> FuzzySystem {
        let (low, high) = if (hi - lo).is_finite() {
            (lo, hi)
        } else {
            (-1.0, 1.0)
        };
        let text = format!(
            "[System]\nName='two'\nType='sugeno'\nNumInputs=2\nNumOutputs=1\nNumRules=2\nAndMethod='prod'\n\
             OrMethod='probor'\nImpMethod='prod'\nAggMethod='sum'\nDefuzzMethod='wtaver'\n\
             [Input1]\nName='{x}'\nRange=[0 1]\nNumMFs=2\nMF1='lo':'trimf',[-1 0 1]\nMF2='hi':'trimf',[0 1 2]\n\
             [Input2]\nName='{y}'\nRange=[0 1]\nNumMFs=1\nMF1='all':'trimf',[-1 0.5 2]\n\
             [Output1]\nName='{u}'\nRange=[{low:e} {high:e}]\nNumMFs=2\nMF1='a':'constant',[{lo:e}]\nMF2='b':'constant',[{hi:e}]\n\
             [Rules]\n1 1, 1 (1) : 1\n2 1, 2 (1) : 1\n"
        );
        load_system(&text).unwrap()
    }

    #[test]
    fn file_names_from_variable_names_neither_collide_nor_escape() {
        // `a b` and `a_b` would both become `a_b`; `A_B` differs only in case: positions instead.
        for (x, y) in [("a b", "a_b"), ("a_b", "A_B"), ("../a", "//.a")] {
            let system = two_inputs(x, y, "u", [0.0, 1.0]);
            let names = PlotNames::new(&system);
            assert_eq!(names.inputs, ["in1", "in2"], "{x}, {y}");
            assert_eq!(names.outputs, ["out1"]);
        }
        // Distinct names stay readable; anything but [A-Za-z0-9_-] becomes `_`, at most 64.
        let long = "y".repeat(300);
        let names = PlotNames::new(&two_inputs("../etc/passwd", &long, "u/v", [0.0, 1.0]));
        assert_eq!(names.inputs[0], "___etc_passwd");
        assert_eq!(names.inputs[1], "y".repeat(64));
        assert_eq!(names.outputs, ["u_v"]);
        let dir = temp_dir("names");
        let written = surface(&two_inputs("a b", "a_b", "u", [0.0, 1.0]), &dir, 3, None).unwrap();
        let files: Vec<_> = written
            .iter()
            .map(|p| p.strip_prefix(&dir).unwrap())
            .collect();
        assert_eq!(
            files,
            [
                Path::new("mf_in1.svg"),
                Path::new("mf_in2.svg"),
                Path::new("surface_out1_in1_in2.svg")
            ]
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn outputs_too_large_to_plot_get_the_non_finite_error() {
        // Finite outputs from -1.7e308 to 1.7e308 (constants beyond the output's range, as
        // Sugeno systems may have): their span overflows double precision.
        let system = two_inputs("x", "y", "u", [-1.7e308, 1.7e308]);
        let dir = temp_dir("huge-outputs");
        let err = surface(&system, &dir, 3, None).unwrap_err();
        assert!(err.contains("cannot plot a non-finite z span"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn surface_output_size_is_capped_up_front() {
        let dir = temp_dir("caps");
        let err = surface(&paper_controller(), &dir, 601, None).unwrap_err();
        assert!(
            err.contains("--resolution must be at least 2 and at most 600"),
            "{err}"
        );
        // 12 surfaces of 600 x 600 cells are about 0.4 GB: allowed. A system with 20 inputs
        // and 2 outputs has 380 surfaces: 12 GB at that resolution, refused before drawing.
        let mut builder = FuzzySystem::builder("wide");
        for i in 0..20 {
            builder = builder.input(
                format!("x{i}"),
                [0.0, 1.0],
                [("A", fuzzy_sugeno::MembershipFn::gaussian(1.0, 0.0))],
            );
        }
        let wide = builder
            .output(
                "u",
                [0.0, 1.0],
                [("c", fuzzy_sugeno::OutputFn::Constant(0.5))],
            )
            .output(
                "v",
                [0.0, 1.0],
                [("c", fuzzy_sugeno::OutputFn::Constant(0.5))],
            )
            .rule(["A"; 20], ["c", "c"])
            .build()
            .unwrap();
        let err = surface(&wide, &dir, 600, None).unwrap_err();
        assert!(
            err.contains("380 surfaces") && err.contains("12.3 GB"),
            "{err}"
        );
        assert!(!dir.exists(), "nothing is written");
    }

    #[test]
    fn an_input_without_membership_functions_gets_no_membership_plot() {
        let text = include_str!("../../fuzzy-sugeno/data/interop/matlab_legacy.fis");
        let dir = temp_dir("no-sets");
        let written = surface(&load_system(text).unwrap(), &dir, 3, None).unwrap();
        assert!(!written.contains(&dir.join("mf_load.svg")));
        assert!(written.contains(&dir.join("mf_angle.svg")));
        assert!(written.contains(&dir.join("surface_torque_rate_load.svg")));
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
