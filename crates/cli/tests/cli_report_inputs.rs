//! `retarget report` on other tools' motions: an .npz of `qpos` (+ `fps`), BeyondMimic's
//! .npz, GMR's .pkl and Unitree's .csv. GMR's own G1 walk (`RETARGET_SHARED`) written in
//! three formats gives the same report; bad inputs give clear errors.

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use npz::Array;
use retarget::writers;
use retarget::RobotMotion;

fn retarget(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_retarget")).args(args).output().expect("runs retarget")
}

fn text(out: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cli_report_inputs_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn g1() -> mjcf::Model {
    retarget::shipped::load_robot("unitree_g1").unwrap()
}

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../retarget/tests/data/gmr").join(name)
}

/// `retarget report FILE --robot unitree_g1 --json OUT [extra]`: the JSON, after success.
fn report_json(file: &Path, json: &Path, extra: &[&str]) -> serde_json::Value {
    let mut args = vec![
        "report",
        file.to_str().unwrap(),
        "--robot",
        "unitree_g1",
        "--json",
        json.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let out = retarget(&args);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{}: {stdout}{stderr}", file.display());
    serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap()
}

/// GMR's walk as a motion of our G1 (its `qpos` and `fps`, our model's names).
fn gmr_walk(model: &mjcf::Model) -> Option<RobotMotion> {
    let path = shared::shared_file("reference/gmr_outputs/unitree_g1_lafan1_walk.npz")?;
    let theirs = writers::read_motion_npz(&path).unwrap();
    assert_eq!((theirs.num_frames(), theirs.nq), (7184, 36));
    Some(RobotMotion {
        fps: theirs.fps,
        nq: theirs.nq,
        qpos: theirs.qpos,
        joint_names: RobotMotion::model_joint_names(model),
        body_names: RobotMotion::model_body_names(model),
        targets: None,
        contacts: None,
    })
}

#[test]
fn gmrs_walk_reports_the_same_as_qpos_npz_pickle_and_csv() {
    let model = g1();
    let Some(walk) = gmr_walk(&model) else { return };
    let dir = temp_dir("walk");
    let npz = dir.join("walk.npz");
    let frames = walk.num_frames();
    let qpos = Array::f64(vec![frames, walk.nq], walk.qpos.clone());
    writers::write_npz(&npz, &[("qpos", qpos), ("fps", Array::f64(vec![], vec![walk.fps]))])
        .unwrap();
    let (pkl, csv) = (dir.join("walk.pkl"), dir.join("walk.csv"));
    writers::write_motion(&pkl, &walk, &model, None).unwrap();
    writers::write_motion(&csv, &walk, &model, None).unwrap();

    let from_npz = report_json(&npz, &dir.join("npz.json"), &[]);
    let from_pkl = report_json(&pkl, &dir.join("pkl.json"), &[]);
    let from_csv = report_json(&csv, &dir.join("csv.json"), &["--fps", "30"]);
    assert_eq!(from_npz["frames"], 7184, "{from_npz}");
    assert_eq!(from_npz, from_pkl);
    assert_eq!(from_npz, from_csv);
    // Issue 39: GMR's walk is flagged for self-collision (its hands through its hips in 1,815
    // frames), by our cap and by GMR's own auto_check criterion.
    let flags: Vec<&str> = from_npz["verdict"]["flags"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["name"].as_str().unwrap())
        .collect();
    assert!(
        flags.contains(&"self_collision") && flags.contains(&"gmr_self_collision"),
        "{flags:?}"
    );
    assert_eq!(from_npz["self_collision"]["frames_deep"], 1815);
    // No targets or contacts in these files: said, not measured.
    let (stdout, _) =
        text(&retarget(&["report", csv.to_str().unwrap(), "--robot", "unitree_g1", "--fps", "30"]));
    assert!(stdout.contains("input: Unitree CSV (fps from --fps)"), "{stdout}");
    assert!(stdout.contains("not measured: tracking error: the file has no targets"), "{stdout}");
    assert!(
        stdout.contains("not measured: skating and stance: the file has no source foot contacts"),
        "{stdout}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issue 39: the default solve's walk, the clip of GMR's above, keeps every cap.
#[test]
fn our_default_walk_is_not_flagged() {
    let Some(bvh) = shared::shared_file("data/bvh/lafan1_take_via_bvhtools_test.bvh") else {
        return;
    };
    let dir = temp_dir("default_walk");
    let npz = dir.join("walk.npz");
    let out = retarget(&[
        "--bvh",
        bvh.to_str().unwrap(),
        "--robot",
        "unitree_g1",
        "--human-height",
        "1.75",
        "-o",
        npz.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let rep = report_json(&npz, &dir.join("walk.json"), &[]);
    assert_eq!(rep["verdict"]["ok"], true, "{}", rep["verdict"]);
    let (stdout, _) = text(&retarget(&["report", npz.to_str().unwrap()]));
    assert!(stdout.starts_with("verdict: ok ("), "{stdout}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn beyondmimic_npz_reports_like_its_qpos() {
    let model = g1();
    let Some(mut walk) = gmr_walk(&model) else { return };
    // 300 frames are enough here.
    walk.qpos.truncate(300 * walk.nq);
    let dir = temp_dir("beyondmimic");
    let keep = ["fps", "joint_pos", "joint_vel", "body_pos_w", "body_quat_w"];
    let arrays: Vec<(&str, Array)> = writers::npz_arrays(&walk, &model)
        .unwrap()
        .into_iter()
        .filter(|(k, _)| keep.contains(k))
        .collect();
    let (bm, npz) = (dir.join("bm.npz"), dir.join("ours.npz"));
    writers::write_npz(&bm, &arrays).unwrap();
    writers::write_motion(&npz, &walk, &model, None).unwrap();
    let theirs = report_json(&bm, &dir.join("bm.json"), &[]);
    let ours = report_json(&npz, &dir.join("ours.json"), &[]);
    assert_eq!(theirs["frames"], 300);
    // The root comes through FK (a normalised quaternion): equal to rounding.
    for key in ["min", "mean", "max"] {
        let (a, b) = (theirs["root_height"][key].as_f64(), ours["root_height"][key].as_f64());
        assert!((a.unwrap() - b.unwrap()).abs() < 1e-9, "{key}: {a:?} {b:?}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn pythons_own_pickles_are_reported() {
    for name in ["g1_protocol2.pkl", "g1_protocol4.pkl", "g1_protocol5.pkl"] {
        let out = retarget(&["report", fixture(name).to_str().unwrap(), "--robot", "unitree_g1"]);
        let (stdout, stderr) = text(&out);
        assert!(out.status.success(), "{name}: {stderr}");
        assert!(stdout.contains("\nrobot unitree_g1 · 3 frames at 30 fps"), "{stdout}");
        assert!(stdout.contains("input: GMR pickle (fps from the file)"), "{stdout}");
    }
}

#[test]
fn a_file_without_robot_or_fps_says_what_to_pass() {
    let pkl = fixture("g1_protocol4.pkl");
    let (_, stderr) = text(&retarget(&["report", pkl.to_str().unwrap()]));
    assert_eq!(
        stderr.trim(),
        format!("error: {}: no robot name stored in the file; pass --robot", pkl.display())
    );
    let dir = temp_dir("fps");
    let csv = dir.join("m.csv");
    let mut row: Vec<String> =
        vec!["0".into(), "0".into(), "0.8".into(), "0".into(), "0".into(), "0".into(), "1".into()];
    row.extend(std::iter::repeat_n("0".to_owned(), 29));
    std::fs::write(&csv, format!("{}\n{}\n", row.join(","), row.join(","))).unwrap();
    let out = retarget(&["report", csv.to_str().unwrap(), "--robot", "unitree_g1"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr.contains("stores no frame rate: pass it (`--fps`"), "{stderr}");
    let out = retarget(&["report", pkl.to_str().unwrap(), "--robot", "unitree_g1", "--fps", "60"]);
    let (_, stderr) = text(&out);
    assert!(stderr.contains("the file stores fps 30, but 60 was given"), "{stderr}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_qpos_without_the_root_is_a_clear_error() {
    let dir = temp_dir("width");
    let npz = dir.join("joints.npz");
    let fps = Array::f64(vec![1], vec![30.0]);
    writers::write_npz(&npz, &[("fps", fps), ("qpos", Array::f64(vec![4, 29], vec![0.0; 116]))])
        .unwrap();
    let out = retarget(&["report", npz.to_str().unwrap(), "--robot", "unitree_g1"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        stderr.trim(),
        format!(
            "error: {}: `qpos` has 29 columns, but robot unitree_g1 has nq = 36 (7 root numbers \
             + 29 joint coordinates), so 36 are expected; it looks like the joints without the \
             root's 7 numbers (x y z and a quaternion)",
            npz.display()
        )
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_pickle_calling_os_system_is_refused_unexecuted() {
    let dir = temp_dir("evil");
    let marker = dir.join("executed");
    // What `pickle.dumps` writes for an object whose __reduce__ is (os.system, (command,)).
    let command = format!("touch {}", marker.display());
    let mut evil =
        b"\x80\x04\x95\x00\x00\x00\x00\x00\x00\x00\x00\x8c\x05posix\x8c\x06system\x93".to_vec();
    evil.push(0x8c);
    evil.push(u8::try_from(command.len()).unwrap());
    evil.extend_from_slice(command.as_bytes());
    evil.extend_from_slice(b"\x85R.");
    let pkl = dir.join("evil.pkl");
    std::fs::write(&pkl, &evil).unwrap();
    let out = retarget(&["report", pkl.to_str().unwrap(), "--robot", "unitree_g1"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        stderr.trim(),
        format!(
            "error: {}: byte 26: the pickle calls `posix.system`, which is not a numpy array, \
             dtype or scalar: refused (nothing is executed)",
            pkl.display()
        )
    );
    assert!(!marker.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
