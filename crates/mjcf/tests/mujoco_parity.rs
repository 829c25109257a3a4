//! Our compiled models and kinematics against MuJoCo 3.17.0 itself (feature `mujoco`, needs
//! `scripts/fetch-mujoco`): every reference MJCF and every model in the repo's `robots/`, and
//! URDFs (ours in `tests/data/urdf`, the shared G1) against MuJoCo's own URDF import. Every
//! model's inertials are compared too, and every model here has some: a check cannot pass by
//! comparing none.

#![cfg(feature = "mujoco")]

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::{Path, PathBuf};

use mjcf::mujoco_check::{
    check_file, check_urdf_file, CheckOptions, CollisionTolerances, Report, INERTIAL_TOLERANCE,
};
use mjcf::{Model, UrdfBase, UrdfOptions};

const TOLERANCE: f64 = 1e-9;

/// The check's own mismatch threshold for inertials is the tolerance of these tests.
#[test]
fn inertial_tolerance_is_the_tests_tolerance() {
    assert_eq!(INERTIAL_TOLERANCE, TOLERANCE);
}

/// Within the tolerance, and with inertials compared.
fn passes(report: &Report) -> bool {
    report.passes(TOLERANCE) && report.inertials > 0
}

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

/// `robots/<key>/<key>.xml` of the repo. Every folder must hold its model and there must be
/// at least the ten robots we ship: a test over them can never pass by checking nothing.
fn repo_models() -> Vec<(String, PathBuf)> {
    let entries = std::fs::read_dir(repo_root().join("robots")).expect("robots/ is readable");
    let mut out: Vec<(String, PathBuf)> = entries
        .filter_map(Result::ok)
        .filter(|e| e.path().is_dir())
        .map(|e| {
            let key = e.file_name().to_string_lossy().into_owned();
            let xml = e.path().join(format!("{key}.xml"));
            assert!(xml.is_file(), "robots/{key}/ has no {key}.xml");
            (key, xml)
        })
        .collect();
    out.sort();
    assert!(out.len() >= 10, "robots/ holds {} models, expected the 10 shipped ones", out.len());
    out
}

fn check(label: &str, path: &Path) -> Result<(), String> {
    let model = Model::from_file(path).map_err(|e| format!("{label}: {e}"))?;
    let report =
        check_file(&model, path, CheckOptions::default()).map_err(|e| format!("{label}: {e}"))?;
    eprintln!("{label}: max deviation {:.2e}\n{report}", report.max_deviation());
    if passes(&report) {
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

// ------------------------------------------------------------------------------------------
// The corpus: every robot model file of the repository's test data and of the shared
// reference robots, read by us and compiled by MuJoCo. Both must load it or both refuse it;
// when both load it, the compiled models must agree (sizes, names, order, frames, ranges,
// `qpos0`, inertials) and so must every body pose and Jacobian at `qpos0` and 100 random
// configurations.

/// Every `.xml` and `.urdf` below `dir`, sorted (an absent folder holds none).
fn model_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    let mut paths: Vec<PathBuf> = entries.filter_map(Result::ok).map(|e| e.path()).collect();
    paths.sort();
    for path in paths {
        if path.is_dir() {
            model_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "xml" || e == "urdf") {
            out.push(path);
        }
    }
}

/// The corpus: `tests/data` and every crate's `tests/data` in the repository, the shipped
/// `robots/`, and (when given) the shared reference robots.
fn corpus(shared: Option<&Path>) -> Vec<PathBuf> {
    let root = repo_root();
    let mut files = Vec::new();
    model_files(&root.join("tests/data"), &mut files);
    model_files(&root.join("robots"), &mut files);
    let crates = std::fs::read_dir(root.join("crates")).expect("crates/ is readable");
    let mut crates: Vec<PathBuf> = crates.filter_map(Result::ok).map(|e| e.path()).collect();
    crates.sort();
    for krate in crates {
        model_files(&krate.join("tests/data"), &mut files);
    }
    if let Some(shared) = shared {
        model_files(&shared.join("reference/robots"), &mut files);
    }
    files
}

/// One corpus file: `Ok(line)` when we and MuJoCo agree (both load it and match, or both
/// refuse it), `Err(why)` otherwise.
fn corpus_entry(path: &Path) -> Result<String, String> {
    let ours = Model::from_path(path);
    let theirs = match &ours {
        Ok(model) => check_file(model, path, CheckOptions::default()),
        // MuJoCo's verdict alone: compared with a model of nothing, it only has to load.
        Err(_) => check_file(
            &Model::from_xml_str("<mujoco/>", None).expect("empty model"),
            path,
            CheckOptions { configs: 0, seed: 1 },
        ),
    };
    match (ours, theirs) {
        (Ok(model), Ok(report)) if report.passes(TOLERANCE) => Ok(format!(
            "loads, nq {} nbody {} njnt {}, max deviation {:.1e} ({} inertials compared)",
            model.nq,
            model.bodies.len(),
            model.joints.len(),
            report.max_deviation(),
            report.inertials
        )),
        (Ok(_), Ok(report)) => Err(format!("differs from mujoco\n{report}")),
        (Err(e), Err(m)) => Ok(format!("refused by both: ours \"{e}\"; mujoco \"{m}\"")),
        (Ok(_), Err(m)) => Err(format!("loads here, mujoco refuses it: {m}")),
        (Err(e), Ok(_)) => Err(format!("mujoco loads it, we refuse it: {e}")),
    }
}

#[test]
fn corpus_agrees_with_mujoco() {
    let shared = shared::shared_dir();
    let files = corpus(shared.as_deref());
    let expected = if shared.is_some() { 30 } else { 10 };
    assert!(files.len() >= expected, "the corpus holds {} files", files.len());
    let root = repo_root();
    let mut failures = Vec::new();
    for path in &files {
        let label = path
            .strip_prefix(&root)
            .or_else(|_| {
                shared.as_deref().map_or(Err(()), |s| path.strip_prefix(s).map_err(|_| ()))
            })
            .map_or_else(|_| path.display().to_string(), |p| p.display().to_string());
        match corpus_entry(path) {
            Ok(line) => eprintln!("{label}: {line}"),
            Err(why) => failures.push(format!("{label}: {why}")),
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} files:\n{}",
        failures.len(),
        files.len(),
        failures.join("\n")
    );
}

// ------------------------------------------------------------------------------------------
// URDF: our reading against MuJoCo's own URDF import (see `mujoco_check`): the robot fixed to
// the world as MuJoCo compiles it, and with the free root we add (added on MuJoCo's side
// through its model-editing API); static links fused (MuJoCo's URDF default) and kept.

fn urdf_variants() -> Vec<(&'static str, UrdfOptions)> {
    let mut out = Vec::new();
    for (base_label, base) in [("floating", UrdfBase::Floating), ("fixed", UrdfBase::Fixed)] {
        for (fuse_label, fuse_static) in [("fused", None), ("unfused", Some(false))] {
            let label = match (base_label, fuse_label) {
                ("floating", "fused") => "floating, fused",
                ("floating", _) => "floating, unfused",
                (_, "fused") => "fixed, fused",
                _ => "fixed, unfused",
            };
            out.push((label, UrdfOptions { base, fuse_static }));
        }
    }
    out
}

fn check_urdf(label: &str, path: &Path, urdf: UrdfOptions) -> Result<(Model, Report), String> {
    let model = Model::from_urdf_file(path, urdf).map_err(|e| format!("{label}: {e}"))?;
    let report = check_urdf_file(&model, path, urdf, CheckOptions::default())
        .map_err(|e| format!("{label}: {e}"))?;
    eprintln!("{label}: max deviation {:.2e}\n{report}", report.max_deviation());
    if passes(&report) {
        Ok((model, report))
    } else {
        Err(format!("{label} ({}): differs from mujoco\n{report}", path.display()))
    }
}

#[test]
fn urdf_feature_models_match_mujoco() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/urdf");
    let mut failures = Vec::new();
    for file in ["features.urdf", "planar_floating.urdf"] {
        for (variant, urdf) in urdf_variants() {
            if file == "planar_floating.urdf" && urdf.fuse_static == Some(false) {
                continue; // see urdf_free_joint_below_a_kept_link_fails_on_both_sides
            }
            if let Err(e) = check_urdf(&format!("{file} ({variant})"), &dir.join(file), urdf) {
                failures.push(e);
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn g1_urdf_matches_mujoco() {
    let Some(shared) = shared::shared_dir() else { return };
    let path = shared.join("reference/robots/unitree_g1/g1_custom_collision_29dof.urdf");
    let mut failures = Vec::new();
    for (variant, urdf) in urdf_variants() {
        match check_urdf(&format!("g1 urdf ({variant})"), &path, urdf) {
            Ok((model, report)) => {
                let free = usize::from(urdf.base == UrdfBase::Floating);
                assert_eq!(model.joints.len(), 29 + free, "{variant}");
                // Every link has an inertial or is a massless frame: fused, every body has one.
                if urdf.fuse_static.is_none() {
                    assert_eq!(report.inertials_skipped, 0, "{variant}\n{report}");
                }
            }
            Err(e) => failures.push(e),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// `check_file` (what `retarget robot check` calls) reads a `.urdf` with the default options.
#[test]
fn check_file_dispatches_urdf() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/urdf/features.urdf");
    let model = Model::from_path(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(model.joints[0].kind, mjcf::JointType::Free);
    let report = check_file(&model, &path, CheckOptions { configs: 10, seed: 1 })
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(passes(&report), "{report}");
}

/// A wrong mass, centre of mass or principal axis on one body is a mismatch naming it.
#[test]
fn inertial_check_catches_a_wrong_inertial() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/features/features.xml");
    let model = Model::from_file(&path).unwrap_or_else(|e| panic!("{e}"));
    let root = model.body_id("root").expect("features.xml has a body root");
    let turn = nalgebra::UnitQuaternion::from_axis_angle(&nalgebra::Vector3::x_axis(), 1e-6);
    for what in ["mass", "centre of mass", "axes"] {
        let mut wrong = model.clone();
        let i = wrong.bodies[root].inertial.as_mut().expect("root has an inertial");
        match what {
            "mass" => i.mass += 1e-7,
            "centre of mass" => i.pos.y -= 1e-7,
            _ => i.quat = turn * i.quat,
        }
        let report = check_file(&wrong, &path, CheckOptions { configs: 0, seed: 1 })
            .unwrap_or_else(|e| panic!("{e}"));
        assert!(!report.passes(TOLERANCE), "{what}\n{report}");
        assert!(
            report.mismatches.iter().any(|m| m.contains("\"root\": inertial")),
            "{what}\n{report}"
        );
    }
}

/// Without fusion, the floating joint of planar_floating.urdf hangs below the kept link
/// `stand`: MuJoCo refuses free joints there, and so do we (with the position).
#[test]
fn urdf_free_joint_below_a_kept_link_fails_on_both_sides() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/urdf/planar_floating.urdf");
    let placeholder = Model::from_urdf_file(&path, UrdfOptions::default()).unwrap();
    for base in [UrdfBase::Floating, UrdfBase::Fixed] {
        let urdf = UrdfOptions { base, fuse_static: Some(false) };
        let ours = Model::from_urdf_file(&path, urdf).unwrap_err().to_string();
        assert!(ours.contains("planar_floating.urdf:24:3: unsupported: floating joint"), "{ours}");
        let theirs = check_urdf_file(&placeholder, &path, urdf, CheckOptions::default());
        let message = theirs.err().map(|e| e.to_string()).unwrap_or_default();
        assert!(message.contains("free joint can only be used on top level"), "{message}");
    }
}

// ------------------------------------------------------------------------------------------
// Collision geometry: filter, distances, lowest points (see `mujoco_check::check_collision`).

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

/// The G1 URDF as MuJoCo imports it (fixed to the world, static links fused): the collision
/// filter and distances of our URDF reading.
#[test]
fn g1_urdf_collision_geometry_matches_mujoco() {
    let Some(shared) = shared::shared_dir() else { return };
    let path = shared.join("reference/robots/unitree_g1/g1_custom_collision_29dof.urdf");
    let urdf = UrdfOptions { base: UrdfBase::Fixed, fuse_static: None };
    let model = Model::from_urdf_file(&path, urdf).unwrap_or_else(|e| panic!("{e}"));
    let report = mjcf::mujoco_check::check_collision(&model, &path, CheckOptions::default())
        .unwrap_or_else(|e| panic!("{e}"));
    eprintln!("g1 urdf:\n{report}");
    assert!(report.pairs > 0 && report.passes(&TOLERANCES), "{report}");
}

/// Two soles, and a sole against a shin box, at random poses near contact: face manifolds
/// point for point as `mj_collision`'s box–box contacts, depths as `mj_geomDistance`'s.
#[test]
fn box_manifolds_match_mujocos_box_box_contacts() {
    use mjcf::mujoco_check::check_box_manifolds;
    for sizes in [[[0.1115, 0.05, 0.015]; 2], [[0.1115, 0.05, 0.015], [0.05, 0.04, 0.05]]] {
        let options = CheckOptions { configs: 20_000, seed: 11 };
        let report = check_box_manifolds(sizes, 0.02, options).expect("mujoco loads the boxes");
        eprintln!("{sizes:?}\n{report}");
        assert!(report.passes(1e-9), "{sizes:?}\n{report}");
        // Every kind of manifold was met often enough to mean something, and ours is as deep
        // as MuJoCo's GJK/EPA on all but a few poses (where EPA stopped short).
        assert!(report.faces > 500 && report.face_points > 1500, "{report}");
        assert!(report.tilted > 400 && report.edges > 1000, "{report}");
        assert!(report.as_deep_as_epa * 200 >= report.overlapping * 199, "{report}");
    }
}
