//! The robots shipped with the library ([`retarget::shipped`]: MJCF, joint speed limits and
//! tuned configs compiled in), and how a `--robot` argument (shipped key, MJCF or URDF path)
//! becomes an [`mjcf::Model`].

/// The MJCF text of a shipped robot.
#[cfg(feature = "mujoco")]
pub fn shipped_xml(key: &str) -> Option<&'static str> {
    retarget::shipped::find(key).map(|r| r.mjcf)
}

/// The keys of all shipped robots.
pub fn shipped_keys() -> impl Iterator<Item = &'static str> {
    retarget::shipped::keys()
}

/// A shipped robot by key, else the model file at that path ([`retarget::shipped::load_robot`]:
/// joint speed limits applied; an unknown name lists the shipped robots).
pub fn robot_model(name_or_path: &str) -> anyhow::Result<mjcf::Model> {
    Ok(retarget::shipped::load_robot(name_or_path)?)
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
