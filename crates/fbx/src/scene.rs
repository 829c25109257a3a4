//! Loading: ufbx's scene, the file's settings and takes ([`Info`]), and which nodes are the
//! skeleton.

use std::collections::BTreeMap;

use nalgebra::{Matrix3, Matrix4, UnitQuaternion};

use crate::conventions::{self, Axes, SignedAxis};
use crate::math;
use crate::Error;

/// What a node of the skeleton is in the file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum NodeKind {
    /// A `LimbNode` (or `Limb`) skeleton attribute: a bone.
    LimbNode,
    /// A `Root` skeleton attribute.
    Root,
    /// A `Null` (or a model without attribute): a locator, an armature object, a helper.
    Null,
    /// Another kind of model that carries bones below it (named by its ufbx element type).
    Other(String),
}

impl std::fmt::Display for NodeKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NodeKind::LimbNode => f.write_str("LimbNode"),
            NodeKind::Root => f.write_str("Root"),
            NodeKind::Null => f.write_str("Null"),
            NodeKind::Other(kind) => f.write_str(kind),
        }
    }
}

/// One node of the skeleton (parents before children).
#[derive(Debug, Clone, PartialEq)]
pub struct Node {
    /// The name as written (UTF-8; invalid bytes replaced), made unique with `.2`, `.3`, ...
    pub name: String,
    pub parent: Option<usize>,
    pub kind: NodeKind,
}

/// An animation stack (take) as declared.
#[derive(Debug, Clone, PartialEq)]
pub struct TakeInfo {
    pub name: String,
    /// The declared range (`LocalStart..LocalStop`), seconds.
    pub start: f64,
    pub stop: f64,
    /// The time span of the keys on the skeleton's curves (`None`: no keys).
    pub keys: Option<(f64, f64)>,
    /// Curves with at least one key on the skeleton's nodes.
    pub curves: usize,
    /// Frames at the file's rate inside the declared range ([`conventions::frame_range`]).
    pub frames: usize,
    /// The first frame's number on the rate grid (time = number / fps).
    pub first_frame: i64,
}

/// The file: exporter, settings, takes and skeleton.
#[derive(Debug, Clone, PartialEq)]
pub struct Info {
    /// FBX version (7400, 7500, 6100, ...).
    pub version: u32,
    pub ascii: bool,
    /// The header's `Creator`.
    pub creator: String,
    /// The original application (`vendor name version`; empty when the file does not say).
    pub application: String,
    pub axes: Axes,
    /// `UnitScaleFactor`: centimetres per file unit.
    pub unit_scale_factor: f64,
    pub metres_per_unit: f64,
    /// `TimeMode` as written (0 = default).
    pub time_mode: u32,
    /// Frames per second the takes are sampled at.
    pub fps: f64,
    /// Where the rate comes from when the file does not give one (`TimeMode` 0).
    pub fps_note: Option<String>,
    pub takes: Vec<TakeInfo>,
    pub skeleton: Vec<Node>,
}

impl Info {
    /// The world-from-file rotation of the file's axis system ([`Axes::world_from_file`]).
    #[must_use]
    pub fn world_from_file(&self) -> Option<Matrix3<f64>> {
        self.axes.world_from_file()
    }
}

/// Options ufbx reads with: FBX only (never OBJ by content), no geometry, no embedded
/// files, memory bounded by the input's size ([`memory_limit`]).
fn load_opts<'a>(input_len: usize) -> ufbx::LoadOpts<'a> {
    let limits = || ufbx::AllocatorOpts {
        memory_limit: memory_limit(input_len),
        allocation_limit: 0,
        ..ufbx::AllocatorOpts::default()
    };
    ufbx::LoadOpts {
        temp_allocator: limits(),
        result_allocator: limits(),
        ignore_geometry: true,
        ignore_embedded: true,
        file_format: ufbx::FileFormat::Fbx,
        no_format_from_extension: true,
        ..ufbx::LoadOpts::default()
    }
}

/// ufbx's memory limit per load (temporary and result each): 64 MiB plus 256 bytes per input
/// byte. Far above what a skeleton and its curves need (deflated key arrays rarely expand
/// more than 100×), and a crafted count in a small file cannot ask for gigabytes: the
/// fuzzer's 13 KB file that asked ufbx for one 1.3 GB buffer is refused as an error.
#[must_use]
pub(crate) fn memory_limit(input_len: usize) -> usize {
    (64usize << 20).saturating_add(input_len.saturating_mul(256))
}

/// The loaded scene and what was read from it.
pub(crate) struct Loaded {
    pub(crate) scene: ufbx::SceneRoot,
    pub(crate) info: Info,
    /// ufbx `typed_id`s of the skeleton's nodes, in [`Info::skeleton`] order.
    pub(crate) node_ids: Vec<usize>,
}

pub(crate) fn load(bytes: &[u8], file: &str) -> Result<Loaded, Error> {
    let scene = ufbx::load_memory(bytes, load_opts(bytes.len()))
        .map_err(|e| Error::Parse { file: file.to_owned(), message: ufbx_message(&e) })?;
    let node_ids = skeleton_nodes(&scene);
    if node_ids.is_empty() {
        return Err(Error::NoSkeleton { file: file.to_owned(), models: model_summary(&scene) });
    }
    let skeleton = describe(&scene, &node_ids);
    let settings = &scene.settings;
    let axes = Axes {
        right: axis(settings.axes.right),
        up: axis(settings.axes.up),
        front: axis(settings.axes.front),
    };
    let time_mode = settings.time_mode as u32;
    let (fps, fps_note) = frame_rate(time_mode, settings.frames_per_second);
    let metres_per_unit = conventions::metres_per_unit(settings.unit_meters);
    let ids: BTreeMap<u32, ()> = node_ids
        .iter()
        .filter_map(|&i| scene.nodes.get(i))
        .map(|n| (n.element.element_id, ()))
        .collect();
    let takes = scene.anim_stacks.iter().map(|stack| take_info(stack, &ids, fps)).collect();
    let meta = &scene.metadata;
    let app = &meta.original_application;
    let application = [app.vendor.as_ref(), app.name.as_ref(), app.version.as_ref()]
        .iter()
        .filter(|s: &&&str| !s.trim().is_empty())
        .map(|s| s.trim())
        .collect::<Vec<_>>()
        .join(" ");
    let info = Info {
        version: meta.version,
        ascii: meta.ascii,
        creator: meta.creator.to_string(),
        application,
        axes,
        unit_scale_factor: metres_per_unit * 100.0,
        metres_per_unit,
        time_mode,
        fps,
        fps_note,
        takes,
        skeleton,
    };
    Ok(Loaded { scene, info, node_ids })
}

/// ufbx's error: its description (the `info` text may carry file bytes: not shown).
pub(crate) fn ufbx_message(e: &ufbx::Error) -> String {
    let text = e.description.to_string();
    let text = text.trim().trim_end_matches('.');
    let mut chars = text.chars();
    match chars.next() {
        Some(c) => c.to_lowercase().chain(chars).collect(),
        None => format!("{:?}", e.type_).to_lowercase(),
    }
}

fn axis(a: ufbx::CoordinateAxis) -> SignedAxis {
    use ufbx::CoordinateAxis as C;
    let (index, positive) = match a {
        C::PositiveX => (0, true),
        C::NegativeX => (0, false),
        C::PositiveY => (1, true),
        C::NegativeY => (1, false),
        C::PositiveZ => (2, true),
        C::NegativeZ => (2, false),
        C::Unknown => (usize::MAX, true),
    };
    SignedAxis { index, positive }
}

/// The sampling rate: `TimeMode`'s, the custom rate, or [`conventions::DEFAULT_FPS`].
fn frame_rate(time_mode: u32, ufbx_fps: f64) -> (f64, Option<String>) {
    if let Some(fps) = conventions::time_mode_fps(time_mode) {
        return (fps, None);
    }
    if time_mode == conventions::TIME_MODE_CUSTOM && ufbx_fps.is_finite() && ufbx_fps > 0.0 {
        return (ufbx_fps, None);
    }
    let fps = conventions::DEFAULT_FPS;
    let why = if time_mode == 0 {
        "TimeMode 0 (default)".to_owned()
    } else {
        format!("TimeMode {time_mode} without a usable rate")
    };
    (fps, Some(format!("{why}: {fps} fps assumed (the FBX SDK's default time mode)")))
}

/// The declared range, the keys on the skeleton's curves and the frames of a stack.
fn take_info(stack: &ufbx::AnimStack, skeleton: &BTreeMap<u32, ()>, fps: f64) -> TakeInfo {
    let mut keys: Option<(f64, f64)> = None;
    let mut curves = 0;
    for layer in stack.layers.iter() {
        for prop in layer.anim_props.iter() {
            if !skeleton.contains_key(&prop.element.element_id) {
                continue;
            }
            for curve in prop.anim_value.curves.iter().flatten() {
                let (Some(first), Some(last)) = (curve.keyframes.first(), curve.keyframes.last())
                else {
                    continue;
                };
                curves += 1;
                let (lo, hi) = keys.unwrap_or((first.time, last.time));
                keys = Some((lo.min(first.time), hi.max(last.time)));
            }
        }
    }
    let (start, stop) = (stack.time_begin, stack.time_end);
    let range = conventions::frame_range(start, stop, fps);
    let (first_frame, frames) = match range {
        Some((a, b)) => (a, usize::try_from(b - a + 1).unwrap_or(0)),
        None => (0, 0),
    };
    TakeInfo {
        name: stack.element.name.to_string(),
        start,
        stop,
        keys,
        curves,
        frames,
        first_frame,
    }
}

/// A model that can be part of a skeleton: a bone, a Null, or a model without attribute.
fn is_skeletal(node: &ufbx::Node) -> bool {
    matches!(node.attrib_type, ufbx::ElementType::Bone | ufbx::ElementType::Empty)
        || node.attrib.is_none()
}

fn is_bone(node: &ufbx::Node) -> bool {
    node.attrib_type == ufbx::ElementType::Bone
}

/// The skeleton: under each top-level model that has bones below it (or is one), the
/// bones, Nulls and attribute-less models, plus any other model that has bones below it (a
/// mesh between two bones keeps the chain). Cameras, lights, meshes and MotionBuilder's
/// system objects are not part of it. A file without bones falls back to its hierarchies
/// of Nulls with at least [`MIN_NULL_TREE`] nodes (exports that skin nothing). Depth-first,
/// children in file order: parents come first.
fn skeleton_nodes(scene: &ufbx::Scene) -> Vec<usize> {
    let count = scene.nodes.len();
    // Nodes come parents first in ufbx's list? Not guaranteed: compute "has a bone below"
    // with an explicit post-order walk from the root.
    let mut has_bone = vec![false; count];
    let mut stack: Vec<(usize, bool)> = vec![(scene.root_node.element.typed_id as usize, false)];
    while let Some((id, done)) = stack.pop() {
        let Some(node) = scene.nodes.get(id) else { continue };
        if done {
            let below = node
                .children
                .iter()
                .any(|c| has_bone.get(c.element.typed_id as usize) == Some(&true));
            if let Some(slot) = has_bone.get_mut(id) {
                *slot = is_bone(node) || below;
            }
        } else {
            stack.push((id, true));
            stack.extend(node.children.iter().map(|c| (c.element.typed_id as usize, false)));
        }
    }
    let bone_tree = |n: &ufbx::Node| has_bone.get(n.element.typed_id as usize) == Some(&true);
    let keep_bones = |n: &ufbx::Node| is_skeletal(n) || bone_tree(n);
    let roots: Vec<&ufbx::Node> = scene.root_node.children.iter().map(|c| &**c).collect();
    let mut out = Vec::new();
    for root in roots.iter().filter(|r| bone_tree(r)) {
        collect(root, &keep_bones, &mut out);
    }
    if out.is_empty() {
        let null = |n: &ufbx::Node| is_skeletal(n);
        for root in roots.iter().filter(|r| null(r)) {
            let mut tree = Vec::new();
            collect(root, &null, &mut tree);
            if tree.len() >= MIN_NULL_TREE {
                out.extend(tree);
            }
        }
    }
    out
}

/// A hierarchy of Nulls this large (without any bone) is read as a skeleton.
const MIN_NULL_TREE: usize = 5;

/// Depth-first from `root`, entering only nodes `keep` accepts.
fn collect(root: &ufbx::Node, keep: &dyn Fn(&ufbx::Node) -> bool, out: &mut Vec<usize>) {
    if !keep(root) {
        return;
    }
    let mut stack = vec![root];
    while let Some(node) = stack.pop() {
        out.push(node.element.typed_id as usize);
        stack.extend(node.children.iter().rev().map(|c| &**c).filter(|c| keep(c)));
    }
}

/// Names (unique), parents and kinds of the skeleton nodes.
fn describe(scene: &ufbx::Scene, ids: &[usize]) -> Vec<Node> {
    let index: BTreeMap<usize, usize> = ids.iter().enumerate().map(|(i, &id)| (id, i)).collect();
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    ids.iter()
        .enumerate()
        .filter_map(|(i, &id)| {
            let node = scene.nodes.get(id)?;
            let parent =
                node.parent.as_ref().and_then(|p| index.get(&(p.element.typed_id as usize)));
            let raw = node.element.name.to_string();
            let base = if raw.trim().is_empty() { format!("node{i}") } else { raw };
            let count = seen.entry(base.clone()).or_insert(0);
            *count += 1;
            let name = if *count == 1 { base } else { format!("{base}.{count}") };
            Some(Node { name, parent: parent.copied(), kind: kind(node) })
        })
        .collect()
}

fn kind(node: &ufbx::Node) -> NodeKind {
    match (&node.bone, node.attrib_type) {
        (Some(bone), _) if bone.is_root => NodeKind::Root,
        (Some(_), _) => NodeKind::LimbNode,
        (None, ufbx::ElementType::Empty) => NodeKind::Null,
        (None, _) if node.attrib.is_none() => NodeKind::Null,
        (None, other) => NodeKind::Other(format!("{other:?}")),
    }
}

/// "3 Mesh, 1 Camera" for the no-skeleton error.
fn model_summary(scene: &ufbx::Scene) -> String {
    let mut counts: BTreeMap<String, usize> = BTreeMap::new();
    for node in scene.nodes.iter().filter(|n| !n.is_root) {
        *counts.entry(format!("{:?}", node.attrib_type)).or_insert(0) += 1;
    }
    if counts.is_empty() {
        return "none".to_owned();
    }
    counts.iter().map(|(k, n)| format!("{n} {k}")).collect::<Vec<_>>().join(", ")
}

/// A ufbx affine matrix as a 4×4 (last row 0 0 0 1).
pub(crate) fn matrix(m: &ufbx::Matrix) -> Matrix4<f64> {
    Matrix4::new(
        m.m00, m.m01, m.m02, m.m03, m.m10, m.m11, m.m12, m.m13, m.m20, m.m21, m.m22, m.m23, 0.0,
        0.0, 0.0, 1.0,
    )
}

/// The rest rotation of each skeleton node, which the BVH's zero pose reproduces: its world
/// rotation in the file's bind pose (the pose a skinned character was bound in, usually a
/// T- or A-pose), else the node's static transform (the properties without animation, which
/// exporters often write at the current frame). Returns how many came from a bind pose.
pub(crate) fn rest_rotations(
    scene: &ufbx::Scene,
    ids: &[usize],
) -> (Vec<UnitQuaternion<f64>>, usize) {
    let mut bind: BTreeMap<usize, Matrix4<f64>> = BTreeMap::new();
    for pose in scene.poses.iter().filter(|p| p.is_bind_pose) {
        for bone in pose.bone_poses.iter() {
            bind.entry(bone.bone_node.element.typed_id as usize)
                .or_insert_with(|| matrix(&bone.bone_to_world));
        }
    }
    let mut from_bind = 0;
    let rotations = ids
        .iter()
        .map(|&id| {
            let m = match (bind.get(&id), scene.nodes.get(id)) {
                (Some(m), _) => {
                    from_bind += 1;
                    *m
                }
                (None, Some(n)) => matrix(&n.node_to_world),
                (None, None) => Matrix4::identity(),
            };
            math::rotation(&m)
        })
        .collect();
    (rotations, from_bind)
}

/// Whether every skeleton node inherits normally (no `InheritType` Rrs or RrSs, no ufbx
/// helper nodes) and every skeleton root hangs from the scene root: then a node's world
/// matrix is its parent's times its local one, as ufbx composes it.
pub(crate) fn normal_inheritance(scene: &ufbx::Scene, ids: &[usize]) -> bool {
    ids.iter().all(|&id| {
        scene.nodes.get(id).is_some_and(|n| {
            n.inherit_mode == ufbx::InheritMode::Normal
                && n.scale_helper.is_none()
                && !n.is_scale_helper
                && !n.is_geometry_transform_helper
        })
    })
}
