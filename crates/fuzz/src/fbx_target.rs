//! The FBX target: structure-aware FBX documents (a node tree written as binary 7.4 or 7.5,
//! or as ASCII), with a random hierarchy of bones, Nulls, meshes and cameras, transform
//! properties (pre-rotation, rotation order, pivots, inherit type, scaling), takes with any
//! range and curves with any keys; then every stage after a successful read (takes, the
//! default take, sampling to BVH, FK and role recognition, straight limbs, the retargeter's
//! clip). Seeds: our fixtures (`crates/fbx/tests/data`, ASCII 7.4 and 6.1).

use std::fmt::Write as _;

use arbitrary::{Arbitrary, Result, Unstructured};

use crate::Target;

/// A property of an FBX node record (binary type codes in the comments).
#[derive(Debug, Clone)]
enum Prop {
    I(i32),    // 'I'
    L(i64),    // 'L'
    D(f64),    // 'D'
    S(String), // 'S'
    /// `Name::Class` in ASCII, `Name\0\x01Class` in binary.
    Name(String, &'static str),
    ArrL(Vec<i64>), // 'l'
    ArrF(Vec<f32>), // 'f'
    ArrI(Vec<i32>), // 'i'
}

#[derive(Debug, Clone)]
struct Node {
    name: &'static str,
    props: Vec<Prop>,
    children: Vec<Node>,
}

fn node(name: &'static str, props: Vec<Prop>, children: Vec<Node>) -> Node {
    Node { name, props, children }
}

fn s(text: &str) -> Prop {
    Prop::S(text.to_owned())
}

/// `P: "name", "type", "label", "flags", values…` (Properties70).
fn p(name: &str, kind: &str, values: Vec<Prop>) -> Node {
    let mut props = vec![s(name), s(kind), s(""), s("A")];
    props.extend(values);
    node("P", props, Vec::new())
}

fn write_ascii(out: &mut String, n: &Node, depth: usize) {
    let pad = "\t".repeat(depth);
    let _ = write!(out, "{pad}{}: ", n.name);
    let mut array_body = None;
    for (k, prop) in n.props.iter().enumerate() {
        if k > 0 {
            out.push_str(", ");
        }
        let _ = match prop {
            Prop::I(v) => write!(out, "{v}"),
            Prop::L(v) => write!(out, "{v}"),
            Prop::D(v) => write!(out, "{v:?}"),
            Prop::S(v) => write!(out, "\"{}\"", v.replace('"', "")),
            Prop::Name(name, class) => write!(out, "\"{class}::{}\"", name.replace('"', "")),
            Prop::ArrL(v) => {
                array_body = Some(v.iter().map(i64::to_string).collect::<Vec<_>>());
                write!(out, "*{}", v.len())
            }
            Prop::ArrF(v) => {
                array_body = Some(v.iter().map(|x| format!("{x:?}")).collect::<Vec<_>>());
                write!(out, "*{}", v.len())
            }
            Prop::ArrI(v) => {
                array_body = Some(v.iter().map(i32::to_string).collect::<Vec<_>>());
                write!(out, "*{}", v.len())
            }
        };
    }
    if let Some(values) = array_body {
        let _ = writeln!(out, " {{\n{pad}\ta: {}\n{pad}}}", values.join(","));
        return;
    }
    if n.children.is_empty() {
        out.push('\n');
        return;
    }
    out.push_str(" {\n");
    for child in &n.children {
        write_ascii(out, child, depth + 1);
    }
    let _ = writeln!(out, "{pad}}}");
}

/// One binary node record at `out.len()` (FBX 7.5 and later: 64-bit offsets and counts).
fn write_binary(out: &mut Vec<u8>, n: &Node, wide: bool) {
    let start = out.len();
    let word = |out: &mut Vec<u8>, v: u64| {
        if wide {
            out.extend(v.to_le_bytes());
        } else {
            out.extend((v as u32).to_le_bytes());
        }
    };
    word(out, 0); // end offset, patched below
    word(out, n.props.len() as u64);
    let props_len_at = out.len();
    word(out, 0);
    out.push(n.name.len() as u8);
    out.extend(n.name.as_bytes());
    let props_start = out.len();
    for prop in &n.props {
        let array = |out: &mut Vec<u8>, code: u8, count: usize, bytes: Vec<u8>| {
            out.push(code);
            out.extend((count as u32).to_le_bytes());
            out.extend(0u32.to_le_bytes()); // not compressed
            out.extend((bytes.len() as u32).to_le_bytes());
            out.extend(bytes);
        };
        match prop {
            Prop::I(v) => {
                out.push(b'I');
                out.extend(v.to_le_bytes());
            }
            Prop::L(v) => {
                out.push(b'L');
                out.extend(v.to_le_bytes());
            }
            Prop::D(v) => {
                out.push(b'D');
                out.extend(v.to_le_bytes());
            }
            Prop::S(v) => {
                out.push(b'S');
                out.extend((v.len() as u32).to_le_bytes());
                out.extend(v.as_bytes());
            }
            Prop::Name(name, class) => {
                let text = format!("{name}\u{0}\u{1}{class}");
                out.push(b'S');
                out.extend((text.len() as u32).to_le_bytes());
                out.extend(text.as_bytes());
            }
            Prop::ArrL(v) => {
                array(out, b'l', v.len(), v.iter().flat_map(|x| x.to_le_bytes()).collect())
            }
            Prop::ArrF(v) => {
                array(out, b'f', v.len(), v.iter().flat_map(|x| x.to_le_bytes()).collect())
            }
            Prop::ArrI(v) => {
                array(out, b'i', v.len(), v.iter().flat_map(|x| x.to_le_bytes()).collect())
            }
        }
    }
    let props_len = (out.len() - props_start) as u64;
    patch(out, props_len_at, props_len, wide);
    if !n.children.is_empty() {
        for child in &n.children {
            write_binary(out, child, wide);
        }
        out.extend(std::iter::repeat_n(0u8, if wide { 25 } else { 13 }));
    }
    let end = out.len() as u64;
    patch(out, start, end, wide);
}

fn patch(out: &mut [u8], at: usize, value: u64, wide: bool) {
    let bytes =
        if wide { value.to_le_bytes().to_vec() } else { (value as u32).to_le_bytes().to_vec() };
    if let Some(slot) = out.get_mut(at..at + bytes.len()) {
        slot.copy_from_slice(&bytes);
    }
}

#[rustfmt::skip]
const NAMES: &[&str] = &[
    "Hips", "Spine", "Spine2", "Neck", "Head", "LeftShoulder", "LeftArm", "LeftForeArm",
    "LeftHand", "RightShoulder", "RightArm", "RightForeArm", "RightHand", "LeftUpLeg", "LeftLeg",
    "LeftFoot", "LeftToeBase", "RightUpLeg", "RightLeg", "RightFoot", "RightToeBase",
    "mixamorig:Hips", "Bip01 L Thigh", "Bip01 Pelvis", "bras droit", "main droite", "tête",
    "jambe gauche", "pied gauche", "HipsCtrl", "LeftFootIK", "Armature", "Root", "",
];

const KINDS: &[&str] =
    &["LimbNode", "LimbNode", "LimbNode", "Null", "Root", "Mesh", "Camera", "Limb"];

#[derive(Debug, Arbitrary)]
struct ModelSpec {
    parent: u8,
    name: u8,
    kind: u8,
    translation: [i16; 3],
    rotation: Option<[i16; 3]>,
    scaling: Option<[i8; 3]>,
    pre_rotation: Option<[i16; 3]>,
    pivot: Option<[i16; 3]>,
    order: Option<u8>,
    inherit: Option<u8>,
}

#[derive(Debug, Arbitrary)]
struct CurveSpec {
    model: u8,
    property: u8,
    axis: u8,
    keys: Vec<(i16, i16)>,
    flags: u8,
}

#[derive(Debug, Arbitrary)]
struct TakeSpec {
    start: i16,
    length: u16,
    curves: Vec<CurveSpec>,
}

#[derive(Debug, Arbitrary)]
struct FbxSpec {
    format: u8,
    up: u8,
    front: u8,
    unit: u8,
    time_mode: u8,
    models: Vec<ModelSpec>,
    takes: Vec<TakeSpec>,
    wild: Option<(u8, f64)>,
}

const KTIME: i64 = 46_186_158_000;

impl FbxSpec {
    fn document(&self) -> Vec<Node> {
        let wild = self.wild.map(|(k, v)| (usize::from(k), v));
        let num = |k: usize, v: f64| -> f64 {
            match wild {
                Some((w, x)) if w % 24 == k % 24 => x,
                _ => v,
            }
        };
        let vec3 = |k: usize, v: [f64; 3]| -> Vec<Prop> {
            v.iter().enumerate().map(|(i, &x)| Prop::D(num(k + i, x))).collect()
        };
        // Mostly Y up (front +Z) or Z up (front −Y); 1 in 8 any axes, valid or not.
        let (up, front, sign) = match self.up % 8 {
            0..=3 => (1, 2, 1),
            4..=6 => (2, 1, -1),
            _ => (
                i32::from(self.front % 4),
                i32::from(self.front / 4 % 4),
                if self.front & 64 == 0 { 1 } else { -1 },
            ),
        };
        let settings = vec![
            p("UpAxis", "int", vec![Prop::I(up)]),
            p("UpAxisSign", "int", vec![Prop::I(1)]),
            p("FrontAxis", "int", vec![Prop::I(front)]),
            p("FrontAxisSign", "int", vec![Prop::I(sign)]),
            p("CoordAxis", "int", vec![Prop::I(0)]),
            p("CoordAxisSign", "int", vec![Prop::I(1)]),
            p(
                "UnitScaleFactor",
                "double",
                vec![Prop::D(num(0, [1.0, 100.0, 0.1, 2.54, 0.0][usize::from(self.unit % 5)]))],
            ),
            p("TimeMode", "enum", vec![Prop::I(i32::from(self.time_mode % 19))]),
            p("CustomFrameRate", "double", vec![Prop::D(num(1, -1.0))]),
        ];
        let mut objects = Vec::new();
        let mut connections = Vec::new();
        let models: Vec<&ModelSpec> = self.models.iter().take(40).collect();
        let id = |i: usize| 1000 + i as i64;
        for (i, m) in models.iter().enumerate() {
            // The first model is a bone: most files have a skeleton to read.
            let kind = if i == 0 { "LimbNode" } else { KINDS[usize::from(m.kind) % KINDS.len()] };
            let name = NAMES[usize::from(m.name) % NAMES.len()];
            let f = |v: i16| f64::from(v) / 10.0;
            let mut props =
                vec![p("Lcl Translation", "Lcl Translation", vec3(2 + i, m.translation.map(f)))];
            if let Some(r) = m.rotation {
                props.push(p("Lcl Rotation", "Lcl Rotation", vec3(5 + i, r.map(f))));
            }
            if let Some(sc) = m.scaling {
                props.push(p(
                    "Lcl Scaling",
                    "Lcl Scaling",
                    vec3(8 + i, sc.map(|x| f64::from(x) / 16.0)),
                ));
            }
            if let Some(r) = m.pre_rotation {
                props.push(p("PreRotation", "Vector3D", vec3(11 + i, r.map(f))));
                props.push(p("RotationActive", "bool", vec![Prop::I(1)]));
            }
            if let Some(v) = m.pivot {
                props.push(p("RotationPivot", "Vector3D", vec3(14 + i, v.map(f))));
                props.push(p("ScalingPivot", "Vector3D", vec3(17 + i, v.map(f))));
            }
            if let Some(o) = m.order {
                props.push(p("RotationOrder", "enum", vec![Prop::I(i32::from(o % 8))]));
            }
            if let Some(h) = m.inherit {
                props.push(p("InheritType", "enum", vec![Prop::I(i32::from(h % 4))]));
            }
            let attr = 5000 + i as i64;
            let flags = if kind == "LimbNode" || kind == "Limb" || kind == "Root" {
                "Skeleton"
            } else {
                kind
            };
            objects.push(node(
                "NodeAttribute",
                vec![Prop::L(attr), Prop::Name(String::new(), "NodeAttribute"), s(kind)],
                vec![node("TypeFlags", vec![s(flags)], Vec::new())],
            ));
            objects.push(node(
                "Model",
                vec![Prop::L(id(i)), Prop::Name(name.to_owned(), "Model"), s(kind)],
                vec![
                    node("Version", vec![Prop::I(232)], Vec::new()),
                    node("Properties70", Vec::new(), props),
                ],
            ));
            let parent =
                if i == 0 || m.parent % 5 == 0 { 0 } else { id(usize::from(m.parent) % i) };
            connections.push(node("C", vec![s("OO"), Prop::L(attr), Prop::L(id(i))], Vec::new()));
            connections.push(node("C", vec![s("OO"), Prop::L(id(i)), Prop::L(parent)], Vec::new()));
        }
        let mut next = 10_000i64;
        for (t, take) in self.takes.iter().take(4).enumerate() {
            let (stack, layer) = (next, next + 1);
            next += 2;
            let start = i64::from(take.start) * KTIME / 30;
            let stop = start + i64::from(take.length % 600) * KTIME / 30;
            let range = vec![
                p("LocalStart", "KTime", vec![Prop::L(start)]),
                p(
                    "LocalStop",
                    "KTime",
                    vec![Prop::L(if take.length > 65000 { i64::MAX / 2 } else { stop })],
                ),
            ];
            objects.push(node(
                "AnimationStack",
                vec![Prop::L(stack), Prop::Name(format!("take{t}"), "AnimStack"), s("")],
                vec![node("Properties70", Vec::new(), range)],
            ));
            objects.push(node(
                "AnimationLayer",
                vec![Prop::L(layer), Prop::Name("Base".into(), "AnimLayer"), s("")],
                Vec::new(),
            ));
            connections.push(node("C", vec![s("OO"), Prop::L(layer), Prop::L(stack)], Vec::new()));
            for curve in take.curves.iter().take(24) {
                if models.is_empty() {
                    break;
                }
                let model = id(usize::from(curve.model) % models.len());
                let property = ["Lcl Translation", "Lcl Rotation", "Lcl Scaling"]
                    [usize::from(curve.property % 3)];
                let (curve_node, curve_id) = (next, next + 1);
                next += 2;
                let keys: Vec<(i16, i16)> = curve.keys.iter().take(40).copied().collect();
                let mut times: Vec<i64> =
                    keys.iter().map(|&(t, _)| i64::from(t) * KTIME / 60).collect();
                if curve.flags & 1 == 0 {
                    times.sort_unstable(); // mostly sorted, as files are
                }
                let values: Vec<f32> = keys.iter().map(|&(_, v)| f32::from(v) / 8.0).collect();
                // Constant, linear or cubic (FbxAnimCurveDef interpolation bits), now and then junk.
                let flag = [2, 4, 8, 0x0000_0108, i32::from(curve.flags) << 20]
                    [usize::from(curve.flags >> 1) % 5];
                let axis = ["d|X", "d|Y", "d|Z"][usize::from(curve.axis % 3)];
                objects.push(node(
                    "AnimationCurveNode",
                    vec![Prop::L(curve_node), Prop::Name("T".into(), "AnimCurveNode"), s("")],
                    Vec::new(),
                ));
                objects.push(node(
                    "AnimationCurve",
                    vec![Prop::L(curve_id), Prop::Name(String::new(), "AnimCurve"), s("")],
                    vec![
                        node("Default", vec![Prop::D(0.0)], Vec::new()),
                        node("KeyVer", vec![Prop::I(4009)], Vec::new()),
                        node("KeyTime", vec![Prop::ArrL(times)], Vec::new()),
                        node("KeyValueFloat", vec![Prop::ArrF(values)], Vec::new()),
                        node("KeyAttrFlags", vec![Prop::ArrI(vec![flag])], Vec::new()),
                        node(
                            "KeyAttrDataFloat",
                            vec![Prop::ArrF(vec![0.0, 0.0, 218_434_821.0, 0.0])],
                            Vec::new(),
                        ),
                        node(
                            "KeyAttrRefCount",
                            vec![Prop::ArrI(vec![keys.len() as i32])],
                            Vec::new(),
                        ),
                    ],
                ));
                connections.push(node(
                    "C",
                    vec![s("OO"), Prop::L(curve_node), Prop::L(layer)],
                    Vec::new(),
                ));
                connections.push(node(
                    "C",
                    vec![s("OP"), Prop::L(curve_node), Prop::L(model), s(property)],
                    Vec::new(),
                ));
                connections.push(node(
                    "C",
                    vec![s("OP"), Prop::L(curve_id), Prop::L(curve_node), s(axis)],
                    Vec::new(),
                ));
            }
        }
        let version = if self.format % 3 == 1 { 7500 } else { 7400 };
        vec![
            node(
                "FBXHeaderExtension",
                Vec::new(),
                vec![
                    node("FBXHeaderVersion", vec![Prop::I(1003)], Vec::new()),
                    node("FBXVersion", vec![Prop::I(version)], Vec::new()),
                    node("Creator", vec![s("fuzz")], Vec::new()),
                ],
            ),
            node(
                "GlobalSettings",
                Vec::new(),
                vec![
                    node("Version", vec![Prop::I(1000)], Vec::new()),
                    node("Properties70", Vec::new(), settings),
                ],
            ),
            node("Objects", Vec::new(), objects),
            node("Connections", Vec::new(), connections),
        ]
    }

    fn bytes(&self) -> Vec<u8> {
        let nodes = self.document();
        match self.format % 3 {
            2 => {
                let mut text = String::from("; FBX 7.4.0 project file\n");
                for n in &nodes {
                    write_ascii(&mut text, n, 0);
                }
                text.into_bytes()
            }
            kind => {
                let wide = kind == 1;
                let mut out = b"Kaydara FBX Binary  \x00\x1a\x00".to_vec();
                out.extend((if wide { 7500u32 } else { 7400 }).to_le_bytes());
                for n in &nodes {
                    write_binary(&mut out, n, wide);
                }
                out.extend(std::iter::repeat_n(0u8, if wide { 25 } else { 13 }));
                out
            }
        }
    }
}

/// At most this many frames × nodes of a take are sampled (a take of any declared length is
/// read; sampling a day of frames is work, not a bug, and is left to the error the library
/// gives past its limit).
const SAMPLED: usize = 2_000;

pub struct FbxTarget;

impl Target for FbxTarget {
    fn name(&self) -> &'static str {
        "fbx"
    }

    fn seeds(&self) -> Vec<Vec<u8>> {
        let mut seeds = crate::seeds::files("crates/fbx/tests/data", ".fbx");
        for k in 0..3u8 {
            let entropy: Vec<u8> =
                (0..4096u32).map(|i| (i * 31 + u32::from(k) * 97) as u8).collect();
            let mut u = Unstructured::new(&entropy);
            if let Ok(spec) = FbxSpec::arbitrary(&mut u) {
                seeds.push(spec.bytes());
            }
        }
        seeds
    }

    fn generate(&self, u: &mut Unstructured<'_>) -> Result<Vec<u8>> {
        let mut spec = FbxSpec::arbitrary(u)?;
        if spec.models.is_empty() {
            spec.models.push(ModelSpec::arbitrary(&mut Unstructured::new(&[3; 64]))?);
        }
        // Most takes move: a curve with keys (entropy left over decides the rest).
        for take in &mut spec.takes {
            if take.curves.is_empty() && take.length % 8 != 0 {
                take.curves.push(CurveSpec::arbitrary(&mut Unstructured::new(&[5; 64]))?);
            }
            for curve in &mut take.curves {
                if curve.keys.len() < 2 && curve.flags % 16 != 0 {
                    curve.keys.extend([(0, 0), (30, i16::from(curve.axis) * 8)]);
                }
            }
        }
        Ok(spec.bytes())
    }

    #[rustfmt::skip]
    fn dictionary(&self) -> &'static [&'static str] {
        &[
            "Kaydara FBX Binary  \u{0}", "; FBX 7.4.0 project file\n", "Objects:  {", "Model: ",
            "\"LimbNode\"", "\"Null\"", "Properties70:  {", "P: ", "\"Lcl Translation\"",
            "\"Lcl Rotation\"", "\"PreRotation\"", "\"RotationOrder\"", "\"InheritType\"",
            "AnimationStack: ", "AnimationCurve: ", "KeyTime: *", "KeyValueFloat: *", "a: ",
            "Connections:  {", "C: \"OO\",", "C: \"OP\",", "Takes:  {", "Key: ", "}", "\n",
            "\u{0}\u{1}Model", "46186158000", "nan", "1e300",
        ]
    }

    fn run(&self, input: &[u8]) -> std::result::Result<(), String> {
        let file = fbx::Fbx::from_bytes(input, "fuzz.fbx").map_err(|e| e.to_string())?;
        let info = file.info();
        let nodes = info.skeleton.len().max(1);
        let _ = file.select_take(Some("take0"));
        for (k, take) in info.takes.iter().enumerate().take(4) {
            if take.frames.saturating_mul(nodes) > SAMPLED {
                let _ = file.poses_at(k, &[take.start, take.stop, -1.0, 1e9]);
                continue;
            }
            let Ok(bvh) = file.bvh(k) else { continue };
            let mut written = bvh.clone();
            fbx::bvh_safe_names(&mut written);
            let mut out = Vec::new();
            bvh::write(&written, &mut out).map_err(|e| e.to_string())?;
            let _ = file.bvh_y_up(k);
            let _ = fk::straighten_limbs(&bvh);
            if let Ok(clip) = retarget::FbxClip::from_fbx(&file, Some(&k.to_string())) {
                let options = clip.fk_options(&fk::FkOptions::default());
                let _ = fk::human_motion(&clip.bvh, &options).map(|(_, r)| r.inferred());
                let _ = clip.summary();
            }
        }
        let small = info.takes.iter().all(|t| t.frames.saturating_mul(nodes) <= SAMPLED);
        if small {
            file.select_take(None).map_err(|e| e.to_string())?;
        }
        Ok(())
    }
}
