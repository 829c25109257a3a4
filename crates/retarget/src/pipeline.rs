//! BVH → robot motion: human FK, targets, IK over every frame with warm start.

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: frames and slots index the clip's own target buffer (`frames × slots`, built here),
// body ids come from the model; the human motion's sizes are checked by `HumanMotion::validate`
// first.
#![allow(clippy::indexing_slicing)]

use std::ops::Range;
use std::time::Instant;

use bvh::Bvh;
use fk::{FkOptions, HumanMotion};
use mjcf::{JointType, Model};
use nalgebra::{UnitQuaternion, Vector3};

use crate::config::IkConfig;
use crate::constraints::{Ground, SelfCollision};
use crate::feet::{is_descendant, FootPlan, RobotFoot};
use crate::lie::Pose;
use crate::motion::{FootContacts, RobotMotion, TrackedTargets};
use crate::solver::{FrameDiagnostics, PointTask, Solver, SolverOptions, TaskSpec};
use crate::targets::TargetMap;
// The crate's error, also reachable here (it was defined in this module).
pub use crate::Error;

/// Which solve [`retarget_motion`] runs.
// (One per solve, never in a loop or a collection: boxing the options would only make them
// harder to build.)
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq)]
pub enum SolveMode {
    /// GMR's algorithm and targets, reproduced exactly (`--gmr`; `tests/parity.rs`).
    Gmr,
    /// The default: GMR's targets and weights as the tracking objective, with the source's
    /// contact phases planted on the floor and hard constraints (ground, joint speed).
    Plausible(PlausibleOptions),
}

impl Default for SolveMode {
    fn default() -> Self {
        SolveMode::Plausible(PlausibleOptions::default())
    }
}

/// A planted foot this far (m) from its target in a crossed stance is stuck there
/// ([`PlausibleOptions::uncross_stuck`]). Where the T1 could not stand crossed, its planted
/// feet were up to 10 cm off.
pub const UNCROSS_STUCK: f64 = 0.03;

/// Frames solved again either side of the frames whose targets an uncrossing changed
/// (`Prepared::resolve_uncrossed`), and the lead-in before them (as a chunk's).
pub const RESOLVE_MARGIN: usize = 30;
pub const RESOLVE_LEAD_IN: usize = 60;

/// The two legs touch where geoms of theirs are closer than this (m)
/// ([`PlausibleOptions::uncross_stuck`]).
pub const LEGS_TOUCH: f64 = 0.005;

/// A robot stuck in a crossed stance has its pelvis at least this far (m) below its target
/// ([`PlausibleOptions::uncross_stuck`]): legs in each other's way are shorter. (The T1 on
/// the LAFAN1 walk: 6–19 cm. The H1, whose feet are off their targets in crossed stances
/// too, as elsewhere, for want of an ankle roll, stands 5–13 cm above its target there,
/// and uncrossing them widened stances its feet could not stand flat in: sliding 6.9 →
/// 7.7 %.)
pub const UNCROSS_SINK: f64 = 0.03;

/// Tunables of [`SolveMode::Plausible`].
#[derive(Debug, Clone, PartialEq)]
pub struct PlausibleOptions {
    /// Whether the robot's feet are planted on the floor during the source's contact phases
    /// (this plans over the whole clip, so it needs the future). The phases themselves are
    /// detected and written in every mode.
    pub planting: Planting,
    pub contact: crate::contact::ContactOptions,
    pub feet: crate::feet::FootPlanOptions,
    /// Every collision geom stays above this height (m): the floor, for the ground
    /// constraint.
    pub floor: f64,
    /// Hold the joints' speed limits (`mjcf::Joint::velocity_limit`) as hard bounds.
    pub speed_limits: SpeedLimits,
    /// Keep the robot's own geoms apart ([`crate::constraints::SelfCollision`]).
    pub self_collision: SelfCollisionMode,
    /// Factor on the rotation weights of every task but the arms' (the trunk and the legs,
    /// [`reweigh`]) where the config pins the pelvis at a height that disagrees with the
    /// robot's legs (its position weight above [`PlausibleOptions::root_position_weight_cap`],
    /// [`PlausibleOptions::pelvis_offset_range`]). GMR balanced
    /// its leg rotation weights (5–10) against feet that follow the human's; planted, the
    /// feet and the pelvis position decide the legs' posture and the legs' orientations gave
    /// way (the G1's hips and knees 2–4° further from their targets than with GMR's solve).
    pub trunk_rotation_scale: f64,
    /// The root's position weight is at most this ([`reweigh`]) where the config's targets
    /// disagree with the robot's legs. GMR weighs the G1's and the H1's pelvis position 100
    /// (its other configs 10–50): with the feet planted on the floor, that held the G1's
    /// pelvis at the scaled human's height, 1.6–3.1 cm under where its legs put it.
    pub root_position_weight_cap: f64,
    /// How far (m) the robot's pelvis stands above or below its target, median over a few
    /// windows of the clip solved with the config's weights (`Prepared::pelvis_offset`),
    /// over which the two changes above fade in (smoothstep from the first to the second).
    /// Measured where the root's position weight is above the cap: GMR's G1 config on the
    /// LAFAN1 walk / jumps 1.3 / 2.8 cm, its H1 config 5.0 / 3.5; our derived configs
    /// (pelvis weight 100 too) 0–0.5 cm on CMU, Mixamo, Rigify and the Bandai kick and run,
    /// 0.5–1.8 cm on the Bandai walks and dance (their scales come from the robot's limbs).
    pub pelvis_offset_range: [f64; 2],
    /// Also run the first pass backwards, from the clip's last frame to its first, and
    /// hand over to it where it tracks better (the sum of the frames' tracking errors lower by
    /// more than the median frame's error per switch, switching only where the two passes
    /// agree to 0.05 rad and 5 cm, so that no switch is a jump). A warm-started solve keeps
    /// the branch a limb is in: on the Bandai kick the PM01's right hip went over into the
    /// hip's other branch (pitch and roll at their limits, yaw −200°) for the 300 frames after
    /// the kick, and the backward pass, which reaches the kick from the normal stance, never
    /// does. Costs a second first pass, run on a second thread of rayon's pool.
    pub both_ways: bool,
    /// Where the robot could not stand in a crossed stance ([`crate::feet::Crossing`]: in a
    /// frame both feet are down, a planted foot [`UNCROSS_STUCK`] or further from its target,
    /// the legs within [`LEGS_TOUCH`] of each other and the pelvis [`UNCROSS_SINK`] or more
    /// below its target), plan those steps again side by side and solve their frames again.
    /// The human crosses over in a crouch on the LAFAN1 walk (near frames 2990, 3240 and 3300,
    /// the right foot landing 11 cm to the left of the left one); the T1's legs are too thick
    /// for it: held crossed, its self-collision rows lifted its planted feet up to 10 cm and
    /// sank its pelvis up to 19 cm below its target. Uncrossing every crossed stance instead
    /// kept the T1's feet down but tripled the foot error of every robot (the G1's walk 14 →
    /// 49 mm), whose legs cross there without trouble. Costs solving again the frames whose
    /// targets that changed (`Prepared::resolve_uncrossed`; the T1's LAFAN1 walk: 2 steps,
    /// 504 frames of 7,184 with the margins and lead-in; 5 % more time).
    pub uncross_stuck: bool,
    /// The trajectory solve over every frame ([`crate::solve::trajectory`]); 0 iterations:
    /// the first pass alone.
    pub trajectory: crate::solve::trajectory::TrajectoryOptions,
    /// [`SolverOptions::max_extra_steps`] of this solve (GMR: 10).
    pub max_extra_steps: usize,
}

/// Whether [`SolveMode::Plausible`] plants the feet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Planting {
    On,
    /// No planted foot targets: the targets are GMR's (the contact labels are still written).
    Off,
}

/// Whether the solve keeps the robot's geoms apart.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SelfCollisionMode {
    On,
    Off,
}

/// Whether the solve holds the robot's joint speed limits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpeedLimits {
    /// Per joint, `mjcf::Joint::velocity_limit` where it is set.
    Robot,
    Off,
}

impl Default for PlausibleOptions {
    fn default() -> Self {
        PlausibleOptions {
            planting: Planting::On,
            contact: crate::contact::ContactOptions::default(),
            feet: crate::feet::FootPlanOptions::default(),
            floor: 0.0,
            speed_limits: SpeedLimits::Robot,
            self_collision: SelfCollisionMode::On,
            trunk_rotation_scale: 2.0,
            root_position_weight_cap: 20.0,
            pelvis_offset_range: [0.005, 0.015],
            both_ways: false,
            uncross_stuck: true,
            trajectory: crate::solve::trajectory::TrajectoryOptions::default(),
            max_extra_steps: 10,
        }
    }
}

impl PlausibleOptions {
    /// The causal part of the default solve: GMR's tasks with the hard constraints (ground,
    /// self-collision, joint speed), warm-started frame by frame; no foot planting, no
    /// smoothing and no backward pass, which all need the frames that follow. What streaming
    /// ([`crate::Retargeter::step`]) runs; a clip solved with it gives the same numbers.
    #[must_use]
    pub fn causal() -> PlausibleOptions {
        PlausibleOptions {
            planting: Planting::Off,
            both_ways: false,
            uncross_stuck: false,
            trajectory: crate::solve::trajectory::TrajectoryOptions {
                iterations: 0,
                ..Default::default()
            },
            ..PlausibleOptions::default()
        }
    }
}

/// Options of [`retarget_bvh`] / [`retarget_motion`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RetargetOptions {
    /// Subject height in metres; `None` uses the FK estimate (GMR assumes 1.75).
    pub human_height: Option<f64>,
    pub solver: SolverOptions,
    /// FK options. Their `roles` also name the source's feet for the contact phases
    /// ([`crate::contact::human_foot_points`]); [`retarget_bvh`] adds the recognised ones.
    pub fk: FkOptions,
    /// Solve long clips as parallel chunks ([`crate::chunked`]); `None`: one serial pass.
    pub chunk: Option<crate::chunked::ChunkOptions>,
    /// The default solve or GMR's.
    pub mode: SolveMode,
}

impl RetargetOptions {
    /// GMR's exact solve.
    #[must_use]
    pub fn gmr() -> RetargetOptions {
        RetargetOptions { mode: SolveMode::Gmr, ..RetargetOptions::default() }
    }

    /// The default solve's causal part ([`PlausibleOptions::causal`]).
    #[must_use]
    pub fn causal() -> RetargetOptions {
        let mode = SolveMode::Plausible(PlausibleOptions::causal());
        RetargetOptions { mode, ..RetargetOptions::default() }
    }
}

/// Per-clip diagnostics: per frame, and which bodies the per-body arrays refer to.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ClipDiagnostics {
    /// Tracked robot bodies (same order as [`TrackedTargets::body_names`]).
    pub body_names: Vec<String>,
    /// Per tracked body: whether some stage gives it a non-zero position weight (its
    /// position error is meaningful) ...
    pub position_tracked: Vec<bool>,
    /// ... and a non-zero rotation weight.
    pub rotation_tracked: Vec<bool>,
    pub frames: Vec<FrameDiagnostics>,
    /// Subject height used for scaling (m) and where it came from.
    pub human_height: f64,
    pub human_height_source: String,
    /// What FK inferred about the source, in one line ([`fk::FkReport::inferred`]: up axis,
    /// unit, skeleton roles, rest pose); empty when a `HumanMotion` was given directly.
    pub human_inferred: String,
    /// Wall time of the IK alone (seconds).
    pub solve_seconds: f64,
    /// How far (m) the robot's pelvis stood above or below its target with the config's
    /// weights ([`PlausibleOptions::pelvis_offset_range`]; default solve with planted feet),
    /// and the share of [`reweigh`]'s changes applied (0 to 1).
    pub pelvis_offset: Option<f64>,
    pub reweigh_share: f64,
    /// Frames of the crossed stances planned again uncrossed
    /// ([`PlausibleOptions::uncross_stuck`]), in order.
    pub uncrossed: Vec<Range<usize>>,
}

impl ClipDiagnostics {
    /// Frames taken from the backward first pass ([`PlausibleOptions::both_ways`]) and the
    /// stretches they form.
    #[must_use]
    pub fn from_backward(&self) -> (usize, usize) {
        let frames = self.frames.iter().filter(|f| f.backward).count();
        let starts = self
            .frames
            .iter()
            .enumerate()
            .filter(|&(t, f)| f.backward && (t == 0 || !self.frames[t - 1].backward))
            .count();
        (frames, starts)
    }

    /// Per body: mean and 95th percentile of the position error (m) over the frames.
    #[must_use]
    pub fn position_error_stats(&self) -> Vec<(f64, f64)> {
        self.stats(|f, k| f.pos_error[k])
    }

    /// Per body: mean and 95th percentile of the rotation error (rad) over the frames.
    #[must_use]
    pub fn rotation_error_stats(&self) -> Vec<(f64, f64)> {
        self.stats(|f, k| f.rot_error[k])
    }

    /// Frames with at least one joint at a limit, and the total joint-frames at a limit.
    #[must_use]
    pub fn limit_hits(&self) -> (usize, usize) {
        let frames = self.frames.iter().filter(|f| !f.at_limit.is_empty()).count();
        (frames, self.frames.iter().map(|f| f.at_limit.len()).sum())
    }

    fn stats(&self, value: impl Fn(&FrameDiagnostics, usize) -> f64) -> Vec<(f64, f64)> {
        (0..self.body_names.len())
            .map(|k| {
                let v: Vec<f64> = self.frames.iter().map(|f| value(f, k)).collect();
                if v.is_empty() {
                    return (0.0, 0.0);
                }
                let mean = v.iter().sum::<f64>() / v.len() as f64;
                (mean, crate::report::percentile(&v, 0.95))
            })
            .collect()
    }
}

/// Human FK of `bvh`, then [`retarget_motion`].
pub fn retarget_bvh(
    bvh: &Bvh,
    model: &Model,
    config: &IkConfig,
    options: &RetargetOptions,
) -> Result<(RobotMotion, ClipDiagnostics), Error> {
    let mut fk_options = options.fk.clone();
    if options.human_height.is_some() {
        fk_options.height = options.human_height;
    }
    let (human, report) = fk::human_motion(bvh, &fk_options)?;
    let mut opts = options.clone();
    opts.human_height = Some(report.height);
    // The recognised roles, so that the source's feet are found whatever their names.
    if let Ok(humanoid) = &report.humanoid {
        for (role, joint) in humanoid.roles.iter() {
            opts.fk.roles.entry(role).or_insert_with(|| joint.name.clone());
        }
    }
    let (motion, mut diag) = match options.chunk {
        Some(chunk) => {
            crate::chunked::retarget_motion_chunked(&human, model, config, &opts, chunk)?
        }
        None => retarget_motion(&human, model, config, &opts)?,
    };
    diag.human_inferred = report.inferred();
    diag.human_height_source = report.height_source;
    Ok((motion, diag))
}

/// Retargets a human motion (world poses, metres, Z up) onto `model`. The subject height
/// is `options.human_height` (required here: the FK report has it for BVH input).
pub fn retarget_motion(
    human: &HumanMotion,
    model: &Model,
    config: &IkConfig,
    options: &RetargetOptions,
) -> Result<(RobotMotion, ClipDiagnostics), Error> {
    let mut prepared = Prepared::new(human, model, config, options)?;
    let start = Instant::now();
    let mut solved = prepared.solve(0..human.num_frames, 0)?;
    prepared.resolve_uncrossed(&mut solved)?;
    Ok(prepared.finish(solved.qpos, solved.frames, start.elapsed().as_secs_f64()))
}

/// One clip made ready to solve: every frame's targets (foot-planned in the default mode),
/// the source's contacts and the task setup. Solving frame ranges of it independently is
/// how [`crate::chunked`] parallelises a clip.
pub(crate) struct Prepared<'a> {
    model: &'a Model,
    options: &'a RetargetOptions,
    stages: Vec<Vec<TaskSpec>>,
    /// `(body, target slot)` of each tracked body, as [`Solver::tracked`] orders them.
    tracked: Vec<(usize, usize)>,
    slots: usize,
    /// `frames × slots` targets.
    targets: Vec<Pose>,
    contacts: Option<FootContacts>,
    /// Foot bodies and per-frame weight factors (default mode).
    plan: Option<([Option<RobotFoot>; 2], FootPlan)>,
    /// The targets before the foot plan rewrote them (default mode, planted feet), to plan
    /// again from ([`Prepared::uncross_stuck`]), and the stance overlaps uncrossed.
    unplanned: Option<Vec<Pose>>,
    uncrossed: Vec<Range<usize>>,
    fps: f64,
    height: f64,
    /// Target slot of the human root.
    root_target: usize,
    /// [`ClipDiagnostics::pelvis_offset`] and [`ClipDiagnostics::reweigh_share`].
    pelvis_offset: Option<f64>,
    reweigh_share: f64,
}

/// Solved frames of a range.
pub(crate) struct Solved {
    pub qpos: Vec<f64>,
    pub frames: Vec<FrameDiagnostics>,
}

impl<'a> Prepared<'a> {
    pub(crate) fn new(
        human: &HumanMotion,
        model: &'a Model,
        config: &IkConfig,
        options: &'a RetargetOptions,
    ) -> Result<Prepared<'a>, Error> {
        human.validate()?;
        let height = options
            .human_height
            .ok_or_else(|| Error::InvalidOption("the subject height is required".to_owned()))?;
        config.validate(model, &human.body_names)?;
        let map = TargetMap::new(config, &human.body_names, height)?;
        let stages = task_specs(config, model, &map);
        let tracked = Solver::new(model, &stages, options.solver.clone())?.tracked().to_vec();
        let (nb, nf) = (human.num_bodies(), human.num_frames);
        let slots = map.bodies.len();
        let mut targets =
            vec![Pose { quat: [1.0, 0.0, 0.0, 0.0], pos: Vector3::zeros() }; nf * slots];
        for f in 0..nf {
            let range = f * nb..(f + 1) * nb;
            let out = &mut targets[f * slots..(f + 1) * slots];
            map.compute(&human.positions[range.clone()], &human.orientations[range], out);
            if let Some(bad) = out.iter().position(|p| !finite_pose(p)) {
                let message =
                    format!("target of human body `{}` is not finite", map.bodies[bad].name);
                return Err(Error::NonFinite { frame: f, message });
            }
        }
        let mut prepared = Prepared {
            model,
            options,
            stages,
            tracked,
            slots,
            targets,
            contacts: None,
            plan: None,
            unplanned: None,
            uncrossed: Vec::new(),
            fps: human.fps,
            height,
            root_target: map.root,
            pelvis_offset: None,
            reweigh_share: 0.0,
        };
        // The source's contact phases are written in both modes (GMR's solve ignores them);
        // the default mode plants the feet on them.
        let contact = match &options.mode {
            SolveMode::Plausible(p) => p.contact.clone(),
            SolveMode::Gmr => crate::contact::ContactOptions::default(),
        };
        if let Some(points) =
            crate::contact::human_foot_points(&human.body_names, &options.fk.roles)
        {
            prepared.contacts = Some(crate::contact::detect(human, points, &contact));
        }
        if let SolveMode::Plausible(plausible) = &options.mode {
            if plausible.planting == Planting::On {
                let feet = robot_feet(model, &prepared.stages);
                prepared.plan_feet(plausible, feet);
                if prepared.plan.is_some() {
                    prepared.reweigh(plausible)?;
                }
            }
        }
        Ok(prepared)
    }

    /// Planted foot targets for the robot's `feet` from the source contacts (when both the
    /// human's and the robot's feet are found; otherwise the targets stay GMR's and only the
    /// constraints apply).
    fn plan_feet(&mut self, options: &PlausibleOptions, feet: [Option<RobotFoot>; 2]) {
        let Some(contacts) = &self.contacts else { return };
        if options.uncross_stuck {
            self.unplanned = Some(self.targets.clone());
        }
        let heading = self.heading();
        let plan = crate::feet::plan_uncrossing(
            &feet,
            contacts,
            &mut self.targets,
            self.slots,
            self.fps,
            &options.feet,
            &crate::feet::Uncrossing { uncross: &[], heading: &heading },
        );
        self.plan = Some((feet, plan));
    }

    /// The robot body a task follows the human root's target with.
    fn root_body(&self) -> Option<usize> {
        self.stages.iter().flatten().find(|t| t.target == self.root_target).map(|t| t.body)
    }

    /// Per frame, the yaw (rad) the robot's pelvis is to face: the root target's turn of the
    /// body's forward direction (world +x at `qpos0`, as for the feet). Empty when no task
    /// follows the root target.
    fn heading(&self) -> Vec<f64> {
        let Some(body) = self.root_body() else { return Vec::new() };
        let mut data = mjcf::Data::new(self.model);
        self.model.kinematics(&self.model.qpos0, &mut data);
        let forward = data.xquat[body].inverse() * Vector3::x();
        (0..self.num_frames())
            .map(|t| {
                let p = &self.frame_targets(t)[self.root_target];
                let q = UnitQuaternion::new_normalize(nalgebra::Quaternion::new(
                    p.quat[0], p.quat[1], p.quat[2], p.quat[3],
                ));
                let f = q * forward;
                f.y.atan2(f.x)
            })
            .collect()
    }

    /// [`PlausibleOptions::uncross_stuck`] on the whole clip's solved frames (`solved`): plans
    /// the feet again with the stuck crossed stances uncrossed ([`Prepared::uncross_stuck`])
    /// and solves again the frames whose targets that changed, with
    /// [`RESOLVE_MARGIN`] frames either side and a lead-in of [`RESOLVE_LEAD_IN`], as a chunk
    /// is solved ([`crate::chunked`]); the rest of the clip is kept.
    pub(crate) fn resolve_uncrossed(&mut self, solved: &mut Solved) -> Result<(), Error> {
        let Some(changed) = self.uncross_stuck(&solved.qpos, &solved.frames) else {
            return Ok(());
        };
        let nq = self.model.nq;
        let n = solved.frames.len();
        let range =
            changed.start.saturating_sub(RESOLVE_MARGIN)..(changed.end + RESOLVE_MARGIN).min(n);
        let mut part = self.solve(range.clone(), RESOLVE_LEAD_IN)?;
        if let Some(before) = range.start.checked_sub(1) {
            crate::chunked::continue_quaternions(
                self.model,
                &solved.qpos[before * nq..range.start * nq],
                &mut part.qpos,
            );
        }
        solved.qpos.splice(range.start * nq..range.end * nq, part.qpos);
        solved.frames.splice(range.clone(), part.frames);
        if range.end < n {
            let (head, tail) = solved.qpos.split_at_mut(range.end * nq);
            crate::chunked::continue_quaternions(self.model, &head[head.len() - nq..], tail);
        }
        Ok(())
    }

    /// [`PlausibleOptions::uncross_stuck`]: plans the feet again, with the crossed stance
    /// phases uncrossed in which the clip's solved frames (`qpos`, `frames`) have a planted
    /// foot [`UNCROSS_STUCK`] or further from its target, the legs touching and the pelvis
    /// sunk. The frames whose targets changed, if it planned again (its weights stay as they
    /// are).
    fn uncross_stuck(&mut self, qpos: &[f64], frames: &[FrameDiagnostics]) -> Option<Range<usize>> {
        let (SolveMode::Plausible(options), Some(unplanned), Some((feet, plan)), Some(contacts)) =
            (&self.options.mode, &self.unplanned, &self.plan, &self.contacts)
        else {
            return None;
        };
        let [Some(left), Some(right)] = feet else { return None };
        if plan.crossed.is_empty() {
            return None;
        }
        let model = self.model;
        // The feet's places among the solver's tracked bodies, whose errors `frames` hold.
        let tracked: Vec<usize> = [left, right]
            .iter()
            .filter_map(|foot| self.tracked.iter().position(|&(_, slot)| slot == foot.slot))
            .collect();
        // The geom pairs between the two legs: each leg is the subtree of the foot's highest
        // ancestor that the other foot does not hang from (as `feet::leg_length` walks up).
        let top = |foot: usize, other: usize| {
            if is_descendant(model, other, foot) {
                return None;
            }
            let mut body = foot;
            while !is_descendant(model, other, model.bodies[body].parent) {
                body = model.bodies[body].parent;
            }
            Some(body)
        };
        let (Some(top_left), Some(top_right)) =
            (top(left.body, right.body), top(right.body, left.body))
        else {
            return None;
        };
        let leg_of = |g: usize| {
            let body = model.geoms[g].body;
            if is_descendant(model, body, top_left) {
                Some(0)
            } else if is_descendant(model, body, top_right) {
                Some(1)
            } else {
                None
            }
        };
        let between: Vec<[usize; 2]> = model
            .self_collision_pairs()
            .pairs
            .into_iter()
            .filter(|&[a, b]| matches!((leg_of(a), leg_of(b)), (Some(x), Some(y)) if x != y))
            .collect();
        let root = self.root_body()?;
        let nq = model.nq;
        let mut data = mjcf::Data::new(model);
        // A frame is stuck where a planted foot is far from its target, the legs touch and the
        // pelvis sinks below its target.
        let mut stuck = |t: usize| {
            let far = frames.get(t).is_some_and(|f| {
                tracked.iter().any(|&k| f.pos_error.get(k).is_some_and(|e| *e >= UNCROSS_STUCK))
            });
            let Some(q) = qpos.get(t * nq..(t + 1) * nq) else { return false };
            if !far {
                return false;
            }
            model.kinematics(q, &mut data);
            let sunk = self.frame_targets(t)[self.root_target].pos.z - data.xpos[root].z;
            sunk >= UNCROSS_SINK
                && between.iter().any(|&[a, b]| {
                    mjcf::geom_distance(model, &data, a, b, LEGS_TOUCH)
                        .is_some_and(|p| p.distance < LEGS_TOUCH)
                })
        };
        let (phases, overlaps): (Vec<(usize, usize)>, Vec<Range<usize>>) = plan
            .crossed
            .iter()
            .filter(|c| c.frames.clone().any(&mut stuck))
            .map(|c| (c.phases, c.frames.clone()))
            .unzip();
        if phases.is_empty() {
            return None;
        }
        let feet = [Some(left.clone()), Some(right.clone())];
        let mut targets = unplanned.clone();
        let heading = self.heading();
        let plan = crate::feet::plan_uncrossing(
            &feet,
            contacts,
            &mut targets,
            self.slots,
            self.fps,
            &options.feet,
            &crate::feet::Uncrossing { uncross: &phases, heading: &heading },
        );
        let slots = self.slots.max(1);
        let differs = |t: &usize| {
            targets[t * slots..(t + 1) * slots] != self.targets[t * slots..(t + 1) * slots]
        };
        let frames_n = self.num_frames();
        let first = (0..frames_n).find(differs)?;
        let last = (0..frames_n).rev().find(differs)?;
        (self.targets, self.plan, self.uncrossed) = (targets, Some((feet, plan)), overlaps);
        Some(first..last + 1)
    }

    /// [`reweigh`]s the tasks by how far the robot's pelvis stands from its target
    /// ([`Prepared::pelvis_offset`], [`PlausibleOptions::pelvis_offset_range`]).
    fn reweigh(&mut self, options: &PlausibleOptions) -> Result<(), Error> {
        // Only a root position weight above the cap holds the pelvis where the legs cannot
        // follow (GMR's G1 and H1 configs, 100; its T1, PM01 and ToddlerBot configs weigh it
        // 10, and doubling their trunk's and legs' rotation weights alone cost the PM01's
        // jumps position, 1.07× → 1.14× `--gmr`'s).
        let cap = options.root_position_weight_cap;
        let root = self.root_target;
        if !self.stages.iter().flatten().any(|t| t.target == root && t.pos_weight > cap) {
            return Ok(());
        }
        let Some(offset) = self.pelvis_offset()? else { return Ok(()) };
        let [from, to] = options.pelvis_offset_range;
        let t = if to > from { ((offset - from) / (to - from)).clamp(0.0, 1.0) } else { 1.0 };
        let share = t * t * (3.0 - 2.0 * t);
        reweigh(&mut self.stages, self.model, self.root_target, options, share);
        (self.pelvis_offset, self.reweigh_share) = (Some(offset), share);
        Ok(())
    }

    /// How far (m) the robot's pelvis stands above or below its target with the config's
    /// weights: the median height difference over [`PELVIS_WINDOWS`] windows of
    /// [`PELVIS_WINDOW`] frames (at a quarter, half and three quarters of the clip, or the
    /// whole of a shorter clip), each solved from its first frame as a clip is, its first
    /// frames left out. Height only: the horizontal offsets follow the direction of travel
    /// within a window (the N1's walk: 3.3 cm in all, 0.1 cm in height). `None` when no task
    /// tracks the root's position.
    fn pelvis_offset(&self) -> Result<Option<f64>, Error> {
        let root = self
            .stages
            .iter()
            .flatten()
            .find(|t| t.target == self.root_target && t.pos_weight > 0.0);
        let Some(body) = root.map(|t| t.body) else { return Ok(None) };
        let frames = self.num_frames();
        let windows: Vec<Range<usize>> = if frames <= PELVIS_WINDOWS * PELVIS_WINDOW {
            std::iter::once(0..frames).collect()
        } else {
            (1..=PELVIS_WINDOWS)
                .map(|k| {
                    let start = frames * k / (PELVIS_WINDOWS + 1) - PELVIS_WINDOW / 2;
                    start..start + PELVIS_WINDOW
                })
                .collect()
        };
        let mut solver = self.solver()?;
        let mut heights = Vec::with_capacity(PELVIS_WINDOWS * PELVIS_WINDOW);
        for window in windows {
            for f in window.clone() {
                self.first_pass_frame(&mut solver, f, f == window.start)?;
                if f >= window.start + PELVIS_SETTLE || window.len() <= PELVIS_SETTLE {
                    let target = &self.frame_targets(f)[self.root_target];
                    heights.push(solver.data().xpos[body].z - target.pos.z);
                }
            }
        }
        if heights.is_empty() {
            return Ok(None);
        }
        let median = crate::report::percentile(&heights, 0.5);
        Ok(Some(median.abs()))
    }

    fn contact_weight(&self) -> f64 {
        match &self.options.mode {
            SolveMode::Plausible(p) => p.feet.contact_weight,
            SolveMode::Gmr => 0.0,
        }
    }

    /// A solver for this clip: GMR's, or with the default mode's constraints.
    fn solver(&self) -> Result<Solver<'a>, Error> {
        build_solver(self.model, &self.stages, self.options)
    }

    /// Solves frames `range`, starting from `qpos0` at frame `range.start − lead_in`
    /// (frames of the lead-in are solved and dropped).
    pub(crate) fn solve(&self, range: Range<usize>, lead_in: usize) -> Result<Solved, Error> {
        let mut solver = self.solver()?;
        let nq = self.model.nq;
        let first = range.start.saturating_sub(lead_in);
        // The trajectory solve's last frames need the frames after them in view: a range
        // that ends before the clip does is solved a window's overlap further (and the extra
        // frames dropped), as a long clip's windows are.
        let ahead = match &self.options.mode {
            SolveMode::Plausible(p) if p.trajectory.iterations > 0 => {
                crate::solve::trajectory::overlap_frames(&p.trajectory, self.fps)
            }
            _ => 0,
        };
        let end = (range.end + ahead).min(self.num_frames());
        // Both passes hold every constraint. (A first pass under box bounds only is 1.4×
        // faster on the G1, but on robots whose tracking drives links into each other, e.g.
        // Toddy's hips, one repair step then cannot get out within the speed limits and drops
        // the self-collision rows: 1402 frames > 1 cm against 14.)
        let forward =
            |solver: &mut Solver<'_>| -> Result<(Vec<f64>, Vec<FrameDiagnostics>), Error> {
                let mut qpos = Vec::with_capacity((end - first) * nq);
                let mut frames = Vec::with_capacity(end - first);
                for f in first..end {
                    frames.push(self.first_pass_frame(solver, f, f == first)?);
                    reject_divergence(solver.qpos(), f)?;
                    qpos.extend_from_slice(solver.qpos());
                }
                Ok((qpos, frames))
            };
        let (mut qpos, mut frames) = if matches!(&self.options.mode, SolveMode::Plausible(p) if p.both_ways)
        {
            // The two directions on two threads of rayon's pool (one, in a busy pool, is
            // the same work in turn).
            let (ahead, back) =
                rayon::join(|| forward(&mut solver), || self.first_pass_backward(first..end));
            let ((mut qpos, mut frames), (back, back_frames)) = (ahead?, back?);
            let (coords, quats) = compared_coordinates(self.model);
            splice_passes(nq, (&coords, &quats), &mut qpos, &mut frames, &back, &back_frames);
            (qpos, frames)
        } else {
            forward(&mut solver)?
        };
        if let SolveMode::Plausible(p) = &self.options.mode {
            if p.trajectory.iterations > 0 && !qpos.is_empty() {
                self.solve_trajectory(&mut solver, &p.trajectory, first, &mut qpos, &mut frames)?;
            }
        }
        let skip = range.start - first;
        qpos.truncate((range.end - first) * nq);
        frames.truncate(range.end - first);
        Ok(Solved { qpos: qpos.split_off(skip * nq), frames: frames.split_off(skip) })
    }

    /// The trajectory solve ([`crate::solve::trajectory`]) of frames `first..` (`qpos`, the
    /// first pass's, in and out), window after window.
    fn solve_trajectory(
        &self,
        solver: &mut Solver<'a>,
        options: &crate::solve::trajectory::TrajectoryOptions,
        first: usize,
        qpos: &mut [f64],
        frames: &mut [FrameDiagnostics],
    ) -> Result<(), Error> {
        let nq = self.model.nq;
        let n = frames.len();
        let mut trajectory =
            crate::solve::trajectory::Trajectory::new(solver, self.stages.len(), options, self.fps);
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

    /// Frame `f` of a first pass: its foot tasks set, solved from the previous frame's pose
    /// (the `first` of a solve: from [`solve_first_frame`]'s start in the default mode, and
    /// without speed limits).
    fn first_pass_frame(
        &self,
        solver: &mut Solver<'_>,
        f: usize,
        first: bool,
    ) -> Result<FrameDiagnostics, Error> {
        self.set_frame_tasks(solver, f)?;
        let targets = self.frame_targets(f);
        let diagnostics = if first && matches!(self.options.mode, SolveMode::Plausible(_)) {
            solve_first_frame(self.model, solver, &self.tracked, targets)?
        } else {
            solver.solve_frame(targets, first_frame_dt(first, self.frame_dt()))?
        };
        Ok(diagnostics)
    }

    /// The first pass run backwards over `range`: from its last frame (solved as a first
    /// frame) to its first, each frame warm-started from the one after it.
    fn first_pass_backward(
        &self,
        range: Range<usize>,
    ) -> Result<(Vec<f64>, Vec<FrameDiagnostics>), Error> {
        let mut solver = self.solver()?;
        let nq = self.model.nq;
        let mut qpos = vec![0.0; range.len() * nq];
        let mut frames = vec![FrameDiagnostics::default(); range.len()];
        for (k, f) in range.clone().enumerate().rev() {
            frames[k] = self.first_pass_frame(&mut solver, f, f + 1 == range.end)?;
            frames[k].backward = true;
            reject_divergence(solver.qpos(), f)?;
            qpos[k * nq..(k + 1) * nq].copy_from_slice(solver.qpos());
        }
        Ok((qpos, frames))
    }

    /// Seconds between frames (0 for a clip without a rate).
    fn frame_dt(&self) -> f64 {
        if self.fps > 0.0 {
            1.0 / self.fps
        } else {
            0.0
        }
    }

    fn frame_targets(&self, f: usize) -> &[Pose] {
        &self.targets[f * self.slots..(f + 1) * self.slots]
    }

    /// Frame `f`'s foot weight factors and contact-point tasks (default mode).
    fn set_frame_tasks(&self, solver: &mut Solver<'_>, f: usize) -> Result<(), Error> {
        self.set_frame_tasks_at(solver, f, None)
    }

    /// [`Prepared::set_frame_tasks`]; with `at` (kinematics of the smoothed pose a repair
    /// starts from), also a vertical task, weighted as the contact points, that lifts each
    /// swing sole found below its swing clearance ([`FootPlan::swing_floor`]) back up to it.
    /// The smoothing filter pulls a swing foot towards its planted neighbours' height, the
    /// further the more passes it has: ToddlerBot's (8 passes) swung 2.6–2.9 cm up (median)
    /// in 1,500 of its LAFAN1 walk's frames, under the report's 3 cm contact height, and the
    /// report counted 12.4 % of its contact frames as sliding (1.6 % lifted; the G1's jumps
    /// 6.5 → 5.3 %).
    fn set_frame_tasks_at(
        &self,
        solver: &mut Solver<'_>,
        f: usize,
        at: Option<&mjcf::Data>,
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
        let w = self.contact_weight();
        for (side, (foot, contact)) in feet.iter().zip(&plan.contact[f]).enumerate() {
            let Some(foot) = foot else { continue };
            let body = foot.body;
            solver.set_weight_scale(body, plan.weight[f][side], 1.0);
            for p in contact {
                let (h, v) = (w * p.horizontal, w * p.vertical);
                let weight = Vector3::new(h, h, v);
                points.push(PointTask { body, point: p.point, target: p.at, weight });
            }
            if let (Some(data), Some(floor)) = (at, plan.swing_floor[f][side]) {
                let rot = data.xquat[body];
                let point = foot.sole_low_point(&rot);
                let world = data.xpos[body] + rot * point;
                if world.z < floor {
                    let target = Vector3::new(world.x, world.y, floor);
                    points.push(PointTask {
                        body,
                        point,
                        target,
                        weight: Vector3::new(0.0, 0.0, w),
                    });
                }
            }
        }
        solver.set_point_tasks(&points)
    }

    /// The clip's motion and diagnostics from its solved frames (all of them, in order).
    pub(crate) fn finish(
        &self,
        qpos: Vec<f64>,
        frames: Vec<FrameDiagnostics>,
        solve_seconds: f64,
    ) -> (RobotMotion, ClipDiagnostics) {
        let model = self.model;
        let nf = frames.len();
        let mut target_pos = Vec::with_capacity(nf * self.tracked.len());
        let mut target_quat = Vec::with_capacity(nf * self.tracked.len());
        for f in 0..nf {
            for &(_, t) in &self.tracked {
                let p = &self.targets[f * self.slots + t];
                target_pos.push(p.pos);
                let q = nalgebra::Quaternion::new(p.quat[0], p.quat[1], p.quat[2], p.quat[3]);
                target_quat.push(UnitQuaternion::new_unchecked(q));
            }
        }
        let body_name = |b: usize| model.bodies[b].name.clone();
        let tracked_names: Vec<String> = self.tracked.iter().map(|&(b, _)| body_name(b)).collect();
        let motion = RobotMotion {
            fps: self.fps,
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
            position_tracked: self
                .tracked
                .iter()
                .map(|&(b, _)| weighted(b, |t| t.pos_weight))
                .collect(),
            rotation_tracked: self
                .tracked
                .iter()
                .map(|&(b, _)| weighted(b, |t| t.rot_weight))
                .collect(),
            frames,
            human_height: self.height,
            human_height_source: "given".to_owned(),
            human_inferred: String::new(),
            solve_seconds,
            pelvis_offset: self.pelvis_offset,
            reweigh_share: self.reweigh_share,
            uncrossed: self.uncrossed.clone(),
        };
        (motion, diag)
    }

    pub(crate) fn num_frames(&self) -> usize {
        self.targets.len().checked_div(self.slots).unwrap_or(0)
    }
}

impl crate::solve::trajectory::Frames for Prepared<'_> {
    fn targets(&self, frame: usize) -> &[Pose] {
        self.frame_targets(frame)
    }

    fn configure(&self, solver: &mut Solver<'_>, frame: usize) -> Result<(), Error> {
        self.set_frame_tasks(solver, frame)
    }

    fn root_reference(&self, frame: usize) -> Option<(Pose, bool)> {
        let free = self.model.joints.iter().find(|j| j.kind == JointType::Free)?;
        let body = self.root_body()?;
        Some((self.frame_targets(frame)[self.root_target], body == free.body))
    }
}

/// The solver of a clip or a stream: GMR's, or with the default mode's constraints (ground,
/// self-collision, joint speed limits). The one place both [`retarget_motion`] and
/// [`crate::Retargeter::step`] build it, so that they solve the same problem.
pub(crate) fn build_solver<'m>(
    model: &'m Model,
    stages: &[Vec<TaskSpec>],
    options: &RetargetOptions,
) -> Result<Solver<'m>, Error> {
    let mut solver_options = options.solver.clone();
    if let SolveMode::Plausible(p) = &options.mode {
        solver_options.max_extra_steps = p.max_extra_steps;
        solver_options.arithmetic = crate::solver::Arithmetic::Lean;
    }
    let mut solver = Solver::new(model, stages, solver_options)?;
    if let SolveMode::Plausible(p) = &options.mode {
        solver.add_constraint(Box::new(Ground::new(model, p.floor)));
        if p.self_collision == SelfCollisionMode::On {
            solver.add_constraint(Box::new(SelfCollision::new(model)));
        }
        if p.speed_limits == SpeedLimits::Robot {
            let limits: Vec<Option<f64>> = model.joints.iter().map(|j| j.velocity_limit).collect();
            solver.set_speed_limits(&limits)?;
        }
    }
    Ok(solver)
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

/// Windows of a clip solved to measure how far the pelvis stands from its target
/// ([`Prepared::pelvis_offset`]), their length in frames, and the frames at the start of each
/// left out (the solve settles from its start pose).
const PELVIS_WINDOWS: usize = 3;
const PELVIS_WINDOW: usize = 30;
const PELVIS_SETTLE: usize = 5;

/// The robot's two feet (sole bodies, as the report finds them) with the task that moves
/// each: a task on the sole body itself, else on its nearest ancestor that has one.
fn robot_feet(model: &Model, stages: &[Vec<TaskSpec>]) -> [Option<RobotFoot>; 2] {
    let Ok(soles) = crate::report::detect_feet(model) else {
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

/// The default solve's weights where the config pins the pelvis at a height that disagrees
/// with the robot's legs:
/// the config's, with the rotation weight of every task whose body is not on an arm
/// multiplied by [`PlausibleOptions::trunk_rotation_scale`], and the position weight of the
/// root's task (the task whose target is the human root, slot `root_target`) at most
/// [`PlausibleOptions::root_position_weight_cap`]; `share` (0 to 1) of each change. The arms
/// are the subtrees that hang from the recognised chest towards each upper arm
/// ([`crate::RobotRoles`]); a robot the recogniser rejects keeps its rotation weights.
///
/// LAFAN1, GMR's configs, default solve, mean rotation error against `--gmr`'s (its
/// position error stays within 1.02× of `--gmr`'s on the G1): G1 walk 1.17× → 1.05×, jumps
/// 1.24× → 1.09× (the per-frame solve with its smoothing filter). On configs whose targets agree with
/// the robot's legs it trades position for little rotation (every share 1, our derived
/// config, the G1 on the Bandai walk: 4.29° → 4.04°, 1.55 → 2.97 cm), hence the share.
pub fn reweigh(
    stages: &mut [Vec<TaskSpec>],
    model: &Model,
    root_target: usize,
    options: &PlausibleOptions,
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
            if !arms.iter().any(|&arm| crate::feet::is_descendant(model, task.body, arm)) {
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
fn diverged(qpos: &[f64]) -> bool {
    qpos.iter().any(|v| !v.is_finite() || v.abs() > fk::MAX_DISTANCE)
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

/// [`Error::NonFinite`] naming `frame` when its solved `qpos` [diverged](diverged).
pub(crate) fn reject_divergence(qpos: &[f64], frame: usize) -> Result<(), Error> {
    if diverged(qpos) {
        return Err(Error::NonFinite { frame, message: "the solver diverged".to_owned() });
    }
    Ok(())
}

pub(crate) fn finite_pose(p: &Pose) -> bool {
    p.pos.iter().all(|v| v.is_finite()) && p.quat.iter().all(|v| v.is_finite())
}

#[cfg(test)]
mod tests {
    use super::{diverged, splice_passes};
    use crate::solver::FrameDiagnostics;

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
    }
}
