//! Stage 3, the foot plan ([`plan`]): the robot's feet, and each frame's planted sole points,
//! foot weights and swing floors from the source's contacts ([`crate::feet`]). Also what
//! the solving stages (5 and 6) ask of the plan: a frame's foot tasks set on the solver
//! ([`Problem::set_frame_tasks`]).

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: frames and slots index the clip's own target buffer (`frames × slots`, built in
// `prepare`), body ids come from the model; the human motion's sizes are checked by
// `HumanMotion::validate` first.
#![allow(clippy::indexing_slicing)]

use mjcf::Model;
use nalgebra::Vector3;

use super::prepare::{Clip, PlannedFeet, Problem};
use crate::feet::RobotFoot;
use crate::ik::{GripPoint, PointTask, Solver, TaskSpec};
use crate::lie::Pose;
use crate::motion::FootContacts;
use crate::Error;

/// Stage 3, the default solve's foot plan, when it plants the feet: the robot's feet found
/// (by `stages`, the tasks) and planted on the source's `contacts`; returns `targets` (all
/// frames', `frames × slots`) with the feet's rewritten, and the plan. Without a plan (when
/// the human's or the robot's feet are not found) the targets stay GMR's and only the
/// constraints apply.
pub(super) fn plan(
    clip: &Clip<'_>,
    stages: &[Vec<TaskSpec>],
    contacts: Option<&FootContacts>,
    mut targets: Vec<Pose>,
) -> (Vec<Pose>, Option<PlannedFeet>) {
    let Some(options) = &clip.pipeline.foot_plan else { return (targets, None) };
    let feet = robot_feet(clip.model, stages);
    let Some(contacts) = contacts else { return (targets, None) };
    let plan = crate::feet::plan(&feet, contacts, &mut targets, clip.slots, clip.fps, options);
    (targets, Some((feet, plan)))
}

/// Which way a pass runs through the clip's frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Pass {
    Forward,
    Backward,
}

impl Problem<'_> {
    /// Frame `f`'s foot weight factors and contact-point tasks (default mode), for a pass
    /// forward through the clip (the trajectory solve's, the first pass's).
    pub(super) fn set_frame_tasks(&self, solver: &mut Solver<'_>, f: usize) -> Result<(), Error> {
        self.set_frame_tasks_in(solver, f, Pass::Forward)
    }

    /// [`Problem::set_frame_tasks`] for a pass that runs through the clip as `pass` says. A
    /// grip holds a point where it was in the frame solved before; backward, that is the
    /// frame after, and a rising sole's grips ([`crate::feet::FootPlan::lifted_at`]) would
    /// hold it where the swing has taken it: backward, they are left out.
    pub(super) fn set_frame_tasks_in(
        &self,
        solver: &mut Solver<'_>,
        f: usize,
        pass: Pass,
    ) -> Result<(), Error> {
        let Some((feet, plan)) = &self.plan else { return Ok(()) };
        let raised: Vec<(usize, f64)> = feet
            .iter()
            .zip(&plan.swing_floor[f])
            .filter_map(|(foot, floor)| Some((foot.as_ref()?, (*floor)?)))
            .flat_map(|(foot, floor)| foot.geoms.iter().map(move |&g| (g, floor)))
            .collect();
        solver.set_raised_geoms(&raised);
        let mut points = Vec::with_capacity(8);
        let mut grips = Vec::with_capacity(8);
        let w = self.contact_weight();
        for (side, (foot, contact)) in feet.iter().zip(&plan.contact[f]).enumerate() {
            let Some(foot) = foot else { continue };
            let body = foot.body;
            solver.set_weight_scale(body, plan.weight[f][side], 1.0);
            let before = f.checked_sub(1).map_or(&[][..], |b| &plan.contact[b][side][..]);
            let rising = pass == Pass::Forward && plan.swing_floor[f][side].is_some();
            for p in contact {
                let (h, v) = (w * p.horizontal, w * p.vertical);
                let weight = Vector3::new(h, h, v);
                points.push(PointTask { body, point: p.point, target: p.at, weight });
                // Held on their footholds: the points a planted sole stands on, and as firmly
                // the points a rising sole stood on at lift-off, until the sole is up (a foot
                // leaves the floor by lifting its last contact, not by sliding it). Each from
                // where the frame before had it.
                let from = if p.vertical > 0.0 && p.horizontal > 0.0 {
                    Some(before.iter().find(|b| b.point == p.point && b.vertical > 0.0))
                } else if rising && p.horizontal > 0.0 && plan.lifted_at(f, side, &p.point) {
                    Some(before.iter().find(|b| b.point == p.point))
                } else {
                    None
                };
                if let Some(from) = from {
                    grips.push(GripPoint {
                        body,
                        point: p.point,
                        at: p.at,
                        from: from.map(|b| b.at),
                    });
                }
            }
        }
        solver.set_grips(&grips, self.grip_slip_speed())?;
        solver.set_point_tasks(&points)
    }
}

/// The robot's two feet (sole bodies, [`crate::feet::detect_feet`]) with the task that moves
/// each: a task on the sole body itself, else on its nearest ancestor that has one.
fn robot_feet(model: &Model, stages: &[Vec<TaskSpec>]) -> [Option<RobotFoot>; 2] {
    let Ok(soles) = crate::feet::detect_feet(model) else {
        return [None, None];
    };
    // The nearest body at or above `from` that has a task, with that task's target slot.
    let tracked_ancestor = |mut body: usize| loop {
        if let Some(task) = stages.iter().flatten().find(|t| t.body == body) {
            return Some((body, task.target));
        }
        if body == 0 {
            return None;
        }
        body = model.bodies[body].parent;
    };
    // The sole's own task, else a tracked body welded to the sole (no joint between them:
    // Toddy's `left_toe_link` under its sole body `ank_roll_link`), which moves rigidly with
    // it; otherwise the nearest tracked ancestor. Walking up from such a sole would plant the
    // shin.
    let tracked_welded = |sole: usize| {
        let welded = |mut b: usize| loop {
            if b == sole {
                return true;
            }
            if b == 0 || model.bodies[b].jnt_num > 0 {
                return false;
            }
            b = model.bodies[b].parent;
        };
        // `min_by_key` keeps the first of equals: the sole if tracked, else the first task's.
        let task =
            stages.iter().flatten().filter(|t| welded(t.body)).min_by_key(|t| t.body != sole);
        task.map(|t| (t.body, t.target))
    };
    soles.map(|sole| {
        let (body, slot) = tracked_welded(sole).or_else(|| tracked_ancestor(sole))?;
        let shin = tracked_ancestor(model.bodies[body].parent);
        RobotFoot::new(model, body, sole, slot, shin)
    })
}
