//! Random configurations for tests, benchmarks and `retarget robot check`: the sampling rule of
//! the reference FK oracle (root x, y ~ U(-2, 2), z ~ U(0, 2), orientations uniform on SO(3),
//! limited joints uniform in their range).

use std::f64::consts::PI;

use rand::Rng;

use crate::model::{Joint, JointType, Model};

impl Model {
    /// A random `qpos`: free joints at a random pose (x, y in [-2, 2], z in [0, 2], uniform
    /// orientation with w ≥ 0), ball joints at a uniform orientation, limited hinges and slides
    /// uniform in their range, unlimited hinges in [-π, π] and unlimited slides in [-1, 1].
    // `qpos_adr` of each joint and its width lie inside `nq` by the model's construction.
    #[allow(clippy::indexing_slicing)]
    pub fn random_qpos<R: Rng + ?Sized>(&self, rng: &mut R) -> Vec<f64> {
        let mut qpos = self.qpos0.clone();
        for joint in &self.joints {
            random_joint(joint, rng, &mut qpos);
        }
        qpos
    }
}

/// Sets `joint`'s coordinates in `qpos` by [`Model::random_qpos`]'s rule.
// `qpos_adr` of each joint and its width lie inside `nq` by the model's construction.
#[allow(clippy::indexing_slicing)]
pub(crate) fn random_joint<R: Rng + ?Sized>(joint: &Joint, rng: &mut R, qpos: &mut [f64]) {
    let a = joint.qpos_adr;
    match joint.kind {
        JointType::Free => {
            qpos[a] = rng.gen_range(-2.0..2.0);
            qpos[a + 1] = rng.gen_range(-2.0..2.0);
            qpos[a + 2] = rng.gen_range(0.0..2.0);
            qpos[a + 3..a + 7].copy_from_slice(&random_quat(rng));
        }
        JointType::Ball => qpos[a..a + 4].copy_from_slice(&random_quat(rng)),
        JointType::Hinge | JointType::Slide => {
            let [lo, hi] = joint.range.unwrap_or(if joint.kind == JointType::Hinge {
                [-PI, PI]
            } else {
                [-1.0, 1.0]
            });
            qpos[a] = if lo < hi { rng.gen_range(lo..hi) } else { lo };
        }
    }
}

/// Uniform random unit quaternion (normalised 4-D Gaussian, Box–Muller), w ≥ 0.
// Constant indices into fixed-size arrays.
#[allow(clippy::indexing_slicing)]
fn random_quat<R: Rng + ?Sized>(rng: &mut R) -> [f64; 4] {
    loop {
        let mut q = [0.0; 4];
        for pair in q.chunks_mut(2) {
            let u1: f64 = rng.gen_range(f64::EPSILON..1.0);
            let u2: f64 = rng.gen_range(0.0..1.0);
            let r = (-2.0 * u1.ln()).sqrt();
            pair[0] = r * (2.0 * PI * u2).cos();
            pair[1] = r * (2.0 * PI * u2).sin();
        }
        let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
        if n > 1e-6 {
            let s = if q[0] < 0.0 { -1.0 / n } else { 1.0 / n };
            return q.map(|v| v * s);
        }
    }
}
