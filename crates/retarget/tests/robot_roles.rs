//! The robot recogniser on every shipped and reference robot, and on small robots we write.

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::{Path, PathBuf};

use fk::Role;
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

/// Every reference robot is recognised, with its left leg and arm on its left (+y: they all
/// face +x at `qpos0`) and feet below hips below shoulders.
#[test]
fn every_reference_robot_is_recognised() {
    let models = reference_models();
    if models.is_empty() {
        return;
    }
    assert_eq!(models.len(), 19);
    for path in models {
        let model = load(&path);
        let roles =
            RobotRoles::recognise(&model).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let what = path.display();
        // Forward is perpendicular to the hips' axis: within 1e-2 of +x, because kuavo_s45's
        // two hips are 1.6 mrad off the y axis at qpos0.
        let off = (roles.forward - nalgebra::Vector3::x()).norm();
        assert!(off < 1e-2, "{what}: forward {:?} ({})", roles.forward, roles.facing);
        let point = |r: Role| roles.roles[&r].point;
        for (l, r) in
            [(Role::LeftThigh, Role::RightThigh), (Role::LeftUpperArm, Role::RightUpperArm)]
        {
            assert!(point(l).y > point(r).y, "{what}: {l} left of {r}");
        }
        assert!(point(Role::LeftFoot).z < point(Role::LeftShin).z, "{what}");
        assert!(point(Role::LeftShin).z < point(Role::LeftThigh).z, "{what}");
        assert!(point(Role::LeftThigh).z < point(Role::LeftUpperArm).z, "{what}");
        for side in 0..2 {
            assert!(roles.soles[side].lowest.z < point(Role::LeftShin).z, "{what}");
        }
    }
}

/// GMR's body choices where they follow the rule (see `robot_roles` docs): every role body of
/// the G1 is GMR's, on the T1 the legs and forearms.
#[test]
fn shipped_g1_and_t1_roles_match_gmr_where_the_rule_says() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let g1 = load(&root.join("robots/unitree_g1/unitree_g1.xml"));
    let roles = RobotRoles::recognise(&g1).unwrap();
    let name = |r: Role| roles.roles[&r].name.clone();
    for (role, body) in [
        (Role::Pelvis, "pelvis"),
        (Role::Chest, "torso_link"),
        (Role::LeftThigh, "left_hip_yaw_link"),
        (Role::LeftShin, "left_knee_link"),
        (Role::LeftFoot, "left_ankle_roll_link"),
        (Role::RightUpperArm, "right_shoulder_yaw_link"),
        (Role::RightForearm, "right_elbow_link"),
        (Role::RightHand, "right_wrist_yaw_link"),
    ] {
        assert_eq!(name(role), body, "{role}");
    }
    let [l, r] = roles.soles();
    assert_eq!(g1.geoms[l.geoms[0]].name, "left_sole");
    assert_eq!(g1.geoms[r.geoms[0]].name, "right_sole");
    let t1 = load(&root.join("robots/booster_t1_29dof/booster_t1_29dof.xml"));
    let roles = RobotRoles::recognise(&t1).unwrap();
    let name = |r: Role| roles.roles[&r].name.clone();
    assert_eq!(name(Role::Pelvis), "Waist");
    assert_eq!(name(Role::Chest), "Trunk");
    assert_eq!(name(Role::LeftThigh), "Hip_Yaw_Left");
    assert_eq!(name(Role::LeftShin), "Shank_Left");
    assert_eq!(name(Role::LeftFoot), "left_foot_link");
    assert_eq!(name(Role::LeftForearm), "AL4");
}
