//! Crossed stances: overlapping stance phases with the left foot planted to the right of the
//! right one ([`Crossing`]), found after the anchors are kept apart, and moved apart across the
//! robot's heading where the solve asks ([`Uncrossing`], [`super::plan_uncrossing`]).

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: frame and slot indices are bounded by `plan`'s `targets.len() / slots` and the contact
// labels' lengths, which `plan` clips to it.
#![allow(clippy::indexing_slicing)]

use std::ops::Range;

use nalgebra::Vector3;

use super::anchors::Planted;
use super::soles::RobotFoot;

/// Two stance phases, one per foot, that overlap in time with the feet crossed: the left
/// foot's footprint centre is to the right of the right one's (across the robot's heading,
/// [`plan_uncrossing`](super::plan_uncrossing)).
/// The human steps over like this in a crossover or a turn; a robot whose legs are too thick
/// for it cannot stand there with both feet down (the T1 in the LAFAN1 walk's crouched
/// crossover steps) and is uncrossed ([`plan_uncrossing`](super::plan_uncrossing)).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Crossing {
    /// First frames of the left and the right foot's stance phase (with the lead).
    pub phases: (usize, usize),
    /// The frames both are planted.
    pub frames: Range<usize>,
}

/// Which crossed stances [`plan_uncrossing`](super::plan_uncrossing) uncrosses, and across what.
#[derive(Debug, Clone, Copy, Default)]
pub struct Uncrossing<'a> {
    /// The [`Crossing::phases`] to move apart.
    pub uncross: &'a [(usize, usize)],
    /// Per frame, the yaw (rad) the robot's pelvis is to face; empty: the two feet's mean
    /// yaw.
    pub heading: &'a [f64],
}

/// The crossed pairs of overlapping stance phases ([`Crossing`]), found after [`super::anchors::separate`];
/// those listed in `uncross` are moved apart across the heading, half the way each,
/// until the left footprint is `gap` to the left of the right one.
pub(super) fn uncrossed(
    left: &RobotFoot,
    right: &RobotFoot,
    anchors: &mut [Vec<Planted>; 2],
    gap: f64,
    uncross: &[(usize, usize)],
    heading: &[f64],
) -> Vec<Crossing> {
    let mut out = Vec::new();
    if left.corners.is_empty() || right.corners.is_empty() || gap.is_nan() {
        return out;
    }
    let [lefts, rights] = anchors;
    for (lr, lxy, lyaw) in lefts.iter_mut() {
        for (rr, rxy, ryaw) in rights.iter_mut() {
            let frames = lr.start.max(rr.start)..lr.end.min(rr.end);
            if frames.is_empty() {
                continue;
            }
            // Across the pelvis's heading over the overlap (the legs hang from it; a foot
            // pivoting in its stance turns the feet's mean heading away from it), else the
            // feet's mean heading. (On the T1's LAFAN1 walk with the derived config, 4 stuck
            // crossings against 5 by the feet's heading, foot error 26.6 → 26.0 mm.)
            let yaw = match heading.get(frames.clone()) {
                Some(h) if !h.is_empty() => {
                    let (s, c) = h.iter().fold((0.0, 0.0), |(s, c), y| (s + y.sin(), c + y.cos()));
                    s.atan2(c)
                }
                _ => (lyaw.sin() + ryaw.sin()).atan2(lyaw.cos() + ryaw.cos()),
            };
            let across = Vector3::new(-yaw.sin(), yaw.cos(), 0.0);
            // The footprints' extents across the heading: the left one's least, the right
            // one's greatest.
            let extent = |foot: &RobotFoot, xy: &Vector3<f64>, foot_yaw: f64| {
                let flat = foot.flat(foot_yaw);
                let at = |c: &Vector3<f64>| (Vector3::new(xy.x, xy.y, 0.0) + flat * c).dot(&across);
                let (lo, hi) = foot
                    .corners
                    .iter()
                    .map(at)
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
                (lo, hi, (lo + hi) / 2.0)
            };
            let (l_lo, _, l_mid) = extent(left, lxy, *lyaw);
            let (_, r_hi, r_mid) = extent(right, rxy, *ryaw);
            if l_mid >= r_mid {
                continue;
            }
            let phases = (lr.start, rr.start);
            if uncross.contains(&phases) {
                // Half the way each. (Moving only the foot that stepped into the crossed stance
                // set the T1's feet wide apart in its crouch: its pelvis then dropped more than
                // 5 cm below its target in 35 frames of the LAFAN1 walk, against 2.)
                let short = gap + r_hi - l_lo;
                *lxy += across * (short / 2.0);
                *rxy -= across * (short / 2.0);
            }
            out.push(Crossing { phases, frames });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::feet::soles::fixtures::box_foot;

    #[test]
    fn crossed_stances_are_found_and_uncrossed_on_request() {
        let foot = box_foot();
        // Facing +x, the left foot planted 4 cm to the right of the right one (10 cm wide
        // soles), 25 cm behind it, over frames 0..10 and 5..15; a later pair is not crossed.
        let mut anchors = [
            vec![
                (0..10, Vector3::new(0.0, -0.02, 0.0), 0.0),
                (20..30, Vector3::new(1.0, 0.1, 0.0), 0.0),
            ],
            vec![
                (5..15, Vector3::new(0.25, 0.02, 0.0), 0.0),
                (25..35, Vector3::new(1.2, -0.1, 0.0), 0.0),
            ],
        ];
        let found = uncrossed(&foot, &foot, &mut anchors.clone(), 0.03, &[], &[]);
        assert_eq!(found, vec![Crossing { phases: (0, 5), frames: 5..10 }]);
        let again = uncrossed(&foot, &foot, &mut anchors, 0.03, &[(0, 5)], &[]);
        assert_eq!(again, found);
        // Each moves half of 4 + 10 + 3 cm sideways: the left sole's right edge is 3 cm to
        // the left of the right sole's left edge.
        let (left, right) = (anchors[0][0].1, anchors[1][0].1);
        assert!((left.y - 0.065).abs() < 1e-12, "{left}");
        assert!((right.y + 0.065).abs() < 1e-12, "{right}");
        assert!((left.x, right.x) == (0.0, 0.25));
        assert_eq!(anchors[0][1].1, Vector3::new(1.0, 0.1, 0.0));
    }
}
