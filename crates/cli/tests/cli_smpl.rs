//! AMASS input through the CLI (issue 31): `retarget smpl info`, `--smplx` with the body
//! model from `--body-model` or `RETARGET_BODY_MODELS`, its default output name, the errors a
//! user meets, and `batch` over an AMASS-style tree (`RETARGET_SHARED`).

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn retarget(args: &[&str], env: Option<&Path>) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_retarget"));
    cmd.args(args).env_remove(smpl::BODY_MODELS_ENV);
    if let Some(dir) = env {
        cmd.env(smpl::BODY_MODELS_ENV, dir);
    }
    cmd.output().unwrap()
}

fn text(out: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr))
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cli_smpl_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The first `frames` frames of an AMASS file, written as AMASS does (a short clip).
fn short_copy(src: &Path, dst: &Path, frames: usize) {
    let motion = smpl::SmplMotion::from_path(src).unwrap().slice(0..frames);
    let w = motion.kind.pose_width();
    let f8 = |v: &[f64]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    let npy = |descr: &str, shape: String, data: Vec<u8>| {
        let header =
            format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}\n");
        let mut out = b"\x93NUMPY\x01\x00".to_vec();
        out.extend_from_slice(&(header.len() as u16).to_le_bytes());
        out.extend_from_slice(header.as_bytes());
        out.extend(data);
        out
    };
    let trans: Vec<f64> = motion.trans.iter().flat_map(|t| [t.x, t.y, t.z]).collect();
    let gender: Vec<u8> = "neutral".chars().flat_map(|c| u32::from(c).to_le_bytes()).collect();
    let rate =
        if motion.kind == smpl::ModelKind::SmplX { "mocap_frame_rate" } else { "mocap_framerate" };
    let members = [
        ("poses", npy("<f8", format!("({frames}, {w})"), f8(&motion.poses))),
        ("trans", npy("<f8", format!("({frames}, 3)"), f8(&trans))),
        ("betas", npy("<f8", format!("({},)", motion.betas.len()), f8(&motion.betas))),
        (rate, npy("<f8", "()".into(), f8(&[motion.fps]))),
        ("gender", npy("<U7", "()".into(), gender)),
    ];
    let mut zip = zip::ZipWriter::new(std::fs::File::create(dst).unwrap());
    for (name, bytes) in members {
        zip.start_file(format!("{name}.npy"), zip::write::SimpleFileOptions::default()).unwrap();
        std::io::Write::write_all(&mut zip, &bytes).unwrap();
    }
    zip.finish().unwrap();
}

#[test]
fn info_retarget_and_errors() {
    let Some(dir) = shared::shared_file("reference/smpl") else { return };
    let models = dir.join("body_models");
    let walk = dir.join("motions/smplx_walk_stageii.npz");
    let out = retarget(&["smpl", "info", walk.to_str().unwrap()], Some(&models));
    let said = text(&out);
    assert!(out.status.success(), "{said}");
    for line in [
        "SMPL-X motion (AMASS)",
        "frames: 7197 at 120 fps",
        "gender: neutral",
        "betas: 16 [0.5000, -0.3000",
        "GMR's subject height: 1.710 m",
        "SMPLX_NEUTRAL.npz (55 joints, 300 shape components)",
        "stature: 1.711 m",
    ] {
        assert!(said.contains(line), "{line}: {said}");
    }

    let work = tmp("retarget");
    let clip = work.join("walk_stageii.npz");
    short_copy(&walk, &clip, 240);
    let out =
        retarget(&["--smplx", clip.to_str().unwrap(), "--robot", "unitree_g1"], Some(&models));
    assert!(out.status.success(), "{}", text(&out));
    let written = work.join("walk_stageii_unitree_g1.npz");
    assert!(text(&out).contains("configs/gmr/smplx_to_g1.json"), "{}", text(&out));
    let motion = retarget::writers::read_motion_npz(&written).unwrap();
    assert_eq!((motion.num_frames(), motion.fps), (240, 120.0));
    let out = retarget(
        &["--smplh", clip.to_str().unwrap(), "--robot", "unitree_g1", "--gmr", "-o"],
        Some(&models),
    );
    assert!(!out.status.success(), "-o needs a value");

    // No body model anywhere; a folder without it; a .pkl in its place.
    let out = retarget(&["--smplx", clip.to_str().unwrap(), "--robot", "unitree_g1"], None);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out).contains("--body-model DIR") && text(&out).contains("RETARGET_BODY_MODELS"));
    let empty = work.join("models");
    std::fs::create_dir_all(empty.join("smplx")).unwrap();
    std::fs::write(empty.join("smplx/SMPLX_NEUTRAL.pkl"), b"\x80\x02}q\x00.").unwrap();
    let out = retarget(
        &[
            "--smplx",
            clip.to_str().unwrap(),
            "--robot",
            "unitree_g1",
            "--body-model",
            empty.to_str().unwrap(),
        ],
        None,
    );
    let said = text(&out);
    assert_eq!(out.status.code(), Some(1), "{said}");
    assert!(said.contains(&empty.join("smplx/SMPLX_NEUTRAL.npz").display().to_string()), "{said}");
    assert!(said.contains("SMPLX_NEUTRAL.pkl is there: a Python pickle"), "{said}");
    assert!(said.contains("smpl-x.is.tue.mpg.de"), "{said}");
    // A BVH given as an AMASS file; an unknown gender.
    let bvh =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../fk/tests/data/skeletons/smpl_metres.bvh");
    let out = retarget(&["--smplx", bvh.to_str().unwrap(), "--robot", "unitree_g1"], Some(&models));
    assert!(text(&out).contains("not an .npz file"), "{}", text(&out));
    let out = retarget(&["smpl", "info", clip.to_str().unwrap(), "--gender", "x"], None);
    assert_eq!(out.status.code(), Some(2));
    std::fs::remove_dir_all(&work).unwrap();
}

#[test]
fn batch_walks_an_amass_tree_and_resumes() {
    let Some(dir) = shared::shared_file("reference/smpl") else { return };
    let models = dir.join("body_models");
    let work = tmp("batch");
    let tree = work.join("AMASS");
    std::fs::create_dir_all(tree.join("CMU/01")).unwrap();
    std::fs::create_dir_all(tree.join("KIT/3")).unwrap();
    short_copy(
        &dir.join("motions/smplx_walk_stageii.npz"),
        &tree.join("CMU/01/a_stageii.npz"),
        120,
    );
    short_copy(&dir.join("motions/smplh_walk_poses.npz"), &tree.join("KIT/3/b_poses.npz"), 60);
    short_copy(&dir.join("motions/smplh_walk_poses.npz"), &tree.join("KIT/3/shape.npz"), 60);
    let out_dir = work.join("out");
    let args = [
        "batch",
        tree.to_str().unwrap(),
        "--robot",
        "unitree_g1",
        "-o",
        out_dir.to_str().unwrap(),
        "--body-model",
        models.to_str().unwrap(),
    ];
    let out = retarget(&args, None);
    let said = text(&out);
    assert!(out.status.success(), "{said}");
    assert!(said.contains("batch: 2 clips"), "shape.npz is not a motion: {said}");
    assert!(said.contains("[1/2]") && said.contains("[2/2]"), "{said}");
    assert!(out_dir.join("CMU/01/a_stageii.npz").is_file());
    assert!(out_dir.join("KIT/3/b_poses.npz").is_file());
    let again = retarget(&args, None);
    assert!(text(&again).contains("converted 0  skipped 2"), "{}", text(&again));
    std::fs::remove_dir_all(&work).unwrap();
}
