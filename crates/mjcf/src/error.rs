//! The crate's one error type. Positions are `file:line:column`, computed only when an error
//! is built (from the byte offset the syntax tree keeps).

use std::fmt;
use std::path::PathBuf;

/// Where in which file something was written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    pub file: String,
    pub line: u32,
    pub column: u32,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}", self.file, self.line, self.column)
    }
}

/// Everything that can go wrong reading or compiling an MJCF model.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file (the model or an `<include>`) could not be read.
    #[error("{}: cannot read file: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The text is not well-formed XML.
    #[error("{at}: invalid xml: {message}")]
    Xml { at: Location, message: String },
    /// Well-formed XML that is not a valid MJCF model (bad value, unknown class, ...).
    #[error("{at}: {message}")]
    Invalid { at: Location, message: String },
    /// Valid MJCF using a feature this crate does not implement and that changes kinematics.
    #[error("{at}: unsupported: {message}")]
    Unsupported { at: Location, message: String },
    /// A problem with the model as a whole (no position in a file).
    #[error("{file}: {message}")]
    Model { file: String, message: String },
}
