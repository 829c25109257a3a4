//! Foot contact phases of the source (the human), per foot and per frame.
//!
//! A foot is watched through up to two points: its heel (the ankle / foot joint) and its toe
//! (the toe joint). Each point's height is measured above its own floor level, the
//! [`ContactOptions::floor_percentile`] of its z over the clip (a planted heel joint sits
//! some centimetres above the ground, a planted toe joint less; a low percentile finds each
//! one's planted height without knowing the skeleton, and ignores outliers), and its
//! horizontal speed is the central difference of x, y (m/s, one-sided at the ends).
//!
//! A point *grips* when it is lower than `height_on` and slower than `speed_on`; it *holds*
//! when lower than `height_off` and slower than `speed_off` (hysteresis: `*_off ≥ *_on`). A
//! foot enters contact when one of its points grips and leaves it when none holds. Then
//! gaps shorter than [`ContactOptions::min_phase_s`] inside contact are filled, and contact
//! phases shorter than it are dropped (but where the clip's first or last frame cuts them
//! short), so one noisy frame neither splits a stance nor makes a step. A foot in contact
//! whose toe holds and heel does not stands on its toes ([`FootContacts::on_toes`]:
//! kneeling, tiptoe, a turn on the ball of the foot, push-off).
//!
//! [`treadmill`]: a source whose lowest foot point slides back on the floor faster than a
//! foot grips, while its root stays, is an in-place loop; the default solve takes it off
//! the belt ([`off_treadmill`]) before anything else.

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: per-frame buffers are built here with the motion's frame count, which
// `HumanMotion::validate` checked against its arrays.
#![allow(clippy::indexing_slicing)]

use std::collections::BTreeMap;

use fk::{HumanMotion, Role};
use nalgebra::{Vector2, Vector3};

use crate::motion::FootContacts;

/// Tunables of the contact detection (`detect`); lengths in metres, speeds in m/s, in the source's (human) scale.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ContactOptions {
    pub height_on: f64,
    pub height_off: f64,
    pub speed_on: f64,
    pub speed_off: f64,
    /// Shortest contact phase and shortest gap inside one (seconds).
    pub min_phase_s: f64,
    /// Percentile (0–1) of a point's height over the clip taken as its floor level.
    pub floor_percentile: f64,
}

impl Default for ContactOptions {
    fn default() -> Self {
        ContactOptions {
            height_on: 0.025,
            height_off: 0.045,
            speed_on: 0.2,
            speed_off: 0.35,
            min_phase_s: 0.1,
            floor_percentile: 0.02,
        }
    }
}

/// The human bodies that show where one foot is: heel (ankle or foot joint) and toe.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FootPoints {
    pub heel: usize,
    pub toe: Option<usize>,
}

/// The heel and toe bodies of each foot (`[left, right]`) among the human body names: the
/// joints playing the foot and toe roles in `roles` (the skeleton recogniser's, any naming
/// convention: `fk::recognise`), else by the common names (LAFAN1, Mixamo-style, CMU, Xsens,
/// C3D marker bodies, for motions given without roles); `None` when a heel is missing.
#[must_use]
pub fn human_foot_points(
    names: &[String],
    roles: &BTreeMap<Role, String>,
) -> Option<[FootPoints; 2]> {
    let find = |candidates: &[&str]| {
        candidates.iter().find_map(|c| names.iter().position(|n| n.eq_ignore_ascii_case(c)))
    };
    let by_role =
        |role: Role| roles.get(&role).and_then(|joint| names.iter().position(|n| n == joint));
    let side = |s: &str, foot: Role, toe: Role| -> Option<FootPoints> {
        if let Some(heel) = by_role(foot) {
            return Some(FootPoints { heel, toe: by_role(toe) });
        }
        let heel = find(&[&format!("{s}Foot"), &format!("{s}Ankle")])?;
        let toe = find(&[&format!("{s}ToeBase"), &format!("{s}Toe"), &format!("{s}Toes")]);
        Some(FootPoints { heel, toe })
    };
    Some([
        side("Left", Role::LeftFoot, Role::LeftToe)?,
        side("Right", Role::RightFoot, Role::RightToe)?,
    ])
}

/// Contact phases of both feet (`[left, right]`) over the clip.
#[must_use]
pub fn detect(
    human: &HumanMotion,
    feet: [FootPoints; 2],
    options: &ContactOptions,
) -> FootContacts {
    let [(left, left_toes), (right, right_toes)] = feet.map(|f| foot_contact(human, f, options));
    let on_toes = match (left_toes, right_toes) {
        (Some(l), Some(r)) => Some([l, r]),
        _ => None,
    };
    FootContacts { left, right, on_toes }
}

/// One foot's contact labels, and where it has a toe point, the frames of contact in which
/// it stands on its toes alone: its toe holds and its heel does not (the same thresholds),
/// runs shorter than [`ContactOptions::min_phase_s`] filled as the contact's are.
fn foot_contact(
    human: &HumanMotion,
    foot: FootPoints,
    o: &ContactOptions,
) -> (Vec<bool>, Option<Vec<bool>>) {
    let n = human.num_frames;
    let points: Vec<PointTrack> = std::iter::once(foot.heel)
        .chain(foot.toe)
        .map(|b| PointTrack::new(human, b, o.floor_percentile))
        .collect();
    let mut contact = vec![false; n];
    let mut on = false;
    for (t, c) in contact.iter_mut().enumerate() {
        on = if on {
            points.iter().any(|p| p.holds(t, o))
        } else {
            points.iter().any(|p| p.grips(t, o))
        };
        *c = on;
    }
    let min_frames = (o.min_phase_s * human.fps).round().max(1.0) as usize;
    settle(&mut contact, min_frames);
    let on_toes = match points.as_slice() {
        [heel, toe] => {
            let mut toes: Vec<bool> =
                (0..n).map(|t| contact[t] && toe.holds(t, o) && !heel.holds(t, o)).collect();
            settle(&mut toes, min_frames);
            Some(toes.iter().zip(&contact).map(|(a, c)| *a && *c).collect())
        }
        _ => None,
    };
    (contact, on_toes)
}

/// Labels with their gaps and runs shorter than `min` frames filled and dropped
/// ([`fill_short_runs`], gaps first).
fn settle(labels: &mut [bool], min: usize) {
    fill_short_runs(labels, false, min);
    fill_short_runs(labels, true, min);
}

/// Runs of `value` shorter than `min` frames become `!value`, but those that the clip's
/// first or last frame cuts short: gaps (`value == false`) only when enclosed by contact on
/// both sides, contacts only when they neither begin nor end the clip (a foot landing in the
/// clip's last frames stands past it).
fn fill_short_runs(labels: &mut [bool], value: bool, min: usize) {
    let n = labels.len();
    let mut t = 0;
    while t < n {
        if labels[t] != value {
            t += 1;
            continue;
        }
        let start = t;
        while t < n && labels[t] == value {
            t += 1;
        }
        let enclosed = start > 0 && t < n;
        if t - start < min && enclosed {
            labels[start..t].fill(!value);
        }
    }
}

/// The velocity (m/s, x y) of the floor under the source's feet where they slide back on it
/// as on a treadmill (an in-place loop: a walk cycle exported without its root's travel),
/// `None` where they stand on a floor that stays put.
///
/// Per frame, the lowest of the feet's points (above its own floor level, as for contacts)
/// is the one the body stands on; where it is on the floor (lower than `height_off`), its
/// velocity is a sample of the floor's. Their median (per axis) is the belt's velocity
/// when it is at least `speed_on` (faster than a foot grips) while the root does not travel
/// with it that fast (a moonwalk slides its feet back and goes back with them). Needs
/// [`ContactOptions::min_phase_s`] of samples.
#[must_use]
pub fn treadmill(
    human: &HumanMotion,
    feet: [FootPoints; 2],
    root: usize,
    options: &ContactOptions,
) -> Option<Vector2<f64>> {
    let n = human.num_frames;
    let points: Vec<PointTrack> = feet
        .iter()
        .flat_map(|f| std::iter::once(f.heel).chain(f.toe))
        .map(|b| PointTrack::new(human, b, options.floor_percentile))
        .collect();
    let mut samples: [Vec<f64>; 2] = Default::default();
    for t in 0..n {
        let lowest = points.iter().min_by(|a, b| a.height[t].total_cmp(&b.height[t]))?;
        if lowest.height[t] < options.height_off {
            samples[0].push(lowest.velocity[t].x);
            samples[1].push(lowest.velocity[t].y);
        }
    }
    if (samples[0].len() as f64) < options.min_phase_s * human.fps {
        return None;
    }
    let [x, y] = samples.map(|mut s| {
        s.sort_by(f64::total_cmp);
        s[s.len() / 2]
    });
    let belt = Vector2::new(x, y);
    let speed = belt.norm();
    let nb = human.num_bodies();
    let duration = (n.saturating_sub(1)) as f64 / human.fps;
    let travel = (human.positions[(n - 1) * nb + root] - human.positions[root]).xy();
    let with_belt = if duration > 0.0 { travel.dot(&belt) / speed / duration } else { 0.0 };
    (speed >= options.speed_on && with_belt < options.speed_on).then_some(belt)
}

/// `human` on a floor that stays put: every position moved against the `belt`'s velocity
/// ([`treadmill`]) by as far as the belt has run since the first frame.
#[must_use]
pub fn off_treadmill(human: &HumanMotion, belt: Vector2<f64>) -> HumanMotion {
    let nb = human.num_bodies();
    let mut out = human.clone();
    for (i, p) in out.positions.iter_mut().enumerate() {
        let run = belt * ((i / nb.max(1)) as f64 / human.fps);
        p.x -= run.x;
        p.y -= run.y;
    }
    out
}

/// Height above its floor level and horizontal velocity and speed of one body, per frame.
struct PointTrack {
    height: Vec<f64>,
    velocity: Vec<Vector2<f64>>,
    speed: Vec<f64>,
}

impl PointTrack {
    /// Whether the point grips the floor at frame `t`: low and slow enough to enter contact.
    fn grips(&self, t: usize, o: &ContactOptions) -> bool {
        self.height[t] < o.height_on && self.speed[t] < o.speed_on
    }

    /// Whether the point holds the floor at frame `t`: low and slow enough to stay in contact.
    fn holds(&self, t: usize, o: &ContactOptions) -> bool {
        self.height[t] < o.height_off && self.speed[t] < o.speed_off
    }

    fn new(human: &HumanMotion, body: usize, floor_percentile: f64) -> PointTrack {
        let n = human.num_frames;
        let nb = human.num_bodies();
        let pos: Vec<Vector3<f64>> = (0..n).map(|t| human.positions[t * nb + body]).collect();
        let mut z: Vec<f64> = pos.iter().map(|p| p.z).collect();
        z.sort_by(f64::total_cmp);
        let floor = if n == 0 {
            0.0
        } else {
            z[((n - 1) as f64 * floor_percentile.clamp(0.0, 1.0)).round() as usize]
        };
        let dt = 1.0 / human.fps;
        let (velocity, speed): (Vec<Vector2<f64>>, Vec<f64>) = (0..n)
            .map(|t| {
                let (a, b) = (t.saturating_sub(1), (t + 1).min(n - 1));
                if a == b {
                    return (Vector2::zeros(), 0.0);
                }
                let d = (pos[b] - pos[a]).xy();
                let span = (b - a) as f64 * dt;
                (d / span, d.norm() / span)
            })
            .unzip();
        PointTrack { height: pos.iter().map(|p| p.z - floor).collect(), velocity, speed }
    }
}

/// Index ranges `[start, end)` of the contact phases in `labels`.
#[must_use]
pub fn phases(labels: &[bool]) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut t = 0;
    while t < labels.len() {
        if labels[t] {
            let start = t;
            while t < labels.len() && labels[t] {
                t += 1;
            }
            out.push(start..t);
        } else {
            t += 1;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::UnitQuaternion;

    /// One body at 30 fps: planted for 10 frames, swinging (up 10 cm, moving 1 m/s) for 10,
    /// planted again; a one-frame lift in the first stance (frame 5) is ignored.
    #[test]
    fn steps_with_hysteresis_and_minimum_phase() {
        let mut positions = Vec::new();
        let mut x = 0.0;
        for t in 0..30 {
            let swing = (10..20).contains(&t);
            if swing {
                x += 1.0 / 30.0;
            }
            let z = if swing || t == 5 { 0.1 } else { 0.05 };
            positions.push(Vector3::new(x, 0.0, z));
        }
        let human = HumanMotion {
            fps: 30.0,
            body_names: vec!["Foot".to_owned()],
            num_frames: 30,
            orientations: vec![UnitQuaternion::identity(); 30],
            positions,
        };
        let foot = FootPoints { heel: 0, toe: None };
        let options = ContactOptions { speed_off: 0.6, ..ContactOptions::default() };
        let c = detect(&human, [foot, foot], &options).left;
        // Frame 9 moves at 0.5 m/s (central difference) but still holds: hysteresis.
        assert_eq!(phases(&c), vec![0..10, 20..30], "{c:?}");
    }

    /// A heel and a toe at 30 fps, standing 1 s: the heel rises 10 cm in frames 10–19
    /// (kneeling, tiptoe) while the toe stays; a one-frame heel rise (frame 25) is ignored.
    /// The foot stands throughout, on its toes alone in frames 10–19.
    #[test]
    fn a_heel_up_while_the_toe_holds_is_standing_on_the_toes() {
        let frames = 30;
        let mut positions = Vec::new();
        for t in 0..frames {
            let heel_up = (10..20).contains(&t) || t == 25;
            positions.push(Vector3::new(0.0, 0.0, if heel_up { 0.17 } else { 0.07 }));
            positions.push(Vector3::new(0.15, 0.0, 0.02));
        }
        let human = HumanMotion {
            fps: 30.0,
            body_names: vec!["Foot".to_owned(), "Toe".to_owned()],
            num_frames: frames,
            orientations: vec![UnitQuaternion::identity(); 2 * frames],
            positions,
        };
        let foot = FootPoints { heel: 0, toe: Some(1) };
        let c = detect(&human, [foot, foot], &ContactOptions::default());
        assert_eq!(c.left, vec![true; frames]);
        let toes = c.on_toes.map(|[left, _]| left).unwrap_or_default();
        assert_eq!(phases(&toes), vec![10..20], "{toes:?}");
        // Seen through its heel alone, a foot's toes are unknown.
        let heel_only = FootPoints { heel: 0, toe: None };
        assert_eq!(detect(&human, [heel_only, foot], &ContactOptions::default()).on_toes, None);
    }

    /// Two feet (heel points) and a root at 30 fps, walking in 0.5 s steps at `speed` m/s:
    /// each foot stands for a step while the other swings 3 cm up. `treadmill` puts the
    /// stance foot on a belt running back at `belt` m/s along x, the root stays put plus
    /// `root` m/s.
    fn walk(belt: f64, root: f64) -> HumanMotion {
        let (fps, frames) = (30.0, 60);
        let mut positions = Vec::new();
        for t in 0..frames {
            let s = t as f64 / fps;
            let step = (t / 15) % 2;
            let phase = (t % 15) as f64 / 15.0;
            let foot = |side: usize| {
                if side == step {
                    Vector3::new(-belt * s, 0.0, 0.07)
                } else {
                    let swing = (std::f64::consts::PI * phase).sin();
                    Vector3::new(-belt * s, 0.0, 0.07 + 0.03 * swing)
                }
            };
            positions.push(Vector3::new(root * s, 0.0, 0.9));
            positions.push(foot(0));
            positions.push(foot(1));
        }
        HumanMotion {
            fps,
            body_names: ["Hips", "LeftFoot", "RightFoot"].map(str::to_owned).to_vec(),
            num_frames: frames,
            orientations: vec![UnitQuaternion::identity(); 3 * frames],
            positions,
        }
    }

    /// An in-place loop's feet slide back at the belt's speed: found, and taken off it the
    /// stance feet stand still and the body walks forward. A walk on a floor that stays put
    /// and a moonwalk (the root goes back with the feet) are no treadmill.
    #[test]
    fn an_in_place_loop_is_walked_off_its_treadmill() {
        let options = ContactOptions::default();
        let feet = [FootPoints { heel: 1, toe: None }, FootPoints { heel: 2, toe: None }];
        let looped = walk(0.8, 0.0);
        let belt = treadmill(&looped, feet, 0, &options).unwrap_or_default();
        assert!((belt - Vector2::new(-0.8, 0.0)).norm() < 1e-9, "{belt}");
        let walked = off_treadmill(&looped, belt);
        assert!((walked.positions[59 * 3].x - 0.8 * 59.0 / 30.0).abs() < 1e-9);
        let contacts = detect(&walked, feet, &options);
        assert!(contacts.left.iter().filter(|c| **c).count() >= 25, "{:?}", contacts.left);
        assert_eq!(detect(&looped, feet, &options).left, vec![false; 60]);
        assert_eq!(treadmill(&walk(0.0, 0.0), feet, 0, &options), None);
        assert_eq!(treadmill(&walk(0.8, -0.8), feet, 0, &options), None);
    }

    #[test]
    fn short_runs() {
        let mut v = vec![true, true, false, true, true, true, false, false, false, true];
        fill_short_runs(&mut v, false, 2);
        assert_eq!(v, [true, true, true, true, true, true, false, false, false, true]);
        // The last frame's contact ends the clip: the foot may stand past it.
        fill_short_runs(&mut v, true, 2);
        assert_eq!(v, [true, true, true, true, true, true, false, false, false, true]);
        let mut v = vec![false, true, false, false, true, true, false];
        fill_short_runs(&mut v, true, 2);
        assert_eq!(v, [false, false, false, false, true, true, false]);
    }
}
