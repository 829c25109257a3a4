//! Golden pairs: `tests/data/bad_*.bvh` and their expected errors in `tests/data/errors.txt`
//! (`<file>: <line>:<column>: <message>`, one line per case); `tests/data/quirk_*.bvh`, one
//! real exporter's quirk each, and their expected dumps (summary, warnings, values) in
//! `quirk_*.txt`; and the accepted fixtures. `BVH_BLESS=1 cargo test -p bvh` rewrites
//! `errors.txt` and the dumps from the current output.

use std::path::Path;

use bvh::{Axis, Channel, Error, JointKind, Warning};

use crate::{assert_round_trip, fixture_dir};

fn cases(prefix: &str) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(fixture_dir())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(prefix) && n.ends_with(".bvh"))
        .collect();
    names.sort();
    names
}

fn bad_cases() -> Vec<String> {
    cases("bad_")
}

fn blessing() -> bool {
    std::env::var_os("BVH_BLESS").is_some()
}

#[test]
fn every_bad_fixture_gives_its_expected_error() {
    let dir = fixture_dir();
    let actual: Vec<String> = bad_cases()
        .iter()
        .map(|name| match bvh::parse(&std::fs::read(dir.join(name)).unwrap()) {
            Ok(_) => format!("{name}: parsed without error"),
            Err(e) => format!("{name}: {e}"),
        })
        .collect();
    let expected_path = dir.join("errors.txt");
    if blessing() {
        std::fs::write(&expected_path, actual.join("\n") + "\n").unwrap();
    }
    let expected = std::fs::read_to_string(&expected_path).unwrap();
    let expected: Vec<&str> = expected.lines().collect();
    for (a, e) in actual.iter().zip(&expected) {
        assert_eq!(a, e);
    }
    assert_eq!(actual.len(), expected.len(), "one line per bad_*.bvh in errors.txt");
    assert!(bad_cases().len() >= 15);
}

#[test]
fn every_error_kind_has_a_case_and_a_position() {
    let dir = fixture_dir();
    let mut kinds = std::collections::BTreeSet::new();
    for name in bad_cases() {
        let err = bvh::parse(&std::fs::read(dir.join(&name)).unwrap()).unwrap_err();
        assert!(err.position().is_some(), "{name}: {err}");
        let kind = format!("{err:?}");
        kinds.insert(kind[..kind.find([' ', '{']).unwrap_or(kind.len())].to_owned());
    }
    for kind in [
        "Expected",
        "ExtraBrace",
        "UnexpectedBrace",
        "MissingBrace",
        "ChannelCount",
        "UnknownChannel",
        "NotANumber",
        "NonFinite",
        "FrameLength",
        "Invalid",
    ] {
        assert!(kinds.contains(kind), "no bad_*.bvh case for Error::{kind}: {kinds:?}");
    }
}

/// What a quirk fixture must read as: the summary, the warnings, every OFFSET and every
/// motion value (`{:?}`, the shortest text that reads back to the same `f64`).
fn dump(name: &str, bvh: &bvh::Bvh, warnings: &[Warning]) -> String {
    let mut out = bvh::Summary::new(bvh, name).to_string();
    out.push_str("offsets:\n");
    for j in &bvh.skeleton.joints {
        let [x, y, z] = j.offset;
        out.push_str(&format!("  `{}`: {x:?} {y:?} {z:?}\n", j.name));
    }
    out.push_str("warnings:\n");
    for w in warnings {
        out.push_str(&format!("  {w}\n"));
    }
    out.push_str("motion:\n");
    for f in 0..bvh.motion.num_frames {
        let row: Vec<String> = bvh.motion.frame(f).iter().map(|v| format!("{v:?}")).collect();
        out.push_str(&format!("  {}\n", row.join(" ")));
    }
    out
}

#[test]
fn every_quirk_fixture_reads_as_its_expected_dump() {
    let dir = fixture_dir();
    let names = cases("quirk_");
    for name in &names {
        let path = dir.join(name);
        let (bvh, warnings) = bvh::from_path_with_warnings(&path).unwrap_or_else(|e| panic!("{e}"));
        let actual = dump(name, &bvh, &warnings);
        let expected_path = path.with_extension("txt");
        if blessing() {
            std::fs::write(&expected_path, &actual).unwrap();
        }
        let expected = std::fs::read_to_string(&expected_path)
            .unwrap_or_else(|e| panic!("{}: {e}", expected_path.display()));
        assert_eq!(actual, expected, "{name}");
        assert_eq!(bvh::parse(&std::fs::read(&path).unwrap()).unwrap(), bvh, "{name}");
        assert_round_trip(&bvh, name);
        // Written back, a file says what it holds: only the scale warning can remain.
        let mut text = Vec::new();
        bvh::write(&bvh, &mut text).unwrap();
        let (_, again) = bvh::parse_with_warnings(&text).unwrap();
        assert!(again.iter().all(|w| matches!(w, Warning::ScaleChannels { .. })), "{again:?}");
    }
    assert!(names.len() >= 10, "{names:?}");
}

#[test]
fn frame_count_disagreements_warn_and_keep_the_rows() {
    let dir = fixture_dir();
    for (name, declared, rows) in [
        ("quirk_frames_one_more_than_rows.bvh", 3, 2),
        ("quirk_frames_one_less_than_rows.bvh", 1, 2),
    ] {
        let (bvh, warnings) = bvh::from_path_with_warnings(&dir.join(name)).unwrap();
        assert_eq!(bvh.motion.num_frames, rows, "{name}");
        assert_eq!(bvh.motion.values.len(), rows * 9, "{name}");
        assert_eq!(bvh.motion.frame(1)[1], 91.0, "{name}");
        let pos = bvh::Pos { line: 17, column: 9 };
        assert_eq!(warnings, [Warning::FrameCount { pos, declared, found: rows }], "{name}");
        assert_eq!(warnings[0].position(), pos);
    }
}

#[test]
fn scale_channels_are_kept_and_reported_with_their_range() {
    let (bvh, warnings) =
        bvh::from_path_with_warnings(&fixture_dir().join("quirk_scale_channels.bvh")).unwrap();
    let spine = &bvh.skeleton.joints[1];
    assert_eq!(spine.channels[3..], [Axis::X, Axis::Y, Axis::Z].map(Channel::Scale));
    assert_eq!(bvh.motion.frame(1)[13..], [1.25, 0.98]);
    let ranges: Vec<(&str, f64, f64, usize)> = warnings
        .iter()
        .map(|w| match w {
            Warning::ScaleChannels { joint, min, max, pos } => {
                (joint.as_str(), *min, *max, pos.line)
            }
            other => panic!("{other:?}"),
        })
        .collect();
    assert_eq!(ranges, [("Hips", 1.0, 1.0, 5), ("Spine", 0.98, 1.25, 9)]);
    assert_eq!(Channel::from_name("Yscale"), Some(Channel::Scale(Axis::Y)));
    assert_eq!(Channel::Scale(Axis::Z).name(), "Zscale");
}

#[test]
fn from_path_names_the_file() {
    let path = fixture_dir().join("bad_short_row.bvh");
    let err = bvh::from_path(&path).unwrap_err();
    let text = err.to_string();
    assert!(text.starts_with(&format!("{}:20:", path.display())), "{text}");
    assert_eq!(err.path(), Some(path.as_path()));
    let missing = bvh::from_path(Path::new("/nonexistent/walk.bvh")).unwrap_err();
    assert!(matches!(missing, Error::Io { .. }));
    assert!(missing.to_string().starts_with("/nonexistent/walk.bvh: "), "{missing}");
}

#[test]
fn mixed_fixture_has_everything_real_files_do() {
    let bvh = bvh::from_path(&fixture_dir().join("good_mixed_crlf.bvh"))
        .unwrap_or_else(|e| panic!("{e}"));
    let s = &bvh.skeleton;
    let names: Vec<&str> = s.joints.iter().map(|j| j.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "mixamorig:Hips",
            "Bip01 L Thigh.001 (copy)",
            "left-knee_2",
            "left-knee_2_End",
            "Spine",
            "Spine_End"
        ]
    );
    let kinds: Vec<JointKind> = s.joints.iter().map(|j| j.kind).collect();
    assert_eq!(kinds[..4], [JointKind::Root, JointKind::Joint, JointKind::Joint, JointKind::End]);
    let parents: Vec<Option<usize>> = s.joints.iter().map(|j| j.parent.map(|p| p.0)).collect();
    assert_eq!(parents, [None, Some(0), Some(1), Some(2), Some(0), Some(4)]);
    let counts: Vec<usize> = s.joints.iter().map(|j| j.channels.len()).collect();
    assert_eq!(counts, [6, 3, 9, 0, 6, 0]);
    let firsts: Vec<usize> = s.joints.iter().map(|j| j.first_channel).collect();
    assert_eq!(firsts[..3], [0, 6, 9]);
    assert_eq!(s.joints[4].first_channel, 18);
    assert_eq!(s.joints[1].channels[0], Channel::Rotation(Axis::Z));
    assert_eq!(s.joints[1].channels[1], Channel::Rotation(Axis::X));
    assert_eq!(
        s.joints[4].channels[3..5],
        [Channel::Rotation(Axis::X), Channel::Rotation(Axis::Z)]
    );
    assert_eq!(s.joints[0].offset, [-224.689499, 91.882057, -431.625488]);
    assert_eq!(s.joints[2].offset, [43.5, -0.000042, 1e-5]);
    assert_eq!(s.joints[3].offset, [0.0, -40.0, 0.5]);
    assert!(s.joints[4].offset[2].is_sign_negative());
    let m = &bvh.motion;
    assert_eq!((m.num_frames, m.num_channels, m.values.len()), (3, 24, 72));
    assert_eq!(m.frame_time, 0.0083333);
    assert_eq!(m.frame(0)[9..11], [150.0, -0.0025]);
    assert_eq!(m.frame(1)[..6], [-0.0, 0.0, -0.0, 1.0, 5.0, 6.0]);
    assert!(m.frame(1)[0].is_sign_negative() && m.frame(1)[2].is_sign_negative());
    assert_eq!(m.frame(2)[0], 2.30145e-07);
    assert_eq!(m.frame(2)[23], 15.0);
    assert_round_trip(&bvh, "good_mixed_crlf.bvh");
}

#[test]
fn fixtures_round_trip_and_summarise() {
    for name in ["minimal.bvh", "good_mixed_crlf.bvh"] {
        let bvh = bvh::from_path(&fixture_dir().join(name)).unwrap();
        assert_round_trip(&bvh, name);
        let text = bvh::Summary::new(&bvh, name).to_string();
        assert!(text.contains("End Sites not counted"), "{text}");
    }
    let bvh = bvh::from_path(&fixture_dir().join("minimal.bvh")).unwrap();
    let s = bvh::Summary::new(&bvh, "minimal.bvh");
    assert_eq!((s.num_joints, s.num_end_sites, s.num_channels, s.num_frames), (2, 1, 9, 2));
    assert_eq!(s.extent, 30.0);
    assert_eq!(s.units, bvh::Units::Unknown);
    let text = s.to_string();
    assert!(
        text.contains(
            "\n  Hips [pos XYZ rot ZYX]\n    Spine [rot ZXY]\n      Spine_End (End Site)\n"
        ),
        "{text}"
    );
    assert!(text.contains("rotation orders: ZYX (1), ZXY (1)"), "{text}");
}

#[test]
fn writer_refuses_what_it_cannot_write() {
    let mut bvh = bvh::from_path(&fixture_dir().join("minimal.bvh")).unwrap();
    bvh.motion.values[3] = f64::NAN;
    assert!(bvh::write(&bvh, Vec::new()).is_err());
    bvh.motion.values.pop();
    assert!(bvh::write(&bvh, Vec::new()).is_err());
    assert!(bvh::write_json(&bvh, Vec::new()).is_err());
    let mut bvh = bvh::from_path(&fixture_dir().join("minimal.bvh")).unwrap();
    bvh.skeleton.joints[1].name = "Spine {".into();
    assert!(bvh::write(&bvh, Vec::new()).is_err());
    bvh.skeleton.joints[1].name = "Spine\nX".into();
    assert!(bvh::write(&bvh, Vec::new()).is_err());
    bvh.skeleton.joints[1].parent = Some(bvh::JointId(2));
    assert!(bvh::write(&bvh, Vec::new()).is_err());
}
