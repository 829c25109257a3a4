//! BVH → robot motion: human FK, targets, IK over every frame with warm start.

use std::time::Instant;

use bvh::Bvh;
use fk::{FkOptions, HumanMotion};
use mjcf::Model;
use nalgebra::{UnitQuaternion, Vector3};

use crate::config::IkConfig;
use crate::lie::Pose;
use crate::motion::{RobotMotion, TrackedTargets};
use crate::solver::{FrameDiagnostics, Solver, SolverOptions, TaskSpec};
use crate::targets::TargetMap;

/// Everything that can go wrong in the retargeting crate.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    #[error("{path}: cannot read file: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
    /// A config that does not parse or breaks a rule; `at` is `file:line:column`.
    #[error("{at}: {message}")]
    Config { at: String, message: String },
    /// A robot or human body name in a config that does not exist.
    #[error("{at}: unknown {side} body `{name}`{}", did_you_mean(nearest))]
    UnknownName { at: String, side: String, name: String, nearest: Vec<String> },
    #[error("invalid option: {0}")]
    InvalidOption(String),
    /// Human forward kinematics failed (bad BVH content, NaN in the motion, ...).
    #[error(transparent)]
    Fk(#[from] fk::Error),
    /// Non-finite target or solver state at a frame.
    #[error("frame {frame}: {message}")]
    NonFinite { frame: usize, message: String },
}

fn did_you_mean(nearest: &[String]) -> String {
    if nearest.is_empty() {
        String::new()
    } else {
        format!("; nearest: {}", nearest.join(", "))
    }
}

/// Options of [`retarget_bvh`] / [`retarget_motion`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RetargetOptions {
    /// Subject height in metres; `None` uses the FK estimate (GMR assumes 1.75).
    pub human_height: Option<f64>,
    pub solver: SolverOptions,
    pub fk: FkOptions,
    /// Solve long clips as parallel chunks ([`crate::chunked`]); `None`: one serial pass.
    pub chunk: Option<crate::chunked::ChunkOptions>,
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
}

impl ClipDiagnostics {
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
                let mut v: Vec<f64> = self.frames.iter().map(|f| value(f, k)).collect();
                if v.is_empty() {
                    return (0.0, 0.0);
                }
                let mean = v.iter().sum::<f64>() / v.len() as f64;
                v.sort_by(f64::total_cmp);
                let idx = ((v.len() as f64 - 1.0) * 0.95).round() as usize;
                (mean, v[idx.min(v.len() - 1)])
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
    let height = options
        .human_height
        .ok_or_else(|| Error::InvalidOption("the subject height is required".to_owned()))?;
    config.validate(model, &human.body_names)?;
    let map = TargetMap::new(config, &human.body_names, height)?;
    let stages = task_specs(config, model, &map);
    let mut solver = Solver::new(model, &stages, options.solver.clone())?;
    let tracked: Vec<(usize, usize)> = solver.tracked().to_vec();

    let (nb, nf, nq) = (human.num_bodies(), human.num_frames, model.nq);
    if human.positions.len() != nf * nb || human.orientations.len() != nf * nb {
        return Err(Error::InvalidOption(format!(
            "human motion holds {} positions and {} orientations, expected {nf} frames × {nb} bodies",
            human.positions.len(),
            human.orientations.len()
        )));
    }
    let dt = if human.fps > 0.0 { 1.0 / human.fps } else { 0.0 };
    let mut poses =
        vec![Pose { quat: [1.0, 0.0, 0.0, 0.0], pos: Vector3::zeros() }; map.bodies.len()];
    let mut qpos = Vec::with_capacity(nf * nq);
    let mut target_pos = Vec::with_capacity(nf * tracked.len());
    let mut target_quat = Vec::with_capacity(nf * tracked.len());
    let mut frames = Vec::with_capacity(nf);
    let start = Instant::now();
    for f in 0..nf {
        let range = f * nb..(f + 1) * nb;
        map.compute(&human.positions[range.clone()], &human.orientations[range], &mut poses);
        if let Some(bad) = poses.iter().position(|p| !finite_pose(p)) {
            let message = format!("target of human body `{}` is not finite", map.bodies[bad].name);
            return Err(Error::NonFinite { frame: f, message });
        }
        let diag = solver.solve_frame(&poses, dt);
        if solver.qpos().iter().any(|v| !v.is_finite()) {
            return Err(Error::NonFinite { frame: f, message: "the solver diverged".to_owned() });
        }
        qpos.extend_from_slice(solver.qpos());
        for &(_, t) in &tracked {
            let p = &poses[t];
            target_pos.push(p.pos);
            let q = nalgebra::Quaternion::new(p.quat[0], p.quat[1], p.quat[2], p.quat[3]);
            target_quat.push(UnitQuaternion::new_unchecked(q));
        }
        frames.push(diag);
    }
    let solve_seconds = start.elapsed().as_secs_f64();
    let body_name = |b: usize| model.bodies[b].name.clone();
    let tracked_names: Vec<String> = tracked.iter().map(|&(b, _)| body_name(b)).collect();
    let motion = RobotMotion {
        fps: human.fps,
        nq,
        qpos,
        joint_names: model
            .joints
            .iter()
            .filter(|j| j.kind != mjcf::JointType::Free)
            .map(|j| j.name.clone())
            .collect(),
        body_names: model.bodies.iter().skip(1).map(|b| b.name.clone()).collect(),
        targets: Some(TrackedTargets {
            body_names: tracked_names.clone(),
            pos: target_pos,
            quat: target_quat,
        }),
        contacts: None,
    };
    let weighted = |body: usize, pick: fn(&TaskSpec) -> f64| {
        stages.iter().flatten().any(|t| t.body == body && pick(t) != 0.0)
    };
    let diag = ClipDiagnostics {
        body_names: tracked_names,
        position_tracked: tracked.iter().map(|&(b, _)| weighted(b, |t| t.pos_weight)).collect(),
        rotation_tracked: tracked.iter().map(|&(b, _)| weighted(b, |t| t.rot_weight)).collect(),
        frames,
        human_height: height,
        human_height_source: "given".to_owned(),
        human_inferred: String::new(),
        solve_seconds,
    };
    Ok((motion, diag))
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

fn finite_pose(p: &Pose) -> bool {
    p.pos.iter().all(|v| v.is_finite()) && p.quat.iter().all(|v| v.is_finite())
}
