use super::*;
use clap::Parser;
use sim_study::study::{RunMetrics, ShardFile, StoredOutcome};

/// `hrm` reduced to its `sweep` subcommand.
#[derive(Parser)]
struct Hrm {
    #[command(subcommand)]
    command: HrmCommand,
}

#[derive(clap::Subcommand)]
enum HrmCommand {
    Sweep(SweepCli),
}

fn parse(args: &[&str]) -> Result<SweepCli, clap::Error> {
    let argv = ["hrm", "sweep"].iter().chain(args);
    Hrm::try_parse_from(argv).map(|hrm| match hrm.command {
        HrmCommand::Sweep(cli) => cli,
    })
}

fn hrm_sweep(args: &[&str]) -> Result<(), String> {
    run(parse(args).map_err(|e| e.to_string())?)
}

/// A fresh temporary folder for test `name`.
fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hrm-sweep-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A small sweep: 2 noise levels x every controller x 3 seeds of 0.15 s (the step is at 0.1 s).
const SMALL: &[&str] = &[
    "--scenario",
    "paper-responses-step",
    "--duration",
    "0.15",
    "--noise",
    "0,0.005",
    "--seeds",
    "3",
    "--base-seed",
    "42",
];

/// The smallest sweep: one controller, no noise, 2 seeds of 0.05 s.
const TINY: &[&str] = &[
    "--scenario",
    "paper-responses-step",
    "--controllers",
    "pd",
    "--noise",
    "0",
    "--seeds",
    "2",
    "--duration",
    "0.05",
];

fn with<'a>(base: &[&'a str], extra: &[&'a str]) -> Vec<&'a str> {
    base.iter().chain(extra).copied().collect()
}

#[test]
fn help_shows_list_defaults_as_they_are_typed() {
    use clap::CommandFactory;
    let mut command = Hrm::command();
    let help = command
        .find_subcommand_mut("sweep")
        .unwrap()
        .render_long_help()
        .to_string();
    assert!(
        help.contains("[default: 0,0.005,0.01,0.02,0.05,0.1]"),
        "{help}"
    );
    assert!(
        help.contains(&format!("[default: {}]", ControllerKind::names(","))),
        "{help}"
    );
}

#[test]
fn a_repeated_option_keeps_its_last_value() {
    let cli = parse(&[
        "--noise",
        "0,0.01",
        "--noise",
        "0.02",
        "--controllers",
        "pd",
        "--controllers",
        "fuzzy",
        "--seeds",
        "1",
        "--seeds",
        "2",
    ])
    .unwrap();
    let a = &cli.sweep;
    assert_eq!(a.noise, [0.02]);
    assert_eq!(a.controllers, [ControllerKind::Fuzzy]);
    assert_eq!(a.seeds, 2);
    // A list typed valid last is valid, whatever came before.
    let cli = parse(&["--noise", "0,0.01", "--noise", "0"]).unwrap();
    assert_eq!(cli.sweep.noise, [0.0]);
}

#[test]
fn the_command_line_parses_with_defaults_and_merge() {
    let cli = parse(&[]).unwrap();
    assert!(cli.command.is_none());
    let a = &cli.sweep;
    assert_eq!(a.scenario, "paper-tracking");
    assert_eq!(a.controllers, ControllerKind::ALL);
    assert_eq!(a.noise, [0.0, 0.005, 0.01, 0.02, 0.05, 0.1]);
    assert_eq!((a.seeds, a.base_seed, a.shard), (10, 1, None));
    // The library's defaults are the command's.
    let defaults = SweepSettings::default();
    assert_eq!(a.controllers, defaults.controllers);
    assert_eq!(a.noise, defaults.noise_levels);
    assert_eq!(a.rate_noise_ratio, defaults.rate_noise_ratio);
    assert_eq!(a.reference_noise_ratio, defaults.reference_noise_ratio);
    assert_eq!(
        (a.seeds, a.base_seed),
        (defaults.seeds as i128, defaults.base_seed as i128)
    );
    let cli = parse(&["--controllers", "pd,fuzzy-gc", "--shard", "2/5"]).unwrap();
    assert_eq!(
        cli.sweep.controllers,
        [ControllerKind::Pd, ControllerKind::FuzzyGc]
    );
    assert_eq!(cli.sweep.shard, Some(Shard { index: 2, count: 5 }));
    let cli = parse(&["merge", "--out", "o", "a.json", "dir"]).unwrap();
    assert!(matches!(
        cli.command,
        Some(SweepCommand::Merge { ref shards, .. }) if shards.len() == 2
    ));
    assert!(parse(&["--seeds", "3", "merge", "a.json"]).is_err());
    assert!(parse(&["merge"]).is_err(), "merge needs shard files");
    assert!(parse(&["--controllers", "bang-bang"]).is_err());
    assert!(parse(&["--shard", "4/3"]).is_err());
}

#[test]
fn bad_settings_are_refused_before_running() {
    let out = temp_dir("bad");
    let out = out.to_str().unwrap();
    let err = hrm_sweep(&["--scenario", "no-such", "--out", out]).unwrap_err();
    assert!(err.contains("neither a built-in scenario"), "{err}");
    let err = hrm_sweep(&with(SMALL, &["--noise", "-0.1", "--out", out])).unwrap_err();
    assert!(err.contains("non-negative"), "{err}");
    // 0.00015 s is not a whole number of the 1e-4 s controller periods.
    let err = hrm_sweep(&with(SMALL, &["--duration", "0.00015", "--out", out])).unwrap_err();
    assert!(err.contains("duration"), "{err}");
    for (value, shown) in [("0", "0"), ("nan", "NaN"), ("-1", "-1"), ("inf", "inf")] {
        let err = hrm_sweep(&with(SMALL, &["--duration", value, "--out", out])).unwrap_err();
        assert_eq!(
            err,
            format!("--duration must be positive and finite (s), got {shown}")
        );
    }
    // The library's refusals, named by the option.
    let err = hrm_sweep(&with(SMALL, &["--noise", "0.01,0", "--out", out])).unwrap_err();
    assert!(
        err.starts_with("--noise must be distinct and ascending"),
        "{err}"
    );
    // 1e308 times the rate ratio 10 overflows: named as --noise and --rate-noise-ratio, not as
    // the scenario's noise or the library's field; a huge ratio is written compactly.
    let err = hrm_sweep(&with(
        SMALL,
        &["--noise", "10", "--rate-noise-ratio", "1e308", "--out", out],
    ))
    .unwrap_err();
    assert_eq!(
        err,
        "--noise 10 times --rate-noise-ratio 1e308 is inf, more than the 1000000 (rad, rad/s) a \
         run's noise may be"
    );
    let err = hrm_sweep(&with(SMALL, &["--noise", "1e6", "--out", out])).unwrap_err();
    assert_eq!(
        err,
        "--noise 1000000 times --rate-noise-ratio 10 is 10000000, more than the 1000000 (rad, \
         rad/s) a run's noise may be"
    );
    let err = hrm_sweep(&with(SMALL, &["--noise", "1e308", "--out", out])).unwrap_err();
    assert_eq!(
        err,
        "--noise must be at most 1000000 (rad, rad/s), got 1e308"
    );
    let err = hrm_sweep(&with(SMALL, &["--rate-noise-ratio", "-1", "--out", out])).unwrap_err();
    assert_eq!(
        err,
        "--rate-noise-ratio must be finite and non-negative, got -1"
    );
    let err = hrm_sweep(&with(
        SMALL,
        &["--controllers", "pd,fuzzy,pd", "--out", out],
    ))
    .unwrap_err();
    assert_eq!(err, "--controllers lists pd twice");
    // Ten million runs of 2 s: refused before any runs, without a folder; the same sweep split
    // into a million shards runs its shard.
    let huge = [
        "--scenario",
        "paper-responses-step",
        "--controllers",
        "pd",
        "--noise",
        "0,0.01,0.02,0.03,0.04,0.05,0.06,0.07,0.08,0.09",
        "--seeds",
        "1000000",
    ];
    let fresh = temp_dir("too-much-work");
    let fresh_out = fresh.join("out");
    let err = hrm_sweep(&with(&huge, &["--out", fresh_out.to_str().unwrap()])).unwrap_err();
    assert!(
        err.starts_with("runs: the 10000000 runs of shard 1/1 would take an estimated"),
        "{err}"
    );
    assert!(!fresh_out.exists());
    let sharded = with(&huge, &["--duration", "0.01", "--shard", "7/1000000"]);
    hrm_sweep(&with(&sharded, &["--out", fresh_out.to_str().unwrap()])).unwrap();
    let shard = read(&fresh_out.join("shard-7-of-1000000.json"));
    assert_eq!(shard.lines().count(), 11, "a header and ten runs");
}

/// The acceptance test of sharding: three shards merged give exactly the unsharded report.
#[test]
fn merged_shards_equal_the_unsharded_sweep_and_bad_merges_are_refused() {
    let root = temp_dir("shards");
    let whole = root.join("whole");
    let shards = root.join("shards");
    let merged = root.join("merged");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    hrm_sweep(&with(SMALL, &["--out", &s(&whole)])).unwrap();
    for k in 1..=3 {
        let shard = format!("{k}/3");
        hrm_sweep(&with(SMALL, &["--shard", &shard, "--out", &s(&shards)])).unwrap();
    }
    hrm_sweep(&["merge", "--out", &s(&merged), &s(&shards)]).unwrap();
    for file in ["summary.json", "table.txt"] {
        assert_eq!(read(&whole.join(file)), read(&merged.join(file)), "{file}");
    }
    let whole_runs = ShardFile::read(&whole.join("runs.json")).unwrap();
    // 2 noise levels x 3 seeds x every controller.
    assert_eq!(whole_runs.runs.len(), 6 * ControllerKind::ALL.len());
    let merged_runs = ShardFile::read(&merged.join("runs.json")).unwrap();
    assert_eq!(whole_runs.config, merged_runs.config);
    let indices = |f: &ShardFile| f.runs.iter().map(|r| r.index).collect::<Vec<_>>();
    assert_eq!(
        indices(&merged_runs),
        (0..whole_runs.runs.len()).collect::<Vec<_>>()
    );
    assert_eq!(indices(&whole_runs), indices(&merged_runs));
    let svg = read(&merged.join("tip_error_rms.svg"));
    assert!(svg.contains("computed-torque: mean ± std"));

    let shard = |k: usize| shards.join(format!("shard-{k}-of-3.json"));
    let merge = |files: &[PathBuf]| {
        let mut args = vec!["merge".to_string(), "--out".into(), s(&root.join("bad"))];
        args.extend(files.iter().map(|f| s(f)));
        hrm_sweep(&args.iter().map(String::as_str).collect::<Vec<_>>()).unwrap_err()
    };
    let err = merge(&[shard(1), shard(3)]);
    assert!(err.contains("shard 2/3 is missing"), "{err}");
    let err = merge(&[shard(1), shard(2), shard(2), shard(3)]);
    assert!(err.contains("shard 2/3 is given twice"), "{err}");
    // A shard of another sweep (another base seed).
    let other = root.join("other");
    hrm_sweep(&with(
        SMALL,
        &["--base-seed", "43", "--shard", "2/3", "--out", &s(&other)],
    ))
    .unwrap();
    let err = merge(&[shard(1), other.join("shard-2-of-3.json"), shard(3)]);
    assert!(
        err.contains("different sweeps") && err.contains("base_seed"),
        "{err}"
    );
    // A shard of another split.
    let err = merge(&[shard(1), whole.join("runs.json")]);
    assert!(err.contains("same split"), "{err}");
    // A shard file cut short.
    let mut cut = ShardFile::read(&shard(2)).unwrap();
    let in_shard = cut.runs.len();
    cut.runs.pop();
    let cut_path = root.join("cut").join("shard-2-of-3.json");
    write(&cut_path, &cut.to_json().unwrap()).unwrap();
    let err = merge(&[shard(1), cut_path.clone(), shard(3)]);
    let cut_short = format!(
        "is cut short: it holds {} of the {in_shard} runs of shard 2/3",
        in_shard - 1
    );
    assert!(err.contains(&cut_short), "{err}");
    // A run moved to a shard it does not belong to.
    let mut moved = ShardFile::read(&shard(2)).unwrap();
    moved.runs[0].index = 0;
    write(&cut_path, &moved.to_json().unwrap()).unwrap();
    let err = merge(&[shard(1), cut_path.clone(), shard(3)]);
    assert!(
        err.contains("holds run 0 (controller fuzzy, ")
            && err.contains("which is not run 1 of this sweep (controller fuzzy, "),
        "{err}"
    );
    // A hand-edited configuration that makes no sweep.
    let mut empty = ShardFile::read(&shard(2)).unwrap();
    empty.config.settings.seeds = 0;
    write(&cut_path, &empty.to_json().unwrap()).unwrap();
    let err = merge(&[shard(1), cut_path.clone(), shard(3)]);
    assert!(
        err.contains("invalid sweep configuration: seeds must be at least 1"),
        "{err}"
    );
    // Counts no sweep could have are refused before anything is sized by them.
    let mut huge = ShardFile::read(&shard(2)).unwrap();
    huge.config.settings.seeds = 1 << 50;
    write(&cut_path, &huge.to_json().unwrap()).unwrap();
    let err = merge(std::slice::from_ref(&cut_path));
    assert!(err.contains("seeds must be at most 1000000"), "{err}");
    let mut split = ShardFile::read(&shard(2)).unwrap();
    split.shard.count = usize::MAX;
    write(&cut_path, &split.to_json().unwrap()).unwrap();
    let err = merge(std::slice::from_ref(&cut_path));
    assert!(err.contains("a split has 1 to 10000000"), "{err}");
    assert!(parse(&["--shard", "1/10000001"]).is_err());
    let mut short = ShardFile::read(&shard(2)).unwrap();
    if let StoredOutcome::Completed(metrics) = &mut short.runs[0].outcome {
        metrics.modal_error_rms_rad.pop();
    }
    write(&cut_path, &short.to_json().unwrap()).unwrap();
    let err = merge(&[shard(1), cut_path.clone(), shard(3)]);
    assert!(
        err.contains("has 1 modal errors, but its scenario has 2"),
        "{err}"
    );
    let err = merge(&[whole.join("summary.json")]);
    assert!(err.contains("not an hrm sweep shard file"), "{err}");
    let err = merge(std::slice::from_ref(&whole));
    assert!(err.contains("no shard-*.json files"), "{err}");
    let err = merge(&[root.join("nothing.json")]);
    assert!(err.contains("cannot read"), "{err}");
    std::fs::remove_dir_all(&root).unwrap();
}

fn small_config(levels: &[f64], seeds: usize) -> SweepConfig {
    let seeds = seeds.to_string();
    let args = parse(&with(SMALL, &["--seeds", &seeds])).unwrap();
    let mut config = configure(&args.sweep).unwrap();
    config.settings.noise_levels = levels.to_vec();
    config
}

#[test]
fn a_run_in_a_sweep_is_the_scenario_run_alone_with_its_seed() {
    let config = small_config(&[0.0, 0.01], 2);
    let whole = study::run_shard(&config, Shard::WHOLE, || {}).unwrap();
    for run in &whole.runs {
        let mut scenario = Scenario::builtin("paper-responses-step").unwrap();
        scenario.duration = 0.15;
        scenario.controller.kind = run.controller;
        scenario.seed = study::run_seed(42, run.seed_index);
        scenario.noise.sensor_a_std = Some(vec![run.noise_level; 2]);
        scenario.noise.sensor_a_dot_std = Some(vec![10.0 * run.noise_level; 2]);
        let alone = scenario.build().unwrap().run().unwrap();
        assert_eq!(
            run.outcome,
            StoredOutcome::Completed(RunMetrics::from_summary(&alone.summary).unwrap()),
            "run {}",
            run.index
        );
    }
}

#[test]
fn noise_spreads_the_errors_and_no_noise_does_not() {
    let config = small_config(&[0.0, 0.01], 4);
    let whole = study::run_shard(&config, Shard::WHOLE, || {}).unwrap();
    let cells = study::cells(&config, &whole.runs);
    let kinds = ControllerKind::ALL.len();
    assert_eq!(cells.len(), 2 * kinds);
    for (quiet, noisy) in cells[..kinds].iter().zip(&cells[kinds..]) {
        assert_eq!(quiet.controller, noisy.controller);
        assert_eq!((quiet.failed, noisy.failed), (0, 0));
        // Without noise every seed gives the same run.
        let q = quiet.tip_error_rms_mm.unwrap();
        assert_eq!((q.std, q.min), (0.0, q.max), "{}", quiet.controller);
        // With noise the seeds differ.
        let n = noisy.modal_error_rms_rad[0].unwrap();
        assert!(n.std > 0.0 && n.min < n.max, "{}", noisy.controller);
    }
}

#[test]
fn diverging_runs_are_counted_per_cell_not_fatal() {
    let root = temp_dir("diverge");
    // A runaway bound of 0.25 rad holds for the 0.2 rad step without noise; a sensor noise of
    // 2 rad throws the arm past it.
    let mut scenario = Scenario::builtin("paper-responses-step").unwrap();
    scenario.limits.max_modal_error = 0.25;
    let file = root.join("tight.toml");
    write(&file, &scenario.to_toml()).unwrap();
    let out = root.join("out");
    let args = [
        "--scenario",
        file.to_str().unwrap(),
        "--duration",
        "0.3",
        "--noise",
        "0,2",
        "--seeds",
        "2",
        "--controllers",
        "fuzzy,pd",
        "--out",
        out.to_str().unwrap(),
    ];
    hrm_sweep(&args).unwrap();
    let summary: serde_json::Value =
        serde_json::from_str(&read(&out.join("summary.json"))).unwrap();
    let cells = summary["cells"].as_array().unwrap();
    let failed: Vec<u64> = cells
        .iter()
        .map(|c| c["failed"].as_u64().unwrap())
        .collect();
    assert_eq!(failed, [0, 0, 2, 2], "{summary}");
    assert!(cells[2]["tip_error_rms_mm"].is_null());
    let error = cells[2]["failures"][0]["error"].as_str().unwrap();
    assert!(error.contains("runaway tracking error"), "{error}");
    let table = read(&out.join("table.txt"));
    assert!(table.contains("4 runs stopped before the end"), "{table}");
    assert!(table.contains("0/2"), "{table}");
    assert!(out.join("tip_error_rms.svg").exists());
    assert!(wrote(&out, &out).ends_with(", tip_error_rms.svg)\n"));
    // Every run failing: no plot, and the line naming the files does not name one.
    let all_failed = root.join("all-failed");
    let noisy = with(
        &args[..10],
        &["--noise", "2", "--out", all_failed.to_str().unwrap()],
    );
    hrm_sweep(&noisy).unwrap();
    assert!(read(&all_failed.join("table.txt")).contains("no run completed: no plot drawn"));
    assert!(!all_failed.join("tip_error_rms.svg").exists());
    assert_eq!(
        wrote(Path::new("D"), &all_failed),
        "wrote D (runs.json, summary.json, table.txt)\n"
    );
    std::fs::remove_dir_all(&root).unwrap();
}

/// Issue 6: a thousand short runs finish with finite statistics (about 5 s in the dev profile
/// on two cores).
#[test]
fn a_thousand_short_runs_complete_without_nan() {
    let args = parse(&[
        "--scenario",
        "paper-responses-step",
        "--duration",
        "0.02",
        "--noise",
        "0,0.005,0.01,0.05,0.1",
        "--seeds",
        "50",
        "--controllers",
        "fuzzy,pd,computed-torque,fuzzy-gc",
    ])
    .unwrap();
    let config = configure(&args.sweep).unwrap();
    assert_eq!(config.runs(), Some(1000));
    let whole = study::run_shard(&config, Shard::WHOLE, || {}).unwrap();
    let text = whole.to_json().unwrap();
    let parsed = ShardFile::parse(&text, Path::new("memory")).unwrap();
    let cells = study::cells(&parsed.config, &parsed.runs);
    assert_eq!(cells.len(), 20);
    for cell in &cells {
        assert_eq!((cell.runs, cell.failed), (50, 0), "{cell:?}");
        assert_eq!(cell.modal_error_rms_rad.len(), 2);
        for stats in [
            cell.tip_error_rms_mm,
            cell.tip_error_max_mm,
            cell.peak_joint_torque_nm,
        ]
        .into_iter()
        .chain(cell.modal_error_rms_rad.iter().copied())
        {
            let s = stats.unwrap();
            assert!(
                [s.mean, s.std, s.min, s.median, s.max]
                    .iter()
                    .all(|v| v.is_finite()),
                "{cell:?}"
            );
        }
    }
}

/// Issue 11: a shard carries the SHA-256 of its scenario and of the `.fis` it references. The
/// same `.fis` merges into exactly the unsharded `runs.json`; an edited one is refused by name.
#[test]
fn shards_run_with_an_edited_fis_are_not_merged() {
    let root = temp_dir("fis-edit");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let fis = root.join("controller.fis");
    let paper = read(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../fuzzy-sugeno/data/paper.fis"
    )));
    write(&fis, &paper).unwrap();
    let mut scenario = Scenario::builtin("paper-responses-step").unwrap();
    scenario.controller.fis = Some(fis.clone());
    let toml = root.join("custom.toml");
    write(&toml, &scenario.to_toml()).unwrap();
    let args = |extra: &[&str]| {
        let mut a = vec![
            "--scenario".to_string(),
            s(&toml),
            "--duration".into(),
            "0.02".into(),
            "--noise".into(),
            "0,0.01".into(),
            "--seeds".into(),
            "3".into(),
            "--controllers".into(),
            "fuzzy,pd".into(),
        ];
        a.extend(extra.iter().map(|e| e.to_string()));
        a
    };
    let sweep = |a: Vec<String>| hrm_sweep(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let (whole, shards, edited) = (root.join("whole"), root.join("shards"), root.join("edited"));
    sweep(args(&["--out", &s(&whole)])).unwrap();
    sweep(args(&["--shard", "1/2", "--out", &s(&shards)])).unwrap();
    sweep(args(&["--shard", "2/2", "--out", &s(&shards)])).unwrap();
    let merged = root.join("merged");
    hrm_sweep(&["merge", "--out", &s(&merged), &s(&shards)]).unwrap();
    let bytes = |p: &Path| std::fs::read(p).unwrap();
    assert_eq!(
        bytes(&whole.join("runs.json")),
        bytes(&merged.join("runs.json"))
    );
    assert_eq!(
        bytes(&whole.join("summary.json")),
        bytes(&merged.join("summary.json"))
    );
    let header = ShardFile::read(&merged.join("runs.json"))
        .unwrap()
        .config
        .inputs;
    assert_eq!(header.len(), 2);
    assert_eq!(header[1].path.as_deref(), Some(fis.as_path()));

    // One rule weight changed between the two shards.
    let before_args = args(&[]);
    let before_args: Vec<&str> = before_args.iter().map(String::as_str).collect();
    let before = configure(&parse(&before_args).unwrap().sweep).unwrap();
    let edited_text = paper.replacen("(1) : 1", "(0.5) : 1", 1);
    assert_ne!(edited_text, paper);
    write(&fis, &edited_text).unwrap();
    // A shard whose `.fis` changes while it runs is refused after its runs, nothing written.
    let during = shards.join("during.json");
    let err = output_dir::write_file_with(&during, "test", |out| {
        write_shard(&before, Shard { index: 1, count: 2 }, out).map(drop)
    })
    .unwrap_err();
    assert!(
        err.contains(&format!(
            "controller.fis ({}) changed while the sweep ran",
            fis.display()
        )),
        "{err}"
    );
    assert!(!during.exists());
    sweep(args(&["--shard", "2/2", "--out", &s(&edited)])).unwrap();
    let err = hrm_sweep(&[
        "merge",
        "--out",
        &s(&root.join("mixed")),
        &s(&shards.join("shard-1-of-2.json")),
        &s(&edited.join("shard-2-of-2.json")),
    ])
    .unwrap_err();
    assert!(
        err.contains(&format!(
            "were run with different contents of controller.fis ({})",
            fis.display()
        )),
        "{err}"
    );
    assert!(!err.contains('\n'), "{err}");
    assert!(!root.join("mixed").exists());
    std::fs::remove_dir_all(&root).unwrap();
}

/// Issue 11: a setting JSON cannot hold is refused before any run, by name.
#[test]
fn a_setting_json_cannot_hold_is_refused_before_running() {
    let root = temp_dir("json-safe");
    let mut scenario = Scenario::builtin("paper-responses-step").unwrap();
    scenario.limits.max_modal_error = f64::INFINITY;
    let toml = root.join("unbounded.toml");
    write(&toml, &scenario.to_toml()).unwrap();
    assert!(read(&toml).contains("max_modal_error = inf"));
    let out = root.join("out");
    let err = hrm_sweep(&[
        "--scenario",
        toml.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ])
    .unwrap_err();
    // `simulate` refuses it by the same rule (issue 32).
    assert!(
        err.contains("limits.max_modal_error") && err.contains("inf"),
        "{err}"
    );
    assert!(!out.exists());
    std::fs::remove_dir_all(&root).unwrap();
}

/// Shard files are JSON lines read one run at a time: older formats are refused by name, a
/// line cut or added is refused, and more shards than the merge keeps open merge the same.
#[test]
fn shard_files_are_streamed_and_checked_line_by_line() {
    let root = temp_dir("stream");
    let args = parse(&[
        "--scenario",
        "paper-responses-step",
        "--duration",
        "0.02",
        "--noise",
        "0",
        "--controllers",
        "pd",
        "--seeds",
        "70",
    ])
    .unwrap();
    let config = configure(&args.sweep).unwrap();
    let whole = root.join("whole");
    std::fs::create_dir_all(&whole).unwrap();
    let table = sweep_whole(&config, &whole).unwrap();
    assert!(table.contains("70 runs"), "{table}");
    let shards = root.join("shards");
    for index in 1..=70 {
        let shard = Shard { index, count: 70 };
        let path = shards.join(format!("shard-{index}-of-70.json"));
        output_dir::write_file_with(&path, "test", |out| {
            write_shard(&config, shard, out).map(drop)
        })
        .unwrap();
    }
    let merged = root.join("merged");
    std::fs::create_dir_all(&merged).unwrap();
    merge_files(std::slice::from_ref(&shards), &merged, &merged.join("x")).unwrap();
    let runs = read(&whole.join("runs.json"));
    assert_eq!(runs, read(&merged.join("runs.json")));
    assert_eq!(runs.lines().count(), 71);

    let check = |text: &str| {
        ShardFile::parse(text, Path::new("f.json"))
            .unwrap_err()
            .to_string()
    };
    let lines: Vec<&str> = runs.lines().collect();
    let err = check(&runs[..runs.len() - 10]);
    assert!(err.contains("f.json: line 71 is not a run"), "{err}");
    // An editor's final blank line, a CRLF copy, a byte-order mark: the same shard.
    let parsed = |text: &str| ShardFile::parse(text, Path::new("f.json")).unwrap();
    let reference = parsed(&runs);
    assert_eq!(parsed(&(runs.clone() + "\n \r\n")), reference);
    assert_eq!(parsed(&runs.replace('\n', "\r\n")), reference);
    assert_eq!(parsed(&format!("\u{feff}{runs}")), reference);
    // A blank line between runs is skipped and counted in the lines of later messages.
    let spaced = runs.replacen(lines[2], &format!("\n{}", lines[2]), 1);
    assert_eq!(parsed(&spaced), reference);
    let err = check(&(spaced + lines[70] + "\n"));
    assert!(
        err.contains("line 73: more lines than the 70 runs"),
        "{err}"
    );
    // A malformed run names the field at fault.
    let completed = lines[2].find("\"outcome\":{").unwrap() + "\"outcome\":".len();
    let blank = format!("{}{{}}}}", &lines[2][..completed]);
    let err = check(&runs.replacen(lines[2], &blank, 1));
    assert!(
        err.contains("f.json: line 3 is not a run: outcome: "),
        "{err}"
    );
    let typed = lines[2].replacen(
        "\"tip_error_rms_m\":",
        "\"tip_error_rms_m\":\"a\",\"x\":",
        1,
    );
    let err = check(&runs.replacen(lines[2], &typed, 1));
    assert!(
        err.contains("line 3 is not a run: outcome.completed.tip_error_rms_m: invalid type"),
        "{err}"
    );
    let err = check(&(lines[..70].join("\n") + "\n"));
    assert!(
        err.contains("cut short: it holds 69 of the 70 runs"),
        "{err}"
    );
    let err = check(&(runs.clone() + lines[70] + "\n"));
    assert!(
        err.contains("line 72: more lines than the 70 runs"),
        "{err}"
    );
    let err = check(&runs.replacen("\"index\":5,", "\"index\":18446744073709551615,", 1));
    assert!(
        err.contains("holds run 18446744073709551615 (controller ")
            && err.contains("which is not run 5 of this sweep (controller "),
        "{err}"
    );
    // A run whose index is right and whose controller is not: the message says which differs.
    let first = lines[1];
    let controller = first
        .split("\"controller\":\"")
        .nth(1)
        .unwrap()
        .split('"')
        .next()
        .unwrap();
    let other = if controller == "pd" { "lqr" } else { "pd" };
    let edited = first.replacen(
        &format!("\"controller\":\"{controller}\""),
        &format!("\"controller\":\"{other}\""),
        1,
    );
    let err = check(&runs.replacen(first, &edited, 1));
    assert!(
        err.contains(&format!("holds run 0 (controller {other}, "))
            && err.contains(&format!(
                "which is not run 0 of this sweep (controller {controller}, "
            )),
        "{err}"
    );
    let older = "{\n  \"format\": \"hrm-sweep-shard/2\",\n  \"runs\": []\n}\n";
    let err = check(older);
    assert!(
        err.contains("(format \"hrm-sweep-shard/2\", expected \"hrm-sweep-shard/4\")")
            && err.contains("older versions cannot be merged"),
        "{err}"
    );
    // Format 3: JSON lines, the sweep's settings beside the scenario rather than nested.
    let err = check(&runs.replacen("hrm-sweep-shard/4", "hrm-sweep-shard/3", 1));
    assert!(
        err.contains("(format \"hrm-sweep-shard/3\", expected \"hrm-sweep-shard/4\")")
            && err.contains("older versions cannot be merged"),
        "{err}"
    );
    let edited = runs.replacen("\"duration\":0.02", "\"duration\":0.03", 1);
    let err = check(&edited);
    assert!(err.contains("SHA-256 does not match its content"), "{err}");
    // A current header that is no longer JSON (a NaN written in) is malformed, not "older".
    let err = check(&runs.replacen("\"duration\":0.02", "\"duration\":NaN", 1));
    assert!(
        err.contains("has a malformed header: its first line is not JSON")
            && !err.contains("older versions"),
        "{err}"
    );
    // Issue 32: a hand-edited metric is checked like any input, by field, before it is averaged.
    let metric = |key: &str, value: &str| {
        let line = lines[3];
        let start = line.find(&format!("\"{key}\":")).unwrap() + key.len() + 3;
        let end = start + line[start..].find([',', '}', ']']).unwrap();
        let line = format!("{}{value}{}", &line[..start], &line[end..]);
        let mut edited: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
        edited[3] = line;
        check(&(edited.join("\n") + "\n"))
    };
    let err = metric("tip_error_rms_m", "-1.586");
    assert!(
        err.contains("f.json: line 4: run 2: tip_error_rms_m = -1.586"),
        "{err}"
    );
    let err = metric("peak_joint_torque_nm", "1e308");
    assert!(
        err.contains("peak_joint_torque_nm = 1e308 is not a metric"),
        "{err}"
    );
    let err = metric("tip_error_max_m", "0");
    assert!(
        err.contains("tip_error_max_m = 0 is below tip_error_rms_m"),
        "{err}"
    );
    let err = metric("modal_error_rms_rad", "[4");
    assert!(
        err.contains("exceeds the scenario's runaway bound"),
        "{err}"
    );
    std::fs::remove_dir_all(&root).unwrap();
}

#[test]
fn a_shard_replaces_only_its_own_file_and_never_enters_another_commands_folder() {
    let root = temp_dir("shard-guards");
    let shard_args = |out: &Path| {
        let out = out.to_str().unwrap().to_string();
        move || hrm_sweep(&with(TINY, &["--shard", "1/2", "--out", &out]))
    };
    // The user's own file of that name is refused, and left as it was.
    let user = root.join("user");
    std::fs::create_dir_all(&user).unwrap();
    let mine = user.join("shard-1-of-2.json");
    std::fs::write(&mine, "my notes").unwrap();
    let err = shard_args(&user)().unwrap_err();
    assert!(
        err.contains("shard-1-of-2.json: exists and hrm did not write it"),
        "{err}"
    );
    assert_eq!(read(&mine), "my notes");
    // A shard file of hrm's is replaced (a shard run again).
    std::fs::remove_file(&mine).unwrap();
    shard_args(&user)().unwrap();
    let first = read(&mine);
    assert!(
        first.starts_with("{\"format\":\"hrm-sweep-shard/"),
        "{first}"
    );
    shard_args(&user)().unwrap();
    assert_eq!(read(&mine), first);
    // The output folder of another command, which replaces it whole, is refused.
    let simulated = root.join("simulated");
    std::fs::create_dir_all(&simulated).unwrap();
    std::fs::write(
        simulated.join(output_dir::MARKER),
        "written by `hrm simulate`\n",
    )
    .unwrap();
    let err = shard_args(&simulated)().unwrap_err();
    assert!(
        err.ends_with(
            "simulated: holds the output of `hrm simulate`, which replaces its folder whole; \
             write the shard file into a folder of its own"
        ),
        "{err}"
    );
    assert!(!simulated.join("shard-1-of-2.json").exists());
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn a_shard_edited_with_its_digest_is_still_checked_as_a_sweep() {
    // A hand-edited header whose digest was recomputed reads, but a scenario `hrm sweep` would
    // refuse is not merged; nor is a failed run that stopped after its scenario's end.
    let root = temp_dir("shard-edited");
    let out = root.join("shards");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    hrm_sweep(&with(TINY, &["--shard", "1/1", "--out", &s(&out)])).unwrap();
    let path = out.join("shard-1-of-1.json");
    let file = ShardFile::parse(&read(&path), &path).unwrap();
    let mut bad = file.clone();
    bad.config.scenario.duration = -1.0;
    bad.config.inputs = study::input_digests(&bad.config.scenario).unwrap();
    let err = study::merge(vec![(path.clone(), bad)])
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("shard-1-of-1.json holds an invalid sweep configuration: ")
            && err.contains("duration"),
        "{err}"
    );
    let mut late = file.clone();
    late.runs[1].outcome = StoredOutcome::Failed {
        error: "runaway".into(),
        simulated_s: 1e308,
    };
    let err = study::merge(vec![(path.clone(), late)])
        .unwrap_err()
        .to_string();
    assert!(
        err.contains(
            "run 1: simulated_s = 1e308 must be finite, non-negative and at most the scenario's \
             duration, 0.05 s"
        ),
        "{err}"
    );
    // A failed run's message as a sweep writes it: one line, of bounded length.
    for error in [
        "x\nforged line".into(),
        "x\u{1b}[31m\u{202e}".into(),
        "A".repeat(3000),
        String::new(),
        "  ".into(),
    ] {
        let mut bad = file.clone();
        bad.runs[1].outcome = StoredOutcome::Failed {
            error,
            simulated_s: 0.05,
        };
        let err = study::merge(vec![(path.clone(), bad)])
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("run 1: outcome.failed.error is not a message a sweep writes")
                && !err.contains("forged"),
            "{err}"
        );
    }
    // A negative zero is not the sweep's noise level 0, nor a time reached.
    let mut signed = file.clone();
    signed.runs[0].noise_level = -0.0;
    let err = study::merge(vec![(path.clone(), signed)])
        .unwrap_err()
        .to_string();
    assert!(err.contains("line 2") && err.contains("run 0"), "{err}");
    let mut signed = file.clone();
    signed.runs[1].outcome = StoredOutcome::Failed {
        error: "runaway".into(),
        simulated_s: -0.0,
    };
    let err = study::merge(vec![(path.clone(), signed)])
        .unwrap_err()
        .to_string();
    assert!(err.contains("run 1: simulated_s = -0 must be"), "{err}");
    // A key given twice in the header, as in a run's line.
    let text = read(&path);
    let doubled = text.replacen("{\"format\":", "{\"format\":\"x\",\"format\":", 1);
    assert_ne!(doubled, text);
    let err = ShardFile::parse(&doubled, &path).unwrap_err().to_string();
    assert!(err.contains("duplicate field `format`"), "{err}");
    let mut on_time = file;
    on_time.runs[1].outcome = StoredOutcome::Failed {
        error: "runaway".into(),
        simulated_s: 0.05,
    };
    study::merge(vec![(path, on_time)]).unwrap();
    let _ = std::fs::remove_dir_all(&root);
}
