//! The skeleton recogniser on every clip of `$RETARGET_SHARED/data/bvh` and on the small
//! skeletons of `tests/data/skeletons` (written by `generate.py` there: one body in many
//! naming conventions, units, up axes and rest poses): every role's joint, the up axis, the
//! unit, the rest pose; and the body frames computed from bone geometry.

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::collections::BTreeMap;
use std::path::PathBuf;

use fk::{FkOptions, FkReport, HumanMotion, Humanoid, RestPose, Role, UpAxis};

fn skeleton(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/skeletons").join(name)
}

fn run(path: &std::path::Path, options: &FkOptions) -> (HumanMotion, FkReport) {
    let bvh = bvh::from_path(path).unwrap_or_else(|e| panic!("{e}"));
    fk::human_motion(&bvh, options).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn humanoid(report: &FkReport, file: &str) -> Humanoid {
    report.humanoid.clone().unwrap_or_else(|e| panic!("{file}: {e}"))
}

/// The role table in [`Role::ALL`] order: trunk (pelvis, spine, chest, neck, head), then per
/// side clavicle, upper arm, forearm, hand (left, right), then thigh, shin, foot, toe.
fn expect(h: &Humanoid, file: &str, trunk: [&str; 5], arms: [[&str; 4]; 2], legs: [[&str; 4]; 2]) {
    let expected: Vec<&str> =
        trunk.iter().chain(arms.iter().flatten()).chain(legs.iter().flatten()).copied().collect();
    for (role, want) in Role::ALL.iter().zip(expected) {
        let got = h.roles.joint(*role).unwrap_or("-");
        assert_eq!(got, want, "{file}: {role} ({:?})", h.roles.get(*role).map(|j| &j.rule));
    }
}

/// Joint names of the LAFAN1 / Mixamo style, with an optional namespace or prefix.
fn lafan_style(
    prefix: &str,
    chest: &str,
    toe: &str,
) -> ([String; 5], [[String; 4]; 2], [[String; 4]; 2]) {
    let n = |s: &str| format!("{prefix}{s}");
    let side = |side: &str, parts: [&str; 4]| parts.map(|p| n(&format!("{side}{p}")));
    (
        ["Hips", "Spine", chest, "Neck", "Head"].map(n),
        [
            side("Left", ["Shoulder", "Arm", "ForeArm", "Hand"]),
            side("Right", ["Shoulder", "Arm", "ForeArm", "Hand"]),
        ],
        [side("Left", ["UpLeg", "Leg", "Foot", toe]), side("Right", ["UpLeg", "Leg", "Foot", toe])],
    )
}

fn expect_owned(
    h: &Humanoid,
    file: &str,
    names: &([String; 5], [[String; 4]; 2], [[String; 4]; 2]),
) {
    #[allow(clippy::ptr_arg)] // mapped over arrays of String
    fn s(v: &String) -> &str {
        v.as_str()
    }
    fn limbs(l: &[[String; 4]; 2]) -> [[&str; 4]; 2] {
        [l[0].each_ref().map(s), l[1].each_ref().map(s)]
    }
    expect(h, file, names.0.each_ref().map(s), limbs(&names.1), limbs(&names.2));
}

const CMU_3DS: ([&str; 5], [[&str; 4]; 2], [[&str; 4]; 2]) = (
    ["Hips", "lowerback", "Chest2", "lowerneck", "Head"],
    [
        ["LeftCollar", "LeftShoulder", "LeftElbow", "LeftWrist"],
        ["RightCollar", "RightShoulder", "RightElbow", "RightWrist"],
    ],
    [
        ["LeftHip", "LeftKnee", "LeftAnkle", "LeftToe"],
        ["RightHip", "RightKnee", "RightAnkle", "RightToe"],
    ],
);

#[test]
fn every_shared_clip_gets_the_right_roles() {
    let Some(dir) = shared::shared_file("data/bvh") else { return };
    let mut seen = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let file = path.file_name().unwrap().to_string_lossy().into_owned();
        if !file.ends_with(".bvh") {
            continue;
        }
        seen += 1;
        let (_, report) = run(&path, &FkOptions::default());
        let h = humanoid(&report, &file);
        assert_eq!(h.up, UpAxis::PosY, "{file}: {}", h.up_reason);
        assert_eq!(report.axes, fk::AxisConvention::YUp, "{file}");
        assert!(h.sides.starts_with("names (geometry agrees)"), "{file}: {}", h.sides);
        if file.starts_with("lafan1") {
            expect_owned(&h, &file, &lafan_style("", "Spine2", "Toe"));
            assert_eq!(h.rest_pose, RestPose::NotUpright, "{file}");
            assert!(matches!(h.reference, fk::Reference::Frame(_)), "{file}");
        } else if file.starts_with("bandai") {
            let side = |s: &str, parts: [&str; 4]| parts.map(|p| format!("{p}_{s}"));
            let names = (
                ["Hips", "Spine", "Chest", "Neck", "Head"].map(String::from),
                [
                    side("L", ["Shoulder", "UpperArm", "LowerArm", "Hand"]),
                    side("R", ["Shoulder", "UpperArm", "LowerArm", "Hand"]),
                ],
                [
                    side("L", ["UpperLeg", "LowerLeg", "Foot", "Toes"]),
                    side("R", ["UpperLeg", "LowerLeg", "Foot", "Toes"]),
                ],
            );
            expect_owned(&h, &file, &names);
            assert_eq!(h.convention, Some("Bandai Namco"));
            assert_eq!(h.rest_pose, RestPose::NotUpright, "{file}");
        } else if file.starts_with("cmu") {
            expect(&h, &file, CMU_3DS.0, CMU_3DS.1, CMU_3DS.2);
            assert_eq!(h.rest_pose, RestPose::ArmsDown, "{file}: {}", h.rest_reason);
        } else if file.contains("mixamo") {
            expect_owned(&h, &file, &lafan_style("mixamorig:", "Spine2", "ToeBase"));
            assert_eq!(h.rest_pose, RestPose::TPose, "{file}: {}", h.rest_reason);
        } else if file.contains("mocapbank") {
            let mut names = CMU_3DS;
            names.0 = ["Hips", "Chest", "Chest2", "Neck", "Head"];
            names.2[0][3] = "-";
            names.2[1][3] = "-";
            expect(&h, &file, names.0, names.1, names.2);
        } else if file.contains("rigify") {
            // No hand joints: the hands are the forearms' End Sites (the wrists).
            expect(
                &h,
                &file,
                ["pelvis", "spine", "spine.001", "neck", "face"],
                [
                    ["shoulder.L", "upper_arm.L", "forearm.L", "forearm.L_End"],
                    ["shoulder.R", "upper_arm.R", "forearm.R", "forearm.R_End"],
                ],
                [["thigh.L", "shin.L", "foot.L", "-"], ["thigh.R", "shin.R", "foot.R", "-"]],
            );
            assert!(h.roles.get(Role::LeftHand).unwrap().end_site);
        } else {
            panic!("{file}: no expectation written for this clip");
        }
    }
    assert_eq!(seen, 13);
}

/// One of our skeletons: roles, up axis, unit, rest pose.
fn own(file: &str, up: UpAxis, metres_per_unit: f64, rest: RestPose) -> (HumanMotion, Humanoid) {
    let (motion, report) = run(&skeleton(file), &FkOptions::default());
    let h = humanoid(&report, file);
    assert_eq!(h.up, up, "{file}: {}", h.up_reason);
    assert_eq!(report.metres_per_unit, metres_per_unit, "{file}: {}", report.unit_reason);
    assert_eq!(h.rest_pose, rest, "{file}: {}", h.rest_reason);
    assert_eq!(h.roles.missing_required(), [], "{file}");
    // The generated body is 1.75 m tall, whatever the file's units and axes.
    assert!((report.height - 1.75).abs() < 0.03, "{file}: {report:?}");
    (motion, h)
}

#[test]
fn xsens_mvn_leftshoulder_is_the_upper_arm() {
    let (_, h) = own("xsens_mvn.bvh", UpAxis::PosY, 0.01, RestPose::TPose);
    assert_eq!(h.convention, Some("Xsens MVN (joints)"));
    expect(
        &h,
        "xsens",
        ["Hips", "Chest", "Chest4", "Neck", "Head"],
        [
            ["LeftCollar", "LeftShoulder", "LeftElbow", "LeftWrist"],
            ["RightCollar", "RightShoulder", "RightElbow", "RightWrist"],
        ],
        [
            ["LeftHip", "LeftKnee", "LeftAnkle", "LeftToe"],
            ["RightHip", "RightKnee", "RightAnkle", "RightToe"],
        ],
    );
}

#[test]
fn cmu_motionbuilder_release_with_lhipjoint_lowerback_neck1() {
    let (_, h) = own("cmu_motionbuilder.bvh", UpAxis::PosY, 0.01, RestPose::ArmsDown);
    assert_eq!(h.convention, Some("CMU (MotionBuilder-friendly BVH)"));
    let mut names = lafan_style("", "Spine1", "ToeBase");
    names.0[1] = "LowerBack".to_owned();
    expect_owned(&h, "cmu mb", &names);
}

#[test]
fn biped_z_up_in_inches() {
    let (motion, h) = own("biped_zup_inches.bvh", UpAxis::PosZ, 0.0254, RestPose::ArmsDown);
    let b = |s: &str, parts: [&str; 4]| parts.map(|p| format!("Bip01 {s} {p}"));
    let names = (
        ["Pelvis", "Spine", "Spine2", "Neck", "Head"].map(|p| format!("Bip01 {p}")),
        [
            b("L", ["Clavicle", "UpperArm", "Forearm", "Hand"]),
            b("R", ["Clavicle", "UpperArm", "Forearm", "Hand"]),
        ],
        [b("L", ["Thigh", "Calf", "Foot", "Toe0"]), b("R", ["Thigh", "Calf", "Foot", "Toe0"])],
    );
    expect_owned(&h, "biped", &names);
    // Z up in the file stays Z up in the world: the head is 1.6 m above the feet.
    let at = |name: &str| motion.position(0, motion.require_body(name).unwrap()).z;
    let rise = at("Bip01 Head") - at("Bip01 L Foot");
    assert!((1.45..1.53).contains(&rise), "{rise}");
}

/// MakeHuman: `Root` carries the translation, the legs hang from `Hips` beside `Spine1`
/// (through midline helpers `__UpLeg_L`), eyes and jaw hang from `Head`; Z up in decimetres.
/// Before, the legs-beside-the-trunk shape had no reading, and the arms were taken for legs.
#[test]
fn makehuman_legs_beside_the_trunk_in_decimetres() {
    let (motion, h) =
        own("makehuman_zup_decimetres_walk.bvh", UpAxis::PosZ, 0.1, RestPose::ArmsDown);
    assert_eq!(h.convention, Some("MakeHuman"));
    let m = |s: &str, parts: [&str; 4]| parts.map(|p| format!("{p}_{s}"));
    let names = (
        ["Hips", "Spine1", "Spine3", "Neck", "Head"].map(String::from),
        [
            m("L", ["Clavicle", "UpArm", "LoArm", "Hand"]),
            m("R", ["Clavicle", "UpArm", "LoArm", "Hand"]),
        ],
        [m("L", ["UpLeg", "LoLeg", "Foot", "Toe"]), m("R", ["UpLeg", "LoLeg", "Foot", "Toe"])],
    );
    expect_owned(&h, "makehuman", &names);
    assert_eq!(motion.num_frames, 180);
}

/// The classic 18-joint Biovision skeleton: no toe joint, inches, arms down.
#[test]
fn biovision_eighteen_joints_in_inches() {
    let (_, h) = own("biovision_inches_sprint.bvh", UpAxis::PosY, 0.0254, RestPose::ArmsDown);
    expect(
        &h,
        "biovision",
        ["Hips", "-", "Chest", "Neck", "Head"],
        [
            ["LeftCollar", "LeftUpArm", "LeftLowArm", "LeftHand"],
            ["RightCollar", "RightUpArm", "RightLowArm", "RightHand"],
        ],
        [
            ["LeftUpLeg", "LeftLowLeg", "LeftFoot", "-"],
            ["RightUpLeg", "RightLowLeg", "RightFoot", "-"],
        ],
    );
}

#[test]
fn daz_poser_in_an_a_pose() {
    let (_, h) = own("daz_poser_apose.bvh", UpAxis::PosY, 0.01, RestPose::APose);
    // lButtock sits at the hip point above lThigh: the thigh bone's carrier is lThigh.
    expect(
        &h,
        "daz",
        ["hip", "abdomen", "chest", "neck", "head"],
        [["lCollar", "lShldr", "lForeArm", "lHand"], ["rCollar", "rShldr", "rForeArm", "rHand"]],
        [["lThigh", "lShin", "lFoot", "-"], ["rThigh", "rShin", "rFoot", "-"]],
    );
}

#[test]
fn unreal_mannequin_ignores_twist_bones_and_ik_chains() {
    let (_, h) = own("unreal_zup.bvh", UpAxis::PosZ, 0.01, RestPose::ArmsDown);
    let u = |s: &str, parts: [&str; 4]| parts.map(|p| format!("{p}_{s}"));
    let names = (
        ["pelvis", "spine_01", "spine_03", "neck_01", "head"].map(String::from),
        [
            u("l", ["clavicle", "upperarm", "lowerarm", "hand"]),
            u("r", ["clavicle", "upperarm", "lowerarm", "hand"]),
        ],
        [u("l", ["thigh", "calf", "foot", "ball"]), u("r", ["thigh", "calf", "foot", "ball"])],
    );
    expect_owned(&h, "unreal", &names);
}

#[test]
fn a_root_on_the_floor_is_not_the_pelvis_even_by_name() {
    // Unreal's `root` lies on the floor under `pelvis`; ASF calls its pelvis `root`. With the
    // pelvis renamed, the name must not pull the pelvis role down to the floor.
    let mut bvh = bvh::from_path(&skeleton("unreal_zup.bvh")).unwrap();
    let pelvis = bvh.skeleton.find("pelvis").unwrap().0;
    bvh.skeleton.joints[pelvis].name = "hip_centre".to_owned();
    let h = fk::recognise(&bvh, &BTreeMap::new()).unwrap();
    assert_eq!(h.roles.joint(Role::Pelvis), Some("hip_centre"));
}

#[test]
fn smpl_in_metres_l_foot_is_the_toe() {
    let (_, h) = own("smpl_metres.bvh", UpAxis::PosY, 1.0, RestPose::TPose);
    expect(
        &h,
        "smpl",
        ["Pelvis", "Spine1", "Spine3", "Neck", "Head"],
        [
            ["L_Collar", "L_Shoulder", "L_Elbow", "L_Wrist"],
            ["R_Collar", "R_Shoulder", "R_Elbow", "R_Wrist"],
        ],
        [["L_Hip", "L_Knee", "L_Ankle", "L_Foot"], ["R_Hip", "R_Knee", "R_Ankle", "R_Foot"]],
    );
}

/// HumanML3D's "joints to BVH" converters (momask's and T2M-GPT's `joints2bvh`, `smpl2bvh`):
/// SMPL's 22 joints on SMPL's template body in its T zero pose (every frame turns the arms
/// down), metres, Y up, End Sites at their joints, the root OFFSET where SMPL's body model
/// has its pelvis (22 cm below its origin) and the pelvis's world position in the channels;
/// named as SMPL (`L_Hip`, or HumanML3D's `left_hip`) or with HumanIK's names.
#[test]
fn humanml3d_exports_on_smpls_template_in_smpl_or_humanik_names() {
    let smpl_names = (
        ["Pelvis", "Spine1", "Spine3", "Neck", "Head"],
        [
            ["L_Collar", "L_Shoulder", "L_Elbow", "L_Wrist"],
            ["R_Collar", "R_Shoulder", "R_Elbow", "R_Wrist"],
        ],
        [["L_Hip", "L_Knee", "L_Ankle", "L_Foot"], ["R_Hip", "R_Knee", "R_Ankle", "R_Foot"]],
    );
    // HumanML3D's own joint list: `pelvis`, `left_hip`, `spine1`, `left_foot` (the toe).
    let humanml3d = |name: &str| {
        let name = name.replacen("L_", "left_", 1).replacen("R_", "right_", 1);
        name.to_lowercase()
    };
    let text = std::fs::read_to_string(skeleton("humanml3d_smpl_walk.bvh")).unwrap();
    let lower: String = text
        .lines()
        .map(|line| match line.trim_start().split_once(' ') {
            Some(("ROOT" | "JOINT", name)) => line.replace(name, &humanml3d(name)),
            _ => line.to_owned(),
        })
        .collect::<Vec<_>>()
        .join("\n");
    let lower_names = (
        smpl_names.0.map(humanml3d),
        smpl_names.1.map(|side| side.map(humanml3d)),
        smpl_names.2.map(|side| side.map(humanml3d)),
    );
    let hik = lafan_style("", "Spine2", "ToeBase");
    let files = [
        ("humanml3d_smpl_walk.bvh", bvh::parse(text.as_bytes()).unwrap(), owned(&smpl_names)),
        ("humanml3d (left_hip)", bvh::parse(lower.as_bytes()).unwrap(), lower_names),
        ("hik_metres_walk.bvh", bvh::from_path(&skeleton("hik_metres_walk.bvh")).unwrap(), hik),
    ];
    for (file, bvh, names) in files {
        let (motion, report) = fk::human_motion(&bvh, &FkOptions::default()).unwrap();
        let h = humanoid(&report, file);
        expect_owned(&h, file, &names);
        assert_eq!(h.up, UpAxis::PosY, "{file}: {}", h.up_reason);
        assert_eq!(report.metres_per_unit, 1.0, "{file}: {}", report.unit_reason);
        assert_eq!(h.rest_pose, RestPose::TPose, "{file}: {}", h.rest_reason);
        // The channels are the pelvis's place: the walk is on the floor at 0 (read as added
        // to the OFFSET, it sank 22 cm under it), the pelvis 0.94 m above it.
        let root = &report.position_channels[0];
        assert_eq!(root.reading, fk::PositionReading::Local, "{file}: {}", root.reason);
        assert!(report.ground.abs() < 0.02, "{file}: ground {}", report.ground);
        let pelvis = motion.body_names.iter().position(|b| b == &names.0[0]).unwrap();
        let z = motion.positions[pelvis].z;
        assert!((z - 0.96).abs() < 0.02, "{file}: pelvis at {z} m in frame 0");
        // The head joint ends the trunk (a zero End Site): a skull is added above it.
        assert!((1.6..1.8).contains(&report.height), "{file}: {report:?}");
    }
}

/// A borrowed name table as an owned one ([`expect_owned`]).
fn owned(
    names: &([&str; 5], [[&str; 4]; 2], [[&str; 4]; 2]),
) -> ([String; 5], [[String; 4]; 2], [[String; 4]; 2]) {
    let side = |s: &[&str; 4]| s.map(str::to_owned);
    (
        names.0.map(str::to_owned),
        [side(&names.1[0]), side(&names.1[1])],
        [side(&names.2[0]), side(&names.2[1])],
    )
}

#[test]
fn asf_style_in_millimetres() {
    let (_, h) = own("asf_millimetres.bvh", UpAxis::PosY, 0.001, RestPose::ArmsDown);
    expect(
        &h,
        "asf",
        ["root", "lowerback", "thorax", "lowerneck", "head"],
        [
            ["lclavicle", "lhumerus", "lradius", "lwrist"],
            ["rclavicle", "rhumerus", "rradius", "rwrist"],
        ],
        [["lfemur", "ltibia", "lfoot", "ltoes"], ["rfemur", "rtibia", "rfoot", "rtoes"]],
    );
}

#[test]
fn rigify_deform_bones_split_in_two_are_one_segment() {
    let (_, h) = own("rigify_def_segments.bvh", UpAxis::PosY, 1.0, RestPose::ArmsDown);
    let d = |s: &str, parts: [&str; 4]| parts.map(|p| format!("DEF-{p}.{s}"));
    let names = (
        ["spine", "spine.001", "spine.003", "spine.004", "spine.006"].map(|p| format!("DEF-{p}")),
        [
            d("L", ["shoulder", "upper_arm", "forearm", "hand"]),
            d("R", ["shoulder", "upper_arm", "forearm", "hand"]),
        ],
        [d("L", ["thigh", "shin", "foot", "toe"]), d("R", ["thigh", "shin", "foot", "toe"])],
    );
    expect_owned(&h, "rigify", &names);
}

#[test]
fn rokoko_with_fingers_and_face_joints() {
    let (_, h) = own("rokoko_fingers_face.bvh", UpAxis::PosY, 0.01, RestPose::ArmsDown);
    expect_owned(&h, "rokoko", &lafan_style("", "Spine3", "ToeBase"));
}

#[test]
fn unnamed_skeleton_by_hierarchy_and_facing() {
    // joint1 … joint20, the right limbs listed first, the subject facing 130° from +Z.
    let (_, h) = own("unnamed_joints.bvh", UpAxis::PosY, 0.01, RestPose::ArmsDown);
    assert_eq!(h.convention, None);
    assert!(h.sides.starts_with("geometry"), "{}", h.sides);
    let j = |n: [u32; 4]| n.map(|i| format!("joint{i}"));
    let names = (
        ["joint1", "-", "joint6", "joint7", "joint8"].map(String::from),
        [j([13, 14, 15, 16]), j([9, 10, 11, 12])],
        [j([17, 18, 19, 20]), j([2, 3, 4, 5])],
    );
    expect_owned(&h, "unnamed", &names);
    for (_, joint) in h.roles.iter() {
        assert!(matches!(joint.rule, fk::Rule::Hierarchy(_)), "{joint:?}");
    }
}

#[test]
fn zero_pose_lying_down_is_not_trusted() {
    let (lying, h) = own("mixamo_zero_pose_lying.bvh", UpAxis::PosY, 0.01, RestPose::NotUpright);
    expect_owned(&h, "lying", &lafan_style("mixamorig_", "Spine2", "ToeBase"));
    assert_eq!(h.reference, fk::Reference::Frame(0));
    // The same body and motion with an upright zero pose (and fingers and a prop): the body
    // frames, carried by the joints, agree in every frame although the zero poses differ.
    let (upright, u) = own("mixamo_prop_in_hand.bvh", UpAxis::PosY, 0.01, RestPose::ArmsDown);
    assert_eq!(u.reference, fk::Reference::Rest);
    for (role, offset) in &h.frame_offsets {
        if matches!(role.part(), fk::Part::Foot | fk::Part::Toe) {
            continue; // flattened to the ground plane in the reference pose, not rigid
        }
        let name = h.roles.joint(*role).unwrap().trim_start_matches("mixamorig_");
        let other = upright.require_body(name).unwrap();
        let mine = lying.require_body(h.roles.joint(*role).unwrap()).unwrap();
        for f in 0..lying.num_frames {
            let a = lying.orientation(f, mine) * offset;
            let b = upright.orientation(f, other) * u.frame_offsets[role];
            assert!(a.angle_to(&b) < 1e-6, "{role} frame {f}: {}", a.angle_to(&b));
        }
    }
}

#[test]
fn a_prop_in_the_hand_changes_neither_roles_nor_unit() {
    // A 1.5 m pole under the right hand: longer than an arm.
    let (_, h) = own("mixamo_prop_in_hand.bvh", UpAxis::PosY, 0.01, RestPose::ArmsDown);
    expect_owned(&h, "prop", &lafan_style("", "Spine2", "ToeBase"));
}

#[test]
fn body_frames_in_a_standing_zero_pose() {
    // SMPL T-pose facing file +Z, Y up: the pelvis frame is (forward, left, up) =
    // (file +Z, file +X, file +Y) and its joint has no rotation in the zero pose.
    let (_, h) = own("smpl_metres.bvh", UpAxis::PosY, 1.0, RestPose::TPose);
    let m = h.frame_offsets[&Role::Pelvis].to_rotation_matrix();
    let expected = nalgebra::Matrix3::new(0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0);
    assert!((m.matrix() - expected).amax() < 1e-9, "{m}");
    // The left upper arm points sideways: its z (towards the shoulder) is file −X.
    let arm = h.frame_offsets[&Role::LeftUpperArm] * nalgebra::Vector3::z();
    assert!((arm + nalgebra::Vector3::x()).norm() < 0.05, "{arm}");
    assert_eq!(h.frame_offsets.len(), Role::ALL.len());
}

#[test]
fn an_unrecognisable_skeleton_is_a_clear_error() {
    let bvh = bvh::from_path(&skeleton("unrecognisable_chain.bvh")).unwrap();
    let err = fk::recognise(&bvh, &BTreeMap::new()).unwrap_err();
    let fk::Error::Unrecognised { missing, .. } = &err else { panic!("{err}") };
    assert!(missing.contains(&Role::LeftHand) && missing.contains(&Role::Pelvis), "{missing:?}");
    let text = err.to_string();
    assert!(text.contains("left_hand: a joint named e.g. LeftHand"), "{text}");
    // FK itself still works, with the BVH norm for the axes.
    let (_, report) = fk::human_motion(&bvh, &FkOptions::default()).unwrap();
    assert!(report.humanoid.is_err());
    assert_eq!(report.axes, fk::AxisConvention::YUp);
    assert!(report.inferred().contains("not recognised"), "{}", report.inferred());
}

#[test]
fn given_roles_override_and_unknown_joints_are_errors() {
    let bvh = bvh::from_path(&skeleton("unnamed_joints.bvh")).unwrap();
    let mut given = BTreeMap::new();
    given.insert(Role::Spine, "joint6".to_owned());
    given.insert(Role::LeftHand, "joint16_End".to_owned());
    let h = fk::recognise(&bvh, &given).unwrap();
    assert_eq!(h.roles.joint(Role::Spine), Some("joint6"));
    assert_eq!(h.roles.get(Role::LeftHand).unwrap().rule, fk::Rule::Given);
    assert!(h.roles.get(Role::LeftHand).unwrap().end_site);
    given.insert(Role::Head, "Skull".to_owned());
    let err = fk::recognise(&bvh, &given).unwrap_err();
    assert_eq!(err, fk::Error::UnknownRoleJoint { role: Role::Head, name: "Skull".to_owned() });
    // Given roles complete a skeleton the recogniser cannot read alone.
    let chain = bvh::from_path(&skeleton("unrecognisable_chain.bvh")).unwrap();
    let err = fk::recognise(&chain, &[(Role::Pelvis, "base".to_owned())].into()).unwrap_err();
    let fk::Error::Unrecognised { missing, .. } = err else { panic!() };
    assert!(!missing.contains(&Role::Pelvis));
}

/// SOMA's role names, the same in every take of the rig (`LeftLeg` is the thigh here, the
/// shin in LAFAN1 and Mixamo).
const SOMA: ([&str; 5], [[&str; 4]; 2], [[&str; 4]; 2]) = (
    ["Hips", "Spine1", "Chest", "Neck1", "Head"],
    [
        ["LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand"],
        ["RightShoulder", "RightArm", "RightForeArm", "RightHand"],
    ],
    [
        ["LeftLeg", "LeftShin", "LeftFoot", "LeftToeBase"],
        ["RightLeg", "RightShin", "RightFoot", "RightToeBase"],
    ],
);

/// A SOMA take (`tests/data/soma/SOURCE.md`: eight frames of a BONES-SEED walk): the thigh
/// is `LeftLeg` and the knee `LeftShin` by the SOMA convention, centimetres, Y up, a zero
/// pose lying along +X (bone-axis aligned), and a 1.75 m subject whose head ends at the
/// `HeadEnd` joint (a joint, not an End Site: no skull is added above it).
#[test]
fn soma_leftleg_is_the_thigh_and_leftshin_the_knee() {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/soma/soma_walk_excerpt.bvh");
    let (motion, report) = run(&path, &FkOptions::default());
    let h = humanoid(&report, "soma");
    assert_eq!(h.convention, Some("SOMA (NVIDIA soma-retargeter, BONES-SEED)"));
    expect(&h, "soma", SOMA.0, SOMA.1, SOMA.2);
    for role in [Role::LeftThigh, Role::RightThigh, Role::LeftShin, Role::RightShin] {
        let rule = &h.roles.get(role).unwrap().rule;
        assert!(
            matches!(rule, fk::Rule::Name { convention, .. } if convention.starts_with("SOMA")),
            "{role}: {rule:?}"
        );
    }
    assert_eq!(h.up, UpAxis::PosY, "{}", h.up_reason);
    assert_eq!(report.axes, fk::AxisConvention::YUp);
    assert_eq!(report.metres_per_unit, 0.01, "{}", report.unit_reason);
    assert_eq!(h.rest_pose, RestPose::NotUpright, "{}", h.rest_reason);
    assert!(matches!(h.reference, fk::Reference::Frame(_)), "{:?}", h.reference);
    assert!(h.sides.starts_with("names (geometry agrees)"), "{}", h.sides);
    assert!((1.72..1.78).contains(&report.height), "{} ({})", report.height, report.height_source);
    // The thigh bone runs hip → knee (43 cm), the shin knee → ankle (42 cm), in every frame.
    let at = |f: usize, name: &str| motion.position(f, motion.require_body(name).unwrap());
    for f in 0..motion.num_frames {
        for side in ["Left", "Right"] {
            let (hip, knee, ankle) = (
                at(f, &format!("{side}Leg")),
                at(f, &format!("{side}Shin")),
                at(f, &format!("{side}Foot")),
            );
            assert!(((hip - knee).norm() - 0.433).abs() < 0.002, "frame {f} {side}");
            assert!(((knee - ankle).norm() - 0.423).abs() < 0.002, "frame {f} {side}");
            assert!(hip.z > knee.z && knee.z > ankle.z, "frame {f} {side}: {hip} {knee} {ankle}");
        }
    }
}

/// The four SOMA takes of the shared data: the same roles, unit and axes as the excerpt.
#[test]
fn every_shared_soma_take_gets_the_soma_roles() {
    let Some(dir) = shared::shared_file("data/soma") else { return };
    let mut seen = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let file = path.file_name().unwrap().to_string_lossy().into_owned();
        if !file.ends_with(".bvh") {
            continue;
        }
        seen += 1;
        let (_, report) = run(&path, &FkOptions::default());
        let h = humanoid(&report, &file);
        expect(&h, &file, SOMA.0, SOMA.1, SOMA.2);
        assert_eq!(h.up, UpAxis::PosY, "{file}: {}", h.up_reason);
        assert_eq!(report.metres_per_unit, 0.01, "{file}");
        assert_eq!(h.rest_pose, RestPose::NotUpright, "{file}");
        assert!(h.sides.starts_with("names (geometry agrees)"), "{file}: {}", h.sides);
    }
    assert_eq!(seen, 4);
}
