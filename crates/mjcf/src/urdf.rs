//! URDF → the same kinematic [`Model`] as MJCF, with the semantics of MuJoCo's own URDF
//! import (`xml_urdf.cc`, then the compiler with `fusestatic` on).
//!
//! Two steps, as for MJCF: [`parse`] reads the XML (roxmltree, positions kept) into a typed
//! tree of what the file says; [`build`] gives it MuJoCo's meaning:
//!
//! - Links become bodies, depth-first from the root; a link's children come in the order of
//!   the joints that name it as parent (MuJoCo's `AddToTree`). A body's frame is its parent
//!   joint's `<origin>`; `rpy` is roll about the fixed x, then pitch about fixed y, then yaw
//!   about fixed z (MuJoCo's Euler sequence `XYZ`); angles are radians.
//! - `revolute` and `continuous` → hinge, `prismatic` → slide, each anchored at the body
//!   origin, axis (default `1 0 0`) normalised; `fixed` → no joint; `floating` → free joint
//!   (only where it ends up a child of the world, as MuJoCo requires); `planar` → slides
//!   `NAME_TX`, `NAME_TY` and hinge `NAME_RZ` (MuJoCo's construction); `spherical` (Bullet's
//!   extension, accepted by MuJoCo) → ball.
//! - `<limit lower upper>` → `range` when both are given and `lower < upper`, else unlimited
//!   (MuJoCo); `continuous` joints are always unlimited (the URDF specification; MuJoCo would
//!   limit a continuous joint that carries `lower`/`upper`). `<limit velocity>` →
//!   [`Joint::velocity_limit`] (MuJoCo has no such field; `0`, which some exporters write for
//!   "not given", and a missing one are `None`; a planar joint's applies to its three joints). `qpos0` is zero for hinges and
//!   slides and the body pose for free joints.
//! - Static links (no joint) are merged into their parent body, as MuJoCo's URDF default
//!   `fusestatic="true"` does, the root link into the world when it has no joint; their
//!   collision geoms move along. `<mujoco><compiler fusestatic="false"/></mujoco>` in the file
//!   or [`UrdfOptions::fuse_static`] keeps them as bodies.
//! - A link called `world` is MuJoCo's world body itself (fixed-base robots).
//! - `<collision>` → geoms in link order: `box` (half sizes), `cylinder` and `capsule` (radius,
//!   half length), `sphere`. `mesh` → a mesh geom kept for the record (mesh named after the
//!   file, as MuJoCo names it): no mesh file is read, so its pose is as written and it has no
//!   size (see [`Geom::mesh`](crate::Geom::mesh)). A repeated geom name is dropped (the geom
//!   stays, unnamed), as MuJoCo does. Collision geoms are MuJoCo's `contype = conaffinity = 1`.
//! - `<inertial>` → [`Body::inertial`](crate::Body::inertial): `<inertia>` is a full tensor in
//!   the frame of the inertial's `<origin>`, diagonalised (all zeros: a point mass, as MuJoCo
//!   reads it), then checked as MuJoCo's compiler checks a body (`balanceinertia` from
//!   `<mujoco><compiler>` applies). A fused static link's mass, centre of mass and inertia are
//!   combined into its body's (parallel-axis theorem, diagonalised again); into the world they
//!   go nowhere. `None` for a body whose mass MuJoCo takes from collision geoms (its own link
//!   or a fused one without `<inertial>` but with collisions, unless `inertiafromgeom="false"`),
//!   and for every body with `inertiafromgeom="true"`, `boundmass` or `boundinertia` (which
//!   MuJoCo applies to every link before fusing, massless ones included).
//! - `<visual>` is discarded (MuJoCo's URDF default `discardvisual="true"`); with
//!   `<mujoco><compiler discardvisual="false">` each becomes a geom that never collides
//!   (`contype = conaffinity = 0`, MuJoCo's visual geoms), among the collisions in the order
//!   written. Dynamics, effort, mimic, transmissions, materials and gazebo tags do not change
//!   kinematics and are skipped.
//! - `<mujoco>` (MuJoCo's extension, read before the links wherever it is written): its
//!   `<compiler>` takes every attribute MuJoCo's does, with MuJoCo's meaning: `fusestatic`,
//!   `discardvisual`, `alignfree`, `autolimits` (`false` refuses a joint with a range, as
//!   MuJoCo does), the inertia attributes below; `coordinate="global"` is MuJoCo's error;
//!   `angle` and `eulerseq` change nothing (MuJoCo forces radians on URDF and reads `rpy` as
//!   `XYZ`), nor do `meshdir`, `strippath` and the rest (no mesh file is read).
//!   `<option><flag filterparent>` sets the collision filter's parent rule.
//!
//! MuJoCo adds no free joint when it compiles a URDF on its own, so the robot is fixed to the
//! world there. Retargeting needs a free root, so by default ([`UrdfBase::Floating`]) the root
//! link gets a free joint named `ROOT_free_joint` (the name MuJoCo gives it when it loads a URDF
//! as a moving body), unless the file has a `floating` joint already.

// Exception to the crate's `deny(clippy::indexing_slicing)`, justified: indices are positions of links and joints in the parsed file's
// own vectors (parent and child names resolved to them first; an unknown name is an error) and
// body, joint and dof ids this builder assigned.
#![allow(clippy::indexing_slicing)]

use std::collections::{HashMap, HashSet};

use nalgebra::{UnitQuaternion, Vector3};

use crate::error::{Error, Location};
use crate::inertia::{self, InertiaOptions, MJ_MINVAL, NO_MASS};
use crate::math::{orientation_to_quat, z_to_quat};
use crate::model::{Body, Geom, GeomType, Inertial, Joint, JointType, Model};
use crate::source::{Pos, Sources};
use crate::syntax::Orientation;
use crate::urdf_options::{UrdfBase, UrdfOptions};

// ------------------------------------------------------------------------------------------
// Syntax: the typed tree of what the file says.

/// `xyz` and `rpy` of an `<origin>` (zeros when absent).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Origin {
    pub xyz: [f64; 3],
    pub rpy: [f64; 3],
}

#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Shape {
    /// Full side lengths, as written.
    Box([f64; 3]),
    Cylinder {
        radius: f64,
        length: f64,
    },
    Capsule {
        radius: f64,
        length: f64,
    },
    Sphere {
        radius: f64,
    },
    Mesh {
        filename: String,
        scale: [f64; 3],
    },
}

/// A `<collision>`, or a `<visual>` when `<mujoco><compiler discardvisual="false">` keeps
/// them (MuJoCo's visual geoms: `contype = conaffinity = 0`).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct CollisionSpec {
    pub name: Option<String>,
    pub origin: Origin,
    pub shape: Shape,
    pub visual: bool,
}

/// An `<inertial>`: `<mass value>` and all six `<inertia>` attributes are required, as in
/// MuJoCo.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct InertialSpec {
    pub origin: Origin,
    pub mass: f64,
    /// `ixx iyy izz ixy ixz iyz` (MuJoCo's `fullinertia` order).
    pub inertia: [f64; 6],
    pub pos: Pos,
}

#[derive(Debug, Clone, PartialEq)]
pub(crate) struct LinkSpec {
    pub name: String,
    pub inertial: Option<InertialSpec>,
    pub collisions: Vec<CollisionSpec>,
    pub pos: Pos,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum UrdfJointType {
    Revolute,
    Continuous,
    Prismatic,
    Fixed,
    Floating,
    Planar,
    Spherical,
}

/// `<limit>`: each attribute `None` when not written.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct LimitSpec {
    pub lower: Option<f64>,
    pub upper: Option<f64>,
    pub velocity: Option<f64>,
}

#[derive(Debug, Clone, PartialEq)]
pub(crate) struct JointSpec {
    pub name: String,
    pub kind: UrdfJointType,
    /// Link name and where it was written.
    pub parent: (String, Pos),
    pub child: (String, Pos),
    pub origin: Origin,
    pub axis: Option<[f64; 3]>,
    pub limit: Option<LimitSpec>,
    pub pos: Pos,
}

/// `<mujoco>` inside `<robot>` (MuJoCo's extension): the `<compiler>` attributes and the
/// `<option>` flag that matter here.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct MujocoSpec {
    pub fusestatic: Option<bool>,
    /// `discardvisual` (MuJoCo's URDF default: `true`, visuals dropped).
    pub discardvisual: Option<bool>,
    pub autolimits: Option<bool>,
    pub alignfree: Option<bool>,
    /// `<option><flag filterparent>`.
    pub filterparent: Option<bool>,
    /// `inertiafromgeom`: `Some(true)` for `true`, `Some(false)` for `false`, `None` for `auto`.
    pub inertiafromgeom: Option<bool>,
    pub boundmass: Option<f64>,
    pub boundinertia: Option<f64>,
    pub balanceinertia: Option<bool>,
    pub settotalmass: Option<f64>,
}

#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Urdf {
    pub name: String,
    pub links: Vec<LinkSpec>,
    pub joints: Vec<JointSpec>,
    pub mujoco: MujocoSpec,
    pub pos: Pos,
}

type Node<'a, 'i> = roxmltree::Node<'a, 'i>;

fn at(node: Node<'_, '_>) -> Pos {
    Pos { file: 0, offset: u32::try_from(node.range().start).unwrap_or(u32::MAX) }
}

fn attr_at(attr: &roxmltree::Attribute<'_, '_>) -> Pos {
    Pos { file: 0, offset: u32::try_from(attr.range().start).unwrap_or(u32::MAX) }
}

fn elements<'a, 'i>(node: Node<'a, 'i>) -> impl Iterator<Item = Node<'a, 'i>> {
    node.children().filter(Node::is_element)
}

/// The first child element called `name` (MuJoCo reads the first one and ignores repeats).
fn child<'a, 'i>(node: Node<'a, 'i>, name: &str) -> Option<Node<'a, 'i>> {
    elements(node).find(|n| n.tag_name().name() == name)
}

fn attribute<'a, 'i>(node: Node<'a, 'i>, name: &str) -> Option<roxmltree::Attribute<'a, 'i>> {
    node.attributes().find(|a| a.name() == name)
}

/// Reads the `.urdf` text into the typed tree; `src` holds the text as its only file.
pub(crate) fn parse(src: &Sources, text: &str) -> Result<Urdf, Error> {
    let doc = roxmltree::Document::parse(text).map_err(|e| {
        let p = e.pos();
        let at = Location { file: src.main_name(), line: p.row, column: p.col };
        Error::Xml { at, message: e.to_string() }
    })?;
    let root = doc.root_element();
    if root.tag_name().name() != "robot" {
        return Err(src.invalid(
            at(root),
            format!("root element is <{}>, expected <robot>", root.tag_name().name()),
        ));
    }
    let p = Parser { src };
    let mut urdf = Urdf {
        name: attribute(root, "name").map(|a| a.value().to_owned()).unwrap_or_default(),
        links: Vec::new(),
        joints: Vec::new(),
        mujoco: MujocoSpec::default(),
        pos: at(root),
    };
    // MuJoCo reads the first <mujoco> before any link, wherever it is written.
    if let Some(mujoco) = child(root, "mujoco") {
        p.mujoco(mujoco, &mut urdf.mujoco)?;
    }
    let keep_visuals = urdf.mujoco.discardvisual == Some(false);
    for el in elements(root) {
        if el.tag_name().namespace().is_some_and(|ns| ns.contains("xacro")) {
            return Err(src.unsupported(at(el), "xacro element: expand the file with xacro first"));
        }
        match el.tag_name().name() {
            "link" => urdf.links.push(p.link(el, keep_visuals)?),
            "joint" => urdf.joints.push(p.joint(el)?),
            // material, transmission, gazebo, ...: no effect on kinematics.
            _ => {}
        }
    }
    Ok(urdf)
}

struct Parser<'s> {
    src: &'s Sources,
}

impl Parser<'_> {
    fn required<'a, 'i>(
        &self,
        node: Node<'a, 'i>,
        name: &str,
    ) -> Result<roxmltree::Attribute<'a, 'i>, Error> {
        attribute(node, name).ok_or_else(|| {
            self.src.invalid(
                at(node),
                format!("<{}> without the required attribute {name}", node.tag_name().name()),
            )
        })
    }

    fn required_child<'a, 'i>(
        &self,
        node: Node<'a, 'i>,
        name: &str,
    ) -> Result<Node<'a, 'i>, Error> {
        child(node, name).ok_or_else(|| {
            self.src.invalid(at(node), format!("<{}> without <{name}>", node.tag_name().name()))
        })
    }

    /// Exactly `N` finite numbers separated by white space.
    fn numbers<const N: usize>(
        &self,
        attr: &roxmltree::Attribute<'_, '_>,
    ) -> Result<[f64; N], Error> {
        let mut out = [0.0; N];
        let mut words = attr.value().split_ascii_whitespace();
        for slot in &mut out {
            let word = words.next().ok_or_else(|| {
                self.src.invalid(
                    attr_at(attr),
                    format!(
                        "attribute {} needs {N} numbers, got \"{}\"",
                        attr.name(),
                        attr.value()
                    ),
                )
            })?;
            *slot = self.number_word(attr, word)?;
        }
        if words.next().is_some() {
            return Err(self.src.invalid(
                attr_at(attr),
                format!("attribute {} needs {N} numbers, got \"{}\"", attr.name(), attr.value()),
            ));
        }
        Ok(out)
    }

    fn number_word(&self, attr: &roxmltree::Attribute<'_, '_>, word: &str) -> Result<f64, Error> {
        match word.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(self.src.invalid(
                attr_at(attr),
                format!("attribute {}: \"{word}\" is not a finite number", attr.name()),
            )),
        }
    }

    fn number(&self, node: Node<'_, '_>, name: &str) -> Result<Option<f64>, Error> {
        attribute(node, name).map(|a| self.numbers::<1>(&a).map(|[v]| v)).transpose()
    }

    fn positive(&self, node: Node<'_, '_>, name: &str) -> Result<f64, Error> {
        let attr = self.required(node, name)?;
        let [v] = self.numbers::<1>(&attr)?;
        if v <= 0.0 {
            return Err(self.src.invalid(attr_at(&attr), format!("{name} must be positive")));
        }
        Ok(v)
    }

    fn origin(&self, node: Node<'_, '_>) -> Result<Origin, Error> {
        let mut origin = Origin::default();
        if let Some(o) = child(node, "origin") {
            if let Some(a) = attribute(o, "xyz") {
                origin.xyz = self.numbers(&a)?;
            }
            if let Some(a) = attribute(o, "rpy") {
                origin.rpy = self.numbers(&a)?;
            }
        }
        Ok(origin)
    }

    fn link(&self, el: Node<'_, '_>, keep_visuals: bool) -> Result<LinkSpec, Error> {
        let name = self.required(el, "name")?.value().to_owned();
        let mut inertials = elements(el).filter(|c| c.tag_name().name() == "inertial");
        let inertial = inertials.next().map(|i| self.inertial(i)).transpose()?;
        if let Some(second) = inertials.next() {
            return Err(self.src.invalid(at(second), "repeated <inertial> in a link"));
        }
        // Visual and collision geoms in the order written (MuJoCo's `mjXURDF::Body`).
        let mut collisions = Vec::new();
        for c in elements(el) {
            let visual = match c.tag_name().name() {
                "collision" => false,
                "visual" if keep_visuals => true,
                _ => continue,
            };
            collisions.push(CollisionSpec {
                name: attribute(c, "name").map(|a| a.value().to_owned()),
                origin: self.origin(c)?,
                shape: self.shape(self.required_child(c, "geometry")?)?,
                visual,
            });
        }
        Ok(LinkSpec { name, inertial, collisions, pos: at(el) })
    }

    /// `<inertial>`: `<origin>`, `<mass value>` (not negative), `<inertia>` with all six
    /// attributes.
    fn inertial(&self, el: Node<'_, '_>) -> Result<InertialSpec, Error> {
        let mass_attr = self.required(self.required_child(el, "mass")?, "value")?;
        let [mass] = self.numbers::<1>(&mass_attr)?;
        if mass < 0.0 {
            return Err(self.src.invalid(attr_at(&mass_attr), "mass must not be negative"));
        }
        let node = self.required_child(el, "inertia")?;
        let mut inertia = [0.0; 6];
        for (slot, name) in inertia.iter_mut().zip(["ixx", "iyy", "izz", "ixy", "ixz", "iyz"]) {
            [*slot] = self.numbers::<1>(&self.required(node, name)?)?;
        }
        Ok(InertialSpec { origin: self.origin(el)?, mass, inertia, pos: at(el) })
    }

    fn shape(&self, geometry: Node<'_, '_>) -> Result<Shape, Error> {
        // MuJoCo takes the first of box, cylinder, sphere, capsule, mesh that is present.
        if let Some(b) = child(geometry, "box") {
            let attr = self.required(b, "size")?;
            let size: [f64; 3] = self.numbers(&attr)?;
            if size.iter().any(|&s| s <= 0.0) {
                return Err(self.src.invalid(attr_at(&attr), "box sizes must be positive"));
            }
            return Ok(Shape::Box(size));
        }
        if let Some(c) = child(geometry, "cylinder") {
            let (radius, length) = (self.positive(c, "radius")?, self.positive(c, "length")?);
            return Ok(Shape::Cylinder { radius, length });
        }
        if let Some(s) = child(geometry, "sphere") {
            return Ok(Shape::Sphere { radius: self.positive(s, "radius")? });
        }
        if let Some(c) = child(geometry, "capsule") {
            let (radius, length) = (self.positive(c, "radius")?, self.positive(c, "length")?);
            return Ok(Shape::Capsule { radius, length });
        }
        if let Some(m) = child(geometry, "mesh") {
            let filename = self.required(m, "filename")?.value().to_owned();
            let scale = match attribute(m, "scale") {
                Some(a) => self.numbers(&a)?,
                None => [1.0; 3],
            };
            return Ok(Shape::Mesh { filename, scale });
        }
        Err(self.src.invalid(
            at(geometry),
            "<geometry> without <box>, <cylinder>, <sphere>, <capsule> or <mesh>",
        ))
    }

    fn joint(&self, el: Node<'_, '_>) -> Result<JointSpec, Error> {
        let name = self.required(el, "name")?.value().to_owned();
        let type_attr = self.required(el, "type")?;
        let kind = match type_attr.value() {
            "revolute" => UrdfJointType::Revolute,
            "continuous" => UrdfJointType::Continuous,
            "prismatic" => UrdfJointType::Prismatic,
            "fixed" => UrdfJointType::Fixed,
            "floating" => UrdfJointType::Floating,
            "planar" => UrdfJointType::Planar,
            "spherical" => UrdfJointType::Spherical,
            other => {
                return Err(self.src.invalid(
                    attr_at(&type_attr),
                    format!(
                        "unknown joint type \"{other}\" (expected revolute, continuous, prismatic, fixed, floating, planar or spherical)"
                    ),
                ))
            }
        };
        let link_of = |tag: &str| -> Result<(String, Pos), Error> {
            let attr = self.required(self.required_child(el, tag)?, "link")?;
            Ok((attr.value().to_owned(), attr_at(&attr)))
        };
        let axis = match child(el, "axis") {
            Some(a) => Some(self.numbers(&self.required(a, "xyz")?)?),
            None => None,
        };
        let limit = match child(el, "limit") {
            Some(l) => Some(self.limit(l)?),
            None => None,
        };
        Ok(JointSpec {
            name,
            kind,
            parent: link_of("parent")?,
            child: link_of("child")?,
            origin: self.origin(el)?,
            axis,
            limit,
            pos: at(el),
        })
    }

    fn limit(&self, el: Node<'_, '_>) -> Result<LimitSpec, Error> {
        let velocity = match attribute(el, "velocity") {
            Some(a) => {
                let [v] = self.numbers::<1>(&a)?;
                if v < 0.0 {
                    return Err(self.src.invalid(attr_at(&a), "velocity must not be negative"));
                }
                Some(v)
            }
            None => None,
        };
        // `effort` is not kinematic, but a malformed number is still an error.
        self.number(el, "effort")?;
        Ok(LimitSpec {
            lower: self.number(el, "lower")?,
            upper: self.number(el, "upper")?,
            velocity,
        })
    }

    /// `<mujoco>`: MuJoCo reads its `<compiler>` with every MJCF compiler attribute, then
    /// forces radians; `<option>` and `<size>` as in MJCF. Kept here: what changes the body
    /// tree, the geoms, the limits or the inertials (and the collision filter); the rest
    /// (`angle`, `eulerseq`: URDF angles and `rpy` are fixed; `meshdir`, `strippath`: no mesh
    /// is read; `usethread`, `fitaabb`, ...) is read and has no effect.
    fn mujoco(&self, el: Node<'_, '_>, out: &mut MujocoSpec) -> Result<(), Error> {
        if let Some(option) = child(el, "option") {
            if let Some(a) = child(option, "flag").and_then(|f| attribute(f, "filterparent")) {
                out.filterparent = Some(match a.value() {
                    "enable" => true,
                    "disable" => false,
                    other => {
                        return Err(self.src.invalid(
                            attr_at(&a),
                            format!("attribute filterparent: \"{other}\" is not enable or disable"),
                        ))
                    }
                });
            }
        }
        let Some(compiler) = child(el, "compiler") else { return Ok(()) };
        for a in compiler.attributes() {
            let flag = || match a.value() {
                "true" => Ok(true),
                "false" => Ok(false),
                other => Err(self.src.invalid(
                    attr_at(&a),
                    format!("attribute {}: \"{other}\" is not true or false", a.name()),
                )),
            };
            let number = || self.numbers::<1>(&a).map(|[v]| Some(v));
            match a.name() {
                "fusestatic" => out.fusestatic = Some(flag()?),
                "discardvisual" => out.discardvisual = Some(flag()?),
                "autolimits" => out.autolimits = Some(flag()?),
                "alignfree" => out.alignfree = Some(flag()?),
                "inertiafromgeom" if a.value() == "auto" => out.inertiafromgeom = None,
                "inertiafromgeom" => out.inertiafromgeom = Some(flag()?),
                "boundmass" => out.boundmass = number()?,
                "boundinertia" => out.boundinertia = number()?,
                "balanceinertia" => out.balanceinertia = Some(flag()?),
                "settotalmass" => out.settotalmass = number()?,
                "coordinate" if a.value() == "global" => {
                    return Err(self.src.invalid(attr_at(&a), crate::syntax::GLOBAL_COORDINATES))
                }
                _ => {}
            }
        }
        Ok(())
    }
}

// ------------------------------------------------------------------------------------------
// Semantics: the typed tree → `Model`.

/// A rigid transform `x_parent = pos + quat * x_child`.
#[derive(Debug, Clone, Copy)]
struct Frame {
    pos: Vector3<f64>,
    quat: UnitQuaternion<f64>,
}

impl Frame {
    fn identity() -> Frame {
        Frame { pos: Vector3::zeros(), quat: UnitQuaternion::identity() }
    }

    fn compose(&self, child: &Frame) -> Frame {
        Frame { pos: self.pos + self.quat * child.pos, quat: self.quat * child.quat }
    }
}

fn origin_frame(o: &Origin) -> Frame {
    // URDF rpy: roll about the fixed x, pitch about fixed y, yaw about fixed z, i.e.
    // Rz(yaw)·Ry(pitch)·Rx(roll): MuJoCo's extrinsic Euler sequence "XYZ" (xml_urdf.cc, Origin).
    let quat = orientation_to_quat(&Orientation::Euler(o.rpy), 1.0, *b"XYZ")
        .unwrap_or_else(UnitQuaternion::identity);
    Frame { pos: Vector3::from(o.xyz), quat }
}

/// The link tree: parent joint and parent link of each link, and the depth-first order.
struct Tree {
    root: usize,
    parent_joint: Vec<Option<usize>>,
    /// Parent link of each link (`None` for the root).
    parent_link: Vec<Option<usize>>,
    /// Links depth-first from the root (MuJoCo's body order before fusion).
    order: Vec<usize>,
}

pub(crate) fn build(urdf: &Urdf, src: &Sources, options: UrdfOptions) -> Result<Model, Error> {
    let tree = link_tree(urdf, src)?;
    let fuse = options.fuse_static.or(urdf.mujoco.fusestatic).unwrap_or(true);
    let has_floating = urdf.joints.iter().any(|j| j.kind == UrdfJointType::Floating);
    let add_free = options.base == UrdfBase::Floating && !has_floating;
    let root = &urdf.links[tree.root];
    if root.name == "world" && add_free {
        return Err(src.invalid(
            root.pos,
            "the root link is called \"world\" (MuJoCo's world body: the robot is fixed to it); \
             load it with UrdfBase::Fixed",
        ));
    }
    let mut b = Builder::new(urdf.name.clone(), src);
    b.inertia_settings(&urdf.mujoco);
    // Where each link ended up: (body id, link frame in that body's frame).
    let mut placed: Vec<Option<(usize, Frame)>> = vec![None; urdf.links.len()];
    for &l in &tree.order {
        let link = &urdf.links[l];
        let (parent_body, parent_frame, joint) = match tree.parent_joint[l] {
            Some(j) => {
                let spec = &urdf.joints[j];
                let parent = tree.parent_link[l].and_then(|p| placed[p]);
                let (body, frame) = parent.unwrap_or((0, Frame::identity()));
                (body, frame.compose(&origin_frame(&spec.origin)), Some(spec))
            }
            None => (0, Frame::identity(), None),
        };
        if link.name == "world" && l != tree.root {
            return Err(src.invalid(link.pos, "a link called \"world\" must be the root link"));
        }
        let moving =
            joint.is_some_and(|j| j.kind != UrdfJointType::Fixed) || (l == tree.root && add_free);
        let is_world = link.name == "world";
        let (body, frame) = if is_world || (fuse && !moving) {
            b.fuse_mass(link, parent_body, &parent_frame)?;
            (parent_body, parent_frame)
        } else {
            let id = b.body(&link.name, parent_body, parent_frame);
            b.body_mass[id] = b.link_mass(link)?;
            if l == tree.root && add_free {
                b.free_joint(&format!("{}_free_joint", link.name), id);
            } else if let Some(spec) = joint {
                b.joints(spec, id)?;
            }
            (id, Frame::identity())
        };
        placed[l] = Some((body, frame));
        for c in &link.collisions {
            b.geom(c, body, &frame);
        }
    }
    Ok(b.finish())
}

fn link_tree(urdf: &Urdf, src: &Sources) -> Result<Tree, Error> {
    if urdf.links.is_empty() {
        return Err(src.invalid(urdf.pos, "<robot> has no <link>"));
    }
    let mut index: HashMap<&str, usize> = HashMap::new();
    for (i, link) in urdf.links.iter().enumerate() {
        if index.insert(link.name.as_str(), i).is_some() {
            return Err(src.invalid(link.pos, format!("repeated link name \"{}\"", link.name)));
        }
    }
    let mut joint_names = HashSet::new();
    let n = urdf.links.len();
    let (mut parent_joint, mut parent_link) = (vec![None; n], vec![None; n]);
    let mut children = vec![Vec::new(); n];
    for (j, joint) in urdf.joints.iter().enumerate() {
        if !joint_names.insert(joint.name.as_str()) {
            return Err(src.invalid(joint.pos, format!("repeated joint name \"{}\"", joint.name)));
        }
        let find = |(name, pos): &(String, Pos), role: &str| {
            index.get(name.as_str()).copied().ok_or_else(|| {
                src.invalid(
                    *pos,
                    format!("joint \"{}\": {role} link \"{name}\" does not exist", joint.name),
                )
            })
        };
        let (p, c) = (find(&joint.parent, "parent")?, find(&joint.child, "child")?);
        if let Some(other) = parent_joint[c] {
            let other: &JointSpec = &urdf.joints[other];
            return Err(src.invalid(
                joint.child.1,
                format!(
                    "link \"{}\" is the child of two joints (\"{}\" and \"{}\")",
                    urdf.links[c].name, other.name, joint.name
                ),
            ));
        }
        parent_joint[c] = Some(j);
        parent_link[c] = Some(p);
        children[p].push(c);
    }
    let roots: Vec<usize> = (0..n).filter(|&l| parent_joint[l].is_none()).collect();
    let root = match roots.as_slice() {
        [root] => *root,
        [] => return Err(cycle_error(urdf, src, &parent_joint, &parent_link, 0)),
        [first, second, ..] => {
            return Err(src.invalid(
                urdf.links[*second].pos,
                format!(
                    "two root links (\"{}\" and \"{}\"): a URDF is one tree, every link but the root is the child of a joint",
                    urdf.links[*first].name, urdf.links[*second].name
                ),
            ))
        }
    };
    let order = depth_first(&children, root);
    if order.len() < n {
        let mut reached = vec![false; n];
        order.iter().for_each(|&l| reached[l] = true);
        let unreached = reached.iter().position(|r| !r).unwrap_or(0);
        return Err(cycle_error(urdf, src, &parent_joint, &parent_link, unreached));
    }
    Ok(Tree { root, parent_joint, parent_link, order })
}

/// Pre-order from `root`, children in joint order (an explicit stack: no recursion depth).
fn depth_first(children: &[Vec<usize>], root: usize) -> Vec<usize> {
    let mut order = Vec::with_capacity(children.len());
    let mut stack = vec![root];
    while let Some(l) = stack.pop() {
        order.push(l);
        stack.extend(children[l].iter().rev());
    }
    order
}

/// Follows parent joints from `start` until a link repeats and reports the joint that closes
/// the loop.
fn cycle_error(
    urdf: &Urdf,
    src: &Sources,
    parent_joint: &[Option<usize>],
    parent_link: &[Option<usize>],
    start: usize,
) -> Error {
    let mut seen = vec![false; urdf.links.len()];
    let mut link = start;
    while let (Some(j), Some(parent)) = (parent_joint[link], parent_link[link]) {
        if seen[link] {
            let joint = &urdf.joints[j];
            return src.invalid(
                joint.pos,
                format!(
                    "joint \"{}\" closes a cycle of links through \"{}\"",
                    joint.name, urdf.links[link].name
                ),
            );
        }
        seen[link] = true;
        link = parent;
    }
    Error::Model { file: src.main_name(), message: "the links form a cycle".to_owned() }
}

/// What is known of a body's mass while static links are fused into it.
#[derive(Debug, Clone, Copy)]
enum Mass {
    /// Nothing with mass yet.
    Zero,
    Known(Inertial),
    /// A link without `<inertial>` but with collision geoms: MuJoCo gives it the geoms' mass
    /// (density 1000, meshes by their volume), which is not computed here.
    FromGeoms,
}

/// Accumulates the model: bodies and joints in order, geoms per body (MuJoCo appends the geoms
/// of a merged link to its new body, so a body's geoms are its own, then its merged
/// descendants' in depth-first order), and each body's mass.
struct Builder<'s> {
    src: &'s Sources,
    model: Model,
    body_geoms: Vec<Vec<Geom>>,
    body_mass: Vec<Mass>,
    inertia: InertiaOptions,
    /// `inertiafromgeom="auto"`: a link without `<inertial>` weighs what its geoms do
    /// (`"false"`: nothing).
    geoms_weigh: bool,
    /// `<mujoco><compiler autolimits>`: `false` makes a joint with a range an error.
    autolimits: bool,
    /// `<mujoco><compiler alignfree>`.
    align_free: bool,
    geom_names: HashSet<String>,
    /// Mesh name of each (file name stem, scale) seen, MuJoCo's naming: `stem`, `stem1`, ...
    meshes: Vec<(String, [f64; 3], String)>,
}

impl<'s> Builder<'s> {
    fn new(name: String, src: &'s Sources) -> Builder<'s> {
        let world = Body {
            name: "world".to_owned(),
            parent: 0,
            pos: Vector3::zeros(),
            quat: UnitQuaternion::identity(),
            jnt_adr: 0,
            jnt_num: 0,
            dof_adr: 0,
            dof_num: 0,
            inertial: None,
        };
        Builder {
            src,
            model: Model {
                name,
                nq: 0,
                nv: 0,
                bodies: vec![world],
                joints: Vec::new(),
                geoms: Vec::new(),
                sites: Vec::new(),
                qpos0: Vec::new(),
                dof_joint: Vec::new(),
                dof_parent: Vec::new(),
                body_last_dof: vec![None],
                jnt_pos_zero: Vec::new(),
                geom_mat: Vec::new(),
                site_mat: Vec::new(),
                contact_excludes: Vec::new(),
                contact_pairs: Vec::new(),
                filter_parent: true,
            },
            body_geoms: vec![Vec::new()],
            body_mass: vec![Mass::Zero],
            inertia: InertiaOptions::default(),
            geoms_weigh: true,
            autolimits: true,
            align_free: false,
            geom_names: HashSet::new(),
            meshes: Vec::new(),
        }
    }

    fn body(&mut self, name: &str, parent: usize, frame: Frame) -> usize {
        let m = &mut self.model;
        m.bodies.push(Body {
            name: name.to_owned(),
            parent,
            pos: frame.pos,
            quat: frame.quat,
            jnt_adr: m.joints.len(),
            jnt_num: 0,
            dof_adr: m.nv,
            dof_num: 0,
            inertial: None,
        });
        m.body_last_dof.push(m.body_last_dof[parent]);
        self.body_geoms.push(Vec::new());
        self.body_mass.push(Mass::Zero);
        m.bodies.len() - 1
    }

    /// The file's `<mujoco><compiler>` inertia attributes (MuJoCo's defaults when absent).
    fn inertia_settings(&mut self, spec: &MujocoSpec) {
        self.inertia = InertiaOptions {
            from_geom: spec.inertiafromgeom == Some(true),
            boundmass: spec.boundmass.unwrap_or(0.0),
            boundinertia: spec.boundinertia.unwrap_or(0.0),
            balance: spec.balanceinertia.unwrap_or(false),
            total_mass: spec.settotalmass.filter(|&m| m > 0.0),
        };
        self.geoms_weigh = spec.inertiafromgeom != Some(false);
        self.autolimits = spec.autolimits.unwrap_or(true);
        self.align_free = spec.alignfree.unwrap_or(false);
        self.model.filter_parent = spec.filterparent.unwrap_or(true);
    }

    /// A link's own mass, its `<inertial>` in the link frame as `xml_urdf.cc` reads it (an
    /// `<inertia>` that is all zeros counts as none given: a point mass) and `mjCBody::Compile`
    /// checks it. Every link is checked, also one fused into the world, as MuJoCo does.
    fn link_mass(&self, link: &LinkSpec) -> Result<Mass, Error> {
        let Some(spec) = &link.inertial else {
            // Visual geoms have density 0 (MuJoCo's URDF import).
            let weighs = self.geoms_weigh && link.collisions.iter().any(|c| !c.visual);
            return Ok(if weighs { Mass::FromGeoms } else { Mass::Zero });
        };
        let (quat, diag) = if spec.inertia == [0.0; 6] {
            (UnitQuaternion::identity(), Vector3::zeros())
        } else {
            inertia::principal_axes(&inertia::full_matrix(spec.inertia))
                .map_err(|e| self.src.invalid(spec.pos, format!("<inertia>: {e}")))?
        };
        // With inertiafromgeom="true" MuJoCo checks the geoms' inertia instead.
        let (mass, diag) = if self.inertia.from_geom {
            (spec.mass, diag)
        } else {
            inertia::bound_and_check(spec.mass, diag, &self.inertia)
                .map_err(|e| self.src.invalid(spec.pos, e))?
        };
        let origin = origin_frame(&spec.origin);
        Ok(Mass::Known(Inertial { mass, pos: origin.pos, quat: origin.quat * quat, diag }))
    }

    /// Fuses the static `link`, placed at `frame` in `body`, into the body's mass
    /// (`mjCBody::AccumulateInertia`, for links of at least `mjMINVAL`); into the world it
    /// adds nothing.
    fn fuse_mass(&mut self, link: &LinkSpec, body: usize, frame: &Frame) -> Result<(), Error> {
        let added = self.link_mass(link)?;
        if body == 0 {
            return Ok(());
        }
        let fused = |into: &Inertial, i: &Inertial| {
            inertia::combine(into, &inertia::placed(i, &frame.pos, &frame.quat)).map_err(|e| {
                let at = link.inertial.map_or(link.pos, |i| i.pos);
                self.src.invalid(at, format!("link \"{}\" fused into its parent: {e}", link.name))
            })
        };
        self.body_mass[body] = match (self.body_mass[body], added) {
            (into, Mass::Zero) => into,
            (Mass::FromGeoms, _) | (_, Mass::FromGeoms) => Mass::FromGeoms,
            (into, Mass::Known(i)) if i.mass < MJ_MINVAL => into,
            (Mass::Zero, Mass::Known(i)) => Mass::Known(fused(&NO_MASS, &i)?),
            (Mass::Known(into), Mass::Known(i)) => Mass::Known(fused(&into, &i)?),
        };
        Ok(())
    }

    /// Appends a joint to `body` (the last body added) with its dofs and `qpos0`.
    fn push_joint(
        &mut self,
        name: String,
        kind: JointType,
        body: usize,
        axis: Vector3<f64>,
    ) -> usize {
        let m = &mut self.model;
        let id = m.joints.len();
        m.joints.push(Joint {
            name,
            kind,
            body,
            qpos_adr: m.nq,
            dof_adr: m.nv,
            range: None,
            axis,
            pos: Vector3::zeros(),
            velocity_limit: None,
        });
        match kind {
            JointType::Free => {
                let b = &m.bodies[body];
                m.qpos0.extend([b.pos.x, b.pos.y, b.pos.z, b.quat.w, b.quat.i, b.quat.j, b.quat.k]);
            }
            JointType::Ball => m.qpos0.extend([1.0, 0.0, 0.0, 0.0]),
            JointType::Hinge | JointType::Slide => m.qpos0.push(0.0),
        }
        m.nq += kind.nq();
        for _ in 0..kind.nv() {
            m.dof_parent.push(m.body_last_dof[body]);
            m.dof_joint.push(id);
            m.body_last_dof[body] = Some(m.nv);
            m.bodies[body].dof_num += 1;
            m.nv += 1;
        }
        m.bodies[body].jnt_num += 1;
        id
    }

    fn free_joint(&mut self, name: &str, body: usize) {
        self.push_joint(name.to_owned(), JointType::Free, body, Vector3::z());
    }

    /// The joint(s) that the URDF joint `spec` puts on `body`.
    fn joints(&mut self, spec: &JointSpec, body: usize) -> Result<(), Error> {
        let raw = Vector3::from(spec.axis.unwrap_or([1.0, 0.0, 0.0]));
        let needs_axis = !matches!(
            spec.kind,
            UrdfJointType::Fixed | UrdfJointType::Floating | UrdfJointType::Spherical
        );
        if needs_axis && raw.norm() < 1e-10 {
            return Err(self
                .src
                .invalid(spec.pos, format!("joint \"{}\": axis has zero length", spec.name)));
        }
        let axis = if needs_axis { raw.normalize() } else { Vector3::z() };
        let limit = spec.limit.unwrap_or_default();
        // Some exporters write velocity="0" for "not given"; a zero limit would freeze the joint.
        let velocity = limit.velocity.filter(|&v| v > 0.0);
        // MuJoCo limits a joint when both bounds are written and lower < upper; else unlimited.
        let range = match (limit.lower, limit.upper) {
            (Some(lo), Some(hi)) if lo < hi => Some([lo, hi]),
            _ => None,
        };
        // MuJoCo leaves such a joint `limited="auto"`, which autolimits="false" refuses.
        let auto = matches!((limit.lower, limit.upper), (Some(lo), Some(hi)) if lo <= hi);
        let nonzero = limit.lower.unwrap_or(0.0) != 0.0 || limit.upper.unwrap_or(0.0) != 0.0;
        if !self.autolimits && auto && nonzero && spec.kind != UrdfJointType::Fixed {
            return Err(self.src.invalid(
                spec.pos,
                format!(
                    "joint \"{}\" has a range but no limited attribute and autolimits is false (MuJoCo refuses it)",
                    spec.name
                ),
            ));
        }
        let name = spec.name.clone();
        let first = match spec.kind {
            UrdfJointType::Fixed => return Ok(()),
            UrdfJointType::Revolute => self.push_joint(name, JointType::Hinge, body, axis),
            UrdfJointType::Continuous => {
                let j = self.push_joint(name, JointType::Hinge, body, axis);
                self.model.joints[j].velocity_limit = velocity;
                return Ok(());
            }
            UrdfJointType::Prismatic => self.push_joint(name, JointType::Slide, body, axis),
            UrdfJointType::Spherical => self.push_joint(name, JointType::Ball, body, axis),
            UrdfJointType::Floating => {
                if self.model.bodies[body].parent != 0 {
                    return Err(self.src.unsupported(
                        spec.pos,
                        format!("floating joint \"{}\" whose parent link is not fixed to the world (MuJoCo allows free joints only there)", spec.name),
                    ));
                }
                self.push_joint(name, JointType::Free, body, Vector3::z());
                return Ok(());
            }
            UrdfJointType::Planar => self.planar(spec, body, &raw, velocity),
        };
        self.model.joints[first].range = range;
        if spec.kind != UrdfJointType::Planar {
            self.model.joints[first].velocity_limit = velocity;
        }
        Ok(())
    }

    /// MuJoCo's planar joint: slides along the x and y axes of the frame whose z is `axis`
    /// (`mjuu_z2quat`), then a hinge about `axis`. Returns the first joint (the only one the
    /// `<limit>` range applies to in MuJoCo).
    fn planar(
        &mut self,
        spec: &JointSpec,
        body: usize,
        raw: &Vector3<f64>,
        velocity: Option<f64>,
    ) -> usize {
        let mat = z_to_quat(raw).to_rotation_matrix();
        let (x, y) = (mat.matrix().column(0).into_owned(), mat.matrix().column(1).into_owned());
        let name = &spec.name;
        let tx = self.push_joint(format!("{name}_TX"), JointType::Slide, body, x.normalize());
        let ty = self.push_joint(format!("{name}_TY"), JointType::Slide, body, y.normalize());
        let rz = self.push_joint(format!("{name}_RZ"), JointType::Hinge, body, raw.normalize());
        for j in [tx, ty, rz] {
            self.model.joints[j].velocity_limit = velocity;
        }
        tx
    }

    fn geom(&mut self, spec: &CollisionSpec, body: usize, frame: &Frame) {
        let placed = frame.compose(&origin_frame(&spec.origin));
        let (kind, size, mesh) = match &spec.shape {
            Shape::Box(s) => (GeomType::Box, [s[0] / 2.0, s[1] / 2.0, s[2] / 2.0], None),
            Shape::Cylinder { radius, length } => {
                (GeomType::Cylinder, [*radius, length / 2.0, 0.0], None)
            }
            Shape::Capsule { radius, length } => {
                (GeomType::Capsule, [*radius, length / 2.0, 0.0], None)
            }
            Shape::Sphere { radius } => (GeomType::Sphere, [*radius, 0.0, 0.0], None),
            Shape::Mesh { filename, scale } => {
                (GeomType::Mesh, [0.0; 3], Some(self.mesh_name(filename, *scale)))
            }
        };
        // MuJoCo keeps the first use of a name and leaves later geoms of that name unnamed.
        let wanted = spec.name.clone().unwrap_or_default();
        let name = if self.geom_names.insert(wanted.clone()) { wanted } else { String::new() };
        self.body_geoms[body].push(Geom {
            name,
            body,
            kind,
            size,
            pos: placed.pos,
            quat: placed.quat,
            mesh,
            // MuJoCo's defaults: URDF has no collision filter of its own; visuals never collide.
            contype: i32::from(!spec.visual),
            conaffinity: i32::from(!spec.visual),
        });
    }

    /// MuJoCo's URDF mesh naming: the file name without directories and extension; the same
    /// file at another scale is a new mesh `stem1`, `stem2`, ...
    fn mesh_name(&mut self, filename: &str, scale: [f64; 3]) -> String {
        let file = filename.rsplit(['/', '\\']).next().unwrap_or(filename);
        let stem = file.rfind('.').map_or(file, |dot| &file[..dot]).to_owned();
        if let Some((_, _, name)) = self.meshes.iter().find(|(s, sc, _)| *s == stem && *sc == scale)
        {
            return name.clone();
        }
        let same_stem = self.meshes.iter().filter(|(s, _, _)| *s == stem).count();
        let name = if same_stem == 0 { stem.clone() } else { format!("{stem}{same_stem}") };
        self.meshes.push((stem, scale, name.clone()));
        name
    }

    fn finish(mut self) -> Model {
        let mut m = self.model;
        // Bounds apply to every link before fusion, also to those without an inertial (whose
        // masses come from geoms): not reproduced, so no inertials at all then.
        let exact = !self.inertia.from_geom
            && self.inertia.boundmass <= 0.0
            && self.inertia.boundinertia <= 0.0;
        for (body, mass) in m.bodies.iter_mut().zip(&self.body_mass) {
            body.inertial = match mass {
                Mass::Known(i) if exact => Some(*i),
                _ => None,
            };
        }
        if let Some(total) = self.inertia.total_mass {
            inertia::set_total_mass(&mut m.bodies, total);
        }
        m.geoms = self.body_geoms.drain(..).flatten().collect();
        if self.align_free {
            let free: Vec<usize> =
                m.joints.iter().filter(|j| j.kind == JointType::Free).map(|j| j.body).collect();
            for b in free {
                if !m.bodies.iter().any(|c| c.parent == b) {
                    m.align_to_inertia(b);
                }
            }
        }
        m.jnt_pos_zero = vec![true; m.joints.len()];
        m.geom_mat = m.geoms.iter().map(|g| *g.quat.to_rotation_matrix().matrix()).collect();
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FIXED: UrdfOptions = UrdfOptions { base: UrdfBase::Fixed, fuse_static: None };

    fn inertial_link(name: &str, xyz: &str, rpy: &str, mass: f64, i: [f64; 6]) -> String {
        let [xx, yy, zz, xy, xz, yz] = i;
        format!(
            r#"<link name="{name}"><inertial><origin xyz="{xyz}" rpy="{rpy}"/><mass value="{mass}"/>
               <inertia ixx="{xx}" iyy="{yy}" izz="{zz}" ixy="{xy}" ixz="{xz}" iyz="{yz}"/></inertial></link>"#
        )
    }

    fn joint(name: &str, kind: &str, parent: &str, child: &str, origin: &str) -> String {
        format!(
            r#"<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>
               <origin {origin}/><axis xyz="0 0 1"/></joint>"#
        )
    }

    /// With the `mujoco` feature: MuJoCo's URDF import of `urdf` gives the same model,
    /// `inertials` bodies compared. Without it the hand numbers of each test stand alone.
    fn matches_mujoco(m: &Model, urdf: &str, options: UrdfOptions, inertials: usize) {
        #[cfg(feature = "mujoco")]
        {
            use crate::mujoco_check::{check_urdf_file, CheckOptions, INERTIAL_TOLERANCE};
            // Tests run in parallel: one file per test (named by the test thread).
            let thread = std::thread::current().name().unwrap_or("test").replace("::", "-");
            let path =
                std::env::temp_dir().join(format!("mjcf-{}-{thread}.urdf", std::process::id()));
            std::fs::write(&path, urdf).unwrap();
            let report = check_urdf_file(m, &path, options, CheckOptions { configs: 2, seed: 1 });
            std::fs::remove_file(&path).ok();
            let report = report.unwrap_or_else(|e| panic!("{e}"));
            assert!(report.passes(INERTIAL_TOLERANCE), "{report}");
            assert_eq!(report.inertials, inertials, "{report}");
        }
        #[cfg(not(feature = "mujoco"))]
        let _ = (m, urdf, options, inertials);
    }

    /// Link `b` is fixed to `a` 0.3 m along x, turned 90° about z; its inertial sits 0.1 m
    /// along its own x. In `a`'s frame: `b`'s centre at (0.3, 0.1, 0), its moments about x and
    /// y swapped. `c` (massless point, no geoms) and `d` (zero mass) add nothing.
    #[test]
    fn fused_static_link_adds_its_inertia_to_the_parent() {
        let urdf = [
            r#"<robot name="r"><link name="base"/>"#.to_owned(),
            inertial_link("a", "0 0 0", "0 0 0", 2.0, [0.1, 0.1, 0.1, 0.0, 0.0, 0.0]),
            inertial_link("b", "0.1 0 0", "0 0 0", 1.0, [0.01, 0.02, 0.03, 0.0, 0.0, 0.0]),
            r#"<link name="c"/>"#.to_owned(),
            inertial_link("d", "0 0 0", "0 0 0", 0.0, [1.0, 1.0, 1.0, 0.0, 0.0, 0.0]),
            joint("ja", "revolute", "base", "a", r#"xyz="0 0 1""#),
            joint("jb", "fixed", "a", "b", r#"xyz="0.3 0 0" rpy="0 0 1.5707963267948966""#),
            joint("jc", "fixed", "b", "c", r#"xyz="1 2 3""#),
            joint("jd", "fixed", "a", "d", r#"xyz="1 2 3""#),
            "</robot>".to_owned(),
        ]
        .concat();
        let m = Model::from_urdf_str(&urdf, FIXED).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.bodies.len(), 2);
        let i = m.bodies[1].inertial.unwrap();
        assert!((i.mass - 3.0).abs() < 1e-15);
        assert!((i.pos - Vector3::new(0.1, 0.1 / 3.0, 0.0)).norm() < 1e-15, "{}", i.pos);
        // About the centre of mass, by the parallel-axis theorem: a is (-0.1, -1/30, 0) from
        // it with 2 kg, b (0.2, 1/15, 0) with 1 kg; Ixx = 0.1 + 2/900 + 0.02 + 4/900, ...
        let expected = inertia::full_matrix([
            0.12 + 6.0 / 900.0,
            0.17,
            0.13 + 2.0 * 0.1 / 9.0 + 0.04 / 9.0 + 0.04,
            -0.02,
            0.0,
            0.0,
        ]);
        let t = inertia::tensor(&i);
        assert!((t - expected).amax() < 1e-15, "{t}");
        matches_mujoco(&m, &urdf, FIXED, 1);
        // Unfused, each link keeps its own (b's and d's as written; base and c have none).
        let apart = UrdfOptions { fuse_static: Some(false), ..FIXED };
        let m = Model::from_urdf_str(&urdf, apart).unwrap_or_else(|e| panic!("{e}"));
        let masses: Vec<_> = m.bodies.iter().map(|b| b.inertial.map(|i| i.mass)).collect();
        assert_eq!(masses, [None, None, Some(2.0), Some(1.0), None, Some(0.0)]);
        matches_mujoco(&m, &urdf, apart, 3);
    }

    /// A URDF `<inertia>` is a full tensor in the frame of the inertial's `<origin>`.
    #[test]
    fn urdf_inertia_is_diagonalised_in_its_origin_frame() {
        let full = [3.0, 3.5, 4.0, 0.1, 0.2, 0.3];
        let urdf = [
            r#"<robot name="r">"#.to_owned(),
            inertial_link("a", "0.1 0.2 0.3", "0.3 -0.2 0.5", 2.0, full),
            "</robot>".to_owned(),
        ]
        .concat();
        let m = Model::from_urdf_str(&urdf, UrdfOptions::default()).unwrap();
        let i = m.bodies[1].inertial.unwrap();
        let origin = origin_frame(&Origin { xyz: [0.1, 0.2, 0.3], rpy: [0.3, -0.2, 0.5] });
        let r = origin.quat.to_rotation_matrix();
        let expected = r.matrix() * inertia::full_matrix(full) * r.matrix().transpose();
        assert!((inertia::tensor(&i) - expected).amax() < 1e-14);
        assert_eq!((i.mass, i.pos), (2.0, origin.pos));
        matches_mujoco(&m, &urdf, UrdfOptions::default(), 1);
    }

    /// What MuJoCo takes from geoms is not computed here: `None` then.
    #[test]
    fn inertials_from_geoms_are_none() {
        let geom = r#"<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>"#;
        let robot = |compiler: &str| {
            [
                format!(r#"<robot name="r"><mujoco><compiler {compiler}/></mujoco>"#),
                inertial_link("a", "0 0 0", "0 0 0", 1.0, [1.0, 1.0, 1.0, 0.0, 0.0, 0.0]),
                format!(r#"<link name="b">{geom}</link>"#),
                joint("jb", "fixed", "a", "b", r#"xyz="0 0 1""#),
                "</robot>".to_owned(),
            ]
            .concat()
        };
        let options = UrdfOptions::default();
        let inertial = |compiler: &str| {
            let m = Model::from_urdf_str(&robot(compiler), options).unwrap();
            m.bodies[1].inertial
        };
        // b's box weighs 8 kg in MuJoCo (density 1000): fused into a, a's mass is unknown here.
        assert_eq!(inertial(""), None);
        assert_eq!(inertial(r#"inertiafromgeom="true""#), None);
        assert_eq!(inertial(r#"boundmass="0.1""#), None);
        // inertiafromgeom="false": b's geom weighs nothing.
        let m = Model::from_urdf_str(&robot(r#"inertiafromgeom="false""#), options).unwrap();
        assert_eq!(m.bodies[1].inertial.map(|i| i.mass), Some(1.0));
        matches_mujoco(&m, &robot(r#"inertiafromgeom="false""#), options, 1);
    }

    fn builder_names(files: &[(&str, [f64; 3])]) -> Vec<String> {
        let src = Sources::default();
        let mut b = Builder::new(String::new(), &src);
        files.iter().map(|(f, scale)| b.mesh_name(f, *scale)).collect()
    }

    #[test]
    fn mesh_names_follow_mujoco() {
        let names = builder_names(&[
            ("package://g1/meshes/foot.STL", [1.0; 3]),
            ("meshes\\foot.stl", [1.0; 3]),
            ("foot.obj", [0.5; 3]),
            ("hand", [1.0; 3]),
        ]);
        assert_eq!(names, ["foot", "foot", "foot1", "hand"]);
    }

    #[test]
    fn rpy_is_roll_pitch_yaw_about_fixed_axes() {
        let o = Origin { xyz: [1.0, 2.0, 3.0], rpy: [0.1, -0.2, 0.3] };
        let f = origin_frame(&o);
        let expected = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.3)
            * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), -0.2)
            * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), 0.1);
        assert!(f.quat.angle_to(&expected) < 1e-15);
        assert_eq!(f.pos, Vector3::new(1.0, 2.0, 3.0));
    }

    #[test]
    fn limits_need_both_bounds_in_order() {
        let urdf = |limit: &str| {
            format!(
                r#"<robot name="r"><link name="a"/><link name="b"/>
                   <joint name="j" type="prismatic"><parent link="a"/><child link="b"/>{limit}</joint></robot>"#
            )
        };
        for (limit, range, speed) in [
            ("", None, None),
            (r#"<limit lower="-0.1" upper="0.2" velocity="1.5"/>"#, Some([-0.1, 0.2]), Some(1.5)),
            (r#"<limit lower="-0.1" velocity="0"/>"#, None, None),
            (r#"<limit upper="0.2"/>"#, None, None),
            (r#"<limit lower="0.2" upper="0.2"/>"#, None, None),
            (r#"<limit lower="0.3" upper="0.2"/>"#, None, None),
        ] {
            let options = UrdfOptions { base: UrdfBase::Fixed, fuse_static: None };
            let m = Model::from_urdf_str(&urdf(limit), options).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!((m.joints[0].range, m.joints[0].velocity_limit), (range, speed), "{limit}");
        }
    }

    /// `<mujoco><compiler discardvisual="false">`: visuals become geoms that never collide,
    /// in the order written among the collisions; every other compiler attribute MuJoCo reads
    /// is accepted, `<option><flag filterparent>` applies.
    #[test]
    fn mujoco_block_keeps_visuals_and_reads_every_compiler_attribute() {
        let urdf = |compiler: &str| {
            format!(
                r#"<robot name="r"><mujoco><compiler {compiler}/><option><flag filterparent="disable"/></option>
                   <size njmax="100"/></mujoco>
                   {}{}{}
                   <joint name="j" type="revolute"><origin rpy="0.5 0 0"/><parent link="a"/><child link="b"/>
                     <limit lower="-1" upper="1"/></joint>
                   <joint name="k" type="fixed"><origin xyz="0 0 0.3"/><parent link="b"/><child link="c"/></joint></robot>"#,
                inertial_link("a", "0 0 0", "0 0 0", 1.0, [1.0, 1.0, 1.0, 0.0, 0.0, 0.0]).replace(
                    "</link>",
                    r#"<visual name="v1"><geometry><box size="0.1 0.1 0.1"/></geometry></visual>
                       <collision name="c1"><origin xyz="0 0 0.1"/><geometry><sphere radius="0.1"/></geometry></collision>
                       <visual><origin xyz="0.2 0 0"/><geometry><sphere radius="0.2"/></geometry></visual></link>"#
                ),
                inertial_link("b", "0 0 0", "0 0 0", 1.0, [1.0, 1.0, 1.0, 0.0, 0.0, 0.0]),
                r#"<link name="c"><visual><geometry><cylinder radius="0.1" length="0.2"/></geometry></visual></link>"#,
            )
        };
        let kept = urdf(
            r#"discardvisual="false" coordinate="local" angle="degree" eulerseq="zyx" strippath="true" meshdir="x" usethread="false""#,
        );
        let m = Model::from_urdf_str(&kept, FIXED).unwrap_or_else(|e| panic!("{e}"));
        let geoms: Vec<_> =
            m.geoms.iter().map(|g| (g.name.as_str(), g.body, g.kind, g.contype)).collect();
        assert_eq!(
            geoms,
            [
                ("v1", 0, GeomType::Box, 0),
                ("c1", 0, GeomType::Sphere, 1),
                ("", 0, GeomType::Sphere, 0),
                ("", 1, GeomType::Cylinder, 0)
            ]
        );
        assert!(!m.filter_parent);
        // Radians whatever `angle` says: the joint origin turns 0.5 rad.
        assert!((m.bodies[1].quat.angle() - 0.5).abs() < 1e-15);
        matches_mujoco(&m, &kept, FIXED, 1);
        let dropped = Model::from_urdf_str(&urdf(""), FIXED).unwrap();
        assert_eq!(dropped.geoms.len(), 1);
        matches_mujoco(&dropped, &urdf(""), FIXED, 1);
        // autolimits="false": a joint with a range is refused, as MuJoCo refuses it.
        let err = Model::from_urdf_str(&urdf(r#"autolimits="false""#), FIXED).unwrap_err();
        assert!(err.to_string().contains("autolimits is false"), "{err}");
    }
}
