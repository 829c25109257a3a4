//! URDF without MuJoCo: our feature file read as MuJoCo reads it (the expected values are
//! MuJoCo 3.17.0's compile of the same file; `tests/mujoco_parity.rs` checks everything with
//! MuJoCo itself), the shared G1 URDF (velocity limits, and its kinematics against our MJCF G1
//! body by body), `Model::from_path`, and errors with their positions.

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::{Path, PathBuf};

use mjcf::{Data, Error, GeomType, JointType, Model, UrdfBase, UrdfOptions};
use nalgebra::{Quaternion, UnitQuaternion};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/urdf")
}

fn load(path: &Path, options: UrdfOptions) -> Model {
    Model::from_urdf_file(path, options).unwrap_or_else(|e| panic!("{e}"))
}

fn body_names(m: &Model) -> Vec<&str> {
    m.bodies.iter().map(|b| b.name.as_str()).collect()
}

#[test]
fn feature_file_reads_as_mujoco_reads_it() {
    let m = load(&data_dir().join("features.urdf"), UrdfOptions::default());
    assert_eq!(m.name, "features");
    // Depth-first, children in joint order; head, head_tip, toe and side are merged.
    assert_eq!(body_names(&m), ["world", "base", "torso", "slider", "cam", "leg", "foot"]);
    let parents: Vec<usize> = m.bodies.iter().map(|b| b.parent).collect();
    assert_eq!(parents, [0, 0, 1, 2, 2, 1, 5]);
    let joints: Vec<(&str, JointType, usize)> =
        m.joints.iter().map(|j| (j.name.as_str(), j.kind, j.body)).collect();
    assert_eq!(
        joints,
        [
            ("base_free_joint", JointType::Free, 1),
            ("yaw", JointType::Hinge, 2),
            ("slide", JointType::Slide, 3),
            ("cam_spin", JointType::Hinge, 4),
            ("hip", JointType::Hinge, 5),
            ("knee", JointType::Hinge, 6),
        ]
    );
    assert_eq!((m.nq, m.nv), (12, 11));
    assert_eq!(m.qpos0, [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    let ranges: Vec<Option<[f64; 2]>> = m.joints.iter().map(|j| j.range).collect();
    assert_eq!(ranges, [None, Some([-1.5, 1.5]), Some([-0.2, 0.3]), None, None, None]);
    let speeds: Vec<Option<f64>> = m.joints.iter().map(|j| j.velocity_limit).collect();
    assert_eq!(speeds, [None, Some(4.0), Some(0.5), Some(2.0), None, Some(6.0)]);
    // Axes normalised: "0 0 2", "0 3 4", "1 1 0".
    let axis = |name: &str| m.joints[m.joint_id(name).unwrap()].axis;
    assert_eq!(axis("yaw").as_slice(), [0.0, 0.0, 1.0]);
    assert!((axis("slide") - nalgebra::Vector3::new(0.0, 0.6, 0.8)).norm() < 1e-15);
    assert!((axis("cam_spin").x - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-15);
    // cam hangs from torso through two merged links: MuJoCo's body_pos and body_quat.
    let cam = &m.bodies[4];
    assert!((cam.pos - nalgebra::Vector3::new(0.07708021, 0.00500833, 0.48083146)).amax() < 1e-8);
    let q = UnitQuaternion::new_normalize(Quaternion::new(
        0.63087353,
        0.75978976,
        0.05621558,
        -0.14682614,
    ));
    assert!(cam.quat.angle_to(&q) < 1e-7);
}

#[test]
fn feature_file_geoms_follow_mujoco() {
    let m = load(&data_dir().join("features.urdf"), UrdfOptions::default());
    let geoms: Vec<(&str, GeomType, usize)> =
        m.geoms.iter().map(|g| (g.name.as_str(), g.kind, g.body)).collect();
    assert_eq!(
        geoms,
        [
            ("dup", GeomType::Box, 1),
            ("", GeomType::Cylinder, 1),
            ("", GeomType::Box, 1),         // side, merged into base
            ("", GeomType::Cylinder, 2),    // the second "dup": unnamed
            ("skull", GeomType::Sphere, 2), // head, merged into torso
            ("block", GeomType::Mesh, 3),
            ("", GeomType::Mesh, 3),
            ("", GeomType::Capsule, 4),
            ("", GeomType::Box, 6),
            ("toe", GeomType::Sphere, 6),
        ]
    );
    assert_eq!(m.geoms[0].size, [0.15, 0.1, 0.05]); // box: half sizes
    assert_eq!(m.geoms[1].size, [0.05, 0.05, 0.0]); // cylinder: radius, half length
    assert_eq!(m.geoms[7].size, [0.01, 0.02, 0.0]); // capsule
    let meshes: Vec<Option<&str>> = m.geoms.iter().map(|g| g.mesh.as_deref()).collect();
    assert_eq!(meshes[5..7], [Some("cube"), Some("cube1")]); // same file, another scale
                                                             // The merged side box: the fixed joint's frame (z by 1 rad) composed with its origin.
    let side = &m.geoms[2];
    assert!((side.pos - nalgebra::Vector3::new(-0.1682942, 0.10806046, 0.05)).amax() < 1e-7);
}

#[test]
fn fixed_base_merges_the_root_into_the_world() {
    let path = data_dir().join("features.urdf");
    let fixed = load(&path, UrdfOptions { base: UrdfBase::Fixed, fuse_static: None });
    assert_eq!(body_names(&fixed), ["world", "torso", "slider", "cam", "leg", "foot"]);
    assert_eq!((fixed.nq, fixed.joints[0].name.as_str()), (5, "yaw"));
    assert_eq!(fixed.geoms.iter().filter(|g| g.body == 0).count(), 3);
    // Without fusion every link is a body, the static ones without joints.
    let kept = load(&path, UrdfOptions { base: UrdfBase::Fixed, fuse_static: Some(false) });
    assert_eq!(
        body_names(&kept),
        [
            "world", "base", "torso", "slider", "head", "head_tip", "cam", "leg", "foot", "toe",
            "side"
        ]
    );
    assert_eq!(kept.nq, 5);
    // The file can ask for it too (MuJoCo's <mujoco><compiler> extension).
    let text = std::fs::read_to_string(&path).unwrap().replace(
        "<robot name=\"features\">",
        "<robot name=\"features\"><mujoco><compiler fusestatic=\"false\"/></mujoco>",
    );
    let from_file =
        Model::from_urdf_str(&text, UrdfOptions { base: UrdfBase::Fixed, fuse_static: None })
            .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(body_names(&from_file), body_names(&kept));
}

#[test]
fn planar_floating_and_spherical_joints() {
    let m = load(&data_dir().join("planar_floating.urdf"), UrdfOptions::default());
    // The file's floating joint is the free root; no second one is added.
    assert_eq!(body_names(&m), ["world", "base", "sled", "ball"]);
    let joints: Vec<(&str, JointType)> =
        m.joints.iter().map(|j| (j.name.as_str(), j.kind)).collect();
    assert_eq!(
        joints,
        [
            ("float", JointType::Free),
            ("plane_TX", JointType::Slide),
            ("plane_TY", JointType::Slide),
            ("plane_RZ", JointType::Hinge),
            ("shoulder", JointType::Ball),
        ]
    );
    assert_eq!(m.joints[1].range, Some([-1.0, 2.0]));
    assert_eq!(m.joints[2].range, None);
    // qpos0 of the free joint: the body pose after merging `stand` into the world.
    assert!((m.qpos0[2] - 1.2).abs() < 1e-15 && (m.qpos0[0] - 0.5).abs() < 1e-15);
    // Geoms of the link called world belong to the world body.
    assert_eq!(m.geoms[0].body, 0);
}

#[test]
fn from_path_dispatches_on_the_extension() {
    let urdf =
        Model::from_path(&data_dir().join("features.urdf")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(urdf.joints[0].kind, JointType::Free);
    let xml = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/features/features.xml");
    let mjcf = Model::from_path(&xml).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(mjcf, Model::from_file(&xml).unwrap());
    let err = Model::from_path(Path::new("robot.sdf")).unwrap_err().to_string();
    assert_eq!(
        err,
        "robot.sdf: unknown robot model format: expected a .xml (MJCF) or .urdf (URDF) file"
    );
    let missing = Model::from_path(Path::new("/nonexistent/robot.URDF")).unwrap_err();
    assert!(matches!(missing, Error::Io { .. }), "{missing}");
}

fn g1_urdf(shared: &Path) -> PathBuf {
    shared.join("reference/robots/unitree_g1/g1_custom_collision_29dof.urdf")
}

#[test]
#[allow(clippy::approx_constant)] // 0.5236 is the file's number, not π/6
fn g1_urdf_reads_joints_and_speed_limits() {
    let Some(shared) = shared::shared_dir() else { return };
    let m = load(&g1_urdf(&shared), UrdfOptions::default());
    assert_eq!(m.name, "g1_29dof_rev_1_0");
    assert_eq!((m.nq, m.nv, m.bodies.len()), (36, 35, 31));
    assert_eq!(
        (m.joints[0].name.as_str(), m.joints[0].kind),
        ("pelvis_free_joint", JointType::Free)
    );
    assert_eq!(m.bodies[1].name, "pelvis");
    assert!(m.joints[1..].iter().all(|j| j.kind == JointType::Hinge && j.range.is_some()));
    // Spot checks against the file's <limit> lines.
    let joint = |name: &str| &m.joints[m.joint_id(name).unwrap_or_else(|| panic!("{name}"))];
    for (name, lower, upper, velocity) in [
        ("left_hip_pitch_joint", -2.5307, 2.8798, 32.0),
        ("left_hip_roll_joint", -0.5236, 2.9671, 20.0),
        ("right_knee_joint", -0.087267, 2.8798, 20.0),
        ("left_ankle_pitch_joint", -0.87267, 0.5236, 37.0),
        ("waist_yaw_joint", -2.618, 2.618, 32.0),
        ("right_wrist_pitch_joint", -1.614429558, 1.614429558, 22.0),
    ] {
        let j = joint(name);
        assert_eq!(j.range, Some([lower, upper]), "{name}");
        assert_eq!(j.velocity_limit, Some(velocity), "{name}");
    }
    assert!(m.joints[1..].iter().all(|j| j.velocity_limit.is_some()));
    // 15 collision cylinders, all kept (the merged links carry none).
    assert_eq!(m.geoms.len(), 15);
    assert!(m.geoms.iter().all(|g| g.kind == GeomType::Cylinder));
}

/// The G1 URDF against our MJCF G1 (`robots/unitree_g1`), body by body. Both come from the same
/// vendor model; where they differ is explained here and tested as such:
/// - the MJCF writes body quaternions to 6 significant digits where the URDF gives rpy, so the
///   local frames agree only after rounding ours the same way (rotations differ by < 5e-7);
/// - the URDF merges its fixed links (MuJoCo's fusestatic); kept as bodies, all but the toes
///   sit where the MJCF puts them (GMR's URDF moves `*_toe_link` to 0.12 0 -0.039, its MJCF
///   has 0.1 0 -0.02);
/// - the MJCF's free joint starts at standing height (qpos0 z = 0.793), the URDF's at 0.
#[test]
fn g1_urdf_matches_the_mjcf_g1_body_by_body() {
    let Some(shared) = shared::shared_dir() else { return };
    let mjcf_path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots/unitree_g1/unitree_g1.xml");
    let xml = Model::from_file(&mjcf_path).unwrap_or_else(|e| panic!("{e}"));
    let kept =
        load(&g1_urdf(&shared), UrdfOptions { base: UrdfBase::Floating, fuse_static: Some(false) });
    for body in &kept.bodies[1..] {
        let other = &xml.bodies[xml.body_id(&body.name).unwrap_or_else(|| panic!("{}", body.name))];
        assert_eq!(xml.bodies[other.parent].name, kept.bodies[body.parent].name, "{}", body.name);
        let round6 =
            |v: f64| if v == 0.0 { 0.0 } else { format!("{v:.5e}").parse::<f64>().unwrap() };
        let q = body.quat;
        let rounded = UnitQuaternion::new_normalize(Quaternion::new(
            round6(q.w),
            round6(q.i),
            round6(q.j),
            round6(q.k),
        ));
        assert!(rounded.angle_to(&other.quat) < 1e-12, "{}: quat", body.name);
        assert!(body.quat.angle_to(&other.quat) < 1e-6, "{}: quat", body.name);
        let dp = (body.pos - other.pos).amax();
        match body.name.as_str() {
            "pelvis" => {} // free joint: its pose is qpos
            "left_toe_link" | "right_toe_link" => assert!(dp > 0.01, "{}", body.name),
            _ => assert!(dp < 1e-15, "{}: pos differs by {dp:e}", body.name),
        }
    }
    // World poses of every body of the default (merged) URDF model at random configurations.
    let urdf = load(&g1_urdf(&shared), UrdfOptions::default());
    let (mut a, mut b) = (Data::new(&urdf), Data::new(&xml));
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut worst = (0.0f64, 0.0f64);
    for _ in 0..100 {
        let q_xml = xml.random_qpos(&mut rng);
        let mut q_urdf = urdf.qpos0.clone();
        q_urdf[..7].copy_from_slice(&q_xml[..7]);
        for j in &urdf.joints[1..] {
            q_urdf[j.qpos_adr] = q_xml[xml.joints[xml.joint_id(&j.name).unwrap()].qpos_adr];
        }
        urdf.kinematics(&q_urdf, &mut a);
        xml.kinematics(&q_xml, &mut b);
        for (i, body) in urdf.bodies.iter().enumerate().skip(1) {
            let k = xml.body_id(&body.name).unwrap();
            worst.0 = worst.0.max((a.xpos[i] - b.xpos[k]).amax());
            worst.1 = worst.1.max(a.xquat[i].angle_to(&b.xquat[k]));
        }
    }
    eprintln!("g1 urdf vs mjcf: max |xpos| {:.2e} m, max angle {:.2e} rad", worst.0, worst.1);
    assert!(worst.0 < 2e-6 && worst.1 < 2e-6, "{worst:?}");
}

#[test]
fn errors_name_file_line_and_column() {
    let link = |name: &str| format!("<link name=\"{name}\"/>");
    let joint = |name: &str, kind: &str, parent: &str, child: &str| {
        format!("<joint name=\"{name}\" type=\"{kind}\"><parent link=\"{parent}\"/><child link=\"{child}\"/></joint>")
    };
    let robot = |body: &str| format!("<robot name=\"r\">{}\n{body}</robot>", link("a"));
    // Link b, fixed to a (fused into it).
    let inertial = |mass: &str, inertia: &str| {
        format!(
            "<link name=\"b\"><inertial>{mass}{inertia}</inertial></link>{}",
            joint("k", "fixed", "a", "b")
        )
    };
    const INERTIA: &str = "<inertia ixx=\"1\" iyy=\"1\" izz=\"1\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>";
    const ZERO_INERTIA: &str =
        "<inertia ixx=\"0\" iyy=\"0\" izz=\"0\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>";
    let cases = [
        (robot(&joint("j", "revolute", "nope", "a")), "<string>:2:41: joint \"j\": parent link \"nope\" does not exist"),
        (robot(&joint("j", "revolute", "a", "nope")), "<string>:2:58: joint \"j\": child link \"nope\" does not exist"),
        (robot(&format!("{}{}", link("b"), joint("j", "hinge", "a", "b"))),
         "<string>:2:33: unknown joint type \"hinge\" (expected revolute, continuous, prismatic, fixed, floating, planar or spherical)"),
        (robot(&format!("{}{}{}", link("b"), link("c"), joint("j", "fixed", "a", "b"))),
         "<string>:2:17: two root links (\"a\" and \"c\")"),
        (robot(&link("a")), "<string>:2:1: repeated link name \"a\""),
        (robot(&format!("{}{}{}{}", link("b"), link("c"), joint("j", "fixed", "a", "b"), joint("j", "fixed", "a", "c"))),
         "<string>:2:105: repeated joint name \"j\""),
        (robot(&format!("{}{}{}", link("b"), joint("j", "fixed", "a", "b"), joint("k", "fixed", "a", "b"))),
         "<string>:2:143: link \"b\" is the child of two joints (\"j\" and \"k\")"),
        (robot(&format!("{}{}{}{}", link("b"), link("c"), joint("j", "fixed", "b", "c"), joint("k", "fixed", "c", "b"))),
         "<string>:2:105: joint \"k\" closes a cycle of links through \"b\""),
        (robot("<joint name=\"j\" type=\"fixed\"><parent link=\"a\"/><child link=\"a\"/></joint>"),
         "<string>:2:1: joint \"j\" closes a cycle of links through \"a\""),
        (robot(&format!("{}<joint name=\"j\" type=\"revolute\"><origin xyz=\"1 2\"/><parent link=\"a\"/><child link=\"b\"/></joint>", link("b"))),
         "<string>:2:57: attribute xyz needs 3 numbers, got \"1 2\""),
        (robot(&format!("{}<joint name=\"j\" type=\"revolute\"><origin rpy=\"0 x 0\"/><parent link=\"a\"/><child link=\"b\"/></joint>", link("b"))),
         "<string>:2:57: attribute rpy: \"x\" is not a finite number"),
        (robot(&format!("{}<joint name=\"j\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/><limit lower=\"-1\" upper=\"1\" velocity=\"-3\"/></joint>", link("b"))),
         "<string>:2:112: velocity must not be negative"),
        (robot(&format!("{}<joint name=\"j\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/><axis xyz=\"0 0 0\"/></joint>", link("b"))),
         "<string>:2:17: joint \"j\": axis has zero length"),
        (robot("<link name=\"b\"><collision><geometry/></collision></link>"),
         "<string>:2:27: <geometry> without <box>, <cylinder>, <sphere>, <capsule> or <mesh>"),
        (robot("<link name=\"b\"><collision><geometry><sphere radius=\"0\"/></geometry></collision></link>"),
         "<string>:2:45: radius must be positive"),
        (robot("<link name=\"b\"><collision><geometry><box size=\"1 1 nan\"/></geometry></collision></link>"),
         "<string>:2:42: attribute size: \"nan\" is not a finite number"),
        (robot("<link/>"), "<string>:2:1: <link> without the required attribute name"),
        (robot("<joint name=\"j\" type=\"fixed\"><child link=\"a\"/></joint>"), "<string>:2:1: <joint> without <parent>"),
        ("<robot xmlns:xacro=\"http://www.ros.org/wiki/xacro\">\n<xacro:include filename=\"x.xacro\"/></robot>".to_owned(),
         "<string>:2:1: unsupported: xacro element: expand the file with xacro first"),
        ("<robot name=\"r\">\n<link name=\"a\"></robot>".to_owned(), "<string>:2:16: invalid xml: expected 'link' tag, not 'robot'"),
        ("<mujoco/>".to_owned(), "<string>:1:1: root element is <mujoco>, expected <robot>"),
        ("<robot name=\"r\"/>".to_owned(), "<string>:1:1: <robot> has no <link>"),
        (robot("<mujoco><compiler coordinate=\"global\"/></mujoco>"),
         "<string>:2:19: global coordinates no longer supported. To convert existing models, load and save them in MuJoCo 2.3.3 or older"),
        (robot("<mujoco><compiler discardvisual=\"no\"/></mujoco>"),
         "<string>:2:19: attribute discardvisual: \"no\" is not true or false"),
        (robot(&format!("{}{}", link("world"), joint("j", "fixed", "a", "world"))),
         "<string>:2:1: a link called \"world\" must be the root link"),
        // <inertial>: MuJoCo's required elements and attributes, and its checks.
        (robot(&inertial("", INERTIA)), "<string>:2:16: <inertial> without <mass>"),
        (robot(&inertial("<mass value=\"1\"/>", "")), "<string>:2:16: <inertial> without <inertia>"),
        (robot(&inertial("<mass/>", INERTIA)), "<string>:2:26: <mass> without the required attribute value"),
        (robot(&inertial("<mass value=\"-1\"/>", INERTIA)), "<string>:2:32: mass must not be negative"),
        (robot(&inertial("<mass value=\"abc\"/>", INERTIA)), "<string>:2:32: attribute value: \"abc\" is not a finite number"),
        (robot(&inertial("<mass value=\"1 2\"/>", INERTIA)), "<string>:2:32: attribute value needs 1 numbers, got \"1 2\""),
        (robot(&inertial("<mass value=\"1\"/>", "<inertia ixx=\"1\" iyy=\"1\" izz=\"1\" ixz=\"0\" iyz=\"0\"/>")),
         "<string>:2:43: <inertia> without the required attribute ixy"),
        (robot(&format!("<link name=\"b\"><inertial><mass value=\"1\"/>{INERTIA}</inertial><inertial/></link>")),
         "<string>:2:112: repeated <inertial> in a link"),
        (robot(&inertial("<mass value=\"1\"/>", "<inertia ixx=\"1\" iyy=\"1\" izz=\"1\" ixy=\"2\" ixz=\"0\" iyz=\"0\"/>")),
         "<string>:2:16: <inertia>: inertia must have positive eigenvalues"),
        (robot(&inertial("<mass value=\"1\"/>", "<inertia ixx=\"1\" iyy=\"1\" izz=\"3\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>")),
         "<string>:2:16: inertia must satisfy A + B >= C; use 'balanceinertia' to fix"),
        // A point mass (all-zero <inertia>) fused into a massless body has no principal axes.
        (robot(&inertial("<mass value=\"1\"/>", ZERO_INERTIA)),
         "<string>:2:16: link \"b\" fused into its parent: inertia must have positive eigenvalues"),
        (robot("<mujoco><compiler boundmass=\"x\"/></mujoco>"), "<string>:2:19: attribute boundmass: \"x\" is not a finite number"),
    ];
    for (urdf, expected) in &cases {
        let message = match Model::from_urdf_str(urdf, UrdfOptions::default()) {
            Ok(_) => panic!("no error for {urdf}"),
            Err(e) => e.to_string(),
        };
        assert!(message.starts_with(expected), "\n got: {message}\nwant: {expected}\n  in: {urdf}");
    }
    // A fixed-base robot (root link "world") needs the fixed base.
    let fixed_arm = format!(
        "<robot name=\"r\">{}{}\n{}</robot>",
        link("world"),
        link("arm"),
        joint("j", "revolute", "world", "arm")
    );
    let err = Model::from_urdf_str(&fixed_arm, UrdfOptions::default()).unwrap_err().to_string();
    assert!(err.starts_with("<string>:1:17: the root link is called \"world\""), "{err}");
    let arm =
        Model::from_urdf_str(&fixed_arm, UrdfOptions { base: UrdfBase::Fixed, fuse_static: None })
            .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((body_names(&arm), arm.nq), (vec!["world", "arm"], 1));
    let missing =
        Model::from_urdf_file(Path::new("/nonexistent/robot.urdf"), UrdfOptions::default());
    assert!(missing
        .unwrap_err()
        .to_string()
        .starts_with("/nonexistent/robot.urdf: cannot read file"));
}

/// A floating base added to the fixed robot is the free root the URDF reader adds itself.
#[test]
fn floating_base_added_later_is_the_urdf_free_root() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/urdf/features.urdf");
    // Unfused: fixed to the world, the root link would be fused into it.
    let fixed = UrdfOptions { base: UrdfBase::Fixed, fuse_static: Some(false) };
    let mut m = Model::from_urdf_file(&path, fixed).unwrap();
    let floating =
        Model::from_urdf_file(&path, UrdfOptions { base: UrdfBase::Floating, ..fixed }).unwrap();
    let root = m.root_body().unwrap();
    let (pos, quat) = (m.bodies[root].pos, m.bodies[root].quat);
    let base = m.add_floating_base(pos, quat).unwrap();
    assert_eq!(base.joint, floating.joints[0].name);
    assert_eq!(m, floating);
    assert_eq!(m.clone().add_floating_base(pos, quat), None, "a second one is not added");
}
