//! The report as text (`retarget report`'s output): [`QualityReport`]'s `Display`.

// Indexing: as in the parent module (the motion is checked against the model first).
#![allow(clippy::indexing_slicing)]

use super::*;

impl fmt::Display for QualityReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let secs = self.frames as f64 / self.fps;
        self.fmt_verdict(f)?;
        writeln!(
            f,
            "robot {} · {} frames at {} fps ({secs:.2} s)",
            self.robot, self.frames, self.fps
        )?;

        if let Some(tracking) = &self.tracking {
            writeln!(f, "\ntracking error           position (cm) mean / p95 / max   rotation (rad) mean / p95 / max")?;
            for b in tracking {
                let r = b.rot_rad;
                // A body whose position is not a target gets dashes, as in the main command.
                let p = b.pos_m.map_or_else(
                    || format!("{:>7} {:>7} {:>7}", "-", "-", "-"),
                    |p| {
                        format!(
                            "{:>7.2} {:>7.2} {:>7.2}",
                            p.mean * 100.0,
                            p.p95 * 100.0,
                            p.max * 100.0
                        )
                    },
                );
                writeln!(
                    f,
                    "  {:<24} {p}          {:>7.3} {:>7.3} {:>7.3}",
                    b.body, r.mean, r.p95, r.max
                )?;
            }
        }
        let l = &self.joint_limits;
        writeln!(
            f,
            "\njoint limits: {} violations (frames × joints), max excess {:.4}",
            l.violations, l.max_excess
        )?;
        for v in &l.joints {
            writeln!(
                f,
                "  {:<28} {:>5} frames, max excess {:.4}",
                v.joint, v.frames, v.max_excess
            )?;
        }
        writeln!(
            f,
            "\njoint                          |q̇| p99    |q̇| max  over limit   jitter |q̈| mean"
        )?;
        for j in &self.joints {
            writeln!(
                f,
                "  {:<28} {:>8.3} {:>10.3} {:>11} {:>17.2}",
                j.joint, j.vel_p99, j.vel_max, j.vel_over_limit, j.jitter
            )?;
        }
        writeln!(f, "\nfoot                      height   contact  phases  sliding  slide/phase cm mean/max  penetration cm mean/max (frames)")?;
        for foot in &self.feet {
            writeln!(
                f,
                "  {:<24} {:<7} {:>7} {:>7} {:>7.1}%      {:>6.2} / {:<6.2}        {:.2} / {:.2} ({})",
                foot.body,
                foot.height_from,
                foot.contact_frames,
                foot.contact_phases,
                foot.sliding_share * 100.0,
                foot.slide_per_phase_cm_mean,
                foot.slide_per_phase_cm_max,
                foot.penetration_cm_mean,
                foot.penetration_cm_max,
                foot.penetration_frames
            )?;
        }
        let fl = &self.floating;
        writeln!(
            f,
            "\nfloating: {} frames ({:.1}%), lowest foot above ground mean {:.2} cm, max {:.2} cm",
            fl.frames,
            fl.share * 100.0,
            fl.cm_mean,
            fl.cm_max
        )?;
        let r = self.root_height;
        writeln!(f, "root height (m): min {:.3}, mean {:.3}, max {:.3}", r.min, r.mean, r.max)?;
        self.fmt_contact_metrics(f)
    }
}

impl QualityReport {
    /// The metrics of the literature (module documentation), one line each.
    fn fmt_contact_metrics(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let g = &self.ground_penetration;
        writeln!(
            f,
            "\nground penetration: {} frames ({:.1}%) deeper than {:.1} cm over {} collision geoms, max {:.2} cm{}",
            g.frames,
            g.duration * 100.0,
            g.tolerance_cm,
            g.geoms,
            g.max_depth_cm,
            g.worst_geom.as_ref().map(|n| format!(" ({n})")).unwrap_or_default()
        )?;
        let s = &self.self_collision;
        writeln!(
            f,
            "self-collision: {} frames deeper than {:.1} cm, {} penetrating, max {:.2} cm{}; {} pairs ({} touching at qpos0, {} adjacent left out)",
            s.frames_deep,
            s.deep_cm,
            s.frames_penetrating,
            s.max_depth_cm,
            s.worst_pair.as_ref().map(|[a, b]| format!(" ({a} / {b})")).unwrap_or_default(),
            s.pairs,
            s.ignored_pairs,
            s.adjacent_pairs
        )?;
        match &self.skating {
            Some(k) => writeln!(
                f,
                "skating: {} of {} source-contact frames ({:.1}%) faster than {} m/s, max {:.2} m/s",
                k.skating_frames,
                k.stance_frames,
                k.duration * 100.0,
                k.threshold_mps,
                k.max_speed
            )?,
            None => writeln!(f, "skating: - (no source foot contacts)")?,
        }
        match &self.stance {
            Some(s) => writeln!(
                f,
                "stance: {} source-contact samples, {:.1}% floating above {:.1} cm, {:.1}% with the sole within [{:.1}, {:.1}] cm",
                s.samples,
                s.floating_share * 100.0,
                s.float_cm,
                s.sole_in_band_share * 100.0,
                s.band_cm[0],
                s.band_cm[1]
            )?,
            None => writeln!(f, "stance: - (no source foot contacts)")?,
        }
        match &self.joint_speed {
            Some(j) => writeln!(
                f,
                "joint speed limits: {} frames × joints over ({} joints with limits), worst {:.2}× ({})",
                j.violations, j.joints, j.worst_ratio, j.worst_joint
            )?,
            None => writeln!(f, "joint speed limits: - (none published)")?,
        }
        self.fmt_over_time(f)
    }

    /// The verdict: ok or the flags with their caps, then what was not measured.
    fn fmt_verdict(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = &self.verdict;
        let measured = v.checks.iter().filter(|c| c.ok.is_some()).count();
        if v.ok {
            writeln!(f, "verdict: ok ({measured} checks within their caps)")?;
        } else {
            let names: Vec<&str> = v.flag_names().collect();
            writeln!(f, "verdict: FLAGGED: {}", names.join(", "))?;
            for c in &v.flags {
                writeln!(
                    f,
                    "  {}: {} (cap {} {}): {}",
                    c.name,
                    num(c.value),
                    num(c.cap),
                    c.unit,
                    c.detail
                )?;
            }
        }
        for c in v.checks.iter().filter(|c| c.ok.is_none()) {
            writeln!(f, "  not checked: {}: {}", c.name, c.detail)?;
        }
        writeln!(f)
    }

    /// Root acceleration, jitter over nv and the dynamics check, one line or two each.
    fn fmt_over_time(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let r = &self.root_acceleration;
        let accel = |a: &AccelStats| {
            format!(
                "mean {:.1} m/s², {} frames ({:.1}%) over 2 g, max {:.1} m/s²",
                a.mean_mps2,
                a.frames_over,
                a.share_over * 100.0,
                a.max_mps2
            )
        };
        let a = &r.averaged;
        writeln!(
            f,
            "\nroot acceleration ({}, averaged over {:.3} s): {}",
            r.body,
            a.window_s,
            accel(&a.motion)
        )?;
        if let (Some(t), Some(body)) = (&a.target, &r.target_body) {
            writeln!(f, "  scaled human (target of {body}): {}", accel(t))?;
        }
        writeln!(f, "  frame by frame: {}", accel(&r.motion))?;
        if let Some(t) = &r.target {
            writeln!(f, "  scaled human, frame by frame: {}", accel(t))?;
        }
        let j = &self.jitter;
        let opt = |v: Option<f64>| v.map_or_else(|| "-".to_owned(), |v| format!("{v:.2}"));
        writeln!(
            f,
            "jitter mean |q̈| over all {} velocity coordinates: {:.2}; root translation {} m/s², root rotation {} rad/s², joints {:.2}",
            j.coordinates,
            j.all,
            opt(j.root_translation),
            opt(j.root_rotation),
            j.joints
        )?;
        let Some(d) = &self.dynamics else {
            let why = self.dynamics_unavailable.as_deref().unwrap_or("-");
            return writeln!(f, "dynamics: not available ({why})");
        };
        writeln!(
            f,
            "dynamics ({:.1} kg, L {:.2} m, μ {}, {}-edge cones, contact within {:.1} cm, accelerations over {:.3} s): residual wrench mean {:.3} / p95 {:.3} / max {:.3} m·g; {} of {} frames ({:.1}%) over {} m·g ({} of {} support frames)",
            d.mass_kg,
            d.lever_m,
            d.friction,
            d.cone_edges,
            d.contact_height_cm,
            d.window_s,
            d.residual_mg.mean,
            d.residual_mg.p95,
            d.residual_mg.max,
            d.frames_over,
            d.frames,
            d.share_over * 100.0,
            d.threshold_mg,
            d.support_frames_over,
            d.support_frames
        )?;
        let c = &d.cop;
        writeln!(
            f,
            "  centre of pressure outside the support: mean {:.2} / p95 {:.2} / max {:.2} cm, {} of {} frames ({:.1}%) beyond {:.1} cm",
            c.outside_cm.mean,
            c.outside_cm.p95,
            c.outside_cm.max,
            c.frames_outside,
            c.frames,
            c.share_outside * 100.0,
            c.tolerance_cm
        )?;
        let fl = &d.flight;
        writeln!(
            f,
            "  flight (no contact): {} frames, needed wrench mean {:.3} / max {:.3} m·g, {} ({:.1}%) over {} m·g",
            fl.frames,
            fl.residual_mg.mean,
            fl.residual_mg.max,
            fl.frames_over,
            fl.share_over * 100.0,
            d.threshold_mg
        )?;
        if let Some(five) = self
            .dynamics_5_frame
            .as_ref()
            .filter(|five| five.half_step_frames != d.half_step_frames)
        {
            writeln!(
                f,
                "  on 5 frames ({:.3} s, the earlier figure): {} of {} frames ({:.1}%) over {} m·g",
                five.window_s,
                five.frames_over,
                five.frames,
                five.share_over * 100.0,
                five.threshold_mg
            )?;
        }
        Ok(())
    }
}

/// A verdict number: integers as such, shares and ratios with three decimals.
fn num(x: f64) -> String {
    if x.fract() == 0.0 && x.abs() < 1e12 {
        format!("{x:.0}")
    } else {
        format!("{x:.3}")
    }
}
