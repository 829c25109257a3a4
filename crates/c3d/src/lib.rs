//! C3D motion-capture files: read and write.
//!
//! A C3D file is 512-byte blocks: a header, a parameter section (groups of typed,
//! dimensioned parameters) and a data section of frames (points, then analog samples).
//! This crate reads all three processor types (Intel, DEC with VAX floats, MIPS big-endian),
//! integer and float data, either whole ([`C3d::from_path`]) or one frame at a time
//! ([`Reader`]), and writes files in any of them ([`C3d::write`]).
//!
//! Values are returned as written: file units (usually mm) and lab axes. Invalid point samples
//! (residual word −1) are `None`, never zeros. Parameter values win over their header copies;
//! the header is kept as read in [`C3d::header`]. Corrupt input gives an [`Error`] or, where
//! the data can still be read, a warning in [`C3d::warnings`]; it never panics, and no count
//! read from a file allocates more than a small multiple of the file's size.
//!
//! ```no_run
//! let c3d = c3d::C3d::from_path(std::path::Path::new("trial.c3d"))?;
//! let first = c3d.points.get(0, 0); // Option<Point>: None when the marker is missing
//! # Ok::<(), c3d::Error>(())
//! ```

// Library code never panics on input (issue 15): the compiler checks it. Tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

mod error;
mod header;
mod layout;
mod model;
mod params;
mod processor;
mod reader;
mod writer;

pub use error::Error;
pub use header::{Header, HeaderEvent};
pub use layout::{DataFormat, Layout};
pub use model::{Analog, C3d, Event, EventSource, Points};
pub use params::{Data, Group, Parameter, Parameters, Value};
pub use processor::{vax_f_to_f32, Processor};
pub use reader::{Frame, Point, Reader};
pub use writer::Format;
