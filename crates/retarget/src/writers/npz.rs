//! Our `.npz`: a motion's arrays (written by the `npz` crate) and the motion read back from
//! them.

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use std::collections::BTreeMap;
use std::path::Path;

use ::npz::{Array, Npz};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

use super::derived::{angular_velocity, body_poses, gradient_rows};
use super::root::root_nq;
use crate::motion::{FootContacts, RobotMotion, TrackedTargets};
use crate::Error;

/// The arrays of a motion's `.npz`, in file order (see [`super::write_motion`]).
pub(crate) fn motion_arrays(
    motion: &RobotMotion,
    model: &mjcf::Model,
) -> Vec<(&'static str, Array)> {
    let frames = motion.num_frames();
    let dt = 1.0 / motion.fps;
    let mut arrays = vec![
        ("fps", Array::f64(vec![1], vec![motion.fps])),
        ("qpos", Array::f64(vec![frames, motion.nq], motion.qpos.clone())),
        ("joint_names", Array::strings(&motion.joint_names)),
        ("body_names", Array::strings(&motion.body_names)),
    ];
    if !model.name.is_empty() {
        arrays.push(("robot", Array::scalar_string(&model.name)));
    }
    let skip = root_nq(model);
    let cols = motion.nq - skip;
    let joint_pos: Vec<f64> = (0..frames)
        .flat_map(|t| motion.frame(t).get(skip..).unwrap_or_default().to_vec())
        .collect();
    let joint_vel = gradient_rows(&joint_pos, cols, dt);
    arrays.push(("joint_pos", Array::f64(vec![frames, cols], joint_pos)));
    arrays.push(("joint_vel", Array::f64(vec![frames, cols], joint_vel)));

    let poses = body_poses(motion, model);
    let b = poses.bodies;
    let flat_pos: Vec<f64> = poses.pos.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
    let lin_vel = gradient_rows(&flat_pos, b * 3, dt);
    let ang_vel: Vec<f64> =
        angular_velocity(&poses.quat, b, dt).iter().flat_map(|w| [w.x, w.y, w.z]).collect();
    arrays.push(("body_pos_w", Array::f64(vec![frames, b, 3], flat_pos)));
    arrays.push(("body_quat_w", Array::f64(vec![frames, b, 4], wxyz_flat(&poses.quat))));
    arrays.push(("body_lin_vel_w", Array::f64(vec![frames, b, 3], lin_vel)));
    arrays.push(("body_ang_vel_w", Array::f64(vec![frames, b, 3], ang_vel)));

    if let Some(targets) = &motion.targets {
        let k = targets.body_names.len();
        let pos = targets.pos.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
        arrays.push(("target_body_names", Array::strings(&targets.body_names)));
        arrays.push(("target_pos", Array::f64(vec![frames, k, 3], pos)));
        arrays.push(("target_quat", Array::f64(vec![frames, k, 4], wxyz_flat(&targets.quat))));
    }
    if let Some(contacts) = &motion.contacts {
        arrays.push(("contact_left", Array::bools(&contacts.left)));
        arrays.push(("contact_right", Array::bools(&contacts.right)));
    }
    arrays
}

fn wxyz_flat(quats: &[UnitQuaternion<f64>]) -> Vec<f64> {
    quats.iter().flat_map(|q| [q.w, q.i, q.j, q.k]).collect()
}

/// Every `<key>.npy` of the `.npz` at `path`, by key.
fn read_npz(path: &Path) -> Result<BTreeMap<String, Array>, Error> {
    Ok(Npz::open(path)?.arrays()?)
}

/// Reads a motion back from an `.npz` written by [`super::write_motion`] (or any `.npz` with
/// `fps` (one number), `qpos` (T×nq), `joint_names`, `body_names` and optionally
/// `target_body_names`, `target_pos` (T×K×3), `target_quat` (T×K×4, w first), and
/// `contact_left`, `contact_right` (T bools)).
pub fn read_motion_npz(path: &Path) -> Result<RobotMotion, Error> {
    motion_from_arrays(&read_npz(path)?, path)
}

/// [`read_motion_npz`] on the bytes of an `.npz` (`name` is used in errors).
pub fn read_motion_npz_bytes(bytes: &[u8], name: &Path) -> Result<RobotMotion, Error> {
    let arrays = Npz::new(std::io::Cursor::new(bytes), name)?.arrays()?;
    motion_from_arrays(&arrays, name)
}

fn motion_from_arrays(arrays: &BTreeMap<String, Array>, path: &Path) -> Result<RobotMotion, Error> {
    let err = |message: String| Error::Read { path: path.to_path_buf(), message };
    let get = |key: &str| arrays.get(key).ok_or_else(|| err(format!("no `{key}` array")));
    let fps = match get("fps")?.as_f64() {
        Some([fps]) => *fps,
        _ => return Err(err("`fps` is not a single number".to_owned())),
    };
    let qpos = get("qpos")?;
    let (Some(values), [frames, nq]) = (qpos.as_f64(), qpos.shape.as_slice()) else {
        return Err(err("`qpos` is not a 2-D float array".to_owned()));
    };
    let joint_names =
        get("joint_names")?.as_strings().ok_or_else(|| err("bad `joint_names`".into()))?;
    let body_names =
        get("body_names")?.as_strings().ok_or_else(|| err("bad `body_names`".into()))?;
    let targets = match arrays.get("target_body_names") {
        None => None,
        Some(names) => Some(
            read_targets(names, get("target_pos")?, get("target_quat")?, *frames).map_err(err)?,
        ),
    };
    let contacts = match (arrays.get("contact_left"), arrays.get("contact_right")) {
        (None, None) => None,
        (Some(l), Some(r)) => Some(read_contacts(l, r, *frames).map_err(err)?),
        _ => return Err(err("only one of `contact_left` and `contact_right`".to_owned())),
    };
    Ok(RobotMotion {
        fps,
        nq: *nq,
        qpos: values.to_vec(),
        joint_names: joint_names.to_vec(),
        body_names: body_names.to_vec(),
        targets,
        contacts,
    })
}

/// The `robot` name stored in an `.npz` by [`super::write_motion`], if any.
pub fn read_npz_robot(path: &Path) -> Result<Option<String>, Error> {
    let arrays = read_npz(path)?;
    Ok(arrays.get("robot").and_then(Array::as_strings).and_then(|s| s.first().cloned()))
}

pub(super) fn read_targets(
    names: &Array,
    pos: &Array,
    quat: &Array,
    frames: usize,
) -> Result<TrackedTargets, String> {
    let names = names.as_strings().ok_or("bad `target_body_names`")?;
    let k = names.len();
    let (Some(p), Some(q)) = (pos.as_f64(), quat.as_f64()) else {
        return Err("`target_pos` and `target_quat` must be float arrays".to_owned());
    };
    if pos.shape != [frames, k, 3] || quat.shape != [frames, k, 4] {
        return Err(format!(
            "target arrays have shapes {:?} and {:?}, expected ({frames}, {k}, 3) and ({frames}, {k}, 4)",
            pos.shape, quat.shape
        ));
    }
    let pos = p.chunks_exact(3).map(Vector3::from_column_slice).collect();
    let quat = q
        .chunks_exact(4)
        .map(|c| {
            let &[w, x, y, z] = c else {
                return Err("a target quaternion has not 4 numbers".to_owned());
            };
            let q = Quaternion::new(w, x, y, z);
            match q.norm() {
                n if (n - 1.0).abs() < 1e-9 => Ok(UnitQuaternion::new_unchecked(q)),
                n if n > 1e-9 && n.is_finite() => Ok(UnitQuaternion::new_normalize(q)),
                _ => Err("a target quaternion is zero or not finite".to_owned()),
            }
        })
        .collect::<Result<_, _>>()?;
    Ok(TrackedTargets { body_names: names.to_vec(), pos, quat })
}

pub(super) fn read_contacts(
    left: &Array,
    right: &Array,
    frames: usize,
) -> Result<FootContacts, String> {
    let side = |a: &Array, key: &str| match a.as_bools() {
        Some(v) if a.shape == [frames] => Ok(v.to_vec()),
        _ => Err(format!("`{key}` is not a bool array of {frames} frames")),
    };
    Ok(FootContacts {
        left: side(left, "contact_left")?,
        right: side(right, "contact_right")?,
        on_toes: None,
    })
}
