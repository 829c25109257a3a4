//! Collision-geometry speed on the Unitree G1 (`robots/unitree_g1`: 6 boxes, 14 capsules,
//! 4 cylinders, 1 sphere; 303 collision pairs): what a self-collision constraint pays per IK
//! step.
//!
//! - `all_pairs_5cm`: `geom_distance` over every robot–robot pair with max distance 5 cm
//!   (its bounding-sphere test rejects most of them) at random configurations.
//! - `near_pairs/<kind>`: only pairs closer than 5 cm, by kind: the narrow phase proper
//!   (closed forms for sphere/capsule pairs, GJK/EPA for the rest).
//! - `parry_contact/<kind>`: the same pairs through parry's generic `query::contact` on
//!   parry's own shapes (capsule, cuboid, y-axis cylinder), the alternative to our split.
//! - `lowest_points`: `geom_lowest_point` of every geom.

use std::hint::black_box;
use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use mjcf::{geom_distance, geom_lowest_point, Data, GeomType, Model};
use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};
use parry3d_f64::shape::{Ball, Capsule, Cuboid, Cylinder, SharedShape};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

const NEAR: f64 = 0.05;

fn parry_shape(model: &Model, g: usize) -> (SharedShape, UnitQuaternion<f64>) {
    let [a, b, c] = model.geoms[g].size;
    let none = UnitQuaternion::identity();
    match model.geoms[g].kind {
        GeomType::Sphere => (SharedShape::new(Ball::new(a)), none),
        GeomType::Capsule => (SharedShape::new(Capsule::new_z(b, a)), none),
        GeomType::Box => (SharedShape::new(Cuboid::new(Vector3::new(a, b, c))), none),
        // parry's cylinder runs along y: turn y onto the geom's z.
        _ => (
            SharedShape::new(Cylinder::new(b, a)),
            UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2),
        ),
    }
}

fn pose(data: &Data, g: usize, extra: UnitQuaternion<f64>) -> Isometry3<f64> {
    let r: Matrix3<f64> = data.geom_xmat[g];
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r));
    Isometry3::from_parts(Translation3::from(data.geom_xpos[g]), q * extra)
}

fn kind_of(model: &Model, [g1, g2]: [usize; 2]) -> &'static str {
    let round = |g: usize| matches!(model.geoms[g].kind, GeomType::Sphere | GeomType::Capsule);
    let boxy = |g: usize| model.geoms[g].kind == GeomType::Box;
    match (round(g1), round(g2)) {
        (true, true) => "sphere_capsule",
        _ if boxy(g1) && boxy(g2) => "box_box",
        _ if (boxy(g1) || boxy(g2)) && (round(g1) || round(g2)) => "capsule_box",
        _ => "with_cylinder",
    }
}

fn collision(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots/unitree_g1/unitree_g1.xml");
    let model = Model::from_file(&path).expect("robots/unitree_g1 compiles");
    let pairs: Vec<[usize; 2]> = model
        .collision_pairs()
        .into_iter()
        .filter(|p| p.iter().all(|&g| model.geoms[g].kind.is_primitive()))
        .collect();
    let shapes: Vec<_> = (0..model.geoms.len()).map(|g| parry_shape(&model, g)).collect();
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let datas: Vec<Data> = (0..64)
        .map(|_| {
            let mut data = Data::new(&model);
            model.kinematics(&model.random_qpos(&mut rng), &mut data);
            data
        })
        .collect();

    let mut group = c.benchmark_group("collision");
    group.throughput(Throughput::Elements((pairs.len() * datas.len()) as u64));
    group.bench_function("all_pairs_5cm", |b| {
        b.iter(|| {
            let mut near = 0usize;
            for data in &datas {
                for &[g1, g2] in &pairs {
                    near += usize::from(geom_distance(&model, data, g1, g2, NEAR).is_some());
                }
            }
            black_box(near)
        });
    });

    for kind in ["sphere_capsule", "capsule_box", "box_box", "with_cylinder"] {
        let model = &model;
        let near: Vec<(usize, [usize; 2])> = datas
            .iter()
            .enumerate()
            .flat_map(|(i, data)| {
                pairs
                    .iter()
                    .filter(move |p| geom_distance(model, data, p[0], p[1], NEAR).is_some())
                    .map(move |p| (i, *p))
            })
            .filter(|(_, p)| kind_of(model, *p) == kind)
            .collect();
        if near.is_empty() {
            continue;
        }
        group.throughput(Throughput::Elements(near.len() as u64));
        group.bench_function(format!("near_pairs/{kind}"), |b| {
            b.iter(|| {
                let mut sum = 0.0;
                for &(i, [g1, g2]) in &near {
                    sum +=
                        geom_distance(model, &datas[i], g1, g2, NEAR).map_or(0.0, |p| p.distance);
                }
                black_box(sum)
            });
        });
        group.bench_function(format!("parry_contact/{kind}"), |b| {
            b.iter(|| {
                let mut sum = 0.0;
                for &(i, [g1, g2]) in &near {
                    let ((s1, e1), (s2, e2)) = (&shapes[g1], &shapes[g2]);
                    let (p1, p2) = (pose(&datas[i], g1, *e1), pose(&datas[i], g2, *e2));
                    let contact = parry3d_f64::query::contact(&p1, &*s1.0, &p2, &*s2.0, NEAR);
                    sum += contact.ok().flatten().map_or(0.0, |c| c.dist);
                }
                black_box(sum)
            });
        });
    }

    group.throughput(Throughput::Elements((model.geoms.len() * datas.len()) as u64));
    group.bench_function("lowest_points", |b| {
        b.iter(|| {
            let mut low = 0.0;
            for data in &datas {
                for g in 0..model.geoms.len() {
                    low += geom_lowest_point(&model, data, g).map_or(0.0, |p| p.z);
                }
            }
            black_box(low)
        });
    });
    group.finish();
}

criterion_group!(benches, collision);
criterion_main!(benches);
