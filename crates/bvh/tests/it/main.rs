//! The `bvh` crate's one integration-test binary: golden error cases, the real files in
//! `../shared/data/bvh`, round trips, JSON and the mutation fuzz.

#[path = "../../../../tests/support/shared.rs"]
mod shared;

mod fuzz;
mod golden;
mod real;

use std::path::PathBuf;

/// This crate's own fixtures.
pub fn fixture_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data")
}

/// Every `.bvh` in the shared data folder, sorted; `None` outside CI without the folder.
pub fn shared_bvh_files() -> Option<Vec<PathBuf>> {
    let dir = shared::shared_file("data/bvh")?;
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "bvh"))
        .collect();
    files.sort();
    assert!(files.len() >= 10, "expected the shared BVH files in {}", dir.display());
    Some(files)
}

/// Write, re-parse and compare bit for bit.
pub fn assert_round_trip(bvh: &bvh::Bvh, what: &str) {
    let mut text = Vec::new();
    bvh::write(bvh, &mut text).unwrap_or_else(|e| panic!("{what}: write: {e}"));
    let again = bvh::parse(&text).unwrap_or_else(|e| panic!("{what}: re-parse: {e}"));
    assert_eq!(again.skeleton, bvh.skeleton, "{what}: structure differs after a round trip");
    assert_eq!(again.motion.num_frames, bvh.motion.num_frames, "{what}");
    assert_eq!(again.motion.frame_time.to_bits(), bvh.motion.frame_time.to_bits(), "{what}");
    let bits = |b: &bvh::Bvh| b.motion.values.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert!(bits(&again) == bits(bvh), "{what}: motion values differ after a round trip");
}
