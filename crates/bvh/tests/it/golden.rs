//! Golden pairs: `tests/data/bad_*.bvh` and their expected errors in `tests/data/errors.txt`
//! (`<file>: <line>:<column>: <message>`, one line per case), and the accepted fixtures.
//! `BVH_BLESS=1 cargo test -p bvh` rewrites `errors.txt` from the current messages.

use std::path::Path;

use bvh::{Axis, Channel, Error, JointKind};

use crate::{assert_round_trip, fixture_dir};

fn bad_cases() -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(fixture_dir())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("bad_") && n.ends_with(".bvh"))
        .collect();
    names.sort();
    names
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
    if std::env::var_os("BVH_BLESS").is_some() {
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
        "TooFewFrames",
        "TooManyFrames",
        "Invalid",
    ] {
        assert!(kinds.contains(kind), "no bad_*.bvh case for Error::{kind}: {kinds:?}");
    }
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
