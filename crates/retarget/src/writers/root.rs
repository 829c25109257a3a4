//! The robot's root in the files: how many `qpos` entries the free root takes, its pose per
//! frame, and the quaternion order of the two formats that write x y z w (Unitree's CSV
//! root, GMR's `root_rot`): the only place where our files change it.

use super::derived::BodyPoses;
use crate::motion::RobotMotion;

/// Number of `qpos` entries of the free root (7), or 0 when the first joint is not a free
/// joint at `qpos[0]`.
pub(crate) fn root_nq(model: &mjcf::Model) -> usize {
    match model.joints.first() {
        Some(j) if j.kind == mjcf::JointType::Free && j.qpos_adr == 0 => 7,
        _ => 0,
    }
}

/// Root position and w-first orientation of one frame: the free joint's `qpos`, or the world
/// pose of the first body for a fixed-base model.
pub(crate) fn root_pose(
    motion: &RobotMotion,
    model: &mjcf::Model,
    poses: &BodyPoses,
    frame: usize,
) -> ([f64; 3], [f64; 4]) {
    if root_nq(model) == 7 {
        match motion.frame(frame) {
            &[x, y, z, w, i, j, k, ..] => ([x, y, z], [w, i, j, k]),
            _ => ([0.0; 3], [1.0, 0.0, 0.0, 0.0]),
        }
    } else {
        let p = poses.pos(frame, 0);
        let q = poses.quat(frame, 0);
        ([p.x, p.y, p.z], [q.w, q.i, q.j, q.k])
    }
}

/// The x y z w (scalar-last) order of a w x y z quaternion: Unitree's CSV root and GMR's
/// `root_rot` use it. The only place where our files change quaternion order.
#[must_use]
pub(crate) const fn xyzw_from_wxyz(wxyz: [f64; 4]) -> [f64; 4] {
    [wxyz[1], wxyz[2], wxyz[3], wxyz[0]]
}

/// The w x y z (scalar-first) order of an x y z w quaternion read from Unitree's CSV or
/// GMR's `root_rot`: [`xyzw_from_wxyz`]'s inverse, the only place where read files change
/// quaternion order.
#[must_use]
pub(crate) const fn wxyz_from_xyzw(xyzw: [f64; 4]) -> [f64; 4] {
    [xyzw[3], xyzw[0], xyzw[1], xyzw[2]]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn xyzw_moves_w_last() {
        assert_eq!(xyzw_from_wxyz([1.0, 2.0, 3.0, 4.0]), [2.0, 3.0, 4.0, 1.0]);
        assert_eq!(wxyz_from_xyzw(xyzw_from_wxyz([1.0, 2.0, 3.0, 4.0])), [1.0, 2.0, 3.0, 4.0]);
    }
}
