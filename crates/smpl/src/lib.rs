//! SMPL-X and SMPL+H input: body model files as their owners distribute them, AMASS motion
//! files, their forward kinematics onto the canonical humanoid, and GMR's SMPL-X loader.
//!
//! ```text
//! BodyModel::from_folder(dir, kind, gender)   smplx/SMPLX_*.npz, smplh/<gender>/model.npz
//! SmplMotion::from_path(file)                  AMASS *_stageii.npz (SMPL-X), *_poses.npz (SMPL+H)
//! forward::clip(&model, &motion) -> Clip      world poses (m, Z up) + roles + height + floor
//! gmr::offline_fast(&model, &motion, 30.0)    GMR's human data, resampled as GMR does
//! ```
//!
//! The body models are licensed by their owners and never shipped or downloaded: a missing
//! one is an error naming the file expected and where it is obtained
//! ([`conventions::ModelKind::obtain`]). Only `.npz` models are read; a `.pkl` (a Python
//! pickle) is an error naming the `.npz` to use. Joint names are smplx's, so the roles come
//! from `fk`'s SMPL naming convention; the world is AMASS's (Z up, metres), which is ours.
//!
//! This crate never prints and never panics on input.

// Library code never panics on input (issue 15): the compiler checks it. Tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

pub mod conventions;
mod error;
pub mod forward;
pub mod gmr;
mod model;
mod models;
mod motion;

pub use conventions::{Gender, ModelKind, BODY_MODELS_ENV};
pub use error::Error;
pub use forward::{clip, forward, Clip};
pub use model::BodyModel;
pub use models::BodyModels;
pub use motion::SmplMotion;
