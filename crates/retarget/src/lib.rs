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
//! assert!(diagnostics.human_inferred.contains("bvh_lafan1_to_unitree_g1"));
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
//! Underneath: [`config`] (GMR-schema IK configs), [`derive`](mod@derive) and [`robot_roles`] (configs
//! derived for any skeleton and robot), [`targets`], [`solver`] and [`solve`] (the solve, stage by stage:
//! [`SolveMode::Gmr`] is GMR's exactly, the default adds planted feet and hard constraints),
//! [`motion`], [`writers`] and [`report`]. Every fallible call returns the one [`Error`].

// Library code never panics on input (issue 15): the compiler checks it. Tests may (clippy.toml).
// Numeric modules allow indexing with the reason in their header.
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

pub(crate) mod centroidal;
pub mod config;
pub mod constraints;
pub mod contact;
pub mod derive;
mod error;
pub mod fbx_clip;
pub mod feet;
pub mod follow;
pub mod gmr;
pub mod joint_speed;
pub mod lie;
pub mod marker_config;
pub mod motion;
pub mod qp;
pub mod report;
pub mod resample;
pub mod retargeter;
pub mod robot_names;
pub mod robot_roles;
pub mod shipped;
pub mod smpl;
pub mod solve;
pub mod solver;
pub mod targets;
pub mod writers;

pub use config::{IkConfig, MatchEntry};
pub use error::Error;
pub use fbx_clip::FbxClip;
pub use marker_config::MarkerConfig;
pub use motion::{FootContacts, RobotMotion, TrackedTargets};
pub use retargeter::{FileResult, HumanFrame, Retargeter};
pub use robot_roles::{RobotRole, RobotRoles, Sole};
pub use solve::{
    retarget_bvh, retarget_motion, retarget_motion_chunked, ChunkOptions, ClipDiagnostics,
    Planting, PlausibleOptions, RetargetOptions, SolveMode, SpeedLimits,
};
pub use solver::{Arithmetic, FrameDiagnostics, Solver, SolverOptions, TaskSpec};
