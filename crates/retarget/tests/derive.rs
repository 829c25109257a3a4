//! Derived IK configs: on the shipped robots against GMR's tuned ones, role-named binding.

#[path = "../../../tests/support/shared.rs"]
mod shared;

use std::path::PathBuf;

use retarget::derive::{self, HumanBody};
use retarget::{IkConfig, RobotRoles};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn shipped(key: &str) -> (mjcf::Model, IkConfig) {
    let model = mjcf::Model::from_file(&root().join(format!("robots/{key}/{key}.xml"))).unwrap();
    let config =
        IkConfig::from_file(&root().join(format!("configs/bvh_lafan1_to_{key}.json"))).unwrap();
    (model, config)
}

fn lafan_walk() -> Option<bvh::Bvh> {
    let path = root().join("data/samples/lafan1_walk.bvh");
    if path.is_file() {
        return Some(bvh::from_path(&path).unwrap());
    }
    let path = shared::shared_file("data/bvh/lafan1_take_via_bvhtools_test.bvh")?;
    Some(bvh::from_path(&path).unwrap())
}

/// A role-named config (`retarget robot init` without `--bvh`) bound to a skeleton is the
/// config derived for that skeleton directly, on every robot with a GMR config.
#[test]
fn binding_a_role_named_config_equals_deriving_for_the_skeleton() {
    let Some(bvh) = lafan_walk() else { return };
    let human = derive::human_body(&bvh, &fk::FkOptions::default(), "walk").unwrap();
    for key in ["unitree_g1", "booster_t1_29dof", "fourier_n1", "engineai_pm01", "stanford_toddy"] {
        let (model, _) = shipped(key);
        let roles = RobotRoles::recognise(&model).unwrap();
        let canonical = derive::derive(&model, &roles, &HumanBody::canonical(), "c").unwrap();
        assert!(derive::is_role_named(&canonical), "{key}");
        let written = IkConfig::from_json_str(canonical.json(), "written").unwrap();
        let bound = derive::bind(&written, &human, &model, &roles).unwrap();
        let direct = derive::derive(&model, &roles, &human, "d").unwrap();
        assert!(!derive::is_role_named(&direct), "{key}");
        assert!((bound.human_height_assumption - direct.human_height_assumption).abs() < 1e-6);
        assert_eq!(bound.human_scale_table.len(), direct.human_scale_table.len());
        for ((a, s), (b, t)) in bound.human_scale_table.iter().zip(&direct.human_scale_table) {
            assert_eq!(a, b, "{key}");
            assert!((s - t).abs() < 1e-6, "{key} {a}: {s} vs {t}");
        }
        for (e, f) in bound.ik_match_table2.iter().zip(&direct.ik_match_table2) {
            assert_eq!((&e.robot_body, &e.human_body), (&f.robot_body, &f.human_body));
            assert_eq!((e.pos_weight, e.rot_weight), (f.pos_weight, f.rot_weight));
            assert!(e.rot_offset.angle_to(&f.rot_offset) < 1e-6, "{key} {}", e.robot_body);
            assert!((e.pos_offset - f.pos_offset).norm() < 1e-6, "{key} {}", e.robot_body);
        }
        // On LAFAN1 the derived offsets are near GMR's tuned ones (its 90° guesses): the
        // trunk and legs within 30°.
        let (_, tuned) = shipped(key);
        for e in direct.ik_match_table1.iter().filter(|e| {
            ["Hips", "LeftUpLeg", "RightUpLeg", "LeftLeg", "RightLeg"]
                .contains(&e.human_body.as_str())
        }) {
            if let Some(t) = tuned.ik_match_table1.iter().find(|t| t.robot_body == e.robot_body) {
                let angle = e.rot_offset.angle_to(&t.rot_offset).to_degrees();
                assert!(angle < 30.0, "{key} {}: {angle:.1}°", e.robot_body);
            }
        }
    }
}

/// The feet are fitted so that the sole is on the floor when the human rolls onto the ball
/// of the foot: the G1's sole reaches farther ahead of its ankle than the scaled human foot,
/// so its ankle target sits behind the human's (foot frame x, the G1's foot body frame at
/// `qpos0` being the canonical one), and a few millimetres above the flat-foot height.
#[test]
fn a_sole_longer_than_the_scaled_foot_is_moved_back() {
    let Some(bvh) = lafan_walk() else { return };
    let human = derive::human_body(&bvh, &fk::FkOptions::default(), "walk").unwrap();
    let (model, _) = shipped("unitree_g1");
    let roles = RobotRoles::recognise(&model).unwrap();
    let config = derive::derive(&model, &roles, &human, "g1").unwrap();
    for foot in ["left_ankle_roll_link", "right_ankle_roll_link"] {
        let e = config.ik_match_table1.iter().find(|e| e.robot_body == foot).unwrap();
        assert!(e.pos_offset.x < -0.003, "{foot}: {:?}", e.pos_offset);
        assert!(e.pos_offset.z.abs() < 0.02, "{foot}: {:?}", e.pos_offset);
    }
}

/// A robot whose arms hang from its pelvis body (no waist: Berkeley Humanoid Lite) has no
/// chest role; its pelvis is tracked with the chest's rotation weight, so that arms which
/// cannot reach their targets do not tilt it. With a chest (the G1) the pelvis keeps GMR's.
#[test]
fn a_pelvis_that_is_also_the_chest_gets_the_chest_weights() {
    let Some(bvh) = lafan_walk() else { return };
    let Some(path) = shared::shared_file("reference/robots/berkeley_humanoid_lite/bhl_scene.xml")
    else {
        return;
    };
    let human = derive::human_body(&bvh, &fk::FkOptions::default(), "walk").unwrap();
    let pelvis_weights = |model: &mjcf::Model, chest: bool| {
        let roles = RobotRoles::recognise(model).unwrap();
        assert_eq!(roles.roles.contains_key(&fk::Role::Chest), chest);
        let config = derive::derive(model, &roles, &human, "c").unwrap();
        let root = &config.robot_root_name;
        let rot = |t: &[retarget::MatchEntry]| {
            t.iter().find(|e| &e.robot_body == root).unwrap().rot_weight
        };
        (rot(&config.ik_match_table1), rot(&config.ik_match_table2))
    };
    let bhl = mjcf::Model::from_path(&path).unwrap();
    assert_eq!(pelvis_weights(&bhl, false), (100.0, 10.0));
    assert_eq!(pelvis_weights(&shipped("unitree_g1").0, true), (10.0, 5.0));
}
