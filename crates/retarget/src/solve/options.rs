//! The solve's options and what it reports of a clip.

// Indexing: per-frame diagnostics hold one entry per tracked body, as `body_names` does.
#![allow(clippy::indexing_slicing)]

use crate::ik::{FrameDiagnostics, SolverOptions};
use fk::FkOptions;
use std::collections::BTreeMap;

/// Which solve [`crate::Retargeter`] runs.
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

/// Tunables of [`SolveMode::Plausible`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct PlausibleOptions {
    /// Whether the robot's feet are planted on the floor during the source's contact phases
    /// (this plans over the whole clip, so it needs the future). The phases themselves are
    /// detected and written in every mode.
    pub planting: Planting,
    pub contact: crate::contact_phases::ContactOptions,
    pub feet: crate::feet::FootPlanOptions,
    /// Every collision geom stays above this height (m): the floor, for the ground
    /// constraint.
    pub floor: f64,
    /// Hold the joints' speed limits (`mjcf::Joint::velocity_limit`) as hard bounds.
    pub speed_limits: SpeedLimits,
    /// Keep the robot's own geoms apart (`SelfCollision`).
    pub self_collision: SelfCollisionMode,
    /// Factor on the rotation weights of every task but the arms' (the trunk and the legs,
    /// `reweigh`) where the config pins the pelvis at a height that disagrees with the
    /// robot's legs (its position weight above [`PlausibleOptions::root_position_weight_cap`],
    /// [`PlausibleOptions::pelvis_offset_range`]). GMR balanced
    /// its leg rotation weights (5–10) against feet that follow the human's; planted, the
    /// feet and the pelvis position decide the legs' posture and the legs' orientations gave
    /// way (the G1's hips and knees 2–4° further from their targets than with GMR's solve).
    pub trunk_rotation_scale: f64,
    /// The root's position weight is at most this (`reweigh`) where the config's targets
    /// disagree with the robot's legs. GMR weighs the G1's and the H1's pelvis position 100
    /// (its other configs 10–50): with the feet planted on the floor, that held the G1's
    /// pelvis at the scaled human's height, 1.6–3.1 cm under where its legs put it.
    pub root_position_weight_cap: f64,
    /// How far (m) the robot's pelvis stands above or below its target, median over a few
    /// windows of the clip solved with the config's weights (`pelvis_offset`, `reweigh.rs`),
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
    /// The trajectory solve over every frame ([`crate::TrajectoryOptions`]); 0 iterations:
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
            contact: crate::contact_phases::ContactOptions::default(),
            feet: crate::feet::FootPlanOptions::default(),
            floor: 0.0,
            speed_limits: SpeedLimits::Robot,
            self_collision: SelfCollisionMode::On,
            trunk_rotation_scale: 2.0,
            root_position_weight_cap: 20.0,
            pelvis_offset_range: [0.005, 0.015],
            both_ways: false,
            trajectory: crate::solve::trajectory::TrajectoryOptions::default(),
            max_extra_steps: 10,
        }
    }
}

impl PlausibleOptions {
    /// The causal part of the default solve: GMR's tasks with the hard constraints (ground,
    /// self-collision, joint speed), warm-started frame by frame; no foot planting (nor the
    /// treadmill stage that goes with it), no smoothing and no backward pass, which all need
    /// the frames that follow. What streaming
    /// ([`crate::Retargeter::step`]) runs; a clip solved with it gives the same numbers.
    #[must_use]
    pub fn causal() -> PlausibleOptions {
        PlausibleOptions {
            planting: Planting::Off,
            both_ways: false,
            trajectory: crate::solve::trajectory::TrajectoryOptions {
                iterations: 0,
                ..Default::default()
            },
            ..PlausibleOptions::default()
        }
    }
}

/// How to cut a clip: chunks of `frames` frames, each preceded by `lead_in` frames of warm-up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ChunkOptions {
    pub frames: usize,
    pub lead_in: usize,
}

impl Default for ChunkOptions {
    /// 20 s chunks at 30 fps with a 2 s lead-in.
    fn default() -> ChunkOptions {
        ChunkOptions { frames: 600, lead_in: 60 }
    }
}

/// Options of a [`crate::Retargeter`]'s solve.
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub struct RetargetOptions {
    /// Subject height in metres; `None` uses the FK estimate (GMR assumes 1.75).
    pub human_height: Option<f64>,
    pub solver: SolverOptions,
    /// FK options. Their `roles` also name the source's feet for the contact phases
    /// (`human_foot_points`), before the recognised ones (`solve::source_roles`).
    pub fk: FkOptions,
    /// Solve long clips as parallel chunks; `None`: one serial pass.
    pub chunk: Option<ChunkOptions>,
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

/// The subject height the targets are scaled by (GMR's `actual_human_height`) and where it
/// came from: decided once per clip, by its source (given in the options, FK's estimate, the
/// markers, the body model, the config's assumption), and reported in [`ClipDiagnostics`].
#[derive(Debug, Clone, PartialEq)]
pub struct SubjectHeight {
    pub metres: f64,
    /// Where it came from, for people (`given`, `config subject_height_m`, how FK measured it).
    pub source: String,
}

impl SubjectHeight {
    /// A height given by the caller ([`RetargetOptions::human_height`]).
    #[must_use]
    pub fn given(metres: f64) -> SubjectHeight {
        SubjectHeight { metres, source: "given".to_owned() }
    }

    /// The height of a motion or a stream: the one given, else the config's
    /// `human_height_assumption` (GMR without `actual_human_height`).
    pub(crate) fn of_motion(given: Option<f64>, config: &crate::config::IkConfig) -> SubjectHeight {
        given.map_or_else(
            || SubjectHeight {
                metres: config.human_height_assumption,
                source: "the config's human_height_assumption".to_owned(),
            },
            SubjectHeight::given,
        )
    }
}

/// Per-clip diagnostics: per frame, and which bodies the per-body arrays refer to.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ClipDiagnostics {
    /// Tracked robot bodies (same order as [`TrackedTargets::body_names`](crate::motion::TrackedTargets::body_names)).
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
    /// What the default solve's stages say about the clip ([`StageReport`]), in the order
    /// they ran; only stages that have something to say (the treadmill where the source walks
    /// in place, the reweighing where the config's pelvis disagrees with the robot's legs).
    pub stages: Vec<StageReport>,
}

/// What one stage of the solve says about a clip: its name, one line for people, and the
/// numbers behind that line for programs. The main command prints each `summary` after
/// `default solve: `; Python gives them as `Motion.stages`, `{stage: {key: value}}` with the
/// summary under `"summary"`.
///
/// A stage that reports returns one of these from its own file (as `solve/treadmill.rs`
/// and `solve/reweigh.rs` do), and the driver (`solve_clip`) collects them in the order the
/// stages ran; the CLI, Python and [`ClipDiagnostics`] show them without knowing the stage.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct StageReport {
    /// The stage's name: its file in `solve/` without `.rs` (`"treadmill"`, `"reweigh"`).
    pub stage: &'static str,
    /// One line, no trailing newline (e.g. `the pelvis stands 1.3 cm off its target with the
    /// config's weights; trunk and leg weights reweighed 87 %`).
    pub summary: String,
    /// The numbers the summary says, by key (documented in the stage's file).
    pub values: BTreeMap<&'static str, StageValue>,
}

/// One value of a [`StageReport`].
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[non_exhaustive]
pub enum StageValue {
    /// A measurement, in SI units (m, s, rad) or a share from 0 to 1.
    Number(f64),
    /// How many of something.
    Count(usize),
    /// Stretches of frames, `(first, last)` with the last frame included.
    Ranges(Vec<(usize, usize)>),
    Text(String),
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
