//! Retargeting: GMR-schema IK configs, per-frame targets, the damped-least-squares solver,
//! the resulting robot motion, its writers and quality metrics.

pub mod motion;

pub use motion::{RobotMotion, TrackedTargets};
