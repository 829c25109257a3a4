//! The feet's metrics: skating (holosoma's), stance heights and the sole band, foot heights
//! and the per-foot report ([`FootReport`], [`Floating`]).

// Indexing: as in the parent module (the motion is checked against the model first).
#![allow(clippy::indexing_slicing)]

use super::*;

/// holosoma's `foot_skating_metrics`: backward-difference speeds with a leading 0, frames
/// with a skating foot over frames with a foot in source contact.
pub(super) fn skating(
    feet_xy: &[Vec<nalgebra::Vector2<f64>>; 2],
    contacts: [&[bool]; 2],
    fps: f64,
    threshold: f64,
) -> Skating {
    let speed = |f: usize, t: usize| {
        if t == 0 {
            0.0
        } else {
            (feet_xy[f][t] - feet_xy[f][t - 1]).norm() * fps
        }
    };
    let (mut stance_frames, mut skating_frames, mut max_speed) = (0, 0, 0.0f64);
    for (t, (&left, &right)) in contacts[0].iter().zip(contacts[1]).enumerate() {
        let stance = [left, right];
        let skate: Vec<f64> =
            (0..2).filter(|&f| stance[f]).map(|f| speed(f, t)).filter(|v| *v > threshold).collect();
        stance_frames += usize::from(stance[0] || stance[1]);
        skating_frames += usize::from(!skate.is_empty());
        max_speed = skate.into_iter().fold(max_speed, f64::max);
    }
    Skating {
        threshold_mps: threshold,
        stance_frames,
        skating_frames,
        duration: ratio(skating_frames, stance_frames),
        max_speed,
    }
}

pub(super) fn stance(
    heights: &[&[f64]; 2],
    contacts: [&[bool]; 2],
    opts: &ReportOptions,
) -> Stance {
    let samples: Vec<f64> = (0..2)
        .flat_map(|f| (0..contacts[f].len()).filter(move |&t| contacts[f][t]).map(move |t| (f, t)))
        .map(|(f, t)| heights[f][t])
        .collect();
    let floating = samples.iter().filter(|h| **h > opts.stance_float_height).count();
    let [lo, hi] = opts.sole_band;
    let in_band = samples.iter().filter(|h| (lo..=hi).contains(*h)).count();
    Stance {
        samples: samples.len(),
        float_cm: opts.stance_float_height * 100.0,
        band_cm: [lo * 100.0, hi * 100.0],
        floating,
        floating_share: ratio(floating, samples.len()),
        sole_in_band_share: ratio(in_band, samples.len()),
    }
}

/// What a foot's height is measured at ([`FootReport::height_from`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum HeightFrom {
    Geoms,
    Inertia,
    Origin,
}

/// Per frame foot height above the ground, the lowest point of the foot (world; the body
/// origin without geoms or inertial), and what they were measured at.
pub(super) fn foot_heights(
    motion: &RobotMotion,
    model: &mjcf::Model,
    foot: usize,
    ground: f64,
) -> (Vec<f64>, Vec<Vector3<f64>>, HeightFrom) {
    let geoms: Vec<usize> = (0..model.geoms.len())
        .filter(|&g| {
            let geom = &model.geoms[g];
            model.is_ancestor_or_self(foot, geom.body) && geom.kind.is_primitive()
        })
        .collect();
    // Without geoms, the foot's equivalent inertia box, as the planner's sole.
    let inertia = if geoms.is_empty() { crate::feet::inertia_sole(model, foot) } else { None };
    let from = match (geoms.is_empty(), inertia.is_some()) {
        (false, _) => HeightFrom::Geoms,
        (true, true) => HeightFrom::Inertia,
        (true, false) => HeightFrom::Origin,
    };
    let mut data = mjcf::Data::new(model);
    let lowest: Vec<Vector3<f64>> = (0..motion.num_frames())
        .map(|t| {
            model.kinematics(motion.frame(t), &mut data);
            if let Some(inertia) = &inertia {
                let at = inertia.world(&data);
                let r = at.rotation.to_rotation_matrix().into_inner();
                return at.translation.vector
                    + support_offset(mjcf::GeomType::Box, &inertia.half, &r);
            }
            geoms
                .iter()
                .filter_map(|&g| mjcf::geom_lowest_point(model, &data, g))
                .min_by(|a, b| a.z.total_cmp(&b.z))
                .unwrap_or(data.xpos[foot])
        })
        .collect();
    let heights = lowest.iter().map(|p| p.z - ground).collect();
    (heights, lowest, from)
}

#[allow(clippy::too_many_arguments)]
pub(super) fn foot_report(
    model: &mjcf::Model,
    poses: &BodyPoses,
    foot: usize,
    heights: &[f64],
    lowest: &[Vector3<f64>],
    from: HeightFrom,
    fps: f64,
    opts: &ReportOptions,
) -> FootReport {
    let frames = heights.len();
    // The contact point: the foot's lowest point at frame t, fixed in the foot body. Its
    // world position at frame u, and its horizontal velocity by numpy's gradient scheme.
    let local: Vec<Vector3<f64>> = (0..frames)
        .map(|t| poses.quat(t, foot - 1).inverse() * (lowest[t] - poses.pos(t, foot - 1)))
        .collect();
    let at = |u: usize, t: usize| poses.pos(u, foot - 1) + poses.quat(u, foot - 1) * local[t];
    let speed: Vec<f64> = (0..frames)
        .map(|t| match gradient_pair(t, frames) {
            Some((a, b)) => {
                let d = (at(b, t) - at(a, t)) * fps / (b - a) as f64;
                d.x.hypot(d.y)
            }
            None => 0.0,
        })
        .collect();
    let contact: Vec<bool> = (0..frames)
        .map(|t| heights[t] < opts.contact_height && speed[t] < opts.contact_speed)
        .collect();
    let contact_frames = contact.iter().filter(|c| **c).count();
    let sliding_frames = (0..frames).filter(|&t| contact[t] && speed[t] > opts.slide_speed).count();
    let mut slides = Vec::new();
    let mut t = 0;
    while t < frames {
        if !contact[t] {
            t += 1;
            continue;
        }
        let mut dist = 0.0;
        while t + 1 < frames && contact[t + 1] {
            let d = at(t + 1, t) - at(t, t);
            dist += d.x.hypot(d.y);
            t += 1;
        }
        slides.push(dist * 100.0);
        t += 1;
    }
    let penetration: Vec<f64> = heights.iter().filter(|h| **h < 0.0).map(|h| -h * 100.0).collect();
    let on_floor: Vec<usize> = (0..frames).filter(|&t| heights[t] < opts.floor_height).collect();
    let floor_skating = on_floor.iter().filter(|&&t| speed[t] > opts.skate_speed).count();
    FootReport {
        floor_frames: on_floor.len(),
        floor_skating_frames: floor_skating,
        floor_skating_share: ratio(floor_skating, on_floor.len()),
        body: model.bodies[foot].name.clone(),
        height_from: match from {
            HeightFrom::Geoms => "geoms",
            HeightFrom::Inertia => "inertia",
            HeightFrom::Origin => "origin",
        },
        contact_frames,
        contact_phases: slides.len(),
        sliding_frames,
        sliding_share: ratio(sliding_frames, contact_frames),
        slide_per_phase_cm_mean: mean(&slides),
        slide_per_phase_cm_max: slides.iter().copied().fold(0.0, f64::max),
        penetration_frames: penetration.len(),
        penetration_cm_max: penetration.iter().copied().fold(0.0, f64::max),
        penetration_cm_mean: mean(&penetration),
    }
}

pub(super) fn floating(left: &[f64], right: &[f64], contact_height: f64) -> Floating {
    let lowest: Vec<f64> = left.iter().zip(right).map(|(l, r)| l.min(*r)).collect();
    let frames = lowest.iter().filter(|h| **h >= contact_height).count();
    let cm: Vec<f64> = lowest.iter().map(|h| h.max(0.0) * 100.0).collect();
    Floating {
        frames,
        share: ratio(frames, lowest.len()),
        cm_mean: mean(&cm),
        cm_max: cm.iter().copied().fold(0.0, f64::max),
    }
}
