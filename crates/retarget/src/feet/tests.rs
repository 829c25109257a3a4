//! Tests of the plan as a whole: a clip's contacts and targets through [`super::plan`],
//! checked at the stage that shaped them (anchors, stance, swing). The stage files test
//! their own functions; these call the plan they are a step of, so they live beside it.

use mjcf::GeomType;
use nalgebra::{Isometry3, UnitQuaternion, Vector3};

use super::math::quat;
use super::soles::fixtures::box_foot;
use super::{plan, FootPlan, FootPlanOptions, RobotFoot};
use crate::lie::Pose;
use crate::motion::FootContacts;

/// One stance phase of 30 frames whose source foot turns through `turn` (rad) about its
/// toe, standing flat: the planned foot targets and the foot.
fn turning_stance(turn: f64) -> (Vec<Pose>, RobotFoot) {
    let mut foot = box_foot();
    foot.sole = vec![(GeomType::Box, [0.1, 0.05, 0.02], Isometry3::identity())];
    let frames = 30;
    let toe = foot.toe_point();
    let mut targets: Vec<Pose> = (0..frames)
        .map(|t| {
            let yaw = turn * t as f64 / (frames - 1) as f64;
            let q = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw);
            // The toe stays at (0.1, 0, ·): the origin turns about it.
            let pos = Vector3::new(toe.x, toe.y, 0.02) - q * Vector3::new(toe.x, toe.y, 0.0);
            Pose { quat: [q.w, q.i, q.j, q.k], pos }
        })
        .collect();
    let contacts =
        FootContacts { left: vec![true; frames], right: vec![false; frames], on_toes: None };
    let options = FootPlanOptions::default();
    plan(&[Some(foot.clone()), None], &contacts, &mut targets, 1, 30.0, &options);
    (targets, foot)
}

#[test]
fn a_foot_that_turns_far_in_stance_pivots_about_its_ball() {
    let yaw = |p: &Pose| quat(p).euler_angles().2;
    // 90°: the planted (left) foot turns with the source's about the ball of its foot,
    // the inner toe corner, which stays still.
    let (targets, foot) = turning_stance(std::f64::consts::FRAC_PI_2);
    assert_eq!(foot.ball_point(0), Vector3::new(0.1, -0.05, -0.02));
    let ball = |p: &Pose| p.pos + quat(p) * foot.ball_point(0);
    let first = ball(&targets[0]);
    for (t, p) in targets.iter().enumerate() {
        let expected = std::f64::consts::FRAC_PI_2 * t as f64 / 29.0;
        assert!((yaw(p) - expected).abs() < 1e-9, "frame {t}: yaw {}", yaw(p));
        let moved = (ball(p) - first).xy().norm();
        assert!(moved < 1e-9, "frame {t}: the ball moved {moved} m");
    }
    // 20°, under `pivot_turn`: one yaw for the whole phase (the mean), the foot still.
    let (targets, _) = turning_stance(20f64.to_radians());
    for p in &targets {
        assert!((yaw(p) - 10f64.to_radians()).abs() < 1e-6, "yaw {}", yaw(p));
        assert!((p.pos - targets[0].pos).norm() < 1e-9);
    }
}

#[test]
fn a_fast_pivot_turns_on_the_ball_of_the_foot_with_its_heel_up() {
    let lift = FootPlanOptions::default().pivot_heel_lift;
    let heel_over_toe = |p: &Pose, foot: &RobotFoot| {
        let z: Vec<f64> = foot.corners.iter().map(|c| (p.pos + quat(p) * c).z).collect();
        (z[0] + z[1]) / 2.0 - (z[2] + z[3]) / 2.0
    };
    // 90° in 1 s: flat, the 20 cm sole's heel would sweep the floor at 0.3 m/s.
    let (targets, foot) = turning_stance(std::f64::consts::FRAC_PI_2);
    for (t, p) in targets.iter().enumerate() {
        let up = heel_over_toe(p, &foot);
        assert!((up - lift).abs() < 1e-9, "frame {t}: heel {up} m above the toe");
        // It stands on the ball alone (the inner toe corner), its outer toe corner up.
        let low = targets[t].pos.z + (quat(p) * foot.corners[2]).z;
        assert!(
            (low - FootPlanOptions::default().clearance).abs() < 1e-9,
            "frame {t}: ball at {low}"
        );
        // (CONTACT_PATCH across the sole, pitched heel up: cos 5.7° of it.)
        let outer = targets[t].pos.z + (quat(p) * foot.corners[3]).z;
        assert!(
            (outer - low - super::soles::CONTACT_PATCH).abs() < 1e-4,
            "frame {t}: outer toe {} m above the ball",
            outer - low
        );
    }
    // A slow pivot, 46° in 1 s (0.16 m/s, under `pivot_heel_speed`), lifts it part of the
    // way.
    let (slow, foot) = turning_stance(46f64.to_radians());
    let up = heel_over_toe(&slow[15], &foot);
    assert!(up > 0.0 && up < lift, "slow pivot: heel {up} m up");
}

/// A planted foot whose human foot stands 10° toes-down: alone on the floor it stands
/// on its whole sole (corners within the band); while the other foot stands too, it
/// rolls with the human's.
#[test]
fn a_foot_alone_on_the_floor_stands_on_its_whole_sole() {
    let options = FootPlanOptions::default();
    let mut foot = box_foot();
    foot.sole = vec![(GeomType::Box, [0.1, 0.05, 0.02], Isometry3::identity())];
    let fps = 30.0;
    let frames = 60;
    let toes_down = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), 0.17);
    let q = toes_down.quaternion();
    let tilted = Pose { quat: [q.w, q.i, q.j, q.k], pos: Vector3::new(0.0, 0.0, 0.05) };
    let beside = Pose { quat: [1.0, 0.0, 0.0, 0.0], pos: Vector3::new(0.0, 0.3, 0.02) };
    let mut targets: Vec<Pose> = (0..frames).flat_map(|_| [tilted, beside]).collect();
    // The right foot stands in the second half only.
    let contacts = FootContacts {
        left: vec![true; frames],
        right: (0..frames).map(|t| t >= 30).collect(),
        on_toes: None,
    };
    let feet = [Some(foot.clone()), Some(RobotFoot { slot: 1, ..foot.clone() })];
    plan(&feet, &contacts, &mut targets, 2, fps, &options);
    let spread = |p: &Pose| foot.height_spread(&quat(p));
    assert!(spread(&targets[10 * 2]) <= options.sole_band + 1e-9, "{}", spread(&targets[20]));
    // Deep in the double support: the human's 10°, its corners 3.5 cm apart in height.
    assert!(spread(&targets[45 * 2]) > 0.03, "{}", spread(&targets[90]));
}

/// A foot alone on the floor whose human stands on its toes, 40° toe-down (kneeling,
/// tiptoe), in the second half: there the sole's heel stands as high above its toes as
/// the human's (sole length × sin 40°) and its front rests on the floor at the anchor;
/// in the first half it stands on its whole sole. Without the label, whole sole
/// throughout.
#[test]
fn a_foot_whose_human_stands_on_its_toes_stands_on_the_front_of_its_sole() {
    let options = FootPlanOptions::default();
    let mut foot = box_foot();
    foot.sole = vec![(GeomType::Box, [0.1, 0.05, 0.02], Isometry3::identity())];
    let frames = 60;
    let toes_down = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), 40f64.to_radians());
    let q = toes_down.quaternion();
    let tilted = Pose { quat: [q.w, q.i, q.j, q.k], pos: Vector3::new(0.0, 0.0, 0.1) };
    let beside = Pose { quat: [1.0, 0.0, 0.0, 0.0], pos: Vector3::new(0.0, 0.3, 0.5) };
    let feet = [Some(foot.clone()), None];
    let planned = |on_toes: Option<[Vec<bool>; 2]>| {
        let mut targets: Vec<Pose> = (0..frames).flat_map(|_| [tilted, beside]).collect();
        let contacts =
            FootContacts { left: vec![true; frames], right: vec![false; frames], on_toes };
        plan(&feet, &contacts, &mut targets, 2, 30.0, &options);
        targets
    };
    let heights =
        |p: &Pose| -> Vec<f64> { foot.corners.iter().map(|c| (quat(p) * c + p.pos).z).collect() };
    let lift = |p: &Pose| foot.height_spread(&quat(p));
    let toes: Vec<bool> = (0..frames).map(|t| t >= 30).collect();
    let on_toes = planned(Some([toes, vec![false; frames]]));
    let human = 0.2 * 40f64.to_radians().sin();
    assert!(lift(&on_toes[10 * 2]) <= options.sole_band + 1e-9, "{}", lift(&on_toes[20]));
    assert!((lift(&on_toes[50 * 2]) - human).abs() < 1e-6, "{} vs {human}", lift(&on_toes[100]));
    let lowest = heights(&on_toes[50 * 2]).into_iter().fold(f64::INFINITY, f64::min);
    assert!((lowest - options.clearance).abs() < 1e-9, "{lowest}");
    let flat = planned(None);
    assert!(lift(&flat[50 * 2]) <= options.sole_band + 1e-9, "{}", lift(&flat[100]));
}

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
            let pos = Vector3::new(0.5 * u, 0.0, 0.02 + 0.01 * (std::f64::consts::PI * u).sin());
            Pose { quat: [1.0, 0.0, 0.0, 0.0], pos }
        })
        .collect();
    let contacts = FootContacts { left: labels.clone(), right: vec![false; frames], on_toes: None };
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
