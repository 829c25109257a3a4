//! Derived IK configs: on the shipped robots against GMR's tuned ones, role-named binding.

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::PathBuf;

use fk::{Part, Role, Side};
use retarget::derive::{self, Choice, HumanBody};
use retarget::{IkConfig, RetargetOptions, RobotRoles};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn shipped(key: &str) -> (mjcf::Model, IkConfig) {
    let model = mjcf::Model::from_file(&root().join(format!("robots/{key}/{key}.xml"))).unwrap();
    let config = retarget::shipped::tuned_config(key).expect("a tuned config").unwrap();
    (model, config)
}

fn lafan_walk() -> Option<bvh::Bvh> {
    let path = root().join("data/samples/lafan1_walk.bvh");
    if path.is_file() {
        return Some(bvh::from_path(&path).unwrap());
    }
    let path = shared::shared_file("data/bvh/lafan1_take_via_bvhtools_test.bvh")?;
    Some(bvh::from_path(&path).unwrap())
}

/// Every robot derive runs on: the shipped ones, the test robots and the reference ones
/// (MJCF and URDF).
fn robots_derive_runs_on() -> Vec<PathBuf> {
    let mut dirs: Vec<PathBuf> =
        std::fs::read_dir(root().join("robots")).unwrap().map(|e| e.unwrap().path()).collect();
    dirs.push(root().join("crates/retarget/tests/data/robots"));
    if let Some(reference) = shared::shared_file("reference/robots") {
        dirs.extend(std::fs::read_dir(reference).unwrap().map(|e| e.unwrap().path()));
    }
    let mut out: Vec<PathBuf> = dirs
        .into_iter()
        .filter(|d| d.is_dir())
        .flat_map(|d| std::fs::read_dir(d).unwrap().map(|f| f.unwrap().path()))
        .filter(|f| matches!(f.extension().and_then(|e| e.to_str()), Some("xml" | "urdf")))
        .collect();
    out.sort();
    out
}

/// A derived or bound config reads back from its text ([`IkConfig::json`], what `retarget
/// robot init` writes) as the same config, on every robot derive runs on, against the
/// canonical human and the LAFAN1 walk; its table rows are one a line, as in GMR's files.
#[test]
fn derived_configs_read_back_from_their_text_unchanged() {
    let Some(bvh) = lafan_walk() else { return };
    let walk = derive::human_body(&bvh, &fk::FkOptions::default(), "walk").unwrap();
    let mut checked = 0;
    for path in robots_derive_runs_on() {
        let model = mjcf::Model::from_path(&path).unwrap();
        let Ok(roles) = RobotRoles::recognise(&model) else { continue };
        let canonical = derive::derive(&model, &roles, &HumanBody::canonical(), "c").unwrap();
        let derived = derive::derive(&model, &roles, &walk, "d").unwrap();
        let bound = derive::bind(&canonical, &walk, &model, &roles).unwrap();
        for config in [canonical, derived, bound] {
            let read = IkConfig::from_json_str(config.json(), &config.source).unwrap();
            assert_eq!(read, config, "{}", path.display());
            let rows = config.json().lines().filter(|l| l.contains("\": [\"")).count();
            let tables = config.ik_match_table1.len() + config.ik_match_table2.len();
            assert_eq!(rows, tables, "{}", path.display());
            checked += 1;
        }
    }
    // The shipped robots and the recognised test robots, and without RETARGET_SHARED skipped
    // (outside CI) the reference ones.
    let reference = shared::shared_file("reference/robots").is_some();
    assert!(checked >= if reference { 26 * 3 } else { 8 * 3 }, "{checked}");
}

/// A role-named config (`retarget robot init` without `--bvh`) bound to a skeleton is the
/// config derived for that skeleton directly, on every robot with a GMR config and on the
/// servo robots whose shoulders cannot turn the arm about its bone (their arm frames turned
/// for the canonical human and for the skeleton, `derive::shoulder`).
#[test]
fn binding_a_role_named_config_equals_deriving_for_the_skeleton() {
    let Some(bvh) = lafan_walk() else { return };
    let human = derive::human_body(&bvh, &fk::FkOptions::default(), "walk").unwrap();
    for key in ["unitree_g1", "booster_t1_29dof", "fourier_n1", "engineai_pm01", "stanford_toddy"] {
        let (model, tuned) = shipped(key);
        let direct = assert_bound_is_direct(key, &model, &human);
        // On LAFAN1 the derived offsets are near GMR's tuned ones (its 90° guesses): the
        // trunk and legs within 30°.
        for e in direct.ik_match_table1.iter().filter(|e| {
            ["Hips", "LeftUpLeg", "RightUpLeg", "LeftLeg", "RightLeg"]
                .contains(&e.human_body.as_str())
        }) {
            if let Some(t) = tuned.ik_match_table1.iter().find(|t| t.robot_body == e.robot_body) {
                let angle = e.rot_offset.angle_to(&t.rot_offset).to_degrees();
                assert!(angle < 30.0, "{key} {}: {angle:.1}°", e.robot_body);
            }
        }
    }
    for servo in ["synthetic/kid_servo.xml", "robotis_op3_urdf/robotis_op3.urdf"] {
        let path = root().join("tests/data/robots").join(servo);
        let model = retarget::shipped::load_robot(&path.to_string_lossy()).unwrap();
        assert_bound_is_direct(servo, &model, &human);
    }
}

/// Binds `model`'s role-named config to `human`, asserts it is the config derived for `human`
/// directly, and returns that.
fn assert_bound_is_direct(key: &str, model: &mjcf::Model, human: &HumanBody) -> IkConfig {
    let roles = RobotRoles::recognise(model).unwrap();
    let canonical = derive::derive(model, &roles, &HumanBody::canonical(), "c").unwrap();
    assert!(derive::is_role_named(&canonical), "{key}");
    let written = IkConfig::from_json_str(canonical.json(), "written").unwrap();
    let bound = derive::bind(&written, human, model, &roles).unwrap();
    let direct = derive::derive(model, &roles, human, "d").unwrap();
    assert!(!derive::is_role_named(&direct), "{key}");
    assert!((bound.human_height_assumption - direct.human_height_assumption).abs() < 1e-6);
    assert_eq!(bound.human_scale_table.len(), direct.human_scale_table.len());
    for ((a, s), (b, t)) in bound.human_scale_table.iter().zip(&direct.human_scale_table) {
        assert_eq!(a, b, "{key}");
        assert!((s - t).abs() < 1e-6, "{key} {a}: {s} vs {t}");
    }
    for (e, f) in bound.ik_match_table2.iter().zip(&direct.ik_match_table2) {
        assert_eq!((&e.robot_body, &e.human_body), (&f.robot_body, &f.human_body));
        assert_eq!((e.pos_weight, e.rot_weight), (f.pos_weight, f.rot_weight));
        assert!(e.rot_offset.angle_to(&f.rot_offset) < 1e-6, "{key} {}", e.robot_body);
        assert!((e.pos_offset - f.pos_offset).norm() < 1e-6, "{key} {}", e.robot_body);
    }
    direct
}

/// The feet are fitted so that the sole is on the floor when the human rolls onto the ball
/// of the foot: the G1's sole reaches farther ahead of its ankle than the scaled human foot,
/// so its ankle target sits behind the human's (foot frame x, the G1's foot body frame at
/// `qpos0` being the canonical one), and a few millimetres above the flat-foot height.
#[test]
fn a_sole_longer_than_the_scaled_foot_is_moved_back() {
    let Some(bvh) = lafan_walk() else { return };
    let human = derive::human_body(&bvh, &fk::FkOptions::default(), "walk").unwrap();
    let (model, _) = shipped("unitree_g1");
    let roles = RobotRoles::recognise(&model).unwrap();
    let config = derive::derive(&model, &roles, &human, "g1").unwrap();
    for foot in ["left_ankle_roll_link", "right_ankle_roll_link"] {
        let e = config.ik_match_table1.iter().find(|e| e.robot_body == foot).unwrap();
        assert!(e.pos_offset.x < -0.003, "{foot}: {:?}", e.pos_offset);
        assert!(e.pos_offset.z.abs() < 0.02, "{foot}: {:?}", e.pos_offset);
    }
}

/// A robot whose arms hang from its pelvis body (no waist: Berkeley Humanoid Lite) has no
/// chest role; its pelvis is tracked with the chest's rotation weight, so that arms which
/// cannot reach their targets do not tilt it. With a chest (the G1) the pelvis keeps GMR's.
#[test]
fn a_pelvis_that_is_also_the_chest_gets_the_chest_weights() {
    let Some(bvh) = lafan_walk() else { return };
    let Some(path) = shared::shared_file("reference/robots/berkeley_humanoid_lite/bhl_scene.xml")
    else {
        return;
    };
    let human = derive::human_body(&bvh, &fk::FkOptions::default(), "walk").unwrap();
    let pelvis_weights = |model: &mjcf::Model, chest: bool| {
        let roles = RobotRoles::recognise(model).unwrap();
        assert_eq!(roles.roles.contains_key(&fk::Role::Chest), chest);
        let config = derive::derive(model, &roles, &human, "c").unwrap();
        let root = &config.robot_root_name;
        let rot = |t: &[retarget::MatchEntry]| {
            t.iter().find(|e| &e.robot_body == root).unwrap().rot_weight
        };
        (rot(&config.ik_match_table1), rot(&config.ik_match_table2))
    };
    let bhl = mjcf::Model::from_path(&path).unwrap();
    assert_eq!(pelvis_weights(&bhl, false), (100.0, 10.0));
    assert_eq!(pelvis_weights(&shipped("unitree_g1").0, true), (10.0, 5.0));
}

/// Whether a robot's tuned (GMR) config applies is a property of the skeleton, not of the motion or
/// of the robot: on every shipped robot (each has one), every LAFAN1 take (both samples and the
/// shared LAFAN1 files) gets it, every other shared skeleton gets the derived config, and so do a
/// LAFAN1 take read with another up axis and a LAFAN1-named skeleton standing upright in its zero
/// pose (the names fit, the joint frames are not LAFAN1's), with `--gmr` too.
#[test]
fn the_tuned_config_is_chosen_for_lafan1_skeletons_only() {
    let Some(dir) = shared::shared_file("data/bvh") else { return };
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .chain(std::fs::read_dir(root().join("data/samples")).into_iter().flatten())
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "bvh"))
        .collect();
    files.sort();
    assert!(files.len() >= 13, "{files:?}");
    let clips: Vec<(String, bvh::Bvh)> = files
        .iter()
        .map(|f| {
            let name = f.file_name().unwrap().to_string_lossy().into_owned();
            (name, first_frames(bvh::from_path(f).unwrap(), 300))
        })
        .collect();
    let upright = bvh::parse(upright_lafan1_named_bvh().as_bytes()).unwrap();
    // A HumanML3D `joints2bvh` export: HumanIK's names on SMPL's T zero pose, in metres.
    let hik =
        bvh::from_path(&root().join("crates/fk/tests/data/skeletons/hik_metres_walk.bvh")).unwrap();
    let default = fk::FkOptions::default();
    let z_up = fk::FkOptions { axes: fk::AxisConvention::ZUp, ..fk::FkOptions::default() };
    let mut lafan = 0;
    let robots: Vec<_> =
        retarget::shipped::ROBOTS.iter().filter(|r| r.config_name().is_some()).collect();
    assert!(robots.len() >= 6, "the G1, H1, T1, N1, PM01 and ToddlerBot");
    for robot in &robots {
        let (key, model) = (robot.key, robot.model().unwrap());
        let tuned = robot.config().unwrap().unwrap();
        let choose = |bvh: &bvh::Bvh, fk: &fk::FkOptions| {
            derive::choose(&model, key, bvh, fk, None, Some(&tuned), false).unwrap()
        };
        for (name, bvh) in &clips {
            let chosen = choose(bvh, &default);
            let expected = if name.starts_with("lafan1") { Choice::Tuned } else { Choice::Derived };
            assert_eq!(chosen.choice, expected, "{name} → {key}: {}", chosen.summary);
            if expected == Choice::Tuned {
                lafan += 1;
                let turned = choose(bvh, &z_up);
                assert_eq!(turned.choice, Choice::Derived, "{name} Z up → {key}");
                assert!(turned.summary.contains("Z up from LAFAN1's +Y up"), "{}", turned.summary);
            }
        }
        let chosen = choose(&upright, &default);
        assert_eq!(chosen.choice, Choice::Derived, "upright → {key}: {}", chosen.summary);
        assert!(chosen.summary.contains("from LAFAN1's"), "{}", chosen.summary);
        // With --gmr too the tuned config only on LAFAN1's joint frames (GMR would take it on
        // any skeleton with the names, and stand a T zero pose on its head); GMR's solve with
        // the derived config elsewhere (GMR stops with a KeyError on other names).
        for (name, bvh) in [("upright", &upright), ("hik_metres_walk", &hik)] {
            let gmr = derive::choose(&model, key, bvh, &default, None, Some(&tuned), true).unwrap();
            assert_eq!(gmr.choice, Choice::Derived, "{name} --gmr → {key}: {}", gmr.summary);
            assert!(gmr.summary.contains("from LAFAN1's"), "{}", gmr.summary);
            assert!(gmr.summary.contains("--gmr: GMR's solve"), "{}", gmr.summary);
        }
        for (name, bvh) in clips.iter().filter(|(name, _)| name.starts_with("lafan1")) {
            let gmr = derive::choose(&model, key, bvh, &default, None, Some(&tuned), true).unwrap();
            assert_eq!(gmr.choice, Choice::Tuned, "{name} --gmr → {key}: {}", gmr.summary);
        }
        let cmu: Vec<_> = clips.iter().filter(|(name, _)| name.starts_with("cmu")).collect();
        assert!(!cmu.is_empty(), "the CMU files of the shared data");
        for (name, bvh) in cmu {
            let gmr = derive::choose(&model, key, bvh, &default, None, Some(&tuned), true).unwrap();
            assert_eq!(gmr.choice, Choice::Derived, "{name} --gmr → {key}: {}", gmr.summary);
            assert!(gmr.summary.contains("--gmr: GMR's solve"), "{}", gmr.summary);
        }
    }
    assert!(lafan >= robots.len() * 4, "{lafan}: both samples and both shared LAFAN1 files");
}

fn first_frames(mut bvh: bvh::Bvh, n: usize) -> bvh::Bvh {
    bvh.motion.truncate(n);
    bvh
}

/// A skeleton with LAFAN1's joint names standing upright in its zero pose (Y up, cm): arms
/// hanging, the toes forward (+Z); the pelvis sways sideways over a few frames.
fn upright_lafan1_named_bvh() -> String {
    let open = |name: &str, offset: &str| {
        format!("JOINT {name}\n{{ OFFSET {offset} CHANNELS 3 Zrotation Yrotation Xrotation\n")
    };
    let chain = |joints: &[(String, String)], end: &str| {
        let opened: String = joints.iter().map(|(n, o)| open(n, o)).collect();
        opened + &format!("End Site\n{{ OFFSET {end} }}\n") + &"}\n".repeat(joints.len())
    };
    let leg = |side: &str, x: f64| {
        let names = ["UpLeg", "Leg", "Foot", "Toe"].map(|p| format!("{side}{p}"));
        let offsets = [format!("{x} 0 0"), "0 -43 0".into(), "0 -42 0".into(), "0 -6 14".into()];
        chain(&names.into_iter().zip(offsets).collect::<Vec<_>>(), "0 0 5")
    };
    let arm = |side: &str, x: f64| {
        let names = ["Shoulder", "Arm", "ForeArm", "Hand"].map(|p| format!("{side}{p}"));
        let offsets = [
            format!("{} 10 0", 4.0 * x),
            format!("{} 0 0", 14.0 * x),
            "0 -28 0".into(),
            "0 -25 0".into(),
        ];
        chain(&names.into_iter().zip(offsets).collect::<Vec<_>>(), "0 -15 0")
    };
    let neck = [("Neck".into(), "0 15 0".into()), ("Head".into(), "0 10 0".into())];
    let frames: String =
        (0..30).map(|f| format!("{} 95 0 {}\n", f as f64 * 0.2, "0 ".repeat(66))).collect();
    "HIERARCHY\nROOT Hips\n{ OFFSET 0 0 0 CHANNELS 6 Xposition Yposition Zposition Zrotation \
     Yrotation Xrotation\n"
        .to_owned()
        + &leg("Left", 9.0)
        + &leg("Right", -9.0)
        + &open("Spine", "0 10 0")
        + &open("Spine1", "0 12 0")
        + &open("Spine2", "0 12 0")
        + &chain(&neck, "0 15 0")
        + &arm("Left", 1.0)
        + &arm("Right", -1.0)
        + "}\n}\n}\n}\nMOTION\nFrames: 30\nFrame Time: 0.033333\n"
        + &frames
}

/// With GMR's solve the derived config's targets are within the robot's reach on the LAFAN1
/// jumps, whole-body: the G1's hands within 10 % of the tuned config's (69 mm; 86 mm when
/// the upper arms' rotation weighed 100 in table 2 as in GMR's G1 config) and its feet
/// within 4 mm; the PM01's feet within 8 mm (14 mm with that weight: its arms pulled the
/// legs).
#[test]
fn the_derived_config_is_reachable_on_the_jumps() {
    let sample = root().join("data/samples/lafan1_jumps.bvh");
    let path = if sample.is_file() {
        sample
    } else {
        let Some(p) = shared::shared_file("data/bvh/lafan1_take_via_bvhtools_test2.bvh") else {
            return;
        };
        p
    };
    let bvh = bvh::from_path(&path).unwrap();
    let human = derive::human_body(&bvh, &fk::FkOptions::default(), "jumps").unwrap();
    for (key, hand_mm, foot_mm) in [("unitree_g1", 76.0, 4.0), ("engineai_pm01", 110.0, 8.0)] {
        let (model, _) = shipped(key);
        let roles = RobotRoles::recognise(&model).unwrap();
        let config = derive::derive(&model, &roles, &human, key).unwrap();
        let (_, diag) = retarget::internals::retarget_bvh(
            &bvh,
            &model,
            &config,
            &retarget::RetargetOptions::gmr(),
        )
        .unwrap();
        let stats = diag.position_error_stats();
        let mean_of = |part: fk::Part| {
            let bodies: Vec<f64> = [fk::Side::Left, fk::Side::Right]
                .iter()
                .map(|&side| {
                    let body = roles.roles[&fk::Role::of(part, side)].name.as_str();
                    let k = diag.body_names.iter().position(|b| b == body).unwrap();
                    stats[k].0 * 1000.0
                })
                .collect();
            bodies.iter().sum::<f64>() / 2.0
        };
        let (hand, foot) = (mean_of(fk::Part::Hand), mean_of(fk::Part::Foot));
        assert!(hand < hand_mm && foot < foot_mm, "{key}: hands {hand:.1} mm, feet {foot:.1} mm");
    }
}

/// The scaled human's feet stand about as far apart as the robot's own (the copy fit's
/// sideways offset): the sideways offset of a foot is not fitted to the sole's height in
/// the postures where the human's foot rolls a little, which put the scaled LAFAN1 walk's
/// feet 134 mm apart on the N1 (its feet stand 240 mm apart) and had the default solve push
/// them back apart (the G1: 188 mm against 237 mm on these frames; 250 mm now). Median over
/// the walk's frames of the foot targets' sideways distance (across the root's heading) in
/// GMR's solve, against the feet's at `qpos0`.
#[test]
fn the_scaled_feet_stand_as_wide_as_the_robots() {
    let Some(bvh) = lafan_walk() else { return };
    let bvh = first_frames(bvh, 900);
    let human = derive::human_body(&bvh, &fk::FkOptions::default(), "walk").unwrap();
    // (ToddlerBot's legs are long for its hips: copying the human's thighs brings its feet
    // in, to 45 mm apart on the whole walk against 74 mm at `qpos0`.)
    for key in ["unitree_g1", "booster_t1_29dof", "fourier_n1", "engineai_pm01"] {
        let (model, _) = shipped(key);
        let roles = RobotRoles::recognise(&model).unwrap();
        let config = derive::derive(&model, &roles, &human, key).unwrap();
        let feet = [Side::Left, Side::Right].map(|s| roles.body(Role::of(Part::Foot, s)).unwrap());
        let mut data = mjcf::Data::new(&model);
        model.kinematics(&model.qpos0, &mut data);
        let stand = (data.xpos[feet[0]] - data.xpos[feet[1]]).y;
        let (motion, _) =
            retarget::internals::retarget_bvh(&bvh, &model, &config, &RetargetOptions::gmr())
                .unwrap();
        let targets = motion.targets.as_ref().unwrap();
        let k = feet
            .map(|b| targets.body_names.iter().position(|n| *n == model.bodies[b].name).unwrap());
        let slots = targets.body_names.len();
        let mut widths: Vec<f64> = (0..motion.num_frames())
            .map(|t| {
                let q = motion.frame(t);
                let yaw = (2.0 * (q[3] * q[6] + q[4] * q[5]))
                    .atan2(1.0 - 2.0 * (q[5] * q[5] + q[6] * q[6]));
                let d = targets.pos[t * slots + k[0]] - targets.pos[t * slots + k[1]];
                -yaw.sin() * d.x + yaw.cos() * d.y
            })
            .collect();
        widths.sort_by(f64::total_cmp);
        let median = widths[widths.len() / 2];
        assert!(median > 0.85 * stand, "{key}: {median:.3} m apart, {stand:.3} m at qpos0");
    }
}

#[test]
fn a_tuned_config_that_turns_a_knee_over_contradicts_the_robot() {
    let (model, _) = shipped("unitree_g1");
    let roles = RobotRoles::recognise(&model).unwrap();
    let human = HumanBody::canonical();
    let derived = derive::derive(&model, &roles, &human, "derived").unwrap();
    assert_eq!(derive::contradiction(&derived, &derived, &roles), None);
    // A copy with one knee's rotation offset turned half a turn about its own z, and one
    // with a hand's: the knee contradicts the robot's joint frames, the hand is not asked.
    let knee = roles.roles[&Role::LeftShin].name.clone();
    let hand = roles.roles[&Role::LeftHand].name.clone();
    let turned = |body: &str, angle: f64| {
        let mut config = derived.clone();
        let entry = config.ik_match_table1.iter_mut().find(|e| e.robot_body == body).unwrap();
        let turn = nalgebra::UnitQuaternion::from_axis_angle(&nalgebra::Vector3::z_axis(), angle);
        entry.rot_offset *= turn;
        config
    };
    let found = derive::contradiction(&turned(&knee, 3.0), &derived, &roles).unwrap();
    assert_eq!(found.body, knee);
    assert!((found.angle - 3.0).abs() < 1e-9, "{}", found.angle);
    assert_eq!(derive::contradiction(&turned(&knee, 1.4), &derived, &roles), None);
    assert_eq!(derive::contradiction(&turned(&hand, 3.0), &derived, &roles), None);
}
