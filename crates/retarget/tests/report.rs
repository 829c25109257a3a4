//! Quality report on hand-made G1 motions whose metrics follow from their construction.

#[path = "../../../tests/support/shared.rs"]
mod shared;

use nalgebra::Vector3;
use retarget::report::{detect_feet, report, ReportOptions};
use retarget::{RobotMotion, TrackedTargets};

const FPS: f64 = 30.0;
const FRAMES: usize = 40;

fn g1() -> Option<mjcf::Model> {
    let path = shared::shared_file("reference/robots/unitree_g1/g1_mocap_29dof.xml")?;
    Some(mjcf::Model::from_file(&path).expect("the reference G1 compiles"))
}

fn motion_from(model: &mjcf::Model, qpos: Vec<f64>) -> RobotMotion {
    RobotMotion {
        fps: FPS,
        nq: model.nq,
        qpos,
        joint_names: model.joints.iter().skip(1).map(|j| j.name.clone()).collect(),
        body_names: model.bodies.iter().skip(1).map(|b| b.name.clone()).collect(),
        targets: None,
        contacts: None,
    }
}

/// Root height that puts the lowest point of the feet's geoms (spheres on the reference G1,
/// boxes on ours) `lift` above z = 0 at `qpos0`.
fn standing_height(model: &mjcf::Model, lift: f64) -> f64 {
    let mut data = mjcf::Data::new(model);
    model.kinematics(&model.qpos0, &mut data);
    let feet = ["left_ankle_roll_link", "right_ankle_roll_link"].map(|n| model.body_id(n).unwrap());
    let lowest = (0..model.geoms.len())
        .filter(|&g| feet.contains(&model.geoms[g].body))
        .map(|g| {
            let (r, s) = (data.geom_xmat[g], model.geoms[g].size);
            let reach = match model.geoms[g].kind {
                mjcf::GeomType::Sphere => s[0],
                mjcf::GeomType::Box => (0..3).map(|i| s[i] * r[(2, i)].abs()).sum::<f64>(),
                other => panic!("unexpected foot geom {other:?}"),
            };
            data.geom_xpos[g].z - reach
        })
        .fold(f64::INFINITY, f64::min);
    assert!(lowest.is_finite(), "the G1's feet have geoms");
    model.qpos0[2] - lowest + lift
}

/// Stands still for 10 frames, slides forward at `speed` for 20 frames, stands still again.
fn sliding_motion(model: &mjcf::Model, speed: f64, lift: f64) -> (RobotMotion, Vec<f64>) {
    let z = standing_height(model, lift);
    let xs: Vec<f64> =
        (0..FRAMES).map(|t| speed / FPS * (t as f64 - 10.0).clamp(0.0, 20.0)).collect();
    let mut qpos = Vec::new();
    for x in &xs {
        let mut q = model.qpos0.clone();
        q[0] = *x;
        q[2] = z;
        qpos.extend(q);
    }
    (motion_from(model, qpos), xs)
}

#[test]
fn feet_are_the_ankle_roll_links() {
    let Some(model) = g1() else { return };
    let [l, r] = detect_feet(&model).unwrap();
    assert_eq!(model.bodies[l].name, "left_ankle_roll_link");
    assert_eq!(model.bodies[r].name, "right_ankle_roll_link");
}

/// Our shipped G1 (box soles; needs no reference data).
fn repo_g1() -> mjcf::Model {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../robots/unitree_g1/unitree_g1.xml");
    mjcf::Model::from_file(&path).expect("robots/unitree_g1 compiles")
}

#[test]
fn a_known_foot_slide_is_measured() {
    if let Some(model) = g1() {
        check_known_slide(&model);
    }
}

#[test]
fn a_known_foot_slide_is_measured_with_box_soles() {
    let model = repo_g1();
    assert!(model.geom_id("left_sole").is_some());
    check_known_slide(&model);
}

fn check_known_slide(model: &mjcf::Model) {
    let speed = 0.3;
    let (motion, xs) = sliding_motion(model, speed, 0.001);
    let opts = ReportOptions::default();
    let rep = report(&motion, model, &opts).unwrap();
    // Central differences: a frame's foot speed is (x[t+1] − x[t−1]) · fps / 2.
    let speeds: Vec<f64> = (0..FRAMES)
        .map(|t| {
            let (a, b) = (t.saturating_sub(1), (t + 1).min(FRAMES - 1));
            (xs[b] - xs[a]) * FPS / (b - a) as f64
        })
        .collect();
    let sliding = speeds.iter().filter(|s| **s > opts.slide_speed).count();
    assert_eq!(sliding, 21, "frames 10..=30 (half speed at the two ends)");
    for foot in &rep.feet {
        assert_eq!(foot.height_from, "geoms");
        assert_eq!(foot.contact_frames, FRAMES, "{foot:?}");
        assert_eq!(foot.contact_phases, 1);
        assert_eq!(foot.sliding_frames, sliding);
        assert!((foot.sliding_share - sliding as f64 / FRAMES as f64).abs() < 1e-15);
        let path_cm = speed * 20.0 / FPS * 100.0;
        assert!((foot.slide_per_phase_cm_mean - path_cm).abs() < 1e-9, "{foot:?}");
        assert!((foot.slide_per_phase_cm_max - path_cm).abs() < 1e-9);
        assert_eq!(foot.penetration_frames, 0);
    }
    assert_eq!(rep.floating.frames, 0);
    assert!((rep.floating.cm_max - 0.1).abs() < 1e-9, "{:?}", rep.floating);
    // A higher sliding threshold leaves only the full-speed frames.
    let strict = ReportOptions { slide_speed: 0.2, ..ReportOptions::default() };
    let rep = report(&motion, model, &strict).unwrap();
    assert_eq!(rep.feet[0].sliding_frames, 19);
    // Too fast for contact (above contact_speed): the sliding frames stop being contact.
    let loose = ReportOptions { contact_speed: 0.2, ..ReportOptions::default() };
    let rep = report(&motion, model, &loose).unwrap();
    assert_eq!(rep.feet[0].contact_frames, FRAMES - 19);
    assert_eq!(rep.feet[0].contact_phases, 2);
}

#[test]
fn penetration_and_floating() {
    let Some(model) = g1() else { return };
    let (sunk, _) = sliding_motion(&model, 0.0, -0.02);
    let rep = report(&sunk, &model, &ReportOptions::default()).unwrap();
    for foot in &rep.feet {
        assert_eq!(foot.penetration_frames, FRAMES);
        assert!((foot.penetration_cm_max - 2.0).abs() < 1e-9, "{foot:?}");
        assert!((foot.penetration_cm_mean - 2.0).abs() < 1e-9);
        assert_eq!(foot.sliding_frames, 0);
    }
    let (lifted, _) = sliding_motion(&model, 0.0, 0.1);
    let rep = report(&lifted, &model, &ReportOptions::default()).unwrap();
    assert_eq!(rep.feet[0].contact_frames, 0);
    assert_eq!(rep.floating.frames, FRAMES);
    assert!((rep.floating.share - 1.0).abs() < 1e-15);
    assert!((rep.floating.cm_mean - 10.0).abs() < 1e-9, "{:?}", rep.floating);
    let z = standing_height(&model, 0.1);
    assert!((rep.root_height.min - z).abs() < 1e-12 && (rep.root_height.max - z).abs() < 1e-12);
}

#[test]
fn limit_violations_are_counted() {
    let Some(model) = g1() else { return };
    let (mut motion, _) = sliding_motion(&model, 0.0, 0.0);
    let knee = &model.joints[model.joint_id("left_knee_joint").unwrap()];
    let elbow = &model.joints[model.joint_id("right_elbow_joint").unwrap()];
    let ([_, knee_hi], [elbow_lo, _]) = (knee.range.unwrap(), elbow.range.unwrap());
    for t in [3, 4, 20] {
        motion.qpos[t * model.nq + knee.qpos_adr] = knee_hi + 0.1;
    }
    for t in [7, 8] {
        motion.qpos[t * model.nq + elbow.qpos_adr] = elbow_lo - 0.05;
    }
    // Within the tolerance: not a violation.
    motion.qpos[30 * model.nq + knee.qpos_adr] = knee_hi + 1e-9;
    let rep = report(&motion, &model, &ReportOptions::default()).unwrap();
    let limits = &rep.joint_limits;
    assert_eq!(limits.violations, 5);
    assert!((limits.max_excess - 0.1).abs() < 1e-12);
    assert_eq!(limits.joints.len(), 2);
    assert_eq!((limits.joints[0].joint.as_str(), limits.joints[0].frames), ("left_knee_joint", 3));
    assert_eq!(
        (limits.joints[1].joint.as_str(), limits.joints[1].frames),
        ("right_elbow_joint", 2)
    );
    assert!((limits.joints[1].max_excess - 0.05).abs() < 1e-12);
}

#[test]
fn velocities_jitter_and_tracking() {
    let Some(model) = g1() else { return };
    let (mut motion, _) = sliding_motion(&model, 0.0, 0.0);
    let knee = model.joints[model.joint_id("left_knee_joint").unwrap()].qpos_adr;
    let rate = 1.5; // rad/s, a linear ramp: constant speed, zero acceleration
    for t in 0..FRAMES {
        motion.qpos[t * model.nq + knee] = 0.1 + rate * t as f64 / FPS;
    }
    // Targets: the motion's own FK poses, one of them 5 cm off.
    let names = ["pelvis", "left_knee_link"];
    let mut data = mjcf::Data::new(&model);
    let (mut pos, mut quat) = (Vec::new(), Vec::new());
    for t in 0..FRAMES {
        model.kinematics(motion.frame(t), &mut data);
        for (k, name) in names.iter().enumerate() {
            let b = model.body_id(name).unwrap();
            pos.push(
                data.xpos[b]
                    + if k == 1 { Vector3::new(0.0, 0.03, 0.04) } else { Vector3::zeros() },
            );
            quat.push(data.xquat[b]);
        }
    }
    motion.targets =
        Some(TrackedTargets { body_names: names.map(str::to_owned).to_vec(), pos, quat });
    let opts = ReportOptions { joint_velocity_limit: Some(1.0), ..ReportOptions::default() };
    let rep = report(&motion, &model, &opts).unwrap();
    let j = rep.joints.iter().find(|j| j.joint == "left_knee_joint").unwrap();
    assert!((j.vel_max - rate).abs() < 1e-9 && (j.vel_p99 - rate).abs() < 1e-9, "{j:?}");
    assert_eq!(j.vel_over_limit, FRAMES);
    assert!(j.jitter < 1e-9, "{j:?}");
    let other = rep.joints.iter().find(|j| j.joint == "right_knee_joint").unwrap();
    assert_eq!((other.vel_max, other.vel_over_limit, other.jitter), (0.0, 0, 0.0));
    let tracking = rep.tracking.as_ref().unwrap();
    assert!(tracking[0].pos_m.max < 1e-12 && tracking[0].rot_rad.max < 1e-7, "{tracking:?}");
    for v in [tracking[1].pos_m.mean, tracking[1].pos_m.p95, tracking[1].pos_m.max] {
        assert!((v - 0.05).abs() < 1e-12, "{v}");
    }
    // The JSON and the table carry the same content.
    let json = serde_json::to_value(&rep).unwrap();
    assert_eq!(json["joint_limits"]["violations"], 0);
    assert_eq!(json["feet"][0]["body"], "left_ankle_roll_link");
    let table = rep.to_string();
    assert!(table.contains("left_knee_link") && table.contains("right_ankle_roll_link"), "{table}");
}

#[test]
fn unknown_foot_names_are_errors() {
    let Some(model) = g1() else { return };
    let (motion, _) = sliding_motion(&model, 0.0, 0.0);
    let opts = ReportOptions {
        feet: Some(["left_foot".to_owned(), "right_ankle_roll_link".to_owned()]),
        ..ReportOptions::default()
    };
    let err = report(&motion, &model, &opts).unwrap_err().to_string();
    assert!(err.contains("left_foot"), "{err}");
}

/// Every shipped robot has two feet found automatically, the left one on the robot's left
/// (+y in the MJCF frame at qpos0, where every model faces +x).
#[test]
fn every_shipped_robot_has_its_feet_detected_on_the_right_sides() {
    let robots = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots");
    let mut checked = 0;
    for entry in std::fs::read_dir(&robots).unwrap() {
        let dir = entry.unwrap().path();
        let Some(key) = dir.file_name().and_then(|n| n.to_str()).map(str::to_owned) else {
            continue;
        };
        let xml = dir.join(format!("{key}.xml"));
        if !xml.is_file() {
            continue;
        }
        let model = mjcf::Model::from_file(&xml).unwrap();
        let [l, r] = detect_feet(&model).unwrap_or_else(|e| panic!("{key}: {e}"));
        let mut data = mjcf::Data::new(&model);
        model.kinematics(&model.qpos0, &mut data);
        assert!(data.xpos[l].y > data.xpos[r].y, "{key}: left foot is not on the left");
        checked += 1;
    }
    assert!(checked >= 6, "only {checked} robots found");
}
