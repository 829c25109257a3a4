//! `retarget batch` end to end: a small tree of real clips, failure isolation, resume after
//! SIGKILL at several points, byte-identical outputs, shards and merged summaries.

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

const BIN: &str = env!("CARGO_BIN_EXE_retarget");

struct TempDir(PathBuf);

impl TempDir {
    fn new(tag: &str) -> TempDir {
        let p =
            std::env::temp_dir().join(format!("retarget-cli-batch-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&p);
        std::fs::create_dir_all(&p).unwrap();
        TempDir(p)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A BVH with the source's hierarchy and `count` frames starting at `start`.
fn excerpt(source: &str, start: usize, count: usize) -> String {
    let (head, motion) = source.split_once("MOTION").expect("a MOTION block");
    let mut lines = motion.lines().filter(|l| !l.trim().is_empty());
    let _frames = lines.next();
    let frame_time = lines.next().expect("Frame Time line");
    let rows: Vec<&str> = lines.skip(start).take(count).collect();
    assert_eq!(rows.len(), count, "source too short for the excerpt");
    format!("{head}MOTION\nFrames: {count}\n{}\n{}\n", frame_time.trim(), rows.join("\n"))
}

/// Five excerpts of the LAFAN1 walk in nested folders, plus one malformed clip.
fn make_tree(root: &Path, source: &str) {
    for (i, rel) in
        ["a/walk0.bvh", "a/walk1.bvh", "b/c/walk2.bvh", "walk3.bvh", "walk4.bvh"].iter().enumerate()
    {
        let path = root.join(rel);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, excerpt(source, 600 * i, 240)).unwrap();
    }
    std::fs::write(root.join("a/broken.bvh"), "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0\n").unwrap();
}

/// A temporary folder holding `tree/` (see [`make_tree`]); `None` without reference data.
fn tree_of_clips(tag: &str) -> Option<(TempDir, PathBuf)> {
    let walk = shared::shared_file("data/bvh/lafan1_take_via_bvhtools_test.bvh")?;
    let source = std::fs::read_to_string(walk).unwrap();
    let tmp = TempDir::new(tag);
    let tree = tmp.0.join("tree");
    make_tree(&tree, &source);
    Some((tmp, tree))
}

/// SIGKILL's number (9 on every Unix this runs on).
fn libc_sigkill() -> i32 {
    9
}

fn batch(args: &[&str]) -> Command {
    let mut cmd = Command::new(BIN);
    cmd.arg("batch").args(args).stdout(Stdio::piped()).stderr(Stdio::piped());
    cmd
}

/// Every regular file under `root`, relative, sorted, with its bytes.
fn files(root: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else {
                let rel = path.strip_prefix(root).unwrap().to_string_lossy().replace('\\', "/");
                out.push((rel, std::fs::read(&path).unwrap()));
            }
        }
    }
    out.sort();
    out
}

fn outputs(root: &Path) -> Vec<(String, Vec<u8>)> {
    files(root).into_iter().filter(|(name, _)| !name.starts_with("summary")).collect()
}

#[test]
fn batch_isolates_failures_and_resumes_after_kills_with_identical_outputs() {
    let Some((tmp, tree)) = tree_of_clips("kill") else { return };
    let tree_s = tree.to_str().unwrap();

    // Uninterrupted reference run.
    let reference = tmp.0.join("ref");
    let done =
        batch(&[tree_s, "--robot", "unitree_g1", "-o", reference.to_str().unwrap(), "--jobs", "2"])
            .output()
            .unwrap();
    let stdout = String::from_utf8_lossy(&done.stdout);
    assert_eq!(done.status.code(), Some(1), "a failed clip makes the exit code 1: {stdout}");
    assert!(stdout.contains("converted 5") && stdout.contains("failed 1"), "{stdout}");
    assert!(stdout.contains("a/broken.bvh"), "the failed clip is named: {stdout}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(reference.join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["totals"]["converted"], 5);
    assert_eq!(summary["totals"]["frames"], 5 * 240);
    let rows = summary["clips"].as_array().unwrap();
    for row in rows.iter().filter(|r| r["status"] == "converted") {
        let inferred = row["inferred"].as_str().unwrap_or_default();
        assert!(inferred.starts_with("+Y up, centimetres"), "{row}");
    }
    let want = outputs(&reference);
    assert_eq!(want.len(), 5, "{:?}", want.iter().map(|f| &f.0).collect::<Vec<_>>());

    // Kill after the k-th clip's progress line (k = 1..4 of 6), then finish the rest. A kill
    // that lands while the batch still runs ends it by SIGKILL before its summary is written:
    // the test counts those, so it cannot pass with every "kill" arriving after the end.
    let resumed = tmp.0.join("resumed");
    let mut landed = 0;
    for k in 1..=4 {
        let mut child = batch(&[
            tree_s,
            "--robot",
            "unitree_g1",
            "-o",
            resumed.to_str().unwrap(),
            "--jobs",
            "2",
        ])
        .spawn()
        .unwrap();
        // The reader stays open until the child is reaped: closing it early would end the
        // child by SIGPIPE instead of our SIGKILL.
        let mut stderr = std::io::BufReader::new(child.stderr.take().unwrap());
        let (mut seen, mut line) = (0, String::new());
        while seen < k && std::io::BufRead::read_line(&mut stderr, &mut line).unwrap_or(0) > 0 {
            seen += usize::from(line.starts_with('['));
            line.clear();
        }
        let _ = child.kill(); // SIGKILL: no chance to clean up
        let status = child.wait().unwrap();
        drop(stderr);
        if std::os::unix::process::ExitStatusExt::signal(&status) == Some(libc_sigkill()) {
            landed += 1;
            assert!(!resumed.join("summary.json").exists(), "killed after {k} clips");
            let complete = outputs(&resumed)
                .iter()
                .filter(|(n, _)| !n.rsplit('/').next().unwrap().starts_with('.'))
                .count();
            assert!(complete < want.len(), "killed after {k} clips, yet all outputs exist");
        }
        let delay = format!("{k} clips");
        // Whatever exists under a final name is complete: it equals the reference.
        for (name, bytes) in outputs(&resumed)
            .iter()
            .filter(|(n, _)| !n.rsplit('/').next().unwrap().starts_with('.'))
        {
            let reference_bytes = &want
                .iter()
                .find(|(n, _)| n == name)
                .unwrap_or_else(|| panic!("unexpected output {name}"))
                .1;
            assert!(bytes == reference_bytes, "{name} is torn after a kill after {delay}");
        }
    }
    eprintln!("{landed} of 4 kills landed while the batch ran");
    assert!(landed >= 2, "only {landed} of 4 kills landed while the batch ran");
    let finish =
        batch(&[tree_s, "--robot", "unitree_g1", "-o", resumed.to_str().unwrap(), "--jobs", "2"])
            .output()
            .unwrap();
    assert_eq!(finish.status.code(), Some(1));
    let got: Vec<_> = outputs(&resumed)
        .into_iter()
        .filter(|(n, _)| !n.rsplit('/').next().unwrap().starts_with('.'))
        .collect();
    assert_eq!(got.len(), want.len());
    for ((gn, gb), (wn, wb)) in got.iter().zip(&want) {
        assert_eq!(gn, wn);
        assert!(gb == wb, "{gn} differs from the uninterrupted run");
    }
}

#[test]
fn shards_cover_the_tree_and_merge() {
    let Some((tmp, tree)) = tree_of_clips("shard") else { return };
    let out = tmp.0.join("out");
    let mut parts = Vec::new();
    for k in 0..2 {
        let shard = format!("{k}/2");
        let done = batch(&[
            tree.to_str().unwrap(),
            "--robot",
            "unitree_g1",
            "-o",
            out.to_str().unwrap(),
            "--shard",
            &shard,
            "--jobs",
            "1",
        ])
        .output()
        .unwrap();
        // Sorted files: a/broken.bvh is index 0, so shard 0 holds the failed clip.
        let stdout = String::from_utf8_lossy(&done.stdout);
        assert_eq!(done.status.code(), Some(if k == 0 { 1 } else { 0 }), "shard {shard}: {stdout}");
        let failed = if k == 0 { 1 } else { 0 };
        assert!(
            stdout.contains(&format!(
                "clips 3  converted {}  skipped 0  failed {failed}",
                3 - failed
            )),
            "{stdout}"
        );
        parts.push(out.join(format!("summary-shard-{k}-of-2.json")));
    }
    let merged = tmp.0.join("merged.json");
    let mut args = vec!["--merge-summaries".to_string()];
    args.extend(parts.iter().map(|p| p.to_string_lossy().into_owned()));
    args.extend(["-o".to_string(), merged.to_string_lossy().into_owned()]);
    let done = Command::new(BIN).arg("batch").args(&args).output().unwrap();
    assert_eq!(done.status.code(), Some(1), "the merged summary still has the failed clip");
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(merged).unwrap()).unwrap();
    assert_eq!(m["totals"]["clips"], 6);
    assert_eq!(m["totals"]["converted"], 5);
    assert_eq!(m["shards"].as_array().unwrap().len(), 2);
}

#[test]
fn long_clips_can_be_split_into_parallel_chunks() {
    let Some((tmp, tree)) = tree_of_clips("chunk") else { return };
    let out = tmp.0.join("out");
    let done = batch(&[
        tree.to_str().unwrap(),
        "--robot",
        "unitree_g1",
        "-o",
        out.to_str().unwrap(),
        "--chunk-frames",
        "100",
        "--lead-in",
        "30",
    ])
    .output()
    .unwrap();
    assert_eq!(done.status.code(), Some(1), "{}", String::from_utf8_lossy(&done.stderr));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["totals"]["converted"], 5);
    assert_eq!(summary["totals"]["frames"], 5 * 240, "chunks keep every frame once");
}
