//! Solver throughput on the LAFAN1 walk take (GMR's G1 config, 1.75 m subject): frames/s of
//! the IK alone, one thread. Needs `RETARGET_SHARED`; prints a note and measures nothing
//! without it.

use std::path::{Path, PathBuf};

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use retarget::internals::task_specs;
use retarget::internals::Pose;
use retarget::internals::Solver;
use retarget::internals::TargetMap;
use retarget::{IkConfig, SolverOptions};

fn shared() -> Option<PathBuf> {
    std::env::var_os("RETARGET_SHARED").map(PathBuf::from)
}

fn bench_solve(c: &mut Criterion) {
    let Some(shared) = shared() else {
        eprintln!("note: RETARGET_SHARED is not set; skipping the solver benchmark");
        return;
    };
    let bvh = bvh::from_path(&shared.join("data/bvh/lafan1_take_via_bvhtools_test.bvh")).unwrap();
    let model =
        mjcf::Model::from_file(&shared.join("reference/robots/unitree_g1/g1_mocap_29dof.xml"))
            .unwrap();
    let config_path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/gmr/bvh_lafan1_to_g1.json");
    let config = IkConfig::from_file(&config_path).unwrap();
    let (human, _) = fk::human_motion(&bvh, &fk::FkOptions::default()).unwrap();
    let map = TargetMap::new(&config, &human.body_names, 1.75).unwrap();
    let stages = task_specs(&config, &model, &map);
    let nb = human.num_bodies();
    let frames = human.num_frames.min(2000);
    let mut targets = Vec::with_capacity(frames);
    for f in 0..frames {
        let mut poses =
            vec![Pose { quat: [1.0, 0.0, 0.0, 0.0], pos: Default::default() }; map.bodies.len()];
        let r = f * nb..(f + 1) * nb;
        map.compute(&human.positions[r.clone()], &human.orientations[r], &mut poses);
        targets.push(poses);
    }
    let mut group = c.benchmark_group("solver");
    group.throughput(Throughput::Elements(frames as u64));
    group.sample_size(10);
    group.bench_function("lafan1_walk_g1_frames", |b| {
        b.iter(|| {
            let mut solver = Solver::new(&model, &stages, SolverOptions::default()).unwrap();
            for t in &targets {
                std::hint::black_box(solver.solve_frame(t, 1.0 / 30.0).ok());
            }
        });
    });
    group.finish();
}

criterion_group!(benches, bench_solve);
criterion_main!(benches);
