//! `sin` and `cos` together, inlined: the FK loop evaluates three per joint per frame, and the
//! platform's `sincos` call was two thirds of its time. Reduction by π/2 (Cody–Waite, two
//! parts) and the minimax kernels of fdlibm (FreeBSD msun `k_sin.c`, `k_cos.c`), within about
//! one ulp of the correctly rounded result for the arguments FK sees (half-angles, |x| < 2¹⁹·π/2);
//! anything larger goes to `f64::sin_cos`.
//!
//! The kernel coefficients: Copyright (C) 1993 by Sun Microsystems, Inc. All rights reserved.
//! Developed at SunPro, a Sun Microsystems, Inc. business. Permission to use, copy, modify,
//! and distribute this software is freely granted, provided that this notice is preserved.

// The coefficients as published in fdlibm, digit for digit.
#![allow(clippy::excessive_precision)]

const S1: f64 = -1.666_666_666_666_663_243_48e-1;
const S2: f64 = 8.333_333_333_322_489_461_24e-3;
const S3: f64 = -1.984_126_982_985_794_931_34e-4;
const S4: f64 = 2.755_731_370_707_006_767_89e-6;
const S5: f64 = -2.505_076_025_340_686_341_95e-8;
const S6: f64 = 1.589_690_995_211_550_102_21e-10;

const C1: f64 = 4.166_666_666_666_660_190_37e-2;
const C2: f64 = -1.388_888_888_887_410_957_49e-3;
const C3: f64 = 2.480_158_728_947_672_941_78e-5;
const C4: f64 = -2.755_731_435_139_066_330_35e-7;
const C5: f64 = 2.087_572_321_298_174_827_90e-9;
const C6: f64 = -1.135_964_755_778_819_482_65e-11;

/// 2/π, and π/2 split into its first 33 bits and the next 53 (fdlibm `e_rem_pio2.c`).
const INV_PIO2: f64 = std::f64::consts::FRAC_2_PI;
const PIO2_1: f64 = 1.570_796_326_734_125_614_17;
const PIO2_1T: f64 = 6.077_100_506_506_192_249_32e-11;

const ROUNDER: f64 = 6_755_399_441_055_744.0;

/// Beyond this, `n · PIO2_1` stops being exact; use the library.
const REDUCE_MAX: f64 = 524_288.0 * std::f64::consts::FRAC_PI_2;

/// sin on [-π/4, π/4], `y` the tail of the reduced argument.
#[inline]
fn kernel_sin(x: f64, y: f64) -> f64 {
    let z = x * x;
    let w = z * z;
    let r = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6);
    let v = z * x;
    x - ((z * (0.5 * y - v * r) - y) - v * S1)
}

/// cos on [-π/4, π/4], `y` the tail of the reduced argument.
#[inline]
fn kernel_cos(x: f64, y: f64) -> f64 {
    let z = x * x;
    let w = z * z;
    let r = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    w + (((1.0 - w) - hz) + (z * r - x * y))
}

/// `(sin x, cos x)`, one at a time (the reference for [`half_angles_sin_cos`]).
#[cfg(test)]
#[must_use]
pub(crate) fn sin_cos(x: f64) -> (f64, f64) {
    if in_range(x) {
        reduced_sin_cos(x)
    } else {
        x.sin_cos()
    }
}

#[inline]
fn in_range(x: f64) -> bool {
    x.abs() < REDUCE_MAX
}

/// The fast path for `|x| < REDUCE_MAX`: no branches and no float-to-integer conversion, so a
/// loop over it vectorizes with SSE2.
#[inline]
fn reduced_sin_cos(x: f64) -> (f64, f64) {
    // Round to nearest by the 1.5·2⁵² trick: the low bits of `shifted` hold n mod 4.
    let shifted = x * INV_PIO2 + ROUNDER;
    let n = shifted - ROUNDER;
    let r = x - n * PIO2_1; // exact: n has at most 20 bits, PIO2_1 33
    let w = n * PIO2_1T;
    let head = r - w;
    let tail = (r - head) - w;
    let (s, c) = (kernel_sin(head, tail), kernel_cos(head, tail));
    // Quadrant q: (sin, cos) = (s, c), (c, −s), (−s, −c), (−c, s). Branch-free: the quadrant
    // of a joint angle is data, and a mispredicted branch costs as much as the polynomials.
    let q = shifted.to_bits();
    let swap = 0u64.wrapping_sub(q & 1);
    let (s, c) = (s.to_bits(), c.to_bits());
    let sin = (s & !swap) | (c & swap);
    let cos = (c & !swap) | (s & swap);
    (f64::from_bits(sin ^ ((q & 2) << 62)), f64::from_bits(cos ^ (((q + 1) & 2) << 62)))
}

/// `sin` and `cos` of half of every angle in `degrees` (converted as `f64::to_radians`), into
/// `sin` and `cos`. One tight loop the compiler vectorizes, then a scalar pass for the rare
/// huge or non-finite argument.
#[allow(clippy::indexing_slicing)]
pub(crate) fn half_angles_sin_cos(degrees: &[f64], sin: &mut [f64], cos: &mut [f64]) {
    // Indexing within slices all cut to one length `n`: the compiler drops the bounds checks
    // and vectorizes the first loop (the fk benchmark: iterator zips ran 25 % slower).
    let n = degrees.len().min(sin.len()).min(cos.len());
    let (values, sin, cos) = (&degrees[..n], &mut sin[..n], &mut cos[..n]);
    for i in 0..n {
        let (s, c) = reduced_sin_cos(values[i].to_radians() / 2.0);
        sin[i] = s;
        cos[i] = c;
    }
    for i in 0..n {
        let x = values[i].to_radians() / 2.0;
        if !in_range(x) {
            (sin[i], cos[i]) = x.sin_cos();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn agrees_with_the_platform_to_an_ulp_or_two() {
        let mut rng = ChaCha8Rng::seed_from_u64(0x5eed_0004);
        let specials = [
            0.0,
            -0.0,
            1e-300,
            std::f64::consts::FRAC_PI_4,
            std::f64::consts::PI,
            -std::f64::consts::PI,
        ];
        let random = (0..200_000).map(|i| match i % 3 {
            0 => rng.gen_range(-4.0..4.0),
            1 => rng.gen_range(-1000.0..1000.0),
            _ => rng.gen_range(-1e-6..1e-6),
        });
        for x in specials.into_iter().chain(random).chain([1e7, -3e9]) {
            let (s, c) = sin_cos(x);
            assert!(
                (s - x.sin()).abs() <= 2.5e-16 * x.sin().abs().max(1e-300) + 1e-300
                    || (s - x.sin()).abs() < 3e-16,
                "sin {x}: {s} vs {}",
                x.sin()
            );
            assert!((c - x.cos()).abs() < 3e-16, "cos {x}: {c} vs {}", x.cos());
        }
    }

    #[test]
    fn the_row_version_is_the_scalar_one() {
        let values = [0.0, 45.0, -179.9, 360.0, 1e9, f64::NAN, f64::INFINITY, -1234.5, 90.0];
        let (mut sin, mut cos) = ([0.0; 9], [0.0; 9]);
        half_angles_sin_cos(&values, &mut sin, &mut cos);
        for (i, v) in values.iter().enumerate() {
            let (s, c) = sin_cos(v.to_radians() / 2.0);
            assert_eq!((s.to_bits(), c.to_bits()), (sin[i].to_bits(), cos[i].to_bits()), "{v}");
        }
    }
}
