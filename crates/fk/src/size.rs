//! How big the subject is: the unit guess (before FK), the subject height and the ground
//! level (after FK, in metres).

// Exception to the crate's `deny(clippy::indexing_slicing)`, justified: Indices here are joint ids of a skeleton `Plan::new` has checked and positions in per-joint
// arrays sized from it (rest pose, landmarks).
#![allow(clippy::indexing_slicing)]

/// Unit candidates, metres per file unit, with the name used in reports.
const CANDIDATES: [(f64, &str); 6] = [
    (1.0, "metres"),
    (0.1, "decimetres"),
    (0.01, "centimetres"),
    (0.001, "millimetres"),
    (0.0254, "inches"),
    (0.05644, "CMU units (3ds Max-friendly release, mocap.cs.cmu.edu FAQ)"),
];

/// A length that tracks stature, the human range it must land in (metres) and its typical
/// value for an adult.
#[derive(Debug, Clone, Copy)]
struct Proxy {
    value: f64,
    range: (f64, f64),
    typical: f64,
    what: &'static str,
}

/// The longest path between two joints along the bones (sum of bone lengths, file units):
/// head-to-toe or fingertip-to-fingertip, which both track stature (arm span ≈ height) in
/// any rest pose, whichever way its bones point. `lengths[i]` is joint `i`'s bone length to
/// its parent (0 for roots); parents come before children.
#[must_use]
pub(crate) fn tree_diameter(parents: &[Option<usize>], lengths: &[f64]) -> f64 {
    let n = parents.len();
    let mut down = vec![0.0_f64; n]; // longest path from a joint down into its subtree
    let mut best_two = vec![[0.0_f64; 2]; n];
    for i in (0..n).rev() {
        down[i] = best_two[i][0];
        if let Some(parent) = parents[i] {
            let reach = down[i] + lengths[i];
            let slot = &mut best_two[parent];
            if reach > slot[0] {
                *slot = [reach, slot[0]];
            } else if reach > slot[1] {
                slot[1] = reach;
            }
        }
    }
    best_two.iter().map(|[a, b]| a + b).fold(0.0, f64::max)
}

/// Metres per file unit for a skeleton of unknown shape, from its [`tree_diameter`] (1.8 m
/// typical, 1.0–2.6 m human): fingers and props count, so this is the fallback.
#[must_use]
pub(crate) fn choose_units(diameter: f64) -> (f64, String) {
    choose(Proxy {
        value: diameter,
        range: (1.0, 2.6),
        typical: 1.8,
        what: "longest bone path (head-to-toe / arm span)",
    })
}

/// Metres per file unit for a recognised humanoid, from its stature path (head joint →
/// pelvis → ankle along the bones, [`crate::Humanoid::stature_path`]): ≈ 0.95 of stature,
/// 1.6 m typical, 0.8–2.4 m human; fingers, face and props do not count.
#[must_use]
pub(crate) fn choose_units_from_stature(path: f64) -> (f64, String) {
    choose(Proxy { value: path, range: (0.8, 2.4), typical: 1.6, what: "head-to-ankle bone path" })
}

/// Metres per file unit for a recognised humanoid in a file that declares its unit
/// (`metres` per unit): that unit when the stature path is a human size in it, else a scale
/// making the path typical ([`choose_units_from_stature`]'s range and typical value).
#[must_use]
pub(crate) fn declared_units_from_stature(metres: f64, path: f64) -> (f64, String) {
    declared(
        metres,
        Proxy { value: path, range: (0.8, 2.4), typical: 1.6, what: "head-to-ankle bone path" },
    )
}

/// [`declared_units_from_stature`] for a skeleton of unknown shape ([`choose_units`]'s proxy).
#[must_use]
pub(crate) fn declared_units(metres: f64, diameter: f64) -> (f64, String) {
    declared(
        metres,
        Proxy {
            value: diameter,
            range: (1.0, 2.6),
            typical: 1.8,
            what: "longest bone path (head-to-toe / arm span)",
        },
    )
}

fn declared(metres: f64, proxy: Proxy) -> (f64, String) {
    let Proxy { value, range, typical, what } = proxy;
    let size = value * metres;
    if !(size.is_finite() && size > 0.0) {
        return (metres, format!("declared: {metres} m/unit ({what} gives no size to go by)"));
    }
    if (range.0..=range.1).contains(&size) {
        return (
            metres,
            format!("declared: {what} is {size:.2} m at {metres} m/unit, a human size"),
        );
    }
    let m = typical / value;
    (
        m,
        format!(
            "scaled: {what} is {size:.2} m at the declared {metres} m/unit, not a human size; \
             scaled by its proportions to {typical} m ({m:.6} m/unit)"
        ),
    )
}

/// The candidate whose result is closest (in ratio) to the typical value, among those in the
/// human range. If none fits, a computed scale making the proxy typical. Returns the scale
/// and the reason.
fn choose(proxy: Proxy) -> (f64, String) {
    let Proxy { value, range, typical, what } = proxy;
    let ratio = |m: f64| ((value * m) / typical).ln().abs();
    let best = CANDIDATES
        .iter()
        .filter(|(m, _)| (range.0..=range.1).contains(&(value * m)))
        .min_by(|a, b| ratio(a.0).total_cmp(&ratio(b.0)));
    let proxy = format!("{what} {value:.4} file units");
    match best {
        Some(&(m, name)) => {
            (m, format!("{name}: {proxy} is {:.2} m at {m} m/unit, a human size", value * m))
        }
        None if value.is_finite() && value > 0.0 => {
            let m = typical / value;
            (m, format!("computed: {proxy} fits no known unit; scaled to {typical} m"))
        }
        None => (1.0, format!("metres (assumed): {proxy} gives no size to go by")),
    }
}

/// Tragion (ear canal, ≈ the skull-base head joint of LAFAN1 and Bandai skeletons) height as
/// a fraction of stature: ANSUR II gives tragion–top of head ≈ 13 cm for a ≈ 1.75 m adult.
pub(crate) const HEAD_JOINT_OF_STATURE: f64 = 0.926;
/// An End Site at least this far (metres) from its head joint marks the top of the head.
const HEAD_TOP_MIN: f64 = 0.02;

/// Which bodies carry the top of the head and which the soles, by name.
#[derive(Debug, Clone, Default)]
pub(crate) struct Landmarks {
    pub(crate) head: Vec<usize>,
    pub(crate) feet: Vec<usize>,
    /// The skeleton reaches the top of the head (`*top*` joint or a real head End Site);
    /// otherwise its highest head point is the head joint and the skull is added.
    pub(crate) head_top: bool,
}

impl Landmarks {
    /// Head: joints named `*head*` and their descendants (End Sites, `HeadTop_End`, eyes);
    /// feet: `*foot*`, `*toe*`, `*ankle*` and descendants. Missing groups fall back to all
    /// joints (top = highest point, sole = lowest point).
    pub(crate) fn find(skeleton: &bvh::Skeleton, metres_per_unit: f64) -> Landmarks {
        let names: Vec<String> =
            skeleton.joints.iter().map(|j| j.name.to_ascii_lowercase()).collect();
        let parents: Vec<Option<usize>> =
            skeleton.joints.iter().map(|j| j.parent.map(|p| p.0)).collect();
        let head = subtree_of(&names, &parents, &["head"]);
        let feet = subtree_of(&names, &parents, &["foot", "toe", "ankle"]);
        Landmarks::new(skeleton, metres_per_unit, head, feet)
    }

    /// Head: the head role's joint and its descendants; feet: the foot and toe roles' joints
    /// and their descendants (for a recognised [`crate::Humanoid`], whatever the names).
    pub(crate) fn from_roles(
        skeleton: &bvh::Skeleton,
        metres_per_unit: f64,
        roles: &crate::RoleMap,
    ) -> Landmarks {
        use crate::Part;
        let n = skeleton.joints.len();
        let mut head = vec![false; n];
        let mut feet = vec![false; n];
        for (role, joint) in roles.iter() {
            match role.part() {
                Part::Head => head[joint.index] = true,
                Part::Foot | Part::Toe => feet[joint.index] = true,
                _ => {}
            }
        }
        for (i, joint) in skeleton.joints.iter().enumerate() {
            if let Some(p) = joint.parent {
                head[i] |= head[p.0];
                feet[i] |= feet[p.0];
            }
        }
        let pick = |marks: Vec<bool>| (0..n).filter(|&i| marks[i]).collect();
        Landmarks::new(skeleton, metres_per_unit, pick(head), pick(feet))
    }

    fn new(
        skeleton: &bvh::Skeleton,
        metres_per_unit: f64,
        head: Vec<usize>,
        feet: Vec<usize>,
    ) -> Landmarks {
        let n = skeleton.joints.len();
        let all: Vec<usize> = (0..n).collect();
        let mut leaf = vec![true; n];
        for joint in &skeleton.joints {
            if let Some(p) = joint.parent {
                leaf[p.0] = false;
            }
        }
        // An End Site, or a leaf joint named as one (SOMA's `HeadEnd`), ends the head.
        let head_top = head.is_empty()
            || head.iter().any(|&i| {
                let joint = &skeleton.joints[i];
                let length = nalgebra::Vector3::from(joint.offset).norm() * metres_per_unit;
                let end = joint.kind == bvh::JointKind::End
                    || (leaf[i] && crate::conventions::names_an_end(&joint.name));
                crate::conventions::names_the_top(&joint.name) || (end && length >= HEAD_TOP_MIN)
            });
        Landmarks {
            head: if head.is_empty() { all.clone() } else { head },
            feet: if feet.is_empty() { all } else { feet },
            head_top,
        }
    }
}

fn subtree_of(names: &[String], parents: &[Option<usize>], words: &[&str]) -> Vec<usize> {
    let mut inside = vec![false; names.len()];
    for i in 0..names.len() {
        inside[i] =
            words.iter().any(|w| names[i].contains(w)) || parents[i].is_some_and(|p| inside[p]);
    }
    (0..names.len()).filter(|&i| inside[i]).collect()
}

/// Height and ground of a clip, see [`stature`].
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Stature {
    pub(crate) height: f64,
    pub(crate) source: String,
    pub(crate) ground: f64,
}

/// Top of the head minus the lowest foot point (world z, metres), and that foot point.
fn head_over_sole(positions: &[nalgebra::Vector3<f64>], marks: &Landmarks) -> (f64, f64) {
    let top = marks.head.iter().map(|&i| positions[i].z).fold(f64::NEG_INFINITY, f64::max);
    let sole = marks.feet.iter().map(|&i| positions[i].z).fold(f64::INFINITY, f64::min);
    (top - sole, sole)
}

/// Fraction of frames allowed above the clip's standing height (tiptoe, glitches).
const STANDING_QUANTILE: f64 = 0.99;
/// The rest pose counts as standing if it is at least this tall relative to the clip.
const REST_UPRIGHT: f64 = 0.9;

/// Subject height: head over sole in the rest pose if the rest pose stands upright (a T- or
/// A-pose: exact skeleton dimensions, no posture), otherwise in the clip's standing frames
/// (the 99th percentile of head over sole per frame: the tallest the subject stands, with
/// tiptoe and glitches excluded; LAFAN1 and Bandai skeletons lie along X in the rest pose).
/// Skeletons that end at the head joint get the skull added ([`HEAD_JOINT_OF_STATURE`]).
/// Ground: the lowest foot point over the clip.
pub(crate) fn stature(
    frames: impl Iterator<Item = impl AsRef<[nalgebra::Vector3<f64>]>>,
    rest: &[nalgebra::Vector3<f64>],
    marks: &Landmarks,
) -> Stature {
    let mut heights = Vec::new();
    let mut ground = f64::INFINITY;
    for positions in frames {
        let (h, sole) = head_over_sole(positions.as_ref(), marks);
        heights.push(h);
        ground = ground.min(sole);
    }
    let (rest_height, rest_sole) = head_over_sole(rest, marks);
    let rank = ((heights.len().max(1) - 1) as f64 * STANDING_QUANTILE).round() as usize;
    let clip =
        (rank < heights.len()).then(|| *heights.select_nth_unstable_by(rank, f64::total_cmp).1);
    let (raw, mut source) = match clip {
        Some(h) if rest_height < REST_UPRIGHT * h => (
            h,
            format!("99th percentile over {} frames of head over lowest foot point", heights.len()),
        ),
        _ => (rest_height, "rest pose, head over lowest foot point".to_owned()),
    };
    let height = if marks.head_top {
        raw
    } else {
        source.push_str(&format!(
            " ({raw:.3} m to the head joint; skull added: head joint at {HEAD_JOINT_OF_STATURE} of stature)"
        ));
        raw / HEAD_JOINT_OF_STATURE
    };
    Stature { height, source, ground: if ground.is_finite() { ground } else { rest_sole } }
}
