//! Errors and help that read well (issue 15): each cause said once, required arguments and
//! every argument described in `--help`, the same options for the main command and `batch`
//! (and they work there), and a report that measures only what was tracked. Clips are
//! excerpts of the shared LAFAN1 walk (`RETARGET_SHARED`).

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn retarget(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_retarget")).args(args).output().expect("runs retarget")
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cli_usage_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(path)
}

/// The walk take cut to its first `frames` frames.
fn walk(frames: usize) -> Option<String> {
    let source = shared::shared_file("data/bvh/lafan1_take_via_bvhtools_test.bvh")?;
    let full = std::fs::read_to_string(source).unwrap();
    let (head, motion) = full.split_once("MOTION").unwrap();
    let mut lines = motion.lines().filter(|l| !l.trim().is_empty());
    let _frames = lines.next().unwrap();
    let frame_time = lines.next().unwrap();
    let rows: Vec<&str> = lines.take(frames).collect();
    Some(format!("{head}MOTION\nFrames: {frames}\n{frame_time}\n{}\n", rows.join("\n")))
}

#[test]
fn a_missing_file_is_named_once_with_its_cause_once() {
    let dir = temp_dir("missing");
    let missing = |name: &str| dir.join(name).to_string_lossy().into_owned();
    let cases: Vec<Vec<String>> = vec![
        vec!["--bvh".into(), missing("a.bvh"), "--robot".into(), "unitree_g1".into()],
        vec![
            "--bvh".into(),
            missing("a.bvh"),
            "--robot".into(),
            "unitree_g1".into(),
            "--config".into(),
            missing("c.json"),
        ],
        vec!["report".into(), missing("m.npz")],
        vec!["c3d".into(), "info".into(), missing("t.c3d")],
        vec!["bvh".into(), "info".into(), missing("a.bvh")],
        vec!["fbx".into(), "info".into(), missing("a.fbx")],
        vec!["--fbx".into(), missing("a.fbx"), "--robot".into(), "unitree_g1".into()],
        vec!["view".into(), missing("a.bvh")],
    ];
    for args in cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = retarget(&args);
        let text = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {text}");
        assert_eq!(text.matches("os error 2").count(), 1, "{args:?}: {text}");
        assert_eq!(text.matches(dir.to_str().unwrap()).count(), 1, "{args:?}: {text}");
        assert_eq!(text.lines().count(), 1, "{args:?}: {text}");
    }
}

/// `Arguments:` and `Options:` of a `--help` text: name → description.
fn help_entries(help: &str) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    let mut last: Option<String> = None;
    for line in help.lines() {
        let trimmed = line.trim_start();
        let indent = line.len() - trimmed.len();
        let starts_entry =
            trimmed.starts_with('-') || trimmed.starts_with('<') || trimmed.starts_with('[');
        // Clap indents `-o, --output` and arguments by 2, `--bvh` (no short flag) by 6.
        if (2..=6).contains(&indent) && starts_entry {
            let (name, rest) = trimmed.split_once("  ").unwrap_or((trimmed, ""));
            let key = name.trim().to_owned();
            out.insert(key.clone(), rest.trim().to_owned());
            last = Some(key);
        } else if indent > 6 && !trimmed.is_empty() {
            if let Some(key) = &last {
                let entry = out.entry(key.clone()).or_default();
                entry.push(' ');
                entry.push_str(trimmed);
            }
        } else {
            last = None;
        }
    }
    out
}

#[test]
fn help_names_required_arguments_and_describes_every_argument() {
    let main = stdout(&retarget(&["--help"]));
    assert!(main.contains("Usage: retarget --bvh <FILE> --robot <ROBOT> [OPTIONS]"), "{main}");
    assert!(main.contains("retarget --c3d <FILE> --config <FILE> --robot <ROBOT>"), "{main}");
    assert!(main.contains("retarget --smplx <FILE> --robot <ROBOT>"), "{main}");
    let entries = help_entries(&main);
    assert!(entries["--robot <ROBOT>"].starts_with("Robot (required)"), "{entries:?}");
    assert!(
        entries["--bvh <FILE>"].contains("this, --fbx, --c3d or --smplx is required"),
        "{entries:?}"
    );
    assert!(main.contains("retarget --fbx <FILE> [--take <NAME|N>] --robot <ROBOT>"), "{main}");
    assert!(entries["--take <NAME|N>"].contains("the take with the most motion"), "{entries:?}");
    let commands = [
        "bvh info",
        "bvh json",
        "bvh cat",
        "bvh fk",
        "bvh map",
        "c3d info",
        "c3d dump",
        "c3d convert",
        "fbx info",
        "fbx bvh",
        "fbx fk",
        "fbx map",
        "smpl info",
        "smpl fk",
        "robot info",
        "robot check",
        "robots",
        "batch",
        "report",
        "view",
    ];
    for command in commands {
        let args: Vec<&str> = command.split(' ').chain(["--help"]).collect();
        let help = stdout(&retarget(&args));
        let entries = help_entries(&help);
        assert!(!entries.is_empty(), "{command}: {help}");
        for (name, description) in entries {
            assert!(!description.is_empty(), "`retarget {command}`: {name} has no description");
        }
    }
    let batch = stdout(&retarget(&["batch", "--help"]));
    assert!(batch.contains("Required unless --merge-summaries"), "{batch}");
    assert!(help_entries(&batch)["-o, --output <OUTPUT>"].contains("(required"), "{batch}");
}

/// `--both-ways` says how much of the clip came from the backward pass, and is not GMR's.
#[test]
fn both_ways_reports_what_it_took_from_the_backward_pass() {
    let Some(kick) = shared::shared_file("data/bvh/bandai_dataset-1_kick_normal_001.bvh") else {
        return;
    };
    let dir = temp_dir("both_ways");
    let out_path = dir.join("kick.npz");
    let args = ["--bvh", kick.to_str().unwrap(), "--robot", "engineai_pm01", "-o"];
    let out = retarget(&[&args[..], &[out_path.to_str().unwrap(), "--both-ways"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    let line = text.lines().find(|l| l.starts_with("both ways: ")).unwrap_or_default();
    let taken: usize = line["both ways: ".len()..].split(' ').next().unwrap().parse().unwrap();
    assert!(taken > 100 && line.contains(" of 358 frames from the backward pass"), "{text}");
    let out =
        retarget(&[&args[..], &[out_path.to_str().unwrap(), "--both-ways", "--gmr"]].concat());
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("cannot be used with"), "{}", stderr(&out));
}

#[test]
fn main_command_and_batch_take_the_same_options() {
    let main = help_entries(&stdout(&retarget(&["--help"])));
    let batch = help_entries(&stdout(&retarget(&["batch", "--help"])));
    // Options of one clip: the same name and value in both (input and output differ by
    // nature: a file and a folder).
    let shared = [
        "--robot <ROBOT>",
        "--config <FILE>",
        "--human-height <METRES>",
        "--fps <HZ>",
        "--chunk-frames <FRAMES>",
        "--lead-in <FRAMES>",
        "--gmr",
        "--both-ways",
        "--body-model <DIR>",
        "--gender <GENDER>",
    ];
    for option in shared {
        assert!(main.contains_key(option), "main command lacks {option}: {main:?}");
        assert!(batch.contains_key(option), "batch lacks {option}: {batch:?}");
    }
    let format = |entries: &BTreeMap<String, String>| {
        entries.iter().find(|(k, _)| k.starts_with("--format")).map(|(_, v)| v.clone()).unwrap()
    };
    for entries in [&main, &batch] {
        assert!(format(entries).contains("[possible values: npz, csv, pkl, json]"), "{entries:?}");
    }
    assert!(
        batch["[IN_DIR]"].starts_with(
            "Directory tree of BVH, FBX (each file's take with the most motion), C3D and AMASS"
        ),
        "{batch:?}"
    );
}

#[test]
fn batch_resamples_solves_as_gmr_and_reads_c3d() {
    let Some(clip) = walk(25) else { return };
    let Some(c3d) = shared::shared_file("data/c3d/c3dorg_s00_Vicon_pyCGM2_Walking01.c3d") else {
        return;
    };
    let dir = temp_dir("batch");
    let tree = dir.join("tree");
    std::fs::create_dir_all(&tree).unwrap();
    std::fs::write(tree.join("walk.bvh"), &clip).unwrap();
    // --fps and --gmr: the batch output equals the main command's, row for row.
    let out_dir = dir.join("out");
    let args = ["--robot", "unitree_g1", "--fps", "60", "--gmr", "--format", "csv"];
    let out = retarget(
        &[&["batch", tree.to_str().unwrap(), "-o", out_dir.to_str().unwrap()][..], &args].concat(),
    );
    assert!(out.status.success(), "{}{}", stdout(&out), stderr(&out));
    let single = dir.join("single.csv");
    let main = retarget(
        &[
            &["--bvh", tree.join("walk.bvh").to_str().unwrap(), "-o", single.to_str().unwrap()][..],
            &args,
        ]
        .concat(),
    );
    assert!(main.status.success(), "{}", stderr(&main));
    let batch_csv = std::fs::read_to_string(out_dir.join("walk.csv")).unwrap();
    // 25 frames at 30 fps span 0.8 s: 49 frames at 60 fps.
    assert_eq!(batch_csv.lines().count(), 49);
    assert_eq!(batch_csv, std::fs::read_to_string(&single).unwrap());

    // A C3D clip with the marker config, next to a BVH clip that this config cannot drive.
    std::fs::copy(&c3d, tree.join("trial.c3d")).unwrap();
    let out_dir = dir.join("c3d_out");
    let config = repo("configs/c3d_plugingait_to_unitree_g1.json");
    let out = retarget(&[
        "batch",
        tree.to_str().unwrap(),
        "-o",
        out_dir.to_str().unwrap(),
        "--robot",
        "unitree_g1",
        "--config",
        config.to_str().unwrap(),
    ]);
    let text = stdout(&out);
    assert_eq!(out.status.code(), Some(1), "{text}{}", stderr(&out));
    assert!(text.contains("clips 2  converted 1  skipped 0  failed 1"), "{text}");
    let motion = retarget::writers::read_motion_npz(&out_dir.join("trial.npz")).unwrap();
    assert_eq!(motion.num_frames(), 493);
    // Without a marker config a C3D clip fails with a reason that says what is missing.
    let out_dir = dir.join("no_markers");
    let out = retarget(&[
        "batch",
        tree.to_str().unwrap(),
        "-o",
        out_dir.to_str().unwrap(),
        "--robot",
        "unitree_g1",
    ]);
    let text = stdout(&out);
    assert!(text.contains("a C3D clip needs a marker config"), "{text}");
}

#[test]
fn report_measures_positions_only_where_they_are_targets() {
    let Some(clip) = walk(20) else { return };
    let dir = temp_dir("report");
    let bvh = dir.join("walk.bvh");
    std::fs::write(&bvh, clip).unwrap();
    let npz = dir.join("walk.npz");
    let out = retarget(&[
        "--bvh",
        bvh.to_str().unwrap(),
        "--robot",
        "unitree_g1",
        "-o",
        npz.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let summary = stdout(&out);
    let report = stdout(&retarget(&["report", npz.to_str().unwrap()]));
    // torso_link has no position weight in the G1 config: dashes in both tables.
    let row = |text: &str, body: &str| -> Vec<String> {
        let line = text.lines().find(|l| l.trim_start().starts_with(body)).unwrap();
        line.split_whitespace().skip(1).map(str::to_owned).collect()
    };
    assert_eq!(row(&summary, "torso_link")[..2], ["-", "-"], "{summary}");
    assert_eq!(row(&report, "torso_link")[..3], ["-", "-", "-"], "{report}");
    // The same percentile rule: the summary's pelvis p95 (mm) is the report's (cm).
    let summary_p95: f64 = row(&summary, "pelvis")[1].trim_end_matches("mm").parse().unwrap();
    let report_p95: f64 = row(&report, "pelvis")[1].parse().unwrap();
    assert!((summary_p95 / 10.0 - report_p95).abs() < 0.006, "{summary_p95} mm vs {report_p95} cm");
}

#[test]
fn report_prints_and_writes_the_motion_over_time_sections() {
    let Some(clip) = walk(40) else { return };
    let dir = temp_dir("report-dynamics");
    let bvh = dir.join("walk.bvh");
    std::fs::write(&bvh, clip).unwrap();
    let npz = dir.join("walk.npz");
    let out = retarget(&[
        "--bvh",
        bvh.to_str().unwrap(),
        "--robot",
        "unitree_g1",
        "-o",
        npz.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (json, csv) = (dir.join("r.json"), dir.join("d.csv"));
    let out = retarget(&[
        "report",
        npz.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
        "--dynamics-frames",
        csv.to_str().unwrap(),
    ]);
    let text = stdout(&out);
    for line in [
        "verdict: ok (",
        "root acceleration (pelvis, averaged over 0.133 s): mean",
        "  scaled human (target of pelvis): mean",
        "  frame by frame: mean",
        "jitter mean |q̈| over all 35",
        "dynamics (34.4 kg",
    ] {
        assert!(text.contains(line), "{line}: {text}");
    }
    let rep: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let d = &rep["dynamics"];
    // The CSV holds the frames the summary is made of: 2..=37, mean residual as reported.
    let rows: Vec<Vec<String>> = std::fs::read_to_string(&csv)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_owned).collect())
        .collect();
    assert_eq!(rows.len(), 36);
    assert_eq!((rows[0][0].as_str(), rows[35][0].as_str()), ("2", "37"));
    let mean = rows.iter().map(|r| r[2].parse::<f64>().unwrap()).sum::<f64>() / 36.0;
    let reported = d["residual_mg"]["mean"].as_f64().unwrap();
    assert!((mean - reported).abs() < 1e-6, "{mean} vs {reported}");
    let over = rows.iter().filter(|r| r[2].parse::<f64>().unwrap() > 0.1).count();
    assert_eq!(d["frames_over"].as_u64(), Some(over as u64));
    assert!(rep["root_acceleration"]["target"]["mean_mps2"].is_number());
}

#[test]
fn report_measures_against_another_runs_targets() {
    let Some(clip) = walk(30) else { return };
    let dir = temp_dir("report-targets-from");
    let bvh = dir.join("walk.bvh");
    std::fs::write(&bvh, clip).unwrap();
    let (mine, gmr) = (dir.join("default.npz"), dir.join("gmr.npz"));
    for (npz, extra) in [(&mine, None), (&gmr, Some("--gmr"))] {
        let mut args = vec!["--bvh", bvh.to_str().unwrap(), "--robot", "unitree_g1"];
        args.extend(["-o", npz.to_str().unwrap()]);
        args.extend(extra);
        let out = retarget(&args);
        assert!(out.status.success(), "{}", stderr(&out));
    }
    let pelvis = |args: &[&str]| -> f64 {
        let out = retarget(args);
        assert!(out.status.success(), "{}", stderr(&out));
        let text = stdout(&out);
        let line = text.lines().find(|l| l.trim_start().starts_with("pelvis")).unwrap();
        line.split_whitespace().nth(1).unwrap().parse().unwrap()
    };
    let own = pelvis(&["report", mine.to_str().unwrap()]);
    let theirs =
        pelvis(&["report", mine.to_str().unwrap(), "--targets-from", gmr.to_str().unwrap()]);
    // The default's targets are planted and shifted to the floor: GMR's are not, and the
    // same motion measures differently against them.
    assert!((own - theirs).abs() > 1e-3, "{own} cm against its own, {theirs} against GMR's");
    // --gmr against its own targets, read from another file: the same numbers.
    let same = pelvis(&["report", gmr.to_str().unwrap(), "--targets-from", gmr.to_str().unwrap()]);
    assert_eq!(same, pelvis(&["report", gmr.to_str().unwrap()]));
    // Another clip's motion is refused, naming the file and both frame counts.
    let short = dir.join("short.bvh");
    std::fs::write(&short, walk(20).unwrap()).unwrap();
    let other = dir.join("short.npz");
    let out = retarget(&[
        "--bvh",
        short.to_str().unwrap(),
        "--robot",
        "unitree_g1",
        "--gmr",
        "-o",
        other.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let out =
        retarget(&["report", mine.to_str().unwrap(), "--targets-from", other.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(err.contains("short.npz") && err.contains("20 frames") && err.contains("30"), "{err}");
}
