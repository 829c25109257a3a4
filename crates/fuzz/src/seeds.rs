//! The seed inputs of the targets: the workspace's own test files.

use std::path::{Path, PathBuf};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Files under `dir` (relative to the workspace) whose name ends with `suffix`.
pub(crate) fn files(dir: &str, suffix: &str) -> Vec<Vec<u8>> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(workspace().join(dir))
        .map(|entries| entries.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    paths.retain(|p| p.to_string_lossy().ends_with(suffix));
    paths.sort();
    paths.iter().filter_map(|p| std::fs::read(p).ok()).collect()
}
