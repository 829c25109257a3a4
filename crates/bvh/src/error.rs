//! The crate's one error type. Positions are computed from byte offsets only when an error
//! is built, so the happy path never counts lines.

use std::fmt;
use std::path::{Path, PathBuf};

/// A 1-based `line:column` position in a BVH file (column counted in characters).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Pos {
    pub line: usize,
    pub column: usize,
}

impl Pos {
    /// The position of byte `offset` in `src` (clamped to the end of `src`).
    #[must_use]
    pub fn from_offset(src: &[u8], offset: usize) -> Pos {
        let before = src.get(..offset).unwrap_or(src);
        let line_start = before.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
        let line = 1 + before.iter().filter(|&&b| b == b'\n').count();
        // Count characters, not bytes: UTF-8 continuation bytes do not start a column.
        let column = 1 + before
            .get(line_start..)
            .unwrap_or_default()
            .iter()
            .filter(|&&b| (b & 0xC0) != 0x80)
            .count();
        Pos { line, column }
    }
}

impl fmt::Display for Pos {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.line, self.column)
    }
}

/// Everything that can go wrong reading a BVH file. Messages are lowercase and start with
/// the position (`line:column`); [`Error::InFile`] prefixes the file name.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A keyword, name or number was expected and something else was found.
    #[error("{pos}: expected {expected}, found {found}")]
    Expected { pos: Pos, expected: &'static str, found: String },
    /// A `}` with no open joint.
    #[error("{pos}: unmatched `}}`")]
    ExtraBrace { pos: Pos },
    /// A `{` where a keyword was expected.
    #[error("{pos}: unexpected `{{`, expected OFFSET, CHANNELS, JOINT, End Site or `}}`")]
    UnexpectedBrace { pos: Pos },
    /// A joint's block ended (end of file, `MOTION`, `ROOT`) before its `}`.
    #[error("{pos}: missing `}}` for `{joint}` (opened at {open}), found {found}")]
    MissingBrace { pos: Pos, joint: String, open: Pos, found: String },
    /// `CHANNELS n` followed by a different number of channel names.
    #[error("{pos}: CHANNELS declares {declared} channels but names {found}")]
    ChannelCount { pos: Pos, declared: usize, found: usize },
    /// A channel name other than the six BVH knows and the three scale channels.
    #[error(
        "{pos}: unknown channel `{name}`, expected Xposition, Yposition, Zposition, \
         Xrotation, Yrotation, Zrotation, Xscale, Yscale or Zscale"
    )]
    UnknownChannel { pos: Pos, name: String },
    /// A token that should be a number and is not.
    #[error("{pos}: expected a number, found `{token}`")]
    NotANumber { pos: Pos, token: String },
    /// NaN or infinity (including overflow such as `1e999`).
    #[error("{pos}: `{token}` is not a finite number")]
    NonFinite { pos: Pos, token: String },
    /// A motion row with too few or too many values (`frame` counts from 1).
    #[error("{pos}: frame {frame} has {found} values, expected {expected}")]
    FrameLength { pos: Pos, frame: usize, found: usize, expected: usize },
    /// Structurally well-formed but meaningless (duplicate OFFSET, zero frame time, …).
    #[error("{pos}: {what}")]
    Invalid { pos: Pos, what: &'static str },
    /// The file could not be read.
    #[error("{}: {err}", path.display())]
    Io { path: PathBuf, err: std::io::Error },
    /// A parse error in a named file: `path:line:column: message`.
    #[error("{}:{inner}", path.display())]
    InFile { path: PathBuf, inner: Box<Error> },
}

impl Error {
    /// Where in the file the error is, if it is about the file's content.
    #[must_use]
    pub fn position(&self) -> Option<Pos> {
        match self {
            Error::Expected { pos, .. }
            | Error::ExtraBrace { pos }
            | Error::UnexpectedBrace { pos }
            | Error::MissingBrace { pos, .. }
            | Error::ChannelCount { pos, .. }
            | Error::UnknownChannel { pos, .. }
            | Error::NotANumber { pos, .. }
            | Error::NonFinite { pos, .. }
            | Error::FrameLength { pos, .. }
            | Error::Invalid { pos, .. } => Some(*pos),
            Error::Io { .. } => None,
            Error::InFile { inner, .. } => inner.position(),
        }
    }

    /// The file the error is about, if known.
    #[must_use]
    pub fn path(&self) -> Option<&Path> {
        match self {
            Error::Io { path, .. } | Error::InFile { path, .. } => Some(path),
            _ => None,
        }
    }

    /// Attach a file name to a parse error.
    #[must_use]
    pub fn in_file(self, path: &Path) -> Error {
        match self {
            Error::Io { .. } | Error::InFile { .. } => self,
            inner => Error::InFile { path: path.to_path_buf(), inner: Box::new(inner) },
        }
    }
}
