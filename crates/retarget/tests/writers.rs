//! Writers: every format written for a smooth G1 motion, read back in Rust (`.npz`) and by
//! Python + numpy through `scripts/check-outputs-python`, and compared with forward kinematics
//! and with velocities known in closed form.

use std::path::{Path, PathBuf};
use std::process::Command;

use nalgebra::{UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use retarget::writers::{
    read_motion, read_motion_npz, read_npz_robot, write_motion, Format, FpsFrom, MotionFormat,
};
use retarget::{Error, RobotMotion, TrackedTargets};
use serde_json::Value;

const FPS: f64 = 30.0;
const FRAMES: usize = 20;
/// Constant world-frame root velocities of [`smooth_motion`].
const ROOT_VEL: [f64; 3] = [0.4, -0.2, 0.05];
const ROOT_ANG_VEL: [f64; 3] = [0.3, -0.5, 1.1];

/// Our shipped G1 (`robots/unitree_g1`, kinematics equal to GMR's; no reference data needed).
fn g1() -> Option<mjcf::Model> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots/unitree_g1/unitree_g1.xml");
    Some(mjcf::Model::from_file(&path).expect("robots/unitree_g1 compiles"))
}

fn scratch_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("writers-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Joints move linearly between two random in-range configurations; the root translates and
/// rotates at constant world-frame rates. Targets: three bodies at random poses.
fn smooth_motion(model: &mjcf::Model, seed: u64) -> RobotMotion {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (a, b) = (model.random_qpos(&mut rng), model.random_qpos(&mut rng));
    let q0 = UnitQuaternion::from_euler_angles(0.2, -0.1, 0.7);
    let mut qpos = Vec::with_capacity(FRAMES * model.nq);
    for t in 0..FRAMES {
        let time = t as f64 / FPS;
        let s = t as f64 / (FRAMES - 1) as f64;
        let q = UnitQuaternion::from_scaled_axis(Vector3::from(ROOT_ANG_VEL) * time) * q0;
        let root = [0.1 + ROOT_VEL[0] * time, -0.3 + ROOT_VEL[1] * time, 0.8 + ROOT_VEL[2] * time];
        qpos.extend_from_slice(&root);
        qpos.extend_from_slice(&[q.w, q.i, q.j, q.k]);
        qpos.extend((7..model.nq).map(|i| a[i] + (b[i] - a[i]) * s));
    }
    let names = ["pelvis", "left_ankle_roll_link", "right_wrist_yaw_link"];
    let k = names.len();
    let targets = TrackedTargets {
        body_names: names.iter().map(|s| (*s).to_owned()).collect(),
        pos: (0..FRAMES * k).map(|_| Vector3::new(rng.gen(), rng.gen(), rng.gen())).collect(),
        quat: (0..FRAMES * k)
            .map(|_| UnitQuaternion::from_euler_angles(rng.gen(), rng.gen(), rng.gen()))
            .collect(),
    };
    RobotMotion {
        fps: FPS,
        nq: model.nq,
        qpos,
        joint_names: model.joints.iter().skip(1).map(|j| j.name.clone()).collect(),
        body_names: model.bodies.iter().skip(1).map(|b| b.name.clone()).collect(),
        targets: Some(targets),
        contacts: None,
    }
}

fn fk(model: &mjcf::Model, motion: &RobotMotion, t: usize) -> mjcf::Data {
    let mut data = mjcf::Data::new(model);
    model.kinematics(motion.frame(t), &mut data);
    data
}

#[test]
fn npz_round_trip_is_exact() {
    let Some(model) = g1() else { return };
    let motion = smooth_motion(&model, 1);
    let dir = scratch_dir("roundtrip");
    let path = dir.join("walk.npz");
    write_motion(&path, &motion, &model, None).unwrap();
    assert_eq!(read_motion_npz(&path).unwrap(), motion);
    assert_eq!(
        read_npz_robot(&path).unwrap().as_deref(),
        Some(model.name.as_str()).filter(|s| !s.is_empty())
    );
    let mut without_targets = motion.clone();
    without_targets.targets = None;
    write_motion(&path, &without_targets, &model, Some(Format::Npz)).unwrap();
    assert_eq!(read_motion_npz(&path).unwrap(), without_targets);
    // Only the final file: no temporary left behind.
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
}

/// Every format we write is read back by `read_motion` (the report's reader): our `.npz` whole
/// (targets included), `.pkl` and `.csv` as their `qpos` (exact: the root is stored as given,
/// numbers round-trip).
#[test]
fn read_motion_reads_every_format_we_write() {
    let Some(model) = g1() else { return };
    let motion = smooth_motion(&model, 3);
    let dir = scratch_dir("read_motion");
    for (ext, format, fps) in [
        ("npz", MotionFormat::Npz, FpsFrom::File),
        ("pkl", MotionFormat::GmrPickle, FpsFrom::File),
        ("csv", MotionFormat::UnitreeCsv, FpsFrom::Caller),
    ] {
        let path = dir.join(format!("walk.{ext}"));
        write_motion(&path, &motion, &model, None).unwrap();
        let (back, source) = read_motion(&path, &model, Some(FPS)).unwrap();
        assert_eq!((source.format, source.fps_from), (format, fps), "{ext}");
        assert_eq!(back.qpos, motion.qpos, "{ext}");
        if ext == "npz" {
            assert_eq!(back, read_motion_npz(&path).unwrap());
            assert_eq!(back, motion);
        } else {
            assert_eq!(back.targets, None);
        }
    }
}

#[test]
fn bad_motions_are_typed_errors_and_write_nothing() {
    let Some(model) = g1() else { return };
    let dir = scratch_dir("bad");
    let mut motion = smooth_motion(&model, 2);
    motion.qpos[3 * model.nq + 9] = f64::NAN;
    let err = write_motion(&dir.join("a.csv"), &motion, &model, None).unwrap_err();
    assert!(matches!(err, Error::NonFiniteQpos { frame: 3, index: 9, .. }), "{err}");
    let mut motion = smooth_motion(&model, 2);
    motion.nq -= 1;
    let err = write_motion(&dir.join("a.npz"), &motion, &model, None).unwrap_err();
    assert!(matches!(err, Error::Mismatch(_)), "{err}");
    let err =
        write_motion(&dir.join("a.txt"), &smooth_motion(&model, 2), &model, None).unwrap_err();
    assert!(matches!(err, Error::UnknownFormat { .. }), "{err}");
    let err = write_motion(&dir.join("missing/a.npz"), &smooth_motion(&model, 2), &model, None);
    assert!(matches!(err, Err(Error::File { .. })));
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
}

/// An `.npz` holding one stored member `key.npy` with these bytes.
fn npz_with(path: &Path, key: &str, npy: &[u8]) {
    use std::io::Write;
    let mut zip = zip::ZipWriter::new(std::fs::File::create(path).unwrap());
    let options =
        zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    zip.start_file(format!("{key}.npy"), options).unwrap();
    zip.write_all(npy).unwrap();
    zip.finish().unwrap();
}

/// Issue 15: a 256-byte `.npz` whose member claims 1e14 `<U0` strings made the reader
/// allocate 2.4 PB and abort. Every count read from a file is now checked against the bytes
/// that hold it: crafted headers are errors naming the member.
#[test]
fn crafted_npz_headers_are_errors_not_allocations() {
    let dir = scratch_dir("crafted");
    let npy = |descr: &str, shape: &str| {
        let header =
            format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}\n");
        let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
        bytes.extend_from_slice(&u16::try_from(header.len()).unwrap().to_le_bytes());
        bytes.extend_from_slice(header.as_bytes());
        bytes
    };
    let cases = [
        ("<U0", "(100000000000000,)", "dtype <U0 with 100000000000000 elements in 0 bytes"),
        ("<U4", "(100000000000000,)", "data truncated (fewer than the 100000000000000 elements"),
        ("<f8", "(4294967296, 65536)", "data truncated"),
        ("<f8", "(4294967296, 4294967296, 4294967296)", "shape overflows"),
        ("<U99999999999999999999", "(1,)", "unsupported dtype `<U99999999999999999999`"),
    ];
    for (descr, shape, expected) in cases {
        let path = dir.join("crafted.npz");
        npz_with(&path, "joint_names", &npy(descr, shape));
        let err = read_motion_npz(&path).unwrap_err().to_string();
        assert!(err.contains("crafted.npz: array `joint_names`: "), "{err}");
        assert!(err.contains(expected), "{descr} {shape}: {err}");
    }
}

#[test]
fn csv_is_unitree_layout_and_round_trips_in_rust() {
    let Some(model) = g1() else { return };
    let motion = smooth_motion(&model, 3);
    let path = scratch_dir("csv").join("walk.csv");
    write_motion(&path, &motion, &model, None).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let rows: Vec<Vec<f64>> =
        text.lines().map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
    assert_eq!(rows.len(), FRAMES);
    for (t, row) in rows.iter().enumerate() {
        let q = motion.frame(t);
        assert_eq!(row.len(), model.nq);
        assert_eq!(row[..3], q[..3]);
        assert_eq!(row[3..7], [q[4], q[5], q[6], q[3]], "x y z w");
        assert_eq!(row[7..], q[7..]);
    }
}

/// Runs the Python check on `files`; `None` (after a note) when Python is missing outside CI.
fn python_summary(files: &[PathBuf]) -> Option<Value> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scripts/check-outputs-python");
    let output = Command::new("bash").arg(&script).arg("--full").args(files).output();
    let in_ci = std::env::var_os("CI").is_some_and(|v| !v.is_empty() && v != "false");
    let output = match output {
        Ok(o) if o.status.success() => o,
        Ok(o) if in_ci || Command::new("python3").arg("--version").output().is_ok() => {
            panic!("check-outputs-python failed:\n{}", String::from_utf8_lossy(&o.stderr))
        }
        _ => {
            eprintln!("note: no python3; skipping the Python check of the writers");
            return None;
        }
    };
    Some(serde_json::from_slice(&output.stdout).expect("the script prints JSON"))
}

fn values(v: &Value) -> Vec<f64> {
    match v {
        Value::Array(items) => items.iter().flat_map(values).collect(),
        Value::Number(n) => vec![n.as_f64().unwrap()],
        other => panic!("not a number: {other}"),
    }
}

fn shape(v: &Value) -> Vec<usize> {
    v["shape"].as_array().unwrap().iter().map(|d| d.as_u64().unwrap() as usize).collect()
}

fn assert_close(a: &[f64], b: &[f64], tol: f64, what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: lengths");
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        assert!((x - y).abs() <= tol, "{what}[{i}]: {x} vs {y}");
    }
}

#[test]
fn python_and_numpy_load_every_format() {
    let Some(model) = g1() else { return };
    let motion = smooth_motion(&model, 4);
    let dir = scratch_dir("python");
    let files: Vec<PathBuf> =
        ["walk.npz", "walk.pkl", "walk.csv", "walk.json"].iter().map(|f| dir.join(f)).collect();
    for f in &files {
        write_motion(f, &motion, &model, None).unwrap();
    }
    let Some(summary) = python_summary(&files) else { return };
    let file = |i: usize| &summary["files"][files[i].to_str().unwrap()];
    check_npz(&model, &motion, &file(0)["keys"]);
    check_pkl(&model, &motion, file(1));
    let csv = &file(2)["table"];
    assert_eq!(shape(csv), [FRAMES, model.nq]);
    let expected: Vec<f64> = (0..FRAMES)
        .flat_map(|t| {
            let q = motion.frame(t);
            [&q[..3], &[q[4], q[5], q[6], q[3]], &q[7..]].concat()
        })
        .collect();
    assert_eq!(values(&csv["values"]), expected);
    assert_eq!(values(&file(3)["qpos"]["values"]), motion.qpos);
    assert_eq!(shape(&file(3)["target_pos"]), [FRAMES, 3, 3]);
}

fn check_npz(model: &mjcf::Model, motion: &RobotMotion, keys: &Value) {
    let nb = model.nbody() - 1;
    let nj = model.nq - 7;
    for (key, dims) in [
        ("fps", vec![1]),
        ("qpos", vec![FRAMES, model.nq]),
        ("joint_names", vec![nj]),
        ("body_names", vec![nb]),
        ("joint_pos", vec![FRAMES, nj]),
        ("joint_vel", vec![FRAMES, nj]),
        ("body_pos_w", vec![FRAMES, nb, 3]),
        ("body_quat_w", vec![FRAMES, nb, 4]),
        ("body_lin_vel_w", vec![FRAMES, nb, 3]),
        ("body_ang_vel_w", vec![FRAMES, nb, 3]),
        ("target_body_names", vec![3]),
        ("target_pos", vec![FRAMES, 3, 3]),
        ("target_quat", vec![FRAMES, 3, 4]),
    ] {
        assert_eq!(shape(&keys[key]), dims, "{key}");
    }
    assert_eq!(keys["qpos"]["dtype"], "float64");
    assert!(keys["body_names"]["dtype"].as_str().unwrap().starts_with("<U"));
    assert_eq!(values(&keys["fps"]["values"]), [FPS]);
    assert_eq!(values(&keys["qpos"]["values"]), motion.qpos);
    let names: Vec<&str> = keys["body_names"]["values"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(names, motion.body_names);
    let (mut pos, mut quat) = (Vec::new(), Vec::new());
    for t in 0..FRAMES {
        let data = fk(model, motion, t);
        pos.extend(data.xpos[1..].iter().flat_map(|p| [p.x, p.y, p.z]));
        quat.extend(data.xquat[1..].iter().flat_map(|q| [q.w, q.i, q.j, q.k]));
    }
    assert_eq!(values(&keys["body_pos_w"]["values"]), pos);
    assert_eq!(values(&keys["body_quat_w"]["values"]), quat);
    // Joints move linearly: every finite difference is the constant rate.
    let joint_vel = values(&keys["joint_vel"]["values"]);
    let (a, b) = (motion.frame(0), motion.frame(FRAMES - 1));
    let rate: Vec<f64> = (7..model.nq).map(|i| (b[i] - a[i]) * FPS / (FRAMES - 1) as f64).collect();
    for row in joint_vel.chunks(nj) {
        assert_close(row, &rate, 1e-9, "joint_vel");
    }
    // The pelvis (body 0) carries the root's constant world-frame velocities.
    let lin = values(&keys["body_lin_vel_w"]["values"]);
    let ang = values(&keys["body_ang_vel_w"]["values"]);
    for t in 0..FRAMES {
        assert_close(&lin[t * nb * 3..t * nb * 3 + 3], &ROOT_VEL, 1e-9, "root lin vel");
        assert_close(&ang[t * nb * 3..t * nb * 3 + 3], &ROOT_ANG_VEL, 1e-9, "root ang vel");
    }
}

fn check_pkl(model: &mjcf::Model, motion: &RobotMotion, file: &Value) {
    let keys = &file["keys"];
    assert_eq!(keys["fps"]["value"].as_f64(), Some(FPS));
    let wxyz = values(&file["root_rot_wxyz"]["values"]);
    let root_pos = values(&keys["root_pos"]["values"]);
    let dof_pos = values(&keys["dof_pos"]["values"]);
    assert_eq!(shape(&keys["dof_pos"]), [FRAMES, model.nq - 7]);
    for t in 0..FRAMES {
        let q = motion.frame(t);
        assert_eq!(wxyz[4 * t..4 * t + 4], q[3..7], "root_rot[:, [3, 0, 1, 2]] is w-first qpos");
        assert_eq!(root_pos[3 * t..3 * t + 3], q[..3]);
        assert_eq!(dof_pos[(model.nq - 7) * t..(model.nq - 7) * (t + 1)], q[7..]);
    }
    let nb = model.nbody() - 1;
    assert_eq!(shape(&keys["local_body_pos"]), [FRAMES, nb, 3]);
    let local = values(&keys["local_body_pos"]["values"]);
    for t in 0..FRAMES {
        let data = fk(model, motion, t);
        for b in 0..nb {
            let v = data.xquat[1].inverse_transform_vector(&(data.xpos[b + 1] - data.xpos[1]));
            assert_close(
                &local[(t * nb + b) * 3..(t * nb + b) * 3 + 3],
                v.as_slice(),
                1e-12,
                "local_body_pos",
            );
        }
    }
    assert_eq!(keys["link_body_list"]["len"].as_u64(), Some(nb as u64));
    assert_eq!(keys["root_pos"]["dtype"], "float64");
}
