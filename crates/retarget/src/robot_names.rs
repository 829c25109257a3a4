//! How robot vendors name sides and body parts: data, consulted by the robot recogniser
//! ([`crate::robot_roles`]) to tell left from right and to say when a body's name agrees with
//! the role geometry gave it. Names never override geometry for the parts, only for sides
//! (vendors name sides reliably, and a robot facing +y at `qpos0` has no other cue).
//!
//! To add a convention: add its side tokens to [`LEFT`] / [`RIGHT`] or its part words to
//! [`PART_WORDS`], and a small robot using it to `crates/retarget/tests/data/robots/`.
//!
//! Names are split into lowercase tokens at `_`, `-`, `.`, `:`, spaces, digit runs and
//! camelCase boundaries: `J03_KNEE_PITCH_L` → `j 03 knee pitch l`, `hipPitchLeft` →
//! `hip pitch left`, `leg_l1_link` → `leg l 1 link`, `Left_Hip_Pitch` → `left hip pitch`.

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use fk::Part;

/// Tokens that mark the left side (`left_knee_link`, `L_ANKLE`, `LINK_HIP_PITCH_L`,
/// `hipPitchLeft`, `leg_l1_link`, `arm_left_1_link`).
pub const LEFT: &[&str] = &["left", "l", "lt", "lft"];
/// Tokens that mark the right side.
pub const RIGHT: &[&str] = &["right", "r", "rt", "rgt"];

/// Words that name a body part, per part (compared with whole tokens, or token pairs joined
/// without separator: `upper arm` = `upperarm`).
pub const PART_WORDS: &[(Part, &[&str])] = &[
    (Part::Pelvis, &["pelvis", "base", "waist", "hips", "root"]),
    (Part::Chest, &["torso", "trunk", "chest", "body", "upperbody", "waist"]),
    (Part::Head, &["head", "neck", "skull"]),
    (Part::UpperArm, &["shoulder", "upperarm", "humerus", "arm", "sho"]),
    (Part::Forearm, &["elbow", "forearm", "lowerarm", "radius"]),
    (Part::Hand, &["wrist", "hand", "palm", "gripper", "effector", "end"]),
    (Part::Thigh, &["hip", "thigh", "femur", "upleg", "upperleg"]),
    (Part::Shin, &["knee", "shank", "shin", "calf", "tibia", "lowerleg"]),
    (Part::Foot, &["ankle", "foot", "sole", "toe", "ank"]),
];

/// Words of bodies that carry sensors, not a body part: never the head (N1's `camera_link`
/// is its highest body), never a limb end.
pub const EXTRAS: &[&str] = &["camera", "imu", "lidar", "sensor", "realsense", "depth", "kinect"];

/// Whether the name marks a sensor body ([`EXTRAS`]).
#[must_use]
pub fn is_extra(name: &str) -> bool {
    tokens(name).iter().any(|w| EXTRAS.contains(&w.as_str()))
}

/// The name's tokens (see the module docs).
#[must_use]
pub fn tokens(name: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut current = String::new();
    let mut previous: Option<char> = None;
    for c in name.chars() {
        let boundary = match previous {
            None => false,
            Some(p) => {
                !c.is_alphanumeric()
                    || (p.is_lowercase() && c.is_uppercase())
                    || (p.is_ascii_digit() != c.is_ascii_digit())
            }
        };
        if boundary && !current.is_empty() {
            out.push(std::mem::take(&mut current));
        }
        if c.is_alphanumeric() {
            current.extend(c.to_lowercase());
        }
        previous = Some(c);
    }
    if !current.is_empty() {
        out.push(current);
    }
    out
}

/// +1 when the name says left, −1 when it says right, 0 when it says neither or both.
#[must_use]
pub fn side_of(name: &str) -> i32 {
    let t = tokens(name);
    let left = t.iter().any(|w| LEFT.contains(&w.as_str()));
    let right = t.iter().any(|w| RIGHT.contains(&w.as_str()));
    i32::from(left) - i32::from(right)
}

/// Whether the name contains a word of `part` ([`PART_WORDS`]).
#[must_use]
pub fn names_part(name: &str, part: Part) -> bool {
    let Some((_, words)) = PART_WORDS.iter().find(|(p, _)| *p == part) else {
        return false;
    };
    let t = tokens(name);
    let pairs = t.iter().zip(t.iter().skip(1)).map(|(a, b)| format!("{a}{b}"));
    t.iter().cloned().chain(pairs).any(|w| words.contains(&w.as_str()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_split_every_convention() {
        assert_eq!(tokens("J03_KNEE_PITCH_L"), ["j", "03", "knee", "pitch", "l"]);
        assert_eq!(tokens("hipPitchLeft"), ["hip", "pitch", "left"]);
        assert_eq!(tokens("leg_l1_link"), ["leg", "l", "1", "link"]);
        assert_eq!(tokens("Left_Hip_Pitch"), ["left", "hip", "pitch"]);
        assert_eq!(tokens("base_link"), ["base", "link"]);
    }

    #[test]
    fn sides_and_parts_from_names() {
        for (name, side) in [
            ("left_knee_link", 1),
            ("L_ANKLE", 1),
            ("J03_KNEE_PITCH_L", 1),
            ("hipPitchRight", -1),
            ("leg_r6_link", -1),
            ("AL2", 0),
            ("Trunk", 0),
            ("left_right", 0),
        ] {
            assert_eq!(side_of(name), side, "{name}");
        }
        assert!(names_part("left_knee_link", Part::Shin));
        assert!(names_part("LINK_ELBOW_PITCH_L", Part::Forearm));
        assert!(names_part("left_upper_arm_roll_link", Part::UpperArm));
        assert!(names_part("Trunk", Part::Chest));
        assert!(!names_part("left_knee_link", Part::Thigh));
        assert!(is_extra("camera_link") && is_extra("imu_in_torso") && !is_extra("head_link"));
    }
}
