//! BVH (Biovision Hierarchy) motion files: parse, write, summarise, export to JSON.
//!
//! The data model is the file as written: a flat skeleton in file order (parents before
//! children) and a dense `frames × channels` matrix of `f64`. Nothing here knows about
//! units, axes or robots; `fk` gives the numbers meaning.
//!
//! Real exporters' quirks are read anyway (see [`parse_with_warnings`]); the ones that change
//! what the file says come back as [`Warning`]s with their position, never printed here.
//!
//! ```
//! let text = "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 Xposition Yposition Zposition\n\
//!             End Site\n {\n  OFFSET 0 1 0\n }\n}\nMOTION\nFrames: 1\nFrame Time: 0.5\n1 2 3\n";
//! let bvh = bvh::from_str(text)?;
//! assert_eq!(bvh.skeleton.joints[1].name, "Hips_End");
//! let mut out = Vec::new();
//! bvh::write(&bvh, &mut out)?;
//! assert_eq!(bvh::parse(&out)?, bvh);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

// Library code never panics on input (issue 15): the compiler checks it. Tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

mod error;
mod float;
mod parse;
mod skeleton;
mod summary;
mod warning;
mod write;

use std::path::Path;

pub use error::{Error, Pos};
pub use parse::{parse, parse_with_warnings};
pub use skeleton::{Axis, Bvh, Channel, Joint, JointId, JointKind, Motion, Skeleton};
pub use summary::{Summary, SummaryJoint, Units};
pub use warning::Warning;
pub use write::{write, write_json};

/// Parse BVH text held in a string (see [`parse()`]).
#[allow(clippy::should_implement_trait)] // a free function, like `serde_json::from_str`
pub fn from_str(text: &str) -> Result<Bvh, Error> {
    parse(text.as_bytes())
}

/// Read and parse a BVH file; errors name the file (`path:line:column: message`).
pub fn from_path(path: &Path) -> Result<Bvh, Error> {
    from_path_with_warnings(path).map(|(bvh, _)| bvh)
}

/// Read and parse a BVH file, with the quirks that were read anyway ([`parse_with_warnings`]).
pub fn from_path_with_warnings(path: &Path) -> Result<(Bvh, Vec<Warning>), Error> {
    let bytes = std::fs::read(path).map_err(|err| Error::Io { path: path.to_path_buf(), err })?;
    parse_with_warnings(&bytes).map_err(|e| e.in_file(path))
}
