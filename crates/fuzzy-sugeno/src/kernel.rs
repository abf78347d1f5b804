//! The inference of eqs 19-21 written once over [`Lane`]: one input point (`f64`) or `W` points
//! side by side in a SIMD register ([`lane_math::Pack`]), with the same operations in the same
//! order, so a point gives the same bits alone or in a batch.
//!
//! Every quantity lives in a *slot*, an array of `N` values (`N = 1` for one point, the widest
//! register's lane count for a batch), of which the first `W` hold one point each. The value
//! slots are,
//! in order (see [`Compiled`]): the membership degrees, their complements if any rule negates,
//! the constants 1 and 0, the AND nodes, the OR nodes, and each rule's firing strength.
//!
//! A rule's antecedents are combined left to right, as `((mu_1 AND mu_2) AND mu_3) ...`, each
//! partial result a *node* shared by every rule with the same leading antecedents (the paper's 16
//! rules over 4 inputs need 4 + 8 + 16 = 28 products instead of 48). "Don't care" antecedents are
//! left out: combining with the neutral element (1 for AND, 0 for OR) is exact for degrees in
//! `[0, 1]`, so the strengths are those of the textbook fold.
//!
//! What is not arithmetic on all points at once, checking and clamping the inputs and the
//! policies of the last step (no rule fired, a non-finite output), is done per point by the
//! callers in `eval.rs`.

use lane_math::Lane;

use crate::compiled_mf::integer_power;
use crate::separable::{MAX_SEPARABLE_SETS, OutputGrid, Separable};
use crate::system::{AndMethod, Compiled, DenseTerms, FuzzySystem, OrMethod};

/// The buffers of one evaluation, in slots of `N` values (see the module docs).
pub(crate) struct Slots<'a, const N: usize> {
    /// One slot per input, after the range policy.
    pub x: &'a [[f64; N]],
    /// The value slots ([`Compiled::slot_count`]); the constants 1 and 0 are filled in once.
    pub values: &'a mut [[f64; N]],
    /// One slot per output term ([`Compiled::term_values`]); constant terms are filled in once.
    pub terms: &'a mut [[f64; N]],
    /// Two slots per output: the weighted sum of the rule outputs and the total strength.
    pub sums: &'a mut [[f64; N]],
    /// The grades of the separable form ([`Separable::grade_count`]; empty without one).
    pub grades: &'a mut [[f64; N]],
}

impl<const N: usize> Slots<'_, N> {
    /// Panics unless the buffers have the sizes that `c` gives them. With
    /// [`Compiled::slots_in_bounds`] (asserted when the tables are built), this makes every slot
    /// that the kernel reads from `c` an index within its buffer: the condition under which
    /// [`get`] and [`set`] skip the bounds checks.
    #[inline(always)]
    fn check_sizes(&self, c: &Compiled) {
        assert!(
            self.x.len() == c.n_inputs
                && self.values.len() == c.slot_count
                && self.terms.len() == c.term_values.len()
                && self.sums.len() == 2 * (c.conclusion_offsets.len() - 1)
                && self.grades.len() == c.separable.as_ref().map_or(0, Separable::grade_count),
            "fuzzy-sugeno: kernel buffers sized for another system"
        );
    }
}

/// The value of slot `slot` of `buffer`, which must be in bounds (see [`Slots::check_sizes`]).
///
/// The kernel's slots are table-driven (a rule base is data), so the compiler cannot see that
/// they are in bounds; the checks it would add are about a fifth of the instructions of the
/// paper's controller. The tables are checked once instead, when they are built.
#[inline(always)]
fn get<L: Lane, const N: usize>(cx: L::Context, buffer: &[[f64; N]], slot: usize) -> L {
    debug_assert!(slot < buffer.len());
    // SAFETY: every slot passed here comes from the compiled tables or is below a count of
    // them, all within the buffer sizes that `Slots::check_sizes` asserted at the kernel's
    // entry (`Compiled::slots_in_bounds`).
    L::load(cx, unsafe { buffer.get_unchecked(slot) })
}

/// Writes `value` into slot `slot` of `buffer`, which must be in bounds (see [`get`]).
#[inline(always)]
fn set<L: Lane, const N: usize>(buffer: &mut [[f64; N]], slot: usize, value: L) {
    debug_assert!(slot < buffer.len());
    // SAFETY: as in `get`.
    value.store(unsafe { buffer.get_unchecked_mut(slot) });
}

/// Layers 1-3: the membership degrees at `slots.x`, their complements, the AND and OR nodes and
/// every rule's strength (its combined antecedents times its weight).
#[inline(always)]
pub(crate) fn fire<L: Lane, const N: usize>(
    cx: L::Context,
    c: &Compiled,
    and: AndMethod,
    or: OrMethod,
    slots: &mut Slots<'_, N>,
) {
    slots.check_sizes(c);
    let values = &mut *slots.values;
    for (k, (mf, &i)) in c.mfs.iter().zip(&c.mf_inputs).enumerate() {
        let x = get::<L, N>(cx, slots.x, i);
        set(values, k, mf.eval_lane(cx, x));
    }
    if c.has_complements {
        let n_mf = c.mfs.len();
        let one = L::splat(cx, 1.0);
        for k in 0..n_mf {
            let degree: L = get(cx, values, k);
            set(values, n_mf + k, one - degree);
        }
    }
    // One monomorphised loop per pair of methods.
    let probor = |s: L, d: L| s + d - s * d;
    let product = |s: L, d: L| s * d;
    match (and, or) {
        (AndMethod::Product, OrMethod::ProbabilisticSum) => nodes(cx, c, values, product, probor),
        (AndMethod::Product, OrMethod::Maximum) => nodes(cx, c, values, product, L::max),
        (AndMethod::Minimum, OrMethod::ProbabilisticSum) => nodes(cx, c, values, L::min, probor),
        (AndMethod::Minimum, OrMethod::Maximum) => nodes(cx, c, values, L::min, L::max),
    }
    if !c.weights_folded {
        for (r, (&slot, &weight)) in c.rule_slots.iter().zip(&c.weights).enumerate() {
            let combined: L = get(cx, values, slot as usize);
            set(values, c.strength_base + r, combined * weight);
        }
    }
}

/// The AND nodes, then the OR nodes, each from two earlier slots.
#[inline(always)]
fn nodes<L: Lane, const N: usize>(
    cx: L::Context,
    c: &Compiled,
    values: &mut [[f64; N]],
    and: impl Fn(L, L) -> L,
    or: impl Fn(L, L) -> L,
) {
    let mut slot = c.node_base;
    for &[a, b] in &c.and_nodes {
        let (a, b): (L, L) = (get(cx, values, a as usize), get(cx, values, b as usize));
        set(values, slot, and(a, b));
        slot += 1;
    }
    for &[a, b] in &c.or_nodes {
        let (a, b): (L, L) = (get(cx, values, a as usize), get(cx, values, b as usize));
        set(values, slot, or(a, b));
        slot += 1;
    }
}

/// Layer 4, after [`fire`]: the first-order terms at `slots.x`, then for every output the
/// weighted sum `sum_r w_r z_r` and the total `sum_r w_r` over the rules that conclude on it, in
/// rule order (the numerator and denominator of eq 21).
#[inline(always)]
pub(crate) fn sums<L: Lane, const N: usize>(
    cx: L::Context,
    c: &Compiled,
    slots: &mut Slots<'_, N>,
) {
    slots.check_sizes(c);
    let n_in = c.n_inputs;
    for &(term, offset) in &c.linear_terms {
        let p = &c.coefficients[offset..offset + n_in + 1];
        let mut acc = L::splat(cx, p[n_in]);
        for (i, &p_i) in p[..n_in].iter().enumerate() {
            acc = acc + get::<L, N>(cx, slots.x, i) * p_i;
        }
        set(slots.terms, term, acc);
    }
    let zero = L::splat(cx, 0.0);
    match &c.dense_terms {
        Some(DenseTerms::Constants(values)) => {
            let terms = |_: &[[f64; N]], &[a, b]: &[f64; 2]| [L::splat(cx, a), L::splat(cx, b)];
            return dense_sums::<L, N, _>(cx, c, values, slots, terms);
        }
        Some(DenseTerms::Slots(indices)) => {
            let terms = |values: &[[f64; N]], &[a, b]: &[u32; 2]| {
                [get(cx, values, a as usize), get(cx, values, b as usize)]
            };
            return dense_sums::<L, N, _>(cx, c, indices, slots, terms);
        }
        None => {}
    }
    for (o, bounds) in c.conclusion_offsets.windows(2).enumerate() {
        let (mut weighted, mut total) = (zero, zero);
        for &[rule, term] in &c.conclusions[bounds[0]..bounds[1]] {
            let w: L = get(cx, slots.values, c.strength_base + rule as usize);
            let z: L = get(cx, slots.terms, term as usize);
            weighted = weighted + w * z;
            total = total + w;
        }
        set(slots.sums, 2 * o, weighted);
        set(slots.sums, 2 * o + 1, total);
    }
}

/// [`sums`] when every rule concludes on every output: the outputs two at a time, side by side
/// (each summed in rule order), with the total strength, the same for all, summed alongside;
/// `terms` gives a rule's two terms from an entry of `dense` and the term slots.
#[inline(always)]
fn dense_sums<L: Lane, const N: usize, T>(
    cx: L::Context,
    c: &Compiled,
    dense: &[T],
    slots: &mut Slots<'_, N>,
    terms: impl Fn(&[[f64; N]], &T) -> [L; 2],
) {
    let n_out = c.conclusion_offsets.len() - 1;
    let n_rules = c.weights.len();
    let zero = L::splat(cx, 0.0);
    let strengths = &slots.values[c.strength_base..c.strength_base + n_rules];
    for (pair, rules) in dense.chunks_exact(n_rules).enumerate() {
        let (mut first, mut second, mut total) = (zero, zero, zero);
        for (strength, rule) in strengths.iter().zip(rules) {
            let w = L::load(cx, strength);
            let [a, b] = terms(slots.terms, rule);
            first = first + w * a;
            second = second + w * b;
            total = total + w;
        }
        let o = 2 * pair;
        set(slots.sums, 2 * o, first);
        set(slots.sums, 2 * o + 1, total);
        if o + 1 < n_out {
            set(slots.sums, 2 * o + 2, second);
            set(slots.sums, 2 * o + 3, total);
        }
    }
}

/// The separable form of `c` (`separable.rs`) at `slots.x`, into `slots.sums` as [`sums`]
/// writes them (the numerator and denominator of eq 21, each multiplied by the same positive
/// product of the grades); `false`, with the sums untouched, when `c` has no separable form or
/// a point of `slots.x` lies where an `A_{ik}` exceeds its limit (then [`fire`] and [`sums`]
/// evaluate it).
#[inline(always)]
pub(crate) fn separable_sums<L: Lane, const N: usize>(
    cx: L::Context,
    c: &Compiled,
    slots: &mut Slots<'_, N>,
) -> bool {
    slots.check_sizes(c);
    let Some(s) = &c.separable else {
        return false;
    };
    // One monomorphised body per common exponent: the paper's `2 b = 4`, the square, any other.
    match s.exponent {
        2 => separable_grid(cx, s, slots, |u: L| u * u),
        4 => separable_grid(cx, s, slots, |u: L| {
            let u2 = u * u;
            u2 * u2
        }),
        e => separable_grid(cx, s, slots, move |u: L| integer_power(cx, u.abs(), e)),
    }
}

/// [`separable_sums`] with `power(u) = |u|^(2 b)`. The loops over an input's sets and over the
/// factors of a grid's terms run for a count known at compile time (one body per count up to
/// [`MAX_SEPARABLE_SETS`] sets and 4 factors), so that they are unrolled and
/// read no loop bounds; every count gives the same operations in the same order.
#[inline(always)]
fn separable_grid<L: Lane, const N: usize>(
    cx: L::Context,
    s: &Separable,
    slots: &mut Slots<'_, N>,
    power: impl Fn(L) -> L + Copy,
) -> bool {
    let one = L::splat(cx, 1.0);
    let n_sets = s.sets.len();
    let mut largest = one;
    // Every input with the same number of sets: the sets in arrays of that length.
    match s.sets_per_input {
        Some(1) => uniform_grades::<L, N, 1>(cx, s, slots, power, &mut largest),
        Some(2) => uniform_grades::<L, N, 2>(cx, s, slots, power, &mut largest),
        Some(3) => uniform_grades::<L, N, 3>(cx, s, slots, power, &mut largest),
        _ => {
            for (i, bounds) in s.set_offsets.windows(2).enumerate() {
                let x: L = get(cx, slots.x, i);
                let sets = &s.sets[bounds[0]..bounds[1]];
                let grades = (&mut *slots.grades, bounds[0]);
                // `Separable::slots_in_bounds`: 1 to `MAX_SEPARABLE_SETS` sets an input.
                let sum = match sets.len() {
                    1 => input_grades::<L, N, 1>(cx, chunk(sets), x, power, &mut largest, grades),
                    2 => input_grades::<L, N, 2>(cx, chunk(sets), x, power, &mut largest, grades),
                    3 => input_grades::<L, N, 3>(cx, chunk(sets), x, power, &mut largest, grades),
                    _ => input_grades::<L, N, MAX_SEPARABLE_SETS>(
                        cx,
                        chunk(sets),
                        x,
                        power,
                        &mut largest,
                        grades,
                    ),
                };
                set(slots.grades, n_sets + i, sum);
            }
        }
    }
    if !L::splat(cx, s.limit).all_greater(largest) {
        return false;
    }
    for (o, grid) in s.outputs.iter().enumerate() {
        let grades = &*slots.grades;
        let [weighted, total] = match (s.sets_per_input, grid.inputs.len()) {
            (Some(2), 1) => uniform_grid_sum::<L, N, 2, 1>(cx, grid, n_sets, grades),
            (Some(2), 2) => uniform_grid_sum::<L, N, 2, 2>(cx, grid, n_sets, grades),
            (Some(2), 3) => uniform_grid_sum::<L, N, 2, 3>(cx, grid, n_sets, grades),
            (Some(3), 1) => uniform_grid_sum::<L, N, 3, 1>(cx, grid, n_sets, grades),
            (Some(3), 2) => uniform_grid_sum::<L, N, 3, 2>(cx, grid, n_sets, grades),
            (_, 1) => grid_sum::<L, N, 1>(cx, grid, n_sets, grades),
            (_, 2) => grid_sum::<L, N, 2>(cx, grid, n_sets, grades),
            (_, 3) => grid_sum::<L, N, 3>(cx, grid, n_sets, grades),
            (_, 4) => grid_sum::<L, N, 4>(cx, grid, n_sets, grades),
            _ => grid_sum_any(cx, grid, n_sets, grades),
        };
        set(slots.sums, 2 * o, weighted);
        set(slots.sums, 2 * o + 1, total);
    }
    true
}

/// The first `C` sets of `sets`, which has `C` (the caller matched the count).
#[inline(always)]
fn chunk<const C: usize>(sets: &[[f64; 2]]) -> &[[f64; 2]; C] {
    let Some(sets) = sets.first_chunk::<C>() else {
        unreachable!("the caller matched the count of sets");
    };
    sets
}

/// [`input_grades`] for every input, each with `C` sets ([`Separable::sets_per_input`]), the
/// sums `S_i` into their grade slots.
#[inline(always)]
fn uniform_grades<L: Lane, const N: usize, const C: usize>(
    cx: L::Context,
    s: &Separable,
    slots: &mut Slots<'_, N>,
    power: impl Fn(L) -> L + Copy,
    largest: &mut L,
) {
    let n_sets = s.sets.len();
    let (sets, _) = s.sets.as_chunks::<C>();
    for (i, (sets, x)) in sets.iter().zip(slots.x).enumerate() {
        let x = L::load(cx, x);
        let sum = input_grades::<L, N, C>(cx, sets, x, power, largest, (slots.grades, i * C));
        set(slots.grades, n_sets + i, sum);
    }
}

/// One input's `C` sets at `x`: `A_k = 1 + |u_k|^(2b)` (the largest so far into `largest`), the
/// grades `P_k = prod_{j != k} A_j` into the grade slots from `grades.1`; returns their sum
/// `S_i`, summed in set order.
#[inline(always)]
fn input_grades<L: Lane, const N: usize, const C: usize>(
    cx: L::Context,
    sets: &[[f64; 2]; C],
    x: L,
    power: impl Fn(L) -> L,
    largest: &mut L,
    (grades, first): (&mut [[f64; N]], usize),
) -> L {
    let one = L::splat(cx, 1.0);
    let mut a = [one; C];
    for (a, &[center, inverse_width]) in a.iter_mut().zip(sets) {
        *a = one + power((x - L::splat(cx, center)) * inverse_width);
        *largest = largest.max(*a);
    }
    let mut sum = L::splat(cx, 0.0);
    for k in 0..C {
        let mut grade = one;
        for (j, &a_j) in a.iter().enumerate() {
            if j != k {
                grade = grade * a_j;
            }
        }
        set(grades, first + k, grade);
        sum = sum + grade;
    }
    sum
}

/// `[sum_k z_k prod P, prod_i S_i]` over the terms of `grid` and its inputs, whose entries have
/// `D` factors each (`grid` depends on `D` inputs): [`weighted_terms`] with the factors in
/// arrays of `D`; the sums `S_i` are the grade slots from `n_sets`.
#[inline(always)]
fn grid_sum<L: Lane, const N: usize, const D: usize>(
    cx: L::Context,
    grid: &OutputGrid,
    n_sets: usize,
    grades: &[[f64; N]],
) -> [L; 2] {
    let (factors, _) = grid.factors.as_chunks::<D>();
    let weighted = weighted_terms(
        cx,
        &grid.terms,
        factors.iter().map(|f| f.as_slice()),
        grades,
    );
    let Some(inputs) = grid.inputs.first_chunk::<D>() else {
        unreachable!("the caller matched the count of inputs");
    };
    [weighted, total_grade(cx, inputs, n_sets, grades)]
}

/// [`grid_sum`] when every input has `C` sets ([`Separable::sets_per_input`]): the factors of
/// entry `e` are the sets of `e`'s digits in base `C` (the last input's the least significant),
/// slot `C i + k` for set `k` of input `i`, so that the `C^D` terms are unrolled and read no
/// factor table; the same operations in the same order as [`weighted_terms`].
#[inline(always)]
fn uniform_grid_sum<L: Lane, const N: usize, const C: usize, const D: usize>(
    cx: L::Context,
    grid: &OutputGrid,
    n_sets: usize,
    grades: &[[f64; N]],
) -> [L; 2] {
    let entries = C.pow(D as u32);
    let Some(inputs) = grid.inputs.first_chunk::<D>() else {
        unreachable!("the caller matched the count of inputs");
    };
    // `Separable::slots_in_bounds`.
    if grid.terms.len() != entries {
        unreachable!("a grid of D inputs of C sets has C^D entries");
    }
    let mut weighted = L::splat(cx, 0.0);
    for e in 0..entries {
        let mut term = L::splat(cx, grid.terms[e]);
        let mut place = entries;
        for &i in inputs {
            place /= C;
            let k = (e / place) % C;
            term = term * get::<L, N>(cx, grades, C * i + k);
        }
        weighted = weighted + term;
    }
    [weighted, total_grade(cx, inputs, n_sets, grades)]
}

/// [`grid_sum`] for any number of inputs.
#[inline(always)]
fn grid_sum_any<L: Lane, const N: usize>(
    cx: L::Context,
    grid: &OutputGrid,
    n_sets: usize,
    grades: &[[f64; N]],
) -> [L; 2] {
    let d = grid.inputs.len();
    let factors = (0..grid.terms.len()).map(|k| &grid.factors[k * d..(k + 1) * d]);
    let weighted = weighted_terms(cx, &grid.terms, factors, grades);
    [weighted, total_grade(cx, &grid.inputs, n_sets, grades)]
}

/// `prod_{i in inputs} S_i`, in input order, the sums `S_i` in the grade slots from `n_sets`.
#[inline(always)]
fn total_grade<L: Lane, const N: usize>(
    cx: L::Context,
    inputs: &[usize],
    n_sets: usize,
    grades: &[[f64; N]],
) -> L {
    let mut total = L::splat(cx, 1.0);
    for &i in inputs {
        total = total * get::<L, N>(cx, grades, n_sets + i);
    }
    total
}

/// `sum_k z_k prod_{slot in factors_k} P_slot`, in term order, each term's factors in order.
#[inline(always)]
fn weighted_terms<'a, L: Lane, const N: usize>(
    cx: L::Context,
    terms: &[f64],
    factors: impl Iterator<Item = &'a [u32]>,
    grades: &[[f64; N]],
) -> L {
    let mut weighted = L::splat(cx, 0.0);
    for (&z, factors) in terms.iter().zip(factors) {
        let mut term = L::splat(cx, z);
        for &slot in factors {
            term = term * get::<L, N>(cx, grades, slot as usize);
        }
        weighted = weighted + term;
    }
    weighted
}

/// The kernel's buffers for `N` points, sized for one system at construction.
#[derive(Debug, Clone)]
pub(crate) struct Workspace<const N: usize> {
    /// One slot per input.
    pub x: Vec<[f64; N]>,
    /// The value slots, the constants 1 and 0 filled in.
    pub values: Vec<[f64; N]>,
    /// One slot per output term, the constant terms filled in.
    pub terms: Vec<[f64; N]>,
    /// Two slots per output.
    pub sums: Vec<[f64; N]>,
    /// The grades of the separable form, if the system has one.
    pub grades: Vec<[f64; N]>,
}

impl<const N: usize> Workspace<N> {
    /// Buffers for `N` points of `system`.
    pub(crate) fn new(system: &FuzzySystem) -> Self {
        let c = system.compiled();
        let mut values = vec![[0.0; N]; c.slot_count];
        // The neutral element of AND, which "don't care" antecedents point at (0, that of OR,
        // is already there).
        values[c.degree_count - 2] = [1.0; N];
        Self {
            x: vec![[0.0; N]; c.n_inputs],
            values,
            terms: c.term_values.iter().map(|&t| [t; N]).collect(),
            sums: vec![[0.0; N]; 2 * system.outputs().len()],
            grades: vec![[0.0; N]; c.separable.as_ref().map_or(0, Separable::grade_count)],
        }
    }

    /// The buffers as the kernel takes them.
    #[inline(always)]
    pub(crate) fn slots(&mut self) -> Slots<'_, N> {
        self.slots_at(None)
    }

    /// The buffers as the kernel takes them, with the inputs read from `x` instead of
    /// [`Workspace::x`] if given (it must have one slot per input).
    #[inline(always)]
    pub(crate) fn slots_at<'a>(&'a mut self, x: Option<&'a [[f64; N]]>) -> Slots<'a, N> {
        Slots {
            x: x.unwrap_or(&self.x),
            values: &mut self.values,
            terms: &mut self.terms,
            sums: &mut self.sums,
            grades: &mut self.grades,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{AndMethod, OrMethod, paper_controller};

    /// Buffers of other sizes than the tables give are refused, before any unchecked access.
    #[test]
    #[should_panic(expected = "kernel buffers sized for another system")]
    fn buffers_of_other_sizes_are_refused() {
        let paper = paper_controller();
        let mut work = Workspace::<1>::new(&paper);
        work.values.pop();
        let (and, or) = (AndMethod::Product, OrMethod::ProbabilisticSum);
        fire::<f64, 1>((), paper.compiled(), and, or, &mut work.slots());
    }
}
