//! Stage 1, the targets: every frame's IK targets from the config (scaled, offset) and the
//! tasks ([`targets`]); and the values the stages pass on: the [`Clip`] stage 1 fixes, and
//! the [`Problem`] the solving stages (5 and 6) solve.

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: frames and slots index the clip's own target buffer (`frames × slots`, built in
// `prepare`), body ids come from the model; the human motion's sizes are checked by
// `HumanMotion::validate` first.
#![allow(clippy::indexing_slicing)]

use mjcf::Model;
use nalgebra::{UnitQuaternion, Vector3};

use super::pipeline::Pipeline;
use super::{
    ClipDiagnostics, RetargetOptions, SelfCollisionMode, SpeedLimits, StageReport, SubjectHeight,
};
use crate::config::IkConfig;
use crate::constraints::{Grip, Ground, SelfCollision};
use crate::feet::{FootPlan, RobotFoot};
use crate::ik::{FrameDiagnostics, Solver, TaskSpec};
use crate::lie::Pose;
use crate::motion::{FootContacts, RobotMotion, TrackedTargets};
use crate::targets::TargetMap;
use crate::Error;
use fk::HumanMotion;

/// What stage 1 fixes of a clip for the rest of the solve: the robot, the stages that run,
/// the frame rate, the subject's height, and how the targets are laid out.
pub(crate) struct Clip<'a> {
    pub(super) model: &'a Model,
    /// The stages that run, and their options.
    pub(super) pipeline: &'a Pipeline,
    pub(super) fps: f64,
    pub(super) height: &'a SubjectHeight,
    /// `(body, target slot)` of each tracked body, as [`Solver::tracked`] orders them.
    pub(super) tracked: Vec<(usize, usize)>,
    /// Targets per frame.
    pub(super) slots: usize,
    /// Target slot of the human root.
    pub(super) root_target: usize,
}

/// The solver's tasks, one list per IK stage of the config ([`task_specs`]).
pub(crate) type Tasks = Vec<Vec<TaskSpec>>;

/// The robot's two feet (those found) and the plan that plants them: stage 3's.
pub(crate) type PlannedFeet = ([Option<RobotFoot>; 2], FootPlan);

/// What the solving stages (5 and 6, over [`super::schedule`]) solve: the [`Clip`], the
/// tasks, every frame's targets (foot-planned in the default mode), the source's contacts and
/// the foot plan. The driver builds it from the outputs of stages 1 to 3; stage 4 returns it
/// with its tasks reweighed where it reweighs them; the solving stages only read it. Solving
/// frame ranges of it independently is how [`super::schedule`] parallelises a clip.
pub(crate) struct Problem<'a> {
    pub(super) clip: Clip<'a>,
    /// The solver's tasks, one list per IK stage of the config (stage 1's; stage 4's where
    /// it reweighs them).
    pub(super) stages: Tasks,
    /// `frames × slots` targets (stage 1's; stage 3 rewrites the feet's).
    pub(super) targets: Vec<Pose>,
    /// The source's contact phases (stage 2), where its feet were found.
    pub(super) contacts: Option<FootContacts>,
    /// Foot bodies and per-frame weight factors (stage 3, default mode).
    pub(super) plan: Option<PlannedFeet>,
}

/// Solved frames of a range: each frame's `qpos` (`nq` numbers a frame) and diagnostics,
/// what stages 5 and 6 return.
pub(crate) struct Solved {
    pub qpos: Vec<f64>,
    pub frames: Vec<FrameDiagnostics>,
}

/// Stage 1: the clip, the config's tasks (one list per IK stage of the config) and every
/// frame's targets (`frames × slots`), from `human` seen by a subject `height` tall.
pub(super) fn targets<'a>(
    human: &HumanMotion,
    model: &'a Model,
    config: &IkConfig,
    options: &RetargetOptions,
    pipeline: &'a Pipeline,
    height: &'a SubjectHeight,
) -> Result<(Clip<'a>, Tasks, Vec<Pose>), Error> {
    human.validate()?;
    config.validate(model, &human.body_names)?;
    let map = TargetMap::new(config, &human.body_names, height.metres)?;
    let stages = task_specs(config, model, &map);
    let tracked = Solver::new(model, &stages, options.solver.clone())?.tracked().to_vec();
    let (nb, nf) = (human.num_bodies(), human.num_frames);
    let slots = map.bodies.len();
    let mut targets = vec![Pose { quat: [1.0, 0.0, 0.0, 0.0], pos: Vector3::zeros() }; nf * slots];
    for f in 0..nf {
        let range = f * nb..(f + 1) * nb;
        let out = &mut targets[f * slots..(f + 1) * slots];
        map.compute(&human.positions[range.clone()], &human.orientations[range], out);
        if let Some(bad) = out.iter().position(|p| !finite_pose(p)) {
            let message = format!("target of human body `{}` is not finite", map.bodies[bad].name);
            return Err(Error::Numerical { frame: f, message });
        }
    }
    let clip =
        Clip { model, pipeline, fps: human.fps, height, tracked, slots, root_target: map.root };
    Ok((clip, stages, targets))
}

impl Clip<'_> {
    /// Seconds between frames (0 for a clip without a rate).
    pub(super) fn frame_dt(&self) -> f64 {
        if self.fps > 0.0 {
            1.0 / self.fps
        } else {
            0.0
        }
    }

    /// The frames in `seconds` at the clip's rate, rounded (30 fps for a clip without one, as
    /// the windows take it): the one conversion of the solve's times into frames.
    pub(super) fn frames_in(&self, seconds: f64) -> usize {
        let fps = if self.fps > 0.0 { self.fps } else { 30.0 };
        (seconds * fps).round().max(0.0) as usize
    }
}

impl<'a> Problem<'a> {
    /// The robot body a task follows the human root's target with.
    pub(super) fn root_body(&self) -> Option<usize> {
        let root = self.clip.root_target;
        self.stages.iter().flatten().find(|t| t.target == root).map(|t| t.body)
    }

    /// The contact points' weight ([`crate::FootPlanOptions::contact_weight`]; 0 without a
    /// foot plan).
    pub(super) fn contact_weight(&self) -> f64 {
        self.clip.pipeline.foot_plan.as_ref().map_or(0.0, |f| f.contact_weight)
    }

    /// How fast a planted sole's points may slide ([`crate::FootPlanOptions::slip_speed`]).
    pub(super) fn grip_slip_speed(&self) -> f64 {
        self.clip.pipeline.foot_plan.as_ref().map_or(0.0, |f| f.slip_speed)
    }

    /// A solver for this problem: GMR's, or with the default mode's constraints.
    pub(super) fn solver(&self) -> Result<Solver<'a>, Error> {
        build_solver(self.clip.model, &self.stages, self.clip.pipeline)
    }

    pub(super) fn frame_targets(&self, f: usize) -> &[Pose] {
        let slots = self.clip.slots;
        &self.targets[f * slots..(f + 1) * slots]
    }

    /// The clip's motion and diagnostics from its solved frames (all of them, in order) and
    /// what the stages that ran had to say, in order ([`ClipDiagnostics::stages`]).
    pub(crate) fn finish(
        &self,
        reports: Vec<StageReport>,
        qpos: Vec<f64>,
        frames: Vec<FrameDiagnostics>,
        solve_seconds: f64,
    ) -> (RobotMotion, ClipDiagnostics) {
        let clip = &self.clip;
        let model = clip.model;
        let nf = frames.len();
        let mut target_pos = Vec::with_capacity(nf * clip.tracked.len());
        let mut target_quat = Vec::with_capacity(nf * clip.tracked.len());
        for f in 0..nf {
            for &(_, t) in &clip.tracked {
                let p = &self.targets[f * clip.slots + t];
                target_pos.push(p.pos);
                let q = nalgebra::Quaternion::new(p.quat[0], p.quat[1], p.quat[2], p.quat[3]);
                target_quat.push(UnitQuaternion::new_unchecked(q));
            }
        }
        let body_name = |b: usize| model.bodies[b].name.clone();
        let tracked_names: Vec<String> = clip.tracked.iter().map(|&(b, _)| body_name(b)).collect();
        let motion = RobotMotion {
            fps: clip.fps,
            nq: model.nq,
            qpos,
            joint_names: RobotMotion::model_joint_names(model),
            body_names: RobotMotion::model_body_names(model),
            targets: Some(TrackedTargets {
                body_names: tracked_names.clone(),
                pos: target_pos,
                quat: target_quat,
            }),
            contacts: self.contacts.clone(),
        };
        let stages = &self.stages;
        let weighted = |body: usize, pick: fn(&TaskSpec) -> f64| {
            stages.iter().flatten().any(|t| t.body == body && pick(t) != 0.0)
        };
        let diag = ClipDiagnostics {
            body_names: tracked_names,
            position_tracked: clip
                .tracked
                .iter()
                .map(|&(b, _)| weighted(b, |t| t.pos_weight))
                .collect(),
            rotation_tracked: clip
                .tracked
                .iter()
                .map(|&(b, _)| weighted(b, |t| t.rot_weight))
                .collect(),
            frames,
            human_height: clip.height.metres,
            human_height_source: clip.height.source.clone(),
            human_inferred: String::new(),
            solve_seconds,
            stages: reports,
        };
        (motion, diag)
    }

    pub(crate) fn num_frames(&self) -> usize {
        self.targets.len().checked_div(self.clip.slots).unwrap_or(0)
    }
}

impl crate::solve::trajectory::Frames for Problem<'_> {
    fn targets(&self, frame: usize) -> &[Pose] {
        self.frame_targets(frame)
    }

    fn configure(&self, solver: &mut Solver<'_>, frame: usize) -> Result<(), Error> {
        self.set_frame_tasks(solver, frame)
    }

    fn root_reference(&self, frame: usize) -> Option<(Pose, usize)> {
        Some((self.frame_targets(frame)[self.clip.root_target], self.root_body()?))
    }
}

/// The solver of a clip or a stream: GMR's, or with the default mode's constraints (ground,
/// self-collision, joint speed limits). The one place both [`retarget_motion`](super::retarget_motion) and
/// [`crate::Retargeter::step`] build it, so that they solve the same problem.
pub(crate) fn build_solver<'m>(
    model: &'m Model,
    stages: &[Vec<TaskSpec>],
    pipeline: &Pipeline,
) -> Result<Solver<'m>, Error> {
    let mut solver = Solver::new(model, stages, pipeline.solver.clone())?;
    if let Some(p) = &pipeline.constraints {
        solver.add_constraint(Box::new(Ground::new(model, p.floor)));
        if p.self_collision == SelfCollisionMode::On {
            solver.add_constraint(Box::new(SelfCollision::new(model)));
        }
        if p.speed_limits == SpeedLimits::Robot {
            let limits: Vec<Option<f64>> = model.joints.iter().map(|j| j.velocity_limit).collect();
            solver.set_speed_limits(&limits)?;
        }
        // Last: the constraint dropped first where a frame cannot hold them all.
        solver.add_constraint(Box::new(Grip));
    }
    Ok(solver)
}

/// Active entries of each enabled table as solver tasks; target slots index `map.bodies`.
#[must_use]
pub fn task_specs(config: &IkConfig, model: &Model, map: &TargetMap) -> Vec<Vec<TaskSpec>> {
    config
        .stages()
        .into_iter()
        .map(|table| {
            table
                .iter()
                .filter(|e| e.is_active())
                .filter_map(|e| {
                    Some(TaskSpec {
                        body: model.body_id(&e.robot_body)?,
                        target: map.index_of(&e.human_body)?,
                        pos_weight: e.pos_weight,
                        rot_weight: e.rot_weight,
                    })
                })
                .collect()
        })
        .collect()
}

/// A configuration no solve of a real motion reaches: a coordinate not finite, or beyond
/// [`fk::MAX_DISTANCE`] (100 km for the root, as many radians for a joint). Written output
/// must never hold one (a near-singular step once put a root at 6.7e10 m).
pub(super) fn diverged(qpos: &[f64]) -> bool {
    qpos.iter().any(|v| !v.is_finite() || v.abs() > fk::MAX_DISTANCE)
}

/// [`Error::Numerical`] naming `frame` when its solved `qpos` [diverged].
pub(crate) fn reject_divergence(qpos: &[f64], frame: usize) -> Result<(), Error> {
    if diverged(qpos) {
        return Err(Error::Numerical { frame, message: "the solver diverged".to_owned() });
    }
    Ok(())
}

pub(crate) fn finite_pose(p: &Pose) -> bool {
    p.pos.iter().all(|v| v.is_finite()) && p.quat.iter().all(|v| v.is_finite())
}
