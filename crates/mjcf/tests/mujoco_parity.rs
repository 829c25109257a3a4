//! Our compiled models and kinematics against MuJoCo 3.17.0 itself (feature `mujoco`, needs
//! `scripts/fetch-mujoco`): every reference MJCF and every model in the repo's `robots/`.

#![cfg(feature = "mujoco")]

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::{Path, PathBuf};

use mjcf::mujoco_check::{check_file, CheckOptions, CollisionTolerances};
use mjcf::Model;

const TOLERANCE: f64 = 1e-9;

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The MJCF of each reference robot, as listed in `reference/robots/index.json`.
fn reference_models(shared: &Path) -> Vec<(String, PathBuf)> {
    let dir = shared.join("reference/robots");
    let index: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("index.json")).expect("index.json"))
            .expect("index.json parses");
    let mut out: Vec<(String, PathBuf)> = index
        .as_object()
        .expect("index.json is an object")
        .iter()
        .map(|(key, entry)| {
            (key.clone(), shared.join("reference").join(entry["file"].as_str().expect("file")))
        })
        .collect();
    out.sort();
    out
}

/// `robots/<key>/<key>.xml` of the repo, for the folders that exist.
fn repo_models() -> Vec<(String, PathBuf)> {
    let Ok(entries) = std::fs::read_dir(repo_root().join("robots")) else { return Vec::new() };
    let mut out: Vec<(String, PathBuf)> = entries
        .filter_map(Result::ok)
        .filter(|e| e.path().is_dir())
        .filter_map(|e| {
            let key = e.file_name().to_string_lossy().into_owned();
            let xml = e.path().join(format!("{key}.xml"));
            xml.is_file().then_some((key, xml))
        })
        .collect();
    out.sort();
    out
}

fn check(label: &str, path: &Path) -> Result<(), String> {
    let model = Model::from_file(path).map_err(|e| format!("{label}: {e}"))?;
    let report =
        check_file(&model, path, CheckOptions::default()).map_err(|e| format!("{label}: {e}"))?;
    eprintln!("{label}: max deviation {:.2e}\n{report}", report.max_deviation());
    if report.passes(TOLERANCE) {
        Ok(())
    } else {
        Err(format!("{label} ({}): differs from mujoco\n{report}", path.display()))
    }
}

#[test]
fn reference_models_match_mujoco() {
    let Some(shared) = shared::shared_dir() else { return };
    let models = reference_models(&shared);
    assert!(models.len() >= 18, "index.json lists {} robots", models.len());
    let failures: Vec<String> =
        models.iter().filter_map(|(key, path)| check(key, path).err()).collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn feature_model_matches_mujoco() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/features/features.xml");
    check("features.xml", &path).unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn repo_models_match_mujoco() {
    let failures: Vec<String> = repo_models()
        .iter()
        .filter_map(|(key, path)| check(&format!("robots/{key}"), path).err())
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Tolerances of the collision check against `mj_geomDistance`, pairs closer than 5 cm, both
/// computed on MuJoCo's geom poses:
/// - distances and normals 1e-9 where MuJoCo and we both use closed forms or exact
///   primitive colliders (sphere/capsule pairs; sphere–box, capsule–box, sphere–cylinder when
///   separated): only rounding differs (measured 1e-15);
/// - distances 1e-4 m and normals 0.1 for pairs both sides hand to GJK/EPA: MuJoCo's native
///   CCD stops at `ccd_tolerance` 1e-6, and in penetration its EPA, like parry's, approximates
///   curved surfaces (cylinder rims, ellipsoids) by polytopes, which moves the depth by up to
///   ~1e-5 (measured 2.4e-5) and the normal by about the square root of that over the rim
///   radius (measured 5.4e-2); our depth is checked against a brute-force minimum
///   translation in the unit test `penetration_depth_is_the_minimum_translation`;
/// - witness points within 1e-6 m of their geoms' surfaces (measured 1e-9); witness points of
///   parallel faces are not unique, so their difference from MuJoCo's is reported, not checked;
/// - lowest points and bounding radii 1e-12 m.
const TOLERANCES: CollisionTolerances = CollisionTolerances {
    exact_distance: 1e-9,
    exact_normal: 1e-9,
    gjk_distance: 1e-4,
    gjk_normal: 0.1,
    surface: 1e-6,
    lowest: 1e-12,
};

fn check_collision_of(label: &str, path: &Path) -> Result<(), String> {
    let model = Model::from_file(path).map_err(|e| format!("{label}: {e}"))?;
    let report = mjcf::mujoco_check::check_collision(&model, path, CheckOptions::default())
        .map_err(|e| format!("{label}: {e}"))?;
    eprintln!("{label}:\n{report}");
    if report.passes(&TOLERANCES) {
        Ok(())
    } else {
        Err(format!(
            "{label} ({}): collision geometry differs from mujoco\n{report}",
            path.display()
        ))
    }
}

#[test]
fn collision_geometry_matches_mujoco() {
    let mut models: Vec<(String, PathBuf)> =
        repo_models().into_iter().map(|(k, p)| (format!("robots/{k}"), p)).collect();
    assert!(models.len() >= 6, "robots/ has {} models", models.len());
    if let Some(shared) = shared::shared_dir() {
        models.extend(reference_models(&shared));
    }
    let failures: Vec<String> =
        models.iter().filter_map(|(key, path)| check_collision_of(key, path).err()).collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
