//! What the recogniser finds ([`crate::recognise`]): the [`Humanoid`], the joint playing
//! each role ([`RoleMap`]) and the rule that decided it, and the conventions the data
//! follows (up axis, rest-pose kind, the pose the body frames are taken in).

use std::collections::BTreeMap;
use std::fmt;

use nalgebra::{UnitQuaternion, Vector3};

use crate::roles::Role;
use crate::AxisConvention;

/// How a role's joint was decided.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Rule {
    /// Its name in a naming convention, among the joints the hierarchy allows for the role.
    Name { convention: &'static str, hierarchy: String },
    /// The hierarchy and bone lengths alone (no name fitted, or the names were refused).
    Hierarchy(String),
    /// Given by the caller (`FkOptions::roles`, `--map`).
    Given,
}

impl fmt::Display for Rule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Rule::Name { convention, hierarchy } => write!(f, "name ({convention}); {hierarchy}"),
            Rule::Hierarchy(why) => write!(f, "hierarchy: {why}"),
            Rule::Given => f.write_str("given"),
        }
    }
}

/// The joint playing a role.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RoleJoint {
    /// Joint name as in the file (`<Parent>_End` for an End Site, as body names).
    pub name: String,
    /// Index in the skeleton's joints (= body index in [`crate::HumanMotion`]).
    pub index: usize,
    pub end_site: bool,
    pub rule: Rule,
}

/// Role → joint, with the rule that decided each.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct RoleMap {
    entries: BTreeMap<Role, RoleJoint>,
}

impl RoleMap {
    #[must_use]
    pub fn get(&self, role: Role) -> Option<&RoleJoint> {
        self.entries.get(&role)
    }

    /// The joint name playing `role`.
    #[must_use]
    pub fn joint(&self, role: Role) -> Option<&str> {
        self.entries.get(&role).map(|j| j.name.as_str())
    }

    /// Assigned roles in [`Role::ALL`] order.
    pub fn iter(&self) -> impl Iterator<Item = (Role, &RoleJoint)> {
        self.entries.iter().map(|(r, j)| (*r, j))
    }

    #[must_use]
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Required roles that no joint plays.
    #[must_use]
    pub fn missing_required(&self) -> Vec<Role> {
        Role::ALL.into_iter().filter(|r| r.is_required() && !self.entries.contains_key(r)).collect()
    }

    pub(crate) fn insert(&mut self, role: Role, joint: RoleJoint) {
        self.entries.insert(role, joint);
    }

    pub(crate) fn remove(&mut self, role: Role) {
        self.entries.remove(&role);
    }

    pub(crate) fn index(&self, role: Role) -> Option<usize> {
        self.entries.get(&role).map(|j| j.index)
    }
}

/// Which file axis points up (towards the head).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UpAxis {
    PosX,
    NegX,
    PosY,
    NegY,
    PosZ,
    NegZ,
}

impl UpAxis {
    pub(crate) const ALL: [UpAxis; 6] =
        [UpAxis::PosX, UpAxis::NegX, UpAxis::PosY, UpAxis::NegY, UpAxis::PosZ, UpAxis::NegZ];

    /// The axis as a unit vector in file coordinates.
    #[must_use]
    pub fn vector(self) -> Vector3<f64> {
        match self {
            UpAxis::PosX => Vector3::x(),
            UpAxis::NegX => -Vector3::x(),
            UpAxis::PosY => Vector3::y(),
            UpAxis::NegY => -Vector3::y(),
            UpAxis::PosZ => Vector3::z(),
            UpAxis::NegZ => -Vector3::z(),
        }
    }

    /// The file-to-world rotation that puts this axis up: [`AxisConvention::YUp`] (GMR's)
    /// for +Y, [`AxisConvention::ZUp`] for +Z, a quarter or half turn otherwise.
    #[must_use]
    pub fn convention(self) -> AxisConvention {
        use std::f64::consts::{FRAC_PI_2, PI};
        let turn = |axis: Vector3<f64>, angle: f64| {
            AxisConvention::Custom(UnitQuaternion::from_axis_angle(
                &nalgebra::Unit::new_normalize(axis),
                angle,
            ))
        };
        match self {
            UpAxis::PosY => AxisConvention::YUp,
            UpAxis::PosZ => AxisConvention::ZUp,
            UpAxis::NegY => turn(Vector3::x(), -FRAC_PI_2),
            UpAxis::PosX => turn(Vector3::y(), -FRAC_PI_2),
            UpAxis::NegX => turn(Vector3::y(), FRAC_PI_2),
            UpAxis::NegZ => turn(Vector3::x(), PI),
        }
    }
}

impl fmt::Display for UpAxis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            UpAxis::PosX => "+X",
            UpAxis::NegX => "-X",
            UpAxis::PosY => "+Y",
            UpAxis::NegY => "-Y",
            UpAxis::PosZ => "+Z",
            UpAxis::NegZ => "-Z",
        })
    }
}

/// What the all-zeros pose (OFFSETs only) is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RestPose {
    /// Standing, arms within 25° of horizontal.
    TPose,
    /// Standing, arms 25°–65° below horizontal.
    APose,
    /// Standing, arms more than 65° below horizontal.
    ArmsDown,
    /// Standing, arms more than 25° above horizontal.
    ArmsUp,
    /// Not standing upright along the up axis: the zero pose means nothing (LAFAN1, Bandai).
    NotUpright,
}

impl fmt::Display for RestPose {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            RestPose::TPose => "T-pose",
            RestPose::APose => "A-pose",
            RestPose::ArmsDown => "arms down",
            RestPose::ArmsUp => "arms up",
            RestPose::NotUpright => "not upright",
        })
    }
}

/// The pose the body frames were taken in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reference {
    /// The zero pose (it stands upright).
    Rest,
    /// A frame of the motion (the zero pose does not stand).
    Frame(usize),
}

impl fmt::Display for Reference {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Reference::Rest => f.write_str("the zero pose"),
            Reference::Frame(i) => write!(f, "frame {i}"),
        }
    }
}

/// A recognised skeleton: its roles and the conventions its data follows.
#[derive(Debug, Clone, PartialEq)]
pub struct Humanoid {
    pub roles: RoleMap,
    /// The naming convention that names most of the skeleton, if any.
    pub convention: Option<&'static str>,
    /// How left and right were told apart.
    pub sides: String,
    pub up: UpAxis,
    pub up_reason: String,
    pub rest_pose: RestPose,
    pub rest_reason: String,
    pub reference: Reference,
    pub reference_reason: String,
    /// Per role, the rotation from the joint's frame to its canonical body frame
    /// ([`crate::frames`]), computed in the reference pose: the canonical frame at any frame
    /// is `q_joint ⊗ offset`. Roles whose frame the geometry does not fix are absent.
    pub frame_offsets: BTreeMap<Role, UnitQuaternion<f64>>,
    /// Head joint → pelvis → ankle along the bones (file units; both legs averaged): the
    /// body proportion the unit is chosen from, fingers and props not included.
    pub stature_path: f64,
    /// Per role, its joint's position in the zero pose (all channels zero, OFFSETs only),
    /// in file axes and units. Every joint's frame is the file's axes there, so these say
    /// where the skeleton's joint frames sit on the body: two skeletons whose zero poses
    /// point each bone the same way have the same joint frames.
    pub rest_points: BTreeMap<Role, Vector3<f64>>,
}
