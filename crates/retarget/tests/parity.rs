//! Parity with GMR (upstream 62ecdff, mink 1.3.0 + daqp) on the LAFAN1 walk take retargeted
//! to the reference Unitree G1 with a 1.75 m subject (`--gmr`: GMR's exact solve): targets
//! to 1e-9, qpos to 1e-6 rad on every one of the 7,184 frames (measured: 3.6e-9 rad). Reads `$RETARGET_SHARED` (see tests/support/shared.rs).

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::Path;

use retarget::{IkConfig, RetargetOptions};

#[test]
fn lafan1_walk_on_g1_matches_gmr() {
    let Some(shared) = shared::shared_dir() else { return };
    let mut npz =
        npz::Npz::open(&shared.join("reference/gmr_outputs/unitree_g1_lafan1_walk.npz")).unwrap();
    let bvh = bvh::from_path(&shared.join("data/bvh/lafan1_take_via_bvhtools_test.bvh")).unwrap();
    let model =
        mjcf::Model::from_file(&shared.join("reference/robots/unitree_g1/g1_mocap_29dof.xml"))
            .unwrap();
    let shipped =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/gmr/bvh_lafan1_to_g1.json");
    let config = IkConfig::from_file(&shipped).unwrap();
    let gmr_config =
        IkConfig::from_file(&shared.join("reference/gmr_ik_configs/bvh_lafan1_to_g1.json"))
            .unwrap();
    assert_same_numbers(&config, &gmr_config);

    let options = {
        let mut o = RetargetOptions::gmr();
        o.human_height = Some(1.75);
        o
    };
    let (motion, diag) =
        retarget::internals::retarget_bvh(&bvh, &model, &config, &options).unwrap();

    let (qshape, gmr_q) = npz.floats("qpos").unwrap();
    assert_eq!(qshape, [motion.num_frames(), motion.nq]);
    let targets = motion.targets.as_ref().unwrap();
    assert_eq!(targets.body_names, npz.strings("body_names").unwrap());
    let nb = targets.body_names.len();
    let (_, gmr_pos) = npz.floats("targets_pos").unwrap();
    let (_, gmr_quat) = npz.floats("targets_quat").unwrap();
    let mut max_pos = 0.0_f64;
    let mut max_quat = 0.0_f64;
    for (k, (p, q)) in targets.pos.iter().zip(&targets.quat).enumerate() {
        for a in 0..3 {
            max_pos = max_pos.max((p[a] - gmr_pos[3 * k + a]).abs());
        }
        let ours = [q.w, q.i, q.j, q.k];
        let g = &gmr_quat[4 * k..4 * k + 4];
        let same: f64 = (0..4).map(|a| (ours[a] - g[a]).abs()).fold(0.0, f64::max);
        let flipped: f64 = (0..4).map(|a| (ours[a] + g[a]).abs()).fold(0.0, f64::max);
        max_quat = max_quat.max(same.min(flipped));
    }
    assert_eq!(targets.pos.len(), motion.num_frames() * nb);

    let mut max_dq = 0.0_f64;
    let mut worst = (0, 0);
    for (i, (a, b)) in motion.qpos.iter().zip(gmr_q).enumerate() {
        let d = (a - b).abs();
        if d > max_dq {
            max_dq = d;
            worst = (i / motion.nq, i % motion.nq);
        }
    }
    let failures: usize = diag.frames.iter().map(|f| f.qp_failures).sum();
    eprintln!(
        "parity: {} frames, max target pos diff {max_pos:.3e} m, max target quat diff {max_quat:.3e}, \
         max |dq| {max_dq:.3e} (frame {}, qpos {}), IK {:.3} s ({:.0} frames/s), qp failures {failures}",
        motion.num_frames(),
        worst.0,
        worst.1,
        diag.solve_seconds,
        motion.num_frames() as f64 / diag.solve_seconds
    );
    assert!(max_pos <= 1e-9, "target positions differ by {max_pos:e}");
    assert!(max_quat <= 1e-9, "target orientations differ by {max_quat:e}");
    assert_eq!(failures, 0);
    assert!(
        max_dq <= 1e-6,
        "qpos differs from GMR by {max_dq:e} at frame {} index {}",
        worst.0,
        worst.1
    );
}

/// Our shipped G1 config must be GMR's numbers, entry for entry.
fn assert_same_numbers(ours: &IkConfig, gmr: &IkConfig) {
    assert_eq!(ours.human_root_name, gmr.human_root_name);
    assert_eq!(ours.ground_height, gmr.ground_height);
    assert_eq!(ours.human_height_assumption, gmr.human_height_assumption);
    assert_eq!(ours.use_ik_match_table1, gmr.use_ik_match_table1);
    assert_eq!(ours.use_ik_match_table2, gmr.use_ik_match_table2);
    assert_eq!(ours.human_scale_table, gmr.human_scale_table);
    assert_eq!(ours.ik_match_table1, gmr.ik_match_table1);
    assert_eq!(ours.ik_match_table2, gmr.ik_match_table2);
}
