//! Parallel chunks of one clip against the serial solve on the LAFAN1 walk (G1).

#[path = "../../../tests/support/shared.rs"]
mod shared;

use retarget::internals::{retarget_motion, retarget_motion_chunked};
use retarget::{ChunkOptions, IkConfig, RetargetOptions};

/// Largest per-joint change between consecutive frames (hinges only), at each frame.
fn jumps(qpos: &[f64], nq: usize) -> Vec<f64> {
    qpos.chunks(nq)
        .zip(qpos.chunks(nq).skip(1))
        .map(|(a, b)| a[7..].iter().zip(&b[7..]).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max))
        .collect()
}

#[test]
fn gmr_chunks_with_lead_in_have_invisible_seams_and_equal_the_serial_solve() {
    // Measured: 3.7e-10 rad (a 2 s lead-in forgets qpos0 entirely on this take).
    chunks_against_serial(RetargetOptions::gmr(), 1e-6);
}

#[test]
fn default_chunks_with_lead_in_have_invisible_seams_and_stay_close_to_the_serial_solve() {
    // Each chunk is a trajectory problem of its own, from a 2 s lead-in to a window's overlap
    // past its end; its frames differ from the serial solve's windows by the difference
    // between two solves of the same problem with different horizons.
    chunks_against_serial(RetargetOptions::default(), 0.05);
}

/// The G1, GMR's config for it, the shared LAFAN1 walk's human motion and the subject's
/// height; `None` without the shared data.
fn g1_walk() -> Option<(mjcf::Model, IkConfig, fk::HumanMotion, f64)> {
    let walk = shared::shared_file("data/bvh/lafan1_take_via_bvhtools_test.bvh")?;
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let model = mjcf::Model::from_file(&root.join("robots/unitree_g1/unitree_g1.xml")).unwrap();
    let config = IkConfig::from_file(&root.join("configs/gmr/bvh_lafan1_to_g1.json")).unwrap();
    let bvh = bvh::from_path(&walk).unwrap();
    let (human, report) = fk::human_motion(&bvh, &fk::FkOptions::default()).unwrap();
    Some((model, config, human, report.height))
}

fn chunks_against_serial(base: RetargetOptions, tolerance: f64) {
    let Some((model, config, full, height)) = g1_walk() else { return };
    // The first 1,800 frames (a minute) keep the test short.
    let n = 1800;
    let nb = full.num_bodies();
    let human = fk::HumanMotion {
        num_frames: n,
        positions: full.positions[..n * nb].to_vec(),
        orientations: full.orientations[..n * nb].to_vec(),
        ..full
    };
    let options = {
        let mut o = base;
        o.human_height = Some(height);
        o
    };
    let (serial, _) = retarget_motion(&human, &model, &config, &options).unwrap();
    let chunk = ChunkOptions { frames: 300, lead_in: 60 };
    let (chunked, diag) =
        retarget_motion_chunked(&human, &model, &config, &options, chunk).unwrap();
    assert_eq!(chunked.qpos.len(), serial.qpos.len());
    assert_eq!(diag.frames.len(), n);
    let targets = (chunked.targets.as_ref().unwrap(), serial.targets.as_ref().unwrap());
    assert_eq!(targets.0.pos, targets.1.pos, "targets do not depend on the chunking");

    let nq = model.nq;
    let serial_jump = jumps(&serial.qpos, nq).into_iter().fold(0.0, f64::max);
    let chunked_jumps = jumps(&chunked.qpos, nq);
    let seam_jump =
        (1..n / chunk.frames).map(|c| chunked_jumps[c * chunk.frames - 1]).fold(0.0, f64::max);
    let max_dq =
        chunked.qpos.iter().zip(&serial.qpos).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    eprintln!("serial max jump {serial_jump:.4} rad, seam max jump {seam_jump:.4} rad, max |dq| vs serial {max_dq:.2e}");
    assert!(
        seam_jump <= serial_jump,
        "a seam jumps {seam_jump} rad, the serial solve at most {serial_jump}"
    );
    assert!(max_dq < tolerance, "chunked frames differ from the serial solve by {max_dq} rad");
}

/// Each chunk starts from `qpos0` and can settle on either sign of the root's quaternion: on
/// the whole walk in 600-frame chunks it flipped at 5 of the 11 seams (the same rotation, but
/// a jump of up to 2 in the numbers for whoever differences them). The stitched clip's
/// quaternions are continuous and equal the serial solve's.
#[test]
fn chunk_seams_keep_the_root_quaternion_on_one_side_of_the_double_cover() {
    let Some((model, config, human, height)) = g1_walk() else { return };
    let options = {
        let mut o = RetargetOptions::gmr();
        o.human_height = Some(height);
        o
    };
    let (serial, _) = retarget_motion(&human, &model, &config, &options).unwrap();
    let chunk = ChunkOptions { frames: 600, lead_in: 60 };
    let (chunked, _) = retarget_motion_chunked(&human, &model, &config, &options, chunk).unwrap();
    let nq = model.nq;
    let quats: Vec<&[f64]> = chunked.qpos.chunks(nq).map(|f| &f[3..7]).collect();
    let flips = quats
        .windows(2)
        .filter(|w| w[0].iter().zip(w[1]).map(|(a, b)| a * b).sum::<f64>() < 0.0)
        .count();
    assert_eq!(flips, 0, "the root's quaternion changes sign between frames");
    let max_dq =
        chunked.qpos.iter().zip(&serial.qpos).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(max_dq < 1e-6, "chunked frames differ from the serial solve by {max_dq}");
}
