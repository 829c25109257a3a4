//! The real files of several vendors: facts from `../shared/data/README.md`, exact round
//! trips on every file, JSON checked by Python's `json` module.

use std::process::Command;

use bvh::{Axis, Channel, JointKind, Summary, Units};

use crate::{assert_round_trip, shared, shared_bvh_files};

struct Facts {
    file: &'static str,
    frames: usize,
    fps: f64,
    joints: usize,
    end_sites: usize,
    units: Units,
}

const FACTS: &[Facts] = &[
    Facts {
        file: "lafan1_take_via_bvhtools_test.bvh",
        frames: 7184,
        fps: 30.0,
        joints: 22,
        end_sites: 5,
        units: Units::Centimetres,
    },
    Facts {
        file: "lafan1_take_via_bvhtools_test2.bvh",
        frames: 3945,
        fps: 30.0,
        joints: 22,
        end_sites: 5,
        units: Units::Centimetres,
    },
    Facts {
        file: "cmu_bvh11_131_01.bvh",
        frames: 994,
        fps: 120.0,
        joints: 31,
        end_sites: 7,
        units: Units::Unknown,
    },
    Facts {
        file: "cmu_bvh11_131_03.bvh",
        frames: 1102,
        fps: 120.0,
        joints: 31,
        end_sites: 7,
        units: Units::Unknown,
    },
    Facts {
        file: "cmu_bvh11_scaled_131_01.bvh",
        frames: 995,
        fps: 120.0,
        joints: 31,
        end_sites: 7,
        units: Units::Metres,
    },
    Facts {
        file: "bandai_dataset-1_walk_normal_001.bvh",
        frames: 195,
        fps: 30.0,
        joints: 22,
        end_sites: 5,
        units: Units::Centimetres,
    },
    Facts {
        file: "bandai_dataset-1_run_normal_001.bvh",
        frames: 24,
        fps: 30.0,
        joints: 22,
        end_sites: 5,
        units: Units::Centimetres,
    },
    Facts {
        file: "bandai_dataset-1_dance-short_normal_001.bvh",
        frames: 1901,
        fps: 30.0,
        joints: 22,
        end_sites: 5,
        units: Units::Centimetres,
    },
    Facts {
        file: "bvhtools_test3_rigify_6ch.bvh",
        frames: 3089,
        fps: 24.0,
        joints: 19,
        end_sites: 7,
        units: Units::Metres,
    },
    Facts {
        file: "bvhtoolbox_test_freebvh_mixamo.bvh",
        frames: 69,
        fps: 30.0,
        joints: 55,
        end_sites: 15,
        units: Units::Centimetres,
    },
    Facts {
        file: "bvhtoolbox_test_mocapbank.bvh",
        frames: 455,
        fps: 30.0,
        joints: 19,
        end_sites: 5,
        units: Units::Centimetres,
    },
];

#[test]
fn summaries_match_the_data_readme() {
    let Some(dir) = shared::shared_file("data/bvh") else { return };
    for f in FACTS {
        let bvh = bvh::from_path(&dir.join(f.file)).unwrap_or_else(|e| panic!("{e}"));
        let s = Summary::new(&bvh, f.file);
        assert_eq!(s.num_frames, f.frames, "{}", f.file);
        assert!((s.fps - f.fps).abs() < 0.01, "{}: {} fps", f.file, s.fps);
        assert_eq!(s.num_joints, f.joints, "{}", f.file);
        assert_eq!(s.num_end_sites, f.end_sites, "{}", f.file);
        assert_eq!(s.units, f.units, "{}: extent {}", f.file, s.extent);
        assert_eq!(bvh.motion.values.len(), f.frames * bvh.skeleton.num_channels(), "{}", f.file);
        let text = s.to_string();
        assert!(text.contains(&format!("frames:          {}\n", f.frames)), "{text}");
        assert!(text.contains(f.file), "{text}");
    }
}

#[test]
fn lafan1_layout_and_last_value() {
    let Some(path) = shared::shared_file("data/bvh/lafan1_take_via_bvhtools_test.bvh") else {
        return;
    };
    let bvh = bvh::from_path(&path).unwrap();
    let root = &bvh.skeleton.joints[0];
    assert_eq!((root.name.as_str(), root.kind), ("Hips", JointKind::Root));
    assert_eq!(root.offset, [-224.689499, 91.882057, -431.625488]);
    let zyx = [Channel::Rotation(Axis::Z), Channel::Rotation(Axis::Y), Channel::Rotation(Axis::X)];
    assert_eq!(root.channels[3..], zyx);
    assert_eq!(bvh.skeleton.num_channels(), 6 + 21 * 3);
    // Compare the first and last numbers of the motion block with the text itself.
    let text = std::fs::read_to_string(&path).unwrap();
    let motion = &text[text.find("Frame Time:").unwrap()..];
    let numbers: Vec<&str> = motion.lines().skip(1).flat_map(str::split_whitespace).collect();
    assert_eq!(numbers.len(), bvh.motion.values.len());
    for i in [0, 1, numbers.len() / 2, numbers.len() - 1] {
        assert_eq!(numbers[i].parse::<f64>().unwrap(), bvh.motion.values[i], "value {i}");
    }
}

#[test]
fn cmu_mixes_rotation_orders_and_mixamo_keeps_colons() {
    let Some(dir) = shared::shared_file("data/bvh") else { return };
    let cmu = bvh::from_path(&dir.join("cmu_bvh11_131_01.bvh")).unwrap();
    let orders = Summary::new(&cmu, "cmu").rotation_orders();
    let names: Vec<&str> = orders.iter().map(|(o, _)| o.as_str()).collect();
    assert!(names.contains(&"ZYX") && names.contains(&"ZXY"), "{orders:?}");
    let mixamo = bvh::from_path(&dir.join("bvhtoolbox_test_freebvh_mixamo.bvh")).unwrap();
    assert_eq!(mixamo.skeleton.joints[0].name, "mixamorig:Hips");
    assert!(mixamo.skeleton.find("mixamorig:LeftHand").is_some());
    let end = mixamo.skeleton.joints.iter().find(|j| j.kind == JointKind::End).unwrap();
    let parent = mixamo.skeleton.joint(end.parent.unwrap());
    assert_eq!(end.name, format!("{}_End", parent.name));
}

#[test]
fn every_shared_file_round_trips_exactly_and_without_warnings() {
    let Some(files) = shared_bvh_files() else { return };
    for path in &files {
        let (bvh, warnings) = bvh::from_path_with_warnings(path).unwrap_or_else(|e| panic!("{e}"));
        assert!(warnings.is_empty(), "{}: {warnings:?}", path.display());
        assert_round_trip(&bvh, &path.display().to_string());
    }
}

/// Python's own JSON parser reads our output and counts frames and rows per joint.
const CHECK_JSON: &str = r#"
import json, sys
d = json.load(open(sys.argv[1]))
frames = int(sys.argv[2])
assert d["frames"] == frames, d["frames"]
joints = ends = channels = 0
stack = list(d["joints"])
while stack:
    j = stack.pop()
    stack.extend(j["children"])
    if j["type"] == "End":
        ends += 1
        assert j["channels"] == [] and j["motion"] == []
        continue
    joints += 1
    channels += len(j["channels"])
    assert len(j["motion"]) == frames, (j["name"], len(j["motion"]))
    assert all(len(r) == len(j["channels"]) for r in j["motion"])
assert channels == d["channels"], (channels, d["channels"])
print(joints, ends)
"#;

#[test]
fn json_of_every_shared_file_is_read_by_python() {
    let Some(files) = shared_bvh_files() else { return };
    let dir = std::env::temp_dir().join(format!("bvh-json-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for path in &files {
        let bvh = bvh::from_path(path).unwrap();
        let out = dir.join("out.json");
        bvh::write_json(&bvh, std::fs::File::create(&out).unwrap()).unwrap();
        let frames = bvh.motion.num_frames.to_string();
        let run = Command::new("python3").arg("-c").arg(CHECK_JSON).arg(&out).arg(&frames).output();
        let run = run.expect("python3 is needed for this test");
        let stdout = String::from_utf8_lossy(&run.stdout);
        assert!(
            run.status.success(),
            "{}: {}",
            path.display(),
            String::from_utf8_lossy(&run.stderr)
        );
        let s = Summary::new(&bvh, "");
        assert_eq!(
            stdout.trim(),
            format!("{} {}", s.num_joints, s.num_end_sites),
            "{}",
            path.display()
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
