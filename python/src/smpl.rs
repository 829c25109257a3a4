//! SMPL-X and SMPL+H input for Python: an AMASS file or the same parameters as arrays, and
//! GMR's SMPL-X loader (`retarget.gmr.get_smplx_data_offline_fast`). Conversions only; the
//! work is the `smpl` crate's and `retarget::Retargeter::retarget_smpl`'s.

use std::path::{Path, PathBuf};

use numpy::{PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use retarget::{ClipDiagnostics, RobotMotion};
use smpl::{BodyModels, Gender, ModelKind, SmplMotion};

use crate::to_py;

fn smpl_err(e: smpl::Error) -> PyErr {
    to_py(e.into())
}

fn gender(text: Option<&str>) -> PyResult<Option<Gender>> {
    text.map(|t| {
        Gender::from_name(t).ok_or_else(|| {
            PyValueError::new_err(format!("gender {t:?}: expected neutral, male or female"))
        })
    })
    .transpose()
}

/// Any array-like as float64 values and their shape.
fn array(py: Python<'_>, value: &Bound<'_, PyAny>) -> PyResult<(Vec<usize>, Vec<f64>)> {
    let numpy = py.import("numpy")?;
    let converted = numpy.call_method1("ascontiguousarray", (value, "float64"))?;
    let a: PyReadonlyArrayDyn<'_, f64> = converted.extract()?;
    let shape = a.shape().to_vec();
    Ok((shape, a.as_slice()?.to_vec()))
}

/// The parameters of a motion given as arrays (`poses` N × 165 SMPL-X or N × 156 SMPL+H).
pub struct Arrays<'a, 'py> {
    pub poses: &'a Bound<'py, PyAny>,
    pub trans: &'a Bound<'py, PyAny>,
    pub betas: Option<&'a Bound<'py, PyAny>>,
    pub fps: Option<f64>,
}

fn from_arrays(py: Python<'_>, a: &Arrays<'_, '_>, g: Option<Gender>) -> PyResult<SmplMotion> {
    let (pshape, poses) = array(py, a.poses)?;
    let (_, trans) = array(py, a.trans)?;
    let betas = match a.betas {
        Some(b) => array(py, b)?.1,
        None => Vec::new(),
    };
    let kind = match pshape.as_slice() {
        [_, 165] => ModelKind::SmplX,
        [_, 156] => ModelKind::SmplH,
        other => {
            return Err(PyValueError::new_err(format!(
                "poses of shape {other:?}: expected (frames, 165) for SMPL-X or (frames, 156) for SMPL+H"
            )))
        }
    };
    let fps = a.fps.ok_or_else(|| PyValueError::new_err("fps is required with arrays"))?;
    SmplMotion::from_parts("<arrays>", kind, g, fps, betas, &trans, poses).map_err(smpl_err)
}

/// Retargets an AMASS file (`path`) or arrays with `inner`; the body model from
/// `body_model` (a folder or a file) or `$RETARGET_BODY_MODELS`.
pub fn retarget_smplx(
    py: Python<'_>,
    inner: &retarget::Retargeter,
    path: Option<PathBuf>,
    arrays: Option<Arrays<'_, '_>>,
    body_model: Option<PathBuf>,
    gender_name: Option<&str>,
) -> PyResult<(RobotMotion, ClipDiagnostics)> {
    let g = gender(gender_name)?;
    let motion = match (path, arrays) {
        (Some(p), None) => py.detach(|| SmplMotion::from_path(&p)).map_err(smpl_err)?,
        (None, Some(a)) => from_arrays(py, &a, g)?,
        _ => {
            return Err(PyValueError::new_err(
                "give either a motion file or the arrays (poses, trans, betas, fps), not both",
            ))
        }
    };
    let models = BodyModels::new(body_model.as_deref());
    py.detach(|| {
        let model = models.for_motion(&motion, g)?;
        inner.retarget_smpl(&motion, &model)
    })
    .map_err(to_py)
}

/// GMR's `load_smplx_file` + `get_smplx_data_offline_fast`: frames of `{joint: (position,
/// wxyz quaternion)}` resampled to `tgt_fps`, the rate, and GMR's height.
#[pyfunction]
#[pyo3(signature = (path, body_model, tgt_fps=30.0, gender=None))]
pub fn load_smplx_gmr<'py>(
    py: Python<'py>,
    path: PathBuf,
    body_model: Option<PathBuf>,
    tgt_fps: f64,
    gender: Option<&str>,
) -> PyResult<(Bound<'py, PyList>, f64, f64)> {
    let g = self::gender(gender)?;
    let human = py
        .detach(|| {
            let motion = SmplMotion::from_path(Path::new(&path))?;
            let model = BodyModels::new(body_model.as_deref()).for_motion(&motion, g)?;
            let human = smpl::gmr::offline_fast(&model, &motion, tgt_fps)?;
            Ok::<_, smpl::Error>((human, smpl::conventions::gmr_height(&motion.betas)))
        })
        .map_err(smpl_err)?;
    let (human, height) = human;
    let frames = PyList::empty(py);
    let nb = human.num_bodies().max(1);
    let rows = human.positions.chunks_exact(nb).zip(human.orientations.chunks_exact(nb));
    for (positions, orientations) in rows {
        let frame = PyDict::new(py);
        for ((name, p), q) in human.body_names.iter().zip(positions).zip(orientations) {
            let pos = numpy::PyArray1::from_slice(py, &[p.x, p.y, p.z]);
            let quat = numpy::PyArray1::from_slice(py, &[q.w, q.i, q.j, q.k]);
            frame.set_item(name, (pos, quat))?;
        }
        frames.append(frame)?;
    }
    Ok((frames, human.fps, height))
}
