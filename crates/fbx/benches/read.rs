//! FBX reading throughput, MB/s of file: ufbx's load with our skeleton and take info
//! (`load`), the default take sampled into a BVH (`take`, load included; `sample_frames`:
//! frames/s of the sampling alone), and for comparison `fbxcel`'s
//! token tree of the same bytes (`fbxcel_tree`: binary 7.4/7.5 only, no semantics; the
//! library we did not choose, see docs/fbx.md).
//!
//! Inputs: the four files of `$RETARGET_SHARED/data/fbx` (binary 7.4, 7.5, 7.7), else our
//! ASCII fixtures (`crates/fbx/tests/data`).

use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};

fn inputs() -> Vec<(String, Vec<u8>)> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let shared = std::env::var_os("RETARGET_SHARED").map(|d| {
        let d = PathBuf::from(d);
        if d.is_relative() {
            root.join("../..").join(d)
        } else {
            d
        }
    });
    let dir = shared.map(|d| d.join("data/fbx")).filter(|d| d.is_dir());
    let dir = dir.unwrap_or_else(|| root.join("tests/data"));
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map(|e| e.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    paths.retain(|p| p.extension().is_some_and(|e| e == "fbx"));
    paths.sort();
    paths
        .into_iter()
        .filter_map(|p| {
            let bytes = std::fs::read(&p).ok()?;
            let name = p.file_stem()?.to_string_lossy().into_owned();
            fbx::Fbx::from_bytes(&bytes, &name).ok()?.select_take(None).ok()?;
            Some((name, bytes))
        })
        .collect()
}

fn benches(c: &mut Criterion) {
    let files = inputs();
    if files.is_empty() {
        eprintln!("note: no FBX input found");
        return;
    }
    for (name, bytes) in &files {
        let mut group = c.benchmark_group(name.as_str());
        group.throughput(Throughput::Bytes(bytes.len() as u64));
        group.sample_size(20);
        group.bench_function("load", |b| b.iter(|| fbx::Fbx::from_bytes(bytes, name).unwrap()));
        group.bench_function("take", |b| {
            b.iter(|| {
                let file = fbx::Fbx::from_bytes(bytes, name).unwrap();
                let take = file.select_take(None).unwrap();
                file.bvh(take.index).unwrap()
            })
        });
        let file = fbx::Fbx::from_bytes(bytes, name).unwrap();
        let take = file.select_take(None).unwrap().index;
        let frames = file.info().takes[take].frames as u64;
        group.throughput(Throughput::Elements(frames));
        group.bench_function("sample_frames", |b| b.iter(|| file.bvh(take).unwrap()));
        group.throughput(Throughput::Bytes(bytes.len() as u64));
        let binary = bytes.starts_with(b"Kaydara FBX Binary");
        if binary {
            group.bench_function("fbxcel_tree", |b| {
                b.iter(|| {
                    fbxcel::tree::any::AnyTree::from_seekable_reader(std::io::Cursor::new(bytes))
                        .unwrap()
                })
            });
        }
        group.finish();
    }
}

criterion_group!(read, benches);
criterion_main!(read);
