//! End to end: `retarget fbx info | bvh | map`, `retarget --fbx`, `batch` and `view` on FBX
//! files (our fixtures in `crates/fbx/tests/data`, and the shared ones).

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../fbx/tests/data").join(name)
}

fn retarget(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_retarget")).args(args).output().expect("run retarget")
}

fn run(args: &[&str]) -> (bool, String, String) {
    let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_ref()).collect();
    let out = retarget(&args);
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    (out.status.success(), text(&out.stdout), text(&out.stderr))
}

fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cli-fbx-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn info_lists_takes_skeleton_units_axes_and_exporter() {
    let file = fixture("mixamo_zup_7400_ascii.fbx");
    let (ok, out, err) = run(&["fbx", "info", path(&file)]);
    assert!(ok, "{err}");
    for line in [
        "format:     FBX 7400 ASCII; creator: retarget tests/data/generate.py; application: retarget generate.py 1\n",
        "axes:       up +Z, front -Y, right +X (Z up, as ours)\n",
        "units:      UnitScaleFactor 1 (0.01 m per file unit)\n",
        "frame rate: 30 fps (TimeMode 6)\n",
        "takes:      2 (default: `walk`, the most motion of 2 takes)\n",
        "  1 `walk`: 0.0000 s .. 2.0000 s, 61 frames (from frame 0); keys 0.0000 s .. 2.0000 s on 11 curves\n",
        "skeleton:   30 nodes (27 LimbNode, 0 Root, 3 Null); roots: Armature\n",
        "      mixamorig:Spine (LimbNode)\n",
    ] {
        assert!(out.contains(line), "{line:?} in\n{out}");
    }
    let (ok, out, _) = run(&["fbx", "info", path(&fixture("default_rate_7400_ascii.fbx"))]);
    assert!(ok);
    assert!(out.contains("frame rate: TimeMode 0 (default): 30 fps assumed"), "{out}");
}

/// World positions (m, Z up) of every joint of a take, through `fk` with the file's axes
/// and its declared unit forced.
fn fbx_positions(file: &Path, take: usize) -> (fk::HumanMotion, Vec<String>) {
    let fbx = fbx::Fbx::from_path(file).unwrap();
    let info = fbx.info();
    let options = fk::FkOptions {
        axes: fk::AxisConvention::from_matrix(&info.world_from_file().unwrap()).unwrap(),
        units: fk::UnitChoice::Scale(info.metres_per_unit),
        ..fk::FkOptions::default()
    };
    let mut bvh = fbx.bvh(take).unwrap();
    let (motion, _) = fk::human_motion(&bvh, &options).unwrap();
    fbx::bvh_safe_names(&mut bvh);
    (motion, bvh.skeleton.joints.iter().map(|j| j.name.clone()).collect())
}

/// Issue 33's "Converts": `retarget fbx bvh` re-read by our BVH reader gives the same joint
/// positions to 1e-6 m (Y up, the file's unit).
fn converts(file: &Path, take: Option<&str>, index: usize, dir: &Path) -> f64 {
    let out_path = dir.join("take.bvh");
    let mut args = vec!["fbx", "bvh", path(file), "-o", path(&out_path)];
    if let Some(take) = take {
        args.extend(["--take", take]);
    }
    let (ok, _, err) = run(&args);
    assert!(ok, "{err}");
    assert!(err.contains("Y up"), "{err}");
    let reread = bvh::from_path(&out_path).unwrap();
    let metres = fbx::Fbx::from_path(file).unwrap().info().metres_per_unit;
    let options = fk::FkOptions {
        axes: fk::AxisConvention::YUp,
        units: fk::UnitChoice::Scale(metres),
        ..fk::FkOptions::default()
    };
    let (again, _) = fk::human_motion(&reread, &options).unwrap();
    let (motion, names) = fbx_positions(file, index);
    assert_eq!(again.num_frames, motion.num_frames);
    let mut worst = 0.0f64;
    for (b, name) in names.iter().enumerate() {
        let c = again.require_body(name).unwrap();
        for f in 0..motion.num_frames {
            worst = worst.max((again.position(f, c) - motion.position(f, b)).norm());
        }
    }
    worst
}

#[test]
fn bvh_of_a_take_rereads_to_the_same_positions() {
    let dir = temp_dir("bvh");
    for (name, take, index) in [
        ("mixamo_zup_7400_ascii.fbx", Some("idle"), 0),
        ("mixamo_zup_7400_ascii.fbx", None, 1),
        ("biped_6100_ascii.fbx", Some("0"), 0),
    ] {
        let worst = converts(&fixture(name), take, index, &dir);
        assert!(worst < 1e-6, "{name}: {worst} m");
    }
    let Some(shared) = shared::shared_file("data/fbx") else { return };
    for stem in [
        "ozz_pab_walk_motionbuilder2015",
        "ufbx_barbarian_idle_blender293",
        "ufbx_kenney_character_maya2023",
        "xna_dude_walk_fbxsdk2017",
    ] {
        let worst = converts(&shared.join(format!("{stem}.fbx")), None, 0, &dir);
        println!("{stem}: written BVH re-read to {worst:.1e} m");
        assert!(worst < 1e-6, "{stem}: {worst} m");
    }
}

#[test]
fn retarget_a_take_by_name_or_the_one_with_the_most_motion() {
    let dir = temp_dir("main");
    let file = fixture("mixamo_zup_7400_ascii.fbx");
    let npz = dir.join("idle.npz");
    let (ok, out, err) =
        run(&["--fbx", path(&file), "--take", "idle", "--robot", "unitree_g1", "-o", path(&npz)]);
    assert!(ok, "{err}");
    assert!(out.contains("inferred: take `idle` (asked for), 31 frames at 30 fps"), "{out}");
    assert_eq!(retarget::writers::read_motion_npz(&npz).unwrap().num_frames(), 31);
    let npz = dir.join("walk.npz");
    let (ok, out, err) =
        run(&["--fbx", path(&file), "--robot", "booster_t1_29dof", "--gmr", "-o", path(&npz)]);
    assert!(ok, "{err}");
    assert!(out.contains("take `walk` (the most motion of 2 takes), 61 frames"), "{out}");
    assert!(out.contains("roles by LAFAN1 / Mixamo"), "{out}");
    assert_eq!(retarget::writers::read_motion_npz(&npz).unwrap().num_frames(), 61);
}

#[test]
fn bad_fbx_input_is_a_clear_error() {
    let cases = [
        ("no_animation_7400_ascii.fbx", None, "no_animation_7400_ascii.fbx: no animation"),
        ("no_skeleton_7400_ascii.fbx", None, "no_skeleton_7400_ascii.fbx: no skeleton"),
        ("empty_take_7400_ascii.fbx", None, "empty_take_7400_ascii.fbx: take `still` has no keys"),
        (
            "mixamo_zup_7400_ascii.fbx",
            Some("run"),
            "unknown take `run`; the file's takes: 0 `idle`, 1 `walk`",
        ),
        ("missing.fbx", None, "missing.fbx: cannot read file"),
    ];
    for (name, take, says) in cases {
        let file = fixture(name);
        let mut args =
            vec!["--fbx", path(&file), "--robot", "unitree_g1", "-o", "/nonexistent/x.npz"];
        if let Some(take) = take {
            args.extend(["--take", take]);
        }
        let (ok, _, err) = run(&args);
        assert!(!ok && err.contains(says), "{name}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        let mut args = vec!["fbx", "bvh", path(&file)];
        if let Some(take) = take {
            args.extend(["--take", take]);
        }
        let (ok, _, err) = run(&args);
        assert!(!ok && err.contains(says), "fbx bvh {name}: {err}");
    }
    let (ok, _, err) = run(&["--bvh", "a.bvh", "--fbx", "b.fbx", "--robot", "unitree_g1"]);
    assert!(!ok && err.contains("cannot be used with"), "{err}");
}

#[test]
fn map_shows_the_roles_of_an_fbx_rig() {
    let (ok, out, err) = run(&["fbx", "map", path(&fixture("biped_6100_ascii.fbx"))]);
    assert!(ok, "{err}");
    assert!(
        out.contains("take:       take `Take 001` (the only take), 31 frames at 30 fps"),
        "{out}"
    );
    assert!(out.contains("names: 3ds Max Biped"), "{out}");
    assert!(out.contains("left_thigh       Bip01 L Thigh"), "{out}");
    let Some(file) = shared::shared_file("data/fbx/ufbx_barbarian_idle_blender293.fbx") else {
        return;
    };
    let (ok, out, err) = run(&["fbx", "map", path(&file)]);
    assert!(ok, "{err}");
    assert!(out.contains("one bone per limb: straight bras droit.elbow"), "{out}");
    assert!(out.contains("names: French (Blender rigs)"), "{out}");
    assert!(out.contains("left_shin        jambe gauche.knee"), "{out}");
}

#[test]
fn batch_and_view_take_fbx_files() {
    let dir = temp_dir("batch");
    let input = dir.join("in");
    std::fs::create_dir_all(&input).unwrap();
    std::fs::copy(fixture("mixamo_zup_7400_ascii.fbx"), input.join("walk.fbx")).unwrap();
    std::fs::copy(fixture("no_animation_7400_ascii.fbx"), input.join("still.FBX")).unwrap();
    let output = dir.join("out");
    let (ok, out, err) =
        run(&["batch", path(&input), "--robot", "unitree_g1", "-o", path(&output), "--jobs", "1"]);
    assert!(!ok, "one clip fails: {out}{err}");
    assert!(out.contains("clips 2  converted 1  skipped 0  failed 1"), "{out}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(output.join("summary.json")).unwrap())
            .unwrap();
    let clips = summary["clips"].as_array().unwrap();
    let walk = clips.iter().find(|c| c["input"] == "walk.fbx").unwrap();
    assert!(walk["inferred"]
        .as_str()
        .unwrap()
        .starts_with("take `walk` (the most motion of 2 takes)"));
    let still = clips.iter().find(|c| c["input"] == "still.FBX").unwrap();
    assert!(still["error"].as_str().unwrap().contains("no animation"), "{still}");
    assert!(output.join("walk.npz").is_file());

    let html = dir.join("walk.html");
    let (ok, out, err) = run(&["view", path(&input.join("walk.fbx")), "-o", path(&html)]);
    assert!(ok, "{err}");
    assert!(out.contains("61 frames"), "{out}");
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(page.contains("mixamorig:LeftUpLeg") && page.contains("take `walk`"));
    let (ok, _, err) = run(&[
        "view",
        path(&output.join("walk.npz")),
        "--source",
        path(&input.join("walk.fbx")),
        "-o",
        path(&dir.join("robot.html")),
    ]);
    assert!(ok, "{err}");
}
