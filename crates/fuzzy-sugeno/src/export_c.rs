//! Export of a system as self-contained C99: one header and one source file that evaluate it
//! exactly as [`Evaluator`](crate::Evaluator) does, with no heap, no mutable global state and no
//! dependency beyond `<math.h>`.
//!
//! The generated code follows the evaluator's compiled tables operation by operation (the same
//! membership formulas, integer bell exponents by the same repeated squaring, the same order of
//! every sum and product), so on an IEEE-754 machine it agrees with the Rust evaluator's general
//! kernel to rounding, and with its separable form of a complete grid (the paper's controller,
//! `separable.rs`) within 8 `f64::EPSILON` times the largest conclusion. The evaluation policies are fixed at export time from [`EvalOptions`]:
//!
//! | return code | meaning (the Rust error) |
//! |---|---|
//! | 0 | success, `out` written |
//! | 1 | an input is NaN or infinite ([`FuzzyError::NonFiniteInput`]) |
//! | 2 | an input lies outside its range under [`OutOfRange::Error`] ([`FuzzyError::InputOutOfRange`]) |
//! | 3 | no rule fired for an output under [`NoRuleFired::Error`] ([`FuzzyError::NoRuleFired`]) |
//! | 4 | an output came out non-finite ([`FuzzyError::NonFiniteOutput`]) |
//!
//! On a non-zero return `out` is left untouched, as the evaluator leaves its buffer.

use crate::compiled_mf::CompiledMf;
use crate::error::FuzzyError;
use crate::options::{EvalOptions, NoRuleFired, OutOfRange};
use crate::system::{AndMethod, Defuzzification, FuzzySystem, OrMethod};
use std::fmt::Write as _;

/// The longest prefix accepted (C99 guarantees 31 significant characters for external names,
/// and the prefix gets `_eval` appended).
const MAX_PREFIX: usize = 26;

/// The two files of an exported system.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CSource {
    /// The header's file name, `<prefix>.h`.
    pub header_name: String,
    /// The header: the evaluation function's declaration, the sizes and the return codes.
    pub header: String,
    /// The source's file name, `<prefix>.c`.
    pub source_name: String,
    /// The source: the evaluation function.
    pub source: String,
}

impl FuzzySystem {
    /// Writes the system as C99 evaluating `int <prefix>_eval(const double *in, double *out)`
    /// under the given policies (see the module documentation for the return codes). The prefix
    /// must be a C identifier of at most 26 characters (`hrm_fis` gives `hrm_fis_eval`).
    ///
    /// ```
    /// use fuzzy_sugeno::{paper_controller, EvalOptions};
    /// let c = paper_controller().to_c("paper", &EvalOptions::default())?;
    /// assert!(c.header.contains("int paper_eval(const double *in, double *out);"));
    /// assert!(!c.source.contains("pow(")); // b = 2 bells: (u^2)^2
    /// # Ok::<(), fuzzy_sugeno::FuzzyError>(())
    /// ```
    pub fn to_c(&self, prefix: &str, options: &EvalOptions) -> Result<CSource, FuzzyError> {
        check_prefix(prefix)?;
        options.check(self.outputs().len())?;
        Ok(CSource {
            header_name: format!("{prefix}.h"),
            header: header(self, prefix, options),
            source_name: format!("{prefix}.c"),
            source: source(self, prefix, options),
        })
    }
}

fn check_prefix(prefix: &str) -> Result<(), FuzzyError> {
    let mut chars = prefix.chars();
    // Names are `{prefix}_{name}`: a leading underscore would make `__name`, reserved in C.
    let valid_start = chars.next().is_some_and(|c| c.is_ascii_alphabetic());
    if !valid_start
        || !chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
        || prefix.len() > MAX_PREFIX
    {
        return Err(FuzzyError::CPrefix {
            prefix: prefix.to_string(),
            max: MAX_PREFIX,
        });
    }
    match STANDARD_HEADERS
        .iter()
        .find(|name| name.eq_ignore_ascii_case(prefix))
    {
        Some(standard) => Err(FuzzyError::CPrefixShadowsHeader {
            prefix: prefix.to_string(),
            standard,
        }),
        None => Ok(()),
    }
}

/// The headers of the C standard library (C99, C11, C23) without `.h`: a prefix naming one
/// (in any case, for case-insensitive file systems) would write a header that shadows it.
const STANDARD_HEADERS: [&str; 31] = [
    "assert",
    "complex",
    "ctype",
    "errno",
    "fenv",
    "float",
    "inttypes",
    "iso646",
    "limits",
    "locale",
    "math",
    "setjmp",
    "signal",
    "stdalign",
    "stdarg",
    "stdatomic",
    "stdbit",
    "stdbool",
    "stdckdint",
    "stddef",
    "stdint",
    "stdio",
    "stdlib",
    "stdnoreturn",
    "string",
    "tgmath",
    "threads",
    "time",
    "uchar",
    "wchar",
    "wctype",
];

/// A C double literal that reads back as exactly `v` (Rust's shortest round-trip form, which
/// is valid C), parenthesised when negative so that `x - (-1)` never becomes `x--1`.
fn lit(v: f64) -> String {
    if v.is_sign_negative() {
        format!("({v:?})")
    } else {
        format!("{v:?}")
    }
}

/// A C comment's text: no `*/` (which would end it) nor `/*` (which `-Wcomment` warns of)
/// inside, and control, zero-width and bidirectional formatting
/// characters written as `\u{202e}` (a right-to-left override in a name would make the
/// source read otherwise than it compiles).
fn comment(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.replace("*/", "* /").replace("/*", "/ *").chars() {
        if c.is_control() || is_invisible_format(c) {
            let _ = write!(out, "{}", c.escape_unicode());
        } else {
            out.push(c);
        }
    }
    out
}

/// Unicode's zero-width and bidirectional formatting characters (category `Cf` in the ranges
/// that reorder or hide text): U+061C, U+200B to U+200F, U+202A to U+202E, U+2060 to U+2069,
/// U+FEFF.
fn is_invisible_format(c: char) -> bool {
    matches!(c, '\u{061c}' | '\u{200b}'..='\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2060}'..='\u{2069}' | '\u{feff}')
}

fn header(system: &FuzzySystem, prefix: &str, options: &EvalOptions) -> String {
    let upper = prefix.to_ascii_uppercase();
    let mut h = String::new();
    let _ = writeln!(
        h,
        "/* {prefix}.h: the Sugeno fuzzy system '{}', exported by hrm (fuzzy-sugeno) as C99.\n * \
         No heap, no global state, only <math.h>. */\n#ifndef {upper}_H\n#define {upper}_H\n\n\
         #ifdef __cplusplus\nextern \"C\" {{\n#endif\n",
        comment(system.name())
    );
    let _ = writeln!(
        h,
        "#define {upper}_N_INPUTS {}\n#define {upper}_N_OUTPUTS {}\n",
        system.inputs().len(),
        system.outputs().len()
    );
    let _ = writeln!(
        h,
        "/* Return codes of {prefix}_eval. */\n#define {upper}_OK 0\n#define {upper}_NON_FINITE_INPUT 1\n\
         #define {upper}_INPUT_OUT_OF_RANGE 2\n#define {upper}_NO_RULE_FIRED 3\n\
         #define {upper}_NON_FINITE_OUTPUT 4\n"
    );
    let _ = writeln!(h, "/* Evaluates the system.\n *\n * in:");
    for (i, input) in system.inputs().iter().enumerate() {
        let _ = writeln!(
            h,
            " *   in[{i}]  {} in [{:?}, {:?}]",
            comment(&input.name),
            input.range[0],
            input.range[1]
        );
    }
    let _ = writeln!(h, " * out:");
    for (o, output) in system.outputs().iter().enumerate() {
        let _ = writeln!(h, " *   out[{o}] {}", comment(&output.name));
    }
    let range = match options.out_of_range {
        OutOfRange::Clamp => "clamped to their ranges",
        OutOfRange::AsGiven => "used as given, even outside their ranges",
        OutOfRange::Error => "refused outside their ranges",
    };
    let no_rule = match options.no_rule_fired {
        NoRuleFired::MiddleOfRange => "the middle of its range",
        NoRuleFired::Values(_) => "a fixed value",
        NoRuleFired::Error => "an error",
    };
    let _ = writeln!(
        h,
        " *\n * Inputs are {range}; an output on which no rule fires is {no_rule}.\n * \
         Returns {upper}_OK and writes out, or a non-zero code and leaves out untouched. */\n\
         int {prefix}_eval(const double *in, double *out);\n\n#ifdef __cplusplus\n}}\n#endif\n\n\
         #endif /* {upper}_H */"
    );
    h
}

fn source(system: &FuzzySystem, prefix: &str, options: &EvalOptions) -> String {
    let c = system.compiled();
    let upper = prefix.to_ascii_uppercase();
    let n_in = system.inputs().len();
    let n_out = system.outputs().len();
    let n_mf = c.mfs.len();
    let n_rules = c.weights.len();
    let mut s = String::new();
    let _ = writeln!(
        s,
        "/* {prefix}.c: the Sugeno fuzzy system '{}', exported by hrm (fuzzy-sugeno) as C99.\n * \
         It evaluates the system as the Rust evaluator does, operation by operation. */\n\
         #include <math.h>\n#include \"{prefix}.h\"\n",
        comment(system.name())
    );
    let uses = |f: fn(&CompiledMf) -> bool| c.mfs.iter().any(f);
    if uses(|m| matches!(m, CompiledMf::BellInteger { .. })) {
        let _ = writeln!(
            s,
            "/* base^exponent by repeated squaring (integer bell exponents, no pow). */\n\
             static double {prefix}_ipow(double base, unsigned exponent)\n{{\n    double result = 1.0;\n    \
             while (exponent > 0u) {{\n        if (exponent & 1u) {{\n            result *= base;\n        }}\n        \
             base *= base;\n        exponent >>= 1;\n    }}\n    return result;\n}}\n"
        );
    }
    if uses(|m| {
        matches!(
            m,
            CompiledMf::Sigmoid { .. }
                | CompiledMf::SigmoidDifference { .. }
                | CompiledMf::SigmoidProduct { .. }
        )
    }) {
        let _ = writeln!(
            s,
            "static double {prefix}_sigmoid(double x, double slope, double center)\n{{\n    \
             return 1.0 / (1.0 + exp(-slope * (x - center)));\n}}\n"
        );
    }
    if uses(|m| {
        matches!(
            m,
            CompiledMf::Gaussian { .. } | CompiledMf::Gaussian2 { .. }
        )
    }) {
        let _ = writeln!(
            s,
            "static double {prefix}_gaussian(double x, double center, double k)\n{{\n    \
             double d = x - center;\n    return exp(-(d * d) * k);\n}}\n"
        );
    }
    if uses(|m| matches!(m, CompiledMf::SShape { .. } | CompiledMf::PiShape { .. })) {
        let _ = writeln!(
            s,
            "/* MATLAB's smf: quadratic spline from 0 at a to 1 at b, a step at (a + b) / 2 if a >= b. */\n\
             static double {prefix}_smf(double x, double a, double b)\n{{\n    \
             double middle = 0.5 * (a + b);\n    double t;\n    \
             if (a >= b) {{\n        return x >= middle ? 1.0 : 0.0;\n    }}\n    \
             if (x <= a) {{\n        return 0.0;\n    }}\n    \
             if (x <= middle) {{\n        t = (x - a) / (b - a);\n        return 2.0 * t * t;\n    }}\n    \
             if (x <= b) {{\n        t = (b - x) / (b - a);\n        return 1.0 - 2.0 * t * t;\n    }}\n    \
             return 1.0;\n}}\n"
        );
    }
    if uses(|m| matches!(m, CompiledMf::ZShape { .. } | CompiledMf::PiShape { .. })) {
        let _ = writeln!(
            s,
            "/* MATLAB's zmf: quadratic spline from 1 at a to 0 at b, a step at (a + b) / 2 if a >= b. */\n\
             static double {prefix}_zmf(double x, double a, double b)\n{{\n    \
             double middle = 0.5 * (a + b);\n    double t;\n    \
             if (a >= b) {{\n        return x <= middle ? 1.0 : 0.0;\n    }}\n    \
             if (x <= a) {{\n        return 1.0;\n    }}\n    \
             if (x <= middle) {{\n        t = (x - a) / (b - a);\n        return 1.0 - 2.0 * t * t;\n    }}\n    \
             if (x <= b) {{\n        t = (b - x) / (b - a);\n        return 2.0 * t * t;\n    }}\n    \
             return 0.0;\n}}\n"
        );
    }
    let methods = system.methods();
    // First-order terms by their index in the term table, and whether any rule uses one.
    let linear: std::collections::HashMap<usize, usize> = c.linear_terms.iter().copied().collect();
    let uses_linear = c
        .conclusions
        .iter()
        .any(|&[_, t]| linear.contains_key(&(t as usize)));
    if c.is_or.iter().any(|&o| o) && methods.or == OrMethod::ProbabilisticSum {
        let _ = writeln!(
            s,
            "static double {prefix}_probor(double a, double b)\n{{\n    return a + b - a * b;\n}}\n"
        );
    }
    let _ = writeln!(
        s,
        "int {prefix}_eval(const double *in, double *out)\n{{\n    double x[{n_in}];\n    \
         double mu[{}];\n{}    double y[{n_out}];\n    double {}weighted, total;\n    int i;\n",
        c.degree_count,
        // A system without rules has no strengths (and C no arrays of length 0).
        if n_rules > 0 {
            format!("    double w[{n_rules}];\n")
        } else {
            String::new()
        },
        if uses_linear { "t, " } else { "" }
    );
    // Inputs and the range policy (Evaluator::load_inputs).
    for (i, input) in system.inputs().iter().enumerate() {
        let [lo, hi] = input.range;
        let _ = writeln!(
            s,
            "    if (!isfinite(in[{i}])) {{\n        return {upper}_NON_FINITE_INPUT;\n    }}"
        );
        match options.out_of_range {
            OutOfRange::Clamp => {
                let _ = writeln!(
                    s,
                    "    x[{i}] = in[{i}] < {lo} ? {lo} : (in[{i}] > {hi} ? {hi} : in[{i}]);",
                    lo = lit(lo),
                    hi = lit(hi)
                );
            }
            OutOfRange::AsGiven => {
                let _ = writeln!(s, "    x[{i}] = in[{i}];");
            }
            OutOfRange::Error => {
                let _ = writeln!(
                    s,
                    "    if (in[{i}] < {lo} || in[{i}] > {hi}) {{\n        return {upper}_INPUT_OUT_OF_RANGE;\n    }}\n    x[{i}] = in[{i}];",
                    lo = lit(lo),
                    hi = lit(hi)
                );
            }
        }
    }
    // A system whose degrees all are constants reads no input: `x` is then set and unused,
    // which `-Wall -Wextra -Werror` refuses.
    if !c
        .mfs
        .iter()
        .any(|mf| !matches!(mf, CompiledMf::Constant(_)))
        && !uses_linear
    {
        let _ = writeln!(
            s,
            "    (void)x; /* no degree or output depends on an input */"
        );
    }
    // Membership degrees, then complements and the neutral elements (Evaluator::fire).
    let _ = writeln!(s, "    /* layer 1: membership degrees */");
    for (k, (mf, &i)) in c.mfs.iter().zip(&c.mf_inputs).enumerate() {
        let _ = writeln!(
            s,
            "    {}",
            degree(mf, &format!("x[{i}]"), &format!("mu[{k}]"), prefix)
        );
    }
    if c.has_complements {
        let _ = writeln!(
            s,
            "    for (i = 0; i < {n_mf}; ++i) {{\n        mu[{n_mf} + i] = 1.0 - mu[i];\n    }}"
        );
    }
    let _ = writeln!(
        s,
        "    mu[{}] = 1.0;\n    mu[{}] = 0.0;",
        c.degree_count - 2,
        c.degree_count - 1
    );
    // Firing strengths (fire_rules): weight * fold(neutral, op) in input order.
    let _ = writeln!(s, "    /* layer 2: firing strengths */");
    for (r, row) in c.antecedents.chunks_exact(n_in).enumerate() {
        let mut expr = if c.is_or[r] { "0.0" } else { "1.0" }.to_string();
        for &d in row {
            expr = match (c.is_or[r], methods.and, methods.or) {
                (false, AndMethod::Product, _) => format!("{expr} * mu[{d}]"),
                (false, AndMethod::Minimum, _) => format!("fmin({expr}, mu[{d}])"),
                (true, _, OrMethod::ProbabilisticSum) => {
                    format!("{prefix}_probor({expr}, mu[{d}])")
                }
                (true, _, OrMethod::Maximum) => format!("fmax({expr}, mu[{d}])"),
            };
        }
        let _ = writeln!(s, "    w[{r}] = {} * ({expr});", lit(c.weights[r]));
    }
    if n_rules == 0 {
        let _ = writeln!(s, "    (void)mu; /* no rule reads the degrees */");
    }
    // Outputs (Evaluator::defuzzify).
    let _ = writeln!(s, "    /* layers 3-5: outputs */");
    for (o, output) in system.outputs().iter().enumerate() {
        // The rules that conclude on the output, in rule order (kernel::sums).
        let bounds = c.conclusion_offsets[o]..c.conclusion_offsets[o + 1];
        let _ = writeln!(s, "    weighted = 0.0;\n    total = 0.0;");
        for &[rule, term] in &c.conclusions[bounds] {
            let term = term as usize;
            match linear.get(&term) {
                Some(&offset) => {
                    let p = &c.coefficients[offset..offset + n_in + 1];
                    let _ = writeln!(s, "    t = {};", lit(p[n_in]));
                    for (i, coefficient) in p[..n_in].iter().enumerate() {
                        let _ = writeln!(s, "    t = t + {} * x[{i}];", lit(*coefficient));
                    }
                    let _ = writeln!(s, "    weighted = weighted + w[{rule}] * t;");
                }
                None => {
                    let _ = writeln!(
                        s,
                        "    weighted = weighted + w[{rule}] * {};",
                        lit(c.term_values[term])
                    );
                }
            }
            let _ = writeln!(s, "    total = total + w[{rule}];");
        }
        let value = match methods.defuzzification {
            Defuzzification::WeightedAverage => "weighted / total",
            Defuzzification::WeightedSum => "weighted",
        };
        let fallback = match &options.no_rule_fired {
            NoRuleFired::MiddleOfRange => {
                format!(
                    "y[{o}] = {};",
                    lit(0.5 * (output.range[0] + output.range[1]))
                )
            }
            NoRuleFired::Values(values) => format!("y[{o}] = {};", lit(values[o])),
            NoRuleFired::Error => format!("return {upper}_NO_RULE_FIRED;"),
        };
        let _ = writeln!(
            s,
            "    if (total > 0.0) {{\n        y[{o}] = {value};\n    }} else {{\n        {fallback}\n    }}\n    \
             if (!isfinite(y[{o}])) {{\n        return {upper}_NON_FINITE_OUTPUT;\n    }}"
        );
    }
    let _ = writeln!(
        s,
        "    for (i = 0; i < {n_out}; ++i) {{\n        out[i] = y[i];\n    }}\n    return {upper}_OK;\n}}"
    );
    s
}

/// The C statement setting `target` to the degree of `x` (CompiledMf::eval, formula by formula).
fn degree(mf: &CompiledMf, x: &str, target: &str, prefix: &str) -> String {
    match *mf {
        CompiledMf::BellSquare { center, width } => format!(
            "{{ double u = ({x} - {}) / {}; {target} = 1.0 / (1.0 + u * u); }}",
            lit(center),
            lit(width)
        ),
        CompiledMf::BellQuartic { center, width } => format!(
            "{{ double u = ({x} - {}) / {}; double u2 = u * u; {target} = 1.0 / (1.0 + u2 * u2); }}",
            lit(center),
            lit(width)
        ),
        CompiledMf::BellInteger {
            center,
            width,
            exponent,
        } => format!(
            "{target} = 1.0 / (1.0 + {prefix}_ipow(fabs(({x} - {}) / {}), {exponent}u));",
            lit(center),
            lit(width)
        ),
        CompiledMf::BellReal {
            center,
            width,
            exponent,
        } => format!(
            "{target} = 1.0 / (1.0 + pow(fabs(({x} - {}) / {}), {}));",
            lit(center),
            lit(width),
            lit(exponent)
        ),
        CompiledMf::Gaussian { center, k } => {
            format!(
                "{target} = {prefix}_gaussian({x}, {}, {});",
                lit(center),
                lit(k)
            )
        }
        CompiledMf::Gaussian2 {
            center1,
            k1,
            center2,
            k2,
        } => format!(
            "{target} = ({x} <= {c1} ? {prefix}_gaussian({x}, {c1}, {}) : 1.0) * ({x} >= {c2} ? {prefix}_gaussian({x}, {c2}, {}) : 1.0);",
            lit(k1),
            lit(k2),
            c1 = lit(center1),
            c2 = lit(center2)
        ),
        CompiledMf::Triangle { left, peak, right } => format!(
            "{target} = {x} == {b} ? 1.0 : ({x} <= {a} || {x} >= {c}) ? 0.0 : {x} < {b} ? ({x} - {a}) / ({b} - {a}) : ({c} - {x}) / ({c} - {b});",
            a = lit(left),
            b = lit(peak),
            c = lit(right)
        ),
        CompiledMf::Trapezoid { a, b, c, d } => format!(
            "{{ double rising = {x} >= {b} ? 1.0 : {x} < {a} ? 0.0 : ({x} - {a}) / ({b} - {a}); \
             double falling = {x} <= {c} ? 1.0 : {x} > {d} ? 0.0 : ({d} - {x}) / ({d} - {c}); \
             {target} = fmin(rising, falling); }}",
            a = lit(a),
            b = lit(b),
            c = lit(c),
            d = lit(d)
        ),
        CompiledMf::Sigmoid { slope, center } => {
            format!(
                "{target} = {prefix}_sigmoid({x}, {}, {});",
                lit(slope),
                lit(center)
            )
        }
        CompiledMf::SigmoidDifference {
            slope1,
            center1,
            slope2,
            center2,
        } => format!(
            "{target} = fabs({prefix}_sigmoid({x}, {}, {}) - {prefix}_sigmoid({x}, {}, {}));",
            lit(slope1),
            lit(center1),
            lit(slope2),
            lit(center2)
        ),
        CompiledMf::SigmoidProduct {
            slope1,
            center1,
            slope2,
            center2,
        } => format!(
            "{target} = {prefix}_sigmoid({x}, {}, {}) * {prefix}_sigmoid({x}, {}, {});",
            lit(slope1),
            lit(center1),
            lit(slope2),
            lit(center2)
        ),
        CompiledMf::SShape { start, end } => format!(
            "{target} = {prefix}_smf({x}, {}, {});",
            lit(start),
            lit(end)
        ),
        CompiledMf::ZShape { start, end } => format!(
            "{target} = {prefix}_zmf({x}, {}, {});",
            lit(start),
            lit(end)
        ),
        CompiledMf::PiShape { a, b, c, d } => format!(
            "{target} = {prefix}_smf({x}, {}, {}) * {prefix}_zmf({x}, {}, {});",
            lit(a),
            lit(b),
            lit(c),
            lit(d)
        ),
        CompiledMf::Constant(value) => format!("{target} = {};", lit(value)),
    }
}
