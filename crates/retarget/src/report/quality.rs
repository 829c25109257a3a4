//! The report's values: what `report` measures, one struct per section of the table.

use serde::Serialize;

use super::checks::Verdict;
use super::dynamics::Dynamics;
use super::rates::{Jitter, RootAcceleration};
use super::stats::Stats;

/// Tracking error of one target body.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BodyTracking {
    pub body: String,
    /// Position error (m); `None` for a body whose position is not a target
    /// ([`ReportOptions::position_targets`](super::ReportOptions::position_targets)).
    pub pos_m: Option<Stats>,
    /// Rotation error (rad).
    pub rot_rad: Stats,
}

/// Joint-limit violations of one joint.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LimitViolation {
    pub joint: String,
    pub frames: usize,
    /// Largest distance outside the range (rad or m).
    pub max_excess: f64,
}

/// Joint-limit summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct JointLimits {
    /// Frames × joints outside their range.
    pub violations: usize,
    pub max_excess: f64,
    /// Only the joints that violate.
    pub joints: Vec<LimitViolation>,
}

/// Speed and smoothness of one hinge or slide joint.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct JointMotion {
    pub joint: String,
    /// 99th percentile of `|q̇|`.
    pub vel_p99: f64,
    pub vel_max: f64,
    /// Frames with `|q̇|` above
    /// [`ReportOptions::joint_velocity_limit`](super::ReportOptions::joint_velocity_limit) (0
    /// without a limit).
    pub vel_over_limit: usize,
    /// Mean `|q̈|` (rad/s² or m/s²).
    pub jitter: f64,
}

/// Ground contact of one foot.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FootReport {
    pub body: String,
    /// `"geoms"` (lowest point of its collision geoms), `"inertia"` (of the equivalent box of
    /// its mass and inertia, for a foot without geoms) or `"origin"` (body origin).
    pub height_from: &'static str,
    pub contact_frames: usize,
    pub contact_phases: usize,
    pub sliding_frames: usize,
    /// Sliding frames / contact frames (0 without contact).
    pub sliding_share: f64,
    pub slide_per_phase_cm_mean: f64,
    pub slide_per_phase_cm_max: f64,
    /// Frames with the sole on the floor (lower than
    /// [`ReportOptions::floor_height`](super::ReportOptions::floor_height)), and those of them in
    /// which its contact point moves faster than
    /// [`ReportOptions::skate_speed`](super::ReportOptions::skate_speed) (skating measured on the
    /// robot's own contacts, whatever the source's), and their share.
    pub floor_frames: usize,
    pub floor_skating_frames: usize,
    pub floor_skating_share: f64,
    /// Frames with the foot below the ground.
    pub penetration_frames: usize,
    pub penetration_cm_max: f64,
    /// Mean over the penetrating frames (0 without any).
    pub penetration_cm_mean: f64,
}

/// Frames with neither foot near the ground.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Floating {
    pub frames: usize,
    pub share: f64,
    /// Mean over all frames of `max(0, lowest foot height)` (cm).
    pub cm_mean: f64,
    pub cm_max: f64,
}

/// Min, mean and max.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Range {
    pub min: f64,
    pub mean: f64,
    pub max: f64,
}

/// Ground penetration of every collision geom (see the module documentation).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GroundPenetration {
    /// Collision geoms considered.
    pub geoms: usize,
    /// [`ReportOptions::penetration_tolerance`](super::ReportOptions::penetration_tolerance) (cm).
    pub tolerance_cm: f64,
    /// Frames deeper than the tolerance.
    pub frames: usize,
    /// `frames` / all frames (holosoma's `penetration_duration`).
    pub duration: f64,
    /// Deepest penetration over all frames (cm), 0 without any.
    pub max_depth_cm: f64,
    /// The geom of the deepest penetration (its name, or `geom N` when it has none).
    pub worst_geom: Option<String>,
}

/// Robot self-collision (see the module documentation).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SelfCollision {
    /// Geom pairs checked.
    pub pairs: usize,
    /// Pairs left out because they touch or overlap at `qpos0`.
    pub ignored_pairs: usize,
    /// Pairs left out because their bodies are adjacent in effect (joined through bodies
    /// without collision geoms; see [`mjcf::Model::self_collision_pairs`]).
    pub adjacent_pairs: usize,
    /// [`ReportOptions::self_collision_depth`](super::ReportOptions::self_collision_depth) (cm).
    pub deep_cm: f64,
    /// Frames with a pair deeper than `deep_cm`.
    pub frames_deep: usize,
    /// Frames with any penetrating pair.
    pub frames_penetrating: usize,
    /// Deepest penetration (cm), 0 without any.
    pub max_depth_cm: f64,
    /// The two geoms of the deepest penetration.
    pub worst_pair: Option<[String; 2]>,
}

/// Foot skating against the source's contacts (holosoma's `foot_skating_metrics`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Skating {
    /// [`ReportOptions::skate_speed`](super::ReportOptions::skate_speed) (m/s).
    pub threshold_mps: f64,
    /// Frames with a foot in source contact.
    pub stance_frames: usize,
    /// Frames with a skating foot.
    pub skating_frames: usize,
    /// `skating_frames / stance_frames` (0 without stance).
    pub duration: f64,
    /// Fastest skating foot (m/s), 0 without any.
    pub max_speed: f64,
}

/// Foot height while the source foot is in contact.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Stance {
    /// Foot × frame samples in source contact.
    pub samples: usize,
    /// [`ReportOptions::stance_float_height`](super::ReportOptions::stance_float_height) and
    /// [`ReportOptions::sole_band`](super::ReportOptions::sole_band) (cm).
    pub float_cm: f64,
    pub band_cm: [f64; 2],
    /// Of those, samples with the foot above the floating height.
    pub floating: usize,
    pub floating_share: f64,
    /// Share of samples with the foot height within the sole band.
    pub sole_in_band_share: f64,
}

/// Joint speeds against the joints' published limits.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct JointSpeedReport {
    /// Joints with a limit.
    pub joints: usize,
    /// Frames × joints over their limit.
    pub violations: usize,
    /// Largest `|q̇| / limit`.
    pub worst_ratio: f64,
    pub worst_joint: String,
}

/// The quality report of one motion (serialises to JSON; `Display` prints a table).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct QualityReport {
    /// Every measure against its cap; printed first.
    pub verdict: Verdict,
    pub robot: String,
    pub frames: usize,
    pub fps: f64,
    /// Per target body, when the motion has targets.
    pub tracking: Option<Vec<BodyTracking>>,
    pub joint_limits: JointLimits,
    pub joints: Vec<JointMotion>,
    pub feet: Vec<FootReport>,
    pub floating: Floating,
    /// Root height (m).
    pub root_height: Range,
    pub ground_penetration: GroundPenetration,
    pub self_collision: SelfCollision,
    /// `None` without the source's foot contacts.
    pub skating: Option<Skating>,
    /// `None` without the source's foot contacts.
    pub stance: Option<Stance>,
    /// `None` when no joint has a published speed limit.
    pub joint_speed: Option<JointSpeedReport>,
    /// The root's acceleration, and its target's.
    pub root_acceleration: RootAcceleration,
    /// Mean `|q̈|` over every velocity coordinate, the root's included.
    pub jitter: Jitter,
    /// The dynamics check, accelerations averaged over
    /// [`DynamicsCheckOptions::span`](super::DynamicsCheckOptions::span); `None` when the model's
    /// masses are not known or the clip is shorter than the span
    /// ([`QualityReport::dynamics_unavailable`] says why).
    pub dynamics: Option<Dynamics>,
    pub dynamics_unavailable: Option<String>,
    /// The same check on the 5 frames around each frame whatever the rate (the figure of
    /// earlier reports, kept beside for continuity; equal to `dynamics` at 24–35 fps).
    pub dynamics_5_frame: Option<Dynamics>,
}
