//! The trajectory solve: every frame of a window at once, so that no frame moves without its
//! neighbours seeing it.
//!
//! Over frames `t` of a window, with the configuration `q_t` (tangent steps `δ_t`):
//!
//! ```text
//! minimise  Σ_t  track_t(q_t)                       GMR's tasks (and the planted sole points)
//!         + Σ_t  ½ Σ_i W_i (a_{t,i})²               a_t = (q_{t+1} ⊖ q_t) − (q_t ⊖ q_{t−1}), over dt²
//! subject to     joint ranges, joint speeds |q_t ⊖ q_{t−1}| ≤ v dt,
//!                every collision geom above the floor (a swing sole above its clearance),
//!                the robot's geoms apart, a planted sole's points moving from frame to frame
//!                as their footholds do ± the slip speed × dt (`grip_terms`)
//! ```
//!
//! `W` weighs the acceleration of every velocity coordinate, the free root's translation and
//! rotation included ([`TrajectoryOptions`]); the root's translation is measured where its
//! target is, at the origin of the body the root task is on, when that is not the free root's
//! body (`Trajectory::root_point_terms`). Gauss–Newton: each iteration linearises the
//! tasks at the current trajectory and solves the window's quadratic model in one piece, a
//! block-pentadiagonal system (`banded.rs`: a second difference couples three frames)
//! in which the constraints that are active (within [`TrajectoryOptions::active_slack`] of
//! their bound, or past it) are held by a stiff penalty
//! ([`TrajectoryOptions::active_penalty`]), and so are those the solved step would cross
//! (joint range ends and the other constraints' rows: the system is solved again with them
//! held), solved and taken twice, linearised afresh
//! ([`TrajectoryOptions::banded_steps`]; the second left out after a short first,
//! [`TrajectoryOptions::step_tolerance`]); then one sweep over the frames solves each
//! frame's subproblem exactly, its neighbours held, every constraint a hard row of the frame's
//! QP ([`crate::ik::Solver::trajectory_step`]). The sweep makes the result feasible and finds the
//! constraints the next iteration holds; the banded step moves the whole window, which a
//! sweep alone (block Gauss–Seidel in time) does only slowly where the smoothness outweighs
//! the tracking: a step in the initial trajectory that it spreads over five frames is still
//! at 40 % of its height after ten sweeps of a one-coordinate model.
//!
//! Long clips are solved in windows ([`TrajectoryOptions::window_s`]) that overlap by
//! [`TrajectoryOptions::overlap_s`]: each window starts from the two frames before it as the
//! previous window left them (held fixed), and keeps its frames up to its overlap, which the
//! next window solves again with the frames after it in view.

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: frame `k` of a window indexes `qpos` (`frames × nq`) and the banded system
// (`frames` blocks of `nv`), both sized from the window here; dofs and qpos addresses come
// from the model.
#![allow(clippy::indexing_slicing)]

use mjcf::{Data, JointType, Model};
use nalgebra::{DVectorView, Vector3};

use super::banded::Banded;
use super::dynamics_term::{Centroidal, DynamicsOptions, FrameState};
use crate::ik::{grip_bounds, FrameDiagnostics, Solver};
use crate::lie::Pose;
use crate::Error;

/// Tunables of the trajectory solve.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct TrajectoryOptions {
    /// Weight of the root's linear acceleration, per (m/s²)²: an acceleration of
    /// `sqrt(1 / w)` m/s² costs as much as one unit of the tracking objective. Measured at the
    /// origin of the body the root task is on (the free root's, or the T1's `Waist`).
    pub root_translation: f64,
    /// Weight of the free root's angular acceleration, per (rad/s²)².
    pub root_rotation: f64,
    /// Weight of every other coordinate's acceleration, per (rad/s²)² (or (m/s²)² for
    /// slide joints), at least: see [`TrajectoryOptions::joint_cutoff_hz`].
    pub joints: f64,
    /// A joint's acceleration weight is its tracking stiffness `k` (the tracking objective's
    /// curvature in that coordinate, averaged over the window) over `ω⁴`, `ω = 2π f` with
    /// this `f` (Hz): the smoothness outweighs the tracking above `f` in every coordinate, a
    /// wrist held by one light rotation task as much as a knee. (One weight for every joint
    /// held the G1's wrists 9–10° off their targets on the LAFAN1 jumps, `--gmr` 1°.)
    pub joint_cutoff_hz: f64,
    /// Iterations, each [`TrajectoryOptions::banded_steps`] banded steps and a sweep.
    pub iterations: usize,
    /// Gauss–Newton steps of the whole window per iteration, each linearised where the one
    /// before it ended. One step left the model's linearisation behind where it turned a joint
    /// far (a waist or hip yaw 0.3–0.45 rad in a step, a planted sole's points 5–12 mm out of
    /// their grip on the SOMA walk onto the T1), and the sweep pulls a frame back only so far.
    pub banded_steps: usize,
    /// An iteration's next banded step is left out when the one before moved no coordinate
    /// of the window further than this (rad, m): from so short a step the linearisation
    /// has little to correct. (0: every step taken.)
    pub step_tolerance: f64,
    /// Window length (s).
    pub window_s: f64,
    /// Frames at the end of a window solved again by the next window (s).
    pub overlap_s: f64,
    /// The banded step moves no coordinate further than this (rad, m): longer steps are
    /// scaled down whole.
    pub max_step: f64,
    /// Penalty weight of a constraint held in the banded step.
    pub active_penalty: f64,
    /// A constraint within this of its bound (m, rad; joint speeds in rad per frame) is held
    /// in the banded step.
    pub active_slack: f64,
    /// Which of the config's stages make the tracking objective (their tasks summed).
    pub objective: Objective,
    /// With [`Objective::AllStages`], the factor on the cost of every stage but the last.
    pub earlier_stages: f64,
    /// The dynamics term ([`crate::DynamicsOptions`]).
    pub dynamics: DynamicsOptions,
}

/// Which stages of the IK config the trajectory solve tracks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Objective {
    /// The last stage's tasks: the one GMR's per-frame solve ends each frame with.
    LastStage,
    /// The tasks of every stage, summed.
    AllStages,
}

impl Default for TrajectoryOptions {
    fn default() -> Self {
        TrajectoryOptions {
            root_translation: 1.0,
            root_rotation: 1e-2,
            joints: 2e-5,
            joint_cutoff_hz: 8.0,
            iterations: 2,
            banded_steps: 2,
            step_tolerance: 0.02,
            window_s: 8.0,
            overlap_s: 1.0,
            max_step: 0.5,
            active_penalty: 1e7,
            active_slack: 1e-3,
            objective: Objective::LastStage,
            earlier_stages: 1.0,
            dynamics: DynamicsOptions::default(),
        }
    }
}

/// What the trajectory solve needs to know of each frame beyond the solver's tasks: its
/// targets, and how to set the solver up for it (weight factors, point tasks, raised geoms).
pub(crate) trait Frames {
    fn targets(&self, frame: usize) -> &[Pose];
    fn configure(&self, solver: &mut Solver<'_>, frame: usize) -> Result<(), Error>;
    /// The pose the human root's task follows in `frame` (its target), if there is one, and
    /// the body that task is on: the root's accelerations are measured against this pose's,
    /// at that body's origin (the rotation's only when the task is on the free root's body).
    fn root_reference(&self, frame: usize) -> Option<(Pose, usize)>;
}

/// Per velocity coordinate, its acceleration weight (before `1 / dt⁴`).
fn coordinate_weights(model: &Model, options: &TrajectoryOptions) -> Vec<f64> {
    let mut w = vec![options.joints; model.nv];
    for joint in &model.joints {
        if joint.kind == JointType::Free {
            let d = joint.dof_adr;
            w[d..d + 3].fill(options.root_translation);
            w[d + 3..d + 6].fill(options.root_rotation);
        }
    }
    w
}

/// The joints' tracking stiffness is averaged over every this many frames of a window.
const STIFFNESS_STRIDE: usize = 4;

/// Frames per window and their overlap at `fps`.
fn window_frames(options: &TrajectoryOptions, fps: f64) -> (usize, usize) {
    let fps = if fps > 0.0 { fps } else { 30.0 };
    let frames = |s: f64| (s * fps).round().max(1.0) as usize;
    let window = frames(options.window_s).max(8);
    (window, frames(options.overlap_s).min(window / 2))
}

/// The frames a window solves again after the ones it keeps, at `fps`: how far a range
/// that ends before its clip does must be solved beyond its end.
pub(crate) fn overlap_frames(options: &TrajectoryOptions, fps: f64) -> usize {
    window_frames(options, fps).1
}

/// The stages the objective sums, with the factor on each one's cost.
fn objective_stages(solver_stages: usize, options: &TrajectoryOptions) -> Vec<(usize, f64)> {
    let last = solver_stages.checked_sub(1);
    match options.objective {
        Objective::LastStage => last.map(|s| (s, 1.0)).into_iter().collect(),
        Objective::AllStages => (0..solver_stages)
            .map(|s| (s, if Some(s) == last { 1.0 } else { options.earlier_stages }))
            .collect(),
    }
}

/// The reference accelerations of a sequence of `fixed + n` frames whose first variable frame
/// is `first` (see [`Sequence::reference`]): the free root's, from [`Frames::root_reference`]
/// (its translation's second difference in the world, its rotation's of the body-frame
/// rotation vectors, as [`Model::differentiate_pos`] measures the root's), where the three
/// frames around have one. (The translation's is the reference of the root task's body's
/// origin, [`Trajectory::root_point_terms`], where that body is not the free root's.)
fn reference_accelerations(
    model: &Model,
    frames: &dyn Frames,
    first: usize,
    fixed: usize,
    n: usize,
) -> Vec<f64> {
    let nv = model.nv;
    let len = fixed + n;
    let mut out = vec![0.0; len * nv];
    let Some(root) = model.joints.iter().find(|j| j.kind == JointType::Free) else { return out };
    let d = root.dof_adr;
    let pose = |j: usize| {
        let f = (first + j).checked_sub(fixed)?;
        frames.root_reference(f).map(|(pose, body)| (pose, body == root.body))
    };
    let poses: Vec<Option<(Pose, bool)>> = (0..len).map(pose).collect();
    let velocity = |a: &Pose, b: &Pose| {
        let qa = nalgebra::UnitQuaternion::new_normalize(nalgebra::Quaternion::new(
            a.quat[0], a.quat[1], a.quat[2], a.quat[3],
        ));
        let qb = nalgebra::UnitQuaternion::new_normalize(nalgebra::Quaternion::new(
            b.quat[0], b.quat[1], b.quat[2], b.quat[3],
        ));
        (b.pos - a.pos, (qa.inverse() * qb).scaled_axis())
    };
    for t in 1..len.saturating_sub(1) {
        let (Some((a, on_root)), Some((b, _)), Some((c, _))) =
            (&poses[t - 1], &poses[t], &poses[t + 1])
        else {
            continue;
        };
        let ((p0, r0), (p1, r1)) = (velocity(a, b), velocity(b, c));
        for i in 0..3 {
            out[t * nv + d + i] = p1[i] - p0[i];
            if *on_root {
                out[t * nv + d + 3 + i] = r1[i] - r0[i];
            }
        }
    }
    out
}

/// A window's frames: `fixed` configurations before it (0 to 2, held), then the variables.
struct Sequence<'a> {
    nq: usize,
    fixed: &'a [Vec<f64>],
    qpos: &'a mut [f64],
    /// Per frame of the sequence, the reference's acceleration in each velocity coordinate
    /// (`len × nv`, zero where there is none): the smoothness costs the difference.
    reference: Vec<f64>,
}

impl Sequence<'_> {
    fn len(&self) -> usize {
        self.fixed.len() + self.qpos.len() / self.nq
    }

    /// Configuration `j` of the whole sequence (fixed frames first).
    fn at(&self, j: usize) -> &[f64] {
        if j < self.fixed.len() {
            &self.fixed[j]
        } else {
            let k = j - self.fixed.len();
            &self.qpos[k * self.nq..(k + 1) * self.nq]
        }
    }
}

/// The trajectory solve of one clip's frames, with its solver (the default solve's: tasks,
/// ground, self-collision, speed limits) and its work buffers.
pub(crate) struct Trajectory<'s, 'm> {
    solver: &'s mut Solver<'m>,
    options: TrajectoryOptions,
    stages: Vec<(usize, f64)>,
    /// Per dof, `W_i / dt⁴`.
    weight: Vec<f64>,
    dt: f64,
    banded: Banded,
    /// The dynamics term, when on and the model's masses are known, and the states of the
    /// sequence's frames it reads.
    centroidal: Option<Centroidal>,
    states: Vec<FrameState>,
    scratch: Vec<f64>,
    /// Kinematics of the frame before the one whose grips are added ([`Trajectory::grip_terms`]).
    before: Data,
    /// The window frame whose frame before `before` holds, when it was kept from that frame's
    /// own terms (the solver's kinematics there) rather than computed for it.
    before_for: Option<usize>,
    /// Per window frame, the constraint rows not held (further than the slack from their
    /// bound where the step is linearised): `a` (`rows × nv`) and `b` of `a · δ ≥ b`.
    loose: Vec<(Vec<f64>, Vec<f64>)>,
    /// The body whose origin the root's translational acceleration is measured at, where the
    /// root task is on a body other than the free root's (the T1's `Waist` under its
    /// `Trunk`): its target is that origin's, and the report measures it there.
    root_point: Option<usize>,
    /// Per sequence frame, that origin and its Jacobian ([`Trajectory::root_point_terms`]).
    points: Vec<RootPoint>,
    /// Kinematics of the frames the solver is not at, for [`Trajectory::points`].
    point_data: Data,
}

/// A body's origin in one frame and its Jacobian's non-zero columns (dof, column).
#[derive(Debug, Clone, Default)]
struct RootPoint {
    at: Vector3<f64>,
    columns: Vec<(usize, Vector3<f64>)>,
}

impl RootPoint {
    fn of(model: &Model, data: &Data, body: usize) -> RootPoint {
        let at = data.xpos[body];
        RootPoint { at, columns: model.jac_point_columns(data, body, at).collect() }
    }
}

/// A bound the banded step would cross, held in the system solved again
/// ([`Trajectory::crossed`], [`Trajectory::hold`]).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Crossed {
    /// Frame `k`'s dof `dof` at a range end, `to` the step there.
    Range { k: usize, dof: usize, to: f64 },
    /// Frame `k`'s loose row `row` at its bound.
    Row { k: usize, row: usize },
}

impl Crossed {
    /// The window frame it is held in (its terms touch that frame's block alone).
    fn frame(self) -> usize {
        match self {
            Crossed::Range { k, .. } | Crossed::Row { k, .. } => k,
        }
    }
}

impl<'s, 'm> Trajectory<'s, 'm> {
    pub(crate) fn new(
        solver: &'s mut Solver<'m>,
        stages: usize,
        options: &TrajectoryOptions,
        fps: f64,
    ) -> Trajectory<'s, 'm> {
        let model = solver.robot();
        let dt = if fps > 0.0 { 1.0 / fps } else { 1.0 / 30.0 };
        let weight = coordinate_weights(model, options).iter().map(|w| w / dt.powi(4)).collect();
        Trajectory {
            options: options.clone(),
            stages: objective_stages(stages, options),
            weight,
            dt,
            banded: Banded::new(model.nv, 0),
            centroidal: Centroidal::new(model, &options.dynamics),
            states: Vec::new(),
            scratch: Vec::new(),
            before: Data::new(model),
            before_for: None,
            loose: Vec::new(),
            root_point: None,
            points: Vec::new(),
            point_data: Data::new(model),
            solver,
        }
    }

    /// Frames per window and their overlap at this frame rate.
    pub(crate) fn window_frames(&self) -> (usize, usize) {
        window_frames(&self.options, 1.0 / self.dt)
    }

    /// Where the root's translational acceleration is measured in the window starting at
    /// frame `first`: at the free root's coordinates where the root task is on the free
    /// root's body (or there is none), else at the task's body's origin
    /// ([`Trajectory::root_point`], whose term then carries the weight).
    fn root_point(&mut self, frames: &dyn Frames, first: usize) {
        let model = self.solver.robot();
        let Some(free) = model.joints.iter().find(|j| j.kind == JointType::Free) else { return };
        let body = frames.root_reference(first).map(|(_, body)| body);
        self.root_point = body.filter(|&b| b != free.body);
        let w = if self.root_point.is_some() { 0.0 } else { self.options.root_translation };
        let d = free.dof_adr;
        self.weight[d..d + 3].fill(w / self.dt.powi(4));
    }

    /// Solves frames `first..first + n` (`qpos`: their configurations, `n × nq`, the initial
    /// trajectory in, the solution out) with `fixed` (the 0 to 2 configurations before them)
    /// held. Returns each frame's diagnostics.
    pub(crate) fn solve_window(
        &mut self,
        frames: &dyn Frames,
        first: usize,
        fixed: &[Vec<f64>],
        qpos: &mut [f64],
    ) -> Result<Vec<FrameDiagnostics>, Error> {
        let model = self.solver.robot();
        let n = qpos.len() / model.nq.max(1);
        if self.banded.frames() != n {
            self.banded = Banded::new(model.nv, n);
        }
        let reference = reference_accelerations(model, frames, first, fixed.len(), n);
        let mut seq = Sequence { nq: model.nq, fixed, qpos, reference };
        self.root_point(frames, first);
        self.joint_weights(frames, first, &seq)?;
        let mut diagnostics = Vec::new();
        for _ in 0..self.options.iterations {
            for _ in 0..self.options.banded_steps {
                if self.banded_step(frames, first, &mut seq)? <= self.options.step_tolerance {
                    break;
                }
            }
            diagnostics = self.sweep(frames, first, &mut seq)?;
        }
        Ok(diagnostics)
    }

    /// The joints' acceleration weights of this window from their tracking stiffness at the
    /// initial trajectory ([`TrajectoryOptions::joint_cutoff_hz`]).
    fn joint_weights(
        &mut self,
        frames: &dyn Frames,
        first: usize,
        seq: &Sequence<'_>,
    ) -> Result<(), Error> {
        let model = self.solver.robot();
        let (nq, nv) = (model.nq, model.nv);
        let n = seq.qpos.len() / nq;
        let mut k = vec![0.0; nv];
        // (A mean over every `STIFFNESS_STRIDE`-th frame: it changes slowly.)
        let sampled: Vec<usize> = (0..n).step_by(STIFFNESS_STRIDE).collect();
        for &f in &sampled {
            self.solver.set_qpos(&seq.qpos[f * nq..(f + 1) * nq])?;
            frames.configure(self.solver, first + f)?;
            let d = self.solver.tracking_stiffness(&self.stages, frames.targets(first + f));
            k.iter_mut().zip(&d).for_each(|(a, b)| *a += b / sampled.len() as f64);
        }
        let omega4 = (std::f64::consts::TAU * self.options.joint_cutoff_hz).powi(4);
        let free: Vec<usize> = model
            .joints
            .iter()
            .filter(|j| j.kind == JointType::Free)
            .flat_map(|j| j.dof_adr..j.dof_adr + 6)
            .collect();
        for (d, (w, k)) in self.weight.iter_mut().zip(&k).enumerate() {
            if !free.contains(&d) {
                *w = (k / omega4).max(self.options.joints) / self.dt.powi(4);
            }
        }
        Ok(())
    }

    /// The window's quadratic model at the current trajectory into the banded system (not yet
    /// factored): every frame's tracking and held constraints, the grips, the smoothness, the
    /// speeds at their limit, the dynamics term.
    fn assemble(
        &mut self,
        frames: &dyn Frames,
        first: usize,
        seq: &Sequence<'_>,
    ) -> Result<(), Error> {
        let nq = self.solver.robot().nq;
        let n = seq.qpos.len() / nq;
        // (frame_terms writes each frame's diagonal block and right-hand side whole.)
        self.banded.clear_couplings();
        self.before_for = None;
        self.fixed_states(seq);
        if let Some(body) = self.root_point {
            let model = self.solver.robot();
            self.points.resize(seq.len(), RootPoint::default());
            for (j, q) in seq.fixed.iter().enumerate() {
                model.body_kinematics(q, &mut self.point_data);
                self.points[j] = RootPoint::of(model, &self.point_data, body);
            }
        }
        for k in 0..n {
            self.frame_terms(frames, first + k, k, &seq.qpos[k * nq..(k + 1) * nq])?;
            self.record_state(seq.fixed.len() + k);
            if let Some(body) = self.root_point {
                let point = RootPoint::of(self.solver.robot(), self.solver.data(), body);
                self.points[seq.fixed.len() + k] = point;
            }
            // The frame before, `dt` earlier (none before the clip's first frame).
            let before = (seq.fixed.len() + k).checked_sub(1).map(|j| seq.at(j));
            self.grip_terms(k, before);
        }
        self.smoothness_terms(seq);
        self.root_point_terms(seq);
        self.speed_terms(seq);
        self.dynamics_terms(seq.fixed.len());
        Ok(())
    }

    /// Every bound that the solved step (`banded.rhs`) takes further than the slack past:
    /// joint range ends, and the loose rows.
    fn crossed(&self, seq: &Sequence<'_>) -> Vec<Crossed> {
        let model = self.solver.robot();
        let (nq, nv) = (model.nq, model.nv);
        let slack = self.options.active_slack;
        let mut crossed = Vec::new();
        for k in 0..seq.qpos.len() / nq {
            let q = &seq.qpos[k * nq..(k + 1) * nq];
            let step = &self.banded.rhs.as_slice()[k * nv..(k + 1) * nv];
            for joint in &model.joints {
                let (JointType::Hinge | JointType::Slide, Some([lo, hi])) =
                    (joint.kind, joint.range)
                else {
                    continue;
                };
                let (v, dof) = (q[joint.qpos_adr], joint.dof_adr);
                let to = v + step[dof];
                let bound = if to < lo - slack {
                    lo
                } else if to > hi + slack {
                    hi
                } else {
                    continue;
                };
                crossed.push(Crossed::Range { k, dof, to: bound - v });
            }
            let (a, b) = &self.loose[k];
            for (row, (a, &b)) in a.chunks_exact(nv).zip(b).enumerate() {
                let reach: f64 = a.iter().zip(step).map(|(a, s)| a * s).sum();
                if reach < b - slack {
                    crossed.push(Crossed::Row { k, row });
                }
            }
        }
        crossed
    }

    /// Adds the stiff penalty that holds each of `crossed` at its bound.
    fn hold(&mut self, crossed: &[Crossed]) {
        let nv = self.solver.robot().nv;
        let rho = self.options.active_penalty;
        for &c in crossed {
            match c {
                Crossed::Range { k, dof, to } => {
                    self.banded.add(k, 0, dof, dof, rho);
                    self.banded.rhs_mut(k)[dof] += rho * to;
                }
                Crossed::Row { k, row } => {
                    let (a, b) = &self.loose[k];
                    let a = &a[row * nv..(row + 1) * nv];
                    self.banded.add_penalty(k, a, None, b[row], rho);
                }
            }
        }
    }

    /// Factors the banded system from frame `from` on and solves it (`banded.rhs` becomes
    /// the step).
    fn factor_and_solve(&mut self, first: usize, from: usize) -> Result<(), Error> {
        if self.banded.factor_from(from).is_err() {
            return Err(Error::numerical(
                first,
                "the trajectory's quadratic model is not positive definite".to_owned(),
            ));
        }
        self.banded.solve();
        Ok(())
    }

    /// One Gauss–Newton step of the whole window: the banded system assembled at the current
    /// trajectory, solved, and taken. Returns how far it moved the coordinate it moved most.
    fn banded_step(
        &mut self,
        frames: &dyn Frames,
        first: usize,
        seq: &mut Sequence<'_>,
    ) -> Result<f64, Error> {
        let model = self.solver.robot();
        let (nq, nv) = (model.nq, model.nv);
        let n = seq.qpos.len() / nq;
        // Bounds the step would cross (joint range ends, and the constraint rows that were
        // further than the slack from theirs where it is linearised), held at the bound in the
        // system solved again: projecting such a step onto the ranges afterwards turns one
        // joint alone, which slides a planted sole (a hip roll the step took 0.1 rad past its
        // range onto the H1, 5 mm a frame at 120 fps), and a row left out lets the step carry
        // a geom through the floor or another that the sweep then cannot take back.
        self.assemble(frames, first, seq)?;
        self.banded.save();
        self.factor_and_solve(first, 0)?;
        let crossed = self.crossed(seq);
        // Solved again with them held: the system kept, not assembled again, and factored
        // again from the first frame with a bound held on (the factor before it stands).
        if let Some(from) = crossed.iter().map(|c| c.frame()).min() {
            self.banded.restore_from(from);
            self.hold(&crossed);
            self.factor_and_solve(first, from)?;
        }
        // A trust region: the whole step is scaled so that no coordinate moves further than
        // `max_step` (a Gauss–Newton step from a poor linearisation, a limb's branch or a
        // constraint far past its bound, must not throw a frame across the clip).
        let largest = self.banded.rhs.amax();
        if largest > self.options.max_step {
            self.banded.rhs *= self.options.max_step / largest;
        }
        for k in 0..n {
            let step = self.banded.rhs.rows(k * nv, nv);
            let q = &mut seq.qpos[k * nq..(k + 1) * nq];
            model.integrate_pos(q, step.as_slice(), 1.0);
            // The joint ranges are a box: what the step still crosses (within the slack, or
            // once solved again) is projected onto it (the sweep's bounds only close 95 % of
            // a gap, as GMR's do).
            for joint in &model.joints {
                if let (JointType::Hinge | JointType::Slide, Some([lo, hi])) =
                    (joint.kind, joint.range)
                {
                    q[joint.qpos_adr] = q[joint.qpos_adr].clamp(lo, hi);
                }
            }
        }
        Ok(largest.min(self.options.max_step))
    }

    /// Frame `k`'s grips ([`crate::constraints::Grip`]) in the window's model, the solver
    /// configured at frame `k` and `before` the frame before it: a planted sole's point stays
    /// in its box ([`crate::ik::grip_bounds`]: where it was, moved as its foothold moved,
    /// ± the slip speed × dt) in x and y. A point at or past a bound is held there, as the
    /// other constraints' rows are (stiff penalty): `½ ρ (e + J_k δ_k − J_{k−1} δ_{k−1})²`,
    /// `e` how far past the bound it is (0 at it), the frame before's part where it is in
    /// the window. (Without it the window's
    /// step slid the planted feet wherever the smoothness outweighed their point tasks, which
    /// each frame's step then pulled back: a frame out of line with both its neighbours.)
    fn grip_terms(&mut self, k: usize, before: Option<&[f64]>) {
        let Some(before) = before else { return };
        let (grips, slip) = self.solver.grips();
        if !grips.iter().any(|g| g.from.is_some()) {
            return;
        }
        let model = self.solver.robot();
        let nv = model.nv;
        if self.before_for != Some(k) {
            // (Bodies and dof frames alone: the grip reads no geom.)
            model.body_kinematics(before, &mut self.before);
        }
        let data = self.solver.data();
        let half = slip * self.dt;
        let slack = self.options.active_slack;
        let (mut now, mut then) = (vec![0.0; nv], vec![0.0; nv]);
        for g in grips.iter().filter(|g| g.from.is_some()) {
            let p = data.xpos[g.body] + data.xquat[g.body] * g.point;
            let was = self.before.xpos[g.body] + self.before.xquat[g.body] * g.point;
            let (lo, hi) = grip_bounds(&was, g, half);
            for axis in 0..2 {
                // How far past the bound the point is at or near (0 at it).
                let e = if p[axis] < lo[axis] + slack {
                    (p[axis] - lo[axis]).min(0.0)
                } else if p[axis] > hi[axis] - slack {
                    (p[axis] - hi[axis]).max(0.0)
                } else {
                    continue;
                };
                now.fill(0.0);
                then.fill(0.0);
                for (d, column) in model.jac_point_columns(data, g.body, p) {
                    now[d] = column[axis];
                }
                for (d, column) in model.jac_point_columns(&self.before, g.body, was) {
                    then[d] = column[axis];
                }
                // The frame before's part where it is in the window.
                let before = (k > 0).then_some(&then[..]);
                self.banded.add_penalty(k, &now, before, -e, self.options.active_penalty);
            }
        }
        // A gripped frame's next is most often gripped too: its frame before is this one,
        // whose kinematics the solver holds now.
        self.before.copy_from(self.solver.data());
        self.before_for = Some(k + 1);
    }

    /// The dynamics term's states of the fixed frames (the solver's kinematics are moved).
    fn fixed_states(&mut self, seq: &Sequence<'_>) {
        let Some(centroidal) = &mut self.centroidal else { return };
        let model = self.solver.robot();
        self.states.resize(seq.len(), FrameState::default());
        let mut data = Data::new(model);
        for (j, q) in seq.fixed.iter().enumerate() {
            model.kinematics(q, &mut data);
            centroidal.state(model, &data, &mut self.states[j]);
        }
    }

    /// The dynamics term's state of sequence frame `j` from the solver's kinematics.
    fn record_state(&mut self, j: usize) {
        let Some(centroidal) = &mut self.centroidal else { return };
        let model = self.solver.robot();
        if self.states.len() <= j {
            self.states.resize(j + 1, FrameState::default());
        }
        centroidal.state(model, self.solver.data(), &mut self.states[j]);
    }

    /// `½ W d_t²` of every residual frame (`d`: the residual's length), linearised along
    /// the residual, into the banded system.
    fn dynamics_terms(&mut self, offset: usize) {
        let Some(centroidal) = &self.centroidal else { return };
        let w = centroidal.options.weight;
        let supplies = centroidal.supplies(&self.states, self.dt);
        let nv = self.solver.robot().nv;
        let mut grads: [Vec<f64>; 3] = Default::default();
        for (t, supply) in supplies.iter().enumerate() {
            let Some(supply) = supply else { continue };
            let mut d = None;
            for (x, g) in grads.iter_mut().enumerate() {
                d = centroidal.distance(
                    &self.states,
                    (t, x as isize - 1),
                    supply,
                    self.dt,
                    (&mut self.scratch, g),
                );
            }
            let Some(d) = d else { continue };
            for x in 0..3 {
                let Some(kx) = (t + x - 1).checked_sub(offset) else { continue };
                let gx = &grads[x];
                let mut rhs = self.banded.rhs_mut(kx);
                for p in 0..nv {
                    rhs[p] -= w * gx[p] * d;
                }
                for (y, gy) in grads.iter().enumerate().take(x + 1) {
                    if (t + y - 1) < offset {
                        continue;
                    }
                    let block = self.banded.block_mut(kx, x - y);
                    let (gx, gy) =
                        (DVectorView::from_slice(gx, nv), DVectorView::from_slice(gy, nv));
                    block.ger(w, &gx, &gy, 1.0);
                }
            }
        }
    }

    /// Frame `frame`'s tracking model and its active constraints into block `k`.
    fn frame_terms(
        &mut self,
        frames: &dyn Frames,
        frame: usize,
        k: usize,
        q: &[f64],
    ) -> Result<(), Error> {
        let model = self.solver.robot();
        let nv = model.nv;
        self.solver.set_qpos(q)?;
        frames.configure(self.solver, frame)?;
        let (rho, slack) = (self.options.active_penalty, self.options.active_slack);
        {
            let (h, c) = self.solver.objective_model(&self.stages, frames.targets(frame));
            let block = self.banded.diag_mut(k);
            for i in 0..nv {
                for j in i..nv {
                    block[(i, j)] = h[i * nv + j];
                    block[(j, i)] = h[i * nv + j];
                }
            }
            let mut rhs = self.banded.rhs_mut(k);
            for i in 0..nv {
                rhs[i] = -c[i];
            }
        }
        // Rows at or past their bound are held: a·δ = max(b, 0) (a point on the floor stays
        // there, one below it comes up to it).
        if self.loose.len() <= k {
            self.loose.resize(k + 1, (Vec::new(), Vec::new()));
        }
        let (loose_a, loose_b) = &mut self.loose[k];
        loose_a.clear();
        loose_b.clear();
        for (a, b) in self.solver.constraint_rows() {
            if b > -slack {
                self.banded.add_penalty(k, a, None, b.max(0.0), rho);
            } else {
                loose_a.extend_from_slice(a);
                loose_b.push(b);
            }
        }
        // Joints at a range end stay there.
        for joint in &model.joints {
            let (JointType::Hinge | JointType::Slide, Some([lo, hi])) = (joint.kind, joint.range)
            else {
                continue;
            };
            let v = q[joint.qpos_adr];
            if v - lo < slack || hi - v < slack {
                self.banded.add(k, 0, joint.dof_adr, joint.dof_adr, rho);
            }
        }
        Ok(())
    }

    /// `½ Σ W_i a_{t,i}²` over the sequence's interior frames, linearised
    /// (`a_t(δ) = a_t + δ_{t+1} − 2 δ_t + δ_{t−1}`, fixed frames' δ zero).
    fn smoothness_terms(&mut self, seq: &Sequence<'_>) {
        let model = self.solver.robot();
        let nv = model.nv;
        let len = seq.len();
        let offset = seq.fixed.len();
        let velocities = self.velocities(seq);
        const COEF: [f64; 3] = [1.0, -2.0, 1.0];
        for t in 1..len.saturating_sub(1) {
            // v_{t+1} − v_t: velocities[j] is q_j ⊖ q_{j−1} (j ≥ 1).
            let (v0, v1) = (&velocities[(t - 1) * nv..t * nv], &velocities[t * nv..(t + 1) * nv]);
            let aref = &seq.reference[t * nv..(t + 1) * nv];
            for (x, &cx) in COEF.iter().enumerate() {
                let Some(kx) = (t + x - 1).checked_sub(offset) else { continue };
                for i in 0..nv {
                    let w = self.weight[i];
                    let a = v1[i] - v0[i] - aref[i];
                    self.banded.rhs_mut(kx)[i] -= w * cx * a;
                }
                for (y, &cy) in COEF.iter().enumerate().take(x + 1) {
                    if (t + y - 1) < offset {
                        continue;
                    }
                    for i in 0..nv {
                        self.banded.add(kx, x - y, i, i, self.weight[i] * cx * cy);
                    }
                }
            }
        }
    }

    /// `½ W |a_t|²` of the root task's body's origin `p` (when [`Trajectory::root_point`]),
    /// `a_t = p_{t+1} − 2 p_t + p_{t−1}` less the reference's, over the sequence's interior
    /// frames, linearised through each frame's Jacobian `J` (`p_s(δ) = p_s + J_s δ_s`), `W`
    /// the root's translational weight: the root's acceleration where its target is, not at
    /// the free root's origin, which the trunk's turns move past it (the T1's `Trunk` origin
    /// sits 13 cm from its `Waist`: on the LAFAN1 walk the `Waist` accelerated 1.47 × its
    /// target, the `Trunk` origin 1.26 ×).
    fn root_point_terms(&mut self, seq: &Sequence<'_>) {
        let Some(free) = self.solver.robot().joints.iter().find(|j| j.kind == JointType::Free)
        else {
            return;
        };
        if self.root_point.is_none() {
            return;
        }
        let d = free.dof_adr;
        let nv = self.solver.robot().nv;
        let w = self.options.root_translation / self.dt.powi(4);
        let offset = seq.fixed.len();
        const COEF: [f64; 3] = [1.0, -2.0, 1.0];
        for t in 1..seq.len().saturating_sub(1) {
            let p = |x: usize| self.points[t + x - 1].at;
            let aref = Vector3::from_column_slice(&seq.reference[t * nv + d..t * nv + d + 3]);
            let a = p(2) - p(1) * 2.0 + p(0) - aref;
            for (x, &cx) in COEF.iter().enumerate() {
                let Some(kx) = (t + x - 1).checked_sub(offset) else { continue };
                let mut rhs = self.banded.rhs_mut(kx);
                for (dof, column) in &self.points[t + x - 1].columns {
                    rhs[*dof] -= w * cx * column.dot(&a);
                }
                for (y, &cy) in COEF.iter().enumerate().take(x + 1) {
                    if (t + y - 1) < offset {
                        continue;
                    }
                    let block = self.banded.block_mut(kx, x - y);
                    for (dx, cx_col) in &self.points[t + x - 1].columns {
                        for (dy, cy_col) in &self.points[t + y - 1].columns {
                            block[(*dx, *dy)] += w * cx * cy * cx_col.dot(cy_col);
                        }
                    }
                }
            }
        }
    }

    /// Per consecutive pair of the sequence, `q_j ⊖ q_{j−1}` (`(len − 1) × nv`).
    fn velocities(&self, seq: &Sequence<'_>) -> Vec<f64> {
        let model = self.solver.robot();
        let nv = model.nv;
        let len = seq.len();
        let mut out = vec![0.0; len.saturating_sub(1) * nv];
        for j in 1..len {
            model.differentiate_pos(&mut out[(j - 1) * nv..j * nv], 1.0, seq.at(j - 1), seq.at(j));
        }
        out
    }

    /// Joint speeds at their limit between two frames stay there in the banded step.
    fn speed_terms(&mut self, seq: &Sequence<'_>) {
        let model = self.solver.robot();
        let nv = model.nv;
        let offset = seq.fixed.len();
        let rho = self.options.active_penalty;
        let velocities = self.velocities(seq);
        let limits: Vec<(usize, f64)> = self
            .solver
            .dof_speed_limits()
            .iter()
            .enumerate()
            .filter_map(|(d, v)| v.map(|v| (d, v * self.dt)))
            .collect();
        for j in 1..seq.len() {
            let Some(k) = j.checked_sub(offset) else { continue };
            for &(d, reach) in &limits {
                if velocities[(j - 1) * nv + d].abs() < reach - self.options.active_slack {
                    continue;
                }
                self.banded.add(k, 0, d, d, rho);
                if k >= 1 {
                    self.banded.add(k - 1, 0, d, d, rho);
                    self.banded.add(k, 1, d, d, -rho);
                }
            }
        }
    }

    /// The sweep's part of [`Trajectory::root_point_terms`] for sequence frame `j`, the
    /// solver at its configuration and its neighbours held: `½ W |c J_j δ + a_t|²` for the
    /// accelerations `a_t` that involve it (`c`: its coefficient in each), into the frame's
    /// extra quadratic (`h`, `nv × nv` row-major, and `c`).
    fn root_point_pull(&self, seq: &Sequence<'_>, j: usize, h: &mut [f64], c: &mut [f64]) {
        let Some(body) = self.root_point else { return };
        let model = self.solver.robot();
        let Some(free) = model.joints.iter().find(|j| j.kind == JointType::Free) else { return };
        let (nv, d, len) = (model.nv, free.dof_adr, seq.len());
        let w = self.options.root_translation / self.dt.powi(4);
        let here = RootPoint::of(model, self.solver.data(), body);
        for t in [j.wrapping_sub(1), j, j + 1] {
            if t == usize::MAX || t == 0 || t + 1 >= len {
                continue;
            }
            let c_self = if t == j { -2.0 } else { 1.0 };
            let aref = Vector3::from_column_slice(&seq.reference[t * nv + d..t * nv + d + 3]);
            let p = |x: usize| if x == j { here.at } else { self.points[x].at };
            let a = p(t + 1) - p(t) * 2.0 + p(t - 1) - aref;
            for (dx, cx) in &here.columns {
                c[*dx] += w * c_self * cx.dot(&a);
                for (dy, cy) in &here.columns {
                    h[dx * nv + dy] += w * c_self * c_self * cx.dot(cy);
                }
            }
        }
    }

    /// One forward sweep: each frame's subproblem solved exactly (one constrained step), its
    /// neighbours held: the smoothness terms that involve the frame are a pull of its step
    /// towards the one that minimises them ([`Solver::set_extra`]). The dynamics term is the
    /// banded step's alone: added here as well (each frame's residuals linearised in its own
    /// step, the supplies held through the sweep) it made the motion worse by the report's
    /// measures (LAFAN1 jumps: frames needing more than 0.1 m·g 30.1 → 32.7 % on the G1,
    /// 26.7 → 29.3 % on the T1, the soles sliding more on both).
    fn sweep(
        &mut self,
        frames: &dyn Frames,
        first: usize,
        seq: &mut Sequence<'_>,
    ) -> Result<Vec<FrameDiagnostics>, Error> {
        let model = self.solver.robot();
        let (nq, nv) = (model.nq, model.nv);
        let offset = seq.fixed.len();
        let len = seq.len();
        let n = len - offset;
        let mut diagnostics = Vec::with_capacity(n);
        let mut weights = vec![0.0; nv];
        let mut target = vec![0.0; nv];
        // The root task's body's origin in every frame as it is now (the frames before `j`
        // as this sweep left them).
        if let Some(body) = self.root_point {
            self.points.resize(len, RootPoint::default());
            for j in 0..len {
                model.body_kinematics(seq.at(j), &mut self.point_data);
                self.points[j] = RootPoint::of(model, &self.point_data, body);
            }
        }
        for k in 0..n {
            let j = k + offset;
            // Tangents at q_j towards each neighbour within two frames.
            let mut u: [Option<Vec<f64>>; 5] = Default::default();
            for (slot, dj) in (-2isize..=2).enumerate() {
                if dj == 0 {
                    continue;
                }
                let Some(i) = j.checked_add_signed(dj).filter(|&i| i < len) else { continue };
                let mut v = vec![0.0; nv];
                model.differentiate_pos(&mut v, 1.0, seq.at(j), seq.at(i));
                u[slot] = Some(v);
            }
            // a_t for t = j−1, j, j+1 (needs t−1 and t+1): c_j x + s_t.
            weights.fill(0.0);
            target.fill(0.0);
            for t in [j.wrapping_sub(1), j, j + 1] {
                if t == usize::MAX || t == 0 || t + 1 >= len {
                    continue;
                }
                let c_self = if t == j { -2.0 } else { 1.0 };
                for i in 0..nv {
                    let mut s = -seq.reference[t * nv + i];
                    for (x, cx) in [(t - 1, 1.0), (t, -2.0), (t + 1, 1.0)] {
                        if x == j {
                            continue;
                        }
                        let slot = x + 2 - j;
                        s += cx * u[slot].as_ref().map_or(0.0, |v| v[i]);
                    }
                    weights[i] += self.weight[i] * c_self * c_self;
                    target[i] -= self.weight[i] * c_self * s;
                }
            }
            // The smoothness's ½ w (x − r)² per dof: w on the diagonal, −w r (here `target`
            // holds −w r) into c.
            let mut extra_h = vec![0.0; nv * nv];
            for i in 0..nv {
                extra_h[i * nv + i] = weights[i];
            }
            let mut extra_c: Vec<f64> = target.iter().map(|t| -t).collect();
            let q = seq.at(j).to_vec();
            self.solver.set_qpos(&q)?;
            frames.configure(self.solver, first + k)?;
            self.root_point_pull(seq, j, &mut extra_h, &mut extra_c);
            self.solver.set_extra(&extra_h, &extra_c)?;
            let previous = if j >= 1 { seq.at(j - 1).to_vec() } else { q.clone() };
            self.solver.set_previous(&previous)?;
            let next = (j + 1 < len).then(|| seq.at(j + 1).to_vec());
            self.solver.set_next(next.as_deref())?;
            let dt = if j >= 1 { self.dt } else { 0.0 };
            let (relaxed, _) =
                self.solver.trajectory_step(&self.stages, frames.targets(first + k), dt)?;
            seq.qpos[k * nq..(k + 1) * nq].copy_from_slice(self.solver.qpos());
            if let Some(body) = self.root_point {
                model.body_kinematics(seq.at(j), &mut self.point_data);
                self.points[j] = RootPoint::of(model, &self.point_data, body);
            }
            diagnostics.push(self.solver.diagnostics(frames.targets(first + k), relaxed)?);
        }
        self.solver.set_extra(&[], &[])?;
        self.solver.set_next(None)?;
        Ok(diagnostics)
    }
}
