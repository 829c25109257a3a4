//! Swing: out of stance the sole keeps clear of the floor, the swing clearance reached over
//! [`FootPlanOptions::lift_s`] after lift-off and left over as long before touch-down; while
//! it rises (comes down), the sole points that stood on the floor at lift-off (stand on it at
//! touch-down) are held where they were (will be), seen from above: a foot leaves the floor
//! by lifting, not sliding, its last contact.

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
    use crate::feet::{plan, FootPlan};
    use crate::motion::FootContacts;

    /// One step of a flat box foot (sole 2 cm below its origin) at `fps`: planted for the
    /// first and last third of a 1 s clip, in between it moves 0.5 m forward barely off the
    /// floor (1 cm at most). Returns the planned foot targets and the contact labels.
    fn low_step(fps: f64) -> (Vec<Pose>, Vec<bool>, FootPlan) {
        low_step_with(fps, &FootPlanOptions::default())
    }

    fn low_step_with(fps: f64, options: &FootPlanOptions) -> (Vec<Pose>, Vec<bool>, FootPlan) {
        let mut foot = box_foot();
        foot.sole = vec![(GeomType::Box, [0.1, 0.05, 0.02], Isometry3::identity())];
        let frames = fps as usize;
        let (lift, touch) = (frames / 3, 2 * frames / 3);
        let labels: Vec<bool> = (0..frames).map(|t| t < lift || t >= touch).collect();
        let mut targets: Vec<Pose> = (0..frames)
            .map(|t| {
                let u = ((t as f64 - lift as f64) / (touch - lift) as f64).clamp(0.0, 1.0);
                let pos =
                    Vector3::new(0.5 * u, 0.0, 0.02 + 0.01 * (std::f64::consts::PI * u).sin());
                Pose { quat: [1.0, 0.0, 0.0, 0.0], pos }
            })
            .collect();
        let contacts =
            FootContacts { left: labels.clone(), right: vec![false; frames], on_toes: None };
        let plan = plan(&[Some(foot), None], &contacts, &mut targets, 1, fps, options);
        (targets, labels, plan)
    }

    /// A foot the source never stands on in the clip (a 24-frame run cycle's, its toe
    /// brushing the floor at 4 m/s) swings from the clip's first frame to its last: it clears
    /// the floor but in those two frames, where it may be landing or leaving.
    #[test]
    fn a_foot_never_planted_clears_the_floor_between_the_clip_ends() {
        let options = FootPlanOptions::default();
        let mut foot = box_foot();
        foot.sole = vec![(GeomType::Box, [0.1, 0.05, 0.02], Isometry3::identity())];
        let (fps, frames) = (30.0, 24);
        let mut targets: Vec<Pose> = (0..frames)
            .map(|t| Pose {
                quat: [1.0, 0.0, 0.0, 0.0],
                pos: Vector3::new(4.0 * t as f64 / fps, 0.0, 0.02),
            })
            .collect();
        let contacts =
            FootContacts { left: vec![false; frames], right: vec![false; frames], on_toes: None };
        let plan = plan(&[Some(foot), None], &contacts, &mut targets, 1, fps, &options);
        for (t, target) in targets.iter().enumerate().take(frames - 1).skip(1) {
            assert_eq!(plan.swing_floor[t][0], Some(options.swing_clearance), "frame {t}");
            assert!(target.pos.z - 0.02 >= options.swing_clearance - 1e-9, "frame {t}");
            assert!(plan.contact[t][0].is_empty(), "nothing to hold: {t}");
        }
        assert!(plan.swing_floor[0][0].unwrap_or(0.0) < options.swing_clearance);
        assert!(plan.swing_floor[frames - 1][0].unwrap_or(0.0) < options.swing_clearance);
    }

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

    #[test]
    fn swing_feet_clear_the_floor_and_lift_before_they_move() {
        let options = FootPlanOptions::default();
        for fps in [30.0, 120.0] {
            let (targets, labels, plan) = low_step(fps);
            let sole = |p: &Pose| p.pos.z - 0.02;
            let lift = labels.iter().position(|c| !c).unwrap_or(0);
            let touch = lift + labels[lift..].iter().position(|c| *c).unwrap_or(0);
            let lead = (options.lead_s * fps).round() as usize;
            let rise = (options.lift_s * fps).round() as usize;
            // Planted frames rest on the floor.
            assert!((sole(&targets[lift - 1]) - options.clearance).abs() < 1e-9, "fps {fps}");
            for t in lift..touch - lead {
                let off = (t + 1 - lift).min(touch - lead - t);
                let floor = plan.swing_floor[t][0].unwrap_or(0.0);
                assert!(sole(&targets[t]) >= floor - 1e-9, "fps {fps} frame {t}");
                if off >= rise {
                    // Clear of the floor (the free target is 1 cm up at most).
                    assert!((floor - options.swing_clearance).abs() < 1e-9, "fps {fps} {t}");
                }
                if off > rise {
                    assert!(plan.contact[t][0].is_empty(), "fps {fps} frame {t}");
                } else {
                    // Rising or coming down: the sole points on the floor at the edge are
                    // held where they stand, horizontally only.
                    let anchor = if t - lift < touch - lead - t { lift - 1 } else { touch - lead };
                    let held = &plan.contact[t][0];
                    assert!(!held.is_empty(), "fps {fps} frame {t}");
                    // As firmly in all as a planted sole's points.
                    let rss = held.iter().map(|p| p.horizontal * p.horizontal).sum::<f64>();
                    assert!((rss - 1.0).abs() < 1e-9, "fps {fps} frame {t}: {rss}");
                    for p in held {
                        let at_edge = targets[anchor].pos + quat(&targets[anchor]) * p.point;
                        assert!(p.vertical == 0.0 && p.horizontal > 0.0);
                        assert!((p.at - at_edge).xy().norm() < 1e-9, "fps {fps} frame {t}");
                    }
                }
            }
            assert_eq!(plan.weight.len(), labels.len());
        }
    }
}
