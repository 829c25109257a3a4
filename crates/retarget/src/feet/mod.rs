//! Planted feet: the source's contact phases turned into foot targets that stand still on
//! the floor.
//!
//! Given the per-frame targets (GMR's, from the config) and the source's contact labels:
//!
//! 1. **Floor**: all targets move by one vertical shift per clip, the median over the
//!    stance samples of "how far the foot target must move for its sole to rest on z = 0"
//!    (the source's floor becomes the robot's floor; jumps keep their height). Then, in
//!    every frame, two feet alongside each other are moved apart sideways until their soles
//!    are [`FootPlanOptions::sole_gap`] apart (the scaled human's feet can pass closer than
//!    the robot's fit).
//! 2. **Planting**: during a stance phase the foot target's horizontal position and yaw are
//!    the phase's anchor ([`Anchor`]), its z puts the sole's lowest point at
//!    [`FootPlanOptions::clearance`], and the foot task's weights are multiplied by
//!    [`FootPlanOptions::stance_weight`]; the sole's bottom points are point tasks that hold it
//!    there ([`SolePoint`]). The foot stands on its whole sole: the human foot's tilt is
//!    scaled down until the sole's bottom points are within [`FootPlanOptions::sole_band`] of
//!    each other, except while the other foot stands too, when it rolls with the human's
//!    (heel strike, toe off), faded in and out over [`FootPlanOptions::roll_s`].
//!    A phase over which the source foot turns through more than
//!    [`FootPlanOptions::pivot_turn`] (45°) is a **pivot**: the planted foot turns with the
//!    source's yaw about the ball of its foot ([`RobotFoot::ball_point`], the inner toe
//!    corner, which stays on the anchor), as a foot turning on its ball does, instead of
//!    holding the mean yaw and twisting the leg by half the turn. Where it turns fast it
//!    stands on its ball alone: it rolls no more with the human's foot, its heel rises up to
//!    [`FootPlanOptions::pivot_heel_lift`] (2 cm) above its toe and its outer toe corner
//!    [`CONTACT_PATCH`](soles::CONTACT_PATCH) above the ball, fully where turning flat would
//!    slide the heel at [`FootPlanOptions::pivot_heel_speed`] (0.2 m/s). (95 % of the frames
//!    the report counted as skating on the LAFAN1 jumps were flat soles turning at up to
//!    450°/s; at 1.75 m, floor skating on the G1's jumps went from 1.40 to 0.31 %, on the
//!    T1's from 2.03 to 1.01 % with the heel up; standing on the one corner took the T1's
//!    mid-stance turns out of it, where both toe corners had slid at the turn's rate times
//!    half the sole's width.)
//!    A foot whose ankle cannot roll (the H1's) turns about the middle of its toes instead.
//!    Where the human stands on its toes ([`FootContacts::on_toes`]: kneeling, tiptoe, a
//!    turn on the ball of the foot, push-off), the foot stands on the front of its sole, its
//!    heel as high above it as the human's, faded in and out over the same
//!    [`FootPlanOptions::roll_s`]. (CMU 131_01 kneels on its toes and turns there: the G1
//!    flattened to stand on its whole sole could not, stood on its toe corners as its knee
//!    allowed and slid them: floor skating 9.9 → 6.4 %, over the ten robots 5.6–23.4 →
//!    0.6–16.5 %.)
//!    Overlapping stance phases of the two feet are kept apart; crossed ones (the left foot
//!    to the right of the right one) stay crossed: the trajectory solve stands in them.
//! 3. **Swing**: out of stance the sole stays at least [`FootPlanOptions::swing_clearance`]
//!    above the floor ([`FootPlan::swing_floor`], which the solve holds as that sole's
//!    floor), risen to it over [`FootPlanOptions::lift_s`] after lift-off and left over as
//!    long before touch-down; in those frames the sole points that stood on the floor at
//!    lift-off (stand on it at touch-down) are held where they were (will be), seen from
//!    above, as firmly in all as a planted sole's: a foot leaves the floor by lifting its
//!    last contact, not by sliding it. After lift-off they are held as a planted sole's
//!    points are, by the solve's grips as well ([`FootPlan::lifted_at`]): by their point
//!    tasks alone, the toes slid 0.3–0.9 m/s within a centimetre of the floor after each
//!    toe-off of the SOMA walk onto the G1 (120 fps). Not before touch-down: a sole held
//!    there cannot reach its foothold (the corpus gate, 79 → 83 rows flagged).
//!
//! The solve ([`crate::solve`]) sees every frame at once: there is no blending of targets
//! into and out of stance; the accelerations cost it makes the transitions.
//!
//! One file per concept: `detect.rs` which bodies are the feet ([`detect_feet`]), `soles.rs`
//! the robot foot and its sole ([`RobotFoot`], [`SolePoint`]: every collision primitive on the
//! foot body and its descendants; `inertia.rs` the sole of a foot without collision geometry),
//! `floor.rs` step 1, `anchors.rs` and `stance.rs` step 2, `swing.rs` step 3, `plan_options.rs`
//! the tunables ([`FootPlanOptions`]); this file holds the plan, in order.

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: frame and slot indices are bounded by `plan`'s `targets.len() / slots` and the contact
// labels' lengths, which `plan` clips to it; body and geom ids come from the model.
#![allow(clippy::indexing_slicing)]

mod anchors;
mod detect;
mod floor;
mod inertia;
mod math;
mod plan_options;
mod soles;
mod stance;
mod swing;
#[cfg(test)]
mod tests;

use crate::lie::Pose;
use crate::motion::FootContacts;
use anchors::{foot_anchors, separate, Planted};
use floor::{floor_shift, keep_feet_apart};
use math::quat;
use nalgebra::Vector3;
use stance::{plant, roll_shares, Stand};
use swing::{swing, Swing};

pub use detect::detect_feet;
pub(crate) use inertia::inertia_sole;
pub(crate) use math::wrap;
pub use plan_options::{Anchor, FootPlanOptions};
pub use soles::{RobotFoot, SolePoint};

/// What `plan` did: the vertical shift and per frame the weight factor of each foot.
#[derive(Debug, Clone, PartialEq)]
pub struct FootPlan {
    /// Added to every target's z (m).
    pub shift: f64,
    /// Per frame, `[left, right]` factors on the foot tasks' weights.
    pub weight: Vec<[f64; 2]>,
    /// Per frame and foot in stance: points of the sole (foot frame), where they stay
    /// (world), and which world axes hold them ([`SolePoint`]).
    pub contact: Vec<[Vec<SolePoint>; 2]>,
    /// Per frame and foot out of stance: the least height (m) above the floor the swing
    /// clearance asks of the sole's lowest point, where it asks any.
    pub swing_floor: Vec<[Option<f64>; 2]>,
}

impl FootPlan {
    /// Whether sole point `point` (foot frame) of foot `side`, held in frame `frame` of a
    /// swing, is one the sole stood on at its lift-off: every frame back to the last planted
    /// one holds it, and there it stands on the floor (a landing's held points are not: the
    /// frames before them, mid-swing, hold none).
    #[must_use]
    pub fn lifted_at(&self, frame: usize, side: usize, point: &Vector3<f64>) -> bool {
        let mut b = frame;
        while let Some(before) = b.checked_sub(1) {
            let Some(p) = self.contact[before][side].iter().find(|p| p.point == *point) else {
                return false;
            };
            if self.swing_floor[before][side].is_none() {
                return p.vertical > 0.0;
            }
            b = before;
        }
        false
    }
}

/// Rewrites `targets` (`frames × slots` poses, frame-major) in place; see the module docs.
pub fn plan(
    feet: &[Option<RobotFoot>; 2],
    contacts: &FootContacts,
    targets: &mut [Pose],
    slots: usize,
    fps: f64,
    options: &FootPlanOptions,
) -> FootPlan {
    let frames = targets.len().checked_div(slots).unwrap_or(0);
    let labels = [&contacts.left, &contacts.right];
    // 1. The floor.
    let shift = floor_shift(feet, &labels, targets, slots, options.clearance);
    for p in targets.iter_mut() {
        p.pos.z += shift;
    }
    if let [Some(left), Some(right)] = feet {
        keep_feet_apart(left, right, targets, slots, options.sole_gap);
    }
    let mut plan = FootPlan {
        shift,
        weight: vec![[1.0; 2]; frames],
        contact: vec![[Vec::new(), Vec::new()]; frames],
        swing_floor: vec![[None; 2]; frames],
    };
    // 2. Planting: each foot's stance phases and their anchors, kept apart, then the
    // planted poses; 3. the swing.
    let lead = (options.lead_s * fps).round().max(0.0) as usize;
    let Free { targets: free, yaw: free_yaw, mut anchors } =
        free_feet(feet, &labels, targets, slots, lead, options);
    if let [Some(left), Some(right)] = feet {
        separate(left, right, &mut anchors, options.sole_gap);
    }
    let planted_mask = anchors.each_ref().map(|phases| planted_frames(phases, frames));
    let roll_frames = (options.roll_s * fps).round().max(1.0);
    for (side, foot) in feet.iter().enumerate() {
        let Some(foot) = foot else { continue };
        let roll = roll_shares(&planted_mask[1 - side], roll_frames);
        let toes = match &contacts.on_toes {
            Some(on_toes) => {
                roll_shares(&on_toes[side][..frames.min(on_toes[side].len())], roll_frames)
            }
            None => Vec::new(),
        };
        let stand = Stand { roll: &roll, toes: &toes };
        let planted =
            plant(foot, side, &anchors[side], &free[side], &free_yaw[side], stand, fps, options);
        plan.set_stance(foot, side, &planted, options.stance_weight, targets, slots);
        let held: Vec<bool> = planted.iter().map(Option::is_some).collect();
        let swings = swing(foot, &held, &free[side], targets, slots, fps, options);
        plan.set_swing(foot, side, swings, targets, slots);
    }
    plan
}

/// The feet before planting, per foot (empty where there is none).
struct Free {
    /// The free targets, one per frame, as the floor step left them.
    targets: [Vec<Pose>; 2],
    /// Their yaws (what a pivot follows).
    yaw: [Vec<f64>; 2],
    /// The stance phases with their anchors.
    anchors: [Vec<Planted>; 2],
}

/// The [`Free`] feet of `targets` (`frames × slots`), with the stance phases of `labels`
/// begun `lead` frames early.
fn free_feet(
    feet: &[Option<RobotFoot>; 2],
    labels: &[&Vec<bool>; 2],
    targets: &[Pose],
    slots: usize,
    lead: usize,
    options: &FootPlanOptions,
) -> Free {
    let frames = targets.len().checked_div(slots).unwrap_or(0);
    let mut free: [Vec<Pose>; 2] = Default::default();
    let mut free_yaw: [Vec<f64>; 2] = Default::default();
    let mut anchors: [Vec<Planted>; 2] = Default::default();
    for (side, foot) in feet.iter().enumerate() {
        let Some(foot) = foot else { continue };
        let label = &labels[side][..frames.min(labels[side].len())];
        let own: Vec<Pose> = (0..frames).map(|t| targets[t * slots + foot.slot]).collect();
        anchors[side] = foot_anchors(foot, label, &own, targets, slots, lead, options.anchor);
        free_yaw[side] = own.iter().map(|p| foot.yaw(&quat(p))).collect();
        free[side] = own;
    }
    Free { targets: free, yaw: free_yaw, anchors }
}

impl FootPlan {
    /// Writes `foot`'s `planted` poses (per frame, `None` out of stance) into `targets` and
    /// their sole points and `weight` into the plan.
    fn set_stance(
        &mut self,
        foot: &RobotFoot,
        side: usize,
        planted: &[Option<Pose>],
        weight: f64,
        targets: &mut [Pose],
        slots: usize,
    ) {
        for (t, pose) in planted.iter().enumerate() {
            let Some(pose) = pose else { continue };
            self.contact[t][side] = foot.contact_points(pose, 1.0);
            targets[t * slots + foot.slot] = *pose;
            self.weight[t][side] = weight;
        }
    }

    /// Writes `foot`'s `swings` (per frame, `None` in stance) into the plan and its raised
    /// targets into `targets`.
    fn set_swing(
        &mut self,
        foot: &RobotFoot,
        side: usize,
        swings: Vec<Option<Swing>>,
        targets: &mut [Pose],
        slots: usize,
    ) {
        for (t, s) in swings.into_iter().enumerate() {
            let Some(s) = s else { continue };
            self.contact[t][side] = s.held;
            self.swing_floor[t][side] = s.floor;
            if let Some(pose) = s.target {
                targets[t * slots + foot.slot] = pose;
            }
        }
    }
}

/// Per frame, whether any of the stance `phases` covers it.
fn planted_frames(phases: &[Planted], frames: usize) -> Vec<bool> {
    let mut m = vec![false; frames];
    for (r, _, _) in phases {
        for t in r.clone() {
            if t < frames {
                m[t] = true;
            }
        }
    }
    m
}
