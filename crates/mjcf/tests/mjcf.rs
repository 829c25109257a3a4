//! Integration tests without MuJoCo: the reference FK oracle, every reference MJCF loading with
//! MuJoCo's sizes, Jacobians against finite differences of our FK, integration, and error
//! messages with their positions.

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::{Path, PathBuf};

use mjcf::{Data, Error, JointType, Model};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde_json::Value;

fn read_json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().expect("array").iter().map(|x| x.as_f64().expect("number")).collect()
}

/// Every reference robot: (key, MJCF path, index.json entry).
fn reference_robots(shared: &Path) -> Vec<(String, PathBuf, Value)> {
    let index = read_json(&shared.join("reference/robots/index.json"));
    let mut out: Vec<_> = index
        .as_object()
        .expect("object")
        .iter()
        .map(|(k, e)| {
            (k.clone(), shared.join("reference").join(e["file"].as_str().expect("file")), e.clone())
        })
        .collect();
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

#[test]
fn fk_matches_the_mujoco_oracle() {
    let Some(shared) = shared::shared_dir() else { return };
    let dir = shared.join("reference/fk_oracle");
    for robot in ["unitree_g1", "booster_t1_29dof"] {
        let oracle = read_json(&dir.join(format!("{robot}.json")));
        let model_path = shared.join(oracle["model_file"].as_str().expect("model_file"));
        let model = Model::from_file(&model_path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(model.nq, oracle["nq"].as_u64().unwrap() as usize, "{robot} nq");
        assert_eq!(model.nv, oracle["nv"].as_u64().unwrap() as usize, "{robot} nv");
        let names: Vec<&str> =
            oracle["body_names"].as_array().unwrap().iter().map(|v| v.as_str().unwrap()).collect();
        let ours: Vec<&str> = model.bodies.iter().map(|b| b.name.as_str()).collect();
        assert_eq!(ours, names, "{robot} body names");
        let parents: Vec<usize> = oracle["body_parent"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_u64().unwrap() as usize)
            .collect();
        assert_eq!(
            model.bodies.iter().map(|b| b.parent).collect::<Vec<_>>(),
            parents,
            "{robot} parents"
        );
        check_layout(robot, &model, &oracle["qpos_layout"]);
        assert_eq!(model.qpos0, floats(&oracle["qpos0"]), "{robot} qpos0");

        let mut data = Data::new(&model);
        let records = std::iter::once(&oracle["home"]).chain(oracle["configs"].as_array().unwrap());
        let mut count = 0;
        for record in records {
            model.kinematics(&floats(&record["qpos"]), &mut data);
            for (b, (xpos, xquat)) in record["xpos"]
                .as_array()
                .unwrap()
                .iter()
                .zip(record["xquat"].as_array().unwrap())
                .enumerate()
            {
                let (p, q) = (floats(xpos), floats(xquat));
                let ours = data.xquat[b];
                let dp = (data.xpos[b] - Vector3::new(p[0], p[1], p[2])).amax();
                let dq = (ours.into_inner().coords
                    - Quaternion::new(q[0], q[1], q[2], q[3]).coords)
                    .amax();
                assert!(
                    dp <= 1e-12 && dq <= 1e-12,
                    "{robot} {} body {b}: dxpos {dp:e} dxquat {dq:e}",
                    record["label"]
                );
            }
            count += 1;
        }
        assert_eq!(count, 51, "{robot}: home + 50 configurations");
    }
}

fn check_layout(robot: &str, model: &Model, layout: &Value) {
    let layout = layout.as_array().unwrap();
    assert_eq!(model.joints.len(), layout.len(), "{robot} joints");
    for (joint, entry) in model.joints.iter().zip(layout) {
        assert_eq!(joint.name, entry["joint"].as_str().unwrap_or(""), "{robot} joint name");
        assert_eq!(joint.kind.as_str(), entry["type"].as_str().unwrap(), "{robot} {}", joint.name);
        assert_eq!(
            joint.qpos_adr,
            entry["qposadr"].as_u64().unwrap() as usize,
            "{robot} {}",
            joint.name
        );
        assert_eq!(
            model.bodies[joint.body].name,
            entry["body"].as_str().unwrap(),
            "{robot} {}",
            joint.name
        );
        let range =
            entry["range"].as_array().map(|r| [r[0].as_f64().unwrap(), r[1].as_f64().unwrap()]);
        assert_eq!(joint.range, range, "{robot} {} range", joint.name);
    }
}

#[test]
fn every_reference_model_loads_with_mujocos_sizes() {
    let Some(shared) = shared::shared_dir() else { return };
    let robots = reference_robots(&shared);
    assert!(robots.len() >= 18);
    for (key, path, entry) in robots {
        let model = Model::from_file(&path).unwrap_or_else(|e| panic!("{key}: {e}"));
        let size = |k: &str| entry[k].as_u64().unwrap() as usize;
        assert_eq!(
            (model.nq, model.nv, model.joints.len(), model.bodies.len(), model.sites.len()),
            (size("nq"), size("nv"), size("njnt"), size("nbody"), size("nsite")),
            "{key}: nq, nv, njnt, nbody, nsite"
        );
        assert_eq!(model.geoms.len(), size("ngeom_ref"), "{key}: ngeom");
        assert_eq!(
            model.body_id(entry["root_body"].as_str().unwrap()).map(|b| model.bodies[b].parent),
            Some(0),
            "{key}"
        );
    }
}

/// World angular velocity that takes `a` to `b` in time `dt`.
fn angular_velocity(a: &UnitQuaternion<f64>, b: &UnitQuaternion<f64>, dt: f64) -> Vector3<f64> {
    (b * a.inverse()).scaled_axis() / dt
}

/// Central differences of our FK along every dof (moved with `integrate_pos`) against the
/// analytic Jacobians of every body.
fn check_jacobians_by_finite_differences(label: &str, model: &Model, seed: u64, configs: usize) {
    let (h, tol) = (1e-6, 1e-7);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (mut data, mut plus, mut minus) = (Data::new(model), Data::new(model), Data::new(model));
    let nv = model.nv;
    let (mut jacp, mut jacr) = (vec![0.0; 3 * nv], vec![0.0; 3 * nv]);
    for _ in 0..configs {
        let qpos = model.random_qpos(&mut rng);
        model.kinematics(&qpos, &mut data);
        for d in 0..nv {
            let mut qvel = vec![0.0; nv];
            qvel[d] = 1.0;
            let (mut qp, mut qm) = (qpos.clone(), qpos.clone());
            model.integrate_pos(&mut qp, &qvel, h);
            model.integrate_pos(&mut qm, &qvel, -h);
            model.kinematics(&qp, &mut plus);
            model.kinematics(&qm, &mut minus);
            for b in 0..model.bodies.len() {
                model.jac_body(&data, b, &mut jacp, &mut jacr);
                let v = (plus.xpos[b] - minus.xpos[b]) / (2.0 * h);
                let w = angular_velocity(&minus.xquat[b], &plus.xquat[b], 2.0 * h);
                for r in 0..3 {
                    let (ep, er) =
                        ((jacp[r * nv + d] - v[r]).abs(), (jacr[r * nv + d] - w[r]).abs());
                    assert!(
                        ep < tol && er < tol,
                        "{label}: body {b} dof {d} row {r}: jacp err {ep:e}, jacr err {er:e}"
                    );
                }
            }
        }
    }
}

#[test]
fn jacobians_match_finite_differences_of_fk() {
    let features = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/features/features.xml");
    let model = Model::from_file(&features).unwrap_or_else(|e| panic!("{e}"));
    check_jacobians_by_finite_differences("features.xml", &model, 7, 5);
    let Some(shared) = shared::shared_dir() else { return };
    for (key, path, _) in reference_robots(&shared) {
        let model = Model::from_file(&path).unwrap_or_else(|e| panic!("{key}: {e}"));
        check_jacobians_by_finite_differences(&key, &model, 11, 2);
    }
}

#[test]
fn jac_of_a_point_is_the_body_jacobian_shifted() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/features/features.xml");
    let model = Model::from_file(&path).unwrap();
    let mut data = Data::new(&model);
    model.kinematics(&model.random_qpos(&mut ChaCha8Rng::seed_from_u64(3)), &mut data);
    let nv = model.nv;
    let b = model.body_id("foot").unwrap();
    let offset = Vector3::new(0.1, -0.2, 0.3);
    let (mut jp, mut jr, mut bp, mut br) =
        (vec![0.0; 3 * nv], vec![0.0; 3 * nv], vec![0.0; 3 * nv], vec![0.0; 3 * nv]);
    model.jac(&data, b, &(data.xpos[b] + offset), &mut jp, &mut jr);
    model.jac_body(&data, b, &mut bp, &mut br);
    assert_eq!(jr, br);
    for d in 0..nv {
        let w = Vector3::new(br[d], br[nv + d], br[2 * nv + d]);
        let shifted = Vector3::new(bp[d], bp[nv + d], bp[2 * nv + d]) + w.cross(&offset);
        for r in 0..3 {
            assert!((jp[r * nv + d] - shifted[r]).abs() < 1e-14);
        }
    }
}

/// `jac_point_columns` lists exactly `jac`'s non-zero translational columns, bit for bit.
#[test]
fn jac_point_columns_are_the_columns_of_jac() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/features/features.xml");
    let model = Model::from_file(&path).unwrap();
    let mut data = Data::new(&model);
    model.kinematics(&model.random_qpos(&mut ChaCha8Rng::seed_from_u64(4)), &mut data);
    let nv = model.nv;
    let (mut jp, mut jr) = (vec![0.0; 3 * nv], vec![0.0; 3 * nv]);
    for b in 0..model.bodies.len() {
        let point = data.xpos[b] + Vector3::new(0.05, 0.1, -0.2);
        model.jac(&data, b, &point, &mut jp, &mut jr);
        let columns: Vec<(usize, Vector3<f64>)> =
            model.jac_point_columns(&data, b, point).collect();
        let dofs: Vec<usize> = model.body_dofs(b).collect();
        assert_eq!(columns.iter().map(|c| c.0).collect::<Vec<_>>(), dofs);
        for d in 0..nv {
            let jac = Vector3::new(jp[d], jp[nv + d], jp[2 * nv + d]);
            match columns.iter().find(|c| c.0 == d) {
                Some((_, column)) => assert_eq!(*column, jac, "body {b} dof {d}"),
                None => assert_eq!(jac, Vector3::zeros(), "body {b} dof {d}"),
            }
        }
    }
    let other = Data::new(&Model::from_xml_str("<mujoco><worldbody/></mujoco>", None).unwrap());
    assert_eq!(model.jac_point_columns(&other, 1, Vector3::zeros()).count(), 0);
}

/// `jac_column` is `jac_chain`'s column of every dof on a body's path, bit for bit.
#[test]
fn jac_column_is_the_column_of_jac_chain() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/features/features.xml");
    let model = Model::from_file(&path).unwrap();
    let mut data = Data::new(&model);
    model.kinematics(&model.random_qpos(&mut ChaCha8Rng::seed_from_u64(5)), &mut data);
    let nv = model.nv;
    let (mut jp, mut jr) = (vec![0.0; 3 * nv], vec![0.0; 3 * nv]);
    for b in 0..model.bodies.len() {
        model.jac_chain(&data, b, &mut jp, &mut jr);
        for d in model.body_dofs(b) {
            let column = |j: &[f64]| Vector3::new(j[d], j[nv + d], j[2 * nv + d]);
            let got = Model::jac_column(&data, &data.xpos[b], d);
            assert_eq!(got, Some((column(&jp), column(&jr))), "body {b} dof {d}");
        }
    }
    assert_eq!(Model::jac_column(&data, &Vector3::zeros(), nv), None);
}

#[test]
fn integrate_pos_follows_mujoco() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/features/features.xml");
    let model = Model::from_file(&path).unwrap();
    let mut qpos = model.random_qpos(&mut ChaCha8Rng::seed_from_u64(5));
    let before = qpos.clone();
    let qvel: Vec<f64> = (0..model.nv).map(|i| 0.1 * (i as f64 + 1.0)).collect();
    let dt = 0.3;
    model.integrate_pos(&mut qpos, &qvel, dt);
    for joint in &model.joints {
        let (a, v) = (joint.qpos_adr, joint.dof_adr);
        let quat_at = |q: &[f64], i: usize| {
            UnitQuaternion::from_quaternion(Quaternion::new(q[i], q[i + 1], q[i + 2], q[i + 3]))
        };
        match joint.kind {
            JointType::Hinge | JointType::Slide => {
                assert!((qpos[a] - (before[a] + dt * qvel[v])).abs() < 1e-15)
            }
            JointType::Free | JointType::Ball => {
                let (qa, va) = if joint.kind == JointType::Free { (a + 3, v + 3) } else { (a, v) };
                if joint.kind == JointType::Free {
                    for k in 0..3 {
                        assert!((qpos[a + k] - (before[a + k] + dt * qvel[v + k])).abs() < 1e-15);
                    }
                }
                // Body-frame angular velocity: q ← q · exp(ω dt).
                let omega = Vector3::new(qvel[va], qvel[va + 1], qvel[va + 2]);
                let expected = quat_at(&before, qa) * UnitQuaternion::from_scaled_axis(omega * dt);
                assert!(quat_at(&qpos, qa).angle_to(&expected) < 1e-14, "{}", joint.name);
            }
        }
    }
}

#[test]
fn orientation_forms_agree() {
    // The same rotation (90° about z) written six ways, in degrees and radians.
    let forms = [
        r#"quat="0.7071067811865476 0 0 0.7071067811865476""#,
        r#"axisangle="0 0 1 90""#,
        r#"euler="0 0 90""#,
        r#"xyaxes="0 1 0 -1 0 0""#,
    ];
    let body_quat = |orientation: &str, compiler: &str| {
        let xml = format!(
            r#"<mujoco>{compiler}<worldbody><body {orientation}><geom size="1"/></body></worldbody></mujoco>"#
        );
        Model::from_xml_str(&xml, None).unwrap_or_else(|e| panic!("{orientation}: {e}")).bodies[1]
            .quat
    };
    let reference = body_quat(forms[0], "");
    for form in forms {
        assert!(body_quat(form, "").angle_to(&reference) < 1e-15, "{form}");
    }
    let radian = body_quat(r#"euler="0 0 1.5707963267948966""#, r#"<compiler angle="radian"/>"#);
    assert!(radian.angle_to(&reference) < 1e-15);
    // zaxis: the shortest rotation taking z to the given direction.
    let z = body_quat(r#"zaxis="1 0 0""#, "");
    assert!((z * Vector3::z() - Vector3::x()).norm() < 1e-15);
}

#[test]
fn errors_name_file_line_and_column() {
    let cases = [
        ("<mujoco><worldbody>\n  <body><joint type=\"cylindrical\"/></body></worldbody></mujoco>",
         "<string>:2:16: attribute type=\"cylindrical\": expected one of free, ball, slide, hinge"),
        ("<mujoco><worldbody>\n<body pos=\"1 2\"/></worldbody></mujoco>",
         "<string>:2:7: attribute pos=\"1 2\": expected 3 numbers, found 2"),
        ("<mujoco><worldbody>\n<body><joint class=\"nope\"/></body></worldbody></mujoco>",
         "<string>:2:14: unknown default class \"nope\""),
        ("<mujoco><worldbody>\n<body><composite/></body></worldbody></mujoco>",
         "<string>:2:7: unsupported: element <composite> in a body"),
        ("<mujoco><worldbody>\n<body><body><freejoint/></body></body></worldbody></mujoco>",
         "<string>:2:13: free joint can only be used on top level"),
        ("<mujoco><compiler autolimits=\"false\"/><worldbody>\n<body><joint range=\"0 1\"/></body></worldbody></mujoco>",
         "<string>:2:7: joint has a range but no limited attribute and autolimits is false; set limited or autolimits"),
        ("<mujoco><worldbody>\n<body quat=\"1 0 0 0\" euler=\"0 0 0\"/></worldbody></mujoco>",
         "<string>:2:22: multiple orientation specifiers on <body>"),
        ("<mujoco><worldbody>\n<body><joint range=\"1 -1\"/></body></worldbody></mujoco>",
         "<string>:2:7: joint range[0] must be smaller than range[1]"),
        ("<mujoco><worldbody><body>\n</worldbody></mujoco>", "<string>:2:1: invalid xml: expected 'body' tag, not 'worldbody' at 2:1"),
        ("<robot/>", "<string>:1:1: root element is <robot>, expected <mujoco>"),
        // <inertial>
        ("<mujoco><worldbody>\n<body><joint/><inertial pos=\"0 0 0\" mass=\"-1\" diaginertia=\"1 1 1\"/></body></worldbody></mujoco>",
         "<string>:2:37: attribute mass=\"-1\": must not be negative"),
        ("<mujoco><worldbody>\n<body><joint/><inertial pos=\"0 0 0\" mass=\"heavy\" diaginertia=\"1 1 1\"/></body></worldbody></mujoco>",
         "<string>:2:37: attribute mass=\"heavy\": not a list of numbers"),
        ("<mujoco><worldbody>\n<body><joint/><inertial pos=\"0 0 0\" mass=\"1\" diaginertia=\"1 1\"/></body></worldbody></mujoco>",
         "<string>:2:46: attribute diaginertia=\"1 1\": expected 3 numbers, found 2"),
        ("<mujoco><worldbody>\n<body><joint/><inertial pos=\"0 0 0\" mass=\"1\" fullinertia=\"1 1 1 0 0\"/></body></worldbody></mujoco>",
         "<string>:2:46: attribute fullinertia=\"1 1 1 0 0\": expected 6 numbers, found 5"),
        ("<mujoco><worldbody>\n<body><joint/><inertial pos=\"0 0 0\" mass=\"1\" diaginertia=\"1 -1 1\"/></body></worldbody></mujoco>",
         "<string>:2:46: attribute diaginertia=\"1 -1 1\": must not be negative"),
        ("<mujoco><worldbody>\n<body><joint/><inertial pos=\"0 0 0\" mass=\"1\" fullinertia=\"1 1 1 0 0 0\" diaginertia=\"1 1 1\"/></body></worldbody></mujoco>",
         "<string>:2:72: <inertial> with both diaginertia and fullinertia"),
        ("<mujoco><worldbody>\n<body><joint/><inertial pos=\"0 0 0\" diaginertia=\"1 1 1\"/></body></worldbody></mujoco>",
         "<string>:2:15: <inertial> needs the attribute mass"),
        ("<mujoco><worldbody>\n<body><joint/><inertial mass=\"1\" diaginertia=\"1 1 1\"/></body></worldbody></mujoco>",
         "<string>:2:15: <inertial> needs the attribute pos"),
        ("<mujoco><worldbody>\n<body><joint/><inertial pos=\"0 0 0\" mass=\"1\" fullinertia=\"1 1 1 0 0 0\" euler=\"0 0 1\"/></body></worldbody></mujoco>",
         "<string>:2:72: fullinertia and an orientation on one <inertial>"),
        ("<mujoco><worldbody>\n<body><inertial pos=\"0 0 0\" mass=\"1\"/><frame><inertial pos=\"0 0 0\" mass=\"1\"/></frame></body></worldbody></mujoco>",
         "<string>:2:46: more than one <inertial> in a body"),
        ("<mujoco><worldbody>\n<body><joint/><inertial pos=\"0 0 0\" mass=\"1\" diaginertia=\"1 1 3\"/></body></worldbody></mujoco>",
         "<string>:2:15: inertia must satisfy A + B >= C; use 'balanceinertia' to fix"),
        ("<mujoco><worldbody>\n<body><joint/><inertial pos=\"0 0 0\" mass=\"1\" fullinertia=\"1 1 1 2 0 0\"/></body></worldbody></mujoco>",
         "<string>:2:15: fullinertia: inertia must have positive eigenvalues"),
        ("<mujoco><worldbody>\n<inertial pos=\"0 0 0\" mass=\"1\"/></worldbody></mujoco>",
         "<string>:2:1: the world body cannot have an <inertial>"),
        ("<mujoco><worldbody>\n<frame><inertial pos=\"0 0 0\" mass=\"1\"/></frame></worldbody></mujoco>",
         "<string>:2:8: the world body cannot have an <inertial>"),
        ("<mujoco>\n<compiler inertiafromgeom=\"maybe\"/></mujoco>",
         "<string>:2:11: attribute inertiafromgeom=\"maybe\": expected one of false, true, auto"),
        ("<mujoco><include file=\"does_not_exist.xml\"/></mujoco>", "<string>:1:18: cannot read included file"),
    ];
    for (xml, expected) in cases {
        let message = match Model::from_xml_str(xml, None) {
            Ok(_) => panic!("no error for {xml}"),
            Err(e) => e.to_string(),
        };
        assert!(message.starts_with(expected), "\n got: {message}\nwant: {expected}");
    }
    let missing = Model::from_file(Path::new("/nonexistent/robot.xml")).unwrap_err();
    assert!(matches!(missing, Error::Io { .. }));
    assert!(missing.to_string().starts_with("/nonexistent/robot.xml: cannot read file"));
}

#[test]
fn errors_in_included_files_name_that_file() {
    let dir = std::env::temp_dir().join(format!("mjcf-include-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("part.xml"),
        "<mujoco>\n<worldbody><body euler=\"1 2\"/></worldbody></mujoco>",
    )
    .unwrap();
    std::fs::write(dir.join("main.xml"), "<mujoco><include file=\"part.xml\"/></mujoco>").unwrap();
    let err = Model::from_file(&dir.join("main.xml")).unwrap_err().to_string();
    std::fs::remove_dir_all(&dir).ok();
    let expected = format!(
        "{}:2:18: attribute euler=\"1 2\": expected 3 numbers, found 2",
        dir.join("part.xml").display()
    );
    assert_eq!(err, expected);
}

/// The repo's `robots/<key>/<key>.xml` with a reference model of the same key: same bodies,
/// joints, ranges and `qpos0`, and the same body poses at random configurations.
#[test]
fn repo_robots_have_the_reference_kinematics() {
    let Some(shared) = shared::shared_dir() else { return };
    let robots_dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots");
    let mut failures = Vec::new();
    let mut compared = 0;
    for (key, reference_path, _) in reference_robots(&shared) {
        let folder = robots_dir.join(&key);
        let ours_path = folder.join(format!("{key}.xml"));
        if !folder.is_dir() {
            continue; // a reference robot we do not ship
        }
        assert!(ours_path.is_file(), "robots/{key}/ has no {key}.xml");
        compared += 1;
        let ours = Model::from_file(&ours_path).unwrap_or_else(|e| panic!("{e}"));
        let reference = Model::from_file(&reference_path).unwrap_or_else(|e| panic!("{e}"));
        if let Err(e) = same_kinematics(&ours, &reference) {
            failures.push(format!("robots/{key}: {e}"));
        } else {
            eprintln!("robots/{key}: same kinematics as the reference");
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // Every robot we ship (ten) has a reference: none may go unchecked.
    assert!(compared >= 10, "only {compared} robots compared with a reference");
}

fn same_kinematics(ours: &Model, reference: &Model) -> Result<(), String> {
    let names = |m: &Model| m.bodies.iter().map(|b| (b.name.clone(), b.parent)).collect::<Vec<_>>();
    if names(ours) != names(reference) {
        return Err(format!(
            "bodies differ:\n ours {:?}\n  ref {:?}",
            names(ours),
            names(reference)
        ));
    }
    let joints = |m: &Model| {
        m.joints.iter().map(|j| (j.name.clone(), j.kind, j.body, j.qpos_adr)).collect::<Vec<_>>()
    };
    if (ours.nq, ours.nv, joints(ours)) != (reference.nq, reference.nv, joints(reference)) {
        return Err(format!(
            "joints differ:\n ours {:?}\n  ref {:?}",
            joints(ours),
            joints(reference)
        ));
    }
    for (a, b) in ours.joints.iter().zip(&reference.joints) {
        let close = match (a.range, b.range) {
            (None, None) => true,
            (Some(x), Some(y)) => (x[0] - y[0]).abs() <= 1e-9 && (x[1] - y[1]).abs() <= 1e-9,
            _ => false,
        };
        if !close {
            return Err(format!("joint {}: range {:?}, reference {:?}", a.name, a.range, b.range));
        }
    }
    let dq0 =
        ours.qpos0.iter().zip(&reference.qpos0).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    if dq0 > 1e-9 {
        return Err(format!("qpos0 differs by {dq0:e}"));
    }
    let (mut a, mut b) = (Data::new(ours), Data::new(reference));
    let mut rng = ChaCha8Rng::seed_from_u64(99);
    for _ in 0..100 {
        let qpos = reference.random_qpos(&mut rng);
        ours.kinematics(&qpos, &mut a);
        reference.kinematics(&qpos, &mut b);
        for i in 0..a.xpos.len() {
            let dp = (a.xpos[i] - b.xpos[i]).amax();
            let dq = a.xquat[i].angle_to(&b.xquat[i]);
            if dp > 1e-9 || dq > 1e-9 {
                return Err(format!(
                    "body {}: xpos differs by {dp:e}, xquat by {dq:e} rad",
                    ours.bodies[i].name
                ));
            }
        }
    }
    Ok(())
}

/// `Model::chain_contacts` finds the pairs our models leave out with `<exclude>` (primitives
/// coarser than the parts, found on the LAFAN1 takes): with the excludes removed from
/// ToddlerBot's and the T1's models, each excluded pair on one chain touches over most of the
/// ranges of the joints between its bodies; with them, none of those pairs is there.
#[test]
fn chain_contacts_find_the_pairs_our_models_exclude() {
    let robots_dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots");
    for (key, excluded, least) in [
        ("stanford_toddy", [("left_calf_link", "ank_roll_link"), ("torso", "waist_link")], 0.5),
        ("booster_t1_29dof", [("AL4", "AL6"), ("AR4", "AR6")], 0.5),
    ] {
        let path = robots_dir.join(format!("{key}/{key}.xml"));
        let xml = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{e}"));
        let stripped: String =
            xml.lines().filter(|l| !l.contains("<exclude")).collect::<Vec<_>>().join("\n");
        assert_ne!(stripped.len(), xml.len(), "{key}: no <exclude> to strip");
        let names = |m: &Model, c: &mjcf::ChainContact| {
            (m.bodies[c.bodies[0]].name.clone(), m.bodies[c.bodies[1]].name.clone())
        };
        let bare = Model::from_xml_str(&stripped, path.parent()).unwrap_or_else(|e| panic!("{e}"));
        let found = bare.chain_contacts(200, 7);
        for (a, b) in excluded {
            let share = found
                .iter()
                .filter(|c| names(&bare, c) == (a.to_owned(), b.to_owned()))
                .map(|c| c.share)
                .fold(0.0, f64::max);
            assert!(share >= least, "{key}: {a} / {b} touch in {share} of their ranges");
        }
        let shipped = Model::from_file(&path).unwrap_or_else(|e| panic!("{e}"));
        for c in shipped.chain_contacts(200, 7) {
            let pair = names(&shipped, &c);
            assert!(
                !excluded.iter().any(|(a, b)| pair == ((*a).to_owned(), (*b).to_owned())),
                "{key}: excluded pair {pair:?} still checked"
            );
        }
    }
}
