//! The main job: `retarget --bvh FILE --robot NAME [-o OUT] [--config C] [--human-height H]`.
//! Uses the first 40 frames of the shared LAFAN1 walk take (`RETARGET_SHARED`).

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn retarget(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_retarget")).args(args).output().expect("runs retarget")
}

fn text(out: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A fresh temporary folder for one test.
fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cli_retarget_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The walk take cut to its first `frames` frames, written to `dir/walk.bvh`.
fn short_walk(dir: &Path, frames: usize) -> Option<PathBuf> {
    let source = shared::shared_file("data/bvh/lafan1_take_via_bvhtools_test.bvh")?;
    let full = std::fs::read_to_string(source).unwrap();
    let (head, motion) = full.split_once("MOTION").unwrap();
    let mut lines = motion.lines().filter(|l| !l.trim().is_empty());
    let _frames_line = lines.next().unwrap();
    let frame_time = lines.next().unwrap();
    let rows: Vec<&str> = lines.take(frames).collect();
    let text = format!("{head}MOTION\nFrames: {frames}\n{frame_time}\n{}\n", rows.join("\n"));
    let path = dir.join("walk.bvh");
    std::fs::write(&path, text).unwrap();
    Some(path)
}

#[test]
fn writes_npz_next_to_the_input_and_prints_a_summary() {
    let dir = temp_dir("npz");
    let Some(bvh) = short_walk(&dir, 40) else { return };
    let out = retarget(&["--bvh", bvh.to_str().unwrap(), "--robot", "unitree_g1"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.contains("40 frames at 30.000 fps"), "{stdout}");
    assert!(
        stdout.contains(
            "inferred: +Y up, centimetres (0.01 m/unit), 21 roles by LAFAN1 / Mixamo / HumanIK"
        ),
        "{stdout}"
    );
    assert!(stdout.contains("left_ankle_roll_link"), "{stdout}");
    assert!(stdout.contains("joint limits:"), "{stdout}");
    let npz = dir.join("walk.npz");
    assert!(npz.is_file());
    assert!(stdout.contains(&format!("wrote {}", npz.display())), "{stdout}");
}

#[test]
fn output_format_from_extension_and_height_option() {
    let dir = temp_dir("json");
    let Some(bvh) = short_walk(&dir, 10) else { return };
    let json = dir.join("out.json");
    let out = retarget(&[
        "--bvh",
        bvh.to_str().unwrap(),
        "--robot",
        "unitree_h1",
        "-o",
        json.to_str().unwrap(),
        "--human-height",
        "1.75",
    ]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.contains("subject height 1.750 m (given)"), "{stdout}");
    let value: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert!(value.is_object());
}

#[test]
fn mjcf_path_without_config_derives_one_and_init_writes_it() {
    let dir = temp_dir("path");
    let Some(bvh) = short_walk(&dir, 5) else { return };
    let xml = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots/unitree_g1/unitree_g1.xml");
    let out = retarget(&["--bvh", bvh.to_str().unwrap(), "--robot", xml.to_str().unwrap()]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.contains("config derived from the roles of unitree_g1"), "{stdout}");
    // The shipped robot keeps GMR's tuned config on a LAFAN1 skeleton.
    let out = retarget(&["--bvh", bvh.to_str().unwrap(), "--robot", "unitree_g1"]);
    let (stdout, _) = text(&out);
    assert!(stdout.contains("configs/gmr/bvh_lafan1_to_g1.json (tuned"), "{stdout}");
    // `robot init` writes a role-named config; --config binds it to the skeleton.
    let config = dir.join("g1.json");
    let out = retarget(&["robot", "init", xml.to_str().unwrap(), "-o", config.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out).1);
    let written = std::fs::read_to_string(&config).unwrap();
    assert!(
        written.contains("\"left_thigh\": [") || written.contains("[\"left_thigh\","),
        "{written}"
    );
    let out = retarget(&[
        "--bvh",
        bvh.to_str().unwrap(),
        "--robot",
        xml.to_str().unwrap(),
        "--config",
        config.to_str().unwrap(),
        "-o",
        dir.join("o.npz").to_str().unwrap(),
    ]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.contains("(role-named), bound to the skeleton"), "{stdout}");
    // Against a skeleton: its joint names.
    let out = retarget(&[
        "robot",
        "init",
        "booster_t1_29dof",
        "--bvh",
        bvh.to_str().unwrap(),
        "-o",
        config.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", text(&out).1);
    assert!(std::fs::read_to_string(&config).unwrap().contains("\"LeftUpLeg\""));
}

#[test]
fn robot_info_prints_the_roles_and_refuses_a_wheeled_robot() {
    let out = retarget(&["robot", "info", "unitree_g1"]);
    let (stdout, _) = text(&out);
    assert!(out.status.success());
    assert!(stdout.contains("left_thigh       left_hip_yaw_link"), "{stdout}");
    assert!(stdout.contains("left  sole       left_ankle_roll_link"), "{stdout}");
    let wheeled =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../retarget/tests/data/robots/wheeled.xml");
    let out = retarget(&["robot", "info", wheeled.to_str().unwrap()]);
    let (stdout, _) = text(&out);
    assert!(
        stdout.contains("not recognised: robot `small` is not a two-armed biped: wheeled"),
        "{stdout}"
    );
}

#[test]
fn bad_config_is_reported_with_its_position() {
    let dir = temp_dir("badcfg");
    let Some(bvh) = short_walk(&dir, 5) else { return };
    let config = dir.join("bad.json");
    std::fs::write(&config, "{\n  \"robot_root_name\": 3\n}\n").unwrap();
    let out = retarget(&[
        "--bvh",
        bvh.to_str().unwrap(),
        "--robot",
        "unitree_g1",
        "--config",
        config.to_str().unwrap(),
    ]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr.contains(&format!("{}:2:", config.display())), "{stderr}");
}

#[test]
fn fps_resamples_the_output_and_unknown_robots_are_named() {
    let dir = temp_dir("fps");
    if let Some(bvh) = short_walk(&dir, 31) {
        let csv = dir.join("walk60.csv");
        let args = ["--bvh", bvh.to_str().unwrap(), "--robot", "unitree_g1", "--fps", "60"];
        let out = retarget(&[&args[..], &["-o", csv.to_str().unwrap()]].concat());
        assert!(out.status.success(), "{}", text(&out).1);
        // 31 frames at 30 fps span 1 s: 61 frames at 60 fps.
        let rows = std::fs::read_to_string(&csv).unwrap().lines().count();
        assert_eq!(rows, 61);
        let bad = retarget(&[&args[..4], &["--fps", "0", "-o", csv.to_str().unwrap()]].concat());
        assert_eq!(bad.status.code(), Some(1));
        assert!(text(&bad).1.contains("--fps"), "{}", text(&bad).1);
    }
    // An unknown robot is reported by the robot lookup (with a config that exists, so the
    // config cannot be what fails): the shipped robots are listed, the nearest name offered.
    let config =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/gmr/bvh_lafan1_to_g1.json");
    for extra in [&["--config", config.to_str().unwrap()][..], &[]] {
        let args = [&["--bvh", "x.bvh", "--robot", "no_such_robot"][..], extra].concat();
        let out = retarget(&args);
        assert_eq!(out.status.code(), Some(1));
        let stderr = text(&out).1;
        assert!(
            stderr.starts_with("error: unknown robot \"no_such_robot\": not a shipped robot (berkeley_humanoid_lite, booster_t1_29dof, engineai_pm01, fourier_n1, pal_talos, pnd_adam_lite, stanford_toddy, unitree_g1, unitree_g1_with_hands, unitree_h1"),
            "{extra:?}: {stderr}"
        );
        assert!(!stderr.contains("did you mean"), "{stderr}");
    }
    let out = retarget(&["--bvh", "x.bvh", "--robot", "unitre_g1"]);
    assert!(text(&out).1.trim_end().ends_with("; did you mean unitree_g1?"), "{}", text(&out).1);
    let out = retarget(&["--bvh", "x.bvh"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out).1.contains("--robot <ROBOT>"), "{}", text(&out).1);
}

/// The G1 URDF (shared reference) as `--robot`, with the G1's LAFAN1 config: its body names
/// are the MJCF G1's (the config names only links with joints, none of the merged ones), and
/// GMR's solve (`--gmr`) on it agrees with the one on our MJCF G1 wherever the URDF's wider
/// joint ranges do not change the solution; the default solve runs on it too.
#[test]
fn urdf_robot_retargets_with_the_g1_config() {
    let dir = temp_dir("urdf");
    let Some(bvh) = short_walk(&dir, 40) else { return };
    let Some(urdf) =
        shared::shared_file("reference/robots/unitree_g1/g1_custom_collision_29dof.urdf")
    else {
        return;
    };
    let config =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/gmr/bvh_lafan1_to_g1.json");
    let mut outputs = Vec::new();
    for (robot, name) in [(urdf.to_str().unwrap(), "urdf.npz"), ("unitree_g1", "mjcf.npz")] {
        let path = dir.join(name);
        let out = retarget(&[
            "--bvh",
            bvh.to_str().unwrap(),
            "--robot",
            robot,
            "--config",
            config.to_str().unwrap(),
            "-o",
            path.to_str().unwrap(),
            "--gmr",
        ]);
        assert!(out.status.success(), "{robot}: {}", text(&out).1);
        outputs.push(retarget::writers::read_motion_npz(&path).unwrap());
    }
    // The default solve runs on the URDF too (its speed limits and collision geometry).
    let path = dir.join("urdf_default.npz");
    let out = retarget(&[
        "--bvh",
        bvh.to_str().unwrap(),
        "--robot",
        urdf.to_str().unwrap(),
        "--config",
        config.to_str().unwrap(),
        "-o",
        path.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "default solve on the URDF: {}", text(&out).1);
    let (urdf_motion, mjcf_motion) = (&outputs[0], &outputs[1]);
    assert_eq!(urdf_motion.nq, 36);
    assert_eq!(urdf_motion.joint_names, mjcf_motion.joint_names);
    let mut diffs: Vec<f64> =
        urdf_motion.qpos.iter().zip(&mjcf_motion.qpos).map(|(a, b)| (a - b).abs()).collect();
    diffs.sort_by(f64::total_cmp);
    let median = diffs[diffs.len() / 2];
    assert!(median < 1e-6, "median |qpos difference| {median:e}");
}
