//! Solving one long clip as chunks in parallel.
//!
//! The solver is sequential (each frame warm-starts from the previous one), so a long clip
//! uses one core. Here the clip is cut into chunks of `frames` frames; each chunk is solved
//! from `qpos0` starting `lead_in` frames before its first frame, and those lead-in frames are
//! thrown away. After the lead-in the warm start has forgotten `qpos0`, so the seam between
//! chunks is as smooth as the rest of the motion. The cost: frames differ slightly from the
//! serial solve (the IK is a local method whose result depends a little on its history);
//! `tests/chunked.rs` measures it on the LAFAN1 walk.

use std::time::Instant;

use fk::HumanMotion;
use mjcf::Model;
use rayon::prelude::*;

use crate::config::IkConfig;
use crate::motion::{RobotMotion, TrackedTargets};
use crate::pipeline::{retarget_motion, ClipDiagnostics, Error, RetargetOptions};

/// How to cut a clip: chunks of `frames` frames, each preceded by `lead_in` frames of warm-up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ChunkOptions {
    pub frames: usize,
    pub lead_in: usize,
}

impl Default for ChunkOptions {
    /// 20 s chunks at 30 fps with a 2 s lead-in.
    fn default() -> ChunkOptions {
        ChunkOptions { frames: 600, lead_in: 60 }
    }
}

/// [`retarget_motion`] with the clip solved as parallel chunks (rayon's current pool).
/// The result has the same layout as the serial one.
pub fn retarget_motion_chunked(
    human: &HumanMotion,
    model: &Model,
    config: &IkConfig,
    options: &RetargetOptions,
    chunk: ChunkOptions,
) -> Result<(RobotMotion, ClipDiagnostics), Error> {
    if chunk.frames == 0 {
        return Err(Error::InvalidOption("chunks need at least one frame".to_owned()));
    }
    let n = human.num_frames;
    let starts: Vec<usize> = (0..n).step_by(chunk.frames).collect();
    let started = Instant::now();
    let parts = starts
        .par_iter()
        .map(|&start| {
            let from = start.saturating_sub(chunk.lead_in);
            let to = (start + chunk.frames).min(n);
            let piece = slice(human, from, to);
            let (motion, diag) =
                retarget_motion(&piece, model, config, options).map_err(|e| match e {
                    Error::NonFinite { frame, message } => {
                        Error::NonFinite { frame: frame + from, message }
                    }
                    other => other,
                })?;
            Ok((start - from, motion, diag))
        })
        .collect::<Result<Vec<_>, Error>>()?;
    let seconds = started.elapsed().as_secs_f64();
    Ok(join(parts, seconds))
}

/// Frames `from..to` of `human`.
fn slice(human: &HumanMotion, from: usize, to: usize) -> HumanMotion {
    let nb = human.num_bodies();
    HumanMotion {
        fps: human.fps,
        body_names: human.body_names.clone(),
        num_frames: to - from,
        positions: human.positions[from * nb..to * nb].to_vec(),
        orientations: human.orientations[from * nb..to * nb].to_vec(),
    }
}

/// Concatenate chunk results, dropping each chunk's first `skip` (lead-in) frames.
fn join(
    parts: Vec<(usize, RobotMotion, ClipDiagnostics)>,
    seconds: f64,
) -> (RobotMotion, ClipDiagnostics) {
    let mut parts = parts.into_iter();
    let (skip, mut motion, mut diag) = parts.next().expect("a clip has at least one chunk");
    debug_assert_eq!(skip, 0);
    for (skip, m, d) in parts {
        motion.qpos.extend_from_slice(&m.qpos[skip * m.nq..]);
        if let (Some(all), Some(t)) = (motion.targets.as_mut(), m.targets) {
            let k = t.body_names.len();
            all.pos.extend_from_slice(&t.pos[skip * k..]);
            all.quat.extend_from_slice(&t.quat[skip * k..]);
        }
        diag.frames.extend(d.frames.into_iter().skip(skip));
    }
    diag.solve_seconds = seconds;
    if let Some(TrackedTargets { pos, .. }) = &motion.targets {
        debug_assert_eq!(pos.len() % motion.num_frames().max(1), 0);
    }
    (motion, diag)
}
