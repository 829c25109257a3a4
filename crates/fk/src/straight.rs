//! Straight limbs for cartoon rigs with one bone per limb (no elbows or knees): the hand
//! hangs directly from the upper arm, the foot from the thigh (the Blender barbarian of
//! ufbx's test files: `bras droit` → `main droite`, `jambe gauche` → `pied gauche`).
//!
//! A retargeter needs the ends of every segment, so such a limb gets an elbow (knee) that
//! never bends: a joint without channels halfway along the bone, named `<upper>.elbow`
//! (`<thigh>.knee`). The skeleton is then an ordinary one and the recogniser reads it; the
//! robot's elbows and knees follow a straight limb. Only limbs named so by a convention
//! ([`crate::conventions`]) are straightened: without names a single bone is not known to be
//! a whole limb.

use bvh::{Bvh, Channel, Joint, JointId, JointKind};

use crate::conventions;
use crate::roles::{Part, Role, Side};

/// `bvh` with a straight elbow or knee in every one-bone limb, and the names of the joints
/// added; `None` when no limb needs one (its distal joint is not the proximal one's child,
/// or a joint is named as the middle segment on that side).
#[must_use]
pub fn straighten_limbs(bvh: &Bvh) -> Option<(Bvh, Vec<String>)> {
    let roles: Vec<Vec<Role>> = bvh
        .skeleton
        .joints
        .iter()
        .map(|j| match j.kind {
            JointKind::End => Vec::new(),
            _ => conventions::matches(&conventions::normalise(&j.name))
                .into_iter()
                .map(|m| m.role)
                .collect(),
        })
        .collect();
    let named = |role: Role| roles.iter().position(|r| r.contains(&role));
    let mut splits: Vec<(usize, &'static str)> = Vec::new(); // (distal joint, suffix)
    for side in [Side::Left, Side::Right] {
        let limbs = [
            (Part::UpperArm, Part::Forearm, Part::Hand, "elbow"),
            (Part::Thigh, Part::Shin, Part::Foot, "knee"),
        ];
        for (upper, middle, distal, what) in limbs {
            let (Some(u), Some(d)) = (named(Role::of(upper, side)), named(Role::of(distal, side)))
            else {
                continue;
            };
            let direct = bvh.skeleton.joints.get(d).and_then(|j| j.parent) == Some(JointId(u));
            if direct && named(Role::of(middle, side)).is_none() {
                splits.push((d, what));
            }
        }
    }
    if splits.is_empty() {
        return None;
    }
    splits.sort_unstable();
    let mut out = bvh.clone();
    let mut added = Vec::new();
    // From the last joint back, so the earlier indices stay valid.
    for &(d, what) in splits.iter().rev() {
        added.push(split(&mut out, d, what)?);
    }
    added.reverse();
    Some((out, added))
}

/// Inserts a channel-less joint halfway between joint `d` and its parent; returns its name.
fn split(bvh: &mut Bvh, d: usize, what: &str) -> Option<String> {
    let joints = &mut bvh.skeleton.joints;
    let distal = joints.get(d)?.clone();
    let parent = distal.parent?;
    let upper = joints.get(parent.0)?.name.clone();
    let half = distal.offset.map(|x| x / 2.0);
    let name = format!("{upper}.{what}");
    let middle = Joint {
        name: name.clone(),
        kind: JointKind::Joint,
        parent: Some(parent),
        offset: half,
        channels: Vec::new(),
        first_channel: distal.first_channel,
    };
    for joint in joints.iter_mut() {
        if let Some(p) = joint.parent.as_mut() {
            if p.0 >= d {
                p.0 += 1;
            }
        }
    }
    joints.insert(d, middle);
    let moved = joints.get_mut(d + 1)?;
    moved.parent = Some(JointId(d));
    moved.offset = half;
    // Position channels (which replace the OFFSET) now measure from the middle joint.
    let motion = &mut bvh.motion;
    for (k, channel) in distal.channels.iter().enumerate() {
        let Channel::Position(axis) = channel else { continue };
        let column = distal.first_channel + k;
        for f in 0..motion.num_frames {
            if let Some(v) = motion.values.get_mut(f * motion.num_channels + column) {
                *v -= half.get(*axis as usize).copied().unwrap_or(0.0);
            }
        }
    }
    Some(name)
}

#[cfg(test)]
mod tests {
    use super::*;
    use bvh::{Axis, Motion, Skeleton};

    fn joint(name: &str, parent: Option<usize>, offset: [f64; 3], first: usize) -> Joint {
        let rotations = vec![
            Channel::Rotation(Axis::Z),
            Channel::Rotation(Axis::X),
            Channel::Rotation(Axis::Y),
        ];
        Joint {
            name: name.to_owned(),
            kind: if parent.is_none() { JointKind::Root } else { JointKind::Joint },
            parent: parent.map(JointId),
            offset,
            channels: rotations,
            first_channel: first,
        }
    }

    #[test]
    fn one_bone_limbs_get_a_joint_halfway_that_keeps_every_position() {
        let names = [
            ("bassin", None, [0.0, 100.0, 0.0]),
            ("jambe gauche", Some(0), [10.0, -5.0, 0.0]),
            ("pied gauche", Some(1), [0.0, -90.0, 0.0]),
            ("jambe droite", Some(0), [-10.0, -5.0, 0.0]),
            ("pied droit", Some(3), [0.0, -90.0, 0.0]),
            ("torse", Some(0), [0.0, 40.0, 0.0]),
            ("bras gauche", Some(5), [15.0, 10.0, 0.0]),
            ("main gauche", Some(6), [50.0, 0.0, 0.0]),
        ];
        let joints: Vec<Joint> =
            names.iter().enumerate().map(|(i, &(n, p, o))| joint(n, p, o, 3 * i)).collect();
        let values: Vec<f64> = (0..2 * 24).map(|k| (k as f64 * 7.3) % 40.0 - 20.0).collect();
        let bvh = Bvh {
            skeleton: Skeleton { joints },
            motion: Motion { frame_time: 0.1, num_frames: 2, num_channels: 24, values },
        };
        let (straight, added) = straighten_limbs(&bvh).unwrap();
        assert_eq!(added, ["jambe gauche.knee", "jambe droite.knee", "bras gauche.elbow"]);
        assert_eq!(straight.skeleton.joints.len(), 11);
        let options = crate::FkOptions {
            units: crate::UnitChoice::Scale(0.01),
            ..crate::FkOptions::default()
        };
        let (before, _) = crate::human_motion(&bvh, &options).unwrap();
        let (after, _) = crate::human_motion(&straight, &options).unwrap();
        for f in 0..2 {
            for name in names.iter().map(|n| n.0) {
                let (a, b) =
                    (before.require_body(name).unwrap(), after.require_body(name).unwrap());
                assert!((before.position(f, a) - after.position(f, b)).norm() < 1e-12, "{name}");
            }
            let [hip, knee, foot] = ["jambe gauche", "jambe gauche.knee", "pied gauche"]
                .map(|n| *after.position(f, after.require_body(n).unwrap()));
            assert!((knee - (hip + foot) / 2.0).norm() < 1e-12, "halfway");
        }
        assert!(straighten_limbs(&straight).is_none(), "nothing left to straighten");
    }
}
