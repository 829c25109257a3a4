//! The crate's one error type. Every variant names the file; those about a take name it too.

use std::path::PathBuf;

/// Everything that can go wrong reading an FBX file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    #[error("{}: cannot read file: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The bytes are not a readable FBX file (ufbx's message: corrupt, truncated, not FBX).
    #[error("{file}: not a readable FBX file: {message}")]
    Parse { file: String, message: String },
    /// No `LimbNode`, `Root` or `Null` hierarchy to read a skeleton from.
    #[error(
        "{file}: no skeleton: the file has no LimbNode/Root/Null hierarchy (models: {models})"
    )]
    NoSkeleton { file: String, models: String },
    /// The file has no animation stack (take).
    #[error("{file}: no animation: the file has no take (AnimationStack)")]
    NoAnimation { file: String },
    /// A `--take` that names no take and is no take index.
    #[error("{file}: unknown take `{take}`; the file's takes: {available}")]
    UnknownTake { file: String, take: String, available: String },
    /// A take without a single animation key.
    #[error("{file}: take `{take}` has no keys: nothing moves in it")]
    EmptyTake { file: String, take: String },
    /// A take whose declared range and keys give no frame at the file's rate.
    #[error("{file}: take `{take}`: {message}")]
    BadTake { file: String, take: String, message: String },
    /// An axis system that no rotation turns into ours (left-handed or degenerate).
    #[error("{file}: unsupported axis system ({axes}): left-handed or degenerate, it would mirror the motion")]
    Axes { file: String, axes: String },
    /// ufbx could not evaluate a take at a time.
    #[error("{file}: take `{take}` at {time} s: {message}")]
    Evaluate { file: String, take: String, time: f64, message: String },
    /// A node's evaluated transform is not finite (NaN or infinite keys or properties).
    #[error("{file}: take `{take}` at {time} s: the transform of node `{node}` is not finite")]
    NonFinite { file: String, take: String, time: f64, node: String },
}
