//! Which stages of the solve run, and with what: the [`SolveMode`] turned once
//! ([`Pipeline::new`]) into the list of enabled stages with their options, which the stages
//! read instead of the mode.

use super::trajectory::TrajectoryOptions;
use super::{PlausibleOptions, RetargetOptions, SelfCollisionMode, SolveMode, SpeedLimits};
use crate::contact_phases::ContactOptions;
use crate::feet::FootPlanOptions;
use crate::ik::SolverOptions;
use crate::Planting;

/// The stages a solve runs, each with its options; `None` (or `false`): the stage does not run.
#[derive(Debug, Clone)]
pub(crate) struct Pipeline {
    /// Stage 0: a source on a treadmill put on a floor that stays put (found with `contacts`),
    /// where the feet are planted.
    pub treadmill: bool,
    /// Stage 2: how the source's contact phases are found (they are written in every mode).
    pub contacts: ContactOptions,
    /// Stage 3: the robot's feet planted on the contacts; `None`: the targets stay GMR's.
    pub foot_plan: Option<FootPlanOptions>,
    /// Stage 4, where stage 3 planted the feet.
    pub reweigh: Option<ReweighOptions>,
    /// Stages 5 and 6: the solver's options (ours override GMR's extra steps and arithmetic).
    pub solver: SolverOptions,
    /// Stages 5 and 6: the hard constraints, and a first frame solved from the better of two
    /// starts; `None`: GMR's solve (its box bounds only, the first frame from `qpos0`).
    pub constraints: Option<HardConstraints>,
    /// Stage 5 also run backwards and spliced ([`crate::PlausibleOptions::both_ways`]).
    pub both_ways: bool,
    /// Stage 6.
    pub trajectory: Option<TrajectoryOptions>,
}

/// The hard constraints of the default solve's stages 5 and 6 (`build_solver`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct HardConstraints {
    /// Every collision geom stays above this height (m).
    pub floor: f64,
    pub self_collision: SelfCollisionMode,
    pub speed_limits: SpeedLimits,
}

impl Pipeline {
    /// The stages `options` ask for: `--gmr` is stages 1, 2 and 5 with GMR's solver and
    /// nothing else; the default solve all of them, as its [`crate::PlausibleOptions`] say.
    pub(crate) fn new(options: &RetargetOptions) -> Pipeline {
        let SolveMode::Plausible(p) = &options.mode else {
            return Pipeline {
                treadmill: false,
                contacts: ContactOptions::default(),
                foot_plan: None,
                reweigh: None,
                solver: options.solver.clone(),
                constraints: None,
                both_ways: false,
                trajectory: None,
            };
        };
        let planting = p.planting == Planting::On;
        let solver = SolverOptions {
            max_extra_steps: p.max_extra_steps,
            arithmetic: crate::ik::Arithmetic::Lean,
            ..options.solver.clone()
        };
        Pipeline {
            // The belt is the whole clip's median (as planting needs the whole clip): a stream
            // cannot run it, so the causal solve (planting off) does not either.
            treadmill: planting,
            contacts: p.contact.clone(),
            foot_plan: planting.then(|| p.feet.clone()),
            reweigh: planting.then(|| ReweighOptions::from(p)),
            solver,
            constraints: Some(HardConstraints {
                floor: p.floor,
                self_collision: p.self_collision,
                speed_limits: p.speed_limits,
            }),
            both_ways: p.both_ways,
            trajectory: (p.trajectory.iterations > 0).then(|| p.trajectory.clone()),
        }
    }

    /// The stages that need no future frame: what a stream runs ([`crate::Retargeter::step`]),
    /// stage 5 forward with this solver and these constraints.
    #[must_use]
    pub(crate) fn causal(self) -> Pipeline {
        Pipeline {
            treadmill: false,
            foot_plan: None,
            reweigh: None,
            both_ways: false,
            trajectory: None,
            ..self
        }
    }

    /// GMR's solve exactly (`--gmr`): no constraint, no stage of ours.
    pub(crate) fn is_gmr(&self) -> bool {
        self.constraints.is_none()
    }
}

/// Stage 4's tunables, [`PlausibleOptions`]' (documented there).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ReweighOptions {
    pub trunk_rotation_scale: f64,
    pub root_position_weight_cap: f64,
    pub pelvis_offset_range: [f64; 2],
}

impl From<&PlausibleOptions> for ReweighOptions {
    fn from(p: &PlausibleOptions) -> ReweighOptions {
        ReweighOptions {
            trunk_rotation_scale: p.trunk_rotation_scale,
            root_position_weight_cap: p.root_position_weight_cap,
            pelvis_offset_range: p.pelvis_offset_range,
        }
    }
}
