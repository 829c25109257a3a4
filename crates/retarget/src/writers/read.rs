//! Robot motions written by other tools, read for the quality report: [`read_motion`].
//!
//! The format is chosen by content (a zip is an `.npz`, a byte 0x80 starts a pickle), then by
//! extension (`.pkl` / `.pickle`, `.csv`). Every reader gives a [`RobotMotion`] of `model`:
//! joint and body names are the model's, `qpos` is checked against its `nq`, quaternions
//! become w x y z here (`wxyz_from_xyzw`, the only place). Targets and source foot contacts
//! are read where the file has them (our `.npz`) and are `None` otherwise: the report then
//! does not measure tracking, skating and stance.
//!
//! Frame rate: the file's (`fps` in an `.npz` or a pickle) or else the caller's; a caller's
//! rate that disagrees with the file's is an error (the file's timing is part of the motion
//! measured; fix the file rather than override it silently). A CSV stores none.

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use std::collections::BTreeMap;
use std::path::Path;

use ::npz::{Array, Npz};

use super::npz::{read_contacts, read_targets};
use super::root::{root_nq, wxyz_from_xyzw};
use super::unpickle;
use crate::motion::RobotMotion;
use crate::Error;

/// The kind of file a motion was read from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum MotionFormat {
    /// Our `.npz` (see [`super::write_motion`]): `qpos` with the model's joint and body names,
    /// targets and contacts when stored.
    Npz,
    /// An `.npz` with `qpos` (T×nq, MuJoCo's layout) and optionally `fps`, e.g. GMR's own
    /// output; `joint_names`, when present, must be the model's.
    QposNpz,
    /// BeyondMimic's / mjlab's `.npz`: `joint_pos` (T×(nq−7)), `body_pos_w` (T×B×3),
    /// `body_quat_w` (T×B×4, w x y z), `fps`. The root pose is body 0 of `body_pos_w` /
    /// `body_quat_w` (the articulation's root, as both write it), or, when the file has
    /// `body_names`, the body of the model's free joint found there by name. Joints are in
    /// MJCF order (mjlab's), or reordered by the file's `joint_names` when present (Isaac
    /// Lab's order is breadth-first).
    BeyondMimic,
    /// GMR's pickle: a dict with `fps`, `root_pos` (T×3), `root_rot` (T×4, x y z w),
    /// `dof_pos` (T×(nq−7)); `local_body_pos` and `link_body_list` are not needed. Read by
    /// a pickle machine that executes nothing (`unpickle.rs`).
    GmrPickle,
    /// Unitree's CSV: one frame per line, no header, `x, y, z, qx, qy, qz, qw, joints…`; no
    /// frame rate stored.
    UnitreeCsv,
}

impl MotionFormat {
    /// A short name for messages.
    #[must_use]
    pub const fn describe(self) -> &'static str {
        match self {
            MotionFormat::Npz => "retarget .npz",
            MotionFormat::QposNpz => ".npz of qpos",
            MotionFormat::BeyondMimic => "BeyondMimic / mjlab .npz",
            MotionFormat::GmrPickle => "GMR pickle",
            MotionFormat::UnitreeCsv => "Unitree CSV",
        }
    }
}

/// Where a motion's frame rate came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FpsFrom {
    /// Stored in the file.
    File,
    /// The caller's (`fps` of [`read_motion`]), as the file stores none.
    Caller,
}

/// What [`read_motion`] read: the format and where the frame rate came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct MotionSource {
    pub format: MotionFormat,
    pub fps_from: FpsFrom,
}

/// Reads a robot motion of `model` from `path`: our `.npz`, an `.npz` of `qpos`,
/// BeyondMimic's `.npz`, GMR's `.pkl` or Unitree's `.csv` ([`MotionFormat`]). `fps` is used
/// when the file stores no frame rate; one that disagrees with the file's is an error.
pub fn read_motion(
    path: &Path,
    model: &mjcf::Model,
    fps: Option<f64>,
) -> Result<(RobotMotion, MotionSource), Error> {
    let bytes =
        std::fs::read(path).map_err(|source| Error::File { path: path.to_path_buf(), source })?;
    read_motion_bytes(&bytes, path, model, fps)
}

/// [`read_motion`] on a file's bytes; `path` gives the extension and names the file in
/// errors.
pub fn read_motion_bytes(
    bytes: &[u8],
    path: &Path,
    model: &mjcf::Model,
    fps: Option<f64>,
) -> Result<(RobotMotion, MotionSource), Error> {
    let reader = Reader { path, model, fps };
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match (bytes, ext.as_deref()) {
        ([b'P', b'K', ..], _) | (_, Some("npz")) => {
            let arrays = Npz::new(std::io::Cursor::new(bytes), path)?.arrays()?;
            reader.npz(&arrays)
        }
        ([0x80, ..], _) | (_, Some("pkl" | "pickle")) => reader.pickle(bytes),
        (_, Some("csv" | "txt") | None) => reader.csv(bytes),
        (_, Some(other)) => Err(reader.error(format!(
            "unknown motion format .{other} (reads .npz, .pkl and .csv; our .json is not read \
             back)"
        ))),
    }
}

/// A file being read, for one model and the caller's frame rate.
struct Reader<'a> {
    path: &'a Path,
    model: &'a mjcf::Model,
    fps: Option<f64>,
}

impl Reader<'_> {
    fn error(&self, message: String) -> Error {
        Error::Read { path: self.path.to_path_buf(), message }
    }

    fn robot(&self) -> &str {
        if self.model.name.is_empty() {
            "(unnamed)"
        } else {
            &self.model.name
        }
    }

    /// The frame rate: the file's, else the caller's; both must agree.
    fn fps(&self, stored: Option<f64>) -> Result<(f64, FpsFrom), Error> {
        let (fps, from) = match (stored, self.fps) {
            (Some(s), Some(given)) if (s - given).abs() > 1e-9 * s.abs().max(1.0) => {
                return Err(self.error(format!(
                    "the file stores fps {s}, but {given} was given: leave the frame rate out \
                     (or fix the file)"
                )))
            }
            (Some(s), _) => (s, FpsFrom::File),
            (None, Some(given)) => (given, FpsFrom::Caller),
            (None, None) => {
                return Err(self.error(
                    "the file stores no frame rate: pass it (`--fps` on the command line)"
                        .to_owned(),
                ))
            }
        };
        if fps.is_finite() && fps > 0.0 {
            Ok((fps, from))
        } else {
            Err(self.error(format!("fps {fps} is not a positive number")))
        }
    }

    /// Checks a row width of `what` against the model's `nq` (with the root) or its joint
    /// coordinates (`nq − 7`, without).
    fn check_width(&self, what: &str, width: usize, with_root: bool) -> Result<(), Error> {
        let (nq, root) = (self.model.nq, root_nq(self.model));
        let joints = nq - root;
        let expected = if with_root { nq } else { joints };
        if width == expected {
            return Ok(());
        }
        let hint = if with_root && root == 7 && width == joints {
            "; it looks like the joints without the root's 7 numbers (x y z and a quaternion)"
        } else if !with_root && width == nq {
            "; it looks like a whole qpos, root included"
        } else {
            ""
        };
        Err(self.error(format!(
            "{what} has {width} columns, but robot {} has nq = {nq} ({root} root numbers + {joints} \
             joint coordinates), so {expected} are expected{hint}",
            self.robot()
        )))
    }

    fn motion(&self, fps: f64, qpos: Vec<f64>) -> RobotMotion {
        RobotMotion {
            fps,
            nq: self.model.nq,
            qpos,
            joint_names: RobotMotion::model_joint_names(self.model),
            body_names: RobotMotion::model_body_names(self.model),
            targets: None,
            contacts: None,
        }
    }

    /// One frame's qpos from a root pose (w x y z) and the joints, for the model's layout.
    fn frame(&self, out: &mut Vec<f64>, pos: &[f64], wxyz: [f64; 4], joints: &[f64]) {
        if root_nq(self.model) == 7 {
            out.extend_from_slice(pos);
            out.extend_from_slice(&wxyz);
        }
        out.extend_from_slice(joints);
    }
}

// ------------------------------------------------------------------------------------------
// .npz

impl Reader<'_> {
    fn npz(&self, arrays: &BTreeMap<String, Array>) -> Result<(RobotMotion, MotionSource), Error> {
        let stored = match arrays.get("fps") {
            None => None,
            Some(a) => match a.as_f64() {
                Some(&[fps]) => Some(fps),
                _ => return Err(self.error("`fps` is not a single number".to_owned())),
            },
        };
        let (fps, fps_from) = self.fps(stored)?;
        let (mut motion, format) = if arrays.contains_key("qpos") {
            self.qpos_npz(arrays, fps)?
        } else if arrays.contains_key("joint_pos") {
            (self.beyondmimic(arrays, fps)?, MotionFormat::BeyondMimic)
        } else {
            let keys: Vec<&str> = arrays.keys().map(String::as_str).collect();
            return Err(self.error(format!(
                "neither `qpos` nor BeyondMimic's `joint_pos` in the .npz (keys: {})",
                keys.join(", ")
            )));
        };
        let frames = motion.num_frames();
        let err = |m: String| self.error(m);
        if let Some(names) = arrays.get("target_body_names") {
            let get = |key: &str| arrays.get(key).ok_or_else(|| err(format!("no `{key}` array")));
            motion.targets = Some(
                read_targets(names, get("target_pos")?, get("target_quat")?, frames)
                    .map_err(err)?,
            );
        }
        motion.contacts = match (arrays.get("contact_left"), arrays.get("contact_right")) {
            (None, None) => None,
            (Some(l), Some(r)) => Some(read_contacts(l, r, frames).map_err(err)?),
            _ => return Err(err("only one of `contact_left` and `contact_right`".to_owned())),
        };
        Ok((motion, MotionSource { format, fps_from }))
    }

    fn qpos_npz(
        &self,
        arrays: &BTreeMap<String, Array>,
        fps: f64,
    ) -> Result<(RobotMotion, MotionFormat), Error> {
        let qpos = arrays.get("qpos").ok_or_else(|| self.error("no `qpos` array".to_owned()))?;
        let (Some(values), [_, width]) = (qpos.as_f64(), qpos.shape.as_slice()) else {
            return Err(
                self.error(format!("`qpos` is not a 2-D number array (shape {:?})", qpos.shape))
            );
        };
        self.check_width("`qpos`", *width, true)?;
        let model_joints = RobotMotion::model_joint_names(self.model);
        if let Some(names) = arrays.get("joint_names") {
            let names = names.as_strings().ok_or_else(|| self.error("bad `joint_names`".into()))?;
            self.same_joints(names, &model_joints)?;
        }
        let ours = arrays
            .get("body_names")
            .and_then(Array::as_strings)
            .is_some_and(|b| b == RobotMotion::model_body_names(self.model).as_slice());
        let format = if ours && arrays.contains_key("joint_names") {
            MotionFormat::Npz
        } else {
            MotionFormat::QposNpz
        };
        Ok((self.motion(fps, values.to_vec()), format))
    }

    fn same_joints(&self, names: &[String], model_joints: &[String]) -> Result<(), Error> {
        if names == model_joints {
            return Ok(());
        }
        let at = names.iter().zip(model_joints).position(|(a, b)| a != b);
        let detail = match at {
            Some(k) => format!(
                "joint {k} is `{}` in the file, `{}` in the robot",
                names.get(k).map_or("", String::as_str),
                model_joints.get(k).map_or("", String::as_str)
            ),
            None => format!("{} in the file, {} in the robot", names.len(), model_joints.len()),
        };
        Err(self.error(format!(
            "`joint_names` are not robot {}'s: {detail} (a motion of another robot?)",
            self.robot()
        )))
    }

    fn beyondmimic(
        &self,
        arrays: &BTreeMap<String, Array>,
        fps: f64,
    ) -> Result<RobotMotion, Error> {
        let get = |key: &str| {
            arrays.get(key).ok_or_else(|| self.error(format!("BeyondMimic .npz without `{key}`")))
        };
        let (joint_pos, pos, quat) = (get("joint_pos")?, get("body_pos_w")?, get("body_quat_w")?);
        let (Some(jp), [frames, width]) = (joint_pos.as_f64(), joint_pos.shape.as_slice()) else {
            return Err(self.error(format!("`joint_pos` is not 2-D (shape {:?})", joint_pos.shape)));
        };
        self.check_width("`joint_pos`", *width, false)?;
        let (Some(p), Some(q)) = (pos.as_f64(), quat.as_f64()) else {
            return Err(self.error("`body_pos_w` and `body_quat_w` must be numbers".to_owned()));
        };
        let bodies = match pos.shape.as_slice() {
            &[t, b, 3] if t == *frames && b > 0 && quat.shape == [t, b, 4] => b,
            _ => {
                return Err(self.error(format!(
                    "`body_pos_w` {:?} and `body_quat_w` {:?} are not ({frames}, B, 3) and \
                     ({frames}, B, 4)",
                    pos.shape, quat.shape
                )))
            }
        };
        let root = self.root_body_index(arrays.get("body_names"), bodies)?;
        let order = match arrays.get("joint_names") {
            Some(names) => self.joint_order(names)?,
            None => (0..*width).collect(),
        };
        let mut qpos = Vec::with_capacity(frames * self.model.nq);
        for f in 0..*frames {
            let pos = p.get(3 * (f * bodies + root)..3 * (f * bodies + root) + 3);
            let quat = q.get(4 * (f * bodies + root)..4 * (f * bodies + root) + 4);
            let row = jp.get(width * f..width * (f + 1));
            let (Some(pos), Some(&[w, x, y, z]), Some(row)) = (pos, quat, row) else { break };
            let joints: Vec<f64> = order.iter().filter_map(|&k| row.get(k).copied()).collect();
            self.frame(&mut qpos, pos, [w, x, y, z], &joints);
        }
        Ok(self.motion(fps, qpos))
    }

    /// The index of the model's floating-base body in the file's bodies: by name when the
    /// file has `body_names`, else 0.
    fn root_body_index(&self, names: Option<&Array>, bodies: usize) -> Result<usize, Error> {
        let Some(names) = names else { return Ok(0) };
        let names = names.as_strings().ok_or_else(|| self.error("bad `body_names`".to_owned()))?;
        if names.len() != bodies {
            return Err(self.error(format!(
                "{} `body_names` for {bodies} bodies in `body_pos_w`",
                names.len()
            )));
        }
        let root = match self.model.joints.first() {
            Some(j) if j.kind == mjcf::JointType::Free => j.body,
            _ => 1,
        };
        let root_name = self.model.bodies.get(root).map_or("", |b| b.name.as_str());
        names.iter().position(|n| n == root_name).ok_or_else(|| {
            self.error(format!("`body_names` has no `{root_name}`, the robot's floating base"))
        })
    }

    /// Column of the file's `joint_pos` for each of the model's joint coordinates, by name
    /// (every joint but the free one must take one coordinate for a reordering).
    fn joint_order(&self, names: &Array) -> Result<Vec<usize>, Error> {
        let names = names.as_strings().ok_or_else(|| self.error("bad `joint_names`".to_owned()))?;
        let model_joints = RobotMotion::model_joint_names(self.model);
        let one_dof = self.model.joints.iter().all(|j| {
            matches!(
                j.kind,
                mjcf::JointType::Free | mjcf::JointType::Hinge | mjcf::JointType::Slide
            )
        });
        let mut sorted_file: Vec<&String> = names.iter().collect();
        let mut sorted_model: Vec<&String> = model_joints.iter().collect();
        sorted_file.sort();
        sorted_model.sort();
        if names == model_joints.as_slice() || !one_dof || sorted_file != sorted_model {
            self.same_joints(names, &model_joints)?;
            return Ok((0..names.len()).collect());
        }
        Ok(model_joints.iter().filter_map(|j| names.iter().position(|n| n == j)).collect())
    }
}

// ------------------------------------------------------------------------------------------
// GMR's pickle

impl Reader<'_> {
    fn pickle(&self, bytes: &[u8]) -> Result<(RobotMotion, MotionSource), Error> {
        let pickle = unpickle::unpickle(bytes).map_err(|e| self.error(e.to_string()))?;
        let root = pickle.root;
        let key = |k: &str| {
            pickle.dict_get(root, k).ok_or_else(|| {
                let keys = pickle.dict_keys(root);
                self.error(if keys.is_empty() {
                    "the pickle is not a dict with string keys (GMR's motion dict)".to_owned()
                } else {
                    format!("no `{k}` in the pickle's dict (keys: {})", keys.join(", "))
                })
            })
        };
        let stored = match pickle.dict_get(root, "fps") {
            Some(id) if !pickle.is_none(id) => {
                Some(pickle.number(id).map_err(|e| self.error(format!("`fps`: {e}")))?)
            }
            _ => None,
        };
        let (fps, fps_from) = self.fps(stored)?;
        let array = |k: &str, cols: Option<usize>| -> Result<(usize, usize, Vec<f64>), Error> {
            let (shape, data) =
                pickle.array(key(k)?).map_err(|e| self.error(format!("`{k}`: {e}")))?;
            match shape.as_slice() {
                &[t, c] if cols.is_none_or(|n| n == c) => Ok((t, c, data)),
                _ => Err(self.error(format!(
                    "`{k}` has shape {shape:?}, expected (T, {})",
                    cols.map_or("n".to_owned(), |c| c.to_string())
                ))),
            }
        };
        let (t, _, root_pos) = array("root_pos", Some(3))?;
        let (t_rot, _, root_rot) = array("root_rot", Some(4))?;
        let (t_dof, width, dof_pos) = array("dof_pos", None)?;
        self.check_width("`dof_pos`", width, false)?;
        if t_rot != t || t_dof != t {
            return Err(self.error(format!(
                "`root_pos`, `root_rot` and `dof_pos` have {t}, {t_rot} and {t_dof} frames"
            )));
        }
        let mut qpos = Vec::with_capacity(t * self.model.nq);
        for f in 0..t {
            let pos = root_pos.get(3 * f..3 * f + 3);
            let rot = root_rot.get(4 * f..4 * f + 4);
            let joints = dof_pos.get(width * f..width * (f + 1));
            if let (Some(pos), Some(&[x, y, z, w]), Some(joints)) = (pos, rot, joints) {
                self.frame(&mut qpos, pos, wxyz_from_xyzw([x, y, z, w]), joints);
            }
        }
        let format = MotionSource { format: MotionFormat::GmrPickle, fps_from };
        Ok((self.motion(fps, qpos), format))
    }
}

// ------------------------------------------------------------------------------------------
// Unitree's CSV

impl Reader<'_> {
    fn csv(&self, bytes: &[u8]) -> Result<(RobotMotion, MotionSource), Error> {
        let text = std::str::from_utf8(bytes).map_err(|e| {
            let (line, column) = line_column(bytes, e.valid_up_to());
            self.error(format!("{line}:{column}: not UTF-8 text (nor an .npz or a pickle)"))
        })?;
        let (fps, fps_from) = self.fps(None)?;
        let root = root_nq(self.model);
        // The CSV always starts with the root's 7 numbers, even for a fixed-base robot.
        let width = 7 + self.model.nq - root;
        let mut qpos = Vec::new();
        let mut row = Vec::with_capacity(width);
        for (n, line) in text.lines().enumerate() {
            if line.trim().is_empty() {
                continue;
            }
            row.clear();
            let mut column = 1;
            for field in line.split(',') {
                let value = field.trim().parse::<f64>().ok().filter(|v| v.is_finite());
                let Some(value) = value else {
                    return Err(self.error(format!(
                        "{}:{column}: `{}` is not a finite number",
                        n + 1,
                        field.trim()
                    )));
                };
                row.push(value);
                column += field.chars().count() + 1;
            }
            if row.len() != width {
                let what = format!("{}:1: the line", n + 1);
                self.check_width(&what, row.len().saturating_sub(7 - root), true)?;
                return Err(
                    self.error(format!("{what} has {} columns, {width} expected", row.len()))
                );
            }
            if let (Some(&[x, y, z]), Some(&[qx, qy, qz, qw]), Some(joints)) =
                (row.get(..3), row.get(3..7), row.get(7..))
            {
                self.frame(&mut qpos, &[x, y, z], wxyz_from_xyzw([qx, qy, qz, qw]), joints);
            }
        }
        if qpos.is_empty() && self.model.nq > 0 {
            return Err(self.error("no frames (an empty CSV)".to_owned()));
        }
        let format = MotionSource { format: MotionFormat::UnitreeCsv, fps_from };
        Ok((self.motion(fps, qpos), format))
    }
}

/// 1-based line and column (in characters) of byte `at`.
fn line_column(bytes: &[u8], at: usize) -> (usize, usize) {
    let before = bytes.get(..at).unwrap_or(bytes);
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let start = before.iter().rposition(|&b| b == b'\n').map_or(0, |p| p + 1);
    let column = String::from_utf8_lossy(before.get(start..).unwrap_or_default()).chars().count();
    (line, column + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn g1() -> mjcf::Model {
        let path =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots/unitree_g1/unitree_g1.xml");
        mjcf::Model::from_file(&path).unwrap()
    }

    fn fixture(name: &str) -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/gmr").join(name)
    }

    /// The numbers `scripts/make-gmr-pickles` writes, as our qpos (w x y z root).
    fn expected_qpos() -> Vec<f64> {
        let mut q = Vec::new();
        for t in 0..3 {
            q.extend([f64::from(t) / 4.0, -0.5, 0.75, 0.8, 0.0, 0.0, 0.6]);
            q.extend((0..29).map(|j| (f64::from(j) - 14.0) / 64.0 + f64::from(t) / 8.0));
        }
        q
    }

    #[test]
    fn pythons_pickles_read_back_exactly() {
        let model = g1();
        for name in ["g1_protocol2.pkl", "g1_protocol4.pkl", "g1_protocol5.pkl"] {
            let (motion, source) = read_motion(&fixture(name), &model, None).unwrap();
            assert_eq!(
                source,
                MotionSource { format: MotionFormat::GmrPickle, fps_from: FpsFrom::File }
            );
            assert_eq!(motion.fps, 30.0, "{name}");
            assert_eq!(motion.qpos, expected_qpos(), "{name}");
            assert_eq!(motion.joint_names, RobotMotion::model_joint_names(&model));
            assert!(motion.targets.is_none() && motion.contacts.is_none());
        }
        // The same fps given again is fine, another is an error naming both.
        assert!(read_motion(&fixture("g1_protocol4.pkl"), &model, Some(30.0)).is_ok());
        let err = read_motion(&fixture("g1_protocol4.pkl"), &model, Some(50.0)).unwrap_err();
        assert!(err.to_string().contains("stores fps 30, but 50 was given"), "{err}");
    }

    #[test]
    fn our_pickles_and_csvs_read_back() {
        let model = g1();
        let mut qpos = expected_qpos();
        // Our writers store the root as FK sees it: a unit quaternion.
        qpos.iter_mut().skip(3).step_by(36).for_each(|w| *w = 0.8);
        let motion = RobotMotion {
            fps: 50.0,
            nq: model.nq,
            qpos,
            joint_names: RobotMotion::model_joint_names(&model),
            body_names: RobotMotion::model_body_names(&model),
            targets: None,
            contacts: None,
        };
        let dir = std::env::temp_dir().join(format!("retarget-read-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for ext in ["pkl", "csv", "npz"] {
            let path = dir.join(format!("m.{ext}"));
            super::super::write_motion(&path, &motion, &model, None).unwrap();
            let (back, source) = read_motion(&path, &model, Some(50.0)).unwrap();
            let close = back.qpos.iter().zip(&motion.qpos).all(|(a, b)| (a - b).abs() < 1e-12);
            assert!(close && back.qpos.len() == motion.qpos.len(), "{ext}");
            assert_eq!(back.fps, 50.0);
            let expected = match ext {
                "pkl" => MotionFormat::GmrPickle,
                "csv" => MotionFormat::UnitreeCsv,
                _ => MotionFormat::Npz,
            };
            assert_eq!(source.format, expected);
        }
        let err = read_motion(&dir.join("m.csv"), &model, None).unwrap_err();
        assert!(err.to_string().contains("--fps"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn csv_errors_name_line_and_column() {
        let model = g1();
        let path = Path::new("walk.csv");
        let row = |bad: &str| {
            let mut fields: Vec<String> =
                (0..36).map(|k| format!("{}", f64::from(k) / 10.0)).collect();
            fields[6] = "1".to_owned();
            fields[3] = bad.to_owned();
            fields.join(",")
        };
        let text = format!("{}\n{}\n", row("0"), row("x"));
        let err = read_motion_bytes(text.as_bytes(), path, &model, Some(30.0)).unwrap_err();
        assert_eq!(err.to_string(), "walk.csv: 2:11: `x` is not a finite number");
        let short = "0,0,0.8,0,0,0,1,0.1,0.2\n";
        let err = read_motion_bytes(short.as_bytes(), path, &model, Some(30.0)).unwrap_err();
        assert!(
            err.to_string().starts_with("walk.csv: 1:1: the line has 9 columns, but robot"),
            "{err}"
        );
    }

    #[test]
    fn a_qpos_of_joints_only_is_explained() {
        let model = g1();
        let arrays = [
            ("fps", Array::f64(vec![], vec![30.0])),
            ("qpos", Array::f64(vec![2, 29], vec![0.0; 58])),
        ];
        let mut buf = std::io::Cursor::new(Vec::new());
        ::npz::write(&mut buf, &arrays).unwrap();
        let err = read_motion_bytes(buf.get_ref(), Path::new("j.npz"), &model, None).unwrap_err();
        let text = err.to_string();
        assert!(text.starts_with("j.npz: `qpos` has 29 columns, but robot"), "{text}");
        assert!(text.contains("nq = 36 (7 root numbers + 29 joint coordinates)"), "{text}");
        assert!(text.contains("without the root's 7 numbers"), "{text}");
    }

    #[test]
    fn beyondmimic_takes_the_root_from_body_zero() {
        let model = g1();
        let bodies = model.bodies.len() - 1;
        let mut pos = vec![0.0; 2 * bodies * 3];
        let mut quat = vec![0.0; 2 * bodies * 4];
        for t in 0..2 {
            pos[t * bodies * 3..t * bodies * 3 + 3].copy_from_slice(&[t as f64, 2.0, 0.8]);
            for b in 0..bodies {
                quat[(t * bodies + b) * 4] = 1.0;
            }
        }
        let joints: Vec<f64> = (0..58).map(|k| f64::from(k) / 100.0).collect();
        let arrays = [
            ("fps", Array::f64(vec![1], vec![50.0])),
            ("joint_pos", Array::f64(vec![2, 29], joints.clone())),
            ("body_pos_w", Array::f64(vec![2, bodies, 3], pos)),
            ("body_quat_w", Array::f64(vec![2, bodies, 4], quat)),
        ];
        let mut buf = std::io::Cursor::new(Vec::new());
        ::npz::write(&mut buf, &arrays).unwrap();
        let (m, source) =
            read_motion_bytes(buf.get_ref(), Path::new("b.npz"), &model, None).unwrap();
        assert_eq!(source.format, MotionFormat::BeyondMimic);
        assert_eq!(m.frame(1)[..7], [1.0, 2.0, 0.8, 1.0, 0.0, 0.0, 0.0]);
        assert_eq!(m.frame(1)[7..], joints[29..]);
    }
}
