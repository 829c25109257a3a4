//! Swing: out of stance the sole keeps clear of the floor, the swing clearance reached over
//! [`FootPlanOptions::lift_s`] after lift-off and left over as long before touch-down; while
//! it rises (comes down), the sole points that stood on the floor at lift-off (stand on it at
//! touch-down) are held where they were (will be), seen from above: a foot leaves the floor
//! by lifting, not sliding, its last contact (after lift-off by the solve's grips too:
//! [`super::FootPlan::lifted_at`]).

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: frame and slot indices are bounded by `plan`'s `targets.len() / slots` and the contact
// labels' lengths, which `plan` clips to it.
#![allow(clippy::indexing_slicing)]

use super::math::{quat, smoothstep};
use super::plan_options::FootPlanOptions;
use super::soles::{RobotFoot, SolePoint};
use crate::lie::Pose;

/// Tolerance on a time in frames (seconds × fps), so that a time of a whole number of frames
/// is that many frames after rounding.
const ROUNDING: f64 = 1e-9;

/// What the swing asks of one foot in one frame out of stance.
#[derive(Debug, Clone, Default)]
pub(super) struct Swing {
    /// The sole points held horizontally while the foot rises or comes down.
    pub held: Vec<SolePoint>,
    /// The least height (m) of the sole's lowest point above the floor, where it asks any.
    pub floor: Option<f64>,
    /// The foot target raised to that floor, where the free target is below it.
    pub target: Option<Pose>,
}

/// Per frame, the [`Swing`] of `foot` (`None` in stance, `planted`): `free` is its free
/// target per frame, `targets` (`frames × slots`) hold its planted ones. A foot never planted
/// in the clip swings from the clip's first frame to its last (the source may stand on it
/// in its first and last frames): it clears the floor but in those two frames.
pub(super) fn swing(
    foot: &RobotFoot,
    planted: &[bool],
    free: &[Pose],
    targets: &[Pose],
    slots: usize,
    fps: f64,
    options: &FootPlanOptions,
) -> Vec<Option<Swing>> {
    let edges = swing_edges(planted);
    let never = !planted.contains(&true);
    // (1/30 s at 30 fps is one frame.)
    let lift_frames = (options.lift_s * fps - ROUNDING).ceil();
    (0..planted.len())
        .map(|t| {
            let (edge, frames_off) = if never {
                (None, t.min(planted.len() - 1 - t))
            } else {
                edges[t].filter(|_| !planted[t]).map(|(edge, off)| (Some(edge), off))?
            };
            let mut out = Swing::default();
            if let Some(edge) = edge.filter(|_| frames_off as f64 <= lift_frames) {
                let edge_pose = targets[edge * slots + foot.slot];
                out.held = held_points(foot, &edge_pose);
            }
            // (At 30 fps and 1/30 s, one frame is all the way up.)
            let rise = smoothstep((frames_off as f64 / (options.lift_s * fps) + ROUNDING).min(1.0));
            let height = options.swing_clearance * rise;
            if height <= 0.0 {
                return Some(out);
            }
            out.floor = Some(height);
            let mut pose = free[t];
            let low = height - pose.pos.z - foot.sole_offset(&quat(&pose));
            if low > 0.0 {
                pose.pos.z += low;
                out.target = Some(pose);
            }
            Some(out)
        })
        .collect()
}

/// The sole points a rising (or landing) foot holds where they stand at `edge` (its last or
/// first planted pose): those on the floor there ([`RobotFoot::contact_points`]), held
/// horizontally only, and as firmly in all as a planted sole's points (their shares' root sum
/// of squares 1). Kept at their shares of the whole sole, the two toe points of a foot that
/// lifts on its toes held half as firmly as a planted foot, and a foot whose human's turned
/// as it left the floor (the LAFAN1 jumps: up to 40° in the frame) slid them: 34 of the T1
/// jumps' 54 frames that skated on the floor were the frame before a lift-off or a touch-down.
fn held_points(foot: &RobotFoot, edge: &Pose) -> Vec<SolePoint> {
    let on_floor: Vec<SolePoint> =
        foot.contact_points(edge, 1.0).into_iter().filter(|p| p.vertical > 0.0).collect();
    let share = 1.0 / (on_floor.len().max(1) as f64).sqrt();
    on_floor.into_iter().map(|p| SolePoint { vertical: 0.0, horizontal: share, ..p }).collect()
}

/// Per frame out of stance, the nearer of the planted frames around it (the last before, the
/// first after; the earlier on a tie) and how many frames away it is; `None` in stance and
/// where the foot is never planted.
fn swing_edges(planted: &[bool]) -> Vec<Option<(usize, usize)>> {
    let mut out = vec![None; planted.len()];
    let mut last = None;
    for (t, &p) in planted.iter().enumerate() {
        if p {
            last = Some(t);
        } else if let Some(a) = last {
            out[t] = Some((a, t - a));
        }
    }
    let mut next = None;
    for (t, &p) in planted.iter().enumerate().rev() {
        if p {
            next = Some(t);
        } else if let Some(b) = next {
            if out[t].is_none_or(|(_, d)| b - t < d) {
                out[t] = Some((b, b - t));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use mjcf::GeomType;
    use nalgebra::{Isometry3, Vector3};

    use super::*;
    use crate::feet::soles::fixtures::box_foot;

    #[test]
    fn a_foot_rising_from_its_toes_holds_them_as_firmly_as_a_planted_sole() {
        let mut foot = box_foot();
        foot.sole = vec![(GeomType::Box, [0.1, 0.05, 0.02], Isometry3::identity())];
        // Heel up 10°: the two toe corners on the floor, the heel 3.5 cm above them.
        let q = nalgebra::UnitQuaternion::from_axis_angle(&Vector3::y_axis(), 0.17);
        let edge = Pose { quat: [q.w, q.i, q.j, q.k], pos: Vector3::new(0.0, 0.0, 0.05) };
        let held = held_points(&foot, &edge);
        assert_eq!(held.len(), 2);
        for p in &held {
            assert!(p.point.x > 0.0, "a toe point: {p:?}");
            assert!((p.horizontal - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-12, "{p:?}");
            assert_eq!(p.vertical, 0.0);
        }
    }
}
