//! The small dense convex QPs of one IK step.
//!
//! - [`BoxQp`]: bounds only, primal active set on a tree-sparse factorisation. GMR's solve
//!   (`--gmr`) uses it: joint ranges are its only constraints.
//! - [`DenseQp`]: bounds plus general linear inequalities `a·x ≥ b`, Goldfarb–Idnani's dual
//!   active-set method. The default solve uses it for the ground, self-collision, contact and
//!   joint-speed constraints.

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

mod boxed;
mod dual;

pub use boxed::{BoxQp, QpStatus};
pub use dual::DenseQp;
