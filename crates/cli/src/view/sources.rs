//! The project's data types → the page's plain data ([`super::Scene`] parts).

use super::{
    JointKind, Plot, PointFigure, PointStyle, RobotBody, RobotFigure, RobotGeom, RobotJoint,
    Series, Shape,
};
use anyhow::{ensure, Context};

pub const HUMAN_COLOR: [f32; 3] = [0.93, 0.52, 0.2];
pub const TARGET_COLOR: [f32; 3] = [0.18, 0.68, 0.3];

// (nalgebra is not a dependency of this crate: the types are reached through the others.)
macro_rules! xyz {
    ($v:expr) => {{
        let v = $v;
        [v.x, v.y, v.z]
    }};
}

macro_rules! wxyz {
    ($q:expr) => {{
        let q = $q;
        [q.w, q.i, q.j, q.k]
    }};
}

fn push_f32(out: &mut Vec<f32>, values: &[f64]) {
    #[allow(clippy::cast_possible_truncation)] // float32 is the page's storage format
    out.extend(values.iter().map(|&v| v as f32));
}

/// A robot motion on its model. The page poses the robot from `qpos` itself; three frames of
/// world body positions from [`mjcf::Model::kinematics`] travel along as a check.
pub fn robot_figure(model: &mjcf::Model, qpos: &[f64], label: &str) -> anyhow::Result<RobotFigure> {
    let nq = model.nq;
    ensure!(
        qpos.len().checked_rem(nq) == Some(0),
        "{label}: qpos length {} is not a multiple of nq = {nq}",
        qpos.len()
    );
    let frames = qpos.len() / nq;
    let body = |id: usize| id.checked_sub(1); // world (0) is implicit in the page
    let bodies = model.bodies.iter().skip(1).map(|b| RobotBody {
        name: b.name.clone(),
        parent: body(b.parent),
        pos: xyz!(b.pos),
        quat: wxyz!(b.quat),
    });
    let joints = model.joints.iter().filter_map(|j| {
        Some(RobotJoint {
            name: j.name.clone(),
            kind: match j.kind {
                mjcf::JointType::Free => JointKind::Free,
                mjcf::JointType::Ball => JointKind::Ball,
                mjcf::JointType::Slide => JointKind::Slide,
                mjcf::JointType::Hinge => JointKind::Hinge,
            },
            body: body(j.body)?,
            qpos_adr: j.qpos_adr,
            axis: xyz!(j.axis),
            pos: xyz!(j.pos),
            range: j.range,
        })
    });
    let geoms = model.geoms.iter().filter_map(|g| {
        let shape = match g.kind {
            mjcf::GeomType::Sphere => Shape::Sphere,
            mjcf::GeomType::Capsule => Shape::Capsule,
            mjcf::GeomType::Cylinder => Shape::Cylinder,
            mjcf::GeomType::Box => Shape::Box,
            mjcf::GeomType::Ellipsoid => Shape::Ellipsoid,
            _ => return None, // planes, meshes, height fields: bones stand in for them
        };
        Some(RobotGeom {
            body: body(g.body)?,
            shape,
            size: g.size,
            pos: xyz!(g.pos),
            quat: wxyz!(g.quat),
        })
    });
    let names = retarget::RobotMotion::model_body_names(model);
    let mut data = mjcf::Data::new(model);
    let mut check = Vec::new();
    for frame in [0, frames / 2, frames.saturating_sub(1)] {
        if frames == 0 || check.iter().any(|c: &(usize, Vec<[f64; 3]>)| c.0 == frame) {
            continue;
        }
        model.kinematics(&qpos[frame * nq..(frame + 1) * nq], &mut data);
        check.push((frame, data.xpos.iter().skip(1).map(|p| xyz!(p)).collect()));
    }
    let mut qpos32 = Vec::with_capacity(qpos.len());
    push_f32(&mut qpos32, qpos);
    Ok(RobotFigure {
        label: label.to_owned(),
        bodies: bodies.collect(),
        joints: joints.collect(),
        geoms: geoms.collect(),
        nq,
        qpos0: model.qpos0.clone(),
        qpos: qpos32,
        feet: robot_feet(model, &names),
        check,
    })
}

/// The robot's feet for the page's foot plots: the soles the robot recogniser finds
/// (`retarget robot info`), else the bodies named like feet. Indices count from the first
/// body after the world, as the page's bodies do.
fn robot_feet(model: &mjcf::Model, names: &[String]) -> Vec<(String, usize)> {
    match retarget::RobotRoles::recognise(model) {
        Ok(roles) => ["left", "right"]
            .into_iter()
            .zip(roles.soles())
            .filter_map(|(side, sole)| Some((side.to_owned(), sole.body.checked_sub(1)?)))
            .collect(),
        Err(_) => super::find_feet(names),
    }
}

/// The source's foot contact phases (npz `contact_left`, `contact_right`), one plot per foot:
/// 1 in contact, 0 not, the phases shaded.
pub fn contact_plots(contacts: &retarget::FootContacts, frames: usize) -> Vec<Plot> {
    [("left", &contacts.left), ("right", &contacts.right)]
        .into_iter()
        .map(|(side, on)| {
            let on = &on[..frames.min(on.len())];
            let mut shaded = Vec::new();
            let mut start = None;
            for (f, &c) in on.iter().chain([&false]).enumerate() {
                match (c, start) {
                    (true, None) => start = Some(f),
                    (false, Some(s)) => {
                        shaded.push([s, f]);
                        start = None;
                    }
                    _ => {}
                }
            }
            let mut values: Vec<f32> = on.iter().map(|&c| if c { 1.0 } else { 0.0 }).collect();
            values.resize(frames, 0.0);
            Plot {
                title: format!("{side} foot: source contact (npz contact_{side}), phases shaded"),
                unit: String::new(),
                series: vec![Series { name: format!("contact_{side}"), values }],
                limits: None,
                shaded,
            }
        })
        .collect()
}

/// Check that a robot motion belongs to `model`: same `nq` and, when the motion names its
/// joints, the same non-free joints in the same order.
pub fn check_motion_fits(
    model: &mjcf::Model,
    motion: &retarget::RobotMotion,
) -> anyhow::Result<()> {
    ensure!(
        motion.nq == model.nq,
        "the motion has nq = {} but the robot model has nq = {}",
        motion.nq,
        model.nq
    );
    if !motion.joint_names.is_empty() {
        ensure!(
            motion.joint_names == retarget::RobotMotion::model_joint_names(model),
            "the motion's joints differ from the robot model's"
        );
    }
    Ok(())
}

/// The IK targets a robot motion tracked, as spheres with orientation axes.
pub fn targets_figure(
    targets: &retarget::TrackedTargets,
    num_frames: usize,
) -> anyhow::Result<PointFigure> {
    let k = targets.body_names.len();
    ensure!(targets.pos.len() == num_frames * k, "targets: positions are not frames × bodies");
    ensure!(
        targets.quat.is_empty() || targets.quat.len() == num_frames * k,
        "targets: orientations are not frames × bodies"
    );
    let mut positions = Vec::with_capacity(num_frames * k * 3);
    for p in &targets.pos {
        push_f32(&mut positions, &xyz!(p));
    }
    let mut orientations = Vec::with_capacity(targets.quat.len() * 4);
    for q in &targets.quat {
        push_f32(&mut orientations, &wxyz!(q));
    }
    Ok(PointFigure {
        label: "IK targets".to_owned(),
        style: PointStyle::Targets,
        color: TARGET_COLOR,
        names: targets.body_names.clone(),
        parents: vec![None; k],
        positions,
        orientations,
        feet: vec![],
    })
}

/// A skeleton figure from world positions of points with parents (`positions[frame * n + i]`).
pub fn skeleton_figure(
    label: &str,
    names: &[String],
    parents: &[Option<usize>],
    positions: impl Iterator<Item = [f64; 3]>,
) -> PointFigure {
    let mut flat = Vec::new();
    for p in positions {
        push_f32(&mut flat, &p);
    }
    PointFigure {
        label: label.to_owned(),
        style: PointStyle::Skeleton,
        color: HUMAN_COLOR,
        names: names.to_vec(),
        parents: parents.to_vec(),
        positions: flat,
        orientations: vec![],
        feet: super::find_feet(names),
    }
}

/// A model read for its geometry only (used by tests before a real MJCF is at hand).
#[allow(dead_code)]
pub fn model_from_xml(xml: &str) -> anyhow::Result<mjcf::Model> {
    mjcf::Model::from_xml_str(xml, None).context("robot model")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn contact_plots_shade_the_phases() {
        let contacts = retarget::FootContacts {
            left: vec![true, true, false, false, true],
            right: vec![false, true, true, true, false],
            on_toes: None,
        };
        let plots = contact_plots(&contacts, 5);
        assert_eq!(plots.len(), 2);
        assert_eq!(plots[0].shaded, vec![[0, 2], [4, 5]]);
        assert_eq!(plots[1].shaded, vec![[1, 4]]);
        assert_eq!(plots[1].series[0].values, vec![0.0, 1.0, 1.0, 1.0, 0.0]);
        // A page cut to fewer frames (the source is shorter) cuts the plots too.
        let cut = contact_plots(&contacts, 3);
        assert_eq!(cut[1].shaded, vec![[1, 3]]);
        assert_eq!(cut[0].series[0].values.len(), 3);
    }

    /// The feet of the foot plots come from the robot recogniser: ToddlerBot's feet have no
    /// foot-like names (`ank_roll_link`, `ank_roll_link_2`).
    #[test]
    fn robot_feet_from_the_recogniser() {
        let model = crate::shipped::robot_model("stanford_toddy").unwrap();
        let names = retarget::RobotMotion::model_body_names(&model);
        let feet = robot_feet(&model, &names);
        let named: Vec<(&str, &str)> =
            feet.iter().map(|(side, i)| (side.as_str(), names[*i].as_str())).collect();
        assert_eq!(named, [("left", "ank_roll_link"), ("right", "ank_roll_link_2")]);
    }
}

#[cfg(test)]
mod synthetic {
    //! A hand-made scene (swinging skeleton, a robot of every primitive) for looking at the
    //! page: `VIEW_SYNTHETIC_OUT=/tmp/s.html cargo test -p cli synthetic`.
    use super::*;
    use crate::view::Scene;

    pub fn scene(frames: usize) -> Scene {
        let xml = r#"<mujoco><worldbody><body name="base" pos="0 0 1">
          <freejoint/><geom type="box" size="0.1 0.15 0.1"/>
          <body name="left_leg" pos="0 0.1 -0.1"><joint name="lh" axis="0 1 0" range="-1 1"/>
            <geom type="capsule" fromto="0 0 0 0 0 -0.4" size="0.04"/>
            <body name="left_ankle_roll_link" pos="0 0 -0.45"><joint name="lk" axis="0 1 0" range="0 2"/>
              <geom type="cylinder" size="0.05 0.02"/></body></body>
          <body name="right_leg" pos="0 -0.1 -0.1"><joint name="rh" axis="0 1 0" range="-1 1"/>
            <geom type="capsule" fromto="0 0 0 0 0 -0.4" size="0.04"/>
            <body name="right_ankle_roll_link" pos="0 0 -0.45"><joint name="rk" axis="0 1 0"/>
              <geom type="sphere" size="0.05"/></body></body>
          <body name="head" pos="0 0 0.25"><geom type="ellipsoid" size="0.08 0.06 0.1"/></body>
        </body></worldbody></mujoco>"#;
        let model = model_from_xml(xml).unwrap();
        let mut qpos = Vec::new();
        for f in 0..frames {
            let t = f as f64 / 30.0;
            let s = (2.0 * t).sin();
            qpos.extend([
                0.3 * t,
                0.0,
                1.0,
                1.0,
                0.0,
                0.0,
                0.0,
                0.6 * s,
                0.5 + 0.4 * s,
                -0.6 * s,
                0.5,
            ]);
        }
        let robot = robot_figure(&model, &qpos, "robot").unwrap();
        let names: Vec<String> =
            ["Hips", "LeftFoot", "RightFoot", "Head"].map(String::from).to_vec();
        let parents = [None, Some(0), Some(0), Some(0)];
        let pos = (0..frames).flat_map(|f| {
            let t = f as f64 / 30.0;
            let x = 0.3 * t + 0.8;
            let s = 0.3 * (2.0 * t).sin();
            [[x, 0.0, 1.0], [x + s, 0.1, 0.05], [x - s, -0.1, 0.05], [x, 0.0, 1.6]]
        });
        let human = skeleton_figure("human", &names, &parents, pos);
        Scene {
            title: "synthetic".into(),
            fps: 30.0,
            num_frames: frames,
            info: vec![("joints".into(), "4".into())],
            tree: Some("Hips\n  LeftFoot\n  RightFoot\n  Head".into()),
            skeletons: vec![human],
            robot: Some(robot),
            plots: vec![],
        }
    }

    #[test]
    fn synthetic_page() {
        let html = scene(300).to_html().unwrap();
        assert!(html.contains("\"check\":[[0,"));
        if let Some(out) = std::env::var_os("VIEW_SYNTHETIC_OUT") {
            std::fs::write(out, html).unwrap();
        }
    }
}
