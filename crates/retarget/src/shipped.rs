//! The robots and IK configs that ship with the library, compiled in: per robot key the
//! mesh-free MJCF (`robots/<key>/<key>.xml`) and its joint speed limits
//! (`robots/<key>/joint_speed_limits.json`); GMR's configs of those robots, byte-identical
//! (`configs/gmr/`, [`CONFIGS`]: per GMR source format and robot); GMR's robot keys whose
//! models we do not ship ([`NOT_SHIPPED`]); and how a robot argument (a shipped key, an MJCF
//! or a URDF path) becomes an [`mjcf::Model`].

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
        }
    };
}

/// Every shipped robot, sorted by key.
pub const ROBOTS: &[ShippedRobot] = &[
    shipped!("berkeley_humanoid_lite"),
    shipped!("booster_t1_29dof"),
    shipped!("engineai_pm01"),
    shipped!("fourier_n1"),
    shipped!("pal_talos"),
    shipped!("pnd_adam_lite"),
    shipped!("stanford_toddy"),
    shipped!("unitree_g1"),
    shipped!("unitree_g1_with_hands"),
    shipped!("unitree_h1"),
];

/// A robot key GMR knows whose model we do not ship, and why.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NotShipped {
    /// GMR's robot key.
    pub key: &'static str,
    /// Why the model is not here (its licence).
    pub reason: &'static str,
    /// Where GMR's model is: its `ROBOT_XML_DICT` path in <https://github.com/YanjieZe/GMR>.
    pub upstream: &'static str,
}

/// GMR's robot keys (`ROBOT_XML_DICT`, upstream master) whose models we do not ship, sorted.
/// `--robot KEY` names the upstream file and asks for its path instead.
pub const NOT_SHIPPED: &[NotShipped] = &[
    NotShipped {
        key: "booster_k1",
        reason: "no licence in GMR's assets/booster_k1/; model by Booster Robotics",
        upstream: "assets/booster_k1/K1_serial.xml",
    },
    NotShipped {
        key: "booster_t1",
        reason: "no licence in GMR's assets/booster_t1/; model by Booster Robotics",
        upstream: "assets/booster_t1/T1_serial.xml",
    },
    NotShipped {
        key: "fourier_gr3",
        reason: "no reference model here to check ours against (licence not reviewed)",
        upstream: "assets/fourier_gr3v2_1_1/mjcf/gr3v2_1_1_dummy_hand.xml",
    },
    NotShipped {
        key: "galaxea_r1pro",
        reason: "no reference model here to check ours against (licence not reviewed)",
        upstream: "assets/galaxea_r1pro/r1_pro.xml",
    },
    NotShipped {
        key: "hightorque_hi",
        reason: "no licence in GMR's assets/hightorque_hi/; model by HighTorque Robotics",
        upstream: "assets/hightorque_hi/hi_25dof.xml",
    },
    NotShipped {
        key: "kuavo_s45",
        reason: "no licence in GMR's assets/kuavo_s45/; model by Leju Robotics",
        upstream: "assets/kuavo_s45/biped_s45_collision.xml",
    },
    NotShipped {
        key: "tienkung",
        reason: "no licence in GMR's assets/tienkung/; model by X-Humanoid",
        upstream: "assets/tienkung/mjcf/tienkung.xml",
    },
    NotShipped {
        key: "unitree_h1_2",
        reason: "no licence in GMR's assets/unitree_h1_2/; model by Unitree Robotics",
        upstream: "assets/unitree_h1_2/h1_2_handless.xml",
    },
];

/// GMR's robot key `key` if we do not ship its model.
#[must_use]
pub fn not_shipped(key: &str) -> Option<&'static NotShipped> {
    NOT_SHIPPED.iter().find(|r| r.key == key)
}

/// One IK config compiled in: GMR's source format, the robot key, its path in the
/// repository and its text.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShippedConfig {
    /// GMR's source format (`bvh_lafan1`, `smplx`, `bvh_nokov`, ...), the keys of its
    /// `IK_CONFIG_DICT`.
    pub source: &'static str,
    /// The robot key.
    pub robot: &'static str,
    /// The file in the repository (`configs/gmr/bvh_lafan1_to_g1.json`), as messages name it.
    pub path: &'static str,
    /// The file's text.
    pub text: &'static str,
}

macro_rules! config {
    ($source:literal, $robot:literal, $file:literal) => {
        ShippedConfig {
            source: $source,
            robot: $robot,
            path: concat!("configs/", $file),
            text: include_str!(concat!("../../../configs/", $file)),
        }
    };
}

/// The IK configs of the shipped robots: GMR's `IK_CONFIG_DICT` entries (upstream master)
/// for them, GMR's files byte-identical in `configs/gmr/`, and ours (`configs/`) where GMR
/// has none (LAFAN1 → H1). One row per (source, robot).
pub const CONFIGS: &[ShippedConfig] = &[
    config!("bvh_lafan1", "booster_t1_29dof", "gmr/bvh_lafan1_to_t1_29dof.json"),
    config!("bvh_lafan1", "engineai_pm01", "gmr/bvh_lafan1_to_pm01.json"),
    config!("bvh_lafan1", "fourier_n1", "gmr/bvh_lafan1_to_n1.json"),
    config!("bvh_lafan1", "pal_talos", "gmr/bvh_to_talos.json"),
    config!("bvh_lafan1", "stanford_toddy", "gmr/bvh_lafan1_to_toddy.json"),
    config!("bvh_lafan1", "unitree_g1", "gmr/bvh_lafan1_to_g1.json"),
    config!("bvh_lafan1", "unitree_g1_with_hands", "gmr/bvh_lafan1_to_g1.json"),
    config!("bvh_lafan1", "unitree_h1", "bvh_lafan1_to_unitree_h1.json"),
    config!("bvh_nokov", "unitree_g1", "gmr/bvh_nokov_to_g1.json"),
    config!("bvh_xsens", "unitree_g1", "gmr/bvh_xsens_to_g1.json"),
    config!("fbx", "unitree_g1", "gmr/fbx_to_g1.json"),
    config!("fbx", "unitree_g1_with_hands", "gmr/fbx_to_g1.json"),
    config!("fbx_offline", "unitree_g1", "gmr/fbx_offline_to_g1.json"),
    config!("xrobot", "unitree_g1", "gmr/xrobot_to_g1.json"),
    config!("xsens_mvn", "unitree_g1", "gmr/xsens_mvn_to_g1.json"),
    config!("smplx", "berkeley_humanoid_lite", "gmr/smplx_to_bhl.json"),
    config!("smplx", "booster_t1_29dof", "gmr/smplx_to_t1_29dof.json"),
    config!("smplx", "engineai_pm01", "gmr/smplx_to_pm01.json"),
    config!("smplx", "fourier_n1", "gmr/smplx_to_n1.json"),
    config!("smplx", "pnd_adam_lite", "gmr/smplx_to_adam.json"),
    config!("smplx", "stanford_toddy", "gmr/smplx_to_toddy.json"),
    config!("smplx", "unitree_g1", "gmr/smplx_to_g1.json"),
    config!("smplx", "unitree_g1_with_hands", "gmr/smplx_to_g1.json"),
    config!("smplx", "unitree_h1", "gmr/smplx_to_h1.json"),
];

impl ShippedConfig {
    /// The parsed config, named by its path in messages.
    pub fn parse(&self) -> Result<IkConfig, Error> {
        IkConfig::from_json_str(self.text, self.path)
    }
}

/// The config for motions of GMR's source format `source` onto the shipped robot `key`
/// ([`CONFIGS`]); `None` when there is none.
#[must_use]
pub fn config(source: &str, key: &str) -> Option<&'static ShippedConfig> {
    CONFIGS.iter().find(|c| c.source == source && c.robot == key)
}

/// The SMPL-X config of the shipped robot `key` (GMR's `smplx_to_*.json`), for SMPL-X and
/// SMPL+H motions; `None` when it has none.
#[must_use]
pub fn smplx_config(key: &str) -> Option<Result<IkConfig, Error>> {
    config("smplx", key).map(ShippedConfig::parse)
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

    /// The tuned IK config of this robot for LAFAN1-named skeletons (GMR's `bvh_lafan1`
    /// config, or ours where GMR has none), named by its path in messages; `None` when there
    /// is none (a derived config is used).
    #[must_use]
    pub fn config(&self) -> Option<Result<IkConfig, Error>> {
        config("bvh_lafan1", self.key).map(ShippedConfig::parse)
    }

    /// The path of [`ShippedRobot::config`] in the repository.
    #[must_use]
    pub fn config_name(&self) -> Option<&'static str> {
        config("bvh_lafan1", self.key).map(|c| c.path)
    }
}

/// The tuned config of the shipped robot `key`; `None` when `key` is not shipped or has none.
#[must_use]
pub fn tuned_config(key: &str) -> Option<Result<IkConfig, Error>> {
    find(key).and_then(ShippedRobot::config)
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
    if let Some(refused) = refused(name_or_path) {
        return Err(refused);
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

/// [`Error::NotShipped`] when `key` is one of GMR's robots we do not ship ([`NOT_SHIPPED`]).
#[must_use]
pub(crate) fn refused(key: &str) -> Option<Error> {
    not_shipped(key).map(|robot| Error::NotShipped {
        key: robot.key.to_owned(),
        reason: robot.reason.to_owned(),
        upstream: robot.upstream.to_owned(),
    })
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
            if let Some(config) = robot.config() {
                let config = config.unwrap_or_else(|e| panic!("{}: {e}", robot.key));
                assert_eq!(Some(config.source.as_str()), robot.config_name());
            }
        }
        for config in CONFIGS {
            assert!(find(config.robot).is_some(), "{}: not shipped", config.robot);
            let parsed = config.parse().unwrap_or_else(|e| panic!("{}: {e}", config.path));
            let model = find(config.robot).unwrap().model().unwrap();
            for entry in parsed.ik_match_table1.iter().chain(&parsed.ik_match_table2) {
                assert!(model.body_id(&entry.robot_body).is_some(), "{}", config.path);
            }
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
    fn keys_gmr_names_are_shipped_or_refused_with_where_to_get_them() {
        assert!(NOT_SHIPPED.windows(2).all(|w| w[0].key < w[1].key), "sorted");
        for robot in NOT_SHIPPED {
            assert!(find(robot.key).is_none(), "{} both shipped and not", robot.key);
            let message = load_robot(robot.key).unwrap_err().to_string();
            assert!(message.contains(robot.key) && message.contains(robot.upstream), "{message}");
            assert!(message.contains("--robot path/to/"), "{message}");
        }
        assert_eq!(ROBOTS.len() + NOT_SHIPPED.len(), 18, "GMR's 18 robot keys");
    }

    #[test]
    fn labels_are_keys_or_file_stems() {
        assert_eq!(robot_label("unitree_g1"), "unitree_g1");
        assert_eq!(robot_label("robots/my_bot.urdf"), "my_bot");
        assert_eq!(robot_label("my_bot.xml"), "my_bot");
    }
}
