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
    let path = Path::new(name_or_path);
    let looks_like_path =
        path.extension().is_some() || name_or_path.contains(std::path::MAIN_SEPARATOR);
    if path.is_file() || looks_like_path {
        return Ok(mjcf::Model::from_path(path)?);
    }
    let keys: Vec<&str> = shipped_keys().collect();
    anyhow::bail!(
        "unknown robot \"{name_or_path}\": not a shipped robot ({}) and not an MJCF or URDF file",
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
    }
}
