//! Where a pose stops being motion capture: the bounds [`crate::HumanMotion::validate`] and
//! the marker reader ([`crate::markers`]) check, and their errors quote.

/// Farthest a body may be from the origin (m) in a valid [`crate::HumanMotion`]: 100 km, far beyond
/// any capture volume or outdoor inertial recording, and far below the magnitudes (1e300, …)
/// of a corrupt number. See [`crate::HumanMotion::validate`].
pub const MAX_DISTANCE: f64 = 1e5;

/// Farthest a body may move between consecutive frames (m) in a valid [`crate::HumanMotion`]:
/// 100 m, i.e. 3 km/s at 30 fps, where a sprinter moves 0.4 m per frame.
pub const MAX_STEP: f64 = 100.0;
