//! The verdict's values: the caps each quality measure is held to (ours and GMR's
//! `auto_check` criteria), and each measure against its cap.

use serde::Serialize;

/// The caps of [`Verdict`] ([`super::ReportOptions::caps`]). Every time is in seconds and
/// every share is of frames (or foot × frame samples), so a clip is judged the same at any
/// rate.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Caps {
    /// `floor_skating`: the largest per-foot share of floor frames in which the sole's
    /// contact point slides ([`super::FootReport::floor_skating_share`]). Default 0.02.
    pub floor_skating_share: f64,
    /// `stance`: the least share of source-contact samples with the sole in its band
    /// ([`super::Stance::sole_in_band_share`]). Default 0.8.
    pub sole_in_band_share: f64,
    /// `floating`: the largest share of source-contact samples with the foot floating
    /// ([`super::Stance::floating_share`]). Default 0.1.
    pub stance_floating_share: f64,
    /// `floating`: the longest time both feet may stay above the contact height (s; a
    /// human flight of 1 s would rise 1.2 m). Default 1.0.
    pub flight_s: f64,
    /// `joint_jumps`: the fastest a hinge or slide joint without a published speed limit may
    /// move between two consecutive frames (rad/s or m/s): GMR's severe jump, 1 rad per frame
    /// at 30 fps, in seconds. Joints with a published limit are held to it (`joint_speed`).
    /// Default 30.
    pub joint_jump_speed: f64,
    /// `root_acceleration`: the root's mean acceleration over the scaled human's (averaged
    /// over the dynamics span). Default 1.25.
    pub root_acceleration_ratio: f64,
    /// `root_acceleration`: below this mean acceleration (m/s²) nothing is flagged (a
    /// standing clip's ratio is noise over noise). Default 1.0.
    pub root_acceleration_floor: f64,
    /// `root_acceleration` without the human's targets: the largest share of frames over
    /// 2 g. Default 0.05.
    pub root_over_2g_share: f64,
    /// `dynamics`: the largest share of checked frames needing more than the threshold of
    /// extra wrench ([`super::Dynamics::share_over`]). Default 0.4.
    pub dynamics_share: f64,
    /// GMR's `scripts/auto_check.py` criteria.
    pub gmr: GmrCaps,
}

impl Default for Caps {
    fn default() -> Self {
        Caps {
            floor_skating_share: 0.02,
            sole_in_band_share: 0.8,
            stance_floating_share: 0.1,
            flight_s: 1.0,
            joint_jump_speed: 30.0,
            root_acceleration_ratio: 1.25,
            root_acceleration_floor: 1.0,
            root_over_2g_share: 0.05,
            dynamics_share: 0.4,
            gmr: GmrCaps::default(),
        }
    }
}

/// GMR's `auto_check.py` thresholds (YanjieZe/GMR `scripts/auto_check.py`).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct GmrCaps {
    /// Both feet higher than this (m) are off the ground. GMR: 0.12.
    pub floating_height: f64,
    /// Floating when both feet are off the ground for this long in one run (s) or for this
    /// share of the clip in one run. GMR: 1.0 and 0.25.
    pub floating_s: f64,
    pub floating_run_share: f64,
    /// A joint past its range by more than this (rad) in this share of frames. GMR: 0.005
    /// and 0.05.
    pub limit_excess: f64,
    pub limit_share: f64,
    /// A joint moving more than `jump` (rad) between frames in `jump_share` of the
    /// transitions, or more than `severe_jump` once. GMR: 0.5, 0.05, 1.0.
    pub jump: f64,
    pub jump_share: f64,
    pub severe_jump: f64,
    /// Bodies interpenetrating by this much (m) in this share of frames or for this long
    /// in one run (s). GMR: 0.003, 0.10, 0.6.
    pub collision_depth: f64,
    pub collision_share: f64,
    pub collision_s: f64,
}

impl Default for GmrCaps {
    fn default() -> Self {
        GmrCaps {
            floating_height: 0.12,
            floating_s: 1.0,
            floating_run_share: 0.25,
            limit_excess: 0.005,
            limit_share: 0.05,
            jump: 0.5,
            jump_share: 0.05,
            severe_jump: 1.0,
            collision_depth: 0.003,
            collision_share: 0.10,
            collision_s: 0.6,
        }
    }
}

/// One criterion of the verdict.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Check {
    /// `penetration`, `self_collision`, `floor_skating`, `stance`, `floating`,
    /// `joint_limits`, `joint_jumps`, `joint_speed`, `root_acceleration`, `dynamics`, and
    /// GMR's `gmr_floating`, `gmr_joint_limits`, `gmr_joint_jumps`, `gmr_self_collision`.
    pub name: &'static str,
    /// `None`: not measured (see `detail`: the file has no source contacts, the model no
    /// masses, no joint a published speed limit).
    pub ok: Option<bool>,
    /// The measured value and the cap it is held to, in `unit`.
    pub value: f64,
    pub cap: f64,
    pub unit: &'static str,
    /// What was measured, in words.
    pub detail: String,
}

/// The verdict of one clip: ok when no check broke its cap.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Verdict {
    pub ok: bool,
    /// The checks that broke their caps.
    pub flags: Vec<Check>,
    /// Every check, in the order above.
    pub checks: Vec<Check>,
}

impl Verdict {
    /// The names of the broken checks.
    pub fn flag_names(&self) -> impl Iterator<Item = &'static str> + '_ {
        self.flags.iter().map(|c| c.name)
    }
}
