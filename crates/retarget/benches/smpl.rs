//! SMPL FK plus retargeting against the BVH path (issue 31): frames/s of
//! `Retargeter::retarget_smpl` on the synthetic SMPL-X walk (120 fps) and of
//! `Retargeter::retarget_bvh` on the LAFAN1 walk (30 fps), first 1200 frames of each (GMR's path resamples the SMPL-X walk to 30 fps and solves
//! a quarter of them; the rate is per source frame), the G1
//! with its tuned configs, both solves, one clip at a time. Needs `RETARGET_SHARED`; prints a
//! note and measures nothing without it.

use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use retarget::{Retargeter, SolveMode};

fn shared() -> Option<PathBuf> {
    std::env::var_os("RETARGET_SHARED").map(PathBuf::from)
}

const FRAMES: usize = 1200;

fn bench(c: &mut Criterion) {
    let Some(shared) = shared() else {
        eprintln!("note: RETARGET_SHARED is not set; skipping the SMPL retargeting benchmark");
        return;
    };
    let dir = shared.join("reference/smpl");
    let models = smpl::BodyModels::new(Some(&dir.join("body_models")));
    let motion = smpl::SmplMotion::from_path(&dir.join("motions/smplx_walk_stageii.npz"))
        .unwrap()
        .slice(0..FRAMES);
    let body = models.for_motion(&motion, None).unwrap();
    let mut bvh =
        bvh::from_path(&shared.join("data/bvh/lafan1_take_via_bvhtools_test.bvh")).unwrap();
    bvh.motion.truncate(FRAMES);
    let mut group = c.benchmark_group("retarget");
    group.sample_size(10);
    group.throughput(Throughput::Elements(FRAMES as u64));
    for (name, mode) in [("default", SolveMode::default()), ("gmr", SolveMode::Gmr)] {
        let r = Retargeter::new("unitree_g1").unwrap().with_mode(mode.clone());
        group.bench_function(format!("bvh_lafan1_walk_{name}_frames"), |b| {
            b.iter(|| r.retarget_bvh(&bvh).unwrap());
        });
        group.bench_function(format!("smplx_walk_{name}_source_frames"), |b| {
            b.iter(|| r.retarget_smpl(&motion, &body).unwrap());
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
