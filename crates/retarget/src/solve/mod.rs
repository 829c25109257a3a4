//! The default solve (and GMR's), stage by stage. `solve_clip` (behind [`retarget_motion`])
//! is the plan: each stage is one file of this module, run in this order.
//!
//! | # | stage | file | what it does | options |
//! |---|---|---|---|---|
//! | 0 | floor | `treadmill.rs` | a source whose feet slide back on its floor as on a treadmill (an in-place loop) put on a floor that stays put | [`crate::contact_phases::ContactOptions`] |
//! | 1 | targets | `prepare.rs` | the config's IK targets of every frame (GMR's scaling and offsets), the tasks | [`RetargetOptions`] |
//! | 2 | contacts | `contacts.rs` | the source's foot contact phases (both modes write them) | [`crate::contact_phases::ContactOptions`] |
//! | 3 | foot plan | `footholds.rs` | the robot's feet planted on them: anchors, soles standing flat, swing floors | [`crate::feet::FootPlanOptions`] |
//! | 4 | reweighing | `reweigh.rs` | trunk and leg weights where the config's pelvis disagrees with the robot's legs | [`PlausibleOptions`] |
//! | 5 | first pass | `first_pass.rs` | every frame solved causally with the hard constraints (what streams run) | [`crate::SolverOptions`] |
//! | 6 | trajectory | `trajectory.rs`, `windows.rs`, `banded.rs`, `dynamics_term.rs` | every frame of a window at once: tracking, smooth accelerations of every coordinate, the wrench the feet cannot supply, every constraint | [`TrajectoryOptions`], [`DynamicsOptions`] |
//!
//! Stages 5 and 6 run over a schedule (`schedule.rs`): the whole clip, or chunks of it in
//! parallel, each with a lead-in and a look-ahead. `--gmr` ([`SolveMode::Gmr`]) is stages 1,
//! 2 and 5 with GMR's solver and nothing else. The mode is read once, by [`Pipeline::new`]
//! (`pipeline.rs`): which stages run and with what options, what the stages read. A stage
//! with something to say about the clip returns a [`StageReport`] (named after its file:
//! `treadmill`, `reweigh`), which the driver collects, in the order the stages ran, into
//! [`ClipDiagnostics::stages`].
//!
//! The stages pass values; `solve_clip` names each one's output and hands it to the next:
//!
//! ```text
//! human ─0 walk_off────► human (off its treadmill), its report
//!       ─1 targets─────► Clip (what stays fixed: model, pipeline, rate, subject height,
//!                        tracked bodies, target slots), the config's tasks, every frame's targets
//!       ─2 contacts────► the source's contact phases
//!       ─3 plan────────► the targets with the feet's planted, the foot plan
//!                        → Problem { clip, tasks, targets, contacts, plan }
//!       ─4 reweigh─────► the Problem with its tasks reweighed (measured by stage 5's
//!                        `first_pass_frame` on the Problem it was given), its report,
//!                        and that pass where it was stage 5's (whole clip, tasks unchanged)
//!       ─5, 6 schedule─► per range: first_pass(&Problem, solver) → Solved (or stage 4's),
//!                        solve_trajectory(&Problem, solver, Solved) → Solved
//!       → RobotMotion and ClipDiagnostics (`Problem::finish`, with the stages' reports)
//! ```
//!
//! The solving stages (5 and 6: `first_pass.rs`, `windows.rs`, and the per-frame foot tasks
//! in `footholds.rs`) are functions of `&Problem` and change nothing in it; stage 4 is the
//! one stage that takes a `Problem` and returns another.

pub(crate) mod banded;
mod contacts;
pub mod dynamics_term;
mod first_pass;
mod footholds;
mod options;
mod pipeline;
mod prepare;
mod reweigh;
mod schedule;
pub mod trajectory;
mod treadmill;
mod windows;

use std::collections::BTreeMap;
use std::time::Instant;

use bvh::Bvh;
use fk::{HumanMotion, Role};
use mjcf::Model;

pub use dynamics_term::DynamicsOptions;
pub(crate) use first_pass::{first_frame_dt, solve_first_frame};
pub use options::{
    ChunkOptions, ClipDiagnostics, Planting, PlausibleOptions, RetargetOptions, SelfCollisionMode,
    SolveMode, SpeedLimits, StageReport, StageValue, SubjectHeight,
};
pub(crate) use pipeline::Pipeline;
pub(crate) use prepare::build_solver;
pub use prepare::task_specs;
pub(crate) use prepare::{finite_pose, reject_divergence};
pub use trajectory::TrajectoryOptions;

use crate::config::IkConfig;
use crate::contact_phases::human_foot_points;
use crate::motion::RobotMotion;
use crate::Error;
use prepare::Problem;

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
    let height = SubjectHeight { metres: report.height, source: report.height_source.clone() };
    // The recognised roles, so that the source's feet are found whatever their names.
    let recognised = report.humanoid.as_ref().ok().map(|humanoid| {
        humanoid.roles.iter().map(|(role, joint)| (role, joint.name.clone())).collect()
    });
    let roles = source_roles(&options.fk.roles, recognised.unwrap_or_default());
    let (motion, mut diag) = solve_clip(&human, model, config, options, &height, &roles)?;
    diag.human_inferred = report.inferred();
    Ok((motion, diag))
}

/// The stages (`solve_clip`) with the subject height given in `options.human_height`
/// (required here).
pub fn retarget_motion(
    human: &HumanMotion,
    model: &Model,
    config: &IkConfig,
    options: &RetargetOptions,
) -> Result<(RobotMotion, ClipDiagnostics), Error> {
    let metres = options.human_height.ok_or_else(|| Error::SubjectHeight {
        why: "none given (retarget_motion reads RetargetOptions::human_height)".to_owned(),
    })?;
    let height = SubjectHeight::given(metres);
    solve_clip(human, model, config, options, &height, &options.fk.roles)
}

/// The roles of a source's joints: those `given` ([`fk::FkOptions::roles`]), and the
/// `recognised` ones for the roles they leave.
pub(crate) fn source_roles(
    given: &BTreeMap<Role, String>,
    recognised: BTreeMap<Role, String>,
) -> BTreeMap<Role, String> {
    let mut roles = recognised;
    roles.extend(given.iter().map(|(role, joint)| (*role, joint.clone())));
    roles
}

/// Retargets a human motion (world poses, metres, Z up) of a subject `height` tall onto
/// `model`: the stages in order (`options.human_height` is not read: `height` is the one
/// decided for the clip). `roles` name the source's joints by role (its feet, for the
/// contact phases, are found by them, else by common names: `human_foot_points`).
pub(crate) fn solve_clip(
    human: &HumanMotion,
    model: &Model,
    config: &IkConfig,
    options: &RetargetOptions,
    height: &SubjectHeight,
    roles: &BTreeMap<Role, String>,
) -> Result<(RobotMotion, ClipDiagnostics), Error> {
    let pipeline = Pipeline::new(options);
    let feet = human_foot_points(&human.body_names, roles);
    // 0. The floor: a source on a treadmill walked off it.
    let walked = feet
        .filter(|_| pipeline.treadmill)
        .and_then(|feet| treadmill::walk_off(human, feet, &pipeline.contacts));
    let human = walked.as_ref().map_or(human, |(walked, _)| walked);
    // 1. The targets: the clip, the config's tasks, every frame's targets.
    let (clip, stages, targets) =
        prepare::targets(human, model, config, options, &pipeline, height)?;
    // 2. The source's contacts.
    let contacts = contacts::contacts(human, feet, &pipeline.contacts);
    // 3. The foot plan: the feet's targets planted on the contacts.
    let (targets, plan) = footholds::plan(&clip, &stages, contacts.as_ref(), targets);
    let problem = Problem { clip, stages, targets, contacts, plan };
    // 4. Reweighing: the tasks, where the config's pelvis disagrees with the robot's legs.
    let (problem, reweighed, done) = reweigh::reweigh_where_planted(problem)?;
    // What the stages that ran have to say, in order.
    let reports = walked.as_ref().map(|(_, report)| report.clone()).into_iter().chain(reweighed);
    let start = Instant::now();
    // 5 and 6. The first pass and the trajectory solve of the problem, over the schedule.
    let n = problem.num_frames();
    let solved = match options.chunk {
        None => schedule::solve_range(&problem, 0..n, 0, done)?,
        Some(chunk) => schedule::solve_chunks(&problem, chunk)?,
    };
    let seconds = start.elapsed().as_secs_f64();
    Ok(problem.finish(reports.collect(), solved.qpos, solved.frames, seconds))
}

/// [`retarget_motion`] with the clip solved as chunks in parallel (rayon's current pool).
pub fn retarget_motion_chunked(
    human: &HumanMotion,
    model: &Model,
    config: &IkConfig,
    options: &RetargetOptions,
    chunk: ChunkOptions,
) -> Result<(RobotMotion, ClipDiagnostics), Error> {
    let options = RetargetOptions { chunk: Some(chunk), ..options.clone() };
    retarget_motion(human, model, config, &options)
}
