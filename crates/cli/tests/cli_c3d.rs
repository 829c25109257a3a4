//! End to end: `retarget c3d info | dump | convert`.

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn retarget(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_retarget")).args(args).output().unwrap()
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn ok(args: &[&str]) -> String {
    let out = retarget(args);
    assert!(out.status.success(), "{args:?}: {}", text(&out.stderr));
    text(&out.stdout)
}

fn sample(name: &str) -> Option<PathBuf> {
    shared::shared_file(&format!("data/c3d/{name}"))
}

/// A scratch folder under the system temp dir, removed when dropped.
struct TempDir(PathBuf);

impl TempDir {
    fn new(name: &str) -> TempDir {
        let dir = std::env::temp_dir().join(format!("cli-c3d-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        TempDir(dir)
    }

    fn file(&self, name: &str) -> String {
        self.0.join(name).to_string_lossy().into_owned()
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

#[test]
fn info_works_on_every_shared_sample() {
    let Some(dir) = shared::shared_file("data/c3d") else { return };
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "c3d"))
        .collect();
    files.sort();
    assert!(files.len() >= 24);
    for file in &files {
        let path = file.to_str().unwrap();
        let out = ok(&["c3d", "info", path]);
        let c = c3d::C3d::from_path(file).unwrap();
        assert!(out.contains(&format!("points: {}\n", c.points.point_count())), "{path}\n{out}");
        assert!(out.contains(&format!("processor: {}", c.processor.name())), "{path}\n{out}");
        assert!(out.contains(&format!("events: {}\n", c.events.len())), "{path}\n{out}");
        assert!(out.contains(&format!("analog: {} channels", c.analog.channel_count())), "{path}");
        for label in c.point_labels().iter().filter(|l| !l.is_empty()) {
            assert!(out.contains(label.as_str()), "{path}: label {label}");
        }
    }
}

#[test]
fn info_names_processor_format_rate_and_groups() {
    let Some(file) = sample("c3dorg_s01_Eb015vi.c3d") else { return };
    let out = ok(&["c3d", "info", file.to_str().unwrap()]);
    for want in [
        "processor: dec (85)",
        "data: integer",
        "frames: 450 (1..450) at 50 Hz",
        "RFT1",
        "POINT:",
        "ANALOG:",
        "force plates: 2",
        "events: 3",
    ] {
        assert!(out.contains(want), "missing {want:?} in\n{out}");
    }
    let Some(bad) = sample("c3dorg_s18_bad_parameter_section.c3d") else { return };
    let out = retarget(&["c3d", "info", bad.to_str().unwrap()]);
    assert!(out.status.success());
    assert!(text(&out.stderr).contains("warning:") && text(&out.stderr).contains("invalid offset"));
}

#[test]
fn dump_points_analog_and_events() {
    let Some(file) = sample("c3dorg_s01_Eb015pr.c3d") else { return };
    let path = file.to_str().unwrap();
    let csv = ok(&["c3d", "dump", path, "--points"]);
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 1 + 450);
    assert!(lines[0].starts_with("frame,time,RFT1_x,RFT1_y,RFT1_z,"), "{}", lines[0]);
    let first: Vec<f32> = lines[1].split(',').skip(2).take(3).map(|v| v.parse().unwrap()).collect();
    for (got, want) in first.iter().zip([248.58, 226.83, 37.42]) {
        assert!((got - want).abs() < 0.005, "{first:?}");
    }
    let dir = TempDir::new("dump");
    let json_path = dir.file("events.json");
    assert_eq!(ok(&["c3d", "dump", path, "--events", "-o", &json_path]), "");
    let events: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json_path).unwrap()).unwrap();
    assert_eq!(events.as_array().unwrap().len(), 3);
    assert_eq!(events[0]["source"], "header");
    let analog_path = dir.file("analog.csv");
    ok(&["c3d", "dump", path, "--analog", "-o", &analog_path]);
    let analog = std::fs::read_to_string(&analog_path).unwrap();
    assert_eq!(analog.lines().count(), 1 + 450 * 4);
    assert_eq!(analog.lines().next().unwrap().split(',').count(), 2 + 16);
    let points_json = dir.file("points.json");
    ok(&["c3d", "dump", path, "--points", "-o", &points_json]);
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&points_json).unwrap()).unwrap();
    assert_eq!(v["frames"].as_array().unwrap().len(), 450);
    assert_eq!(v["labels"][0], "RFT1");
    // Exactly one of --points, --analog, --events.
    assert_eq!(retarget(&["c3d", "dump", path]).status.code(), Some(2));
    assert_eq!(
        retarget(&["c3d", "dump", path, "--points", "-o", &dir.file("x.txt")]).status.code(),
        Some(1)
    );
}

#[test]
fn convert_writes_files_that_read_back() {
    let Some(file) = sample("c3dorg_s02_sgi_real.c3d") else { return };
    let dir = TempDir::new("convert");
    let original = c3d::C3d::from_path(&file).unwrap();
    for (flag, data) in [("--float", c3d::DataFormat::Float), ("--int", c3d::DataFormat::Integer)] {
        let out = dir.file(&format!("out{flag}.c3d"));
        ok(&["c3d", "convert", file.to_str().unwrap(), "-o", &out, flag]);
        let back = c3d::C3d::from_path(Path::new(&out)).unwrap();
        assert_eq!((back.processor, back.format), (c3d::Processor::Intel, data));
        assert_eq!(back.point_labels(), original.point_labels());
        assert_eq!(back.points.frame_count(), original.points.frame_count());
        assert!(back.warnings.is_empty(), "{:?}", back.warnings);
        let info = ok(&["c3d", "info", &out]);
        assert!(info.contains("processor: intel (84)"), "{info}");
    }
    // No temporary files left behind.
    let names: Vec<String> = std::fs::read_dir(&dir.0)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().all(|n| !n.contains(".tmp")), "{names:?}");
}

#[test]
fn bad_input_exits_1_naming_the_file() {
    let dir = TempDir::new("bad");
    let garbage = dir.file("garbage.c3d");
    std::fs::write(&garbage, b"this is not a c3d file at all").unwrap();
    let missing = dir.file("missing.c3d");
    for path in [&garbage, &missing] {
        for args in
            [vec!["c3d", "info", path], vec!["c3d", "convert", path, "-o", &dir.file("o.c3d")]]
        {
            let out = retarget(&args);
            assert_eq!(out.status.code(), Some(1), "{args:?}");
            assert!(text(&out.stderr).contains(path.as_str()), "{args:?}: {}", text(&out.stderr));
        }
    }
    assert!(!Path::new(&dir.file("o.c3d")).exists());
}
