use super::*;
use clap::Parser;
use sim_core::study::RunMetrics;

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
fn the_command_line_parses_with_defaults_and_merge() {
    let cli = parse(&[]).unwrap();
    assert!(cli.command.is_none());
    let a = &cli.sweep;
    assert_eq!(a.scenario, "paper-tracking");
    assert_eq!(a.controllers, ControllerKind::ALL);
    assert_eq!(a.noise, [0.0, 0.005, 0.01, 0.02, 0.05, 0.1]);
    assert_eq!((a.seeds, a.base_seed, a.shard), (10, 1, None));
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
    assert_eq!(whole_runs.runs.len(), 2 * 3 * ControllerKind::ALL.len());
    let merged_runs = ShardFile::read(&merged.join("runs.json")).unwrap();
    assert_eq!(whole_runs.config, merged_runs.config);
    let indices = |f: &ShardFile| f.runs.iter().map(|r| r.index).collect::<Vec<_>>();
    assert_eq!(
        indices(&merged_runs),
        (0..2 * 3 * ControllerKind::ALL.len()).collect::<Vec<_>>()
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
    cut.runs.pop();
    let cut_path = root.join("cut").join("shard-2-of-3.json");
    write(&cut_path, &cut.to_json().unwrap()).unwrap();
    let err = merge(&[shard(1), cut_path.clone(), shard(3)]);
    let missing = format!(
        "1 of {} runs are missing",
        2 * 3 * ControllerKind::ALL.len()
    );
    assert!(err.contains(&missing), "{err}");
    // A run moved to a shard it does not belong to.
    let mut moved = ShardFile::read(&shard(2)).unwrap();
    moved.runs[0].index = 0;
    write(&cut_path, &moved.to_json().unwrap()).unwrap();
    let err = merge(&[shard(1), cut_path.clone(), shard(3)]);
    assert!(err.contains("not run 0 of its shard"), "{err}");
    // A hand-edited configuration that makes no sweep.
    let mut empty = ShardFile::read(&shard(2)).unwrap();
    empty.config.seeds = 0;
    write(&cut_path, &empty.to_json().unwrap()).unwrap();
    let err = merge(&[shard(1), cut_path.clone(), shard(3)]);
    assert!(
        err.contains("invalid sweep configuration: --seeds"),
        "{err}"
    );
    // Counts no sweep could have are refused before anything is sized by them.
    let mut huge = ShardFile::read(&shard(2)).unwrap();
    huge.config.seeds = 1 << 50;
    write(&cut_path, &huge.to_json().unwrap()).unwrap();
    let err = merge(std::slice::from_ref(&cut_path));
    assert!(err.contains("runs allowed"), "{err}");
    let mut split = ShardFile::read(&shard(2)).unwrap();
    split.shard.count = usize::MAX;
    write(&cut_path, &split.to_json().unwrap()).unwrap();
    let err = merge(std::slice::from_ref(&cut_path));
    assert!(err.contains("a split has 1 to 10000000"), "{err}");
    assert!(parse(&["--shard", "1/10000001"]).is_err());
    let mut short = ShardFile::read(&shard(2)).unwrap();
    if let Outcome::Completed(metrics) = &mut short.runs[0].outcome {
        metrics.modal_error_rms.pop();
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
    config.noise_levels = levels.to_vec();
    config
}

#[test]
fn a_run_in_a_sweep_is_the_scenario_run_alone_with_its_seed() {
    let config = small_config(&[0.0, 0.01], 2);
    let whole = run_shard(&config, Shard::WHOLE);
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
            Outcome::Completed(RunMetrics::from_summary(&alone.summary).unwrap()),
            "run {}",
            run.index
        );
    }
}

#[test]
fn noise_spreads_the_errors_and_no_noise_does_not() {
    let config = small_config(&[0.0, 0.01], 4);
    let whole = run_shard(&config, Shard::WHOLE);
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
        let n = noisy.modal_error_rms[0].unwrap();
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
    ])
    .unwrap();
    let config = configure(&args.sweep).unwrap();
    assert_eq!(config.runs(), Some(5 * 50 * ControllerKind::ALL.len()));
    let whole = run_shard(&config, Shard::WHOLE);
    let text = whole.to_json().unwrap();
    let parsed = ShardFile::parse(&text, Path::new("memory")).unwrap();
    let cells = study::cells(&parsed.config, &parsed.runs);
    assert_eq!(cells.len(), 5 * ControllerKind::ALL.len());
    for cell in &cells {
        assert_eq!((cell.runs, cell.failed), (50, 0), "{cell:?}");
        assert_eq!(cell.modal_error_rms.len(), 2);
        for stats in [
            cell.tip_error_rms_mm,
            cell.tip_error_max_mm,
            cell.peak_joint_torque_nm,
        ]
        .into_iter()
        .chain(cell.modal_error_rms.iter().copied())
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
