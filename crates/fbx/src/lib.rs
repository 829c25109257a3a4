//! FBX skeletal animation: the skeleton and every take of a file, sampled with FBX's
//! transform semantics, as the same [`bvh::Bvh`] our BVH path reads, so that the rest of the
//! pipeline (`fk`, the retargeter) is unchanged.
//!
//! ```text
//! Fbx::from_path(p)? -> info() (exporter, axes, units, rate, takes, skeleton)
//!                    -> select_take(None | "name" | "index")? -> bvh(take)?  (file axes and units)
//! ```
//!
//! Reading and evaluation are [ufbx](https://github.com/ufbx/ufbx) (through the `ufbx`
//! crate): binary FBX 6.x and 7.x (7.5+ 64-bit offsets), ASCII, every animation stack,
//! curves evaluated as the FBX SDK does (cubic and linear keys, extrapolation outside the
//! keys), and the full transform chain (`Lcl Translation`, pre-/post-rotation, rotation
//! order, rotation and scaling pivots and offsets, inherit type). We chose it over `fbxcel`
//! (pure Rust, binary 7.4/7.5 tokens only, the semantics left to us): see `docs/fbx.md` for
//! the measurements. A dependency's `unsafe` (the C loader) is fine; this crate has none.
//!
//! The file's conventions (frame rate, frame grid, axis system, units) are interpreted in
//! [`conventions`]; the conversion to metres and Z up happens once, in `fk`, with
//! [`Info::world_from_file`] and [`Info::metres_per_unit`].
//!
//! This crate does no printing, never panics on input, and knows nothing of robots.

// Library code never panics on input (issue 15): the compiler checks it. Tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

pub mod conventions;
mod error;
mod math;
mod sample;
mod scene;

use std::path::Path;

use nalgebra::UnitQuaternion;

pub use conventions::{Axes, SignedAxis};
pub use error::Error;
pub use sample::{Poses, MAX_NODE_SAMPLES};
pub use scene::{Info, Node, NodeKind, TakeInfo};

/// A loaded FBX file: its [`Info`] and what is needed to sample its takes.
pub struct Fbx {
    scene: ufbx::SceneRoot,
    file: String,
    info: Info,
    node_ids: Vec<usize>,
    rest: Vec<UnitQuaternion<f64>>,
    /// ufbx's memory limit for evaluating the scene (as for loading it).
    memory_limit: usize,
    /// Every skeleton node inherits its parent's transform normally (`InheritType` RSrs):
    /// world matrices are chained from local ones ([`Fbx::poses_at`]).
    normal_inheritance: bool,
}

impl std::fmt::Debug for Fbx {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Fbx").field("file", &self.file).field("info", &self.info).finish()
    }
}

/// Which take [`Fbx::select_take`] chose, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Selected {
    pub index: usize,
    pub name: String,
    /// "asked for", "the only take", or "the most motion of 3 takes".
    pub reason: String,
}

/// At most this many evenly spaced frames of each take measure its motion.
const MOTION_SAMPLES: usize = 32;

impl Fbx {
    /// Reads the FBX file at `path`; errors name it.
    pub fn from_path(path: &Path) -> Result<Fbx, Error> {
        let bytes =
            std::fs::read(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
        Fbx::from_bytes(&bytes, &path.display().to_string())
    }

    /// Reads FBX bytes; `file` names them in errors.
    pub fn from_bytes(bytes: &[u8], file: &str) -> Result<Fbx, Error> {
        let loaded = scene::load(bytes, file)?;
        if loaded.info.world_from_file().is_none() {
            return Err(Error::Axes { file: file.to_owned(), axes: loaded.info.axes.to_string() });
        }
        let (rest, _from_bind) = scene::rest_rotations(&loaded.scene, &loaded.node_ids);
        let normal_inheritance = scene::normal_inheritance(&loaded.scene, &loaded.node_ids);
        Ok(Fbx {
            scene: loaded.scene,
            file: file.to_owned(),
            info: loaded.info,
            node_ids: loaded.node_ids,
            rest,
            memory_limit: scene::memory_limit(bytes.len()),
            normal_inheritance,
        })
    }

    #[must_use]
    pub fn info(&self) -> &Info {
        &self.info
    }

    /// The name the file goes by in errors.
    #[must_use]
    pub fn file(&self) -> &str {
        &self.file
    }

    /// The take `selector` names (its name, else its index in [`Info::takes`]), or with
    /// `None` the take with the most motion (the sum of the skeleton's joint paths over up to
    /// 32 frames; the first of equals). Errors: no take at all, an unknown
    /// take, or (default) no take with keys.
    pub fn select_take(&self, selector: Option<&str>) -> Result<Selected, Error> {
        let takes = &self.info.takes;
        if takes.is_empty() {
            return Err(Error::NoAnimation { file: self.file.clone() });
        }
        let pick =
            |index: usize, reason: String| Selected { index, name: self.take_name(index), reason };
        if let Some(wanted) = selector {
            let by_name = takes.iter().position(|t| t.name == wanted);
            let by_index = wanted.trim().parse::<usize>().ok().filter(|&i| i < takes.len());
            return match by_name.or(by_index) {
                Some(i) => Ok(pick(i, "asked for".to_owned())),
                None => Err(Error::UnknownTake {
                    file: self.file.clone(),
                    take: wanted.to_owned(),
                    available: self.takes_list(),
                }),
            };
        }
        let keyed: Vec<usize> = (0..takes.len()).filter(|&i| self.has_keys(i)).collect();
        match keyed.as_slice() {
            [] => Err(Error::EmptyTake { file: self.file.clone(), take: self.take_name(0) }),
            [only] if takes.len() == 1 => Ok(pick(*only, "the only take".to_owned())),
            [only] => Ok(pick(*only, format!("the only one of {} takes with keys", takes.len()))),
            _ => {
                let mut best = (0.0, usize::MAX);
                for &i in &keyed {
                    let score = self.motion(i)?;
                    if best.1 == usize::MAX || score > best.0 {
                        best = (score, i);
                    }
                }
                Ok(pick(best.1, format!("the most motion of {} takes", takes.len())))
            }
        }
    }

    /// How much take `take` moves: the summed path of every node over up to
    /// 32 of its frames, in file units.
    pub fn motion(&self, take: usize) -> Result<f64, Error> {
        let times = self.frame_times(take)?;
        let count = times.len().min(MOTION_SAMPLES);
        let picked: Vec<f64> = (0..count)
            .filter_map(|k| {
                times.get(if count > 1 { k * (times.len() - 1) / (count - 1) } else { 0 })
            })
            .copied()
            .collect();
        let poses = self.poses_at(take, &picked)?;
        let n = poses.num_nodes;
        let path = poses
            .positions
            .iter()
            .skip(n)
            .zip(&poses.positions)
            .map(|(now, before)| (now - before).norm())
            .sum();
        Ok(path)
    }

    fn has_keys(&self, take: usize) -> bool {
        self.info.takes.get(take).is_some_and(|t| t.keys.is_some())
    }

    fn take_info(&self, take: usize) -> Result<&TakeInfo, Error> {
        self.info.takes.get(take).ok_or_else(|| Error::UnknownTake {
            file: self.file.clone(),
            take: take.to_string(),
            available: self.takes_list(),
        })
    }

    fn take_name(&self, take: usize) -> String {
        self.info.takes.get(take).map_or_else(|| take.to_string(), |t| t.name.clone())
    }

    /// "0 `walk`, 1 `run`" (or "none").
    fn takes_list(&self) -> String {
        if self.info.takes.is_empty() {
            return "none".to_owned();
        }
        let list: Vec<String> =
            self.info.takes.iter().enumerate().map(|(i, t)| format!("{i} `{}`", t.name)).collect();
        list.join(", ")
    }
}

/// Names a BVH file can hold: whitespace becomes `_` (as Blender's BVH exporter writes
/// them), and names made equal by that get `.2`, `.3`, ... For [`bvh::write`] of an
/// [`Fbx::bvh`], whose names are the file's (`bras droit`, `Bip01 L Thigh`).
pub fn bvh_safe_names(bvh: &mut bvh::Bvh) {
    let mut seen = std::collections::BTreeMap::<String, usize>::new();
    for joint in &mut bvh.skeleton.joints {
        let base: String = joint
            .name
            .chars()
            .map(|c| if c.is_whitespace() || c == '{' || c == '}' { '_' } else { c })
            .collect();
        let count = seen.entry(base.clone()).or_insert(0);
        *count += 1;
        joint.name = if *count == 1 { base } else { format!("{base}.{count}") };
    }
}
