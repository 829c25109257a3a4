//! Standing: a planted foot stands on its whole sole ([`RobotFoot::within_band`]) except in
//! double support, where it rolls with the human's (heel strike, toe off: `roll_shares`); a
//! pivot's foot turns with the source's about its toe, on its ball where it turns fast (heel
//! up); the planted pose rests the sole's
//! lowest point on the floor at the anchor (`planted_pose`).

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: frame and slot indices are bounded by `plan`'s `targets.len() / slots` and the contact
// labels' lengths, which `plan` clips to it.
#![allow(clippy::indexing_slicing)]

use std::ops::Range;

use nalgebra::{UnitQuaternion, Vector3};

use super::anchors::{anchored, pivot, turn_of, Planted};
use super::math::{quat, smoothstep, wrap};
use super::plan_options::FootPlanOptions;
use super::soles::{RobotFoot, CONTACT_PATCH};
use crate::lie::Pose;

/// Rescalings of a planted foot's tilt in [`RobotFoot::within_band`]: the spread of the sole's
/// bottom points grows about linearly with the tilt's angle, so a few settle it.
const BAND_RESCALINGS: usize = 4;

impl RobotFoot {
    /// `rot` with its tilt (from standing flat at its yaw) scaled down until the sole's
    /// bottom points are within `band` (m) of each other in height: a planted foot stands
    /// on its whole sole (the dynamics check counts the points within 1 cm of the floor as
    /// its support).
    #[must_use]
    pub fn within_band(&self, rot: &UnitQuaternion<f64>, band: f64) -> UnitQuaternion<f64> {
        let flat = self.flat(self.yaw(rot));
        let tilt = flat.inverse() * rot;
        let rest = self.height_spread(&flat);
        if self.corners.len() < 2 || self.height_spread(rot) - rest <= band {
            return *rot;
        }
        let mut share = 1.0;
        for _ in 0..BAND_RESCALINGS {
            let at = flat * UnitQuaternion::identity().slerp(&tilt, share);
            let over = self.height_spread(&at) - rest;
            if over <= band {
                break;
            }
            share *= band / over;
        }
        flat * UnitQuaternion::identity().slerp(&tilt, share)
    }

    /// How far (m) the sole's highest bottom point stands above its lowest at orientation
    /// `rot`.
    pub(super) fn height_spread(&self, rot: &UnitQuaternion<f64>) -> f64 {
        let z = self.corners.iter().map(|c| (rot * c).z);
        let (lo, hi) = z.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
        hi - lo
    }

    /// The sole's length (m): the spread of its bottom points along its forward direction.
    fn length(&self) -> f64 {
        self.spread_along(&self.forward)
    }

    /// The sole's width (m): the spread of its bottom points across its forward direction.
    fn width(&self) -> f64 {
        self.spread_along(&self.left())
    }

    /// The spread of the sole's bottom points along `axis` (foot frame; 0 for none).
    fn spread_along(&self, axis: &Vector3<f64>) -> f64 {
        let along = self.corners.iter().map(|c| axis.dot(c));
        let (lo, hi) =
            along.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
        if lo < hi {
            hi - lo
        } else {
            0.0
        }
    }

    /// `rot` rolled about the foot's own forward axis so that the sole's outer edge (the left
    /// foot's left, `side` 0; the right foot's right) rises `lift` (m) above its inner edge;
    /// unchanged where the ankle cannot roll ([`RobotFoot::rolls`]).
    fn outside_up(&self, rot: &UnitQuaternion<f64>, lift: f64, side: usize) -> UnitQuaternion<f64> {
        let width = self.width();
        if !self.rolls || lift <= 0.0 || width <= lift {
            return *rot;
        }
        // A positive turn about forward raises the left edge.
        let sign = if side == 0 { 1.0 } else { -1.0 };
        match nalgebra::Unit::try_new(rot * self.forward, 1e-9) {
            Some(axis) => {
                UnitQuaternion::from_axis_angle(&axis, sign * (lift / width).asin()) * rot
            }
            None => *rot,
        }
    }

    /// `rot` pitched toe-down about the foot's own left axis, so that the sole's back end
    /// rises at least `lift` (m) above its front.
    fn heel_up(&self, rot: &UnitQuaternion<f64>, lift: f64) -> UnitQuaternion<f64> {
        let length = self.length();
        let now = self.heel_lift(rot);
        if lift <= now.max(0.0) || length <= lift {
            return *rot;
        }
        let forward = rot * self.forward;
        let left = Vector3::z().cross(&forward);
        let turn = (lift / length).asin() - (now / length).clamp(-1.0, 1.0).asin();
        match nalgebra::Unit::try_new(left, 1e-9) {
            Some(axis) => UnitQuaternion::from_axis_angle(&axis, turn) * rot,
            None => *rot,
        }
    }

    /// How far (m) the sole's back end stands above its front at orientation `rot`: its
    /// length times the sine of its toe-down pitch (negative toes up).
    fn heel_lift(&self, rot: &UnitQuaternion<f64>) -> f64 {
        -(rot * self.forward).z * self.length()
    }
}

/// Per frame, how far a planted foot may roll as the human's does (1) or stands on its whole
/// sole (0): only while the other foot stands too (`other`, per frame), fading in and out over
/// `roll_frames` at the double support's ends.
pub(super) fn roll_shares(other: &[bool], roll_frames: f64) -> Vec<f64> {
    let frames = other.len();
    (0..frames)
        .map(|t| {
            if !other[t] {
                return 0.0;
            }
            let since = (0..=t).rev().take_while(|&u| other[u]).count() as f64;
            let until = (t..frames).take_while(|&u| other[u]).count() as f64;
            smoothstep((since.min(until) / roll_frames).min(1.0))
        })
        .collect()
}

/// Per frame of one foot, how far its planted pose follows the human foot's (0 standing on
/// its whole sole): `roll`, its tilt, while the other foot stands too ([`roll_shares`]);
/// `toes`, its heel's lift, where the human foot stands on its toes alone (the same fade;
/// empty where unknown).
#[derive(Debug, Clone, Copy)]
pub(super) struct Stand<'a> {
    pub roll: &'a [f64],
    pub toes: &'a [f64],
}

/// Per frame, the planted pose of `foot` (`side` 0 left, 1 right) in its stance `phases`
/// (`None` out of stance): the flat foot at the phase's anchor (a pivot's turned with the
/// source's yaw, `free_yaw`, about the ball of the foot, [`RobotFoot::ball_point`]), tilted
/// as the `free` target within [`FootPlanOptions::sole_band`], rolled by `roll` towards the
/// free target's tilt, resting at [`FootPlanOptions::clearance`]. Where the human stands on
/// its toes (`stand.toes`) the foot stands on the front of its sole, its heel as high above
/// it as the human's (the free target's pitch), rolling no more with the human's foot. A pivot turns on the ball:
/// as fast as it turns (at `fps` frames a second), it rolls no more with the human's foot,
/// its heel rises ([`FootPlanOptions::pivot_heel_lift`]) and its outer toe rises
/// [`CONTACT_PATCH`], so that the ball is the one point it stands on (a rigid sole turning on
/// two points slides one of them).
#[allow(clippy::too_many_arguments)]
pub(super) fn plant(
    foot: &RobotFoot,
    side: usize,
    phases: &[Planted],
    free: &[Pose],
    free_yaw: &[f64],
    stand: Stand<'_>,
    fps: f64,
    options: &FootPlanOptions,
) -> Vec<Option<Pose>> {
    let mut planted = vec![None; free.len()];
    let ball = foot.ball_point(side);
    for (r, xy, yaw) in phases {
        let (xy, yaw) = (*xy, *yaw);
        let pivots = turn_of(&free_yaw[r.clone()], yaw) > options.pivot_turn;
        for t in r.clone() {
            let (xy, yaw) = if pivots {
                (pivot(foot, ball, xy, yaw, free_yaw[t]), free_yaw[t])
            } else {
                (xy, yaw)
            };
            let tilt = quat(&free[t]);
            let turning = if pivots {
                let rate = turn_rate(free_yaw, r.clone(), t, fps);
                smoothstep((rate * foot.length() / options.pivot_heel_speed).min(1.0))
            } else {
                0.0
            };
            let toes = stand.toes.get(t).copied().unwrap_or(0.0);
            let lean = stand.roll[t] * (1.0 - turning) * (1.0 - toes);
            let q = foot.within_band(&tilt, options.sole_band).slerp(&tilt, lean);
            let lift =
                (turning * options.pivot_heel_lift).max(toes * foot.heel_lift(&tilt).max(0.0));
            let q = foot.heel_up(&q, lift);
            let q = foot.outside_up(&q, turning * CONTACT_PATCH, side);
            let rolled = Pose { quat: [q.w, q.i, q.j, q.k], pos: free[t].pos };
            planted[t] = Some(planted_pose(foot, &rolled, xy, yaw, options.clearance));
        }
    }
    planted
}

/// How fast (rad/s) the yaws turn at frame `t` of the phase `r` (central differences
/// inside it, one-sided at its ends).
fn turn_rate(yaws: &[f64], r: Range<usize>, t: usize, fps: f64) -> f64 {
    let a = t.saturating_sub(1).max(r.start);
    let b = (t + 1).min(r.end.saturating_sub(1)).min(yaws.len().saturating_sub(1));
    if b <= a {
        return 0.0;
    }
    (wrap(yaws[b] - yaws[a]) / (b - a) as f64 * fps).abs()
}

/// The planted pose: the free target's tilt with the anchor's yaw, rolled over the sole's
/// lowest point, which stays where it is on the flat foot at the anchor and rests at
/// `clearance` above the floor.
pub(super) fn planted_pose(
    foot: &RobotFoot,
    free: &Pose,
    anchor: Vector3<f64>,
    yaw: f64,
    clearance: f64,
) -> Pose {
    let q = anchored(foot, free, yaw);
    let flat = foot.flat(yaw);
    let low = foot.sole_low_point(&q);
    let contact = Vector3::new(anchor.x, anchor.y, 0.0) + flat * low;
    let rolled = q * low;
    let pos = Vector3::new(contact.x - rolled.x, contact.y - rolled.y, clearance - rolled.z);
    Pose { quat: [q.w, q.i, q.j, q.k], pos }
}
