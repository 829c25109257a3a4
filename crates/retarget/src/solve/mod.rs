//! The default solve's stages.

pub mod banded;
pub mod dynamics;
pub mod trajectory;
