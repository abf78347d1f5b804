//! `hrm.Arm`: the planar chain and its dynamics (eq 12), from `manip-dyn`.

use crate::args;
use crate::args::count;
use crate::array::{Output, States, evaluate, evaluate_chunks};
use crate::errors::{Error, check_finite};
use manip_dyn::faer::MatMut;
use manip_dyn::{AbaBatchData, BatchError, ChainData, ChainModel, DynError, MAX_DENSE_LINKS};
use numpy::{IntoPyArray, PyArray1};
use pyo3::prelude::*;
use sim_study::{ArmSpec, Gravity, Inertias};
use std::sync::Mutex;

/// A planar serial chain of revolute joints under gravity along -y (the paper's eq 12:
/// tau = M(theta) theta_ddot + C(theta, theta_dot) + G(theta)).
///
/// Arm(links=None, link_length=None, link_mass=None, gravity=9.81, lengths=None, masses=None,
/// inertias=None)
///
/// `links` uniform beams (10 when neither `links` nor a per-link array is given) of
/// `link_length` (m, default 0.1) and `link_mass` (kg, default 0.1), centre of mass at mid-link
/// and inertia m L^2 / 12; `lengths` and `masses` give them per link instead (a list and its
/// scalar together raise InvalidInput), `inertias` (about the centre of mass, kg m^2) the
/// beams' inertias.
/// theta_i is the angle of link i relative to link i - 1 (theta_1 from the x axis).
///
/// Every method takes one state (arrays of shape (n,)) or a batch (shape (N, n)) and answers
/// with the same leading dimension. Raises InvalidInput for a bad parameter, naming it as the
/// `hrm` command line does (e.g. "arm.masses[1] is invalid: link 1: mass must be positive and finite, got
/// -1").
#[pyclass(module = "hrm", frozen)]
pub struct Arm {
    chain: ChainModel,
    workspace: Mutex<ChainData>,
    /// The workspace of `aba` (one state and batches), built by its first call.
    aba_workspace: Mutex<Option<AbaBatchData>>,
}

impl Arm {
    /// The Python arm of `chain`.
    pub(crate) fn from_chain(chain: ChainModel) -> crate::errors::Result<Self> {
        Ok(Self {
            workspace: Mutex::new(ChainData::try_recursive(&chain)?),
            aba_workspace: Mutex::new(None),
            chain,
        })
    }

    /// The chain.
    pub(crate) fn chain(&self) -> &ChainModel {
        &self.chain
    }

    /// A workspace of the recursive algorithms: `O(n)`, since no method here factorises `M`.
    fn fresh(&self) -> crate::errors::Result<ChainData> {
        Ok(ChainData::try_recursive(&self.chain)?)
    }

    fn n(&self) -> usize {
        self.chain.n_links()
    }

    fn column(&self, value: impl Fn(&manip_dyn::Link) -> f64) -> Vec<f64> {
        self.chain.links().iter().map(value).collect()
    }
}

#[pymethods]
impl Arm {
    #[new]
    #[pyo3(
        signature = (links=None, link_length=None, link_mass=None, gravity=None, lengths=None, masses=None, inertias=None),
        text_signature = "(links=None, link_length=None, link_mass=None, gravity=9.81, lengths=None, masses=None, inertias=None)"
    )]
    fn new(
        links: Option<&Bound<'_, PyAny>>,
        link_length: Option<&Bound<'_, PyAny>>,
        link_mass: Option<&Bound<'_, PyAny>>,
        gravity: Option<&Bound<'_, PyAny>>,
        lengths: Option<&Bound<'_, PyAny>>,
        masses: Option<&Bound<'_, PyAny>>,
        inertias: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let links = links.map(|n| count(n, "arm.links", 1)).transpose()?;
        let real = |value: Option<&Bound<'_, PyAny>>, name, default| {
            value.map_or(Ok(default), |v| args::real(v, name))
        };
        let given =
            |value: Option<&Bound<'_, PyAny>>, name| value.map(|v| args::real(v, name)).transpose();
        let (link_length, link_mass, gravity) = (
            given(link_length, "link_length")?,
            given(link_mass, "link_mass")?,
            real(gravity, "gravity", 9.81)?,
        );
        let per_link = |value: Option<&Bound<'_, PyAny>>, name| {
            value
                .map(|v| args::reals(v, name, backbone_kin::MAX_LINKS))
                .transpose()
        };
        let (lengths, masses, inertias) = (
            per_link(lengths, "lengths")?,
            per_link(masses, "masses")?,
            per_link(inertias, "inertias")?,
        );
        let spec = ArmSpec {
            links,
            link_length,
            link_mass,
            gravity: Some(Gravity::Magnitude(gravity)),
            lengths,
            masses,
            inertias: inertias.map(Inertias::PerLink),
            ..ArmSpec::default()
        };
        let chain = spec.to_chain().map_err(Error::from)?;
        Ok(Self::from_chain(chain)?)
    }

    /// Number of links (and joints) n.
    #[getter]
    fn n_links(&self) -> usize {
        self.n()
    }

    /// Gravitational acceleration along -y (m/s^2).
    #[getter]
    fn gravity_acceleration(&self) -> f64 {
        self.chain.gravity()
    }

    /// Link lengths (m), base first, shape (n,).
    #[getter]
    fn lengths<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.column(|l| l.length).into_pyarray(py)
    }

    /// Link masses (kg), shape (n,).
    #[getter]
    fn masses<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.column(|l| l.mass).into_pyarray(py)
    }

    /// Link inertias about their centres of mass, about z (kg m^2), shape (n,).
    #[getter]
    fn inertias<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.column(|l| l.inertia).into_pyarray(py)
    }

    /// Distance of each link's centre of mass from its joint, along the link (m), shape (n,).
    #[getter]
    fn coms<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.column(|l| l.com).into_pyarray(py)
    }

    /// A spatial chain read from URDF: `hrm.Chain.from_urdf(urdf, gravity)` (an `hrm.Chain`, the
    /// class of URDF chains, not a planar `Arm`).
    #[staticmethod]
    #[pyo3(signature = (urdf, gravity=None), text_signature = "(urdf, gravity=(0, 0, -9.81))")]
    fn from_urdf(
        urdf: &Bound<'_, PyAny>,
        gravity: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<crate::chain::Chain> {
        crate::chain::Chain::from_urdf(urdf, gravity)
    }

    /// The arm as URDF text: joints about z in the base's x-y plane, links along x. URDF has no
    /// gravity: set it along -y (the arm's) in the engine that reads it. Raises InvalidInput for
    /// more than 40,000 links (`robot_desc::MAX_EXPORT_JOINTS`) or a number the URDF reader would refuse (a mass above 1e9).
    fn to_urdf(&self) -> PyResult<String> {
        let (robot, _) = crate::chain::planar_robot(&self.chain)?;
        Ok(robot_desc::write_urdf(&robot).map_err(|e| Error::input(e.to_string()))?)
    }

    /// The arm as one MJCF document for MuJoCo (as `to_urdf`), its gravity along -y in
    /// `<option>`. Raises InvalidInput, naming the link, for a mass or inertia below MuJoCo's
    /// mjMINVAL (1e-15), which MuJoCo refuses.
    fn to_mjcf(&self) -> PyResult<String> {
        let (robot, gravity) = crate::chain::planar_robot(&self.chain)?;
        crate::chain::mjcf(&robot, gravity)
    }

    /// `pickle` and `copy.deepcopy` support: the arm rebuilt from its gravity and per-link
    /// lengths, masses and inertias (its defining parameters).
    #[allow(
        clippy::type_complexity,
        reason = "pickle's (callable, arguments) pair"
    )]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(
        Bound<'py, PyAny>,
        (
            Option<usize>,
            Option<f64>,
            Option<f64>,
            f64,
            Vec<f64>,
            Vec<f64>,
            Vec<f64>,
        ),
    )> {
        let arm = slf.get();
        Ok((
            slf.get_type().into_any(),
            (
                None,
                None,
                None,
                arm.chain.gravity(),
                arm.column(|l| l.length),
                arm.column(|l| l.mass),
                arm.column(|l| l.inertia),
            ),
        ))
    }

    fn __repr__(&self) -> String {
        format!(
            "Arm(links={}, total_length={}, total_mass={}, gravity={})",
            self.n(),
            self.chain.total_length(),
            self.chain.links().iter().map(|l| l.mass).sum::<f64>(),
            self.chain.gravity()
        )
    }

    /// The joint-space mass matrix M(theta) (CRBA), shape (n, n) or (N, n, n). Raises
    /// InvalidInput for an arm of more than 4096 links (`manip_dyn::MAX_DENSE_LINKS`, the limit of
    /// the n x n algorithms; every other method takes arms of up to 10^6 links).
    fn mass_matrix<'py>(
        &self,
        py: Python<'py>,
        theta: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = self.n();
        if n > MAX_DENSE_LINKS {
            return Err(Error::from(DynError::TooManyLinks {
                what: "Arm.mass_matrix (an n x n matrix)",
                got: n,
                max: MAX_DENSE_LINKS,
            })
            .into());
        }
        let theta = States::read(theta, "theta", n)?;
        let out = evaluate(
            py,
            [&theta],
            n * n,
            n * n,
            &self.workspace,
            || self.fresh(),
            |data, [q], out| {
                manip_dyn::mass_matrix(
                    &self.chain,
                    data,
                    q,
                    MatMut::from_row_major_slice_mut(out, n, n),
                )?;
                check_finite("mass_matrix", out)
            },
        )?;
        Ok(out.into_py(py, &[n, n]))
    }

    /// The Coriolis and centrifugal torques C(theta, theta_dot) (the vector of eq 12, not a
    /// matrix), shape (n,) or (N, n).
    fn coriolis<'py>(
        &self,
        py: Python<'py>,
        theta: &Bound<'py, PyAny>,
        theta_dot: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = self.n();
        let (theta, theta_dot) = (
            States::read(theta, "theta", n)?,
            States::read(theta_dot, "theta_dot", n)?,
        );
        let out = evaluate(
            py,
            [&theta, &theta_dot],
            n,
            20 * n,
            &self.workspace,
            || self.fresh(),
            |data, [q, v], out| {
                manip_dyn::coriolis(&self.chain, data, q, v, out)?;
                check_finite("coriolis", out)
            },
        )?;
        Ok(out.into_py(py, &[n]))
    }

    /// The gravity torques G(theta), shape (n,) or (N, n).
    fn gravity<'py>(
        &self,
        py: Python<'py>,
        theta: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = self.n();
        let theta = States::read(theta, "theta", n)?;
        let out = evaluate(
            py,
            [&theta],
            n,
            20 * n,
            &self.workspace,
            || self.fresh(),
            |data, [q], out| {
                manip_dyn::gravity(&self.chain, data, q, out)?;
                check_finite("gravity", out)
            },
        )?;
        Ok(out.into_py(py, &[n]))
    }

    /// Inverse dynamics (RNEA): the joint torques tau = M theta_ddot + C + G, shape (n,) or (N, n).
    fn rnea<'py>(
        &self,
        py: Python<'py>,
        theta: &Bound<'py, PyAny>,
        theta_dot: &Bound<'py, PyAny>,
        theta_ddot: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = self.n();
        let inputs = States::read_all(
            [
                (theta, "theta"),
                (theta_dot, "theta_dot"),
                (theta_ddot, "theta_ddot"),
            ],
            n,
        )?;
        let [q, v, qdd] = &inputs;
        let out = evaluate(
            py,
            [q, v, qdd],
            n,
            30 * n,
            &self.workspace,
            || self.fresh(),
            |data, [q, v, qdd], out| {
                manip_dyn::rnea(&self.chain, data, q, v, qdd, out)?;
                check_finite("tau", out)
            },
        )?;
        Ok(out.into_py(py, &[n]))
    }

    /// Forward dynamics (ABA, O(n)): the joint accelerations theta_ddot under the torques tau,
    /// shape (n,) or (N, n). A batch runs through `manip_dyn::aba_batch`, several states at once
    /// in the processor's SIMD registers, with the results of one state at a time. Raises
    /// NumericalError if the mass matrix is not numerically positive definite.
    fn aba<'py>(
        &self,
        py: Python<'py>,
        theta: &Bound<'py, PyAny>,
        theta_dot: &Bound<'py, PyAny>,
        tau: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = self.n();
        let inputs = States::read_all(
            [(theta, "theta"), (theta_dot, "theta_dot"), (tau, "tau")],
            n,
        )?;
        let [q, v, t] = &inputs;
        let out = evaluate_chunks(
            py,
            [q, v, t],
            n,
            40 * n,
            &self.aba_workspace,
            || Ok(None),
            |workspace, [q, v, t], out| {
                let data = match workspace {
                    Some(data) => data,
                    empty => empty.insert(
                        AbaBatchData::try_new(&self.chain).map_err(|e| (0, Error::from(e)))?,
                    ),
                };
                manip_dyn::aba_batch(&self.chain, data, q, v, t, out).map_err(|error| match error {
                    BatchError::State { state, error } => (state, Error::from(error)),
                    // The driver passes whole states: a shape error cannot happen.
                    other => (0, Error::input(other.to_string())),
                })
            },
        )?;
        Ok(out.into_py(py, &[n]))
    }

    /// Total mechanical energy, kinetic plus potential (J, zero potential at y = 0): a float for
    /// one state, shape (N,) for a batch.
    fn energy<'py>(
        &self,
        py: Python<'py>,
        theta: &Bound<'py, PyAny>,
        theta_dot: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = self.n();
        let (theta, theta_dot) = (
            States::read(theta, "theta", n)?,
            States::read(theta_dot, "theta_dot", n)?,
        );
        let out: Output = evaluate(
            py,
            [&theta, &theta_dot],
            1,
            20 * n,
            &self.workspace,
            || self.fresh(),
            |data, [q, v], out| {
                out[0] = manip_dyn::kinetic_energy(&self.chain, data, q, v)?
                    + manip_dyn::potential_energy(&self.chain, data, q)?;
                check_finite("energy", out)
            },
        )?;
        Ok(out.into_py(py, &[]))
    }
}
