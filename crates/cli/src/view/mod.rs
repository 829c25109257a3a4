//! The self-contained HTML player of `retarget view`: plain data in ([`Scene`]), one HTML file
//! out (WebGL renderer, controls and SVG plots inline, no network).
//!
//! Large arrays travel as little-endian `float32` in base64 inside a JSON block; the robot is
//! sent as its kinematic tree plus `qpos` per frame and posed in the page (MuJoCo's
//! `mj_kinematics` loop), which keeps a 7,000-frame clip to a few MB. Optional reference poses
//! ([`RobotFigure::check`]) let the page verify its forward kinematics against ours on load.

mod base64;
pub mod sources;

use serde::{Serialize, Serializer};

const TEMPLATE: &str = include_str!("page.html");
const STYLE: &str = include_str!("style.css");
const SCRIPT: &str = include_str!("player.js");

/// Everything one page shows. Every per-frame array has `num_frames` rows.
#[derive(Debug, Clone, Serialize)]
pub struct Scene {
    /// Shown in the overlay and the page title (usually the input file name).
    pub title: String,
    pub fps: f64,
    pub num_frames: usize,
    /// Extra overlay lines (label, value), e.g. ("joints", "22").
    pub info: Vec<(String, String)>,
    /// A joint-name tree to show beside the view (BVH pages), one name per line, indented.
    pub tree: Option<String>,
    /// Figures drawn as bones between points (human skeletons, tracked targets).
    pub skeletons: Vec<PointFigure>,
    pub robot: Option<RobotFigure>,
    /// Ready-made plots (in addition to those the page derives from the figures).
    pub plots: Vec<Plot>,
}

/// How a point figure is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PointStyle {
    /// Bones to the parent and a sphere per joint.
    Skeleton,
    /// Spheres and, when orientations are given, small axes (IK targets).
    Targets,
}

/// A set of named points moving over time, optionally oriented and linked to parents.
/// Serialised compactly: point 0 as float32, the others as int16 offsets from it.
#[derive(Debug, Clone, Serialize)]
#[serde(into = "PointFigureOut")]
pub struct PointFigure {
    /// Label of the figure's toggle in the page.
    pub label: String,
    pub style: PointStyle,
    /// RGB in 0..1.
    pub color: [f32; 3],
    pub names: Vec<String>,
    /// Parent point of each point (bones), `None` for roots.
    pub parents: Vec<Option<usize>>,
    /// `[frame][point][xyz]`, metres, world frame (Z up).
    pub positions: Vec<f32>,
    /// `[frame][point][wxyz]`, world orientations; empty when unknown.
    pub orientations: Vec<f32>,
    /// Indices of the points used for foot plots, with a label ("left", "right").
    pub feet: Vec<(String, usize)>,
}

/// [`PointFigure`] as the page reads it. Positions: `root` is point 0 per frame (float32);
/// `offsets` is every point minus point 0 in units of `step` metres (int16), with `step`
/// the smallest that fits the figure's largest offset (0.1 mm for a person).
#[derive(Serialize)]
struct PointFigureOut {
    label: String,
    style: PointStyle,
    color: [f32; 3],
    names: Vec<String>,
    parents: Vec<Option<usize>>,
    #[serde(serialize_with = "f32_base64")]
    root: Vec<f32>,
    step: f64,
    #[serde(serialize_with = "i16_base64")]
    offsets: Vec<i16>,
    #[serde(serialize_with = "unit_i16_base64")]
    orientations: Vec<f32>,
    feet: Vec<(String, usize)>,
}

impl From<PointFigure> for PointFigureOut {
    fn from(f: PointFigure) -> Self {
        let n = f.names.len().max(1);
        let frames: Vec<&[f32]> = f.positions.chunks(n * 3).collect();
        let root: Vec<f32> = frames.iter().flat_map(|fr| fr[..3].to_vec()).collect();
        let offset = |fr: &[f32], k: usize| f64::from(fr[k]) - f64::from(fr[k % 3]);
        let widest = frames
            .iter()
            .flat_map(|fr| (0..fr.len()).map(|k| offset(fr, k).abs()))
            .fold(0.0, f64::max);
        let step = (widest / 32000.0).max(1e-4);
        #[allow(clippy::cast_possible_truncation)] // |offset / step| <= 32000 by the choice of step
        let offsets = frames
            .iter()
            .flat_map(|fr| (0..fr.len()).map(move |k| (offset(fr, k) / step).round() as i16))
            .collect();
        PointFigureOut {
            label: f.label,
            style: f.style,
            color: f.color,
            names: f.names,
            parents: f.parents,
            root,
            step,
            offsets,
            orientations: f.orientations,
            feet: f.feet,
        }
    }
}

fn i16_base64<S: Serializer>(values: &[i16], s: S) -> Result<S::Ok, S::Error> {
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    s.serialize_str(&base64::encode(&bytes))
}

/// A robot as its kinematic tree (MuJoCo's body/joint/geom arrays without the world body)
/// and its configurations over time.
#[derive(Debug, Clone, Serialize)]
pub struct RobotFigure {
    pub label: String,
    pub bodies: Vec<RobotBody>,
    pub joints: Vec<RobotJoint>,
    pub geoms: Vec<RobotGeom>,
    pub nq: usize,
    /// MuJoCo `qpos0`: hinge and slide joints move by `qpos - qpos0`.
    pub qpos0: Vec<f64>,
    /// `[frame][nq]`.
    #[serde(serialize_with = "f32_base64")]
    pub qpos: Vec<f32>,
    /// Bodies used for foot plots, with a label.
    pub feet: Vec<(String, usize)>,
    /// Reference world body positions at a few frames (frame, `[body][xyz]`).
    pub check: Vec<(usize, Vec<[f64; 3]>)>,
}

#[derive(Debug, Clone, Serialize)]
pub struct RobotBody {
    pub name: String,
    /// Index into [`RobotFigure::bodies`], `None` for a child of the world.
    pub parent: Option<usize>,
    /// Pose in the parent's frame (quaternion w first).
    pub pos: [f64; 3],
    pub quat: [f64; 4],
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum JointKind {
    Free,
    Ball,
    Slide,
    Hinge,
}

#[derive(Debug, Clone, Serialize)]
pub struct RobotJoint {
    pub name: String,
    pub kind: JointKind,
    pub body: usize,
    pub qpos_adr: usize,
    pub axis: [f64; 3],
    pub pos: [f64; 3],
    pub range: Option<[f64; 2]>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Shape {
    Sphere,
    Capsule,
    Cylinder,
    Box,
    Ellipsoid,
}

/// A primitive geom in its body's frame, with MuJoCo's `size` convention (radius,
/// half-length, half-extents).
#[derive(Debug, Clone, Serialize)]
pub struct RobotGeom {
    pub body: usize,
    pub shape: Shape,
    pub size: [f64; 3],
    pub pos: [f64; 3],
    pub quat: [f64; 4],
}

/// A time series plot: lines over frames, optional limit lines and shaded frame ranges.
#[derive(Debug, Clone, Serialize)]
pub struct Plot {
    pub title: String,
    pub unit: String,
    pub series: Vec<Series>,
    /// Horizontal limit lines (e.g. a joint range).
    pub limits: Option<[f64; 2]>,
    /// Frame ranges `[start, end)` to shade (e.g. contact phases).
    pub shaded: Vec<[usize; 2]>,
}

#[derive(Debug, Clone, Serialize)]
pub struct Series {
    pub name: String,
    #[serde(serialize_with = "f32_base64")]
    pub values: Vec<f32>,
}

fn f32_base64<S: Serializer>(values: &[f32], s: S) -> Result<S::Ok, S::Error> {
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    s.serialize_str(&base64::encode(&bytes))
}

/// Values in [-1, 1] (quaternion components) as `round(v * 32767)` in int16: half the size
/// of float32, 3e-5 resolution, invisible at any zoom.
fn unit_i16_base64<S: Serializer>(values: &[f32], s: S) -> Result<S::Ok, S::Error> {
    #[allow(clippy::cast_possible_truncation)] // clamped to the int16 range first
    let quantize = |v: f32| (v.clamp(-1.0, 1.0) * 32767.0).round() as i16;
    let bytes: Vec<u8> = values.iter().flat_map(|&v| quantize(v).to_le_bytes()).collect();
    s.serialize_str(&base64::encode(&bytes))
}

impl Scene {
    /// Check that every per-frame array has `num_frames` rows.
    pub fn validate(&self) -> anyhow::Result<()> {
        let n = self.num_frames;
        for f in &self.skeletons {
            let k = f.names.len();
            anyhow::ensure!(
                f.parents.len() == k,
                "{}: {} parents for {k} points",
                f.label,
                f.parents.len()
            );
            anyhow::ensure!(
                f.positions.len() == n * k * 3,
                "{}: positions are not frames × points × 3",
                f.label
            );
            anyhow::ensure!(
                f.orientations.is_empty() || f.orientations.len() == n * k * 4,
                "{}: orientations are not frames × points × 4",
                f.label
            );
            anyhow::ensure!(
                f.parents.iter().flatten().all(|&p| p < k),
                "{}: parent out of range",
                f.label
            );
        }
        if let Some(r) = &self.robot {
            anyhow::ensure!(
                r.qpos.len() == n * r.nq && r.qpos0.len() == r.nq,
                "{}: qpos is not frames × nq",
                r.label
            );
            anyhow::ensure!(
                r.joints.iter().all(|j| j.body < r.bodies.len() && j.qpos_adr < r.nq),
                "{}: joint out of range",
                r.label
            );
            anyhow::ensure!(
                r.geoms.iter().all(|g| g.body < r.bodies.len()),
                "{}: geom out of range",
                r.label
            );
        }
        for p in &self.plots {
            anyhow::ensure!(
                p.series.iter().all(|s| s.values.len() == n),
                "plot {}: a series is not one value per frame",
                p.title
            );
        }
        Ok(())
    }

    /// The whole page as one HTML string.
    pub fn to_html(&self) -> anyhow::Result<String> {
        self.validate()?;
        // `</` inside a <script> block would end it early; JSON allows escaping `/`.
        let json = serde_json::to_string(self)?.replace("</", "<\\/");
        let title = html_escape(&self.title);
        fill(TEMPLATE, &[("TITLE", &title), ("STYLE", STYLE), ("SCRIPT", SCRIPT), ("SCENE", &json)])
    }
}

/// Replace each `{{KEY}}` of `template` in one pass, so inserted text is never rescanned.
fn fill(template: &str, values: &[(&str, &str)]) -> anyhow::Result<String> {
    let mut out =
        String::with_capacity(template.len() + values.iter().map(|v| v.1.len()).sum::<usize>());
    let mut rest = template;
    while let Some(start) = rest.find("{{") {
        let end = rest[start..].find("}}").map(|e| start + e);
        let end = end.ok_or_else(|| anyhow::anyhow!("page template: unclosed {{{{"))?;
        let key = &rest[start + 2..end];
        let value = values.iter().find(|v| v.0 == key).map(|v| v.1);
        out.push_str(&rest[..start]);
        out.push_str(value.ok_or_else(|| anyhow::anyhow!("page template: unknown key {key}"))?);
        rest = &rest[end + 2..];
    }
    out.push_str(rest);
    Ok(out)
}

fn html_escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// The left and right foot among `names`: per side, the first name matching the most specific
/// pattern (`ankle_roll`, then `foot`, `ankle`, `toe`), case-insensitive.
#[must_use]
pub fn find_feet(names: &[String]) -> Vec<(String, usize)> {
    let lower: Vec<String> = names.iter().map(|n| n.to_ascii_lowercase()).collect();
    let mut feet = Vec::new();
    for (side, prefixes) in [("left", ["left", "l_"]), ("right", ["right", "r_"])] {
        let on_side =
            |n: &str| prefixes.iter().any(|p| n.starts_with(p) || n.contains(&format!("_{p}")));
        let found = ["ankle_roll", "foot", "ankle", "toe"]
            .iter()
            .find_map(|pat| lower.iter().position(|n| on_side(n) && n.contains(pat)));
        if let Some(i) = found {
            feet.push((side.to_owned(), i));
        }
    }
    feet
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(list: &[&str]) -> Vec<String> {
        list.iter().map(|s| (*s).to_owned()).collect()
    }

    #[test]
    fn feet_of_a_bvh_and_a_robot() {
        let bvh = names(&[
            "Hips",
            "LeftUpLeg",
            "LeftLeg",
            "LeftFoot",
            "LeftToe",
            "RightUpLeg",
            "RightFoot",
        ]);
        assert_eq!(find_feet(&bvh), vec![("left".to_owned(), 3), ("right".to_owned(), 6)]);
        let g1 = names(&[
            "pelvis",
            "left_ankle_pitch_link",
            "left_ankle_roll_link",
            "right_ankle_roll_link",
        ]);
        assert_eq!(find_feet(&g1), vec![("left".to_owned(), 2), ("right".to_owned(), 3)]);
        assert!(find_feet(&names(&["torso"])).is_empty());
    }

    #[test]
    fn page_escapes_script_end_in_names() {
        let scene = Scene {
            title: "a</script><b>.bvh".into(),
            fps: 30.0,
            num_frames: 1,
            info: vec![],
            tree: None,
            skeletons: vec![PointFigure {
                label: "x</script>".into(),
                style: PointStyle::Skeleton,
                color: [1.0, 0.5, 0.0],
                names: names(&["a"]),
                parents: vec![None],
                positions: vec![0.0, 0.0, 1.0],
                orientations: vec![],
                feet: vec![],
            }],
            robot: None,
            plots: vec![],
        };
        let html = scene.to_html().unwrap();
        assert_eq!(html.matches("</script>").count(), html.matches("<script").count());
        assert!(html.contains("a&lt;/script&gt;&lt;b&gt;.bvh"));
    }

    #[test]
    fn point_offsets_round_trip_within_half_a_step() {
        let positions: Vec<f32> =
            (0..2 * 3 * 3).map(|i| (i as f32 * 0.37).sin() * 1.9 + 5.0).collect();
        let figure = PointFigure {
            label: "p".into(),
            style: PointStyle::Skeleton,
            color: [1.0; 3],
            names: names(&["a", "b", "c"]),
            parents: vec![None, Some(0), Some(1)],
            positions: positions.clone(),
            orientations: vec![],
            feet: vec![],
        };
        let out = PointFigureOut::from(figure);
        assert!(out.step >= 1e-4 && out.step < 1e-3);
        for (k, &p) in positions.iter().enumerate() {
            let root = f64::from(out.root[k / 9 * 3 + k % 3]);
            let back = root + f64::from(out.offsets[k]) * out.step;
            assert!((back - f64::from(p)).abs() <= out.step / 2.0 + 1e-6, "{k}: {back} vs {p}");
        }
    }

    #[test]
    fn rejects_ragged_data() {
        let scene = Scene {
            title: "t".into(),
            fps: 30.0,
            num_frames: 2,
            info: vec![],
            tree: None,
            skeletons: vec![PointFigure {
                label: "s".into(),
                style: PointStyle::Skeleton,
                color: [1.0; 3],
                names: names(&["a"]),
                parents: vec![None],
                positions: vec![0.0; 3],
                orientations: vec![],
                feet: vec![],
            }],
            robot: None,
            plots: vec![],
        };
        assert!(scene.to_html().is_err());
    }
}
