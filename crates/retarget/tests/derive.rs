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

#[test]
fn print_g1() {
    let Some(bvh) = lafan_walk() else { return };
    for key in ["unitree_g1", "booster_t1_29dof", "fourier_n1", "engineai_pm01", "stanford_toddy"] {
        let (model, tuned) = shipped(key);
        let roles = RobotRoles::recognise(&model).unwrap();
        let human = derive::human_body(&bvh, &fk::FkOptions::default(), "walk").unwrap();
        let config = derive::derive(&model, &roles, &human, "derived").unwrap();
        println!("== {key}: height {}", config.human_height_assumption);
        for (n, s) in &config.human_scale_table {
            print!("{n}={s:.3} ");
        }
        println!();
        for e in &config.ik_match_table1 {
            let t = tuned.ik_match_table1.iter().find(|t| {
                t.human_body == e.human_body || t.human_body == format!("{}Mod", e.human_body)
            });
            let diff = t
                .map(|t| (t.robot_body.clone(), e.rot_offset.angle_to(&t.rot_offset).to_degrees()));
            println!(
                "{:<28} {:<14} pos {:.3?} rot {:.3?} vs {:?}",
                e.robot_body,
                e.human_body,
                e.pos_offset.as_slice(),
                e.rot_offset.coords.as_slice(),
                diff
            );
        }
    }
}
