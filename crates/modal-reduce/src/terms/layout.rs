//! How the kernel's numbers sit in registers: the [`Layout`] trait and its three
//! implementations (see the [parent module](super)).

use lane_math::{Lane, Pack, sin_cos_in_range};
use pulp::Simd;

use super::links::{
    AcrossStates, LinkBuffers, link_angle_rate, link_products, link_values_across_links, store_link,
};
use crate::data::Pair;
use crate::model::{LINK_PADDING, ReducedModel};

/// How a kernel's numbers sit in registers (see the [module documentation](super)): the part
/// of a [`Layout`] that the spatial kernel ([`spatial::terms`](crate::spatial::terms)) shares.
pub(crate) trait Registers: Copy {
    /// A register of the pass: several coordinates of one state, or one coordinate (of one state
    /// or of several side by side).
    type Register: Lane;
    /// One number of each state: `f64` for one state, a register of states for a batch.
    type Value: Lane;
    /// What building a register needs.
    fn register_context(self) -> <Self::Register as Lane>::Context;
    /// What building a value needs.
    fn value_context(self) -> <Self::Value as Lane>::Context;
    /// How many registers a row of `m` coordinates takes.
    fn chunks(self, m: usize) -> usize;
    /// `value` in every coordinate of a register.
    fn spread(self, value: Self::Value) -> Self::Register;
    /// Register `chunk` of a constant row of the layout's `m` coordinates starting at `row[0]`;
    /// `row` continues for at least [`LINK_PADDING`] values (the lanes past the `m` coordinates
    /// are zero).
    fn constant_row(self, row: &[f64], chunk: usize) -> Self::Register;
    /// Coordinate `k` of the row held in the registers `row`.
    fn coordinate(self, row: &[Self::Register], k: usize) -> Self::Value;
}

/// How the planar kernel's numbers sit in registers (see the [module documentation](super)).
pub(crate) trait Layout: Registers {
    /// The step `P_{l+1} = P_l + L_l w_l Phi_l` of register `chunk` of the columns `pair` of
    /// `P_l`, from `L_l sin phi_l`, `L_l cos phi_l` and the constant row `row` of `Phi` (see
    /// [`constant_row`](Registers::constant_row)).
    #[inline(always)]
    fn joint_step(
        self,
        [px, py]: Pair<Self::Register>,
        [l_sin, l_cos]: Pair<Self::Register>,
        row: &[f64],
        chunk: usize,
    ) -> Pair<Self::Register> {
        joint_step_by([px, py], [l_sin, l_cos], self.constant_row(row, chunk))
    }

    /// The per-link values of all links into `links` (the pre-pass).
    fn link_values(
        self,
        model: &ReducedModel,
        a: &[Self::Value],
        a_dot: &[Self::Value],
        links: &mut LinkBuffers<'_>,
    );
}

/// One state, its coordinates side by side in one register of the instruction set `S` (`m` at
/// most its lanes, which are at most [`LINK_PADDING`]); the pre-pass runs across links.
#[derive(Clone, Copy)]
pub(crate) struct CoordinateLanes<S: Simd> {
    simd: S,
    /// All bits set in the lanes of the `m` coordinates, none past them.
    mask: Pack<S>,
}

impl<S: Simd> CoordinateLanes<S> {
    /// The layout for `m` coordinates.
    #[inline(always)]
    pub(crate) fn new(simd: S, m: usize) -> Self {
        let mut mask = [0.0; LINK_PADDING];
        for lane in &mut mask[..m] {
            *lane = f64::from_bits(!0);
        }
        Self {
            simd,
            mask: Pack::load(simd, &mask),
        }
    }
}

impl<S: Simd> Registers for CoordinateLanes<S> {
    type Register = Pack<S>;
    type Value = f64;

    #[inline(always)]
    fn register_context(self) -> S {
        self.simd
    }

    #[inline(always)]
    fn value_context(self) {}

    #[inline(always)]
    fn chunks(self, _: usize) -> usize {
        1
    }

    #[inline(always)]
    fn spread(self, value: f64) -> Pack<S> {
        Pack::splat(self.simd, value)
    }

    #[inline(always)]
    fn constant_row(self, row: &[f64], _: usize) -> Pack<S> {
        Pack::load(self.simd, row).and_bits(self.mask)
    }

    #[inline(always)]
    fn coordinate(self, row: &[Pack<S>], k: usize) -> f64 {
        row[0].lane(k)
    }
}

impl<S: Simd> Layout for CoordinateLanes<S> {
    #[inline(always)]
    fn link_values(
        self,
        model: &ReducedModel,
        a: &[f64],
        a_dot: &[f64],
        links: &mut LinkBuffers<'_>,
    ) {
        link_values_across_links(self.simd, model, a, a_dot, links);
    }
}

/// One state, one coordinate a number (for more coordinates than a register holds); the
/// pre-pass runs across links in registers of `S`.
#[derive(Clone, Copy)]
pub(crate) struct OneStateScalar<S>(pub(crate) S);

impl<S: Simd> Registers for OneStateScalar<S> {
    type Register = f64;
    type Value = f64;

    #[inline(always)]
    fn register_context(self) {}

    #[inline(always)]
    fn value_context(self) {}

    #[inline(always)]
    fn chunks(self, m: usize) -> usize {
        m
    }

    #[inline(always)]
    fn spread(self, value: f64) -> f64 {
        value
    }

    #[inline(always)]
    fn constant_row(self, row: &[f64], chunk: usize) -> f64 {
        row[chunk]
    }

    #[inline(always)]
    fn coordinate(self, row: &[f64], k: usize) -> f64 {
        row[k]
    }
}

impl<S: Simd> Layout for OneStateScalar<S> {
    #[inline(always)]
    fn link_values(
        self,
        model: &ReducedModel,
        a: &[f64],
        a_dot: &[f64],
        links: &mut LinkBuffers<'_>,
    ) {
        link_values_across_links(self.0, model, a, a_dot, links);
    }
}

/// Several states side by side, lane `i` of every register holding state `i`; one coordinate a
/// register. Only for states that pass [`angles_in_range`]: its sines and cosines skip the test
/// for angles beyond the reduction's range (four vector operations a link).
#[derive(Clone, Copy)]
pub(crate) struct StateLanes<S: Simd> {
    simd: S,
    /// A coordinate whose column of `Phi` is all ones ([`ReducedModel::unit_column`]), or
    /// `usize::MAX`: the multiplications by that column are skipped, which gives the same bits
    /// (`x * 1 = x` exactly) with fewer operations.
    unit: usize,
}

impl<S: Simd> StateLanes<S> {
    /// The layout of `S`, skipping the multiplications by the column `unit` of `Phi` (all ones;
    /// `usize::MAX` for none).
    #[inline(always)]
    pub(crate) fn new(simd: S, unit: usize) -> Self {
        Self { simd, unit }
    }
}

impl<S: Simd> Registers for StateLanes<S> {
    type Register = Pack<S>;
    type Value = Pack<S>;

    #[inline(always)]
    fn register_context(self) -> S {
        self.simd
    }

    #[inline(always)]
    fn value_context(self) -> S {
        self.simd
    }

    #[inline(always)]
    fn chunks(self, m: usize) -> usize {
        m
    }

    #[inline(always)]
    fn spread(self, value: Pack<S>) -> Pack<S> {
        value
    }

    #[inline(always)]
    fn constant_row(self, row: &[f64], chunk: usize) -> Pack<S> {
        Pack::splat(self.simd, row[chunk])
    }

    #[inline(always)]
    fn coordinate(self, row: &[Pack<S>], k: usize) -> Pack<S> {
        row[k]
    }
}

impl<S: Simd> Layout for StateLanes<S> {
    #[inline(always)]
    fn joint_step(
        self,
        [px, py]: Pair<Pack<S>>,
        [l_sin, l_cos]: Pair<Pack<S>>,
        row: &[f64],
        chunk: usize,
    ) -> Pair<Pack<S>> {
        if chunk == self.unit {
            // `x * 1 + y` rounds as `x + y`.
            [px - l_sin, py + l_cos]
        } else {
            joint_step_by([px, py], [l_sin, l_cos], self.constant_row(row, chunk))
        }
    }

    #[inline(always)]
    fn link_values(
        self,
        model: &ReducedModel,
        a: &[Pack<S>],
        a_dot: &[Pack<S>],
        links: &mut LinkBuffers<'_>,
    ) {
        let simd = self.simd;
        let width = S::F64_LANES;
        let constants = model.link_constants();
        let m = a.len();
        let n = model.n_links();
        let rows = model.angle_rows()[..n * m].chunks_exact(m);
        let offsets = &constants.angle_offset[..n];
        let LinkBuffers {
            angle, products, ..
        } = links;
        let angles = angle[..n * width].chunks_exact_mut(width);
        // The rates where the first product goes, until the products replace them.
        let rates = products[..n * width].chunks_exact_mut(width);
        for (((phi, &offset), angle), rate) in rows.zip(offsets).zip(angles).zip(rates) {
            let inputs = AcrossStates {
                simd,
                a,
                a_dot,
                phi,
                unit: self.unit,
            };
            let [angle_l, rate_l] = link_angle_rate(simd, Pack::splat(simd, offset), &inputs);
            angle_l.store(angle);
            rate_l.store(rate);
        }
        let (moments, lengths) = (&constants.first_moment[..n], &constants.length[..n]);
        let (angle, registers) = links.angles_and_registers(n, width);
        let per_link = angle.chunks_exact(width).zip(moments).zip(lengths);
        for (((angle, &moment), &length), out) in per_link.zip(registers) {
            let rate = Pack::load(simd, &*out[2]);
            // Within the reduction's range: `angles_in_range` held (see `StateLanes`).
            let (sin, cos) = sin_cos_in_range(simd, Pack::load(simd, angle));
            let (moment, length) = (Pack::splat(simd, moment), Pack::splat(simd, length));
            let [p0, p1, p2, p3, p4] = link_products([sin, cos, rate], moment, length);
            store_link(out, [sin, cos, p0, p1, p2, p3, p4]);
        }
    }
}

/// `[px - l_sin phi, py + l_cos phi]`, each rounded once: the step of a column pair of `P_l`
/// (see [`Layout::joint_step`]).
#[inline(always)]
pub(super) fn joint_step_by<R: Lane>(
    [px, py]: Pair<R>,
    [l_sin, l_cos]: Pair<R>,
    phi: R,
) -> Pair<R> {
    [l_sin.neg_mul_add(phi, px), l_cos.mul_add(phi, py)]
}
