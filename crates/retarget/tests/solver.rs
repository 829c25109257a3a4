//! Solver behaviour on the shipped and reference models: recovering poses made by the
//! robot's own FK, joint limits, config checks on real names, every shipped config against
//! its robot and the LAFAN1 skeleton.

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::{Path, PathBuf};

use mjcf::{Data, JointType, Model};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use retarget::internals::{mat_to_quat, Pose};
use retarget::internals::{GripPoint, Solver, TaskSpec};
use retarget::{IkConfig, SolverOptions};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn g1() -> Model {
    Model::from_file(&repo().join("robots/unitree_g1/unitree_g1.xml")).unwrap()
}

/// A random configuration near `qpos0` (±`spread` rad per hinge) with every limited joint at
/// least 5 % of its span inside its range.
fn random_pose(model: &Model, rng: &mut ChaCha8Rng, spread: f64) -> Vec<f64> {
    let mut q = model.qpos0.clone();
    for j in &model.joints {
        if let (JointType::Hinge, Some([lo, hi])) = (j.kind, j.range) {
            let m = 0.05 * (hi - lo);
            let v = q[j.qpos_adr] + rng.gen_range(-spread..spread);
            q[j.qpos_adr] = v.clamp(lo + m, hi - m);
        }
    }
    q
}

fn poses_of(model: &Model, q: &[f64], bodies: &[usize]) -> Vec<Pose> {
    let mut data = Data::new(model);
    model.kinematics(q, &mut data);
    bodies.iter().map(|&b| Pose { quat: mat_to_quat(&data.xmat[b]), pos: data.xpos[b] }).collect()
}

/// Targets made by the model's own FK at an in-range pose are recovered when iterated to
/// convergence (no stop threshold, many frames on the same targets).
#[test]
fn recovers_own_fk_pose() {
    let model = g1();
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let names = [
        "pelvis",
        "left_ankle_roll_link",
        "right_ankle_roll_link",
        "torso_link",
        "left_wrist_yaw_link",
        "right_wrist_yaw_link",
        "left_knee_link",
        "right_knee_link",
        "left_elbow_link",
        "right_elbow_link",
        "left_hip_yaw_link",
        "right_hip_yaw_link",
        "left_shoulder_yaw_link",
        "right_shoulder_yaw_link",
    ];
    let bodies: Vec<usize> = names.iter().map(|n| model.body_id(n).unwrap()).collect();
    let tasks: Vec<TaskSpec> = bodies
        .iter()
        .enumerate()
        .map(|(k, &body)| TaskSpec { body, target: k, pos_weight: 1.0, rot_weight: 1.0 })
        .collect();
    for _ in 0..3 {
        let mut q = random_pose(&model, &mut rng, 0.5);
        q[0] += 0.3;
        q[1] -= 0.2;
        let targets = poses_of(&model, &q, &bodies);
        let options = {
            let mut o = SolverOptions::default();
            o.stop_threshold = -1.0;
            o
        };
        let mut solver = Solver::new(&model, std::slice::from_ref(&tasks), options).unwrap();
        let mut last = f64::INFINITY;
        for _ in 0..300 {
            last = solver.solve_frame(&targets, 1.0 / 30.0).unwrap().error;
        }
        assert!(last < 1e-6, "remaining error {last}");
        let back = poses_of(&model, solver.qpos(), &bodies);
        for (a, b) in back.iter().zip(&targets) {
            assert!((a.pos - b.pos).norm() < 1e-6);
        }
    }
}

/// An elbow target beyond the joint's range (upper arm and pelvis held) ends on the limit,
/// never past it.
#[test]
fn out_of_range_target_stops_at_the_limit() {
    let model = g1();
    let elbow = model.joint_id("left_elbow_joint").unwrap();
    let [lo, hi] = model.joints[elbow].range.unwrap();
    let adr = model.joints[elbow].qpos_adr;
    let mut q = model.qpos0.clone();
    q[adr] = hi + 0.5;
    let names = ["left_elbow_link", "left_shoulder_yaw_link", "pelvis"];
    let bodies: Vec<usize> = names.iter().map(|n| model.body_id(n).unwrap()).collect();
    let targets = poses_of(&model, &q, &bodies);
    let tasks: Vec<TaskSpec> = bodies
        .iter()
        .enumerate()
        .map(|(k, &body)| TaskSpec { body, target: k, pos_weight: 0.0, rot_weight: 10.0 })
        .collect();
    let mut solver = Solver::new(&model, &[tasks], SolverOptions::default()).unwrap();
    let mut last = None;
    for _ in 0..100 {
        let d = solver.solve_frame(&targets, 1.0 / 30.0).unwrap();
        let qe = solver.qpos()[adr];
        assert!(qe <= hi && qe >= lo, "elbow {qe} outside [{lo}, {hi}]");
        last = Some(d);
    }
    let gap = hi - solver.qpos()[adr];
    assert!(gap < 1e-6, "elbow stays {gap} below its limit");
    assert!(last.unwrap().at_limit.contains(&elbow));
}

/// What a solver is handed that does not fit it: each refusal names the value.
#[test]
fn the_solvers_refusals_name_what_does_not_fit() {
    use retarget::Error;
    let model = g1();
    let pelvis = model.body_id("pelvis").unwrap();
    let task = |body| vec![TaskSpec { body, target: 0, pos_weight: 1.0, rot_weight: 1.0 }];
    let mut o = SolverOptions::default();
    o.limit_gain = 1.5;
    let err = Solver::new(&model, &[task(pelvis)], o).unwrap_err();
    let text = err.to_string();
    assert!(matches!(err, Error::InvalidOption { value: 1.5, .. }), "{text}");
    assert!(text.contains("limit_gain"), "{text}");
    let err = Solver::new(&model, &[task(model.nbody())], SolverOptions::default()).unwrap_err();
    assert!(matches!(err, Error::NotABody { what: "task", .. }), "{err}");
    let mut solver = Solver::new(&model, &[task(pelvis)], SolverOptions::default()).unwrap();
    let err = solver.set_qpos(&[0.0; 3]).unwrap_err();
    assert!(matches!(err, Error::WrongLength { what: "qpos", got: 3, .. }), "{err}");
    let mut nan = model.qpos0.clone();
    nan[7] = f64::NAN;
    assert!(matches!(solver.set_qpos(&nan), Err(Error::NotFinite { what: "qpos" })));
    let err = solver.solve_frame(&[], 1.0 / 30.0).unwrap_err();
    assert!(matches!(err, Error::WrongLength { got: 0, expected: 1, .. }), "{err}");
}

#[test]
fn max_joint_speed_bounds_every_frame() {
    let model = g1();
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let q = random_pose(&model, &mut rng, 1.0);
    let body = model.body_id("left_wrist_yaw_link").unwrap();
    let targets = poses_of(&model, &q, &[body]);
    let tasks = vec![TaskSpec { body, target: 0, pos_weight: 10.0, rot_weight: 10.0 }];
    let options = {
        let mut o = SolverOptions::default();
        o.max_joint_speed = Some(1.0);
        o
    };
    let mut solver = Solver::new(&model, &[tasks], options).unwrap();
    for _ in 0..5 {
        let before = solver.qpos().to_vec();
        solver.solve_frame(&targets, 0.1).unwrap();
        for j in model.joints.iter().filter(|j| j.kind == JointType::Hinge) {
            let moved = (solver.qpos()[j.qpos_adr] - before[j.qpos_adr]).abs();
            assert!(moved <= 0.1 + 1e-12, "{} moved {moved}", j.name);
        }
    }
}

/// LAFAN1 skeleton body names (22 joints + End Sites + GMR's derived feet), from the take.
fn lafan1_bodies() -> Option<Vec<String>> {
    let path = shared::shared_file("data/bvh/lafan1_take_via_bvhtools_test.bvh")?;
    let bvh = bvh::from_path(&path).unwrap();
    let (human, _) = fk::human_motion(&bvh, &fk::FkOptions::default()).unwrap();
    Some(human.body_names)
}

#[test]
fn every_shipped_config_fits_its_robot_and_lafan1() {
    let Some(human) = lafan1_bodies() else { return };
    let mut count = 0;
    for config in retarget::shipped::CONFIGS.iter().filter(|c| c.source == "bvh_lafan1") {
        let key = config.robot;
        let model_path = repo().join(format!("robots/{key}/{key}.xml"));
        let model = Model::from_file(&model_path).unwrap_or_else(|e| panic!("{key}: {e}"));
        let parsed = IkConfig::from_file(&repo().join(config.path)).unwrap();
        parsed.validate(&model, &human).unwrap_or_else(|e| panic!("{}: {e}", config.path));
        count += 1;
    }
    assert!(count >= 8, "only {count} shipped configs");
}

#[test]
fn unknown_names_are_located_with_suggestions() {
    let Some(human) = lafan1_bodies() else { return };
    let model = g1();
    let text = std::fs::read_to_string(repo().join("configs/gmr/bvh_lafan1_to_g1.json")).unwrap();
    let bad = text.replace("\"left_knee_link\"", "\"left_kne_link\"");
    let config = IkConfig::from_json_str(&bad, "g1.json").unwrap();
    let err = config.validate(&model, &human).unwrap_err().to_string();
    assert!(err.starts_with("g1.json:"), "{err}");
    assert!(err.contains("unknown robot body `left_kne_link`"), "{err}");
    assert!(err.contains("nearest: left_knee_link"), "{err}");
    let bad = text.replace("\"LeftForeArm\"", "\"LeftForArm\"");
    let config = IkConfig::from_json_str(&bad, "g1.json").unwrap();
    let err = config.validate(&model, &human).unwrap_err().to_string();
    assert!(
        err.contains("unknown human body `LeftForArm`") && err.contains("LeftForeArm"),
        "{err}"
    );
}

#[test]
fn root_position_is_in_metres_and_far_targets_stay_finite() {
    let model = g1();
    let body = model.body_id("pelvis").unwrap();
    let tasks = vec![TaskSpec { body, target: 0, pos_weight: 1.0, rot_weight: 1.0 }];
    // A pelvis target 0.5 m forward and 0.3 m right of its home pose: after a second of
    // frames the free root (`qpos[0..3]`, metres) stands there, not 100× or 1/100 of it.
    let home = Vector3::new(model.qpos0[0], model.qpos0[1], model.qpos0[2]);
    let goal = home + Vector3::new(0.5, -0.3, 0.0);
    let target = Pose { quat: [1.0, 0.0, 0.0, 0.0], pos: goal };
    let mut solver =
        Solver::new(&model, std::slice::from_ref(&tasks), SolverOptions::default()).unwrap();
    for _ in 0..30 {
        solver.solve_frame(&[target], 1.0 / 30.0).unwrap();
    }
    let q = solver.qpos();
    let root = Vector3::new(q[0], q[1], q[2]);
    assert!((root - goal).norm() < 1e-3, "root at {root:?}, target {goal:?} (metres)");
    // A target a kilometre away: one damped step, finite, no QP failure.
    let far = Pose { quat: [1.0, 0.0, 0.0, 0.0], pos: Vector3::new(1e3, -1e3, 1e3) };
    let mut solver = Solver::new(&model, &[tasks], SolverOptions::default()).unwrap();
    let d = solver.solve_frame(&[far], 1.0 / 30.0).unwrap();
    assert!(solver.qpos().iter().all(|v| v.is_finite()));
    assert_eq!(d.qp_failures, 0);
}

/// A gripped point ([`GripPoint`]) moves from the previous frame as its foothold does, give or
/// take the slip speed × dt (to first order: the rows are the point's linearised motion, 10 %
/// here), however hard a task pulls it; the same pull without the grip takes it further; a
/// point without a foothold in the frame before is free.
#[test]
fn a_gripped_sole_point_slides_no_faster_than_the_slip_speed() {
    let model = g1();
    let foot = model.body_id("left_ankle_roll_link").unwrap();
    let pelvis = model.body_id("pelvis").unwrap();
    let q0 = model.qpos0.clone();
    let start = poses_of(&model, &q0, &[foot, pelvis]);
    // The foot and the pelvis pulled 2 cm sideways and 1 cm forward.
    let pull = Vector3::new(0.01, 0.02, 0.0);
    let targets: Vec<Pose> = start.iter().map(|p| Pose { pos: p.pos + pull, ..*p }).collect();
    let tasks = vec![
        TaskSpec { body: foot, target: 0, pos_weight: 100.0, rot_weight: 10.0 },
        TaskSpec { body: pelvis, target: 1, pos_weight: 100.0, rot_weight: 10.0 },
    ];
    let point = Vector3::new(0.1, 0.02, -0.03);
    let world = |q: &[f64]| {
        let mut data = Data::new(&model);
        model.kinematics(q, &mut data);
        data.xpos[foot] + data.xquat[foot] * point
    };
    let at = world(&q0);
    // The foothold itself moves 1 mm along x per frame.
    let step = Vector3::new(0.001, 0.0, 0.0);
    let (dt, slip) = (1.0 / 30.0, 0.1);
    let moved = |grip: Option<Option<Vector3<f64>>>| {
        let mut solver =
            Solver::new(&model, std::slice::from_ref(&tasks), SolverOptions::default()).unwrap();
        solver.add_constraint(Box::new(retarget::internals::Grip));
        if let Some(from) = grip {
            let g = GripPoint { body: foot, point, at: at + step, from };
            solver.set_grips(&[g], slip).unwrap();
        }
        solver.solve_frame(&targets, dt).unwrap();
        world(solver.qpos()) - at
    };
    let held = moved(Some(Some(at)));
    for axis in 0..2 {
        let off = held[axis] - step[axis];
        assert!(off.abs() <= 1.1 * slip * dt, "axis {axis}: {off} m past the foothold's move");
    }
    let free = moved(None);
    assert!(free.xy().norm() > 0.01, "the pull alone moves the point {} m", free.xy().norm());
    let landing = moved(Some(None));
    assert!((landing - free).norm() < 1e-12, "a first planted frame is not held");
}

#[test]
fn a_trajectory_step_that_ends_inside_another_geom_steps_out() {
    // A ball on a rail pulled towards a point 10 cm past a post's centre, from 40 cm
    // away: no row holds them apart where the step starts (further than the
    // self-collision's activation), and the step alone ends deep in the post.
    let model = Model::from_xml_str(
        r#"<mujoco><worldbody><body name="base">
             <geom name="base" size="0.02" pos="0 0 -1"/>
             <body name="ball"><joint type="slide" axis="1 0 0" range="-1 1"/><geom name="ball" size="0.05"/></body>
             <body name="post" pos="0.5 0 0"><geom name="post" size="0.05"/></body>
           </body></worldbody></mujoco>"#,
        None,
    )
    .unwrap();
    let ball = model.body_id("ball").unwrap();
    let (g_ball, g_post) = (1, 2);
    let tasks = vec![TaskSpec { body: ball, target: 0, pos_weight: 1.0, rot_weight: 0.0 }];
    let target = Pose { quat: [1.0, 0.0, 0.0, 0.0], pos: Vector3::new(0.6, 0.0, 0.0) };
    let depth = |with_constraint: bool| {
        let mut options = SolverOptions::default();
        options.damping = 1e-6;
        let mut solver = Solver::new(&model, std::slice::from_ref(&tasks), options).unwrap();
        if with_constraint {
            let collision = retarget::internals::SelfCollision::new(&model);
            solver.add_constraint(Box::new(collision));
        }
        solver.set_qpos(&[0.0]).unwrap();
        solver.trajectory_step(&[(0, 1.0)], &[target], 1.0 / 30.0).unwrap();
        let mut data = Data::new(&model);
        model.kinematics(solver.qpos(), &mut data);
        -mjcf::geom_distance(&model, &data, g_ball, g_post, 1.0).unwrap().distance
    };
    let free = depth(false);
    assert!(free > 0.03, "without the constraint the ball ends {free} m deep");
    let held = depth(true);
    assert!(held < 1e-3, "the step ends {held} m deep in the post");
}
