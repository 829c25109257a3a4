//! `retarget bvh fk FILE --frame N`: world poses of every body at one frame (metres, Z up,
//! quaternions w x y z) and what `fk` decided (units, subject height, ground); plus the
//! lines `retarget bvh info` shows about the subject.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use clap::{Args, ValueEnum};
use fk::{AxisConvention, FkOptions, FkReport, PositionReading, UnitChoice};

/// Arguments of `retarget bvh fk`.
#[derive(Args, Debug, Clone)]
pub struct FkArgs {
    /// The BVH file.
    pub file: PathBuf,
    /// Frame to print (0-based).
    #[arg(long, default_value_t = 0)]
    pub frame: usize,
    /// File units: auto, m, cm, mm, inch, cmu, or metres per unit as a number.
    #[arg(long, default_value = "auto", value_parser = parse_units)]
    pub units: UnitChoice,
    /// Which way is up in the file (auto: the axis the head is above the feet along).
    #[arg(long, value_enum, default_value_t = Axes::Auto)]
    pub axes: Axes,
    /// Subject height in metres instead of the estimate.
    #[arg(long)]
    pub height: Option<f64>,
    /// Also write every frame to this `.npz`: `fps`, `body_names`, `body_pos_w` (T×B×3, m,
    /// Z up), `body_quat_w` (T×B×4, w x y z), `ground`, `height`, and the recognised roles:
    /// `role_names`, `role_bodies` (the joint playing each), `role_frame_offsets` (R×4: a
    /// role's canonical body frame is its joint's `body_quat_w` ⊗ this offset).
    #[arg(long, value_name = "OUT.npz")]
    pub npz: Option<PathBuf>,
}

/// `--axes` values (see `fk::AxisConvention`).
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axes {
    /// Inferred from the motion (Y up converted as GMR does).
    Auto,
    /// Y up, as GMR: +90° about X (a subject facing file +Z faces world −Y).
    YUp,
    /// Already Z up.
    ZUp,
    /// Y up, turned to face world +X.
    YUpFaceX,
}

impl FkArgs {
    #[must_use]
    pub fn options(&self) -> FkOptions {
        let axes = match self.axes {
            Axes::Auto => AxisConvention::Auto,
            Axes::YUp => AxisConvention::YUp,
            Axes::ZUp => AxisConvention::ZUp,
            Axes::YUpFaceX => AxisConvention::YUpFaceX,
        };
        FkOptions { axes, units: self.units, height: self.height, ..FkOptions::default() }
    }
}

fn parse_units(text: &str) -> Result<UnitChoice, String> {
    Ok(match text {
        "auto" => UnitChoice::Auto,
        "m" => UnitChoice::Scale(1.0),
        "cm" => UnitChoice::Scale(0.01),
        "mm" => UnitChoice::Scale(0.001),
        "inch" => UnitChoice::Scale(0.0254),
        "cmu" => UnitChoice::Scale(0.05644),
        _ => match text.parse::<f64>() {
            Ok(m) if m.is_finite() && m > 0.0 => UnitChoice::Scale(m),
            _ => {
                return Err(format!(
                    "`{text}`: expected auto, m, cm, mm, inch, cmu or metres per unit"
                ))
            }
        },
    })
}

/// `retarget bvh fk`, from parsed arguments.
pub fn run(args: &FkArgs) -> anyhow::Result<ExitCode> {
    if let Some(out) = &args.npz {
        let bvh = crate::files::read_bvh(&args.file)?;
        write_npz(&bvh, &args.options(), out).with_context(|| args.file.display().to_string())?;
    }
    print_fk(&args.file, args.frame, &args.options())
}

/// The whole clip's FK and roles as an `.npz` (see [`FkArgs::npz`]).
pub fn write_npz(bvh: &bvh::Bvh, options: &FkOptions, out: &Path) -> anyhow::Result<()> {
    use npz::Array;
    let (motion, report) = fk::human_motion(bvh, options)?;
    let (t, b) = (motion.num_frames, motion.body_names.len());
    let mut pos = Vec::with_capacity(t * b * 3);
    let mut quat = Vec::with_capacity(t * b * 4);
    for f in 0..t {
        for body in 0..b {
            let (p, q) = (motion.position(f, body), motion.orientation(f, body));
            pos.extend([p.x, p.y, p.z]);
            quat.extend([q.w, q.i, q.j, q.k]);
        }
    }
    let (mut names, mut bodies, mut offsets) = (Vec::new(), Vec::new(), Vec::new());
    if let Ok(humanoid) = &report.humanoid {
        for (role, joint) in humanoid.roles.iter() {
            let q = humanoid.frame_offsets.get(&role).copied().unwrap_or_default();
            names.push(role.name().to_owned());
            bodies.push(joint.name.clone());
            offsets.extend([q.w, q.i, q.j, q.k]);
        }
    }
    let arrays = [
        ("fps", Array::f64(vec![1], vec![motion.fps])),
        ("body_names", Array::strings(&motion.body_names)),
        ("body_pos_w", Array::f64(vec![t, b, 3], pos)),
        ("body_quat_w", Array::f64(vec![t, b, 4], quat)),
        ("ground", Array::f64(vec![1], vec![report.ground])),
        ("height", Array::f64(vec![1], vec![report.height])),
        ("role_names", Array::strings(&names)),
        ("role_bodies", Array::strings(&bodies)),
        ("role_frame_offsets", Array::f64(vec![names.len(), 4], offsets)),
    ];
    retarget::writers::write_npz(out, &arrays)?;
    Ok(())
}

/// Print every body's world pose at `frame`, then the [`FkReport`].
pub fn print_fk(file: &Path, frame: usize, options: &FkOptions) -> anyhow::Result<ExitCode> {
    let bvh = crate::files::read_bvh(file)?;
    let poses = frame_poses(&bvh, frame, options).with_context(|| file.display().to_string())?;
    println!("{}: {}", file.display(), poses.header());
    for line in poses.lines() {
        println!("{line}");
    }
    Ok(ExitCode::SUCCESS)
}

/// The `fk` lines of `retarget bvh info`: subject height, units, ground.
pub fn report_lines(bvh: &bvh::Bvh) -> anyhow::Result<Vec<String>> {
    let (_, report) = fk::human_motion(bvh, &FkOptions::default())?;
    Ok(summary_lines(&report))
}

fn summary_lines(report: &FkReport) -> Vec<String> {
    let mut lines = vec![
        format!("units: {} m per file unit ({})", report.metres_per_unit, report.unit_reason),
        format!("subject height: {:.3} m ({})", report.height, report.height_source),
        format!("ground: {:.4} m (lowest foot point over the clip, Z up)", report.ground),
    ];
    // GMR's reading (channels replace OFFSET) goes without saying; the others are news.
    let unusual = report.position_channels.iter().filter(|p| p.reading != PositionReading::Local);
    lines.extend(unusual.map(|p| {
        let reading = match p.reading {
            PositionReading::Added => "a displacement added to OFFSET",
            _ => "world positions",
        };
        format!("position channels of `{}`: {reading} ({})", p.joint, p.reason)
    }));
    lines
}

/// One body's world pose.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyPose {
    pub name: String,
    /// Metres, Z up.
    pub position: [f64; 3],
    /// w, x, y, z.
    pub orientation: [f64; 4],
}

/// Every body at one frame, with the clip's FK report.
#[derive(Debug, Clone, PartialEq)]
pub struct FramePoses {
    pub frame: usize,
    pub num_frames: usize,
    pub fps: f64,
    pub bodies: Vec<BodyPose>,
    pub report: FkReport,
}

/// FK of the whole clip (the ground and height need it), poses of `frame`.
pub fn frame_poses(
    bvh: &bvh::Bvh,
    frame: usize,
    options: &FkOptions,
) -> anyhow::Result<FramePoses> {
    let (motion, report) = fk::human_motion(bvh, options)?;
    anyhow::ensure!(
        frame < motion.num_frames,
        "frame {frame} is out of range: the clip has {} frames",
        motion.num_frames
    );
    let bodies = motion
        .body_names
        .iter()
        .enumerate()
        .map(|(b, name)| {
            let (p, q) = (motion.position(frame, b), motion.orientation(frame, b));
            BodyPose {
                name: name.clone(),
                position: [p.x, p.y, p.z],
                orientation: [q.w, q.i, q.j, q.k],
            }
        })
        .collect();
    Ok(FramePoses { frame, num_frames: motion.num_frames, fps: motion.fps, bodies, report })
}

impl FramePoses {
    fn header(&self) -> String {
        format!(
            "frame {} of {} ({:.3} fps), {} bodies; world: metres, Z up; quaternions w x y z",
            self.frame,
            self.num_frames,
            self.fps,
            self.bodies.len()
        )
    }

    /// The body table, then the report.
    #[must_use]
    pub fn lines(&self) -> Vec<String> {
        let width = self.bodies.iter().map(|b| b.name.len()).max().unwrap_or(4).max(4);
        let mut lines = vec![format!(
            "{:width$} {:>9} {:>9} {:>9}  {:>9} {:>9} {:>9} {:>9}",
            "body", "x", "y", "z", "qw", "qx", "qy", "qz"
        )];
        for body in &self.bodies {
            let [x, y, z] = body.position;
            let [w, i, j, k] = body.orientation;
            lines.push(format!(
                "{:width$} {x:>9.4} {y:>9.4} {z:>9.4}  {w:>9.6} {i:>9.6} {j:>9.6} {k:>9.6}",
                body.name
            ));
        }
        lines.extend(summary_lines(&self.report));
        lines
    }

    /// World pose of a body by name.
    #[must_use]
    #[cfg(test)]
    pub fn body(&self, name: &str) -> Option<&BodyPose> {
        self.bodies.iter().find(|b| b.name == name)
    }
}

#[cfg(test)]
#[path = "../../../tests/support/shared.rs"]
mod shared;

#[cfg(test)]
mod tests {
    use super::*;

    const TINY: &str = "HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
  JOINT Spine
  {
    OFFSET 0 10 0
    CHANNELS 3 Zrotation Yrotation Xrotation
    JOINT Head
    {
      OFFSET 0 50 0
      CHANNELS 3 Zrotation Yrotation Xrotation
      End Site
      {
        OFFSET 0 20 0
      }
    }
  }
  JOINT LeftUpLeg
  {
    OFFSET 10 -5 0
    CHANNELS 3 Zrotation Yrotation Xrotation
    JOINT LeftFoot
    {
      OFFSET 0 -85 0
      CHANNELS 3 Zrotation Yrotation Xrotation
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.033333
0 95 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0
0 95 10 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0
";

    #[test]
    fn prints_world_poses_and_the_report() {
        let bvh = bvh::from_str(TINY).unwrap();
        let poses = frame_poses(&bvh, 1, &FkOptions::default()).unwrap();
        assert_eq!(poses.bodies.len(), 6);
        let head = poses.body("Head_End").unwrap();
        // (x, y, z) cm, Y up → (x, −z, y) m, Z up.
        let expected = [0.0, -0.1, 1.75];
        assert!(head.position.iter().zip(expected).all(|(a, b)| (a - b).abs() < 1e-12), "{head:?}");
        let lines = poses.lines();
        assert!(lines[0].starts_with("body"));
        assert!(lines[1].starts_with("Hips"));
        assert!(lines.iter().any(|l| l.starts_with("units: 0.01 m per file unit (centimetres")));
        assert!(lines.iter().any(|l| l.starts_with("subject height: 1.700 m")), "{lines:#?}");
        assert!(frame_poses(&bvh, 2, &FkOptions::default())
            .unwrap_err()
            .to_string()
            .contains("2 frames"));
        assert_eq!(report_lines(&bvh).unwrap().len(), 3);
    }

    /// `--npz`: every frame's poses, as `frame_poses` gives them one frame at a time.
    #[test]
    fn npz_holds_every_frame() {
        let bvh = bvh::from_str(TINY).unwrap();
        let path = std::env::temp_dir().join(format!("fk-npz-{}.npz", std::process::id()));
        write_npz(&bvh, &FkOptions::default(), &path).unwrap();
        let mut npz = npz::Npz::open(&path).unwrap();
        let (shape, pos) = npz.floats("body_pos_w").unwrap();
        assert_eq!(shape, [2, 6, 3]);
        assert_eq!(npz.header("body_quat_w").unwrap().shape, [2, 6, 4]);
        // Not a humanoid (no arms): no roles, but the arrays are there.
        assert_eq!(npz.header("role_frame_offsets").unwrap().shape, [0, 4]);
        let poses = frame_poses(&bvh, 1, &FkOptions::default()).unwrap();
        for (b, body) in poses.bodies.iter().enumerate() {
            let at = &pos[(6 + b) * 3..(6 + b) * 3 + 3];
            assert!(at.iter().zip(body.position).all(|(a, e)| (a - e).abs() < 1e-12));
        }
        std::fs::remove_file(&path).unwrap();
    }

    #[test]
    fn units_argument() {
        assert_eq!(parse_units("cm"), Ok(UnitChoice::Scale(0.01)));
        assert_eq!(parse_units("0.5"), Ok(UnitChoice::Scale(0.5)));
        assert_eq!(parse_units("auto"), Ok(UnitChoice::Auto));
        assert!(parse_units("-1").is_err() && parse_units("feet").is_err());
    }

    #[test]
    fn lafan1_walk_head_is_1_6_to_1_8_m_above_the_feet() {
        let Some(path) = shared::shared_file("data/bvh/lafan1_take_via_bvhtools_test.bvh") else {
            return;
        };
        let bvh = bvh::from_path(&path).unwrap();
        let poses = frame_poses(&bvh, 0, &FkOptions::default()).unwrap();
        let head = poses.body("Head").unwrap().position[2];
        let feet = ["LeftFoot", "LeftToe", "RightFoot", "RightToe"];
        let sole =
            feet.iter().map(|f| poses.body(f).unwrap().position[2]).fold(f64::INFINITY, f64::min);
        assert!((1.6..=1.8).contains(&(head - sole)), "head {head} m, sole {sole} m");
        assert!((1.6..=1.9).contains(&poses.report.height), "{:?}", poses.report);
    }
}
