//! Stage 4, reweighing: where the config pins the pelvis at a height the robot's legs
//! disagree with, the trunk's and legs' rotation weights are raised and the pelvis's
//! position weight capped.

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: frames and slots index the clip's own target buffer (`frames × slots`, built in
// `prepare`), body ids come from the model; the human motion's sizes are checked by
// `HumanMotion::validate` first.
#![allow(clippy::indexing_slicing)]

use std::collections::BTreeMap;
use std::ops::Range;

use mjcf::Model;

use super::first_pass::{first_pass_frame, DonePass};
use super::pipeline::ReweighOptions;
use super::prepare::{Problem, Solved, Tasks};
use super::{StageReport, StageValue};
use crate::ik::TaskSpec;
use crate::Error;

/// Stage 4 (default solve, feet planted): the `problem` of stages 1 to 3 with its tasks
/// [`reweigh`]ed by how far the robot's pelvis stands from its target with the config's
/// ([`pelvis_offset`]: stage 5's [`first_pass_frame`] over a few windows of that problem),
/// and what was done. Where the stage does not run, or the config does not pin the pelvis,
/// the problem comes back as it was, with no report. Where its one window was the whole
/// clip and the tasks stay as they were (share 0), the pass it ran is stage 5's forward
/// first pass, given back ([`DonePass`]) so that stage 5 does not run it again.
pub(super) fn reweigh_where_planted(
    problem: Problem<'_>,
) -> Result<(Problem<'_>, Option<StageReport>, Option<DonePass<'_>>), Error> {
    Ok(match reweighed_tasks(&problem)? {
        Some((stages, report, pass)) => (Problem { stages, ..problem }, Some(report), pass),
        None => (problem, None, None),
    })
}

/// [`reweigh_where_planted`]'s tasks, report and pass, the share of the change set by where
/// the offset falls in [`crate::PlausibleOptions::pelvis_offset_range`]; `None` where the
/// tasks stay the config's.
fn reweighed_tasks<'a>(
    problem: &Problem<'a>,
) -> Result<Option<(Tasks, StageReport, Option<DonePass<'a>>)>, Error> {
    let Some(options) = problem.clip.pipeline.reweigh else { return Ok(None) };
    if problem.plan.is_none() {
        return Ok(None);
    }
    // Only a root position weight above the cap holds the pelvis where the legs cannot
    // follow (GMR's G1 and H1 configs, 100; its T1, PM01 and ToddlerBot configs weigh it
    // 10, and doubling their trunk's and legs' rotation weights alone cost the PM01's
    // jumps position, 1.07× → 1.14× `--gmr`'s).
    let cap = options.root_position_weight_cap;
    let root = problem.clip.root_target;
    if !problem.stages.iter().flatten().any(|t| t.target == root && t.pos_weight > cap) {
        return Ok(None);
    }
    let Some((offset, pass)) = pelvis_offset(problem)? else { return Ok(None) };
    let [from, to] = options.pelvis_offset_range;
    let t = if to > from { ((offset - from) / (to - from)).clamp(0.0, 1.0) } else { 1.0 };
    let share = t * t * (3.0 - 2.0 * t);
    let mut stages = problem.stages.clone();
    reweigh(&mut stages, problem.clip.model, root, &options, share);
    // Reweighed tasks are another problem: stage 5 solves it from the start.
    let pass = pass.filter(|_| share <= 0.0);
    Ok(Some((stages, report(offset, share), pass)))
}

/// How far (m) the robot's pelvis stands above or below its target with `problem`'s
/// weights: the median height difference over [`PELVIS_WINDOWS`] windows of
/// [`PELVIS_WINDOW_S`] (at a quarter, half and three quarters of the clip, or the
/// whole of a shorter clip), each solved from its first frame as a clip is, its first
/// frames left out. Height only: the horizontal offsets follow the direction of travel
/// within a window (the N1's walk: 3.3 cm in all, 0.1 cm in height). With it, where the
/// one window was the whole clip (and stage 5 runs forward only), the pass: stage 5's
/// forward first pass of `problem`. `None` when no task tracks the root's position.
fn pelvis_offset<'a>(problem: &Problem<'a>) -> Result<Option<(f64, Option<DonePass<'a>>)>, Error> {
    let root_target = problem.clip.root_target;
    let root =
        problem.stages.iter().flatten().find(|t| t.target == root_target && t.pos_weight > 0.0);
    let Some(body) = root.map(|t| t.body) else { return Ok(None) };
    let frames = problem.num_frames();
    let clip = &problem.clip;
    let (window_frames, settle) =
        (clip.frames_in(PELVIS_WINDOW_S).max(1), clip.frames_in(PELVIS_SETTLE_S));
    let whole = frames <= PELVIS_WINDOWS * window_frames;
    let windows: Vec<Range<usize>> = if whole {
        std::iter::once(0..frames).collect()
    } else {
        (1..=PELVIS_WINDOWS)
            .map(|k| {
                let start = frames * k / (PELVIS_WINDOWS + 1) - window_frames / 2;
                start..start + window_frames
            })
            .collect()
    };
    // The whole clip solved forward is stage 5's first pass: kept, as `first_pass` keeps it.
    let keep = whole && !clip.pipeline.both_ways;
    let nq = clip.model.nq;
    let mut solved = Solved {
        qpos: Vec::with_capacity(if keep { frames * nq } else { 0 }),
        frames: Vec::with_capacity(if keep { frames } else { 0 }),
    };
    let mut solver = problem.solver()?;
    let mut heights = Vec::with_capacity(PELVIS_WINDOWS * window_frames);
    for window in windows {
        for f in window.clone() {
            let diagnostics = first_pass_frame(problem, &mut solver, f, f == window.start)?;
            if keep {
                solved.frames.push(diagnostics);
                solved.qpos.extend_from_slice(solver.qpos());
            }
            if f >= window.start + settle || window.len() <= settle {
                let target = &problem.frame_targets(f)[root_target];
                heights.push(solver.data().xpos[body].z - target.pos.z);
            }
        }
    }
    if heights.is_empty() {
        return Ok(None);
    }
    let median = crate::report::percentile(&heights, 0.5);
    Ok(Some((median.abs(), keep.then_some(DonePass { solver, solved }))))
}

/// What the reweighing says of a clip whose pelvis stood `offset` (m) above or below its
/// target with the config's weights, `share` (0 to 1) of [`reweigh`]'s changes applied:
/// values `pelvis_offset` (m) and `share`.
fn report(offset: f64, share: f64) -> StageReport {
    StageReport {
        stage: "reweigh",
        summary: format!(
            "the pelvis stands {:.1} cm off its target with the config's weights; trunk and \
             leg weights reweighed {:.0} %",
            100.0 * offset,
            100.0 * share
        ),
        values: BTreeMap::from([
            ("pelvis_offset", StageValue::Number(offset)),
            ("share", StageValue::Number(share)),
        ]),
    }
}

/// Windows of a clip solved to measure how far the pelvis stands from its target
/// ([`pelvis_offset`]), their length (s), and the time at the start of each left
/// out (s; the solve settles from its start pose). 30 and 5 frames at 30 fps.
const PELVIS_WINDOWS: usize = 3;
const PELVIS_WINDOW_S: f64 = 1.0;
const PELVIS_SETTLE_S: f64 = 1.0 / 6.0;

/// The default solve's weights where the config pins the pelvis at a height that disagrees
/// with the robot's legs:
/// the config's, with the rotation weight of every task whose body is not on an arm
/// multiplied by [`crate::PlausibleOptions::trunk_rotation_scale`], and the position weight of the
/// root's task (the task whose target is the human root, slot `root_target`) at most
/// [`crate::PlausibleOptions::root_position_weight_cap`] (`options`: those two); `share` (0 to 1) of each change. The arms
/// are the subtrees that hang from the recognised chest towards each upper arm
/// ([`crate::RobotRoles`]); a robot the recogniser rejects keeps its rotation weights.
///
/// LAFAN1, GMR's configs, default solve, mean rotation error against `--gmr`'s (its
/// position error stays within 1.02× of `--gmr`'s on the G1): G1 walk 1.17× → 1.05×, jumps
/// 1.24× → 1.09× (the per-frame solve with its smoothing filter). On configs whose targets agree with
/// the robot's legs it trades position for little rotation (every share 1, our derived
/// config, the G1 on the Bandai walk: 4.29° → 4.04°, 1.55 → 2.97 cm), hence the share.
pub(crate) fn reweigh(
    stages: &mut [Vec<TaskSpec>],
    model: &Model,
    root_target: usize,
    options: &ReweighOptions,
    share: f64,
) {
    if share <= 0.0 {
        return;
    }
    let arms = crate::RobotRoles::recognise(model).ok().and_then(|roles| arm_roots(model, &roles));
    let trunk = 1.0 + share * (options.trunk_rotation_scale - 1.0);
    for task in stages.iter_mut().flatten() {
        if task.target == root_target && task.pos_weight > options.root_position_weight_cap {
            task.pos_weight -= share * (task.pos_weight - options.root_position_weight_cap);
        }
        if let Some(arms) = &arms {
            if !arms.iter().any(|&arm| model.is_ancestor_or_self(arm, task.body)) {
                task.rot_weight *= trunk;
            }
        }
    }
}

/// The first body of each arm: the chest's child on the way to the upper arm (`None` unless
/// both are found).
fn arm_roots(model: &Model, roles: &crate::RobotRoles) -> Option<[usize; 2]> {
    let chest = roles.body(fk::Role::Chest)?;
    let root = |role: fk::Role| {
        let mut body = roles.body(role)?;
        while body != 0 && model.bodies[body].parent != chest {
            body = model.bodies[body].parent;
        }
        (body != 0).then_some(body)
    };
    Some([root(fk::Role::LeftUpperArm)?, root(fk::Role::RightUpperArm)?])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The report's summary says what its values hold, as the main command prints it.
    #[test]
    fn the_report_says_the_offset_and_the_share() {
        let r = report(0.013, 0.87);
        assert_eq!(r.stage, "reweigh");
        assert_eq!(r.values["pelvis_offset"], StageValue::Number(0.013));
        assert_eq!(r.values["share"], StageValue::Number(0.87));
        assert_eq!(
            r.summary,
            "the pelvis stands 1.3 cm off its target with the config's weights; trunk and leg \
             weights reweighed 87 %"
        );
    }
}
