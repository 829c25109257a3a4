//! What a BVH viewer prints on load: frames, timing, joints as a tree, channel layout and a
//! guess of the length unit.

use std::fmt;

use crate::skeleton::{Axis, Bvh, Channel, JointKind, Skeleton};

/// The length unit a skeleton's numbers are probably in, guessed from its size.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Units {
    Metres,
    Centimetres,
    Millimetres,
    /// Fits no human size in m, cm or mm (CMU's own unit is about 0.0564 m).
    Unknown,
}

impl Units {
    /// Guess from the rest pose's extent (largest side of its bounding box, in file units):
    /// a human skeleton spans about 1–2 m, whether standing or in a T-pose.
    #[must_use]
    pub fn guess(extent: f64) -> Units {
        match extent {
            e if (0.5..=3.0).contains(&e) => Units::Metres,
            e if (50.0..=300.0).contains(&e) => Units::Centimetres,
            e if (500.0..=3000.0).contains(&e) => Units::Millimetres,
            _ => Units::Unknown,
        }
    }

    /// Short name: `m`, `cm`, `mm` or `unknown/custom`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Units::Metres => "m",
            Units::Centimetres => "cm",
            Units::Millimetres => "mm",
            Units::Unknown => "unknown/custom",
        }
    }
}

/// One line of the joint tree.
#[derive(Debug, Clone, PartialEq)]
pub struct SummaryJoint {
    pub name: String,
    pub kind: JointKind,
    /// 0 for roots.
    pub depth: usize,
    pub channels: Vec<Channel>,
}

/// A file's summary; `Display` prints it the way `retarget bvh info` shows it.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// The name the file is shown under (usually its file name).
    pub name: String,
    pub num_frames: usize,
    /// Seconds per frame.
    pub frame_time: f64,
    pub fps: f64,
    /// `num_frames × frame_time`, seconds.
    pub duration: f64,
    /// ROOT and JOINT nodes; End Sites are counted separately.
    pub num_joints: usize,
    pub num_end_sites: usize,
    pub num_channels: usize,
    /// Every node in file order, End Sites included.
    pub tree: Vec<SummaryJoint>,
    /// Largest side of the rest pose's bounding box (roots at the origin), file units.
    pub extent: f64,
    pub units: Units,
}

impl Summary {
    #[must_use]
    pub fn new(bvh: &Bvh, name: &str) -> Summary {
        let joints = &bvh.skeleton.joints;
        let num_end_sites = joints.iter().filter(|j| j.kind == JointKind::End).count();
        let mut depth: Vec<usize> = Vec::with_capacity(joints.len());
        let tree = joints
            .iter()
            .enumerate()
            .map(|(i, j)| {
                let d =
                    j.parent.filter(|p| p.0 < i).and_then(|p| depth.get(p.0)).map_or(0, |d| d + 1);
                depth.push(d);
                SummaryJoint {
                    name: j.name.clone(),
                    kind: j.kind,
                    depth: d,
                    channels: j.channels.clone(),
                }
            })
            .collect();
        let m = &bvh.motion;
        let extent = rest_extent(&bvh.skeleton);
        Summary {
            name: name.to_owned(),
            num_frames: m.num_frames,
            frame_time: m.frame_time,
            fps: m.fps(),
            duration: m.num_frames as f64 * m.frame_time,
            num_joints: joints.len() - num_end_sites,
            num_end_sites,
            num_channels: bvh.skeleton.num_channels(),
            tree,
            extent,
            units: Units::guess(extent),
        }
    }

    /// Distinct channel lists with how many joints use each, in order of first use.
    #[must_use]
    pub fn channel_layouts(&self) -> Vec<(Vec<Channel>, usize)> {
        let mut layouts: Vec<(Vec<Channel>, usize)> = Vec::new();
        for j in self.tree.iter().filter(|j| j.kind != JointKind::End) {
            match layouts.iter_mut().find(|(l, _)| *l == j.channels) {
                Some((_, n)) => *n += 1,
                None => layouts.push((j.channels.clone(), 1)),
            }
        }
        layouts
    }

    /// Distinct rotation orders (`"ZYX"`, `""` for none) with how many joints use each.
    #[must_use]
    pub fn rotation_orders(&self) -> Vec<(String, usize)> {
        let mut orders: Vec<(String, usize)> = Vec::new();
        for j in self.tree.iter().filter(|j| j.kind != JointKind::End) {
            let order = rotation_order(&j.channels);
            match orders.iter_mut().find(|(o, _)| *o == order) {
                Some((_, n)) => *n += 1,
                None => orders.push((order, 1)),
            }
        }
        orders
    }
}

/// The rotation axes of a channel list in file order, e.g. `"ZXY"`.
fn rotation_order(channels: &[Channel]) -> String {
    channels
        .iter()
        .filter_map(|c| match c {
            Channel::Rotation(a) => Some(axis_name(*a)),
            Channel::Position(_) | Channel::Scale(_) => None,
        })
        .collect()
}

fn axis_name(a: Axis) -> char {
    match a {
        Axis::X => 'X',
        Axis::Y => 'Y',
        Axis::Z => 'Z',
    }
}

/// Largest side of the bounding box of all joints in the rest pose (offsets only).
fn rest_extent(skeleton: &Skeleton) -> f64 {
    let mut pos: Vec<[f64; 3]> = Vec::with_capacity(skeleton.joints.len());
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for j in &skeleton.joints {
        let parent = j.parent.and_then(|p| pos.get(p.0)).copied();
        let here = parent
            .map_or([0.0; 3], |p| [p[0] + j.offset[0], p[1] + j.offset[1], p[2] + j.offset[2]]);
        pos.push(here);
        for ((lo, hi), v) in lo.iter_mut().zip(hi.iter_mut()).zip(here) {
            *lo = lo.min(v);
            *hi = hi.max(v);
        }
    }
    lo.iter().zip(&hi).map(|(lo, hi)| hi - lo).fold(0.0, f64::max)
}

impl fmt::Display for Summary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "file:            {}", self.name)?;
        writeln!(f, "frames:          {}", self.num_frames)?;
        writeln!(f, "frame time:      {} s ({:.2} fps)", self.frame_time, self.fps)?;
        writeln!(f, "duration:        {:.3} s", self.duration)?;
        let ends = self.num_end_sites;
        writeln!(
            f,
            "joints:          {} (ROOT + JOINT; {ends} End Sites not counted)",
            self.num_joints
        )?;
        writeln!(f, "channels:        {}", self.num_channels)?;
        for (layout, n) in self.channel_layouts() {
            let names: Vec<&str> = layout.iter().map(|c| c.name()).collect();
            writeln!(f, "  {n:>3} × {}: {}", layout.len(), names.join(" "))?;
        }
        let orders: Vec<String> = self
            .rotation_orders()
            .into_iter()
            .map(|(o, n)| format!("{} ({n})", if o.is_empty() { "none" } else { &o }))
            .collect();
        writeln!(f, "rotation orders: {}", orders.join(", "))?;
        writeln!(
            f,
            "units (guess):   {} (rest pose spans {:.4} units)",
            self.units.name(),
            self.extent
        )?;
        writeln!(f, "hierarchy:")?;
        for j in &self.tree {
            let indent = "  ".repeat(j.depth + 1);
            match j.kind {
                JointKind::End => writeln!(f, "{indent}{} (End Site)", j.name)?,
                _ => writeln!(f, "{indent}{} [{}]", j.name, layout_short(&j.channels))?,
            }
        }
        Ok(())
    }
}

/// `pos XYZ rot ZYX` (`scale XYZ`) for a joint's channels, in file order.
fn layout_short(channels: &[Channel]) -> String {
    let mut out = String::new();
    let mut last = None;
    for c in channels {
        let (word, axis) = match c {
            Channel::Position(a) => ("pos", a),
            Channel::Rotation(a) => ("rot", a),
            Channel::Scale(a) => ("scale", a),
        };
        if last != Some(word) {
            if !out.is_empty() {
                out.push(' ');
            }
            out.push_str(word);
            out.push(' ');
            last = Some(word);
        }
        out.push(axis_name(*axis));
    }
    out
}
