//! Full-clip FK throughput: the LAFAN1 walk take (7,184 frames, 22 joints + 5 End Sites),
//! from the shared reference data or the README sample. Goal: ≤ 10 ms per clip on one core.
//!
//! `RETARGET_SHARED=/work/shared cargo bench -p fk`

use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};

#[path = "../../../tests/support/shared.rs"]
mod shared;

fn clip() -> Option<PathBuf> {
    let shared = shared::shared_file("data/bvh/lafan1_take_via_bvhtools_test.bvh");
    let sample =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/samples/lafan1_walk.bvh");
    shared.into_iter().chain([sample]).find(|p| p.is_file())
}

fn bench(c: &mut Criterion) {
    let Some(path) = clip() else {
        eprintln!(
            "note: no LAFAN1 clip ($RETARGET_SHARED/data/bvh or data/samples); skipping fk bench"
        );
        return;
    };
    let bvh = bvh::from_path(&path).expect("the LAFAN1 clip parses");
    let options = fk::FkOptions::default();
    let mut group = c.benchmark_group("fk");
    group.throughput(Throughput::Elements(bvh.motion.num_frames as u64));
    group.bench_function("human_motion/lafan1_7184_frames", |b| {
        b.iter(|| fk::human_motion(std::hint::black_box(&bvh), &options).expect("fk"))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
