//! `hrm.Chain`: a spatial serial chain read from URDF (`robot-desc`) and its dynamics, analytic
//! derivatives and frames (`manip_dyn::spatial`); and the description of any arm as URDF or MJCF
//! text.

use crate::array::{States, evaluate, evaluate_chunks};
use crate::errors::{Error, check_finite};
use crate::spatial::field;
use manip_dyn::faer::MatMut;
use manip_dyn::spatial::{
    self, SpatialBatchData, SpatialData, SpatialDerivativeData, SpatialModel,
};
use manip_dyn::{BatchError, DynError, MAX_DENSE_LINKS};
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyString, PyTuple};
use robot_desc::{JointKind, MAX_URDF_BYTES, Robot, read_urdf};
use std::path::PathBuf;
use std::sync::Mutex;

/// The URDF text of `source`: a string holding `<` is the text itself (no path holds one, all
/// URDF text does); any other string or a path-like object names the file to read, which is
/// read only if it is a regular file of at most [`MAX_URDF_BYTES`] bytes.
fn urdf_text(source: &Bound<'_, PyAny>) -> PyResult<String> {
    let path = if let Ok(text) = source.cast::<PyString>() {
        let text: String = text.extract()?;
        if text.contains('<') {
            return Ok(text);
        }
        PathBuf::from(text)
    } else {
        source.extract::<PathBuf>().map_err(|_| {
            crate::args::wrong_type("urdf", "URDF text or a path to a URDF file", source)
        })?
    };
    sim_study::read_text_file(&path, MAX_URDF_BYTES as u64)
        .map_err(|e| Error::input(format!("urdf file {}: {e}", path.display())).into())
}

/// The per-thread workspace: the recursive algorithms' data, and the derivatives' (`O(n^2)`)
/// and the batch ABA's workspaces, built by their first use.
struct Workspace {
    data: SpatialData,
    derivatives: Option<SpatialDerivativeData>,
    batch: Option<SpatialBatchData>,
}

impl Workspace {
    fn new(model: &SpatialModel) -> crate::errors::Result<Self> {
        Ok(Self {
            data: SpatialData::try_new(model)?,
            derivatives: None,
            batch: None,
        })
    }
}

/// A spatial serial chain with a fixed base, read from URDF: revolute, continuous and prismatic
/// joints about or along any axis (links behind fixed joints merged into their parent), links
/// with full rigid-body inertias, a gravity vector (URDF carries none; ROS's (0, 0, -9.81) by
/// default). tau = M(q) q_ddot + C(q, q_dot) q_dot + G(q), one entry per movable joint in chain
/// order (torques for revolute joints, forces for prismatic ones).
///
/// Build with `Chain.from_urdf(urdf, gravity=(0, 0, -9.81))` or `Arm.from_urdf(...)`; `urdf`
/// is URDF text (a string holding `<`), or a path-like object or other string naming a regular
/// file of at most 32 MiB.
///
/// Every method takes one state (arrays of shape (n,)) or a batch (shape (N, n)) and answers
/// with the same leading dimension; a batch runs with the GIL released, on all cores from 512
/// states on, and gives each state the bits it gets alone. Raises InvalidInput for a bad
/// argument, naming it, and NumericalError for a mass matrix that is not numerically positive
/// definite or a non-finite result. Pickles as its URDF text and gravity.
#[pyclass(module = "hrm", frozen)]
pub struct Chain {
    robot: Robot,
    model: SpatialModel,
    workspace: Mutex<Workspace>,
}

impl Chain {
    /// The chain of URDF text under `gravity`.
    fn read(text: &str, gravity: [f64; 3]) -> crate::errors::Result<Self> {
        let robot = read_urdf(text)
            .map_err(|e| Error::input(format!("urdf: {e}")))?
            .robot;
        if robot.n_joints() == 0 {
            return Err(Error::input(
                "urdf: the chain has no movable joint (revolute, continuous or prismatic)",
            ));
        }
        let model = robot_desc::to_spatial(&robot, gravity)
            .map_err(|e| Error::input(format!("urdf: {e}")))?;
        Ok(Self {
            workspace: Mutex::new(Workspace::new(&model)?),
            robot,
            model,
        })
    }

    fn n(&self) -> usize {
        self.model.n_links()
    }

    fn fresh(&self) -> crate::errors::Result<Workspace> {
        Workspace::new(&self.model)
    }

    /// Refuses the `n x n` results past [`MAX_DENSE_LINKS`].
    fn dense(&self, what: &'static str) -> crate::errors::Result<()> {
        if self.n() > MAX_DENSE_LINKS {
            return Err(Error::from(DynError::TooManyLinks {
                what,
                got: self.n(),
                max: MAX_DENSE_LINKS,
            }));
        }
        Ok(())
    }

    /// The derivative methods: `(value, d_q, d_v[, d_input])` of `run` on each state.
    #[allow(
        clippy::type_complexity,
        reason = "the derivative algorithms' common signature"
    )]
    fn derivatives<'py>(
        &self,
        py: Python<'py>,
        names: [&'static str; 3],
        inputs: [&Bound<'py, PyAny>; 3],
        with_input: bool,
        run: fn(
            &SpatialModel,
            &mut SpatialData,
            &mut SpatialDerivativeData,
            &[f64],
            &[f64],
            &[f64],
        ) -> Result<(), DynError>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        self.dense("Chain derivatives (n x n matrices)")?;
        let n = self.n();
        let inputs = States::read_all(
            [
                (inputs[0], names[0]),
                (inputs[1], names[1]),
                (inputs[2], names[2]),
            ],
            n,
        )?;
        let batch = inputs[0].is_batch();
        let [a, b, c] = &inputs;
        let matrices = if with_input { 3 } else { 2 };
        let per_state = n + matrices * n * n;
        let out = evaluate(
            py,
            [a, b, c],
            per_state,
            100 * n * n + 200 * n,
            &self.workspace,
            || self.fresh(),
            |ws, [a, b, c], out| {
                let derivatives = ws
                    .derivatives
                    .get_or_insert_with(|| SpatialDerivativeData::new(&self.model));
                run(&self.model, &mut ws.data, derivatives, a, b, c)?;
                let (value, rest) = out.split_at_mut(n);
                value.copy_from_slice(derivatives.value());
                let blocks = [derivatives.d_q(), derivatives.d_v(), derivatives.d_input()];
                for (block, target) in blocks.iter().zip(rest.chunks_exact_mut(n * n)) {
                    MatMut::from_row_major_slice_mut(target, n, n).copy_from(block);
                }
                check_finite("derivatives", out)
            },
        )?;
        let all = out.into_py(py, &[per_state]);
        let mut parts = vec![field(&all, batch, 0, n, &[n])?];
        for k in 0..matrices {
            let first = n + k * n * n;
            parts.push(field(&all, batch, first, first + n * n, &[n, n])?);
        }
        PyTuple::new(py, parts)
    }
}

#[pymethods]
impl Chain {
    /// The chain of a URDF description (text, which holds `<`, or a path-like object or other
    /// string naming a file) under the gravity vector `gravity` (m/s^2, base frame; one number `g` is
    /// `(0, 0, -g)`, as `SpatialArm` and `hrm eval` read it).
    #[staticmethod]
    #[pyo3(signature = (urdf, gravity=None), text_signature = "(urdf, gravity=(0, 0, -9.81))")]
    pub(crate) fn from_urdf(
        urdf: &Bound<'_, PyAny>,
        gravity: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let gravity = crate::args::spatial_gravity(gravity)?.spatial();
        robot_desc::check_gravity(gravity).map_err(Error::from)?;
        let text = urdf_text(urdf)?;
        Ok(Self::read(&text, gravity)?)
    }

    /// Number of movable joints (and moving links) n.
    #[getter]
    fn n_joints(&self) -> usize {
        self.n()
    }

    /// The robot's name (the URDF `<robot name>`).
    #[getter]
    fn name(&self) -> &str {
        &self.robot.name
    }

    /// The movable joints' names, in chain order.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.robot.joints.iter().map(|j| j.name.clone()).collect()
    }

    /// The moving links' names (each movable joint's child, fixed links merged into it).
    #[getter]
    fn link_names(&self) -> Vec<String> {
        self.robot
            .joints
            .iter()
            .map(|j| j.child.name.clone())
            .collect()
    }

    /// The joints' kinds, in chain order: "revolute", "continuous" or "prismatic".
    #[getter]
    fn joint_kinds(&self) -> Vec<&'static str> {
        self.robot
            .joints
            .iter()
            .map(|j| j.kind.urdf_name())
            .collect()
    }

    /// The gravitational acceleration in the base frame (m/s^2), a tuple (gx, gy, gz).
    #[getter]
    fn gravity_vector(&self) -> (f64, f64, f64) {
        let [x, y, z] = self.model.gravity();
        (x, y, z)
    }

    fn __repr__(&self) -> String {
        let mass: f64 = self.model.links().iter().map(|l| l.mass).sum();
        format!(
            "Chain(name={:?}, joints={}, moving_mass={mass:?}, gravity={:?})",
            self.robot.name,
            self.n(),
            self.model.gravity()
        )
    }

    /// Pickling: `Chain.from_urdf` of the chain's URDF text and gravity (the URDF round trip
    /// gives the same model bit for bit).
    #[allow(
        clippy::type_complexity,
        reason = "pickle's (callable, arguments) pair"
    )]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let chain = slf.get();
        let constructor = slf.get_type().getattr("from_urdf")?;
        let text = robot_desc::write_urdf(&chain.robot).map_err(|e| Error::input(e.to_string()))?;
        let arguments = (text, chain.model.gravity()).into_pyobject(slf.py())?;
        Ok((constructor, arguments))
    }

    /// The chain as URDF text (reading it back gives the same chain bit for bit; URDF has no
    /// gravity).
    fn to_urdf(&self) -> PyResult<String> {
        Ok(robot_desc::write_urdf(&self.robot).map_err(|e| Error::input(e.to_string()))?)
    }

    /// The chain as one MJCF document for MuJoCo, the gravity vector in `<option>`. Raises
    /// InvalidInput past the bodies MuJoCo's parser nests in one document (use `hrm arm export`)
    /// and, naming the link, for what MuJoCo refuses (a moving body's mass or principal moment
    /// below mjMINVAL, 1e-15).
    fn to_mjcf(&self) -> PyResult<String> {
        mjcf(&self.robot, self.model.gravity())
    }

    /// The joint-space mass matrix M(q) (CRBA), shape (n, n) or (N, n, n). Raises InvalidInput
    /// for a chain of more than 4096 joints (the limit of the n x n algorithms).
    fn mass_matrix<'py>(
        &self,
        py: Python<'py>,
        theta: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.dense("Chain.mass_matrix (an n x n matrix)")?;
        let n = self.n();
        let theta = States::read(theta, "theta", n)?;
        let out = evaluate(
            py,
            [&theta],
            n * n,
            50 * n * n + 100 * n,
            &self.workspace,
            || self.fresh(),
            |ws, [q], out| {
                spatial::mass_matrix(
                    &self.model,
                    &mut ws.data,
                    q,
                    MatMut::from_row_major_slice_mut(out, n, n),
                )?;
                check_finite("mass_matrix", out)
            },
        )?;
        Ok(out.into_py(py, &[n, n]))
    }

    /// The Coriolis and centrifugal efforts C(q, q_dot) q_dot, shape (n,) or (N, n).
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
            300 * n,
            &self.workspace,
            || self.fresh(),
            |ws, [q, v], out| {
                spatial::coriolis(&self.model, &mut ws.data, q, v, out)?;
                check_finite("coriolis", out)
            },
        )?;
        Ok(out.into_py(py, &[n]))
    }

    /// The gravity efforts G(q), shape (n,) or (N, n).
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
            300 * n,
            &self.workspace,
            || self.fresh(),
            |ws, [q], out| {
                spatial::gravity(&self.model, &mut ws.data, q, out)?;
                check_finite("gravity", out)
            },
        )?;
        Ok(out.into_py(py, &[n]))
    }

    /// Inverse dynamics (RNEA, O(n)): the joint efforts tau = M q_ddot + C q_dot + G, shape (n,)
    /// or (N, n).
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
        let [q, v, a] = &inputs;
        let out = evaluate(
            py,
            [q, v, a],
            n,
            300 * n,
            &self.workspace,
            || self.fresh(),
            |ws, [q, v, a], out| {
                spatial::rnea(&self.model, &mut ws.data, q, v, a, out)?;
                check_finite("tau", out)
            },
        )?;
        Ok(out.into_py(py, &[n]))
    }

    /// Forward dynamics (ABA, O(n)): the joint accelerations under the efforts tau, shape (n,)
    /// or (N, n). A batch runs through `manip_dyn::spatial::aba_batch`, several states at once
    /// in the processor's SIMD registers, with the results of one state at a time.
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
            300 * n,
            &self.workspace,
            || self.fresh(),
            |ws, [q, v, t], out| {
                let batch = match &mut ws.batch {
                    Some(batch) => batch,
                    empty => empty.insert(
                        SpatialBatchData::try_new(&self.model).map_err(|e| (0, Error::from(e)))?,
                    ),
                };
                spatial::aba_batch(&self.model, batch, q, v, t, out).map_err(|error| match error {
                    BatchError::State { state, error } => (state, Error::from(error)),
                    // The driver passes whole states: a shape error cannot happen.
                    other => (0, Error::input(other.to_string())),
                })
            },
        )?;
        Ok(out.into_py(py, &[n]))
    }

    /// The RNEA and its analytic derivatives at (q, q_dot, q_ddot): a tuple (tau, d tau / d q,
    /// d tau / d q_dot), shapes (n,), (n, n), (n, n) or with a leading N (Carpentier and
    /// Mansard's, as Pinocchio's computeRNEADerivatives).
    fn rnea_derivatives<'py>(
        &self,
        py: Python<'py>,
        theta: &Bound<'py, PyAny>,
        theta_dot: &Bound<'py, PyAny>,
        theta_ddot: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        self.derivatives(
            py,
            ["theta", "theta_dot", "theta_ddot"],
            [theta, theta_dot, theta_ddot],
            false,
            spatial::rnea_derivatives,
        )
    }

    /// The ABA and its analytic derivatives at (q, q_dot, tau): a tuple (q_ddot, d q_ddot / d q,
    /// d q_ddot / d q_dot, d q_ddot / d tau = M^-1), shapes (n,), (n, n), (n, n), (n, n) or with
    /// a leading N (as Pinocchio's computeABADerivatives).
    fn aba_derivatives<'py>(
        &self,
        py: Python<'py>,
        theta: &Bound<'py, PyAny>,
        theta_dot: &Bound<'py, PyAny>,
        tau: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        self.derivatives(
            py,
            ["theta", "theta_dot", "tau"],
            [theta, theta_dot, tau],
            true,
            spatial::aba_derivatives,
        )
    }

    /// Forward kinematics: a tuple (positions, rotations) of every moving link's frame in the
    /// base frame, shapes (n, 3) and (n, 3, 3) (rotation matrices, the link's axes as columns),
    /// or with a leading N.
    fn frames<'py>(
        &self,
        py: Python<'py>,
        theta: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let n = self.n();
        let theta = States::read(theta, "theta", n)?;
        let batch = theta.is_batch();
        let per_state = 12 * n;
        let out = evaluate(
            py,
            [&theta],
            per_state,
            100 * n * n + 200 * n,
            &self.workspace,
            || self.fresh(),
            |ws, [q], out| {
                spatial::forward_kinematics(&self.model, &mut ws.data, q)?;
                let (positions, rotations) = out.split_at_mut(3 * n);
                for i in 0..n {
                    let pose = ws.data.link_pose(i).expect("i < n");
                    positions[3 * i..3 * i + 3].copy_from_slice(&pose.translation);
                    for (r, row) in pose.rotation.iter().enumerate() {
                        rotations[9 * i + 3 * r..9 * i + 3 * r + 3].copy_from_slice(row);
                    }
                }
                check_finite("frames", out)
            },
        )?;
        let all = out.into_py(py, &[per_state]);
        PyTuple::new(
            py,
            [
                field(&all, batch, 0, 3 * n, &[n, 3])?,
                field(&all, batch, 3 * n, 12 * n, &[n, 3, 3])?,
            ],
        )
    }

    /// Total mechanical energy, kinetic plus potential (J, zero potential at the base origin): a
    /// float for one state, shape (N,) for a batch.
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
        let out = evaluate(
            py,
            [&theta, &theta_dot],
            1,
            300 * n,
            &self.workspace,
            || self.fresh(),
            |ws, [q, v], out| {
                out[0] = spatial::kinetic_energy(&self.model, &mut ws.data, q, v)?
                    + spatial::potential_energy(&self.model, &mut ws.data, q)?;
                check_finite("energy", out)
            },
        )?;
        Ok(out.into_py(py, &[]))
    }

    /// The joint values' lower and upper limits from the URDF, shape (n, 2) (-inf and inf for
    /// continuous joints and joints without limits).
    #[getter]
    fn limits<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        let values: Vec<f64> = self
            .robot
            .joints
            .iter()
            .flat_map(|j| {
                let limits = j.limits.filter(|_| j.kind != JointKind::Continuous);
                [
                    limits.and_then(|l| l.lower).unwrap_or(f64::NEG_INFINITY),
                    limits.and_then(|l| l.upper).unwrap_or(f64::INFINITY),
                ]
            })
            .collect();
        numpy::ndarray::Array2::from_shape_vec((self.n(), 2), values)
            .expect("two values per joint")
            .into_pyarray(py)
            .into_any()
    }
}

/// The planar arm `chain` as a description (joints about z, links along x, in the base's x-y
/// plane) and its gravity vector (along -y).
pub(crate) fn planar_robot(chain: &manip_dyn::ChainModel) -> PyResult<(Robot, [f64; 3])> {
    let robot = robot_desc::from_planar(chain, "hrm_planar_arm")
        .map_err(|e| Error::input(e.to_string()))?;
    Ok((robot, [0.0, -chain.gravity(), 0.0]))
}

/// MJCF text of a description under `gravity`.
pub(crate) fn mjcf(robot: &Robot, gravity: [f64; 3]) -> PyResult<String> {
    Ok(robot_desc::write_mjcf(robot, gravity).map_err(|e| Error::input(e.to_string()))?)
}
