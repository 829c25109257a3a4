//! The tunables of the foot plan, each documented once: [`FootPlanOptions`], with [`Anchor`].

/// Where a planted foot stays during its stance phase.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Anchor {
    /// Where the phase began (needs no look-ahead).
    PhaseStart,
    /// The mean over the phase of the free target (position) and its yaw (circular mean).
    PhaseMean,
}

/// Tunables of the foot plan (`plan`).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct FootPlanOptions {
    /// Where a planted foot stays during its stance phase.
    pub anchor: Anchor,
    /// Planting starts this long before the source's touch-down (s), so that the foot has
    /// arrived when the source's contact begins.
    pub lead_s: f64,
    /// Factor on the foot task's weights while planted.
    pub stance_weight: f64,
    /// Height of the sole's lowest point above the floor while planted (m).
    pub clearance: f64,
    /// Weight of the contact-point task that holds the sole's contact point on its anchor
    /// in stance (the foot tasks' position weights are 50 in GMR's configs).
    pub contact_weight: f64,
    /// A planted sole's points that stand on the floor move from one frame to the next as
    /// their footholds do, give or take this speed (m/s) horizontally: a hard constraint of
    /// each frame's step (`constraints::Grip`), so that no pull on the robot (the root's
    /// smoothness, the other tasks) slides a planted foot faster, whatever the contact
    /// weight, while a foot that lands off its foothold still reaches it. The report's
    /// contact sliding speed (`ReportOptions::slide_speed`, 0.1 m/s).
    pub slip_speed: f64,
    /// Least horizontal gap (m) between the two soles when both are planted at once: anchors
    /// closer than this are moved apart, half the shortfall each, along the footprints'
    /// separating axis, so that the planted feet do not ask for the soles inside each other,
    /// which the self-collision constraint then fights. In every frame, soles alongside each
    /// other are also kept this far apart sideways (`keep_feet_apart`), before planting.
    pub sole_gap: f64,
    /// Least height (m) of the sole's lowest point above the floor out of stance, once the
    /// foot has risen ([`FootPlanOptions::lift_s`]); the solve holds it as the sole's floor
    /// (`FootPlan::swing_floor`). A foot is either planted or clear of the floor: the
    /// dynamics check and the report's skating on the floor count a sole within 1 cm as on
    /// it. (3.2 cm, held from the first frame off the floor, hiked ToddlerBot's short legs:
    /// its walk's jitter 12.5 rad/s² against 10.0 at 1.5 cm, `--gmr` 7.6.)
    pub swing_clearance: f64,
    /// Time (s) over which the swing clearance fades in after lift-off and out before
    /// touch-down (smoothstep).
    pub lift_s: f64,
    /// A stance phase over which the source foot's yaw turns through more than this (rad,
    /// largest minus smallest) is a **pivot**: the planted foot turns with the source's, about
    /// the ball of its foot (`RobotFoot::ball_point`: the inner toe corner; the middle of the
    /// toes, `RobotFoot::toe_point`, where the ankle cannot roll), which stays where the anchor
    /// puts it. Holding the mean yaw there
    /// (a dancer or a jumper turning on one foot) twisted the leg by half the turn: 45° on
    /// the LAFAN1 jumps, where the PM01's hip then went past its yaw range's middle and
    /// stayed there for the 2,000 frames that followed. A turning sole sweeps the floor, so
    /// the threshold trades rotation error for the report's sliding share: on the G1 jumps
    /// 30° gives 6.78° / 15.4 %, 45° 6.84° / 13.3 %, 60° 6.99° / 12.1 %, none 7.42° / 9.7 %.
    pub pivot_turn: f64,
    /// A planted foot stands on its whole sole: its tilt from standing flat is scaled down
    /// until its bottom points are within this height (m) of each other (the dynamics check
    /// counts the points within 1 cm of the floor as support; a sole on its edge supports no
    /// torque about that edge). Copied whole, the tilt GMR's G1 config gives the feet (4°
    /// nose-up) stood them on their heel edges: 30 % of the LAFAN1 walk's frames on two
    /// points, and the motion needed more than 0.1 m·g of wrench the feet could not give in
    /// a third of its frames.
    pub sole_band: f64,
    /// While the other foot is planted too, a planted foot rolls with the human's (heel
    /// strike, toe off: the other foot carries the centre of pressure); the roll fades in and
    /// out over this time (s) at the double support's ends.
    pub roll_s: f64,
    /// A pivoting foot turns on its ball: its heel rises this far (m) above its toe (the
    /// pitch about the toe edge that lifts the sole's back end by it) where the foot turns
    /// fast, so that the sole's back does not sweep the floor. Turning flat, a sole of length
    /// `l` slides its heel at `ω l`: on the LAFAN1 jumps the G1's feet turned up to 450°/s on
    /// the floor, and 95 % of the frames the report counted as skating on the floor were
    /// such turns.
    pub pivot_heel_lift: f64,
    /// The heel is fully up ([`FootPlanOptions::pivot_heel_lift`]) where turning flat would
    /// slide it faster than this (m/s), and down where the foot does not turn (smoothstep in
    /// between).
    pub pivot_heel_speed: f64,
}

impl Default for FootPlanOptions {
    fn default() -> Self {
        FootPlanOptions {
            anchor: Anchor::PhaseMean,
            lead_s: 1.0 / 30.0,
            stance_weight: 2.0,
            clearance: 0.002,
            contact_weight: 400.0,
            slip_speed: 0.1,
            sole_gap: 0.03,
            swing_clearance: 0.015,
            lift_s: 1.0 / 30.0,
            pivot_turn: 45f64.to_radians(),
            sole_band: 0.006,
            roll_s: 0.1,
            pivot_heel_lift: 0.02,
            pivot_heel_speed: 0.2,
        }
    }
}
