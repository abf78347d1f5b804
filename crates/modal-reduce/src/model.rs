//! The immutable reduced model: a chain and a constant modal map (the "Model" of the Model/Data
//! split).

use backbone_kin::{BaseAngle, ModalMap};
use manip_dyn::ChainModel;

use crate::error::ReduceError;
use lane_math::dense::{cholesky, symmetric_eigen_extremes};

/// The most `f64` lanes of a SIMD register (AVX-512): the per-link buffers of one state are
/// padded to a multiple of it.
pub(crate) const LINK_PADDING: usize = 8;

/// Below this smallest eigenvalue of the column-normalised Gram matrix of `J` (the square of the
/// smallest singular value of `J` with unit columns) the map is treated as rank-deficient: `M*`
/// would then be singular or too ill-conditioned for a solve to mean anything.
const RANK_TOLERANCE: f64 = 1e-10;

/// Largest relative difference between a map's and a chain's link fractions `L_i / l` that counts
/// as the same geometry, for up to `GEOMETRY_TOLERANCE / (2 eps)` (4503) links: rounding of the
/// two sums, far below any real difference in design. Each sum of `n` lengths is within
/// `(n - 1) eps / 2` of exact (relative), so longer chains get `2 n eps` (4.4e-10 at 10^6 links).
const GEOMETRY_TOLERANCE: f64 = 1e-12;

/// The per-link constants of the default path (see [`crate::terms`]), one array per quantity
/// (structure of arrays), each `n` values followed by zeros up to a multiple of [`LINK_PADDING`]
/// links, so that whole registers of consecutive links load from them.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct LinkConstants {
    /// Link length `L_l`.
    pub length: Vec<f64>,
    /// `S_l = m_l r_l + L_l mu_l`: the first moment of mass about joint `l` of the link and,
    /// lumped at its far joint, all the mass `mu_l` beyond it.
    pub first_moment: Vec<f64>,
    /// Absolute angle of the link at `a = 0`: `phi0_l = theta0_0 + ... + theta0_l`.
    pub angle_offset: Vec<f64>,
    /// The columns of `Phi` (entry `k` of every `Phi_l`), column `k` at `k` times the padded
    /// length.
    pub angle_columns: Vec<f64>,
    /// The padded length of each array and column.
    pub padded: usize,
}

impl LinkConstants {
    /// Column `k` of `Phi`, padded.
    pub(crate) fn angle_column(&self, k: usize) -> &[f64] {
        &self.angle_columns[k * self.padded..(k + 1) * self.padded]
    }
}

/// A planar chain constrained to a constant modal map `theta = J a + theta_0` (eqs 8-11), with
/// what the reduced dynamics (eqs 13-18) needs precomputed.
///
/// Because `J` is constant the constraint is holonomic and exact, and the reduced model is itself
/// Lagrangian with coordinates `a`: `M* = J^T M J`, `C* = J^T C(J a + theta_0, J a_dot)`,
/// `G* = J^T G(J a + theta_0)` and `tau* = J^T tau` (eqs 14-15).
///
/// ```
/// use backbone_kin::ModalMap;
/// use manip_dyn::ChainModel;
/// use modal_reduce::ReducedModel;
///
/// let model = ReducedModel::new(ChainModel::uniform(10, 0.1, 0.1, 9.81)?, ModalMap::paper(10)?)?;
/// assert_eq!((model.n_links(), model.n_coords()), (10, 3));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct ReducedModel {
    chain: ChainModel,
    map: ModalMap,
    /// Row `l` is `Phi_l = J_0 + ... + J_l`, the gradient of link `l`'s absolute angle with
    /// respect to `a` (row-major, `n x m`), followed by [`LINK_PADDING`] zeros so that a whole
    /// register loads from the start of any row.
    angle_rows: Vec<f64>,
    /// Row `l` is `S_l Phi_l` (see [`LinkConstants::first_moment`]), laid out like `angle_rows`.
    moment_rows: Vec<f64>,
    /// The first coordinate whose column of `Phi` is all ones (a free base angle `alpha0`).
    unit_column: Option<usize>,
    links: LinkConstants,
    /// `K = sum_l h_ll Phi_l^T Phi_l` (row-major `m x m`): the constant part of `M*`, followed
    /// by [`LINK_PADDING`] zeros like `angle_rows`.
    constant_mass: Vec<f64>,
    /// `[max_l |phi0_l|, max_l |(Phi_l)_0|, ..., max_l |(Phi_l)_{m-1}|]`: every absolute angle
    /// is at most `angle_bound[0] + sum_k angle_bound[k + 1] |a_k|` in size.
    angle_bound: Vec<f64>,
}

impl ReducedModel {
    /// The reduced model of `chain` under the `harmonics`-mode map built from the chain's own
    /// link lengths (eq 7 with `s_i` the midpoints of its links), `alpha0` a coordinate or fixed
    /// as `base` says. Fails as [`new`](Self::new) does, and with
    /// [`ReduceError::Kin`] for a bad harmonic count or `alpha0`.
    ///
    /// ```
    /// use backbone_kin::BaseAngle;
    /// use manip_dyn::{ChainModel, Link};
    /// use modal_reduce::ReducedModel;
    ///
    /// let links = [0.3, 0.2, 0.2, 0.1].map(|length| Link::uniform_beam(length, 0.1));
    /// let chain = ChainModel::new(links.into_iter().collect::<Result<_, _>>()?, 9.81)?;
    /// let model = ReducedModel::from_chain(chain, 1, BaseAngle::Fixed(1.0))?;
    /// assert_eq!(model.n_coords(), 2);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn from_chain(
        chain: ChainModel,
        harmonics: usize,
        base: BaseAngle,
    ) -> Result<Self, ReduceError> {
        let lengths: Vec<f64> = chain.link_lengths().collect();
        let map = ModalMap::new(&lengths, harmonics, base)?;
        Self::new(chain, map)
    }

    /// Builds the reduced model of `chain` under `map`.
    ///
    /// Fails if the map's joint count differs from the chain's link count, if the map was built
    /// for links of other relative lengths (`L_i / l` differing by more than `1e-12` relative, or
    /// `2 n eps` for chains of more than 4503 links, the rounding of the sums:
    /// for example [`ModalMap::paper`] with a chain of unequal links, whose `J` would be
    /// silently wrong), or if `J` is column-rank-deficient (for example three coordinates on
    /// fewer than three links, or more harmonics than the links can resolve), since
    /// `M* = J^T M J` would then be singular. [`from_chain`](Self::from_chain) builds the map
    /// that fits.
    pub fn new(chain: ChainModel, map: ModalMap) -> Result<Self, ReduceError> {
        let (n, m) = (map.n_joints(), map.n_coords());
        if n != chain.n_links() {
            return Err(ReduceError::LinkCountMismatch {
                joints: n,
                links: chain.n_links(),
            });
        }
        check_geometry(&chain, &map)?;
        check_column_rank(&map)?;
        // mu_l, the mass beyond link l (see the module `terms` for this and S_l, h_ll and K).
        let chain_links = chain.links();
        let zeros = |len: usize, what| lane_math::try_filled(len, 0.0, what);
        let mut beyond = zeros(n, "the reduced model's link masses")?;
        for l in (0..n - 1).rev() {
            beyond[l] = beyond[l + 1] + chain_links[l + 1].mass;
        }
        let rows = n * m + LINK_PADDING;
        let mut angle_rows = zeros(rows, "the reduced model's angle rows")?;
        let mut moment_rows = zeros(rows, "the reduced model's moment rows")?;
        let padded = n.next_multiple_of(LINK_PADDING);
        let mut links = LinkConstants {
            length: zeros(padded, "the reduced model's link lengths")?,
            first_moment: zeros(padded, "the reduced model's first moments")?,
            angle_offset: zeros(padded, "the reduced model's angle offsets")?,
            angle_columns: zeros(m * padded, "the reduced model's angle columns")?,
            padded,
        };
        let mut constant_mass = vec![0.0; m * m + LINK_PADDING];
        let mut running = vec![0.0; m];
        let mut angle_offset = 0.0;
        for (l, (link, phi)) in chain_links
            .iter()
            .zip(angle_rows.chunks_exact_mut(m))
            .enumerate()
        {
            // Phi_l = Phi_{l-1} + J_l.
            for (sum, &entry) in running.iter_mut().zip(map.row(l)) {
                *sum += entry;
            }
            phi.copy_from_slice(&running);
            for (k, &entry) in running.iter().enumerate() {
                links.angle_columns[k * padded + l] = entry;
            }
            angle_offset += map.offset()[l];
            links.length[l] = link.length;
            links.first_moment[l] = link.mass * link.com + link.length * beyond[l];
            for (k, &entry) in running.iter().enumerate() {
                moment_rows[l * m + k] = links.first_moment[l] * entry;
            }
            links.angle_offset[l] = angle_offset;
            let diagonal = link.inertia
                + link.mass * link.com * link.com
                + link.length * link.length * beyond[l];
            for j in 0..m {
                for k in 0..m {
                    constant_mass[j * m + k] += diagonal * phi[j] * phi[k];
                }
            }
        }
        let unit_column =
            (0..m).find(|&k| angle_rows[..n * m].chunks_exact(m).all(|row| row[k] == 1.0));
        let mut angle_bound = vec![0.0; m + 1];
        for (offset, row) in links.angle_offset[..n]
            .iter()
            .zip(angle_rows.chunks_exact(m))
        {
            angle_bound[0] = f64::max(angle_bound[0], offset.abs());
            for (bound, entry) in angle_bound[1..].iter_mut().zip(row) {
                *bound = f64::max(*bound, entry.abs());
            }
        }
        Ok(Self {
            chain,
            map,
            angle_rows,
            moment_rows,
            unit_column,
            links,
            constant_mass,
            angle_bound,
        })
    }

    /// The full chain.
    pub fn chain(&self) -> &ChainModel {
        &self.chain
    }

    /// The modal map `theta = J a + theta_0`.
    pub fn map(&self) -> &ModalMap {
        &self.map
    }

    /// Number of links (and joints) `n`.
    pub fn n_links(&self) -> usize {
        self.map.n_joints()
    }

    /// Number of modal coordinates `m`.
    pub fn n_coords(&self) -> usize {
        self.map.n_coords()
    }

    /// `J` as a faer matrix (a view of the map's row-major entries).
    pub(crate) fn jacobian(&self) -> faer::MatRef<'_, f64> {
        faer::MatRef::from_row_major_slice(self.map.jacobian(), self.n_links(), self.n_coords())
    }

    /// Row-major `n x m` gradients of the absolute link angles, `Phi_i`, followed by
    /// [`LINK_PADDING`] zeros.
    pub(crate) fn angle_rows(&self) -> &[f64] {
        &self.angle_rows
    }

    /// The first coordinate whose column of `Phi` is exactly one for every link, if any: a free
    /// base angle `alpha0`, which adds to every absolute angle. A batch skips the
    /// multiplications by it (the same bits).
    pub(crate) fn unit_column(&self) -> Option<usize> {
        self.unit_column
    }

    /// Row-major `n x m` rows `S_l Phi_l`, followed by [`LINK_PADDING`] zeros.
    pub(crate) fn moment_rows(&self) -> &[f64] {
        &self.moment_rows
    }

    /// A bound on the absolute angles: see the field `angle_bound`.
    pub(crate) fn angle_bound(&self) -> &[f64] {
        &self.angle_bound
    }

    /// The constant part `K` of `M*`, row-major `m x m`, followed by [`LINK_PADDING`] zeros.
    pub(crate) fn constant_mass(&self) -> &[f64] {
        &self.constant_mass
    }

    /// Per-link constants, base first.
    pub(crate) fn link_constants(&self) -> &LinkConstants {
        &self.links
    }
}

/// Refuses a map built for links of other relative lengths than the chain's.
fn check_geometry(chain: &ChainModel, map: &ModalMap) -> Result<(), ReduceError> {
    let map_total: f64 = map.link_lengths().iter().sum();
    let chain_total = chain.total_length();
    let tolerance = GEOMETRY_TOLERANCE.max(2.0 * chain.n_links() as f64 * f64::EPSILON);
    for (link, (&map_length, chain_length)) in map
        .link_lengths()
        .iter()
        .zip(chain.link_lengths())
        .enumerate()
    {
        let (map_fraction, chain_fraction) = (map_length / map_total, chain_length / chain_total);
        if (map_fraction - chain_fraction).abs() > tolerance * chain_fraction {
            return Err(ReduceError::GeometryMismatch {
                link,
                map_fraction,
                chain_fraction,
            });
        }
    }
    Ok(())
}

/// Refuses a map whose `J` has (numerically) dependent columns.
pub(crate) fn check_column_rank(map: &ModalMap) -> Result<(), ReduceError> {
    let (n, m) = (map.n_joints(), map.n_coords());
    let deficient = |min_eigenvalue| ReduceError::RankDeficient {
        links: n,
        coords: m,
        min_eigenvalue,
    };
    // `J` has at most `n` independent columns: no need to form `J^T J` to say so.
    if m > n {
        return Err(deficient(0.0));
    }
    let mut gram = vec![0.0; m * m];
    for i in 0..n {
        let row = map.row(i);
        for j in 0..m {
            for k in 0..m {
                gram[j * m + k] += row[j] * row[k];
            }
        }
    }
    let scale: Vec<f64> = (0..m).map(|j| gram[j * m + j].sqrt()).collect();
    if scale.contains(&0.0) {
        return Err(deficient(0.0));
    }
    for j in 0..m {
        for k in 0..m {
            gram[j * m + k] /= scale[j] * scale[k];
        }
    }
    // The smallest eigenvalue is above the tolerance when `G - tol I` is positive definite, which
    // a Cholesky factorisation (m^3 / 3 operations) decides; the Jacobi iteration of the
    // eigenvalues (tens of m^3) only runs to name a failing one.
    let mut shifted = gram.clone();
    for j in 0..m {
        shifted[j * m + j] -= RANK_TOLERANCE;
    }
    if cholesky(&mut shifted, m) {
        return Ok(());
    }
    let (min_eigenvalue, _) = symmetric_eigen_extremes(&mut gram, m);
    if min_eigenvalue <= RANK_TOLERANCE {
        return Err(deficient(min_eigenvalue));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_free_base_angle_is_the_unit_column_and_a_fixed_one_leaves_none() {
        let chain = ChainModel::uniform(10, 0.1, 0.1, 9.81).unwrap();
        let paper = ReducedModel::new(chain.clone(), ModalMap::paper(10).unwrap()).unwrap();
        // (a1, a2, alpha0): alpha0 adds to every absolute angle.
        assert_eq!(paper.unit_column(), Some(2));
        let fixed = ModalMap::uniform(10, 2, BaseAngle::Fixed(0.3)).unwrap();
        let fixed = ReducedModel::new(chain, fixed).unwrap();
        assert_eq!(fixed.unit_column(), None);
    }
}
