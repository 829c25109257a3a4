//! [`SmplMotion`]: an AMASS motion file's parameters (or the same handed over as arrays).
//!
//! AMASS's keys ([`crate::conventions`] keeps the layouts):
//! - SMPL-X stage-ii (`*_stageii.npz`): `root_orient` (N, 3), `pose_body` (N, 63),
//!   `pose_hand` (N, 90), `pose_jaw` (N, 3), `pose_eye` (N, 6), and the same as one `poses`
//!   (N, 165); `trans` (N, 3), `betas`, `gender`, `mocap_frame_rate`, `surface_model_type`;
//! - SMPL+H (`*_poses.npz`): `poses` (N, 156), `trans`, `betas`, `gender`, `mocap_framerate`
//!   (AMASS's spelling there), `dmpls` (soft-tissue, not read).
//!
//! The separate arrays win over `poses` when both are there (GMR reads them). Rotations are
//! axis-angle, local to the parent joint; `trans` is in metres in a Z-up world.

use std::path::{Path, PathBuf};

use nalgebra::Vector3;

use crate::conventions::{Gender, ModelKind};
use crate::Error;
use npz::Npz;

/// One motion: who (model kind, gender, betas), how fast, and every frame's pose.
#[derive(Debug, Clone, PartialEq)]
pub struct SmplMotion {
    /// The file (or a name for arrays handed over), for messages.
    pub source: PathBuf,
    pub kind: ModelKind,
    /// `None` when the file does not say (then it must be given).
    pub gender: Option<Gender>,
    pub fps: f64,
    pub betas: Vec<f64>,
    /// Root translation per frame (m, Z up).
    pub trans: Vec<Vector3<f64>>,
    /// Per frame the full pose in the model's joint order ([`ModelKind::joint_names`]),
    /// axis-angle: `3 × joints` values, hands as written (no hand mean added).
    pub poses: Vec<f64>,
}

/// Arrays read from one file, by key.
struct Keys<'a, R: std::io::Read + std::io::Seek> {
    npz: &'a mut Npz<R>,
}

impl<R: std::io::Read + std::io::Seek> Keys<'_, R> {
    fn err(&self, message: String) -> Error {
        Error::Motion { path: self.npz.path().to_path_buf(), message }
    }

    /// A (N, width) float array (`width` checked when given), finite.
    fn matrix(&mut self, key: &str, width: Option<usize>) -> Result<(usize, Vec<f64>), Error> {
        let (shape, values) = self.npz.floats(key)?;
        let (rows, cols) = match shape.as_slice() {
            [r, c] => (*r, *c),
            _ => {
                return Err(
                    self.err(format!("`{key}` has shape {shape:?}, expected (frames, values)"))
                )
            }
        };
        if let Some(w) = width.filter(|w| *w != cols) {
            return Err(self.err(format!("`{key}` has {cols} values per frame, expected {w}")));
        }
        finite(self.npz.path(), key, &values)?;
        Ok((rows, values))
    }

    fn number(&mut self, key: &str) -> Result<f64, Error> {
        let (_, values) = self.npz.floats(key)?;
        match values.as_slice() {
            [v] => Ok(*v),
            _ => Err(self.err(format!("`{key}` is not one number"))),
        }
    }
}

fn finite(path: &Path, key: &str, values: &[f64]) -> Result<(), Error> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(index) => Err(Error::NonFinite {
            path: path.to_path_buf(),
            key: key.to_owned(),
            index,
            value: values.get(index).copied().unwrap_or(f64::NAN),
        }),
    }
}

impl SmplMotion {
    /// Reads an AMASS motion file (SMPL-X stage-ii or SMPL+H).
    pub fn from_path(path: &Path) -> Result<SmplMotion, Error> {
        let mut npz = Npz::open(path)?;
        read(&mut npz)
    }

    /// [`SmplMotion::from_path`] on the bytes of a file (`name` is used in errors).
    pub fn from_bytes(bytes: &[u8], name: &Path) -> Result<SmplMotion, Error> {
        let mut npz = Npz::new(std::io::Cursor::new(bytes), name)?;
        read(&mut npz)
    }

    /// A motion from its parameters (Python's arrays): `poses` holds `3 × joints` values
    /// per frame in the model's joint order, `trans` 3 per frame.
    pub fn from_parts(
        source: &str,
        kind: ModelKind,
        gender: Option<Gender>,
        fps: f64,
        betas: Vec<f64>,
        trans: &[f64],
        poses: Vec<f64>,
    ) -> Result<SmplMotion, Error> {
        let path = PathBuf::from(source);
        let err = |message: String| Error::Motion { path: path.clone(), message };
        if !(fps.is_finite() && fps > 0.0) {
            return Err(err(format!("frame rate {fps}: expected a positive number")));
        }
        let width = kind.pose_width();
        let frames = trans.len() / 3;
        if trans.len() != 3 * frames || poses.len() != width * frames {
            return Err(err(format!(
                "{} trans values and {} pose values: expected 3 and {width} ({kind}) per frame for the same frames",
                trans.len(),
                poses.len()
            )));
        }
        if poses.is_empty() {
            return Err(err("the motion has no frames".to_owned()));
        }
        finite(&path, "trans", trans)?;
        finite(&path, "poses", &poses)?;
        finite(&path, "betas", &betas)?;
        let trans = trans.chunks_exact(3).map(Vector3::from_column_slice).collect();
        Ok(SmplMotion { source: path, kind, gender, fps, betas, trans, poses })
    }

    #[must_use]
    pub fn num_frames(&self) -> usize {
        self.trans.len()
    }

    /// Seconds from the first to the last frame.
    #[must_use]
    pub fn duration(&self) -> f64 {
        self.num_frames().saturating_sub(1) as f64 / self.fps
    }

    /// Frame `f`'s pose (`3 × joints` values).
    #[must_use]
    pub fn pose(&self, f: usize) -> &[f64] {
        let w = self.kind.pose_width();
        self.poses.get(f * w..(f + 1) * w).unwrap_or_default()
    }

    /// The frames `range` (clamped to the clip) as a motion of their own.
    #[must_use]
    pub fn slice(&self, range: std::ops::Range<usize>) -> SmplMotion {
        let end = range.end.min(self.num_frames());
        let start = range.start.min(end);
        let w = self.kind.pose_width();
        SmplMotion {
            trans: self.trans.get(start..end).unwrap_or_default().to_vec(),
            poses: self.poses.get(start * w..end * w).unwrap_or_default().to_vec(),
            ..self.clone()
        }
    }
}

/// The model kind a file says it is fitted with: `surface_model_type`, else the width of
/// `poses`, else stage-ii's separate arrays (SMPL-X).
fn kind_of<R: std::io::Read + std::io::Seek>(keys: &mut Keys<'_, R>) -> Result<ModelKind, Error> {
    let from_width = |w: usize| match w {
        165 => Some(ModelKind::SmplX),
        156 => Some(ModelKind::SmplH),
        _ => None,
    };
    let width = if keys.npz.has("poses") {
        let shape = keys.npz.header("poses")?.shape;
        Some(shape.get(1).copied().unwrap_or(0))
    } else {
        None
    };
    let stated = if keys.npz.has("surface_model_type") {
        let text = keys.npz.strings("surface_model_type")?.concat().to_ascii_lowercase();
        match text.trim() {
            "smplx" | "smpl-x" => Some(ModelKind::SmplX),
            "smplh" | "smpl+h" => Some(ModelKind::SmplH),
            other => {
                return Err(keys.err(format!(
                    "surface_model_type `{other}`: only SMPL-X and SMPL+H motions are read"
                )))
            }
        }
    } else {
        None
    };
    match (stated, width) {
        (Some(k), Some(w)) if keys.npz.has("pose_body") || from_width(w) == Some(k) => Ok(k),
        (Some(k), Some(w)) => Err(keys.err(format!(
            "surface_model_type says {k} ({} pose values per frame) but `poses` has {w}",
            k.pose_width()
        ))),
        (Some(k), None) => Ok(k),
        (None, Some(w)) => from_width(w).ok_or_else(|| {
            let smpl = if w == 72 { ": an SMPL motion (24 joints), which is not read" } else { "" };
            keys.err(format!(
                "`poses` has {w} values per frame{smpl}; SMPL-X motions have 165, SMPL+H 156"
            ))
        }),
        (None, None) if keys.npz.has("pose_body") => Ok(ModelKind::SmplX),
        (None, None) => Err(npz::Error::Missing {
            path: keys.npz.path().to_path_buf(),
            key: "poses".to_owned(),
            available: keys.npz.keys(),
        }
        .into()),
    }
}

fn read<R: std::io::Read + std::io::Seek>(npz: &mut Npz<R>) -> Result<SmplMotion, Error> {
    let mut keys = Keys { npz };
    let kind = kind_of(&mut keys)?;
    let (frames, trans) = keys.matrix("trans", Some(3))?;
    let poses = if keys.npz.has("root_orient") && keys.npz.has("pose_body") {
        separate_poses(&mut keys, kind, frames)?
    } else {
        let (rows, poses) = keys.matrix("poses", Some(kind.pose_width()))?;
        if rows != frames {
            return Err(keys.err(format!("`poses` has {rows} frames but `trans` {frames}")));
        }
        poses
    };
    if frames == 0 {
        return Err(keys.err("the motion has no frames".to_owned()));
    }
    let fps =
        ["mocap_frame_rate", "mocap_framerate"].into_iter().find(|k| keys.npz.has(k)).ok_or_else(
            || keys.err("no frame rate (`mocap_frame_rate` or `mocap_framerate`)".to_owned()),
        )?;
    let fps = keys.number(fps)?;
    if !(fps.is_finite() && fps > 0.0) {
        return Err(keys.err(format!("frame rate {fps}: expected a positive number")));
    }
    let (bshape, betas) = keys.npz.floats("betas")?;
    // (B,), or (1, B) / (N, B) as some exports write it: the first row (GMR's betas[0]).
    let betas = match bshape.as_slice() {
        [_] => betas,
        [_, b] => betas.get(..*b).unwrap_or_default().to_vec(),
        _ => return Err(keys.err(format!("`betas` has shape {bshape:?}, expected (B,)"))),
    };
    finite(keys.npz.path(), "betas", &betas)?;
    let gender = if keys.npz.has("gender") {
        let text = keys.npz.strings("gender")?.concat();
        Some(Gender::from_name(&text).ok_or_else(|| Error::Gender {
            path: keys.npz.path().to_path_buf(),
            value: text.clone(),
        })?)
    } else {
        None
    };
    let trans = trans.chunks_exact(3).map(Vector3::from_column_slice).collect();
    Ok(SmplMotion { source: keys.npz.path().to_path_buf(), kind, gender, fps, betas, trans, poses })
}

/// Stage-ii's separate arrays in joint order (missing hand, jaw and eye poses are zero).
fn separate_poses<R: std::io::Read + std::io::Seek>(
    keys: &mut Keys<'_, R>,
    kind: ModelKind,
    frames: usize,
) -> Result<Vec<f64>, Error> {
    let parts: &[(&str, usize)] = match kind {
        ModelKind::SmplX => &[
            ("root_orient", 3),
            ("pose_body", 63),
            ("pose_jaw", 3),
            ("pose_eye", 6),
            ("pose_hand", 90),
        ],
        ModelKind::SmplH => &[("root_orient", 3), ("pose_body", 63), ("pose_hand", 90)],
    };
    let width = kind.pose_width();
    let mut poses = vec![0.0; frames * width];
    let mut column = 0;
    for &(key, w) in parts {
        if keys.npz.has(key) || matches!(key, "root_orient" | "pose_body") {
            let (rows, values) = keys.matrix(key, Some(w))?;
            if rows != frames {
                return Err(keys.err(format!("`{key}` has {rows} frames but `trans` {frames}")));
            }
            for (f, row) in values.chunks_exact(w).enumerate() {
                if let Some(dst) = poses.get_mut(f * width + column..f * width + column + w) {
                    dst.copy_from_slice(row);
                }
            }
        }
        column += w;
    }
    Ok(poses)
}
