//! MATLAB's `.fis` text format for Sugeno systems: `[System]`, `[InputN]`, `[OutputN]` and
//! `[Rules]` sections, rule lines like `1 -2 0, 3 (0.5) : 1`.
//!
//! Writing then reading gives back the identical system (numbers are written in the shortest
//! form that parses back to the same `f64`). Reading accepts what MATLAB's `readfis` reads,
//! including the habits of files written by older MATLAB releases, Octave's fuzzy-logic-toolkit
//! and fuzzylite (`docs/fuzzy-formats.md` lists them); what it accepts but does not keep or use is
//! reported as [`FisNote`]s. Every malformed line is an error that gives its line number and
//! what was expected, and Mamdani systems are refused.

use crate::error::FuzzyError;
use crate::membership::{MembershipFn, format_params};
use crate::system::{
    AndMethod, Antecedent, Connective, Defuzzification, FuzzySet, FuzzySystem, InputVariable,
    Methods, OrMethod, OutputFn, OutputTerm, OutputVariable, Rule, check_name, check_rule,
};
use std::collections::HashMap;
use std::fmt::Write as _;

impl FuzzySystem {
    /// Reads a Sugeno system from the text of a MATLAB `.fis` file.
    ///
    /// ```
    /// use fuzzy_sugeno::{paper_controller, FuzzySystem};
    /// let text = paper_controller().to_fis();
    /// assert_eq!(FuzzySystem::from_fis(&text)?, paper_controller());
    ///
    /// let error = FuzzySystem::from_fis("[System]\nName='x'\nType='mamdani'\n").unwrap_err();
    /// assert!(error.to_string().starts_with("line 3: Mamdani systems are not supported"));
    /// # Ok::<(), fuzzy_sugeno::FuzzyError>(())
    /// ```
    pub fn from_fis(text: &str) -> Result<Self, FuzzyError> {
        Self::from_fis_with_notes(text).map(|(system, _)| system)
    }

    /// Reads a Sugeno system like [`from_fis`](Self::from_fis), and also returns what the file
    /// said that was accepted but is neither kept in the system nor used by its evaluation:
    /// `ImpMethod`/`AggMethod` values other than `'prod'`/`'sum'`, an `AndMethod` or `OrMethod`
    /// that no rule needs and this crate cannot evaluate (such as fuzzylite's `''`), unknown
    /// keys (fuzzylite's `Enabled=1`, `LockRange=0`, ...), parameters beyond those a function
    /// takes, `MF` keys that disagree with their position (functions are read by position, as
    /// MATLAB does), and a `Version` other than 2.0.
    ///
    /// ```
    /// use fuzzy_sugeno::FuzzySystem;
    /// let text = "[System]\nName='s'\nType='sugeno'\nNumInputs=1\nNumOutputs=1\nNumRules=1\n\
    ///     AndMethod=''\nOrMethod=''\nImpMethod='min'\nAggMethod='max'\nDefuzzMethod='wtaver'\n\
    ///     [Input1]\nName='x'\nRange=[0 1]\nEnabled=1\nNumMFs=1\nMF1='a':'gbellmf',[1 2 0 9]\n\
    ///     [Output1]\nName='y'\nRange=[0 1]\nNumMFs=1\nMF1='c':'constant',[0.5]\n\
    ///     [Rules]\n1.000 , 1.000 (1.000) : 1\n";
    /// let (system, notes) = FuzzySystem::from_fis_with_notes(text)?;
    /// assert_eq!(system.inputs()[0].sets.len(), 1);
    /// assert_eq!(notes.len(), 6); // AndMethod, OrMethod, ImpMethod, AggMethod, Enabled, [... 9]
    /// assert!(notes[0].to_string().starts_with("line 7: AndMethod=''"));
    /// # Ok::<(), fuzzy_sugeno::FuzzyError>(())
    /// ```
    pub fn from_fis_with_notes(text: &str) -> Result<(Self, Vec<FisNote>), FuzzyError> {
        let mut notes = Vec::new();
        let system = Parser::split(text)?.system(&mut notes)?;
        notes.sort_by_key(|note| note.line);
        Ok((system, notes))
    }

    /// Writes the system as the text of a MATLAB `.fis` file.
    pub fn to_fis(&self) -> String {
        let mut out = String::new();
        let methods = self.methods();
        let and = match methods.and {
            AndMethod::Product => "prod",
            AndMethod::Minimum => "min",
        };
        let or = match methods.or {
            OrMethod::ProbabilisticSum => "probor",
            OrMethod::Maximum => "max",
        };
        let defuzz = match methods.defuzzification {
            Defuzzification::WeightedAverage => "wtaver",
            Defuzzification::WeightedSum => "wtsum",
        };
        // Writing to a String cannot fail.
        let _ = write!(
            out,
            "[System]\nName='{}'\nType='sugeno'\nVersion=2.0\nNumInputs={}\nNumOutputs={}\nNumRules={}\n\
             AndMethod='{and}'\nOrMethod='{or}'\nImpMethod='prod'\nAggMethod='sum'\nDefuzzMethod='{defuzz}'\n",
            self.name(),
            self.inputs().len(),
            self.outputs().len(),
            self.rules().len(),
        );
        for (i, input) in self.inputs().iter().enumerate() {
            let _ = write!(out, "\n[Input{}]\n", i + 1);
            write_variable_header(&mut out, &input.name, input.range, input.sets.len());
            for (k, set) in input.sets.iter().enumerate() {
                let mf = &set.membership;
                let _ = writeln!(
                    out,
                    "MF{}='{}':'{}',{}",
                    k + 1,
                    set.name,
                    mf.matlab_name(),
                    fis_numbers(&mf.params())
                );
            }
        }
        for (o, output) in self.outputs().iter().enumerate() {
            let _ = write!(out, "\n[Output{}]\n", o + 1);
            write_variable_header(&mut out, &output.name, output.range, output.terms.len());
            for (k, term) in output.terms.iter().enumerate() {
                let (kind, params) = match &term.function {
                    OutputFn::Constant(c) => ("constant", vec![*c]),
                    OutputFn::Linear {
                        coefficients,
                        constant,
                    } => (
                        "linear",
                        coefficients.iter().copied().chain([*constant]).collect(),
                    ),
                };
                let _ = writeln!(
                    out,
                    "MF{}='{}':'{kind}',{}",
                    k + 1,
                    term.name,
                    fis_numbers(&params)
                );
            }
        }
        out.push_str("\n[Rules]\n");
        for rule in self.rules() {
            let antecedents: Vec<String> = rule
                .antecedents
                .iter()
                .map(|a| match *a {
                    Antecedent::Any => "0".to_string(),
                    Antecedent::Is(k) => (k + 1).to_string(),
                    Antecedent::IsNot(k) => format!("-{}", k + 1),
                })
                .collect();
            let consequents: Vec<String> = rule
                .consequents
                .iter()
                .map(|c| c.map_or(0, |k| k + 1).to_string())
                .collect();
            let connective = match rule.connective {
                Connective::And => 1,
                Connective::Or => 2,
            };
            let _ = writeln!(
                out,
                "{}, {} ({}) : {connective}",
                antecedents.join(" "),
                consequents.join(" "),
                fis_number(rule.weight)
            );
        }
        out
    }
}

fn write_variable_header(out: &mut String, name: &str, range: [f64; 2], count: usize) {
    let _ = write!(
        out,
        "Name='{name}'\nRange={}\nNumMFs={count}\n",
        fis_numbers(&range)
    );
}

/// The shortest decimal that parses back to the same `f64`, in exponent form for very large or
/// very small magnitudes.
fn fis_number(x: f64) -> String {
    let magnitude = x.abs();
    if magnitude != 0.0 && !(1e-5..1e15).contains(&magnitude) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

fn fis_numbers(values: &[f64]) -> String {
    let inner: Vec<String> = values.iter().map(|&v| fis_number(v)).collect();
    format!("[{}]", inner.join(" "))
}

/// Something a `.fis` file said that [`FuzzySystem::from_fis_with_notes`] accepted but neither
/// kept in the system nor used to evaluate it (so [`FuzzySystem::to_fis`] does not write it
/// back). Displayed as `line N: message`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FisNote {
    /// The 1-based line number.
    pub line: usize,
    /// What was ignored, and why that is harmless.
    pub message: String,
}

impl std::fmt::Display for FisNote {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "line {}: {}", self.line, self.message)
    }
}

fn note(notes: &mut Vec<FisNote>, line: usize, message: impl Into<String>) {
    notes.push(FisNote {
        line,
        message: message.into(),
    });
}

/// A `key=value` line or a rule line, with its 1-based line number.
#[derive(Debug, Clone, Copy)]
struct Line<'a> {
    number: usize,
    text: &'a str,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum SectionKind {
    System,
    Input(usize),
    Output(usize),
    Rules,
}

#[derive(Debug)]
struct Section<'a> {
    kind: SectionKind,
    header: usize,
    lines: Vec<Line<'a>>,
}

/// The file split into sections; turned into a system by [`Parser::system`].
struct Parser<'a> {
    sections: Vec<Section<'a>>,
    /// Where each kind of section is in `sections`: a file of 10^5 inputs is looked up in
    /// constant time a section, not by a scan.
    index: HashMap<SectionKind, usize>,
}

fn error(line: usize, message: impl Into<String>) -> FuzzyError {
    FuzzyError::Fis {
        line,
        message: message.into(),
    }
}

impl<'a> Parser<'a> {
    /// Splits the text into sections, skipping blank lines and comment lines (`%` in MATLAB's
    /// files, `#` in Octave's and fuzzylite's).
    fn split(text: &'a str) -> Result<Self, FuzzyError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut sections: Vec<Section<'a>> = Vec::new();
        let mut index = HashMap::new();
        for (line_index, raw) in text.lines().enumerate() {
            let number = line_index + 1;
            let line = raw.trim();
            if line.is_empty() || line.starts_with('%') || line.starts_with('#') {
                continue;
            }
            if let Some(name) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
                let kind = section_kind(name.trim()).ok_or_else(|| {
                    error(number, format!("unknown section [{name}]; expected [System], [InputN], [OutputN] or [Rules]"))
                })?;
                if let Some(&first) = index.get(&kind) {
                    let first: &Section<'_> = &sections[first];
                    return Err(error(
                        number,
                        format!(
                            "duplicate section [{name}] (first at line {})",
                            first.header
                        ),
                    ));
                }
                index.insert(kind, sections.len());
                sections.push(Section {
                    kind,
                    header: number,
                    lines: Vec::new(),
                });
                continue;
            }
            match sections.last_mut() {
                Some(section) => section.lines.push(Line { number, text: line }),
                None => {
                    return Err(error(
                        number,
                        format!("expected the [System] section header, found `{line}`"),
                    ));
                }
            }
        }
        Ok(Self { sections, index })
    }

    fn section(&self, kind: SectionKind) -> Option<&Section<'a>> {
        self.index.get(&kind).map(|&i| &self.sections[i])
    }

    fn system(&self, notes: &mut Vec<FisNote>) -> Result<FuzzySystem, FuzzyError> {
        let Some(section) = self.section(SectionKind::System) else {
            return Err(error(1, "expected a [System] section"));
        };
        let keys = Keys::new(
            section,
            &[
                "Name",
                "Type",
                "Version",
                "NumInputs",
                "NumOutputs",
                "NumRules",
                "AndMethod",
                "OrMethod",
                "ImpMethod",
                "AggMethod",
                "DefuzzMethod",
            ],
            false,
            notes,
        )?;
        // The type first, so that a Mamdani file is named as such whatever else it contains.
        let (line, kind) = keys.string("Type")?;
        match kind {
            "sugeno" => {}
            "mamdani" => {
                return Err(error(
                    line,
                    "Mamdani systems are not supported (this crate implements Takagi-Sugeno inference); \
                     expected Type='sugeno'",
                ));
            }
            other => {
                return Err(error(
                    line,
                    format!("expected Type='sugeno', found Type='{other}'"),
                ));
            }
        }
        let (line, name) = keys.string("Name")?;
        check_name("system", name).map_err(|problem| error(line, problem.to_string()))?;
        if let Some((line, version)) = keys.find("Version")
            && !matches!(version.trim_matches('\''), "2.0" | "2")
        {
            note(
                notes,
                line,
                format!(
                    "Version={version} is not used (every version is read alike; files are written with Version=2.0)"
                ),
            );
        }
        let n_inputs = keys.count("NumInputs", 1)?;
        let n_outputs = keys.count("NumOutputs", 1)?;
        let n_rules = match keys.find("NumRules") {
            Some(_) => Some(keys.count("NumRules", 0)?),
            None => None,
        };
        let and = keys.method(
            "AndMethod",
            &[("prod", AndMethod::Product), ("min", AndMethod::Minimum)],
        )?;
        let or = keys.method(
            "OrMethod",
            &[
                ("probor", OrMethod::ProbabilisticSum),
                ("max", OrMethod::Maximum),
            ],
        )?;
        let defuzzification = keys.choice(
            "DefuzzMethod",
            &[
                ("wtaver", Defuzzification::WeightedAverage),
                ("wtsum", Defuzzification::WeightedSum),
            ],
        )?;
        // MATLAB evaluates a Sugeno system as the weighted average (or sum) of its rule outputs
        // whatever these two say; any value is accepted and reported.
        for (key, standard) in [("ImpMethod", "prod"), ("AggMethod", "sum")] {
            if keys.find(key).is_some() {
                let (line, value) = keys.string(key)?;
                if value != standard {
                    note(
                        notes,
                        line,
                        format!(
                            "{key}='{value}' is not used: a Sugeno output is the weighted average (or sum) \
                             of the rule outputs whatever {key} says, as in MATLAB"
                        ),
                    );
                }
            }
        }
        for section in &self.sections {
            match section.kind {
                SectionKind::Input(k) if k > n_inputs => {
                    return Err(error(
                        section.header,
                        format!("section [Input{k}] but NumInputs={n_inputs}"),
                    ));
                }
                SectionKind::Output(k) if k > n_outputs => {
                    return Err(error(
                        section.header,
                        format!("section [Output{k}] but NumOutputs={n_outputs}"),
                    ));
                }
                _ => {}
            }
        }
        let header = section.header;
        let missing = |what: String, count: String| {
            error(header, format!("missing section [{what}] ({count})"))
        };
        let mut names: HashMap<String, usize> = HashMap::new();
        // No capacity from the counts: they are untrusted (a missing section ends the loop early).
        let mut inputs = Vec::new();
        for i in 1..=n_inputs {
            let section = self
                .section(SectionKind::Input(i))
                .ok_or_else(|| missing(format!("Input{i}"), format!("NumInputs={n_inputs}")))?;
            inputs.push(parse_input(section, &mut names, notes)?);
        }
        let mut outputs = Vec::new();
        for o in 1..=n_outputs {
            let section = self
                .section(SectionKind::Output(o))
                .ok_or_else(|| missing(format!("Output{o}"), format!("NumOutputs={n_outputs}")))?;
            outputs.push(parse_output(section, n_inputs, &mut names, notes)?);
        }
        let mut rule_lines = Vec::new();
        let rules = match (self.section(SectionKind::Rules), n_rules) {
            (Some(section), n_rules) => {
                if let Some(n_rules) = n_rules
                    && section.lines.len() != n_rules
                {
                    return Err(error(
                        section.header,
                        format!(
                            "NumRules={n_rules} but [Rules] has {} rule lines",
                            section.lines.len()
                        ),
                    ));
                }
                rule_lines.extend(section.lines.iter().map(|line| line.number));
                section
                    .lines
                    .iter()
                    .map(|line| parse_rule(*line, &inputs, &outputs))
                    .collect::<Result<Vec<_>, _>>()?
            }
            (None, None | Some(0)) => Vec::new(),
            (None, Some(n_rules)) => {
                return Err(missing("Rules".to_string(), format!("NumRules={n_rules}")));
            }
        };
        let methods = Methods {
            and: and.resolve(&rules, &rule_lines, Connective::And, notes)?,
            or: or.resolve(&rules, &rule_lines, Connective::Or, notes)?,
            defuzzification,
        };
        FuzzySystem::new(name.to_string(), inputs, outputs, rules, methods)
            .map_err(|e| error(header, e.to_string()))
    }
}

/// An `AndMethod` or `OrMethod` as read: one this crate evaluates, or another value (such as
/// fuzzylite's `''`) that is acceptable only if no rule needs it.
enum Method<'a, T> {
    Known(T),
    Other {
        key: &'static str,
        /// The line and value, `None` when the key is absent.
        found: Option<(usize, &'a str)>,
        /// The names this crate evaluates, and the default written back.
        options: &'a [(&'a str, T)],
    },
}

impl<T: Copy + Default> Method<'_, T> {
    /// The method, or the default if no rule needs it (noted), or an error naming the first
    /// rule that does. A rule needs its connective only to combine two or more antecedents:
    /// with a single one, every t-norm and s-norm gives that antecedent's degree.
    fn resolve(
        self,
        rules: &[Rule],
        rule_lines: &[usize],
        connective: Connective,
        notes: &mut Vec<FisNote>,
    ) -> Result<T, FuzzyError> {
        let (key, found, options) = match self {
            Self::Known(method) => return Ok(method),
            Self::Other {
                key,
                found,
                options,
            } => (key, found, options),
        };
        let list: Vec<String> = options.iter().map(|(n, _)| format!("'{n}'")).collect();
        let needs = rules.iter().zip(rule_lines).find(|(rule, _)| {
            rule.connective == connective
                && rule
                    .antecedents
                    .iter()
                    .filter(|a| **a != Antecedent::Any)
                    .count()
                    >= 2
        });
        match (needs, found) {
            (Some((_, &rule_line)), Some((line, value))) => Err(error(
                line,
                format!(
                    "expected {key}={}, found {key}='{value}' (the rule at line {rule_line} needs it)",
                    list.join(" or ")
                ),
            )),
            (Some((_, &rule_line)), None) => Err(error(
                rule_line,
                format!(
                    "this rule combines inputs but [System] has no {key}= line; expected {key}={}",
                    list.join(" or ")
                ),
            )),
            (None, Some((line, value))) => {
                note(
                    notes,
                    line,
                    format!(
                        "{key}='{value}' is not used by any rule (none combines two inputs with it); \
                         written back as '{}'",
                        options[0].0
                    ),
                );
                Ok(T::default())
            }
            (None, None) => Ok(T::default()),
        }
    }
}

fn section_kind(name: &str) -> Option<SectionKind> {
    let index = |digits: &str| digits.parse::<usize>().ok().filter(|&k| k >= 1);
    match name {
        "System" => Some(SectionKind::System),
        "Rules" => Some(SectionKind::Rules),
        _ => {
            if let Some(k) = name.strip_prefix("Input").and_then(index) {
                Some(SectionKind::Input(k))
            } else {
                name.strip_prefix("Output")
                    .and_then(index)
                    .map(SectionKind::Output)
            }
        }
    }
}

/// The `key=value` lines of one section, each key at most once.
struct Keys<'a> {
    section: String,
    header: usize,
    entries: Vec<(&'a str, &'a str, usize)>,
    /// The `MFk` lines, in file order (MATLAB's `readfis` reads them by position).
    function_entries: Vec<(&'a str, &'a str, usize)>,
    /// Keys outside the format (fuzzylite's `Enabled`, ...), with their lines: ignored.
    ignored: Vec<(&'a str, usize)>,
}

impl<'a> Keys<'a> {
    /// Collects the entries; `allowed` lists the plain keys, and `with_functions` allows the
    /// `MF1`, `MF2`, ... keys too (counted later against `NumMFs`). Other keys made of letters,
    /// digits and `_` are ignored, with a note; anything else is an error.
    fn new(
        section: &Section<'a>,
        allowed: &[&str],
        with_functions: bool,
        notes: &mut Vec<FisNote>,
    ) -> Result<Self, FuzzyError> {
        let title = match section.kind {
            SectionKind::System => "[System]".to_string(),
            SectionKind::Input(k) => format!("[Input{k}]"),
            SectionKind::Output(k) => format!("[Output{k}]"),
            SectionKind::Rules => "[Rules]".to_string(),
        };
        let mut entries: Vec<(&str, &str, usize)> = Vec::new();
        let mut function_entries = Vec::new();
        let mut ignored = Vec::new();
        for line in &section.lines {
            let Some((key, value)) = line.text.split_once('=') else {
                return Err(error(
                    line.number,
                    format!("expected key=value in {title}, found `{}`", line.text),
                ));
            };
            let key = key.trim();
            let is_mf = with_functions
                && key
                    .strip_prefix("MF")
                    .is_some_and(|k| !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()));
            if !allowed.contains(&key) && !is_mf {
                let mut expected = allowed.join(", ");
                if with_functions {
                    expected.push_str(", MF1, MF2, ...");
                }
                if key.is_empty() || !key.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
                    return Err(error(
                        line.number,
                        format!("unknown key `{key}` in {title}; expected one of {expected}"),
                    ));
                }
                let consequence = if key == "Default" {
                    "where no rule fires, the evaluator's no-rule-fired policy applies instead \
                     (by default MATLAB's middle of the range)"
                } else {
                    "the system is evaluated as MATLAB evaluates it"
                };
                note(
                    notes,
                    line.number,
                    format!(
                        "`{key}={}` in {title} is not a MATLAB key; ignored ({consequence})",
                        value.trim()
                    ),
                );
                ignored.push((key, line.number));
                continue;
            }
            if is_mf {
                function_entries.push((key, value.trim(), line.number));
                continue;
            }
            if let Some((_, _, first)) = entries.iter().find(|(k, _, _)| *k == key) {
                return Err(error(
                    line.number,
                    format!("duplicate key `{key}` in {title} (first at line {first})"),
                ));
            }
            entries.push((key, value.trim(), line.number));
        }
        Ok(Self {
            section: title,
            header: section.header,
            entries,
            function_entries,
            ignored,
        })
    }

    /// The line and value of a key, if present.
    fn find(&self, key: &str) -> Option<(usize, &'a str)> {
        self.entries
            .iter()
            .find(|(k, _, _)| *k == key)
            .map(|&(_, value, line)| (line, value))
    }

    /// The value and line of a required key; a missing key's message points at the ignored
    /// unknown keys, in case one of them is a misspelling.
    fn get(&self, key: &str) -> Result<(usize, &'a str), FuzzyError> {
        self.find(key).ok_or_else(|| {
            let mut message = format!("{} has no {key}= line", self.section);
            if let Some((unknown, line)) = self.ignored.first() {
                let _ = write!(
                    message,
                    " (the unknown key `{unknown}` at line {line} was ignored)"
                );
            }
            error(self.header, message)
        })
    }

    /// A `'quoted'` value.
    fn string(&self, key: &str) -> Result<(usize, &'a str), FuzzyError> {
        let (line, value) = self.get(key)?;
        let (text, rest) = quoted(value).map_err(|m| error(line, format!("{key}: {m}")))?;
        if !rest.trim().is_empty() {
            return Err(error(
                line,
                format!(
                    "{key}: unexpected text `{}` after the quoted value",
                    rest.trim()
                ),
            ));
        }
        Ok((line, text))
    }

    /// A non-negative integer of at least `min`, written as an integer or an integer-valued
    /// decimal (`3.000`), as MATLAB's `readfis` reads it.
    fn count(&self, key: &str, min: usize) -> Result<usize, FuzzyError> {
        let (line, value) = self.get(key)?;
        let n = value
            .parse::<usize>()
            .ok()
            .or_else(|| integer(value).and_then(|n| usize::try_from(n).ok()));
        match n {
            Some(n) if n >= min => Ok(n),
            _ => Err(error(
                line,
                format!("expected {key}=<integer >= {min}>, found {key}={value}"),
            )),
        }
    }

    /// A quoted value from a closed list.
    fn choice<T: Copy>(&self, key: &str, options: &[(&str, T)]) -> Result<T, FuzzyError> {
        let (line, value) = self.string(key)?;
        options
            .iter()
            .find(|(name, _)| *name == value)
            .map(|&(_, v)| v)
            .ok_or_else(|| {
                let list: Vec<String> = options
                    .iter()
                    .map(|(name, _)| format!("'{name}'"))
                    .collect();
                error(
                    line,
                    format!(
                        "expected {key}={}, found {key}='{value}'",
                        list.join(" or ")
                    ),
                )
            })
    }

    /// An optional quoted AND or OR method: one of `options`, or another value to be checked
    /// against the rules by [`Method::resolve`].
    fn method<T: Copy>(
        &self,
        key: &'static str,
        options: &'a [(&'a str, T)],
    ) -> Result<Method<'a, T>, FuzzyError> {
        let found = match self.find(key) {
            Some(_) => Some(self.string(key)?),
            None => None,
        };
        let known = found.and_then(|(_, value)| {
            options
                .iter()
                .find(|(name, _)| *name == value)
                .map(|&(_, v)| v)
        });
        Ok(match known {
            Some(method) => Method::Known(method),
            None => Method::Other {
                key,
                found,
                options,
            },
        })
    }

    /// `[min max]`, finite with `min < max`, or `min <= max` for an output (`point_allowed`).
    fn range(&self, point_allowed: bool) -> Result<[f64; 2], FuzzyError> {
        let (line, value) = self.get("Range")?;
        let numbers = bracketed(value).map_err(|m| error(line, format!("Range: {m}")))?;
        match numbers[..] {
            [min, max]
                if min.is_finite()
                    && max.is_finite()
                    && (min < max || point_allowed && min == max) =>
            {
                // Ends within double precision whose width is not ([-1e308 1e308]): every grid
                // over the range would step by infinity.
                if (max - min).is_finite() {
                    Ok([min, max])
                } else {
                    Err(error(
                        line,
                        format!(
                            "Range width max - min must be finite (within double precision), \
                             found [{} {}]",
                            lane_math::Compact(min),
                            lane_math::Compact(max)
                        ),
                    ))
                }
            }
            [min, max] => Err(error(
                line,
                format!(
                    "Range must be finite with min {} max, found [{min} {max}]",
                    if point_allowed { "<=" } else { "<" }
                ),
            )),
            _ => Err(error(
                line,
                format!("expected Range=[min max], found Range={value}"),
            )),
        }
    }

    /// The `NumMFs` (at least `min`) functions. Like MATLAB's `readfis`, the k-th `MF` line
    /// is function k whatever its key says (MATLAB's own `slcp1.fis` has two `MF2` lines); a
    /// key that disagrees with its position is noted. Names may repeat, as in MATLAB.
    fn functions(
        &self,
        min: usize,
        notes: &mut Vec<FisNote>,
    ) -> Result<Vec<FunctionLine<'a>>, FuzzyError> {
        let n = self.count("NumMFs", min)?;
        if self.function_entries.len() != n {
            let (line, _) = self.get("NumMFs")?;
            return Err(error(
                line,
                format!(
                    "NumMFs={n} but {} has {} MF lines",
                    self.section,
                    self.function_entries.len()
                ),
            ));
        }
        let mut functions: Vec<FunctionLine<'a>> = Vec::with_capacity(n);
        for (index, &(key, value, line)) in self.function_entries.iter().enumerate() {
            let k = index + 1;
            if key != format!("MF{k}") {
                note(
                    notes,
                    line,
                    format!(
                        "`{key}` is the MF line number {k} of {}: read as MF{k}, by position, as MATLAB's readfis does",
                        self.section
                    ),
                );
            }
            let (name, kind, params) =
                function(value).map_err(|m| error(line, format!("MF{k}: {m}")))?;
            check_name("set", name).map_err(|problem| error(line, problem.to_string()))?;
            functions.push(FunctionLine {
                line,
                key: k,
                name,
                kind,
                params,
            });
        }
        Ok(functions)
    }
}

/// One `MFk='name':'type',[params]` line.
struct FunctionLine<'a> {
    line: usize,
    /// `k`.
    key: usize,
    name: &'a str,
    kind: &'a str,
    params: Vec<f64>,
}

impl FunctionLine<'_> {
    /// Keeps the leading `needed` parameters, as MATLAB does, noting the ignored rest.
    fn leading_params(&mut self, needed: usize, section: &str, notes: &mut Vec<FisNote>) {
        if self.params.len() > needed {
            let extra = self.params.split_off(needed);
            note(
                notes,
                self.line,
                format!(
                    "{section} MF{} '{}': '{}' takes {needed} parameter{}; the extra {} ignored, as MATLAB does",
                    self.key,
                    self.name,
                    self.kind,
                    if needed == 1 { "" } else { "s" },
                    extra_params(&extra)
                ),
            );
        }
    }
}

/// The parameters a line gives beyond those its function takes, as a note shows them: the
/// first eight and how many more (a line of a hundred thousand would make a note of as many).
fn extra_params(extra: &[f64]) -> String {
    const SHOWN: usize = 8;
    if extra.len() <= SHOWN {
        return format_params(extra);
    }
    let head = format_params(&extra[..SHOWN]);
    format!(
        "{} ... and {} more]",
        &head[..head.len() - 1],
        extra.len() - SHOWN
    )
}

/// An integer written as such or as an integer-valued decimal (`1.000`, `2e0`), within
/// `±2^53`; `None` otherwise.
fn integer(text: &str) -> Option<i64> {
    const EXACT: f64 = 9_007_199_254_740_992.0; // 2^53
    let text = text.trim();
    text.parse::<i64>().ok().or_else(|| {
        let x = text.parse::<f64>().ok()?;
        (x.is_finite() && x.fract() == 0.0 && x.abs() <= EXACT).then_some(x as i64)
    })
}

/// Parses the variable's `Name=` and checks it is new.
fn variable_name<'a>(
    keys: &Keys<'a>,
    names: &mut HashMap<String, usize>,
) -> Result<&'a str, FuzzyError> {
    let (line, name) = keys.string("Name")?;
    check_name("variable", name).map_err(|problem| error(line, problem.to_string()))?;
    if let Some(first) = names.get(name) {
        return Err(error(
            line,
            format!("variable name '{name}' is already used at line {first}"),
        ));
    }
    names.insert(name.to_string(), line);
    Ok(name)
}

fn parse_input(
    section: &Section<'_>,
    names: &mut HashMap<String, usize>,
    notes: &mut Vec<FisNote>,
) -> Result<InputVariable, FuzzyError> {
    let keys = Keys::new(section, &["Name", "Range", "NumMFs"], true, notes)?;
    let name = variable_name(&keys, names)?;
    let range = keys.range(false)?;
    let sets = keys
        .functions(0, notes)?
        .into_iter()
        .map(|mut function| {
            if let Some(needed) = MembershipFn::matlab_parameter_count(function.kind) {
                function.leading_params(needed, &keys.section, notes);
            }
            let membership = MembershipFn::from_matlab(function.kind, &function.params)
                .map_err(|e| error(function.line, e.to_string()))?;
            Ok(FuzzySet {
                name: function.name.to_string(),
                membership,
            })
        })
        .collect::<Result<Vec<_>, FuzzyError>>()?;
    Ok(InputVariable {
        name: name.to_string(),
        range,
        sets,
    })
}

fn parse_output(
    section: &Section<'_>,
    n_inputs: usize,
    names: &mut HashMap<String, usize>,
    notes: &mut Vec<FisNote>,
) -> Result<OutputVariable, FuzzyError> {
    let keys = Keys::new(section, &["Name", "Range", "NumMFs"], true, notes)?;
    let name = variable_name(&keys, names)?;
    let range = keys.range(true)?;
    let terms = keys
        .functions(1, notes)?
        .into_iter()
        .map(|mut f| {
            let line = f.line;
            let needed = match f.kind {
                "constant" => 1,
                "linear" => n_inputs + 1,
                other => {
                    return Err(error(
                        line,
                        format!("a Sugeno output function must be 'constant' or 'linear', found '{other}'"),
                    ));
                }
            };
            if f.params.len() < needed {
                let found = f.params.len();
                return Err(error(
                    line,
                    if needed == 1 {
                        format!("'constant' takes 1 parameter, found {found}")
                    } else {
                        format!("'linear' takes NumInputs + 1 = {needed} parameters [p1 ... pn r], found {found}")
                    },
                ));
            }
            f.leading_params(needed, &keys.section, notes);
            let params = f.params;
            if params.iter().any(|p| !p.is_finite()) {
                return Err(error(line, format!("parameters must be finite, found {}", format_params(&params))));
            }
            let function = if f.kind == "constant" {
                OutputFn::Constant(params[0])
            } else {
                OutputFn::Linear { coefficients: params[..n_inputs].to_vec(), constant: params[n_inputs] }
            };
            Ok(OutputTerm { name: f.name.to_string(), function })
        })
        .collect::<Result<Vec<_>, FuzzyError>>()?;
    Ok(OutputVariable {
        name: name.to_string(),
        range,
        terms,
    })
}

/// Parses `i1 i2 ... in, o1 ... om (weight) : connective`; indices and the connective may be
/// written as integer-valued decimals (`1.000`, fuzzylite).
fn parse_rule(
    line: Line<'_>,
    inputs: &[InputVariable],
    outputs: &[OutputVariable],
) -> Result<Rule, FuzzyError> {
    let fail = |m: String| error(line.number, m);
    let shape = "expected a rule `i1 ... in, o1 ... om (weight) : connective`";
    let Some((left, right)) = line.text.split_once(',') else {
        return Err(fail(format!("{shape}, found `{}` (no comma)", line.text)));
    };
    let Some((open, close)) = right
        .find('(')
        .and_then(|open| Some((open, open + right[open..].find(')')?)))
    else {
        return Err(fail(format!(
            "{shape}, found `{}` (no weight in parentheses)",
            line.text
        )));
    };
    let Some(connective) = right[close + 1..].trim().strip_prefix(':') else {
        return Err(fail(format!(
            "{shape}, found `{}` (no `:` after the weight)",
            line.text
        )));
    };
    let integers = |text: &str, what: &str, expected: usize| -> Result<Vec<i64>, FuzzyError> {
        let values = text
            .split_whitespace()
            .map(|t| {
                integer(t).ok_or_else(|| {
                    let hedge = if t.parse::<f64>().is_ok_and(f64::is_finite) {
                        " (fuzzylite writes hedges such as `very` as fractions; they are not supported)"
                    } else {
                        ""
                    };
                    fail(format!("expected an integer {what} index, found `{t}`{hedge}"))
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        if values.len() != expected {
            return Err(fail(format!(
                "expected {expected} {what} indices (one per {what}), found {}",
                values.len()
            )));
        }
        Ok(values)
    };
    let antecedents = integers(left, "input", inputs.len())?
        .into_iter()
        .map(|k| match k {
            0 => Antecedent::Any,
            k if k > 0 => Antecedent::Is(k.unsigned_abs() as usize - 1),
            k => Antecedent::IsNot(k.unsigned_abs() as usize - 1),
        })
        .collect();
    let consequents = integers(&right[..open], "output", outputs.len())?
        .into_iter()
        .map(|k| match k {
            0 => Ok(None),
            k if k > 0 => Ok(Some(k.unsigned_abs() as usize - 1)),
            k => Err(fail(format!("negated consequent {k}: negation applies to Mamdani output sets, not to Sugeno functions"))),
        })
        .collect::<Result<Vec<_>, _>>()?;
    let weight_text = right[open + 1..close].trim();
    let weight = weight_text.parse::<f64>().map_err(|_| {
        fail(format!(
            "expected a rule weight between the parentheses, found `{weight_text}`"
        ))
    })?;
    let connective = match integer(connective) {
        Some(1) => Connective::And,
        Some(2) => Connective::Or,
        _ => {
            return Err(fail(format!(
                "expected connective 1 (AND) or 2 (OR) after `:`, found `{}`",
                connective.trim()
            )));
        }
    };
    let rule = Rule {
        antecedents,
        consequents,
        weight,
        connective,
    };
    check_rule(&rule, inputs, outputs).map_err(|m| fail(format!("rule {m}")))?;
    Ok(rule)
}

/// Why a `.fis` value (a quoted name, a bracketed list, a membership function) could not be
/// read; the caller adds the line and the key. Each names the text it found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
enum ValueError {
    /// No opening quote.
    #[error("expected a quoted string like 'name', found `{found}`")]
    NotQuoted {
        /// The value.
        found: String,
    },
    /// No closing quote.
    #[error("unterminated quoted string `{found}`")]
    Unterminated {
        /// The value.
        found: String,
    },
    /// Not `[...]`.
    #[error("expected numbers in brackets like [0 1], found `{found}`")]
    NotBracketed {
        /// The value.
        found: String,
    },
    /// A list item that is not a [`number`].
    #[error("expected a number, found `{found}`")]
    NotANumber {
        /// The item.
        found: String,
    },
    /// Two commas with no number between them (or a comma at either end of the list).
    #[error("expected a number between the commas of `{found}`")]
    EmptyEntry {
        /// The list.
        found: String,
    },
    /// A quoted part of a membership function `'name':'type',[parameters]` is malformed.
    #[error("{FUNCTION_SHAPE}: {quote}")]
    FunctionQuote {
        /// What is wrong with the quoted name or type.
        quote: Box<ValueError>,
    },
    /// A membership function lacks the `separator` (`:` after the name, `,` after the type).
    #[error("{FUNCTION_SHAPE}, found `{found}` (no `{separator}` after the {after})")]
    FunctionSeparator {
        /// The value.
        found: String,
        /// The missing separator.
        separator: char,
        /// What it should follow: `name` or `type`.
        after: &'static str,
    },
}

/// The form of a membership function's value, named by [`ValueError`].
const FUNCTION_SHAPE: &str = "expected 'name':'type',[parameters]";

/// Splits `'text'rest` into `text` and `rest`.
fn quoted(value: &str) -> Result<(&str, &str), ValueError> {
    let found = || value.to_string();
    let inner = value
        .strip_prefix('\'')
        .ok_or_else(|| ValueError::NotQuoted { found: found() })?;
    let end = inner
        .find('\'')
        .ok_or_else(|| ValueError::Unterminated { found: found() })?;
    Ok((&inner[..end], &inner[end + 1..]))
}

/// Parses `[a b c]` (spaces or commas between the numbers; each a [`number`]).
fn bracketed(value: &str) -> Result<Vec<f64>, ValueError> {
    let inner = value
        .trim()
        .strip_prefix('[')
        .and_then(|v| v.strip_suffix(']'))
        .ok_or_else(|| ValueError::NotBracketed {
            found: value.to_string(),
        })?;
    // Commas separate entries as spaces do, but a comma with no number on one side is a slip
    // (`[1 , , 0]` is not `[1 0]`).
    let parts: Vec<&str> = inner.split(',').collect();
    if parts.len() > 1 && parts.iter().any(|part| part.trim().is_empty()) {
        return Err(ValueError::EmptyEntry {
            found: value.trim().to_string(),
        });
    }
    inner
        .split(|c: char| c.is_whitespace() || c == ',')
        .filter(|t| !t.is_empty())
        .map(|t| {
            number(t).ok_or_else(|| ValueError::NotANumber {
                found: t.to_string(),
            })
        })
        .collect()
}

/// A number, or the products and quotients of numbers and `pi` that MATLAB's `readfis`
/// evaluates in its examples (`Range = [-pi/4 pi/4]`): `[+-]factor ([*/] [+-]factor)*` with
/// each factor a decimal or `pi`.
fn number(token: &str) -> Option<f64> {
    let factor = |text: &str| -> Option<f64> {
        let (sign, magnitude) = match text.strip_prefix('-') {
            Some(rest) => (-1.0, rest),
            None => (1.0, text.strip_prefix('+').unwrap_or(text)),
        };
        let value = if magnitude == "pi" {
            std::f64::consts::PI
        } else if magnitude.starts_with(['+', '-']) {
            return None;
        } else {
            magnitude.parse::<f64>().ok()?
        };
        Some(sign * value)
    };
    if let Ok(x) = token.parse::<f64>() {
        return Some(x);
    }
    let mut operators = token.match_indices(['*', '/']);
    let mut start = 0;
    let mut value: Option<f64> = None;
    let mut pending = '*';
    loop {
        let (end, next) = match operators.next() {
            Some((index, op)) => (index, op.chars().next()),
            None => (token.len(), None),
        };
        let x = factor(&token[start..end])?;
        value = Some(match (value, pending) {
            (None, _) => x,
            (Some(v), '*') => v * x,
            (Some(v), _) => v / x,
        });
        match next {
            Some(op) => {
                pending = op;
                start = end + 1;
            }
            None => return value,
        }
    }
}

/// Parses `'name':'type',[params]`.
fn function(value: &str) -> Result<(&str, &str, Vec<f64>), ValueError> {
    let quote = |quote| ValueError::FunctionQuote {
        quote: Box::new(quote),
    };
    let separator = |separator, after| ValueError::FunctionSeparator {
        found: value.to_string(),
        separator,
        after,
    };
    let (name, rest) = quoted(value).map_err(quote)?;
    let rest = rest
        .trim_start()
        .strip_prefix(':')
        .ok_or_else(|| separator(':', "name"))?;
    let (kind, rest) = quoted(rest.trim_start()).map_err(quote)?;
    let rest = rest
        .trim_start()
        .strip_prefix(',')
        .ok_or_else(|| separator(',', "type"))?;
    Ok((name, kind, bracketed(rest)?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::paper_controller;

    const TINY: &str = "[System]\nName='t'\nType='sugeno'\nVersion=2.0\nNumInputs=1\nNumOutputs=1\nNumRules=2\n\
        AndMethod='prod'\nOrMethod='probor'\nImpMethod='prod'\nAggMethod='sum'\nDefuzzMethod='wtaver'\n\n\
        [Input1]\nName='x'\nRange=[-5 5]\nNumMFs=2\nMF1='low':'gaussmf',[4 -5]\nMF2='high':'gaussmf',[4 5]\n\n\
        [Output1]\nName='y'\nRange=[0 1]\nNumMFs=2\nMF1='line1':'linear',[-1 -1]\nMF2='line2':'constant',[0.5]\n\n\
        [Rules]\n1, 1 (0.5) : 1\n-2, 2 (1) : 1\n";

    fn parse_error(text: &str) -> String {
        FuzzySystem::from_fis(text).unwrap_err().to_string()
    }

    #[test]
    fn extra_parameters_are_noted_in_a_line_of_bounded_length() {
        let extra = vec!["1"; 100_000].join(" ");
        let text = TINY.replace(
            "MF1='low':'gaussmf',[4 -5]",
            &format!("MF1='low':'gaussmf',[4 -5 {extra}]"),
        );
        let (system, notes) = FuzzySystem::from_fis_with_notes(&text).unwrap();
        assert_eq!(
            system.inputs()[0].sets[0].membership,
            MembershipFn::Gaussian {
                sigma: 4.0,
                center: -5.0
            }
        );
        let message = &notes[0].message;
        assert!(
            message.ends_with("takes 2 parameters; the extra [1 1 1 1 1 1 1 1 ... and 99992 more] ignored, as MATLAB does")
                && message.len() < 200,
            "{message}"
        );
        let (_, notes) =
            FuzzySystem::from_fis_with_notes(&TINY.replace("[4 -5]", "[4 -5 0 0]")).unwrap();
        assert!(
            notes[0].message.contains("the extra [0 0] ignored"),
            "{notes:?}"
        );
    }

    #[test]
    fn reads_a_first_order_file_and_writes_it_back_verbatim() {
        let system = FuzzySystem::from_fis(TINY).unwrap();
        assert_eq!(
            system.outputs()[0].terms[0].function,
            OutputFn::Linear {
                coefficients: vec![-1.0],
                constant: -1.0
            }
        );
        assert_eq!(system.rules()[0].weight, 0.5);
        assert_eq!(system.rules()[1].antecedents, [Antecedent::IsNot(1)]);
        assert_eq!(system.to_fis(), TINY);
    }

    #[test]
    fn tolerates_matlab_variations() {
        let variant = TINY
            .replace(
                "[Rules]\n1, 1 (0.5) : 1",
                "% a comment\n[Rules]\n  1 ,1(0.5):1",
            )
            .replace("[4 -5]", "[4, -5]")
            .replace('\n', "\r\n");
        assert_eq!(
            FuzzySystem::from_fis(&format!("\u{feff}{variant}")).unwrap(),
            FuzzySystem::from_fis(TINY).unwrap()
        );
    }

    #[test]
    fn malformed_files_name_the_line_and_what_was_expected() {
        let cases = [
            (
                TINY.replace("Range=[-5 5]", "Range=[-5]"),
                "line 16: expected Range=[min max], found Range=[-5]",
            ),
            (
                TINY.replace("Range=[-5 5]", "Range=[5 -5]"),
                "line 16: Range must be finite with min < max, found [5 -5]",
            ),
            (
                TINY.replace("Range=[-5 5]", "Range=[-1e308 1e308]"),
                "line 16: Range width max - min must be finite (within double precision), found \
                 [-1e308 1e308]",
            ),
            (
                TINY.replace("[4 -5]", "[0 -5]"),
                "line 18: gaussmf: sigma must be positive, got 0",
            ),
            (
                TINY.replace("[4 -5]", "[4 x]"),
                "line 18: MF1: expected a number, found `x`",
            ),
            (
                TINY.replace("'gaussmf',[4 5]", "'gausmf',[4 5]"),
                "line 19: gausmf: unknown membership function type",
            ),
            (
                TINY.replace("NumRules=2", "NumRules=3"),
                "line 28: NumRules=3 but [Rules] has 2 rule lines",
            ),
            (
                TINY.replace("-2, 2 (1) : 1", "-2 1, 2 (1) : 1"),
                "line 30: expected 1 input indices (one per input), found 2",
            ),
            (
                TINY.replace("-2, 2 (1) : 1", "3, 2 (1) : 1"),
                "line 30: rule input 'x' has 2 sets, there is no set 3",
            ),
            (
                TINY.replace("-2, 2 (1) : 1", "-2, -2 (1) : 1"),
                "line 30: negated consequent -2: negation applies",
            ),
            (
                TINY.replace("-2, 2 (1) : 1", "-2, 2 (1) : 3"),
                "line 30: expected connective 1 (AND) or 2 (OR)",
            ),
            (
                TINY.replace("-2, 2 (1) : 1", "-2 2 (1) : 1"),
                "line 30: expected a rule `i1 ... in, o1 ... om (weight) : connective`",
            ),
            (
                TINY.replace("-2, 2 (1) : 1", "-2, 2 (1.5) : 1"),
                "line 30: rule weight must lie in [0, 1], got 1.5",
            ),
            (
                TINY.replace("DefuzzMethod='wtaver'", "DefuzzMethod='centroid'"),
                "line 12: expected DefuzzMethod='wtaver' or 'wtsum', found DefuzzMethod='centroid'",
            ),
            (
                TINY.replace("-2, 2 (1) : 1", "-2, 2 (1) : 1 x"),
                "line 30: expected connective 1 (AND) or 2 (OR) after `:`, found `1 x`",
            ),
            (
                TINY.replace("-2, 2 (1) : 1", "-2.5, 2 (1) : 1"),
                "line 30: expected an integer input index, found `-2.5` (fuzzylite writes hedges",
            ),
            (
                TINY.replace("NumMFs=2\nMF1='low'", "NumMFs=2.5\nMF1='low'"),
                "line 17: expected NumMFs=<integer >= 0>, found NumMFs=2.5",
            ),
            (
                TINY.replace("[4 5]", "[4]"),
                "line 19: gaussmf: expected 2 parameters, got 1",
            ),
            (
                TINY.replace("'constant',[0.5]", "'constant',[]"),
                "line 26: 'constant' takes 1 parameter, found 0",
            ),
            (
                TINY.replace("NumMFs=2\nMF1='low'", "NumMFs=3\nMF1='low'"),
                "line 17: NumMFs=3 but [Input1] has 2 MF lines",
            ),
            (
                TINY.replace("Name='y'", "Na me='y'"),
                "line 22: unknown key `Na me` in [Output1]",
            ),
            (
                TINY.replace("NumInputs=1", "NumInputs=x"),
                "line 5: expected NumInputs=<integer >= 1>, found NumInputs=x",
            ),
            (
                TINY.replace("NumInputs=1\n", ""),
                "line 1: [System] has no NumInputs= line",
            ),
            (
                TINY.replace("Name='y'", "Name='x'"),
                "line 22: variable name 'x' is already used at line 15",
            ),
            (
                TINY.replace("Name='y'", "Nome='y'"),
                "line 21: [Output1] has no Name= line (the unknown key `Nome` at line 22 was ignored)",
            ),
            (
                TINY.replace("MF2='line2'", "MF2='line2'\nMF3='line3':'constant',[1]"),
                "line 24: NumMFs=2 but [Output1] has 3 MF lines",
            ),
            (
                TINY.replace("[Output1]", "[Output2]"),
                "line 21: section [Output2] but NumOutputs=1",
            ),
            (
                TINY.replace("[Output1]", "[Outputs]"),
                "line 21: unknown section [Outputs]",
            ),
            (
                TINY.replace("'constant',[0.5]", "'trimf',[0 0.5 1]"),
                "line 26: a Sugeno output function must be 'constant' or 'linear', found 'trimf'",
            ),
            (
                TINY.replace("'linear',[-1 -1]", "'linear',[-1]"),
                "line 25: 'linear' takes NumInputs + 1 = 2 parameters",
            ),
            (
                TINY.replace("MF1='line1':'linear'", "MF1='line1''linear'"),
                "line 25: MF1: expected 'name':'type',[parameters], found",
            ),
            (
                format!("Name='x'\n{TINY}"),
                "line 1: expected the [System] section header, found `Name='x'`",
            ),
            (
                format!("{TINY}[Input1]\n"),
                "line 31: duplicate section [Input1] (first at line 14)",
            ),
        ];
        for (text, expected) in cases {
            let message = parse_error(&text);
            assert!(
                message.starts_with(expected),
                "got    {message}\nwanted {expected}"
            );
        }
        // Version is optional (its value is not used).
        assert!(FuzzySystem::from_fis(&TINY.replace("Version=2.0\n", "")).is_ok());
        // A removed section is reported at the [System] header.
        let no_output = TINY.split("[Output1]").next().unwrap().to_string()
            + "[Rules]\n1, 1 (0.5) : 1\n-2, 2 (1) : 1\n";
        assert_eq!(
            parse_error(&no_output),
            "line 1: missing section [Output1] (NumOutputs=1)"
        );
    }

    #[test]
    fn functions_are_read_by_position_as_matlab_does() {
        // MATLAB's slcp1.fis numbers its third function MF2 again; readfis goes by position.
        let misnumbered = TINY.replace("MF2='high'", "MF1='high'");
        let (system, notes) = FuzzySystem::from_fis_with_notes(&misnumbered).unwrap();
        assert_eq!(system, FuzzySystem::from_fis(TINY).unwrap());
        assert_eq!(notes.len(), 1);
        assert_eq!(
            notes[0].to_string(),
            "line 19: `MF1` is the MF line number 2 of [Input1]: read as MF2, by position, as MATLAB's readfis does"
        );
        // Swapped keys: the first line is the first function, whatever its key.
        let swapped = TINY
            .replace("MF1='low'", "MF9='low'")
            .replace("MF2='high'", "MF1='high'");
        let (system, notes) = FuzzySystem::from_fis_with_notes(&swapped).unwrap();
        assert_eq!(system.inputs()[0].sets[0].name, "low");
        assert_eq!(notes.len(), 2);
    }

    #[test]
    fn mamdani_files_are_refused_by_name() {
        let mamdani = TINY
            .replace("Type='sugeno'", "Type='mamdani'")
            .replace("AndMethod='prod'", "AndMethod='bogus'");
        assert_eq!(
            parse_error(&mamdani),
            "line 3: Mamdani systems are not supported (this crate implements Takagi-Sugeno inference); expected Type='sugeno'"
        );
        assert_eq!(
            parse_error(&TINY.replace("'sugeno'", "'tsk'")),
            "line 3: expected Type='sugeno', found Type='tsk'"
        );
    }

    #[test]
    fn numbers_may_be_written_as_matlab_expressions_of_pi() {
        use std::f64::consts::PI;
        let cases = [
            ("-pi/4", Some(-PI / 4.0)),
            ("pi", Some(PI)),
            ("+pi", Some(PI)),
            ("2*pi", Some(2.0 * PI)),
            ("pi/-2", Some(PI / -2.0)),
            ("3/4*pi", Some(3.0 / 4.0 * PI)),
            ("1e-3", Some(1e-3)),
            ("0.250", Some(0.25)),
            ("pi/", None),
            ("*2", None),
            ("--1", None),
            ("p", None),
            ("pi+1", None),
        ];
        for (text, expected) in cases {
            assert_eq!(number(text), expected, "{text}");
        }
        assert_eq!(bracketed("[-pi/4, pi/4]").unwrap(), [-PI / 4.0, PI / 4.0]);
        assert_eq!(bracketed("[ 1 , 2  0]").unwrap(), [1.0, 2.0, 0.0]);
        assert_eq!(bracketed("[]").unwrap(), [] as [f64; 0]);
        for list in ["[1 , , 0]", "[1, 2,]", "[,1]", "[,]"] {
            assert_eq!(
                bracketed(list).unwrap_err().to_string(),
                format!("expected a number between the commas of `{list}`")
            );
        }
    }

    #[test]
    fn numbers_are_written_in_their_shortest_exact_form() {
        for x in [
            0.3,
            -0.3,
            2.0,
            0.0,
            -0.0,
            1e-20,
            1.5e300,
            123456.789,
            0.1 + 0.2,
            f64::MIN_POSITIVE,
            1e15,
            99999.0,
        ] {
            let text = fis_number(x);
            assert_eq!(
                text.parse::<f64>().unwrap().to_bits(),
                x.to_bits(),
                "{x} written as {text}"
            );
        }
        assert_eq!(fis_numbers(&[0.3, 2.0, -0.3]), "[0.3 2 -0.3]");
        assert_eq!(fis_number(1e-20), "1e-20");
    }

    #[test]
    fn the_paper_controller_round_trips() {
        let text = paper_controller().to_fis();
        assert_eq!(FuzzySystem::from_fis(&text).unwrap(), paper_controller());
        assert!(text.contains("MF1='N':'gbellmf',[0.3 2 -0.3]"));
        assert!(text.contains("\n1 1 1 1, 4 4 (1) : 1\n"));
    }
}
