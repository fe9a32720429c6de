//! The clothoid (Euler or Cornu spiral) in the x-y plane of the joint frame: the curve whose
//! curvature grows linearly with its arc length, `κ(s) = κ₀ + s/A²` (A > 0 the clothoid
//! parameter, m; κ₀ the curvature at the start, 1/m), starting at the origin along x. Its
//! tangent angle is `θ(s) = κ₀ s + s²/(2A²)`, its tangent `t = (cos θ, sin θ, 0)`, and its
//! position the Fresnel-type integral
//!
//! `x + i y = ∫₀ˢ exp(iθ(σ)) dσ`.
//!
//! Completing the square, `θ = (π/2) w² − θ₀` with `w(σ) = (σ + κ₀A²)/(A√π)` and
//! `θ₀ = κ₀²A²/2`, so `x + i y = A√π exp(−iθ₀) (E(w(s)) − E(w(0)))` with the Fresnel integral
//! `E = C + iS` (`math::fresnel`). Written with E's split form `E(w) = e(w) + exp(iπw²/2) h(w)`
//! that is `A√π (exp(−iθ₀) (e₁ − e₀) + exp(iθ(s)) h₁ − h₀)` — the oscillating factors taken
//! from θ itself, and the constants `±(1 + i)/2` cancelling exactly between two large arguments.
//! That form loses digits only when the arc [0, s] turns little while w is large (κ₀ ≠ 0,
//! short s): the difference of two nearly equal values. There (the tangent angle varying by at
//! most 8 rad over the arc) the integral is taken directly by 16-point Gauss–Legendre on at
//! most four pieces of at most 2 rad each, where the rule is exact to rounding. Both branches
//! agree with 30-digit quadrature to about 1e-14 relative (tests).

use nalgebra::Complex;

use super::jet::{JVec, Jet};
use crate::math::fresnel::fresnel_split;
use crate::math::quadrature::gl16;
use crate::math::Vec3;

/// A clothoid in the joint frame's x-y plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clothoid {
    /// The clothoid parameter A (m), > 0: κ grows by 1/A² per metre.
    pub a: f64,
    /// Curvature at s = 0 (1/m; positive: turning towards +y).
    pub kappa0: f64,
}

/// Largest variation of the tangent angle (rad) over [0, s] integrated by Gauss–Legendre.
const DIRECT: f64 = 8.0;

impl Clothoid {
    /// Signed curvature κ(s) = κ₀ + s/A² (1/m), about the z-axis.
    #[inline]
    pub fn curvature(&self, s: f64) -> f64 {
        self.kappa0 + s / (self.a * self.a)
    }
    /// Tangent angle θ(s) = κ₀ s + s²/(2A²) (rad) from the x-axis.
    #[inline]
    pub fn angle(&self, s: f64) -> f64 {
        s * (self.kappa0 + 0.5 * s / (self.a * self.a))
    }
    /// Position (x, y) at arc length s.
    pub fn position(&self, s: f64) -> [f64; 2] {
        let a2 = self.a * self.a;
        // range of θ over [0, s]: its ends and the vertex σ = −κ₀A² if inside
        let (th_s, vertex) = (self.angle(s), -self.kappa0 * a2);
        let (mut lo, mut hi) = (th_s.min(0.0), th_s.max(0.0));
        if vertex > s.min(0.0) && vertex < s.max(0.0) {
            let th_v = self.angle(vertex);
            lo = lo.min(th_v);
            hi = hi.max(th_v);
        }
        if hi - lo <= DIRECT {
            return self.direct(s, ((hi - lo) / 2.0).ceil().max(1.0) as usize);
        }
        let scale = self.a * std::f64::consts::PI.sqrt();
        let (w0, w1) = (self.kappa0 * a2 / scale, (s + self.kappa0 * a2) / scale);
        let (e0, h0) = fresnel_split(w0);
        let (e1, h1) = fresnel_split(w1);
        let th0 = 0.5 * self.kappa0 * self.kappa0 * a2;
        let v = Complex::new(th0.cos(), -th0.sin()) * (e1 - e0) + Complex::new(th_s.cos(), th_s.sin()) * h1 - h0;
        [scale * v.re, scale * v.im]
    }
    /// ∫₀ˢ (cos θ, sin θ) by Gauss–Legendre on `pieces` equal pieces.
    fn direct(&self, s: f64, pieces: usize) -> [f64; 2] {
        let rule = gl16();
        let hw = 0.5 * s / pieces as f64;
        let (mut x, mut y) = (0.0, 0.0);
        for p in 0..pieces {
            let mid = (2 * p + 1) as f64 * hw;
            for i in 0..16 {
                let (sn, cs) = self.angle(mid + hw * rule.0[i]).sin_cos();
                x += rule.1[i] * cs;
                y += rule.1[i] * sn;
            }
        }
        [x * hw, y * hw]
    }
    /// Position as a series in δ = s − s₀: θ is a quadratic, t = (cos θ, sin θ, 0) its series,
    /// r = r(s₀) + ∫ t.
    pub(super) fn r_jet<const N: usize>(&self, s0: f64) -> JVec<N> {
        let mut th = Jet::<N>::constant(self.angle(s0));
        if N > 1 {
            th.0[1] = self.curvature(s0);
        }
        if N > 2 {
            th.0[2] = 0.5 / (self.a * self.a);
        }
        let (sn, cs) = th.sin_cos();
        let [x, y] = self.position(s0);
        JVec([cs, sn, Jet::constant(0.0)]).integral(&Vec3::new(x, y, 0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// (A, κ₀, s, x, y): 30-digit quadrature of ∫₀ˢ exp(iθ) (mpmath), a reference from outside
    /// this code, over both branches (short arcs, long spirals, κ₀ of either sign, s < 0).
    const TABLE: [(f64, f64, f64, f64, f64); 8] = [
        (1.0, 0.0, 0.5, 0.49921931493660255782, 0.020810093401773634289),
        (1.0, 0.0, 3.0, 0.57648924917175973229, 0.98635161075101877579),
        (2.0, 0.3, 1.0, 0.9742863639951063867, 0.18899524089700865216),
        (0.5, -2.0, 4.0, 1.0032815901381303221, -0.014473009992730381596),
        (10.0, 1.0, 0.001, 0.00099999983333209168512, 5.0000162499950140765e-7),
        (10.0, 1.0, 25.0, 0.13405397133805969928, 1.7899390062191746083),
        (3.0, 0.0, -2.0, -1.9901460111922189399, -0.14762640011191546687),
        (1.5, 0.2, 30.0, 0.8659810338632544188, 1.2653316896051368763),
    ];

    #[test]
    fn position_matches_high_precision_quadrature_in_both_branches() {
        for (a, k0, s, x, y) in TABLE {
            let c = Clothoid { a, kappa0: k0 };
            let [px, py] = c.position(s);
            let err = (px - x).hypot(py - y) / x.hypot(y);
            assert!(err < 1e-13, "A = {a}, κ₀ = {k0}, s = {s}: ({px}, {py}) vs ({x}, {y}), rel. error {err:.1e}");
        }
    }

    #[test]
    fn series_derivatives_are_the_tangent_and_the_curvature() {
        let c = Clothoid { a: 1.3, kappa0: -0.4 };
        for s in [-2.0, 0.0, 0.7, 5.0] {
            let r = c.r_jet::<5>(s);
            let th = c.angle(s);
            assert!((r.derivative(1) - Vec3::new(th.cos(), th.sin(), 0.0)).norm() < 1e-15);
            let k = c.curvature(s);
            assert!((r.derivative(2) - Vec3::new(-th.sin(), th.cos(), 0.0) * k).norm() < 1e-14);
            // the position's series against differences of the position itself
            let e = 1e-5;
            let d = (Vec3::new(c.position(s + e)[0], c.position(s + e)[1], 0.0)
                - Vec3::new(c.position(s - e)[0], c.position(s - e)[1], 0.0))
                / (2.0 * e);
            assert!((d - r.derivative(1)).norm() < 1e-9, "s = {s}: {:.2e}", (d - r.derivative(1)).norm());
        }
    }
}
