//! The canonical humanoid's vocabulary: its body [`Part`]s, the [`Side`]s and the 21
//! [`Role`]s (a part on a side), with their stable names. The recogniser
//! ([`crate::recognise`]) decides which joint plays each role; the naming conventions
//! ([`crate::conventions`]), the hierarchy reading (`structure`) and the canonical body
//! frames ([`crate::frames`]) are written in these words and need nothing from the
//! recogniser.
//!
//! Required roles: pelvis, head, and per side upper arm, forearm, hand, thigh, shin, foot
//! (a retargeter needs the ends of every limb and the trunk between them). Optional: spine,
//! chest, neck, clavicles, toes (many skeletons lack some; a robot rarely has them all).

use std::fmt;

/// Left or right, as the subject sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Side {
    Left,
    Right,
}

impl Side {
    #[must_use]
    pub fn other(self) -> Side {
        match self {
            Side::Left => Side::Right,
            Side::Right => Side::Left,
        }
    }
}

/// A body part of the canonical humanoid, without its side.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Part {
    Pelvis,
    Spine,
    Chest,
    Neck,
    Head,
    Clavicle,
    UpperArm,
    Forearm,
    Hand,
    Thigh,
    Shin,
    Foot,
    Toe,
}

impl Part {
    /// Whether the part comes in a left and a right one.
    #[must_use]
    pub fn is_sided(self) -> bool {
        !matches!(self, Part::Pelvis | Part::Spine | Part::Chest | Part::Neck | Part::Head)
    }

    /// `[Left, Right]` for sided parts, `[None]` otherwise.
    pub(crate) fn sides(self) -> &'static [Option<Side>] {
        if self.is_sided() {
            &[Some(Side::Left), Some(Side::Right)]
        } else {
            &[None]
        }
    }
}

macro_rules! roles {
    ($($role:ident = $name:literal: $part:ident $(, $side:ident)?;)*) => {
        /// A role of the canonical humanoid. Each role is played by one joint: the one at the
        /// proximal end of the body segment it names (the thigh is the hip joint, whose
        /// rotation carries the thigh bone), except the hand, foot and head, which are the
        /// joints at the wrist, ankle and skull base.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
        pub enum Role { $($role,)* }

        impl Role {
            /// Every role, trunk first, then the arms and the legs, left before right.
            pub const ALL: [Role; 21] = [$(Role::$role,)*];

            /// Stable snake_case name (JSON keys, `--map`, reports): `left_thigh`.
            #[must_use]
            pub fn name(self) -> &'static str {
                match self { $(Role::$role => $name,)* }
            }

            #[must_use]
            pub fn part(self) -> Part {
                match self { $(Role::$role => Part::$part,)* }
            }

            #[must_use]
            pub fn side(self) -> Option<Side> {
                match self { $(Role::$role => roles!(@side $($side)?),)* }
            }
        }
    };
    (@side) => { None };
    (@side $side:ident) => { Some(Side::$side) };
}

roles! {
    Pelvis = "pelvis": Pelvis;
    Spine = "spine": Spine;
    Chest = "chest": Chest;
    Neck = "neck": Neck;
    Head = "head": Head;
    LeftClavicle = "left_clavicle": Clavicle, Left;
    LeftUpperArm = "left_upper_arm": UpperArm, Left;
    LeftForearm = "left_forearm": Forearm, Left;
    LeftHand = "left_hand": Hand, Left;
    RightClavicle = "right_clavicle": Clavicle, Right;
    RightUpperArm = "right_upper_arm": UpperArm, Right;
    RightForearm = "right_forearm": Forearm, Right;
    RightHand = "right_hand": Hand, Right;
    LeftThigh = "left_thigh": Thigh, Left;
    LeftShin = "left_shin": Shin, Left;
    LeftFoot = "left_foot": Foot, Left;
    LeftToe = "left_toe": Toe, Left;
    RightThigh = "right_thigh": Thigh, Right;
    RightShin = "right_shin": Shin, Right;
    RightFoot = "right_foot": Foot, Right;
    RightToe = "right_toe": Toe, Right;
}

impl Role {
    /// The role of `part` on `side` (`None` when the side does not fit the part).
    #[must_use]
    pub fn new(part: Part, side: Option<Side>) -> Option<Role> {
        Role::ALL.into_iter().find(|r| r.part() == part && r.side() == side)
    }

    /// The role of a sided `part` on `side`; for a central part, that part (no side).
    #[must_use]
    pub fn of(part: Part, side: Side) -> Role {
        Role::new(part, part.is_sided().then_some(side))
            .unwrap_or(Role::Pelvis /* unreachable: every part has a role */)
    }

    /// Inverse of [`Role::name`].
    #[must_use]
    pub fn from_name(name: &str) -> Option<Role> {
        Role::ALL.into_iter().find(|r| r.name() == name)
    }

    /// Roles without which a skeleton is not recognised (see the module docs).
    #[must_use]
    pub fn is_required(self) -> bool {
        !matches!(self.part(), Part::Spine | Part::Chest | Part::Neck | Part::Clavicle | Part::Toe)
    }
}

impl fmt::Display for Role {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
