//! Kinematics speed on the Unitree G1 (29 hinges + free joint): FK alone, and FK plus the 14
//! body Jacobians GMR's G1 config tracks. Goals: FK <= 2 µs, FK + 14 Jacobians <= 10 µs.
//!
//! The model is the repo's `robots/unitree_g1/unitree_g1.xml`, else the reference model under
//! `$RETARGET_SHARED/reference/robots/unitree_g1/`.

use std::hint::black_box;
use std::path::{Path, PathBuf};

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use mjcf::{Data, Model};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// The bodies of GMR's `ik_match_table1` for the G1.
const TRACKED: [&str; 14] = [
    "pelvis",
    "left_hip_yaw_link",
    "left_knee_link",
    "left_ankle_roll_link",
    "right_hip_yaw_link",
    "right_knee_link",
    "right_ankle_roll_link",
    "torso_link",
    "left_shoulder_yaw_link",
    "left_elbow_link",
    "left_wrist_yaw_link",
    "right_shoulder_yaw_link",
    "right_elbow_link",
    "right_wrist_yaw_link",
];

fn g1_path() -> Option<PathBuf> {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots/unitree_g1/unitree_g1.xml");
    if repo.is_file() {
        return Some(repo);
    }
    let shared = PathBuf::from(std::env::var_os("RETARGET_SHARED")?);
    let shared = if shared.is_relative() {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(shared)
    } else {
        shared
    };
    Some(shared.join("reference/robots/unitree_g1/g1_mocap_29dof.xml")).filter(|p| p.is_file())
}

fn kinematics(c: &mut Criterion) {
    let Some(path) = g1_path() else {
        eprintln!(
            "no G1 model: add robots/unitree_g1/unitree_g1.xml or set RETARGET_SHARED; skipping"
        );
        return;
    };
    let model = Model::from_file(&path).expect("G1 model compiles");
    let tracked: Vec<usize> = TRACKED.iter().filter_map(|n| model.body_id(n)).collect();
    assert_eq!(tracked.len(), TRACKED.len(), "G1 model lacks a tracked body");
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let configs: Vec<Vec<f64>> = (0..64).map(|_| model.random_qpos(&mut rng)).collect();
    let mut data = Data::new(&model);
    let (mut jacp, mut jacr) = (vec![0.0; 3 * model.nv], vec![0.0; 3 * model.nv]);

    let mut group = c.benchmark_group("g1");
    group.throughput(Throughput::Elements(1));
    let mut i = 0;
    group.bench_function("fk", |b| {
        b.iter(|| {
            i = (i + 1) % configs.len();
            model.kinematics(black_box(&configs[i]), &mut data);
            black_box(&data.xpos);
        });
    });
    group.bench_function("fk_plus_14_jacobians", |b| {
        b.iter(|| {
            i = (i + 1) % configs.len();
            model.kinematics(black_box(&configs[i]), &mut data);
            for &body in &tracked {
                model.jac_body(&data, body, &mut jacp, &mut jacr);
                black_box((&jacp, &jacr));
            }
        });
    });
    group.finish();
}

criterion_group!(benches, kinematics);
criterion_main!(benches);
