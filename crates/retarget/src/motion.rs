//! The retargeter's output: robot configurations over time, plus what they tracked.

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use nalgebra::{UnitQuaternion, Vector3};

/// The world targets the solver tracked, per frame and per target body.
#[derive(Debug, Clone, PartialEq)]
pub struct TrackedTargets {
    /// Robot bodies with a task, in config (table) order.
    pub body_names: Vec<String>,
    /// `[frame * body_names.len() + k]`, metres, world frame (Z up).
    pub pos: Vec<Vector3<f64>>,
    /// Same layout; world orientation targets.
    pub quat: Vec<UnitQuaternion<f64>>,
}

/// Per frame, whether each foot of the source (the human) is in contact with the floor.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FootContacts {
    pub left: Vec<bool>,
    pub right: Vec<bool>,
    /// Per foot (`[left, right]`) and frame, whether the foot stands on its toes alone: in
    /// contact with its toe point holding and its heel point not (kneeling, tiptoe, a turn
    /// on the ball of the foot, push-off). `None` where unknown (contacts read from a file,
    /// a foot seen through its heel alone).
    pub on_toes: Option<[Vec<bool>; 2]>,
}

/// Joint trajectories for one robot: `qpos` per frame in MuJoCo's layout.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotMotion {
    pub fps: f64,
    /// Length of one configuration (MuJoCo `nq`).
    pub nq: usize,
    /// `frames × nq`, row-major. Free root first: x y z (m), quaternion w x y z, then the
    /// other joints in MJCF order (rad or m).
    pub qpos: Vec<f64>,
    /// Names of the non-free joints, in qpos order.
    pub joint_names: Vec<String>,
    /// Every body of the model except the world, in MuJoCo order.
    pub body_names: Vec<String>,
    /// What the solver tracked, when known.
    pub targets: Option<TrackedTargets>,
    /// The source's foot contact phases, when known (npz `contact_left`, `contact_right`).
    pub contacts: Option<FootContacts>,
}

impl RobotMotion {
    /// The joint names a motion of `model` carries: every joint but the free root, in model
    /// order ([`RobotMotion::joint_names`]).
    #[must_use]
    pub fn model_joint_names(model: &mjcf::Model) -> Vec<String> {
        model
            .joints
            .iter()
            .filter(|j| j.kind != mjcf::JointType::Free)
            .map(|j| j.name.clone())
            .collect()
    }

    /// The body names a motion of `model` carries: every body but the world, in model order
    /// ([`RobotMotion::body_names`]).
    #[must_use]
    pub fn model_body_names(model: &mjcf::Model) -> Vec<String> {
        model.bodies.iter().skip(1).map(|b| b.name.clone()).collect()
    }

    #[must_use]
    pub fn num_frames(&self) -> usize {
        self.qpos.len().checked_div(self.nq).unwrap_or(0)
    }

    /// One frame's configuration. Panics if `index >= num_frames()`.
    #[must_use]
    // A caller's out-of-range frame is a bug, like slice indexing (documented above).
    #[allow(clippy::indexing_slicing)]
    pub fn frame(&self, index: usize) -> &[f64] {
        &self.qpos[index * self.nq..(index + 1) * self.nq]
    }
}
