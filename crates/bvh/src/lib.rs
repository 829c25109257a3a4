//! BVH (Biovision Hierarchy) motion files: parse, write, summarise, export to JSON.
//!
//! The data model is the file as written: a flat skeleton in file order (parents before
//! children) and a dense `frames × channels` matrix of `f64`. Nothing here knows about
//! units, axes or robots; `fk` gives the numbers meaning.

mod skeleton;

pub use skeleton::{Axis, Bvh, Channel, Joint, JointId, JointKind, Motion, Skeleton};
