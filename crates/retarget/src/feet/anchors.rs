//! Where a planted foot stands in each stance phase: its anchor (the phase's mean or first
//! position and yaw, [`Anchor`]), the shin's say in its yaw (`convention_turn`), anchors of
//! overlapping phases kept apart (`separate`), and a pivot's anchor turning about the toe.

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: frame indices are bounded by the free targets' length (`frames`), which the
// stance phases are clipped to; slots come from the target layout.
#![allow(clippy::indexing_slicing)]

use std::ops::Range;

use nalgebra::{UnitQuaternion, Vector3};

use super::math::{quat, wrap};
use super::plan_options::Anchor;
use super::soles::RobotFoot;
use crate::contact_phases::phases;
use crate::lie::Pose;

/// A stance phase (frames) with its anchor: the flat foot's horizontal position and yaw.
pub(super) type Planted = (Range<usize>, Vector3<f64>, f64);

/// A shin and a foot target whose yaws differ by more than this (rad) over the clip face
/// apart: the difference is a frame convention of the config, not the human's toe-out
/// (`convention_turn`).
const FACING_APART: f64 = std::f64::consts::FRAC_PI_2;

/// Stance phases of one foot's source `label` (each begun `lead` frames early) and their
/// anchors, from the foot's `free` targets (one per frame) and the shin's in `targets`
/// (`frames × slots`).
pub(super) fn foot_anchors(
    foot: &RobotFoot,
    label: &[bool],
    free: &[Pose],
    targets: &[Pose],
    slots: usize,
    lead: usize,
    kind: Anchor,
) -> Vec<Planted> {
    let phase_list: Vec<Range<usize>> =
        phases(label).into_iter().map(|r| r.start.saturating_sub(lead)..r.end).collect();
    let shin = shin_feet(foot, free, targets, slots);
    phase_list
        .into_iter()
        .map(|r| {
            let (xy, yaw) = anchor(foot, free, &shin, r.clone(), kind);
            (r, xy, yaw)
        })
        .collect()
}

/// Per frame, the foot orientation the shin's target implies (the ankle straight), where the
/// foot has a shin.
fn shin_feet(
    foot: &RobotFoot,
    free: &[Pose],
    targets: &[Pose],
    slots: usize,
) -> Vec<Option<UnitQuaternion<f64>>> {
    let frames = free.len();
    let mut shin: Vec<Option<UnitQuaternion<f64>>> = (0..frames)
        .map(|t| foot.shin.map(|(slot, rel)| quat(&targets[t * slots + slot]) * rel))
        .collect();
    // The config's shin and foot offsets need not agree about yaw (Toddy's left calf and
    // toe targets disagree by 177°, with GMR's config and with ours): turn the shin's by
    // the half turn of their mean difference over the clip, if any
    // (`convention_turn`), so that a frame convention never outvotes the foot, while the
    // human's toe-out stays and the planted yaw shares it between the foot and the leg
    // above, as GMR's solve does. (Turned by the whole difference, the planted yaw was
    // the foot's, and a robot without an ankle yaw turned the whole leg to it.)
    let (mut s, mut c) = (0.0, 0.0);
    for (t, q) in shin.iter().enumerate() {
        if let Some(q) = q {
            let d = wrap(foot.yaw(q) - foot.yaw(&quat(&free[t])));
            (s, c) = (s + d.sin(), c + d.cos());
        }
    }
    let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), -convention_turn(s.atan2(c)));
    for q in shin.iter_mut().flatten() {
        *q = turn * *q;
    }
    shin
}

/// The part of a mean yaw difference (rad) between a foot's target and the foot its shin's
/// target implies that comes from the config's frames, not from the human: a half turn
/// where the two face apart (ToddlerBot's left calf and toe, 177° with GMR's config and with
/// ours), none otherwise. A human foot turns out from its shin by a few degrees (the LAFAN1
/// walk 3–4°, CMU 131_01 6–9°, the Bandai walk's right foot 18°, its kick 20–28°; the first
/// 15 s of the Bandai dance 46°, where its left foot turns on the floor), and that is
/// kept: removing it planted the foot at its own yaw, which a leg without an ankle yaw can
/// only follow by turning the hip, knee and foot together (the G1 on the Bandai walk:
/// rotation error 4.13° against `--gmr`'s 3.35°; 3.45° with the toe-out kept). (Rounding to
/// the nearest quarter turn instead turned that dance's left shin by 90°: the leg's rotation
/// error went from 0.75 to 1.07 rad.)
fn convention_turn(mean: f64) -> f64 {
    if mean.abs() > FACING_APART {
        std::f64::consts::PI.copysign(mean)
    } else {
        0.0
    }
}

/// Anchor of one phase: the yaw (circular mean or first frame of the free targets' yaws),
/// then the horizontal position of the flat foot that, rolled over its sole's lowest point
/// to each free target's tilt, puts the foot origin where the free target is (its mean over
/// the phase, or its first frame): a foot rolling from heel to toe without slipping has one
/// such position.
fn anchor(
    foot: &RobotFoot,
    free: &[Pose],
    shin: &[Option<UnitQuaternion<f64>>],
    range: Range<usize>,
    kind: Anchor,
) -> (Vector3<f64>, f64) {
    let frames: Vec<usize> = match kind {
        Anchor::PhaseStart => vec![range.start],
        Anchor::PhaseMean => range.collect(),
    };
    let (mut s, mut c) = (0.0, 0.0);
    for &t in &frames {
        let yaws = std::iter::once(foot.yaw(&quat(&free[t]))).chain(shin[t].map(|q| foot.yaw(&q)));
        for yaw in yaws {
            (s, c) = (s + yaw.sin(), c + yaw.cos());
        }
    }
    let yaw = s.atan2(c);
    let flat = foot.flat(yaw);
    let mut sum = Vector3::zeros();
    for &t in &frames {
        let q = anchored(foot, &free[t], yaw);
        let low = foot.sole_low_point(&q);
        sum += free[t].pos + q * low - flat * low;
    }
    (sum / frames.len().max(1) as f64, yaw)
}

/// The free target's orientation turned about world z to yaw `yaw`.
pub(super) fn anchored(foot: &RobotFoot, free: &Pose, yaw: f64) -> UnitQuaternion<f64> {
    let q = quat(free);
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), wrap(yaw - foot.yaw(&q))) * q
}

/// How far (rad) `yaws` turn: the largest minus the smallest of their differences from
/// `reference` (wrapped), 0 for none.
pub(super) fn turn_of(yaws: &[f64], reference: f64) -> f64 {
    let d = yaws.iter().map(|y| wrap(y - reference));
    let (lo, hi) = d.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if lo <= hi {
        hi - lo
    } else {
        0.0
    }
}

/// The flat foot's horizontal position (`xy` at `yaw0`) turned to `yaw` about `c` (a point of
/// the foot, foot frame: the ball a pivot turns on, [`RobotFoot::ball_point`]).
pub(super) fn pivot(
    foot: &RobotFoot,
    c: Vector3<f64>,
    xy: Vector3<f64>,
    yaw0: f64,
    yaw: f64,
) -> Vector3<f64> {
    let d = foot.flat(yaw0) * c - foot.flat(yaw) * c;
    Vector3::new(xy.x + d.x, xy.y + d.y, xy.z)
}

/// Sweeps of `separate` over the overlapping stance phases: a phase moved for one of the other
/// foot's can come too close to another, and three settle such chains.
const SEPARATE_SWEEPS: usize = 3;

/// Moves the anchors of stance phases that overlap in time apart until the flat soles'
/// footprints (their bottom points at the anchors) are at least `gap` apart along one of the
/// footprints' edge directions (the separating axis along which they are furthest apart, so
/// the shortest way apart: sideways for feet side by side, forwards for one behind the
/// other): each moves half the shortfall, along that axis. Separation along an axis bounds
/// the true gap from below, so the result is conservative. A phase that
/// overlaps several of the other foot's is moved for each ([`SEPARATE_SWEEPS`] sweeps settle
/// chains).
/// Soles without bottom points have no footprint and are left alone.
pub(super) fn separate(
    left: &RobotFoot,
    right: &RobotFoot,
    anchors: &mut [Vec<Planted>; 2],
    gap: f64,
) {
    if left.corners.is_empty() || right.corners.is_empty() || gap.is_nan() {
        return;
    }
    let footprint = |foot: &RobotFoot, xy: &Vector3<f64>, yaw: f64| -> Vec<Vector3<f64>> {
        let flat = foot.flat(yaw);
        foot.corners.iter().map(|c| Vector3::new(xy.x, xy.y, 0.0) + flat * c).collect()
    };
    let [lefts, rights] = anchors;
    for _ in 0..SEPARATE_SWEEPS {
        for (lr, lxy, lyaw) in lefts.iter_mut() {
            for (rr, rxy, ryaw) in rights.iter_mut() {
                if lr.end <= rr.start || rr.end <= lr.start {
                    continue;
                }
                let (a, b) = (footprint(left, lxy, *lyaw), footprint(right, rxy, *ryaw));
                // Separating-axis test over both footprints' edge directions: the axis with
                // the largest separation is the shortest way apart.
                let axes = [*lyaw, *ryaw].map(|yaw| {
                    let (s, c) = yaw.sin_cos();
                    [Vector3::new(c, s, 0.0), Vector3::new(-s, c, 0.0)]
                });
                let centre = |p: &[Vector3<f64>]| p.iter().sum::<Vector3<f64>>() / p.len() as f64;
                let apart = centre(&b) - centre(&a);
                let (d, separation) = axes
                    .iter()
                    .flatten()
                    .map(|u| {
                        let d = if apart.dot(u) < 0.0 { -u } else { *u };
                        let reach = a.iter().map(|p| p.dot(&d)).fold(f64::NEG_INFINITY, f64::max);
                        let start = b.iter().map(|p| p.dot(&d)).fold(f64::INFINITY, f64::min);
                        (d, start - reach)
                    })
                    .fold((Vector3::zeros(), f64::NEG_INFINITY), |best, x| {
                        if x.1 > best.1 {
                            x
                        } else {
                            best
                        }
                    });
                let short = gap - separation;
                if short > 0.0 {
                    *lxy -= d * (short / 2.0);
                    *rxy += d * (short / 2.0);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::feet::soles::fixtures::box_foot;

    #[test]
    fn planted_soles_are_kept_apart() {
        let foot = box_foot();
        // Both planted over frames 5..15, side by side 6 cm apart: the soles overlap by 4 cm.
        // A third, later left phase does not overlap any right one and stays.
        let mut anchors = [
            vec![
                (0..10, Vector3::new(0.0, 0.03, 0.0), 0.0),
                (20..30, Vector3::new(1.0, 0.0, 0.0), 0.0),
            ],
            vec![(5..15, Vector3::new(0.0, -0.03, 0.0), 0.0)],
        ];
        separate(&foot, &foot, &mut anchors, 0.02);
        let (left, right) = (anchors[0][0].1, anchors[1][0].1);
        // Centres 6 cm apart, footprints 10 cm wide: 6 cm short of a 2 cm gap, 3 cm each.
        assert!((left.y - 0.06).abs() < 1e-12, "{left}");
        assert!((right.y + 0.06).abs() < 1e-12, "{right}");
        assert_eq!(anchors[0][1].1, Vector3::new(1.0, 0.0, 0.0));
        // Already apart: nothing moves.
        let before = anchors.clone();
        separate(&foot, &foot, &mut anchors, 0.02);
        assert_eq!(anchors, before);
    }

    #[test]
    fn only_a_frame_convention_is_turned_away() {
        let deg = f64::to_radians;
        assert!((convention_turn(deg(177.0)) - deg(180.0)).abs() < 1e-12, "Toddy's left calf");
        assert!((convention_turn(deg(-170.0)) + deg(180.0)).abs() < 1e-12);
        for toe_out in [3.7, -3.0, 18.3, -46.3, 60.0] {
            assert_eq!(convention_turn(deg(toe_out)), 0.0, "{toe_out}° is the human's");
        }
    }
}
