//! Finding `../shared` (reference data) from tests. Included by path from each crate's
//! integration tests: `#[path = "../../../tests/support/shared.rs"] mod shared;`.
//!
//! Without `RETARGET_SHARED` a test says so on stderr and skips, except under CI (`CI` set),
//! where a missing or wrong path is a failure: CI must never skip reference-data tests.

#![allow(dead_code)]

use std::path::PathBuf;

/// The shared reference folder, or `None` (after a note on stderr) outside CI.
pub fn shared_dir() -> Option<PathBuf> {
    let in_ci = std::env::var_os("CI").is_some_and(|v| !v.is_empty() && v != "false");
    match std::env::var_os("RETARGET_SHARED") {
        Some(dir) => {
            let dir = PathBuf::from(dir);
            let dir = if dir.is_relative() {
                // Relative to the workspace root, where `.ci/run` and the README run from.
                PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..").join(dir)
            } else {
                dir
            };
            assert!(
                dir.join("DESIGN.md").is_file(),
                "RETARGET_SHARED={} has no DESIGN.md",
                dir.display()
            );
            Some(dir)
        }
        None if in_ci => {
            panic!("RETARGET_SHARED is not set under CI: reference-data tests must run")
        }
        None => {
            eprintln!("note: RETARGET_SHARED is not set; skipping a test on reference data");
            None
        }
    }
}

/// A file under the shared folder, or `None` when [`shared_dir`] is `None`.
pub fn shared_file(relative: &str) -> Option<PathBuf> {
    shared_dir().map(|d| d.join(relative))
}
