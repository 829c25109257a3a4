//! The IK step's QP at our size: the G1 (nv = 35) with GMR's 14 body tasks at random
//! configurations near the robot's home pose, its joint-range bounds, and the rows the
//! default solve adds (the four lowest corners of each sole below the floor plane, a few
//! self-collision-like rows). Our Goldfarb–Idnani solver ([`DenseQp`]), with the dense
//! factorisation and on the dof tree as the solver runs it ([`DenseQp::set_tree`]), against
//! `clarabel` (an interior-point solver) on the same problems; all reach the same minimiser
//! (checked before timing). Runs without reference data.

use std::path::Path;

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rand::{Rng, SeedableRng};
use retarget::internals::{DenseQp, QpStatus};

const BODIES: [&str; 14] = [
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

/// `count` problems: H = Σ w² JᵀJ + λI, random c, range bounds around q, sole-corner rows
/// whose floor sits a little above the corners (so some bind), and random sparse rows.
fn problems(model: &mjcf::Model, count: usize) -> Vec<DenseQp> {
    let nv = model.nv;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let mut data = mjcf::Data::new(model);
    let (mut jacp, mut jacr) = (vec![0.0; 3 * nv], vec![0.0; 3 * nv]);
    let bodies: Vec<usize> = BODIES.iter().map(|b| model.body_id(b).unwrap()).collect();
    let soles: Vec<usize> =
        ["left_sole", "right_sole"].iter().map(|g| model.geom_id(g).unwrap()).collect();
    (0..count)
        .map(|_| {
            let mut q = model.qpos0.clone();
            for joint in model.joints.iter().filter(|j| j.range.is_some()) {
                let [lo, hi] = joint.range.unwrap();
                q[joint.qpos_adr] = rng.gen_range(lo * 0.3..hi * 0.3);
            }
            model.kinematics(&q, &mut data);
            let mut qp = DenseQp::new(nv);
            for &b in &bodies {
                model.jac_body(&data, b, &mut jacp, &mut jacr);
                let w: f64 = rng.gen_range(5.0..50.0);
                for jac in [&jacp, &jacr] {
                    for r in 0..3 {
                        let row = &jac[r * nv..(r + 1) * nv];
                        let e: f64 = rng.gen_range(-0.05..0.05);
                        for i in 0..nv {
                            qp.c[i] -= w * w * e * row[i];
                            for j in 0..nv {
                                qp.h[i * nv + j] += w * w * row[i] * row[j];
                            }
                        }
                    }
                }
            }
            for i in 0..nv {
                qp.h[i * nv + i] += 0.5;
            }
            for joint in model.joints.iter() {
                if let Some([lo, hi]) = joint.range {
                    let v = q[joint.qpos_adr];
                    qp.lb[joint.dof_adr] = 0.95 * (lo - v);
                    qp.ub[joint.dof_adr] = 0.95 * (hi - v);
                }
            }
            for &g in &soles {
                let (c, r, s) = (data.geom_xpos[g], data.geom_xmat[g], model.geoms[g].size);
                for k in 0..4 {
                    let sx = if k & 1 == 0 { -1.0 } else { 1.0 };
                    let sy = if k & 2 == 0 { -1.0 } else { 1.0 };
                    let p = c + r * nalgebra::Vector3::new(sx * s[0], sy * s[1], -s[2]);
                    model.jac(&data, model.geoms[g].body, &p, &mut jacp, &mut jacr);
                    // Floor 0–1 cm above the corner: the row binds or nearly does.
                    qp.add_row(rng.gen_range(0.0..0.01)).copy_from_slice(&jacp[2 * nv..]);
                }
            }
            for _ in 0..4 {
                let b = model.body_id(BODIES[rng.gen_range(8..14)]).unwrap();
                model.jac_body(&data, b, &mut jacp, &mut jacr);
                let n: f64 = rng.gen_range(-1.0..1.0);
                let row: Vec<f64> =
                    (0..nv).map(|d| n * jacp[d] + (1.0 - n.abs()) * jacp[nv + d]).collect();
                qp.add_row(rng.gen_range(-0.02..0.005)).copy_from_slice(&row);
            }
            qp
        })
        .collect()
}

/// The same problem for clarabel: `P` upper triangle, `A x + s = b, s ≥ 0` with rows
/// `−a x ≤ −b` and the bounds as rows.
fn clarabel_solve(qp: &DenseQp) -> Vec<f64> {
    let n = qp.dim();
    let dense_p: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..n).map(|j| if j >= i { qp.h[i * n + j] } else { 0.0 }).collect())
        .collect();
    let mut a_rows: Vec<Vec<f64>> = Vec::new();
    let mut b = Vec::new();
    for k in 0..qp.num_rows() {
        let (a, bk) = qp.row(k).unwrap();
        a_rows.push(a.iter().map(|v| -v).collect());
        b.push(-bk);
    }
    for i in 0..n {
        if qp.ub[i].is_finite() {
            let mut row = vec![0.0; n];
            row[i] = 1.0;
            a_rows.push(row);
            b.push(qp.ub[i]);
        }
        if qp.lb[i].is_finite() {
            let mut row = vec![0.0; n];
            row[i] = -1.0;
            a_rows.push(row);
            b.push(-qp.lb[i]);
        }
    }
    let p = CscMatrix::from(&dense_p);
    let a = CscMatrix::from(&a_rows);
    let cones = [NonnegativeConeT(b.len())];
    let settings = DefaultSettingsBuilder::default().verbose(false).build().unwrap();
    let mut solver = DefaultSolver::new(&p, &qp.c, &a, &b, &cones, settings).unwrap();
    solver.solve();
    solver.solution.x.clone()
}

fn bench_qp(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let model = mjcf::Model::from_file(&root.join("robots/unitree_g1/unitree_g1.xml")).unwrap();
    let mut set = problems(&model, 200);
    let mut tree_set = set.clone();
    let parents = model.dof_parents().to_vec();
    let mut active = 0;
    for (qp, tree) in set.iter_mut().zip(&mut tree_set) {
        assert_eq!(qp.solve(), QpStatus::Optimal);
        active += (0..qp.num_rows()).filter(|&k| qp.row_is_active(k)).count();
        let theirs = clarabel_solve(qp);
        let diff = qp.x.iter().zip(&theirs).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(diff < 1e-5, "clarabel disagrees by {diff}");
        tree.set_tree(&parents);
        assert_eq!(tree.solve(), QpStatus::Optimal);
        let diff = qp.x.iter().zip(&tree.x).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(diff < 1e-8, "the tree factorisation disagrees by {diff}");
    }
    eprintln!("{} problems, {:.1} active rows each on average", set.len(), active as f64 / 200.0);
    let mut group = c.benchmark_group("qp_g1");
    group.throughput(Throughput::Elements(set.len() as u64));
    group.sample_size(20);
    group.bench_function("dense_goldfarb_idnani", |b| {
        b.iter(|| {
            for qp in set.iter_mut() {
                std::hint::black_box(qp.solve());
            }
        })
    });
    group.bench_function("tree_goldfarb_idnani", |b| {
        b.iter(|| {
            for qp in tree_set.iter_mut() {
                std::hint::black_box(qp.solve());
            }
        })
    });
    group.sample_size(10);
    group.bench_function("clarabel", |b| {
        b.iter(|| {
            for qp in &set {
                std::hint::black_box(clarabel_solve(qp));
            }
        })
    });
    group.finish();
}

criterion_group!(benches, bench_qp);
criterion_main!(benches);
