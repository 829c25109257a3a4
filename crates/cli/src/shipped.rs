//! The robot models compiled into the binary (`robots/<key>/<key>.xml`, mesh-free MJCF), and
//! how a `--robot` argument (shipped key, MJCF or URDF path) becomes an [`mjcf::Model`].

use std::path::Path;

use anyhow::Context;

/// `(key, MJCF text)` of every shipped robot, sorted by key.
pub const SHIPPED: &[(&str, &str)] = &[
    ("booster_t1_29dof", include_str!("../../../robots/booster_t1_29dof/booster_t1_29dof.xml")),
    ("engineai_pm01", include_str!("../../../robots/engineai_pm01/engineai_pm01.xml")),
    ("fourier_n1", include_str!("../../../robots/fourier_n1/fourier_n1.xml")),
    ("stanford_toddy", include_str!("../../../robots/stanford_toddy/stanford_toddy.xml")),
    ("unitree_g1", include_str!("../../../robots/unitree_g1/unitree_g1.xml")),
    ("unitree_h1", include_str!("../../../robots/unitree_h1/unitree_h1.xml")),
];

/// The MJCF text of a shipped robot.
pub fn shipped_xml(key: &str) -> Option<&'static str> {
    SHIPPED.iter().find(|(k, _)| *k == key).map(|(_, xml)| *xml)
}

/// The keys of all shipped robots.
pub fn shipped_keys() -> impl Iterator<Item = &'static str> {
    SHIPPED.iter().map(|(k, _)| *k)
}

/// A shipped robot by key, else the model file at that path (`.xml` MJCF or `.urdf` URDF, by
/// [`mjcf::Model::from_path`]). An unknown name that is not a file errors with the list of
/// shipped keys.
pub fn robot_model(name_or_path: &str) -> anyhow::Result<mjcf::Model> {
    if let Some(xml) = shipped_xml(name_or_path) {
        return mjcf::Model::from_xml_str(xml, None).with_context(|| {
            format!("shipped robot {name_or_path} (robots/{name_or_path}/{name_or_path}.xml)")
        });
    }
    if looks_like_path(name_or_path) {
        return Ok(mjcf::Model::from_path(Path::new(name_or_path))?);
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
