//! `cargo xtask bench --check`: hrm's benches measured against the anchors (Pinocchio,
//! fuzzylite, Crocoddyl) in the same invocation, interleaved, and the targets of
//! `benches/targets.toml` checked on the medians.
//!
//! A round runs every `[[runner]]` of `benches/targets.toml` (the anchors' harnesses under
//! `benches/`, and hrm programs whose figures are not Criterion's), then the Criterion benches the
//! targets name (filtered to exactly those ids, with short warm-up and measurement times).
//! Rounds repeat (A B A B ...), so a change of the host's clock or load between the two halves of a
//! ratio shows as a spread across rounds instead of a bias. A ratio target is checked on the
//! median over the rounds of the ratio within each round; a bound on one figure on its median.
//! Every figure of every round goes to `target/bench-check.json`.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::SystemTime;

/// Options of `bench --check`.
pub struct Options {
    /// Rounds of runners and Criterion benches.
    pub rounds: usize,
    /// Criterion's measurement time per bench and round, seconds.
    pub measurement_seconds: f64,
    /// Only targets whose id or reference contains this (and the runners they need).
    pub only: Option<String>,
}

/// The most rounds `--rounds` accepts.
pub const MAX_ROUNDS: usize = 50;

/// A program run once a round: `build` once before the first round, then `run`; every line of
/// its standard output of the form `<id> <value> <unit>` with `id` starting with `prefix` is a
/// figure.
struct Runner {
    name: String,
    prefix: String,
    needs: String,
    build: Option<Vec<String>>,
    run: Vec<String>,
}

/// One target of `benches/targets.toml`.
enum Target {
    /// `[[max]]`: the median of `id` at most `limit` (nanoseconds).
    Max { id: String, limit: f64 },
    /// `[[speedup]]`: `over / id` at least `factor`.
    Speedup {
        id: String,
        over: String,
        factor: f64,
    },
    /// `[[scaling]]`: `id / over` at most `factor`.
    Scaling {
        id: String,
        over: String,
        factor: f64,
    },
    /// `[[accuracy]]`: `id <= (1 + within) than`.
    Accuracy {
        id: String,
        than: String,
        within: f64,
    },
}

impl Target {
    /// The figures the target needs.
    fn ids(&self) -> Vec<&str> {
        match self {
            Self::Max { id, .. } => vec![id],
            Self::Speedup { id, over, .. } | Self::Scaling { id, over, .. } => vec![id, over],
            Self::Accuracy { id, than, .. } => vec![id, than],
        }
    }
}

/// Figures of one round: id -> value (nanoseconds for a time, metres for a length).
type Round = BTreeMap<String, f64>;

/// Runs the check; fails if a target falls short (a target left unmeasured is reported, not
/// failed: an engine may be missing on this machine).
pub fn run(root: &Path, target_dir: &Path, options: &Options) -> Result<(), String> {
    let targets_path = root.join("benches").join("targets.toml");
    let text = std::fs::read_to_string(&targets_path)
        .map_err(|e| format!("{}: {e}", targets_path.display()))?;
    let table: toml::Table =
        toml::from_str(&text).map_err(|e| format!("{}: {e}", targets_path.display()))?;
    let runners = parse_runners(&table)?;
    let mut targets = parse_targets(&table)?;
    if let Some(only) = &options.only {
        targets.retain(|t| t.ids().iter().any(|id| id.contains(only.as_str())));
        if targets.is_empty() {
            return Err(format!(
                "no target of benches/targets.toml mentions `{only}`"
            ));
        }
    }
    let wanted: BTreeSet<&str> = targets.iter().flat_map(Target::ids).collect();
    let runner_of = |id: &str| runners.iter().position(|r| id.starts_with(&r.prefix));
    let used: BTreeSet<usize> = wanted.iter().filter_map(|id| runner_of(id)).collect();
    let criterion_ids: Vec<&str> = wanted
        .iter()
        .copied()
        .filter(|id| runner_of(id).is_none())
        .collect();

    let python = bench_python(root, target_dir);
    let work = target_dir.join("bench-anchors");
    std::fs::create_dir_all(&work).map_err(|e| format!("{}: {e}", work.display()))?;
    let env = [
        ("PYTHON", python.to_string_lossy().into_owned()),
        ("HRM_BENCH_DIR", work.to_string_lossy().into_owned()),
    ];
    // Build everything first, so that no round pays for a compilation.
    let mut missing: BTreeMap<usize, String> = BTreeMap::new();
    for &index in &used {
        let runner = &runners[index];
        if let Some(build) = &runner.build {
            println!("xtask: building runner `{}`", runner.name);
            if let Err(reason) = capture(root, build, &env) {
                println!("xtask: runner `{}` unavailable: {reason}", runner.name);
                missing.insert(index, format!("{} ({})", reason, runner.needs));
            }
        }
    }
    if !criterion_ids.is_empty() {
        crate::cargo(&["bench", "--package", "hrm-benches", "--no-run"], &[])?;
    }

    let filter = format!(
        "^({})$",
        criterion_ids
            .iter()
            .map(|id| regex_escape(id))
            .collect::<Vec<_>>()
            .join("|")
    );
    let measurement = format!("{}", options.measurement_seconds);
    let warm_up = format!("{}", (options.measurement_seconds / 2.0).max(0.5));
    let mut rounds: Vec<Round> = Vec::new();
    for r in 0..options.rounds {
        let mut round = Round::new();
        for &index in &used {
            if missing.contains_key(&index) {
                continue;
            }
            let runner = &runners[index];
            println!(
                "xtask: round {}/{}: runner `{}`",
                r + 1,
                options.rounds,
                runner.name
            );
            match capture(root, &runner.run, &env) {
                Ok(out) => {
                    for line in out.lines() {
                        if let Some((id, value)) = parse_figure(line)
                            && id.starts_with(&runner.prefix)
                        {
                            round.insert(id.to_string(), value);
                        }
                    }
                }
                Err(reason) => {
                    println!("xtask: runner `{}` failed: {reason}", runner.name);
                    missing.insert(index, reason);
                }
            }
        }
        if !criterion_ids.is_empty() {
            println!(
                "xtask: round {}/{}: {} Criterion bench(es)",
                r + 1,
                options.rounds,
                criterion_ids.len()
            );
            let started = SystemTime::now();
            let args = [
                "bench",
                "--package",
                "hrm-benches",
                "--",
                "--noplot",
                "--warm-up-time",
                &warm_up,
                "--measurement-time",
                &measurement,
                &filter,
            ];
            capture(
                root,
                &std::iter::once(cargo_program())
                    .chain(args.iter().map(|a| a.to_string()))
                    .collect::<Vec<_>>(),
                &[],
            )?;
            let mut rows = Vec::new();
            crate::collect_medians(&target_dir.join("criterion"), &mut rows, Some(started))?;
            for (id, ns) in rows {
                if criterion_ids.contains(&id.as_str()) {
                    round.insert(id, ns);
                }
            }
        }
        rounds.push(round);
    }
    write_rounds(target_dir, &rounds)?;
    report(&targets, &rounds, &runners, &missing, &runner_of)
}

/// Prints every target with both figures (medians over the rounds) and the verdict.
fn report(
    targets: &[Target],
    rounds: &[Round],
    runners: &[Runner],
    missing: &BTreeMap<usize, String>,
    runner_of: &dyn Fn(&str) -> Option<usize>,
) -> Result<(), String> {
    let median_of = |id: &str| median(rounds.iter().filter_map(|r| r.get(id).copied()).collect());
    // The ratio within each round, then the median and range of those.
    let ratios = |num: &str, den: &str| -> Vec<f64> {
        rounds
            .iter()
            .filter_map(|r| Some(r.get(num)? / r.get(den)?))
            .collect()
    };
    let why = |id: &str| match runner_of(id).and_then(|i| missing.get(&i).map(|m| (i, m))) {
        Some((i, reason)) => format!("not measured: runner `{}`: {reason}", runners[i].name),
        None => format!("not measured: `{id}` gave no figure"),
    };
    let (mut short, mut unmeasured) = (0usize, 0usize);
    let width = targets
        .iter()
        .map(|t| t.ids()[0].len())
        .max()
        .unwrap_or(0)
        .max(6);
    println!(
        "\n{:<width$}  {:>10}  {:<34}  {:>10}  {:>21}  {:<24}  result",
        "target", "hrm", "against", "there", "measured [range]", "wanted"
    );
    let mut verdict = |ok: bool| {
        short += usize::from(!ok);
        if ok { "ok" } else { "SHORT" }
    };
    for target in targets {
        match target {
            Target::Max { id, limit } => match median_of(id) {
                Some(ns) => {
                    let v = verdict(ns <= *limit);
                    println!(
                        "{id:<width$}  {:>10}  {:<34}  {:>10}  {:>21}  {:<24}  {v}",
                        human(id, ns),
                        "(no anchor)",
                        "",
                        "",
                        format!("<= {}", human(id, *limit))
                    );
                }
                None => {
                    unmeasured += 1;
                    println!("{id:<width$}  {}", why(id));
                }
            },
            Target::Speedup { id, over, factor }
            | Target::Scaling { id, over, factor }
            | Target::Accuracy {
                id,
                than: over,
                within: factor,
            } => {
                let (num, den) = match target {
                    Target::Speedup { .. } => (over, id),
                    _ => (id, over),
                };
                let r = ratios(num, den);
                let (Some(mid), Some(a), Some(b)) =
                    (median(r.clone()), median_of(id), median_of(over))
                else {
                    unmeasured += 1;
                    let absent = if median_of(id).is_none() { id } else { over };
                    println!("{id:<width$}  {}", why(absent));
                    continue;
                };
                let lo = r.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = r.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                let (ok, wanted) = match target {
                    Target::Speedup { .. } => (mid >= *factor, format!(">= {factor}x faster")),
                    Target::Scaling { .. } => (mid <= *factor, format!("<= {factor}x")),
                    _ => (
                        mid <= 1.0 + factor,
                        format!("<= {:.0}% above", factor * 100.0),
                    ),
                };
                let v = verdict(ok);
                println!(
                    "{id:<width$}  {:>10}  {over:<34}  {:>10}  {:>21}  {wanted:<24}  {v}",
                    human(id, a),
                    human(over, b),
                    format!("{mid:.3}x [{lo:.3}-{hi:.3}]")
                );
            }
        }
    }
    println!(
        "\n{short} target(s) short, {unmeasured} not measured; {} round(s), figures in target/bench-check.json",
        rounds.len()
    );
    if short == 0 {
        Ok(())
    } else {
        Err(format!("{short} bench target(s) fall short"))
    }
}

fn median(mut values: Vec<f64>) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    let n = values.len();
    Some(if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    })
}

/// A figure in the units of its id: lengths (ids ending in `_m`) in millimetres, else a time.
fn human(id: &str, value: f64) -> String {
    if id.ends_with("_m") {
        format!("{:.3} mm", value * 1e3)
    } else {
        crate::human_time(value)
    }
}

/// `<id> <value> <unit>`, the value converted to nanoseconds or metres.
fn parse_figure(line: &str) -> Option<(&str, f64)> {
    let mut words = line.split_whitespace();
    let (id, value, unit) = (words.next()?, words.next()?, words.next()?);
    if words.next().is_some() {
        return None;
    }
    let value: f64 = value.parse().ok().filter(|v: &f64| v.is_finite())?;
    let scale = match unit {
        "ns" | "m" => 1.0,
        "us" => 1e3,
        "ms" => 1e6,
        "s" => 1e9,
        "mm" => 1e-3,
        _ => return None,
    };
    Some((id, value * scale))
}

fn regex_escape(id: &str) -> String {
    id.chars()
        .flat_map(|c| {
            let special = "\\.+*?()|[]{}^$".contains(c);
            special
                .then_some('\\')
                .into_iter()
                .chain(std::iter::once(c))
        })
        .collect()
}

fn cargo_program() -> String {
    std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_string())
}

/// Runs `argv` in the workspace root with `env`; its standard output, or the reason it failed
/// (the last line of its standard error).
fn capture(root: &Path, argv: &[String], env: &[(&str, String)]) -> Result<String, String> {
    let (program, args) = argv.split_first().ok_or("an empty command")?;
    let out = Command::new(program)
        .args(args)
        .envs(env.iter().map(|(k, v)| (*k, v.as_str())))
        .current_dir(root)
        .stdin(Stdio::null())
        .output()
        .map_err(|e| format!("cannot run `{program}`: {e}"))?;
    if out.status.success() {
        Ok(String::from_utf8_lossy(&out.stdout).into_owned())
    } else {
        let stderr = String::from_utf8_lossy(&out.stderr);
        let last = stderr.lines().rev().find(|l| !l.trim().is_empty());
        Err(format!(
            "`{}` failed ({}): {}",
            argv.join(" "),
            out.status,
            last.unwrap_or("no message")
        ))
    }
}

/// The Python of the anchors' harnesses: a virtual environment `target/bench-venv` with
/// `benches/requirements.txt` installed (created on first use; needs network access to PyPI).
/// Falls back to `$PYTHON` or `python3` if it cannot be made; the runners needing a package
/// then report it missing.
fn bench_python(root: &Path, target_dir: &Path) -> PathBuf {
    let venv = target_dir.join("bench-venv");
    let python = venv.join("bin").join("python");
    let system = PathBuf::from(std::env::var("PYTHON").unwrap_or_else(|_| "python3".to_string()));
    let requirements = root.join("benches").join("requirements.txt");
    let stamp = venv.join("requirements.installed");
    let current = std::fs::read_to_string(&requirements).ok();
    if python.exists() && std::fs::read_to_string(&stamp).ok() == current {
        return python;
    }
    let made =
        python.exists() || crate::run(&system, &["-m", "venv", &venv.to_string_lossy()]).is_ok();
    let installed = made
        && crate::run(
            &python,
            &[
                "-m",
                "pip",
                "install",
                "--quiet",
                "--disable-pip-version-check",
                "-r",
                &requirements.to_string_lossy(),
            ],
        )
        .is_ok();
    if installed {
        if let Some(text) = current {
            let _ = std::fs::write(&stamp, text);
        }
        python
    } else {
        println!(
            "xtask: no bench virtual environment; the anchors run with {}",
            system.display()
        );
        system
    }
}

fn write_rounds(target_dir: &Path, rounds: &[Round]) -> Result<(), String> {
    let value = serde_json::Value::Array(
        rounds
            .iter()
            .map(|r| {
                serde_json::Value::Object(
                    r.iter()
                        .map(|(k, v)| (k.clone(), serde_json::Value::from(*v)))
                        .collect(),
                )
            })
            .collect(),
    );
    let path = target_dir.join("bench-check.json");
    let text = serde_json::to_string_pretty(&value).map_err(|e| e.to_string())?;
    std::fs::write(&path, text + "\n").map_err(|e| format!("{}: {e}", path.display()))
}

fn entries<'a>(table: &'a toml::Table, kind: &str) -> Result<Vec<&'a toml::Table>, String> {
    match table.get(kind) {
        None => Ok(Vec::new()),
        Some(toml::Value::Array(items)) => items
            .iter()
            .map(|item| {
                item.as_table()
                    .ok_or_else(|| format!("[[{kind}]] entries must be tables"))
            })
            .collect(),
        Some(_) => Err(format!("`{kind}` must be an array of tables ([[{kind}]])")),
    }
}

fn string(table: &toml::Table, kind: &str, key: &str) -> Result<String, String> {
    table
        .get(key)
        .and_then(toml::Value::as_str)
        .map(str::to_owned)
        .ok_or_else(|| format!("a [[{kind}]] entry lacks the string `{key}`: {table}"))
}

fn number(table: &toml::Table, kind: &str, key: &str) -> Result<f64, String> {
    match table.get(key) {
        Some(toml::Value::Float(x)) if x.is_finite() && *x >= 0.0 => Ok(*x),
        Some(toml::Value::Integer(x)) if *x >= 0 => Ok(*x as f64),
        _ => Err(format!(
            "a [[{kind}]] entry lacks the non-negative number `{key}`: {table}"
        )),
    }
}

fn command(table: &toml::Table, key: &str) -> Result<Option<Vec<String>>, String> {
    match table.get(key) {
        None => Ok(None),
        Some(toml::Value::Array(items)) if !items.is_empty() => items
            .iter()
            .map(|v| {
                v.as_str()
                    .map(str::to_owned)
                    .ok_or_else(|| format!("[[runner]] `{key}` must be strings: {table}"))
            })
            .collect::<Result<Vec<_>, _>>()
            .map(Some),
        Some(_) => Err(format!(
            "[[runner]] `{key}` must be a non-empty array of strings: {table}"
        )),
    }
}

fn parse_runners(table: &toml::Table) -> Result<Vec<Runner>, String> {
    entries(table, "runner")?
        .into_iter()
        .map(|t| {
            let cargo = cargo_program();
            // `cargo` in a command is the cargo running xtask.
            let resolve = |argv: Vec<String>| -> Vec<String> {
                argv.into_iter()
                    .enumerate()
                    .map(|(i, a)| {
                        if i == 0 && a == "cargo" {
                            cargo.clone()
                        } else {
                            a
                        }
                    })
                    .collect()
            };
            Ok(Runner {
                name: string(t, "runner", "name")?,
                prefix: string(t, "runner", "prefix")?,
                needs: string(t, "runner", "needs")?,
                build: command(t, "build")?.map(resolve),
                run: command(t, "run")?
                    .map(resolve)
                    .ok_or_else(|| format!("a [[runner]] entry lacks `run`: {t}"))?,
            })
        })
        .collect()
}

fn parse_targets(table: &toml::Table) -> Result<Vec<Target>, String> {
    let mut targets = Vec::new();
    for t in entries(table, "max")? {
        targets.push(Target::Max {
            id: string(t, "max", "id")?,
            limit: number(t, "max", "ns")?,
        });
    }
    for t in entries(table, "speedup")? {
        targets.push(Target::Speedup {
            id: string(t, "speedup", "id")?,
            over: string(t, "speedup", "over")?,
            factor: number(t, "speedup", "at_least")?,
        });
    }
    for t in entries(table, "scaling")? {
        targets.push(Target::Scaling {
            id: string(t, "scaling", "id")?,
            over: string(t, "scaling", "over")?,
            factor: number(t, "scaling", "at_most")?,
        });
    }
    for t in entries(table, "accuracy")? {
        targets.push(Target::Accuracy {
            id: string(t, "accuracy", "id")?,
            than: string(t, "accuracy", "than")?,
            within: number(t, "accuracy", "within")?,
        });
    }
    Ok(targets)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_parse_with_their_units() {
        assert_eq!(
            parse_figure("pinocchio/aba/10 2.5 us"),
            Some(("pinocchio/aba/10", 2500.0))
        );
        assert_eq!(
            parse_figure("x/tip_rms_m 4.8 mm"),
            Some(("x/tip_rms_m", 4.8e-3))
        );
        assert_eq!(parse_figure("  check: qdd 1.0"), None);
        assert_eq!(parse_figure("a nan ns"), None);
        assert_eq!(parse_figure("a 1 furlong"), None);
    }

    #[test]
    fn medians_and_escapes() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(vec![4.0, 1.0]), Some(2.5));
        assert_eq!(median(vec![]), None);
        assert_eq!(regex_escape("fuzzy/paper"), "fuzzy/paper");
        assert_eq!(regex_escape("a.b(c)"), "a\\.b\\(c\\)");
    }
}
