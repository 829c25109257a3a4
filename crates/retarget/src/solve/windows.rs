//! Stage 6's schedule: a clip's trajectory solve window after window ([`super::trajectory`]).

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: frames and slots index the clip's own target buffer (`frames × slots`, built in
// `prepare`), body ids come from the model; the human motion's sizes are checked by
// `HumanMotion::validate` first.
#![allow(clippy::indexing_slicing)]

use super::prepare::Problem;
use crate::ik::{FrameDiagnostics, Solver};
use crate::Error;

impl<'a> Problem<'a> {
    /// The trajectory solve ([`crate::solve::trajectory`]) of frames `first..` (`qpos`, the
    /// first pass's, in and out), window after window.
    pub(super) fn solve_trajectory(
        &self,
        solver: &mut Solver<'a>,
        options: &crate::solve::trajectory::TrajectoryOptions,
        first: usize,
        qpos: &mut [f64],
        frames: &mut [FrameDiagnostics],
    ) -> Result<(), Error> {
        let nq = self.clip.model.nq;
        let n = frames.len();
        let (stages, fps) = (self.stages.len(), self.clip.fps);
        let mut trajectory =
            crate::solve::trajectory::Trajectory::new(solver, stages, options, fps);
        let (window, overlap) = trajectory.window_frames();
        let mut start = 0;
        let mut fixed: Vec<Vec<f64>> = Vec::new();
        loop {
            let stop = (start + window).min(n);
            let part = &mut qpos[start * nq..stop * nq];
            let diagnostics = trajectory.solve_window(self, first + start, &fixed, part)?;
            for (k, d) in diagnostics.into_iter().enumerate() {
                // (Which first pass a frame started from stays said.)
                let backward = frames[start + k].backward;
                frames[start + k] = FrameDiagnostics { backward, ..d };
            }
            if stop == n {
                return Ok(());
            }
            let keep = stop - overlap;
            fixed = (keep.saturating_sub(2)..keep)
                .map(|t| qpos[t * nq..(t + 1) * nq].to_vec())
                .collect();
            start = keep;
        }
    }
}
