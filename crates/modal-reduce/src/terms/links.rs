//! The per-link pre-pass of the kernel: each link's angle, rate, sine, cosine and products,
//! in the buffers of [`LinkBuffers`] (see the [parent module](super)).

use lane_math::{Lane, Pack, REDUCTION_LIMIT, sin_cos_lanes};
use pulp::Simd;

use crate::data::PRODUCTS;
use crate::model::{LINK_PADDING, ReducedModel};

/// Whether every link's absolute angle is within [`REDUCTION_LIMIT`] in every state of `a` (of
/// [`StateLanes`]), by the model's bound `|phi_l| <= max |phi0| + sum_k max_l |(Phi_l)_k| |a_k|`
/// kept under half the limit, a margin far beyond the rounding of the sums. One test for a
/// group of states instead of one a link; a group that fails is left to the one-state path,
/// which tests each angle (far beyond any arm's range: a quarter of a million turns).
#[inline(always)]
pub(crate) fn angles_in_range<S: Simd>(simd: S, model: &ReducedModel, a: &[Pack<S>]) -> bool {
    let (offset, columns) = model.angle_bound().split_first().unwrap_or((&0.0, &[]));
    let mut bound = Pack::splat(simd, *offset);
    for (a_k, &column) in a.iter().zip(columns) {
        bound = bound + a_k.abs() * Pack::splat(simd, column);
    }
    Pack::splat(simd, 0.5 * REDUCTION_LIMIT).all_greater(bound)
}

/// The pre-pass of one state: [`link_angle_rate`], the sines and cosines, then
/// [`link_products`], each a loop over registers of consecutive links (the last one padded with
/// the zeros of the padded constants). Separate loops, so that the sines and cosines (long
/// chains of dependent operations) run alone, short enough for the processor to overlap them.
#[inline(always)]
pub(super) fn link_values_across_links<S: Simd>(
    simd: S,
    model: &ReducedModel,
    a: &[f64],
    a_dot: &[f64],
    links: &mut LinkBuffers<'_>,
) {
    if S::F64_LANES > LINK_PADDING {
        // Wider registers than the padding: one link at a time.
        across_links::<f64>((), model, a, a_dot, links);
    } else {
        across_links::<Pack<S>>(simd, model, a, a_dot, links);
    }
}

/// [`link_values_across_links`] in registers of `L` (`L::WIDTH` at most [`LINK_PADDING`]).
#[inline(always)]
pub(super) fn across_links<L: Lane>(
    context: L::Context,
    model: &ReducedModel,
    a: &[f64],
    a_dot: &[f64],
    links: &mut LinkBuffers<'_>,
) {
    let constants = model.link_constants();
    let n = model.n_links();
    for l in (0..n).step_by(L::WIDTH) {
        let inputs = AcrossLinks::<L> {
            context,
            model,
            a,
            a_dot,
            l,
        };
        let offset = L::load(context, &constants.angle_offset[l..]);
        links.store_angle_rate(l, 1, link_angle_rate(context, offset, &inputs));
    }
    links.sin_cos::<L>(context, n.next_multiple_of(L::WIDTH));
    for l in (0..n).step_by(L::WIDTH) {
        let angles = links.load_trig_rate(context, l, 1);
        let moment = L::load(context, &constants.first_moment[l..]);
        let length = L::load(context, &constants.length[l..]);
        links.store_products(l, 1, link_products(angles, moment, length));
    }
}

/// The inputs of [`link_angle_rate`] for the consecutive links `l..l + L::WIDTH` of one state (its
/// coordinates spread across the lanes).
pub(super) struct AcrossLinks<'a, L: Lane> {
    pub(super) context: L::Context,
    pub(super) model: &'a ReducedModel,
    pub(super) a: &'a [f64],
    pub(super) a_dot: &'a [f64],
    pub(super) l: usize,
}

impl<L: Lane> LinkInputs<L> for AcrossLinks<'_, L> {
    #[inline(always)]
    fn coords(&self) -> usize {
        self.a.len()
    }

    #[inline(always)]
    fn add_terms(&self, k: usize, angle: L, rate: L) -> (L, L) {
        let column = self.model.link_constants().angle_column(k);
        let phi = L::load(self.context, &column[self.l..]);
        (
            L::splat(self.context, self.a[k]).mul_add(phi, angle),
            L::splat(self.context, self.a_dot[k]).mul_add(phi, rate),
        )
    }
}

/// The inputs of [`link_angle_rate`] for link `phi` (its row `Phi_l`) of several states side by side.
pub(super) struct AcrossStates<'a, S: Simd> {
    pub(super) simd: S,
    pub(super) a: &'a [Pack<S>],
    pub(super) a_dot: &'a [Pack<S>],
    pub(super) phi: &'a [f64],
    /// The column of ones of `Phi`, or `usize::MAX` (see [`StateLanes`]).
    pub(super) unit: usize,
}

impl<S: Simd> LinkInputs<Pack<S>> for AcrossStates<'_, S> {
    #[inline(always)]
    fn coords(&self) -> usize {
        self.a.len()
    }

    #[inline(always)]
    fn add_terms(&self, k: usize, angle: Pack<S>, rate: Pack<S>) -> (Pack<S>, Pack<S>) {
        if k == self.unit {
            // `x * 1 + y` rounds as `x + y`.
            return (angle + self.a[k], rate + self.a_dot[k]);
        }
        let phi = Pack::splat(self.simd, self.phi[k]);
        (
            self.a[k].mul_add(phi, angle),
            self.a_dot[k].mul_add(phi, rate),
        )
    }
}

/// The state-dependent inputs of [`link_angle_rate`].
pub(super) trait LinkInputs<L> {
    /// The number of coordinates `m`.
    fn coords(&self) -> usize;
    /// `(angle + a_k (Phi_l)_k, rate + a_dot_k (Phi_l)_k)`, each rounded once.
    fn add_terms(&self, k: usize, angle: L, rate: L) -> (L, L);
}

/// `[phi_l, phi_dot_l]` of one link (or one lane's link each), from its angle offset `phi0_l`
/// and the state: `phi_l = phi0_l + Phi_l . a`, `phi_dot_l = Phi_l . a_dot`.
#[inline(always)]
pub(super) fn link_angle_rate<L: Lane>(
    context: L::Context,
    angle_offset: L,
    inputs: &impl LinkInputs<L>,
) -> [L; 2] {
    let mut angle = angle_offset;
    let mut rate = L::splat(context, 0.0);
    for k in 0..inputs.coords() {
        (angle, rate) = inputs.add_terms(k, angle, rate);
    }
    [angle, rate]
}

/// The [`PRODUCTS`] of one link (or one lane's link each) from `[sin phi_l, cos phi_l, phi_dot_l]`, its first moment
/// `S_l` and its length `L_l`.
#[inline(always)]
pub(super) fn link_products<L: Lane>(
    [sin, cos, rate]: [L; 3],
    moment: L,
    length: L,
) -> [L; PRODUCTS] {
    let rate2 = rate * rate;
    let (l_sin, l_cos) = (sin * length, cos * length);
    [rate2 * moment, l_sin, l_cos, l_cos * rate2, l_sin * rate2]
}

/// The per-link buffers of the kernel: every link's angle, its sine and cosine, and the
/// [`PRODUCTS`], each entry `W` values side by side (`W` the lanes of the layout's
/// [`Value`](super::Registers::Value): one state's links have one, a batch's the states of a group).
pub(crate) struct LinkBuffers<'a> {
    /// `phi_l`, `[link][lane]`.
    pub(crate) angle: &'a mut [f64],
    /// `sin phi_l`, as `angle`.
    pub(crate) sin: &'a mut [f64],
    /// `cos phi_l`, as `sin`.
    pub(crate) cos: &'a mut [f64],
    /// The products, `[product][link][lane]`.
    pub(crate) products: &'a mut [f64],
    /// The links of each product's buffer: `n`, or more for padding.
    pub(crate) links: usize,
}

impl LinkBuffers<'_> {
    /// Stores `[phi_l, phi_dot_l]` of link `l` (the rate where the first product goes, until
    /// [`store_products`](Self::store_products)), entries of `width` lanes: of the links
    /// `l..l + L::WIDTH` for a register across links (`width` 1), of link `l` for a register of
    /// states (`width` `L::WIDTH`).
    #[inline(always)]
    fn store_angle_rate<L: Lane>(&mut self, l: usize, width: usize, [angle, rate]: [L; 2]) {
        let entry = l * width;
        angle.store(&mut self.angle[entry..]);
        rate.store(&mut self.products[entry..]);
    }

    /// The sines and cosines of the first `entries` angles (a whole number of registers of
    /// `L`), a register at a time.
    #[inline(always)]
    fn sin_cos<L: Lane>(&mut self, context: L::Context, entries: usize) {
        let width = L::WIDTH;
        let angle = self.angle[..entries].chunks_exact(width);
        let sin = self.sin[..entries].chunks_exact_mut(width);
        let cos = self.cos[..entries].chunks_exact_mut(width);
        for ((angle, sin), cos) in angle.zip(sin).zip(cos) {
            let (sin_x, cos_x) = sin_cos_lanes(context, L::load(context, angle));
            sin_x.store(sin);
            cos_x.store(cos);
        }
    }

    /// The entries of the first `registers` registers of `width` lanes, in the order of
    /// [`values`](Self::values), to be written by [`store_link`]; and the angles.
    #[inline(always)]
    pub(super) fn angles_and_registers(
        &mut self,
        registers: usize,
        width: usize,
    ) -> (&[f64], impl Iterator<Item = [&mut [f64]; 2 + PRODUCTS]>) {
        let size = registers * width;
        let mut rest = &mut *self.products;
        let [p0, p1, p2, p3, p4] = std::array::from_fn(|_| {
            let (product, tail) = std::mem::take(&mut rest).split_at_mut(self.links * width);
            rest = tail;
            product[..size].chunks_exact_mut(width)
        });
        let sin = self.sin[..size].chunks_exact_mut(width);
        let registers = sin
            .zip(self.cos[..size].chunks_exact_mut(width))
            .zip(p0)
            .zip(p1)
            .zip(p2)
            .zip(p3)
            .zip(p4)
            .map(|((((((sin, cos), p0), p1), p2), p3), p4)| [sin, cos, p0, p1, p2, p3, p4]);
        (&self.angle[..size], registers)
    }

    /// `[sin phi_l, cos phi_l, phi_dot_l]` of link `l` after [`sin_cos`](Self::sin_cos).
    #[inline(always)]
    fn load_trig_rate<L: Lane>(&self, context: L::Context, l: usize, width: usize) -> [L; 3] {
        let entry = l * width;
        [
            L::load(context, &self.sin[entry..]),
            L::load(context, &self.cos[entry..]),
            L::load(context, &self.products[entry..]),
        ]
    }

    /// Stores the [`PRODUCTS`] of link `l` (entries as in
    /// [`store_angle_rate`](Self::store_angle_rate)).
    #[inline(always)]
    fn store_products<L: Lane>(&mut self, l: usize, width: usize, products: [L; PRODUCTS]) {
        for (p, value) in products.iter().enumerate() {
            value.store(&mut self.products[(p * self.links + l) * width..]);
        }
    }

    /// The entries the pre-pass left for the first `registers` registers of `width` lanes, for
    /// the pass: `[sin phi_l, cos phi_l]` and the [`PRODUCTS`], each a slice of `width`
    /// values (read by [`load_link`]), zipped so that the pass reads them without bounds
    /// checks.
    #[inline(always)]
    pub(super) fn values(
        &self,
        registers: usize,
        width: usize,
    ) -> impl Iterator<Item = [&[f64]; 2 + PRODUCTS]> {
        let size = registers * width;
        let stride = self.links * width;
        let [p0, p1, p2, p3, p4] =
            std::array::from_fn(|p| self.products[p * stride..][..size].chunks_exact(width));
        let sin = self.sin[..size].chunks_exact(width);
        sin.zip(self.cos[..size].chunks_exact(width))
            .zip(p0)
            .zip(p1)
            .zip(p2)
            .zip(p3)
            .zip(p4)
            .map(|((((((sin, cos), p0), p1), p2), p3), p4)| [sin, cos, p0, p1, p2, p3, p4])
    }
}

/// Writes a register of [`LinkBuffers::angles_and_registers`].
#[inline(always)]
pub(super) fn store_link<L: Lane>(out: [&mut [f64]; 2 + PRODUCTS], values: [L; 2 + PRODUCTS]) {
    for (value, out) in values.into_iter().zip(out) {
        value.store(out);
    }
}

/// Reads a register of [`LinkBuffers::values`].
#[inline(always)]
pub(super) fn load_link<L: Lane>(
    context: L::Context,
    entries: [&[f64]; 2 + PRODUCTS],
) -> [L; 2 + PRODUCTS] {
    // (No closure: its body would be compiled without the dispatch's instruction set.)
    let [sin, cos, p0, p1, p2, p3, p4] = entries;
    [
        L::load(context, sin),
        L::load(context, cos),
        L::load(context, p0),
        L::load(context, p1),
        L::load(context, p2),
        L::load(context, p3),
        L::load(context, p4),
    ]
}
