//! Our kinematics against MuJoCo 3.17.0's on the same file (cargo feature `mujoco`): the
//! compiled model (sizes, names, order, ranges, `qpos0`, body and joint frames, the inertial
//! of every body that has one here) and, at random configurations, every body pose, every
//! body Jacobian and every geom and site position. Shared by the parity tests and
//! `retarget robot check`.
//!
//! A URDF is compiled by MuJoCo's own URDF import (`mj_loadXML` reads `<robot>` files). MuJoCo
//! adds no free joint there, so a model read with [`UrdfBase::Fixed`] is compared with that
//! compile as it is; for [`UrdfBase::Floating`] the free joint is added on MuJoCo's side too,
//! through its model-editing API on the parsed spec, the way MuJoCo itself does it when it
//! loads a URDF as a moving body (`xml_urdf.cc`: `ROOT_free_joint` on the root link), then
//! MuJoCo compiles it (static links fused as usual).

// Exception to the crate's `deny(clippy::indexing_slicing)`, justified: indices are ids of our `Model` and of MuJoCo's `mjModel` of
// the same file, used only after the counts were compared; this module is a checker behind the
// `mujoco` feature, not a reader of user input.
#![allow(clippy::indexing_slicing)]

use std::fmt;
use std::path::Path;

use mujoco_rs::prelude::{MjModel, MjSpec, MjtJoint, MjtObjBase, SpecElement, SpecItem};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::{Data, Error, GeomType, Inertial, JointType, Model, UrdfBase, UrdfOptions};

/// How many random configurations (checked in addition to `qpos0`), from which seed.
#[derive(Debug, Clone, Copy)]
pub struct CheckOptions {
    pub configs: usize,
    pub seed: u64,
}

impl Default for CheckOptions {
    fn default() -> Self {
        CheckOptions { configs: 100, seed: 20_251_122 }
    }
}

/// An inertial deviating from MuJoCo's by more than this (kg, m, kg m²: the parity tests'
/// tolerance) is also a [`Report::mismatches`] line, naming the body.
pub const INERTIAL_TOLERANCE: f64 = 1e-9;

/// Result of [`check_file`]: structural mismatches (empty when the models agree) and the
/// largest absolute deviations seen (quaternions compared up to sign).
#[derive(Debug, Clone, Default)]
pub struct Report {
    pub mismatches: Vec<String>,
    pub configs: usize,
    /// Compiled model data: body/joint/geom/site frames, ranges, `qpos0`.
    pub max_static: f64,
    pub max_xpos: f64,
    pub max_xquat: f64,
    pub max_jacp: f64,
    pub max_jacr: f64,
    /// Geoms other than meshes, and sites.
    pub max_geom_site: f64,
    /// Bodies (the world aside) whose inertial was compared, and those without one here
    /// ([`Body::inertial`](crate::Body::inertial) `None`), not compared.
    pub inertials: usize,
    pub inertials_skipped: usize,
    /// Largest deviation of mass, centre of mass or inertia tensor about it in the body frame.
    pub max_inertial: f64,
}

impl Report {
    /// The largest of all deviations.
    #[must_use]
    pub fn max_deviation(&self) -> f64 {
        [
            self.max_static,
            self.max_xpos,
            self.max_xquat,
            self.max_jacp,
            self.max_jacr,
            self.max_geom_site,
            self.max_inertial,
        ]
        .into_iter()
        .fold(0.0, f64::max)
    }

    /// No structural mismatch and every deviation within `tolerance`.
    #[must_use]
    pub fn passes(&self, tolerance: f64) -> bool {
        self.mismatches.is_empty() && self.max_deviation() <= tolerance
    }
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "structure: {}",
            if self.mismatches.is_empty() { "identical" } else { "MISMATCH" }
        )?;
        for m in &self.mismatches {
            writeln!(f, "  {m}")?;
        }
        writeln!(f, "max |model data| deviation:  {:.3e}", self.max_static)?;
        writeln!(
            f,
            "max |inertial| deviation:    {:.3e} ({} bodies compared, {} without an inertial here)",
            self.max_inertial, self.inertials, self.inertials_skipped
        )?;
        writeln!(f, "over qpos0 and {} random configurations:", self.configs)?;
        writeln!(f, "  max |xpos| deviation:        {:.3e} m", self.max_xpos)?;
        writeln!(f, "  max |xquat| deviation:       {:.3e}", self.max_xquat)?;
        writeln!(f, "  max |jacp| deviation:        {:.3e}", self.max_jacp)?;
        writeln!(f, "  max |jacr| deviation:        {:.3e}", self.max_jacr)?;
        write!(f, "  max |geom/site xpos| dev.:   {:.3e} m", self.max_geom_site)
    }
}

fn mujoco_error(path: &Path, message: impl fmt::Display) -> Error {
    Error::Model { file: path.display().to_string(), message: format!("mujoco: {message}") }
}

/// Loads `path` with MuJoCo and compares it with `model` (normally `Model::from_path(path)`):
/// MJCF as it is, a `.urdf` as [`check_urdf_file`] does with the default [`UrdfOptions`].
pub fn check_file(model: &Model, path: &Path, options: CheckOptions) -> Result<Report, Error> {
    let is_urdf = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("urdf"));
    if is_urdf {
        return check_urdf_file(model, path, UrdfOptions::default(), options);
    }
    let mj = MjModel::from_xml(path).map_err(|e| mujoco_error(path, e))?;
    Ok(check_loaded(model, &mj, options))
}

/// Compiles the URDF at `path` with MuJoCo as `urdf` asks (see the module documentation) and
/// compares it with `model` (normally `Model::from_urdf_file(path, urdf)`).
pub fn check_urdf_file(
    model: &Model,
    path: &Path,
    urdf: UrdfOptions,
    options: CheckOptions,
) -> Result<Report, Error> {
    let err = |e: mujoco_rs::error::MjEditError| mujoco_error(path, e);
    let mut spec = MjSpec::from_xml(path).map_err(err)?;
    if let Some(fuse) = urdf.fuse_static {
        spec.compiler_mut().set_fusestatic(fuse);
    }
    if urdf.base == UrdfBase::Floating {
        // The root link is the world's first child in the parsed spec; a file with a floating
        // joint of its own keeps it and gets no second one.
        let world = spec.world_body_mut();
        let has_free = world.joint_iter(true).any(|j| j.type_() == MjtJoint::mjJNT_FREE);
        if let (false, Some(root)) = (has_free, world.body_iter_mut().next()) {
            let name = format!("{}_free_joint", root.name());
            root.add_free_joint().set_name(&name).map_err(err)?;
        }
    }
    let mj = spec.compile().map_err(err)?;
    Ok(check_loaded(model, &mj, options))
}

/// Like [`check_file`] for MJCF text without `<include>` (e.g. a model embedded in a binary);
/// `label` names it in errors.
pub fn check_xml_str(
    model: &Model,
    xml: &str,
    label: &str,
    options: CheckOptions,
) -> Result<Report, Error> {
    let mj = MjModel::from_xml_string(xml).map_err(|e| mujoco_error(Path::new(label), e))?;
    Ok(check_loaded(model, &mj, options))
}

fn check_loaded(model: &Model, mj: &MjModel, options: CheckOptions) -> Report {
    let mut report = Report { configs: options.configs, ..Report::default() };
    compare_structure(model, mj, &mut report);
    if report.mismatches.is_empty() {
        compare_kinematics(model, mj, options, &mut report);
    }
    report
}

fn max_abs(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

/// Deviation of two w-first quaternions, up to sign.
fn quat_dev(a: &[f64], b: &[f64; 4]) -> f64 {
    let plus = max_abs(a, b);
    let minus = a.iter().zip(b).map(|(x, y)| (x + y).abs()).fold(0.0, f64::max);
    plus.min(minus)
}

fn name_of(mj: &MjModel, kind: MjtObjBase, id: usize) -> String {
    mj.id_to_name(kind, id).unwrap_or("").to_owned()
}

fn compare_structure(model: &Model, mj: &MjModel, report: &mut Report) {
    let sizes = [
        ("nq", model.nq, mj.ffi().nq as usize),
        ("nv", model.nv, mj.ffi().nv as usize),
        ("nbody", model.bodies.len(), mj.ffi().nbody as usize),
        ("njnt", model.joints.len(), mj.ffi().njnt as usize),
        ("ngeom", model.geoms.len(), mj.ffi().ngeom as usize),
        ("nsite", model.sites.len(), mj.ffi().nsite as usize),
    ];
    for (what, ours, theirs) in sizes {
        if ours != theirs {
            report.mismatches.push(format!("{what}: ours {ours}, mujoco {theirs}"));
        }
    }
    if !report.mismatches.is_empty() {
        return;
    }
    compare_bodies(model, mj, report);
    compare_inertials(model, mj, report);
    compare_joints(model, mj, report);
    let qpos0 = mj.qpos0();
    report.max_static = report.max_static.max(qpos0_dev(model, qpos0));
    compare_geoms_sites(model, mj, report);
}

fn compare_bodies(model: &Model, mj: &MjModel, report: &mut Report) {
    let (parents, pos, quat) = (mj.body_parentid(), mj.body_pos(), mj.body_quat());
    for (i, b) in model.bodies.iter().enumerate() {
        let name = name_of(mj, MjtObjBase::mjOBJ_BODY, i);
        if b.name != name || b.parent != parents[i] as usize {
            report.mismatches.push(format!(
                "body {i}: ours {:?} (parent {}), mujoco {name:?} (parent {})",
                b.name, b.parent, parents[i]
            ));
        }
        let d = max_abs(b.pos.as_slice(), &pos[i])
            .max(quat_dev(&[b.quat.w, b.quat.i, b.quat.j, b.quat.k], &quat[i]));
        report.max_static = report.max_static.max(d);
    }
}

/// Every body with an inertial here against MuJoCo's `body_mass`, `body_ipos` and the tensor
/// `R diag Rᵀ` of `body_iquat`, `body_inertia` (principal axes have no unique order or sign).
fn compare_inertials(model: &Model, mj: &MjModel, report: &mut Report) {
    let (mass, ipos, iquat, inertia) =
        (mj.body_mass(), mj.body_ipos(), mj.body_iquat(), mj.body_inertia());
    for (i, body) in model.bodies.iter().enumerate().skip(1) {
        let Some(ours) = &body.inertial else {
            report.inertials_skipped += 1;
            continue;
        };
        let [w, x, y, z] = iquat[i];
        let theirs = Inertial {
            mass: mass[i],
            pos: Vector3::from(ipos[i]),
            quat: UnitQuaternion::new_normalize(Quaternion::new(w, x, y, z)),
            diag: Vector3::from(inertia[i]),
        };
        let tensor = crate::inertia::tensor;
        let d = (ours.mass - theirs.mass)
            .abs()
            .max((ours.pos - theirs.pos).amax())
            .max((tensor(ours) - tensor(&theirs)).amax());
        report.inertials += 1;
        report.max_inertial = report.max_inertial.max(d);
        if d > INERTIAL_TOLERANCE {
            report.mismatches.push(format!(
                "body {i} {:?}: inertial ours mass {} com {:?} moments {:?}, mujoco mass {} com {:?} moments {:?} (deviation {d:.3e})",
                body.name,
                ours.mass,
                ours.pos.as_slice(),
                ours.diag.as_slice(),
                theirs.mass,
                theirs.pos.as_slice(),
                theirs.diag.as_slice()
            ));
        }
    }
}

fn compare_joints(model: &Model, mj: &MjModel, report: &mut Report) {
    let (types, qadr, dadr, body) =
        (mj.jnt_type(), mj.jnt_qposadr(), mj.jnt_dofadr(), mj.jnt_bodyid());
    let (limited, range, axis, pos) =
        (mj.jnt_limited(), mj.jnt_range(), mj.jnt_axis(), mj.jnt_pos());
    for (j, joint) in model.joints.iter().enumerate() {
        let name = name_of(mj, MjtObjBase::mjOBJ_JOINT, j);
        let kind = match types[j] as u32 {
            0 => JointType::Free,
            1 => JointType::Ball,
            2 => JointType::Slide,
            _ => JointType::Hinge,
        };
        let same = joint.name == name
            && joint.kind == kind
            && joint.qpos_adr == qadr[j] as usize
            && joint.dof_adr == dadr[j] as usize
            && joint.body == body[j] as usize
            && joint.range.is_some() == limited[j];
        if !same {
            report.mismatches.push(format!(
                "joint {j}: ours {:?} {} limited={}, mujoco {name:?} {} limited={}",
                joint.name,
                joint.kind.as_str(),
                joint.range.is_some(),
                kind.as_str(),
                limited[j]
            ));
        }
        let mut d = max_abs(joint.pos.as_slice(), &pos[j]);
        if matches!(kind, JointType::Hinge | JointType::Slide) {
            d = d.max(max_abs(joint.axis.as_slice(), &axis[j]));
        }
        if let Some(r) = joint.range {
            d = d.max(max_abs(&r, &range[j]));
        }
        report.max_static = report.max_static.max(d);
    }
}

fn qpos0_dev(model: &Model, qpos0: &[f64]) -> f64 {
    let mut d = 0.0f64;
    for joint in &model.joints {
        let a = joint.qpos_adr;
        let ours = &model.qpos0[a..a + joint.kind.nq()];
        let theirs = &qpos0[a..a + joint.kind.nq()];
        d = d.max(match joint.kind {
            JointType::Free => max_abs(&ours[..3], &theirs[..3])
                .max(quat_dev(&ours[3..], &[theirs[3], theirs[4], theirs[5], theirs[6]])),
            JointType::Ball => quat_dev(ours, &[theirs[0], theirs[1], theirs[2], theirs[3]]),
            _ => max_abs(ours, theirs),
        });
    }
    d
}

fn compare_geoms_sites(model: &Model, mj: &MjModel, report: &mut Report) {
    let (gbody, gpos, gquat) = (mj.geom_bodyid(), mj.geom_pos(), mj.geom_quat());
    for (g, geom) in model.geoms.iter().enumerate() {
        if geom.body != gbody[g] as usize {
            report.mismatches.push(format!(
                "geom {g} {:?}: body ours {}, mujoco {}",
                geom.name, geom.body, gbody[g]
            ));
        }
        if geom.kind != GeomType::Mesh {
            let q = [geom.quat.w, geom.quat.i, geom.quat.j, geom.quat.k];
            report.max_static = report
                .max_static
                .max(max_abs(geom.pos.as_slice(), &gpos[g]).max(quat_dev(&q, &gquat[g])));
        }
    }
    let (sbody, spos, squat) = (mj.site_bodyid(), mj.site_pos(), mj.site_quat());
    for (s, site) in model.sites.iter().enumerate() {
        if site.body != sbody[s] as usize {
            report.mismatches.push(format!(
                "site {s} {:?}: body ours {}, mujoco {}",
                site.name, site.body, sbody[s]
            ));
        }
        let q = [site.quat.w, site.quat.i, site.quat.j, site.quat.k];
        report.max_static = report
            .max_static
            .max(max_abs(site.pos.as_slice(), &spos[s]).max(quat_dev(&q, &squat[s])));
    }
}

fn compare_kinematics(model: &Model, mj: &MjModel, options: CheckOptions, report: &mut Report) {
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
    let mut data = Data::new(model);
    let mut mjd = mj.make_data();
    let n = 3 * model.nv;
    let (mut jacp, mut jacr) = (vec![0.0; n], vec![0.0; n]);
    let mesh: Vec<bool> = model.geoms.iter().map(|g| g.kind == GeomType::Mesh).collect();
    // qpos0 first, then `configs` random configurations.
    for c in 0..=options.configs {
        let qpos = if c == 0 { model.qpos0.clone() } else { model.random_qpos(&mut rng) };
        model.kinematics(&qpos, &mut data);
        mjd.qpos_mut().copy_from_slice(&qpos);
        mjd.kinematics();
        mjd.com_pos();
        for b in 0..model.bodies.len() {
            let q = data.xquat[b];
            report.max_xpos = report.max_xpos.max(max_abs(data.xpos[b].as_slice(), &mjd.xpos()[b]));
            report.max_xquat =
                report.max_xquat.max(quat_dev(&[q.w, q.i, q.j, q.k], &mjd.xquat()[b]));
            model.jac_body(&data, b, &mut jacp, &mut jacr);
            let (mp, mr) = mjd.jac_body(true, true, b);
            report.max_jacp = report.max_jacp.max(max_abs(&jacp, &mp));
            report.max_jacr = report.max_jacr.max(max_abs(&jacr, &mr));
        }
        for (g, x) in data.geom_xpos.iter().enumerate().filter(|(g, _)| !mesh[*g]) {
            report.max_geom_site = report.max_geom_site.max(dev3(x, &mjd.geom_xpos()[g]));
        }
        for (s, x) in data.site_xpos.iter().enumerate() {
            report.max_geom_site = report.max_geom_site.max(dev3(x, &mjd.site_xpos()[s]));
        }
    }
}

fn dev3(a: &Vector3<f64>, b: &[f64; 3]) -> f64 {
    max_abs(a.as_slice(), b)
}

// ------------------------------------------------------------------------------------------
// Collision geometry
// ------------------------------------------------------------------------------------------

/// [`check_collision`] compares distances only for pairs closer than this (m).
pub const NEAR: f64 = 0.05;

/// Deviations of one kind of distance computation from `mj_geomDistance`.
#[derive(Debug, Clone, Copy, Default)]
pub struct DistanceDeviation {
    /// Pair × configuration comparisons (pairs closer than [`NEAR`] by either computation).
    pub compared: usize,
    /// Of those, penetrating ones.
    pub penetrating: usize,
    /// Largest |signed distance difference| (m).
    pub distance: f64,
    /// Largest distance of one of our witness points from its geom's surface (m), measured
    /// with MuJoCo's `geom_xpos`, `geom_xmat` and `geom_size`. Witness points need not be
    /// unique (parallel faces), so this, not their difference from MuJoCo's, is what we check.
    pub surface: f64,
    /// Largest |witness point − MuJoCo's| (m): information only (see `surface`).
    pub point: f64,
    /// Largest |normal − MuJoCo's| where |distance| > 1 mm (MuJoCo's normal is
    /// `(to − from) / distance`).
    pub normal: f64,
}

impl DistanceDeviation {
    fn add(
        &mut self,
        penetrating: bool,
        distance: f64,
        surface: f64,
        point: f64,
        normal: Option<f64>,
    ) {
        self.compared += 1;
        self.penetrating += usize::from(penetrating);
        self.distance = self.distance.max(distance);
        self.surface = self.surface.max(surface);
        self.point = self.point.max(point);
        self.normal = self.normal.max(normal.unwrap_or(0.0));
    }

    fn within(&self, distance: f64, surface: f64, normal: f64) -> bool {
        self.distance <= distance && self.surface <= surface && self.normal <= normal
    }
}

/// Result of [`check_collision`].
#[derive(Debug, Clone, Default)]
pub struct CollisionReport {
    /// Differences in the filter's inputs or in the pair list, and distances that disagree in
    /// kind (empty when everything agrees).
    pub mismatches: Vec<String>,
    /// Our [`Model::collision_pairs`], and how many of them have two primitive geoms.
    pub pairs: usize,
    pub primitive_pairs: usize,
    pub configs: usize,
    /// Contacts `mj_collision` found over all configurations (each must be one of our pairs).
    pub engine_contacts: usize,
    /// Sphere and capsule pairs: closed forms on both sides.
    pub closed_form: DistanceDeviation,
    /// Pairs MuJoCo hands to its native GJK/EPA (box–box, and every pair with an ellipsoid or
    /// a cylinder except sphere–cylinder), as do we.
    pub gjk: DistanceDeviation,
    /// Sphere–box, capsule–box and sphere–cylinder apart (MuJoCo's primitive colliders, our
    /// GJK); penetrating ones are in `shallower`.
    pub primitive: DistanceDeviation,
    /// Penetrating pairs of the kind above where MuJoCo's depth is shallower than ours:
    /// `mjc_CapsuleBox` reports a contact depth, not the minimum separating translation (the
    /// unit test `penetration_depth_is_the_minimum_translation` shows ours is that minimum).
    /// Each is checked to be no deeper in MuJoCo than in ours.
    pub shallower: usize,
    /// Largest deviation of a lowest point beyond what the two models' geom frames explain:
    /// |z − (centre z − support along −z)| and the point's distance outside its geom, both
    /// from MuJoCo's `geom_xpos`/`geom_xmat`/`geom_size`, less |Δxmat|·|size|.
    pub max_lowest: f64,
    /// Largest |our geom_xmat − MuJoCo's| (MuJoCo snaps a geom frame within ~1e-6 of its
    /// body's or inertial frame onto it, `geom_sameframe`).
    pub max_xmat: f64,
    /// Largest |bounding radius − MuJoCo `geom_rbound`| over primitives.
    pub max_rbound: f64,
}

/// Tolerances of [`CollisionReport::passes`].
#[derive(Debug, Clone, Copy)]
pub struct CollisionTolerances {
    /// |Δ distance| (m) and |Δ normal| where both sides use closed forms or exact primitive
    /// colliders (sphere/capsule pairs; sphere–box, capsule–box, sphere–cylinder when
    /// separated).
    pub exact_distance: f64,
    pub exact_normal: f64,
    /// |Δ distance| (m) and |Δ normal| where both sides use GJK/EPA.
    pub gjk_distance: f64,
    pub gjk_normal: f64,
    /// Witness points' distance from their geoms' surfaces (m).
    pub surface: f64,
    /// Lowest points beyond the frame difference, bounding radii (m).
    pub lowest: f64,
}

impl CollisionReport {
    /// No mismatch and every deviation within `tol`.
    #[must_use]
    pub fn passes(&self, tol: &CollisionTolerances) -> bool {
        self.mismatches.is_empty()
            && self.closed_form.within(tol.exact_distance, tol.surface, tol.exact_normal)
            && self.primitive.within(tol.exact_distance, tol.surface, tol.exact_normal)
            && self.gjk.within(tol.gjk_distance, tol.surface, tol.gjk_normal)
            && self.max_lowest <= tol.lowest
            && self.max_rbound <= tol.lowest
    }
}

impl fmt::Display for CollisionReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let status = if self.mismatches.is_empty() { "identical" } else { "MISMATCH" };
        writeln!(f, "collision filter inputs and pairs: {status} ({} pairs)", self.pairs)?;
        for m in &self.mismatches {
            writeln!(f, "  {m}")?;
        }
        writeln!(
            f,
            "over {} configurations: {} mj_collision contacts, all on our pair list",
            self.configs, self.engine_contacts
        )?;
        for (what, d) in [
            ("sphere/capsule", self.closed_form),
            ("gjk/epa", self.gjk),
            ("sphere,capsule-box/cyl", self.primitive),
        ] {
            writeln!(
                f,
                "  {what:<22} {:>5} < {NEAR} m ({:>4} pen.): |Δdist| {:.1e}, off surface {:.1e}, |Δnormal| {:.1e}, |Δpoint| {:.1e}",
                d.compared, d.penetrating, d.distance, d.surface, d.normal, d.point
            )?;
        }
        writeln!(f, "  penetrating, shallower in mjc_CapsuleBox/SphereBox: {}", self.shallower)?;
        write!(
            f,
            "  lowest points {:.1e} m (geom frames differ by up to {:.1e}), bounding radii {:.1e} m",
            self.max_lowest, self.max_xmat, self.max_rbound
        )
    }
}

fn geom_type_of(code: u32) -> GeomType {
    [
        GeomType::Plane,
        GeomType::Hfield,
        GeomType::Sphere,
        GeomType::Capsule,
        GeomType::Ellipsoid,
        GeomType::Cylinder,
        GeomType::Box,
        GeomType::Mesh,
    ]
    .get(code as usize)
    .copied()
    .unwrap_or(GeomType::Sdf)
}

/// MuJoCo's collision filter (see [`Model::collision_pairs`] for the rule and its source)
/// applied to MuJoCo's own compiled arrays: `geom_type`, `geom_bodyid`, `geom_contype`,
/// `geom_conaffinity`, `body_weldid`, `body_parentid`, `exclude_signature`, `pair_geom1/2` and
/// `opt.disableflags`.
fn mujoco_pairs(mj: &MjModel) -> Vec<[usize; 2]> {
    let kinds: Vec<GeomType> = mj.geom_type().iter().map(|t| geom_type_of(*t as u32)).collect();
    let (body, contype, conaff) = (mj.geom_bodyid(), mj.geom_contype(), mj.geom_conaffinity());
    let (weld, parent) = (mj.body_weldid(), mj.body_parentid());
    let filterparent = mj.ffi().opt.disableflags
        & mujoco_rs::mujoco_c::mjtDisableBit::mjDSBL_FILTERPARENT as i32
        == 0;
    let excluded: std::collections::BTreeSet<[usize; 2]> = mj
        .exclude_signature()
        .iter()
        .map(|s| {
            let (a, b) = ((s >> 16) as usize, (s & 0xFFFF) as usize);
            [a.min(b), a.max(b)]
        })
        .collect();
    let flat = |t: GeomType| matches!(t, GeomType::Plane | GeomType::Hfield);
    let mut pairs = std::collections::BTreeSet::new();
    let n = kinds.len();
    for g1 in 0..n {
        for g2 in g1 + 1..n {
            let (b1, b2) = (body[g1] as usize, body[g2] as usize);
            let (w1, w2) = (weld[b1], weld[b2]);
            let (pw1, pw2) =
                (weld[parent[w1 as usize] as usize], weld[parent[w2 as usize] as usize]);
            let welded = w1 == w2;
            let related = filterparent && w1 != 0 && w2 != 0 && (w1 == pw2 || w2 == pw1);
            let bitmask = contype[g1] & conaff[g2] != 0 || contype[g2] & conaff[g1] != 0;
            let no_function = flat(kinds[g1]) && flat(kinds[g2]);
            let exclude = excluded.contains(&[b1.min(b2), b1.max(b2)]);
            if bitmask && !(welded || related || no_function || exclude) {
                pairs.insert([g1, g2]);
            }
        }
    }
    for (a, b) in mj.pair_geom1().iter().zip(mj.pair_geom2()) {
        let (a, b) = (*a as usize, *b as usize);
        if a != b && !(flat(kinds[a]) && flat(kinds[b])) {
            pairs.insert([a.min(b), a.max(b)]);
        }
    }
    pairs.into_iter().collect()
}

fn compare_filter_inputs(model: &Model, mj: &MjModel, report: &mut CollisionReport) {
    if model.geoms.len() != mj.ffi().ngeom as usize {
        report.mismatches.push(format!(
            "ngeom: ours {}, mujoco {}",
            model.geoms.len(),
            mj.ffi().ngeom
        ));
        return;
    }
    let (contype, conaff, rbound) = (mj.geom_contype(), mj.geom_conaffinity(), mj.geom_rbound());
    for (g, geom) in model.geoms.iter().enumerate() {
        if geom.contype != contype[g] || geom.conaffinity != conaff[g] {
            report.mismatches.push(format!(
                "geom {g} {:?}: contype/conaffinity ours {}/{}, mujoco {}/{}",
                geom.name, geom.contype, geom.conaffinity, contype[g], conaff[g]
            ));
        }
        if let Some(r) = geom.bounding_radius() {
            report.max_rbound = report.max_rbound.max((r - rbound[g]).abs());
        }
    }
    let weld = model.body_weld_ids();
    for (b, (ours, theirs)) in weld.iter().zip(mj.body_weldid()).enumerate() {
        if *ours != *theirs as usize {
            report.mismatches.push(format!("body {b}: weld id ours {ours}, mujoco {theirs}"));
        }
    }
    let (ours, theirs) = (model.collision_pairs(), mujoco_pairs(mj));
    let name = |g: usize| name_of(mj, MjtObjBase::mjOBJ_GEOM, g);
    for p in ours.iter().filter(|p| !theirs.contains(p)) {
        report.mismatches.push(format!("pair {p:?} ({}, {}) only ours", name(p[0]), name(p[1])));
    }
    for p in theirs.iter().filter(|p| !ours.contains(p)) {
        report.mismatches.push(format!(
            "pair {p:?} ({}, {}) only mujoco's",
            name(p[0]),
            name(p[1])
        ));
    }
}

/// Our collision geometry against MuJoCo 3.17.0 on `path` (the file `model` was read from):
/// - the filter's inputs (`contype`, `conaffinity`, weld ids) and [`Model::collision_pairs`]
///   against MuJoCo's filtering rule applied to MuJoCo's compiled arrays, and, at every
///   configuration, every contact `mj_collision` finds is on our list;
/// - at `qpos0` and `options.configs` random configurations, [`crate::geom_distance`] against
///   `mj_geomDistance` for every primitive pair closer than [`NEAR`] (signed distance, witness
///   points on their surfaces, normal), on MuJoCo's geom poses;
/// - [`crate::geom_lowest_point`] of every primitive against the support function along −z
///   computed from MuJoCo's `geom_xpos`, `geom_xmat`, `geom_size`, and the point lying on the
///   geom; [`crate::Geom::bounding_radius`] against `geom_rbound`.
pub fn check_collision(
    model: &Model,
    path: &Path,
    options: CheckOptions,
) -> Result<CollisionReport, Error> {
    let mj = MjModel::from_xml(path).map_err(|e| mujoco_error(path, e))?;
    let mut report = CollisionReport { configs: options.configs, ..CollisionReport::default() };
    compare_filter_inputs(model, &mj, &mut report);
    if !report.mismatches.is_empty() {
        return Ok(report);
    }
    let pairs = model.collision_pairs();
    let primitive: Vec<[usize; 2]> = pairs
        .iter()
        .copied()
        .filter(|p| p.iter().all(|&g| model.geoms[g].kind.is_primitive()))
        .collect();
    (report.pairs, report.primitive_pairs) = (pairs.len(), primitive.len());
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
    let mut data = Data::new(model);
    let mut mjd = mj.make_data();
    for c in 0..=options.configs {
        let qpos = if c == 0 { model.qpos0.clone() } else { model.random_qpos(&mut rng) };
        model.kinematics(&qpos, &mut data);
        mjd.qpos_mut().copy_from_slice(&qpos);
        mjd.forward();
        for contact in mjd.contact() {
            let (a, b) = (contact.geom[0] as usize, contact.geom[1] as usize);
            report.engine_contacts += 1;
            if pairs.binary_search(&[a.min(b), a.max(b)]).is_err() {
                report
                    .mismatches
                    .push(format!("config {c}: mj_collision collided {a}, {b}, not on our list"));
            }
        }
        // Distances on MuJoCo's own geom poses: this compares the geometry, not the frames
        // (MuJoCo snaps a geom frame within ~1e-6 of its body's or inertial frame onto it).
        let mut posed = data.clone();
        for g in 0..model.geoms.len() {
            posed.geom_xpos[g] = Vector3::from(mjd.geom_xpos()[g]);
            posed.geom_xmat[g] = nalgebra::Matrix3::from_row_slice(&mjd.geom_xmat()[g]);
        }
        for &[g1, g2] in &primitive {
            compare_distance(model, &posed, &mut mjd, [g1, g2], c, &mut report);
        }
        compare_lowest_points(model, &data, &mj, &mjd, &mut report);
    }
    Ok(report)
}

/// How MuJoCo's `mj_geomDistance` computes a pair (`mjCOLLISIONFUNC`): 0 closed-form
/// sphere/capsule colliders, 1 native GJK/EPA (`mjc_Convex`, `mjc_BoxBox`), 2 the other
/// primitive colliders (`mjc_SphereBox`, `mjc_CapsuleBox`, `mjc_SphereCylinder`).
fn mujoco_method(a: GeomType, b: GeomType) -> usize {
    use GeomType::{Box, Capsule, Cylinder, Sphere};
    match (a, b) {
        (Sphere | Capsule, Sphere | Capsule) => 0,
        (Sphere | Capsule, Box) | (Box, Sphere | Capsule) => 2,
        (Sphere, Cylinder) | (Cylinder, Sphere) => 2,
        _ => 1,
    }
}

/// Signed distance of `p` from the surface of a primitive of MuJoCo's `kind`, `size` at
/// `xpos`, `xmat` (row-major). Exact except for the ellipsoid, where it is the radial scaling
/// residual (zero on the surface, like the others).
fn surface_offset(
    kind: GeomType,
    size: [f64; 3],
    xpos: &[f64; 3],
    xmat: &[f64; 9],
    p: &Vector3<f64>,
) -> f64 {
    let m = nalgebra::Matrix3::from_row_slice(xmat);
    let l = m.tr_mul(&(p - Vector3::from(*xpos)));
    let [a, b, c] = size;
    let outside_inside =
        |d: Vector3<f64>| d.map(|v| v.max(0.0)).norm() + d.x.max(d.y).max(d.z).min(0.0);
    match kind {
        GeomType::Sphere => l.norm() - a,
        GeomType::Capsule => Vector3::new(l.x, l.y, l.z - l.z.clamp(-b, b)).norm() - a,
        GeomType::Cylinder => {
            let (dr, dz) = (l.x.hypot(l.y) - a, l.z.abs() - b);
            dr.max(0.0).hypot(dz.max(0.0)) + dr.max(dz).min(0.0)
        }
        GeomType::Box => outside_inside(l.abs() - Vector3::new(a, b, c)),
        _ => (l.component_div(&Vector3::new(a, b, c)).norm() - 1.0) * a.min(b).min(c),
    }
}

fn compare_distance(
    model: &Model,
    data: &Data,
    mjd: &mut mujoco_rs::prelude::MjData<&MjModel>,
    [g1, g2]: [usize; 2],
    config: usize,
    report: &mut CollisionReport,
) {
    // Ask both for more than NEAR so that a pair near the threshold is seen by both.
    let reach = 2.0 * NEAR;
    let mut fromto = [0.0; 6];
    let theirs = mjd.geom_distance(g1, g2, reach, Some(&mut fromto));
    let ours = crate::geom_distance(model, data, g1, g2, reach);
    if theirs >= NEAR && ours.is_none_or(|p| p.distance >= NEAR) {
        return;
    }
    let Some(p) = ours else {
        report.mismatches.push(format!(
            "config {config}: geoms {g1}, {g2}: mujoco distance {theirs:.6}, ours none"
        ));
        return;
    };
    let (k1, k2) = (model.geoms[g1].kind, model.geoms[g2].kind);
    let (from, to) = (
        Vector3::new(fromto[0], fromto[1], fromto[2]),
        Vector3::new(fromto[3], fromto[4], fromto[5]),
    );
    let (xpos, xmat) = (mjd.geom_xpos(), mjd.geom_xmat());
    let size = |g: usize| model.geoms[g].size;
    let surface = surface_offset(k1, size(g1), &xpos[g1], &xmat[g1], &p.point1)
        .abs()
        .max(surface_offset(k2, size(g2), &xpos[g2], &xmat[g2], &p.point2).abs());
    let point = (p.point1 - from).norm().max((p.point2 - to).norm());
    let penetrating = p.distance < 0.0 || theirs < 0.0;
    let method = mujoco_method(k1, k2);
    if method == 2 && penetrating {
        report.shallower += usize::from(p.distance < theirs);
        if p.distance > theirs + 1e-9 {
            report.mismatches.push(format!(
                "config {config}: geoms {g1}, {g2} ({k1:?}, {k2:?}): ours {:.6} shallower than mujoco's {theirs:.6}",
                p.distance
            ));
        }
        report.primitive.surface = report.primitive.surface.max(surface);
        return;
    }
    let normal = (theirs.abs() > 1e-3).then(|| (p.normal - (to - from) / theirs).norm());
    let stats = match method {
        0 => &mut report.closed_form,
        1 => &mut report.gjk,
        _ => &mut report.primitive,
    };
    stats.add(penetrating, (p.distance - theirs).abs(), surface, point, normal);
}

fn compare_lowest_points(
    model: &Model,
    data: &Data,
    mj: &MjModel,
    mjd: &mujoco_rs::prelude::MjData<&MjModel>,
    report: &mut CollisionReport,
) {
    let (xpos, xmat, size) = (mjd.geom_xpos(), mjd.geom_xmat(), mj.geom_size());
    for (g, geom) in model.geoms.iter().enumerate() {
        let Some(low) = crate::geom_lowest_point(model, data, g) else { continue };
        let c = Vector3::from(xpos[g]);
        // xmat is row-major: rz is the world-z row, the local axes' heights.
        let m = nalgebra::Matrix3::from_row_slice(&xmat[g]);
        let rz = m.row(2).transpose();
        let [a, b, h] = size[g];
        let (extent, outside) = {
            let l = m.tr_mul(&(low - c));
            match geom.kind {
                GeomType::Sphere => (a, l.norm() - a),
                GeomType::Capsule => {
                    (b * rz.z.abs() + a, Vector3::new(l.x, l.y, l.z - l.z.clamp(-b, b)).norm() - a)
                }
                GeomType::Cylinder => (
                    // √(1 − R_zz²), precisely
                    b * rz.z.abs() + a * rz.x.hypot(rz.y),
                    (l.x.hypot(l.y) - a).max(l.z.abs() - b),
                ),
                GeomType::Box => (
                    a * rz.x.abs() + b * rz.y.abs() + h * rz.z.abs(),
                    (l.x.abs() - a).max(l.y.abs() - b).max(l.z.abs() - h),
                ),
                _ => {
                    let s = Vector3::new(a, b, h);
                    (s.component_mul(&rz).norm(), l.component_div(&s).norm() - 1.0)
                }
            }
        };
        let dev = (low.z - (c.z - extent)).abs().max(outside.max(0.0));
        let dxmat = (data.geom_xmat[g] - m).norm();
        let allowance = dxmat * Vector3::from(size[g]).norm() + (data.geom_xpos[g] - c).norm();
        report.max_xmat = report.max_xmat.max(dxmat);
        report.max_lowest = report.max_lowest.max(dev - allowance);
    }
}

// ------------------------------------------------------------------------------------------
// Box–box contact manifolds
// ------------------------------------------------------------------------------------------

/// Result of [`check_box_manifolds`].
#[derive(Debug, Clone, Default)]
pub struct ManifoldReport {
    /// Poses drawn, and of those with a manifold here.
    pub configs: usize,
    pub touching: usize,
    /// Face manifolds with the incident face within 60° of the reference face, where MuJoCo
    /// clips the same face: compared point by point (count, midpoints, depths).
    pub faces: usize,
    pub face_points: usize,
    /// Face manifolds with the incident face tilted further, where MuJoCo clips only the
    /// incident box's edges within 60° of the reference face (one edge or one corner): the
    /// deepest contact and the normal compared.
    pub tilted: usize,
    /// Edge–edge manifolds: one point here; MuJoCo's collider puts several along its own
    /// normal, so these are compared with `mj_geomDistance` instead (below).
    pub edges: usize,
    pub edge_points: usize,
    /// Boxes apart, with contacts within the margin in MuJoCo and no manifold here: the faces
    /// (projected along the normal) meet only beside each other, where MuJoCo keeps the
    /// deepest corner or edge points anyway (and [`crate::geom_distance`] gives the witness).
    pub beside: usize,
    /// Largest |our midpoint − MuJoCo's contact position| (m), point by point.
    pub max_point: f64,
    /// Largest |our distance − MuJoCo's| (m): point by point, and deepest against deepest.
    pub max_distance: f64,
    /// Largest |our normal − MuJoCo's contact normal| (face manifolds).
    pub max_normal: f64,
    /// Overlapping poses, and of those where our depth is within 1e-6 m of
    /// `mj_geomDistance`'s (MuJoCo's GJK/EPA). Where it is not, EPA stopped short: its
    /// polytope lies inside the Minkowski difference, so an early stop is shallower, and ours
    /// must then be the deeper (a mismatch otherwise).
    pub overlapping: usize,
    pub as_deep_as_epa: usize,
    /// Poses where the two disagree in kind: overlapping boxes without a manifold here, a
    /// face manifold without contacts in MuJoCo, a different number of points, or a depth
    /// shallower than EPA's.
    pub mismatches: Vec<String>,
}

impl ManifoldReport {
    /// No mismatch and every face deviation within `tolerance`.
    #[must_use]
    pub fn passes(&self, tolerance: f64) -> bool {
        self.mismatches.is_empty()
            && self.max_point <= tolerance
            && self.max_distance <= tolerance
            && self.max_normal <= tolerance
    }
}

impl fmt::Display for ManifoldReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{} poses, {} with a manifold: {} faces ({} points) compared point by point, {} tilted, {} edge-edge ({} points); {} apart beside the faces",
            self.configs,
            self.touching,
            self.faces,
            self.face_points,
            self.tilted,
            self.edges,
            self.edge_points,
            self.beside
        )?;
        for m in &self.mismatches {
            writeln!(f, "  {m}")?;
        }
        writeln!(
            f,
            "  against mj_collision: |Δpoint| {:.1e} m, |Δdistance| {:.1e} m, |Δnormal| {:.1e}",
            self.max_point, self.max_distance, self.max_normal
        )?;
        write!(
            f,
            "  against mj_geomDistance: {} of {} overlapping poses as deep within 1e-6 m",
            self.as_deep_as_epa, self.overlapping
        )
    }
}

/// [`crate::box_manifold`] against MuJoCo for two free boxes of half sizes `sizes` with geom
/// margin `margin`, at `options.configs` random relative poses near contact (box 2's centre
/// within the sum of the bounding radii of box 1's), on MuJoCo's own geom poses:
/// - face manifolds against the contacts of `mj_collision` (its box–box collider, contacts
///   no farther than `margin`), which it reports midway between the surfaces (ours: the
///   midpoint of each point pair);
/// - where the boxes overlap, the manifold's depth against `mj_geomDistance`'s: never
///   shallower. (Apart, the two measure different things: a face manifold's points are
///   pairs of surface points, no closer than the distance; an edge pair's gap along the
///   normal can be smaller.)
pub fn check_box_manifolds(
    sizes: [[f64; 3]; 2],
    margin: f64,
    options: CheckOptions,
) -> Result<ManifoldReport, Error> {
    let body = |s: [f64; 3]| {
        format!(
            r#"<body><freejoint/><geom type="box" size="{} {} {}" margin="{margin}"/></body>"#,
            s[0], s[1], s[2]
        )
    };
    let xml =
        format!("<mujoco><worldbody>{}{}</worldbody></mujoco>", body(sizes[0]), body(sizes[1]));
    let model = Model::from_xml_str(&xml, None)?;
    let mj = MjModel::from_xml_string(&xml).map_err(|e| mujoco_error(Path::new("<boxes>"), e))?;
    let reach: f64 = sizes.iter().map(|s| Vector3::from(*s).norm()).sum();
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
    let mut data = Data::new(&model);
    let mut mjd = mj.make_data();
    let mut report = ManifoldReport { configs: options.configs, ..ManifoldReport::default() };
    for c in 0..options.configs {
        let mut qpos = model.random_qpos(&mut rng);
        qpos[..3].fill(0.0);
        for v in &mut qpos[7..10] {
            *v = rand::Rng::gen_range(&mut rng, -reach..reach);
        }
        mjd.qpos_mut().copy_from_slice(&qpos);
        mjd.forward();
        for g in 0..2 {
            data.geom_xpos[g] = Vector3::from(mjd.geom_xpos()[g]);
            data.geom_xmat[g] = nalgebra::Matrix3::from_row_slice(&mjd.geom_xmat()[g]);
        }
        let ours = crate::box_manifold(&model, &data, 0, 1, margin);
        // Contact normals from geom 0 to geom 1.
        let theirs: Vec<Contact> = mjd
            .contact()
            .iter()
            .filter(|k| k.dist <= margin)
            .map(|k| {
                let n = Vector3::new(k.frame[0], k.frame[1], k.frame[2]);
                Contact {
                    pos: Vector3::from(k.pos),
                    dist: k.dist,
                    normal: if k.geom[0] == 0 { n } else { -n },
                }
            })
            .collect();
        if let Some(m) = &ours {
            let exact = mjd.geom_distance(0, 1, 2.0 * reach, None);
            compare_with_epa(c, m.distance(), exact, &mut report);
        }
        compare_manifold(c, ours.as_ref(), &theirs, &data, &mut report);
    }
    Ok(report)
}

/// One contact of `mj_collision` (normal from geom 0 to geom 1).
struct Contact {
    pos: Vector3<f64>,
    dist: f64,
    normal: Vector3<f64>,
}

fn compare_with_epa(config: usize, ours: f64, exact: f64, report: &mut ManifoldReport) {
    if ours >= 0.0 && exact >= 0.0 {
        return;
    }
    report.overlapping += 1;
    report.as_deep_as_epa += usize::from((ours - exact).abs() <= 1e-6);
    if ours > exact + 1e-9 {
        report.mismatches.push(format!(
            "pose {config}: distance {ours:.9}, shallower than mj_geomDistance's {exact:.9}"
        ));
    }
}

fn compare_manifold(
    config: usize,
    ours: Option<&crate::Manifold>,
    theirs: &[Contact],
    data: &Data,
    report: &mut ManifoldReport,
) {
    use crate::ManifoldFeature::{Edges, Face1, Face2};
    let Some(m) = ours else {
        if theirs.iter().any(|t| t.dist < 0.0) {
            report.mismatches.push(format!(
                "pose {config}: {} contacts in mujoco, one penetrating; none here",
                theirs.len()
            ));
        } else if !theirs.is_empty() {
            report.beside += 1;
        }
        return;
    };
    report.touching += 1;
    let incident = match m.feature {
        Edges(..) => {
            report.edges += 1;
            report.edge_points += m.points().len();
            return;
        }
        Face1(_) => 1,
        Face2(_) => 0,
    };
    let Some(first) = theirs.first() else {
        report
            .mismatches
            .push(format!("pose {config}: {:?} here, no contact in mujoco", m.feature));
        return;
    };
    let deepest = theirs.iter().map(|t| t.dist).fold(f64::INFINITY, f64::min);
    report.max_distance = report.max_distance.max((deepest - m.distance()).abs());
    report.max_normal = report.max_normal.max((first.normal - m.normal).norm());
    // MuJoCo clips a whole face when two of the incident box's axes are within 60° of the
    // reference face (|cos| < 0.5 to its normal).
    let in_plane =
        (0..3).filter(|&k| data.geom_xmat[incident].column(k).dot(&m.normal).abs() < 0.5).count();
    if in_plane < 2 {
        report.tilted += 1;
        return;
    }
    report.faces += 1;
    if m.points().len() != theirs.len() {
        report.mismatches.push(format!(
            "pose {config}: {:?} with {} points, mujoco {}",
            m.feature,
            m.points().len(),
            theirs.len()
        ));
        return;
    }
    for p in m.points() {
        report.face_points += 1;
        let mid = (p.point1 + p.point2) / 2.0;
        let nearest =
            theirs.iter().min_by(|x, y| (x.pos - mid).norm().total_cmp(&(y.pos - mid).norm()));
        if let Some(t) = nearest {
            report.max_point = report.max_point.max((t.pos - mid).norm());
            report.max_distance = report.max_distance.max((t.dist - p.distance).abs());
        }
    }
}
