//! Our kinematics against MuJoCo 3.17.0's on the same file (cargo feature `mujoco`): the
//! compiled model (sizes, names, order, ranges, `qpos0`, body and joint frames) and, at random
//! configurations, every body pose, every body Jacobian and every geom and site position.
//! Shared by the parity tests and `retarget robot check`.
//!
//! A URDF is compiled by MuJoCo's own URDF import (`mj_loadXML` reads `<robot>` files). MuJoCo
//! adds no free joint there, so a model read with [`UrdfBase::Fixed`] is compared with that
//! compile as it is; for [`UrdfBase::Floating`] the free joint is added on MuJoCo's side too,
//! through its model-editing API on the parsed spec, the way MuJoCo itself does it when it
//! loads a URDF as a moving body (`xml_urdf.cc`: `ROOT_free_joint` on the root link), then
//! MuJoCo compiles it (static links fused as usual).

use std::fmt;
use std::path::Path;

use mujoco_rs::prelude::{MjModel, MjSpec, MjtJoint, MjtObjBase, SpecElement, SpecItem};
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::{Data, Error, GeomType, JointType, Model, UrdfBase, UrdfOptions};

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
