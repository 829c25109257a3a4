//! The typed MJCF tree: what the file says, attribute by attribute, before any default,
//! class, unit or frame is applied (that is `compile`'s job). Only the parts that matter for
//! kinematics and collision filtering are kept (geom `contype`/`conaffinity`, `<contact>`'s
//! `<exclude>` and `<pair>`, `<option><flag filterparent>`), plus `<inertial>` and the
//! `<compiler>` attributes that change it or the body tree (`fusestatic`, `alignfree`), and
//! the names other elements give bodies (a body named there is never fused). Elements that
//! cannot change a body pose or which geoms may collide (actuators, sensors, assets, visual,
//! ...) are skipped; so are the `<compiler>` attributes MuJoCo 3.17 reads that change
//! neither (`meshdir`, `strippath`, `discardvisual`, `usethread`, the deprecated
//! `coordinate="local"`, ...; `coordinate="global"` is MuJoCo's error). Elements that would
//! change a pose but are not implemented are an
//! [`Error::Unsupported`].

use std::collections::HashSet;

use crate::error::Error;
use crate::model::{GeomType, JointType};
use crate::source::{Attr, Element, Pos, Sources};

/// `angle` of `<compiler>`: the unit of angles in the file (MuJoCo's default: degrees).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum AngleUnit {
    Degree,
    Radian,
}

#[derive(Debug, Clone, Default)]
pub(crate) struct CompilerSpec {
    pub angle: Option<AngleUnit>,
    pub eulerseq: Option<[u8; 3]>,
    pub autolimits: Option<bool>,
    /// `inertiafromgeom="true"` (`false` and `auto` both keep explicit inertials).
    pub inertiafromgeom: Option<bool>,
    pub boundmass: Option<f64>,
    pub boundinertia: Option<f64>,
    pub balanceinertia: Option<bool>,
    pub settotalmass: Option<f64>,
    /// `fusestatic`: bodies without joints merged into their parents (MuJoCo's default: no).
    pub fusestatic: Option<bool>,
    /// `alignfree`: childless free bodies moved to their inertial frame (default: no).
    pub alignfree: Option<bool>,
}

/// One orientation specifier as written (units and sequence resolved by `compile`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Orientation {
    Quat([f64; 4]),
    AxisAngle([f64; 4]),
    Euler([f64; 3]),
    XyAxes([f64; 6]),
    ZAxis([f64; 3]),
}

/// `limited="false|true|auto"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Limited {
    False,
    True,
    Auto,
}

/// Joint attributes that a `<default>` can set, each `None` when not written.
#[derive(Debug, Clone, Default)]
pub(crate) struct JointAttrs {
    pub kind: Option<JointType>,
    pub pos: Option<[f64; 3]>,
    pub axis: Option<[f64; 3]>,
    pub range: Option<[f64; 2]>,
    pub limited: Option<Limited>,
    pub reference: Option<f64>,
}

/// Geom and site attributes that a `<default>` can set.
#[derive(Debug, Clone, Default)]
pub(crate) struct GeomAttrs {
    pub kind: Option<GeomType>,
    pub size: Option<Vec<f64>>,
    pub pos: Option<[f64; 3]>,
    pub orientation: Option<(Orientation, Pos)>,
    pub fromto: Option<[f64; 6]>,
    pub mesh: Option<String>,
    pub contype: Option<i32>,
    pub conaffinity: Option<i32>,
}

#[derive(Debug, Clone)]
pub(crate) struct DefaultSpec {
    pub class: String,
    pub joint: JointAttrs,
    pub geom: GeomAttrs,
    pub site: GeomAttrs,
    pub children: Vec<DefaultSpec>,
    pub pos: Pos,
}

#[derive(Debug, Clone)]
pub(crate) struct JointSpec {
    pub name: Option<String>,
    pub class: Option<(String, Pos)>,
    pub attrs: JointAttrs,
    /// `<freejoint>` (ignores defaults).
    pub is_freejoint: bool,
    /// `align` of a free joint: `Some` when written `true`/`false`, `None` for `auto` (the
    /// compiler's `alignfree` decides).
    pub align: Option<bool>,
    pub pos: Pos,
}

#[derive(Debug, Clone)]
pub(crate) struct GeomSpec {
    pub name: Option<String>,
    pub class: Option<(String, Pos)>,
    pub attrs: GeomAttrs,
    pub pos: Pos,
}

/// The inertia of an `<inertial>`: `diaginertia` on the axes of its orientation, or
/// `fullinertia` (`ixx iyy izz ixy ixz iyz`), which brings its own axes. Neither: zero.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum InertiaSpec {
    Diag([f64; 3]),
    Full([f64; 6]),
}

/// `<inertial>`: `pos` and `mass` are required, as in MuJoCo.
#[derive(Debug, Clone)]
pub(crate) struct InertialSpec {
    pub translation: [f64; 3],
    pub mass: f64,
    pub inertia: InertiaSpec,
    pub orientation: Option<(Orientation, Pos)>,
    pub pos: Pos,
}

#[derive(Debug, Clone)]
pub(crate) enum Item {
    Joint(JointSpec),
    Geom(GeomSpec),
    Site(GeomSpec),
    Inertial(InertialSpec),
    Body(BodySpec),
    Frame(BodySpec),
    Replicate(ReplicateSpec),
}

/// `<replicate count offset euler sep>`: its children `count` times, copy `i` placed by the
/// `i`-th power of the frame (`offset`, `euler`), every name in it suffixed by `sep` and `i`
/// (zero-padded to the digits of `count`), as MuJoCo 3.17 expands it.
#[derive(Debug, Clone)]
pub(crate) struct ReplicateSpec {
    pub count: usize,
    pub offset: [f64; 3],
    pub euler: [f64; 3],
    pub sep: String,
    pub items: Vec<Item>,
    pub pos: Pos,
}

/// A `<body>`, a `<frame>` or the `<worldbody>` (name `world`).
#[derive(Debug, Clone)]
pub(crate) struct BodySpec {
    pub name: Option<String>,
    pub childclass: Option<(String, Pos)>,
    pub translation: Option<[f64; 3]>,
    pub orientation: Option<(Orientation, Pos)>,
    pub items: Vec<Item>,
    /// `mocap="true"`: a static body placed by `mocap_pos` (its own pose at `qpos0`).
    pub mocap: bool,
    pub pos: Pos,
}

/// A name as written in an attribute, with where it was written (resolved by `compile`).
#[derive(Debug, Clone)]
pub(crate) struct NameRef {
    pub name: String,
    pub pos: Pos,
}

/// `<contact>`: `<exclude body1 body2>` and `<pair geom1 geom2>`, in file order.
#[derive(Debug, Clone, Default)]
pub(crate) struct ContactSpec {
    pub excludes: Vec<[NameRef; 2]>,
    pub pairs: Vec<[NameRef; 2]>,
}

#[derive(Debug, Clone)]
pub(crate) struct Mjcf {
    pub model_name: Option<String>,
    pub compiler: CompilerSpec,
    pub default: DefaultSpec,
    pub worldbody: BodySpec,
    pub contact: ContactSpec,
    /// `<option><flag filterparent>`: `None` when not written (MuJoCo's default: enabled).
    pub filterparent: Option<bool>,
    /// Names that some element refers to as a body (`body`, `body1`, `body2`, `target`,
    /// `objname`, `refname` attributes anywhere in the file): MuJoCo's `fusestatic` keeps
    /// such a body.
    pub referenced_bodies: HashSet<String>,
}

/// Top-level sections that cannot change body poses or collision filtering: skipped.
const IGNORED_SECTIONS: &[&str] = &[
    "size",
    "visual",
    "statistic",
    "asset",
    "equality",
    "tendon",
    "actuator",
    "sensor",
    "keyframe",
    "extension",
    "custom",
    "deformable",
];

/// Elements inside bodies that cannot change body poses: skipped.
const IGNORED_IN_BODY: &[&str] = &["camera", "light", "plugin"];

pub(crate) fn parse(root: &Element, src: &Sources) -> Result<Mjcf, Error> {
    let mut mjcf = Mjcf {
        model_name: root.attr("model").map(|a| a.value.clone()),
        compiler: CompilerSpec::default(),
        default: DefaultSpec {
            class: "main".into(),
            joint: JointAttrs::default(),
            geom: GeomAttrs::default(),
            site: GeomAttrs::default(),
            children: Vec::new(),
            pos: root.pos,
        },
        worldbody: BodySpec {
            name: Some("world".into()),
            childclass: None,
            translation: None,
            orientation: None,
            items: Vec::new(),
            mocap: false,
            pos: root.pos,
        },
        contact: ContactSpec::default(),
        filterparent: None,
        referenced_bodies: HashSet::new(),
    };
    collect_body_references(root, &mut mjcf.referenced_bodies);
    for el in &root.children {
        match el.name.as_str() {
            "compiler" => parse_compiler(el, src, &mut mjcf.compiler)?,
            "option" => parse_option(el, src, &mut mjcf.filterparent)?,
            "contact" => parse_contact(el, src, &mut mjcf.contact)?,
            "default" => parse_top_default(el, src, &mut mjcf.default)?,
            "worldbody" => {
                for child in &el.children {
                    if let Some(item) = parse_item(child, src, true)? {
                        mjcf.worldbody.items.push(item);
                    }
                }
            }
            name if IGNORED_SECTIONS.contains(&name) => {}
            other => return Err(src.unsupported(el.pos, format!("element <{other}> in <mujoco>"))),
        }
    }
    Ok(mjcf)
}

fn parse_compiler(el: &Element, src: &Sources, c: &mut CompilerSpec) -> Result<(), Error> {
    for a in &el.attrs {
        match a.name.as_str() {
            "angle" => {
                c.angle = Some(keyword(
                    a,
                    src,
                    &[("degree", AngleUnit::Degree), ("radian", AngleUnit::Radian)],
                )?)
            }
            "eulerseq" => c.eulerseq = Some(eulerseq(a, src)?),
            "autolimits" => c.autolimits = Some(boolean(a, src)?),
            "inertiafromgeom" => {
                let options = [("false", false), ("true", true), ("auto", false)];
                c.inertiafromgeom = Some(keyword(a, src, &options)?);
            }
            "boundmass" => c.boundmass = Some(floats::<1>(a, src)?[0]),
            "boundinertia" => c.boundinertia = Some(floats::<1>(a, src)?[0]),
            "balanceinertia" => c.balanceinertia = Some(boolean(a, src)?),
            "settotalmass" => c.settotalmass = Some(floats::<1>(a, src)?[0]),
            "fusestatic" => c.fusestatic = Some(boolean(a, src)?),
            "alignfree" => c.alignfree = Some(boolean(a, src)?),
            // Deprecated and still read by MuJoCo 3.17: `local` is the only meaning left.
            "coordinate" if keyword(a, src, &[("local", true), ("global", false)])? => {}
            "coordinate" => return Err(src.invalid(a.pos, GLOBAL_COORDINATES)),
            // Everything else MuJoCo reads here changes no body pose (meshdir, strippath,
            // discardvisual, usethread, fitaabb, lengthrange, ...): read and ignored.
            _ => {}
        }
    }
    Ok(())
}

/// MuJoCo 3.17's error for `<compiler coordinate="global">`.
pub(crate) const GLOBAL_COORDINATES: &str = "global coordinates no longer supported. To convert \
     existing models, load and save them in MuJoCo 2.3.3 or older";

/// Attributes whose value names a body (sensors, equalities, excludes, lights, cameras,
/// adhesion actuators).
const BODY_REFERENCES: &[&str] = &["body", "body1", "body2", "target", "objname", "refname"];

fn collect_body_references(el: &Element, out: &mut HashSet<String>) {
    for a in &el.attrs {
        if BODY_REFERENCES.contains(&a.name.as_str()) {
            out.insert(a.value.clone());
        }
    }
    for child in &el.children {
        collect_body_references(child, out);
    }
}

/// `<option>`: only `<flag filterparent="enable|disable">` matters here (the last one wins,
/// as when MuJoCo reads several `<option>` elements).
fn parse_option(el: &Element, src: &Sources, filterparent: &mut Option<bool>) -> Result<(), Error> {
    for flag in el.children.iter().filter(|c| c.name == "flag") {
        if let Some(a) = flag.attr("filterparent") {
            *filterparent = Some(keyword(a, src, &[("enable", true), ("disable", false)])?);
        }
    }
    Ok(())
}

/// `<contact>`: `<exclude body1 body2>` and `<pair geom1 geom2>` (both names required, as in
/// MuJoCo); the contact parameters of a pair (condim, friction, margin, ...) are not kept.
fn parse_contact(el: &Element, src: &Sources, contact: &mut ContactSpec) -> Result<(), Error> {
    for child in &el.children {
        let (list, keys) = match child.name.as_str() {
            "exclude" => (&mut contact.excludes, ["body1", "body2"]),
            "pair" => (&mut contact.pairs, ["geom1", "geom2"]),
            _ => continue,
        };
        let name = |key: &str| {
            child.attr(key).map(|a| NameRef { name: a.value.clone(), pos: a.pos }).ok_or_else(
                || src.invalid(child.pos, format!("<{}> needs the attribute {key}", child.name)),
            )
        };
        list.push([name(keys[0])?, name(keys[1])?]);
    }
    Ok(())
}

/// The top-level `<default>` is class `main` (its `class` attribute, if any, renames it).
fn parse_top_default(el: &Element, src: &Sources, main: &mut DefaultSpec) -> Result<(), Error> {
    let parsed = parse_default(el, src, "main")?;
    main.class = parsed.class;
    main.pos = parsed.pos;
    main.joint = parsed.joint;
    main.geom = parsed.geom;
    main.site = parsed.site;
    main.children.extend(parsed.children);
    Ok(())
}

fn parse_default(el: &Element, src: &Sources, fallback_class: &str) -> Result<DefaultSpec, Error> {
    let class = match el.attr("class") {
        Some(a) => a.value.clone(),
        None if fallback_class.is_empty() => {
            return Err(src.invalid(el.pos, "nested <default> without a class"))
        }
        None => fallback_class.to_owned(),
    };
    let mut spec = DefaultSpec {
        class,
        joint: JointAttrs::default(),
        geom: GeomAttrs::default(),
        site: GeomAttrs::default(),
        children: Vec::new(),
        pos: el.pos,
    };
    for child in &el.children {
        match child.name.as_str() {
            "default" => spec.children.push(parse_default(child, src, "")?),
            "joint" => spec.joint = joint_attrs(child, src)?,
            "geom" => spec.geom = geom_attrs(child, src)?,
            "site" => spec.site = geom_attrs(child, src)?,
            _ => {}
        }
    }
    Ok(spec)
}

/// A child of `<worldbody>`, `<body>` or `<frame>`; `None` for ignored elements.
fn parse_item(el: &Element, src: &Sources, in_world: bool) -> Result<Option<Item>, Error> {
    let item = match el.name.as_str() {
        "body" => Item::Body(parse_body(el, src)?),
        "frame" => Item::Frame(parse_body(el, src)?),
        "replicate" => Item::Replicate(parse_replicate(el, src, in_world)?),
        "joint" | "freejoint" if in_world => {
            return Err(src.invalid(el.pos, format!("<{}> directly in <worldbody>", el.name)));
        }
        "joint" => Item::Joint(parse_joint(el, src)?),
        "freejoint" => Item::Joint(parse_freejoint(el, src)?),
        "geom" => Item::Geom(parse_geom(el, src)?),
        "site" => Item::Site(parse_geom(el, src)?),
        "inertial" if in_world => {
            return Err(src.invalid(el.pos, "the world body cannot have an <inertial>"));
        }
        "inertial" => Item::Inertial(parse_inertial(el, src)?),
        name if IGNORED_IN_BODY.contains(&name) => return Ok(None),
        other => return Err(src.unsupported(el.pos, format!("element <{other}> in a body"))),
    };
    Ok(Some(item))
}

fn parse_body(el: &Element, src: &Sources) -> Result<BodySpec, Error> {
    let mocap = el.attr("mocap").map(|a| boolean(a, src)).transpose()?.unwrap_or(false);
    let mut body = BodySpec {
        name: el.attr("name").map(|a| a.value.clone()),
        childclass: el.attr("childclass").map(|a| (a.value.clone(), a.pos)),
        translation: el.attr("pos").map(|a| floats::<3>(a, src)).transpose()?,
        orientation: orientation(el, src)?,
        items: Vec::new(),
        mocap,
        pos: el.pos,
    };
    for child in &el.children {
        if let Some(item) = parse_item(child, src, false)? {
            body.items.push(item);
        }
    }
    Ok(body)
}

fn parse_replicate(el: &Element, src: &Sources, in_world: bool) -> Result<ReplicateSpec, Error> {
    let count_attr = el
        .attr("count")
        .ok_or_else(|| src.invalid(el.pos, "<replicate> needs the attribute count"))?;
    let count = usize::try_from(int(count_attr, src)?)
        .ok()
        .filter(|c| (1..=MAX_REPLICATE).contains(c))
        .ok_or_else(|| {
            src.invalid(count_attr.pos, format!("replicate count must be 1 to {MAX_REPLICATE}"))
        })?;
    let mut spec = ReplicateSpec {
        count,
        offset: el.attr("offset").map(|a| floats::<3>(a, src)).transpose()?.unwrap_or_default(),
        euler: el.attr("euler").map(|a| floats::<3>(a, src)).transpose()?.unwrap_or_default(),
        sep: el.attr("sep").map(|a| a.value.clone()).unwrap_or_default(),
        items: Vec::new(),
        pos: el.pos,
    };
    for child in &el.children {
        if let Some(item) = parse_item(child, src, in_world)? {
            spec.items.push(item);
        }
    }
    Ok(spec)
}

/// Copies one `<replicate>` may make (each a copy of its subtree: the file's size bounds it).
const MAX_REPLICATE: usize = 10_000;

fn parse_joint(el: &Element, src: &Sources) -> Result<JointSpec, Error> {
    Ok(JointSpec {
        name: el.attr("name").map(|a| a.value.clone()),
        class: el.attr("class").map(|a| (a.value.clone(), a.pos)),
        attrs: joint_attrs(el, src)?,
        is_freejoint: false,
        align: align(el, src)?,
        pos: el.pos,
    })
}

fn parse_freejoint(el: &Element, src: &Sources) -> Result<JointSpec, Error> {
    Ok(JointSpec {
        name: el.attr("name").map(|a| a.value.clone()),
        class: None,
        attrs: JointAttrs { kind: Some(JointType::Free), ..JointAttrs::default() },
        is_freejoint: true,
        align: align(el, src)?,
        pos: el.pos,
    })
}

/// `align="false|true|auto"` of a free joint (`auto`: as the compiler's `alignfree` says).
fn align(el: &Element, src: &Sources) -> Result<Option<bool>, Error> {
    let options = [("false", Some(false)), ("true", Some(true)), ("auto", None)];
    Ok(el.attr("align").map(|a| keyword(a, src, &options)).transpose()?.flatten())
}

fn parse_geom(el: &Element, src: &Sources) -> Result<GeomSpec, Error> {
    Ok(GeomSpec {
        name: el.attr("name").map(|a| a.value.clone()),
        class: el.attr("class").map(|a| (a.value.clone(), a.pos)),
        attrs: geom_attrs(el, src)?,
        pos: el.pos,
    })
}

/// `<inertial>` with MuJoCo's rules: `pos` and `mass` required, one of `diaginertia` and
/// `fullinertia`, no orientation with `fullinertia`; a negative mass or moment is an error here
/// (MuJoCo raises it to `boundmass`, 0 by default, and then rejects it on a moving body).
fn parse_inertial(el: &Element, src: &Sources) -> Result<InertialSpec, Error> {
    let required = |name: &str| {
        el.attr(name)
            .ok_or_else(|| src.invalid(el.pos, format!("<inertial> needs the attribute {name}")))
    };
    let mass_attr = required("mass")?;
    let [mass] = floats::<1>(mass_attr, src)?;
    if mass < 0.0 {
        let message = format!("attribute mass=\"{}\": must not be negative", mass_attr.value);
        return Err(src.invalid(mass_attr.pos, message));
    }
    let spec = InertialSpec {
        translation: floats::<3>(required("pos")?, src)?,
        mass,
        inertia: inertia(el, src)?,
        orientation: orientation(el, src)?,
        pos: el.pos,
    };
    if let (InertiaSpec::Full(_), Some((_, at))) = (spec.inertia, spec.orientation) {
        return Err(src.invalid(
            at,
            "fullinertia and an orientation on one <inertial> (fullinertia brings its own axes)",
        ));
    }
    Ok(spec)
}

/// `diaginertia` (non-negative) or `fullinertia`, not both.
fn inertia(el: &Element, src: &Sources) -> Result<InertiaSpec, Error> {
    let full = el.attr("fullinertia").map(|a| floats::<6>(a, src)).transpose()?;
    let Some(a) = el.attr("diaginertia") else {
        return Ok(full.map_or(InertiaSpec::Diag([0.0; 3]), InertiaSpec::Full));
    };
    let diag = floats::<3>(a, src)?;
    if full.is_some() {
        return Err(src.invalid(a.pos, "<inertial> with both diaginertia and fullinertia"));
    }
    if diag.iter().any(|&d| d < 0.0) {
        let message = format!("attribute diaginertia=\"{}\": must not be negative", a.value);
        return Err(src.invalid(a.pos, message));
    }
    Ok(InertiaSpec::Diag(diag))
}

fn joint_attrs(el: &Element, src: &Sources) -> Result<JointAttrs, Error> {
    let kinds = [
        ("free", JointType::Free),
        ("ball", JointType::Ball),
        ("slide", JointType::Slide),
        ("hinge", JointType::Hinge),
    ];
    let mut j = JointAttrs::default();
    for a in &el.attrs {
        match a.name.as_str() {
            "type" => j.kind = Some(keyword(a, src, &kinds)?),
            "pos" => j.pos = Some(floats::<3>(a, src)?),
            "axis" => j.axis = Some(floats::<3>(a, src)?),
            "range" => j.range = Some(floats::<2>(a, src)?),
            "limited" => {
                let options =
                    [("false", Limited::False), ("true", Limited::True), ("auto", Limited::Auto)];
                j.limited = Some(keyword(a, src, &options)?);
            }
            "ref" => j.reference = Some(floats::<1>(a, src)?[0]),
            _ => {}
        }
    }
    Ok(j)
}

fn geom_attrs(el: &Element, src: &Sources) -> Result<GeomAttrs, Error> {
    let kinds = [
        ("plane", GeomType::Plane),
        ("hfield", GeomType::Hfield),
        ("sphere", GeomType::Sphere),
        ("capsule", GeomType::Capsule),
        ("ellipsoid", GeomType::Ellipsoid),
        ("cylinder", GeomType::Cylinder),
        ("box", GeomType::Box),
        ("mesh", GeomType::Mesh),
        ("sdf", GeomType::Sdf),
    ];
    let mut g = GeomAttrs { orientation: orientation(el, src)?, ..GeomAttrs::default() };
    for a in &el.attrs {
        match a.name.as_str() {
            "type" => g.kind = Some(keyword(a, src, &kinds)?),
            "size" => g.size = Some(float_list(a, src, 1, 3)?),
            "pos" => g.pos = Some(floats::<3>(a, src)?),
            "fromto" => g.fromto = Some(floats::<6>(a, src)?),
            "mesh" => g.mesh = Some(a.value.clone()),
            "contype" => g.contype = Some(int(a, src)?),
            "conaffinity" => g.conaffinity = Some(int(a, src)?),
            _ => {}
        }
    }
    Ok(g)
}

/// The one orientation attribute of an element, if any (two of them are an error, as in
/// MuJoCo).
fn orientation(el: &Element, src: &Sources) -> Result<Option<(Orientation, Pos)>, Error> {
    let mut found: Option<(Orientation, Pos)> = None;
    for a in &el.attrs {
        let o = match a.name.as_str() {
            "quat" => Orientation::Quat(floats::<4>(a, src)?),
            "axisangle" => Orientation::AxisAngle(floats::<4>(a, src)?),
            "euler" => Orientation::Euler(floats::<3>(a, src)?),
            "xyaxes" => Orientation::XyAxes(floats::<6>(a, src)?),
            "zaxis" => Orientation::ZAxis(floats::<3>(a, src)?),
            _ => continue,
        };
        if found.is_some() {
            return Err(
                src.invalid(a.pos, format!("multiple orientation specifiers on <{}>", el.name))
            );
        }
        found = Some((o, a.pos));
    }
    Ok(found)
}

fn float_list(a: &Attr, src: &Sources, min: usize, max: usize) -> Result<Vec<f64>, Error> {
    let values: Vec<f64> = a
        .value
        .split_ascii_whitespace()
        .map(|t| t.parse::<f64>().ok().filter(|v| v.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(|| {
            src.invalid(
                a.pos,
                format!("attribute {}=\"{}\": not a list of numbers", a.name, a.value),
            )
        })?;
    if values.len() < min || values.len() > max {
        let expected = if min == max { format!("{min}") } else { format!("{min} to {max}") };
        return Err(src.invalid(
            a.pos,
            format!(
                "attribute {}=\"{}\": expected {expected} numbers, found {}",
                a.name,
                a.value,
                values.len()
            ),
        ));
    }
    Ok(values)
}

fn floats<const N: usize>(a: &Attr, src: &Sources) -> Result<[f64; N], Error> {
    let values = float_list(a, src, N, N)?;
    let mut out = [0.0; N];
    out.copy_from_slice(&values);
    Ok(out)
}

fn int(a: &Attr, src: &Sources) -> Result<i32, Error> {
    a.value.trim().parse::<i32>().map_err(|_| {
        src.invalid(a.pos, format!("attribute {}=\"{}\": not an integer", a.name, a.value))
    })
}

fn boolean(a: &Attr, src: &Sources) -> Result<bool, Error> {
    keyword(a, src, &[("false", false), ("true", true)])
}

fn keyword<T: Copy>(a: &Attr, src: &Sources, options: &[(&str, T)]) -> Result<T, Error> {
    options.iter().find(|(k, _)| *k == a.value).map(|(_, v)| *v).ok_or_else(|| {
        let names: Vec<&str> = options.iter().map(|(k, _)| *k).collect();
        src.invalid(
            a.pos,
            format!("attribute {}=\"{}\": expected one of {}", a.name, a.value, names.join(", ")),
        )
    })
}

fn eulerseq(a: &Attr, src: &Sources) -> Result<[u8; 3], Error> {
    let bytes = a.value.as_bytes();
    if bytes.len() != 3 || !bytes.iter().all(|b| b"xyzXYZ".contains(b)) {
        return Err(src.invalid(
            a.pos,
            format!("eulerseq=\"{}\": expected three of x, y, z, X, Y, Z", a.value),
        ));
    }
    match bytes {
        &[a, b, c] => Ok([a, b, c]),
        _ => Err(src.invalid(a.pos, "eulerseq: expected three axes")),
    }
}
