//! Writers: BVH text (round-trips bit-identically through [`crate::parse()`]) and a streamed
//! JSON dump. Both walk the tree with an explicit stack and write motion row by row from
//! the parsed matrix, so memory stays at the size of [`Motion::values`].

use std::io::{self, BufWriter, Write};

use crate::float::is_space;
use crate::skeleton::{Bvh, Joint, JointKind, Motion};

/// Write `bvh` as BVH text. Numbers use the shortest representation that parses back to the
/// same `f64` (ryu), so `parse(write(b)) == b` for any `b` that [`crate::parse()`] returned.
///
/// End Sites are written as `End Site` (their names are not stored in BVH and come back as
/// `<Parent>_End`). A data model that cannot be written faithfully (non-finite numbers,
/// inconsistent channel columns, a motion matrix of the wrong size, parents after children,
/// names with line breaks) is an [`io::ErrorKind::InvalidInput`] error; nothing is written then.
pub fn write(bvh: &Bvh, out: impl Write) -> io::Result<()> {
    let tree = Tree::new(bvh)?;
    check_numbers(bvh)?;
    let mut w = BufWriter::with_capacity(1 << 16, out);
    w.write_all(b"HIERARCHY\n")?;
    let mut num = ryu::Buffer::new();
    for step in tree.walk() {
        // The walk visits only joints `Tree::new` checked.
        let Some(joint) = bvh.skeleton.joints.get(step.joint()) else { continue };
        let indent = "\t".repeat(tree.depth.get(step.joint()).copied().unwrap_or(0));
        match step {
            Step::Enter(_) => write_joint_head(&mut w, joint, &indent, &mut num)?,
            Step::Exit(_) => writeln!(w, "{indent}}}")?,
        }
    }
    let motion = &bvh.motion;
    let frame_time = short(&mut num, motion.frame_time);
    writeln!(w, "MOTION\nFrames: {}\nFrame Time: {frame_time}", motion.num_frames)?;
    let columns = tree.columns(bvh);
    for frame in 0..motion.num_frames {
        let row = motion.frame(frame);
        for (i, &c) in columns.iter().enumerate() {
            if i > 0 {
                w.write_all(b" ")?;
            }
            w.write_all(short(&mut num, row.get(c).copied().unwrap_or(0.0)).as_bytes())?;
        }
        w.write_all(b"\n")?;
    }
    w.flush()
}

/// ryu's shortest round-trip form without a trailing `.0` (`90`, not `90.0`): the same
/// number, as exporters write it. `v` must be finite (checked before writing).
fn short(num: &mut ryu::Buffer, v: f64) -> &str {
    let text = num.format_finite(v);
    text.strip_suffix(".0").unwrap_or(text)
}

fn write_joint_head(
    w: &mut impl Write,
    joint: &Joint,
    indent: &str,
    num: &mut ryu::Buffer,
) -> io::Result<()> {
    match joint.kind {
        JointKind::Root => writeln!(w, "{indent}ROOT {}\n{indent}{{", joint.name)?,
        JointKind::Joint => writeln!(w, "{indent}JOINT {}\n{indent}{{", joint.name)?,
        JointKind::End => writeln!(w, "{indent}End Site\n{indent}{{")?,
    }
    write!(w, "{indent}\tOFFSET")?;
    for v in joint.offset {
        write!(w, " {}", short(num, v))?;
    }
    writeln!(w)?;
    if joint.kind != JointKind::End {
        write!(w, "{indent}\tCHANNELS {}", joint.channels.len())?;
        for c in &joint.channels {
            write!(w, " {}", c.name())?;
        }
        writeln!(w)?;
    }
    Ok(())
}

/// Write `bvh` as JSON, streamed joint by joint:
///
/// ```text
/// {"frames": N, "frame_time": t, "fps": f, "channels": C,
///  "joints": [ {"type": "ROOT", "name": …, "offset": [x, y, z], "channels": ["Xposition", …],
///               "motion": [[row of this joint's channels, frame 0], …],
///               "children": [ {"type": "JOINT" | "End", …}, … ]} ]}
/// ```
///
/// `type` is `ROOT`, `JOINT` or `End`; End Sites have no channels and an empty `motion`.
/// Non-finite numbers (which [`crate::parse()`] never returns) are written as `null`.
pub fn write_json(bvh: &Bvh, out: impl Write) -> io::Result<()> {
    let tree = Tree::new(bvh)?;
    let mut w = BufWriter::with_capacity(1 << 16, out);
    let m = &bvh.motion;
    let mut num = ryu::Buffer::new();
    write!(w, "{{\"frames\":{},\"frame_time\":", m.num_frames)?;
    json_number(&mut w, &mut num, m.frame_time)?;
    w.write_all(b",\"fps\":")?;
    json_number(&mut w, &mut num, m.fps())?;
    write!(w, ",\"channels\":{},\"joints\":[", m.num_channels)?;
    for step in tree.walk() {
        let id = step.joint();
        match step {
            Step::Enter(_) => {
                if !tree.first_sibling.get(id).copied().unwrap_or(true) {
                    w.write_all(b",")?;
                }
                if let Some(joint) = bvh.skeleton.joints.get(id) {
                    json_joint(&mut w, &mut num, joint, m)?;
                }
            }
            Step::Exit(_) => w.write_all(b"]}")?,
        }
    }
    w.write_all(b"]}\n")?;
    w.flush()
}

/// Everything of one joint up to and including `"children":[`.
fn json_joint(
    w: &mut impl Write,
    num: &mut ryu::Buffer,
    joint: &Joint,
    m: &Motion,
) -> io::Result<()> {
    let kind = match joint.kind {
        JointKind::Root => "ROOT",
        JointKind::Joint => "JOINT",
        JointKind::End => "End",
    };
    write!(w, "\n{{\"type\":\"{kind}\",\"name\":")?;
    json_string(w, &joint.name)?;
    w.write_all(b",\"offset\":")?;
    json_array(w, num, &joint.offset)?;
    w.write_all(b",\"channels\":[")?;
    for (i, c) in joint.channels.iter().enumerate() {
        let sep = if i > 0 { "," } else { "" };
        write!(w, "{sep}\"{}\"", c.name())?;
    }
    w.write_all(b"],\"motion\":[")?;
    let columns = joint.first_channel..joint.first_channel + joint.channels.len();
    if !columns.is_empty() {
        for frame in 0..m.num_frames {
            w.write_all(if frame > 0 { b",\n" } else { b"\n" })?;
            json_array(w, num, m.frame(frame).get(columns.clone()).unwrap_or_default())?;
        }
    }
    w.write_all(b"],\"children\":[")
}

fn json_array(w: &mut impl Write, num: &mut ryu::Buffer, values: &[f64]) -> io::Result<()> {
    w.write_all(b"[")?;
    for (i, &v) in values.iter().enumerate() {
        if i > 0 {
            w.write_all(b",")?;
        }
        json_number(w, num, v)?;
    }
    w.write_all(b"]")
}

fn json_number(w: &mut impl Write, num: &mut ryu::Buffer, v: f64) -> io::Result<()> {
    if v.is_finite() {
        w.write_all(num.format_finite(v).as_bytes())
    } else {
        w.write_all(b"null")
    }
}

fn json_string(w: &mut impl Write, s: &str) -> io::Result<()> {
    w.write_all(b"\"")?;
    for c in s.chars() {
        match c {
            '"' => w.write_all(b"\\\"")?,
            '\\' => w.write_all(b"\\\\")?,
            '\n' => w.write_all(b"\\n")?,
            '\r' => w.write_all(b"\\r")?,
            '\t' => w.write_all(b"\\t")?,
            c if (c as u32) < 0x20 => write!(w, "\\u{:04x}", c as u32)?,
            c => write!(w, "{c}")?,
        }
    }
    w.write_all(b"\"")
}

fn invalid(message: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, message)
}

fn check_numbers(bvh: &Bvh) -> io::Result<()> {
    let m = &bvh.motion;
    if !(m.frame_time.is_finite() && m.frame_time > 0.0) {
        return Err(invalid(format!("frame time {} is not a positive number", m.frame_time)));
    }
    if m.num_channels == 0 && m.num_frames > 0 {
        return Err(invalid("frames without channels cannot be written as BVH".to_owned()));
    }
    for joint in &bvh.skeleton.joints {
        if joint.offset.iter().any(|v| !v.is_finite()) {
            return Err(invalid(format!("joint `{}` has a non-finite offset", joint.name)));
        }
        let name_ok = name_survives_parsing(&joint.name);
        if joint.kind != JointKind::End && !name_ok {
            return Err(invalid(format!("joint name {:?} cannot be written as BVH", joint.name)));
        }
    }
    match m.values.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(invalid(format!("motion value {i} is not finite"))),
        None => Ok(()),
    }
}

/// Whether the parser reads `name` back unchanged from `JOINT name`: the rest of a line,
/// trimmed, where a final ` {` would be taken for the joint's brace.
fn name_survives_parsing(name: &str) -> bool {
    let bytes = name.as_bytes();
    let trimmed =
        bytes.first().is_some_and(|&b| !is_space(b)) && bytes.last().is_some_and(|&b| !is_space(b));
    let brace = match bytes.split_last() {
        Some((b'{', head)) => head.last().is_none_or(|&b| is_space(b)),
        _ => false,
    };
    trimmed && !brace && !bytes.contains(&b'\n')
}

/// One step of a depth-first walk: open a joint, or close it after its children.
#[derive(Clone, Copy)]
enum Step {
    Enter(usize),
    Exit(usize),
}

impl Step {
    fn joint(self) -> usize {
        match self {
            Step::Enter(j) | Step::Exit(j) => j,
        }
    }
}

/// The skeleton's tree, checked: parents before children, kinds consistent, columns a
/// partition of the motion row, motion matrix of the right size.
struct Tree {
    children: Vec<Vec<usize>>,
    roots: Vec<usize>,
    depth: Vec<usize>,
    first_sibling: Vec<bool>,
}

impl Tree {
    fn new(bvh: &Bvh) -> io::Result<Tree> {
        let joints = &bvh.skeleton.joints;
        let n = joints.len();
        let mut tree = Tree {
            children: vec![Vec::new(); n],
            roots: Vec::new(),
            depth: vec![0; n],
            first_sibling: vec![false; n],
        };
        for (i, joint) in joints.iter().enumerate() {
            let parent =
                joint.parent.filter(|p| p.0 < i).and_then(|p| Some((p.0, joints.get(p.0)?)));
            let siblings = match (parent, joint.kind) {
                (None, JointKind::Root) if joint.parent.is_none() => &mut tree.roots,
                (Some((p, parent)), JointKind::Joint | JointKind::End)
                    if parent.kind != JointKind::End =>
                {
                    let depth = tree.depth.get(p).map_or(0, |d| d + 1);
                    if let Some(slot) = tree.depth.get_mut(i) {
                        *slot = depth;
                    }
                    match tree.children.get_mut(p) {
                        Some(children) => children,
                        None => return Err(invalid(format!("joint {i}: bad parent"))),
                    }
                }
                _ => {
                    return Err(invalid(format!(
                        "joint {i} (`{}`): bad parent or kind",
                        joint.name
                    )))
                }
            };
            let first = siblings.is_empty();
            if let Some(slot) = tree.first_sibling.get_mut(i) {
                *slot = first;
            }
            siblings.push(i);
            if joint.kind == JointKind::End && !joint.channels.is_empty() {
                return Err(invalid(format!("End Site `{}` has channels", joint.name)));
            }
        }
        check_columns(bvh)?;
        Ok(tree)
    }

    /// Depth-first, children in index order: file order for a parsed skeleton.
    fn walk(&self) -> impl Iterator<Item = Step> + '_ {
        let mut stack: Vec<Step> = self.roots.iter().rev().map(|&r| Step::Enter(r)).collect();
        std::iter::from_fn(move || {
            let step = stack.pop()?;
            if let Step::Enter(j) = step {
                stack.push(Step::Exit(j));
                let children = self.children.get(j).map_or(&[][..], Vec::as_slice);
                stack.extend(children.iter().rev().map(|&c| Step::Enter(c)));
            }
            Some(step)
        })
    }

    /// Motion columns in the order the walk writes the channels.
    fn columns(&self, bvh: &Bvh) -> Vec<usize> {
        let joints = &bvh.skeleton.joints;
        self.walk()
            .filter_map(|s| match s {
                Step::Enter(j) => {
                    joints.get(j).map(|j| j.first_channel..j.first_channel + j.channels.len())
                }
                Step::Exit(_) => None,
            })
            .flatten()
            .collect()
    }
}

fn check_columns(bvh: &Bvh) -> io::Result<()> {
    let m = &bvh.motion;
    let width = bvh.skeleton.num_channels();
    if m.num_channels != width || m.num_frames.checked_mul(width) != Some(m.values.len()) {
        return Err(invalid(format!(
            "motion is {} values of {} frames × {} channels, the skeleton has {width} channels",
            m.values.len(),
            m.num_frames,
            m.num_channels
        )));
    }
    let mut used = vec![false; width];
    for joint in &bvh.skeleton.joints {
        for c in joint.first_channel..joint.first_channel.saturating_add(joint.channels.len()) {
            match used.get_mut(c) {
                Some(u) if !*u => *u = true,
                _ => {
                    return Err(invalid(format!(
                        "joint `{}`: channel columns overlap or exceed the row",
                        joint.name
                    )))
                }
            }
        }
    }
    Ok(())
}
