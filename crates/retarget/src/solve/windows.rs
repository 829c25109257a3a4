//! Stage 6's windows ([`solve_trajectory`]): a range's trajectory solve
//! ([`super::trajectory`]) window after window, from its first pass.

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: frames and slots index the clip's own target buffer (`frames × slots`, built in
// `prepare`), body ids come from the model; the human motion's sizes are checked by
// `HumanMotion::validate` first.
#![allow(clippy::indexing_slicing)]

use super::prepare::{Problem, Solved};
use super::trajectory::{Trajectory, TrajectoryOptions};
use crate::ik::{FrameDiagnostics, Solver};
use crate::Error;

/// Stage 6 over `problem`'s frames `first..` from their first pass (`solved`): the
/// trajectory solve ([`super::trajectory`]) window after window, each window's frames
/// replaced by its solution, each window after the first held to the two frames before it.
pub(super) fn solve_trajectory<'a>(
    problem: &Problem<'a>,
    solver: &mut Solver<'a>,
    options: &TrajectoryOptions,
    first: usize,
    solved: Solved,
) -> Result<Solved, Error> {
    let Solved { mut qpos, mut frames } = solved;
    let nq = problem.clip.model.nq;
    let n = frames.len();
    let (stages, fps) = (problem.stages.len(), problem.clip.fps);
    let mut trajectory = Trajectory::new(solver, stages, options, fps);
    let (window, overlap) = trajectory.window_frames();
    let mut start = 0;
    let mut fixed: Vec<Vec<f64>> = Vec::new();
    loop {
        let stop = (start + window).min(n);
        let part = &mut qpos[start * nq..stop * nq];
        let diagnostics = trajectory.solve_window(problem, first + start, &fixed, part)?;
        for (k, d) in diagnostics.into_iter().enumerate() {
            // (Which first pass a frame started from stays said.)
            let backward = frames[start + k].backward;
            frames[start + k] = FrameDiagnostics { backward, ..d };
        }
        if stop == n {
            return Ok(Solved { qpos, frames });
        }
        let keep = stop - overlap;
        fixed =
            (keep.saturating_sub(2)..keep).map(|t| qpos[t * nq..(t + 1) * nq].to_vec()).collect();
        start = keep;
    }
}
