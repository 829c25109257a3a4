//! Read and write throughput (MB/s) on a synthetic trial: 60 markers, 8 analog channels at
//! 10 samples per frame, 6000 frames, Intel float and integer.

use std::hint::black_box;
use std::io::Cursor;

use c3d::{Analog, C3d, Format, Point, Points};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};

fn trial() -> C3d {
    let frames = 6000;
    let mut c = C3d::new(100.0);
    c.points = Points::new((0..60).map(|i| format!("M{i}")).collect(), frames);
    for f in 0..frames {
        for p in 0..60 {
            let v = (f * 60 + p) as f32 * 0.01;
            let point = Point { position: [v, -v, 0.5 * v], residual: 0.5, cameras: 3 };
            c.points.set(f, p, (p % 17 != 0).then_some(point));
        }
    }
    c.analog = Analog::new((0..8).map(|i| format!("A{i}")).collect(), 1000.0, 10, frames);
    for s in 0..c.analog.sample_count() {
        for ch in 0..8 {
            c.analog.set(s, ch, ((s + ch) % 200) as f32 * 0.05);
        }
    }
    c
}

fn bench(crit: &mut Criterion) {
    let c = trial();
    for (name, format) in [("float", Format::INTEL_FLOAT), ("int", Format::INTEL_INT)] {
        let mut bytes = Vec::new();
        c.write(&mut bytes, format).unwrap();
        let mut group = crit.benchmark_group(format!("c3d_{name}"));
        group.throughput(Throughput::Bytes(bytes.len() as u64));
        group.bench_function("read", |b| {
            b.iter(|| C3d::from_reader(Cursor::new(black_box(&bytes))).unwrap())
        });
        group.bench_function("write", |b| {
            b.iter(|| {
                let mut out = Vec::with_capacity(bytes.len());
                c.write(&mut out, format).unwrap();
                out
            })
        });
        group.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
