//! The body models and motions of `../shared/reference/smpl` (synthetic models in the real
//! files' layouts, LAFAN1-derived AMASS motions): our forward kinematics against smplx's
//! (`fk_oracle`), GMR's human data against GMR's own (`gmr_outputs`), and the errors a user
//! meets. Reads `$RETARGET_SHARED` (see tests/support/shared.rs).

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::{Path, PathBuf};

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use npz::Npz;
use smpl::{BodyModel, BodyModels, Error, Gender, ModelKind, SmplMotion};

fn reference() -> Option<PathBuf> {
    shared::shared_dir().map(|d| d.join("reference/smpl"))
}

fn floats(path: &Path, key: &str) -> (Vec<usize>, Vec<f64>) {
    Npz::open(path).unwrap().floats(key).unwrap()
}

fn quat(q: &[f64]) -> UnitQuaternion<f64> {
    UnitQuaternion::new_normalize(Quaternion::new(q[0], q[1], q[2], q[3]))
}

/// Largest position (m) and rotation (rad) differences between `human` (frames `frames`)
/// and the reference arrays (`(K, J, 3)` positions, `(K, J, 4)` w-first quaternions).
fn max_diff(human: &fk::HumanMotion, frames: &[usize], pos: &[f64], rot: &[f64]) -> (f64, f64) {
    let nb = human.num_bodies();
    let (mut dp, mut dr) = (0.0_f64, 0.0_f64);
    for (k, &f) in frames.iter().enumerate() {
        for b in 0..nb {
            let i = k * nb + b;
            let p = Vector3::new(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]);
            dp = dp.max((human.position(f, b) - p).amax());
            dr = dr.max(human.orientation(f, b).angle_to(&quat(&rot[4 * i..4 * i + 4])));
        }
    }
    (dp, dr)
}

fn oracle(kind: ModelKind, file: &str, model: &str) {
    let Some(dir) = reference() else { return };
    let oracle = dir.join("fk_oracle").join(file);
    let (shape, pos) = floats(&oracle, "joints_pos");
    let (_, rot) = floats(&oracle, "joints_quat_wxyz");
    let (_, frames) = Npz::open(&oracle).unwrap().ints("frames").unwrap();
    let names = Npz::open(&oracle).unwrap().strings("joint_names").unwrap();
    let source = Npz::open(&oracle).unwrap().strings("source_file").unwrap().concat();
    assert_eq!(names, kind.joint_names());
    let model = BodyModel::from_path(&dir.join(model), None).unwrap();
    assert_eq!(model.kind, kind);
    let motion = SmplMotion::from_path(&dir.join("motions").join(&source)).unwrap();
    assert_eq!(motion.kind, kind);
    let frames: Vec<usize> = frames.iter().map(|&f| f as usize).collect();
    assert_eq!(frames, (0..shape[0]).collect::<Vec<_>>());
    let slice = motion.slice(0..shape[0]);
    let human = smpl::forward(&model, &slice).unwrap();
    assert_eq!(human.body_names, kind.joint_names());
    let (dp, dr) = max_diff(&human, &frames, &pos, &rot);
    eprintln!(
        "{kind} FK vs smplx ({} frames): max position {dp:.2e} m, max rotation {:.2e}°",
        frames.len(),
        dr.to_degrees()
    );
    assert!(dp < 1e-5, "positions differ by {dp} m");
    assert!(dr < 1e-5_f64.to_radians().max(2e-6), "rotations differ by {dr} rad");
}

#[test]
fn smplx_fk_matches_smplx() {
    oracle(ModelKind::SmplX, "smplx_walk_fk.npz", "body_models/smplx/SMPLX_NEUTRAL.npz");
}

#[test]
fn smplh_fk_matches_smplx() {
    oracle(ModelKind::SmplH, "smplh_walk_fk.npz", "body_models/smplh/neutral/model.npz");
}

/// GMR's human data (its `get_smplx_data_offline_fast` on the whole 120 fps walk) against
/// what GMR recorded, float32 from smplx.
#[test]
fn gmr_human_data_matches_gmr() {
    let Some(dir) = reference() else { return };
    for motion_name in ["walk", "jumps"] {
        let out = dir.join(format!("gmr_outputs/gmr_unitree_g1_smplx_{motion_name}.npz"));
        let (shape, pos) = floats(&out, "human_pos");
        let (_, rot) = floats(&out, "human_quat_wxyz");
        let (_, fps) = floats(&out, "fps");
        let (_, height) = floats(&out, "human_height");
        let models = BodyModels::new(Some(&dir.join("body_models")));
        let motion =
            SmplMotion::from_path(&dir.join(format!("motions/smplx_{motion_name}_stageii.npz")))
                .unwrap();
        let model = models.for_motion(&motion, None).unwrap();
        let human = smpl::gmr::offline_fast(&model, &motion, 30.0).unwrap();
        assert_eq!(human.num_frames, shape[0]);
        assert!((human.fps - fps[0]).abs() < 1e-12, "{} vs {}", human.fps, fps[0]);
        assert!((smpl::conventions::gmr_height(&motion.betas) - height[0]).abs() < 1e-12);
        let frames: Vec<usize> = (0..shape[0]).collect();
        let (dp, dr) = max_diff(&human, &frames, &pos, &rot);
        eprintln!(
            "GMR human data, {motion_name}: {} frames, max position {dp:.2e} m, max rotation {:.2e}°",
            frames.len(),
            dr.to_degrees()
        );
        assert!(dp < 1e-5, "positions differ by {dp} m");
        assert!(dr < 1e-5, "rotations differ by {dr} rad");
    }
}

#[test]
fn the_stature_and_the_roles_are_the_models() {
    let Some(dir) = reference() else { return };
    let models = BodyModels::new(Some(&dir.join("body_models")));
    let motion = SmplMotion::from_path(&dir.join("motions/smplh_walk_poses.npz")).unwrap();
    assert_eq!(
        (motion.kind, motion.gender, motion.fps),
        (ModelKind::SmplH, Some(Gender::Neutral), 60.0)
    );
    let model = models.for_motion(&motion, None).unwrap();
    // The README: 1.66 m at betas 0, 1.7106 m at the files' betas; male 1.75 / 1.8006.
    assert!((model.stature(&[]) - 1.66).abs() < 2e-3, "{}", model.stature(&[]));
    assert!((model.stature(&motion.betas) - 1.7106).abs() < 2e-3);
    let male = models.get(ModelKind::SmplX, Gender::Male).unwrap();
    assert!((male.stature(&motion.betas) - 1.8006).abs() < 2e-3);
    let clip = smpl::clip(&model, &motion.slice(0..600)).unwrap();
    let roles = clip.roles();
    for (role, joint) in [
        (fk::Role::Pelvis, "pelvis"),
        (fk::Role::Chest, "spine3"),
        (fk::Role::LeftThigh, "left_hip"),
        (fk::Role::LeftShin, "left_knee"),
        (fk::Role::LeftFoot, "left_ankle"),
        (fk::Role::LeftToe, "left_foot"),
        (fk::Role::RightUpperArm, "right_shoulder"),
        (fk::Role::RightHand, "right_wrist"),
        (fk::Role::Head, "head"),
    ] {
        assert_eq!(roles.get(&role).map(String::as_str), Some(joint), "{role}");
    }
    // The motions' soles touch z = 0 (README: lowest heel/ball vertex of the clip at 0).
    assert!(clip.ground.abs() < 0.03, "ground {}", clip.ground);
}

#[test]
fn errors_name_the_file_and_what_to_do() {
    let Some(dir) = reference() else { return };
    let tmp = std::env::temp_dir().join(format!("smpl-errors-{}", std::process::id()));
    std::fs::create_dir_all(tmp.join("smplx")).unwrap();
    // Missing model: the exact path expected and where to get it.
    let err = BodyModel::from_folder(&tmp, ModelKind::SmplX, Gender::Male).unwrap_err();
    let text = err.to_string();
    let expected = tmp.join("smplx/SMPLX_MALE.npz");
    assert!(text.contains(&expected.display().to_string()), "{text}");
    assert!(text.contains("smpl-x.is.tue.mpg.de"), "{text}");
    let err = BodyModel::from_folder(&tmp, ModelKind::SmplH, Gender::Female).unwrap_err();
    assert!(err.to_string().contains(&tmp.join("smplh/female/model.npz").display().to_string()));
    assert!(err.to_string().contains("mano.is.tue.mpg.de"), "{err}");
    // A .pkl beside it: named, and the .npz to use instead.
    std::fs::write(tmp.join("smplx/SMPLX_MALE.pkl"), b"\x80\x02}q\x00.").unwrap();
    let err = BodyModel::from_folder(&tmp, ModelKind::SmplX, Gender::Male).unwrap_err();
    assert!(err.to_string().contains("SMPLX_MALE.pkl is there: a Python pickle"), "{err}");
    let err = BodyModel::from_path(&tmp.join("smplx/SMPLX_MALE.pkl"), None).unwrap_err();
    assert!(matches!(err, Error::PickleModel { .. }));
    assert!(err.to_string().contains("SMPLX_MALE.npz"), "{err}");
    // Wrong type: a motion file given as the model, a model given as the motion.
    let walk = dir.join("motions/smplx_walk_stageii.npz");
    let err = BodyModel::from_path(&walk, None).unwrap_err().to_string();
    assert!(err.contains("no `J_regressor` array"), "{err}");
    let neutral = dir.join("body_models/smplx/SMPLX_NEUTRAL.npz");
    let err = SmplMotion::from_path(&neutral).unwrap_err().to_string();
    assert!(err.contains("SMPLX_NEUTRAL.npz") && err.contains("no `poses` array"), "{err}");
    let err = BodyModel::from_path(&dir.join("README.md"), None).unwrap_err().to_string();
    assert!(err.contains("not an .npz file"), "{err}");
    // Truncated files: errors, never a panic, whatever the cut.
    let bytes = std::fs::read(&walk).unwrap();
    for cut in [0, 10, 100, 1000, bytes.len() / 3, bytes.len() - 30] {
        let err = SmplMotion::from_bytes(&bytes[..cut], Path::new("cut.npz")).unwrap_err();
        assert!(err.to_string().starts_with("cut.npz"), "{err}");
    }
    let model_bytes = std::fs::read(&neutral).unwrap();
    let cut = tmp.join("smplx/SMPLX_NEUTRAL.npz");
    std::fs::write(&cut, &model_bytes[..model_bytes.len() / 2]).unwrap();
    assert!(BodyModel::from_path(&cut, None).is_err());
    // A SMPL-X motion with an SMPL+H model; too many betas.
    let smplh = BodyModels::new(Some(&dir.join("body_models/smplh/neutral/model.npz")));
    let motion = SmplMotion::from_path(&walk).unwrap();
    let err = smplh.for_motion(&motion, None).unwrap_err().to_string();
    assert!(
        err.contains(
            "a SMPL-X motion (165 pose values per frame) needs a SMPL-X body model, not SMPL+H"
        ),
        "{err}"
    );
    let mut long = SmplMotion::from_path(&dir.join("motions/smplh_walk_poses.npz")).unwrap();
    long.betas = vec![0.1; 17];
    let models = BodyModels::new(Some(&dir.join("body_models")));
    let err = models.for_motion(&long, None).unwrap_err();
    assert!(matches!(err, Error::TooManyBetas { betas: 17, components: 16, .. }), "{err}");
    // No folder at all.
    let err = BodyModels::new(None).get(ModelKind::SmplX, Gender::Neutral);
    if std::env::var_os(smpl::BODY_MODELS_ENV).is_none() {
        assert!(err.unwrap_err().to_string().contains("--body-model DIR"));
    }
    std::fs::remove_dir_all(&tmp).unwrap();
}
