//! Output writers: a [`RobotMotion`] to `.npz` (numpy, the default), Unitree's `.csv`, GMR's
//! `.pkl` and a human-readable `.json`; and readers, for the report: our `.npz`
//! ([`read_motion_npz`]) and other tools' motions ([`read_motion`]: `.npz` of `qpos`,
//! BeyondMimic's `.npz`, GMR's `.pkl`, Unitree's `.csv`).
//!
//! Every file is in the world frame of the pipeline: Z up, metres, radians. Quaternions are
//! w-first in our own files (`.npz`, `.json`); the two formats that define x y z w (the
//! Unitree CSV root and GMR's `root_rot`) are converted by `xyzw_from_wxyz` and nowhere else.
//!
//! Files are written atomically: into a temporary file next to the target, flushed to disk,
//! then renamed over it. On error the temporary file is removed, so an interrupted or failed
//! run never leaves a half-written file under the final name.

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

mod csv;
mod derived;
mod json;
mod npz;
mod pickle;
mod read;
mod root;
mod unpickle;

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

use crate::motion::RobotMotion;
use crate::Error;

pub(crate) use derived::{body_poses, gradient_pair, gradient_rows, BodyPoses};
pub use npz::{read_motion_npz, read_motion_npz_bytes, read_npz_robot};
pub use read::{read_motion, read_motion_bytes, FpsFrom, MotionFormat, MotionSource};

/// Output formats, chosen by file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Format {
    /// numpy `.npz`: `qpos`, names and BeyondMimic's keys (see [`write_motion`]).
    Npz,
    /// Unitree's LAFAN1-retargeting CSV: `x y z qx qy qz qw joints…` per line, no header.
    Csv,
    /// GMR's pickle: `fps`, `root_pos`, `root_rot` (x y z w), `dof_pos`, `local_body_pos`,
    /// `link_body_list`.
    Pkl,
    /// Everything, human-readable.
    Json,
}

impl Format {
    /// The format of a path by its extension (case-insensitive): `npz`, `csv`, `pkl`
    /// (or `pickle`), `json`.
    #[must_use]
    pub fn from_path(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "npz" => Some(Format::Npz),
            "csv" => Some(Format::Csv),
            "pkl" | "pickle" => Some(Format::Pkl),
            "json" => Some(Format::Json),
            _ => None,
        }
    }

    /// The usual extension, without the dot.
    #[must_use]
    pub const fn extension(self) -> &'static str {
        match self {
            Format::Npz => "npz",
            Format::Csv => "csv",
            Format::Pkl => "pkl",
            Format::Json => "json",
        }
    }
}

/// Writes `motion` to `path` in `format` (by default the one of the extension), atomically.
///
/// `model` is the robot the motion was solved for: it gives the body poses (forward
/// kinematics) that `.npz` and `.pkl` carry, and must match the motion (`nq`, body names).
///
/// `.npz` keys (float64 little-endian, names as numpy unicode arrays, T frames, B bodies
/// without the world, K target bodies; loads with `numpy.load(path, allow_pickle=False)`):
/// - `fps` (shape `(1,)`, as BeyondMimic writes it), `qpos` (T×nq), `joint_names`,
///   `body_names`, `robot` (0-d string: the MJCF `model` attribute, when the model has one);
/// - BeyondMimic's: `joint_pos` (T×(nq−7): `qpos` after the free root), `joint_vel` (same
///   shape), `body_pos_w` (T×B×3), `body_quat_w` (T×B×4, w x y z), `body_lin_vel_w` and
///   `body_ang_vel_w` (T×B×3, world frame);
/// - when the motion has targets: `target_body_names`, `target_pos` (T×K×3), `target_quat`
///   (T×K×4, w x y z).
///
/// Velocities are finite differences with numpy's `gradient` scheme: central differences
/// `(x[t+1] − x[t−1]) / 2Δt` inside, one-sided `(x[1] − x[0]) / Δt` and
/// `(x[T−1] − x[T−2]) / Δt` at the ends, zero for a single frame. Angular velocity is the
/// same scheme on rotations: `log(q[b] q[a]⁻¹) / ((b − a) Δt)`, the world-frame rotation
/// vector between the two frames (shortest way).
pub fn write_motion(
    path: &Path,
    motion: &RobotMotion,
    model: &mjcf::Model,
    format: Option<Format>,
) -> Result<(), Error> {
    let format = match format.or_else(|| Format::from_path(path)) {
        Some(f) => f,
        None => return Err(Error::UnknownFormat { path: path.to_path_buf() }),
    };
    check_motion(motion, model)?;
    match format {
        Format::Npz => {
            let arrays = npz::motion_arrays(motion, model);
            write_atomically(path, |w| ::npz::write(w, &arrays))
        }
        Format::Csv => write_atomically(path, |w| csv::write_csv(w, motion, model)),
        Format::Pkl => {
            let bytes = pickle::motion_pickle(motion, model)?;
            write_atomically(path, |w| w.write_all(&bytes))
        }
        Format::Json => write_atomically(path, |w| json::write_json(w, motion, model)),
    }
}

/// Writes `arrays` (name, array, in file order) as an `.npz` in numpy's `savez` layout
/// ([`::npz::write()`]), atomically ([`write_atomically`]): for arrays other than a robot
/// motion's (the CLI's export of a human motion).
pub fn write_npz(path: &Path, arrays: &[(&str, ::npz::Array)]) -> Result<(), Error> {
    write_atomically(path, |w| ::npz::write(w, arrays))
}

/// The arrays [`write_motion`] puts in an `.npz`, in file order, by key (checked as
/// `write_motion` checks): what the Python package hands over as numpy arrays.
pub fn npz_arrays(
    motion: &RobotMotion,
    model: &mjcf::Model,
) -> Result<Vec<(&'static str, ::npz::Array)>, Error> {
    check_motion(motion, model)?;
    Ok(npz::motion_arrays(motion, model))
}

/// Checks that `motion` is one of `model`'s and holds only finite numbers.
pub(crate) fn check_motion(motion: &RobotMotion, model: &mjcf::Model) -> Result<(), Error> {
    if motion.nq != model.nq {
        return Err(Error::Mismatch(format!("motion nq {} but model nq {}", motion.nq, model.nq)));
    }
    if motion.qpos.len().checked_rem(motion.nq) != Some(0) {
        return Err(Error::Mismatch(format!(
            "qpos length {} is not a multiple of nq {}",
            motion.qpos.len(),
            motion.nq
        )));
    }
    let model_bodies = model.bodies.iter().skip(1).map(|b| b.name.as_str());
    if !motion.body_names.iter().map(String::as_str).eq(model_bodies) {
        return Err(Error::Mismatch("body names differ from the model's".to_owned()));
    }
    if !(motion.fps.is_finite() && motion.fps > 0.0) {
        return Err(Error::Mismatch(format!("fps {} is not positive", motion.fps)));
    }
    if let Some(i) = motion.qpos.iter().position(|v| !v.is_finite()) {
        let (frame, index) = (i / motion.nq, i % motion.nq);
        let value = motion.qpos.get(i).copied().unwrap_or(f64::NAN);
        return Err(Error::NonFiniteQpos { frame, index, value });
    }
    if let Some(t) = &motion.targets {
        let expected = motion.num_frames() * t.body_names.len();
        if t.pos.len() != expected || t.quat.len() != expected {
            return Err(Error::Mismatch(format!(
                "targets hold {} positions and {} orientations, expected {expected}",
                t.pos.len(),
                t.quat.len()
            )));
        }
    }
    Ok(())
}

static TEMP_COUNTER: AtomicUsize = AtomicUsize::new(0);

/// Writes through `fill` into `.<name>.tmp-<pid>-<n>` next to `path`, syncs, renames it to
/// `path`; removes the temporary file on any error. Every output of the project goes through
/// this one function (the CLI's too), so a killed run leaves only `.<name>.tmp-*` files.
pub fn write_atomically<F>(path: &Path, fill: F) -> Result<(), Error>
where
    F: FnOnce(&mut BufWriter<File>) -> std::io::Result<()>,
{
    let io_error = |source| Error::File { path: path.to_path_buf(), source };
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let n = TEMP_COUNTER.fetch_add(1, Ordering::Relaxed);
    let tmp = path.with_file_name(format!(".{name}.tmp-{}-{n}", std::process::id()));
    let file = File::create(&tmp).map_err(io_error)?;
    let mut writer = BufWriter::new(file);
    let result = fill(&mut writer)
        .and_then(|()| writer.into_inner().map_err(std::io::IntoInnerError::into_error))
        .and_then(|file| file.sync_all())
        .and_then(|()| std::fs::rename(&tmp, path));
    if let Err(source) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(io_error(source));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_by_extension() {
        assert_eq!(Format::from_path(Path::new("a/b.NPZ")), Some(Format::Npz));
        assert_eq!(Format::from_path(Path::new("b.csv")), Some(Format::Csv));
        assert_eq!(Format::from_path(Path::new("b.pkl")), Some(Format::Pkl));
        assert_eq!(Format::from_path(Path::new("b.json")), Some(Format::Json));
        assert_eq!(Format::from_path(Path::new("b.bvh")), None);
        assert_eq!(Format::from_path(Path::new("npz")), None);
    }

    #[test]
    fn failed_writes_leave_nothing_behind() {
        let dir = std::env::temp_dir().join(format!("retarget-atomic-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("out.csv");
        let result = write_atomically(&path, |w| {
            w.write_all(b"partial")?;
            Err(std::io::Error::other("interrupted"))
        });
        assert!(result.is_err());
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
        write_atomically(&path, |w| w.write_all(b"whole")).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"whole");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
