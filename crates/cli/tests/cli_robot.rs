//! `retarget robots`, `retarget robot info` and (feature `mujoco`) `retarget robot check`.

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn retarget(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_retarget")).args(args).output().expect("runs retarget")
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The robots folders with a `<key>/<key>.xml` (what the binary ships).
fn repo_robot_keys() -> Vec<String> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots");
    let mut keys: Vec<String> = std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .filter_map(Result::ok)
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|k| {
                    Path::new(env!("CARGO_MANIFEST_DIR"))
                        .join(format!("../../robots/{k}/{k}.xml"))
                        .is_file()
                })
                .collect()
        })
        .unwrap_or_default();
    keys.sort();
    keys
}

fn features_xml() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../mjcf/tests/data/features/features.xml")
}

#[test]
fn robots_lists_shipped_models_with_sizes() {
    let out = retarget(&["robots"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = stdout(&out);
    assert!(text.starts_with("robot "), "{text}");
    let rows: Vec<&str> = text.lines().skip(1).take_while(|l| !l.is_empty()).collect();
    let keys: Vec<&str> = rows.iter().filter_map(|r| r.split_whitespace().next()).collect();
    for key in &keys {
        assert!(
            repo_robot_keys().iter().any(|k| k == key),
            "{key} listed but robots/{key}/{key}.xml missing"
        );
    }
    for row in rows {
        let cols: Vec<&str> = row.split_whitespace().collect();
        let model = mjcf::Model::from_file(
            &Path::new(env!("CARGO_MANIFEST_DIR"))
                .join(format!("../../robots/{0}/{0}.xml", cols[0])),
        )
        .expect("shipped model compiles");
        assert_eq!(cols[1].parse::<usize>().unwrap(), model.nq, "{row}");
        assert_eq!(cols[2].parse::<usize>().unwrap(), model.nv, "{row}");
        assert_eq!(cols[4].parse::<usize>().unwrap(), model.bodies.len(), "{row}");
    }
}

#[test]
fn robot_info_prints_joints_and_bodies() {
    let path = features_xml();
    let out = retarget(&["robot", "info", path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = stdout(&out);
    let model = mjcf::Model::from_file(&path).unwrap();
    assert!(text.contains(&format!("nq {}  nv {}", model.nq, model.nv)), "{text}");
    for joint in &model.joints {
        let line = text
            .lines()
            .find(|l| l.split_whitespace().nth(1) == Some(joint.name.as_str()))
            .expect("joint line");
        assert!(line.contains(joint.kind.as_str()), "{line}");
        assert_eq!(line.contains("unlimited"), joint.range.is_none(), "{line}");
    }
    for body in &model.bodies[1..] {
        let parent = &model.bodies[body.parent].name;
        assert!(
            text.lines()
                .any(|l| l.split_whitespace().skip(1).eq([body.name.as_str(), parent.as_str()])),
            "{}",
            body.name
        );
    }
    for key in repo_robot_keys() {
        let out = retarget(&["robot", "info", &key]);
        assert!(out.status.success(), "{key}: {}", String::from_utf8_lossy(&out.stderr));
    }
}

/// `robot info` counts the self-collision pairs and, for the T1 with its `<exclude>`s taken
/// out, names the forearm pairs that they leave out as touching over most of their ranges.
#[test]
fn robot_info_hints_at_chain_pairs_that_touch_over_their_ranges() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../robots/booster_t1_29dof/booster_t1_29dof.xml");
    let xml = std::fs::read_to_string(&path).unwrap();
    let dir = std::env::temp_dir().join(format!("retarget-chain-hint-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bare = dir.join("t1_no_excludes.xml");
    let stripped: Vec<&str> = xml.lines().filter(|l| !l.contains("<exclude")).collect();
    std::fs::write(&bare, stripped.join("\n")).unwrap();
    let hinted = |p: &Path| {
        let out = retarget(&["robot", "info", p.to_str().unwrap()]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let text = stdout(&out);
        assert!(text.contains("self-collision: "), "{text}");
        text.lines().any(|l| l.contains("AL4_col / AL6_col") && l.contains("2 joints between"))
    };
    assert!(hinted(&bare), "no hint for the T1's forearm pair without its <exclude>");
    assert!(!hinted(&path), "a hint for a pair the shipped T1 excludes");
    std::fs::remove_dir_all(&dir).ok();
}

/// `robot info` on the shared G1 URDF: a free root and 29 hinges with the file's ranges and
/// speed limits.
#[test]
fn robot_info_reads_a_urdf() {
    let Some(path) =
        shared::shared_file("reference/robots/unitree_g1/g1_custom_collision_29dof.urdf")
    else {
        return;
    };
    let out = retarget(&["robot", "info", path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = stdout(&out);
    assert!(text.contains("nq 36  nv 35  joint dofs 29  bodies 31"), "{text}");
    let hinges: Vec<&str> =
        text.lines().filter(|l| l.split_whitespace().nth(2) == Some("hinge")).collect();
    assert_eq!(hinges.len(), 29, "{text}");
    assert!(hinges.iter().all(|l| l.contains("] rad") && l.contains("rad/s")), "{text}");
    let knee = hinges.iter().find(|l| l.contains(" left_knee_joint ")).expect("knee");
    assert!(knee.contains("[-0.0873, 2.8798] rad") && knee.contains("speed 20 rad/s"), "{knee}");
    assert!(text.contains("pelvis_free_joint                free"), "{text}");
}

/// GMR's robot keys whose models we do not ship: listed with the reason, and `--robot KEY`
/// fails naming the key, the upstream file and how to pass it.
#[test]
fn gmrs_robots_not_shipped_are_listed_and_refused_with_where_to_get_them() {
    let text = stdout(&retarget(&["robots"]));
    let (shipped, not_shipped) = text.split_once("\n\n").expect("two sections");
    assert_eq!(shipped.lines().count() - 1, repo_robot_keys().len(), "{text}");
    let rows: Vec<&str> = not_shipped.lines().skip(1).collect();
    assert_eq!(rows.len() + repo_robot_keys().len(), 18, "GMR's 18 keys: {text}");
    let bvh = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/samples/lafan1_walk.bvh");
    for row in rows {
        let key = row.split_whitespace().next().unwrap();
        assert!(row.contains("YanjieZe/GMR assets/"), "{row}");
        let out =
            retarget(&["--bvh", bvh.to_str().unwrap(), "--robot", key, "-o", "/nonexistent/x.npz"]);
        assert_eq!(out.status.code(), Some(1), "{key}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains(&format!(
                "robot \"{key}\" is one of GMR's robots, but its model is not shipped"
            )) && err.contains("https://github.com/YanjieZe/GMR")
                && err.contains("--robot path/to/"),
            "{err}"
        );
        let out = retarget(&["robot", "info", key]);
        assert!(String::from_utf8_lossy(&out.stderr).contains("--robot path/to/"), "{key}");
    }
}

#[test]
fn unknown_robot_fails_listing_shipped_keys() {
    let out = retarget(&["robot", "info", "no_such_robot"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("unknown robot \"no_such_robot\""), "{err}");
    for key in repo_robot_keys() {
        assert!(err.contains(&key), "{err}");
    }
}

#[test]
fn bad_mjcf_reports_file_line_and_column() {
    let dir = std::env::temp_dir().join(format!("cli-robot-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.xml");
    std::fs::write(&path, "<mujoco>\n<worldbody><body pos=\"1\"/></worldbody></mujoco>").unwrap();
    let out = retarget(&["robot", "info", path.to_str().unwrap()]);
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(&format!("{}:2:18: attribute pos=\"1\"", path.display())), "{err}");
}

#[cfg(feature = "mujoco")]
#[test]
fn robot_check_agrees_with_mujoco() {
    let path = features_xml();
    let mut targets: Vec<String> = repo_robot_keys();
    targets.push(path.to_str().unwrap().to_owned());
    let urdf = Path::new(env!("CARGO_MANIFEST_DIR")).join("../mjcf/tests/data/urdf/features.urdf");
    targets.push(urdf.to_str().unwrap().to_owned());
    for target in targets {
        let out = retarget(&["robot", "check", &target, "--configs", "20"]);
        let text = stdout(&out);
        assert!(out.status.success(), "{target}: {text}{}", String::from_utf8_lossy(&out.stderr));
        assert!(text.contains("structure: identical") && text.contains("PASS"), "{target}: {text}");
    }
}

#[cfg(not(feature = "mujoco"))]
#[test]
fn robot_check_needs_the_mujoco_feature() {
    let out = retarget(&["robot", "check", "unitree_g1"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("mujoco"));
}
