//! The quality report's cost on the LAFAN1 walk (7,184 frames, unitree_g1, `--gmr` solve at a
//! 1.75 m subject): the whole report, and the dynamics check alone (frames/s). Needs
//! `data/samples/lafan1_walk.bvh` (scripts/fetch-samples); prints a note and measures nothing
//! without it.

use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use retarget::report::{dynamics_frames, report, ReportOptions};
use retarget::{Retargeter, SolveMode};

fn bench_report(c: &mut Criterion) {
    let walk = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/samples/lafan1_walk.bvh");
    if !walk.is_file() {
        eprintln!("note: {} is missing; skipping the report benchmark", walk.display());
        return;
    }
    let retargeter = Retargeter::shipped("unitree_g1")
        .unwrap()
        .with_mode(SolveMode::Gmr)
        .with_human_height(Some(1.75));
    let (motion, _) = retargeter.retarget_bvh_file(&walk).unwrap();
    let model = retargeter.model();
    let opts = ReportOptions::default();
    let mut group = c.benchmark_group("report");
    group.throughput(Throughput::Elements(motion.num_frames() as u64));
    group.sample_size(10);
    group.bench_function("lafan1_walk_g1_whole_report", |b| {
        b.iter(|| std::hint::black_box(report(&motion, model, &opts).unwrap()));
    });
    group.bench_function("lafan1_walk_g1_dynamics_check", |b| {
        b.iter(|| std::hint::black_box(dynamics_frames(&motion, model, &opts).unwrap()));
    });
    group.finish();
}

criterion_group!(benches, bench_report);
criterion_main!(benches);
