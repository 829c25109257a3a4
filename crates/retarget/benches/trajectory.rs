//! The trajectory solve's linear algebra on our problem (issue 30: the candidates measured).
//! One window of the default solve as stage 6 sees it: the G1 (nv = 35) on 240 frames of the
//! LAFAN1 walk (8,400 unknowns), GMR's G1 config at 1.75 m, the initial trajectory from the
//! per-frame solve with the ground and self-collision constraints, each frame's Gauss–Newton
//! model of its tasks, the acceleration cost of every coordinate (root 1 and 1e-2, joints
//! 2e-5, per (unit/s²)²), and the constraint rows within 2 cm of their bound at the initial
//! trajectory (about four a frame: as many as a planted sole's corners hold in the default
//! solve, whose initial trajectory stands on the floor; this one's does not).
//!
//! - `banded`: our block-pentadiagonal Cholesky (`internals::Banded`), active rows held by a
//!   stiff penalty, as `trajectory.rs` does: factor and solve.
//! - `clarabel_penalty`: the same unconstrained system (`P` the whole window, sparse) with
//!   clarabel's interior-point solver (a QP with no constraints).
//! - `clarabel_qp`: the active rows as hard inequalities `a·δ ≥ max(b, 0)` instead of the
//!   penalty, with clarabel: the true QP a general sparse solver would be given.
//!
//! The setup checks that the two unconstrained solutions agree and prints the sizes. Needs
//! `data/samples/lafan1_walk.bvh` (`scripts/fetch-samples`); without it, a note and nothing.

// Index loops over dofs, as the solve's own assembly reads.
#![allow(clippy::needless_range_loop)]

use std::path::Path;

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use retarget::internals::{task_specs, Banded, Ground, Pose, SelfCollision, Solver, TargetMap};
use retarget::{IkConfig, SolverOptions};

const FIRST: usize = 1000;
const FRAMES: usize = 240;
const PENALTY: f64 = 1e7;
const SLACK: f64 = 0.02;

/// One window's system: the banded form, and the same as sparse triplets of the upper
/// triangle (without the penalty, which `rows` lists instead), with the right-hand side.
struct Window {
    n: usize,
    banded: Banded,
    upper: Vec<(usize, usize, f64)>,
    rhs: Vec<f64>,
    /// Active rows `(frame, a, max(b, 0))`.
    rows: Vec<(usize, Vec<f64>, f64)>,
}

fn window(root: &Path) -> Option<Window> {
    let walk = root.join("data/samples/lafan1_walk.bvh");
    if !walk.is_file() {
        eprintln!("note: {} is missing (scripts/fetch-samples); nothing measured", walk.display());
        return None;
    }
    let bvh = bvh::from_path(&walk).unwrap();
    let model = mjcf::Model::from_file(&root.join("robots/unitree_g1/unitree_g1.xml")).unwrap();
    let config = IkConfig::from_file(&root.join("configs/gmr/bvh_lafan1_to_g1.json")).unwrap();
    let (human, _) = fk::human_motion(&bvh, &fk::FkOptions::default()).unwrap();
    let map = TargetMap::new(&config, &human.body_names, 1.75).unwrap();
    let stages = task_specs(&config, &model, &map);
    let last = stages.len() - 1;
    let nb = human.num_bodies();
    let targets: Vec<Vec<Pose>> = (FIRST..FIRST + FRAMES)
        .map(|f| {
            let mut poses = vec![
                Pose { quat: [1.0, 0.0, 0.0, 0.0], pos: Default::default() };
                map.bodies.len()
            ];
            let r = f * nb..(f + 1) * nb;
            map.compute(&human.positions[r.clone()], &human.orientations[r], &mut poses);
            poses
        })
        .collect();
    let mut solver = Solver::new(&model, &stages, SolverOptions::default()).unwrap();
    solver.add_constraint(Box::new(Ground::new(&model, 0.0)));
    solver.add_constraint(Box::new(SelfCollision::new(&model)));
    let dt = 1.0 / 30.0;
    let mut qs = Vec::with_capacity(FRAMES);
    for (k, t) in targets.iter().enumerate() {
        solver.solve_frame(t, if k == 0 { 0.0 } else { dt }).unwrap();
        qs.push(solver.qpos().to_vec());
    }
    let nv = model.nv;
    let mut weight = vec![2e-5; nv];
    weight[..3].fill(1.0);
    weight[3..6].fill(1e-2);
    weight.iter_mut().for_each(|w| *w /= dt.powi(4));
    let mut banded = Banded::new(nv, FRAMES);
    let mut upper = Vec::new();
    let mut rows = Vec::new();
    for (k, (q, t)) in qs.iter().zip(&targets).enumerate() {
        solver.set_qpos(q).unwrap();
        let (h, c) = solver.objective_model(&[(last, 1.0)], t);
        let (h, c) = (h.to_vec(), c.to_vec());
        let block = banded.diag_mut(k);
        for i in 0..nv {
            for j in i..nv {
                block[(i, j)] = h[i * nv + j];
                block[(j, i)] = h[i * nv + j];
                if h[i * nv + j] != 0.0 {
                    upper.push((k * nv + i, k * nv + j, h[i * nv + j]));
                }
            }
        }
        let mut rhs = banded.rhs_mut(k);
        for i in 0..nv {
            rhs[i] = -c[i];
        }
        for (a, b) in solver.constraint_rows() {
            if b > -SLACK {
                rows.push((k, a.to_vec(), b.max(0.0)));
            }
        }
    }
    let rhs: Vec<f64> = banded.rhs.iter().copied().collect();
    // The penalty into the banded form only.
    for (k, a, b) in &rows {
        let block = banded.diag_mut(*k);
        for i in 0..nv {
            for j in 0..nv {
                block[(i, j)] += PENALTY * a[i] * a[j];
            }
        }
        let mut r = banded.rhs_mut(*k);
        for i in 0..nv {
            r[i] += PENALTY * a[i] * b;
        }
    }
    // Accelerations: ½ W (δ_{t−1} − 2δ_t + δ_{t+1} + a_t)² over interior frames.
    let mut vel = vec![vec![0.0; nv]; FRAMES];
    for j in 1..FRAMES {
        model.differentiate_pos(&mut vel[j], 1.0, &qs[j - 1], &qs[j]);
    }
    let mut rhs = rhs;
    const COEF: [f64; 3] = [1.0, -2.0, 1.0];
    for t in 1..FRAMES - 1 {
        for (x, &cx) in COEF.iter().enumerate() {
            let kx = t + x - 1;
            for i in 0..nv {
                let a = vel[t + 1][i] - vel[t][i];
                banded.rhs_mut(kx)[i] -= weight[i] * cx * a;
                rhs[kx * nv + i] -= weight[i] * cx * a;
            }
            for (y, &cy) in COEF.iter().enumerate().take(x + 1) {
                let ky = t + y - 1;
                for i in 0..nv {
                    let w = weight[i] * cx * cy;
                    banded.add(kx, x - y, i, i, w);
                    // Upper triangle: row of the earlier frame.
                    upper.push((ky * nv + i, kx * nv + i, w));
                }
            }
        }
    }
    Some(Window { n: FRAMES * nv, banded, upper, rhs, rows })
}

/// The upper-triangular CSC matrix of `n × n` from triplets (duplicates summed).
fn csc(n: usize, mut triplets: Vec<(usize, usize, f64)>) -> CscMatrix<f64> {
    triplets.sort_by_key(|&(r, c, _)| (c, r));
    let mut colptr = vec![0usize; n + 1];
    let (mut rowval, mut nzval): (Vec<usize>, Vec<f64>) = (Vec::new(), Vec::new());
    let mut last = None;
    for (r, c, v) in triplets {
        if last == Some((r, c)) {
            *nzval.last_mut().unwrap() += v;
            continue;
        }
        last = Some((r, c));
        rowval.push(r);
        nzval.push(v);
        colptr[c + 1] += 1;
    }
    for c in 0..n {
        colptr[c + 1] += colptr[c];
    }
    CscMatrix::new(n, n, colptr, rowval, nzval)
}

/// clarabel on `P`, `q = −rhs`, with the active rows as `a·δ ≥ b` (penalised into `P`
/// instead when `penalty`).
fn clarabel_solve(w: &Window, penalty: bool) -> Vec<f64> {
    let nv = w.n / FRAMES;
    let mut upper = w.upper.clone();
    let mut q: Vec<f64> = w.rhs.iter().map(|v| -v).collect();
    let (mut a_trip, mut b) = (Vec::new(), Vec::new());
    for (k, a, bk) in &w.rows {
        let nz: Vec<usize> = (0..nv).filter(|&d| a[d] != 0.0).collect();
        if penalty {
            for &i in &nz {
                for &j in nz.iter().filter(|&&j| j >= i) {
                    upper.push((k * nv + i, k * nv + j, PENALTY * a[i] * a[j]));
                }
                q[k * nv + i] -= PENALTY * a[i] * bk;
            }
        } else {
            for &i in &nz {
                a_trip.push((b.len(), k * nv + i, -a[i]));
            }
            b.push(-bk);
        }
    }
    let p = csc(w.n, upper);
    // A general (not upper-triangular) CSC of `b.len() × n`.
    a_trip.sort_by_key(|&(r, c, _)| (c, r));
    let mut colptr = vec![0usize; w.n + 1];
    for &(_, c, _) in &a_trip {
        colptr[c + 1] += 1;
    }
    for c in 0..w.n {
        colptr[c + 1] += colptr[c];
    }
    let a = CscMatrix::new(
        b.len(),
        w.n,
        colptr,
        a_trip.iter().map(|t| t.0).collect(),
        a_trip.iter().map(|t| t.2).collect(),
    );
    let cones = [NonnegativeConeT(b.len())];
    let settings = DefaultSettingsBuilder::default().verbose(false).build().unwrap();
    let mut solver = DefaultSolver::new(&p, &q, &a, &b, &cones, settings).unwrap();
    solver.solve();
    solver.solution.x.clone()
}

fn banded_solve(w: &Window) -> Vec<f64> {
    let mut banded = w.banded.clone();
    banded.factor().unwrap();
    banded.solve();
    banded.rhs.iter().copied().collect()
}

fn bench_trajectory(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let Some(w) = window(&root) else { return };
    let (ours, theirs) = (banded_solve(&w), clarabel_solve(&w, true));
    let scale = ours.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let gap = ours.iter().zip(&theirs).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    eprintln!(
        "window: {} frames, {} unknowns, {} nonzeros in P's upper triangle, {} active rows; \
         banded vs clarabel (penalty): largest difference {gap:.2e} (largest step {scale:.2e})",
        FRAMES,
        w.n,
        w.upper.len(),
        w.rows.len()
    );
    let mut group = c.benchmark_group("trajectory_window");
    group.throughput(Throughput::Elements(FRAMES as u64));
    group.sample_size(10);
    group.bench_function("banded", |b| b.iter(|| std::hint::black_box(banded_solve(&w))));
    group.bench_function("clarabel_penalty", |b| {
        b.iter(|| std::hint::black_box(clarabel_solve(&w, true)));
    });
    group.bench_function("clarabel_qp", |b| {
        b.iter(|| std::hint::black_box(clarabel_solve(&w, false)));
    });
    group.finish();
}

criterion_group!(benches, bench_trajectory);
criterion_main!(benches);
