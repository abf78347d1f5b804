//! IEC 61131-7 Fuzzy Control Language (FCL) for Sugeno systems, read and written, including
//! the files fuzzylite's FCL exporter writes.
//!
//! Written files are read by fuzzylite 6 (tested against the program in CI) and follow the
//! standard's blocks: `FUNCTION_BLOCK`, `VAR_INPUT`, `FUZZIFY`, `DEFUZZIFY` with singleton
//! terms, `METHOD : COGS` and fuzzylite's `ACCU : UnboundedSum`, `RULEBLOCK` with `ACT : PROD`
//! and rules `if x is a and y is not b then z is c and w is d with 0.5;`, and the standard's
//! point lists for triangles and trapezoids. Where the two differ the file is written as
//! fuzzylite reads it: rule keywords in lower case (the standard's keywords are
//! case-insensitive, fuzzylite's rule parser knows only the lower-case ones), conclusions joined
//! by `and` (the standard's grammar also has `,`, which fuzzylite does not understand), no
//! comment (fuzzylite stops at `(*`, the standard has no `//`). The standard has no bell,
//! Gaussian, sigmoid or linear terms; those are written as fuzzylite writes them
//! (`TERM N := Bell -0.3 0.3 2.0;`, `TERM z := Linear 1.0 2.0 0.5;`), and a `RANGE` is written
//! in every `FUZZIFY` block as fuzzylite does. MATLAB's steps (`smf`, `zmf`, `pimf` with a foot
//! at or past its shoulder) are refused: fuzzylite's shapes with those parameters evaluate
//! otherwise. Two terms of a variable sharing a name (which a `.fis` file allows) are refused too.
//! Names must be identifiers that are no keyword of
//! either (`END_VAR`, `RANGE`, `then`, fuzzylite's hedges `any`, `very`, ...): writing refuses
//! any other name rather than write a file that reads as something else.
//!
//! Reading accepts both forms, `(* *)` and `//` comments, any case of the keywords, `,` or
//! `and` between conclusions, and rules with or without the final `;`. Numbers are written in
//! their shortest exact form (always with a decimal point), so writing then reading gives back
//! the identical system.

use crate::error::{FuzzyError, SystemProblem};
use crate::membership::{KINDS, Kind, MembershipFn};
use crate::system::{
    AndMethod, Antecedent, Connective, Defuzzification, FuzzySet, FuzzySystem, InputVariable,
    Methods, OrMethod, OutputFn, OutputTerm, OutputVariable, Rule,
};
use std::collections::HashMap;
use std::fmt::Write as _;

/// The largest FCL text read, in bytes.
const MAX_FCL_BYTES: usize = 16 << 20;

/// FCL keywords, which cannot be variable or term names.
const KEYWORDS: [&str; 9] = [
    "IF", "THEN", "IS", "NOT", "AND", "OR", "WITH", "RULE", "TERM",
];

/// Further words a written name cannot be (compared ignoring case): the rest of IEC 61131-7's
/// keywords, and the words fuzzylite's rule parser takes for hedges.
const RESERVED: [&str; 39] = [
    "ACCU",
    "ACT",
    "ASUM",
    "BDIF",
    "BSUM",
    "COA",
    "COG",
    "COGS",
    "COGSS",
    "DEFAULT",
    "DEFUZZIFY",
    "END_DEFUZZIFY",
    "END_FUNCTION_BLOCK",
    "END_FUZZIFY",
    "END_OPTIONS",
    "END_RULEBLOCK",
    "END_VAR",
    "FUNCTION_BLOCK",
    "FUZZIFY",
    "LM",
    "MAX",
    "METHOD",
    "MIN",
    "MM",
    "NC",
    "NSUM",
    "OPTIONS",
    "PROD",
    "RANGE",
    "REAL",
    "RM",
    "RULEBLOCK",
    "VAR_INPUT",
    "VAR_OUTPUT",
    "ANY",
    "VERY",
    "SOMEWHAT",
    "SELDOM",
    "EXTREMELY",
];

impl FuzzySystem {
    /// Writes the system as FCL that fuzzylite 6 and IEC 61131-7 read (see the module
    /// documentation). Fails if a name is not an FCL identifier (ASCII letters, digits and `_`,
    /// not starting with a digit) or is a keyword of the standard or of fuzzylite's rules.
    ///
    /// ```
    /// use fuzzy_sugeno::{paper_controller, FuzzySystem};
    /// let fcl = paper_controller().to_fcl()?;
    /// assert!(fcl.contains("TERM N := Bell -0.3 0.3 2.0;"));
    /// assert!(fcl.contains("then tau1 is VP and tau2 is VP;"));
    /// assert_eq!(FuzzySystem::from_fcl(&fcl)?, paper_controller());
    /// # Ok::<(), fuzzy_sugeno::FuzzyError>(())
    /// ```
    pub fn to_fcl(&self) -> Result<String, FuzzyError> {
        let identifier = |kind: &'static str, name: &str| {
            if is_identifier(name) && !RESERVED.iter().any(|k| k.eq_ignore_ascii_case(name)) {
                Ok(())
            } else {
                Err(FuzzyError::FclName {
                    kind,
                    name: name.to_string(),
                })
            }
        };
        identifier("system", self.name())?;
        let mut out = format!("FUNCTION_BLOCK {}\n\nVAR_INPUT\n", self.name());
        for input in self.inputs() {
            identifier("input", &input.name)?;
            let _ = writeln!(out, "    {} : REAL;", input.name);
        }
        out.push_str("END_VAR\n\nVAR_OUTPUT\n");
        for output in self.outputs() {
            identifier("output", &output.name)?;
            let _ = writeln!(out, "    {} : REAL;", output.name);
        }
        out.push_str("END_VAR\n");
        for input in self.inputs() {
            let _ = write!(
                out,
                "\nFUZZIFY {}\n    RANGE := ({} .. {});\n",
                input.name,
                real(input.range[0]),
                real(input.range[1])
            );
            unique(
                "input",
                &input.name,
                input.sets.iter().map(|set| set.name.as_str()),
            )?;
            for set in &input.sets {
                identifier("set", &set.name)?;
                if let Some(shape) = matlab_step(&set.membership) {
                    return Err(FuzzyError::FclStep {
                        input: input.name.clone(),
                        set: set.name.clone(),
                        shape,
                    });
                }
                let _ = writeln!(out, "    TERM {} := {};", set.name, term(&set.membership));
            }
            out.push_str("END_FUZZIFY\n");
        }
        let methods = self.methods();
        for output in self.outputs() {
            let _ = write!(
                out,
                "\nDEFUZZIFY {}\n    RANGE := ({} .. {});\n",
                output.name,
                real(output.range[0]),
                real(output.range[1])
            );
            unique(
                "output",
                &output.name,
                output.terms.iter().map(|t| t.name.as_str()),
            )?;
            for t in &output.terms {
                identifier("term", &t.name)?;
                let value = match &t.function {
                    OutputFn::Constant(c) => real(*c),
                    OutputFn::Linear {
                        coefficients,
                        constant,
                    } => {
                        let mut s = "Linear".to_string();
                        for p in coefficients.iter().chain([constant]) {
                            let _ = write!(s, " {}", real(*p));
                        }
                        s
                    }
                };
                let _ = writeln!(out, "    TERM {} := {value};", t.name);
            }
            let method = match methods.defuzzification {
                Defuzzification::WeightedAverage => "COGS",
                Defuzzification::WeightedSum => "COGSS",
            };
            let _ = writeln!(
                out,
                "    METHOD : {method};\n    ACCU : UnboundedSum;\n    DEFAULT := {};\n\
                 END_DEFUZZIFY",
                real(0.5 * (output.range[0] + output.range[1]))
            );
        }
        let and = match methods.and {
            AndMethod::Product => "PROD",
            AndMethod::Minimum => "MIN",
        };
        let or = match methods.or {
            OrMethod::ProbabilisticSum => "ASUM",
            OrMethod::Maximum => "MAX",
        };
        let _ = writeln!(
            out,
            "\nRULEBLOCK rules\n    AND : {and};\n    OR : {or};\n    ACT : PROD;"
        );
        for (r, rule) in self.rules().iter().enumerate() {
            let connective = match rule.connective {
                Connective::And => " and ",
                Connective::Or => " or ",
            };
            let premises: Vec<String> = rule
                .antecedents
                .iter()
                .zip(self.inputs())
                .filter_map(|(a, input)| match *a {
                    Antecedent::Any => None,
                    Antecedent::Is(k) => Some(format!("{} is {}", input.name, input.sets[k].name)),
                    Antecedent::IsNot(k) => {
                        Some(format!("{} is not {}", input.name, input.sets[k].name))
                    }
                })
                .collect();
            let conclusions: Vec<String> = rule
                .consequents
                .iter()
                .zip(self.outputs())
                .filter_map(|(c, output)| {
                    c.map(|k| format!("{} is {}", output.name, output.terms[k].name))
                })
                .collect();
            let weight = if rule.weight == 1.0 {
                String::new()
            } else {
                format!(" with {}", real(rule.weight))
            };
            let _ = writeln!(
                out,
                "    RULE {} : if {} then {}{weight};",
                r + 1,
                premises.join(connective),
                conclusions.join(" and ")
            );
        }
        out.push_str("END_RULEBLOCK\n\nEND_FUNCTION_BLOCK\n");
        Ok(out)
    }

    /// Reads a Sugeno system from FCL text (IEC 61131-7, or as fuzzylite writes it). Errors
    /// give the line and what was expected; Mamdani defuzzifiers, membership shapes this crate
    /// does not have and hedges other than `NOT` are refused by name. `DEFAULT`, `ACT` and
    /// `ACCU` are read and ignored: a Sugeno system has no implication or accumulation, and the
    /// output when no rule fires is an evaluation policy ([`EvalOptions`](crate::EvalOptions)).
    pub fn from_fcl(text: &str) -> Result<Self, FuzzyError> {
        if text.len() > MAX_FCL_BYTES {
            return Err(error(
                1,
                format!("{} bytes exceed the limit of {MAX_FCL_BYTES}", text.len()),
            ));
        }
        Reader::default().read(text)
    }
}

/// A term's FCL value: IEC point lists for triangles and trapezoids, fuzzylite's class names
/// and parameter order otherwise.
fn term(mf: &MembershipFn) -> String {
    let (p, _) = mf.param_array();
    match *mf {
        MembershipFn::Triangle { .. } => {
            format!(
                "({}, 0.0) ({}, 1.0) ({}, 0.0)",
                real(p[0]),
                real(p[1]),
                real(p[2])
            )
        }
        MembershipFn::Trapezoid { .. } => format!(
            "({}, 0.0) ({}, 1.0) ({}, 1.0) ({}, 0.0)",
            real(p[0]),
            real(p[1]),
            real(p[2]),
            real(p[3])
        ),
        _ => {
            let kind = mf.kind();
            let mut text = kind.fcl.to_string();
            for &i in kind.fcl_order {
                let _ = write!(text, " {}", real(p[i]));
            }
            text
        }
    }
}

/// Refuses a variable two of whose terms share a name.
fn unique<'a>(
    kind: &str,
    variable: &str,
    mut names: impl Iterator<Item = &'a str> + Clone,
) -> Result<(), FuzzyError> {
    while let Some(name) = names.next() {
        if names.clone().any(|other| other == name) {
            return Err(FuzzyError::FclDuplicateTerm {
                variable: format!("{kind} '{variable}'"),
                name: name.to_string(),
            });
        }
    }
    Ok(())
}

/// The MATLAB name of a set that is one of MATLAB's steps (`smf`/`zmf` with `a >= b`, `pimf`
/// with `a >= b` or `c >= d`): fuzzylite's `SShape`, `ZShape` and `PiShape` with those
/// parameters are 0 where MATLAB's steps are 1.
fn matlab_step(mf: &MembershipFn) -> Option<&'static str> {
    match *mf {
        MembershipFn::SShape { start, end } if start >= end => Some("smf"),
        MembershipFn::ZShape { start, end } if start >= end => Some("zmf"),
        MembershipFn::PiShape {
            left_foot,
            left_shoulder,
            right_shoulder,
            right_foot,
        } if left_foot >= left_shoulder || right_shoulder >= right_foot => Some("pimf"),
        _ => None,
    }
}

/// A finite number in its shortest exact form, with the decimal point an IEC 61131 REAL
/// literal needs (`1.0e-7`, not Rust's `1e-7`).
fn real(x: f64) -> String {
    let text = format!("{x:?}");
    match text.find('e') {
        Some(e) if !text.contains('.') => format!("{}.0{}", &text[..e], &text[e..]),
        _ => text,
    }
}

fn is_identifier(name: &str) -> bool {
    let mut chars = name.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
        && !KEYWORDS.iter().any(|k| k.eq_ignore_ascii_case(name))
}

fn error(line: usize, message: impl Into<String>) -> FuzzyError {
    FuzzyError::Fcl {
        line,
        message: message.into(),
    }
}

/// The block being read (FCL calls them blocks).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
enum Section {
    #[default]
    Outside,
    FunctionBlock,
    VarInput,
    VarOutput,
    Fuzzify(usize),
    Defuzzify(usize),
    RuleBlock,
    Done,
}

/// A variable as declared and then defined, with the line of its declaration.
#[derive(Debug, Default)]
struct Variable {
    name: String,
    line: usize,
    range: Option<[f64; 2]>,
    /// The line of its `RANGE`.
    range_line: usize,
    input_sets: Vec<FuzzySet>,
    /// The line of each `TERM`, in the order of its sets or terms.
    term_lines: Vec<usize>,
    /// The names of its terms so far: rules name terms, so two may not share one.
    term_names: std::collections::HashSet<String>,
    output_terms: Vec<OutputTerm>,
    defined: bool,
}

impl Variable {
    /// Records a `TERM` named `name` at `line`, refusing a name it already has.
    fn new_term(&mut self, line: usize, name: &str) -> Result<(), FuzzyError> {
        if !self.term_names.insert(name.to_string()) {
            return Err(error(
                line,
                format!(
                    "variable '{}' already has a term named '{name}'; rules name terms, so \
                     rename one",
                    self.name
                ),
            ));
        }
        self.term_lines.push(line);
        Ok(())
    }
}

#[derive(Debug, Default)]
struct Reader {
    block: Section,
    name: String,
    inputs: Vec<Variable>,
    outputs: Vec<Variable>,
    /// Each declared variable's place in `inputs` and `outputs`, by name: a file of 10^5
    /// variables is read in time linear in its length.
    input_index: HashMap<String, usize>,
    output_index: HashMap<String, usize>,
    and: Option<(AndMethod, usize)>,
    or: Option<(OrMethod, usize)>,
    defuzzification: Option<(Defuzzification, usize)>,
    /// Rules as text with their lines, resolved once every variable is known.
    rules: Vec<(usize, String)>,
}

impl Reader {
    fn read(mut self, text: &str) -> Result<FuzzySystem, FuzzyError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut in_comment = false;
        let mut last_line = 1;
        for (index, raw) in text.lines().enumerate() {
            let number = index + 1;
            last_line = number;
            let line = strip_comments(raw, &mut in_comment);
            for statement in split_statements(&line) {
                self.statement(number, statement)?;
            }
        }
        if in_comment {
            return Err(error(last_line, "unterminated (* comment"));
        }
        if self.block != Section::Done {
            return Err(error(
                last_line,
                "expected END_FUNCTION_BLOCK before the end of the text",
            ));
        }
        self.finish()
    }

    fn statement(&mut self, line: usize, statement: &str) -> Result<(), FuzzyError> {
        let (head, rest) = split_word(statement);
        let keyword = head.to_ascii_uppercase();
        match (self.block, keyword.as_str()) {
            (Section::Outside, "FUNCTION_BLOCK") => {
                self.name = if rest.is_empty() {
                    "fcl".to_string()
                } else {
                    rest.to_string()
                };
                self.block = Section::FunctionBlock;
            }
            (Section::Outside, _) => {
                return Err(error(
                    line,
                    format!("expected FUNCTION_BLOCK, found `{statement}`"),
                ));
            }
            (Section::FunctionBlock, "VAR_INPUT" | "VAR_OUTPUT") => {
                self.block = if keyword == "VAR_INPUT" {
                    Section::VarInput
                } else {
                    Section::VarOutput
                };
                // A declaration may follow on the same line: `VAR_INPUT x : REAL;`.
                if !rest.is_empty() {
                    self.statement(line, rest)?;
                }
            }
            (Section::FunctionBlock, "FUZZIFY") => {
                let k = self.input_index.get(rest).copied().ok_or_else(|| {
                    error(
                        line,
                        format!("FUZZIFY of '{rest}', which VAR_INPUT does not declare"),
                    )
                })?;
                if self.inputs[k].defined {
                    return Err(error(line, format!("a second FUZZIFY block for '{rest}'")));
                }
                self.inputs[k].defined = true;
                self.block = Section::Fuzzify(k);
            }
            (Section::FunctionBlock, "DEFUZZIFY") => {
                let k = self.output_index.get(rest).copied().ok_or_else(|| {
                    error(
                        line,
                        format!("DEFUZZIFY of '{rest}', which VAR_OUTPUT does not declare"),
                    )
                })?;
                if self.outputs[k].defined {
                    return Err(error(
                        line,
                        format!("a second DEFUZZIFY block for '{rest}'"),
                    ));
                }
                self.outputs[k].defined = true;
                self.block = Section::Defuzzify(k);
            }
            (Section::FunctionBlock, "RULEBLOCK") => self.block = Section::RuleBlock,
            (Section::FunctionBlock, "END_FUNCTION_BLOCK") => self.block = Section::Done,
            (Section::FunctionBlock, _) => {
                return Err(error(
                    line,
                    format!(
                        "expected VAR_INPUT, VAR_OUTPUT, FUZZIFY, DEFUZZIFY, RULEBLOCK or \
                         END_FUNCTION_BLOCK, found `{statement}`"
                    ),
                ));
            }
            (Section::VarInput | Section::VarOutput, "END_VAR") => {
                self.block = Section::FunctionBlock
            }
            (Section::VarInput | Section::VarOutput, _) => {
                let (name, kind) = statement
                    .split_once(':')
                    .map(|(n, k)| (n.trim(), k.trim()))
                    .ok_or_else(|| {
                        error(line, format!("expected `name : REAL`, found `{statement}`"))
                    })?;
                if !kind.eq_ignore_ascii_case("REAL") {
                    return Err(error(
                        line,
                        format!("variable '{name}' has type {kind}; expected REAL"),
                    ));
                }
                if !is_identifier(name) {
                    return Err(error(line, format!("'{name}' is not an FCL identifier")));
                }
                if self.input_index.contains_key(name) || self.output_index.contains_key(name) {
                    return Err(error(line, format!("variable '{name}' is declared twice")));
                }
                let variable = Variable {
                    name: name.to_string(),
                    line,
                    ..Variable::default()
                };
                if self.block == Section::VarInput {
                    self.input_index.insert(name.to_string(), self.inputs.len());
                    self.inputs.push(variable);
                } else {
                    self.output_index
                        .insert(name.to_string(), self.outputs.len());
                    self.outputs.push(variable);
                }
            }
            (Section::Fuzzify(_), "END_FUZZIFY") | (Section::Defuzzify(_), "END_DEFUZZIFY") => {
                self.block = Section::FunctionBlock;
            }
            (Section::Fuzzify(k) | Section::Defuzzify(k), "RANGE") => {
                let variable = match self.block {
                    Section::Fuzzify(_) => &mut self.inputs[k],
                    _ => &mut self.outputs[k],
                };
                variable.range = Some(parse_range(line, rest)?);
                variable.range_line = line;
            }
            (Section::Fuzzify(k), "TERM") => {
                let (name, value) = term_definition(line, rest)?;
                let membership = input_term(line, value)?;
                self.inputs[k].new_term(line, name)?;
                self.inputs[k].input_sets.push(FuzzySet {
                    name: name.to_string(),
                    membership,
                });
            }
            (Section::Defuzzify(k), "TERM") => {
                let (name, value) = term_definition(line, rest)?;
                let n_inputs = self.inputs.len();
                let function = output_term(line, value, n_inputs)?;
                self.outputs[k].new_term(line, name)?;
                self.outputs[k].output_terms.push(OutputTerm {
                    name: name.to_string(),
                    function,
                });
            }
            (Section::Defuzzify(_), "METHOD") => {
                let method = setting(line, rest)?;
                let value = match method.to_ascii_uppercase().as_str() {
                    "COGS" => Defuzzification::WeightedAverage,
                    "COGSS" => Defuzzification::WeightedSum,
                    _ => {
                        return Err(error(
                            line,
                            format!(
                                "METHOD {method} is a Mamdani defuzzifier; this crate reads Sugeno \
                                 systems (COGS, or fuzzylite's COGSS)"
                            ),
                        ));
                    }
                };
                match self.defuzzification {
                    Some((other, first)) if other != value => {
                        return Err(error(
                            line,
                            format!(
                                "METHOD differs from the one at line {first}; a system has one defuzzifier"
                            ),
                        ));
                    }
                    _ => self.defuzzification = Some((value, line)),
                }
            }
            (Section::Defuzzify(_), "DEFAULT" | "ACCU" | "LOCK")
            | (Section::RuleBlock, "ACT" | "ACCU") => {}
            (Section::Fuzzify(_), _) => {
                return Err(error(
                    line,
                    format!("expected RANGE, TERM or END_FUZZIFY, found `{statement}`"),
                ));
            }
            (Section::Defuzzify(_), _) => {
                return Err(error(
                    line,
                    format!(
                        "expected RANGE, TERM, METHOD, DEFAULT, ACCU or END_DEFUZZIFY, found `{statement}`"
                    ),
                ));
            }
            (Section::RuleBlock, "AND") => {
                let value = match setting(line, rest)?.to_ascii_uppercase().as_str() {
                    "PROD" => AndMethod::Product,
                    "MIN" => AndMethod::Minimum,
                    other => {
                        return Err(error(
                            line,
                            format!("AND : {other} is not supported; expected PROD or MIN"),
                        ));
                    }
                };
                agree(&mut self.and, value, line, "AND")?;
            }
            (Section::RuleBlock, "OR") => {
                let value = match setting(line, rest)?.to_ascii_uppercase().as_str() {
                    "ASUM" => OrMethod::ProbabilisticSum,
                    "MAX" => OrMethod::Maximum,
                    other => {
                        return Err(error(
                            line,
                            format!("OR : {other} is not supported; expected ASUM or MAX"),
                        ));
                    }
                };
                agree(&mut self.or, value, line, "OR")?;
            }
            (Section::RuleBlock, "RULE") => {
                let body = rest
                    .split_once(':')
                    .map(|(_, body)| body.trim())
                    .ok_or_else(|| {
                        error(
                            line,
                            format!("expected `RULE n : IF ...`, found `{statement}`"),
                        )
                    })?;
                self.rules.push((line, body.to_string()));
            }
            (Section::RuleBlock, "END_RULEBLOCK") => self.block = Section::FunctionBlock,
            (Section::RuleBlock, _) => {
                return Err(error(
                    line,
                    format!(
                        "expected AND, OR, ACT, ACCU, RULE or END_RULEBLOCK, found `{statement}`"
                    ),
                ));
            }
            (Section::Done, _) => {
                return Err(error(
                    line,
                    format!("text after END_FUNCTION_BLOCK: `{statement}`"),
                ));
            }
        }
        Ok(())
    }

    fn finish(self) -> Result<FuzzySystem, FuzzyError> {
        let mut inputs = Vec::with_capacity(self.inputs.len());
        for v in &self.inputs {
            if !v.defined {
                return Err(error(
                    v.line,
                    format!("input '{}' has no FUZZIFY block", v.name),
                ));
            }
            let range = v.range.ok_or_else(|| {
                error(
                    v.line,
                    format!(
                        "input '{}' has no RANGE (this crate needs every variable's range)",
                        v.name
                    ),
                )
            })?;
            inputs.push(InputVariable {
                name: v.name.clone(),
                range,
                sets: v.input_sets.clone(),
            });
        }
        let mut outputs = Vec::with_capacity(self.outputs.len());
        for v in &self.outputs {
            if !v.defined {
                return Err(error(
                    v.line,
                    format!("output '{}' has no DEFUZZIFY block", v.name),
                ));
            }
            let range = v.range.ok_or_else(|| {
                error(
                    v.line,
                    format!(
                        "output '{}' has no RANGE (this crate needs every variable's range)",
                        v.name
                    ),
                )
            })?;
            outputs.push(OutputVariable {
                name: v.name.clone(),
                range,
                terms: v.output_terms.clone(),
            });
        }
        let mut rules = Vec::with_capacity(self.rules.len());
        for (line, text) in &self.rules {
            let variables = Variables {
                inputs: &inputs,
                outputs: &outputs,
                input_index: &self.input_index,
                output_index: &self.output_index,
            };
            rules.push(parse_rule(*line, text, &variables)?);
        }
        let methods = Methods {
            and: self.and.map_or(AndMethod::default(), |(m, _)| m),
            or: self.or.map_or(OrMethod::default(), |(m, _)| m),
            defuzzification: self
                .defuzzification
                .map_or(Defuzzification::default(), |(m, _)| m),
        };
        FuzzySystem::new(self.name.clone(), inputs, outputs, rules, methods)
            .map_err(|e| error(self.line_of(&e), e.to_string()))
    }

    /// The line a refusal of the whole system points at: the `RANGE`, `TERM` or `RULE` it names
    /// (an invalid range, set, term or rule weight), else the variable's declaration, else 1.
    fn line_of(&self, e: &FuzzyError) -> usize {
        let FuzzyError::InvalidSystem { context, problem } = e else {
            return 1;
        };
        if let Some(n) = context.strip_prefix("rule ") {
            return n
                .parse::<usize>()
                .ok()
                .and_then(|n| self.rules.get(n.wrapping_sub(1)))
                .map_or(1, |(line, _)| *line);
        }
        // `input 'x'`, `input 'x' set 's'`, `output 'y' term 't'`: FCL names carry no quote.
        let parts: Vec<&str> = context.split('\'').collect();
        let variables = match parts[0].trim() {
            "input" => &self.inputs,
            "output" => &self.outputs,
            _ => return 1,
        };
        let Some(v) = parts
            .get(1)
            .and_then(|name| variables.iter().find(|v| v.name == *name))
        else {
            return 1;
        };
        if let Some(term) = parts.get(3) {
            let names = v
                .input_sets
                .iter()
                .map(|s| s.name.as_str())
                .chain(v.output_terms.iter().map(|t| t.name.as_str()));
            return names
                .zip(&v.term_lines)
                .find(|(name, _)| name == term)
                .map_or(v.line, |(_, line)| *line);
        }
        match problem {
            SystemProblem::Range { .. } => v.range_line,
            _ => v.line,
        }
    }
}

fn agree<T: PartialEq + Copy>(
    slot: &mut Option<(T, usize)>,
    value: T,
    line: usize,
    what: &str,
) -> Result<(), FuzzyError> {
    match *slot {
        Some((other, first)) if other != value => Err(error(
            line,
            format!("{what} differs from the one at line {first}; a system has one {what} method"),
        )),
        _ => {
            *slot = Some((value, line));
            Ok(())
        }
    }
}

/// The line without its comments; `in_comment` carries an open `(*` to the next line.
fn strip_comments(raw: &str, in_comment: &mut bool) -> String {
    let mut out = String::new();
    let mut rest = raw;
    loop {
        if *in_comment {
            match rest.find("*)") {
                Some(end) => {
                    rest = &rest[end + 2..];
                    *in_comment = false;
                }
                None => return out,
            }
        }
        let open = rest.find("(*");
        let slash = rest.find("//");
        match (open, slash) {
            (Some(o), Some(s)) if s < o => return out + &rest[..s],
            (None, Some(s)) => return out + &rest[..s],
            (Some(o), _) => {
                out.push_str(&rest[..o]);
                out.push(' ');
                rest = &rest[o + 2..];
                *in_comment = true;
            }
            (None, None) => return out + rest,
        }
    }
}

/// The `;`-separated statements of a line, trimmed, empty ones dropped.
fn split_statements(line: &str) -> impl Iterator<Item = &str> {
    line.split(';').map(str::trim).filter(|s| !s.is_empty())
}

/// The first word (up to whitespace or `:`) and the rest, trimmed.
fn split_word(statement: &str) -> (&str, &str) {
    let end = statement
        .find(|c: char| c.is_whitespace() || c == ':')
        .unwrap_or(statement.len());
    (&statement[..end], statement[end..].trim())
}

/// The value of `: VALUE`.
fn setting(line: usize, rest: &str) -> Result<&str, FuzzyError> {
    rest.strip_prefix(':')
        .map(str::trim)
        .filter(|v| !v.is_empty())
        .ok_or_else(|| error(line, format!("expected `: VALUE`, found `{rest}`")))
}

fn number(line: usize, text: &str) -> Result<f64, FuzzyError> {
    let value: f64 = text
        .trim()
        .parse()
        .map_err(|_| error(line, format!("expected a number, found `{}`", text.trim())))?;
    if value.is_finite() {
        Ok(value)
    } else {
        Err(error(
            line,
            format!("expected a finite number, found {value}"),
        ))
    }
}

/// `:= (min .. max)`.
fn parse_range(line: usize, rest: &str) -> Result<[f64; 2], FuzzyError> {
    let inner = rest
        .strip_prefix(":=")
        .map(str::trim)
        .and_then(|r| r.strip_prefix('('))
        .and_then(|r| r.strip_suffix(')'))
        .ok_or_else(|| {
            error(
                line,
                format!("expected `RANGE := (min .. max)`, found `RANGE {rest}`"),
            )
        })?;
    let (lo, hi) = inner
        .split_once("..")
        .ok_or_else(|| error(line, format!("expected `min .. max`, found `{inner}`")))?;
    Ok([number(line, lo)?, number(line, hi)?])
}

/// `name := value`.
fn term_definition(line: usize, rest: &str) -> Result<(&str, &str), FuzzyError> {
    let (name, value) = rest
        .split_once(":=")
        .map(|(n, v)| (n.trim(), v.trim()))
        .ok_or_else(|| {
            error(
                line,
                format!("expected `TERM name := ...`, found `TERM {rest}`"),
            )
        })?;
    if !is_identifier(name) {
        return Err(error(line, format!("'{name}' is not an FCL identifier")));
    }
    Ok((name, value))
}

/// A fuzzylite class name and its parameters, the last one a height that must be 1 if present.
fn class_parameters(line: usize, value: &str) -> Result<(&str, Vec<f64>), FuzzyError> {
    let mut words = value.split_whitespace();
    let class = words.next().unwrap_or("");
    let params = words
        .map(|w| number(line, w))
        .collect::<Result<Vec<_>, _>>()?;
    Ok((class, params))
}

fn arity(line: usize, class: &str, params: &[f64], n: usize) -> Result<(), FuzzyError> {
    match params.len() {
        k if k == n => Ok(()),
        k if k == n + 1 && params[n] == 1.0 => Ok(()),
        k if k == n + 1 => Err(error(
            line,
            format!(
                "{class} with height {}: only height 1 is supported",
                params[n]
            ),
        )),
        k => Err(error(
            line,
            format!("{class} takes {n} parameters, got {k}"),
        )),
    }
}

/// An input term: an IEC point list (triangle, trapezoid or shoulder) or a fuzzylite class.
fn input_term(line: usize, value: &str) -> Result<MembershipFn, FuzzyError> {
    let mf = if value.starts_with('(') {
        points(line, value)?
    } else {
        let (class, p) = class_parameters(line, value)?;
        let Some(kind) = Kind::by_fcl_class(class) else {
            if class.parse::<f64>().is_ok() {
                return Err(error(line, "singleton input terms are not supported"));
            }
            let classes: Vec<&str> = KINDS.iter().map(|kind| kind.fcl).collect();
            return Err(error(
                line,
                format!(
                    "input term class '{class}' is not supported; expected a point list or one \
                     of {}",
                    classes.join(", ")
                ),
            ));
        };
        arity(line, class, &p, kind.parameters)?;
        // fuzzylite's order to MATLAB's.
        let mut params = [0.0; 4];
        for (&i, &value) in kind.fcl_order.iter().zip(&p) {
            params[i] = value;
        }
        (kind.build)(&params[..kind.parameters])
    };
    mf.validate().map_err(|e| error(line, e.to_string()))?;
    Ok(mf)
}

/// A point list `(x1, y1) (x2, y2) ...` of the shapes MATLAB has: a triangle (0 1 0) or a
/// trapezoid (0 1 1 0).
fn points(line: usize, value: &str) -> Result<MembershipFn, FuzzyError> {
    let mut pts = Vec::new();
    let mut rest = value.trim();
    while !rest.is_empty() {
        let inner = rest
            .strip_prefix('(')
            .and_then(|r| r.split_once(')'))
            .ok_or_else(|| error(line, format!("expected `(x, y)` points, found `{rest}`")))?;
        let (x, y) = inner
            .0
            .split_once(',')
            .ok_or_else(|| error(line, format!("expected `(x, y)`, found `({})`", inner.0)))?;
        pts.push((number(line, x)?, number(line, y)?));
        rest = inner.1.trim();
        if pts.len() > 4 {
            break;
        }
    }
    let xs: Vec<f64> = pts.iter().map(|p| p.0).collect();
    let ys: Vec<f64> = pts.iter().map(|p| p.1).collect();
    match ys.as_slice() {
        [0.0, 1.0, 0.0] => Ok(MembershipFn::triangle(xs[0], xs[1], xs[2])),
        [0.0, 1.0, 1.0, 0.0] => Ok(MembershipFn::trapezoid(xs[0], xs[1], xs[2], xs[3])),
        _ => Err(error(
            line,
            format!(
                "the point list `{value}` is not a triangle (0 1 0) or a trapezoid (0 1 1 0), the \
                 piecewise-linear shapes MATLAB's .fis has"
            ),
        )),
    }
}

/// An output term: a singleton (IEC), `Constant c` or `Linear p1 .. pn r` (fuzzylite).
fn output_term(line: usize, value: &str, n_inputs: usize) -> Result<OutputFn, FuzzyError> {
    if let Ok(c) = value.parse::<f64>() {
        return Ok(OutputFn::Constant(number(line, value).map(|_| c)?));
    }
    let (class, p) = class_parameters(line, value)?;
    match class {
        "Constant" => {
            arity(line, class, &p, 1)?;
            Ok(OutputFn::Constant(p[0]))
        }
        "Linear" if p.len() == n_inputs + 1 => Ok(OutputFn::Linear {
            coefficients: p[..n_inputs].to_vec(),
            constant: p[n_inputs],
        }),
        "Linear" => Err(error(
            line,
            format!(
                "Linear has {} parameters; with {n_inputs} inputs it needs {}",
                p.len(),
                n_inputs + 1
            ),
        )),
        _ => Err(error(
            line,
            format!(
                "output term `{value}` is not a Sugeno consequent; expected a number, Constant or Linear"
            ),
        )),
    }
}

/// The variables a rule names, with their places by name.
struct Variables<'a> {
    inputs: &'a [InputVariable],
    outputs: &'a [OutputVariable],
    input_index: &'a HashMap<String, usize>,
    output_index: &'a HashMap<String, usize>,
}

/// `IF x IS [NOT] a AND|OR ... THEN z IS c [, AND ...] [WITH w]`.
fn parse_rule(line: usize, text: &str, variables: &Variables<'_>) -> Result<Rule, FuzzyError> {
    let Variables {
        inputs,
        outputs,
        input_index,
        output_index,
    } = *variables;
    let words: Vec<&str> = text.split_whitespace().collect();
    let upper: Vec<String> = words.iter().map(|w| w.to_ascii_uppercase()).collect();
    let fail = |message: String| error(line, message);
    if upper.first().map(String::as_str) != Some("IF") {
        return Err(fail(format!(
            "expected the rule to start with IF, found `{text}`"
        )));
    }
    if words.iter().any(|w| w.contains('(') || w.contains(')')) {
        return Err(fail(
            "parentheses in rules are not supported (a .fis rule has one connective)".to_string(),
        ));
    }
    let then = upper
        .iter()
        .position(|w| w == "THEN")
        .ok_or_else(|| fail("expected THEN".to_string()))?;
    let with = upper.iter().position(|w| w == "WITH");
    let weight = match with {
        Some(k) if k + 2 == words.len() => number(line, words[k + 1])?,
        Some(_) => {
            return Err(fail(
                "expected one number after WITH, at the end of the rule".to_string(),
            ));
        }
        None => 1.0,
    };
    let mut antecedents = vec![Antecedent::Any; inputs.len()];
    let mut connective = None;
    let mut k = 1;
    while k < then {
        if k > 1 {
            let c = match upper[k].as_str() {
                "AND" => Connective::And,
                "OR" => Connective::Or,
                other => return Err(fail(format!("expected AND or OR, found `{other}`"))),
            };
            if connective.is_some_and(|first| first != c) {
                return Err(fail(
                    "the rule mixes AND and OR; a .fis rule has one connective".to_string(),
                ));
            }
            connective = Some(c);
            k += 1;
        }
        let negated = upper.get(k + 2).is_some_and(|w| w == "NOT");
        let end = k + 3 + usize::from(negated);
        if end > then || upper[k + 1] != "IS" {
            return Err(fail(format!(
                "expected `variable IS [NOT] term` at `{}`",
                words[k..then].join(" ")
            )));
        }
        let (variable, term) = (words[k], words[end - 1]);
        let i = input_index
            .get(variable)
            .copied()
            .ok_or_else(|| fail(format!("'{variable}' is not an input")))?;
        let set = inputs[i]
            .sets
            .iter()
            .position(|s| s.name == term)
            .ok_or_else(|| {
                fail(format!(
                    "input '{variable}' has no term '{term}' (hedges other than NOT are not supported)"
                ))
            })?;
        if antecedents[i] != Antecedent::Any {
            return Err(fail(format!(
                "input '{variable}' appears twice in the premise"
            )));
        }
        antecedents[i] = if negated {
            Antecedent::IsNot(set)
        } else {
            Antecedent::Is(set)
        };
        k = end;
    }
    let mut consequents = vec![None; outputs.len()];
    let conclusion_end = with.unwrap_or(words.len());
    let mut k = then + 1;
    while k < conclusion_end {
        if k > then + 1 && (upper[k] == "AND" || upper[k] == ",") {
            k += 1;
        }
        let (variable, term) = match words.get(k..k + 3) {
            Some([v, is, t]) if is.eq_ignore_ascii_case("IS") => (*v, t.trim_end_matches(',')),
            _ => {
                return Err(fail(format!(
                    "expected `variable IS term` after THEN, at `{}`",
                    words[k..conclusion_end].join(" ")
                )));
            }
        };
        let o = output_index
            .get(variable.trim_start_matches(','))
            .copied()
            .ok_or_else(|| fail(format!("'{variable}' is not an output")))?;
        let t = outputs[o]
            .terms
            .iter()
            .position(|t| t.name == term)
            .ok_or_else(|| fail(format!("output '{variable}' has no term '{term}'")))?;
        if consequents[o].is_some() {
            return Err(fail(format!(
                "output '{variable}' appears twice in the conclusion"
            )));
        }
        consequents[o] = Some(t);
        k += 3;
    }
    Ok(Rule {
        antecedents,
        consequents,
        weight,
        connective: connective.unwrap_or_default(),
    })
}
