//! Our own small FBX files (`tests/data/generate.py`): ASCII 7.4 (Z up, two takes, a prop
//! with a pre-rotation and a pivot) and ASCII 6.1 (keys under `Takes`), checked against
//! values computed by hand; and every kind of bad input, each an error naming the file.

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::PathBuf;

use nalgebra::{Matrix3, Rotation3, Vector3};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

fn open(name: &str) -> fbx::Fbx {
    fbx::Fbx::from_path(&data(name)).unwrap_or_else(|e| panic!("{e}"))
}

fn node(fbx: &fbx::Fbx, name: &str) -> usize {
    fbx.info().skeleton.iter().position(|n| n.name == name).unwrap_or_else(|| panic!("{name}"))
}

/// The walk's hips in body coordinates (cm, Z up, facing −Y) at a time: keys every 0.1 s,
/// linear between them (`generate.py`).
fn hips(t: f64) -> Vector3<f64> {
    let key = |k: f64| {
        let t = k * 0.1;
        Vector3::new(0.0, -100.0 * t, 100.0 + 2.0 * (2.0 * std::f64::consts::PI * t).sin())
    };
    let k = (t / 0.1).floor();
    let a = t / 0.1 - k;
    key(k) * (1.0 - a) + key(k + 1.0) * a
}

#[test]
fn an_ascii_7400_z_up_file_with_two_takes() {
    let fbx = open("mixamo_zup_7400_ascii.fbx");
    let info = fbx.info();
    assert_eq!(
        (info.version, info.ascii, info.fps, info.metres_per_unit),
        (7400, true, 30.0, 0.01)
    );
    assert_eq!(info.axes.to_string(), "up +Z, front -Y, right +X");
    assert_eq!(info.world_from_file(), Some(Matrix3::identity()), "Z up is our world");
    assert_eq!(info.application, "retarget generate.py 1");
    let takes: Vec<(&str, usize)> =
        info.takes.iter().map(|t| (t.name.as_str(), t.frames)).collect();
    assert_eq!(takes, [("idle", 31), ("walk", 61)]);
    // The skeleton: the Null armature, 27 bones and the prop; the camera is not in it.
    assert_eq!(info.skeleton.len(), 30);
    assert_eq!(info.skeleton[0].kind, fbx::NodeKind::Null);
    assert!(info.skeleton.iter().all(|n| !n.name.contains("Camera")));
    assert_eq!(info.skeleton[node(&fbx, "mixamorig:LeftUpLeg")].kind, fbx::NodeKind::LimbNode);

    let default = fbx.select_take(None).unwrap();
    assert_eq!((default.index, default.reason.as_str()), (1, "the most motion of 2 takes"));
    assert_eq!(fbx.select_take(Some("idle")).unwrap().index, 0);
    assert_eq!(fbx.select_take(Some("0")).unwrap().index, 0);
    let err = fbx.select_take(Some("run")).unwrap_err().to_string();
    assert!(
        err.ends_with(
            "mixamo_zup_7400_ascii.fbx: unknown take `run`; the file's takes: 0 `idle`, 1 `walk`"
        ),
        "{err}"
    );

    // The hips at keys and between them: linear keys, exactly.
    let times = [0.0, 0.05, 0.1, 0.37, 1.0, 1.999];
    let poses = fbx.poses_at(1, &times).unwrap();
    let h = node(&fbx, "mixamorig:Hips");
    for (k, &t) in times.iter().enumerate() {
        let p = poses.positions[k * poses.num_nodes + h];
        assert!((p - hips(t)).norm() < 1e-9, "t {t}: {p} vs {}", hips(t));
    }
    // The prop: T · Rp · Rpre · R · Rp⁻¹ (FBX's transform, no offsets or scaling pivots),
    // R = Ry(20°) · Rx(30°) (rotation order XYZ), Rpre = Rz(90°), Rp = (0, 5, 0).
    let rot = |axis: Vector3<f64>, deg: f64| {
        Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), deg.to_radians())
    };
    let r = rot(Vector3::z(), 90.0) * rot(Vector3::y(), 20.0) * rot(Vector3::x(), 30.0);
    let pivot = Vector3::new(0.0, 5.0, 0.0);
    let origin = |t: f64| hips(t) + Vector3::new(0.0, 0.0, 20.0) + pivot - r * pivot;
    let tip = |t: f64| origin(t) + r * Vector3::new(10.0, 0.0, 0.0);
    let (root, end) = (node(&fbx, "PropRoot"), node(&fbx, "PropTip"));
    for (k, &t) in times.iter().enumerate() {
        let at = |i: usize| poses.positions[k * poses.num_nodes + i];
        assert!((at(root) - origin(t)).norm() < 1e-9, "prop at {t}: {}", at(root));
        assert!((at(end) - tip(t)).norm() < 1e-9, "prop tip at {t}: {}", at(end));
        let q = poses.rotations[k * poses.num_nodes + root];
        assert!(q.to_rotation_matrix().angle_to(&r) < 1e-9);
    }
}

#[test]
fn the_bvh_is_the_same_motion_in_y_up_axes_too() {
    let fbx = open("mixamo_zup_7400_ascii.fbx");
    let options = fk::FkOptions {
        axes: fk::AxisConvention::ZUp,
        units: fk::UnitChoice::Scale(0.01),
        ..fk::FkOptions::default()
    };
    let (z, report) = fk::human_motion(&fbx.bvh(1).unwrap(), &options).unwrap();
    let humanoid = report.humanoid.unwrap();
    assert_eq!(humanoid.convention, Some("LAFAN1 / Mixamo / HumanIK / Rokoko / Perception Neuron"));
    assert_eq!(humanoid.roles.joint(fk::Role::LeftThigh), Some("mixamorig:LeftUpLeg"));
    assert_eq!(humanoid.rest_pose, fk::RestPose::TPose, "{}", humanoid.rest_reason);
    let y_up = fk::FkOptions { axes: fk::AxisConvention::YUp, ..options };
    let (y, _) = fk::human_motion(&fbx.bvh_y_up(1).unwrap(), &y_up).unwrap();
    let body = z.require_body("mixamorig:Hips").unwrap();
    let mut worst = 0.0f64;
    for f in 0..z.num_frames {
        for b in 0..fbx.info().skeleton.len() {
            worst = worst.max((z.position(f, b) - y.position(f, b)).norm());
        }
        let expected = hips(f as f64 / 30.0) * 0.01;
        assert!((z.position(f, body) - expected).norm() < 1e-9, "frame {f}");
    }
    assert!(worst < 1e-9, "Y-up BVH differs by {worst} m");
}

/// The 6.1 file is the same body and walk in Y-up axes with Biped names: the same world
/// positions once each file's axes are applied.
#[test]
fn an_ascii_6100_file_reads_as_the_same_walk() {
    let six = open("biped_6100_ascii.fbx");
    let seven = open("mixamo_zup_7400_ascii.fbx");
    let info = six.info();
    assert_eq!((info.version, info.takes.len(), info.takes[0].frames), (6100, 1, 31));
    assert_eq!(info.axes.to_string(), "up +Y, front +Z, right +X");
    let times: Vec<f64> = (0..31).map(|k| f64::from(k) / 30.0).collect();
    let (a, b) = (six.poses_at(0, &times).unwrap(), seven.poses_at(1, &times).unwrap());
    let (ma, mb) = (info.world_from_file().unwrap(), seven.info().world_from_file().unwrap());
    let pairs = [
        ("Bip01 Pelvis", "mixamorig:Hips"),
        ("Bip01 L Thigh", "mixamorig:LeftUpLeg"),
        ("Bip01 L Foot", "mixamorig:LeftFoot"),
        ("Bip01 R Hand", "mixamorig:RightHand"),
        ("Bip01 HeadNub", "mixamorig:HeadTop_End"),
    ];
    for (k, _) in times.iter().enumerate() {
        for (p, q) in pairs {
            let pa = ma * a.positions[k * a.num_nodes + node(&six, p)];
            let pb = mb * b.positions[k * b.num_nodes + node(&seven, q)];
            assert!((pa - pb).norm() < 1e-9, "{p} at frame {k}: {pa} vs {pb}");
        }
    }
    let (_, report) = fk::human_motion(&six.bvh(0).unwrap(), &fk::FkOptions::default()).unwrap();
    let humanoid = report.humanoid.unwrap();
    assert_eq!(humanoid.convention, Some("3ds Max Biped"));
    assert_eq!(humanoid.roles.joint(fk::Role::RightShin), Some("Bip01 R Calf"));
}

#[test]
fn chained_local_transforms_equal_ufbxs_scene_evaluation() {
    for (name, take) in [("mixamo_zup_7400_ascii.fbx", 1), ("biped_6100_ascii.fbx", 0)] {
        let fbx = open(name);
        let times = [-0.5, 0.0, 0.33, 1.0, 1.7, 3.0];
        let (a, b) = (
            fbx.poses_at(take, &times).unwrap(),
            fbx.poses_by_scene_evaluation(take, &times).unwrap(),
        );
        for (p, q) in a.positions.iter().zip(&b.positions) {
            assert!((p - q).norm() < 1e-9, "{name}: {p} vs {q}");
        }
        for (p, q) in a.rotations.iter().zip(&b.rotations) {
            assert!(p.angle_to(q) < 1e-9, "{name}");
        }
    }
}

#[test]
fn a_file_without_a_rate_says_which_it_assumed() {
    let fbx = open("default_rate_7400_ascii.fbx");
    let info = fbx.info();
    assert_eq!((info.time_mode, info.fps), (0, 30.0));
    let note = info.fps_note.as_deref().unwrap();
    assert_eq!(note, "TimeMode 0 (default): 30 fps assumed (the FBX SDK's default time mode)");
}

fn error(bytes: &[u8], name: &str) -> String {
    match fbx::Fbx::from_bytes(bytes, name) {
        Ok(file) => match file.select_take(None) {
            Ok(take) => match file.bvh(take.index) {
                Ok(_) => String::new(),
                Err(e) => e.to_string(),
            },
            Err(e) => e.to_string(),
        },
        Err(e) => e.to_string(),
    }
}

#[test]
fn bad_input_is_an_error_naming_the_file_and_the_take() {
    let read = |name: &str| std::fs::read(data(name)).unwrap();
    let cases = [
        (
            read("no_skeleton_7400_ascii.fbx"),
            "no skeleton: the file has no LimbNode/Root/Null hierarchy (models: 1 Camera, 1 Mesh)",
        ),
        (
            read("no_animation_7400_ascii.fbx"),
            "no animation: the file has no take (AnimationStack)",
        ),
        (read("empty_take_7400_ascii.fbx"), "take `still` has no keys: nothing moves in it"),
        (
            b"Kaydara FBX Binary  \x00\x1a\x00\xe8\x1c\x00\x00garbage".to_vec(),
            "not a readable FBX file",
        ),
        (b"not an fbx file at all".to_vec(), "not a readable FBX file"),
        (Vec::new(), "not a readable FBX file"),
    ];
    for (bytes, says) in &cases {
        let message = error(bytes, "clip.fbx");
        assert!(message.starts_with("clip.fbx: "), "{message}");
        assert!(message.contains(says), "{message} (expected: {says})");
    }
    let empty = open("empty_take_7400_ascii.fbx");
    let err = empty.bvh(0).unwrap_err().to_string();
    assert!(err.contains("empty_take_7400_ascii.fbx: take `still` has no keys"), "{err}");
    let err = fbx::Fbx::from_path(&data("missing.fbx")).unwrap_err().to_string();
    assert!(err.contains("missing.fbx: cannot read file"), "{err}");
    // Every prefix of a good file: an error or a file, never a panic.
    let good = read("mixamo_zup_7400_ascii.fbx");
    for cut in (0..good.len()).step_by(97) {
        let message = error(&good[..cut], "cut.fbx");
        assert!(message.is_empty() || message.starts_with("cut.fbx: "), "{message}");
    }
}

/// Truncated and corrupted copies of the shared binary files (7.4, 7.5, 7.7): errors that
/// name the file, never a panic.
#[test]
fn truncated_and_corrupted_binary_files_are_errors() {
    let Some(dir) = shared::shared_file("data/fbx") else { return };
    for stem in [
        "ozz_pab_walk_motionbuilder2015",
        "ufbx_kenney_character_maya2023",
        "xna_dude_walk_fbxsdk2017",
    ] {
        let bytes = std::fs::read(dir.join(format!("{stem}.fbx"))).unwrap();
        for share in [0.0, 0.001, 0.1, 0.5, 0.9, 0.999] {
            let cut = (bytes.len() as f64 * share) as usize;
            let message = error(&bytes[..cut], "cut.fbx");
            assert!(message.starts_with("cut.fbx: "), "{stem} cut at {cut}: {message:?}");
        }
        let mut corrupt = bytes.clone();
        for k in (27..corrupt.len()).step_by(4099) {
            corrupt[k] ^= 0x5a;
        }
        let message = error(&corrupt, "corrupt.fbx");
        assert!(message.is_empty() || message.starts_with("corrupt.fbx: "), "{stem}: {message}");
    }
}
