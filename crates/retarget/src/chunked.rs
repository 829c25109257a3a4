//! Solving one long clip as chunks in parallel.
//!
//! The solver is sequential (each frame warm-starts from the previous one), so a long clip
//! uses one core. Here the clip is cut into chunks of `frames` frames; each chunk is solved
//! from `qpos0` starting `lead_in` frames before its first frame (the targets, contact phases
//! and foot plans are the whole clip's, computed once), and those lead-in frames are
//! thrown away. After the lead-in the warm start has forgotten `qpos0`, so the seam between
//! chunks is as smooth as the rest of the motion. The cost: frames differ slightly from the
//! serial solve (the IK is a local method whose result depends a little on its history);
//! `tests/chunked.rs` measures it on the LAFAN1 walk.

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use std::time::Instant;

use fk::HumanMotion;
use mjcf::Model;
use rayon::prelude::*;

use crate::config::IkConfig;
use crate::motion::RobotMotion;
use crate::pipeline::{ClipDiagnostics, Error, Prepared, RetargetOptions, Solved};

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

/// [`retarget_motion`](crate::retarget_motion) with the clip solved as parallel chunks
/// (rayon's current pool). Targets, contacts and foot plans are prepared once for the whole
/// clip; the result has the same layout as the serial one.
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
    let prepared = Prepared::new(human, model, config, options)?;
    let n = prepared.num_frames();
    let starts: Vec<usize> = (0..n).step_by(chunk.frames).collect();
    let started = Instant::now();
    let parts = starts
        .par_iter()
        .map(|&start| prepared.solve(start..(start + chunk.frames).min(n), chunk.lead_in))
        .collect::<Result<Vec<Solved>, Error>>()?;
    let seconds = started.elapsed().as_secs_f64();
    let mut qpos = Vec::with_capacity(n * model.nq);
    let mut frames = Vec::with_capacity(n);
    for part in parts {
        qpos.extend(part.qpos);
        frames.extend(part.frames);
    }
    Ok(prepared.finish(qpos, frames, seconds))
}
