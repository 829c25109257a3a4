//! What the parser tolerated: quirks of real exporters that are read anyway, reported as data
//! (this crate never prints).

use std::fmt;

use crate::error::Pos;

/// Something in a file that is not quite BVH but is read anyway, with its position. `Display`
/// gives `line:column: warning: message`; prefix the file name when showing it.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Warning {
    /// `Frames:` disagrees with the rows the file holds (Biovision's own exports are often
    /// one off); the rows present are used. `pos` is the count after `Frames:`.
    FrameCount { pos: Pos, declared: usize, found: usize },
    /// A joint has scale channels (`Xscale` …): they are kept (a file round-trips) but forward
    /// kinematics does not apply them. `min` and `max` are their values over the clip (1 and
    /// 1 when they scale nothing). `pos` is the joint's `CHANNELS` line.
    ScaleChannels { pos: Pos, joint: String, min: f64, max: f64 },
}

impl Warning {
    /// Where in the file the warning is.
    #[must_use]
    pub fn position(&self) -> Pos {
        match self {
            Warning::FrameCount { pos, .. } | Warning::ScaleChannels { pos, .. } => *pos,
        }
    }
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: warning: ", self.position())?;
        match self {
            Warning::FrameCount { declared, found, .. } => write!(
                f,
                "`Frames:` declares {declared} frames but the file has {found}; \
                 using the {found} present"
            ),
            Warning::ScaleChannels { joint, min, max, .. } if min == max && *min == 1.0 => {
                write!(f, "scale channels of `{joint}` are all 1; they are kept but not applied")
            }
            Warning::ScaleChannels { joint, min, max, .. } => write!(
                f,
                "scale channels of `{joint}` range over {min}..{max}; they are kept but not \
                 applied, so the motion keeps the skeleton's OFFSET proportions"
            ),
        }
    }
}
