//! Hard constraints of the IK step beyond joint ranges: each kind is one small type that
//! adds its linearised rows `a · Δq ≥ b` to the step's QP ([`crate::qp::DenseQp`]) at the
//! current configuration. The solver ([`crate::ik::Solver::add_constraint`]) holds them in
//! every step; the next kind of constraint is one new type here.
//!
//! Linearisation: a point `p(q)` on body `B` moves by `J_p(q) Δq` to first order (`J_p`:
//! MuJoCo's `mj_jac` at `p`), so "the lowest point of a geom stays above the floor" becomes
//! `z + J_z Δq ≥ floor`. The next step re-linearises at the new configuration, so the error
//! of one step is second order in its length.

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: geom, body and dof ids come from the model the constraint was built for (`mjcf::Model`
// guarantees them in range) and row buffers are sized `nv`.
#![allow(clippy::indexing_slicing)]

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
    /// Geoms held higher than the floor in this frame, with the height each keeps above it
    /// (a swing foot's sole, [`crate::ik::Solver::set_raised_geoms`]), sorted by geom.
    pub raised: &'a [(usize, f64)],
    /// Planted sole points and where this step may put them ([`Grip`]).
    pub grips: &'a [GripBox],
}

/// A hard constraint of the IK step.
pub trait Constraint: std::fmt::Debug + Send {
    /// Short name for diagnostics.
    fn name(&self) -> &'static str;
    /// Appends this constraint's rows at the configuration of `ctx`.
    fn add_rows(&mut self, ctx: &StepContext<'_>, qp: &mut DenseQp);
}

/// Nothing through the floor: the lowest point of every collision geom stays at or above
/// `floor` (world z). Points higher than `floor + activation` add no row (one step does not
/// bring them down that far; the next step re-linearises).
#[derive(Debug, Clone)]
pub struct Ground {
    geoms: Vec<usize>,
    /// Bounding-sphere radius per geom of `geoms`: a geom whose sphere is above the
    /// activation height has no candidate point below it either.
    radius: Vec<f64>,
    pub floor: f64,
    pub activation: f64,
    /// Scratch: one geom's candidate points.
    points: Vec<Vector3<f64>>,
}

impl Ground {
    /// Every collision primitive of `model` (contype or conaffinity non-zero; planes,
    /// height fields, meshes and SDFs left out: the first two are the ground itself, the
    /// last two have no geometry here).
    #[must_use]
    pub fn new(model: &Model, floor: f64) -> Ground {
        let geoms = collision_primitives(model);
        let radius = geoms
            .iter()
            .map(|&g| model.geoms[g].bounding_radius().unwrap_or(f64::INFINITY))
            .collect();
        Ground { geoms, radius, floor, activation: 0.1, points: Vec::with_capacity(8) }
    }
}

impl Constraint for Ground {
    fn name(&self) -> &'static str {
        "ground"
    }

    fn add_rows(&mut self, ctx: &StepContext<'_>, qp: &mut DenseQp) {
        for (&g, &radius) in self.geoms.iter().zip(&self.radius) {
            let floor = self.floor
                + ctx.raised.binary_search_by_key(&g, |r| r.0).map_or(0.0, |k| ctx.raised[k].1);
            let top = floor + self.activation;
            // (The margin covers the rounding of the candidate points.)
            if ctx.data.geom_xpos[g].z - radius > top + 1e-9 {
                continue;
            }
            candidate_low_points(ctx.model, ctx.data, g, &mut self.points);
            let body = ctx.model.geoms[g].body;
            for p in &self.points {
                if p.z > top {
                    continue;
                }
                // The z row of the point's Jacobian (zero off the body's dof chain).
                let row = qp.add_row(floor - p.z);
                for (d, column) in ctx.model.jac_point_columns(ctx.data, body, *p) {
                    row[d] = column.z;
                }
            }
        }
    }
}

/// The points of geom `g` that can become its lowest under a small rotation: a box's four
/// lowest corners (one linearised corner does not stop another from dipping when the box
/// tilts), the lowest points of a capsule's two end spheres and of a cylinder's two rims,
/// the support point of a sphere or ellipsoid.
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
            out.sort_by(|a, b| a.z.total_cmp(&b.z));
            out.truncate(4);
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
}

/// Geoms of the robot (not the world's) that collide (contype or conaffinity non-zero) and
/// have a primitive shape.
#[must_use]
pub fn collision_primitives(model: &Model) -> Vec<usize> {
    (0..model.geoms.len())
        .filter(|&g| {
            let geom = &model.geoms[g];
            geom.body != 0 && geom.kind.is_primitive() && (geom.contype | geom.conaffinity) != 0
        })
        .collect()
}

/// Nothing through itself: every pair of [`Model::self_collision_pairs`] closer than
/// `activation` keeps its signed distance at or above `margin`, linearised at the witness
/// points: `d + nᵀ (J₂(p₂) − J₁(p₁)) Δq ≥ margin` (`n` from geom 1 to geom 2).
///
/// Two boxes get one such row per point of their contact manifold ([`mjcf::box_manifold`]:
/// the incident face clipped by the reference face, up to eight points, one normal), so that
/// every corner and edge crossing that can go in is held, not only the deepest point: with
/// one witness row a sole tilting or turning on the other dipped another corner in
/// (ToddlerBot's LAFAN1 walk: 46 frames of sole in sole deeper than 1 cm, none with the
/// manifold). Every point's gap is at least the pair's separation along the normal, so
/// moving apart along it by the depth clears them all: the rows ask no more translation than
/// the one witness row did. Where the manifold has no point within `activation` (the boxes
/// face each other only beside their faces), the witness row as for other pairs.
///
/// Pairs whose bounding spheres are farther apart than `activation` are left out first.
/// Most pairs stay so for many calls: each pair remembers by how much its spheres cleared
/// the activation distance when last tested, and each geom how far its centre has moved
/// since the solver started (summed over the calls); a pair is tested again only once the
/// two centres can have moved by its clearance. The same pairs reach the distance query as
/// when every pair is tested.
#[derive(Debug, Clone)]
pub struct SelfCollision {
    pairs: Vec<[usize; 2]>,
    /// Per pair: both geoms are boxes (rows from the contact manifold).
    boxes: Vec<bool>,
    /// Bounding-sphere radius per geom (0 for geoms without one).
    radius: Vec<f64>,
    pub margin: f64,
    pub activation: f64,
    /// Per geom: its centre at the last call (none before the first) and the distance the
    /// centre has moved over the calls so far.
    centre: Vec<Option<Vector3<f64>>>,
    travel: Vec<f64>,
    /// Per pair: its spheres' clearance beyond `activation` when last tested plus both
    /// geoms' `travel` then (−∞: test at the next call).
    clear: Vec<f64>,
    /// Scratch: geom 1's Jacobian columns.
    columns: Vec<(usize, Vector3<f64>)>,
}

impl SelfCollision {
    #[must_use]
    pub fn new(model: &Model) -> SelfCollision {
        let pairs = model.self_collision_pairs().pairs;
        let is_box = |g: usize| model.geoms[g].kind == GeomType::Box;
        SelfCollision {
            boxes: pairs.iter().map(|&[g1, g2]| is_box(g1) && is_box(g2)).collect(),
            radius: model.geoms.iter().map(|g| g.bounding_radius().unwrap_or(0.0)).collect(),
            margin: 0.0,
            activation: 0.03,
            centre: vec![None; model.geoms.len()],
            travel: vec![0.0; model.geoms.len()],
            clear: vec![f64::NEG_INFINITY; pairs.len()],
            pairs,
            columns: Vec::with_capacity(model.nv),
        }
    }

    /// The row of a pair at the points `point1` on geom 1 and `point2` on geom 2 with the
    /// normal `n`: `nᵀ (J₂ − J₁)` over both bodies' dof chains (zero elsewhere).
    fn fill_row(
        &mut self,
        ctx: &StepContext<'_>,
        [g1, g2]: [usize; 2],
        (point1, point2, n): (Vector3<f64>, Vector3<f64>, Vector3<f64>),
        row: &mut [f64],
    ) {
        let (model, data) = (ctx.model, ctx.data);
        self.columns.clear();
        self.columns.extend(model.jac_point_columns(data, model.geoms[g1].body, point1));
        let mut first = self.columns.iter().peekable();
        let mut second = model.jac_point_columns(data, model.geoms[g2].body, point2).peekable();
        let zero = Vector3::zeros();
        // Both chains run from the body towards the world (dofs descending): merge them.
        loop {
            let (d, j1, j2) = match (first.peek(), second.peek()) {
                (Some(&&(d1, j1)), Some(&(d2, j2))) if d1 == d2 => {
                    first.next();
                    second.next();
                    (d1, j1, j2)
                }
                (Some(&&(d1, j1)), Some(&(d2, _))) if d1 > d2 => {
                    first.next();
                    (d1, j1, zero)
                }
                (Some(&&(d1, j1)), None) => {
                    first.next();
                    (d1, j1, zero)
                }
                (_, Some(&(d2, j2))) => {
                    second.next();
                    (d2, zero, j2)
                }
                (None, None) => break,
            };
            row[d] = (0..3).map(|r| n[r] * (j2[r] - j1[r])).sum();
        }
    }
}

impl Constraint for SelfCollision {
    fn name(&self) -> &'static str {
        "self-collision"
    }

    fn add_rows(&mut self, ctx: &StepContext<'_>, qp: &mut DenseQp) {
        // Below this clearance a pair is tested exactly (rounding of the bound).
        const SLACK: f64 = 1e-9;
        let (model, data) = (ctx.model, ctx.data);
        for ((centre, travel), now) in
            self.centre.iter_mut().zip(&mut self.travel).zip(&data.geom_xpos)
        {
            if let Some(seen) = centre {
                *travel += (now - *seen).norm();
            }
            *centre = Some(*now);
        }
        for k in 0..self.pairs.len() {
            let [g1, g2] = self.pairs[k];
            let moved = self.travel[g1] + self.travel[g2];
            if self.clear[k] - moved > SLACK {
                continue;
            }
            let reach = self.radius[g1] + self.radius[g2] + self.activation;
            let apart = (data.geom_xpos[g1] - data.geom_xpos[g2]).norm_squared();
            if apart > reach * reach {
                self.clear[k] = apart.sqrt() - reach + moved;
                continue;
            }
            self.clear[k] = f64::NEG_INFINITY;
            if self.boxes[k] {
                if let Some(m) = mjcf::box_manifold(model, data, g1, g2, self.activation) {
                    for c in m.points() {
                        let row = qp.add_row(self.margin - c.distance);
                        self.fill_row(ctx, [g1, g2], (c.point1, c.point2, m.normal), row);
                    }
                    continue;
                }
            }
            let Some(p) = mjcf::geom_distance(model, data, g1, g2, self.activation) else {
                continue;
            };
            let row = qp.add_row(self.margin - p.distance);
            self.fill_row(ctx, [g1, g2], (p.point1, p.point2, p.normal), row);
        }
    }
}

/// A planted sole's point (`point`, body `body`'s frame) in one step: where the step may put it
/// horizontally, `lo ..= hi` in x and y (world, m). [`crate::ik::Solver`] makes these from the
/// foot plan's footholds ([`crate::ik::Solver::set_grips`]) and the previous frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GripBox {
    pub body: usize,
    pub point: Vector3<f64>,
    pub lo: nalgebra::Vector2<f64>,
    pub hi: nalgebra::Vector2<f64>,
}

/// A planted foot does not slide: each of the step's [`GripBox`]es holds its point within
/// its box, four rows `±(p + J Δq) ≥ …` in x and y; a point outside its box is held where it
/// is on that side (its point task brings it back). Asked to come back, the four corners of
/// a sole tipped onto its toes could be asked for a shape no small step makes: their rows
/// nearly depend on each other, and the exact step of such a QP is huge. Asked back whole,
/// Talos's root jumped metres in a frame on CMU 131_01's toe spin; asked back half the box,
/// the H1's root 10.5 m in a frame of the second LAFAN1 take, and 17 cm in another (once
/// the window's step no longer slid that sole). Added last, so that where a frame cannot
/// hold it with the floor, the robot's geoms apart and the speed limits, it is the one
/// dropped for that step.
#[derive(Debug, Clone, Copy, Default)]
pub struct Grip;

impl Constraint for Grip {
    fn name(&self) -> &'static str {
        "grip"
    }

    fn add_rows(&mut self, ctx: &StepContext<'_>, qp: &mut DenseQp) {
        for g in ctx.grips {
            let p = ctx.data.xpos[g.body] + ctx.data.xquat[g.body] * g.point;
            for axis in 0..2 {
                // p + J Δq ≥ lo, and −(p + J Δq) ≥ −hi; past a bound, no further past it.
                for (sign, b) in [(1.0, g.lo[axis] - p[axis]), (-1.0, p[axis] - g.hi[axis])] {
                    let row = qp.add_row(b.min(0.0));
                    for (d, column) in ctx.model.jac_point_columns(ctx.data, g.body, p) {
                        row[d] = sign * column[axis];
                    }
                }
            }
        }
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Two slabs (geoms 0, 1: the second turned 30° about z and 5 mm into the first) and a
    /// sphere (geom 2) beside the first, each on a free body.
    fn slabs_and_sphere() -> (Model, Vec<f64>) {
        let m = Model::from_xml_str(
            r#"<mujoco><worldbody>
                 <body><freejoint/><geom type="box" size="0.1 0.05 0.015"/></body>
                 <body pos="0 0 0.5"><freejoint/><geom type="box" size="0.1 0.05 0.015"/></body>
                 <body pos="1 0 0"><freejoint/><geom size="0.03"/></body>
               </worldbody></mujoco>"#,
            None,
        )
        .unwrap();
        let half = 15f64.to_radians();
        let q = [
            [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
            [0.02, 0.01, 0.025, half.cos(), 0.0, 0.0, half.sin()],
            [0.14, 0.0, -0.02, 1.0, 0.0, 0.0, 0.0],
        ];
        (m, q.concat())
    }

    fn rows_at(m: &Model, q: &[f64]) -> (Data, DenseQp) {
        let mut data = Data::new(m);
        m.kinematics(q, &mut data);
        let mut qp = DenseQp::new(m.nv);
        let ctx = StepContext { model: m, data: &data, qpos: q, raised: &[], grips: &[] };
        SelfCollision::new(m).add_rows(&ctx, &mut qp);
        (data, qp)
    }

    /// The box pair gives one row per manifold point (its rows first: pairs are sorted), the
    /// sphere pairs one witness row each; each box row is the gap of its own point pair to
    /// first order, and moving the second slab out along the normal by the depth meets them all.
    #[test]
    fn box_pairs_get_a_row_per_manifold_point() {
        let (m, q) = slabs_and_sphere();
        let (data, qp) = rows_at(&m, &q);
        let manifold = mjcf::box_manifold(&m, &data, 0, 1, 0.03).unwrap();
        let points = manifold.points();
        let witness = |g1, g2| usize::from(mjcf::geom_distance(&m, &data, g1, g2, 0.03).is_some());
        assert!(points.len() >= 4 && witness(0, 2) == 1, "{manifold:?}");
        assert_eq!(qp.num_rows(), points.len() + witness(0, 2) + witness(1, 2));
        // Each row against its points carried along a small motion (body-fixed points).
        let dq: Vec<f64> = (0..m.nv).map(|d| 1e-6 * ((d * 7 % 5) as f64 - 2.0)).collect();
        let mut q2 = q.clone();
        m.integrate_pos(&mut q2, &dq, 1.0);
        let mut moved = Data::new(&m);
        m.kinematics(&q2, &mut moved);
        let carry = |g: usize, p: Vector3<f64>| {
            let b = m.geoms[g].body;
            moved.xpos[b] + moved.xmat[b] * data.xmat[b].tr_mul(&(p - data.xpos[b]))
        };
        for (k, c) in points.iter().enumerate() {
            let (row, rhs) = qp.row(k).unwrap();
            assert!((rhs + c.distance).abs() < 1e-15);
            let gap = manifold.normal.dot(&(carry(1, c.point2) - carry(0, c.point1)));
            let linear: f64 = row.iter().zip(&dq).map(|(a, x)| a * x).sum();
            assert!((gap - c.distance - linear).abs() < 1e-11, "point {k}: {gap} {linear}");
            // Slab 2's free joint: world translation in its first three dofs.
            let mut out = vec![0.0; m.nv];
            for i in 0..3 {
                out[6 + i] = manifold.normal[i] * -manifold.distance();
            }
            let lhs: f64 = row.iter().zip(&out).map(|(a, x)| a * x).sum();
            assert!(lhs >= rhs - 1e-12, "point {k}: {lhs} < {rhs}");
        }
    }
}
