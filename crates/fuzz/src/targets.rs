//! The fuzz targets: one per parser, each running the stages that follow a successful parse
//! (BVH → FK and role recognition; C3D → markers; MJCF/URDF → kinematics; IK config →
//! validation and targets against the G1; npz (ours, qpos only, BeyondMimic's) → the quality
//! report on the G1; FBX → takes, BVH and FK, in `fbx_target`; GMR's pickle and Unitree's
//! CSV → the report, in `motions`).

use std::fmt::Write as _;
use std::io::Cursor;

use arbitrary::{Arbitrary, Result, Unstructured};
use npz::{Array, ArrayData};

use crate::generate::{g1, num_value, Num};
use crate::seeds::files;
use crate::Target;

/// Every target, by name.
#[must_use]
pub fn all() -> Vec<Box<dyn Target>> {
    vec![
        Box::new(BvhTarget),
        Box::new(C3dTarget),
        Box::new(MjcfTarget),
        Box::new(UrdfTarget),
        Box::new(ConfigTarget),
        Box::new(NpzTarget),
        Box::new(crate::fbx_target::FbxTarget),
        Box::new(crate::amass::AmassTarget),
        Box::new(crate::motions::PickleTarget),
        Box::new(crate::motions::CsvTarget),
    ]
}

/// The target called `name`.
#[must_use]
pub fn by_name(name: &str) -> Option<Box<dyn Target>> {
    all().into_iter().find(|t| t.name() == name)
}

fn text(input: &[u8]) -> std::result::Result<&str, String> {
    std::str::from_utf8(input).map_err(|e| format!("not UTF-8: {e}"))
}

fn nums(out: &mut String, values: &[Num], wild: bool) {
    for (k, v) in values.iter().enumerate() {
        if k > 0 {
            out.push(' ');
        }
        v.write(out, wild);
    }
}

/// A name from `names` most of the time, else arbitrary text.
fn name(u: &mut Unstructured<'_>, names: &[&str]) -> Result<String> {
    if u.ratio(31, 32)? {
        Ok((*u.choose(names)?).to_owned())
    } else {
        let s: String = u.arbitrary()?;
        Ok(s.chars().take(12).collect())
    }
}

// ------------------------------------------------------------------------------------------
// BVH

#[rustfmt::skip]
const JOINT_NAMES: &[&str] = &[
    "Hips", "Spine", "Spine1", "Spine2", "Neck", "Head", "LeftShoulder", "LeftArm",
    "LeftForeArm", "LeftHand", "RightShoulder", "RightArm", "RightForeArm", "RightHand",
    "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToe", "LeftToeBase", "RightUpLeg", "RightLeg",
    "RightFoot", "RightToe", "RightToeBase", "pelvis", "lThigh", "Bip01 L Calf", "thigh_l",
    "LeftHip", "LeftKnee", "LeftAnkle", "L_Hip", "root", "lfemur", "ltibia",
];

#[derive(Debug, Arbitrary)]
struct BvhJoint {
    /// Index of the parent among earlier joints (the root has none).
    parent: u8,
    offset: [Num; 3],
    channels: Vec<u8>,
    end_site: Option<[Num; 3]>,
}

struct BvhTarget;

impl BvhTarget {
    fn write_joint(
        out: &mut String,
        joints: &[(String, BvhJoint)],
        children: &[Vec<usize>],
        j: usize,
        depth: usize,
        columns: &mut usize,
        wild: bool,
    ) {
        const CHANNELS: &[&str] = &[
            "Xposition",
            "Yposition",
            "Zposition",
            "Zrotation",
            "Xrotation",
            "Yrotation",
            "Xscale",
            "Wrotation",
        ];
        let (Some((name, joint)), Some(kids)) = (joints.get(j), children.get(j)) else {
            return;
        };
        let pad = "  ".repeat(depth);
        let kind = if depth == 0 { "ROOT" } else { "JOINT" };
        let _ = writeln!(out, "{pad}{kind} {name}\n{pad}{{");
        out.push_str(&pad);
        out.push_str("  OFFSET ");
        nums(out, &joint.offset, wild);
        let names: Vec<&str> = joint
            .channels
            .iter()
            .take(9)
            // Mostly the six real channels; scale and unknown ones now and then.
            .map(|&c| {
                CHANNELS[if c < 250 { usize::from(c) % 6 } else { usize::from(c) % CHANNELS.len() }]
            })
            .collect();
        let _ = writeln!(out, "\n{pad}  CHANNELS {} {}", names.len(), names.join(" "));
        *columns += names.len();
        for &k in kids {
            Self::write_joint(out, joints, children, k, depth + 1, columns, wild);
        }
        if let Some(end) = joint.end_site {
            let _ = write!(out, "{pad}  End Site\n{pad}  {{\n{pad}    OFFSET ");
            nums(out, &end, wild);
            let _ = writeln!(out, "\n{pad}  }}");
        }
        let _ = writeln!(out, "{pad}}}");
    }
}

impl Target for BvhTarget {
    fn name(&self) -> &'static str {
        "bvh"
    }

    fn seeds(&self) -> Vec<Vec<u8>> {
        let mut seeds = files("crates/bvh/tests/data", ".bvh");
        seeds.extend(files("crates/fk/tests/data/skeletons", ".bvh"));
        seeds
    }

    fn generate(&self, u: &mut Unstructured<'_>) -> Result<Vec<u8>> {
        let wild = u.ratio(1, 4)?;
        let count = u.int_in_range(1..=30)?;
        let mut joints = Vec::with_capacity(count);
        for _ in 0..count {
            let joint =
                if wild { name(u, JOINT_NAMES)? } else { (*u.choose(JOINT_NAMES)?).to_owned() };
            joints.push((joint, BvhJoint::arbitrary(u)?));
        }
        let mut children = vec![Vec::new(); count];
        for j in 1..count {
            let parent = joints.get(j).map_or(0, |(_, b)| usize::from(b.parent) % j);
            if let Some(c) = children.get_mut(parent) {
                c.push(j);
            }
        }
        let mut out = String::from("HIERARCHY\n");
        let mut columns = 0;
        Self::write_joint(&mut out, &joints, &children, 0, 0, &mut columns, wild);
        let frames = u.int_in_range(0..=40)?;
        let declared = if u.ratio(1, 8)? { u.int_in_range(0..=50)? } else { frames };
        out.push_str("MOTION\nFrames: ");
        let _ = write!(out, "{declared}\nFrame Time: ");
        if wild {
            Num::arbitrary(u)?.write(&mut out, wild);
        } else {
            out.push_str(["0.033333", "0.0083333", "0.01", "0.04"][u.choose_index(4)?]);
        }
        out.push('\n');
        for _ in 0..frames {
            let row: Vec<Num> = (0..columns).map(|_| Num::arbitrary(u)).collect::<Result<_>>()?;
            nums(&mut out, &row, wild);
            out.push('\n');
        }
        Ok(out.into_bytes())
    }

    #[rustfmt::skip]
    fn dictionary(&self) -> &'static [&'static str] {
        &[
            "{", "}", "\n", "\r\n", "\t", " ", "ROOT ", "JOINT ", "End Site", "OFFSET ",
            "CHANNELS ",
            "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation",
            "CHANNELS 3 Zrotation Xrotation Yrotation", "MOTION\n", "Frames: ", "Frame Time: ",
            "HIERARCHY\n", "Xposition", "Yrotation", "nan", "1e300", "\u{feff}",
        ]
    }

    fn run(&self, input: &[u8]) -> std::result::Result<(), String> {
        let (bvh, _warnings) = bvh::parse_with_warnings(input).map_err(|e| e.to_string())?;
        let _ = bvh::Summary::new(&bvh, "fuzz").to_string();
        let mut written = Vec::new();
        bvh::write(&bvh, &mut written).map_err(|e| e.to_string())?;
        let _ = fk::recognise(&bvh, &Default::default());
        let (motion, report) =
            fk::human_motion(&bvh, &fk::FkOptions::default()).map_err(|e| e.to_string())?;
        let _ = report.inferred();
        let _ = motion.frame_positions(0);
        Ok(())
    }
}

// ------------------------------------------------------------------------------------------
// C3D

#[derive(Debug, Arbitrary)]
struct C3dSpec {
    rate: Num,
    labels: Vec<u8>,
    frames: u8,
    points: Vec<(i16, i16, i16, u8)>,
    analog: Option<(u8, u8, Vec<i16>)>,
    scale: Num,
    format: u8,
}

struct C3dTarget;

impl C3dTarget {
    fn make(spec: &C3dSpec) -> Option<Vec<u8>> {
        let rate = num_value(spec.rate).abs().clamp(1.0, 2000.0) as f32;
        let mut c = c3d::C3d::new(rate);
        let labels: Vec<String> = spec
            .labels
            .iter()
            .take(40)
            .map(|&k| LABELS[usize::from(k) % LABELS.len()].to_owned())
            .collect();
        let frames = usize::from(spec.frames % 30);
        c.points = c3d::Points::new(labels.clone(), frames);
        let mut values = spec.points.iter().cycle();
        for f in 0..frames {
            for p in 0..labels.len() {
                let Some(&(x, y, z, r)) = values.next() else { break };
                let point = c3d::Point {
                    position: [f32::from(x) / 8.0, f32::from(y) / 8.0, f32::from(z) / 8.0],
                    residual: f32::from(r % 4) * 0.25,
                    cameras: r,
                };
                c.points.set(f, p, (r % 7 != 0).then_some(point));
            }
        }
        if let Some((channels, spf, samples)) = &spec.analog {
            let labels = (0..channels % 6).map(|k| format!("A{k}")).collect();
            let spf = usize::from(spf % 5).max(1);
            c.analog = c3d::Analog::new(labels, rate * spf as f32, spf, frames);
            let mut values = samples.iter().cycle();
            for s in 0..c.analog.sample_count() {
                for ch in 0..c.analog.channel_count() {
                    c.analog.set(s, ch, values.next().map_or(0.0, |&v| f32::from(v)));
                }
            }
        }
        c.point_scale = num_value(spec.scale) as f32;
        let format = match spec.format % 4 {
            0 => c3d::Format::INTEL_FLOAT,
            1 => c3d::Format::INTEL_INT,
            2 => c3d::Format { processor: c3d::Processor::Dec, data: c3d::DataFormat::Float },
            _ => c3d::Format { processor: c3d::Processor::Mips, data: c3d::DataFormat::Integer },
        };
        let mut out = Vec::new();
        c.write(&mut out, format).ok()?;
        Some(out)
    }
}

#[rustfmt::skip]
const LABELS: &[&str] = &[
    "LASI", "RASI", "LPSI", "RPSI", "LTHI", "LKNE", "LTIB", "LANK", "LHEE", "LTOE", "RANK", "RHEE",
    "RTOE", "C7", "T10", "CLAV", "STRN", "LSHO", "LELB", "LWRA", "LFIN", "RFHD", "",
];

impl Target for C3dTarget {
    fn name(&self) -> &'static str {
        "c3d"
    }

    fn seeds(&self) -> Vec<Vec<u8>> {
        let mut u = Unstructured::new(&[7; 512]);
        let spec = C3dSpec::arbitrary(&mut u).ok();
        spec.and_then(|s| Self::make(&s)).into_iter().collect()
    }

    fn generate(&self, u: &mut Unstructured<'_>) -> Result<Vec<u8>> {
        let spec = C3dSpec::arbitrary(u)?;
        Ok(Self::make(&spec).unwrap_or_default())
    }

    #[rustfmt::skip]
    fn dictionary(&self) -> &'static [&'static str] {
        &["POINT", "ANALOG", "LABELS", "USED", "SCALE", "RATE", "FRAMES", "DATA_START", "EVENT"]
    }

    fn run(&self, input: &[u8]) -> std::result::Result<(), String> {
        if let Ok(reader) = c3d::Reader::new(Cursor::new(input)) {
            for frame in reader.take(10_000) {
                if frame.is_err() {
                    break;
                }
            }
        }
        let file = c3d::C3d::from_reader(Cursor::new(input)).map_err(|e| e.to_string())?;
        let mut out = Vec::new();
        let _ = file.write(&mut out, c3d::Format::INTEL_FLOAT);
        let (labels, frames) = retarget::internals::labelled_points(&file);
        let bodies: Vec<fk::markers::MarkerBody> = labels
            .chunks(3)
            .enumerate()
            .map(|(k, chunk)| fk::markers::MarkerBody {
                name: format!("body{k}"),
                markers: chunk.to_vec(),
                frame: match chunk {
                    [a, b, c] => Some([a.clone(), b.clone(), c.clone()]),
                    _ => None,
                },
            })
            .collect();
        let axes = nalgebra::UnitQuaternion::identity();
        let fps = f64::from(file.point_rate());
        fk::markers::marker_motion(&labels, &frames, fps, 0.001, &axes, &bodies)
            .map_err(|e| e.to_string())?;
        Ok(())
    }
}

// ------------------------------------------------------------------------------------------
// MJCF and URDF: element trees over the formats' vocabulary.

#[derive(Debug)]
struct Element {
    tag: String,
    attrs: Vec<(String, String)>,
    children: Vec<Element>,
}

impl Element {
    fn generate(
        u: &mut Unstructured<'_>,
        tags: &[&str],
        attrs: &[&str],
        depth: usize,
        wild: bool,
    ) -> Result<Element> {
        let pick = |u: &mut Unstructured<'_>, names: &[&str]| -> Result<String> {
            if wild {
                name(u, names)
            } else {
                Ok((*u.choose(names)?).to_owned())
            }
        };
        let tag = pick(u, tags)?;
        let mut list: Vec<(String, String)> = Vec::new();
        for _ in 0..u.int_in_range(0..=5)? {
            let attr = pick(u, attrs)?;
            if wild || list.iter().all(|(a, _)| *a != attr) {
                list.push((attr, value(u, wild)?));
            }
        }
        let mut children = Vec::new();
        if depth < 7 {
            for _ in 0..u.int_in_range(0..=4)? {
                children.push(Element::generate(u, tags, attrs, depth + 1, wild)?);
            }
        }
        Ok(Element { tag, attrs: list, children })
    }

    fn write(&self, out: &mut String) {
        let _ = write!(out, "<{}", self.tag);
        for (k, v) in &self.attrs {
            let _ = write!(out, " {k}=\"{}\"", v.replace('"', "&quot;").replace('<', "&lt;"));
        }
        if self.children.is_empty() {
            out.push_str("/>\n");
        } else {
            out.push_str(">\n");
            for c in &self.children {
                c.write(out);
            }
            let _ = writeln!(out, "</{}>", self.tag);
        }
    }
}

/// An attribute value: numbers (1 to 9), a keyword or a name.
fn value(u: &mut Unstructured<'_>, wild: bool) -> Result<String> {
    const WORDS: &[&str] = &[
        "hinge",
        "slide",
        "ball",
        "free",
        "true",
        "false",
        "auto",
        "radian",
        "degree",
        "xyz",
        "XYZ",
        "zyx",
        "box",
        "sphere",
        "capsule",
        "cylinder",
        "ellipsoid",
        "plane",
        "mesh",
        "main",
        "a",
        "b",
        "base",
        "link1",
        "link2",
        "revolute",
        "continuous",
        "prismatic",
        "fixed",
        "floating",
        "planar",
        "world",
        "local",
        "",
    ];
    Ok(match u.int_in_range(0..=2)? {
        0 => (*u.choose(WORDS)?).to_owned(),
        1 => {
            let mut s = String::new();
            let n = u.int_in_range(1..=9)?;
            let values: Vec<Num> = (0..n).map(|_| Num::arbitrary(u)).collect::<Result<_>>()?;
            nums(&mut s, &values, wild);
            s
        }
        _ => {
            let mut s = String::new();
            let values: Vec<Num> = (0..3).map(|_| Num::arbitrary(u)).collect::<Result<_>>()?;
            nums(&mut s, &values, wild);
            s
        }
    })
}

/// Every body's world pose at `qpos0` and at a perturbed configuration, Jacobians included.
fn exercise(model: &mjcf::Model) {
    let mut data = mjcf::Data::new(model);
    model.kinematics(&model.qpos0, &mut data);
    let mut qpos = model.qpos0.clone();
    let qvel = vec![0.1; model.nv];
    model.integrate_pos(&mut qpos, &qvel, 0.5);
    model.kinematics(&qpos, &mut data);
    let (mut jacp, mut jacr) = (vec![0.0; 3 * model.nv], vec![0.0; 3 * model.nv]);
    for body in 0..model.nbody() {
        model.jac_body(&data, body, &mut jacp, &mut jacr);
    }
}

struct MjcfTarget;

#[rustfmt::skip]
const MJCF_TAGS: &[&str] = &[
    "mujoco", "worldbody", "body", "joint", "freejoint", "geom", "site", "inertial", "default",
    "compiler", "option", "frame", "asset", "mesh", "actuator", "motor", "contact", "exclude",
    "equality", "sensor", "keyframe", "key", "size", "visual", "camera", "light",
];
#[rustfmt::skip]
const MJCF_ATTRS: &[&str] = &[
    "name", "pos", "quat", "axisangle", "euler", "xyaxes", "zaxis", "type", "axis", "range",
    "limited", "size", "fromto", "class", "childclass", "angle", "eulerseq", "autolimits",
    "mass", "diaginertia", "fullinertia", "ref", "springref", "armature", "damping", "joint",
    "body1", "body2", "qpos", "model", "file", "meshdir", "contype", "conaffinity", "group",
];

impl Target for MjcfTarget {
    fn name(&self) -> &'static str {
        "mjcf"
    }

    fn seeds(&self) -> Vec<Vec<u8>> {
        let mut seeds = files("crates/mjcf/tests/data/features", ".xml");
        for robot in ["unitree_g1", "unitree_h1", "booster_t1_29dof", "stanford_toddy"] {
            seeds.extend(files(&format!("robots/{robot}"), ".xml"));
        }
        seeds
    }

    fn generate(&self, u: &mut Unstructured<'_>) -> Result<Vec<u8>> {
        let wild = u.ratio(1, 4)?;
        let mut root = Element::generate(u, MJCF_TAGS, MJCF_ATTRS, 0, wild)?;
        if u.ratio(7, 8)? {
            root.tag = "mujoco".to_owned();
        }
        root.attrs.retain(|(k, v)| !(k == "file" || v.contains('/')));
        let mut out = String::new();
        root.write(&mut out);
        Ok(out.into_bytes())
    }

    #[rustfmt::skip]
    fn dictionary(&self) -> &'static [&'static str] {
        &[
            "<body>", "</body>", "<joint/>", "<geom size=\"1\"/>", "name=\"", "pos=\"", "\"",
            "<", ">", "/>", "&amp;", "<!--", "-->",
        ]
    }

    fn run(&self, input: &[u8]) -> std::result::Result<(), String> {
        // Includes resolve against an empty folder: the harness reads no other files.
        let empty = std::env::temp_dir().join("retarget-fuzz-empty");
        let _ = std::fs::create_dir_all(&empty);
        let model =
            mjcf::Model::from_xml_str(text(input)?, Some(&empty)).map_err(|e| e.to_string())?;
        exercise(&model);
        Ok(())
    }
}

struct UrdfTarget;

#[rustfmt::skip]
const URDF_TAGS: &[&str] = &[
    "robot", "link", "joint", "parent", "child", "origin", "axis", "limit", "inertial", "mass",
    "inertia", "collision", "visual", "geometry", "box", "sphere", "cylinder", "mesh", "mimic",
    "dynamics", "mujoco", "compiler",
];
#[rustfmt::skip]
const URDF_ATTRS: &[&str] = &[
    "name", "type", "link", "xyz", "rpy", "lower", "upper", "effort", "velocity", "size",
    "radius", "length", "filename", "value", "ixx", "iyy", "izz", "ixy", "ixz", "iyz",
    "fusestatic", "joint", "multiplier",
];

/// A URDF robot: links joined into a random tree by joints of every type, with origins,
/// axes, limits, inertials and collision shapes of arbitrary numbers.
fn urdf_tree(u: &mut Unstructured<'_>, wild: bool) -> Result<Vec<u8>> {
    const TYPES: &[&str] = &["revolute", "continuous", "prismatic", "fixed", "floating", "planar"];
    const SHAPES: &[&str] = &["box size", "sphere radius", "cylinder radius"];
    let numbers = |u: &mut Unstructured<'_>, n: usize| -> Result<String> {
        let values: Vec<Num> = (0..n).map(|_| Num::arbitrary(u)).collect::<Result<_>>()?;
        let mut s = String::new();
        nums(&mut s, &values, wild);
        // Clean files have positive sizes, masses and inertias (and positive offsets).
        Ok(if wild { s } else { s.replace('-', "") })
    };
    let links = u.int_in_range(1..=12)?;
    let mut out = String::from("<robot name=\"r\">\n");
    for k in 0..links {
        let _ = write!(out, "<link name=\"l{k}\">");
        if u.arbitrary()? {
            let m = numbers(u, 1)?;
            // Clean files have inertias MuJoCo accepts (positive moments that satisfy the
            // triangle inequality: here equal, with no products); wild ones arbitrary tensors,
            // which the reader rejects as MuJoCo does, mostly.
            let i = if wild {
                numbers(u, 6)?
            } else {
                let moment = numbers(u, 1)?;
                format!("{moment} {moment} {moment} 0 0 0")
            };
            let i: Vec<&str> = i.split(' ').collect();
            let _ = write!(
                out,
                "<inertial><origin xyz=\"{}\"/><mass value=\"{m}\"/><inertia ixx=\"{}\" iyy=\"{}\" izz=\"{}\" ixy=\"{}\" ixz=\"{}\" iyz=\"{}\"/></inertial>",
                numbers(u, 3)?,
                i.first().unwrap_or(&"1"),
                i.get(1).unwrap_or(&"1"),
                i.get(2).unwrap_or(&"1"),
                i.get(3).unwrap_or(&"0"),
                i.get(4).unwrap_or(&"0"),
                i.get(5).unwrap_or(&"0")
            );
        }
        if u.arbitrary()? {
            let shape = *u.choose(SHAPES)?;
            let (tag, attr) = shape.split_once(' ').unwrap_or(("box", "size"));
            let n = if tag == "box" { 3 } else { 1 };
            let extra = if tag == "cylinder" {
                format!(" length=\"{}\"", numbers(u, 1)?)
            } else {
                String::new()
            };
            let _ = write!(
                out,
                "<collision><origin xyz=\"{}\" rpy=\"{}\"/><geometry><{tag} {attr}=\"{}\"{extra}/></geometry></collision>",
                numbers(u, 3)?,
                numbers(u, 3)?,
                numbers(u, n)?
            );
        }
        out.push_str("</link>\n");
    }
    for k in 1..links {
        let parent = u.int_in_range(0..=k - 1)?;
        let kind = *u.choose(TYPES)?;
        let _ = write!(
            out,
            "<joint name=\"j{k}\" type=\"{kind}\"><parent link=\"l{parent}\"/><child link=\"l{k}\"/><origin xyz=\"{}\" rpy=\"{}\"/><axis xyz=\"{}\"/>",
            numbers(u, 3)?,
            numbers(u, 3)?,
            numbers(u, 3)?
        );
        if u.arbitrary()? {
            let l = numbers(u, 4)?;
            let l: Vec<&str> = l.split(' ').collect();
            let _ = write!(
                out,
                "<limit lower=\"{}\" upper=\"{}\" effort=\"{}\" velocity=\"{}\"/>",
                l.first().unwrap_or(&"-1"),
                l.get(1).unwrap_or(&"1"),
                l.get(2).unwrap_or(&"1"),
                l.get(3).unwrap_or(&"1")
            );
        }
        out.push_str("</joint>\n");
    }
    out.push_str("</robot>\n");
    Ok(out.into_bytes())
}

impl Target for UrdfTarget {
    fn name(&self) -> &'static str {
        "urdf"
    }

    fn seeds(&self) -> Vec<Vec<u8>> {
        files("crates/mjcf/tests/data/urdf", ".urdf")
    }

    fn generate(&self, u: &mut Unstructured<'_>) -> Result<Vec<u8>> {
        let wild = u.ratio(1, 4)?;
        if u.ratio(3, 4)? {
            return urdf_tree(u, wild);
        }
        let mut root = Element::generate(u, URDF_TAGS, URDF_ATTRS, 0, wild)?;
        if u.ratio(7, 8)? {
            root.tag = "robot".to_owned();
        }
        let mut out = String::new();
        root.write(&mut out);
        Ok(out.into_bytes())
    }

    #[rustfmt::skip]
    fn dictionary(&self) -> &'static [&'static str] {
        &[
            "<link name=\"a\"/>", "<joint name=\"j\" type=\"revolute\">", "</joint>",
            "<parent link=\"a\"/>", "<child link=\"b\"/>", "\"", "<", ">", "/>",
        ]
    }

    fn run(&self, input: &[u8]) -> std::result::Result<(), String> {
        let model = mjcf::Model::from_urdf_str(text(input)?, mjcf::UrdfOptions::default())
            .map_err(|e| e.to_string())?;
        exercise(&model);
        Ok(())
    }
}

// ------------------------------------------------------------------------------------------
// IK config (GMR JSON schema)

#[rustfmt::skip]
const LAFAN1_BODIES: &[&str] = &[
    "Hips", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToe", "RightUpLeg", "RightLeg", "RightFoot",
    "RightToe", "Spine", "Spine1", "Spine2", "Neck", "Head", "LeftShoulder", "LeftArm",
    "LeftForeArm", "LeftHand", "RightShoulder", "RightArm", "RightForeArm", "RightHand",
    "LeftFootMod", "RightFootMod",
];
#[rustfmt::skip]
const G1_BODIES: &[&str] = &[
    "pelvis", "left_hip_yaw_link", "left_knee_link", "left_ankle_roll_link", "torso_link",
    "right_hip_yaw_link", "right_knee_link", "right_ankle_roll_link", "left_elbow_link",
    "left_shoulder_yaw_link", "left_wrist_yaw_link", "right_elbow_link", "world",
];

struct ConfigTarget;

fn json_number(u: &mut Unstructured<'_>, wild: bool) -> Result<serde_json::Value> {
    Ok(match Num::arbitrary(u)? {
        Num::Special(_) | Num::Any(_) if !wild => serde_json::json!(1.0),
        n if !wild => serde_json::Number::from_f64(num_value(n).abs())
            .map_or(serde_json::Value::Null, Into::into),
        Num::Special(k) => match k % 4 {
            0 => serde_json::Value::Null,
            1 => serde_json::json!("x"),
            2 => serde_json::json!(1e308),
            _ => serde_json::json!(-1),
        },
        n => serde_json::Number::from_f64(num_value(n)).map_or(serde_json::Value::Null, Into::into),
    })
}

fn json_entry(u: &mut Unstructured<'_>, wild: bool) -> Result<serde_json::Value> {
    let mut items = vec![
        serde_json::Value::String(name(u, LAFAN1_BODIES)?),
        json_number(u, wild)?,
        json_number(u, wild)?,
        serde_json::Value::Array((0..3).map(|_| json_number(u, wild)).collect::<Result<_>>()?),
        serde_json::Value::Array((0..4).map(|_| json_number(u, wild)).collect::<Result<_>>()?),
    ];
    if wild && u.ratio(1, 8)? {
        items.truncate(u.int_in_range(0..=4)?);
    }
    Ok(serde_json::Value::Array(items))
}

/// A config that keeps GMR's structural rules (distinct bodies, every tracked human body
/// scaled, the root in the scale table), so that validation passes and targets are built.
fn clean_config(u: &mut Unstructured<'_>) -> Result<Vec<u8>> {
    let robots: Vec<&str> = G1_BODIES.iter().copied().filter(|b| *b != "world").collect();
    let mut scale = serde_json::Map::new();
    scale.insert("Hips".to_owned(), json_number(u, false)?);
    let mut tables = Vec::new();
    for _ in 0..2 {
        let mut table = serde_json::Map::new();
        let n = u.int_in_range(0..=robots.len())?;
        let offset = u.int_in_range(0..=LAFAN1_BODIES.len())?;
        for (k, robot) in robots.iter().take(n).enumerate() {
            let human = LAFAN1_BODIES[(k + offset) % LAFAN1_BODIES.len()];
            scale.insert(human.to_owned(), json_number(u, false)?);
            let mut entry = json_entry(u, false)?;
            if let Some(first) = entry.as_array_mut().and_then(|a| a.first_mut()) {
                *first = human.into();
            }
            table.insert((*robot).to_owned(), entry);
        }
        tables.push(table);
    }
    let [t1, t2] = [tables.remove(0), tables.remove(0)];
    let config = serde_json::json!({
        "robot_root_name": "pelvis",
        "human_root_name": "Hips",
        "ground_height": json_number(u, false)?,
        "human_height_assumption": json_number(u, false)?,
        "use_ik_match_table1": u.arbitrary::<bool>()?,
        "use_ik_match_table2": u.arbitrary::<bool>()?,
        "human_scale_table": scale,
        "ik_match_table1": t1,
        "ik_match_table2": t2,
    });
    Ok(serde_json::to_vec_pretty(&config).unwrap_or_default())
}

impl Target for ConfigTarget {
    fn name(&self) -> &'static str {
        "config"
    }

    fn seeds(&self) -> Vec<Vec<u8>> {
        files("configs", ".json")
    }

    fn generate(&self, u: &mut Unstructured<'_>) -> Result<Vec<u8>> {
        let wild = u.ratio(1, 4)?;
        if !wild && u.ratio(1, 2)? {
            return clean_config(u);
        }
        let mut map = serde_json::Map::new();
        let keys = [
            "robot_root_name",
            "human_root_name",
            "ground_height",
            "human_height_assumption",
            "use_ik_match_table1",
            "use_ik_match_table2",
            "human_scale_table",
            "ik_match_table1",
            "ik_match_table2",
            "extra_key",
        ];
        for key in keys {
            let skip = if key == "extra_key" { u.ratio(15, 16)? } else { u.ratio(1, 32)? };
            if skip {
                continue;
            }
            let v = match key {
                "robot_root_name" => name(u, G1_BODIES)?.into(),
                "human_root_name" => name(u, LAFAN1_BODIES)?.into(),
                "use_ik_match_table1" | "use_ik_match_table2" => u.arbitrary::<bool>()?.into(),
                "human_scale_table" => {
                    let mut t = serde_json::Map::new();
                    for _ in 0..u.int_in_range(0..=16)? {
                        t.insert(name(u, LAFAN1_BODIES)?, json_number(u, wild)?);
                    }
                    t.into()
                }
                "ik_match_table1" | "ik_match_table2" => {
                    let mut t = serde_json::Map::new();
                    for _ in 0..u.int_in_range(0..=14)? {
                        t.insert(name(u, G1_BODIES)?, json_entry(u, wild)?);
                    }
                    t.into()
                }
                _ => json_number(u, wild)?,
            };
            map.insert(key.to_owned(), v);
        }
        Ok(serde_json::to_vec_pretty(&serde_json::Value::Object(map)).unwrap_or_default())
    }

    #[rustfmt::skip]
    fn dictionary(&self) -> &'static [&'static str] {
        &[
            "{", "}", "[", "]", ",", ":", "\"", "null", "true", "1e999", "\"Hips\"",
            "\"pelvis\"", "\\u0000", "\\ud800",
        ]
    }

    fn run(&self, input: &[u8]) -> std::result::Result<(), String> {
        let config = retarget::IkConfig::from_json_str(text(input)?, "fuzz.json")
            .map_err(|e| e.to_string())?;
        let human: Vec<String> = LAFAN1_BODIES.iter().map(|s| (*s).to_owned()).collect();
        let model = g1();
        config.validate(model, &human).map_err(|e| e.to_string())?;
        let map =
            retarget::internals::TargetMap::new(&config, &human, 1.7).map_err(|e| e.to_string())?;
        let positions: Vec<nalgebra::Vector3<f64>> =
            (0..human.len()).map(|k| nalgebra::Vector3::new(0.0, 0.1 * k as f64, 1.0)).collect();
        let orientations = vec![nalgebra::UnitQuaternion::identity(); human.len()];
        let mut out = vec![
            retarget::internals::Pose {
                quat: [1.0, 0.0, 0.0, 0.0],
                pos: nalgebra::Vector3::zeros()
            };
            map.bodies.len()
        ];
        map.compute(&positions, &orientations, &mut out);
        let _ = retarget::internals::task_specs(&config, model, &map);
        Ok(())
    }
}

// ------------------------------------------------------------------------------------------
// npz

#[derive(Debug, Arbitrary)]
struct NpyMember {
    key: u8,
    descr: u8,
    shape: Vec<u16>,
    /// Shape entries replaced by huge numbers.
    huge: Option<(u8, u64)>,
    fortran: bool,
    version: u8,
    data: Vec<u8>,
    deflate: bool,
}

struct NpzTarget;

impl NpzTarget {
    fn npy(m: &NpyMember) -> Vec<u8> {
        #[rustfmt::skip]
        const DESCR: &[&str] = &[
            "<f8", "<f4", "<i8", "<i4", "|b1", "<U0", "<U1", "<U12", "<u2", ">f8", "<U", "<f2",
            ">i2", "|u1", "<u8", "|S4", "|S0", ">U3", "|O", "<c16",
        ];
        let mut shape: Vec<String> = m.shape.iter().take(4).map(|d| (d % 64).to_string()).collect();
        if let Some((at, big)) = m.huge {
            let i = usize::from(at) % shape.len().max(1);
            if let Some(slot) = shape.get_mut(i) {
                *slot = big.to_string();
            } else {
                shape.push(big.to_string());
            }
        }
        let shape = match shape.len() {
            1 => format!("({},)", shape.join("")),
            _ => format!("({})", shape.join(", ")),
        };
        let descr = DESCR[usize::from(m.descr) % DESCR.len()];
        let fortran = if m.fortran { "True" } else { "False" };
        let header =
            format!("{{'descr': '{descr}', 'fortran_order': {fortran}, 'shape': {shape}, }}\n");
        let version = [1u8, 2, 3, 9][usize::from(m.version % 4)];
        let mut out = b"\x93NUMPY".to_vec();
        out.extend_from_slice(&[version, 0]);
        let len = header.len();
        if version == 1 {
            out.extend_from_slice(&u16::try_from(len).unwrap_or(u16::MAX).to_le_bytes());
        } else {
            out.extend_from_slice(&u32::try_from(len).unwrap_or(u32::MAX).to_le_bytes());
        }
        out.extend_from_slice(header.as_bytes());
        out.extend_from_slice(&m.data);
        out
    }

    fn zip(members: &[(String, Vec<u8>, bool)]) -> Vec<u8> {
        use std::io::Write;
        let mut zip = zip::ZipWriter::new(Cursor::new(Vec::new()));
        for (name, bytes, deflate) in members {
            let method = if *deflate {
                zip::CompressionMethod::Deflated
            } else {
                zip::CompressionMethod::Stored
            };
            let options = zip::write::SimpleFileOptions::default().compression_method(method);
            if zip.start_file(name.as_str(), options).is_err() || zip.write_all(bytes).is_err() {
                break;
            }
        }
        zip.finish().map(Cursor::into_inner).unwrap_or_default()
    }

    /// The members of a motion of the G1 (so that the report runs), numbers arbitrary,
    /// written by the `npz` crate's writer.
    fn coherent(u: &mut Unstructured<'_>) -> Result<Vec<(String, Vec<u8>, bool)>> {
        let model = g1();
        let wild = u.ratio(1, 4)?;
        let frames = u.int_in_range(1..=6)?;
        let floats = |u: &mut Unstructured<'_>, shape: Vec<usize>, base: &[f64]| -> Result<Array> {
            let n = shape.iter().product();
            let mut out = Vec::with_capacity(n);
            for k in 0..n {
                let b = base.get(k % base.len().max(1)).copied().unwrap_or(0.0);
                out.push(match Num::arbitrary(u)? {
                    Num::Tenths(t) => b + f64::from(t) * 1e-3,
                    Num::Small(t) => b + f64::from(t) * 1e-2,
                    other if wild => num_value(other),
                    _ => b,
                });
            }
            Ok(Array::f64(shape, out))
        };
        let member = |key: &str, array: Array| (format!("{key}.npy"), array.to_npy(), false);
        let joints = retarget::RobotMotion::model_joint_names(model);
        let bodies = retarget::RobotMotion::model_body_names(model);
        let nq = model.nq;
        let mut members = vec![
            member("fps", floats(u, vec![1], &[30.0])?),
            member("qpos", floats(u, vec![frames, nq], &model.qpos0)?),
            member("joint_names", Array::strings(&joints)),
            member("body_names", Array::strings(&bodies)),
        ];
        // Other tools' layouts (`read_motion`): qpos without names, or BeyondMimic's keys.
        match u.int_in_range(0..=3)? {
            2 => members.retain(|(n, _, _)| n != "joint_names.npy" && n != "body_names.npy"),
            3 => {
                let keep_names: bool = u.arbitrary()?;
                members.retain(|(n, _, _)| {
                    n != "qpos.npy"
                        && n != "body_names.npy"
                        && (keep_names || n != "joint_names.npy")
                });
                let b = u.int_in_range(1..=4)?;
                let base = model.qpos0.get(7..).unwrap_or_default();
                members.push(member("joint_pos", floats(u, vec![frames, nq - 7], base)?));
                members
                    .push(member("body_pos_w", floats(u, vec![frames, b, 3], &[0.0, 0.0, 0.79])?));
                let identity = [1.0, 0.0, 0.0, 0.0];
                members.push(member("body_quat_w", floats(u, vec![frames, b, 4], &identity)?));
            }
            _ => {}
        }
        if u.arbitrary()? {
            let bools: Vec<bool> = (0..frames).map(|_| u.arbitrary()).collect::<Result<_>>()?;
            members.push(member("contact_left", Array::bools(&bools)));
            members.push(member("contact_right", Array::bools(&bools)));
        }
        if u.arbitrary()? {
            let names = ["pelvis".to_owned(), "left_ankle_roll_link".to_owned()];
            members.push(member("target_body_names", Array::strings(&names)));
            members.push(member("target_pos", floats(u, vec![frames, 2, 3], &[0.0, 0.0, 0.8])?));
            let identity = [1.0, 0.0, 0.0, 0.0];
            members.push(member("target_quat", floats(u, vec![frames, 2, 4], &identity)?));
        }
        Ok(members)
    }

    /// A small valid motion of the G1, written by our own writer.
    fn written_motion(frames: usize) -> Vec<u8> {
        let model = g1();
        let mut qpos = Vec::new();
        for f in 0..frames {
            let mut q = model.qpos0.clone();
            q.iter_mut().skip(7).for_each(|v| *v += 0.01 * f as f64);
            qpos.extend(q);
        }
        let motion = retarget::RobotMotion {
            fps: 30.0,
            nq: model.nq,
            qpos,
            joint_names: retarget::RobotMotion::model_joint_names(model),
            body_names: retarget::RobotMotion::model_body_names(model),
            targets: None,
            contacts: Some(retarget::FootContacts {
                left: (0..frames).map(|f| f % 2 == 0).collect(),
                right: vec![true; frames],
                on_toes: None,
            }),
        };
        let dir = std::env::temp_dir().join(format!("retarget-fuzz-npz-{}", std::process::id()));
        let _ = std::fs::create_dir_all(&dir);
        let path = dir.join("seed.npz");
        let written = retarget::writers::write_motion(&path, &motion, model, None);
        let bytes = written.ok().and_then(|()| std::fs::read(&path).ok()).unwrap_or_default();
        let _ = std::fs::remove_dir_all(&dir);
        bytes
    }
}

/// The `npz` crate's ways of reading a member give the same numbers: whole (`array`), as
/// `f64`s (`floats`) and streamed in rows of its last dimension (`rows`); a disagreement is a
/// bug (a panic, which the harness reports).
fn readers_agree(input: &[u8], name: &std::path::Path) {
    let Ok(mut npz) = npz::Npz::new(Cursor::new(input), name) else { return };
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    for key in npz.keys() {
        let Ok(array) = npz.array(&key) else { continue };
        let numbers = match &array.data {
            ArrayData::F64(v) => v.clone(),
            ArrayData::Bool(v) => v.iter().map(|&b| f64::from(u8::from(b))).collect(),
            ArrayData::Str(_) => continue,
        };
        let floats = npz.floats(&key).ok().map(|(shape, v)| (shape, bits(&v)));
        assert_eq!(floats, Some((array.shape.clone(), bits(&numbers))), "`{key}`: floats ≠ array");
        let row = array.shape.last().copied().unwrap_or(1);
        if row > 0 {
            let mut streamed = Vec::new();
            let shape = npz.rows(&key, row, |_, r| streamed.extend_from_slice(r));
            assert!(shape.is_ok() && bits(&streamed) == bits(&numbers), "`{key}`: rows ≠ array");
        }
    }
}

#[rustfmt::skip]
const NPZ_KEYS: &[&str] = &[
    "fps", "qpos", "joint_names", "body_names", "target_body_names", "target_pos", "target_quat",
    "contact_left", "contact_right", "robot", "joint_pos", "body_pos_w", "body_quat_w",
];

impl Target for NpzTarget {
    fn name(&self) -> &'static str {
        "npz"
    }

    fn seeds(&self) -> Vec<Vec<u8>> {
        vec![Self::written_motion(3), Self::written_motion(1)]
    }

    fn generate(&self, u: &mut Unstructured<'_>) -> Result<Vec<u8>> {
        let mut members = if u.ratio(3, 4)? { Self::coherent(u)? } else { Vec::new() };
        let wild: Vec<NpyMember> = u.arbitrary()?;
        for m in wild.iter().take(if members.is_empty() { 12 } else { 2 }) {
            let key = NPZ_KEYS[usize::from(m.key) % NPZ_KEYS.len()];
            let entry = (format!("{key}.npy"), Self::npy(m), m.deflate);
            match members.iter_mut().find(|(name, _, _)| *name == entry.0) {
                Some(slot) => *slot = entry,
                None => members.push(entry),
            }
        }
        Ok(Self::zip(&members))
    }

    #[rustfmt::skip]
    fn dictionary(&self) -> &'static [&'static str] {
        &[
            "'descr'", "'shape'", "<U0", "<f8", "(1,)", "(100000000000000,)", "PK\x03\x04",
            "PK\x01\x02", "PK\x05\x06",
        ]
    }

    fn run(&self, input: &[u8]) -> std::result::Result<(), String> {
        let name = std::path::Path::new("fuzz.npz");
        readers_agree(input, name);
        // Our own reader, then the reader of every .npz layout, whose motion is reported.
        let _ = retarget::writers::read_motion_npz_bytes(input, name).map(|m| m.num_frames());
        let (motion, _) = retarget::writers::read_motion_bytes(input, name, g1(), None)
            .map_err(|e| e.to_string())?;
        let report =
            retarget::report::report(&motion, g1(), &retarget::report::ReportOptions::default())
                .map_err(|e| e.to_string())?;
        let _ = format!("{report:?}");
        Ok(())
    }
}
