//! `hrm.SpatialArm`: a chain of universal joints constrained to a spatial backbone curve's modal
//! coordinates (the paper's eqs 7-18 in two bending planes), from `backbone-kin` and
//! `modal-reduce::spatial`.

use crate::args;
use crate::args::count;
use crate::array::{Output, States, evaluate};
use crate::errors::{Error, check_finite};
use backbone_kin::{MAX_CURVE_STEPS, SpatialIk, spatial_tip_position};
use modal_reduce::spatial::{
    SpatialReducedData, SpatialReducedDerivatives, SpatialReducedModel, spatial_forward_dynamics,
    spatial_joint_torques, spatial_reduced_derivatives,
};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PySlice, PyTuple};
use std::sync::Mutex;

/// Most harmonics per plane (`m = 4K` coordinates): the bound of `hrm eval` on spatial arms, which
/// keeps `ik` (up to 100 evaluations of the tip and its `3 x m` Jacobian) and the `O(n m^2)`
/// reduced terms within a second for arms of thousands of links.
const MAX_HARMONICS: usize = 16;

/// Operations of one Runge-Kutta step of the curve's frame, for `fk`'s work estimate.
const CURVE_STEP_WORK: usize = 256;

/// The workspace of one thread: the reduced model's data and derivatives, the joint angles of
/// one state, the modal accelerations of `reduced` and the inverse-kinematics solver.
struct Workspace {
    data: SpatialReducedData,
    derivatives: SpatialReducedDerivatives,
    theta: Vec<f64>,
    a_ddot: Vec<f64>,
    ik: SpatialIk,
}

impl Workspace {
    fn new(model: &SpatialReducedModel) -> crate::errors::Result<Self> {
        Ok(Self {
            data: SpatialReducedData::try_new(model).map_err(Error::from)?,
            derivatives: SpatialReducedDerivatives::try_new(model).map_err(Error::from)?,
            theta: vec![0.0; model.map().n_joints()],
            a_ddot: vec![0.0; model.n_coords()],
            ik: SpatialIk::new(model.map().try_clone().map_err(Error::from)?, *model.base())
                .map_err(Error::from)?,
        })
    }
}

/// A spatial hyper-redundant arm: n links joined by universal joints (yaw about the link's z axis,
/// then pitch about its y axis), constrained to a backbone curve whose curvature in each of two
/// planes is a K-harmonic modal expansion (eqs 7-11 per plane), so theta = J a with a constant
/// Jacobian J (2n x 4K), and the reduced dynamics M*(a) a_ddot + C*(a, a_dot) + G*(a) = tau*
/// (eqs 13-15) with M* = J^T M J, C* = J^T C, G* = J^T G.
///
/// SpatialArm(links=None, link_length=None, link_mass=None, gravity=(0, 0, -9.81), lengths=None,
/// masses=None, inertias=None, base_xyz=(0, 0, 0), base_rpy=(0, 0, 0), harmonics=1)
///
/// `links` equal slender rods (10 when neither `links` nor a per-link list is given) of
/// `link_length` (m, default 0.1) and `link_mass` (kg, default 0.1), principal inertias (0,
/// m L^2 / 12, m L^2 / 12) about the mid-link centre of mass; `lengths` and `masses` give them
/// per link instead (a list and its scalar together raise InvalidInput), `inertias` (n rows of
/// principal moments [Ixx, Iyy, Izz], kg m^2, x along the link) the rods' inertias. `gravity`
/// is the world acceleration vector (m/s^2), or one number g for (0, 0, -g) as in a scenario;
/// the base sits at `base_xyz` (m) rotated by roll, pitch and yaw `base_rpy` (rad,
/// R = Rz Ry Rx), the straight arm along the base's x axis. The coordinates are
/// a = (a_z, a_y): 2K for the yaw plane then 2K for the pitch plane; theta is
/// (z_1, y_1, z_2, y_2, ...).
///
/// Every method takes one state (shape (m,)) or a batch (shape (N, m)) and answers with the same
/// leading dimension; a batch runs with the GIL released. Raises InvalidInput for a bad
/// parameter, naming it. Pickles by its defining parameters.
#[pyclass(module = "hrm", frozen)]
pub struct SpatialArm {
    model: SpatialReducedModel,
    /// The principal inertias, resolved (the rods' when none were given), for pickling.
    inertias: Vec<[f64; 3]>,
    workspace: Mutex<Workspace>,
}

impl SpatialArm {
    fn fresh(&self) -> crate::errors::Result<Workspace> {
        Workspace::new(&self.model)
    }

    /// The arm's chain as a description, refused past
    /// [`robot_desc::MAX_SPATIAL_EXPORT_LINKS`].
    fn robot(&self) -> crate::errors::Result<robot_desc::Robot> {
        robot_desc::from_spatial_arm(&self.model, "hrm_spatial_arm")
            .map_err(|e| Error::input(format!("links: {e}")))
    }

    fn m(&self) -> usize {
        self.model.n_coords()
    }

    /// The work of one state of the O(n m^2) terms, for the driver's GIL threshold.
    fn work(&self) -> usize {
        self.model
            .n_links()
            .saturating_mul(self.m())
            .saturating_mul(self.m())
    }

    /// The work of one state of `fk`: the chain's terms and, at worst, the curve's
    /// [`MAX_CURVE_STEPS`] Runge-Kutta steps of a few hundred operations each (about a second),
    /// so that the driver runs a batch a state a chunk with Ctrl-C checked between them.
    fn fk_work(&self) -> usize {
        self.work()
            .saturating_add(MAX_CURVE_STEPS.saturating_mul(CURVE_STEP_WORK))
    }

    fn joints_count(&self) -> usize {
        self.model.map().n_joints()
    }

    fn total_length(&self) -> f64 {
        self.model.map().link_lengths().iter().sum()
    }
}

/// The model of the constructor's arguments (`SpatialArm`'s docs): a scenario's spatial
/// `[arm]` ([`sim_study::ArmSpec::spatial_model`], whose refusals name the field as a scenario
/// would, `harmonics` for its `modal.harmonics`), and the principal inertias it resolved (the
/// rods' when none were given).
#[allow(
    clippy::too_many_arguments,
    reason = "the constructor's keyword arguments"
)]
fn build(
    links: Option<usize>,
    link_length: Option<f64>,
    link_mass: Option<f64>,
    gravity: sim_study::Gravity,
    lengths: Option<Vec<f64>>,
    masses: Option<Vec<f64>>,
    inertias: Option<Vec<[f64; 3]>>,
    base: sim_study::BaseSpec,
    harmonics: usize,
) -> crate::errors::Result<(SpatialReducedModel, Vec<[f64; 3]>)> {
    if !(1..=MAX_HARMONICS).contains(&harmonics) {
        return Err(Error::input(format!(
            "harmonics must be from 1 to {MAX_HARMONICS}, got {harmonics}"
        )));
    }
    let arm = sim_study::ArmSpec {
        kind: sim_study::ArmKind::Spatial,
        links,
        link_length,
        link_mass,
        gravity: Some(gravity),
        lengths,
        masses,
        inertias: inertias.map(sim_study::Inertias::Principal),
        base: Some(base),
        ..sim_study::ArmSpec::default()
    };
    let model = arm
        .spatial_model(harmonics)
        .map_err(|e| Error::from(e.renamed("modal.harmonics", "harmonics")))?;
    let inertias = model.links().iter().map(|link| link.principal).collect();
    Ok((model, inertias))
}

/// `array[..., first:last]` reshaped to `shape` after the batch dimension (when `batch`), as a
/// contiguous copy: one field of a result computed as one flat row per state.
pub(crate) fn field<'py>(
    array: &Bound<'py, PyAny>,
    batch: bool,
    first: usize,
    last: usize,
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    let py = array.py();
    let numpy = py.import("numpy")?;
    let slice = PySlice::new(py, first as isize, last as isize, 1);
    let part = array.get_item((py.Ellipsis(), slice))?;
    let mut full: Vec<usize> = Vec::with_capacity(shape.len() + 1);
    if batch {
        full.push(array.getattr("shape")?.get_item(0)?.extract()?);
    }
    full.extend_from_slice(shape);
    let reshaped = part.call_method1("reshape", (PyTuple::new(py, full)?,))?;
    numpy.call_method1("ascontiguousarray", (reshaped,))
}

/// One state's reduced derivatives in the layout of [`derivatives_dict`]: `a_ddot`, then the
/// blocks `d_a`, `d_a_dot`, `d_tau_star` (`m x m` each, row-major), from the rows
/// `[d_a row i | d_a_dot row i | d_tau_star row i]` of `jacobians`.
pub(crate) fn split_derivatives(m: usize, a_ddot: &[f64], jacobians: &[f64], out: &mut [f64]) {
    let (value, blocks) = out.split_at_mut(m);
    value.copy_from_slice(&a_ddot[..m]);
    for (b, block) in blocks.chunks_exact_mut(m * m).enumerate() {
        for (row, target) in jacobians.chunks_exact(3 * m).zip(block.chunks_exact_mut(m)) {
            target.copy_from_slice(&row[b * m..(b + 1) * m]);
        }
    }
}

/// The results of `reduced_derivatives` (`m + 3 m^2` a state, [`split_derivatives`]) as a dict
/// of `a_ddot` (m,) and `d_a`, `d_a_dot`, `d_tau_star` (m, m), each with a leading N for a
/// batch.
pub(crate) fn derivatives_dict<'py>(
    py: Python<'py>,
    out: Output,
    batch: bool,
    m: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let all = flat(py, out, m + 3 * m * m);
    let dict = PyDict::new(py);
    let mut first = 0;
    for (name, shape) in [
        ("a_ddot", &[m][..]),
        ("d_a", &[m, m][..]),
        ("d_a_dot", &[m, m][..]),
        ("d_tau_star", &[m, m][..]),
    ] {
        let last = first + shape.iter().product::<usize>();
        dict.set_item(name, field(&all, batch, first, last, shape)?)?;
        first = last;
    }
    Ok(dict)
}

/// One flat result per state as a numpy array of shape (per_state,) or (N, per_state).
fn flat<'py>(py: Python<'py>, out: Output, per_state: usize) -> Bound<'py, PyAny> {
    out.into_py(py, &[per_state])
}

#[pymethods]
impl SpatialArm {
    #[new]
    #[pyo3(signature = (links=None, link_length=None, link_mass=None, gravity=None, lengths=None, masses=None, inertias=None, base_xyz=None, base_rpy=None, harmonics=None),
           text_signature = "(links=None, link_length=None, link_mass=None, gravity=(0, 0, -9.81), lengths=None, masses=None, inertias=None, base_xyz=(0, 0, 0), base_rpy=(0, 0, 0), harmonics=1)")]
    #[allow(
        clippy::too_many_arguments,
        reason = "the constructor's keyword arguments"
    )]
    fn new(
        links: Option<&Bound<'_, PyAny>>,
        link_length: Option<&Bound<'_, PyAny>>,
        link_mass: Option<&Bound<'_, PyAny>>,
        gravity: Option<&Bound<'_, PyAny>>,
        lengths: Option<&Bound<'_, PyAny>>,
        masses: Option<&Bound<'_, PyAny>>,
        inertias: Option<&Bound<'_, PyAny>>,
        base_xyz: Option<&Bound<'_, PyAny>>,
        base_rpy: Option<&Bound<'_, PyAny>>,
        harmonics: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let links = links.map(|n| count(n, "arm.links", 1)).transpose()?;
        let given =
            |value: Option<&Bound<'_, PyAny>>, name| value.map(|v| args::real(v, name)).transpose();
        let (link_length, link_mass) = (
            given(link_length, "link_length")?,
            given(link_mass, "link_mass")?,
        );
        let vec3 = |value: Option<&Bound<'_, PyAny>>, name, default| {
            value.map_or(Ok(default), |v| args::vec3(v, name))
        };
        let gravity = args::spatial_gravity(gravity)?;
        let (base_xyz, base_rpy) = (
            vec3(base_xyz, "base_xyz", [0.0; 3])?,
            vec3(base_rpy, "base_rpy", [0.0; 3])?,
        );
        let per_link = |value: Option<&Bound<'_, PyAny>>, name| {
            value
                .map(|v| args::reals(v, name, backbone_kin::MAX_LINKS))
                .transpose()
        };
        let (lengths, masses) = (per_link(lengths, "lengths")?, per_link(masses, "masses")?);
        let inertias = inertias.map(|v| args::rows3(v, "inertias")).transpose()?;
        let harmonics = harmonics.map_or(Ok(1), |k| count(k, "harmonics", 1))?;
        let base = sim_study::BaseSpec {
            xyz: base_xyz,
            rpy: base_rpy,
        };
        let (model, inertias) = build(
            links,
            link_length,
            link_mass,
            gravity,
            lengths,
            masses,
            inertias,
            base,
            harmonics,
        )?;
        Ok(Self {
            workspace: Mutex::new(Workspace::new(&model)?),
            model,
            inertias,
        })
    }

    /// Number of links n (the arm has 2n joint angles).
    #[getter]
    fn n_links(&self) -> usize {
        self.model.n_links()
    }

    /// Number of modal coordinates m = 4K.
    #[getter]
    fn n_coords(&self) -> usize {
        self.m()
    }

    /// Number of harmonics K per plane.
    #[getter]
    fn harmonics(&self) -> usize {
        self.model.map().harmonics()
    }

    /// Link lengths (m), base first, shape (n,).
    #[getter]
    fn lengths<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.model.map().link_lengths().to_vec().into_pyarray(py)
    }

    /// Link masses (kg), shape (n,).
    #[getter]
    fn masses<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let masses: Vec<f64> = self.model.links().iter().map(|l| l.mass).collect();
        masses.into_pyarray(py)
    }

    /// Principal moments of inertia [Ixx, Iyy, Izz] about each centre of mass (kg m^2), shape
    /// (n, 3).
    #[getter]
    fn inertias<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        Array2::from_shape_vec((self.n_links(), 3), self.inertias.concat())
            .expect("n rows of 3")
            .into_pyarray(py)
    }

    /// The gravity vector (m/s^2, world frame), a tuple of 3 floats.
    #[getter]
    fn gravity(&self) -> (f64, f64, f64) {
        let [x, y, z] = self.model.gravity();
        (x, y, z)
    }

    /// The base position (m), a tuple of 3 floats.
    #[getter]
    fn base_xyz(&self) -> (f64, f64, f64) {
        let [x, y, z] = self.model.base().xyz;
        (x, y, z)
    }

    /// The base roll, pitch and yaw (rad), a tuple of 3 floats.
    #[getter]
    fn base_rpy(&self) -> (f64, f64, f64) {
        let [x, y, z] = self.model.base().rpy;
        (x, y, z)
    }

    fn __repr__(&self) -> String {
        format!(
            "SpatialArm(links={}, harmonics={}, total_length={}, gravity={:?}, base_xyz={:?}, \
             base_rpy={:?})",
            self.n_links(),
            self.harmonics(),
            self.total_length(),
            self.model.gravity(),
            self.model.base().xyz,
            self.model.base().rpy
        )
    }

    /// Pickling: the class and its defining parameters (the resolved per-link lists).
    #[allow(
        clippy::type_complexity,
        reason = "pickle's (callable, arguments) pair"
    )]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let arm = slf.get();
        let masses: Vec<f64> = arm.model.links().iter().map(|l| l.mass).collect();
        let arguments = (
            arm.n_links(),
            None::<f64>,
            None::<f64>,
            arm.model.gravity(),
            arm.model.map().link_lengths().to_vec(),
            masses,
            arm.inertias.clone(),
            arm.model.base().xyz,
            arm.model.base().rpy,
            arm.harmonics(),
        )
            .into_pyobject(slf.py())?;
        Ok((slf.get_type().into_any(), arguments))
    }

    /// The joint angles theta = J a (eq 8 per plane), shape (2n,) or (N, 2n), and the constant
    /// modal Jacobian J = d theta / d a, shape (2n, m): a tuple (theta, jacobian).
    fn joints<'py>(
        &self,
        py: Python<'py>,
        a: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyArray2<f64>>)> {
        let (m, joints) = (self.m(), self.joints_count());
        let a = States::read(a, "a", m)?;
        let out = evaluate(
            py,
            [&a],
            joints,
            self.work(),
            &self.workspace,
            || self.fresh(),
            |_, [a], out| {
                self.model.map().joint_angles(a, out).map_err(Error::from)?;
                check_finite("theta", out)
            },
        )?;
        let jacobian = Array2::from_shape_vec((joints, m), self.model.map().jacobian().to_vec())
            .expect("J is 2n x m")
            .into_pyarray(py);
        Ok((out.into_py(py, &[joints]), jacobian))
    }

    /// The tip of the backbone curve (integrated to 1e-12 of the arm's length) and of the
    /// universal-joint chain at theta = J a, each (m) of shape (3,) or (N, 3): a tuple
    /// (tip, tip_chain).
    fn fk<'py>(
        &self,
        py: Python<'py>,
        a: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let a = States::read(a, "a", self.m())?;
        let batch = a.is_batch();
        let out = evaluate(
            py,
            [&a],
            6,
            self.fk_work(),
            &self.workspace,
            || self.fresh(),
            |ws, [a], out| {
                let map = self.model.map();
                map.joint_angles(a, &mut ws.theta).map_err(Error::from)?;
                check_finite("theta", &ws.theta)?;
                let tip_chain =
                    spatial_tip_position(map.link_lengths(), self.model.base(), &ws.theta)
                        .map_err(Error::from)?;
                let tip = map.curve_tip(a, *self.model.base()).map_err(Error::from)?;
                out[..3].copy_from_slice(&tip);
                out[3..].copy_from_slice(&tip_chain);
                check_finite("tip", out)
            },
        )?;
        let all = flat(py, out, 6);
        Ok((
            field(&all, batch, 0, 3, &[3])?,
            field(&all, batch, 3, 6, &[3])?,
        ))
    }

    /// Inverse kinematics of the chain: modal coordinates a (shape (m,) or (N, m)) whose chain's
    /// tip is on `target` (m, shape (3,) or (N, 3)), by damped least squares from `guess`
    /// (shape (m,) or (N, m), entries at most 10 in magnitude; default a quarter bend in each
    /// plane's first coefficient, away from the straight arm's singularity). Raises Unreachable
    /// for a target farther from the base than the arm is long and NumericalError if the
    /// iteration does not converge or converges to coordinates whose curve `fk` cannot integrate
    /// (it oscillates beyond the quadrature's nodes: a guess far out).
    #[pyo3(signature = (target, guess=None))]
    fn ik<'py>(
        &self,
        py: Python<'py>,
        target: &Bound<'py, PyAny>,
        guess: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let m = self.m();
        let target = States::read(target, "target", 3)?;
        let solve = |ws: &mut Workspace, target: &[f64], guess: Option<&[f64]>, out: &mut [f64]| {
            ws.ik
                .solve_evaluable([target[0], target[1], target[2]], guess, out)
                .map_err(Error::from)?;
            check_finite("a", out)
        };
        let out = match guess {
            None => evaluate(
                py,
                [&target],
                m,
                self.work(),
                &self.workspace,
                || self.fresh(),
                |ws, [target], out| solve(ws, target, None, out),
            )?,
            Some(guess) => {
                let guess = States::read(guess, "guess", m)?;
                evaluate(
                    py,
                    [&target, &guess],
                    m,
                    self.work(),
                    &self.workspace,
                    || self.fresh(),
                    |ws, [target, guess], out| solve(ws, target, Some(guess), out),
                )?
            }
        };
        Ok(out.into_py(py, &[m]))
    }

    /// The reduced dynamics at (a, a_dot) under the modal forces tau_star (eqs 13-15): a dict of
    /// mass_matrix M* (m, m), coriolis C* (m,), gravity G* (m,), a_ddot = M*^-1 (tau* - C* - G*)
    /// (m,) and joint_torques (2n,), the torques of the universal joints that realise the modal
    /// motion (J^T joint_torques = tau*), each with a leading N for a batch. Raises
    /// NumericalError if M* is not numerically positive definite.
    fn reduced<'py>(
        &self,
        py: Python<'py>,
        a: &Bound<'py, PyAny>,
        a_dot: &Bound<'py, PyAny>,
        tau_star: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (m, joints) = (self.m(), self.joints_count());
        let inputs = States::read_all([(a, "a"), (a_dot, "a_dot"), (tau_star, "tau_star")], m)?;
        let batch = inputs[0].is_batch();
        let [a, a_dot, tau] = &inputs;
        let per_state = m * m + 3 * m + joints;
        let out = evaluate(
            py,
            [a, a_dot, tau],
            per_state,
            self.work(),
            &self.workspace,
            || self.fresh(),
            |ws, [a, a_dot, tau], out| {
                spatial_forward_dynamics(&self.model, &mut ws.data, a, a_dot, tau, &mut ws.a_ddot)
                    .map_err(Error::from)?;
                let (mass, rest) = out.split_at_mut(m * m);
                let (coriolis, rest) = rest.split_at_mut(m);
                let (gravity, rest) = rest.split_at_mut(m);
                let (a_ddot, torques) = rest.split_at_mut(m);
                mass.copy_from_slice(ws.data.mass_matrix());
                coriolis.copy_from_slice(ws.data.coriolis());
                gravity.copy_from_slice(ws.data.gravity());
                a_ddot.copy_from_slice(&ws.a_ddot);
                spatial_joint_torques(&self.model, &mut ws.data, a, a_dot, a_ddot, torques)
                    .map_err(Error::from)?;
                check_finite("reduced terms", out)
            },
        )?;
        let all = flat(py, out, per_state);
        let dict = PyDict::new(py);
        let mut first = 0;
        for (name, shape) in [
            ("mass_matrix", &[m, m][..]),
            ("coriolis", &[m][..]),
            ("gravity", &[m][..]),
            ("a_ddot", &[m][..]),
            ("joint_torques", &[joints][..]),
        ] {
            let last = first + shape.iter().product::<usize>();
            dict.set_item(name, field(&all, batch, first, last, shape)?)?;
            first = last;
        }
        Ok(dict)
    }

    /// Reduced forward dynamics (eq 15): a_ddot = M*^-1 (tau* - C* - G*), shape (m,) or (N, m).
    /// Raises NumericalError if M* is not numerically positive definite.
    fn forward_dynamics<'py>(
        &self,
        py: Python<'py>,
        a: &Bound<'py, PyAny>,
        a_dot: &Bound<'py, PyAny>,
        tau_star: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let m = self.m();
        let inputs = States::read_all([(a, "a"), (a_dot, "a_dot"), (tau_star, "tau_star")], m)?;
        let [a, a_dot, tau] = &inputs;
        let out = evaluate(
            py,
            [a, a_dot, tau],
            m,
            self.work(),
            &self.workspace,
            || self.fresh(),
            |ws, [a, a_dot, tau], out| {
                spatial_forward_dynamics(&self.model, &mut ws.data, a, a_dot, tau, out)
                    .map_err(Error::from)?;
                check_finite("a_ddot", out)
            },
        )?;
        Ok(out.into_py(py, &[m]))
    }

    /// The reduced forward dynamics and its analytic derivatives at (a, a_dot, tau_star): a dict
    /// of a_ddot (m,), d_a = d a_ddot / d a, d_a_dot = d a_ddot / d a_dot and
    /// d_tau_star = M*^-1 (m, m each, entry (i, j) = d a_ddot_i / d in_j), each with a leading N
    /// for a batch; O(n m^2) from the tangent of the Newton-Euler recursion. Raises
    /// NumericalError if M* is not numerically positive definite.
    fn reduced_derivatives<'py>(
        &self,
        py: Python<'py>,
        a: &Bound<'py, PyAny>,
        a_dot: &Bound<'py, PyAny>,
        tau_star: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let m = self.m();
        let inputs = States::read_all([(a, "a"), (a_dot, "a_dot"), (tau_star, "tau_star")], m)?;
        let batch = inputs[0].is_batch();
        let [a, a_dot, tau] = &inputs;
        let per_state = m + 3 * m * m;
        let out = evaluate(
            py,
            [a, a_dot, tau],
            per_state,
            self.work() * m,
            &self.workspace,
            || self.fresh(),
            |ws, [a, a_dot, tau], out| {
                spatial_reduced_derivatives(
                    &self.model,
                    &mut ws.data,
                    &mut ws.derivatives,
                    a,
                    a_dot,
                    tau,
                )
                .map_err(Error::from)?;
                let derivatives = &ws.derivatives;
                split_derivatives(m, derivatives.a_ddot(), derivatives.jacobians(), out);
                check_finite("reduced dynamics derivatives", out)
            },
        )?;
        derivatives_dict(py, out, batch, m)
    }

    /// The arm's chain as URDF text (hrm eval's `export`): per link `joint_i_z` about the
    /// parent's z axis (moving the massless `link_i_z`) and `joint_i_y` about its y axis (moving
    /// `link_i`), the movable joints in the order of theta, the first pair at the base pose. URDF
    /// carries no gravity: set the arm's `gravity` in the engine. At most 10,000 links.
    fn to_urdf(&self) -> PyResult<String> {
        Ok(robot_desc::write_urdf(&self.robot()?).map_err(|e| Error::input(e.to_string()))?)
    }

    /// The arm's chain as MJCF text for MuJoCo, its gravity in `<option>` (the two hinges of a
    /// universal joint in one body). MuJoCo refuses principal moments below mjMINVAL (1e-15),
    /// zero included, so slender rods (the default inertias, Ixx = 0) raise InvalidInput; give
    /// `inertias`. At most 495 links (MuJoCo's XML nesting).
    fn to_mjcf(&self) -> PyResult<String> {
        robot_desc::write_mjcf(&self.robot()?, self.model.gravity())
            .map_err(|e| Error::input(e.to_string()).into())
    }
}
