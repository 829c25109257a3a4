//! MJCF (MuJoCo's XML model format) → a kinematic [`Model`] with MuJoCo's compiler semantics,
//! plus forward kinematics, Jacobians and `qpos` integration in pure Rust.
//!
//! Two steps, syntax apart from semantics: the text is read (with `<include>` expanded) into a
//! typed tree of what the file says (`syntax`), which is then compiled (`compile`) the way
//! MuJoCo's compiler does it: default classes and `childclass`, the compiler's `angle` unit and
//! `eulerseq`, every orientation form (`quat`, `axisangle`, `euler`, `xyaxes`, `zaxis`),
//! `<frame>`, `fromto`, `autolimits`, and body mass and inertia from `<inertial>`
//! ([`Body::inertial`]). The kinematic functions reproduce `mj_kinematics`,
//! `mj_jac`/`mj_jacBody` and `mj_integratePos`; the `mujoco` feature adds the module
//! `mujoco_check`, which compares everything with MuJoCo 3.17.0 itself (a plain name: without
//! the feature there is nothing to link to, and rustdoc denies the broken link).
//!
//! URDF is read into the same [`Model`] ([`Model::from_urdf_file`], [`Model::from_path`]) with
//! the semantics of MuJoCo's URDF import (static links fused into their parent with their
//! inertia, visuals dropped, `rpy` as fixed-axis roll-pitch-yaw), plus a free root joint unless
//! [`UrdfBase::Fixed`] is asked for; `<limit velocity>` becomes [`Joint::velocity_limit`].
//!
//! ```
//! let xml = r#"<mujoco><worldbody><body name="a" pos="0 0 1">
//!   <joint name="j" axis="0 1 0" range="-90 90"/><geom size="0.1"/>
//! </body></worldbody></mujoco>"#;
//! let model = mjcf::Model::from_xml_str(xml, None).unwrap();
//! let mut data = mjcf::Data::new(&model);
//! model.kinematics(&[0.5], &mut data);
//! assert_eq!(model.joints[0].range, Some([-std::f64::consts::FRAC_PI_2, std::f64::consts::FRAC_PI_2]));
//! assert!((data.xpos[1].z - 1.0).abs() < 1e-15);
//! ```

// Library code never panics on input (issue 15): the compiler checks it. Tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

pub mod collision;
mod compile;
mod error;
mod inertia;
mod kinematics;
mod math;
mod model;
#[cfg(feature = "mujoco")]
pub mod mujoco_check;
mod sample;
mod source;
mod syntax;
mod urdf;
mod urdf_options;

use std::path::Path;

pub use collision::{
    box_manifold, geom_bounding_sphere, geom_distance, geom_lowest_point, ChainContact,
    ContactPoint, Manifold, ManifoldFeature, Proximity, SelfCollisionPairs, MAX_MANIFOLD_POINTS,
};
pub use error::{Error, Location};
pub use kinematics::Data;
pub use math::axis_angle;
pub use model::{Body, FloatingBase, Geom, GeomType, Inertial, Joint, JointType, Model, Site};
pub use urdf_options::{UrdfBase, UrdfOptions};

impl Model {
    /// Reads and compiles an MJCF file; `<include>` paths are relative to its directory.
    /// Errors name the file and `line:column`.
    pub fn from_file(path: &Path) -> Result<Model, Error> {
        let text = std::fs::read_to_string(path)
            .map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
        Self::build(path.display().to_string(), text, path.parent())
    }

    /// Compiles MJCF text; `base_dir` resolves `<include file>` (the current directory when
    /// `None`). Errors name the file `<string>`.
    pub fn from_xml_str(xml: &str, base_dir: Option<&Path>) -> Result<Model, Error> {
        Self::build("<string>".to_owned(), xml.to_owned(), base_dir)
    }

    /// Reads a URDF file with MuJoCo's URDF semantics (see [`UrdfOptions`] for the root and
    /// static links). Errors name the file and `line:column`.
    pub fn from_urdf_file(path: &Path, options: UrdfOptions) -> Result<Model, Error> {
        let text = std::fs::read_to_string(path)
            .map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
        Self::build_urdf(path.display().to_string(), text, options)
    }

    /// Compiles URDF text. Errors name the file `<string>`.
    pub fn from_urdf_str(urdf: &str, options: UrdfOptions) -> Result<Model, Error> {
        Self::build_urdf("<string>".to_owned(), urdf.to_owned(), options)
    }

    /// Reads a robot model by its extension: `.xml` as MJCF ([`Model::from_file`]), `.urdf` as
    /// URDF with the default options (a free root: [`Model::from_urdf_file`]).
    pub fn from_path(path: &Path) -> Result<Model, Error> {
        let extension = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
        match extension.as_deref() {
            Some("xml") => Self::from_file(path),
            Some("urdf") => Self::from_urdf_file(path, UrdfOptions::default()),
            _ => Err(Error::Model {
                file: path.display().to_string(),
                message: "unknown robot model format: expected a .xml (MJCF) or .urdf (URDF) file"
                    .to_owned(),
            }),
        }
    }

    fn build_urdf(name: String, text: String, options: UrdfOptions) -> Result<Model, Error> {
        let mut sources = source::Sources::default();
        sources.add(name, text.clone());
        let tree = urdf::parse(&sources, &text)?;
        urdf::build(&tree, &sources, options)
    }

    fn build(name: String, text: String, base_dir: Option<&Path>) -> Result<Model, Error> {
        let mut sources = source::Sources::default();
        let root = source::load(name, text, base_dir, &mut sources)?;
        let mjcf = syntax::parse(&root, &sources)?;
        compile::compile(&mjcf, &sources)
    }
}
