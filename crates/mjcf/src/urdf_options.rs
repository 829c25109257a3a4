//! How a URDF becomes a [`Model`](crate::Model): the options of the `urdf` builder, apart
//! from it so that the MuJoCo cross-check (`mujoco_check`) names them without the builder.

/// What becomes of the root link.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UrdfBase {
    /// The root link gets a free joint (`ROOT_free_joint`), unless the file has a `floating`
    /// joint: what retargeting needs.
    #[default]
    Floating,
    /// No joint is added: the robot is fixed to the world, exactly as MuJoCo compiles the file.
    Fixed,
}

/// How a URDF becomes a [`Model`](crate::Model).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct UrdfOptions {
    pub base: UrdfBase,
    /// Merge links without a joint into their parent body (MuJoCo's `fusestatic`). `None`:
    /// as the file's `<mujoco><compiler fusestatic>` says, else MuJoCo's URDF default (merge).
    pub fuse_static: Option<bool>,
}
