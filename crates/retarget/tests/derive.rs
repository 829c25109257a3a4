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
        let bound = derive::bind(&written, &human).unwrap();
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
