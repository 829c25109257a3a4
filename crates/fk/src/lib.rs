//! Human forward kinematics: a parsed BVH becomes world poses of named bodies, in metres,
//! Z up, quaternions w-first and continuous in time. This is the unit and axis boundary of
//! the toolkit: everything downstream is metres and Z up.
//!
//! ```text
//! human_motion(&bvh, &FkOptions::default()) -> (HumanMotion, FkReport)
//! ```
//!
//! The numbers follow GMR's LAFAN1 loader operation by operation (`forward`, `math`): local
//! `q = q(c₁) ⊗ (q(c₂) ⊗ q(c₃))` in each joint's channel order, position channels replace
//! OFFSET (unless the numbers say otherwise: [`PositionReading`]), `q = q_parent ⊗ q_local`,
//! `p = q_parent · p_local + p_parent`; world `p' = (x, −z, y) / 100` and `q' = q_x90 ⊗ q`
//! for a Y-up centimetre file. Where we differ on purpose:
//! - End Sites are bodies too (`<Parent>_End`);
//! - orientations are made continuous on the world quaternions (GMR does it on the local
//!   ones: same rotations, possibly opposite signs; compare up to sign);
//! - units are chosen from the skeleton's size instead of assumed to be centimetres
//!   ([`UnitChoice`], reported in [`FkReport::unit_reason`]);
//! - the subject height is measured instead of assumed to be 1.75 m: head over the lowest
//!   foot point in the rest pose when it stands upright, otherwise the 99th percentile over
//!   the clip's frames, plus the skull for skeletons that end at the head joint
//!   ([`FkReport::height_source`]);
//! - `fps` is snapped to the integer a rounded Frame Time stands for (`0.033333` → 30).
//!
//! `fk` does no IO, never prints and never panics on input.

// Library code never panics on input (issue 15): the compiler checks it. Tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

pub mod conventions;
mod error;
mod forward;
pub mod frames;
mod humanoid;
mod limits;
pub mod markers;
mod math;
mod motion;
mod options;
mod posture;
mod recogniser;
mod roles;
mod size;
mod straight;
mod structure;
mod trig;

pub use error::Error;
pub use forward::{PositionChannels, PositionReading};
pub use frames::canonical_frames;
pub use humanoid::{Humanoid, Reference, RestPose, RoleJoint, RoleMap, Rule, UpAxis};
pub use limits::{MAX_DISTANCE, MAX_STEP};
pub use motion::HumanMotion;
pub use options::{AxisConvention, DerivedBody, FkOptions, UnitChoice};
pub use recogniser::{recognise, recognise_posed, PosedFrame};
pub use roles::{Part, Role, Side};
pub use straight::straighten_limbs;

use bvh::Bvh;
use nalgebra::Vector3;

use forward::{check_finite, rest_pose, Plan, ToWorld};
use size::Landmarks;

/// What [`human_motion`] decided and measured, for reports and for the retargeter.
#[derive(Debug, Clone, PartialEq)]
pub struct FkReport {
    /// Metres per file unit that was applied.
    pub metres_per_unit: f64,
    /// Why that unit (the candidate and the measurement behind it, or "forced").
    pub unit_reason: String,
    /// Subject height in metres (estimated, or the one given in [`FkOptions::height`]).
    pub height: f64,
    /// How the height was obtained.
    pub height_source: String,
    /// Lowest foot point over the clip: world z in metres (0 for a clip on the floor).
    pub ground: f64,
    /// How each joint with position channels was read, in joint order ([`PositionReading`]).
    pub position_channels: Vec<PositionChannels>,
    /// The file-to-world rotation that was applied (never [`AxisConvention::Auto`]).
    pub axes: AxisConvention,
    /// Why those axes (inferred up axis and the evidence, or "given").
    pub axes_reason: String,
    /// The recognised humanoid (roles, up axis, rest pose, body frames), or why the skeleton
    /// was not recognised (FK works on any skeleton; only the conventions fall back).
    pub humanoid: Result<Humanoid, Error>,
}

impl FkReport {
    /// One line on what was inferred: up axis, unit, naming convention, rest pose.
    #[must_use]
    pub fn inferred(&self) -> String {
        let unit = self.unit_reason.split(':').next().unwrap_or("").trim();
        let up = match (&self.humanoid, self.axes_reason.as_str()) {
            (_, "given") => "axes given".to_owned(),
            (Ok(h), _) => format!("{} up", h.up),
            (Err(_), _) => "+Y up assumed".to_owned(),
        };
        match &self.humanoid {
            Ok(h) => format!(
                "{up}, {unit} ({} m/unit), {} roles by {}, rest pose {}",
                self.metres_per_unit,
                h.roles.len(),
                h.convention.unwrap_or("hierarchy alone"),
                h.rest_pose
            ),
            Err(_) => {
                format!(
                    "{up}, {unit} ({} m/unit), skeleton not recognised as a humanoid",
                    self.metres_per_unit
                )
            }
        }
    }
}

/// The body names [`human_motion`] gives `bvh` with `options` (joints, End Sites, derived
/// bodies), without running the forward kinematics.
pub fn body_names(bvh: &Bvh, options: &FkOptions) -> Result<Vec<String>, Error> {
    let mut names: Vec<String> = bvh.skeleton.joints.iter().map(|j| j.name.clone()).collect();
    let derived = resolve_derived(&names, &options.derived)?;
    names.extend(derived.into_iter().map(|d| d.name));
    Ok(names)
}

/// Forward kinematics of every frame of `bvh`, converted to our world (see [`FkOptions`]).
/// A clip without frames, or whose poses are absurd ([`HumanMotion::validate`]), is an error.
pub fn human_motion(bvh: &Bvh, options: &FkOptions) -> Result<(HumanMotion, FkReport), Error> {
    let plan = Plan::new(bvh)?;
    let fps = frames_per_second(bvh)?;
    if bvh.motion.num_frames == 0 {
        return Err(Error::NoFrames);
    }
    check_finite(bvh)?;
    let joint_names: Vec<String> = bvh.skeleton.joints.iter().map(|j| j.name.clone()).collect();
    let derived = resolve_derived(&joint_names, &options.derived)?;
    let samples = recogniser::samples(&plan, bvh);
    let humanoid = match recogniser::from_samples(&bvh.skeleton, &samples, &options.roles) {
        Err(e @ Error::UnknownRoleJoint { .. }) => return Err(e),
        other => other,
    };
    let (axes, axes_reason) = match (options.axes, &humanoid) {
        (AxisConvention::Auto, Ok(h)) => {
            (h.up.convention(), format!("{} up: {}", h.up, h.up_reason))
        }
        (AxisConvention::Auto, Err(_)) => {
            (AxisConvention::YUp, "+Y up assumed (the BVH norm): no humanoid recognised".to_owned())
        }
        (given, _) => (given, "given".to_owned()),
    };
    let (metres_per_unit, unit_reason) = units(&plan, options.units, humanoid.as_ref().ok())?;
    if let Some(h) = options.height {
        positive("height", h)?;
    }

    let world = ToWorld::new(&axes, metres_per_unit);
    let num_frames = bvh.motion.num_frames;
    let num_joints = plan.num_joints();
    let sources: Vec<(usize, usize)> =
        derived.iter().map(|d| (d.position_from, d.orientation_from)).collect();
    let (positions, orientations) = forward::run(&plan, bvh, &world, &sources);
    let mut body_names = joint_names;
    body_names.extend(derived.into_iter().map(|d| d.name));
    let landmarks = match &humanoid {
        Ok(h) => Landmarks::from_roles(&bvh.skeleton, metres_per_unit, &h.roles),
        Err(_) => Landmarks::find(&bvh.skeleton, metres_per_unit),
    };
    let rest = rest_pose(&plan, &world);
    let motion = HumanMotion { fps, body_names, num_frames, positions, orientations };
    motion.validate()?;
    let frames = (0..num_frames).map(|f| {
        let all = motion.frame_positions(f);
        all.get(..num_joints).unwrap_or(all)
    });
    let stature = size::stature(frames, &rest, &landmarks);
    let (height, height_source) = match options.height {
        Some(h) => (h, "given".to_owned()),
        None => (stature.height, stature.source),
    };
    let position_channels = plan.position_channels().to_vec();
    let report = FkReport {
        metres_per_unit,
        unit_reason,
        height,
        height_source,
        ground: stature.ground,
        position_channels,
        axes,
        axes_reason,
        humanoid,
    };
    Ok((motion, report))
}

/// `1 / Frame Time`, snapped to the integer N when the Frame Time is 1/N rounded to a few
/// decimals (LAFAN1's `0.033333` is 30 fps, not 30.0003; CMU's `.0083333` is 120).
fn frames_per_second(bvh: &Bvh) -> Result<f64, Error> {
    let t = bvh.motion.frame_time;
    if !(t.is_finite() && t > 0.0) {
        return Err(Error::BadFrameTime(t));
    }
    let n = (1.0 / t).round();
    Ok(if n >= 1.0 && (t * n - 1.0).abs() < 1e-4 { n } else { 1.0 / t })
}

fn positive(name: &'static str, value: f64) -> Result<f64, Error> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Error::InvalidOption { name, value })
    }
}

/// A derived body with its sources resolved to joint indices.
struct Derived {
    name: String,
    position_from: usize,
    orientation_from: usize,
}

fn resolve_derived(joints: &[String], requested: &[DerivedBody]) -> Result<Vec<Derived>, Error> {
    let defaults = DerivedBody::gmr_defaults();
    let mut out: Vec<Derived> = Vec::new();
    for entry in requested {
        let lenient = defaults.contains(entry);
        let taken = joints.contains(&entry.name) || out.iter().any(|d| d.name == entry.name);
        let find = |name: &str| joints.iter().position(|j| j == name);
        let sources = (find(&entry.position_from), find(&entry.orientation_from));
        match (taken, sources) {
            (true, _) if lenient => {}
            (true, _) => return Err(Error::DuplicateBody(entry.name.clone())),
            (false, (Some(position_from), Some(orientation_from))) => {
                out.push(Derived { name: entry.name.clone(), position_from, orientation_from });
            }
            (false, _) if lenient => {}
            (false, (p, _)) => {
                let missing =
                    if p.is_none() { &entry.position_from } else { &entry.orientation_from };
                return Err(Error::UnknownBody {
                    name: missing.clone(),
                    available: joints.to_vec(),
                });
            }
        }
    }
    Ok(out)
}

/// Metres per file unit: forced, or chosen from the body's proportions (a recognised
/// humanoid's head-to-ankle bone path), or else from the skeleton's size. Bone lengths are
/// the OFFSETs, except those of the roots' children: in some files (Bandai) the root sits on
/// the floor and that OFFSET is the hip height, not a bone.
fn units(
    plan: &Plan,
    choice: UnitChoice,
    humanoid: Option<&Humanoid>,
) -> Result<(f64, String), Error> {
    if let UnitChoice::Scale(m) = choice {
        positive("metres per unit", m)?;
        return Ok((m, format!("forced: {m} m per file unit")));
    }
    let stature = humanoid.map(|h| h.stature_path).filter(|&p| p > 0.0);
    if let UnitChoice::Declared(m) = choice {
        positive("metres per unit", m)?;
        if let Some(path) = stature {
            return Ok(size::declared_units_from_stature(m, path));
        }
    }
    if let Some(path) = stature {
        return Ok(size::choose_units_from_stature(path));
    }
    let parents: Vec<Option<usize>> = plan.parents().collect();
    let lengths: Vec<f64> = plan
        .offsets()
        .zip(&parents)
        .map(|(offset, parent)| match parent {
            Some(p) if parents.get(*p).is_some_and(Option::is_some) => Vector3::from(offset).norm(),
            _ => 0.0,
        })
        .collect();
    let diameter = size::tree_diameter(&parents, &lengths);
    Ok(match choice {
        UnitChoice::Declared(m) => size::declared_units(m, diameter),
        _ => size::choose_units(diameter),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::forward::Scale;
    use bvh::{Axis, Channel, Joint, JointId, JointKind, Motion, Skeleton};
    use nalgebra::{Matrix3, Rotation3, UnitQuaternion};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    const ROTATIONS: [Channel; 3] =
        [Channel::Rotation(Axis::X), Channel::Rotation(Axis::Y), Channel::Rotation(Axis::Z)];
    const POSITIONS: [Channel; 3] =
        [Channel::Position(Axis::X), Channel::Position(Axis::Y), Channel::Position(Axis::Z)];

    /// Builds a `Bvh` joint by joint, assigning channel columns in file order.
    #[derive(Default)]
    struct Builder {
        joints: Vec<Joint>,
        columns: usize,
    }

    impl Builder {
        fn add(
            &mut self,
            name: &str,
            parent: Option<usize>,
            offset: [f64; 3],
            channels: &[Channel],
        ) -> usize {
            let kind = match (parent, channels.is_empty()) {
                (None, _) => JointKind::Root,
                (Some(_), false) => JointKind::Joint,
                (Some(_), true) => JointKind::End,
            };
            self.joints.push(Joint {
                name: name.to_owned(),
                kind,
                parent: parent.map(JointId),
                offset,
                channels: channels.to_vec(),
                first_channel: self.columns,
            });
            self.columns += channels.len();
            self.joints.len() - 1
        }

        fn end(&mut self, parent: usize, offset: [f64; 3]) -> usize {
            let name = format!("{}_End", self.joints[parent].name);
            self.add(&name, Some(parent), offset, &[])
        }

        fn build(self, frames: Vec<Vec<f64>>) -> Bvh {
            let num_frames = frames.len();
            let values: Vec<f64> = frames.into_iter().flatten().collect();
            Bvh {
                skeleton: Skeleton { joints: self.joints },
                motion: Motion {
                    frame_time: 1.0 / 30.0,
                    num_frames,
                    num_channels: self.columns,
                    values,
                },
            }
        }
    }

    /// A random tree (parents first), random channel orders and motion.
    fn random_bvh(rng: &mut ChaCha8Rng, num_joints: usize, num_frames: usize) -> Bvh {
        let mut b = Builder::default();
        let mut ids = Vec::new(); // joints that can be parents (not End Sites)
        for i in 0..num_joints {
            let parent = (i > 0).then(|| ids[rng.gen_range(0..i)]);
            let offset = std::array::from_fn(|_| rng.gen_range(-40.0..40.0));
            let mut rotations = ROTATIONS.to_vec();
            for k in (1..3).rev() {
                rotations.swap(k, rng.gen_range(0..=k));
            }
            let mut channels = match (parent, rng.gen_range(0..4)) {
                (None, _) | (_, 0) => POSITIONS.to_vec(),
                _ => Vec::new(),
            };
            channels.extend(rotations.iter().take(rng.gen_range(1..=3)));
            let id = b.add(&format!("j{i}"), parent, offset, &channels);
            ids.push(id);
            if rng.gen_bool(0.3) {
                b.end(id, std::array::from_fn(|_| rng.gen_range(-10.0..10.0)));
            }
        }
        let columns = b.columns;
        let frames = (0..num_frames)
            .map(|_| (0..columns).map(|_| rng.gen_range(-200.0..200.0)).collect())
            .collect();
        b.build(frames)
    }

    fn axis_matrix(channel: Channel, degrees: f64) -> Matrix3<f64> {
        let axis = match channel {
            Channel::Rotation(Axis::X) => Vector3::x_axis(),
            Channel::Rotation(Axis::Y) => Vector3::y_axis(),
            Channel::Rotation(Axis::Z) => Vector3::z_axis(),
            Channel::Position(_) | Channel::Scale(_) => return Matrix3::identity(),
        };
        Rotation3::from_axis_angle(&axis, degrees.to_radians()).into_inner()
    }

    /// Independent FK: rotation matrices chained parent to child, world = scale · R_axes;
    /// position channels read as `report` says ([`PositionReading`]).
    fn matrix_chain(
        bvh: &Bvh,
        frame: usize,
        axes: Matrix3<f64>,
        report: &FkReport,
    ) -> Vec<(Vector3<f64>, Matrix3<f64>)> {
        let row = bvh.motion.frame(frame);
        let mut global: Vec<(Vector3<f64>, Matrix3<f64>)> = Vec::new();
        for joint in &bvh.skeleton.joints {
            let read = report.position_channels.iter().find(|r| r.joint == joint.name);
            let reading = read.map_or(PositionReading::Local, |r| r.reading);
            let mut p = Vector3::from(joint.offset);
            let mut r = Matrix3::identity();
            for (k, &channel) in joint.channels.iter().enumerate() {
                let value = row[joint.first_channel + k];
                match (channel, reading) {
                    (Channel::Position(a), PositionReading::Added) => p[a as usize] += value,
                    (Channel::Position(a), _) => p[a as usize] = value,
                    (Channel::Rotation(_), _) => r *= axis_matrix(channel, value),
                    (Channel::Scale(_), _) => {}
                }
            }
            global.push(match joint.parent {
                None => (p, r),
                Some(JointId(i)) if reading == PositionReading::World => (p, global[i].1 * r),
                Some(JointId(i)) => (global[i].1 * p + global[i].0, global[i].1 * r),
            });
        }
        let scale = report.metres_per_unit;
        global.into_iter().map(|(p, r)| (axes * p * scale, axes * r)).collect()
    }

    #[test]
    fn fk_matches_an_independent_matrix_chain_on_random_skeletons() {
        let mut rng = ChaCha8Rng::seed_from_u64(0x5eed_f00d);
        let axes = [
            AxisConvention::YUp,
            AxisConvention::ZUp,
            AxisConvention::YUpFaceX,
            AxisConvention::Custom(UnitQuaternion::from_euler_angles(0.3, -1.2, 2.0)),
        ];
        for case in 0..60 {
            let num_joints = rng.gen_range(1..25);
            let bvh = random_bvh(&mut rng, num_joints, 8);
            let options = FkOptions {
                axes: axes[case % axes.len()],
                // Random channels in metres would teleport bodies by hundreds of metres per frame,
                // which `HumanMotion::validate` rightly refuses: file units are cm, mm, CMU's.
                units: UnitChoice::Scale([0.01, 0.001, 0.05644][case % 3]),
                ..FkOptions::default()
            };
            let (motion, report) = human_motion(&bvh, &options).unwrap();
            assert_eq!(motion.num_bodies(), bvh.skeleton.joints.len());
            for frame in 0..motion.num_frames {
                let expected =
                    matrix_chain(&bvh, frame, options.axes.world_from_file_matrix(), &report);
                for (body, (p, r)) in expected.iter().enumerate() {
                    let q = motion.orientation(frame, body);
                    assert!(
                        (motion.position(frame, body) - p).amax() < 1e-12,
                        "case {case} body {body}"
                    );
                    assert!(
                        (q.to_rotation_matrix().into_inner() - r).amax() < 1e-12,
                        "case {case} body {body}"
                    );
                    assert!((q.norm() - 1.0).abs() < 1e-14);
                    if frame > 0 {
                        assert!(
                            q.coords.dot(&motion.orientation(frame - 1, body).coords) >= 0.0,
                            "continuity"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn axis_conventions_are_proper_rotations_consistent_with_their_quaternions() {
        for axes in [AxisConvention::YUp, AxisConvention::ZUp, AxisConvention::YUpFaceX] {
            let m = axes.world_from_file_matrix();
            assert!((m.determinant() - 1.0).abs() < 1e-15, "{axes:?}");
            assert!(
                (axes.world_from_file().to_rotation_matrix().into_inner() - m).amax() < 1e-15,
                "{axes:?}"
            );
        }
        // GMR's conversion: (x, y, z) ↦ (x, −z, y).
        let p = AxisConvention::YUp.world_from_file_matrix() * Vector3::new(1.0, 2.0, 3.0);
        assert_eq!(p, Vector3::new(1.0, -3.0, 2.0));
        // YUpFaceX turns the BVH forward (+Z) into world +X and keeps up up.
        let m = AxisConvention::YUpFaceX.world_from_file_matrix();
        assert_eq!(m * Vector3::z(), Vector3::x());
        assert_eq!(m * Vector3::y(), Vector3::z());
    }

    /// A small Y-up T-pose facing +Z (BVH convention: the subject's left is +X), in cm.
    fn tpose(frames: Vec<Vec<f64>>) -> Bvh {
        let mut b = Builder::default();
        let hips =
            b.add("Hips", None, [0.0, 95.0, 0.0], &[POSITIONS.as_slice(), &ROTATIONS].concat());
        let spine = b.add("Spine", Some(hips), [0.0, 10.0, 0.0], &ROTATIONS);
        let head = b.add("Head", Some(spine), [0.0, 55.0, 0.0], &ROTATIONS);
        b.end(head, [0.0, 20.0, 0.0]);
        for (side, x) in [("Left", 10.0), ("Right", -10.0)] {
            let leg = b.add(&format!("{side}UpLeg"), Some(hips), [x, -5.0, 0.0], &ROTATIONS);
            let foot = b.add(&format!("{side}Foot"), Some(leg), [0.0, -82.0, 0.0], &ROTATIONS);
            let toe = b.add(&format!("{side}Toe"), Some(foot), [0.0, -8.0, 12.0], &ROTATIONS);
            b.end(toe, [0.0, 0.0, 4.0]);
        }
        b.build(frames)
    }

    fn still(bvh_channels: usize, root: [f64; 3]) -> Vec<f64> {
        let mut row = vec![0.0; bvh_channels];
        row[..3].copy_from_slice(&root);
        row
    }

    #[test]
    fn tpose_converts_to_z_up_metres_keeping_left_on_the_left() {
        let channels = tpose(Vec::new()).skeleton.num_channels();
        let bvh = tpose(vec![still(channels, [0.0, 95.0, 0.0]); 3]);
        let (motion, report) = human_motion(&bvh, &FkOptions::default()).unwrap();
        assert_eq!(report.metres_per_unit, 0.01);
        let at = |name: &str| *motion.position(0, motion.require_body(name).unwrap());
        // Facing: the toes point forward; left = up × forward.
        let forward = (at("LeftToe_End") - at("LeftToe")).normalize();
        let left = Vector3::z().cross(&forward);
        assert!(
            (forward - Vector3::new(0.0, -1.0, 0.0)).norm() < 1e-12,
            "GMR: BVH +Z becomes world -Y"
        );
        assert!((at("LeftFoot") - at("RightFoot")).dot(&left) > 0.19);
        assert!((at("Head_End").z - 1.80).abs() < 1e-12);
        assert!(report.ground.abs() < 1e-12);
        assert!((report.height - 1.80).abs() < 1e-12, "{report:?}");
        assert_eq!(report.height_source, "rest pose, head over lowest foot point");
    }

    #[test]
    fn default_derived_bodies_follow_gmr() {
        let channels = tpose(Vec::new()).skeleton.num_channels();
        let mut row = still(channels, [1.0, 90.0, 2.0]);
        row[3..].iter_mut().enumerate().for_each(|(i, v)| *v = (i as f64 * 7.0) % 50.0 - 25.0);
        let bvh = tpose(vec![row]);
        let (motion, _) = human_motion(&bvh, &FkOptions::default()).unwrap();
        let names = &motion.body_names;
        assert_eq!(&names[names.len() - 2..], ["LeftFootMod", "RightFootMod"]);
        for side in ["Left", "Right"] {
            let m = motion.require_body(&format!("{side}FootMod")).unwrap();
            let foot = motion.require_body(&format!("{side}Foot")).unwrap();
            let toe = motion.require_body(&format!("{side}Toe")).unwrap();
            assert_eq!(motion.position(0, m), motion.position(0, foot));
            assert_eq!(motion.orientation(0, m), motion.orientation(0, toe));
        }
    }

    #[test]
    fn unknown_names_are_errors_listing_the_bodies() {
        let bvh = tpose(vec![still(tpose(Vec::new()).skeleton.num_channels(), [0.0; 3])]);
        let options = FkOptions {
            derived: vec![DerivedBody::new("X", "LeftFoot", "LeftToeBase")],
            ..FkOptions::default()
        };
        let err = human_motion(&bvh, &options).unwrap_err();
        assert!(
            matches!(&err, Error::UnknownBody { name, available } if name == "LeftToeBase" && available.len() == 12)
        );
        assert!(
            err.to_string()
                .starts_with("unknown body `LeftToeBase`; available bodies: Hips, Spine, Head"),
            "{err}"
        );
        let (motion, _) = human_motion(&bvh, &FkOptions::default()).unwrap();
        assert!(motion.require_body("Nose").unwrap_err().to_string().contains("LeftFootMod"));
        // Defaults whose joints are missing are skipped.
        let mut b = Builder::default();
        b.add("Root", None, [0.0; 3], &ROTATIONS);
        let (motion, _) =
            human_motion(&b.build(vec![vec![0.0; 3]]), &FkOptions::default()).unwrap();
        assert_eq!(motion.body_names, ["Root"]);
    }

    #[test]
    fn bad_input_is_an_error_not_a_panic() {
        let channels = tpose(Vec::new()).skeleton.num_channels();
        let mut bvh = tpose(vec![still(channels, [0.0; 3]); 2]);
        bvh.motion.values[channels + 4] = f64::NAN;
        let err = human_motion(&bvh, &FkOptions::default()).unwrap_err();
        assert_eq!(err.to_string(), "frame 1: channel Yrotation of joint `Hips` is NaN");
        bvh.motion.values.pop();
        assert!(matches!(
            human_motion(&bvh, &FkOptions::default()),
            Err(Error::MotionShape { .. })
        ));
        let bvh = tpose(vec![still(channels, [0.0; 3])]);
        for units in [UnitChoice::Scale(0.0), UnitChoice::Scale(f64::NAN)] {
            let options = FkOptions { units, ..FkOptions::default() };
            assert!(matches!(human_motion(&bvh, &options), Err(Error::InvalidOption { .. })));
        }
        let options = FkOptions { height: Some(-1.0), ..FkOptions::default() };
        assert!(matches!(human_motion(&bvh, &options), Err(Error::InvalidOption { .. })));
        assert!(matches!(
            human_motion(&Bvh::default(), &FkOptions::default()),
            Err(Error::EmptySkeleton)
        ));
        let mut bad = bvh.clone();
        bad.motion.frame_time = 0.0;
        assert!(matches!(human_motion(&bad, &FkOptions::default()), Err(Error::BadFrameTime(_))));
        let mut bad = bvh.clone();
        bad.skeleton.joints[1].parent = Some(JointId(5));
        assert!(matches!(human_motion(&bad, &FkOptions::default()), Err(Error::BadParent { .. })));
        let mut bad = bvh;
        bad.skeleton.joints[2].first_channel = channels;
        assert!(matches!(
            human_motion(&bad, &FkOptions::default()),
            Err(Error::ChannelOutOfRange { .. })
        ));
    }

    #[test]
    fn units_are_chosen_from_the_skeleton_size_or_forced() {
        let channels = tpose(Vec::new()).skeleton.num_channels();
        for (scale, expected) in
            [(1.0, 0.01), (0.01, 1.0), (1.0 / 2.54, 0.0254), (1.0 / 5.644, 0.05644), (10.0, 0.001)]
        {
            let mut bvh = tpose(vec![still(channels, [0.0, 95.0 * scale, 0.0])]);
            bvh.skeleton
                .joints
                .iter_mut()
                .for_each(|j| j.offset.iter_mut().for_each(|v| *v *= scale));
            let (motion, report) = human_motion(&bvh, &FkOptions::default()).unwrap();
            assert_eq!(report.metres_per_unit, expected, "{}", report.unit_reason);
            assert!((report.height - 1.80).abs() < 1e-9, "{report:?}");
            let head = motion.require_body("Head_End").unwrap();
            assert!((motion.position(0, head).z - 1.80).abs() < 1e-9);
        }
        let bvh = tpose(vec![still(channels, [0.0; 3])]);
        let options =
            FkOptions { units: UnitChoice::Scale(0.5), height: Some(1.7), ..FkOptions::default() };
        let (_, report) = human_motion(&bvh, &options).unwrap();
        assert_eq!((report.metres_per_unit, report.height), (0.5, 1.7));
        assert!(report.unit_reason.starts_with("forced"));
    }

    #[test]
    fn a_declared_unit_holds_for_human_sizes_and_gives_way_to_proportions() {
        let channels = tpose(Vec::new()).skeleton.num_channels();
        let mut heights = Vec::new();
        for scale in [1.0, 1.0 / 3.0, 2.7] {
            // A 1.8 m figure (cm), a 0.6 m one and a 4.9 m one, all declared centimetres.
            let mut bvh = tpose(vec![still(channels, [0.0, 95.0 * scale, 0.0])]);
            bvh.skeleton
                .joints
                .iter_mut()
                .for_each(|j| j.offset.iter_mut().for_each(|v| *v *= scale));
            let options = FkOptions { units: UnitChoice::Declared(0.01), ..FkOptions::default() };
            let (_, report) = human_motion(&bvh, &options).unwrap();
            let kind = if scale == 1.0 { "declared" } else { "scaled" };
            assert!(report.unit_reason.starts_with(kind), "{}", report.unit_reason);
            if scale == 1.0 {
                assert_eq!(report.metres_per_unit, 0.01);
            } else {
                // Scaled by the proportions: the same size whatever the file's size.
                heights.push((report.height, report.metres_per_unit * scale));
            }
        }
        assert!((heights[0].0 - heights[1].0).abs() < 1e-9, "{heights:?}");
        assert!((heights[0].1 - heights[1].1).abs() < 1e-12, "{heights:?}");
        assert!((1.5..2.1).contains(&heights[0].0), "{heights:?}");
    }

    #[test]
    fn axis_conventions_from_matrices_are_the_named_ones_when_they_equal_them() {
        for axes in [AxisConvention::YUp, AxisConvention::ZUp, AxisConvention::YUpFaceX] {
            assert_eq!(AxisConvention::from_matrix(&axes.world_from_file_matrix()), Some(axes));
        }
        let q = UnitQuaternion::from_euler_angles(0.3, -1.2, 2.0);
        let m = q.to_rotation_matrix().into_inner();
        match AxisConvention::from_matrix(&m) {
            Some(AxisConvention::Custom(c)) => assert!(c.angle_to(&q) < 1e-12),
            other => panic!("{other:?}"),
        }
        assert_eq!(AxisConvention::from_matrix(&-Matrix3::identity()), None, "a mirror");
    }

    #[test]
    fn fps_snaps_to_the_integer_the_frame_time_rounds() {
        let mut bvh = tpose(Vec::new());
        for (t, fps) in [
            (0.033333, 30.0),
            (0.0083333, 120.0),
            (0.008333, 120.0),
            (0.04, 25.0),
            (0.3, 1.0 / 0.3),
        ] {
            bvh.motion.frame_time = t;
            assert_eq!(frames_per_second(&bvh).unwrap(), fps, "{t}");
        }
    }

    #[test]
    fn centimetres_divide_by_100_like_gmr() {
        assert_eq!(Scale::from_metres_per_unit(0.01), Scale::Divide(100.0));
        assert_eq!(Scale::from_metres_per_unit(0.001), Scale::Divide(1000.0));
        assert_eq!(Scale::from_metres_per_unit(1.0), Scale::Multiply(1.0));
        assert_eq!(Scale::from_metres_per_unit(0.05644), Scale::Multiply(0.05644));
    }
}
