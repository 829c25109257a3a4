//! The crate's one error type.

use std::path::PathBuf;

/// Everything that can go wrong reading or writing a C3D file.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The underlying reader or writer failed.
    #[error("i/o error: {0}")]
    Io(#[from] std::io::Error),
    /// The first bytes do not look like a C3D header.
    #[error("not a c3d file: {0}")]
    NotC3d(String),
    /// The processor byte of the parameter section is not 84, 85 or 86.
    #[error("unsupported processor type {0} (expected 84 intel, 85 dec or 86 mips)")]
    Processor(u8),
    /// The parameter section cannot be decoded at all.
    #[error("corrupt parameter section at byte {offset}: {message}")]
    Parameters {
        /// Byte offset in the file.
        offset: u64,
        /// What is wrong there.
        message: String,
    },
    /// Header and parameters describe a data section this file cannot hold.
    #[error("inconsistent file: {0}")]
    Layout(String),
    /// The data section ends inside a frame (streaming reader).
    #[error("truncated data section: frame {frame} of {frames} is incomplete")]
    Truncated {
        /// Zero-based index of the incomplete frame.
        frame: usize,
        /// Frames announced by the file.
        frames: usize,
    },
    /// The in-memory file cannot be written in the requested format.
    #[error("cannot write c3d: {0}")]
    Write(String),
    /// Any of the above, with the file it happened in.
    #[error("{}: {source}", path.display())]
    InFile {
        /// The file.
        path: PathBuf,
        /// The error.
        #[source]
        source: Box<Error>,
    },
}

impl Error {
    pub(crate) fn in_file(self, path: &std::path::Path) -> Self {
        Error::InFile { path: path.to_path_buf(), source: Box::new(self) }
    }
}
