//! The binary's file helpers, shared by every subcommand: reading a BVH with its warnings
//! on stderr, and writing outputs atomically.

use std::path::Path;

/// Parse a BVH file and print what the parser tolerated to stderr, one line per warning:
/// `file:line:column: warning: message`.
pub(crate) fn read_bvh(path: &Path) -> anyhow::Result<bvh::Bvh> {
    let (bvh, warnings) = bvh::from_path_with_warnings(path)?;
    for warning in &warnings {
        eprintln!("{}:{warning}", path.display());
    }
    Ok(bvh)
}

/// Write `bytes` to `path` atomically (see [`atomic_write_with`]).
pub(crate) fn atomic_write(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    atomic_write_with(path, |w| w.write_all(bytes))
}

/// Fill a temporary file beside `path` through `write`, then rename it into place
/// ([`retarget::writers::write_atomically`]): an interrupted or failed run never leaves a
/// half-written file under the final name.
pub(crate) fn atomic_write_with(
    path: &Path,
    write: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
) -> anyhow::Result<()> {
    retarget::writers::write_atomically(path, |w| write(w))
        .map_err(|e| anyhow::anyhow!("cannot write {e}"))
}
