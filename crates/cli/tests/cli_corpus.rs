//! The corpus gate (issue 39): a fixed, short subset of `scripts/quality-corpus` (every kind
//! of source: BVH at 30 and 120 fps, FBX, AMASS SMPL+H) onto the G1 with `--gmr` beside the
//! default, which must keep every cap; and `retarget batch`'s per-clip verdicts. Clips from
//! the shared data (`RETARGET_SHARED`).

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::{Path, PathBuf};
use std::process::Command;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cli_corpus_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The subset CI runs: short clips of four kinds whose default solve keeps every cap today.
const SUBSET: [&str; 4] = [
    "data/bvh/bandai_dataset-1_walk_normal_001.bvh",
    "data/soma/item_pick_up_standing_R_001__A410.bvh",
    "data/fbx/ozz_pab_walk_motionbuilder2015.fbx",
    "reference/smpl/motions/smplh_walk_poses.npz",
];

#[test]
fn the_corpus_subset_keeps_every_cap() {
    let Some(shared) = shared::shared_dir() else { return };
    let out = temp_dir("subset");
    let clips: Vec<String> = SUBSET.iter().map(|c| shared.join(c).display().to_string()).collect();
    let run = Command::new("bash")
        .arg(repo().join("scripts/quality-corpus"))
        .args(["--robots", "unitree_g1", "--jobs", "2", "--out"])
        .arg(&out)
        .arg("--clips")
        .args(&clips)
        .env("RETARGET_BIN", env!("CARGO_BIN_EXE_retarget"))
        .env("RETARGET_SHARED", &shared)
        .output()
        .expect("runs scripts/quality-corpus");
    let (stdout, stderr) =
        (String::from_utf8_lossy(&run.stdout), String::from_utf8_lossy(&run.stderr));
    assert!(run.status.success(), "a default row broke a cap:\n{stdout}\n{stderr}");
    assert!(stderr.contains("default: 0 of 4 clip × robot rows flagged"), "{stderr}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("quality-corpus.json")).unwrap())
            .unwrap();
    let rows = json["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 8, "4 clips × default and --gmr");
    for row in rows {
        assert!(row.get("error").is_none(), "{row}");
        assert!(row["verdict"]["ok"].is_boolean() && row["dynamics_share"].is_number(), "{row}");
    }
    // --gmr is measured for comparison: GMR's solve leaves geoms under the floor here.
    assert!(rows.iter().any(|r| r["solve"] == "gmr" && r["verdict"]["ok"] == false));
    let page = std::fs::read_to_string(out.join("quality-corpus.md")).unwrap();
    assert!(
        page.contains("| bandai_dataset-1_walk_normal_001.bvh | unitree_g1 | 30 | ok |"),
        "{page}"
    );
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn batch_writes_each_clips_verdict_and_names_the_flagged_ones() {
    let Some(shared) = shared::shared_dir() else { return };
    let input = temp_dir("batch_in");
    let output = temp_dir("batch_out");
    std::fs::create_dir_all(input.join("walks")).unwrap();
    for (name, to) in [
        ("bandai_dataset-1_walk_normal_001.bvh", "walks/walk.bvh"),
        ("bandai_dataset-1_run_normal_001.bvh", "run.bvh"),
    ] {
        std::fs::copy(shared.join("data/bvh").join(name), input.join(to)).unwrap();
    }
    // GMR's solve puts geoms through the floor on both clips: each is flagged.
    let batch = |extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_retarget"))
            .arg("batch")
            .arg(&input)
            .args(["--robot", "unitree_g1", "--gmr", "--overwrite", "-o"])
            .arg(&output)
            .args(extra)
            .output()
            .unwrap()
    };
    let run = batch(&[]);
    let stdout = String::from_utf8_lossy(&run.stdout).into_owned();
    assert_eq!(run.status.code(), Some(0), "{stdout}");
    assert!(stdout.contains("verdicts: 2 of 2 clips flagged"), "{stdout}");
    assert!(
        stdout.contains("  flagged run.bvh: ") && stdout.contains("  flagged walks/walk.bvh: ")
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(output.join("summary.json")).unwrap())
            .unwrap();
    for clip in summary["clips"].as_array().unwrap() {
        let verdict = &clip["verdict"];
        assert_eq!(verdict["ok"], false, "{clip}");
        let flags: Vec<&str> =
            verdict["flags"].as_array().unwrap().iter().map(|f| f.as_str().unwrap()).collect();
        assert!(flags.contains(&"floor_skating"), "{flags:?}");
        // The full checks, values and caps are in the row's report.
        assert!(clip["metrics"]["verdict"]["checks"].as_array().unwrap().len() >= 10);
    }
    assert_eq!(summary["totals"]["flagged"], 2);
    assert_eq!(summary["totals"]["flags"]["floor_skating"], 2);
    // --fail-on-flag: the exit code says so.
    assert_eq!(batch(&["--fail-on-flag"]).status.code(), Some(3));
    std::fs::remove_dir_all(&input).unwrap();
    std::fs::remove_dir_all(&output).unwrap();
}
