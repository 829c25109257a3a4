//! Retargeting: human motion (BVH, C3D markers, or any [`fk::HumanMotion`]) onto humanoid
//! robots described in MJCF or URDF, as GMR does and beyond.
//!
//! # The way in: [`Retargeter`]
//!
//! A [`Retargeter`] owns a robot (a shipped one by key, see [`shipped`], or a model file),
//! how its IK config is chosen, and the solve options. It retargets clips (BVH, C3D, human
//! motions) and streams (one frame at a time with [`Retargeter::step`], warm-started), and
//! writes ([`Retargeter::write`]: npz, csv, pkl, json) and measures
//! ([`Retargeter::report`]) what it solved.
//!
//! ```
//! use retarget::{Retargeter, SolveMode};
//!
//! // A BVH text: here a tiny LAFAN1-named skeleton standing upright (Y up, cm), two frames.
//! let text = tiny_lafan1_bvh();
//! # fn tiny_lafan1_bvh() -> String {
//! #     let open = |name: &str, offset: &str| {
//! #         format!("JOINT {name}\n{{ OFFSET {offset} CHANNELS 3 Zrotation Yrotation Xrotation\n")
//! #     };
//! #     let chain = |joints: &[(String, String)], end: &str| {
//! #         let opened: String = joints.iter().map(|(n, o)| open(n, o)).collect();
//! #         opened + &format!("End Site\n{{ OFFSET {end} }}\n") + &"}\n".repeat(joints.len())
//! #     };
//! #     let leg = |side: &str, x: f64| {
//! #         let names = ["UpLeg", "Leg", "Foot", "Toe"].map(|p| format!("{side}{p}"));
//! #         let offsets = [format!("{x} 0 0"), "0 -43 0".into(), "0 -42 0".into(), "0 -6 14".into()];
//! #         chain(&names.into_iter().zip(offsets).collect::<Vec<_>>(), "0 0 5")
//! #     };
//! #     let arm = |side: &str, x: f64| {
//! #         let names = ["Shoulder", "Arm", "ForeArm", "Hand"].map(|p| format!("{side}{p}"));
//! #         let offsets =
//! #             [format!("{} 10 0", 4.0 * x), format!("{} 0 0", 14.0 * x), "0 -28 0".into(), "0 -25 0".into()];
//! #         chain(&names.into_iter().zip(offsets).collect::<Vec<_>>(), "0 -15 0")
//! #     };
//! #     let neck = [("Neck".into(), "0 15 0".into()), ("Head".into(), "0 10 0".into())];
//! #     let frame = |z: f64| format!("0 95 {z} {}\n", "0 ".repeat(66));
//! #     "HIERARCHY\nROOT Hips\n{ OFFSET 0 0 0 CHANNELS 6 Xposition Yposition Zposition Zrotation \
//! #      Yrotation Xrotation\n".to_owned()
//! #         + &leg("Left", 9.0) + &leg("Right", -9.0)
//! #         + &open("Spine", "0 10 0") + &open("Spine1", "0 12 0") + &open("Spine2", "0 12 0")
//! #         + &chain(&neck, "0 15 0") + &arm("Left", 1.0) + &arm("Right", -1.0)
//! #         + "}\n}\n}\n}\nMOTION\nFrames: 2\nFrame Time: 0.033333\n" + &frame(0.0) + &frame(1.0)
//! # }
//! let bvh = bvh::parse(text.as_bytes())?;
//!
//! // The shipped Unitree G1 with GMR's exact solve and GMR's tuned LAFAN1 config.
//! let retargeter = Retargeter::new("unitree_g1")?.with_mode(SolveMode::Gmr);
//! let (motion, diagnostics) = retargeter.retarget_bvh(&bvh)?;
//! assert_eq!((motion.num_frames(), motion.nq), (2, 36));
//! assert!(diagnostics.human_inferred.contains("configs/gmr/bvh_lafan1_to_g1.json"));
//!
//! // Write it as BeyondMimic's npz (or .csv, .pkl, .json) and measure it.
//! let path = std::env::temp_dir().join(format!("retarget-doc-{}.npz", std::process::id()));
//! retargeter.write(&motion, &path, None)?;
//! let report = retargeter.report(&motion, &Default::default())?;
//! assert_eq!(report.frames, 2);
//! # std::fs::remove_file(&path)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # The API
//!
//! - **The way in**: [`Retargeter`], fed whole clips or one [`HumanFrame`] at a time;
//!   [`Retargeter::retarget_files`] gives one [`FileResult`] per file.
//! - **Options** (each with a `Default`): [`RetargetOptions`] holds the [`SolveMode`] —
//!   [`SolveMode::Gmr`] is GMR's solve exactly, [`SolveMode::Plausible`] (the default) adds
//!   planted feet and hard constraints, tuned by [`PlausibleOptions`]: [`Planting`],
//!   [`SpeedLimits`], [`SelfCollisionMode`], [`ContactOptions`], [`FootPlanOptions`] (with its
//!   [`Anchor`]), [`TrajectoryOptions`] (with its [`Objective`] and [`DynamicsOptions`]). Beside
//!   the mode: [`SolverOptions`] (with its [`Arithmetic`]) and [`ChunkOptions`].
//! - **Inputs** besides the human motion: [`IkConfig`] (GMR's schema, of [`MatchEntry`]s),
//!   [`MarkerConfig`] (C3D markers: [`MarkerHeight`], [`MarkerMotion`]), [`FbxClip`], and
//!   the robot's recognised [`RobotRoles`] ([`RobotRole`], [`Sole`]).
//! - **Outputs**: [`RobotMotion`] (with its [`FootContacts`] and [`TrackedTargets`]),
//!   [`ClipDiagnostics`] of [`FrameDiagnostics`] and [`StageReport`]s ([`StageValue`]),
//!   [`resample()`] to another frame rate, [`blocked_limbs`] ([`BlockedLimb`], [`PinnedJoint`]):
//!   where a limb could not follow.
//! - **GMR's BVH loader**, for code written against GMR: [`load_bvh_gmr`], [`GmrBvhFormat`],
//!   [`GMR_HUMAN_HEIGHT`].
//! - **Modules**: [`writers`] (npz, csv, pkl, json; reading our npz back), [`report`] (the
//!   quality report), [`derive`](mod@derive) (IK configs derived for any skeleton and robot)
//!   and [`shipped`] (the robots shipped with the crate).
//!
//! Every fallible call returns the one [`Error`].

// Library code never panics on input (issue 15): the compiler checks it. Tests may (clippy.toml).
// Numeric modules allow indexing with the reason in their header.
// Every type a public signature mentions has a public name (the facade or `internals`).
#![deny(unnameable_types)]
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

// The crate's modules are its own; what users call is the facade below, the four public
// modules and nothing else (each item has one path). Benches, fuzz targets and integration
// tests reach internals through `internals`.
mod centroidal;
mod config;
mod constraints;
mod contact_phases;
pub mod derive;
mod error;
mod fbx_clip;
mod feet;
mod follow;
mod gmr;
mod ik;
mod joint_speed;
mod lie;
mod marker_config;
mod motion;
mod qp;
pub mod report;
mod resample;
mod retargeter;
mod robot_names;
mod robot_roles;
pub mod shipped;
mod smpl;
mod solve;
mod targets;
pub mod writers;

// The way in.
pub use retargeter::{FileResult, HumanFrame, Retargeter};

// The options: what a user sets.
pub use contact_phases::ContactOptions;
pub use feet::{Anchor, FootPlanOptions};
pub use ik::{Arithmetic, SolverOptions};
pub use solve::trajectory::Objective;
pub use solve::{
    ChunkOptions, DynamicsOptions, Planting, PlausibleOptions, RetargetOptions, SelfCollisionMode,
    SolveMode, SpeedLimits, SubjectHeight, TrajectoryOptions,
};

// The inputs besides the human motion: IK and marker configs, FBX clips, robot roles.
pub use config::{IkConfig, MatchEntry};
pub use fbx_clip::FbxClip;
pub use marker_config::{MarkerConfig, MarkerHeight, MarkerMotion};
pub use robot_roles::{RobotRole, RobotRoles, Sole};

// The outputs.
pub use follow::{blocked_limbs, Blocked as BlockedLimb, PinnedJoint};
pub use ik::FrameDiagnostics;
pub use motion::{FootContacts, RobotMotion, TrackedTargets};
pub use resample::resample;
pub use solve::{ClipDiagnostics, StageReport, StageValue};

// GMR's BVH loader, for code written against GMR.
pub use gmr::{
    load_bvh as load_bvh_gmr, BvhFormat as GmrBvhFormat, HUMAN_HEIGHT as GMR_HUMAN_HEIGHT,
};

pub use error::Error;

/// Not API: the crate's internals, for benches, fuzz targets and integration tests. They may
/// change at any time.
#[doc(hidden)]
pub mod internals {
    pub use crate::constraints::{Constraint, Grip, GripBox, Ground, SelfCollision, StepContext};
    pub use crate::feet::detect_feet;
    pub use crate::ik::{GripPoint, PointTask, Solver, TaskSpec};
    pub use crate::joint_speed::JointSpeedLimits;
    pub use crate::lie::{mat_to_quat, Pose};
    pub use crate::marker_config::labelled_points;
    pub use crate::qp::{DenseQp, QpStatus};
    pub use crate::smpl::{frames_from, GMR_FIRST_FRAME};
    pub use crate::solve::banded::{Banded, NotPositiveDefinite};
    pub use crate::solve::{retarget_bvh, retarget_motion, retarget_motion_chunked, task_specs};
    pub use crate::targets::{ScaledBody, TargetMap};
}
