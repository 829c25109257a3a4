//! `retarget view`: the pages it writes, read back as data (the browser side is tested by
//! `scripts/browser-test` in headless Chromium).

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

fn retarget(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_retarget")).args(args).output().expect("run retarget")
}

fn sample(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/samples").join(name)
}

fn tmp(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_view");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// Runs `retarget view ARGS -o OUT` and returns the page and its embedded scene.
fn view(args: &[&str], out: &Path) -> (String, Value) {
    let mut all: Vec<&str> = vec!["view"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["-o", out.to_str().unwrap()]);
    let result = retarget(&all);
    assert!(
        result.status.success(),
        "retarget {all:?}: {}",
        String::from_utf8_lossy(&result.stderr)
    );
    let html = std::fs::read_to_string(out).unwrap();
    let start = html.find(r#"<script type="application/json" id="scene">"#).expect("scene block");
    let json = &html[start..];
    let json = &json[json.find('>').unwrap() + 1..json.find("</script>").unwrap()];
    (html.clone(), serde_json::from_str(json).expect("scene JSON"))
}

/// Number of bytes a standard padded base64 string decodes to.
fn decoded_len(b64: &Value) -> usize {
    let s = b64.as_str().expect("base64 string");
    assert!(
        s.len().checked_rem(4) == Some(0)
            && s.bytes().all(|c| c.is_ascii_alphanumeric() || b"+/=".contains(&c))
    );
    s.len() / 4 * 3 - s.bytes().rev().take_while(|&c| c == b'=').count()
}

/// Facts read straight from the BVH text: frame count and node count (ROOT, JOINT, End Site).
fn bvh_facts(path: &Path) -> (usize, usize) {
    let text = std::fs::read_to_string(path).unwrap();
    let frames = text
        .lines()
        .find_map(|l| l.trim().strip_prefix("Frames:"))
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    let nodes = text
        .lines()
        .map(str::trim_start)
        .filter(|l| l.starts_with("ROOT ") || l.starts_with("JOINT ") || l.starts_with("End Site"))
        .count();
    (frames, nodes)
}

/// Self-contained: no external scripts, styles, fonts or requests.
fn assert_offline(html: &str) {
    for needle in
        ["<script src", "<link", "@import", "url(", "fetch(", "XMLHttpRequest", "https://"]
    {
        assert!(!html.contains(needle), "the page references something outside itself: {needle}");
    }
}

#[test]
fn bvh_page_holds_every_joint_of_every_frame() {
    let bvh = sample("lafan1_walk.bvh");
    let (frames, nodes) = bvh_facts(&bvh);
    let out = tmp("walk.html");
    let (html, scene) = view(&[bvh.to_str().unwrap()], &out);
    assert_offline(&html);
    assert_eq!(scene["title"], "lafan1_walk.bvh");
    assert_eq!(scene["num_frames"].as_u64().unwrap() as usize, frames);
    assert!(scene["robot"].is_null());
    let skeleton = &scene["skeletons"][0];
    assert_eq!(skeleton["names"].as_array().unwrap().len(), nodes);
    assert_eq!(skeleton["names"][0], "Hips");
    assert!(skeleton["parents"][0].is_null());
    assert_eq!(decoded_len(&skeleton["root"]), frames * 3 * 4);
    assert_eq!(decoded_len(&skeleton["offsets"]), frames * nodes * 3 * 2);
    let feet: Vec<&str> =
        skeleton["feet"].as_array().unwrap().iter().map(|f| f[0].as_str().unwrap()).collect();
    assert_eq!(feet, ["left", "right"]);
    let tree = scene["tree"].as_str().unwrap();
    assert!(tree.starts_with("Hips\n  "), "{tree}");
    assert!(!tree.contains("_End"));
    // A few MB at most for a 4-minute clip: float32 positions in base64 and nothing else big.
    assert!(html.len() < frames * (nodes * 6 + 12) * 4 / 3 + 300_000, "{} bytes", html.len());
}

#[test]
fn default_output_is_beside_the_input() {
    let bvh = sample("lafan1_jumps.bvh");
    let input = tmp("jumps.bvh");
    std::fs::copy(bvh, &input).unwrap();
    let result = retarget(&["view", input.to_str().unwrap()]);
    assert!(result.status.success(), "{}", String::from_utf8_lossy(&result.stderr));
    assert!(input.with_extension("html").is_file());
}

#[test]
fn bad_inputs_are_errors_naming_the_file() {
    let missing = tmp("missing.bvh");
    let result =
        retarget(&["view", missing.to_str().unwrap(), "-o", tmp("missing.html").to_str().unwrap()]);
    assert_eq!(result.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&result.stderr).contains("missing.bvh"));
    assert!(!tmp("missing.html").exists());

    let other = tmp("notes.txt");
    std::fs::write(&other, "hello").unwrap();
    let result = retarget(&["view", other.to_str().unwrap()]);
    assert_eq!(result.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&result.stderr).contains("notes.txt"));

    let bvh = sample("lafan1_walk.bvh");
    let result = retarget(&["view", bvh.to_str().unwrap(), "--robot", "unitree_g1"]);
    assert_eq!(result.status.code(), Some(1));
}

/// A short motion of the shipped G1 written by our own npz writer, with targets at three
/// bodies (their own poses, so the page's tracking error is zero).
fn write_g1_motion(path: &Path, frames: usize) -> mjcf::Model {
    let xml = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots/unitree_g1/unitree_g1.xml");
    let model = mjcf::Model::from_file(&xml).unwrap();
    let mut data = mjcf::Data::new(&model);
    let tracked = ["pelvis", "left_ankle_roll_link", "right_ankle_roll_link"];
    let ids: Vec<usize> = tracked.iter().map(|n| model.body_id(n).unwrap()).collect();
    let (mut qpos, mut pos, mut quat) = (Vec::new(), Vec::new(), Vec::new());
    for f in 0..frames {
        let mut q = model.qpos0.clone();
        for (i, v) in q.iter_mut().enumerate().skip(7) {
            *v += 0.3 * ((f + i) as f64 * 0.2).sin();
        }
        q[0] = 0.01 * f as f64;
        model.kinematics(&q, &mut data);
        pos.extend(ids.iter().map(|&b| data.xpos[b]));
        quat.extend(ids.iter().map(|&b| data.xquat[b]));
        qpos.extend(q);
    }
    let motion = retarget::RobotMotion {
        fps: 30.0,
        nq: model.nq,
        qpos,
        joint_names: model.joints.iter().skip(1).map(|j| j.name.clone()).collect(),
        body_names: model.bodies.iter().skip(1).map(|b| b.name.clone()).collect(),
        targets: Some(retarget::TrackedTargets {
            body_names: tracked.map(String::from).to_vec(),
            pos,
            quat,
        }),
        contacts: None,
    };
    retarget::writers::write_motion(path, &motion, &model, None).unwrap();
    model
}

#[test]
fn robot_page_from_our_npz_names_its_robot_and_targets() {
    let npz = tmp("g1_motion.npz");
    let frames = 40;
    let model = write_g1_motion(&npz, frames);
    let out = tmp("g1_motion.html");
    let (html, scene) = view(&[npz.to_str().unwrap()], &out);
    assert_offline(&html);
    assert_eq!(scene["num_frames"].as_u64().unwrap() as usize, frames);
    assert!(scene["info"]
        .as_array()
        .unwrap()
        .iter()
        .any(|kv| kv[0] == "robot" && kv[1] == "unitree_g1"));
    let robot = &scene["robot"];
    let bodies = robot["bodies"].as_array().unwrap();
    assert_eq!(bodies.len(), model.bodies.len() - 1);
    assert!(bodies[0]["parent"].is_null());
    assert_eq!(robot["joints"][0]["kind"], "free");
    assert_eq!(decoded_len(&robot["qpos"]), frames * model.nq * 4);
    // Reference poses for the page's own kinematics: first, middle and last frame.
    let checked: Vec<u64> =
        robot["check"].as_array().unwrap().iter().map(|c| c[0].as_u64().unwrap()).collect();
    assert_eq!(checked, [0, frames as u64 / 2, frames as u64 - 1]);
    assert_eq!(robot["check"][0][1].as_array().unwrap().len(), bodies.len());
    let feet: Vec<&str> =
        robot["feet"].as_array().unwrap().iter().map(|f| f[0].as_str().unwrap()).collect();
    assert_eq!(feet, ["left", "right"]);
    let targets = &scene["skeletons"][0];
    assert_eq!(targets["style"], "targets");
    assert_eq!(targets["names"].as_array().unwrap().len(), 3);
    assert_eq!(decoded_len(&targets["offsets"]), frames * 3 * 3 * 2);
    assert_eq!(decoded_len(&targets["orientations"]), frames * 3 * 4 * 2);
}

#[test]
fn robot_page_rejects_a_motion_of_another_robot() {
    let npz = tmp("g1_other.npz");
    write_g1_motion(&npz, 3);
    let result = retarget(&[
        "view",
        npz.to_str().unwrap(),
        "--robot",
        "unitree_h1",
        "-o",
        tmp("other.html").to_str().unwrap(),
    ]);
    assert_eq!(result.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&result.stderr).contains("nq"),
        "{}",
        String::from_utf8_lossy(&result.stderr)
    );
}

#[test]
fn robot_page_from_gmr_output_on_the_reference_g1() {
    let Some(dir) = shared::shared_dir() else { return };
    let npz = dir.join("reference/gmr_outputs/unitree_g1_lafan1_walk.npz");
    let xml = dir.join("reference/robots/unitree_g1/g1_mocap_29dof.xml");
    let out = tmp("gmr_g1.html");
    let (html, scene) = view(&[npz.to_str().unwrap(), "--robot", xml.to_str().unwrap()], &out);
    let frames = scene["num_frames"].as_u64().unwrap() as usize;
    let nq = scene["robot"]["nq"].as_u64().unwrap() as usize;
    assert_eq!(decoded_len(&scene["robot"]["qpos"]), frames * nq * 4);
    // A whole LAFAN1 take on the G1 stays a few MB (float32 qpos; the page does the FK).
    assert!(html.len() < frames * nq * 4 * 4 / 3 + 300_000, "{} bytes", html.len());
}
