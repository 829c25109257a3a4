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
//! phases shorter than it are dropped, so one noisy frame neither splits a stance nor makes
//! a step.

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: per-frame buffers are built here with the motion's frame count, which
// `HumanMotion::validate` checked against its arrays.
#![allow(clippy::indexing_slicing)]

use std::collections::BTreeMap;

use fk::{HumanMotion, Role};
use nalgebra::Vector3;

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
    let [left, right] = feet.map(|f| foot_contact(human, f, options));
    FootContacts { left, right }
}

fn foot_contact(human: &HumanMotion, foot: FootPoints, o: &ContactOptions) -> Vec<bool> {
    let n = human.num_frames;
    let points: Vec<PointTrack> = std::iter::once(foot.heel)
        .chain(foot.toe)
        .map(|b| PointTrack::new(human, b, o.floor_percentile))
        .collect();
    let mut contact = vec![false; n];
    let mut on = false;
    for (t, c) in contact.iter_mut().enumerate() {
        let grips = points.iter().any(|p| p.height[t] < o.height_on && p.speed[t] < o.speed_on);
        let holds = points.iter().any(|p| p.height[t] < o.height_off && p.speed[t] < o.speed_off);
        on = if on { holds } else { grips };
        *c = on;
    }
    let min_frames = (o.min_phase_s * human.fps).round().max(1.0) as usize;
    fill_short_runs(&mut contact, false, min_frames);
    fill_short_runs(&mut contact, true, min_frames);
    contact
}

/// Runs of `value` shorter than `min` frames become `!value`; for gaps (`value == false`)
/// only those enclosed by contact on both sides.
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
        if t - start < min && (value || enclosed) {
            labels[start..t].fill(!value);
        }
    }
}

/// Height above its floor level and horizontal speed of one body, per frame.
struct PointTrack {
    height: Vec<f64>,
    speed: Vec<f64>,
}

impl PointTrack {
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
        let speed = (0..n)
            .map(|t| {
                let (a, b) = (t.saturating_sub(1), (t + 1).min(n - 1));
                if a == b {
                    return 0.0;
                }
                let d = pos[b] - pos[a];
                d.xy().norm() / ((b - a) as f64 * dt)
            })
            .collect();
        PointTrack { height: pos.iter().map(|p| p.z - floor).collect(), speed }
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

    #[test]
    fn short_runs() {
        let mut v = vec![true, true, false, true, true, true, false, false, false, true];
        fill_short_runs(&mut v, false, 2);
        assert_eq!(v, [true, true, true, true, true, true, false, false, false, true]);
        fill_short_runs(&mut v, true, 2);
        assert_eq!(v, [true, true, true, true, true, true, false, false, false, false]);
    }
}
