//! Real exporters' BVH quirks in forward kinematics: how position channels are read
//! (`fk::PositionReading`: a root OFFSET repeated in the channels or not, non-root channels
//! that repeat the OFFSET, carry a translation, a displacement or world positions), scale
//! channels, joints without End Sites and a frame rate that is not an integer.
//!
//! The files are written here; world poses are checked in file coordinates (Z-up convention
//! and 1 m per unit: no axis or unit conversion), against positions worked out by hand.

#[path = "../../../tests/support/shared.rs"]
mod shared;

use fk::{AxisConvention, FkOptions, FkReport, HumanMotion, PositionReading, UnitChoice};
use nalgebra::Vector3;

/// A BVH file from its hierarchy (between `HIERARCHY` and `MOTION`) and motion rows.
fn parse(hierarchy: &str, frame_time: &str, rows: &[&str]) -> bvh::Bvh {
    let text = format!(
        "HIERARCHY\n{hierarchy}MOTION\nFrames: {}\nFrame Time: {frame_time}\n{}\n",
        rows.len(),
        rows.join("\n")
    );
    bvh::from_str(&text).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

/// FK with the file's own axes and units, so world positions are the file's numbers.
fn file_frame_fk(bvh: &bvh::Bvh) -> (HumanMotion, FkReport) {
    let options = FkOptions {
        axes: AxisConvention::ZUp,
        units: UnitChoice::Scale(1.0),
        ..FkOptions::default()
    };
    fk::human_motion(bvh, &options).unwrap_or_else(|e| panic!("{e}"))
}

fn at(motion: &HumanMotion, frame: usize, body: &str) -> Vector3<f64> {
    *motion.position(frame, motion.require_body(body).unwrap())
}

#[track_caller]
fn assert_near(actual: Vector3<f64>, expected: [f64; 3]) {
    let expected = Vector3::from(expected);
    assert!((actual - expected).amax() < 1e-9, "{actual:?} != {expected:?}");
}

/// The reading `fk` chose for `joint`, and why.
fn reading(report: &FkReport, joint: &str) -> (PositionReading, String) {
    let found = report.position_channels.iter().find(|p| p.joint == joint);
    let found = found.unwrap_or_else(|| panic!("{joint} in {:?}", report.position_channels));
    (found.reading, found.reason.clone())
}

/// Hips (6 channels, `hips_offset`) with one leg down to the floor: Knee 50 below the hips,
/// Foot 45 below the knee, an End Site 5 below that: the sole is 100 below the hips.
fn hips_and_leg(hips_offset: &str) -> String {
    format!(
        "ROOT Hips\n{{\n OFFSET {hips_offset}\n \
         CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n \
         JOINT Knee\n {{\n  OFFSET 0 -50 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n  \
         JOINT Foot\n  {{\n   OFFSET 0 -45 0\n   CHANNELS 3 Zrotation Xrotation Yrotation\n   \
         End Site\n   {{\n    OFFSET 0 -5 0\n   }}\n  }}\n }}\n}}\n"
    )
}

#[test]
fn a_root_offset_repeated_in_frame_0_is_not_added_twice() {
    // LAFAN1: the root OFFSET is the first frame's position. Added to the channels, the hips
    // would stand at twice their height, 100 above the floor.
    let bvh = parse(
        &hips_and_leg("-224.5 100 -431.5"),
        "0.033333",
        &["-224.5 100 -431.5 0 0 0 0 0 0 0 0 0", "-200 101 -400 0 0 0 0 0 0 0 0 0"],
    );
    let (motion, report) = file_frame_fk(&bvh);
    assert_eq!(
        reading(&report, "Hips"),
        (PositionReading::Local, "frame 0 repeats the OFFSET".into())
    );
    assert_near(at(&motion, 0, "Hips"), [-224.5, 100.0, -431.5]);
    assert_near(at(&motion, 1, "Hips"), [-200.0, 101.0, -400.0]);
    assert_near(at(&motion, 0, "Foot_End"), [-224.5, 0.0, -431.5]);
}

#[test]
fn a_root_offset_at_standing_height_included_in_the_channels_is_not_added() {
    // MotionBuilder-style: OFFSET = standing hip height, channels = the hips' world position
    // (walking far from the origin, bobbing; frame 0 is not the OFFSET).
    let rows: Vec<String> = (0..40)
        .map(|f| {
            let f = f64::from(f);
            format!(
                "{} {} {} 0 0 0 0 0 0 0 0 0",
                300.0 - 20.0 * f,
                97.0 + (f * 0.7).sin(),
                -250.0 + 15.0 * f
            )
        })
        .collect();
    let rows: Vec<&str> = rows.iter().map(String::as_str).collect();
    let bvh = parse(&hips_and_leg("0 100 0"), "0.033333", &rows);
    let (motion, report) = file_frame_fk(&bvh);
    let (read, why) = reading(&report, "Hips");
    assert_eq!(read, PositionReading::Local, "{why}");
    // Y is the axis that varies least for its OFFSET component: the height decides.
    assert_eq!(
        why,
        "Y median 97.0672 stands it 97.0672 above 0, nearer its zero pose's depth 100.0000 than \
         with the OFFSET's 100.0000 added"
    );
    assert_near(at(&motion, 0, "Hips"), [300.0, 97.0, -250.0]);
    let sole = at(&motion, 10, "Foot_End");
    assert!((sole.y - (97.0 + 7f64.sin() - 100.0)).abs() < 1e-9, "{sole:?}");
}

#[test]
fn a_root_offset_missing_from_the_channels_is_added() {
    // The Rigify export in the shared data: OFFSET = pelvis height, channels = a few
    // centimetres of sway. Read as GMR does, the feet would sink 100 below the floor.
    let bvh = parse(
        &hips_and_leg("0 100 0"),
        "0.041667",
        &["0.6 -1 0.3 0 0 0 0 0 0 0 0 0", "0.7 -0.5 0.2 0 0 0 0 0 0 0 0 0"],
    );
    let (motion, report) = file_frame_fk(&bvh);
    assert_eq!(
        reading(&report, "Hips"),
        (
            PositionReading::Added,
            "Y median -0.5000 plus the OFFSET's 100.0000 stands it 99.5000 above 0, nearer its \
             zero pose's depth 100.0000 than the median alone"
                .into()
        )
    );
    assert_near(at(&motion, 0, "Hips"), [0.6, 99.0, 0.3]);
    assert_near(at(&motion, 1, "Foot_End"), [0.7, -0.5, 0.2]);
}

#[test]
fn a_root_offset_below_the_origin_with_the_world_position_in_the_channels_is_not_added() {
    // HumanML3D's converters (smpl2bvh, joints2bvh): the root OFFSET is where SMPL's body
    // model has its pelvis, 22 below its origin, the channels the pelvis's world position.
    // The channels' median (93) is nearer 0 than that OFFSET, but added to it the feet would
    // sink 22 under the floor the walk is on.
    let bvh = parse(
        &hips_and_leg("0 -22 3"),
        "0.05",
        &["0 100.5 3 0 0 0 0 0 0 0 0 0", "0 99 13 0 0 0 0 0 0 0 0 0"],
    );
    let (motion, report) = file_frame_fk(&bvh);
    let (read, why) = reading(&report, "Hips");
    assert_eq!(read, PositionReading::Local, "{why}");
    assert_near(at(&motion, 0, "Hips"), [0.0, 100.5, 3.0]);
    assert_near(at(&motion, 1, "Foot_End"), [0.0, -1.0, 13.0]);
}

#[test]
fn a_partial_set_of_position_channels_keeps_the_other_offset_components() {
    // Only Yposition: X and Z come from the OFFSET in every reading.
    let bvh = parse(
        "ROOT Hips\n{\n OFFSET 5 100 -3\n CHANNELS 2 Yposition Yrotation\n \
         End Site\n {\n  OFFSET 0 -100 0\n }\n}\n",
        "0.033333",
        &["98 0", "96 90"],
    );
    let (motion, report) = file_frame_fk(&bvh);
    assert_eq!(reading(&report, "Hips").0, PositionReading::Local);
    assert_near(at(&motion, 1, "Hips"), [5.0, 96.0, -3.0]);
    assert_near(at(&motion, 1, "Hips_End"), [5.0, -4.0, -3.0]);
}

/// Bandai Namco's layout: a floor root, and every joint with six channels.
const BANDAI: &str = "ROOT joint_Root\n{\n OFFSET 0 0 0\n \
    CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n \
    JOINT Hips\n {\n  OFFSET 0 93.9 -3\n  \
    CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n  \
    JOINT Spine\n  {\n   OFFSET 15.7 0 0\n   \
    CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n   \
    End Site\n   {\n    OFFSET 10 0 0\n   }\n  }\n }\n}\n";

#[test]
fn non_root_channels_that_repeat_the_offset_are_harmless() {
    // Spine repeats its OFFSET up to Bandai's float noise (5.1e-06 for 0); Hips, under a
    // floor root that never moves, carries the translation, hip height included (Blender
    // writes OFFSET + translation the same way).
    let bvh = parse(
        BANDAI,
        "0.0333333",
        &[
            "0 0 0 0 0 -0 -1.7 90.3 -407.1 90 0 0 15.7 5.1e-06 -5.5e-07 0 0 0",
            "0 0 0 0 0 -0 -1.8 90.4 -400.2 90 0 0 15.7 5.1e-06 -5.5e-07 0 0 0",
            "0 0 0 0 0 -0 -2.0 90.6 -393.0 90 0 0 15.7 5.1e-06 -5.5e-07 0 0 0",
        ],
    );
    let (motion, report) = file_frame_fk(&bvh);
    let (hips, why) = reading(&report, "Hips");
    assert_eq!(hips, PositionReading::Local, "{why}");
    assert_eq!(
        reading(&report, "Spine"),
        (PositionReading::Local, "frame 0 repeats the OFFSET".into())
    );
    assert_eq!(reading(&report, "joint_Root").0, PositionReading::Local);
    // Hips at its channels (not 93.9 higher); Zrotation 90 turns Spine's +X bone to +Y.
    assert_near(at(&motion, 2, "Hips"), [-2.0, 90.6, -393.0]);
    let spine = at(&motion, 2, "Spine");
    assert!((spine - Vector3::new(-2.0 - 5.1e-6, 90.6 + 15.7, -393.0 - 5.5e-7)).amax() < 1e-12);
    assert!((at(&motion, 2, "Spine_End") - spine - Vector3::new(0.0, 10.0, 0.0)).amax() < 1e-12);
}

/// Root (translation, Y rotation), Spine (six channels), Head (rotations), Head_End.
const ROOT_SPINE_HEAD: &str = "ROOT Root\n{\n OFFSET 0 0 0\n \
    CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n \
    JOINT Spine\n {\n  OFFSET 0 10 2\n  \
    CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n  \
    JOINT Head\n  {\n   OFFSET 0 50 0\n   CHANNELS 3 Zrotation Xrotation Yrotation\n   \
    End Site\n   {\n    OFFSET 0 0 8\n   }\n  }\n }\n}\n";

#[test]
fn non_root_world_positions_are_recognised() {
    // Spine's channels hold its world position: the root at (10, 90, 5) turned 90° about Y
    // puts OFFSET (0, 10, 2) at (12, 100, 5). Read as local, Spine would land at
    // (15, 190, −7).
    let bvh = parse(
        ROOT_SPINE_HEAD,
        "0.033333",
        &[
            "10 90 5 0 0 90 12 100 5 0 0 0 0 0 0",
            "12 90 5 0 0 0 12 100 7 0 0 0 0 0 0",
            "14 91 5 0 0 -90 12 101 5 0 0 0 0 0 90",
        ],
    );
    let (motion, report) = file_frame_fk(&bvh);
    assert_eq!(
        reading(&report, "Spine"),
        (
            PositionReading::World,
            "at the world position parent + OFFSET predicts in 3 of 3 frames".into()
        )
    );
    assert_near(at(&motion, 0, "Spine"), [12.0, 100.0, 5.0]);
    // Orientation still chains: the head 50 up, its End Site 8 along the root-turned +Z.
    assert_near(at(&motion, 0, "Head"), [12.0, 150.0, 5.0]);
    assert_near(at(&motion, 0, "Head_End"), [20.0, 150.0, 5.0]);
    assert_near(at(&motion, 1, "Head_End"), [12.0, 150.0, 15.0]);
    // Frame 2: root −90° about Y, head +90: the End Site points along +Z again.
    assert_near(at(&motion, 2, "Head_End"), [12.0, 151.0, 13.0]);
}

#[test]
fn non_root_displacements_are_added_to_the_offset() {
    // Channels near zero on a bone 10.2 long: a stretch added to OFFSET, not the bone itself.
    let bvh = parse(
        ROOT_SPINE_HEAD,
        "0.033333",
        &["0 90 0 0 0 0 0.2 -0.1 0 0 0 0 0 0 0", "0 90 0 0 0 0 0.3 0 0.1 0 0 0 0 0 0"],
    );
    let (motion, report) = file_frame_fk(&bvh);
    assert_eq!(reading(&report, "Spine").0, PositionReading::Added);
    assert_near(at(&motion, 0, "Spine"), [0.2, 99.9, 2.0]);
    assert_near(at(&motion, 1, "Head"), [0.3, 150.0, 2.1]);
}

#[test]
fn scale_channels_are_ignored() {
    let with_scale = parse(
        "ROOT Hips\n{\n OFFSET 0 90 0\n \
         CHANNELS 9 Xposition Yposition Zposition Zrotation Xrotation Yrotation Xscale Yscale Zscale\n \
         JOINT Spine\n {\n  OFFSET 0 10 0\n  CHANNELS 6 Zrotation Xscale Xrotation Yscale Zscale Yrotation\n  \
         End Site\n  {\n   OFFSET 0 50 0\n  }\n }\n}\n",
        "0.0333333",
        &["1 90 2 10 20 30 1 1 1 5 2 6 0.5 0.5 7", "1 91 2 11 21 31 1 1 1 8 2 9 0.5 0.5 9"],
    );
    let without = parse(
        "ROOT Hips\n{\n OFFSET 0 90 0\n \
         CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n \
         JOINT Spine\n {\n  OFFSET 0 10 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n  \
         End Site\n  {\n   OFFSET 0 50 0\n  }\n }\n}\n",
        "0.0333333",
        &["1 90 2 10 20 30 5 6 7", "1 91 2 11 21 31 8 9 9"],
    );
    let (a, _) = file_frame_fk(&with_scale);
    let (b, _) = file_frame_fk(&without);
    assert_eq!(a.positions, b.positions);
    assert_eq!(a.orientations, b.orientations);
}

#[test]
fn joints_without_end_sites_are_bodies_like_any_other() {
    let bvh = parse(
        "ROOT Hips\n{\n OFFSET 0 90 0\n \
         CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n \
         JOINT Head\n {\n  OFFSET 0 60 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n }\n \
         JOINT Foot\n {\n  OFFSET 0 -90 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n }\n}\n",
        "0.0333333",
        &["0 90 0 0 0 0 0 0 0 0 0 0"],
    );
    let (motion, _) = file_frame_fk(&bvh);
    assert_eq!(motion.body_names, ["Hips", "Head", "Foot"]);
    assert_near(at(&motion, 0, "Head"), [0.0, 150.0, 0.0]);
    assert_near(at(&motion, 0, "Foot"), [0.0, 0.0, 0.0]);
}

#[test]
fn a_frame_rate_of_119_875_is_not_snapped_to_120() {
    let hierarchy = hips_and_leg("0 100 0");
    let row = "0 100 0 0 0 0 0 0 0 0 0 0";
    for (frame_time, fps) in [
        ("0.00834202", 1.0 / 0.00834202),
        ("0.008342", 1.0 / 0.008342),
        ("8.342023e-003", 1.0 / 8.342023e-3),
        ("0.0083333", 120.0),
    ] {
        let bvh = parse(&hierarchy, frame_time, &[row, row]);
        let (motion, _) = file_frame_fk(&bvh);
        assert_eq!(motion.fps, fps, "{frame_time}");
        if fps != 120.0 {
            assert!((motion.fps - 119.875).abs() < 1e-3, "{frame_time}: {}", motion.fps);
        }
    }
}

/// A LAFAN1 take with its first 100 frames cut: the root OFFSET (the old first position,
/// mostly horizontal) no longer matches frame 0, and the hips wander 7 m around it; the
/// height axis still tells that the channels include the OFFSET.
fn lafan1_cut_after_frame_0_still_reads_local(bvh: &bvh::Bvh, report: &FkReport) {
    let mut cut = bvh.clone();
    let skip = 100 * cut.motion.num_channels;
    cut.motion.values.drain(..skip);
    cut.motion.num_frames -= 100;
    let (_, cut_report) = fk::human_motion(&cut, &FkOptions::default()).unwrap();
    let (read, why) = reading(&cut_report, "Hips");
    assert_eq!(read, PositionReading::Local, "{why}");
    assert!(why.starts_with("Y median "), "{why}");
    assert!((cut_report.ground - report.ground).abs() < 0.05, "{cut_report:?} vs {report:?}");
}

#[test]
fn shared_files_read_their_position_channels_as_their_exporters_wrote_them() {
    let Some(dir) = shared::shared_file("data/bvh") else { return };
    let mut files: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
    files.retain(|p| p.extension().is_some_and(|e| e == "bvh"));
    files.sort();
    assert!(files.len() >= 13);
    for path in files {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let bvh = bvh::from_path(&path).unwrap();
        let (_, report) = fk::human_motion(&bvh, &FkOptions::default()).unwrap();
        for p in &report.position_channels {
            // Only the Rigify export's root leaves its OFFSET out of its channels.
            let expected = if name.contains("rigify") && p.joint == "pelvis" {
                PositionReading::Added
            } else {
                PositionReading::Local
            };
            assert_eq!(p.reading, expected, "{name}: {p:?}");
        }
        let moving_hips = name.starts_with("bandai") || name.starts_with("lafan1");
        if moving_hips {
            let hips = report.position_channels.iter().find(|p| p.joint == "Hips").unwrap();
            eprintln!("{name}: Hips {}", hips.reason);
        }
        if name.starts_with("lafan1") {
            assert_eq!(reading(&report, "Hips").1, "frame 0 repeats the OFFSET");
            lafan1_cut_after_frame_0_still_reads_local(&bvh, &report);
        }
        // The Rigify pelvis now stands at its height: the feet reach the floor.
        assert!(report.ground.abs() < 0.06, "{name}: {report:?}");
    }
}
