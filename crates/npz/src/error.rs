//! The one error type of this crate: which file, which member, what is wrong with it.

use std::path::PathBuf;

use crate::Dtype;

/// Everything that can go wrong reading an `.npz`. Each names the file; those about one
/// array name its key too.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The file cannot be opened or read.
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// Not a readable `.npz` (zip) archive.
    #[error("{}: not an .npz file: {message}", path.display())]
    NotNpz { path: PathBuf, message: String },
    /// An array asked for is not in the file.
    #[error("{}: no `{key}` array (the file has: {})", path.display(), available.join(", "))]
    Missing { path: PathBuf, key: String, available: Vec<String> },
    /// An array that is a pickled Python object, which is never unpickled.
    #[error(
        "{}: array `{key}` is a pickled Python object (dtype object), which is not read",
        path.display()
    )]
    Pickled { path: PathBuf, key: String },
    /// An array that cannot be read as asked ([`Problem`]: header, dtype, shape, data).
    #[error("{}: array `{key}`: {problem}", path.display())]
    Array { path: PathBuf, key: String, problem: Problem },
}

/// What is wrong with one member of an `.npz` (the `problem` of [`Error::Array`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum Problem {
    /// The zip member itself cannot be opened (the zip library's message).
    #[error("cannot open the member: {0}")]
    Member(String),
    /// No `\x93NUMPY` magic, or too short to hold it.
    #[error("not a .npy array ({0})")]
    NotNpy(&'static str),
    /// A format version other than 1, 2 or 3.
    #[error("unsupported .npy format version {0}")]
    Version(u8),
    /// The header ends before its stated length.
    #[error("truncated .npy header")]
    TruncatedHeader,
    /// A header length far above any numpy writes.
    #[error("a .npy header of {0} bytes")]
    HugeHeader(usize),
    /// A header dict without a readable `descr` or `shape`.
    #[error("no valid '{0}' in the .npy header")]
    HeaderKey(&'static str),
    /// A `descr` that is not one of the dtypes read.
    #[error("unsupported dtype `{0}`")]
    Dtype(String),
    /// A shape whose element count overflows.
    #[error("shape overflows")]
    ShapeOverflows,
    /// Fewer data bytes than the shape needs.
    #[error("data truncated (fewer than the {count} elements of its shape)")]
    Truncated { count: usize },
    /// Reading (decompressing) the data failed.
    #[error("cannot read the data: {0}")]
    Read(String),
    /// Zero-width strings claiming more elements than the member has bytes: they take no
    /// bytes, so nothing else bounds their count (numpy never writes `<U0` with elements).
    #[error("dtype {dtype} with {count} elements in {bytes} bytes of data")]
    ZeroWidth { dtype: Dtype, count: usize, bytes: u64 },
    /// String elements wider than any name or label (1 MiB).
    #[error("strings of {0} bytes")]
    StringWidth(usize),
    /// A dtype other than the one asked for (numbers, integers, strings).
    #[error("dtype {dtype}: expected {expected}")]
    Kind { dtype: Dtype, expected: &'static str },
    /// A unicode element that is not a Unicode scalar value.
    #[error("invalid unicode in a string array")]
    Unicode,
    /// Rows asked for that do not divide the array.
    #[error("{count} elements are not rows of {row}")]
    Rows { count: usize, row: usize },
}
