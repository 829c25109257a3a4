//! Parity with GMR's SMPL-X path (GMR 62ecdff: `smplx_to_robot.py` with its `smplx_to_g1`
//! and `smplx_to_t1_29dof` configs, smplx git master in float32, mink 1.3.0 + daqp) on the
//! synthetic SMPL-X walk and jumps of `../shared/reference/smpl` (`--gmr`: GMR's solve).
//!
//! Two checks per run, on every frame:
//! - the solve: GMR's own recorded human data (`human_pos`, `human_quat_wxyz`, stored as
//!   float32) through our GMR solve gives GMR's `qpos` to [`TOLERANCE`] (measured 1.5e-6);
//! - the whole path (the body model's FK, GMR's 30 fps resampling, its height, frame 1 on):
//!   GMR's targets to 1e-5 m / 1e-5 rad (measured 6.8e-7 m, 9.6e-8 rad) and its `qpos` to
//!   [`TOLERANCE`] (measured 1.07e-6 rad on the G1 walk, the largest of the four). GMR's
//!   human data come from smplx in float32 (1e-6 m from ours, `smpl`'s tests), so the
//!   BVH parity test's 1e-6 is out of reach by that rounding alone, not by the solve.

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::{Path, PathBuf};

use fk::HumanMotion;
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use npz::Npz;
use retarget::{IkConfig, Retargeter, SolveMode, SubjectHeight};

/// Largest |qpos − GMR's| allowed (rad, m), the float32 rounding of GMR's human data.
const TOLERANCE: f64 = 1e-5;

fn floats(path: &Path, key: &str) -> (Vec<usize>, Vec<f64>) {
    Npz::open(path).unwrap().floats(key).unwrap()
}

fn strings(path: &Path, key: &str) -> Vec<String> {
    Npz::open(path).unwrap().strings(key).unwrap()
}

struct Run {
    robot: &'static str,
    mjcf: &'static str,
    ours: &'static str,
    gmr: &'static str,
    motion: &'static str,
}

const RUNS: [Run; 4] = [
    Run {
        robot: "unitree_g1",
        mjcf: "unitree_g1/g1_mocap_29dof.xml",
        ours: "gmr/smplx_to_g1.json",
        gmr: "smplx_to_g1.json",
        motion: "walk",
    },
    Run {
        robot: "booster_t1_29dof",
        mjcf: "booster_t1_29dof/t1_mocap.xml",
        ours: "gmr/smplx_to_t1_29dof.json",
        gmr: "smplx_to_t1_29dof.json",
        motion: "walk",
    },
    Run {
        robot: "unitree_g1",
        mjcf: "unitree_g1/g1_mocap_29dof.xml",
        ours: "gmr/smplx_to_g1.json",
        gmr: "smplx_to_g1.json",
        motion: "jumps",
    },
    Run {
        robot: "booster_t1_29dof",
        mjcf: "booster_t1_29dof/t1_mocap.xml",
        ours: "gmr/smplx_to_t1_29dof.json",
        gmr: "smplx_to_t1_29dof.json",
        motion: "jumps",
    },
];

/// GMR's recorded human data, frames `qpos_frame_index`.
fn gmr_human(out: &Path, rows: usize) -> HumanMotion {
    let names = strings(out, "joint_names");
    let (shape, pos) = floats(out, "human_pos");
    let (_, quat) = floats(out, "human_quat_wxyz");
    let (_, fps) = floats(out, "fps");
    let nb = shape[1];
    let first = 1;
    let positions = pos[first * nb * 3..(first + rows) * nb * 3]
        .chunks_exact(3)
        .map(Vector3::from_column_slice)
        .collect();
    let orientations = quat[first * nb * 4..(first + rows) * nb * 4]
        .chunks_exact(4)
        .map(|q| UnitQuaternion::new_normalize(Quaternion::new(q[0], q[1], q[2], q[3])))
        .collect();
    HumanMotion { fps: fps[0], body_names: names, num_frames: rows, positions, orientations }
}

/// The first `rows` frames of `human`.
fn prefix(human: &HumanMotion, rows: usize) -> HumanMotion {
    let n = rows * human.num_bodies();
    HumanMotion {
        num_frames: rows,
        positions: human.positions[..n].to_vec(),
        orientations: human.orientations[..n].to_vec(),
        ..human.clone()
    }
}

fn max_abs(a: &[f64], b: &[f64]) -> (f64, usize) {
    a.iter().zip(b).enumerate().map(|(i, (x, y))| ((x - y).abs(), i)).fold((0.0, 0), |m, v| {
        if v.0 > m.0 {
            v
        } else {
            m
        }
    })
}

#[test]
fn gmr_smplx_path_matches_gmr_on_g1_and_t1() {
    let Some(shared) = shared::shared_dir() else { return };
    let smpl_dir = shared.join("reference/smpl");
    let configs = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../configs");
    let models = smpl::BodyModels::new(Some(&smpl_dir.join("body_models")));
    for run in &RUNS {
        let out = smpl_dir.join(format!("gmr_outputs/gmr_{}_smplx_{}.npz", run.robot, run.motion));
        let config = IkConfig::from_file(&configs.join(run.ours)).unwrap();
        let gmr_config =
            IkConfig::from_file(&smpl_dir.join("gmr_ik_configs").join(run.gmr)).unwrap();
        assert_same_numbers(&config, &gmr_config);
        let (qshape, gmr_q) = floats(&out, "qpos");
        let rows = qshape[0];
        let nq = qshape[1];
        let gmr_q = &gmr_q[..rows * nq];
        let model =
            mjcf::Model::from_file(&shared.join("reference/robots").join(run.mjcf)).unwrap();
        let retargeter = Retargeter::from_model(model, run.robot)
            .with_config(config.clone())
            .with_mode(SolveMode::Gmr);

        // The solve alone, on GMR's own human data.
        let (_, height) = floats(&out, "human_height");
        let human = gmr_human(&out, rows);
        let (solved, _) =
            retargeter.retarget_with(&human, &config, SubjectHeight::given(height[0])).unwrap();
        let (solve_dq, _) = max_abs(&solved.qpos, gmr_q);

        // The whole path from the motion file.
        let file = smpl_dir.join(format!("motions/smplx_{}_stageii.npz", run.motion));
        let motion = smpl::SmplMotion::from_path(&file).unwrap();
        let body = models.for_motion(&motion, None).unwrap();
        // The resampling grid depends on the clip's length: resample it whole, then keep the
        // frames retargeted (from frame 1 on, as GMR's script).
        let resampled = smpl::gmr::offline_fast(&body, &motion, 30.0).unwrap();
        let human = prefix(&retarget::internals::frames_from(&resampled, 1), rows);
        let height = smpl::conventions::gmr_height(&motion.betas);
        let (ours, diag) =
            retargeter.retarget_with(&human, &config, SubjectHeight::given(height)).unwrap();
        if run.motion == "walk" && run.robot == "unitree_g1" {
            // The entry point users call gives the same numbers.
            let (direct, _) = retargeter.retarget_smpl(&motion, &body).unwrap();
            assert_eq!(direct.qpos, ours.qpos);
            assert!((direct.fps - floats(&out, "fps").1[0]).abs() < 1e-12);
        }
        let (dq, at) = max_abs(&ours.qpos, gmr_q);
        let (dp, dr) = target_diff(&ours, &config, &out, rows);
        let failures: usize = diag.frames.iter().map(|f| f.qp_failures).sum();
        eprintln!(
            "SMPL-X parity {} {}: {rows} frames; GMR's human data: max |dq| {solve_dq:.2e}; \
             ours: targets {dp:.2e} m {dr:.2e} rad, max |dq| {dq:.2e} (frame {}, qpos {}), \
             IK {:.0} frames/s",
            run.robot,
            run.motion,
            at / nq,
            at % nq,
            rows as f64 / diag.solve_seconds
        );
        assert!(
            solve_dq <= TOLERANCE,
            "{} {}: the solve differs by {solve_dq:e}",
            run.robot,
            run.motion
        );
        assert_eq!(failures, 0);
        assert!(
            dp <= 1e-5 && dr <= 1e-5,
            "{} {}: targets differ by {dp:e} m, {dr:e} rad",
            run.robot,
            run.motion
        );
        assert!(dq <= TOLERANCE, "{} {}: qpos differs by {dq:e}", run.robot, run.motion);
    }
}

/// Largest differences of our targets from GMR's `ik_target_pos` / `ik_target_quat_wxyz`,
/// matched through the config's table 1 (robot body ↔ human body).
fn target_diff(
    motion: &retarget::RobotMotion,
    config: &IkConfig,
    out: &Path,
    rows: usize,
) -> (f64, f64) {
    let names = strings(out, "ik_target_names");
    let (_, pos) = floats(out, "ik_target_pos");
    let (_, quat) = floats(out, "ik_target_quat_wxyz");
    let targets = motion.targets.as_ref().unwrap();
    let k = names.len();
    let ours = targets.body_names.len();
    let (mut dp, mut dr) = (0.0_f64, 0.0_f64);
    for (g, name) in names.iter().enumerate() {
        let robot = config.ik_match_table1.iter().find(|e| &e.human_body == name);
        let robot = &robot.expect("every GMR target is in table 1").robot_body;
        let b = targets.body_names.iter().position(|n| n == robot).unwrap();
        for f in 0..rows {
            let i = f * k + g;
            let p = Vector3::new(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]);
            let q = &quat[4 * i..4 * i + 4];
            let q = UnitQuaternion::new_normalize(Quaternion::new(q[0], q[1], q[2], q[3]));
            dp = dp.max((targets.pos[f * ours + b] - p).amax());
            dr = dr.max(targets.quat[f * ours + b].angle_to(&q));
        }
    }
    (dp, dr)
}

/// Our shipped SMPL-X config must be GMR's numbers, entry for entry.
fn assert_same_numbers(ours: &IkConfig, gmr: &IkConfig) {
    assert_eq!(ours.human_root_name, gmr.human_root_name);
    assert_eq!(ours.ground_height, gmr.ground_height);
    assert_eq!(ours.human_height_assumption, gmr.human_height_assumption);
    assert_eq!(ours.human_scale_table, gmr.human_scale_table);
    assert_eq!(ours.ik_match_table1, gmr.ik_match_table1);
    assert_eq!(ours.ik_match_table2, gmr.ik_match_table2);
}
