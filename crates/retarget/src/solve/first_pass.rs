//! Stage 5, the first pass ([`first_pass`]): every frame solved causally (GMR's tasks and
//! stage loop with the hard constraints, warm-started from the frame before; the first frame
//! from the better of two starts), optionally also backwards and spliced. What streams run;
//! the trajectory solve's initial trajectory.

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: frames and slots index the clip's own target buffer (`frames × slots`, built in
// `prepare`), body ids come from the model; the human motion's sizes are checked by
// `HumanMotion::validate` first.
#![allow(clippy::indexing_slicing)]

use std::ops::Range;

use mjcf::{JointType, Model};
use nalgebra::Vector3;

use super::footholds::Pass;
use super::prepare::reject_divergence;
use super::prepare::{Problem, Solved};
use crate::ik::{FrameDiagnostics, Solver};
use crate::lie::Pose;
use crate::Error;

/// Stage 5 over frames `frames` of `problem` with `solver` (forward; with
/// [`crate::PlausibleOptions::both_ways`] also backward, on a second thread of rayon's pool
/// with a solver of its own, and spliced): each frame's `qpos` and diagnostics.
pub(super) fn first_pass<'a>(
    problem: &Problem<'a>,
    solver: &mut Solver<'a>,
    frames: Range<usize>,
) -> Result<Solved, Error> {
    let nq = problem.clip.model.nq;
    let (first, end) = (frames.start, frames.end);
    // Every constraint holds from the first pass on. (A first pass under box bounds only
    // is 1.4× faster on the G1, but on robots whose tracking drives links into each
    // other, e.g. Toddy's hips, the next step cannot get out within the speed limits.)
    let forward = |solver: &mut Solver<'_>| -> Result<Solved, Error> {
        let mut qpos = Vec::with_capacity((end - first) * nq);
        let mut out = Vec::with_capacity(end - first);
        for f in first..end {
            out.push(first_pass_frame(problem, solver, f, f == first)?);
            reject_divergence(solver.qpos(), f)?;
            qpos.extend_from_slice(solver.qpos());
        }
        Ok(Solved { qpos, frames: out })
    };
    if !problem.clip.pipeline.both_ways {
        return forward(solver);
    }
    // The two directions on two threads of rayon's pool (one, in a busy pool, is the same
    // work in turn).
    let (ahead, back) =
        rayon::join(|| forward(solver), || first_pass_backward(problem, first..end));
    let (mut ahead, back) = (ahead?, back?);
    let (coords, quats) = compared_coordinates(problem.clip.model);
    splice_passes(
        nq,
        (&coords, &quats),
        &mut ahead.qpos,
        &mut ahead.frames,
        &back.qpos,
        &back.frames,
    );
    Ok(ahead)
}

/// A forward first pass over a whole clip that stage 4 ran with the tasks stage 5 solves
/// (its windows covered the clip, and it left the tasks as they were): the solver as the
/// pass left it and the solved frames, what [`first_pass`] from a new solver would return.
pub(super) struct DonePass<'a> {
    pub solver: Solver<'a>,
    pub solved: Solved,
}

impl<'a> DonePass<'a> {
    /// The solver and frames, each frame checked for divergence in order, as [`first_pass`]
    /// checks them.
    pub(super) fn checked(self) -> Result<(Solver<'a>, Solved), Error> {
        let nq = self.solver.qpos().len();
        for (f, qpos) in self.solved.qpos.chunks(nq.max(1)).enumerate() {
            reject_divergence(qpos, f)?;
        }
        Ok((self.solver, self.solved))
    }
}

/// Frame `f` of a first pass over `problem`: its foot tasks set, solved from the previous
/// frame's pose (the `first` of a solve: from [`solve_first_frame`]'s start in the default
/// mode, and without speed limits). Stage 4 measures the pelvis with it.
pub(super) fn first_pass_frame(
    problem: &Problem<'_>,
    solver: &mut Solver<'_>,
    f: usize,
    first: bool,
) -> Result<FrameDiagnostics, Error> {
    first_pass_frame_in(problem, solver, f, first, Pass::Forward)
}

/// [`first_pass_frame`] in a pass that runs as `pass` says ([`Problem::set_frame_tasks_in`]).
fn first_pass_frame_in(
    problem: &Problem<'_>,
    solver: &mut Solver<'_>,
    f: usize,
    first: bool,
    pass: Pass,
) -> Result<FrameDiagnostics, Error> {
    problem.set_frame_tasks_in(solver, f, pass)?;
    let clip = &problem.clip;
    let targets = problem.frame_targets(f);
    let diagnostics = if first && !clip.pipeline.is_gmr() {
        solve_first_frame(clip.model, solver, &clip.tracked, targets)?
    } else {
        solver.solve_frame(targets, first_frame_dt(first, clip.frame_dt()))?
    };
    Ok(diagnostics)
}

/// The first pass run backwards over `range`: from its last frame (solved as a first
/// frame) to its first, each frame warm-started from the one after it.
fn first_pass_backward(problem: &Problem<'_>, range: Range<usize>) -> Result<Solved, Error> {
    let mut solver = problem.solver()?;
    let nq = problem.clip.model.nq;
    let mut qpos = vec![0.0; range.len() * nq];
    let mut frames = vec![FrameDiagnostics::default(); range.len()];
    for (k, f) in range.clone().enumerate().rev() {
        frames[k] =
            first_pass_frame_in(problem, &mut solver, f, f + 1 == range.end, Pass::Backward)?;
        frames[k].backward = true;
        reject_divergence(solver.qpos(), f)?;
        qpos[k * nq..(k + 1) * nq].copy_from_slice(solver.qpos());
    }
    Ok(Solved { qpos, frames })
}

/// The `dt` a solve's first frame is solved with: 0, so that no joint speed limit holds
/// there. Its start configuration (`qpos0`, or [`start_pose`]) is no frame of the motion:
/// limits counted from it held the G1's joints up to 1.6 rad back on clips that begin
/// mid-motion (`tests/plausible.rs`).
pub(crate) fn first_frame_dt(first: bool, dt: f64) -> f64 {
    if first {
        0.0
    } else {
        dt
    }
}

/// Solves the first frame of a solve (no previous frame: no speed limits) from the better of
/// two starts ([`start_poses`]): `qpos0` at the root target turned to its heading, and not
/// turned. The start decides which of several solutions a limb settles in for the rest of
/// the clip (the T1's arms on the Bandai kick, which begins with the subject turned 90°:
/// from the turned start both wrists stayed 90–130° off their targets to the end, mean
/// rotation error 38.8° against 18.3° from the other). The better is the one with the
/// smaller error at the end of the frame's solve; it is solved again from its start, so the
/// solver is left as if it had been the only one.
pub(crate) fn solve_first_frame(
    model: &Model,
    solver: &mut Solver<'_>,
    tracked: &[(usize, usize)],
    targets: &[Pose],
) -> Result<FrameDiagnostics, Error> {
    let starts = start_poses(model, tracked, targets);
    let mut best = (f64::INFINITY, 0);
    if starts.len() > 1 {
        for (k, start) in starts.iter().enumerate() {
            solver.set_qpos(start)?;
            let error = solver.solve_frame(targets, 0.0)?.error;
            if error < best.0 {
                best = (error, k);
            }
        }
    }
    if let Some(start) = starts.get(best.1) {
        solver.set_qpos(start)?;
    }
    solver.solve_frame(targets, 0.0)
}

/// The starts of [`solve_first_frame`]: [`start_pose`], and the same not turned when that
/// differs.
fn start_poses(model: &Model, tracked: &[(usize, usize)], targets: &[Pose]) -> Vec<Vec<f64>> {
    let Some(turned) = start_pose(model, tracked, targets) else { return Vec::new() };
    let mut straight = model.qpos0.clone();
    if let Some(root) = model.joints.iter().find(|j| j.kind == JointType::Free) {
        let a = root.qpos_adr;
        straight[a..a + 2].copy_from_slice(&turned[a..a + 2]);
    }
    if straight == turned {
        vec![turned]
    } else {
        vec![turned, straight]
    }
}

/// `qpos0` with the free root moved to one frame's target (`targets`, by slot) of the root
/// body and turned to its heading (about world z), so that a solve starting far from the
/// origin, or facing away from the robot's rest heading, starts where the motion is. `None`
/// without a free root or a task on its body.
pub(crate) fn start_pose(
    model: &Model,
    tracked: &[(usize, usize)],
    targets: &[Pose],
) -> Option<Vec<f64>> {
    let root = model.joints.iter().find(|j| j.kind == JointType::Free)?;
    let &(_, slot) = tracked.iter().find(|(b, _)| *b == root.body)?;
    let target = targets.get(slot)?;
    let mut q = model.qpos0.clone();
    let a = root.qpos_adr;
    let rest = nalgebra::UnitQuaternion::new_normalize(nalgebra::Quaternion::new(
        q[a + 3],
        q[a + 4],
        q[a + 5],
        q[a + 6],
    ));
    let goal = nalgebra::UnitQuaternion::new_normalize(nalgebra::Quaternion::new(
        target.quat[0],
        target.quat[1],
        target.quat[2],
        target.quat[3],
    ));
    // The heading change that turns the rest forward axis onto the target's.
    let heading = |r: &nalgebra::UnitQuaternion<f64>| {
        let f = r * (rest.inverse() * Vector3::x());
        f.y.atan2(f.x)
    };
    let turn = nalgebra::UnitQuaternion::from_axis_angle(
        &Vector3::z_axis(),
        heading(&goal) - heading(&rest),
    );
    let start = turn * rest;
    q[a] = target.pos.x;
    q[a + 1] = target.pos.y;
    q[a + 3..a + 7].copy_from_slice(&[start.w, start.i, start.j, start.k]);
    Some(q)
}

/// Two solutions closer than this in every hinge and slide coordinate and the free root's
/// position (rad, m), and in the angle between each free or ball joint's quaternions (rad):
/// the same branch, where one pass may hand over to the other.
const PASSES_AGREE: f64 = 0.05;

/// What [`splice_passes`] compares: every hinge and slide joint's coordinate and the free
/// root's position, and where each free or ball joint's quaternion starts (compared by the
/// angle between the two).
fn compared_coordinates(model: &Model) -> (Vec<usize>, Vec<usize>) {
    let scalars = model
        .joints
        .iter()
        .flat_map(|j| match j.kind {
            JointType::Hinge | JointType::Slide => j.qpos_adr..j.qpos_adr + 1,
            JointType::Free => j.qpos_adr..j.qpos_adr + 3,
            JointType::Ball => j.qpos_adr..j.qpos_adr,
        })
        .collect();
    (scalars, model.joints.iter().filter_map(mjcf::Joint::quat_adr).collect())
}

/// Replaces stretches of the forward first pass (`qpos`, `frames`: `nq` numbers and one
/// diagnostics per frame) by the backward one's (`back`, `back_frames`) where that lowers the
/// sum of the frames' tracking errors by more than a typical frame's error per switch,
/// switching only between frames where the two agree in every coordinate of `coords`
/// ([`PASSES_AGREE`]), so that no switch is a jump. Returns the frames (indices into the
/// range) where the result switches from one pass to the other.
fn splice_passes(
    nq: usize,
    (coords, quats): (&[usize], &[usize]),
    qpos: &mut [f64],
    frames: &mut [FrameDiagnostics],
    back: &[f64],
    back_frames: &[FrameDiagnostics],
) -> Vec<usize> {
    let n = frames.len();
    if n == 0 || back.len() != qpos.len() || qpos.len() != n * nq || back_frames.len() != n {
        return Vec::new();
    }
    let agree = |t: usize| {
        let (a, b) = (&qpos[t * nq..(t + 1) * nq], &back[t * nq..(t + 1) * nq]);
        let apart = |q: usize| {
            let dot = |x: &[f64], y: &[f64]| (0..4).map(|i| x[q + i] * y[q + i]).sum::<f64>();
            let norms = (dot(a, a) * dot(b, b)).sqrt().max(f64::MIN_POSITIVE);
            2.0 * (dot(a, b).abs() / norms).min(1.0).acos()
        };
        coords.iter().all(|&c| (a[c] - b[c]).abs() < PASSES_AGREE)
            && quats.iter().all(|&q| apart(q) < PASSES_AGREE)
    };
    let error = |side: usize, t: usize| {
        if side == 0 {
            frames[t].error
        } else {
            back_frames[t].error
        }
    };
    // Each switch costs as much as a typical frame's error, so that the passes do not trade
    // places for hundredths where they agree.
    let mut sorted: Vec<f64> = frames.iter().map(|f| f.error).collect();
    sorted.sort_by(f64::total_cmp);
    let penalty = sorted[n / 2];
    // The least total error up to frame t on each side, and the side frame t − 1 is on.
    // (Starting on the backward pass counts as a switch.)
    let mut cost = [error(0, 0), error(1, 0) + penalty];
    let mut from = vec![[0usize, 1usize]; n];
    for (t, came) in from.iter_mut().enumerate().skip(1) {
        let can_switch = agree(t - 1);
        let mut next = [0.0; 2];
        for side in 0..2 {
            let (stay, switch) = (cost[side], cost[1 - side] + penalty);
            if can_switch && switch < stay {
                (next[side], came[side]) = (switch + error(side, t), 1 - side);
            } else {
                (next[side], came[side]) = (stay + error(side, t), side);
            }
        }
        cost = next;
    }
    let mut side = usize::from(cost[1] < cost[0]);
    let mut switches = Vec::new();
    for t in (0..n).rev() {
        if side == 1 {
            qpos[t * nq..(t + 1) * nq].copy_from_slice(&back[t * nq..(t + 1) * nq]);
            frames[t] = back_frames[t].clone();
        }
        if from[t][side] != side {
            switches.push(t);
        }
        side = from[t][side];
    }
    switches.reverse();
    switches
}

#[cfg(test)]
mod tests {
    use super::super::prepare::{diverged, reject_divergence};
    use super::splice_passes;
    use crate::ik::FrameDiagnostics;

    /// One coordinate per frame, and the frames' errors.
    fn pass(q: &[f64], errors: &[f64]) -> (Vec<f64>, Vec<FrameDiagnostics>) {
        let frames = errors.iter().map(|&error| FrameDiagnostics { error, ..Default::default() });
        (q.to_vec(), frames.collect())
    }

    #[test]
    fn a_forward_pass_stuck_in_another_branch_hands_over_where_the_two_agree() {
        // Forward: fine for 4 frames, then a branch 1 rad away with twice the error.
        let (mut q, mut f) = pass(&[0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0], &[1.0; 8]);
        for d in &mut f[4..] {
            d.error = 2.0;
        }
        let (b, bf) = pass(&[0.01, 0.01, 0.0, 0.02, 0.1, 0.1, 0.1, 0.1], &[1.1; 8]);
        let switches = splice_passes(1, (&[0], &[]), &mut q, &mut f, &b, &bf);
        // The last frame both agree on is 3; the backward pass from frame 4 on.
        assert_eq!(switches, vec![4]);
        assert_eq!(q, vec![0.0, 0.0, 0.0, 0.0, 0.1, 0.1, 0.1, 0.1]);
        assert!(f[4..].iter().all(|d| d.error == 1.1));
    }

    #[test]
    fn passes_that_never_agree_or_gain_little_are_not_spliced() {
        let (q0, f0) = pass(&[0.0, 0.0, 1.0, 1.0], &[1.0, 1.0, 2.0, 2.0]);
        // Never within reach of each other: no switch, even though the backward pass is
        // better from frame 2 on (by less than a typical frame's error in all).
        let (b, bf) = pass(&[0.5, 0.5, 0.5, 0.5], &[1.2, 1.2, 1.0, 1.0]);
        let (mut q, mut f) = (q0.clone(), f0.clone());
        assert!(splice_passes(1, (&[0], &[]), &mut q, &mut f, &b, &bf).is_empty());
        assert_eq!(q, q0);
        // Agreeing everywhere, but better by less than a typical frame's error in all: kept.
        let (q1, f1) = pass(&[0.0; 4], &[1.0; 4]);
        let (b, bf) = pass(&[0.01; 4], &[0.9, 0.9, 0.9, 1.0]);
        let (mut q, mut f) = (q1.clone(), f1.clone());
        assert!(splice_passes(1, (&[0], &[]), &mut q, &mut f, &b, &bf).is_empty());
        assert_eq!(q, q1);
        // A coordinate and a quaternion per frame; the backward pass better from frame 2 on,
        // and worse before, so only a switch gains. A quaternion of the opposite sign agrees;
        // one turned 90° apart does not.
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let forward: Vec<f64> = [0.0, 1.0, 0.0, 0.0, 0.0].repeat(4);
        let (_, ff) = pass(&[0.0; 4], &[1.0, 1.0, 2.0, 2.0]);
        let (_, bf) = pass(&[0.0; 4], &[3.0, 3.0, 0.5, 0.5]);
        for (back, switched) in [([0.0, -1.0, 0.0, 0.0, 0.0], true), ([0.0, h, 0.0, 0.0, h], false)]
        {
            let (mut q, mut f) = (forward.clone(), ff.clone());
            let spliced = splice_passes(5, (&[0], &[1]), &mut q, &mut f, &back.repeat(4), &bf);
            assert_eq!(spliced, if switched { vec![2] } else { vec![] }, "{back:?}");
        }
        // A backward pass better throughout from its first frame on is taken whole.
        let (b, bf) = pass(&[0.5; 4], &[0.1; 4]);
        let (mut q, mut f) = (q0.clone(), f0.clone());
        assert!(splice_passes(1, (&[0], &[]), &mut q, &mut f, &b, &bf).is_empty());
        assert_eq!(q, vec![0.5; 4]);
    }

    #[test]
    fn absurd_configurations_are_divergence() {
        let mut q = vec![0.0, 0.0, 0.8, 1.0, 0.0, 0.0, 0.0, 0.3, -2.0];
        assert!(!diverged(&q));
        q[0] = 6.7e10; // the root of a blown-up step
        assert!(diverged(&q));
        q[0] = 0.0;
        q[8] = f64::NAN;
        assert!(diverged(&q));
        // A numerical failure, not an option: which frame, and what.
        let err = reject_divergence(&q, 7).unwrap_err();
        assert!(matches!(err, crate::Error::Numerical { frame: 7, .. }), "{err:?}");
        assert_eq!(err.to_string(), "frame 7: the solver diverged");
    }
}
