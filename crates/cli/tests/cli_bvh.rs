//! End to end: `retarget bvh info | json | cat` on the `bvh` crate's fixtures.

use std::path::PathBuf;
use std::process::{Command, Output};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../bvh/tests/data").join(name)
}

fn retarget(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_retarget")).args(args).output().expect("run retarget")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cli-bvh-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn info_prints_the_summary() {
    let file = fixture("minimal.bvh");
    let out = retarget(&["bvh".as_ref(), "info".as_ref(), file.as_os_str()]);
    let stdout = text(&out.stdout);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(stdout.contains(&format!("file:            {}\n", file.display())), "{stdout}");
    assert!(stdout.contains("frames:          2\n"), "{stdout}");
    assert!(stdout.contains("(30.00 fps)"), "{stdout}");
    assert!(
        stdout.contains("joints:          2 (ROOT + JOINT; 1 End Sites not counted)"),
        "{stdout}"
    );
    assert!(stdout.contains("\n  Hips [pos XYZ rot ZYX]\n    Spine [rot ZXY]\n"), "{stdout}");
}

#[test]
fn json_to_a_file_is_valid_and_complete() {
    let dir = temp_dir("json");
    let out_path = dir.join("mixed.json");
    let file = fixture("good_mixed_crlf.bvh");
    let out = retarget(&[
        "bvh".as_ref(),
        "json".as_ref(),
        file.as_os_str(),
        "-o".as_ref(),
        out_path.as_os_str(),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(out.stdout.is_empty());
    let leftovers: Vec<_> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(leftovers, ["mixed.json"], "no temporary file is left behind");
    let check = "import json,sys; d=json.load(open(sys.argv[1])); \
                 r=d['joints'][0]; print(d['frames'], r['name'], len(r['motion']), r['children'][0]['name'])";
    let py = Command::new("python3").args(["-c", check]).arg(&out_path).output().expect("python3");
    assert!(py.status.success(), "{}", text(&py.stderr));
    assert_eq!(text(&py.stdout).trim(), "3 mixamorig:Hips 3 Bip01 L Thigh.001 (copy)");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn cat_round_trips_through_stdout_and_files() {
    let file = fixture("good_mixed_crlf.bvh");
    let original = bvh::from_path(&file).unwrap();
    let out = retarget(&["bvh".as_ref(), "cat".as_ref(), file.as_os_str()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(bvh::parse(&out.stdout).unwrap(), original);

    let dir = temp_dir("cat");
    let copy = dir.join("copy.bvh");
    let out = retarget(&[
        "bvh".as_ref(),
        "cat".as_ref(),
        file.as_os_str(),
        "-o".as_ref(),
        copy.as_os_str(),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(std::fs::read(&copy).unwrap(), out_of(&original));
    std::fs::remove_dir_all(&dir).unwrap();
}

fn out_of(bvh: &bvh::Bvh) -> Vec<u8> {
    let mut bytes = Vec::new();
    bvh::write(bvh, &mut bytes).unwrap();
    bytes
}

#[test]
fn a_bad_file_fails_with_its_name_and_position() {
    let file = fixture("bad_short_row.bvh");
    let dir = temp_dir("bad");
    let target = dir.join("never.json");
    let out = retarget(&[
        "bvh".as_ref(),
        "json".as_ref(),
        file.as_os_str(),
        "-o".as_ref(),
        target.as_os_str(),
    ]);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    let expected = format!("error: {}:20:17: frame 2 has 8 values, expected 9", file.display());
    assert_eq!(stderr.trim(), expected);
    assert!(std::fs::read_dir(&dir).unwrap().next().is_none(), "nothing written");
    std::fs::remove_dir_all(&dir).unwrap();

    let missing = fixture("no_such_file.bvh");
    let out = retarget(&["bvh".as_ref(), "info".as_ref(), missing.as_os_str()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains(&missing.display().to_string()));
}

#[test]
fn usage_errors_exit_2() {
    let out = retarget(&["bvh".as_ref(), "info".as_ref()]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    let out = retarget(&["bvh".as_ref(), "json".as_ref(), "a.bvh".as_ref(), "--bogus".as_ref()]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn warnings_go_to_stderr_one_line_each_prefixed_by_the_file() {
    let file = fixture("quirk_frames_one_more_than_rows.bvh");
    let out = retarget(&["bvh".as_ref(), "info".as_ref(), file.as_os_str()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(
        text(&out.stderr),
        format!(
            "{}:17:9: warning: `Frames:` declares 3 frames but the file has 2; using the 2 \
             present\n",
            file.display()
        )
    );
    assert!(text(&out.stdout).contains("frames:          2\n"));
    // `bvh cat` writes the rows present, so its output parses without the warning.
    let out = retarget(&["bvh".as_ref(), "cat".as_ref(), file.as_os_str()]);
    assert_eq!(text(&out.stderr).lines().count(), 1);
    let (_, warnings) = bvh::parse_with_warnings(&out.stdout).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
}

fn skeleton(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../fk/tests/data/skeletons").join(name)
}

#[test]
fn map_prints_roles_conventions_and_rules() {
    let file = skeleton("biped_zup_inches.bvh");
    let out = retarget(&["bvh".as_ref(), "map".as_ref(), file.as_os_str()]);
    let stdout = text(&out.stdout);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(stdout.contains("skeleton:   21 roles; names: 3ds Max Biped\n"), "{stdout}");
    assert!(stdout.contains("up axis:    +Z ("), "{stdout}");
    assert!(stdout.contains("unit:       0.0254 m per file unit (inches"), "{stdout}");
    assert!(stdout.contains("rest pose:  arms down"), "{stdout}");
    let row = stdout.lines().find(|l| l.starts_with("left_shin ")).unwrap();
    assert!(row.contains("Bip01 L Calf") && row.contains("name (3ds Max Biped)"), "{row}");
}

/// A SOMA take (BONES-SEED): `LeftLeg` is the thigh and `LeftShin` the knee, by name.
#[test]
fn map_of_a_soma_take_names_leftleg_the_thigh() {
    let file = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../fk/tests/data/soma/soma_walk_excerpt.bvh");
    let out = retarget(&["bvh".as_ref(), "map".as_ref(), file.as_os_str()]);
    let stdout = text(&out.stdout);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(stdout.contains("names: SOMA (NVIDIA soma-retargeter, BONES-SEED)\n"), "{stdout}");
    assert!(stdout.contains("unit:       0.01 m per file unit (centimetres"), "{stdout}");
    assert!(stdout.contains("up axis:    +Y ("), "{stdout}");
    for (role, joint) in [("left_thigh", "LeftLeg"), ("left_shin", "LeftShin")] {
        let row = stdout.lines().find(|l| l.starts_with(&format!("{role} "))).unwrap();
        assert!(
            row.split_whitespace().nth(1) == Some(joint) && row.contains("name (SOMA"),
            "{row}"
        );
    }
}

#[test]
fn map_overrides_roles_from_json_and_reports_bad_maps() {
    let dir = temp_dir("map");
    let map = dir.join("map.json");
    std::fs::write(&map, r#"{"spine": "joint6", "left_hand": "joint16_End"}"#).unwrap();
    let file = skeleton("unnamed_joints.bvh");
    let args = |m: &std::path::Path| {
        retarget(&[
            "bvh".as_ref(),
            "map".as_ref(),
            file.as_os_str(),
            "--map".as_ref(),
            m.as_os_str(),
        ])
    };
    let out = args(&map);
    let stdout = text(&out.stdout);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(stdout.contains("names: none recognised (hierarchy alone)"), "{stdout}");
    let row = |role: &str| stdout.lines().find(|l| l.starts_with(role)).unwrap().to_owned();
    assert!(row("spine ").contains("joint6") && row("spine ").ends_with("given"), "{stdout}");
    assert!(row("left_hand ").contains("joint16_End"), "{stdout}");
    assert!(row("right_hand ").contains("joint12") && row("right_hand ").contains("hierarchy"));

    std::fs::write(&map, r#"{"left_wing": "joint3"}"#).unwrap();
    let out = args(&map);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("unknown role `left_wing`; roles: pelvis, spine"),
        "{}",
        text(&out.stderr)
    );
    std::fs::write(&map, r#"{"head": "Skull"}"#).unwrap();
    let out = args(&map);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("role head is given as joint `Skull`"),
        "{}",
        text(&out.stderr)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn map_of_an_unrecognisable_skeleton_says_what_is_missing() {
    let file = skeleton("unrecognisable_chain.bvh");
    let out = retarget(&["bvh".as_ref(), "map".as_ref(), file.as_os_str()]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = text(&out.stderr);
    assert!(stderr.contains("not recognised as a humanoid skeleton"), "{stderr}");
    assert!(stderr.contains("left_thigh: a joint named e.g. LeftUpLeg"), "{stderr}");
}
