//! Parse (and write) throughput on the 5 MB LAFAN1 take: MB/s and frames/s.
//!
//! The file is `$RETARGET_SHARED/data/bvh/lafan1_take_via_bvhtools_test.bvh` or, after
//! `scripts/fetch-samples`, `data/samples/lafan1_walk.bvh`; without either the benchmark
//! says so and measures nothing.

use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};

fn input() -> Option<(PathBuf, Vec<u8>)> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let shared = std::env::var_os("RETARGET_SHARED").map(|d| {
        let d = PathBuf::from(d);
        if d.is_relative() {
            root.join(d)
        } else {
            d
        }
    });
    let candidates = shared
        .map(|d| d.join("data/bvh/lafan1_take_via_bvhtools_test.bvh"))
        .into_iter()
        .chain([root.join("data/samples/lafan1_walk.bvh")]);
    candidates.into_iter().find_map(|p| std::fs::read(&p).ok().map(|bytes| (p, bytes)))
}

fn benches(c: &mut Criterion) {
    let Some((path, bytes)) = input() else {
        eprintln!("note: no LAFAN1 take found (set RETARGET_SHARED or run scripts/fetch-samples)");
        return;
    };
    let bvh = bvh::parse(&bytes).expect("the benchmark input parses");
    let frames = bvh.motion.num_frames as u64;
    eprintln!("input: {} ({} bytes, {frames} frames)", path.display(), bytes.len());

    let mut group = c.benchmark_group("parse");
    group.throughput(Throughput::Bytes(bytes.len() as u64));
    group.bench_function("bytes", |b| b.iter(|| bvh::parse(&bytes).unwrap()));
    group.throughput(Throughput::Elements(frames));
    group.bench_function("frames", |b| b.iter(|| bvh::parse(&bytes).unwrap()));
    group.finish();

    let mut out = Vec::with_capacity(bytes.len() * 2);
    let mut group = c.benchmark_group("write");
    group.throughput(Throughput::Elements(frames));
    group.bench_function("bvh", |b| {
        b.iter(|| {
            out.clear();
            bvh::write(&bvh, &mut out).unwrap();
        })
    });
    group.bench_function("json", |b| {
        b.iter(|| {
            out.clear();
            bvh::write_json(&bvh, &mut out).unwrap();
        })
    });
    group.finish();
}

criterion_group!(parse, benches);
criterion_main!(parse);
