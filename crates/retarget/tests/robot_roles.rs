//! The robot recogniser on every shipped and reference robot, and on small robots we write.

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::{Path, PathBuf};

use retarget::RobotRoles;

/// Every reference robot model (`reference/robots/<key>/*.xml` and the G1 URDF).
fn reference_models() -> Vec<PathBuf> {
    let Some(dir) = shared::shared_file("reference/robots") else { return Vec::new() };
    let mut out = Vec::new();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let d = entry.unwrap().path();
        if !d.is_dir() {
            continue;
        }
        for f in std::fs::read_dir(&d).unwrap() {
            let f = f.unwrap().path();
            if matches!(f.extension().and_then(|e| e.to_str()), Some("xml" | "urdf")) {
                out.push(f);
            }
        }
    }
    out.sort();
    out
}

fn load(path: &Path) -> mjcf::Model {
    mjcf::Model::from_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn dump() {
    for path in reference_models() {
        let model = load(&path);
        match RobotRoles::recognise(&model) {
            Ok(r) => println!("== {}\n{}", path.display(), r.describe(&model)),
            Err(e) => println!("== {}\nERROR {e}", path.display()),
        }
    }
}
