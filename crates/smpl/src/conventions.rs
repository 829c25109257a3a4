//! The outside world's conventions, written down once: the body models' joint order and
//! names (smplx's `JOINT_NAMES`), where `smplx.create` and AMASS put the model files, where
//! users obtain them, the AMASS motion files' keys and names, and GMR's constants.
//!
//! Joint names are smplx's, so the canonical roles come from the SMPL naming convention in
//! [`fk::conventions`] (`left_hip` = thigh, `left_ankle` = foot, `left_foot` = toe,
//! `left_shoulder` = upper arm, `spine3` = chest): nothing here maps names to roles.

use std::fmt;
use std::path::{Path, PathBuf};

/// Which body model a motion was fitted with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ModelKind {
    /// SMPL-X: 55 joints (22 body, jaw, two eyes, 2 × 15 finger joints), 165 pose values.
    SmplX,
    /// SMPL+H as AMASS distributes it: 52 joints (22 body, 2 × 15 finger joints), 156 pose
    /// values, no hand pose mean.
    SmplH,
}

impl ModelKind {
    /// Joint names in the model's joint order (smplx's names).
    #[must_use]
    pub fn joint_names(self) -> &'static [&'static str] {
        match self {
            ModelKind::SmplX => &SMPLX_JOINTS,
            ModelKind::SmplH => &SMPLH_JOINTS,
        }
    }

    #[must_use]
    pub fn num_joints(self) -> usize {
        self.joint_names().len()
    }

    /// The folder under a body model folder that holds this kind's files.
    #[must_use]
    pub fn folder(self) -> &'static str {
        match self {
            ModelKind::SmplX => "smplx",
            ModelKind::SmplH => "smplh",
        }
    }

    /// Where the model file of `gender` sits under the body model folder `dir`:
    /// `smplx/SMPLX_NEUTRAL.npz` (as `smplx.create(dir, "smplx")` finds it), or AMASS's
    /// `smplh/neutral/model.npz`.
    #[must_use]
    pub fn model_path(self, dir: &Path, gender: Gender) -> PathBuf {
        match self {
            ModelKind::SmplX => {
                dir.join("smplx").join(format!("SMPLX_{}.npz", gender.name().to_ascii_uppercase()))
            }
            ModelKind::SmplH => dir.join("smplh").join(gender.name()).join("model.npz"),
        }
    }

    /// Where users obtain the model (we never ship or download one).
    #[must_use]
    pub fn obtain(self) -> &'static str {
        match self {
            ModelKind::SmplX => {
                "the SMPL-X model (SMPLX_NEUTRAL/MALE/FEMALE.npz) is downloaded, under its \
                 licence, from https://smpl-x.is.tue.mpg.de (\"SMPL-X v1.1 (NPZ+PKL)\"); \
                 put the .npz files in <DIR>/smplx/"
            }
            ModelKind::SmplH => {
                "the SMPL+H model AMASS uses is the \"Extended SMPL+H model\" downloaded, under \
                 its licence, from https://mano.is.tue.mpg.de; unpack it as \
                 <DIR>/smplh/{neutral,male,female}/model.npz"
            }
        }
    }

    /// Pose values per frame of a motion of this kind (3 per joint).
    #[must_use]
    pub fn pose_width(self) -> usize {
        3 * self.num_joints()
    }

    /// Shape components (betas) of a model whose `shapedirs` has `columns` columns: SMPL-X
    /// files hold 300 shape then 100 expression directions (v1.1; 10 + 10 in older files,
    /// as smplx reads them), SMPL+H's are all shape (16 in AMASS's).
    #[must_use]
    pub fn shape_components(self, columns: usize) -> usize {
        match self {
            ModelKind::SmplX if columns >= SMPLX_SHAPE_SPACE + SMPLX_EXPRESSION_SPACE => {
                SMPLX_SHAPE_SPACE
            }
            ModelKind::SmplX => columns.min(10),
            ModelKind::SmplH => columns,
        }
    }
}

impl fmt::Display for ModelKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ModelKind::SmplX => "SMPL-X",
            ModelKind::SmplH => "SMPL+H",
        })
    }
}

/// smplx's `SMPLX.SHAPE_SPACE_DIM` and `EXPRESSION_SPACE_DIM`.
const SMPLX_SHAPE_SPACE: usize = 300;
const SMPLX_EXPRESSION_SPACE: usize = 100;

/// The body model's gender (AMASS's `gender` key).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Gender {
    Neutral,
    Male,
    Female,
}

impl Gender {
    /// `neutral`, `male`, `female`: AMASS's spelling, and the folder names of SMPL+H.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Gender::Neutral => "neutral",
            Gender::Male => "male",
            Gender::Female => "female",
        }
    }

    /// AMASS's values, case and surrounding blanks ignored; old files write `b'male'`.
    #[must_use]
    pub fn from_name(text: &str) -> Option<Gender> {
        let t = text.trim().trim_start_matches("b'").trim_end_matches('\'').to_ascii_lowercase();
        match t.as_str() {
            "neutral" => Some(Gender::Neutral),
            "male" => Some(Gender::Male),
            "female" => Some(Gender::Female),
            _ => None,
        }
    }
}

impl fmt::Display for Gender {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The environment variable that names the body model folder when no `--body-model` is given.
pub const BODY_MODELS_ENV: &str = "RETARGET_BODY_MODELS";

/// The 22 body joints shared by SMPL-X and SMPL+H.
const BODY: [&str; 22] = [
    "pelvis",
    "left_hip",
    "right_hip",
    "spine1",
    "left_knee",
    "right_knee",
    "spine2",
    "left_ankle",
    "right_ankle",
    "spine3",
    "left_foot",
    "right_foot",
    "neck",
    "left_collar",
    "right_collar",
    "head",
    "left_shoulder",
    "right_shoulder",
    "left_elbow",
    "right_elbow",
    "left_wrist",
    "right_wrist",
];

/// Finger joints of one hand in smplx's order (index, middle, pinky, ring, thumb; 1 at the
/// knuckle).
macro_rules! hand {
    ($s:literal) => {
        [
            concat!($s, "_index1"),
            concat!($s, "_index2"),
            concat!($s, "_index3"),
            concat!($s, "_middle1"),
            concat!($s, "_middle2"),
            concat!($s, "_middle3"),
            concat!($s, "_pinky1"),
            concat!($s, "_pinky2"),
            concat!($s, "_pinky3"),
            concat!($s, "_ring1"),
            concat!($s, "_ring2"),
            concat!($s, "_ring3"),
            concat!($s, "_thumb1"),
            concat!($s, "_thumb2"),
            concat!($s, "_thumb3"),
        ]
    };
}

const LEFT_HAND: [&str; 15] = hand!("left");
const RIGHT_HAND: [&str; 15] = hand!("right");

// Evaluated at compile time: an index out of range there is a compile error, not a panic.
#[allow(clippy::indexing_slicing)]
const fn concat<const N: usize>(parts: [&[&'static str]; 4]) -> [&'static str; N] {
    let mut out = [""; N];
    let mut k = 0;
    let mut p = 0;
    while p < parts.len() {
        let mut i = 0;
        while i < parts[p].len() {
            out[k] = parts[p][i];
            k += 1;
            i += 1;
        }
        p += 1;
    }
    out
}

/// smplx's `JOINT_NAMES[:55]`: SMPL-X's joints in model order.
pub const SMPLX_JOINTS: [&str; 55] =
    concat([&BODY, &["jaw", "left_eye_smplhf", "right_eye_smplhf"], &LEFT_HAND, &RIGHT_HAND]);

/// SMPL+H's joints in model order (body, then the hands as in SMPL-X).
pub const SMPLH_JOINTS: [&str; 52] = concat([&BODY, &[], &LEFT_HAND, &RIGHT_HAND]);

/// The joints of the left and right hand poses: 25..40 and 40..55 in SMPL-X, 22..37 and
/// 37..52 in SMPL+H.
#[must_use]
pub fn hand_joints(kind: ModelKind) -> [std::ops::Range<usize>; 2] {
    let first = match kind {
        ModelKind::SmplX => 25,
        ModelKind::SmplH => 22,
    };
    [first..first + 15, first + 15..first + 30]
}

/// Whether a file name is an AMASS motion: `*_stageii.npz` (SMPL-X) or `*_poses.npz`
/// (SMPL+H). AMASS's other files, `shape.npz` (a subject's betas) and `*_stagei.npz`
/// (MoSh's first stage), are not motions.
#[must_use]
pub fn is_motion_file_name(path: &Path) -> bool {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("").to_ascii_lowercase();
    name.ends_with("_stageii.npz") || name.ends_with("_poses.npz")
}

/// GMR's subject height for an SMPL-X motion (`utils/smpl.py`: `1.66 + 0.1 * betas[0]`).
#[must_use]
pub fn gmr_height(betas: &[f64]) -> f64 {
    1.66 + 0.1 * betas.first().copied().unwrap_or(0.0)
}

/// The frame rate GMR's `smplx_to_robot.py` resamples to (`tgt_fps`).
pub const GMR_FPS: f64 = 30.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joint_names_follow_smplx() {
        assert_eq!(SMPLX_JOINTS[22], "jaw");
        assert_eq!(SMPLX_JOINTS[25], "left_index1");
        assert_eq!(SMPLX_JOINTS[54], "right_thumb3");
        assert_eq!(SMPLH_JOINTS[22], "left_index1");
        assert_eq!(SMPLH_JOINTS[51], "right_thumb3");
        assert_eq!(ModelKind::SmplX.pose_width(), 165);
        assert_eq!(ModelKind::SmplH.pose_width(), 156);
        for kind in [ModelKind::SmplX, ModelKind::SmplH] {
            let [l, r] = hand_joints(kind);
            assert_eq!(kind.joint_names()[l.start], "left_index1");
            assert_eq!(kind.joint_names()[r.start], "right_index1");
            assert_eq!(r.end, kind.num_joints());
        }
    }

    #[test]
    fn layouts_and_names() {
        let dir = Path::new("/m");
        assert_eq!(
            ModelKind::SmplX.model_path(dir, Gender::Female),
            Path::new("/m/smplx/SMPLX_FEMALE.npz")
        );
        assert_eq!(
            ModelKind::SmplH.model_path(dir, Gender::Neutral),
            Path::new("/m/smplh/neutral/model.npz")
        );
        assert_eq!(Gender::from_name(" Male "), Some(Gender::Male));
        assert_eq!(Gender::from_name("b'female'"), Some(Gender::Female));
        assert_eq!(Gender::from_name("other"), None);
        assert!(is_motion_file_name(Path::new("a/B_stageii.npz")));
        assert!(is_motion_file_name(Path::new("01_01_poses.npz")));
        assert!(!is_motion_file_name(Path::new("a/shape.npz")));
        assert!(!is_motion_file_name(Path::new("a/neutral_stagei.npz")));
        assert_eq!(ModelKind::SmplX.shape_components(400), 300);
        assert_eq!(ModelKind::SmplX.shape_components(20), 10);
        assert_eq!(ModelKind::SmplH.shape_components(16), 16);
        assert!((gmr_height(&[0.5, 1.0]) - 1.71).abs() < 1e-12);
    }
}
