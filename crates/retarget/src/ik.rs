//! Weighted damped-least-squares IK with hard joint limits: GMR's solver (mink 1.3.0
//! `solve_ik` with `FrameTask`s and a `ConfigurationLimit`, QP solved exactly) reproduced
//! operation by operation.
//!
//! Per task (a robot body tracking a target pose `T_t`, costs `C = (w_pos ×3, w_rot ×3)`,
//! gain 1): error `e = log(T_b⁻¹ T_t)` (body twist, translation first), Jacobian
//! `J = −Jlog(T_t⁻¹ T_b) · blockdiag(Rᵀ, Rᵀ) [jacp; jacr]`. Weighted `J̃ = diag(C) J`,
//! `ẽ = −diag(C) e`, Levenberg–Marquardt term `μ = lm_damping ‖ẽ‖²`. Each step solves
//!
//! ```text
//! min ½ Δqᵀ (Σ J̃ᵀJ̃ + (λ + Σ μ) I) Δq − (Σ ẽᵀ J̃) Δq
//! s.t. 0.95 (q_min − q) ≤ Δq ≤ 0.95 (q_max − q)   for every limited hinge/slide joint
//! ```
//!
//! and integrates `q ← q ⊕ Δq` (`mj_integratePos`). Per frame and stage GMR iterates: one
//! step, then more while the unweighted error norm drops by more than the threshold, at
//! most `max_extra_steps` more. The first frame starts from `qpos0`, every later one from
//! the previous solution.
//!
//! This module is one frame's IK (the [`Solver`]: `bounds.rs` the step's bounds, `qp_step.rs`
//! its QP, `trajectory_step.rs` what the trajectory solve asks of it); the stages that run it
//! over a clip are [`crate::solve`].

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: buffers are sized from the model (`nq`, `nv`, bodies) in `Solver::new`, which checks
// the task bodies; `solve_frame`/`errors` check the target slots; the model's own ids (parents,
// dof and qpos addresses) are in range by `mjcf::Model`'s construction.
#![allow(clippy::indexing_slicing)]

use std::ops::AddAssign;

use mjcf::{Data, JointType, Model};

use crate::constraints::{Constraint, GripBox, StepContext};
use crate::lie::{self, Pose};
use crate::qp::{BoxQp, DenseQp, QpStatus};
use crate::Error;

mod bounds;
mod qp_step;
mod task_terms;
mod trajectory_step;

/// Fraction of a joint speed limit the solver allows itself ([`Solver::set_speed_limits`]).
const SPEED_MARGIN: f64 = 0.999;

/// Tunables of the solver. [`Default`] reproduces GMR.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct SolverOptions {
    /// Global Levenberg–Marquardt damping λ on every dof, free root included (GMR: 0.5).
    pub damping: f64,
    /// Per-task LM damping scale (mink `lm_damping`; GMR: 1).
    pub lm_damping: f64,
    /// Keep stepping while the stage error drops by more than this (GMR: 0.001).
    pub stop_threshold: f64,
    /// Steps after the first one per stage, at most (GMR `max_iter`: 10).
    pub max_extra_steps: usize,
    /// Fraction of the distance to a joint limit one step may cover (mink: 0.95).
    pub limit_gain: f64,
    /// Per-frame velocity limit on hinge and slide joints (rad/s or m/s), off by default
    /// (GMR constructs a velocity limit but mink 1.3.0 ignores it, see `solve_ik`'s
    /// positional arguments). When set, `|q − q_previous frame| ≤ max_joint_speed · dt`.
    pub max_joint_speed: Option<f64>,
    /// Whether the task terms follow mink operation by operation (GMR) or take shortcuts
    /// that are equal to rounding.
    pub arithmetic: Arithmetic,
}

/// How closely the solver follows mink's arithmetic ([`SolverOptions::arithmetic`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Arithmetic {
    /// Operation by operation as mink: GMR's numbers, bit for bit (`--gmr`).
    #[default]
    Mink,
    /// The same quantities in fewer operations, equal to rounding: a task's `Jlog` from the
    /// error computed just before (`e = log(T_b⁻¹ T_t) = −log(T_t⁻¹ T_b)`, one SE(3)
    /// logarithm per task and step fewer), body orientations from the kinematics'
    /// quaternions instead of read back from the rotation matrices.
    Lean,
}

impl Default for SolverOptions {
    fn default() -> SolverOptions {
        SolverOptions {
            damping: 0.5,
            lm_damping: 1.0,
            stop_threshold: 0.001,
            max_extra_steps: 10,
            limit_gain: 0.95,
            max_joint_speed: None,
            arithmetic: Arithmetic::Mink,
        }
    }
}

/// One frame task: robot `body` tracks target slot `target`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TaskSpec {
    pub body: usize,
    pub target: usize,
    pub pos_weight: f64,
    pub rot_weight: f64,
}

/// A planted sole's point (`point`, in body `body`'s frame) on its foothold: `at` (world) in
/// this frame, `from` in the frame before where the foot was planted there too
/// ([`Solver::set_grips`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GripPoint {
    pub body: usize,
    pub point: nalgebra::Vector3<f64>,
    pub at: nalgebra::Vector3<f64>,
    pub from: Option<nalgebra::Vector3<f64>>,
}

/// Where a gripped point may be this frame, `(lo, hi)` in x and y: where it was in the frame
/// before (`was`, world) moved as its foothold moved (`g.at − g.from`), give or take
/// `half_width`. (Not widened to take in the foothold itself: widened so that a foot that
/// landed off it could close the gap at once, 4 more clip-robot pairs of the corpus were
/// flagged, a foot pulled to a foothold it cannot reach sliding there.)
#[must_use]
pub fn grip_bounds(
    was: &nalgebra::Vector3<f64>,
    g: &GripPoint,
    half_width: f64,
) -> (nalgebra::Vector2<f64>, nalgebra::Vector2<f64>) {
    let centre = (was + (g.at - g.from.unwrap_or(g.at))).xy();
    let w = nalgebra::Vector2::repeat(half_width);
    (centre - w, centre + w)
}

/// A point fixed in a body that should be at a world position (e.g. a foot's contact point
/// on its anchor): cost `½ Σ_axis w_axis² (target − p(q))_axis²` (world axes), in every
/// stage of the frame's solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointTask {
    pub body: usize,
    /// In the body's frame.
    pub point: nalgebra::Vector3<f64>,
    /// World position (m).
    pub target: nalgebra::Vector3<f64>,
    /// Per world axis x, y, z.
    pub weight: nalgebra::Vector3<f64>,
}

/// What one frame's solve did.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FrameDiagnostics {
    /// QP steps per stage (1 to `1 + max_extra_steps`; 0 for an empty stage).
    pub steps: Vec<usize>,
    /// Unweighted error norm of the last stage at the final configuration.
    pub error: f64,
    /// Per tracked body ([`Solver::tracked`]): distance to its target position (m).
    pub pos_error: Vec<f64>,
    /// Per tracked body: angle to its target orientation (rad).
    pub rot_error: Vec<f64>,
    /// Joints (indices into `Model::joints`) within `AT_LIMIT` of a range end.
    pub at_limit: Vec<usize>,
    /// QP solves that did not reach the exact optimum (should stay 0).
    pub qp_failures: usize,
    /// Steps whose constraints could not all hold together, so that some were relaxed
    /// (self-collision first, then joint speed); see [`Solver::add_constraint`].
    pub relaxed_steps: usize,
    /// The frame comes from the backward first pass
    /// ([`crate::PlausibleOptions::both_ways`]).
    pub backward: bool,
}

/// Distance to a range end (rad or m) below which a joint counts as at its limit.
pub const AT_LIMIT: f64 = 1e-3;

#[derive(Debug, Clone)]
struct TaskWork {
    spec: TaskSpec,
    /// Cost vector C.
    cost: [f64; 6],
    /// Per-frame factors on `cost`, position rows then rotation rows
    /// ([`Solver::set_weight_scale`]; 1 for GMR).
    scale: [f64; 6],
    /// Dofs moving the body (its Jacobian's non-zero columns), ascending.
    dofs: Vec<usize>,
    /// Error at the current configuration, and the body's pose it was computed from.
    err: nalgebra::Vector6<f64>,
    frame: Pose,
    /// Runs of consecutive ids in `dofs` (`task_terms::runs`).
    runs: Vec<(usize, usize)>,
    /// Weighted Jacobian, six rows of one entry per dof of `dofs`.
    wjac: task_terms::Rows,
}

/// A range-limited hinge or slide joint: its dof, qpos address and range.
#[derive(Debug, Clone, Copy)]
struct Limit {
    joint: usize,
    dof: usize,
    qpos: usize,
    range: [f64; 2],
}

/// The IK solver for one model and one set of stages. Work buffers are allocated once.
#[derive(Debug)]
pub struct Solver<'m> {
    model: &'m Model,
    options: SolverOptions,
    stages: Vec<Vec<TaskWork>>,
    tracked: Vec<(usize, usize)>,
    limits: Vec<Limit>,
    data: Data,
    qpos: Vec<f64>,
    previous: Vec<f64>,
    dq: Vec<f64>,
    jacp: Vec<f64>,
    jacr: Vec<f64>,
    qp: BoxQp,
    qp_failures: usize,
    /// Hard constraints beyond joint ranges, in priority order (GMR: none).
    constraints: Vec<Box<dyn Constraint + 'm>>,
    /// Per dof: the speed limit of its joint (rad/s or m/s), if any.
    dof_speed: Vec<Option<f64>>,
    dense: DenseQp,
    /// Dofs moving each body, ascending.
    body_dofs: Vec<Vec<usize>>,
    /// Scratch: a body's Jacobian columns `J₆` and `M J₆` ([`Solver::add_point_tasks`]).
    point_cols: Vec<(nalgebra::Vector6<f64>, nalgebra::Vector6<f64>)>,
    /// Whether the constraints are held ([`Solver::hold_constraints`]).
    constraints_on: bool,
    /// This frame's point tasks ([`Solver::set_point_tasks`]).
    point_tasks: Vec<PointTask>,
    /// The constraints' rows are linearised once per frame (and pass), at the first
    /// constrained step; later steps of the frame re-centre them on the configuration
    /// reached (`moved`: the sum of the steps since, tangent space). Whether they are made,
    /// their right-hand sides as made, and where each constraint's rows end.
    rows_made: bool,
    row_base: Vec<f64>,
    row_ends: Vec<usize>,
    moved: Vec<f64>,
    relaxed_steps: usize,
    /// The trajectory solve's extra objective terms ([`Solver::set_extra`]; empty: none).
    extra_h: Vec<f64>,
    extra_c: Vec<f64>,
    /// The configuration of the frame after this one, when the trajectory solve knows it: the
    /// speed limits hold towards it too ([`Solver::set_next`]).
    next: Option<Vec<f64>>,
    /// Geoms held above the floor in this frame ([`Solver::set_raised_geoms`]).
    raised: Vec<(usize, f64)>,
    /// Planted sole points of this frame ([`Solver::set_grips`]) and the boxes the steps
    /// hold them in (from the previous frame's configuration, `grips_dt` apart).
    grips: Vec<GripPoint>,
    slip_speed: f64,
    grip_boxes: Vec<GripBox>,
    grips_dt: f64,
    /// Whether `grip_boxes` are made for the current `previous` and grips.
    grip_boxes_made: bool,
    /// Kinematics of `previous` (the grips' boxes).
    previous_data: Data,
    /// Whether `data`'s geoms and sites are at its bodies' poses ([`Solver::take_step`]).
    geoms_placed: bool,
}

impl<'m> Solver<'m> {
    /// `stages`: the tasks of each stage in order (GMR: table 1, then table 2). Starts at
    /// `model.qpos0`.
    pub fn new(
        model: &'m Model,
        stages: &[Vec<TaskSpec>],
        options: SolverOptions,
    ) -> Result<Solver<'m>, Error> {
        check_options(&options)?;
        let nv = model.nv;
        let mut tracked: Vec<(usize, usize)> = Vec::new();
        let mut works = Vec::with_capacity(stages.len());
        for stage in stages {
            let mut tasks = Vec::with_capacity(stage.len());
            for spec in stage {
                if spec.body == 0 || spec.body >= model.nbody() {
                    return Err(Error::NotABody { what: "task", body: spec.body });
                }
                if !tracked.iter().any(|(b, _)| *b == spec.body) {
                    tracked.push((spec.body, spec.target));
                }
                let mut dofs: Vec<usize> = model.body_dofs(spec.body).collect();
                dofs.sort_unstable();
                let (p, r) = (spec.pos_weight, spec.rot_weight);
                tasks.push(TaskWork {
                    spec: *spec,
                    cost: [p, p, p, r, r, r],
                    scale: [1.0; 6],
                    wjac: std::array::from_fn(|_| vec![0.0; dofs.len()]),
                    runs: task_terms::runs(&dofs),
                    dofs,
                    err: nalgebra::Vector6::zeros(),
                    frame: Pose { quat: [1.0, 0.0, 0.0, 0.0], pos: nalgebra::Vector3::zeros() },
                });
            }
            works.push(tasks);
        }
        let limits = model
            .joints
            .iter()
            .enumerate()
            .filter(|(_, j)| matches!(j.kind, JointType::Hinge | JointType::Slide))
            .filter_map(|(i, j)| {
                j.range.map(|range| Limit { joint: i, dof: j.dof_adr, qpos: j.qpos_adr, range })
            })
            .collect();
        let parents = model.dof_parents().to_vec();
        let mut qp = BoxQp::new(nv);
        qp.set_tree(parents.clone());
        let mut dense = DenseQp::new(nv);
        dense.set_tree(&parents);
        let mut solver = Solver {
            model,
            options,
            stages: works,
            tracked,
            limits,
            data: Data::new(model),
            qpos: model.qpos0.clone(),
            previous: model.qpos0.clone(),
            dq: vec![0.0; nv],
            jacp: vec![0.0; 3 * nv],
            jacr: vec![0.0; 3 * nv],
            qp,
            qp_failures: 0,
            constraints: Vec::new(),
            dof_speed: vec![None; nv],
            dense,
            point_tasks: Vec::new(),
            body_dofs: (0..model.nbody())
                .map(|b| {
                    let mut d: Vec<usize> = model.body_dofs(b).collect();
                    d.sort_unstable();
                    d
                })
                .collect(),
            point_cols: Vec::with_capacity(nv),
            constraints_on: true,
            rows_made: false,
            row_base: Vec::new(),
            row_ends: Vec::new(),
            moved: vec![0.0; nv],
            relaxed_steps: 0,
            extra_h: Vec::new(),
            extra_c: Vec::new(),
            next: None,
            raised: Vec::new(),
            grips: Vec::new(),
            slip_speed: 0.0,
            grip_boxes: Vec::new(),
            grips_dt: 0.0,
            grip_boxes_made: false,
            previous_data: Data::new(model),
            geoms_placed: true,
        };
        solver.model.kinematics(&solver.qpos, &mut solver.data);
        Ok(solver)
    }

    /// Adds a hard constraint, held in every step from now on. Constraints added earlier
    /// take priority: when a step cannot satisfy all of them (with the joint ranges and
    /// speed limits), the later ones are dropped for that step first.
    pub fn add_constraint(&mut self, constraint: Box<dyn Constraint + 'm>) {
        self.constraints.push(constraint);
    }

    /// Whether the steps from now on hold the constraints added with
    /// [`Solver::add_constraint`] (on by default; joint ranges and speed limits always hold).
    pub fn hold_constraints(&mut self, on: bool) {
        self.constraints_on = on;
    }

    /// Per-joint speed limits (indexed like `Model::joints`; rad/s or m/s), held as hard
    /// bounds `|q − q_previous frame| ≤ limit · dt` on hinge and slide joints.
    pub fn set_speed_limits(&mut self, per_joint: &[Option<f64>]) -> Result<(), Error> {
        let joints = &self.model.joints;
        same_len("speed limits (one per joint)", per_joint.len(), joints.len())?;
        let bad = joints.iter().zip(per_joint).find_map(|(joint, limit)| {
            limit.filter(|v| !(v.is_finite() && *v > 0.0)).map(|v| (joint, v))
        });
        if let Some((joint, value)) = bad {
            return Err(Error::InvalidOption {
                name: format!("speed limit of joint {}", joint.name),
                value,
                expected: "a positive speed or none",
            });
        }
        for (joint, limit) in self.model.joints.iter().zip(per_joint) {
            if matches!(joint.kind, JointType::Hinge | JointType::Slide) {
                self.dof_speed[joint.dof_adr] = *limit;
            }
        }
        Ok(())
    }

    /// The planted sole points of the next frames (replacing the previous ones), held by a
    /// [`crate::constraints::Grip`] constraint where the solver has one: each moves from the
    /// previous frame's configuration ([`Solver::set_previous`]; in [`Solver::solve_frame`]
    /// the configuration it starts from) as its foothold does (`at − from`), give or take
    /// `slip_speed · dt` (m/s) in x and y. A point without a foothold in the previous frame
    /// (`from`: none, the first frame of a stance) is free in its frame.
    pub fn set_grips(&mut self, grips: &[GripPoint], slip_speed: f64) -> Result<(), Error> {
        if let Some(g) = grips.iter().find(|g| g.body >= self.model.bodies.len()) {
            return Err(Error::NotABody { what: "grip", body: g.body });
        }
        if self.grips.as_slice() != grips || self.slip_speed != slip_speed {
            self.grips.clear();
            self.grips.extend_from_slice(grips);
            self.slip_speed = slip_speed;
            self.rows_made = false;
            self.grip_boxes_made = false;
        }
        Ok(())
    }

    /// This frame's grips ([`Solver::set_grips`]) and their slip speed (m/s).
    #[must_use]
    pub fn grips(&self) -> (&[GripPoint], f64) {
        (&self.grips, self.slip_speed)
    }

    /// The grips' boxes for a step `dt` after [`Solver::previous`]'s configuration.
    pub(super) fn make_grip_boxes(&mut self, dt: f64) {
        // The same frame's later steps: the boxes stand (made from `previous` and the grips).
        if self.grip_boxes_made && self.grips_dt == dt {
            return;
        }
        self.grip_boxes_made = true;
        self.grip_boxes.clear();
        self.grips_dt = dt;
        if dt <= 0.0 || !self.grips.iter().any(|g| g.from.is_some()) {
            return;
        }
        // (Its bodies' poses alone: no geom is read.)
        self.model.body_kinematics(&self.previous, &mut self.previous_data);
        let data = &self.previous_data;
        let slip = self.slip_speed;
        for g in self.grips.iter().filter(|g| g.from.is_some()) {
            let was = data.xpos[g.body] + data.xquat[g.body] * g.point;
            let half_width = slip * dt;
            let (lo, hi) = grip_bounds(&was, g, half_width);
            self.grip_boxes.push(GripBox { body: g.body, point: g.point, lo, hi });
        }
    }

    /// The point tasks of the next frames (replacing the previous ones; bodies must exist).
    pub fn set_point_tasks(&mut self, tasks: &[PointTask]) -> Result<(), Error> {
        if let Some(t) = tasks.iter().find(|t| t.body == 0 || t.body >= self.model.nbody()) {
            return Err(Error::NotABody { what: "point task", body: t.body });
        }
        self.point_tasks.clear();
        self.point_tasks.extend_from_slice(tasks);
        Ok(())
    }

    /// Multiplies the position and rotation weights of every task on `body` by `position`
    /// and `rotation` (≥ 0) until changed again.
    pub fn set_weight_scale(&mut self, body: usize, position: f64, rotation: f64) {
        for task in self.stages.iter_mut().flatten().filter(|t| t.spec.body == body) {
            task.scale = [position, position, position, rotation, rotation, rotation];
        }
    }

    /// Current configuration.
    #[must_use]
    pub fn qpos(&self) -> &[f64] {
        &self.qpos
    }

    /// Restart from `qpos` (length `nq`).
    pub fn set_qpos(&mut self, qpos: &[f64]) -> Result<(), Error> {
        self.check_qpos(qpos)?;
        self.qpos.copy_from_slice(qpos);
        self.rows_made = false;
        self.model.kinematics(&self.qpos, &mut self.data);
        self.geoms_placed = true;
        Ok(())
    }

    /// The current kinematics (of [`Solver::qpos`]).
    #[must_use]
    pub fn data(&self) -> &Data {
        &self.data
    }

    /// Bodies with a task, first occurrence over the stages, as `(body id, target slot)`.
    #[must_use]
    pub fn tracked(&self) -> &[(usize, usize)] {
        &self.tracked
    }

    /// Solves one frame from the current configuration. `targets` are indexed by the task
    /// specs' `target`; `dt` (seconds per frame) is used by `max_joint_speed` only.
    ///
    /// # Errors
    /// [`Error::WrongLength`] when `targets` is shorter than the task specs' largest
    /// `target` slot.
    pub fn solve_frame(&mut self, targets: &[Pose], dt: f64) -> Result<FrameDiagnostics, Error> {
        self.check_targets(targets)?;
        self.previous.copy_from_slice(&self.qpos);
        self.grip_boxes_made = false;
        self.rows_made = false;
        self.qp_failures = 0;
        self.relaxed_steps = 0;
        let mut steps = Vec::with_capacity(self.stages.len());
        let mut error = 0.0;
        // The last stage solved: its tasks' errors are at the current configuration.
        let mut current = None;
        for s in 0..self.stages.len() {
            let (n, e) = self.solve_stage(s, targets, dt, current);
            if n > 0 {
                current = Some(s);
            }
            steps.push(n);
            error = e;
        }
        self.place_geoms();
        let (pos_error, rot_error) = self.tracking_errors(targets);
        Ok(FrameDiagnostics {
            steps,
            error,
            pos_error,
            rot_error,
            at_limit: self.at_limit(),
            qp_failures: self.qp_failures,
            relaxed_steps: self.relaxed_steps,
            backward: false,
        })
    }

    /// Stage `s`'s steps; `current`: a stage whose errors are at the current configuration.
    fn solve_stage(
        &mut self,
        s: usize,
        targets: &[Pose],
        dt: f64,
        current: Option<usize>,
    ) -> (usize, f64) {
        if self.stages[s].is_empty() {
            return (0, 0.0);
        }
        let mut current = self.stage_error_from(s, targets, current);
        self.step(s, targets, dt);
        let mut next = self.stage_error(s, targets);
        let mut steps = 1;
        while current - next > self.options.stop_threshold && steps <= self.options.max_extra_steps
        {
            current = next;
            self.step(s, targets, dt);
            next = self.stage_error(s, targets);
            steps += 1;
        }
        (steps, next)
    }

    /// Frame pose as mink reads it (quaternion from `xmat`), or the kinematics' own
    /// quaternion ([`Arithmetic::Lean`]); position `xpos`.
    fn body_pose(&self, body: usize) -> Pose {
        let quat = match self.options.arithmetic {
            Arithmetic::Mink => lie::mat_to_quat(&self.data.xmat[body]),
            Arithmetic::Lean => {
                let q = self.data.xquat[body];
                [q.w, q.i, q.j, q.k]
            }
        };
        Pose { quat, pos: self.data.xpos[body] }
    }

    /// Updates every task's error at the current configuration; returns the norm of all.
    fn stage_error(&mut self, s: usize, targets: &[Pose]) -> f64 {
        self.stage_error_from(s, targets, None)
    }

    /// [`Solver::stage_error`], where stage `from`'s errors are at the current configuration
    /// (and targets): a task on the same body and target takes its error and pose from there
    /// (GMR's two tables track the same bodies, so a frame's second stage starts from the
    /// first one's last errors).
    fn stage_error_from(&mut self, s: usize, targets: &[Pose], from: Option<usize>) -> f64 {
        let mut sum = 0.0;
        for k in 0..self.stages[s].len() {
            let spec = self.stages[s][k].spec;
            let known = from.and_then(|f| {
                let same = |t: &&TaskWork| (t.spec.body, t.spec.target) == (spec.body, spec.target);
                self.stages[f].iter().find(same).map(|t| (t.err, t.frame))
            });
            let (e, frame) = known.unwrap_or_else(|| {
                let frame = self.body_pose(spec.body);
                (lie::rminus(&targets[spec.target], &frame), frame)
            });
            sum += e.norm_squared();
            (self.stages[s][k].err, self.stages[s][k].frame) = (e, frame);
        }
        sum.sqrt()
    }

    /// One QP step at the current configuration (errors from `stage_error`).
    fn step(&mut self, s: usize, targets: &[Pose], dt: f64) {
        self.clear_objective();
        let mut mu_total = 0.0;
        for k in 0..self.stages[s].len() {
            mu_total += self.task_objective(s, k, targets);
        }
        self.add_point_tasks();
        self.add_diagonal(self.options.damping + mu_total);
        self.set_bounds(dt);
        self.make_grip_boxes(dt);
        let status = self.solve_step();
        if status != QpStatus::Optimal {
            self.qp_failures += 1;
            if status != QpStatus::IterationLimit {
                return; // no finite step: keep the configuration
            }
        }
        self.take_step();
    }

    /// H and c to zero: H's upper triangle, all that the terms add to and the QP solvers and
    /// the trajectory solve read (the lower one holds whatever the last solve left there).
    fn clear_objective(&mut self) {
        let nv = self.model.nv;
        for d in 0..nv {
            self.qp.h[d * nv + d..(d + 1) * nv].fill(0.0);
        }
        self.qp.c.fill(0.0);
    }

    /// Adds `diagonal` to H's diagonal.
    fn add_diagonal(&mut self, diagonal: f64) {
        let nv = self.model.nv;
        for d in 0..nv {
            self.qp.h[d * nv + d] += diagonal;
        }
    }

    /// Moves by `self.dq` (and counts it in `moved`) and updates the kinematics. Without
    /// constraints nothing in a step reads the geoms and sites: they are placed once the
    /// frame is solved ([`Solver::place_geoms`]).
    fn take_step(&mut self) {
        self.model.integrate_pos(&mut self.qpos, &self.dq, 1.0);
        self.moved.iter_mut().zip(&self.dq).for_each(|(m, d)| *m += d);
        if self.constraints.is_empty() {
            self.geoms_placed = !self.model.body_kinematics(&self.qpos, &mut self.data);
        } else {
            self.model.kinematics(&self.qpos, &mut self.data);
        }
    }

    /// Places the geoms and sites at the bodies' poses if a step left them behind, so that
    /// [`Solver::data`] is the whole kinematics of [`Solver::qpos`].
    fn place_geoms(&mut self) {
        if !self.geoms_placed {
            self.model.place_geoms_and_sites(&mut self.data);
            self.geoms_placed = true;
        }
    }

    /// Adds task `k`'s `J̃ᵀJ̃` to H and `−ẽᵀJ̃` to c; returns its μ.
    fn task_objective(&mut self, s: usize, k: usize, targets: &[Pose]) -> f64 {
        let nv = self.model.nv;
        let task = &self.stages[s][k];
        let body = task.spec.body;
        // The pose and error `stage_error` found at this configuration (every step follows one).
        let jlog = match self.options.arithmetic {
            Arithmetic::Mink => {
                lie::se3_jlog(&lie::inverse_multiply(&targets[task.spec.target], &task.frame))
            }
            Arithmetic::Lean => lie::se3_jlog_at(&task.err),
        };
        let xmat = self.data.xmat[body];
        let task = &mut self.stages[s][k];
        let w: [f64; 6] = std::array::from_fn(|r| task.cost[r] * task.scale[r]);
        // The body's Jacobian column by column as the rows take it (`jac_chain`'s numbers).
        let jac = (&self.data, &self.data.xpos[body]);
        match self.options.arithmetic {
            Arithmetic::Mink => {
                task_terms::mink_rows(&jlog, &xmat, &w, jac, &task.dofs, &mut task.wjac)
            }
            Arithmetic::Lean => {
                task_terms::lean_rows(&jlog, &xmat, &w, jac, &task.dofs, &mut task.wjac)
            }
        }
        let we: [f64; 6] = std::array::from_fn(|r| w[r] * (-task.err[r]));
        let mu: f64 = we.iter().map(|w| w * w).sum();
        for (a, &da) in task.dofs.iter().enumerate() {
            let col: [f64; 6] = std::array::from_fn(|r| task.wjac[r][a]);
            self.qp.c[da] -= dot6(&we, &col);
        }
        // Upper triangle only (dofs ascending), which is what both QP solvers read.
        task_terms::add_gram(&task.wjac, &w, &task.dofs, &task.runs, nv, &mut self.qp.h);
        self.options.lm_damping * mu
    }

    /// `w² JᵀJ` into H and `−w² Jᵀ e` into c for each point task (`J`: the point's
    /// translational Jacobian, `e = target − p`).
    /// Upper triangle only (dofs ascending). Points on one body share
    /// its Jacobian at the origin, `J_o` and `J_ω`: a point `r` away moves by
    /// `J_o − [r]× J_ω = A J₆` (`A = [I, −[r]×]`, `J₆ = [J_o; J_ω]`), so the body's points
    /// add `J₆ᵀ M J₆` with `M = Σ Aᵀ W A` (6 × 6) and `−J₆ᵀ Σ Aᵀ W e`: one pass over the
    /// body's dof pairs whatever the number of points.
    fn add_point_tasks(&mut self) {
        let nv = self.model.nv;
        let mut k = 0;
        while k < self.point_tasks.len() {
            let b = self.point_tasks[k].body;
            self.model.jac_chain(&self.data, b, &mut self.jacp, &mut self.jacr);
            let (origin, rotation) = (self.data.xpos[b], self.data.xmat[b]);
            let mut m = nalgebra::Matrix6::<f64>::zeros();
            let mut g = nalgebra::Vector6::<f64>::zeros();
            while let Some(task) = self.point_tasks.get(k).filter(|t| t.body == b) {
                let r = rotation * task.point;
                let e = task.target - (origin + r);
                let w = nalgebra::Matrix3::from_diagonal(&task.weight.component_mul(&task.weight));
                let s = r.cross_matrix();
                let ws = w * s;
                // Aᵀ W A = [[W, −W S], [−Sᵀ W, Sᵀ W S]], Aᵀ W e = [W e; −Sᵀ W e] (S = [r]×).
                let mut block = |row: usize, col: usize, v: &nalgebra::Matrix3<f64>| {
                    let mut view = m.fixed_view_mut::<3, 3>(row, col);
                    view += v;
                };
                block(0, 0, &w);
                block(0, 3, &-ws);
                block(3, 0, &-ws.transpose());
                block(3, 3, &(s.transpose() * ws));
                let we = w * e;
                g.fixed_rows_mut::<3>(0).add_assign(&we);
                g.fixed_rows_mut::<3>(3).add_assign(&r.cross(&we));
                k += 1;
            }
            let dofs = &self.body_dofs[b];
            self.point_cols.clear();
            for &d in dofs {
                let j = nalgebra::Vector6::new(
                    self.jacp[d],
                    self.jacp[nv + d],
                    self.jacp[2 * nv + d],
                    self.jacr[d],
                    self.jacr[nv + d],
                    self.jacr[2 * nv + d],
                );
                self.point_cols.push((j, m * j));
            }
            for (a, (&da, (ja, _))) in dofs.iter().zip(&self.point_cols).enumerate() {
                self.qp.c[da] -= ja.dot(&g);
                let row = &mut self.qp.h[da * nv..(da + 1) * nv];
                for (&db, (_, mb)) in dofs[a..].iter().zip(&self.point_cols[a..]) {
                    row[db] += ja.dot(mb);
                }
            }
        }
    }

    /// Per dof, the speed limit its joint holds (rad/s or m/s), if any
    /// ([`Solver::set_speed_limits`]).
    #[must_use]
    pub fn dof_speed_limits(&self) -> &[Option<f64>] {
        &self.dof_speed
    }

    /// The model this solver was built for.
    #[must_use]
    pub fn robot(&self) -> &'m Model {
        self.model
    }

    /// Tracking errors at the current configuration (as in [`FrameDiagnostics`]).
    ///
    /// # Errors
    /// As [`Solver::solve_frame`].
    pub fn errors(&self, targets: &[Pose]) -> Result<(Vec<f64>, Vec<f64>), Error> {
        self.check_targets(targets)?;
        Ok(self.tracking_errors(targets))
    }

    /// `qpos` is a configuration of this model: `nq` finite numbers.
    fn check_qpos(&self, qpos: &[f64]) -> Result<(), Error> {
        same_len("qpos", qpos.len(), self.model.nq)?;
        if qpos.iter().any(|v| !v.is_finite()) {
            return Err(Error::NotFinite { what: "qpos" });
        }
        Ok(())
    }

    /// `targets` has a pose for every task's and point task's target slot.
    fn check_targets(&self, targets: &[Pose]) -> Result<(), Error> {
        let needed = self.stages.iter().flatten().map(|t| t.spec.target + 1).max().unwrap_or(0);
        if targets.len() < needed {
            let got = targets.len();
            return Err(Error::WrongLength { what: "target poses", got, expected: needed });
        }
        Ok(())
    }

    fn tracking_errors(&self, targets: &[Pose]) -> (Vec<f64>, Vec<f64>) {
        self.tracked
            .iter()
            .map(|&(body, t)| {
                let frame = self.body_pose(body);
                let rel = lie::inverse_multiply(&frame, &targets[t]);
                ((targets[t].pos - frame.pos).norm(), lie::so3_log(&rel.quat).norm())
            })
            .unzip()
    }

    fn at_limit(&self) -> Vec<usize> {
        self.limits
            .iter()
            .filter(|l| {
                let q = self.qpos[l.qpos];
                q - l.range[0] <= AT_LIMIT || l.range[1] - q <= AT_LIMIT
            })
            .map(|l| l.joint)
            .collect()
    }
}

/// [`Error::WrongLength`] unless `got == expected`.
fn same_len(what: &'static str, got: usize, expected: usize) -> Result<(), Error> {
    if got == expected {
        Ok(())
    } else {
        Err(Error::WrongLength { what, got, expected })
    }
}

/// The first of `o`'s values out of its range, named as in [`SolverOptions`].
fn check_options(o: &SolverOptions) -> Result<(), Error> {
    let speed = o.max_joint_speed;
    let checks = [
        ("damping", o.damping, o.damping.is_finite() && o.damping > 0.0, "a positive number"),
        ("lm_damping", o.lm_damping, o.lm_damping.is_finite() && o.lm_damping >= 0.0, "≥ 0"),
        ("stop_threshold", o.stop_threshold, o.stop_threshold.is_finite(), "a finite number"),
        ("limit_gain", o.limit_gain, o.limit_gain > 0.0 && o.limit_gain <= 1.0, "in (0, 1]"),
        (
            "max_joint_speed",
            speed.unwrap_or(0.0),
            speed.is_none_or(|v| v.is_finite() && v > 0.0),
            "a positive speed or none",
        ),
    ];
    match checks.into_iter().find(|(_, _, ok, _)| !ok) {
        Some((name, value, _, expected)) => {
            Err(Error::InvalidOption { name: format!("solver option {name}"), value, expected })
        }
        None => Ok(()),
    }
}

#[inline]
fn dot6(a: &[f64; 6], b: &[f64; 6]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5]
}
