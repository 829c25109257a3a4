//! Reading and posing SMPL-X / SMPL+H (issue 31): a body model file read (ms), forward
//! kinematics of an AMASS motion (frames/s), GMR's 30 fps loader (source frames/s), beside
//! `fk`'s BVH forward kinematics on the LAFAN1 walk. Needs `RETARGET_SHARED`; prints a note
//! and measures nothing without it.

use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};

fn shared() -> Option<PathBuf> {
    std::env::var_os("RETARGET_SHARED").map(PathBuf::from)
}

fn bench(c: &mut Criterion) {
    let Some(shared) = shared() else {
        eprintln!("note: RETARGET_SHARED is not set; skipping the SMPL benchmark");
        return;
    };
    let dir = shared.join("reference/smpl");
    let model_path = dir.join("body_models/smplx/SMPLX_NEUTRAL.npz");
    let mut group = c.benchmark_group("smpl");
    group.sample_size(10);
    group.bench_function("read_smplx_model", |b| {
        b.iter(|| smpl::BodyModel::from_path(&model_path, None).unwrap());
    });
    let model = smpl::BodyModel::from_path(&model_path, None).unwrap();
    let motion = smpl::SmplMotion::from_path(&dir.join("motions/smplx_walk_stageii.npz")).unwrap();
    group.throughput(Throughput::Elements(motion.num_frames() as u64));
    group.bench_function("read_smplx_walk_frames", |b| {
        b.iter(|| {
            smpl::SmplMotion::from_path(&dir.join("motions/smplx_walk_stageii.npz")).unwrap()
        });
    });
    group.bench_function("fk_smplx_walk_frames", |b| {
        b.iter(|| smpl::forward(&model, &motion).unwrap())
    });
    group.bench_function("clip_smplx_walk_frames", |b| {
        b.iter(|| smpl::clip(&model, &motion).unwrap())
    });
    group.bench_function("gmr_loader_smplx_walk_source_frames", |b| {
        b.iter(|| smpl::gmr::offline_fast(&model, &motion, 30.0).unwrap());
    });
    let bvh = bvh::from_path(&shared.join("data/bvh/lafan1_take_via_bvhtools_test.bvh")).unwrap();
    group.throughput(Throughput::Elements(bvh.motion.num_frames as u64));
    group.bench_function("fk_bvh_lafan1_walk_frames", |b| {
        b.iter(|| fk::human_motion(&bvh, &fk::FkOptions::default()).unwrap());
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
