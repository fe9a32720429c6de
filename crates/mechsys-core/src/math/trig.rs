//! sin and cos together, for the joint angles of every evaluation: a Cody–Waite reduction by π/2
//! and the classic minimax kernels on [-π/4, π/4] (coefficients as published with fdlibm), with
//! fewer branches than the C library's general `sincos` and within an ulp or two of it. Arguments
//! beyond ±10⁵ rad fall back to the standard library.

#![allow(clippy::excessive_precision)] // the constants are quoted as published

// π/2 split into three parts whose products with the quadrant number are exact
const PIO2_1: f64 = 1.570_796_326_734_125_614_17e+00;
const PIO2_2: f64 = 6.077_100_506_303_965_976_60e-11;
const PIO2_3: f64 = 2.022_266_248_711_166_455_80e-21;
const PIO2_3T: f64 = 8.478_427_660_368_899_569_97e-32;
const INV_PIO2: f64 = std::f64::consts::FRAC_2_PI;

const S1: f64 = -1.666_666_666_666_663_243_48e-01;
const S2: f64 = 8.333_333_333_322_489_461_24e-03;
const S3: f64 = -1.984_126_982_985_794_931_34e-04;
const S4: f64 = 2.755_731_370_707_006_767_89e-06;
const S5: f64 = -2.505_076_025_340_686_341_95e-08;
const S6: f64 = 1.589_690_995_211_550_102_21e-10;

const C1: f64 = 4.166_666_666_666_660_190_37e-02;
const C2: f64 = -1.388_888_888_887_410_957_49e-03;
const C3: f64 = 2.480_158_728_947_672_941_78e-05;
const C4: f64 = -2.755_731_435_139_066_330_35e-07;
const C5: f64 = 2.087_572_321_298_174_827_90e-09;
const C6: f64 = -1.135_964_755_778_819_482_65e-11;

#[inline(always)]
fn kernel_sin(x: f64) -> f64 {
    let z = x * x;
    let v = z * x;
    let r = S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)));
    x + v * (S1 + z * r)
}

#[inline(always)]
fn kernel_cos(x: f64) -> f64 {
    let z = x * x;
    let r = z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    w + (((1.0 - w) - hz) + z * r)
}

/// `(sin x, cos x)`.
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    if !(x.abs() <= 1e5) {
        return x.sin_cos();
    }
    // the nearest whole number of quarter turns (ties to even) by the 1.5·2⁵² shift, exact for
    // |x·2/π| < 2⁵¹: `f64::round` is a call into the C library on the baseline x86-64 target
    const SHIFT: f64 = 6_755_399_441_055_744.0;
    let n = (x * INV_PIO2 + SHIFT) - SHIFT;
    let r = ((x - n * PIO2_1) - n * PIO2_2) - n * (PIO2_3 + PIO2_3T);
    let (s, c) = (kernel_sin(r), kernel_cos(r));
    // quadrants 0..3 give (s, c), (c, -s), (-s, -c), (-c, s): a swap on odd quadrants and signs
    // from the two low bits, as selects and exact multiplications by ±1 instead of a branch
    let k = n as i64;
    let (a, b) = if k & 1 == 0 { (s, c) } else { (c, s) };
    let sign_sin = if k & 2 == 0 { 1.0 } else { -1.0 };
    let sign_cos = if (k ^ (k >> 1)) & 1 == 0 { 1.0 } else { -1.0 };
    (a * sign_sin, b * sign_cos)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn agrees_with_the_standard_library_to_a_few_ulps() {
        let mut worst: f64 = 0.0;
        let mut x = -60.0;
        while x < 60.0 {
            let (s, c) = sin_cos(x);
            let (s0, c0) = x.sin_cos();
            worst = worst.max((s - s0).abs()).max((c - c0).abs());
            x += 0.000_731;
        }
        assert!(worst < 4.0 * f64::EPSILON, "worst difference {worst:e}");
        // quadrant boundaries and exact values
        let (s, c) = sin_cos(std::f64::consts::FRAC_PI_2);
        assert!((s - 1.0).abs() < 1e-16 && c.abs() < 1e-16);
        let (s, c) = sin_cos(-std::f64::consts::PI);
        assert!(s.abs() < 1e-15 && (c + 1.0).abs() < 1e-16);
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        // large arguments fall back, NaN stays NaN
        let (s, _) = sin_cos(1e7);
        assert_eq!(s, 1e7f64.sin());
        assert!(sin_cos(f64::NAN).0.is_nan());
    }
}
