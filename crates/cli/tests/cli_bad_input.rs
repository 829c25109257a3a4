//! Issue 15's reproductions, each now a clean error: exit code 1, a message naming the file
//! (and the frame where there is one), nothing written, and a batch that reports the clip
//! and goes on. Uses excerpts of the shared LAFAN1 walk take (`RETARGET_SHARED`).

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn retarget(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_retarget")).args(args).output().expect("runs retarget")
}

fn text(out: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cli_bad_input_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The walk take's hierarchy with its first `frames` frames, rows passed through `edit`.
fn walk_excerpt(frames: usize, edit: impl Fn(usize, &str) -> String) -> Option<String> {
    let source = shared::shared_file("data/bvh/lafan1_take_via_bvhtools_test.bvh")?;
    let full = std::fs::read_to_string(source).unwrap();
    let (head, motion) = full.split_once("MOTION").unwrap();
    let mut lines = motion.lines().filter(|l| !l.trim().is_empty());
    let _frames_line = lines.next().unwrap();
    let frame_time = lines.next().unwrap();
    let rows: Vec<String> = lines.take(frames).enumerate().map(|(f, r)| edit(f, r)).collect();
    Some(format!("{head}MOTION\nFrames: {frames}\n{frame_time}\n{}\n", rows.join("\n")))
}

fn unchanged(_: usize, row: &str) -> String {
    row.to_owned()
}

/// Every file under `dir`, relative and sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else {
                out.push(path.strip_prefix(dir).unwrap().to_string_lossy().into_owned());
            }
        }
    }
    out.sort();
    out
}

/// `Frames: 0` used to print a subject height of −0.048 m and write a 0-frame file (with
/// `--human-height` too).
#[test]
fn a_clip_without_frames_is_an_error_and_writes_nothing() {
    let dir = temp_dir("zero");
    let Some(zero) = walk_excerpt(0, unchanged) else { return };
    let bvh = dir.join("zero.bvh");
    std::fs::write(&bvh, zero).unwrap();
    for extra in [&[][..], &["--human-height", "1.7"], &["--gmr"]] {
        let args = [&["--bvh", bvh.to_str().unwrap(), "--robot", "unitree_g1"][..], extra];
        let out = retarget(&args.concat());
        let (stdout, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(1), "{extra:?}: {stdout}{stderr}");
        // The file, then the step that found it (config choice or retargeting), then why.
        let (text, path) = (stderr.trim(), format!("error: {}: ", bvh.display()));
        assert!(text.starts_with(&path) && text.ends_with(": the motion has no frames"), "{text}");
        assert_eq!(text.lines().count(), 1, "{text}");
        assert!(stdout.is_empty(), "{stdout}");
        assert_eq!(listing(&dir), ["zero.bvh"]);
    }
}

/// With `--chunk-frames`, a `Frames: 0` clip used to panic in `chunked.rs` (exit 101, no
/// summary): now it is one failed clip with a clear reason, and the others are converted.
#[test]
fn a_batch_reports_a_clip_without_frames_and_goes_on() {
    let dir = temp_dir("batch");
    let (Some(zero), Some(short)) = (walk_excerpt(0, unchanged), walk_excerpt(25, unchanged))
    else {
        return;
    };
    let tree = dir.join("tree");
    std::fs::create_dir_all(tree.join("a")).unwrap();
    std::fs::write(tree.join("a/zero.bvh"), zero).unwrap();
    std::fs::write(tree.join("b.bvh"), short).unwrap();
    let out_dir = dir.join("out");
    let out = retarget(&[
        "batch",
        tree.to_str().unwrap(),
        "--robot",
        "unitree_g1",
        "-o",
        out_dir.to_str().unwrap(),
        "--chunk-frames",
        "10",
        "--lead-in",
        "5",
    ]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{stdout}{stderr}");
    assert!(stdout.contains("converted 1  skipped 0  failed 1"), "{stdout}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap())
            .unwrap();
    let rows = summary["clips"].as_array().unwrap();
    let failed = rows.iter().find(|r| r["input"] == "a/zero.bvh").unwrap();
    assert_eq!(failed["status"], "failed");
    let error = failed["error"].as_str().unwrap();
    assert!(
        error.contains("zero.bvh: ") && error.ends_with(": the motion has no frames"),
        "{error}"
    );
    assert_eq!(rows.iter().find(|r| r["input"] == "b.bvh").unwrap()["frames"], 25);
    assert_eq!(listing(&out_dir), ["b.npz", "summary.json"]);
}

/// A root coordinate of 1e300 in one frame used to be retargeted and written without a word.
#[test]
fn an_absurd_coordinate_is_an_error_naming_the_frame() {
    let dir = temp_dir("huge");
    let edit = |f: usize, row: &str| {
        if f == 7 {
            let rest = row.trim().split_once(char::is_whitespace).unwrap().1;
            format!("1e300 {rest}")
        } else {
            row.to_owned()
        }
    };
    let Some(huge) = walk_excerpt(20, edit) else { return };
    let bvh = dir.join("huge.bvh");
    std::fs::write(&bvh, huge).unwrap();
    let out = retarget(&["--bvh", bvh.to_str().unwrap(), "--robot", "unitree_g1"]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{stdout}{stderr}");
    assert!(
        stderr.starts_with(&format!("error: {}: ", bvh.display()))
            && stderr.contains(": frame 7: body `Hips` is 1.000e298 m from the origin"),
        "{stderr}"
    );
    assert_eq!(listing(&dir), ["huge.bvh"]);
}

/// A 256-byte `.npz` whose member claims 1e14 `<U0` strings used to abort `retarget report`
/// on a 2.4 PB allocation (exit 134).
#[test]
fn a_crafted_npz_is_an_error_not_an_abort() {
    let dir = temp_dir("npz");
    let header = "{'descr': '<U0', 'fortran_order': False, 'shape': (100000000000000,), }\n";
    let mut npy = b"\x93NUMPY\x01\x00".to_vec();
    npy.extend_from_slice(&u16::try_from(header.len()).unwrap().to_le_bytes());
    npy.extend_from_slice(header.as_bytes());
    let path = dir.join("crafted.npz");
    {
        use std::io::Write;
        let mut zip = zip::ZipWriter::new(std::fs::File::create(&path).unwrap());
        let options = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Stored);
        zip.start_file("joint_names.npy", options).unwrap();
        zip.write_all(&npy).unwrap();
        zip.finish().unwrap();
    }
    let out = retarget(&["report", path.to_str().unwrap()]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{stdout}{stderr}");
    assert_eq!(
        stderr.trim(),
        format!(
            "error: {}: array `joint_names`: dtype <U0 with 100000000000000 elements in 0 bytes \
             of data",
            path.display()
        )
    );
}
