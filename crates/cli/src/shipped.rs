//! The robot models compiled into the binary (`robots/<key>/<key>.xml`, mesh-free MJCF), and
//! how a `--robot` argument (shipped key, MJCF or URDF path) becomes an [`mjcf::Model`].

use std::path::Path;

use anyhow::Context;
use retarget::joint_speed::JointSpeedLimits;

/// `robots/<key>/<key>.xml` and `robots/<key>/joint_speed_limits.json`, compiled in.
macro_rules! shipped {
    ($key:literal) => {
        (
            $key,
            include_str!(concat!("../../../robots/", $key, "/", $key, ".xml")),
            include_str!(concat!("../../../robots/", $key, "/joint_speed_limits.json")),
        )
    };
}

/// `(key, MJCF text, joint speed limits)` of every shipped robot, sorted by key.
pub const SHIPPED: &[(&str, &str, &str)] = &[
    shipped!("booster_t1_29dof"),
    shipped!("engineai_pm01"),
    shipped!("fourier_n1"),
    shipped!("stanford_toddy"),
    shipped!("unitree_g1"),
    shipped!("unitree_h1"),
];

/// The MJCF text of a shipped robot.
#[cfg(feature = "mujoco")]
pub fn shipped_xml(key: &str) -> Option<&'static str> {
    SHIPPED.iter().find(|(k, _, _)| *k == key).map(|(_, xml, _)| *xml)
}

/// The keys of all shipped robots.
pub fn shipped_keys() -> impl Iterator<Item = &'static str> {
    SHIPPED.iter().map(|(k, _, _)| *k)
}

/// A shipped robot by key, else the model file at that path (`.xml` MJCF or `.urdf` URDF, by
/// [`mjcf::Model::from_path`]). An unknown name that is not a file errors with the list of
/// shipped keys. Joint speed limits come from the robot's `joint_speed_limits.json`
/// ([`retarget::joint_speed`]): the shipped one, or one beside a model file when present
/// (a URDF's own `velocity` limits are kept unless the file lists the joint).
pub fn robot_model(name_or_path: &str) -> anyhow::Result<mjcf::Model> {
    if let Some((key, xml, speeds)) = SHIPPED.iter().find(|(k, _, _)| *k == name_or_path) {
        let mut model = mjcf::Model::from_xml_str(xml, None)
            .with_context(|| format!("shipped robot {key} (robots/{key}/{key}.xml)"))?;
        let origin = format!("robots/{key}/joint_speed_limits.json");
        JointSpeedLimits::from_json_str(speeds, &origin)?.apply(&mut model, &origin)?;
        return Ok(model);
    }
    if looks_like_path(name_or_path) {
        let path = Path::new(name_or_path);
        let mut model = mjcf::Model::from_path(path)?;
        let speeds = path.with_file_name("joint_speed_limits.json");
        if speeds.is_file() {
            let origin = speeds.display().to_string();
            let text = std::fs::read_to_string(&speeds).with_context(|| origin.clone())?;
            JointSpeedLimits::from_json_str(&text, &origin)?.apply(&mut model, &origin)?;
        }
        return Ok(model);
    }
    Err(unknown_robot(name_or_path))
}

/// Whether a `--robot` argument names a model file rather than a shipped robot.
pub fn looks_like_path(name_or_path: &str) -> bool {
    let path = Path::new(name_or_path);
    path.is_file() || path.extension().is_some() || name_or_path.contains(std::path::MAIN_SEPARATOR)
}

/// The error for a `--robot` that is neither a shipped robot nor a model file: the shipped
/// robots, and the nearest one by name when one is close (Jaro-Winkler similarity ≥ 0.7, as
/// clap suggests subcommands).
pub fn unknown_robot(name: &str) -> anyhow::Error {
    let keys: Vec<&str> = shipped_keys().collect();
    let nearest = keys
        .iter()
        .map(|k| (strsim::jaro_winkler(name, k), *k))
        .filter(|(score, _)| *score >= 0.7)
        .max_by(|a, b| a.0.total_cmp(&b.0));
    let hint = nearest.map_or(String::new(), |(_, k)| format!("; did you mean {k}?"));
    anyhow::anyhow!(
        "unknown robot \"{name}\": not a shipped robot ({}) nor an MJCF (.xml) or URDF (.urdf) file{hint}",
        keys.join(", ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_shipped_robot_compiles() {
        for key in shipped_keys() {
            let model = robot_model(key).unwrap_or_else(|e| panic!("{key}: {e:#}"));
            assert!(model.nq > 7, "{key}");
            let limited = model.joints.iter().filter(|j| j.velocity_limit.is_some()).count();
            assert_eq!(limited, model.joints.len() - 1, "{key}: every joint but the root");
        }
    }

    #[test]
    fn unknown_names_list_the_shipped_robots() {
        let message = robot_model("no_such_robot").unwrap_err().to_string();
        assert!(message.contains("unitree_g1"), "{message}");
        assert!(!message.contains("did you mean"), "nothing is near: {message}");
        let message = robot_model("unitre_g1").unwrap_err().to_string();
        assert!(message.ends_with("; did you mean unitree_g1?"), "{message}");
        let message = robot_model("fourier").unwrap_err().to_string();
        assert!(message.ends_with("; did you mean fourier_n1?"), "{message}");
    }
}
