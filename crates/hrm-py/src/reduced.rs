//! `hrm.ReducedModel`: the arm constrained to the backbone curve's modal coordinates (eqs 7-18),
//! from `backbone-kin` and `modal-reduce`.

use crate::args::count;
use crate::arm::Arm;
use crate::array::{States, evaluate, evaluate_chunks, zeros};
use crate::errors::{Error, check_finite};
use crate::spatial::{derivatives_dict, split_derivatives};
use backbone_kin::{BaseAngle, Branch, HarmonicIk, ModalMap, reduce_angle};
use modal_reduce::{
    BatchError, ReducedBatchData, ReducedData, ReducedDerivativesBatch, reduced_derivatives_batch,
};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::Mutex;

/// The workspace of one thread: the reduced model's data (one state and batches) and the joint
/// angles of one state.
struct Workspace {
    data: ReducedData,
    batch: ReducedBatchData,
    theta: Vec<f64>,
    zeros: Vec<f64>,
    /// The batch derivatives' workspace and a chunk's results (built on first use).
    derivatives: Option<ReducedDerivativesBatch>,
    a_ddot: Vec<f64>,
    jacobians: Vec<f64>,
}

/// The arm's dynamics in the modal coordinates a of its backbone curve (eqs 7-18 of the
/// paper): theta = J a + theta_0 with a constant Jacobian J (n x m), and
/// M*(a) a_ddot + C*(a, a_dot) + G*(a) = tau* with M* = J^T M J, C* = J^T C, G* = J^T G.
///
/// ReducedModel(arm, harmonics=1, alpha0=None)
///
/// `harmonics` K gives the coordinates (a_1, ..., a_2K) of the curvature's K harmonics (K = 1 is
/// the paper's (a1, a2)). `alpha0=None` makes the base angle the last coordinate, so m = 2K + 1
/// (the paper's (a1, a2, alpha0)); a number holds it fixed (m = 2K, theta_0 = alpha0 e_1, the
/// paper's experiments; an alpha0 outside (-pi, pi] is reduced into it, exactly). Raises
/// InvalidInput if J is column-rank-deficient (fewer than m links). The construction, O(n m^2),
/// runs with the GIL released.
///
/// Every method takes one state (shape (m,)) or a batch (shape (N, m)) and answers with the same
/// leading dimension.
#[pyclass(module = "hrm", frozen)]
pub struct ReducedModel {
    model: modal_reduce::ReducedModel,
    lengths: Vec<f64>,
    workspace: Mutex<Workspace>,
}

impl Workspace {
    fn new(model: &modal_reduce::ReducedModel) -> crate::errors::Result<Self> {
        Ok(Self {
            data: ReducedData::try_new(model)?,
            batch: ReducedBatchData::try_new(model)?,
            theta: zeros(model.n_links(), "the workspace of the reduced model")?,
            zeros: vec![0.0; model.n_coords()],
            derivatives: None,
            a_ddot: Vec::new(),
            jacobians: Vec::new(),
        })
    }
}

impl ReducedModel {
    fn fresh(&self) -> crate::errors::Result<Workspace> {
        Workspace::new(&self.model)
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

    fn n(&self) -> usize {
        self.model.n_links()
    }

    /// `M*`, `C*` and `G*` at `(a, a_dot)` into the workspace (eq 14, the O(n m^2) path).
    fn terms(
        &self,
        workspace: &mut Workspace,
        a: &[f64],
        a_dot: Option<&[f64]>,
    ) -> crate::errors::Result<()> {
        let a_dot = a_dot.unwrap_or(&workspace.zeros);
        modal_reduce::reduced_terms(&self.model, &mut workspace.data, a, a_dot)?;
        Ok(())
    }
}

#[pymethods]
impl ReducedModel {
    #[new]
    #[pyo3(signature = (arm, harmonics=None, alpha0=None), text_signature = "(arm, harmonics=1, alpha0=None)")]
    fn new(
        py: Python<'_>,
        arm: &Arm,
        harmonics: Option<&Bound<'_, PyAny>>,
        alpha0: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let harmonics = harmonics.map_or(Ok(1), |k| count(k, "harmonics", 1))?;
        if harmonics == 0 {
            // The modal map's own message ("a modal family needs at least one harmonic") names
            // no argument.
            return Err(Error::input("harmonics must be at least 1, got 0").into());
        }
        let alpha0 = alpha0.map(|a| crate::args::real(a, "alpha0")).transpose()?;
        let chain = arm.chain().clone();
        let base = alpha0.map_or(BaseAngle::Free, |a| BaseAngle::Fixed(reduce_angle(a)));
        // O(n m^2) and more: other Python threads run meanwhile.
        py.detach(|| {
            let lengths: Vec<f64> = chain.link_lengths().collect();
            let map = ModalMap::new(&lengths, harmonics, base).map_err(Error::from)?;
            let model = modal_reduce::ReducedModel::new(chain, map).map_err(Error::from)?;
            Ok(Self {
                workspace: Mutex::new(Workspace::new(&model)?),
                model,
                lengths,
            })
        })
    }

    /// `pickle` and `copy.deepcopy` support: the model rebuilt from its arm, harmonics and
    /// alpha0 (its defining parameters).
    #[allow(
        clippy::type_complexity,
        reason = "pickle's (callable, arguments) pair"
    )]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, (Py<Arm>, usize, Option<f64>))> {
        let model = slf.get();
        let arm = Py::new(slf.py(), Arm::from_chain(model.model.chain().clone())?)?;
        Ok((
            slf.get_type().into_any(),
            (arm, model.harmonics(), model.alpha0()),
        ))
    }

    /// Number of modal coordinates m (2 K, plus 1 when alpha0 is a coordinate).
    #[getter]
    fn n_coords(&self) -> usize {
        self.m()
    }

    /// Number of links (and joints) n.
    #[getter]
    fn n_links(&self) -> usize {
        self.n()
    }

    /// Number of harmonics K.
    #[getter]
    fn harmonics(&self) -> usize {
        self.model.map().harmonics()
    }

    /// The fixed base angle alpha0 (rad), or None when it is the last coordinate.
    #[getter]
    fn alpha0(&self) -> Option<f64> {
        match self.model.map().base_angle() {
            BaseAngle::Free => None,
            BaseAngle::Fixed(alpha0) => Some(alpha0),
        }
    }

    /// The constant modal Jacobian J = d theta / d a (eqs 8-11), shape (n, m).
    #[getter]
    fn jacobian<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let map = self.model.map();
        Array2::from_shape_vec((self.n(), self.m()), map.jacobian().to_vec())
            .expect("J is n x m")
            .into_pyarray(py)
    }

    /// The constant offset theta_0 of theta = J a + theta_0 (alpha0 e_1 when alpha0 is fixed,
    /// zero otherwise), shape (n,).
    #[getter]
    fn offset<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.model.map().offset().to_vec().into_pyarray(py)
    }

    fn __repr__(&self) -> String {
        let alpha0 = match self.alpha0() {
            None => "None".to_string(),
            Some(value) => value.to_string(),
        };
        format!(
            "ReducedModel(links={}, harmonics={}, alpha0={alpha0}, n_coords={})",
            self.n(),
            self.harmonics(),
            self.m()
        )
    }

    /// Joint angles theta = J a + theta_0 (eq 8), shape (n,) or (N, n).
    fn joint_angles<'py>(
        &self,
        py: Python<'py>,
        a: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let a = States::read(a, "a", self.m())?;
        let out = evaluate(
            py,
            [&a],
            self.n(),
            self.n() * self.m(),
            &self.workspace,
            || self.fresh(),
            |_, [a], out| {
                self.model.map().joint_angles(a, out).map_err(Error::from)?;
                check_finite("theta", out)
            },
        )?;
        Ok(out.into_py(py, &[self.n()]))
    }

    /// The tip of the discrete chain (the arm's end point, m) at the joint angles J a + theta_0,
    /// shape (2,) or (N, 2). It lies within the discretisation error of the backbone curve's end
    /// point, which `ik` inverts.
    fn fk<'py>(&self, py: Python<'py>, a: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let a = States::read(a, "a", self.m())?;
        let out = evaluate(
            py,
            [&a],
            2,
            self.n() * self.m(),
            &self.workspace,
            || self.fresh(),
            |ws, [a], out| {
                self.model
                    .map()
                    .joint_angles(a, &mut ws.theta)
                    .map_err(Error::from)?;
                check_finite("theta", &ws.theta)?;
                // Finite joint angles whose running sums overflow: named by `a`.
                let tip = backbone_kin::tip_position(&self.lengths, &ws.theta)
                    .map_err(|e| Error::input(format!("a: {e}")))?;
                out.copy_from_slice(&tip);
                check_finite("tip", out)
            },
        )?;
        Ok(out.into_py(py, &[2]))
    }

    /// Inverse kinematics of the backbone curve: modal coordinates whose curve ends at `target`
    /// (m), shape (m,) or (N, m) for targets of shape (2,) or (N, 2).
    ///
    /// For K = 1 the closed form of eqs 5-6 (through the restricted inverse of J0) on `branch`
    /// ("positive": a1 >= 0, the paper's; or "negative"); for K > 1 Levenberg-Marquardt from that
    /// solution, the higher harmonics starting at zero, and where the K = 1 family does not
    /// reach the target or the iteration does not converge from there, from the other branch's
    /// closed form and a fixed list of moderate curves (`backbone_kin::HarmonicIk::solve_unguided`). The base angle is the model's fixed
    /// alpha0; for a model whose alpha0 is a coordinate, pass `alpha0` (it becomes the last
    /// coordinate of the result, reduced to (-pi, pi] when it is outside, as the model's fixed
    /// alpha0 is). Raises Unreachable for a target the curve cannot reach and
    /// NumericalError if the iteration does not converge.
    #[pyo3(
        signature = (target, alpha0=None, branch=None),
        text_signature = "($self, target, alpha0=None, branch=\"positive\")"
    )]
    fn ik<'py>(
        &self,
        py: Python<'py>,
        target: &Bound<'py, PyAny>,
        alpha0: Option<&Bound<'py, PyAny>>,
        branch: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let alpha0 = alpha0.map(|a| crate::args::real(a, "alpha0")).transpose()?;
        let branch = branch.map_or(Ok("positive".to_string()), |b| {
            crate::args::text(b, "branch")
        })?;
        let branch = match branch.as_str() {
            "positive" => Branch::Positive,
            "negative" => Branch::Negative,
            other => {
                return Err(Error::input(format!(
                    "branch must be \"positive\" or \"negative\", got {other:?}"
                ))
                .into());
            }
        };
        let (alpha0, free) = match (self.model.map().base_angle(), alpha0) {
            (BaseAngle::Fixed(fixed), None) => (fixed, false),
            (BaseAngle::Free, Some(given)) => (reduce_angle(given), true),
            (BaseAngle::Fixed(fixed), Some(_)) => {
                return Err(Error::input(format!(
                    "this model holds alpha0 fixed at {fixed}: ik takes alpha0 only for a model \
                     whose alpha0 is a coordinate"
                ))
                .into());
            }
            (BaseAngle::Free, None) => {
                return Err(Error::input(
                    "this model's alpha0 is a coordinate: give ik the base angle, ik(target, alpha0=...)",
                )
                .into());
            }
        };
        let harmonics = self.model.map().harmonics();
        let length = self.model.chain().total_length();
        let solver = match harmonics {
            1 => None,
            k => Some(HarmonicIk::new(length, k, alpha0).map_err(Error::from)?),
        };
        let shared = Mutex::new(solver.clone());
        let target = States::read(target, "target", 2)?;
        let out = evaluate(
            py,
            [&target],
            self.m(),
            1000 * self.m() * self.m(),
            &shared,
            || Ok(solver.clone()),
            |solver, [target], out| {
                let target = [target[0], target[1]];
                out.fill(0.0);
                match solver {
                    None => {
                        let a = backbone_kin::inverse_kinematics(length, target, alpha0, branch)?;
                        out[..2].copy_from_slice(&a);
                    }
                    Some(solver) => {
                        solver.solve_unguided(target, branch, &mut out[..2 * harmonics])?;
                    }
                }
                if free {
                    out[2 * harmonics] = alpha0;
                }
                check_finite("a", out)
            },
        )?;
        Ok(out.into_py(py, &[self.m()]))
    }

    /// The reduced mass matrix M* = J^T M J (eq 14), shape (m, m) or (N, m, m).
    fn mass_matrix<'py>(
        &self,
        py: Python<'py>,
        a: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let m = self.m();
        let a = States::read(a, "a", m)?;
        let out = evaluate(
            py,
            [&a],
            m * m,
            self.work(),
            &self.workspace,
            || self.fresh(),
            |ws, [a], out| {
                self.terms(ws, a, None)?;
                let mass = ws.data.mass_matrix();
                for (k, entry) in out.iter_mut().enumerate() {
                    *entry = mass[(k / m, k % m)];
                }
                check_finite("mass_matrix", out)
            },
        )?;
        Ok(out.into_py(py, &[m, m]))
    }

    /// The reduced Coriolis and centrifugal vector C* = J^T C(theta, J a_dot) (eq 14), shape (m,)
    /// or (N, m).
    fn coriolis<'py>(
        &self,
        py: Python<'py>,
        a: &Bound<'py, PyAny>,
        a_dot: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let m = self.m();
        let (a, a_dot) = (States::read(a, "a", m)?, States::read(a_dot, "a_dot", m)?);
        let out = evaluate(
            py,
            [&a, &a_dot],
            m,
            self.work(),
            &self.workspace,
            || self.fresh(),
            |ws, [a, a_dot], out| {
                self.terms(ws, a, Some(a_dot))?;
                out.copy_from_slice(ws.data.coriolis());
                check_finite("coriolis", out)
            },
        )?;
        Ok(out.into_py(py, &[m]))
    }

    /// The reduced gravity vector G* = J^T G(theta) (eq 14), shape (m,) or (N, m).
    fn gravity<'py>(&self, py: Python<'py>, a: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let m = self.m();
        let a = States::read(a, "a", m)?;
        let out = evaluate(
            py,
            [&a],
            m,
            self.work(),
            &self.workspace,
            || self.fresh(),
            |ws, [a], out| {
                self.terms(ws, a, None)?;
                out.copy_from_slice(ws.data.gravity());
                check_finite("gravity", out)
            },
        )?;
        Ok(out.into_py(py, &[m]))
    }

    /// Reduced forward dynamics (eq 15): a_ddot = M*^-1 (tau* - C* - G*), shape (m,) or (N, m).
    /// A batch runs SIMD across states (AVX-512 or AVX2 when the processor has them). Raises
    /// NumericalError if M* is not numerically positive definite.
    fn forward_dynamics<'py>(
        &self,
        py: Python<'py>,
        a: &Bound<'py, PyAny>,
        a_dot: &Bound<'py, PyAny>,
        tau_star: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let m = self.m();
        let inputs = States::read_all([(a, "a"), (a_dot, "a_dot"), (tau_star, "tau_star")], m)?;
        let [a, a_dot, tau_star] = &inputs;
        let out = evaluate_chunks(
            py,
            [a, a_dot, tau_star],
            m,
            self.work(),
            &self.workspace,
            || self.fresh(),
            |ws, [a, a_dot, tau], out| {
                modal_reduce::forward_dynamics_batch(&self.model, &mut ws.batch, a, a_dot, tau, out)
                    .map_err(|error| match error {
                        BatchError::State { state, error } => (state, Error::from(error)),
                        // The driver passes whole states: a shape error cannot happen.
                        other => (0, Error::input(other.to_string())),
                    })
            },
        )?;
        Ok(out.into_py(py, &[m]))
    }

    /// The reduced forward dynamics and its analytic derivatives at (a, a_dot, tau_star): a dict
    /// of a_ddot (m,), d_a = d a_ddot / d a, d_a_dot = d a_ddot / d a_dot and
    /// d_tau_star = M*^-1 (m, m each, entry (i, j) = d a_ddot_i / d in_j), each with a leading N
    /// for a batch; O(n m^2) from prefix sums along the chain, a batch SIMD across states (each
    /// state the same numbers as alone). Raises NumericalError if M* is not numerically
    /// positive definite.
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
        let [a, a_dot, tau_star] = &inputs;
        let per_state = m + 3 * m * m;
        let out = evaluate_chunks(
            py,
            [a, a_dot, tau_star],
            per_state,
            self.work() * m,
            &self.workspace,
            || self.fresh(),
            |ws, [a, a_dot, tau], out| {
                let states = a.len() / m;
                let derivatives = match &mut ws.derivatives {
                    Some(derivatives) => derivatives,
                    empty => empty.insert(
                        ReducedDerivativesBatch::try_new(&self.model)
                            .map_err(|error| (0, Error::from(error)))?,
                    ),
                };
                ws.a_ddot.resize(states * m, 0.0);
                ws.jacobians.resize(states * 3 * m * m, 0.0);
                reduced_derivatives_batch(
                    &self.model,
                    derivatives,
                    a,
                    a_dot,
                    tau,
                    &mut ws.a_ddot,
                    &mut ws.jacobians,
                )
                .map_err(|error| match error {
                    BatchError::State { state, error } => (state, Error::from(error)),
                    // The driver passes whole states: a shape error cannot happen.
                    other => (0, Error::input(other.to_string())),
                })?;
                let values = ws.a_ddot.chunks_exact(m);
                let jacobians = ws.jacobians.chunks_exact(3 * m * m);
                for ((a_ddot, jacobians), out) in
                    values.zip(jacobians).zip(out.chunks_exact_mut(per_state))
                {
                    split_derivatives(m, a_ddot, jacobians, out);
                }
                Ok(())
            },
        )?;
        derivatives_dict(py, out, batch, m)
    }

    /// The joint torques tau = M J a_ddot + C + G that the real arm's actuators must deliver for
    /// the modal motion (a, a_dot, a_ddot) (eq 13), shape (n,) or (N, n); J^T tau = tau*.
    fn joint_torques<'py>(
        &self,
        py: Python<'py>,
        a: &Bound<'py, PyAny>,
        a_dot: &Bound<'py, PyAny>,
        a_ddot: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let m = self.m();
        let inputs = States::read_all([(a, "a"), (a_dot, "a_dot"), (a_ddot, "a_ddot")], m)?;
        let [a, a_dot, a_ddot] = &inputs;
        let out = evaluate(
            py,
            [a, a_dot, a_ddot],
            self.n(),
            self.work(),
            &self.workspace,
            || self.fresh(),
            |ws, [a, a_dot, a_ddot], out| {
                modal_reduce::joint_torques(&self.model, &mut ws.data, a, a_dot, a_ddot, out)?;
                check_finite("joint_torques", out)
            },
        )?;
        Ok(out.into_py(py, &[self.n()]))
    }
}
