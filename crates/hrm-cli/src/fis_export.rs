//! `hrm fis export`: a system (`.fis` or `.fcl`) as self-contained C99 source and header, or as
//! IEC 61131-7 FCL (`fuzzy_sugeno`'s `to_c` and `to_fcl`; docs/fuzzy-formats.md says what each
//! format carries).

use crate::fis_input::{self, RangePolicy, read_system};
use crate::output_dir;
use clap::{Args, ValueEnum};
use fuzzy_sugeno::{EvalOptions, NoRuleFired};
use std::path::{Path, PathBuf};

/// The arguments of `hrm fis export`.
#[derive(Debug, Args)]
pub struct ExportArgs {
    /// The system, a MATLAB .fis or an FCL .fcl file.
    file: PathBuf,
    /// What to write.
    #[arg(long, value_enum)]
    format: Format,
    /// The directory to write into (created if missing).
    #[arg(long)]
    out: PathBuf,
    /// C: the prefix of the file names and of the function, `<prefix>_eval`.
    #[arg(long, default_value = "hrm_fis")]
    prefix: String,
    /// C: what the function does with an input outside its range (as-given: MATLAB's
    /// evalfis, the default of `hrm fis eval`).
    #[arg(long, value_enum, default_value_t = RangePolicy::AsGiven)]
    out_of_range: RangePolicy,
    /// C: what the function does when no rule fires for an output.
    #[arg(long, value_enum, default_value_t = NoRulePolicy::Middle)]
    no_rule_fired: NoRulePolicy,
}

/// The export formats.
#[derive(Debug, Clone, Copy, ValueEnum)]
enum Format {
    /// C99 source and header evaluating the system.
    C,
    /// IEC 61131-7 Fuzzy Control Language.
    Fcl,
}

/// The no-rule-fired policies, as command-line values.
#[derive(Debug, Clone, Copy, ValueEnum)]
enum NoRulePolicy {
    /// The middle of the output's range.
    Middle,
    /// Return a non-zero code.
    Error,
}

/// Runs `hrm fis export`; prints the paths written.
pub fn run(args: ExportArgs) -> Result<(), String> {
    let system = read_system(&args.file)?;
    let files: Vec<(String, String)> = match args.format {
        Format::C => {
            let options = EvalOptions {
                out_of_range: args.out_of_range.policy(),
                no_rule_fired: match args.no_rule_fired {
                    NoRulePolicy::Middle => NoRuleFired::MiddleOfRange,
                    NoRulePolicy::Error => NoRuleFired::Error,
                },
            };
            let c = system
                .to_c(&args.prefix, &options)
                .map_err(|e| e.to_string())?;
            vec![(c.header_name, c.header), (c.source_name, c.source)]
        }
        Format::Fcl => {
            let stem = args
                .file
                .file_stem()
                .map_or("system".into(), |s| s.to_string_lossy());
            let text = system.to_fcl().map_err(|e| e.to_string())?;
            vec![(
                format!("{stem}.fcl"),
                format!("{}{text}", fis_input::FCL_SIGNATURE),
            )]
        }
    };
    // All files whole or none: a failure leaves the folder's existing files as they were.
    let files: Vec<(PathBuf, String)> = files
        .into_iter()
        .map(|(name, text)| (Path::new(&args.out).join(name), text))
        .collect();
    let paths: Vec<PathBuf> = files.iter().map(|(path, _)| path.clone()).collect();
    // Not into another command's output, which that command replaces whole.
    output_dir::refuse_marked_folder(Path::new(&args.out), "fis export", "the exported files")?;
    output_dir::refuse_foreign_files(
        &paths,
        "fis export",
        (fis_input::RECOGNISED_BYTES, fis_input::written_by_hrm),
    )?;
    output_dir::write_files(&files, "fis export")?;
    for (path, _) in &files {
        crate::console::print(&format!("{}\n", path.display()))?;
    }
    Ok(())
}
