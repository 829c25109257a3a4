//! The robots and IK configs that ship with the library, compiled in: per robot key the
//! mesh-free MJCF (`robots/<key>/<key>.xml`), its joint speed limits
//! (`robots/<key>/joint_speed_limits.json`) and GMR's tuned config for LAFAN1-named skeletons
//! (`configs/bvh_lafan1_to_<key>.json`); and how a robot argument (a shipped key, an MJCF or a
//! URDF path) becomes an [`mjcf::Model`].

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use std::path::Path;

use mjcf::Model;

use crate::config::IkConfig;
use crate::joint_speed::JointSpeedLimits;
use crate::Error;

/// One shipped robot: its key and the texts compiled in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShippedRobot {
    /// The name users type (`unitree_g1`), GMR's robot name.
    pub key: &'static str,
    /// `robots/<key>/<key>.xml`.
    pub mjcf: &'static str,
    /// `robots/<key>/joint_speed_limits.json`.
    pub joint_speed_limits: &'static str,
    /// `configs/bvh_lafan1_to_<key>.json`: GMR's tuned IK config for LAFAN1-named skeletons.
    pub config: &'static str,
}

macro_rules! shipped {
    ($key:literal) => {
        ShippedRobot {
            key: $key,
            mjcf: include_str!(concat!("../../../robots/", $key, "/", $key, ".xml")),
            joint_speed_limits: include_str!(concat!(
                "../../../robots/",
                $key,
                "/joint_speed_limits.json"
            )),
            config: include_str!(concat!("../../../configs/bvh_lafan1_to_", $key, ".json")),
        }
    };
}

/// Every shipped robot, sorted by key.
pub const ROBOTS: &[ShippedRobot] = &[
    shipped!("booster_t1_29dof"),
    shipped!("engineai_pm01"),
    shipped!("fourier_n1"),
    shipped!("stanford_toddy"),
    shipped!("unitree_g1"),
    shipped!("unitree_h1"),
];

/// GMR's SMPL-X configs of the shipped robots that have one (`configs/smplx_to_<key>.json`,
/// GMR's `smplx_to_*.json` reformatted), for SMPL-X and SMPL+H motions, by robot key.
pub(crate) const SMPLX_CONFIGS: &[(&str, &str)] = &[
    ("booster_t1_29dof", include_str!("../../../configs/smplx_to_booster_t1_29dof.json")),
    ("unitree_g1", include_str!("../../../configs/smplx_to_unitree_g1.json")),
];

/// The SMPL-X config of the shipped robot `key` (`SMPLX_CONFIGS`), named by its path in
/// the repository; `None` when it has none.
#[must_use]
pub fn smplx_config(key: &str) -> Option<Result<IkConfig, Error>> {
    SMPLX_CONFIGS
        .iter()
        .find(|(k, _)| *k == key)
        .map(|(k, text)| IkConfig::from_json_str(text, &format!("configs/smplx_to_{k}.json")))
}

/// The shipped robot `key`, if there is one.
#[must_use]
pub fn find(key: &str) -> Option<&'static ShippedRobot> {
    ROBOTS.iter().find(|r| r.key == key)
}

/// The keys of all shipped robots, sorted.
pub fn keys() -> impl Iterator<Item = &'static str> {
    ROBOTS.iter().map(|r| r.key)
}

impl ShippedRobot {
    /// The compiled model with the joint speed limits applied.
    pub fn model(&self) -> Result<Model, Error> {
        let mut model = Model::from_xml_str(self.mjcf, None)?;
        let origin = format!("robots/{}/joint_speed_limits.json", self.key);
        JointSpeedLimits::from_json_str(self.joint_speed_limits, &origin)?
            .apply(&mut model, &origin)?;
        Ok(model)
    }

    /// GMR's tuned IK config of this robot (for LAFAN1-named skeletons), named by its path in
    /// the repository in messages.
    pub fn config(&self) -> Result<IkConfig, Error> {
        IkConfig::from_json_str(self.config, &self.config_name())
    }

    /// `configs/bvh_lafan1_to_<key>.json`.
    #[must_use]
    pub fn config_name(&self) -> String {
        format!("configs/bvh_lafan1_to_{}.json", self.key)
    }
}

/// The tuned config of the shipped robot `key`; `None` when `key` is not shipped.
#[must_use]
pub fn tuned_config(key: &str) -> Option<Result<IkConfig, Error>> {
    find(key).map(ShippedRobot::config)
}

/// A shipped robot by key, else the model file at that path (`.xml` MJCF or `.urdf` URDF, by
/// [`Model::from_path`]). An unknown name that is not a file is [`Error::UnknownRobot`].
/// Joint speed limits come from the robot's `joint_speed_limits.json`
/// (`joint_speed_limits.json`): the shipped one, or one beside a model file when present (a
/// URDF's own `velocity` limits are kept unless the file lists the joint).
///
/// A model without a free joint gets a floating base
/// (`add_floating_base`); [`load_robot_noted`] says so.
pub fn load_robot(name_or_path: &str) -> Result<Model, Error> {
    load_robot_noted(name_or_path).map(|(model, _)| model)
}

/// [`load_robot`], with what was done to the file's model to retarget onto it (a floating
/// base added), one sentence each, for the output to say once.
pub fn load_robot_noted(name_or_path: &str) -> Result<(Model, Vec<String>), Error> {
    if let Some(robot) = find(name_or_path) {
        return Ok((robot.model()?, Vec::new()));
    }
    if !looks_like_path(name_or_path) {
        return Err(unknown_robot(name_or_path));
    }
    let path = Path::new(name_or_path);
    let mut model = Model::from_path(path)?;
    let notes: Vec<String> =
        crate::robot_roles::add_floating_base(&mut model).into_iter().collect();
    let speeds = path.with_file_name("joint_speed_limits.json");
    if speeds.is_file() {
        let origin = speeds.display().to_string();
        let text = std::fs::read_to_string(&speeds)
            .map_err(|source| Error::Io { path: origin.clone(), source })?;
        JointSpeedLimits::from_json_str(&text, &origin)?.apply(&mut model, &origin)?;
    }
    Ok((model, notes))
}

/// [`Error::UnknownRobot`] for `name`: the shipped robots, and the nearest one by name when
/// one is close (Jaro-Winkler similarity ≥ 0.7, as clap suggests subcommands).
#[must_use]
pub(crate) fn unknown_robot(name: &str) -> Error {
    let nearest = keys()
        .map(|k| (strsim::jaro_winkler(name, k), k))
        .filter(|(score, _)| *score >= 0.7)
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, k)| k.to_owned());
    Error::UnknownRobot {
        name: name.to_owned(),
        shipped: keys().map(str::to_owned).collect(),
        nearest,
    }
}

/// Whether a robot argument names a model file rather than a shipped robot: an existing file,
/// or a name with an extension or a path separator.
#[must_use]
pub(crate) fn looks_like_path(name_or_path: &str) -> bool {
    let path = Path::new(name_or_path);
    path.is_file() || path.extension().is_some() || name_or_path.contains(std::path::MAIN_SEPARATOR)
}

/// A robot argument as messages name it: the shipped key, or the model file's stem.
#[must_use]
pub fn robot_label(name_or_path: &str) -> String {
    match Path::new(name_or_path).file_stem() {
        Some(stem)
            if name_or_path.contains('.') || name_or_path.contains(std::path::MAIN_SEPARATOR) =>
        {
            stem.to_string_lossy().into_owned()
        }
        _ => name_or_path.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_shipped_robot_compiles_with_its_limits_and_config() {
        for robot in ROBOTS {
            let model = robot.model().unwrap_or_else(|e| panic!("{}: {e}", robot.key));
            assert!(model.nq > 7, "{}", robot.key);
            let limited = model.joints.iter().filter(|j| j.velocity_limit.is_some()).count();
            assert_eq!(limited, model.joints.len() - 1, "{}: every joint but the root", robot.key);
            let config = robot.config().unwrap_or_else(|e| panic!("{}: {e}", robot.key));
            assert_eq!(config.source, robot.config_name());
        }
        let sorted: Vec<&str> = keys().collect();
        let mut expected = sorted.clone();
        expected.sort_unstable();
        assert_eq!(sorted, expected);
    }

    #[test]
    fn unknown_names_list_the_shipped_robots() {
        let message = load_robot("no_such_robot").unwrap_err().to_string();
        assert!(message.contains("unitree_g1"), "{message}");
        assert!(!message.contains("did you mean"), "nothing is near: {message}");
        let message = load_robot("unitre_g1").unwrap_err().to_string();
        assert!(message.ends_with("; did you mean unitree_g1?"), "{message}");
        assert!(matches!(load_robot("no_such_robot"), Err(Error::UnknownRobot { .. })));
        assert!(matches!(load_robot("/no/such/robot.xml"), Err(Error::Mjcf(_))));
    }

    #[test]
    fn labels_are_keys_or_file_stems() {
        assert_eq!(robot_label("unitree_g1"), "unitree_g1");
        assert_eq!(robot_label("robots/my_bot.urdf"), "my_bot");
        assert_eq!(robot_label("my_bot.xml"), "my_bot");
    }
}
