//! The floor the feet stand on: one vertical shift per clip that rests the soles on it
//! (`floor_shift`), and in every frame two feet alongside each other kept apart sideways
//! (`keep_feet_apart`), before planting.

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: frame and slot indices are bounded by `plan`'s `targets.len() / slots` and the contact
// labels' lengths, which `plan` clips to it.
#![allow(clippy::indexing_slicing)]

use nalgebra::Vector3;

use super::math::{quat, smoothstep};
use super::soles::RobotFoot;
use crate::lie::Pose;

/// Median over stance samples of the vertical move that rests the sole on the floor.
pub(super) fn floor_shift(
    feet: &[Option<RobotFoot>; 2],
    labels: &[&Vec<bool>; 2],
    targets: &[Pose],
    slots: usize,
    clearance: f64,
) -> f64 {
    let mut moves = Vec::new();
    for (side, foot) in feet.iter().enumerate() {
        let Some(foot) = foot else { continue };
        for (t, _) in labels[side].iter().enumerate().filter(|(_, c)| **c) {
            let Some(p) = targets.get(t * slots + foot.slot) else { break };
            moves.push(clearance - foot.sole_offset(&quat(p)) - p.pos.z);
        }
    }
    if moves.is_empty() {
        return 0.0;
    }
    moves.sort_by(f64::total_cmp);
    moves[moves.len() / 2]
}

/// Sideways push between the two feet ([`keep_feet_apart`]) fades in over this much (m) of
/// forward distance as the soles come alongside each other.
const ALONGSIDE_FADE: f64 = 0.05;

/// At most this much (m) of sideways push between the two feet: a step that crosses over
/// (a dance) is narrowed, not uncrossed.
const MAX_WIDENING: f64 = 0.1;

/// Moves the two foot targets of every frame apart sideways (perpendicular to their mean
/// heading, half each) until the inner edges of their flat soles, each turned to its own yaw,
/// are `gap` apart, while the soles are alongside each other: the push fades out over
/// [`ALONGSIDE_FADE`] once one is `gap` ahead of the other, and is at most [`MAX_WIDENING`].
/// The scaled human's feet can pass closer than the robot's feet fit (ToddlerBot: 4.9 cm
/// apart, median, against soles 4.2 cm wide); the self-collision rows then stop a foot short
/// of its anchor, and it catches up later at a skate.
pub(super) fn keep_feet_apart(
    left: &RobotFoot,
    right: &RobotFoot,
    targets: &mut [Pose],
    slots: usize,
    gap: f64,
) {
    if left.corners.is_empty() || right.corners.is_empty() || gap.is_nan() || gap < 0.0 {
        return;
    }
    let frames = targets.len().checked_div(slots).unwrap_or(0);
    for t in 0..frames {
        let (l, r) = (targets[t * slots + left.slot], targets[t * slots + right.slot]);
        let (yl, yr) = (left.yaw(&quat(&l)), right.yaw(&quat(&r)));
        let yaw = (yl.sin() + yr.sin()).atan2(yl.cos() + yr.cos());
        let lateral = Vector3::new(-yaw.sin(), yaw.cos(), 0.0);
        let forward = Vector3::new(yaw.cos(), yaw.sin(), 0.0);
        // How far a flat sole turned to its own yaw reaches from its body origin along `axis`
        // (a foot turned across the other reaches further sideways than along the mean
        // heading: ToddlerBot's 12 cm feet, on the LAFAN1 walk's turns).
        let reach = |foot: &RobotFoot, foot_yaw: f64, axis: Vector3<f64>| {
            let flat = foot.flat(foot_yaw);
            foot.corners.iter().map(|c| (flat * c).dot(&axis)).fold(0.0, f64::max)
        };
        let apart = (l.pos - r.pos).dot(&lateral);
        let short = reach(left, yl, -lateral) + reach(right, yr, lateral) + gap - apart;
        if short <= 0.0 {
            continue;
        }
        let ahead = (l.pos - r.pos).dot(&forward);
        let clear = if ahead >= 0.0 {
            ahead - reach(left, yl, -forward) - reach(right, yr, forward)
        } else {
            -ahead - reach(left, yl, forward) - reach(right, yr, -forward)
        };
        let alongside =
            smoothstep(((gap + ALONGSIDE_FADE - clear) / ALONGSIDE_FADE).clamp(0.0, 1.0));
        let push = (short * alongside).min(MAX_WIDENING) / 2.0;
        targets[t * slots + left.slot].pos += lateral * push;
        targets[t * slots + right.slot].pos -= lateral * push;
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::UnitQuaternion;

    use super::*;
    use crate::feet::soles::fixtures::box_foot;

    #[test]
    fn feet_alongside_each_other_are_kept_apart_sideways() {
        let (left, mut right) = (box_foot(), box_foot());
        right.slot = 1;
        let at = |x: f64, y: f64| Pose { quat: [1.0, 0.0, 0.0, 0.0], pos: Vector3::new(x, y, 0.0) };
        let apart = |left_x: f64, left_y: f64, right_y: f64| {
            let mut targets = vec![at(left_x, left_y), at(0.0, right_y)];
            keep_feet_apart(&left, &right, &mut targets, 2, 0.03);
            (targets[0].pos - targets[1].pos, targets[0].pos.x - left_x)
        };
        // Side by side, 6 cm apart: soles 10 cm wide need 13 cm (half the push each).
        let (d, dx) = apart(0.0, 0.03, -0.03);
        assert!((d.y - 0.13).abs() < 1e-12 && d.x.abs() < 1e-12 && dx.abs() < 1e-12, "{d}");
        // Already far enough apart, or one well ahead of the other: left alone.
        assert!((apart(0.0, 0.1, -0.1).0.y - 0.2).abs() < 1e-12);
        assert!((apart(0.5, 0.03, -0.03).0.y - 0.06).abs() < 1e-12);
        // Crossed over by 20 cm: narrowed by at most MAX_WIDENING, not uncrossed.
        let (d, _) = apart(0.0, -0.1, 0.1);
        assert!((d.y - (-0.2 + MAX_WIDENING)).abs() < 1e-12, "{d}");
    }

    /// A foot turned across the other (a turn on the spot) reaches sideways by its own
    /// footprint, not by the footprint it would have facing the mean heading: the left foot
    /// turned 90° to the left (yaw ±45° about the mean, 20 × 10 cm soles) is moved until the
    /// two turned footprints are `gap` apart across the mean heading.
    #[test]
    fn a_foot_turned_across_the_other_is_kept_apart_by_its_own_footprint() {
        let (left, mut right) = (box_foot(), box_foot());
        right.slot = 1;
        let turned = |yaw: f64, y: f64| {
            let q = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw);
            let q = [q.w, q.i, q.j, q.k];
            Pose { quat: q, pos: Vector3::new(0.0, y, 0.0) }
        };
        let quarter = std::f64::consts::FRAC_PI_4;
        let mut targets = vec![turned(quarter, 0.08), turned(-quarter, -0.08)];
        keep_feet_apart(&left, &right, &mut targets, 2, 0.03);
        // Each turned sole reaches (0.1 + 0.05) cos 45° = 10.6 cm across the mean heading
        // (+x): 21.2 cm + the 3 cm gap between the origins.
        let need = 2.0 * 0.15 * quarter.cos() + 0.03;
        let d = targets[0].pos - targets[1].pos;
        assert!((d.y - need).abs() < 1e-12, "{d} against {need}");
        assert!(d.x.abs() < 1e-12, "{d}");
    }
}
