//! Membership functions of the input fuzzy sets, with MATLAB's names, parameter order and
//! formulas (`gbellmf`, `gaussmf`, ...).
//!
//! [`MembershipFn`] is the description a user writes. What the crate knows about each kind
//! (names in `.fis` and FCL, parameter count and order, constructor, landmarks) is one entry of
//! `KINDS`, so readers and writers share it instead of matching on the variants. A system
//! compiles each function once, when it is built, into the evaluation form of `eval.rs`
//! (`CompiledMf`), which picks the cheapest exact formula (for example repeated squaring instead
//! of `powf` for the integer bell slopes the paper uses).

use crate::compiled_mf::{CompiledMf, MAX_INTEGER_BELL_EXPONENT};
use crate::error::FuzzyError;

/// A membership function `mu(x) in [0, 1]` of one input fuzzy set.
///
/// Parameters follow MATLAB's Fuzzy Logic Toolbox, in the same order as in a `.fis` file; the
/// formulas are MATLAB's, including its conventions at the edges (documented per variant).
/// Parameters are checked by [`MembershipFn::validate`], which every system build calls.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MembershipFn {
    /// `gbellmf [a b c]`: the generalized bell `1 / (1 + |(x - c) / a|^(2 b))` (the paper's
    /// choice, section 4). Requires `a > 0` and `b > 0`.
    Bell {
        /// `a`: the half-width at membership 1/2.
        width: f64,
        /// `b`: the slope; `mu'(c ± a) = ∓ b / (2 a)`.
        slope: f64,
        /// `c`: the centre, where `mu = 1`.
        center: f64,
    },
    /// `gaussmf [sigma c]`: `exp(-(x - c)^2 / (2 sigma^2))`. Requires `sigma > 0`.
    Gaussian {
        /// `sigma`: the standard deviation.
        sigma: f64,
        /// `c`: the centre.
        center: f64,
    },
    /// `gauss2mf [sigma1 c1 sigma2 c2]`: the left Gaussian `(sigma1, c1)` for `x < c1`, the right
    /// one `(sigma2, c2)` for `x > c2`, multiplied where both apply (MATLAB's definition, so with
    /// `c1 > c2` the top stays below 1). Requires both sigmas positive.
    Gaussian2 {
        /// `sigma1`: the left side's standard deviation.
        sigma1: f64,
        /// `c1`: the left shoulder.
        center1: f64,
        /// `sigma2`: the right side's standard deviation.
        sigma2: f64,
        /// `c2`: the right shoulder.
        center2: f64,
    },
    /// `trimf [a b c]`: 0 outside `(a, c)`, rising linearly on `(a, b)`, 1 at `b`, falling on
    /// `(b, c)`. Requires `a <= b <= c`; `a = b` or `b = c` give a vertical side (MATLAB: 1 at `b`).
    Triangle {
        /// `a`: the left foot.
        left: f64,
        /// `b`: the peak.
        peak: f64,
        /// `c`: the right foot.
        right: f64,
    },
    /// `trapmf [a b c d]`: 0 below `a` and above `d`, 1 on `[b, c]`, linear in between.
    /// Requires `a <= b <= c <= d`.
    Trapezoid {
        /// `a`: the left foot.
        left_foot: f64,
        /// `b`: the left shoulder.
        left_shoulder: f64,
        /// `c`: the right shoulder.
        right_shoulder: f64,
        /// `d`: the right foot.
        right_foot: f64,
    },
    /// `sigmf [a c]`: `1 / (1 + exp(-a (x - c)))`; `a > 0` opens to the right, `a < 0` to the left.
    Sigmoid {
        /// `a`: the slope at `c` is `a / 4`.
        slope: f64,
        /// `c`: the crossover point, where `mu = 1/2`.
        center: f64,
    },
    /// `dsigmf [a1 c1 a2 c2]`: `|sig(a1, c1) - sig(a2, c2)|`.
    SigmoidDifference {
        /// `a1`: the first sigmoid's slope.
        slope1: f64,
        /// `c1`: the first sigmoid's crossover.
        center1: f64,
        /// `a2`: the second sigmoid's slope.
        slope2: f64,
        /// `c2`: the second sigmoid's crossover.
        center2: f64,
    },
    /// `psigmf [a1 c1 a2 c2]`: `sig(a1, c1) * sig(a2, c2)`.
    SigmoidProduct {
        /// `a1`: the first sigmoid's slope.
        slope1: f64,
        /// `c1`: the first sigmoid's crossover.
        center1: f64,
        /// `a2`: the second sigmoid's slope.
        slope2: f64,
        /// `c2`: the second sigmoid's crossover.
        center2: f64,
    },
    /// `smf [a b]`: MATLAB's S-shaped spline, 0 up to `a`, `2 ((x - a) / (b - a))^2` up to the
    /// midpoint `(a + b) / 2`, `1 - 2 ((b - x) / (b - a))^2` up to `b`, then 1. With `a >= b`
    /// it is MATLAB's step: 1 where `x >= (a + b) / 2`, else 0.
    SShape {
        /// `a`: the foot, where the rise starts.
        start: f64,
        /// `b`: the shoulder, where the rise ends.
        end: f64,
    },
    /// `zmf [a b]`: MATLAB's Z-shaped spline, the mirror image of `smf`: 1 up to `a`,
    /// `1 - 2 ((x - a) / (b - a))^2` up to `(a + b) / 2`, `2 ((b - x) / (b - a))^2` up to `b`,
    /// then 0. With `a >= b` it is MATLAB's step: 1 where `x <= (a + b) / 2`, else 0.
    ZShape {
        /// `a`: the shoulder, where the fall starts.
        start: f64,
        /// `b`: the foot, where the fall ends.
        end: f64,
    },
    /// `pimf [a b c d]`: MATLAB's product `smf(x, [a b]) * zmf(x, [c d])`, a smooth trapezoid
    /// (0 below `a` and above `d`, 1 on `[b, c]` when `b <= c`).
    PiShape {
        /// `a`: the left foot.
        left_foot: f64,
        /// `b`: the left shoulder.
        left_shoulder: f64,
        /// `c`: the right shoulder.
        right_shoulder: f64,
        /// `d`: the right foot.
        right_foot: f64,
    },
    /// `constant [k]`: the same degree `k in [0, 1]` everywhere (written as `'constant'` in an
    /// input section of a `.fis` file; MATLAB itself uses that name only for Sugeno outputs).
    Constant {
        /// `k`: the degree.
        value: f64,
    },
}

impl MembershipFn {
    /// The generalized bell `gbellmf [width slope center]`.
    pub fn bell(width: f64, slope: f64, center: f64) -> Self {
        Self::Bell {
            width,
            slope,
            center,
        }
    }

    /// The Gaussian `gaussmf [sigma center]`.
    pub fn gaussian(sigma: f64, center: f64) -> Self {
        Self::Gaussian { sigma, center }
    }

    /// The triangle `trimf [left peak right]`.
    pub fn triangle(left: f64, peak: f64, right: f64) -> Self {
        Self::Triangle { left, peak, right }
    }

    /// The trapezoid `trapmf [a b c d]`.
    pub fn trapezoid(a: f64, b: f64, c: f64, d: f64) -> Self {
        Self::Trapezoid {
            left_foot: a,
            left_shoulder: b,
            right_shoulder: c,
            right_foot: d,
        }
    }

    /// The sigmoid `sigmf [slope center]`.
    pub fn sigmoid(slope: f64, center: f64) -> Self {
        Self::Sigmoid { slope, center }
    }

    /// MATLAB's name of this type (`"gbellmf"`, `"gaussmf"`, ...).
    pub fn matlab_name(&self) -> &'static str {
        self.kind().matlab
    }

    /// This function's kind: its entry in [`KINDS`].
    pub(crate) fn kind(&self) -> &'static Kind {
        self.described().0
    }

    /// The function's kind and its parameters in MATLAB's order (unused slots 0): the one place
    /// that takes a variant apart, as [`Kind::build`] is the one that puts it together.
    fn described(&self) -> (&'static Kind, [f64; 4]) {
        let (index, params) = match *self {
            Self::Triangle { left, peak, right } => (0, [left, peak, right, 0.0]),
            Self::Trapezoid {
                left_foot,
                left_shoulder,
                right_shoulder,
                right_foot,
            } => (1, [left_foot, left_shoulder, right_shoulder, right_foot]),
            Self::Bell {
                width,
                slope,
                center,
            } => (2, [width, slope, center, 0.0]),
            Self::Gaussian { sigma, center } => (3, [sigma, center, 0.0, 0.0]),
            Self::Gaussian2 {
                sigma1,
                center1,
                sigma2,
                center2,
            } => (4, [sigma1, center1, sigma2, center2]),
            Self::Sigmoid { slope, center } => (5, [slope, center, 0.0, 0.0]),
            Self::SigmoidDifference {
                slope1,
                center1,
                slope2,
                center2,
            } => (6, [slope1, center1, slope2, center2]),
            Self::SigmoidProduct {
                slope1,
                center1,
                slope2,
                center2,
            } => (7, [slope1, center1, slope2, center2]),
            Self::SShape { start, end } => (8, [start, end, 0.0, 0.0]),
            Self::ZShape { start, end } => (9, [start, end, 0.0, 0.0]),
            Self::PiShape {
                left_foot,
                left_shoulder,
                right_shoulder,
                right_foot,
            } => (10, [left_foot, left_shoulder, right_shoulder, right_foot]),
            Self::Constant { value } => (11, [value, 0.0, 0.0, 0.0]),
        };
        (&KINDS[index], params)
    }

    /// The function of the same kind with parameters `p` (MATLAB's order, this kind's count),
    /// not validated.
    #[cfg_attr(
        not(feature = "learn"),
        allow(dead_code, reason = "only learning moves parameters")
    )]
    pub(crate) fn with_params(&self, p: &[f64]) -> Self {
        (self.kind().build)(p)
    }

    /// The parameters in MATLAB's order (the `[...]` of a `.fis` line).
    pub fn params(&self) -> Vec<f64> {
        let (params, count) = self.param_array();
        params[..count].to_vec()
    }

    /// The parameters in MATLAB's order in a fixed array, and how many there are (at most 4):
    /// [`params`](Self::params) without allocating.
    pub(crate) fn param_array(&self) -> ([f64; 4], usize) {
        let (kind, params) = self.described();
        (params, kind.parameters)
    }

    /// How many parameters MATLAB's type `name` takes (`None` for an unknown type). A `.fis`
    /// file may list more; MATLAB, and [`FuzzySystem::from_fis`](crate::FuzzySystem::from_fis),
    /// use the leading ones.
    ///
    /// ```
    /// use fuzzy_sugeno::MembershipFn;
    /// assert_eq!(MembershipFn::matlab_parameter_count("gbellmf"), Some(3));
    /// assert_eq!(MembershipFn::matlab_parameter_count("pimf"), Some(4));
    /// assert_eq!(MembershipFn::matlab_parameter_count("rampmf"), None);
    /// ```
    pub fn matlab_parameter_count(name: &str) -> Option<usize> {
        Kind::by_matlab_name(name).map(|kind| kind.parameters)
    }

    /// Builds a function from MATLAB's type name and parameter list, and validates it.
    ///
    /// ```
    /// use fuzzy_sugeno::MembershipFn;
    /// let mf = MembershipFn::from_matlab("gbellmf", &[0.3, 2.0, -0.3])?;
    /// assert_eq!(mf, MembershipFn::bell(0.3, 2.0, -0.3));
    /// assert!(MembershipFn::from_matlab("gbellmf", &[0.0, 2.0, 0.0]).is_err());
    /// # Ok::<(), fuzzy_sugeno::FuzzyError>(())
    /// ```
    pub fn from_matlab(name: &str, params: &[f64]) -> Result<Self, FuzzyError> {
        let Some(kind) = Kind::by_matlab_name(name) else {
            let names: Vec<&str> = KINDS.iter().map(|kind| kind.matlab).collect();
            return Err(FuzzyError::InvalidMembership {
                function: name.to_string(),
                reason: format!(
                    "unknown membership function type; expected one of {}",
                    names.join(", ")
                ),
            });
        };
        if params.len() != kind.parameters {
            return Err(FuzzyError::InvalidMembership {
                function: name.to_string(),
                reason: format!(
                    "expected {} parameters, got {}",
                    kind.parameters,
                    params.len()
                ),
            });
        }
        let mf = (kind.build)(params);
        mf.validate()?;
        Ok(mf)
    }

    /// Checks the parameters: all finite, widths and sigmas positive, bell slope positive, the
    /// corners of triangles and trapezoids in order with feet apart (a zero-width set would be
    /// a single point, where a rule could essentially never fire), a constant degree within `[0, 1]`.
    pub fn validate(&self) -> Result<(), FuzzyError> {
        let fail = |reason: String| {
            Err(FuzzyError::InvalidMembership {
                function: self.matlab_name().to_string(),
                reason,
            })
        };
        let (params, count) = self.param_array();
        let params = &params[..count];
        if let Some((_, v)) = lane_math::first_non_finite(params) {
            return fail(format!(
                "parameters must be finite, got {v} in {}",
                format_params(params)
            ));
        }
        match *self {
            Self::Bell { width, slope, .. } => {
                if width <= 0.0 {
                    return fail(format!("width a must be positive, got {width}"));
                }
                if slope <= 0.0 {
                    return fail(format!("slope b must be positive, got {slope}"));
                }
            }
            Self::Gaussian { sigma, .. } if sigma <= 0.0 => {
                return fail(format!("sigma must be positive, got {sigma}"));
            }
            Self::Gaussian2 { sigma1, sigma2, .. } if sigma1 <= 0.0 || sigma2 <= 0.0 => {
                return fail(format!(
                    "sigma1 and sigma2 must be positive, got {sigma1} and {sigma2}"
                ));
            }
            // The evaluation's `1 / (2 sigma^2)` must be finite and normal: a sigma of 1e308
            // or 1e-300 gave NaN degrees, read as rules that did not fire.
            Self::Gaussian { sigma, .. } | Self::Gaussian2 { sigma1: sigma, .. }
                if !gauss_scale_fits(sigma) =>
            {
                return fail(format!(
                    "sigma must be within [1e-154, 1e153] (1 / (2 sigma^2) in double precision), \
                     got {}",
                    lane_math::Compact(sigma)
                ));
            }
            Self::Gaussian2 { sigma2, .. } if !gauss_scale_fits(sigma2) => {
                return fail(format!(
                    "sigma2 must be within [1e-154, 1e153] (1 / (2 sigma^2) in double precision), \
                     got {}",
                    lane_math::Compact(sigma2)
                ));
            }
            Self::Triangle { left, peak, right } if !(left <= peak && peak <= right) => {
                return fail(format!(
                    "corners must satisfy a <= b <= c, got {}",
                    format_params(params)
                ));
            }
            Self::Triangle { left, right, .. } if left == right => {
                return fail(format!(
                    "zero width: the feet must satisfy a < c, got {}",
                    format_params(params)
                ));
            }
            Self::Trapezoid {
                left_foot,
                left_shoulder,
                right_shoulder,
                right_foot,
            } if !(left_foot <= left_shoulder
                && left_shoulder <= right_shoulder
                && right_shoulder <= right_foot) =>
            {
                return fail(format!(
                    "corners must satisfy a <= b <= c <= d, got {}",
                    format_params(params)
                ));
            }
            Self::Trapezoid {
                left_foot,
                right_foot,
                ..
            } if left_foot == right_foot => {
                return fail(format!(
                    "zero width: the feet must satisfy a < d, got {}",
                    format_params(params)
                ));
            }
            Self::Constant { value } if !(0.0..=1.0).contains(&value) => {
                return fail(format!("a constant degree must lie in [0, 1], got {value}"));
            }
            _ => {}
        }
        Ok(())
    }

    /// The degree of membership of `x`, or an error if the parameters are invalid or `x` is NaN
    /// ([`FuzzyError::NonFiniteInput`] naming the input `x`; an infinite `x` has the function's
    /// limit).
    ///
    /// Systems evaluate their sets through a compiled form made once at build time; this is
    /// the same code, for plotting or checking a single function.
    ///
    /// ```
    /// use fuzzy_sugeno::MembershipFn;
    /// let n = MembershipFn::bell(0.3, 2.0, -0.3);
    /// assert_eq!(n.degree(0.0)?, 0.5); // |(0 + 0.3) / 0.3|^4 = 1
    /// assert_eq!(n.degree(f64::INFINITY)?, 0.0);
    /// assert!(n.degree(f64::NAN).is_err());
    /// # Ok::<(), fuzzy_sugeno::FuzzyError>(())
    /// ```
    pub fn degree(&self, x: f64) -> Result<f64, FuzzyError> {
        let compiled = self.compile()?;
        if x.is_nan() {
            return Err(FuzzyError::NonFiniteInput {
                index: 0,
                name: "x".into(),
                value: x,
            });
        }
        Ok(compiled.eval(x))
    }

    /// Validates the function and picks its evaluation form ([`CompiledMf`]).
    pub(crate) fn compile(&self) -> Result<CompiledMf, FuzzyError> {
        self.validate()?;
        Ok(match *self {
            MembershipFn::Bell {
                width,
                slope,
                center,
            } => {
                let exponent = 2.0 * slope;
                if exponent == 2.0 {
                    CompiledMf::BellSquare { center, width }
                } else if exponent == 4.0 {
                    CompiledMf::BellQuartic { center, width }
                } else if exponent.fract() == 0.0 && exponent <= MAX_INTEGER_BELL_EXPONENT {
                    CompiledMf::BellInteger {
                        center,
                        width,
                        exponent: exponent as u32,
                    }
                } else {
                    CompiledMf::BellReal {
                        center,
                        width,
                        exponent,
                    }
                }
            }
            MembershipFn::Gaussian { sigma, center } => CompiledMf::Gaussian {
                center,
                k: gauss_k(sigma),
            },
            MembershipFn::Gaussian2 {
                sigma1,
                center1,
                sigma2,
                center2,
            } => CompiledMf::Gaussian2 {
                center1,
                k1: gauss_k(sigma1),
                center2,
                k2: gauss_k(sigma2),
            },
            MembershipFn::Triangle { left, peak, right } => {
                CompiledMf::Triangle { left, peak, right }
            }
            MembershipFn::Trapezoid {
                left_foot,
                left_shoulder,
                right_shoulder,
                right_foot,
            } => CompiledMf::Trapezoid {
                a: left_foot,
                b: left_shoulder,
                c: right_shoulder,
                d: right_foot,
            },
            MembershipFn::Sigmoid { slope, center } => CompiledMf::Sigmoid { slope, center },
            MembershipFn::SigmoidDifference {
                slope1,
                center1,
                slope2,
                center2,
            } => CompiledMf::SigmoidDifference {
                slope1,
                center1,
                slope2,
                center2,
            },
            MembershipFn::SigmoidProduct {
                slope1,
                center1,
                slope2,
                center2,
            } => CompiledMf::SigmoidProduct {
                slope1,
                center1,
                slope2,
                center2,
            },
            MembershipFn::SShape { start, end } => CompiledMf::SShape { start, end },
            MembershipFn::ZShape { start, end } => CompiledMf::ZShape { start, end },
            MembershipFn::PiShape {
                left_foot,
                left_shoulder,
                right_shoulder,
                right_foot,
            } => CompiledMf::PiShape {
                a: left_foot,
                b: left_shoulder,
                c: right_shoulder,
                d: right_foot,
            },
            MembershipFn::Constant { value } => CompiledMf::Constant(value),
        })
    }
}

/// One membership-function kind, described once: its names in the formats the crate reads and
/// writes (MATLAB's `.fis`, fuzzylite's FCL), its parameters, their order in FCL, how to build
/// the function from them, and where its degree changes character. The formulas themselves are
/// the compiled form's (`compiled_mf::CompiledMf`); the gradients are ANFIS's (`learn::premise`).
#[derive(Debug)]
pub(crate) struct Kind {
    /// MATLAB's type name (`.fis`).
    pub(crate) matlab: &'static str,
    /// fuzzylite's term class (FCL); triangles and trapezoids are written as IEC point lists.
    #[cfg_attr(
        not(feature = "formats"),
        allow(dead_code, reason = "read by the FCL format")
    )]
    pub(crate) fcl: &'static str,
    /// How many parameters the kind takes.
    pub(crate) parameters: usize,
    /// fuzzylite's parameter order: FCL position `i` holds MATLAB's parameter `fcl_order[i]`.
    #[cfg_attr(
        not(feature = "formats"),
        allow(dead_code, reason = "read by the FCL format")
    )]
    pub(crate) fcl_order: &'static [usize],
    /// The function with these parameters (MATLAB's order, [`Kind::parameters`] of them), not
    /// validated.
    pub(crate) build: fn(&[f64]) -> MembershipFn,
    /// Where the degree changes character (centres, feet, shoulders, half-power points), from
    /// the parameters in MATLAB's order: the sample points of the rule-base analysis.
    pub(crate) landmarks: fn(&[f64; 4]) -> Vec<f64>,
}

impl Kind {
    /// The kind of MATLAB type `name`.
    pub(crate) fn by_matlab_name(name: &str) -> Option<&'static Kind> {
        KINDS.iter().find(|kind| kind.matlab == name)
    }

    /// The kind of fuzzylite term class `class`.
    #[cfg_attr(
        not(feature = "formats"),
        allow(dead_code, reason = "read by the FCL format")
    )]
    pub(crate) fn by_fcl_class(class: &str) -> Option<&'static Kind> {
        KINDS.iter().find(|kind| kind.fcl == class)
    }
}

/// Every kind, in the order error messages list them.
pub(crate) static KINDS: [Kind; 12] = [
    Kind {
        matlab: "trimf",
        fcl: "Triangle",
        parameters: 3,
        fcl_order: &[0, 1, 2],
        build: |p| MembershipFn::triangle(p[0], p[1], p[2]),
        landmarks: |p| vec![p[0], p[1], p[2]],
    },
    Kind {
        matlab: "trapmf",
        fcl: "Trapezoid",
        parameters: 4,
        fcl_order: &[0, 1, 2, 3],
        build: |p| MembershipFn::trapezoid(p[0], p[1], p[2], p[3]),
        landmarks: |p| p.to_vec(),
    },
    Kind {
        matlab: "gbellmf",
        fcl: "Bell",
        parameters: 3,
        // fuzzylite's Bell(center, width, slope).
        fcl_order: &[2, 0, 1],
        build: |p| MembershipFn::bell(p[0], p[1], p[2]),
        // The centre and the half-power points c ± a.
        landmarks: |&[width, _, center, _]| vec![center - width, center, center + width],
    },
    Kind {
        matlab: "gaussmf",
        fcl: "Gaussian",
        parameters: 2,
        // fuzzylite's Gaussian(mean, standardDeviation).
        fcl_order: &[1, 0],
        build: |p| MembershipFn::gaussian(p[0], p[1]),
        landmarks: |&[sigma, center, _, _]| vec![center - sigma, center, center + sigma],
    },
    Kind {
        matlab: "gauss2mf",
        fcl: "GaussianProduct",
        parameters: 4,
        // fuzzylite's GaussianProduct(meanA, standardDeviationA, meanB, standardDeviationB).
        fcl_order: &[1, 0, 3, 2],
        build: |p| MembershipFn::Gaussian2 {
            sigma1: p[0],
            center1: p[1],
            sigma2: p[2],
            center2: p[3],
        },
        landmarks: |&[sigma1, center1, sigma2, center2]| {
            vec![center1 - sigma1, center1, center2, center2 + sigma2]
        },
    },
    Kind {
        matlab: "sigmf",
        fcl: "Sigmoid",
        parameters: 2,
        // fuzzylite's Sigmoid(inflection, slope).
        fcl_order: &[1, 0],
        build: |p| MembershipFn::sigmoid(p[0], p[1]),
        landmarks: |&[_, center, _, _]| vec![center],
    },
    Kind {
        matlab: "dsigmf",
        fcl: "SigmoidDifference",
        parameters: 4,
        // fuzzylite's SigmoidDifference(left, rising, falling, right).
        fcl_order: &[1, 0, 2, 3],
        build: |p| MembershipFn::SigmoidDifference {
            slope1: p[0],
            center1: p[1],
            slope2: p[2],
            center2: p[3],
        },
        landmarks: |&[_, center1, _, center2]| vec![center1, center2],
    },
    Kind {
        matlab: "psigmf",
        fcl: "SigmoidProduct",
        parameters: 4,
        // fuzzylite's SigmoidProduct(left, rising, falling, right).
        fcl_order: &[1, 0, 2, 3],
        build: |p| MembershipFn::SigmoidProduct {
            slope1: p[0],
            center1: p[1],
            slope2: p[2],
            center2: p[3],
        },
        landmarks: |&[_, center1, _, center2]| vec![center1, center2],
    },
    Kind {
        matlab: "smf",
        fcl: "SShape",
        parameters: 2,
        // fuzzylite's SShape(start, end): MATLAB's order.
        fcl_order: &[0, 1],
        build: |p| MembershipFn::SShape {
            start: p[0],
            end: p[1],
        },
        landmarks: |&[start, end, _, _]| vec![start, 0.5 * (start + end), end],
    },
    Kind {
        matlab: "zmf",
        fcl: "ZShape",
        parameters: 2,
        // fuzzylite's ZShape(start, end): MATLAB's order.
        fcl_order: &[0, 1],
        build: |p| MembershipFn::ZShape {
            start: p[0],
            end: p[1],
        },
        landmarks: |&[start, end, _, _]| vec![start, 0.5 * (start + end), end],
    },
    Kind {
        matlab: "pimf",
        fcl: "PiShape",
        parameters: 4,
        // fuzzylite's PiShape(bottomLeft, topLeft, topRight, bottomRight): MATLAB's order.
        fcl_order: &[0, 1, 2, 3],
        build: |p| MembershipFn::PiShape {
            left_foot: p[0],
            left_shoulder: p[1],
            right_shoulder: p[2],
            right_foot: p[3],
        },
        landmarks: |p| p.to_vec(),
    },
    Kind {
        matlab: "constant",
        fcl: "Constant",
        parameters: 1,
        fcl_order: &[0],
        build: |p| MembershipFn::Constant { value: p[0] },
        landmarks: |_| Vec::new(),
    },
];

/// A Gaussian's evaluation constant `1 / (2 sigma^2)`.
fn gauss_k(sigma: f64) -> f64 {
    1.0 / (2.0 * sigma * sigma)
}

/// Whether a Gaussian's `sigma` gives a finite, normal [`gauss_k`]: from about `5e-155` to
/// `4.7e153` (messages quote [1e-154, 1e153]).
fn gauss_scale_fits(sigma: f64) -> bool {
    let k = gauss_k(sigma);
    k.is_finite() && k >= f64::MIN_POSITIVE
}

/// Formats parameters the way a `.fis` file shows them: `[0.3 2 -0.3]`.
pub(crate) fn format_params(params: &[f64]) -> String {
    let inner: Vec<String> = params.iter().map(|v| v.to_string()).collect();
    format!("[{}]", inner.join(" "))
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    fn mu(mf: MembershipFn, x: f64) -> f64 {
        mf.degree(x).unwrap()
    }

    #[test]
    fn bell_matches_its_formula_and_its_landmarks() {
        // mu(c) = 1, mu(c +- a) = 1/2 for every slope; MATLAB's 1 / (1 + |(x-c)/a|^(2b)) elsewhere.
        for slope in [0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 2.5, 7.0, 32.0, 40.0] {
            let mf = MembershipFn::bell(0.4, slope, 0.1);
            assert_eq!(mu(mf, 0.1), 1.0);
            assert_relative_eq!(mu(mf, 0.5), 0.5, max_relative = 1e-15);
            assert_relative_eq!(mu(mf, -0.3), 0.5, max_relative = 1e-15);
            for x in [-3.0, -0.7, 0.0, 0.23, 0.9, 12.0] {
                let formula = 1.0 / (1.0 + ((x - 0.1f64) / 0.4).abs().powf(2.0 * slope));
                assert_relative_eq!(mu(mf, x), formula, max_relative = 1e-13);
            }
        }
        // Far tails underflow to 0, never NaN.
        assert_eq!(mu(MembershipFn::bell(1e-3, 40.0, 0.0), 1e300), 0.0);
    }

    #[test]
    fn every_kind_is_described_once_and_consistently() {
        let params = [0.1, 0.2, 0.3, 0.4];
        for kind in &KINDS {
            let mf = (kind.build)(&params[..kind.parameters]);
            // The variant's kind is this entry, and its parameters come back in MATLAB's order.
            assert!(std::ptr::eq(mf.kind(), kind), "{}", kind.matlab);
            assert_eq!(mf.params(), &params[..kind.parameters], "{}", kind.matlab);
            assert_eq!(mf.with_params(&params[..kind.parameters]), mf);
            assert_eq!(
                MembershipFn::matlab_parameter_count(kind.matlab),
                Some(kind.parameters)
            );
            assert!(std::ptr::eq(Kind::by_fcl_class(kind.fcl).unwrap(), kind));
            // fuzzylite's order is a permutation of MATLAB's.
            let mut order = kind.fcl_order.to_vec();
            order.sort_unstable();
            assert_eq!(
                order,
                (0..kind.parameters).collect::<Vec<_>>(),
                "{}",
                kind.fcl
            );
        }
    }

    #[test]
    fn gaussians_match_their_formulas() {
        let g = MembershipFn::gaussian(0.2, 0.5);
        for x in [-1.0, 0.3, 0.5, 0.71, 4.0] {
            assert_relative_eq!(
                mu(g, x),
                (-(x - 0.5f64).powi(2) / (2.0 * 0.04)).exp(),
                max_relative = 1e-14
            );
        }
        assert_eq!(mu(g, 0.5), 1.0);
        // gauss2mf: left tail, flat top, right tail.
        let g2 = MembershipFn::Gaussian2 {
            sigma1: 0.1,
            center1: -0.2,
            sigma2: 0.3,
            center2: 0.4,
        };
        assert_relative_eq!(mu(g2, -0.4), (-0.04f64 / 0.02).exp(), max_relative = 1e-14);
        assert_eq!(mu(g2, -0.2), 1.0);
        assert_eq!(mu(g2, 0.1), 1.0);
        assert_eq!(mu(g2, 0.4), 1.0);
        assert_relative_eq!(mu(g2, 0.7), (-0.09f64 / 0.18).exp(), max_relative = 1e-14);
        // Crossed centres (c1 > c2): MATLAB multiplies both tails in between, so the top is < 1.
        let crossed = MembershipFn::Gaussian2 {
            sigma1: 1.0,
            center1: 1.0,
            sigma2: 1.0,
            center2: -1.0,
        };
        assert_relative_eq!(
            mu(crossed, 0.0),
            (-0.5f64).exp() * (-0.5f64).exp(),
            max_relative = 1e-14
        );
    }

    #[test]
    fn triangle_and_trapezoid_follow_matlab_at_every_edge() {
        let t = MembershipFn::triangle(-1.0, 0.0, 2.0);
        let expect = [
            (-2.0, 0.0),
            (-1.0, 0.0),
            (-0.25, 0.75),
            (0.0, 1.0),
            (1.5, 0.25),
            (2.0, 0.0),
            (3.0, 0.0),
        ];
        for (x, y) in expect {
            assert_eq!(mu(t, x), y, "trimf at {x}");
        }
        // Vertical sides: a = b gives 1 at b (MATLAB's centre rule wins over the shoulder).
        let left_shoulder = MembershipFn::triangle(0.0, 0.0, 1.0);
        assert_eq!(mu(left_shoulder, 0.0), 1.0);
        assert_eq!(mu(left_shoulder, -1e-12), 0.0);
        assert_eq!(mu(left_shoulder, 0.5), 0.5);
        // A spike (a = b = c) has zero width: a rule on it would essentially never fire.
        assert!(MembershipFn::triangle(0.5, 0.5, 0.5).validate().is_err());

        let z = MembershipFn::trapezoid(-1.0, 0.0, 1.0, 3.0);
        let expect = [
            (-1.5, 0.0),
            (-1.0, 0.0),
            (-0.5, 0.5),
            (0.0, 1.0),
            (0.7, 1.0),
            (1.0, 1.0),
            (2.5, 0.25),
            (3.0, 0.0),
        ];
        for (x, y) in expect {
            assert_eq!(mu(z, x), y, "trapmf at {x}");
        }
        let shoulder = MembershipFn::trapezoid(-5.0, -5.0, 0.0, 1.0);
        assert_eq!(
            (mu(shoulder, -5.0), mu(shoulder, -5.1), mu(shoulder, 0.5)),
            (1.0, 0.0, 0.5)
        );
    }

    #[test]
    fn sigmoids_match_their_formulas() {
        let s = |a: f64, c: f64, x: f64| 1.0 / (1.0 + (-a * (x - c)).exp());
        let right = MembershipFn::sigmoid(8.0, 0.25);
        let left = MembershipFn::sigmoid(-3.0, -0.5);
        let d = MembershipFn::SigmoidDifference {
            slope1: 5.0,
            center1: -1.0,
            slope2: 5.0,
            center2: 1.0,
        };
        let p = MembershipFn::SigmoidProduct {
            slope1: 5.0,
            center1: -1.0,
            slope2: -5.0,
            center2: 1.0,
        };
        assert_eq!(mu(right, 0.25), 0.5);
        for x in [-2.0, -0.5, 0.0, 0.25, 0.9, 2.0] {
            assert_relative_eq!(mu(right, x), s(8.0, 0.25, x), max_relative = 1e-14);
            assert_relative_eq!(mu(left, x), s(-3.0, -0.5, x), max_relative = 1e-14);
            assert_relative_eq!(
                mu(d, x),
                (s(5.0, -1.0, x) - s(5.0, 1.0, x)).abs(),
                max_relative = 1e-14
            );
            assert_relative_eq!(
                mu(p, x),
                s(5.0, -1.0, x) * s(-5.0, 1.0, x),
                max_relative = 1e-14
            );
        }
        // Saturation far out: exactly 0 or 1, never NaN.
        assert_eq!(mu(right, -1e6), 0.0);
        assert_eq!(mu(right, 1e6), 1.0);
        assert_eq!(mu(MembershipFn::Constant { value: 0.3 }, 1e9), 0.3);
    }

    #[test]
    fn s_z_and_pi_shapes_follow_matlab_at_their_landmarks() {
        let s = MembershipFn::SShape {
            start: 1.0,
            end: 3.0,
        };
        let z = MembershipFn::ZShape {
            start: 1.0,
            end: 3.0,
        };
        // Feet, midpoint (1/2), quarter points (2 (1/4)^2 = 1/8 and 1 - 1/8), shoulders.
        let expect = [
            (0.0, 0.0),
            (1.0, 0.0),
            (1.5, 0.125),
            (2.0, 0.5),
            (2.5, 0.875),
            (3.0, 1.0),
            (9.0, 1.0),
        ];
        for (x, y) in expect {
            assert_eq!(mu(s, x), y, "smf at {x}");
            assert_eq!(mu(z, x), 1.0 - y, "zmf at {x}");
        }
        // a >= b: MATLAB's steps at (a + b) / 2, the midpoint itself included on both sides.
        let step_up = MembershipFn::SShape {
            start: 2.0,
            end: 1.0,
        };
        let step_down = MembershipFn::ZShape {
            start: 1.0,
            end: 1.0,
        };
        assert_eq!((mu(step_up, 1.49), mu(step_up, 1.5)), (0.0, 1.0));
        assert_eq!((mu(step_down, 1.0), mu(step_down, 1.01)), (1.0, 0.0));
        // pimf is smf on the left times zmf on the right.
        let pi = MembershipFn::PiShape {
            left_foot: 0.0,
            left_shoulder: 2.0,
            right_shoulder: 4.0,
            right_foot: 8.0,
        };
        for (x, y) in [
            (-1.0, 0.0),
            (0.5, 0.125),
            (1.0, 0.5),
            (3.0, 1.0),
            (5.0, 0.875),
            (6.0, 0.5),
            (8.0, 0.0),
        ] {
            assert_eq!(mu(pi, x), y, "pimf at {x}");
        }
        for mf in [s, z, pi, step_up] {
            assert_eq!(
                MembershipFn::from_matlab(mf.matlab_name(), &mf.params()).unwrap(),
                mf
            );
        }
        assert!(
            MembershipFn::from_matlab("smf", &[f64::NAN, 1.0])
                .unwrap_err()
                .to_string()
                .starts_with("smf: parameters must be finite")
        );
    }

    #[test]
    fn invalid_parameters_are_refused_with_the_reason() {
        let message = |mf: MembershipFn| mf.validate().unwrap_err().to_string();
        assert_eq!(
            message(MembershipFn::bell(0.0, 2.0, 0.0)),
            "gbellmf: width a must be positive, got 0"
        );
        assert_eq!(
            message(MembershipFn::bell(1.0, -2.0, 0.0)),
            "gbellmf: slope b must be positive, got -2"
        );
        assert_eq!(
            message(MembershipFn::gaussian(0.0, 0.0)),
            "gaussmf: sigma must be positive, got 0"
        );
        assert_eq!(
            message(MembershipFn::triangle(0.0, 2.0, 1.0)),
            "trimf: corners must satisfy a <= b <= c, got [0 2 1]"
        );
        assert_eq!(
            message(MembershipFn::trapezoid(0.0, 1.0, 0.5, 2.0)),
            "trapmf: corners must satisfy a <= b <= c <= d, got [0 1 0.5 2]"
        );
        assert_eq!(
            message(MembershipFn::sigmoid(f64::NAN, 0.0)),
            "sigmf: parameters must be finite, got NaN in [NaN 0]"
        );
        assert_eq!(
            message(MembershipFn::Constant { value: 1.5 }),
            "constant: a constant degree must lie in [0, 1], got 1.5"
        );
        let g2 = MembershipFn::Gaussian2 {
            sigma1: 1.0,
            center1: 0.0,
            sigma2: -1.0,
            center2: 0.0,
        };
        assert!(message(g2).contains("sigma1 and sigma2 must be positive"));
        assert!(
            MembershipFn::from_matlab("rampmf", &[0.0; 2])
                .unwrap_err()
                .to_string()
                .contains("unknown membership")
        );
        assert!(
            MembershipFn::from_matlab("trimf", &[0.0; 2])
                .unwrap_err()
                .to_string()
                .contains("expected 3 parameters, got 2")
        );
    }

    #[test]
    fn matlab_names_and_params_round_trip() {
        let all = [
            MembershipFn::bell(0.3, 2.0, -0.3),
            MembershipFn::gaussian(0.1, 0.2),
            MembershipFn::Gaussian2 {
                sigma1: 0.1,
                center1: 0.2,
                sigma2: 0.3,
                center2: 0.4,
            },
            MembershipFn::triangle(0.0, 0.5, 1.0),
            MembershipFn::trapezoid(0.0, 0.25, 0.5, 1.0),
            MembershipFn::sigmoid(-2.0, 0.1),
            MembershipFn::SigmoidDifference {
                slope1: 1.0,
                center1: 2.0,
                slope2: 3.0,
                center2: 4.0,
            },
            MembershipFn::SigmoidProduct {
                slope1: 1.0,
                center1: 2.0,
                slope2: -3.0,
                center2: 4.0,
            },
            MembershipFn::Constant { value: 0.25 },
        ];
        for mf in all {
            assert_eq!(
                MembershipFn::from_matlab(mf.matlab_name(), &mf.params()).unwrap(),
                mf
            );
        }
    }

    proptest! {
        #[test]
        fn every_degree_lies_in_the_unit_interval(
            kind in 0usize..12, p in prop::array::uniform4(-3.0f64..3.0), x in -1e3f64..1e3,
        ) {
            let mut sorted = p;
            sorted.sort_by(f64::total_cmp);
            let mf = match kind {
                0 => MembershipFn::bell(p[0].abs() + 1e-3, p[1].abs() * 10.0 + 1e-3, p[2]),
                1 => MembershipFn::gaussian(p[0].abs() + 1e-3, p[1]),
                2 => MembershipFn::Gaussian2 { sigma1: p[0].abs() + 1e-3, center1: p[1], sigma2: p[2].abs() + 1e-3, center2: p[3] },
                3 => MembershipFn::triangle(sorted[0], sorted[1], sorted[2]),
                4 => MembershipFn::trapezoid(sorted[0], sorted[1], sorted[2], sorted[3]),
                5 => MembershipFn::sigmoid(p[0] * 10.0, p[1]),
                6 => MembershipFn::SigmoidDifference { slope1: p[0], center1: p[1], slope2: p[2], center2: p[3] },
                7 => MembershipFn::SigmoidProduct { slope1: p[0], center1: p[1], slope2: p[2], center2: p[3] },
                8 => MembershipFn::SShape { start: p[0], end: p[1] },
                9 => MembershipFn::ZShape { start: p[0], end: p[1] },
                10 => MembershipFn::PiShape { left_foot: p[0], left_shoulder: p[1], right_shoulder: p[2], right_foot: p[3] },
                _ => MembershipFn::Constant { value: p[0].abs() / 3.0 },
            };
            let y = mu(mf, x);
            prop_assert!((0.0..=1.0).contains(&y), "{mf:?} at {x} gave {y}");
        }

        #[test]
        fn triangle_is_the_min_of_its_two_sides(a in -2.0f64..0.0, b in 0.0f64..0.5, c in 0.5f64..2.0, x in -3.0f64..3.0) {
            // An independent closed form for a < b < c: max(min((x-a)/(b-a), (c-x)/(c-b)), 0).
            let formula = ((x - a) / (b - a)).min((c - x) / (c - b)).max(0.0);
            prop_assert!((mu(MembershipFn::triangle(a, b, c), x) - formula).abs() <= 1e-12);
        }
    }
}
