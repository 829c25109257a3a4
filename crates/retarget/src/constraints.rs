//! Hard constraints of the IK step beyond joint ranges: each kind is one small type that
//! adds its linearised rows `a · Δq ≥ b` to the step's QP ([`crate::qp::DenseQp`]) at the
//! current configuration. The solver ([`crate::Solver::add_constraint`]) holds them in
//! every step; the next kind of constraint is one new type here.
//!
//! Linearisation: a point `p(q)` on body `B` moves by `J_p(q) Δq` to first order (`J_p`:
//! MuJoCo's `mj_jac` at `p`), so "the lowest point of a geom stays above the floor" becomes
//! `z + J_z Δq ≥ floor`. The next step re-linearises at the new configuration, so the error
//! of one step is second order in its length.

use mjcf::{Data, GeomType, Model};
use nalgebra::{Matrix3, Vector3};

use crate::qp::DenseQp;

/// The configuration a step linearises at.
#[derive(Debug, Clone, Copy)]
pub struct StepContext<'a> {
    pub model: &'a Model,
    /// Kinematics at `qpos`.
    pub data: &'a Data,
    pub qpos: &'a [f64],
}

/// A hard constraint of the IK step.
pub trait Constraint: std::fmt::Debug + Send {
    /// Short name for diagnostics.
    fn name(&self) -> &'static str;
    /// Appends this constraint's rows at the configuration of `ctx`.
    fn add_rows(&mut self, ctx: &StepContext<'_>, qp: &mut DenseQp);
}

/// Nothing through the floor: the lowest point of every collision geom stays at or above
/// `floor` (world z). Geoms whose lowest point is higher than `floor + activation` add no
/// row (one step cannot bring them down that far).
#[derive(Debug, Clone)]
pub struct Ground {
    geoms: Vec<usize>,
    pub floor: f64,
    pub activation: f64,
    jacp: Vec<f64>,
    jacr: Vec<f64>,
}

impl Ground {
    /// Every collision primitive of `model` (contype or conaffinity non-zero; planes,
    /// height fields, meshes and SDFs left out: the first two are the ground itself, the
    /// last two have no geometry here).
    #[must_use]
    pub fn new(model: &Model, floor: f64) -> Ground {
        let geoms = collision_primitives(model);
        Ground {
            geoms,
            floor,
            activation: 0.15,
            jacp: vec![0.0; 3 * model.nv],
            jacr: vec![0.0; 3 * model.nv],
        }
    }
}

impl Constraint for Ground {
    fn name(&self) -> &'static str {
        "ground"
    }

    fn add_rows(&mut self, ctx: &StepContext<'_>, qp: &mut DenseQp) {
        let nv = ctx.model.nv;
        let mut points = Vec::with_capacity(8);
        for &g in &self.geoms {
            candidate_low_points(ctx.model, ctx.data, g, &mut points);
            let body = ctx.model.geoms[g].body;
            for p in &points {
                if p.z > self.floor + self.activation {
                    continue;
                }
                ctx.model.jac(ctx.data, body, p, &mut self.jacp, &mut self.jacr);
                qp.add_row(self.floor - p.z).copy_from_slice(&self.jacp[2 * nv..3 * nv]);
            }
        }
    }
}

/// The points of geom `g` that can become its lowest under a small rotation: a box's
/// bottom corners (one linearised corner does not stop another from dipping when the box
/// tilts), the lowest points of a capsule's two end spheres and of a cylinder's two rims,
/// the support point of a sphere or ellipsoid. Corners and ends higher than the lowest by
/// more than half the geom's size are left out.
fn candidate_low_points(model: &Model, data: &Data, g: usize, out: &mut Vec<Vector3<f64>>) {
    out.clear();
    let geom = &model.geoms[g];
    let (c, r, s) = (data.geom_xpos[g], &data.geom_xmat[g], geom.size);
    match geom.kind {
        GeomType::Box => {
            for k in 0..8 {
                let sign = |bit: usize| if k & (1 << bit) == 0 { -1.0 } else { 1.0 };
                out.push(c + r * Vector3::new(sign(0) * s[0], sign(1) * s[1], sign(2) * s[2]));
            }
        }
        GeomType::Capsule | GeomType::Cylinder => {
            let axis = r.column(2).into_owned();
            let down = if geom.kind == GeomType::Capsule {
                Vector3::new(0.0, 0.0, -s[0])
            } else {
                let radial = Vector3::new(0.0, 0.0, -1.0) - axis * (-axis.z);
                let n = radial.norm();
                if n > 1e-12 {
                    radial / n * s[0]
                } else {
                    Vector3::zeros()
                }
            };
            out.push(c + axis * s[1] + down);
            out.push(c - axis * s[1] + down);
        }
        _ => out.push(lowest_point(model, data, g)),
    }
    let low = out.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
    let reach = s.iter().copied().fold(0.0, f64::max);
    out.retain(|p| p.z <= low + reach);
}

/// Geoms that collide (contype or conaffinity non-zero) and have a primitive shape.
#[must_use]
pub fn collision_primitives(model: &Model) -> Vec<usize> {
    (0..model.geoms.len())
        .filter(|&g| {
            matches!(
                model.geoms[g].kind,
                GeomType::Sphere
                    | GeomType::Capsule
                    | GeomType::Ellipsoid
                    | GeomType::Cylinder
                    | GeomType::Box
            )
        })
        .collect()
}

/// The world point of geom `g` with the smallest z (a support point in −z).
#[must_use]
pub fn lowest_point(model: &Model, data: &Data, g: usize) -> Vector3<f64> {
    let geom = &model.geoms[g];
    data.geom_xpos[g] + support_offset(geom.kind, &geom.size, &data.geom_xmat[g])
}

/// From the centre of a primitive (`kind`, MuJoCo `size`, world orientation `r`) to its
/// lowest point, in world axes. Planes, meshes and other non-primitives: zero.
#[must_use]
pub fn support_offset(kind: GeomType, s: &[f64; 3], r: &Matrix3<f64>) -> Vector3<f64> {
    // Row 2 of R: the z components of the geom's local axes in the world.
    let rz = Vector3::new(r[(2, 0)], r[(2, 1)], r[(2, 2)]);
    let local: Vector3<f64> = match kind {
        GeomType::Sphere => return Vector3::new(0.0, 0.0, -s[0]),
        GeomType::Capsule => {
            let end = r * Vector3::new(0.0, 0.0, -s[1] * rz.z.signum());
            return end - Vector3::new(0.0, 0.0, s[0]);
        }
        GeomType::Box => {
            Vector3::new(-s[0] * rz.x.signum(), -s[1] * rz.y.signum(), -s[2] * rz.z.signum())
        }
        GeomType::Cylinder => {
            // Rim point: along the axis to the lower cap, then radially against z.
            let radial = Vector3::new(rz.x, rz.y, 0.0);
            let n = radial.norm();
            let rim = if n > 1e-12 { -radial / n * s[0] } else { Vector3::zeros() };
            rim + Vector3::new(0.0, 0.0, -s[1] * rz.z.signum())
        }
        GeomType::Ellipsoid => {
            // Support of the ellipsoid diag(s) in direction −ẑ (local −rz): −S² rz / |S rz|.
            let sr = Vector3::new(s[0] * rz.x, s[1] * rz.y, s[2] * rz.z);
            let n = sr.norm();
            if n < 1e-12 {
                return Vector3::zeros();
            }
            -Vector3::new(s[0] * sr.x, s[1] * sr.y, s[2] * sr.z) / n
        }
        _ => return Vector3::zeros(),
    };
    r * local
}
