//! Canonical body frames from joint positions alone: pure geometry, the same for a human
//! skeleton (in any pose where the body is recognisable) and for a robot (its body positions
//! at `qpos0`), so that the rotation between a human joint and a robot body is computed, not
//! tuned. Nothing here knows BVH or MJCF.
//!
//! The body's own axes come first, from the trunk and the hips (not from the world: the
//! reference pose may lie on its side):
//! - `up` U: pelvis → the highest trunk point given (neck, else head, chest, spine);
//! - `left` L: right thigh → left thigh (else right → left upper arm), made perpendicular to U;
//! - `forward` F = L × U.
//!
//! Every frame is a rotation whose columns are its x, y, z axes in the input's coordinates:
//! - pelvis: x = F, y = L, z = U;
//! - spine, chest, neck, head: z along the trunk towards the head (from the joint to the next
//!   trunk point above it; the head continues the neck's direction), y = L made perpendicular
//!   (the chest and neck take L from the upper arms when both are given), x = y × z;
//! - clavicle, upper arm, forearm, thigh, shin: z along the bone towards its parent joint
//!   (e.g. thigh: knee → hip), x = F made perpendicular to z (when the bone points within 30°
//!   of ±F, as an arm raised forward: y = L made perpendicular, x = y × z); the hand
//!   continues the forearm's axis and x;
//! - foot, toe: x = heel-to-toe direction (foot → toe) made perpendicular to U (F when there
//!   is no toe, or when the foot points more than 60° down), z = U made perpendicular to x.
//!
//! Standing upright facing +x with the arms hanging, every frame but the clavicles' is the
//! identity. A body's frame rotates with its bone, so for a joint with world orientation `q`
//! in the reference pose the constant `q⁻¹ ⊗ R` gives the canonical frame in every frame of
//! the motion.

use std::collections::BTreeMap;

use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

use crate::roles::{Part, Role, Side};

/// Shorter vectors than this (relative to the body's size) have no direction.
const DEGENERATE: f64 = 1e-6;
/// sin 30°: a limb closer than this to the forward axis takes its x from the left axis.
const ALONG_FORWARD: f64 = 0.5;
/// cos 60°: a foot whose heel-to-toe direction is steeper than 60° faces forward.
const STEEP_FOOT: f64 = 0.5;

/// Canonical frame (world-from-frame rotation, in the input's coordinates) of every role
/// whose geometry the given points determine. `points` are joint positions per role in any
/// unit; the pelvis, a point above it and a left-right pair (thighs or upper arms) are needed
/// for any frame at all.
#[must_use]
pub fn canonical_frames(
    points: &BTreeMap<Role, Vector3<f64>>,
) -> BTreeMap<Role, UnitQuaternion<f64>> {
    let mut out = BTreeMap::new();
    let Some(body) = BodyAxes::new(points) else {
        return out;
    };
    let at = |role: Role| points.get(&role).copied();
    out.insert(Role::Pelvis, body.rotation(body.forward, body.left, body.up));
    let shoulders = pair_left(points, Part::UpperArm).map(|l| body.perpendicular(l));
    let trunk = [Role::Pelvis, Role::Spine, Role::Chest, Role::Neck, Role::Head];
    for (i, &role) in trunk.iter().enumerate().skip(1) {
        let Some(p) = at(role) else { continue };
        let (lower, upper) = trunk.split_at(i);
        let above = upper.iter().skip(1).find_map(|&r| at(r));
        let below = lower.iter().rev().find_map(|&r| at(r));
        let z = match (above, below) {
            (Some(a), _) => unit(a - p, body.size),
            (None, Some(b)) => unit(p - b, body.size),
            (None, None) => None,
        }
        .unwrap_or(body.up);
        let left = match role {
            Role::Chest | Role::Neck => shoulders.unwrap_or(body.left),
            _ => body.left,
        };
        if let Some(r) = body.frame_from_z_and_y(z, left) {
            out.insert(role, r);
        }
    }
    for side in [Side::Left, Side::Right] {
        // Every part of these chains has sides, so `Role::new` finds each role.
        let role = |part| Role::new(part, Some(side));
        let chains: [&[Part]; 2] = [
            &[Part::Clavicle, Part::UpperArm, Part::Forearm, Part::Hand],
            &[Part::Thigh, Part::Shin, Part::Foot],
        ];
        for chain in chains {
            for w in chain.windows(2) {
                let &[a, b] = w else { continue };
                let (Some(joint), Some(child)) = (role(a), role(b)) else { continue };
                if let (Some(p), Some(c)) = (at(joint), at(child)) {
                    if let Some(r) = unit(p - c, body.size).and_then(|z| body.limb_frame(z)) {
                        out.insert(joint, r);
                    }
                }
            }
        }
        let parts = [Part::Forearm, Part::Hand, Part::Foot, Part::Toe].map(role);
        let [Some(forearm_role), Some(hand), Some(foot_role), Some(toe_role)] = parts else {
            continue;
        };
        if let Some(&forearm) = out.get(&forearm_role) {
            if at(hand).is_some() {
                out.insert(hand, forearm);
            }
        }
        let foot = at(foot_role);
        let toe = at(toe_role);
        // A foot pitched more than 60° (pushing off, as in a run's reference frame) points
        // its toe nearly down: the rest of the heel-to-toe direction says little about which
        // way the foot faces (the Bandai run's left foot: backwards), so it faces forward.
        let heel_to_toe = match (foot, toe) {
            (Some(f), Some(t))
                if body.perpendicular(t - f).norm() >= STEEP_FOOT * (t - f).norm() =>
            {
                unit(body.perpendicular(t - f), body.size)
            }
            _ => None,
        }
        .unwrap_or(body.forward);
        let up = unit(body.up - heel_to_toe * body.up.dot(&heel_to_toe), 1.0).unwrap_or(body.up);
        let r = body.rotation(heel_to_toe, up.cross(&heel_to_toe), up);
        for part in [foot_role, toe_role] {
            if at(part).is_some() {
                out.insert(part, r);
            }
        }
    }
    out
}

/// Right → left vector of a sided part, when both sides are given.
fn pair_left(points: &BTreeMap<Role, Vector3<f64>>, part: Part) -> Option<Vector3<f64>> {
    let l = points.get(&Role::new(part, Some(Side::Left))?)?;
    let r = points.get(&Role::new(part, Some(Side::Right))?)?;
    Some(l - r)
}

/// `v / |v|`, or `None` if `v` is shorter than [`DEGENERATE`] × `size`.
fn unit(v: Vector3<f64>, size: f64) -> Option<Vector3<f64>> {
    let n = v.norm();
    (n > DEGENERATE * size && n.is_finite()).then(|| v / n)
}

/// The body's up, left and forward axes.
#[derive(Debug, Clone, Copy)]
struct BodyAxes {
    up: Vector3<f64>,
    left: Vector3<f64>,
    forward: Vector3<f64>,
    /// Pelvis to top point: the scale for degeneracy tests.
    size: f64,
}

impl BodyAxes {
    fn new(points: &BTreeMap<Role, Vector3<f64>>) -> Option<BodyAxes> {
        let pelvis = points.get(&Role::Pelvis)?;
        let top = [Role::Neck, Role::Head, Role::Chest, Role::Spine]
            .iter()
            .find_map(|r| points.get(r))?;
        let size = (top - pelvis).norm();
        let up = unit(top - pelvis, 1.0)?;
        let left = [Part::Thigh, Part::UpperArm].iter().find_map(|&part| {
            let l = pair_left(points, part)?;
            unit(l - up * up.dot(&l), size)
        })?;
        Some(BodyAxes { up, left, forward: left.cross(&up), size })
    }

    fn rotation(&self, x: Vector3<f64>, y: Vector3<f64>, z: Vector3<f64>) -> UnitQuaternion<f64> {
        let m = Matrix3::from_columns(&[x, y, z]);
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m))
    }

    /// `v` without its component along `up`.
    fn perpendicular(&self, v: Vector3<f64>) -> Vector3<f64> {
        v - self.up * self.up.dot(&v)
    }

    /// z given, y from `left` made perpendicular to z, x = y × z.
    fn frame_from_z_and_y(
        &self,
        z: Vector3<f64>,
        left: Vector3<f64>,
    ) -> Option<UnitQuaternion<f64>> {
        let y = unit(left - z * z.dot(&left), 1.0)?;
        Some(self.rotation(y.cross(&z), y, z))
    }

    /// A limb bone's frame: z given; x = forward made perpendicular to z, unless the bone
    /// points within 30° of forward or backward (then y from left, x = y × z). The switch is
    /// far from hanging, T- and A-pose limbs, where both rules would be valid but differ.
    fn limb_frame(&self, z: Vector3<f64>) -> Option<UnitQuaternion<f64>> {
        let across = self.forward - z * z.dot(&self.forward);
        if across.norm() >= ALONG_FORWARD {
            let x = across.normalize();
            Some(self.rotation(x, z.cross(&x), z))
        } else {
            self.frame_from_z_and_y(z, self.left)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    /// A standing I-pose facing +x, Z up, metres.
    fn standing() -> BTreeMap<Role, Vector3<f64>> {
        let mut p = BTreeMap::new();
        p.insert(Role::Pelvis, Vector3::new(0.0, 0.0, 1.0));
        p.insert(Role::Spine, Vector3::new(0.0, 0.0, 1.1));
        p.insert(Role::Chest, Vector3::new(0.0, 0.0, 1.3));
        p.insert(Role::Neck, Vector3::new(0.0, 0.0, 1.5));
        p.insert(Role::Head, Vector3::new(0.0, 0.0, 1.6));
        for (side, y) in [(Side::Left, 1.0), (Side::Right, -1.0)] {
            let mut put = |part, v: Vector3<f64>| {
                p.insert(Role::new(part, Some(side)).unwrap(), v);
            };
            put(Part::Clavicle, Vector3::new(0.0, 0.03 * y, 1.45));
            put(Part::UpperArm, Vector3::new(0.0, 0.18 * y, 1.45));
            put(Part::Forearm, Vector3::new(0.0, 0.18 * y, 1.15));
            put(Part::Hand, Vector3::new(0.0, 0.18 * y, 0.9));
            put(Part::Thigh, Vector3::new(0.0, 0.1 * y, 0.95));
            put(Part::Shin, Vector3::new(0.0, 0.1 * y, 0.5));
            put(Part::Foot, Vector3::new(0.0, 0.1 * y, 0.08));
            put(Part::Toe, Vector3::new(0.14, 0.1 * y, 0.0));
        }
        p
    }

    #[test]
    fn standing_upright_facing_x_gives_identity_frames() {
        let frames = canonical_frames(&standing());
        assert_eq!(frames.len(), Role::ALL.len());
        for (role, q) in &frames {
            if role.part() == Part::Clavicle {
                // z medial (towards the sternum), x forward.
                let m = q.to_rotation_matrix();
                let medial = if role.side() == Some(Side::Left) { -1.0 } else { 1.0 };
                assert!((m * Vector3::z() - Vector3::y() * medial).norm() < 1e-12, "{role}");
                assert!((m * Vector3::x() - Vector3::x()).norm() < 1e-12, "{role}");
            } else {
                assert!(q.angle() < 1e-12, "{role}: {q:?}");
            }
        }
    }

    #[test]
    fn frames_turn_with_the_body_and_follow_the_bones() {
        // The same body turned to face +y and lying on its back changes every frame by the
        // same rotation: the frames are the body's, not the world's.
        let turn = UnitQuaternion::from_euler_angles(0.3, -FRAC_PI_2 + 0.2, 1.1);
        let turned: BTreeMap<Role, Vector3<f64>> =
            standing().into_iter().map(|(r, p)| (r, turn * p)).collect();
        let (a, b) = (canonical_frames(&standing()), canonical_frames(&turned));
        for (role, q) in &a {
            assert!((turn * q).angle_to(&b[role]) < 1e-9, "{role}");
        }
        // Arms raised sideways (T-pose): the upper arm's z points to the body's midline and
        // its x stays forward.
        let mut t = standing();
        t.insert(Role::LeftForearm, Vector3::new(0.0, 0.48, 1.45));
        t.insert(Role::LeftHand, Vector3::new(0.0, 0.73, 1.45));
        let m = canonical_frames(&t)[&Role::LeftUpperArm].to_rotation_matrix();
        assert!((m * Vector3::z() + Vector3::y()).norm() < 1e-12);
        assert!((m * Vector3::x() - Vector3::x()).norm() < 1e-12);
        // An arm raised forward: x turns up (flexion about the left axis keeps y = left).
        t.insert(Role::LeftForearm, Vector3::new(0.3, 0.18, 1.45));
        let m = canonical_frames(&t)[&Role::LeftUpperArm].to_rotation_matrix();
        assert!((m * Vector3::z() + Vector3::x()).norm() < 1e-12);
        assert!((m * Vector3::y() - Vector3::y()).norm() < 1e-12);
        assert!((m * Vector3::x() - Vector3::z()).norm() < 1e-12);
    }

    #[test]
    fn a_foot_pointing_down_faces_forward() {
        // Pushing off: the left toe 70° below the heel-to-toe horizontal and a little behind
        // and outside the foot. The little that is horizontal points back and out; the foot
        // faces forward, as the body does.
        let mut p = standing();
        let (down, back, out) = (0.14 * 70f64.to_radians().sin(), 0.04, 0.02);
        p.insert(Role::LeftToe, Vector3::new(-back, 0.1 + out, 0.08 - down));
        let m = canonical_frames(&p)[&Role::LeftFoot].to_rotation_matrix();
        assert!((m * Vector3::x() - Vector3::x()).norm() < 1e-12, "{m}");
        // Pitched 50°, the foot still says which way it faces: back and out.
        p.insert(Role::LeftToe, Vector3::new(-back, 0.1 + out, 0.08 - 0.06));
        let m = canonical_frames(&p)[&Role::LeftFoot].to_rotation_matrix();
        let x = m * Vector3::x();
        assert!(x.x < 0.0 && x.y > 0.0 && x.z.abs() < 1e-12, "{m}");
    }

    #[test]
    fn too_little_geometry_gives_no_frames() {
        let mut p = BTreeMap::new();
        p.insert(Role::Pelvis, Vector3::zeros());
        p.insert(Role::Head, Vector3::z());
        assert!(canonical_frames(&p).is_empty());
    }
}
