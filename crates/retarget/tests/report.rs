//! Quality report on hand-made G1 motions whose metrics follow from their construction.

#[path = "../../../tests/support/shared.rs"]
mod shared;

use nalgebra::Vector3;
use retarget::internals::detect_feet;
use retarget::report::{report, ReportOptions};
use retarget::{FootContacts, RobotMotion, TrackedTargets};

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
    let strict = {
        let mut o = ReportOptions::default();
        o.slide_speed = 0.2;
        o
    };
    let rep = report(&motion, model, &strict).unwrap();
    assert_eq!(rep.feet[0].sliding_frames, 19);
    // Too fast for contact (above contact_speed): the sliding frames stop being contact.
    let loose = {
        let mut o = ReportOptions::default();
        o.contact_speed = 0.2;
        o
    };
    let rep = report(&motion, model, &loose).unwrap();
    assert_eq!(rep.feet[0].contact_frames, FRAMES - 19);
    assert_eq!(rep.feet[0].contact_phases, 2);
}

/// The whole robot pitches forward about the front bottom edge of its soles (heels up, as a
/// foot rolling onto its toes): the feet's contact points stay where they are while the
/// ankles move at over 0.1 m/s. Nothing slides.
#[test]
fn a_foot_rolling_over_its_toes_does_not_slide() {
    let model = repo_g1();
    let z = standing_height(&model, 0.0);
    let mut data = mjcf::Data::new(&model);
    let mut q0 = model.qpos0.clone();
    q0[2] = z;
    model.kinematics(&q0, &mut data);
    let sole = model.geom_id("left_sole").unwrap();
    let (c, r, s) = (data.geom_xpos[sole], data.geom_xmat[sole], model.geoms[sole].size);
    // The front bottom edge of the box sole (x forward at rest), on the floor.
    let front = (0..3).map(|i| s[0] * r[(0, i)].abs()).sum::<f64>();
    let pivot = Vector3::new(c.x + front, 0.0, 0.0);
    let mut qpos = Vec::new();
    for t in 0..FRAMES {
        // Still, then 0 → 0.6 rad in 10 frames (1.8 rad/s), then still.
        let angle = 0.6 * ((t as f64 - 10.0) / 10.0).clamp(0.0, 1.0);
        let turn = nalgebra::UnitQuaternion::from_axis_angle(&Vector3::y_axis(), angle);
        let root = Vector3::new(q0[0], q0[1], q0[2]);
        let moved = pivot + turn * (root - pivot);
        let mut q = q0.clone();
        q[..3].copy_from_slice(moved.as_slice());
        q[3..7].copy_from_slice(&[turn.w, turn.i, turn.j, turn.k]);
        qpos.extend(q);
    }
    let rep =
        report(&motion_from(&model, qpos.clone()), &model, &ReportOptions::default()).unwrap();
    let ankle = model.body_id("left_ankle_roll_link").unwrap();
    let origin_speed = {
        let (a, b) = (14, 16);
        let mut at = |t: usize| {
            model.kinematics(&qpos[t * model.nq..(t + 1) * model.nq], &mut data);
            data.xpos[ankle]
        };
        let d = at(b) - at(a);
        d.x.hypot(d.y) * FPS / 2.0
    };
    assert!(origin_speed > 0.1, "the ankle moves at {origin_speed} m/s");
    for foot in &rep.feet {
        assert!(foot.contact_frames > FRAMES / 2, "{foot:?}");
        assert_eq!(foot.sliding_frames, 0, "{foot:?}");
        assert!(foot.slide_per_phase_cm_max < 0.5, "{foot:?}");
    }
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
    let opts = {
        let mut o = ReportOptions::default();
        o.joint_velocity_limit = Some(1.0);
        o
    };
    let rep = report(&motion, &model, &opts).unwrap();
    let j = rep.joints.iter().find(|j| j.joint == "left_knee_joint").unwrap();
    assert!((j.vel_max - rate).abs() < 1e-9 && (j.vel_p99 - rate).abs() < 1e-9, "{j:?}");
    assert_eq!(j.vel_over_limit, FRAMES);
    assert!(j.jitter < 1e-9, "{j:?}");
    let other = rep.joints.iter().find(|j| j.joint == "right_knee_joint").unwrap();
    assert_eq!((other.vel_max, other.vel_over_limit, other.jitter), (0.0, 0, 0.0));
    let tracking = rep.tracking.as_ref().unwrap();
    let pos = |k: usize| tracking[k].pos_m.expect("every body is a position target by default");
    assert!(pos(0).max < 1e-12 && tracking[0].rot_rad.max < 1e-7, "{tracking:?}");
    for v in [pos(1).mean, pos(1).p95, pos(1).max] {
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
    let opts = {
        let mut o = ReportOptions::default();
        o.feet = Some(["left_foot".to_owned(), "right_ankle_roll_link".to_owned()]);
        o
    };
    let err = report(&motion, &model, &opts).unwrap_err().to_string();
    assert!(err.contains("left_foot"), "{err}");
}

/// A robot whose names say nothing (`link1`…) gets the recogniser's feet: the report works
/// and the default solve plants them (both use `detect_feet`).
#[test]
fn feet_of_a_robot_with_numbered_names_come_from_the_recogniser() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/robots/numbered.xml");
    let model = mjcf::Model::from_file(&path).unwrap();
    let roles = retarget::RobotRoles::recognise(&model).unwrap();
    let feet = detect_feet(&model).unwrap();
    assert_eq!(feet, roles.soles.map(|s| s.body));
    let mut data = mjcf::Data::new(&model);
    model.kinematics(&model.qpos0, &mut data);
    let [l, r] = feet;
    let left = Vector3::z().cross(&roles.forward);
    assert!((data.xpos[l] - data.xpos[r]).dot(&left) > 0.0, "the left foot is on the left");
}

/// A body named like an ankle above the recognised foot (Adam Lite's `anklePitchLeft` over
/// its `toeLeft`) is an ankle link, not the foot: planting it planted its tracked ancestor,
/// the shin, and Adam Lite's soles were in the stance band in 6 % of the LAFAN1 walk.
#[test]
fn an_ankle_link_above_the_foot_is_not_taken_for_the_foot() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/robots/numbered.xml");
    // link16 / link22: the bodies of the ankle pitch joints, above the feet link15 / link21.
    let xml = std::fs::read_to_string(path)
        .unwrap()
        .replace(r#""link16""#, r#""anklePitchLeft""#)
        .replace(r#""link22""#, r#""anklePitchRight""#);
    let model = mjcf::Model::from_xml_str(&xml, None).unwrap();
    let roles = retarget::RobotRoles::recognise(&model).unwrap();
    let feet = detect_feet(&model).unwrap();
    assert_eq!(feet.map(|b| model.bodies[b].name.clone()), ["link15", "link21"]);
    assert_eq!(feet, roles.soles.map(|s| s.body));
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

/// A toy robot: a box base on a free joint; spheres `a` and `b` slide towards each other
/// along y; spheres `e` and `f` overlap by 2 cm at qpos0 (a pair the model is built with).
const TOY: &str = r#"<mujoco model="toy"><worldbody>
  <body name="base" pos="0 0 1"><freejoint/><geom name="base" type="box" size="0.1 0.1 0.1"/>
    <body name="a" pos="0 0.3 0"><joint name="ja" type="slide" axis="0 1 0"/><geom name="a" size="0.05"/></body>
    <body name="b" pos="0 -0.3 0"><joint name="jb" type="slide" axis="0 1 0"/><geom name="b" size="0.05"/></body>
    <body name="e" pos="0.5 0 0"><joint name="je" type="slide"/><geom name="e" size="0.05"/></body>
    <body name="f" pos="0.58 0 0"><joint name="jf" type="slide"/><geom name="f" size="0.05"/></body>
  </body></worldbody></mujoco>"#;

fn toy_motion(model: &mjcf::Model, frames: &[(f64, f64)]) -> RobotMotion {
    // (root z, slide of `a`)
    let mut qpos = Vec::new();
    for &(z, qa) in frames {
        let mut q = model.qpos0.clone();
        q[2] = z;
        q[model.joints[model.joint_id("ja").unwrap()].qpos_adr] = qa;
        qpos.extend(q);
    }
    motion_from(model, qpos)
}

fn toy_options() -> ReportOptions {
    {
        let mut o = ReportOptions::default();
        o.feet = Some(["e".to_owned(), "f".to_owned()]);
        o
    }
}

#[test]
fn self_collision_is_counted_without_the_pairs_touching_at_rest() {
    let model = mjcf::Model::from_xml_str(TOY, None).unwrap();
    // a and b 0.6 apart at rest: slide a by −0.52 → centres 0.08 apart, 2 cm deep; by −0.505
    // → 0.5 cm deep (penetrating, not deep).
    let frames: Vec<(f64, f64)> =
        [0.0; 4].into_iter().chain([-0.52; 3]).chain([-0.505; 3]).map(|qa| (1.0, qa)).collect();
    let rep = report(&toy_motion(&model, &frames), &model, &toy_options()).unwrap();
    let s = &rep.self_collision;
    // Pairs: a-b, a-e, a-f, b-e, b-f, e-f (each sphere with the base is parent-child).
    assert_eq!((s.pairs, s.ignored_pairs), (5, 1), "{s:?}");
    assert_eq!((s.frames_deep, s.frames_penetrating), (3, 6), "{s:?}");
    assert!((s.max_depth_cm - 2.0).abs() < 1e-9, "{s:?}");
    assert_eq!(s.worst_pair, Some(["a".to_owned(), "b".to_owned()]));
    assert_eq!(rep.ground_penetration.frames, 0);
    // No contacts, no published speed limits: those metrics are absent, not zero.
    assert!(rep.skating.is_none() && rep.stance.is_none() && rep.joint_speed.is_none());
    let json = serde_json::to_value(&rep).unwrap();
    assert!(json["skating"].is_null() && json["joint_speed"].is_null());
    assert_eq!(json["self_collision"]["worst_pair"][1], "b");
    let table = rep.to_string();
    assert!(
        table.contains("self-collision: 3 frames deeper than 1.0 cm, 6 penetrating"),
        "{table}"
    );
    assert!(table.contains("skating: - (no source foot contacts)"), "{table}");
}

#[test]
fn ground_penetration_covers_every_collision_geom() {
    let model = mjcf::Model::from_xml_str(TOY, None).unwrap();
    // The base box (half height 0.1) is the lowest geom: its bottom at z − 0.1.
    let frames: Vec<(f64, f64)> = [1.0, 0.08, 0.095, 0.085].into_iter().map(|z| (z, 0.0)).collect();
    let rep = report(&toy_motion(&model, &frames), &model, &toy_options()).unwrap();
    let g = &rep.ground_penetration;
    assert_eq!((g.geoms, g.frames), (5, 2), "{g:?}");
    assert!((g.duration - 0.5).abs() < 1e-15);
    assert!((g.max_depth_cm - 2.0).abs() < 1e-9, "{g:?}");
    assert_eq!(g.worst_geom.as_deref(), Some("base"));
    // The feet (spheres e, f: bottoms 5 cm above the box's) stay above the ground: the old
    // per-foot metric sees nothing.
    assert_eq!(rep.feet[0].penetration_frames, 0, "{:?}", rep.feet[0]);
    // A geom without contype and conaffinity is no collision geom.
    let off = TOY.replace(
        r#"name="base" type="box""#,
        r#"name="base" contype="0" conaffinity="0" type="box""#,
    );
    let model = mjcf::Model::from_xml_str(&off, None).unwrap();
    let rep = report(&toy_motion(&model, &frames), &model, &toy_options()).unwrap();
    let g = &rep.ground_penetration;
    assert_eq!((g.geoms, g.frames, g.max_depth_cm, g.worst_geom.as_deref()), (4, 0, 0.0, None));
}

fn contacts(left: impl Fn(usize) -> bool, right: impl Fn(usize) -> bool) -> FootContacts {
    FootContacts {
        left: (0..FRAMES).map(left).collect(),
        right: (0..FRAMES).map(right).collect(),
        on_toes: None,
    }
}

#[test]
fn skating_and_stance_follow_the_source_contacts() {
    let model = repo_g1();
    // Frames 11..=30 move 0.02 m each (0.6 m/s, backward differences); the rest stand.
    let (mut motion, _) = sliding_motion(&model, 0.6, 0.001);
    motion.contacts = Some(contacts(|_| true, |t| t < 20));
    let rep = report(&motion, &model, &ReportOptions::default()).unwrap();
    let k = rep.skating.as_ref().unwrap();
    assert_eq!((k.stance_frames, k.skating_frames), (FRAMES, 20), "{k:?}");
    assert!((k.duration - 0.5).abs() < 1e-15 && (k.max_speed - 0.6).abs() < 1e-9, "{k:?}");
    // Left foot in contact for frames 0..15 only: skating frames 11..=14.
    motion.contacts = Some(contacts(|t| t < 15, |_| false));
    let k = report(&motion, &model, &ReportOptions::default()).unwrap().skating.unwrap();
    assert_eq!((k.stance_frames, k.skating_frames), (15, 4), "{k:?}");
    // 0.6 m/s is below a 1 m/s threshold.
    let lax = {
        let mut o = ReportOptions::default();
        o.skate_speed = 1.0;
        o
    };
    assert_eq!(report(&motion, &model, &lax).unwrap().skating.unwrap().skating_frames, 0);

    // Stance: soles 1 mm up (in the band), then 3 cm up (floating) in the last 10 frames.
    let (mut motion, _) = sliding_motion(&model, 0.0, 0.001);
    let high = standing_height(&model, 0.03);
    for t in 30..FRAMES {
        motion.qpos[t * model.nq + 2] = high;
    }
    motion.contacts = Some(contacts(|_| true, |t| t % 2 == 0));
    let rep = report(&motion, &model, &ReportOptions::default()).unwrap();
    let s = rep.stance.as_ref().unwrap();
    // Samples: 40 left + 20 right; floating: frames 30..40, 10 left + 5 right.
    assert_eq!((s.samples, s.floating), (60, 15), "{s:?}");
    assert!((s.floating_share - 0.25).abs() < 1e-15 && (s.sole_in_band_share - 0.75).abs() < 1e-15);
    let table = rep.to_string();
    assert!(
        table.contains("stance: 60 source-contact samples, 25.0% floating above 2.0 cm"),
        "{table}"
    );
    // Contacts of the wrong length are an error.
    motion.contacts =
        Some(FootContacts { left: vec![true; 3], right: vec![true; 3], on_toes: None });
    assert!(report(&motion, &model, &ReportOptions::default()).is_err());
}

#[test]
fn joint_speed_over_published_limits() {
    let mut model = repo_g1();
    let (mut motion, _) = sliding_motion(&model, 0.0, 0.0);
    let knee = model.joint_id("left_knee_joint").unwrap();
    let adr = model.joints[knee].qpos_adr;
    for t in 0..FRAMES {
        motion.qpos[t * model.nq + adr] = 0.1 + 1.5 * t as f64 / FPS; // 1.5 rad/s
    }
    model.joints[knee].velocity_limit = Some(1.0);
    let elbow = model.joint_id("left_elbow_joint").unwrap();
    model.joints[elbow].velocity_limit = Some(2.0);
    let rep = report(&motion, &model, &ReportOptions::default()).unwrap();
    let j = rep.joint_speed.as_ref().unwrap();
    assert_eq!((j.joints, j.violations), (2, FRAMES), "{j:?}");
    assert!((j.worst_ratio - 1.5).abs() < 1e-9 && j.worst_joint == "left_knee_joint", "{j:?}");
    let json = serde_json::to_value(&rep).unwrap();
    assert_eq!(json["joint_speed"]["violations"], FRAMES);
    assert!(rep.to_string().contains("joint speed limits: 40 frames × joints over (2 joints"));
}

// Motion over time (issue 30): root acceleration, jitter over nv, the dynamics check.

/// The shipped G1 at `qpos0` with its root at `root(t)` (m) turned by `yaw(t)` (rad) about z.
fn root_motion(
    model: &mjcf::Model,
    frames: usize,
    root: impl Fn(f64) -> Vector3<f64>,
    yaw: impl Fn(f64) -> f64,
) -> RobotMotion {
    let mut qpos = Vec::new();
    for t in 0..frames {
        let s = t as f64 / FPS;
        let mut q = model.qpos0.clone();
        let p = root(s);
        q[..3].copy_from_slice(&[p.x, p.y, p.z]);
        let h = yaw(s) / 2.0;
        q[3..7].copy_from_slice(&[h.cos(), 0.0, 0.0, h.sin()]);
        qpos.extend(q);
    }
    motion_from(model, qpos)
}

const G: f64 = retarget::report::GRAVITY;

#[test]
fn free_fall_accelerates_the_root_by_g_and_needs_no_wrench() {
    let model = repo_g1();
    let z0 = standing_height(&model, 3.0);
    // Thrown forward and up: 2 m/s ahead, 4 m/s up, falling at g; no contact (3 m up and more).
    let motion = root_motion(
        &model,
        FRAMES,
        |s| Vector3::new(2.0 * s, 0.0, z0 + 4.0 * s - G * s * s / 2.0),
        |_| 0.3,
    );
    let rep = report(&motion, &model, &ReportOptions::default()).unwrap();
    let a = &rep.root_acceleration;
    assert_eq!(a.body, "pelvis");
    assert_eq!((a.motion.frames, a.motion.frames_over), (FRAMES - 2, 0), "{a:?}");
    assert!((a.motion.mean_mps2 - G).abs() < 1e-9 && (a.motion.max_mps2 - G).abs() < 1e-9);
    assert!(a.target.is_none(), "no targets");
    let d = rep.dynamics.as_ref().expect("the G1 has its inertials");
    assert!((d.mass_kg - 34.4).abs() < 0.1, "{}", d.mass_kg);
    assert_eq!((d.frames, d.support_frames, d.flight.frames), (FRAMES - 4, 0, FRAMES - 4));
    assert!(d.flight.residual_mg.max < 1e-9, "{:?}", d.flight);
    assert_eq!(d.flight.frames_over, 0);
    // Held still in the air instead, it needs its whole weight.
    let held = root_motion(&model, FRAMES, |_| Vector3::new(0.0, 0.0, z0), |_| 0.3);
    let d = report(&held, &model, &ReportOptions::default()).unwrap().dynamics.unwrap();
    assert!((d.flight.residual_mg.mean - 1.0).abs() < 1e-9, "{:?}", d.flight);
    assert_eq!((d.flight.share_over, d.share_over), (1.0, 1.0));
}

#[test]
fn a_kick_of_the_root_is_one_frame_over_2g() {
    let model = repo_g1();
    let z = standing_height(&model, 0.5);
    // At rest until frame 10, then 1 m/s sideways: one second difference of 1/30 m, 30 m/s².
    let motion =
        root_motion(&model, FRAMES, |s| Vector3::new(0.0, (s - 10.0 / FPS).max(0.0), z), |_| 0.0);
    let a = report(&motion, &model, &ReportOptions::default()).unwrap().root_acceleration;
    assert_eq!(a.motion.frames_over, 1, "{a:?}");
    assert!((a.motion.max_mps2 - FPS).abs() < 1e-9, "{a:?}");
    assert!((a.motion.mean_mps2 - FPS / (FRAMES - 2) as f64).abs() < 1e-9);
    assert!((a.motion.share_over - 1.0 / (FRAMES - 2) as f64).abs() < 1e-15);
}

#[test]
fn the_root_targets_acceleration_is_the_scaled_humans() {
    let model = repo_g1();
    let z = standing_height(&model, 0.0);
    let mut motion = root_motion(&model, FRAMES, |_| Vector3::new(0.0, 0.0, z), |_| 0.0);
    // Targets: the pelvis bobbing at 3 g (a parabola), a hand target moving anyhow.
    let names = vec!["left_wrist_yaw_link".to_owned(), "pelvis".to_owned()];
    let mut pos = Vec::new();
    for t in 0..FRAMES {
        let s = t as f64 / FPS;
        pos.push(Vector3::new(s * s * 50.0, 0.0, 1.0));
        pos.push(Vector3::new(0.0, 0.0, 0.8 + 1.5 * G * s * s));
    }
    let quat = vec![nalgebra::UnitQuaternion::identity(); pos.len()];
    motion.targets = Some(TrackedTargets { body_names: names, pos, quat });
    // The config's root (GMR's `robot_root_name`) names the pelvis target.
    let opts = {
        let mut o = ReportOptions::default();
        o.root_target = Some("pelvis".to_owned());
        o
    };
    let rep = report(&motion, &model, &opts).unwrap();
    let t = rep.root_acceleration.target.expect("the pelvis is a target");
    assert!((t.mean_mps2 - 3.0 * G).abs() < 1e-6 && t.share_over == 1.0, "{t:?}");
    assert_eq!(rep.root_acceleration.target_body.as_deref(), Some("pelvis"));
    assert_eq!(rep.root_acceleration.motion.mean_mps2, 0.0);
    assert!(rep.to_string().contains("scaled human (target of pelvis): mean 29.4 m/s²"), "{rep}");
    // Without a config, the first target (here the hand, at 100 m/s²).
    let first = report(&motion, &model, &ReportOptions::default()).unwrap().root_acceleration;
    assert_eq!(first.target_body.as_deref(), Some("left_wrist_yaw_link"));
    assert!((first.target.unwrap().mean_mps2 - 100.0).abs() < 1e-6);
    // A root that is no target: none.
    let opts = {
        let mut o = ReportOptions::default();
        o.root_target = Some("torso_link".to_owned());
        o
    };
    assert!(report(&motion, &model, &opts).unwrap().root_acceleration.target.is_none());
}

#[test]
fn jitter_counts_every_velocity_coordinate() {
    let model = repo_g1();
    let z = standing_height(&model, 0.0);
    // Root: 3 m/s² along x, yaw at 2 rad/s²; the left knee at 5 rad/s²; the rest still.
    let mut motion = root_motion(&model, FRAMES, |s| Vector3::new(1.5 * s * s, 0.0, z), |s| s * s);
    let knee = model.joints[model.joint_id("left_knee_joint").unwrap()].qpos_adr;
    for t in 0..FRAMES {
        let s = t as f64 / FPS;
        motion.qpos[t * model.nq + knee] = 0.3 + 2.5 * s * s;
    }
    let j = report(&motion, &model, &ReportOptions::default()).unwrap().jitter;
    assert_eq!(j.coordinates, model.nv);
    // Mean |q̈| over each group's coordinates: one of three moves in each root group.
    assert!((j.root_translation.unwrap() - 1.0).abs() < 1e-6, "{j:?}");
    assert!((j.root_rotation.unwrap() - 2.0 / 3.0).abs() < 1e-6, "{j:?}");
    let joints = (model.nv - 6) as f64;
    assert!((j.joints - 5.0 / joints).abs() < 1e-6, "{j:?}");
    assert!((j.all - 10.0 / model.nv as f64).abs() < 1e-6, "{j:?}");
    // A yaw past half a turn between frames is the shorter way round: no jump at ±π.
    let spin = root_motion(&model, FRAMES, |_| Vector3::new(0.0, 0.0, z), |s| 0.5 * FPS * s);
    let j = report(&spin, &model, &ReportOptions::default()).unwrap().jitter;
    assert!(j.root_rotation.unwrap() < 1e-9, "{j:?}");
}

#[test]
fn standing_on_the_floor_needs_no_extra_wrench_and_floating_needs_its_weight() {
    let model = repo_g1();
    let stand = standing_height(&model, 0.001);
    let motion = root_motion(&model, FRAMES, |_| Vector3::new(0.3, -0.2, stand), |_| 0.7);
    let rep = report(&motion, &model, &ReportOptions::default()).unwrap();
    let d = rep.dynamics.as_ref().unwrap();
    assert_eq!((d.support_frames, d.flight.frames), (FRAMES - 4, 0), "{d:?}");
    assert!(d.residual_mg.max < 1e-6, "{:?}", d.residual_mg);
    assert_eq!((d.frames_over, d.cop.frames, d.cop.frames_outside), (0, FRAMES - 4, 0));
    assert_eq!(d.cop.outside_cm.max, 0.0);
    // 5 cm up: no point within 1 cm of the floor, the whole weight is missing.
    let high = standing_height(&model, 0.05);
    let floating = root_motion(&model, FRAMES, |_| Vector3::new(0.3, -0.2, high), |_| 0.7);
    let d = report(&floating, &model, &ReportOptions::default()).unwrap().dynamics.unwrap();
    assert_eq!((d.support_frames, d.flight.frames), (0, FRAMES - 4));
    assert!(
        (d.residual_mg.mean - 1.0).abs() < 1e-9 && (d.residual_force_mg.max - 1.0).abs() < 1e-9
    );
    assert!(d.residual_torque_mgl.max < 1e-9 && d.share_over == 1.0, "{d:?}");
    // The feet pitched at the ankles (0.5 rad), the root as high: one edge of each sole is on
    // the floor, not under the centre of mass, which no force there can hold up alone.
    let mut tiptoe = motion.clone();
    for side in ["left", "right"] {
        let a =
            model.joints[model.joint_id(&format!("{side}_ankle_pitch_joint")).unwrap()].qpos_adr;
        for t in 0..FRAMES {
            tiptoe.qpos[t * model.nq + a] = 0.5;
        }
    }
    let d = report(&tiptoe, &model, &ReportOptions::default()).unwrap().dynamics.unwrap();
    assert_eq!((d.support_frames, d.cop.frames_outside), (FRAMES - 4, FRAMES - 4), "{d:?}");
    let out = d.cop.outside_cm;
    assert!(out.mean > 3.0 && out.max < 15.0 && d.residual_mg.mean > 0.03, "{d:?}");
}

#[test]
fn the_dynamics_check_is_not_available_without_masses() {
    // The toy robot's bodies have geoms and no inertials: MuJoCo would infer their masses.
    let model = mjcf::Model::from_xml_str(TOY, None).unwrap();
    let frames: Vec<(f64, f64)> = (0..10).map(|_| (1.0, 0.0)).collect();
    let rep = report(&toy_motion(&model, &frames), &model, &toy_options()).unwrap();
    assert!(rep.dynamics.is_none());
    let why = rep.dynamics_unavailable.as_deref().unwrap();
    assert!(why.contains("\"base\" has geoms but no inertial"), "{why}");
    assert!(rep.to_string().contains("dynamics: not available (body \"base\""), "{rep}");
    let err =
        retarget::report::dynamics_frames(&toy_motion(&model, &frames), &model, &toy_options());
    assert!(matches!(err, Err(retarget::Error::NoMasses(_))), "{err:?}");
}

#[test]
fn the_json_carries_the_new_sections() {
    let model = repo_g1();
    let (motion, _) = sliding_motion(&model, 0.3, 0.001);
    let json =
        serde_json::to_value(report(&motion, &model, &ReportOptions::default()).unwrap()).unwrap();
    for key in ["mean_mps2", "max_mps2", "share_over", "frames_over", "frames"] {
        assert!(json["root_acceleration"]["motion"][key].is_number(), "{key}: {json}");
    }
    assert!(json["root_acceleration"]["target"].is_null());
    assert_eq!(json["root_acceleration"]["threshold_mps2"], 2.0 * G);
    for key in ["root_translation", "root_rotation", "joints", "all", "coordinates"] {
        assert!(json["jitter"][key].is_number(), "{key}");
    }
    let d = &json["dynamics"];
    for key in ["mass_kg", "lever_m", "share_over", "frames_over", "support_share_over"] {
        assert!(d[key].is_number(), "{key}: {d}");
    }
    assert!(d["residual_mg"]["p95"].is_number() && d["flight"]["residual_mg"]["mean"].is_number());
    assert!(d["cop"]["outside_cm"]["max"].is_number() && d["cop"]["share_outside"].is_number());
    assert_eq!((d["friction"].as_f64(), d["cone_edges"].as_u64()), (Some(0.8), Some(8)));
    assert!(json["dynamics_unavailable"].is_null());
}

#[test]
fn the_needed_torque_is_the_rate_of_the_centroidal_angular_momentum() {
    // One free body, 2 kg, principal moments (1, 2, 3) about axes turned 90° about x (the
    // third principal axis along the body's −y), spun up about the world's y at α = 4 rad/s²
    // while held in place: it needs its weight and the torque 3 α about y. No geoms: no
    // contact, and L = 1 m.
    let xml = r#"<mujoco model="spinner"><worldbody><body name="b" pos="0 0 1"><freejoint/>
        <inertial pos="0 0 0" quat="0.7071067811865476 0.7071067811865476 0 0" mass="2" diaginertia="1 2 3"/>
        </body></worldbody></mujoco>"#;
    let model = mjcf::Model::from_xml_str(xml, None).unwrap();
    let alpha = 4.0;
    let mut qpos = Vec::new();
    for t in 0..FRAMES {
        let s = t as f64 / FPS;
        let h = alpha * s * s / 4.0; // half the angle ½ α s²
        qpos.extend([0.0, 0.0, 1.0, h.cos(), 0.0, h.sin(), 0.0]);
    }
    let motion = RobotMotion {
        fps: FPS,
        nq: model.nq,
        qpos,
        joint_names: vec![],
        body_names: vec!["b".to_owned()],
        targets: None,
        contacts: None,
    };
    let frames =
        retarget::report::dynamics_frames(&motion, &model, &ReportOptions::default()).unwrap();
    assert_eq!(frames.len(), FRAMES - 4);
    for d in &frames {
        assert_eq!(d.contacts, 0);
        assert!((d.force[2] - 2.0 * G).abs() < 1e-9 && d.force[0].abs() < 1e-9, "{d:?}");
        assert!((d.torque[1] - 3.0 * alpha).abs() < 1e-6, "{d:?}");
        assert!(d.torque[0].abs() < 1e-6 && d.torque[2].abs() < 1e-6, "{d:?}");
        let expected = (1.0f64 + (3.0 * alpha / (2.0 * G)).powi(2)).sqrt();
        assert!((d.residual - expected).abs() < 1e-6, "{} vs {expected}", d.residual);
    }
    let rep = report(&motion, &model, &ReportOptions::default());
    // The report needs feet; this body has none, so only the per-frame check runs here.
    assert!(rep.is_err());
}

// The verdict and the accelerations averaged over a time (issue 39).

/// The names of the checks `rep` flags.
fn flags(rep: &retarget::report::QualityReport) -> Vec<&'static str> {
    rep.verdict.flag_names().collect()
}

/// The shipped G1 at `qpos0`, its root at `root(s)` (m), sampled at `fps` for `seconds`.
fn root_motion_at(
    model: &mjcf::Model,
    fps: f64,
    seconds: f64,
    root: impl Fn(f64, usize) -> Vector3<f64>,
) -> RobotMotion {
    let frames = (seconds * fps).round() as usize + 1;
    let mut qpos = Vec::new();
    for t in 0..frames {
        let mut q = model.qpos0.clone();
        let p = root(t as f64 / fps, t);
        q[..3].copy_from_slice(&[p.x, p.y, p.z]);
        qpos.extend(q);
    }
    RobotMotion { fps, ..motion_from(model, qpos) }
}

/// Uniform in [−1, 1], a fixed function of `k` (a hash: no state, no crate).
fn noise(k: usize) -> f64 {
    let mut x = (k as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    x ^= x >> 29;
    x = x.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x ^= x >> 32;
    (x % 2_000_001) as f64 / 1_000_000.0 - 1.0
}

#[test]
fn the_same_motion_at_30_and_120_fps_needs_the_same_wrench() {
    let model = repo_g1();
    let z = standing_height(&model, 0.005);
    // Standing, the root swaying 2.8 cm forth and back at 2 Hz (0.45 g at the peaks: more
    // torque than the soles can take), `noise` (m) of capture noise in every frame (forward
    // and up), whatever the rate.
    let measure = |fps: f64, sway: f64, noise_m: f64| {
        let root = |s: f64, t: usize| {
            let x = sway * (std::f64::consts::TAU * 2.0 * s).sin();
            Vector3::new(x + noise_m * noise(2 * t), 0.0, z + noise_m * noise(2 * t + 1))
        };
        let rep =
            report(&root_motion_at(&model, fps, 6.0, root), &model, &ReportOptions::default())
                .unwrap();
        let (d, five) = (rep.dynamics.unwrap(), rep.dynamics_5_frame.unwrap());
        let a = rep.root_acceleration.averaged;
        (d.share_over, five.share_over, d.half_step_frames, a.motion.mean_mps2, d.window_s)
    };
    let (at30, five30, h30, a30, w30) = measure(30.0, 0.028, 0.0005);
    let (at120, _, h120, a120, w120) = measure(120.0, 0.028, 0.0005);
    assert_eq!((h30, h120), (1, 5));
    assert!((w30 - 4.0 / 30.0).abs() < 1e-12 && (w120 - 1.0 / 6.0).abs() < 1e-12);
    // At 30 fps the averaged figure is the 5-frame one.
    assert_eq!(at30, five30);
    assert!(at30 > 0.3 && at30 < 0.8, "the sway's peaks need wrench: {at30}");
    // The stated tolerance: 5 points of share, and 10 % of the mean root acceleration.
    assert!((at120 - at30).abs() < 0.05, "30 fps {at30}, 120 fps {at120}");
    assert!((a120 / a30 - 1.0).abs() < 0.10, "30 fps {a30} m/s², 120 fps {a120} m/s²");
    // Standing still with 1 mm of capture noise needs no wrench at either rate over 1/6 s;
    // five frames at 120 fps (42 ms) read the noise as force.
    let (still30, _, _, _, _) = measure(30.0, 0.0, 0.001);
    let (still120, five120, _, _, _) = measure(120.0, 0.0, 0.001);
    assert!(still30 < 0.05 && still120 < 0.05, "30 fps {still30}, 120 fps {still120}");
    assert!(five120 > 0.5, "{five120}");
}

#[test]
fn standing_still_on_the_floor_is_ok() {
    let mut model = repo_g1();
    let knee = model.joint_id("left_knee_joint").unwrap();
    model.joints[knee].velocity_limit = Some(1.0);
    let stand = standing_height(&model, 0.001);
    let mut motion = root_motion(&model, FRAMES, |_| Vector3::new(0.3, -0.2, stand), |_| 0.7);
    motion.contacts = Some(contacts(|_| true, |_| true));
    let rep = report(&motion, &model, &ReportOptions::default()).unwrap();
    assert!(rep.verdict.ok, "{:?}", rep.verdict.flags);
    // Every check was measured: contacts, masses and the G1's published speed limits exist.
    let names: Vec<&str> = rep.verdict.checks.iter().map(|c| c.name).collect();
    assert_eq!(
        names,
        [
            "penetration",
            "self_collision",
            "floor_skating",
            "stance",
            "floating",
            "joint_limits",
            "joint_jumps",
            "joint_speed",
            "root_acceleration",
            "dynamics",
            "gmr_floating",
            "gmr_joint_limits",
            "gmr_joint_jumps",
            "gmr_self_collision"
        ]
    );
    assert!(rep.verdict.checks.iter().all(|c| c.ok == Some(true)), "{:?}", rep.verdict.checks);
    let text = rep.to_string();
    assert!(text.starts_with("verdict: ok (14 checks within their caps)"), "{text}");
    let json = serde_json::to_value(&rep).unwrap();
    assert_eq!(json["verdict"]["ok"], true);
    assert_eq!(json["verdict"]["flags"].as_array().map(Vec::len), Some(0));
}

#[test]
fn each_flag_fires_on_a_motion_made_to_break_it() {
    let model = repo_g1();
    let opts = ReportOptions::default();
    // Sunk 2 cm: the soles under the floor in every frame.
    let (sunk, _) = sliding_motion(&model, 0.0, -0.02);
    assert_eq!(flags(&report(&sunk, &model, &opts).unwrap()), ["penetration"]);
    // Sliding 0.6 m/s on the floor for 20 of 40 frames.
    let (slide, _) = sliding_motion(&model, 0.6, 0.001);
    let rep = report(&slide, &model, &opts).unwrap();
    assert!(flags(&rep).contains(&"floor_skating"), "{:?}", flags(&rep));
    // 5 cm up while the source stands: out of the sole band, floating in stance; the robot
    // needs its whole weight.
    let (mut up, _) = sliding_motion(&model, 0.0, 0.05);
    up.contacts = Some(contacts(|_| true, |_| true));
    let rep = report(&up, &model, &opts).unwrap();
    assert_eq!(flags(&rep), ["stance", "floating", "dynamics"], "{:?}", rep.verdict.flags);
    let text = rep.to_string();
    assert!(text.starts_with("verdict: FLAGGED: stance, floating, dynamics\n"), "{text}");
    // 3 m up for 1.3 s: flying too long by our cap and by GMR's (12 cm for 1 s).
    let z = standing_height(&model, 3.0);
    let high = root_motion(&model, FRAMES, |_| Vector3::new(0.0, 0.0, z), |_| 0.0);
    let rep = report(&high, &model, &opts).unwrap();
    assert_eq!(flags(&rep), ["floating", "dynamics", "gmr_floating"], "{:?}", rep.verdict.flags);
    assert!(rep.to_string().contains("not checked: stance: no source foot contacts"));
    // A knee past its range in every frame by 0.1 rad.
    let (mut bent, _) = sliding_motion(&model, 0.0, 0.0);
    let knee = &model.joints[model.joint_id("left_knee_joint").unwrap()];
    for t in 0..FRAMES {
        bent.qpos[t * model.nq + knee.qpos_adr] = knee.range.unwrap()[1] + 0.1;
    }
    let bent = flags(&report(&bent, &model, &opts).unwrap());
    assert!(bent.contains(&"joint_limits") && bent.contains(&"gmr_joint_limits"), "{bent:?}");
    // An elbow jumping 1.2 rad in one frame (36 rad/s) and back.
    let (mut jump, _) = sliding_motion(&model, 0.0, 0.0);
    let elbow = model.joints[model.joint_id("left_elbow_joint").unwrap()].qpos_adr;
    jump.qpos[20 * model.nq + elbow] += 1.2;
    assert_eq!(flags(&report(&jump, &model, &opts).unwrap()), ["joint_jumps", "gmr_joint_jumps"]);
    // Every joint with a published speed limit (10 rad/s): held to it, not to the jump cap.
    let mut limited = model.clone();
    for j in &mut limited.joints {
        j.velocity_limit = Some(10.0);
    }
    let rep = report(&jump, &limited, &opts).unwrap();
    assert_eq!(flags(&rep), ["joint_speed", "gmr_joint_jumps"]);
    let jumps = rep.verdict.checks.iter().find(|c| c.name == "joint_jumps").unwrap();
    assert!(jumps.ok.is_none() && jumps.detail.contains("published speed limit"), "{jumps:?}");
    // The root shaken sideways at 3 g while the scaled human's pelvis stands still.
    let stand = standing_height(&model, 0.001);
    let mut shaken = root_motion(
        &model,
        FRAMES,
        |s| Vector3::new(0.0, 0.08 * (std::f64::consts::TAU * 3.0 * s).sin(), stand),
        |_| 0.0,
    );
    let names = vec!["pelvis".to_owned()];
    let pos = (0..FRAMES).map(|_| Vector3::new(0.0, 0.0, stand)).collect();
    let quat = vec![nalgebra::UnitQuaternion::identity(); FRAMES];
    shaken.targets = Some(TrackedTargets { body_names: names, pos, quat });
    let rep = report(&shaken, &model, &opts).unwrap();
    assert!(flags(&rep).contains(&"root_acceleration"), "{:?}", rep.verdict.flags);
    // The same without the human's targets: judged by the frames over 2 g.
    shaken.targets = None;
    let rep = report(&shaken, &model, &opts).unwrap();
    let root = rep.verdict.flags.iter().find(|c| c.name == "root_acceleration").unwrap();
    assert_eq!((root.unit, root.cap), ("share", 0.05), "{root:?}");
}

#[test]
fn self_collision_flags_ours_and_gmrs() {
    let model = mjcf::Model::from_xml_str(TOY, None).unwrap();
    // a into b: 2 cm deep in 3 of 40 frames (ours: any frame deeper than 1 cm; GMR's: 3 mm
    // in 7.5 % of the frames, under its 10 %, and 0.1 s, under its 0.6 s), then 5 mm deep in
    // 3 more frames: 15 % of the frames at 3 mm or more.
    let mut frames: Vec<(f64, f64)> = (0..FRAMES).map(|_| (1.0, 0.0)).collect();
    for f in &mut frames[10..13] {
        f.1 = -0.52;
    }
    let rep = report(&toy_motion(&model, &frames), &model, &toy_options()).unwrap();
    assert!(flags(&rep).contains(&"self_collision"), "{:?}", flags(&rep));
    assert!(!flags(&rep).contains(&"gmr_self_collision"), "{:?}", flags(&rep));
    for f in &mut frames[20..23] {
        f.1 = -0.505;
    }
    let rep = report(&toy_motion(&model, &frames), &model, &toy_options()).unwrap();
    assert!(flags(&rep).contains(&"gmr_self_collision"), "{:?}", rep.verdict.flags);
    // The toy has no masses: the dynamics check is said to be not measured, not passed.
    let d = rep.verdict.checks.iter().find(|c| c.name == "dynamics").unwrap();
    assert!(d.ok.is_none() && d.detail.contains("no inertial"), "{d:?}");
}
