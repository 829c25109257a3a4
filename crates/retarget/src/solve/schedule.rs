//! The schedule of stages 5 and 6: a range of frames through both ([`solve_range`]: the
//! whole clip), or one long clip as chunks in parallel ([`solve_chunks`]).
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

use std::ops::Range;

use mjcf::Model;
use rayon::prelude::*;

use super::first_pass::{first_pass, DonePass};
use super::prepare::{Problem, Solved};
use super::windows::solve_trajectory;
use super::ChunkOptions;
use crate::Error;

/// Frames `range` of `problem` through stages 5 and 6, from `qpos0` at `range.start −
/// lead_in` (the lead-in's frames are solved and dropped) to a window's overlap past its end
/// (the trajectory solve's last frames need the frames after them in view). `done`: stage
/// 4's first pass of the whole clip, used instead of running it again when that is the range.
pub(super) fn solve_range<'a>(
    problem: &Problem<'a>,
    range: Range<usize>,
    lead_in: usize,
    done: Option<DonePass<'a>>,
) -> Result<Solved, Error> {
    let nq = problem.clip.model.nq;
    let first = range.start.saturating_sub(lead_in);
    let trajectory = problem.clip.pipeline.trajectory.as_ref();
    let ahead = trajectory.map_or(0, |t| super::trajectory::overlap_frames(t, problem.clip.fps));
    let end = (range.end + ahead).min(problem.num_frames());
    // 5. The first pass: stage 4's where it ran this one ([`DonePass`]: the whole clip).
    let (mut solver, mut solved) = match done {
        Some(pass) if first == 0 && end == problem.num_frames() => pass.checked()?,
        _ => {
            let mut solver = problem.solver()?;
            let solved = first_pass(problem, &mut solver, first..end)?;
            (solver, solved)
        }
    };
    // 6. The trajectory solve.
    if let (Some(options), false) = (trajectory, solved.qpos.is_empty()) {
        solved = solve_trajectory(problem, &mut solver, options, first, solved)?;
    }
    let Solved { mut qpos, mut frames } = solved;
    let skip = range.start - first;
    qpos.truncate((range.end - first) * nq);
    frames.truncate(range.end - first);
    Ok(Solved { qpos: qpos.split_off(skip * nq), frames: frames.split_off(skip) })
}

/// Frames `0..n` of `problem` solved as chunks on rayon's current pool (stages 5 and 6 of
/// each, [`solve_range`]) and stitched, each chunk's quaternions continued across
/// its seam.
pub(super) fn solve_chunks(problem: &Problem<'_>, chunk: ChunkOptions) -> Result<Solved, Error> {
    if chunk.frames == 0 {
        let name = "chunk frames".to_owned();
        return Err(Error::InvalidOption { name, value: 0.0, expected: "at least one frame" });
    }
    let model = problem.clip.model;
    let n = problem.num_frames();
    let starts: Vec<usize> = (0..n).step_by(chunk.frames).collect();
    let parts = starts
        .par_iter()
        .map(|&start| {
            solve_range(problem, start..(start + chunk.frames).min(n), chunk.lead_in, None)
        })
        .collect::<Result<Vec<Solved>, Error>>()?;
    let mut solved =
        Solved { qpos: Vec::with_capacity(n * model.nq), frames: Vec::with_capacity(n) };
    for mut part in parts {
        let qpos = &solved.qpos;
        if let Some(last) = qpos.len().checked_sub(model.nq).and_then(|at| qpos.get(at..)) {
            continue_quaternions(model, last, &mut part.qpos);
        }
        solved.qpos.extend(part.qpos);
        solved.frames.extend(part.frames);
    }
    Ok(solved)
}

/// Negates a chunk's quaternions (free and ball joints; `qpos`: its frames) where its first
/// frame's is on the other side of the double cover from the frame before the chunk (`last`),
/// so that the clip's quaternions stay continuous across the seam as they do in the serial
/// solve. Each chunk starts from `qpos0` and may settle on either sign: the LAFAN1 walk in
/// chunks of 600 frames had the root's quaternion flip sign at 5 of its 11 seams.
pub(crate) fn continue_quaternions(model: &Model, last: &[f64], qpos: &mut [f64]) {
    let nq = model.nq.max(1);
    for joint in &model.joints {
        let Some(at) = joint.quat_adr() else { continue };
        let (Some(before), Some(first)) = (last.get(at..at + 4), qpos.get(at..at + 4)) else {
            continue;
        };
        if before.iter().zip(first).map(|(a, b)| a * b).sum::<f64>() >= 0.0 {
            continue;
        }
        for frame in qpos.chunks_mut(nq) {
            if let Some(q) = frame.get_mut(at..at + 4) {
                q.iter_mut().for_each(|v| *v = -*v);
            }
        }
    }
}
