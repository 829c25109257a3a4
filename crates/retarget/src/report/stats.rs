//! Small statistics over frames shared by the report's measures and its verdict: means,
//! shares, numpy's percentile, and the joints they are taken over.

use serde::Serialize;

/// Mean, 95th percentile and maximum over frames.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Stats {
    pub mean: f64,
    pub p95: f64,
    pub max: f64,
}

/// Limited hinge and slide joints: `(joint index, qpos address)`.
pub(super) fn scalar_joints(model: &mjcf::Model) -> impl Iterator<Item = (usize, usize)> + '_ {
    model.joints.iter().enumerate().filter_map(|(j, joint)| {
        matches!(joint.kind, mjcf::JointType::Hinge | mjcf::JointType::Slide)
            .then_some((j, joint.qpos_adr))
    })
}

pub(super) fn ratio(a: usize, b: usize) -> f64 {
    if b == 0 {
        0.0
    } else {
        a as f64 / b as f64
    }
}

pub(super) fn mean(x: &[f64]) -> f64 {
    if x.is_empty() {
        0.0
    } else {
        x.iter().sum::<f64>() / x.len() as f64
    }
}

/// numpy's `percentile(x, 100 p)` with linear interpolation; 0 for no data. The one rule of
/// every percentile we print (the report, the main command's summary, batch summaries).
#[must_use]
pub fn percentile(x: &[f64], p: f64) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    let mut s = x.to_vec();
    let pos = p * (s.len() - 1) as f64;
    let (i, frac) = (pos.floor() as usize, pos - pos.floor());
    // The two order statistics `i` and `i + 1` (by `total_cmp`, as a sort would place
    // them) without sorting: a selection, then the least of what lies above it.
    let (_, &mut at, above) = s.select_nth_unstable_by(i, f64::total_cmp);
    let next = above.iter().copied().min_by(f64::total_cmp).unwrap_or(at);
    at + (next - at) * frac
}

pub(super) fn stats(x: &[f64]) -> Stats {
    Stats { mean: mean(x), p95: percentile(x, 0.95), max: x.iter().copied().fold(0.0, f64::max) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentile_is_numpys_linear() {
        // numpy.percentile([1, 2, 3, 4], 95) = 3.85
        assert!((percentile(&[4.0, 1.0, 3.0, 2.0], 0.95) - 3.85).abs() < 1e-12);
        assert_eq!(percentile(&[7.0], 0.99), 7.0);
        assert_eq!(percentile(&[], 0.5), 0.0);
    }
}
