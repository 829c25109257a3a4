//! Retargeting: GMR-schema IK configs, per-frame targets, the damped-least-squares solver,
//! the resulting robot motion, its writers and quality metrics.

// Library code never panics on input (issue 15): the compiler checks it. Tests may (clippy.toml).
// Numeric modules allow indexing with the reason in their header.
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

pub mod chunked;
pub mod config;
pub mod constraints;
pub mod contact;
pub mod derive;
pub mod feet;
pub mod joint_speed;
pub mod lie;
pub mod motion;
pub mod pipeline;
pub mod qp;
pub mod report;
pub mod resample;
pub mod robot_names;
pub mod robot_roles;
pub mod solver;
pub mod targets;
pub mod writers;

pub use config::{IkConfig, MatchEntry};
pub use motion::{FootContacts, RobotMotion, TrackedTargets};
pub use pipeline::{
    retarget_bvh, retarget_motion, ClipDiagnostics, Error, PlausibleOptions, RetargetOptions,
    SolveMode, SpeedLimits,
};
pub use robot_roles::{RobotRole, RobotRoles, Sole};
pub use solver::{FrameDiagnostics, Solver, SolverOptions, TaskSpec};
