//! Typed MJCF tree → [`Model`], following MuJoCo's compiler (`user_model.cc`, `user_objects.cc`):
//! default classes with inheritance and `childclass`, angle units, orientation specifiers,
//! `<frame>` composition (bodies, geoms, sites and joints), `autolimits`, joint addresses and
//! `qpos0`; `fusestatic` (`mjCModel::FuseStatic` as 3.17 does it: every body without joints
//! merges into its parent unless it is a mocap body or another element names it) and
//! `alignfree` (childless free bodies in their inertial frame); mocap bodies (static, at
//! their pose); the collision filter's inputs (geom `contype`/`conaffinity`, `<contact>`
//! excludes and pairs, `filterparent`); body mass and inertia from `<inertial>` (see
//! `inertia`). MuJoCo's dynamic checks (a moving body without mass) are not made: a model
//! for retargeting needs no mass.

use std::collections::{HashMap, HashSet};
use std::f64::consts::PI;

use nalgebra::{UnitQuaternion, Vector3};

use crate::error::Error;
use crate::inertia::{self, InertiaOptions, MJ_MINVAL, NO_MASS};
use crate::math::{orientation_to_quat, z_to_quat};
use crate::model::{Body, Geom, GeomType, Inertial, Joint, JointType, Model, Site};
use crate::source::{Pos, Sources};
use crate::syntax::{
    AngleUnit, BodySpec, CompilerSpec, DefaultSpec, GeomAttrs, GeomSpec, InertiaSpec, InertialSpec,
    Item, JointAttrs, JointSpec, Limited, Mjcf, NameRef, Orientation,
};

/// A default class with its ancestors' attributes merged in.
#[derive(Debug, Clone, Default)]
struct Class {
    joint: JointAttrs,
    geom: GeomAttrs,
    site: GeomAttrs,
}

/// A rigid transform accumulated through `<frame>` elements: `x_parent = pos + quat * x_child`.
#[derive(Debug, Clone, Copy)]
struct Frame {
    pos: Vector3<f64>,
    quat: UnitQuaternion<f64>,
}

impl Frame {
    const IDENTITY: Frame = Frame {
        pos: Vector3::new(0.0, 0.0, 0.0),
        quat: UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(1.0, 0.0, 0.0, 0.0)),
    };

    fn compose(&self, pos: Vector3<f64>, quat: UnitQuaternion<f64>) -> Frame {
        Frame { pos: self.pos + self.quat * pos, quat: self.quat * quat }
    }
}

pub(crate) fn compile(mjcf: &Mjcf, src: &Sources) -> Result<Model, Error> {
    let mut classes = HashMap::new();
    flatten_defaults(&mjcf.default, &Class::default(), src, &mut classes)?;
    let c = &mjcf.compiler;
    let mut compiler = Compiler {
        src,
        classes,
        angle_scale: if c.angle.unwrap_or(AngleUnit::Degree) == AngleUnit::Degree {
            PI / 180.0
        } else {
            1.0
        },
        eulerseq: c.eulerseq.unwrap_or(*b"xyz"),
        autolimits: c.autolimits.unwrap_or(true),
        inertia: inertia_options(c),
        fuse_static: c.fusestatic.unwrap_or(false),
        referenced: &mjcf.referenced_bodies,
        align_free: c.alignfree.unwrap_or(false),
        model: Model {
            name: mjcf.model_name.clone().unwrap_or_default(),
            nq: 0,
            nv: 0,
            bodies: Vec::new(),
            joints: Vec::new(),
            geoms: Vec::new(),
            sites: Vec::new(),
            qpos0: Vec::new(),
            dof_joint: Vec::new(),
            dof_parent: Vec::new(),
            body_last_dof: Vec::new(),
            jnt_pos_zero: Vec::new(),
            geom_mat: Vec::new(),
            site_mat: Vec::new(),
            contact_excludes: Vec::new(),
            contact_pairs: Vec::new(),
            filter_parent: mjcf.filterparent.unwrap_or(true),
        },
    };
    let main_class = mjcf.default.class.clone();
    let mut budget = MAX_EXPANDED;
    let world = expand_replicates(
        &mjcf.worldbody,
        compiler.angle_scale,
        compiler.eulerseq,
        src,
        &mut budget,
    )?;
    compiler.body(&world, 0, Frame::IDENTITY, &main_class)?;
    let total_mass = compiler.inertia.total_mass;
    let mut model = compiler.model;
    if let Some(total) = total_mass {
        inertia::set_total_mass(&mut model.bodies, total);
    }
    model.contact_excludes = resolve_names(&mjcf.contact.excludes, src, "body", |n| {
        model.bodies.iter().position(|b| b.name == n)
    })?;
    model.contact_pairs = resolve_names(&mjcf.contact.pairs, src, "geom", |n| model.geom_id(n))?;
    model.jnt_pos_zero = model.joints.iter().map(|j| j.pos == Vector3::zeros()).collect();
    model.geom_mat = model.geoms.iter().map(|g| *g.quat.to_rotation_matrix().matrix()).collect();
    model.site_mat = model.sites.iter().map(|s| *s.quat.to_rotation_matrix().matrix()).collect();
    Ok(model)
}

/// The body tree with every `<replicate>` turned into its copies, each a `<frame>` placing it
/// (MuJoCo 3.17 expands them the same way before compiling: copy `i` at the `i`-th power of
/// the replicate's frame, names suffixed).
fn expand_replicates(
    body: &BodySpec,
    angle_scale: f64,
    eulerseq: [u8; 3],
    src: &Sources,
    budget: &mut usize,
) -> Result<BodySpec, Error> {
    let mut out = body.clone();
    out.items = expand_items(&body.items, angle_scale, eulerseq, src, budget)?;
    Ok(out)
}

/// Items nested replicates may make in all (their product grows fast).
const MAX_EXPANDED: usize = 1_000_000;

fn expand_items(
    items: &[Item],
    angle_scale: f64,
    eulerseq: [u8; 3],
    src: &Sources,
    budget: &mut usize,
) -> Result<Vec<Item>, Error> {
    let mut out = Vec::with_capacity(items.len());
    for item in items {
        match item {
            Item::Body(b) => {
                out.push(Item::Body(expand_replicates(b, angle_scale, eulerseq, src, budget)?))
            }
            Item::Frame(f) => {
                out.push(Item::Frame(expand_replicates(f, angle_scale, eulerseq, src, budget)?))
            }
            Item::Replicate(r) => {
                let inner = expand_items(&r.items, angle_scale, eulerseq, src, budget)?;
                let size = inner.iter().map(item_count).sum::<usize>().max(1);
                *budget = budget.checked_sub(size.saturating_mul(r.count)).ok_or_else(|| {
                    src.invalid(
                        r.pos,
                        format!("replicates expand to more than {MAX_EXPANDED} elements"),
                    )
                })?;
                let step = Frame {
                    pos: Vector3::from(r.offset),
                    quat: orientation_to_quat(&Orientation::Euler(r.euler), angle_scale, eulerseq)
                        .ok_or_else(|| src.invalid(r.pos, "degenerate replicate euler"))?,
                };
                let digits = r.count.to_string().len();
                let mut frame = Frame::IDENTITY;
                for i in 0..r.count {
                    let suffix = format!("{}{i:0digits$}", r.sep);
                    let mut copy = inner.clone();
                    copy.iter_mut().for_each(|item| suffix_names(item, &suffix));
                    let q = frame.quat;
                    out.push(Item::Frame(BodySpec {
                        name: None,
                        childclass: None,
                        translation: Some(frame.pos.into()),
                        orientation: Some((Orientation::Quat([q.w, q.i, q.j, q.k]), r.pos)),
                        items: copy,
                        mocap: false,
                        pos: r.pos,
                    }));
                    frame = frame.compose(step.pos, step.quat);
                }
            }
            other => out.push(other.clone()),
        }
    }
    Ok(out)
}

/// Elements in `item`, itself included.
fn item_count(item: &Item) -> usize {
    1 + match item {
        Item::Body(b) | Item::Frame(b) => b.items.iter().map(item_count).sum(),
        Item::Replicate(r) => r.items.iter().map(item_count).sum(),
        _ => 0,
    }
}

/// Appends `suffix` to every name in `item` (bodies, joints, geoms, sites, and within).
fn suffix_names(item: &mut Item, suffix: &str) {
    let add = |name: &mut Option<String>| {
        if let Some(n) = name.as_mut() {
            n.push_str(suffix);
        }
    };
    match item {
        Item::Joint(j) => add(&mut j.name),
        Item::Geom(g) | Item::Site(g) => add(&mut g.name),
        Item::Inertial(_) => {}
        Item::Body(b) | Item::Frame(b) => {
            add(&mut b.name);
            b.items.iter_mut().for_each(|i| suffix_names(i, suffix));
        }
        Item::Replicate(r) => r.items.iter_mut().for_each(|i| suffix_names(i, suffix)),
    }
}

/// MuJoCo's defaults: `inertiafromgeom="auto"`, no bounds, no balancing, no total mass.
fn inertia_options(c: &CompilerSpec) -> InertiaOptions {
    InertiaOptions {
        from_geom: c.inertiafromgeom.unwrap_or(false),
        boundmass: c.boundmass.unwrap_or(0.0),
        boundinertia: c.boundinertia.unwrap_or(0.0),
        balance: c.balanceinertia.unwrap_or(false),
        total_mass: c.settotalmass.filter(|&m| m > 0.0),
    }
}

/// Ids of the named bodies or geoms of `<exclude>`/`<pair>` elements (MuJoCo rejects unknown
/// names, and so do we).
fn resolve_names(
    pairs: &[[NameRef; 2]],
    src: &Sources,
    what: &str,
    find: impl Fn(&str) -> Option<usize>,
) -> Result<Vec<[usize; 2]>, Error> {
    let id = |r: &NameRef| {
        find(&r.name).ok_or_else(|| src.invalid(r.pos, format!("unknown {what} \"{}\"", r.name)))
    };
    pairs.iter().map(|[a, b]| Ok([id(a)?, id(b)?])).collect()
}

fn flatten_defaults(
    spec: &DefaultSpec,
    parent: &Class,
    src: &Sources,
    out: &mut HashMap<String, Class>,
) -> Result<(), Error> {
    let class = Class {
        joint: merge_joint(&spec.joint, &parent.joint),
        geom: merge_geom(&spec.geom, &parent.geom),
        site: merge_geom(&spec.site, &parent.site),
    };
    if out.contains_key(&spec.class) {
        return Err(src.invalid(spec.pos, format!("repeated default class \"{}\"", spec.class)));
    }
    for child in &spec.children {
        flatten_defaults(child, &class, src, out)?;
    }
    out.insert(spec.class.clone(), class);
    Ok(())
}

fn merge_joint(own: &JointAttrs, base: &JointAttrs) -> JointAttrs {
    JointAttrs {
        kind: own.kind.or(base.kind),
        pos: own.pos.or(base.pos),
        axis: own.axis.or(base.axis),
        range: own.range.or(base.range),
        limited: own.limited.or(base.limited),
        reference: own.reference.or(base.reference),
    }
}

fn merge_geom(own: &GeomAttrs, base: &GeomAttrs) -> GeomAttrs {
    // A shorter `size` overwrites only its leading entries (MuJoCo reads into the default array).
    let size = match (&own.size, &base.size) {
        (Some(o), Some(b)) if o.len() < b.len() => {
            let mut merged = b.clone();
            merged.iter_mut().zip(o).for_each(|(m, o)| *m = *o);
            Some(merged)
        }
        (o, b) => o.clone().or_else(|| b.clone()),
    };
    GeomAttrs {
        kind: own.kind.or(base.kind),
        size,
        pos: own.pos.or(base.pos),
        orientation: own.orientation.or(base.orientation),
        fromto: own.fromto.or(base.fromto),
        mesh: own.mesh.clone().or_else(|| base.mesh.clone()),
        contype: own.contype.or(base.contype),
        conaffinity: own.conaffinity.or(base.conaffinity),
    }
}

/// What a body owns directly (also through `<frame>`s): joints, geoms, sites, inertials (one
/// at most), child bodies; each with the frame it was written in, relative to the body.
struct Contents<'a> {
    joints: Vec<(&'a JointSpec, Frame, &'a str)>,
    geoms: Vec<(&'a GeomSpec, Frame, &'a str)>,
    sites: Vec<(&'a GeomSpec, Frame, &'a str)>,
    inertials: Vec<(&'a InertialSpec, Frame)>,
    bodies: Vec<(&'a BodySpec, Frame, &'a str)>,
}

impl Contents<'_> {
    fn new() -> Self {
        Contents {
            joints: Vec::new(),
            geoms: Vec::new(),
            sites: Vec::new(),
            inertials: Vec::new(),
            bodies: Vec::new(),
        }
    }
}

/// What is known of a body's mass while static bodies are fused into it.
#[derive(Debug, Clone, Copy)]
enum Mass {
    /// Nothing with mass.
    Zero,
    Known(Inertial),
    /// Taken by MuJoCo from geoms (not computed here).
    Unknown,
}

struct Compiler<'a> {
    src: &'a Sources,
    classes: HashMap<String, Class>,
    angle_scale: f64,
    eulerseq: [u8; 3],
    autolimits: bool,
    inertia: InertiaOptions,
    /// `fusestatic`, and the names it must keep.
    fuse_static: bool,
    referenced: &'a HashSet<String>,
    align_free: bool,
    model: Model,
}

impl<'a> Compiler<'a> {
    /// Adds `spec` as a body with the given parent and placement, then its subtree (depth-first,
    /// MuJoCo's body order). With `fusestatic`, child bodies without joints are merged into it
    /// first (`mjCModel::FuseStatic`): their children take their place among this body's
    /// children, their geoms and sites follow this body's own (in depth-first order), their
    /// mass is added to this body's.
    fn body(
        &mut self,
        spec: &'a BodySpec,
        parent: usize,
        placement: Frame,
        class: &'a str,
    ) -> Result<(), Error> {
        let id = self.model.bodies.len();
        let class = self.childclass(spec, class)?;
        let mut contents = Contents::new();
        self.collect(&spec.items, Frame::IDENTITY, class, &mut contents)?;
        if spec.mocap && (parent != 0 || !contents.joints.is_empty()) {
            return Err(self.src.invalid(
                spec.pos,
                "a mocap body must be a child of the world and have no joints",
            ));
        }
        let mut mass = self.mass(&contents, id)?;
        let children = std::mem::take(&mut contents.bodies);
        let children = self.fuse(children, id, &mut contents, &mut mass)?;
        self.model.bodies.push(Body {
            name: spec.name.clone().unwrap_or_default(),
            parent,
            pos: placement.pos,
            quat: placement.quat,
            jnt_adr: self.model.joints.len(),
            jnt_num: contents.joints.len(),
            dof_adr: self.model.nv,
            dof_num: 0,
            inertial: match mass {
                Mass::Known(i) if id != 0 => Some(i),
                _ => None,
            },
        });
        let parent_last_dof =
            if id == 0 { None } else { self.model.body_last_dof.get(parent).copied().flatten() };
        self.model.body_last_dof.push(parent_last_dof);
        for (joint, frame, class) in &contents.joints {
            self.joint(joint, id, *frame, class)?;
        }
        for (geom, frame, class) in &contents.geoms {
            let geom = self.geom(geom, id, *frame, class, false)?;
            self.model.geoms.push(geom);
        }
        for (site, frame, class) in &contents.sites {
            let geom = self.geom(site, id, *frame, class, true)?;
            let Geom { name, body, kind, size, pos, quat, .. } = geom;
            self.model.sites.push(Site { name, body, kind, size, pos, quat });
        }
        let align = contents.joints.iter().any(|(j, _, _)| {
            j.attrs.kind == Some(JointType::Free) && j.align.unwrap_or(self.align_free)
        });
        if align && children.is_empty() {
            self.model.align_to_inertia(id);
        }
        for (child, frame, class) in children {
            let pos = Vector3::from(child.translation.unwrap_or_default());
            let quat = self.orientation(child.orientation.as_ref())?;
            self.body(child, id, frame.compose(pos, quat), class)?;
        }
        Ok(())
    }

    /// The body's own mass: its `<inertial>` compiled, else nothing (no geoms) or unknown.
    fn mass(&self, contents: &Contents<'a>, id: usize) -> Result<Mass, Error> {
        Ok(match self.inertial(&contents.inertials, id)? {
            Some(i) => Mass::Known(i),
            None if contents.geoms.is_empty() && contents.inertials.is_empty() => Mass::Zero,
            None => Mass::Unknown,
        })
    }

    /// `fusestatic`: of `children` (placed in body `id`), merges those without joints (not
    /// mocap, not named by another element) into `contents` and `mass`; returns the bodies
    /// that stay, in MuJoCo's order.
    fn fuse(
        &self,
        children: Vec<(&'a BodySpec, Frame, &'a str)>,
        id: usize,
        contents: &mut Contents<'a>,
        mass: &mut Mass,
    ) -> Result<Vec<(&'a BodySpec, Frame, &'a str)>, Error> {
        if !self.fuse_static {
            return Ok(children);
        }
        let mut queue: std::collections::VecDeque<_> = children.into();
        let mut kept = Vec::new();
        while let Some((child, frame, class)) = queue.pop_front() {
            let pos = Vector3::from(child.translation.unwrap_or_default());
            let at = frame.compose(pos, self.orientation(child.orientation.as_ref())?);
            let inner = self.childclass(child, class)?;
            let mut own = Contents::new();
            self.collect(&child.items, at, inner, &mut own)?;
            let named = child.name.as_ref().is_some_and(|n| self.referenced.contains(n));
            if !own.joints.is_empty() || child.mocap || named {
                kept.push((child, frame, class));
                continue;
            }
            let added = self.mass(&own, id)?;
            *mass = self.add_mass(*mass, added, child, id)?;
            contents.geoms.append(&mut own.geoms);
            contents.sites.append(&mut own.sites);
            // The fused body's children come next, in its place (MuJoCo inserts them there).
            for grandchild in own.bodies.into_iter().rev() {
                queue.push_front(grandchild);
            }
        }
        Ok(kept)
    }

    /// `mjCModel::FuseStatic`'s mass: bodies lighter than `mjMINVAL` add nothing, nothing
    /// is added to the world.
    fn add_mass(
        &self,
        into: Mass,
        added: Mass,
        child: &BodySpec,
        id: usize,
    ) -> Result<Mass, Error> {
        let combined = |a: &Inertial, b: &Inertial| {
            inertia::combine(a, b).map_err(|e| {
                self.src.invalid(child.pos, format!("error '{e}' in fusing static body inertias"))
            })
        };
        Ok(match (into, added) {
            _ if id == 0 => into,
            (into, Mass::Zero) => into,
            (Mass::Unknown, _) | (_, Mass::Unknown) => Mass::Unknown,
            (into, Mass::Known(i)) if i.mass < MJ_MINVAL => into,
            (Mass::Zero, Mass::Known(i)) => Mass::Known(combined(&NO_MASS, &i)?),
            (Mass::Known(a), Mass::Known(b)) => Mass::Known(combined(&a, &b)?),
        })
    }

    fn childclass(&self, spec: &'a BodySpec, inherited: &'a str) -> Result<&'a str, Error> {
        match &spec.childclass {
            Some((name, at)) if !self.classes.contains_key(name) => {
                Err(self.src.invalid(*at, format!("unknown default class \"{name}\"")))
            }
            Some((name, _)) => Ok(name),
            None => Ok(inherited),
        }
    }

    fn collect(
        &self,
        items: &'a [Item],
        frame: Frame,
        class: &'a str,
        out: &mut Contents<'a>,
    ) -> Result<(), Error> {
        for item in items {
            match item {
                Item::Joint(j) => out.joints.push((j, frame, class)),
                Item::Geom(g) => out.geoms.push((g, frame, class)),
                Item::Site(s) => out.sites.push((s, frame, class)),
                Item::Inertial(i) => out.inertials.push((i, frame)),
                Item::Body(b) => out.bodies.push((b, frame, class)),
                Item::Frame(f) => {
                    let pos = Vector3::from(f.translation.unwrap_or_default());
                    let quat = self.orientation(f.orientation.as_ref())?;
                    let inner = self.childclass(f, class)?;
                    self.collect(&f.items, frame.compose(pos, quat), inner, out)?;
                }
                // Expanded into frames before compiling (`expand_replicates`).
                Item::Replicate(_) => {}
            }
        }
        Ok(())
    }

    fn class(&self, explicit: Option<&(String, Pos)>, inherited: &str) -> Result<&Class, Error> {
        let (name, at) = match explicit {
            Some((name, at)) => (name.as_str(), Some(*at)),
            None => (inherited, None),
        };
        self.classes.get(name).ok_or_else(|| match at {
            Some(at) => self.src.invalid(at, format!("unknown default class \"{name}\"")),
            None => Error::Model {
                file: self.src.main_name(),
                message: format!("unknown default class \"{name}\""),
            },
        })
    }

    fn orientation(&self, o: Option<&(Orientation, Pos)>) -> Result<UnitQuaternion<f64>, Error> {
        match o {
            None => Ok(UnitQuaternion::identity()),
            Some((o, at)) => {
                orientation_to_quat(o, self.angle_scale, self.eulerseq).ok_or_else(|| {
                    self.src.invalid(*at, "degenerate orientation (zero quaternion or axis)")
                })
            }
        }
    }

    /// The body's mass and inertia as `mjCBody::Compile` makes them from its `<inertial>`:
    /// `fullinertia` diagonalised, orientation in the compiler's angle unit and `eulerseq`,
    /// bounds and balancing, placed through the `<frame>`s around it. `None` without one, and
    /// with `inertiafromgeom="true"` (MuJoCo then ignores it for the geoms' masses).
    fn inertial(
        &self,
        found: &[(&InertialSpec, Frame)],
        body: usize,
    ) -> Result<Option<Inertial>, Error> {
        let (spec, frame) = match found {
            [] => return Ok(None),
            [one] => one,
            // MuJoCo's schema rejects two in one body; through <frame>s the last would win.
            [_, (second, _), ..] => {
                return Err(self.src.invalid(second.pos, "more than one <inertial> in a body"))
            }
        };
        if body == 0 {
            return Err(self.src.invalid(spec.pos, "the world body cannot have an <inertial>"));
        }
        let (quat, diag) = match spec.inertia {
            InertiaSpec::Full(full) => inertia::principal_axes(&inertia::full_matrix(full))
                .map_err(|e| self.src.invalid(spec.pos, format!("fullinertia: {e}")))?,
            InertiaSpec::Diag(d) => (self.orientation(spec.orientation.as_ref())?, d.into()),
        };
        if self.inertia.from_geom {
            return Ok(None);
        }
        let (mass, diag) = inertia::bound_and_check(spec.mass, diag, &self.inertia)
            .map_err(|e| self.src.invalid(spec.pos, e))?;
        let local = Inertial { mass, pos: spec.translation.into(), quat, diag };
        Ok(Some(inertia::placed(&local, &frame.pos, &frame.quat)))
    }

    // `body` and its parent are ids this builder assigned (the body being compiled).
    #[allow(clippy::indexing_slicing)]
    fn joint(
        &mut self,
        spec: &JointSpec,
        body: usize,
        frame: Frame,
        class: &str,
    ) -> Result<(), Error> {
        let attrs = if spec.is_freejoint {
            spec.attrs.clone()
        } else {
            merge_joint(&spec.attrs, &self.class(spec.class.as_ref(), class)?.joint)
        };
        let kind = attrs.kind.unwrap_or(JointType::Hinge);
        let parent = self.model.bodies[body].parent;
        if kind == JointType::Free && (parent != 0 || self.model.bodies[body].jnt_num != 1) {
            // MuJoCo 3.17 refuses both.
            let what = if parent != 0 {
                "free joint can only be used on top level"
            } else {
                "a free joint together with other joints in one body (more than 6 dofs)"
            };
            return Err(self.src.invalid(spec.pos, what));
        }
        let axis = match kind {
            JointType::Hinge | JointType::Slide => {
                let a = Vector3::from(attrs.axis.unwrap_or([0.0, 0.0, 1.0]));
                let n = a.norm();
                if n < 1e-10 {
                    return Err(self.src.invalid(spec.pos, "joint axis has zero length"));
                }
                // A joint inside a <frame> is placed by it, axis and anchor.
                frame.quat * (a / n)
            }
            JointType::Ball | JointType::Free => Vector3::z(),
        };
        let range = self.joint_range(spec, &attrs, kind)?;
        let joint = Joint {
            name: spec.name.clone().unwrap_or_default(),
            kind,
            body,
            qpos_adr: self.model.nq,
            dof_adr: self.model.nv,
            range,
            axis,
            pos: frame.pos + frame.quat * Vector3::from(attrs.pos.unwrap_or_default()),
            velocity_limit: None,
        };
        self.push_qpos0(&joint, &attrs);
        self.push_dofs(&joint);
        self.model.joints.push(joint);
        Ok(())
    }

    /// `limited` with `autolimits` (MuJoCo's `checklimited`), angle units, range order.
    fn joint_range(
        &self,
        spec: &JointSpec,
        attrs: &JointAttrs,
        kind: JointType,
    ) -> Result<Option<[f64; 2]>, Error> {
        if kind == JointType::Free {
            return Ok(None);
        }
        let raw = attrs.range.unwrap_or([0.0, 0.0]);
        let has_range = raw != [0.0, 0.0];
        let limited = match attrs.limited.unwrap_or(Limited::Auto) {
            Limited::True => true,
            Limited::False => false,
            Limited::Auto if has_range && !self.autolimits => {
                return Err(self.src.invalid(
                    spec.pos,
                    "joint has a range but no limited attribute and autolimits is false; set limited or autolimits",
                ));
            }
            Limited::Auto => has_range,
        };
        if !limited {
            return Ok(None);
        }
        let scale = if kind == JointType::Slide { 1.0 } else { self.angle_scale };
        let range = [raw[0] * scale, raw[1] * scale];
        if kind != JointType::Ball && range[0] >= range[1] {
            return Err(self.src.invalid(spec.pos, "joint range[0] must be smaller than range[1]"));
        }
        Ok(Some(range))
    }

    // `joint.body` is the body this builder is compiling.
    #[allow(clippy::indexing_slicing)]
    fn push_qpos0(&mut self, joint: &Joint, attrs: &JointAttrs) {
        match joint.kind {
            JointType::Free => {
                let b = &self.model.bodies[joint.body];
                self.model.qpos0.extend([b.pos.x, b.pos.y, b.pos.z]);
                self.model.qpos0.extend([b.quat.w, b.quat.i, b.quat.j, b.quat.k]);
            }
            JointType::Ball => self.model.qpos0.extend([1.0, 0.0, 0.0, 0.0]),
            JointType::Hinge => {
                self.model.qpos0.push(attrs.reference.unwrap_or(0.0) * self.angle_scale)
            }
            JointType::Slide => self.model.qpos0.push(attrs.reference.unwrap_or(0.0)),
        }
        self.model.nq += joint.kind.nq();
    }

    // `joint.body` is the body this builder is compiling; `body_last_dof` has one entry per body.
    #[allow(clippy::indexing_slicing)]
    fn push_dofs(&mut self, joint: &Joint) {
        let joint_id = self.model.joints.len();
        for _ in 0..joint.kind.nv() {
            let dof = self.model.nv;
            self.model.dof_parent.push(self.model.body_last_dof[joint.body]);
            self.model.dof_joint.push(joint_id);
            self.model.body_last_dof[joint.body] = Some(dof);
            self.model.bodies[joint.body].dof_num += 1;
            self.model.nv += 1;
        }
    }

    fn geom(
        &self,
        spec: &GeomSpec,
        body: usize,
        frame: Frame,
        class: &str,
        is_site: bool,
    ) -> Result<Geom, Error> {
        let class = self.class(spec.class.as_ref(), class)?;
        let attrs = merge_geom(&spec.attrs, if is_site { &class.site } else { &class.geom });
        let kind = attrs.kind.unwrap_or(GeomType::Sphere);
        let mut size = [0.0; 3];
        let default_size: &[f64] = if is_site { &[0.005, 0.005, 0.005] } else { &[0.0] };
        let given = attrs.size.as_deref().unwrap_or(default_size);
        size.iter_mut().zip(given).for_each(|(s, g)| *s = *g);
        let (pos, quat) = match attrs.fromto {
            Some(ft) => {
                let (from, to) =
                    (Vector3::new(ft[0], ft[1], ft[2]), Vector3::new(ft[3], ft[4], ft[5]));
                if !matches!(
                    kind,
                    GeomType::Capsule | GeomType::Cylinder | GeomType::Box | GeomType::Ellipsoid
                ) {
                    return Err(self
                        .src
                        .invalid(spec.pos, "fromto needs a capsule, cylinder, box or ellipsoid"));
                }
                let dir = to - from;
                if dir.norm() < 1e-10 {
                    return Err(self.src.invalid(spec.pos, "fromto with coincident end points"));
                }
                let half = dir.norm() / 2.0;
                match kind {
                    GeomType::Capsule | GeomType::Cylinder => size[1] = half,
                    _ => size[2] = half,
                }
                // MuJoCo aligns the geom's z axis with from − to (mjCGeom's fromto rule).
                ((from + to) / 2.0, z_to_quat(&(-dir).normalize()))
            }
            None => (
                Vector3::from(attrs.pos.unwrap_or_default()),
                self.orientation(attrs.orientation.as_ref())?,
            ),
        };
        let placed = frame.compose(pos, quat);
        Ok(Geom {
            name: spec.name.clone().unwrap_or_default(),
            body,
            kind,
            size,
            pos: placed.pos,
            quat: placed.quat,
            mesh: attrs.mesh.filter(|_| kind == GeomType::Mesh),
            contype: attrs.contype.unwrap_or(1),
            conaffinity: attrs.conaffinity.unwrap_or(1),
        })
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::FRAC_PI_2;

    use nalgebra::{Quaternion, UnitQuaternion, Vector3};

    use crate::inertia::{full_matrix, tensor};
    use crate::{Inertial, JointType, Model};

    fn model(xml: &str) -> Model {
        Model::from_xml_str(xml, None).unwrap_or_else(|e| panic!("{e}"))
    }

    fn inertial(m: &Model, body: &str) -> Inertial {
        m.bodies[m.body_id(body).unwrap()].inertial.unwrap()
    }

    /// With the `mujoco` feature: MuJoCo 3.17.0 compiles `xml` to the same model, `inertials`
    /// bodies compared. Without it the hand numbers of each test stand alone.
    fn matches_mujoco(m: &Model, xml: &str, inertials: usize) {
        #[cfg(feature = "mujoco")]
        {
            use crate::mujoco_check::{check_xml_str, CheckOptions, INERTIAL_TOLERANCE};
            let options = CheckOptions { configs: 2, seed: 1 };
            let report = check_xml_str(m, xml, "<test>", options).unwrap_or_else(|e| panic!("{e}"));
            assert!(report.passes(INERTIAL_TOLERANCE), "{report}");
            assert_eq!(report.inertials, inertials, "{report}");
        }
        #[cfg(not(feature = "mujoco"))]
        let _ = (m, xml, inertials);
    }

    #[test]
    fn diaginertia_takes_its_orientation_and_frames() {
        let xml = r#"<mujoco><compiler eulerseq="zyx"/><worldbody>
            <body name="a" pos="0 0 1"><joint/><geom size="0.1"/>
              <inertial pos="0.1 0.2 0.3" mass="2" quat="0 1 0 1" diaginertia="0.1 0.2 0.25"/>
            </body>
            <body name="b"><joint/><geom size="0.1"/>
              <frame pos="1 0 0" euler="90 0 0">
                <inertial pos="1 0 0" mass="1" euler="0 0 90" diaginertia="1 2 3"/>
              </frame>
            </body>
            <body name="c"><joint/><geom size="0.1"/></body>
          </worldbody></mujoco>"#;
        let m = model(xml);
        let a = inertial(&m, "a");
        let h = std::f64::consts::FRAC_1_SQRT_2;
        assert_eq!(
            (a.mass, a.pos, a.diag),
            (2.0, Vector3::new(0.1, 0.2, 0.3), Vector3::new(0.1, 0.2, 0.25))
        );
        assert!((a.quat.coords - Quaternion::new(0.0, h, 0.0, h).coords).norm() < 1e-15);
        // eulerseq zyx in degrees: the frame turns 90° about z, the inertial 90° about x.
        let b = inertial(&m, "b");
        let (rz, rx) = (Vector3::z_axis(), Vector3::x_axis());
        let expected = UnitQuaternion::from_axis_angle(&rz, FRAC_PI_2)
            * UnitQuaternion::from_axis_angle(&rx, FRAC_PI_2);
        assert!((b.pos - Vector3::new(1.0, 1.0, 0.0)).norm() < 1e-15);
        assert!(b.quat.angle_to(&expected) < 1e-15);
        assert_eq!(m.bodies[m.body_id("c").unwrap()].inertial, None);
        matches_mujoco(&m, xml, 2);
    }

    #[test]
    fn fullinertia_is_diagonalised() {
        let xml = r#"<mujoco><worldbody><body name="a"><joint/><geom size="0.1"/>
            <inertial pos="0 0 0.1" mass="1.5" fullinertia="3 3.5 4 0.1 0.2 0.3"/>
          </body></worldbody></mujoco>"#;
        let m = model(xml);
        let a = inertial(&m, "a");
        // MuJoCo 3.17.0's body_inertia for this body, largest first.
        let moments = Vector3::new(4.18276016566592, 3.3595649771583007, 2.957674857175793);
        assert!((a.diag - moments).norm() < 1e-13, "{}", a.diag);
        assert!((tensor(&a) - full_matrix([3.0, 3.5, 4.0, 0.1, 0.2, 0.3])).norm() < 1e-14);
        assert_eq!((a.mass, a.pos), (1.5, Vector3::new(0.0, 0.0, 0.1)));
        matches_mujoco(&m, xml, 1);
    }

    #[test]
    fn inertiafromgeom_true_ignores_inertials() {
        let xml = |compiler: &str| {
            format!(
                r#"<mujoco><compiler {compiler}/><worldbody><body name="a"><joint/><geom size="0.1"/>
                   <inertial pos="0 0 0" mass="1" diaginertia="1 1 3"/></body></worldbody></mujoco>"#
            )
        };
        // MuJoCo checks A + B >= C on the geoms' inertia then: no error for the unused one.
        let m = model(&xml(r#"inertiafromgeom="true""#));
        assert_eq!(m.bodies[1].inertial, None);
        matches_mujoco(&m, &xml(r#"inertiafromgeom="true""#), 0);
        let err = Model::from_xml_str(&xml(r#"inertiafromgeom="false""#), None).unwrap_err();
        assert!(err.to_string().contains("inertia must satisfy A + B >= C"), "{err}");
        let balanced = xml(r#"inertiafromgeom="false" balanceinertia="true""#);
        assert_eq!(inertial(&model(&balanced), "a").diag, Vector3::repeat(5.0 / 3.0));
        matches_mujoco(&model(&balanced), &balanced, 1);
    }

    #[test]
    fn bounds_and_total_mass_follow_mujoco() {
        let xml = |compiler: &str, extra: &str| {
            format!(
                r#"<mujoco><compiler {compiler}/><worldbody>
                   <body name="a"><joint/><inertial pos="0 0 0" mass="0.001" diaginertia="1 2 3"/></body>
                   <body name="b"><joint/><inertial pos="0 0 0" mass="3" diaginertia="0.1 0.1 0.1"/></body>
                   {extra}</worldbody></mujoco>"#
            )
        };
        let bounded = xml(r#"boundmass="0.01" boundinertia="1.5""#, "");
        let m = model(&bounded);
        assert_eq!(
            (inertial(&m, "a").mass, inertial(&m, "a").diag),
            (0.01, Vector3::new(1.5, 2.0, 3.0))
        );
        assert_eq!(inertial(&m, "b").diag, Vector3::repeat(1.5));
        matches_mujoco(&m, &bounded, 2);
        // settotalmass scales every mass and moment by one factor: 6 / 3.001. (MuJoCo 3.17.0
        // does the same, and warns that the attribute is deprecated into MUJOCO_LOG.TXT, so
        // it is not asked here.)
        let m = model(&xml(r#"settotalmass="6""#, ""));
        let scale = 6.0 / 3.001;
        assert!((inertial(&m, "b").mass - 3.0 * scale).abs() < 1e-15);
        assert!((inertial(&m, "a").diag - Vector3::new(1.0, 2.0, 3.0) * scale).norm() < 1e-14);
        // A body whose mass MuJoCo takes from its geom: the sum is unknown here.
        let partly = xml(r#"settotalmass="6""#, r#"<body name="c"><geom size="0.1"/></body>"#);
        assert!(model(&partly).bodies.iter().all(|b| b.inertial.is_none()));
    }

    #[test]
    fn classes_inherit_and_childclass_applies_to_descendants() {
        let m = model(
            r#"<mujoco><default><joint axis="1 0 0" range="-10 10"/>
                 <default class="a"><joint range="-20 20"/><default class="b"><joint axis="0 1 0"/></default></default>
               </default>
               <worldbody><body childclass="b"><joint name="j1"/>
                 <body><joint name="j2" class="a"/><body><joint name="j3" class="main"/></body></body>
               </body></worldbody></mujoco>"#,
        );
        let deg = |d: f64| d.to_radians();
        let j = |n: &str| &m.joints[m.joint_id(n).unwrap()];
        assert_eq!((j("j1").axis.y, j("j1").range), (1.0, Some([deg(-20.0), deg(20.0)])));
        assert_eq!((j("j2").axis.x, j("j2").range), (1.0, Some([deg(-20.0), deg(20.0)])));
        assert_eq!((j("j3").axis.x, j("j3").range), (1.0, Some([deg(-10.0), deg(10.0)])));
    }

    #[test]
    fn frames_compose_into_body_placement() {
        let m = model(
            r#"<mujoco><compiler angle="radian"/><worldbody>
                 <frame pos="1 0 0" euler="0 0 1.5707963267948966"><body name="b" pos="1 0 0"/></frame>
               </worldbody></mujoco>"#,
        );
        let b = &m.bodies[1];
        assert!((b.pos - nalgebra::Vector3::new(1.0, 1.0, 0.0)).norm() < 1e-15);
        assert!((b.quat.angle() - FRAC_PI_2).abs() < 1e-15);
    }

    #[test]
    fn autolimits_and_limited() {
        let m = model(
            r#"<mujoco><worldbody><body><joint name="a"/><joint name="b" range="0 1" type="slide"/>
                 <joint name="c" range="0 1" limited="false"/></body></worldbody></mujoco>"#,
        );
        let ranges: Vec<_> = m.joints.iter().map(|j| j.range).collect();
        assert_eq!(ranges, vec![None, Some([0.0, 1.0]), None]);
    }

    #[test]
    fn qpos0_follows_mujoco() {
        let m = model(
            r#"<mujoco><worldbody>
                 <body pos="1 2 3" quat="0 1 0 0"><freejoint/><body><joint type="ball"/>
                   <body><joint ref="90"/><joint type="slide" ref="0.5"/></body></body></body>
               </worldbody></mujoco>"#,
        );
        let kinds: Vec<_> = m.joints.iter().map(|j| j.kind).collect();
        assert_eq!(kinds, [JointType::Free, JointType::Ball, JointType::Hinge, JointType::Slide]);
        assert_eq!((m.nq, m.nv), (13, 11));
        assert_eq!(&m.qpos0[..11], &[1.0, 2.0, 3.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]);
        assert!((m.qpos0[11] - FRAC_PI_2).abs() < 1e-15);
        assert_eq!(m.qpos0[12], 0.5);
    }

    #[test]
    fn bodies_are_depth_first_and_joints_by_body() {
        let m = model(
            r#"<mujoco><worldbody>
                 <body name="a"><body name="a1"><joint name="ja1"/></body><joint name="ja"/><body name="a2"/></body>
                 <body name="b"/>
               </worldbody></mujoco>"#,
        );
        let names: Vec<_> = m.bodies.iter().map(|b| b.name.as_str()).collect();
        assert_eq!(names, ["world", "a", "a1", "a2", "b"]);
        let joints: Vec<_> = m.joints.iter().map(|j| (j.name.as_str(), j.body)).collect();
        assert_eq!(joints, [("ja", 1), ("ja1", 2)]);
    }

    #[test]
    fn coordinate_local_is_read_and_global_refused_as_mujoco_does() {
        let xml = |c: &str| {
            format!(
                r#"<mujoco><compiler coordinate="{c}" angle="degree"/><worldbody>
                   <body name="a" pos="0 0 1"><joint axis="0 1 0" range="-90 90"/>
                   <inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/><geom size="0.1"/></body>
                   </worldbody></mujoco>"#
            )
        };
        let m = model(&xml("local"));
        assert_eq!(m.joints[0].range, Some([-FRAC_PI_2, FRAC_PI_2]));
        matches_mujoco(&m, &xml("local"), 1);
        let err = Model::from_xml_str(&xml("global"), None).unwrap_err().to_string();
        assert!(err.contains("global coordinates no longer supported"), "{err}");
        assert!(err.starts_with("<string>:1:"), "{err}");
    }

    #[test]
    fn joints_inside_frames_are_placed_by_them() {
        let xml = r#"<mujoco><worldbody><body name="a" pos="0 0 1">
              <inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/><geom size="0.1"/>
              <frame pos="0.1 0.2 0.3" euler="0 0 90"><joint name="j" pos="0.5 0 0" axis="1 0 0"/></frame>
              <body name="b" pos="0 0 0.5"><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
                <geom size="0.1"/><frame euler="90 0 0"><joint name="k" type="ball"/></frame></body>
            </body></worldbody></mujoco>"#;
        let m = model(xml);
        let j = &m.joints[0];
        assert!((j.pos - Vector3::new(0.1, 0.7, 0.3)).norm() < 1e-12, "{}", j.pos);
        assert!((j.axis - Vector3::y()).norm() < 1e-12, "{}", j.axis);
        matches_mujoco(&m, xml, 2);
    }

    /// `fusestatic` as MuJoCo 3.17 does it: jointless bodies merge into their parents unless
    /// another element names them; their children take their place, their geoms follow the
    /// parent's own, their mass adds to the parent's.
    #[test]
    fn fusestatic_merges_jointless_bodies() {
        let xml = |refs: &str| {
            format!(
                r#"<mujoco><compiler fusestatic="true"/><worldbody>
                 <body name="a" pos="0 0 1"><joint name="ja" axis="0 1 0"/>
                   <inertial pos="0 0 0" mass="2" diaginertia="0.1 0.1 0.1"/>
                   <body name="b" pos="0 0 0.5" euler="0 0 90"><geom name="gb" type="box" size="0.1 0.2 0.3"/>
                     <inertial pos="0.1 0 0" mass="1" diaginertia="0.01 0.02 0.03"/>
                     <body name="c" pos="0 0.2 0"><joint name="jc"/><geom name="gc" size="0.1"/>
                       <inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body>
                     <body name="d" pos="0.3 0 0"><site name="sd"/></body>
                   </body>
                   <geom name="ga" size="0.05"/>
                   <body name="e" pos="0 0 -0.5"><joint name="je"/>
                     <inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body>
                 </body>
                 <body name="s" pos="1 0 0"><geom name="gs" size="0.1"/></body>
               </worldbody>{refs}</mujoco>"#
            )
        };
        let m = model(&xml(""));
        let names: Vec<_> = m.bodies.iter().map(|b| b.name.as_str()).collect();
        assert_eq!(names, ["world", "a", "c", "e"]);
        let geoms: Vec<_> = m.geoms.iter().map(|g| (g.name.as_str(), g.body)).collect();
        assert_eq!(geoms, [("gs", 0), ("ga", 1), ("gb", 1), ("gc", 2)]);
        let c = &m.bodies[2];
        assert!((c.pos - Vector3::new(-0.2, 0.0, 0.5)).norm() < 1e-12, "{}", c.pos);
        assert_eq!(m.sites[0].body, 1);
        assert!((inertial(&m, "a").mass - 3.0).abs() < 1e-15);
        matches_mujoco(&m, &xml(""), 3);
        // Named by a sensor or an exclude, a body stays.
        let refs = r#"<sensor><framepos objtype="body" objname="d"/></sensor>
                      <contact><exclude body1="s" body2="a"/></contact>"#;
        let m = model(&xml(refs));
        let names: Vec<_> = m.bodies.iter().map(|b| b.name.as_str()).collect();
        assert_eq!(names, ["world", "a", "c", "d", "e", "s"]);
        matches_mujoco(&m, &xml(refs), 3);
    }

    #[test]
    fn mocap_bodies_are_static_and_alignfree_moves_childless_free_bodies() {
        let xml = r#"<mujoco><compiler alignfree="true"/><worldbody>
              <body name="m" mocap="true" pos="0 0 1"><geom size="0.1" contype="0" conaffinity="0"/></body>
              <body name="box" pos="1 0 0" euler="0 0 30"><freejoint/><geom type="box" size="0.1 0.2 0.3"/>
                <inertial pos="0.1 0.2 0.3" euler="10 20 30" mass="1" diaginertia="0.1 0.2 0.25"/>
                <site name="s" pos="0.1 0 0"/></body>
              <body name="robot" pos="0 1 1"><freejoint/>
                <inertial pos="0.1 0 0" mass="1" diaginertia="1 1 1"/><geom size="0.1"/>
                <body name="arm"><joint/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body>
              </body>
            </worldbody></mujoco>"#;
        let m = model(xml);
        assert_eq!(m.bodies.len(), 5);
        let b = &m.bodies[m.body_id("box").unwrap()];
        assert!(b.inertial.unwrap().pos.norm() < 1e-15);
        // The robot's body frame stays: it has a child.
        assert_eq!(m.bodies[m.body_id("robot").unwrap()].pos, Vector3::new(0.0, 1.0, 1.0));
        matches_mujoco(&m, xml, 3);
        let bad = r#"<mujoco><worldbody><body><body mocap="true"/></body></worldbody></mujoco>"#;
        let err = Model::from_xml_str(bad, None).unwrap_err().to_string();
        assert!(err.contains("mocap body must be a child of the world"), "{err}");
    }

    /// `<replicate>` as MuJoCo 3.17 expands it: copy `i` at the `i`-th power of its frame,
    /// names suffixed by `sep` and `i` padded to the digits of `count`, inner suffixes first.
    #[test]
    fn replicate_copies_its_children() {
        let xml = r#"<mujoco><worldbody><body name="base"><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
              <replicate count="3" offset="0 0.2 0" euler="0 0 30" sep="-">
                <body name="a" pos="1 0 0"><joint name="j"/><geom name="g" size="0.1"/>
                  <inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body></replicate></body>
              <replicate count="2" offset="1 0 0" sep="o"><replicate count="12" offset="0 0.2 0" sep="i">
                <body name="c"><joint/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body>
              </replicate></replicate></worldbody></mujoco>"#;
        let m = model(xml);
        let names: Vec<_> = m.bodies.iter().map(|b| b.name.as_str()).take(6).collect();
        assert_eq!(names, ["world", "base", "a-0", "a-1", "a-2", "ci00o0"]);
        assert_eq!(m.bodies.len(), 2 + 3 + 24);
        let a2 = &m.bodies[4];
        assert!((a2.pos - Vector3::new(0.4, 1.2392304845413262, 0.0)).norm() < 1e-12, "{}", a2.pos);
        assert_eq!(m.joints[2].name, "j-2");
        matches_mujoco(&m, xml, 28);
    }
}
