//! `retarget._native`: the Python face of [`retarget::Retargeter`]. Everything here converts
//! between Python objects and the library's types and releases the GIL around the work; the
//! algorithms live in the library crates (the Python package adds `retarget.gmr`, a thin
//! layer of GMR's names over these functions).

// No panics on input: a panic would reach Python as `PanicException`, not a `RetargetError`.
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

mod smpl;

use std::path::PathBuf;
use std::sync::{Arc, OnceLock};

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use numpy::{IntoPyArray, PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyMapping};

use npz::{Array, ArrayData};
use retarget::writers::Format;
use retarget::{ClipDiagnostics, HumanFrame, RetargetOptions, RobotMotion, StageValue};

pyo3::create_exception!(
    _native,
    RetargetError,
    PyValueError,
    "A retargeting error: a bad file, config, robot or option (the message says which)."
);

/// The library's error as a Python exception: missing files are `FileNotFoundError`, other
/// file system failures `OSError`, everything else `RetargetError` (a `ValueError`).
fn to_py(err: retarget::Error) -> PyErr {
    match io_kind(&err) {
        Some(std::io::ErrorKind::NotFound) => PyFileNotFoundError::new_err(err.to_string()),
        Some(_) => PyOSError::new_err(err.to_string()),
        None => RetargetError::new_err(err.to_string()),
    }
}

/// The kind of the file system error behind `err`, if one is: along the source chain, and
/// inside the BVH reader's error (which keeps its I/O error as a field, not a source).
fn io_kind(err: &retarget::Error) -> Option<std::io::ErrorKind> {
    match err {
        retarget::Error::Bvh(bvh::Error::Io { err, .. }) => return Some(err.kind()),
        retarget::Error::InFile { source, .. } => return io_kind(source),
        _ => {}
    }
    let mut cause: Option<&(dyn std::error::Error + 'static)> = Some(err);
    while let Some(e) = cause {
        if let Some(io) = e.downcast_ref::<std::io::Error>() {
            return Some(io.kind());
        }
        cause = e.source();
    }
    None
}

fn options_for(mode: &str, human_height: Option<f64>) -> PyResult<RetargetOptions> {
    let mut options = match mode {
        "default" | "plausible" => RetargetOptions::default(),
        "gmr" => RetargetOptions::gmr(),
        "causal" => RetargetOptions::causal(),
        "both_ways" => {
            let mut plausible = retarget::PlausibleOptions::default();
            plausible.both_ways = true;
            let mut options = RetargetOptions::default();
            options.mode = retarget::SolveMode::Plausible(plausible);
            options
        }
        other => {
            return Err(PyValueError::new_err(format!(
                "mode {other:?}: expected \"default\", \"gmr\", \"causal\" or \"both_ways\""
            )))
        }
    };
    options.human_height = human_height;
    Ok(options)
}

fn build(
    robot: &str,
    config: Option<PathBuf>,
    mode: &str,
    human_height: Option<f64>,
    fps: f64,
) -> PyResult<retarget::Retargeter> {
    let mut inner = retarget::Retargeter::new(robot)
        .map_err(to_py)?
        .with_options(options_for(mode, human_height)?)
        .with_stream_fps(fps);
    if let Some(path) = config {
        inner = inner.with_config(retarget::IkConfig::from_file(&path).map_err(to_py)?);
    }
    Ok(inner)
}

/// Retargets human motion onto one robot.
///
/// Args:
///     robot: a shipped robot (``"unitree_g1"``, see ``retarget.shipped_robots()``) or the
///         path of an MJCF (``.xml``) or URDF (``.urdf``) file.
///     config: an IK config file (GMR's JSON schema). Default: for a BVH, GMR's tuned config
///         for LAFAN1 skeletons (names and joint frames, in either mode) on shipped robots,
///         else one derived from the skeleton's and the robot's roles; for frames, the
///         shipped robot's tuned config.
///     mode: ``"default"`` (planted feet, ground, self-collision and joint-speed
///         constraints, a smoothing pass), ``"gmr"`` (GMR's exact solve), ``"causal"``
///         (the default's constraints without planting or smoothing: what ``step`` runs) or
///         ``"both_ways"`` (the default, its first pass also run backwards, the better
///         direction taken where the two agree: ``retarget --both-ways``).
///     human_height: subject height in metres. Default: estimated from a BVH skeleton; the
///         config's ``human_height_assumption`` for frames.
///     fps: frame rate of streamed frames (``step``), for the joint speed limits.
#[pyclass(module = "retarget")]
struct Retargeter {
    inner: retarget::Retargeter,
}

#[pymethods]
impl Retargeter {
    #[new]
    #[pyo3(signature = (robot, config=None, *, mode="default", human_height=None, fps=30.0))]
    fn new(
        robot: &str,
        config: Option<PathBuf>,
        mode: &str,
        human_height: Option<f64>,
        fps: f64,
    ) -> PyResult<Retargeter> {
        Ok(Retargeter { inner: build(robot, config, mode, human_height, fps)? })
    }

    /// The robot's name: the shipped key or the model file's stem.
    #[getter]
    fn robot(&self) -> String {
        self.inner.label().to_owned()
    }

    /// Length of one ``qpos`` (root position, root quaternion w x y z, joints).
    #[getter]
    fn nq(&self) -> usize {
        self.inner.model().nq
    }

    /// The robot's non-root joints, in ``qpos`` order.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        retarget::RobotMotion::model_joint_names(self.inner.model())
    }

    /// The robot's bodies (the world left out), in MuJoCo order.
    #[getter]
    fn body_names(&self) -> Vec<String> {
        retarget::RobotMotion::model_body_names(self.inner.model())
    }

    /// The JSON text of the config that frames and ``retarget_frames`` use.
    fn config_json(&self) -> PyResult<String> {
        Ok(self.inner.motion_config().map_err(to_py)?.json().to_owned())
    }

    /// Retargets a BVH file; returns a ``Motion``.
    fn retarget_bvh(&self, py: Python<'_>, path: PathBuf) -> PyResult<Motion> {
        let inner = &self.inner;
        let (motion, diag) = py.detach(|| inner.retarget_bvh_file(&path)).map_err(to_py)?;
        Ok(Motion::new(motion, diag, inner.shared_model()))
    }

    /// Retargets one take of an FBX file: ``take`` is its name or index (``None``: the take
    /// with the most motion; ``Motion.inferred`` says which).
    #[pyo3(signature = (path, take=None))]
    fn retarget_fbx(
        &self,
        py: Python<'_>,
        path: PathBuf,
        take: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Motion> {
        let take = take_selector(take)?;
        let inner = &self.inner;
        let (motion, diag) =
            py.detach(|| inner.retarget_fbx_file(&path, take.as_deref())).map_err(to_py)?;
        Ok(Motion::new(motion, diag, inner.shared_model()))
    }

    /// Retargets a C3D marker file with a marker-driven IK config (``marker_bodies`` and the
    /// IK tables in one JSON file, e.g. ``configs/c3d_plugingait_to_unitree_g1.json``).
    fn retarget_c3d(&self, py: Python<'_>, path: PathBuf, config: PathBuf) -> PyResult<Motion> {
        let inner = &self.inner;
        let (motion, diag) =
            py.detach(|| inner.retarget_c3d_file(&path, &config)).map_err(to_py)?;
        Ok(Motion::new(motion, diag, inner.shared_model()))
    }

    /// Retargets an AMASS motion: a file (SMPL-X stage-ii ``*_stageii.npz`` or SMPL+H
    /// ``*_poses.npz``, told apart by content) or the same parameters as arrays (``poses``
    /// N × 165 SMPL-X or N × 156 SMPL+H axis-angle in the model's joint order, ``trans``
    /// N × 3, ``betas``, ``fps``). ``body_model``: the folder holding ``smplx/`` and
    /// ``smplh/`` (or one model ``.npz``); default ``$RETARGET_BODY_MODELS``. ``gender``
    /// overrides the file's.
    #[pyo3(signature = (path=None, *, body_model=None, gender=None, poses=None, trans=None, betas=None, fps=None))]
    #[allow(clippy::too_many_arguments)]
    fn retarget_smplx(
        &self,
        py: Python<'_>,
        path: Option<PathBuf>,
        body_model: Option<PathBuf>,
        gender: Option<&str>,
        poses: Option<Bound<'_, PyAny>>,
        trans: Option<Bound<'_, PyAny>>,
        betas: Option<Bound<'_, PyAny>>,
        fps: Option<f64>,
    ) -> PyResult<Motion> {
        let arrays = match (&poses, &trans) {
            (Some(poses), Some(trans)) => {
                Some(smpl::Arrays { poses, trans, betas: betas.as_ref(), fps })
            }
            (None, None) => None,
            _ => return Err(PyValueError::new_err("poses and trans go together")),
        };
        let inner = &self.inner;
        let (motion, diag) = smpl::retarget_smplx(py, inner, path, arrays, body_model, gender)?;
        Ok(Motion::new(motion, diag, inner.shared_model()))
    }

    /// Use the shipped robot's config for ``source``, GMR's ``src_human``: ``"bvh_lafan1"``
    /// (GMR's LAFAN1 config, the default for frames), ``"smplx"`` (GMR's ``smplx_to_*``
    /// config) or any other source GMR has a config of this robot for (``"bvh_nokov"``,
    /// ``"bvh_xsens"``, ``"fbx"``, ``"fbx_offline"``, ``"xsens_mvn"``, ``"xrobot"``; see
    /// ``gmr_configs``), as GMR's ``IK_CONFIG_DICT`` chooses it.
    fn select_config(&mut self, source: &str) -> PyResult<()> {
        let config = match source {
            "bvh_lafan1" => self.inner.tuned_config().cloned(),
            "smplx" => self.inner.smplx_config().cloned(),
            other => retarget::shipped::config(other, self.inner.label())
                .map(retarget::shipped::ShippedConfig::parse)
                .transpose()
                .map_err(|e| RetargetError::new_err(e.to_string()))?,
        };
        let config = config.ok_or_else(|| {
            RetargetError::new_err(format!(
                "robot {}: no {source} config ships",
                self.inner.label()
            ))
        })?;
        self.inner.set_config(config);
        Ok(())
    }

    /// Retargets a clip given as frames of ``{body: (position, wxyz quaternion)}`` (GMR's
    /// ``human_data``, e.g. from ``retarget.gmr.load_bvh_file``) at ``fps``.
    #[pyo3(signature = (frames, fps=30.0))]
    fn retarget_frames(
        &self,
        py: Python<'_>,
        frames: &Bound<'_, PyAny>,
        fps: f64,
    ) -> PyResult<Motion> {
        let human = human_motion(frames, fps)?;
        let inner = &self.inner;
        let (motion, diag) = py.detach(|| inner.retarget(&human)).map_err(to_py)?;
        Ok(Motion::new(motion, diag, inner.shared_model()))
    }

    /// Retargets one streamed frame ``{body: (position, wxyz quaternion)}`` (GMR's
    /// ``human_data``: metres, Z up) and returns the robot's ``qpos`` (a new array).
    /// Warm-started from the previous frame; runs the causal solve (see ``mode``).
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        frame: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let frame = human_frame(frame)?;
        let inner = &mut self.inner;
        let qpos = py.detach(|| inner.step(&frame).map(<[f64]>::to_vec)).map_err(to_py)?;
        Ok(qpos.into_pyarray(py))
    }

    /// Forgets the stream: the next ``step`` starts again from the robot's home pose.
    fn reset(&mut self) {
        self.inner.reset();
    }

    /// The targets of the last streamed frame, ``{human body: (position, wxyz quaternion)}``
    /// after scaling and offsets (GMR's ``scaled_human_data``).
    fn last_targets<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let out = PyDict::new(py);
        for (name, pose) in self.inner.last_step_targets() {
            let (t, q) = (&pose.translation.vector, &pose.rotation);
            let pos = vec![t.x, t.y, t.z].into_pyarray(py);
            let quat = vec![q.w, q.i, q.j, q.k].into_pyarray(py);
            out.set_item(name, (pos, quat))?;
        }
        Ok(out)
    }

    fn __repr__(&self) -> String {
        format!("Retargeter({:?}, nq={})", self.inner.label(), self.inner.model().nq)
    }
}

/// ``(position, quaternion)`` of one body: sequences or arrays of 3 and 4 floats.
fn pose(value: &Bound<'_, PyAny>) -> PyResult<(Vector3<f64>, UnitQuaternion<f64>)> {
    let p: [f64; 3] = floats(&value.get_item(0)?)?;
    let q: [f64; 4] = floats(&value.get_item(1)?)?;
    let quat = Quaternion::new(q[0], q[1], q[2], q[3]);
    let norm = quat.norm();
    if !(norm.is_finite() && norm > 0.0) {
        return Err(PyValueError::new_err(format!("quaternion {q:?} has no direction")));
    }
    // A unit quaternion is taken as it is (bit for bit), anything else normalised.
    let unit = if (norm - 1.0).abs() <= 4.0 * f64::EPSILON {
        UnitQuaternion::new_unchecked(quat)
    } else {
        UnitQuaternion::new_normalize(quat)
    };
    Ok((Vector3::new(p[0], p[1], p[2]), unit))
}

fn floats<const N: usize>(value: &Bound<'_, PyAny>) -> PyResult<[f64; N]> {
    if let Ok(array) = value.extract::<PyReadonlyArray1<'_, f64>>() {
        if let Ok(slice) = array.as_slice() {
            if let Ok(out) = <[f64; N]>::try_from(slice) {
                return Ok(out);
            }
        }
    }
    value.extract::<[f64; N]>()
}

/// A ``{body: (position, quaternion)}`` mapping as a frame.
fn human_frame(frame: &Bound<'_, PyAny>) -> PyResult<HumanFrame> {
    let mapping = frame.cast::<PyMapping>()?;
    let items = mapping.items()?;
    let mut out = HumanFrame::with_capacity(items.len());
    for item in items.iter() {
        let (name, value): (String, Bound<'_, PyAny>) = item.extract()?;
        let (p, q) = pose(&value).map_err(|e| {
            PyValueError::new_err(format!(
                "body {name:?}: expected (position, wxyz quaternion): {e}"
            ))
        })?;
        out.push(&name, p, q);
    }
    Ok(out)
}

/// Frames of ``{body: (position, quaternion)}`` as one motion (bodies of the first frame).
fn human_motion(frames: &Bound<'_, PyAny>, fps: f64) -> PyResult<fk::HumanMotion> {
    let mut human = fk::HumanMotion {
        fps,
        body_names: Vec::new(),
        num_frames: 0,
        positions: Vec::new(),
        orientations: Vec::new(),
    };
    for item in frames.try_iter()? {
        let frame = human_frame(&item?)?;
        if human.num_frames == 0 {
            human.body_names.clone_from(&frame.body_names);
        }
        for name in &human.body_names {
            let (position, orientation) = frame.pose(name).ok_or_else(|| {
                PyValueError::new_err(format!("frame {}: no body {name:?}", human.num_frames))
            })?;
            human.positions.push(*position);
            human.orientations.push(*orientation);
        }
        human.num_frames += 1;
    }
    Ok(human)
}

/// A retargeted clip. Its fields are numpy arrays named as in the ``.npz`` it saves
/// (``qpos``, ``joint_pos``, ``joint_vel``, ``body_pos_w``, ``body_quat_w``,
/// ``body_lin_vel_w``, ``body_ang_vel_w``, ``target_pos``, ``target_quat``,
/// ``contact_left``/``contact_right``), plus ``fps``, ``joint_names``, ``body_names``,
/// ``target_body_names`` and ``robot``. Arrays are computed on first access and handed to
/// numpy without a copy; they are read-only (copy one to change it).
#[pyclass(module = "retarget", frozen)]
struct Motion {
    motion: RobotMotion,
    model: Arc<mjcf::Model>,
    diag: ClipDiagnostics,
    arrays: OnceLock<Py<PyDict>>,
}

impl Motion {
    fn new(motion: RobotMotion, diag: ClipDiagnostics, model: Arc<mjcf::Model>) -> Motion {
        Motion { motion, model, diag, arrays: OnceLock::new() }
    }

    /// Every array of the ``.npz``, built once.
    fn arrays<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        if let Some(dict) = self.arrays.get() {
            return Ok(dict.bind(py).clone());
        }
        let (motion, model) = (&self.motion, &self.model);
        let arrays = py.detach(|| retarget::writers::npz_arrays(motion, model)).map_err(to_py)?;
        let dict = PyDict::new(py);
        for (key, array) in arrays {
            dict.set_item(key, to_numpy(py, array)?)?;
        }
        let _ = self.arrays.set(dict.clone().unbind());
        Ok(dict)
    }

    fn get<'py>(&self, py: Python<'py>, key: &str) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.arrays(py)?.get_item(key)
    }
}

/// One value of a stage's report as Python: float, int, list of ``(first, last)`` or str.
fn stage_value<'py>(py: Python<'py>, value: &StageValue) -> PyResult<Bound<'py, PyAny>> {
    Ok(match value {
        StageValue::Number(x) => x.into_pyobject(py)?.into_any(),
        StageValue::Count(n) => n.into_pyobject(py)?.into_any(),
        StageValue::Ranges(ranges) => PyList::new(py, ranges)?.into_any(),
        StageValue::Text(text) => text.into_pyobject(py)?.into_any(),
        _ => py.None().into_bound(py),
    })
}

/// An npz array as numpy: float64 and bool arrays moved (no copy) and reshaped (a view),
/// read-only; strings as a numpy unicode array.
fn to_numpy(py: Python<'_>, array: Array) -> PyResult<Bound<'_, PyAny>> {
    let shape = array.shape;
    let out = match array.data {
        ArrayData::F64(data) => read_only(data.into_pyarray(py).reshape(shape)?.into_any())?,
        ArrayData::Bool(data) => read_only(data.into_pyarray(py).reshape(shape)?.into_any())?,
        ArrayData::Str(items) => {
            let numpy = py.import("numpy")?;
            let list = if shape.is_empty() {
                items.into_iter().next().unwrap_or_default().into_pyobject(py)?.into_any()
            } else {
                PyList::new(py, items)?.into_any()
            };
            numpy.call_method1("array", (list,))?
        }
    };
    Ok(out)
}

fn read_only(array: Bound<'_, PyAny>) -> PyResult<Bound<'_, PyAny>> {
    array.getattr("flags")?.setattr("writeable", false)?;
    Ok(array)
}

#[pymethods]
impl Motion {
    /// Frames per second.
    #[getter]
    fn fps(&self) -> f64 {
        self.motion.fps
    }

    /// ``qpos`` per frame (T × nq): root position, root quaternion w x y z, joints.
    #[getter]
    fn qpos<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.get(py, "qpos")
    }

    /// Joint positions (T × (nq − 7)), BeyondMimic's ``joint_pos``.
    #[getter]
    fn joint_pos<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.get(py, "joint_pos")
    }

    /// Joint velocities (T × (nq − 7)), numpy ``gradient``'s scheme.
    #[getter]
    fn joint_vel<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.get(py, "joint_vel")
    }

    /// World body positions (T × B × 3).
    #[getter]
    fn body_pos_w<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.get(py, "body_pos_w")
    }

    /// World body orientations (T × B × 4, w x y z).
    #[getter]
    fn body_quat_w<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.get(py, "body_quat_w")
    }

    /// World body linear velocities (T × B × 3).
    #[getter]
    fn body_lin_vel_w<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.get(py, "body_lin_vel_w")
    }

    /// World body angular velocities (T × B × 3).
    #[getter]
    fn body_ang_vel_w<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.get(py, "body_ang_vel_w")
    }

    /// The IK target positions the solver tracked (T × K × 3).
    #[getter]
    fn target_pos<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.get(py, "target_pos")
    }

    /// The IK target orientations (T × K × 4, w x y z).
    #[getter]
    fn target_quat<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.get(py, "target_quat")
    }

    /// Per frame, whether the source's left foot is on the floor (``None`` when unknown).
    #[getter]
    fn contact_left<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.get(py, "contact_left")
    }

    /// Per frame, whether the source's right foot is on the floor (``None`` when unknown).
    #[getter]
    fn contact_right<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.get(py, "contact_right")
    }

    /// The robot's non-root joints, in ``qpos`` order.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.motion.joint_names.clone()
    }

    /// The robot's bodies (the world left out), in MuJoCo order.
    #[getter]
    fn body_names(&self) -> Vec<String> {
        self.motion.body_names.clone()
    }

    /// The bodies with IK targets, in ``target_pos`` order.
    #[getter]
    fn target_body_names(&self) -> Vec<String> {
        self.motion.targets.as_ref().map(|t| t.body_names.clone()).unwrap_or_default()
    }

    /// The robot model's name (MJCF ``model`` attribute).
    #[getter]
    fn robot(&self) -> String {
        self.model.name.clone()
    }

    /// Subject height used (m) and where it came from.
    #[getter]
    fn human_height(&self) -> (f64, String) {
        (self.diag.human_height, self.diag.human_height_source.clone())
    }

    /// What was inferred about the source (up axis, unit, roles) and the config used.
    #[getter]
    fn inferred(&self) -> String {
        self.diag.human_inferred.clone()
    }

    /// Seconds the IK took.
    #[getter]
    fn solve_seconds(&self) -> f64 {
        self.diag.solve_seconds
    }

    /// What the default solve's stages said about the clip, ``{stage: {key: value}}`` in the
    /// order they ran, only stages with something to say: each with its one-line
    /// ``"summary"`` (as the main command prints it) and its values (numbers as float or int,
    /// frame stretches as lists of ``(first, last)``). ``"reweigh"``: ``pelvis_offset`` (m,
    /// the pelvis off its target with the config's weights) and ``share`` (0 to 1);
    /// ``"treadmill"``: ``belt_mps`` and ``heading_rad``, an in-place loop walked forward.
    #[getter]
    fn stages<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let out = PyDict::new(py);
        for report in &self.diag.stages {
            let values = PyDict::new(py);
            values.set_item("summary", &report.summary)?;
            for (key, value) in &report.values {
                values.set_item(key, stage_value(py, value)?)?;
            }
            out.set_item(report.stage, values)?;
        }
        Ok(out)
    }

    /// Frames taken from the backward first pass (``mode="both_ways"``; 0 otherwise) and
    /// the stretches they form.
    #[getter]
    fn backward(&self) -> (usize, usize) {
        self.diag.from_backward()
    }

    /// Every array of the ``.npz`` by key, exactly as ``numpy.load`` gives them (``fps`` of
    /// shape (1,), names as unicode arrays).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.arrays(py)?.copy()
    }

    /// Writes the motion: ``.npz`` (BeyondMimic's keys), ``.csv`` (Unitree's layout), ``.pkl``
    /// (GMR's pickle) or ``.json``, by the extension unless ``format`` names one. Atomic.
    #[pyo3(signature = (path, format=None))]
    fn save(&self, py: Python<'_>, path: PathBuf, format: Option<&str>) -> PyResult<()> {
        let format = match format {
            None => None,
            Some(name) => {
                Some(Format::from_path(&PathBuf::from(format!("x.{name}"))).ok_or_else(|| {
                    PyValueError::new_err(format!(
                        "format {name:?}: expected npz, csv, pkl or json"
                    ))
                })?)
            }
        };
        let (motion, model) = (&self.motion, &self.model);
        py.detach(|| retarget::writers::write_motion(&path, motion, model, format)).map_err(to_py)
    }

    /// The quality report as JSON text (``retarget.report`` returns it as a dict).
    fn report_json(&self, py: Python<'_>) -> PyResult<String> {
        let (motion, model) = (&self.motion, &self.model);
        let options = retarget::report::ReportOptions::default();
        let report =
            py.detach(|| retarget::report::report(motion, model, &options)).map_err(to_py)?;
        serde_json::to_string(&report).map_err(|e| RetargetError::new_err(e.to_string()))
    }

    fn __len__(&self) -> usize {
        self.motion.num_frames()
    }

    fn __repr__(&self) -> String {
        format!(
            "Motion(robot={:?}, frames={}, fps={}, nq={})",
            self.model.name,
            self.motion.num_frames(),
            self.motion.fps,
            self.motion.nq
        )
    }
}

/// GMR's ``load_bvh_file``: frames of ``{body: [position, wxyz quaternion]}`` (joints, no End
/// Sites, then ``LeftFootMod``/``RightFootMod``; metres, Z up) and GMR's height for the format
/// (1.75 m; ``"soma"``, GMR PR #169's loader: 1.70 m).
#[pyfunction]
#[pyo3(signature = (path, format="lafan1"))]
fn load_bvh_gmr<'py>(
    py: Python<'py>,
    path: PathBuf,
    format: &str,
) -> PyResult<(Bound<'py, PyList>, f64)> {
    let format = retarget::GmrBvhFormat::from_name(format)
        .ok_or_else(|| PyValueError::new_err(format!("Invalid format: {format}")))?;
    let human = py
        .detach(|| {
            let bvh = bvh::from_path(&path)?;
            retarget::load_bvh_gmr(&bvh, format)
        })
        .map_err(|e: retarget::Error| to_py(e))?;
    let frames = PyList::empty(py);
    // Frame by frame (`max(1)`: a motion without bodies has no rows to split).
    let nb = human.num_bodies().max(1);
    let rows = human.positions.chunks_exact(nb).zip(human.orientations.chunks_exact(nb));
    for (positions, orientations) in rows {
        let frame = PyDict::new(py);
        for ((name, p), q) in human.body_names.iter().zip(positions).zip(orientations) {
            let pos = PyArray1::from_slice(py, &[p.x, p.y, p.z]);
            let quat = PyArray1::from_slice(py, &[q.w, q.i, q.j, q.k]);
            frame.set_item(name, PyList::new(py, [pos.into_any(), quat.into_any()])?)?;
        }
        frames.append(frame)?;
    }
    Ok((frames, format.human_height()))
}

/// A take given as a name (``str``) or an index (``int``).
fn take_selector(take: Option<&Bound<'_, PyAny>>) -> PyResult<Option<String>> {
    let Some(take) = take else { return Ok(None) };
    if let Ok(index) = take.extract::<usize>() {
        return Ok(Some(index.to_string()));
    }
    take.extract::<String>()
        .map(Some)
        .map_err(|_| PyTypeError::new_err("take: expected a take name (str) or index (int)"))
}

/// One take of an FBX file as frames of ``{body: [position, wxyz quaternion]}`` (every
/// skeleton joint; metres, Z up, the file's axes and unit as ``retarget_fbx`` reads them),
/// with the frame rate and the take's name.
#[pyfunction]
#[pyo3(signature = (path, take=None))]
fn load_fbx_frames<'py>(
    py: Python<'py>,
    path: PathBuf,
    take: Option<&Bound<'py, PyAny>>,
) -> PyResult<(Bound<'py, PyList>, f64, String)> {
    let take = take_selector(take)?;
    let (human, name) = py
        .detach(|| {
            let clip = retarget::FbxClip::read(&path, take.as_deref())?;
            let options =
                clip.fk_options(&fk::FkOptions { derived: Vec::new(), ..Default::default() });
            let (human, _) = fk::human_motion(&clip.bvh, &options)?;
            Ok((human, clip.take.name))
        })
        .map_err(|e: retarget::Error| to_py(e))?;
    let frames = PyList::empty(py);
    let nb = human.num_bodies().max(1);
    let rows = human.positions.chunks_exact(nb).zip(human.orientations.chunks_exact(nb));
    for (positions, orientations) in rows {
        let frame = PyDict::new(py);
        for ((body, p), q) in human.body_names.iter().zip(positions).zip(orientations) {
            let pos = PyArray1::from_slice(py, &[p.x, p.y, p.z]);
            let quat = PyArray1::from_slice(py, &[q.w, q.i, q.j, q.k]);
            frame.set_item(body, PyList::new(py, [pos.into_any(), quat.into_any()])?)?;
        }
        frames.append(frame)?;
    }
    Ok((frames, human.fps, name))
}

/// Retargets BVH and FBX files (the take with the most motion) into ``out_dir``
/// (``<stem>.<format>``) on ``jobs`` threads (0: one per core); returns one dict per file: ``input``, ``output``, and ``frames``, ``seconds``,
/// ``inferred`` or ``error``.
#[pyfunction]
#[pyo3(signature = (paths, robot, out_dir, jobs=0, *, config=None, mode="default", format="npz", human_height=None))]
#[allow(clippy::too_many_arguments)]
fn batch<'py>(
    py: Python<'py>,
    paths: Vec<PathBuf>,
    robot: &str,
    out_dir: PathBuf,
    jobs: usize,
    config: Option<PathBuf>,
    mode: &str,
    format: &str,
    human_height: Option<f64>,
) -> PyResult<Bound<'py, PyList>> {
    let inner = build(robot, config, mode, human_height, 30.0)?;
    let pairs: Vec<(PathBuf, PathBuf)> = paths
        .iter()
        .map(|p| {
            let stem = p.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
            (p.clone(), out_dir.join(format!("{stem}.{format}")))
        })
        .collect();
    std::fs::create_dir_all(&out_dir)
        .map_err(|e| PyOSError::new_err(format!("{}: {e}", out_dir.display())))?;
    let results = py.detach(|| inner.retarget_files(&pairs, jobs)).map_err(to_py)?;
    let out = PyList::empty(py);
    for ((input, output), result) in pairs.iter().zip(results) {
        let row = PyDict::new(py);
        row.set_item("input", input.display().to_string())?;
        row.set_item("output", output.display().to_string())?;
        match result {
            Ok(r) => {
                row.set_item("frames", r.frames)?;
                row.set_item("seconds", r.seconds)?;
                row.set_item("inferred", r.inferred)?;
            }
            Err(e) => row.set_item("error", e.to_string())?,
        }
        out.append(row)?;
    }
    Ok(out)
}

/// The shipped robots' keys.
#[pyfunction]
fn shipped_robots() -> Vec<&'static str> {
    retarget::shipped::keys().collect()
}

/// The shipped configs as ``(source, robot, path)``: GMR's ``IK_CONFIG_DICT`` for the
/// shipped robots (``retarget::shipped::CONFIGS``).
#[pyfunction]
fn gmr_configs() -> Vec<(&'static str, &'static str, &'static str)> {
    retarget::shipped::CONFIGS.iter().map(|c| (c.source, c.robot, c.path)).collect()
}

/// GMR's robot keys whose models are not shipped, as ``(key, reason, upstream path)``.
#[pyfunction]
fn not_shipped_robots() -> Vec<(&'static str, &'static str, &'static str)> {
    retarget::shipped::NOT_SHIPPED.iter().map(|r| (r.key, r.reason, r.upstream)).collect()
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Retargeter>()?;
    m.add_class::<Motion>()?;
    m.add("RetargetError", m.py().get_type::<RetargetError>())?;
    m.add_function(wrap_pyfunction!(load_bvh_gmr, m)?)?;
    m.add_function(wrap_pyfunction!(gmr_configs, m)?)?;
    m.add_function(wrap_pyfunction!(not_shipped_robots, m)?)?;
    m.add_function(wrap_pyfunction!(load_fbx_frames, m)?)?;
    m.add_function(wrap_pyfunction!(smpl::load_smplx_gmr, m)?)?;
    m.add_function(wrap_pyfunction!(batch, m)?)?;
    m.add_function(wrap_pyfunction!(shipped_robots, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
