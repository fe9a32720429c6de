//! Truncated Taylor series ("jets") in one variable: `f(s₀ + δ) = Σₖ cₖ δᵏ + O(δᴺ)`, stored as
//! the N coefficients `cₖ = f⁽ᵏ⁾(s₀)/k!`. Sums, products, reciprocals, square roots, sin/cos,
//! derivatives and antiderivatives act on the coefficients (the usual recurrences of automatic
//! Taylor expansion), so a curve evaluated once on jets at the real s₀ carries all its arc-length
//! derivatives up to order N − 1 — exactly, not by differences.
//!
//! The path curves use them to (1) re-parameterize a spline by arc length (`dτ/ds = 1/|P'(τ)|`
//! solved as a series, one more order per pass), (2) build the child frame and its Darboux vector
//! from the position's series, and (3) hand any `DualNum` scalar its value and derivatives: a
//! jet evaluated at `δ = s − re(s)` (a number with zero real part) by Horner's rule carries the
//! value and every derivative up to order N − 1 into the dual number's parts.

use nalgebra::Vector3;
use num_dual::DualNum;

use crate::math::Vec3;

/// A truncated Taylor series with N coefficients.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jet<const N: usize>(pub [f64; N]);

impl<const N: usize> Jet<N> {
    /// A constant.
    #[inline]
    pub fn constant(x: f64) -> Self {
        let mut c = [0.0; N];
        c[0] = x;
        Jet(c)
    }
    /// The independent variable at `x`: x + δ.
    #[inline]
    pub fn variable(x: f64) -> Self {
        let mut c = [0.0; N];
        c[0] = x;
        if N > 1 {
            c[1] = 1.0;
        }
        Jet(c)
    }
    /// The value f(s₀).
    #[inline]
    pub fn value(&self) -> f64 {
        self.0[0]
    }
    /// The k-th derivative f⁽ᵏ⁾(s₀) = k! cₖ.
    #[inline]
    pub fn derivative(&self, k: usize) -> f64 {
        let mut f = 1.0;
        for i in 2..=k {
            f *= i as f64;
        }
        self.0[k] * f
    }
    /// d/dδ; the result is valid to one order less (its last coefficient is set to 0).
    #[inline]
    pub fn diff(&self) -> Self {
        let mut c = [0.0; N];
        for k in 0..N - 1 {
            c[k] = (k + 1) as f64 * self.0[k + 1];
        }
        Jet(c)
    }
    /// The antiderivative with value `c0` at δ = 0 (the last coefficient of `self` drops out).
    #[inline]
    pub fn integral(&self, c0: f64) -> Self {
        let mut c = [0.0; N];
        c[0] = c0;
        for k in 1..N {
            c[k] = self.0[k - 1] / k as f64;
        }
        Jet(c)
    }
    /// 1/f (f(s₀) ≠ 0).
    #[inline]
    pub fn recip(&self) -> Self {
        let a = &self.0;
        let mut b = [0.0; N];
        b[0] = 1.0 / a[0];
        for k in 1..N {
            let mut acc = 0.0;
            for j in 1..=k {
                acc += a[j] * b[k - j];
            }
            b[k] = -acc * b[0];
        }
        Jet(b)
    }
    /// √f (f(s₀) > 0).
    #[inline]
    pub fn sqrt(&self) -> Self {
        let a = &self.0;
        let mut b = [0.0; N];
        b[0] = a[0].sqrt();
        for k in 1..N {
            let mut acc = a[k];
            for j in 1..k {
                acc -= b[j] * b[k - j];
            }
            b[k] = acc / (2.0 * b[0]);
        }
        Jet(b)
    }
    /// (sin f, cos f), from `(sin f)' = cos f · f'`, `(cos f)' = −sin f · f'`.
    #[inline]
    pub fn sin_cos(&self) -> (Self, Self) {
        let a = &self.0;
        let (mut s, mut c) = ([0.0; N], [0.0; N]);
        (s[0], c[0]) = a[0].sin_cos();
        for k in 1..N {
            let (mut ds, mut dc) = (0.0, 0.0);
            for j in 1..=k {
                let ja = j as f64 * a[j];
                ds += ja * c[k - j];
                dc -= ja * s[k - j];
            }
            s[k] = ds / k as f64;
            c[k] = dc / k as f64;
        }
        (Jet(s), Jet(c))
    }
    /// The series evaluated at `d` (a number whose real part is zero: its dual parts receive the
    /// derivatives), by Horner's rule; at `d = 0.0` just the value.
    #[inline]
    pub fn eval<T: DualNum<f64> + Copy>(&self, d: T) -> T {
        let mut acc = T::from(self.0[N - 1]);
        for k in (0..N - 1).rev() {
            acc = acc * d + self.0[k];
        }
        acc
    }
}

impl<const N: usize> std::ops::Add for Jet<N> {
    type Output = Self;
    #[inline]
    fn add(mut self, o: Self) -> Self {
        for k in 0..N {
            self.0[k] += o.0[k];
        }
        self
    }
}

impl<const N: usize> std::ops::Sub for Jet<N> {
    type Output = Self;
    #[inline]
    fn sub(mut self, o: Self) -> Self {
        for k in 0..N {
            self.0[k] -= o.0[k];
        }
        self
    }
}

impl<const N: usize> std::ops::Neg for Jet<N> {
    type Output = Self;
    #[inline]
    fn neg(mut self) -> Self {
        for k in 0..N {
            self.0[k] = -self.0[k];
        }
        self
    }
}

impl<const N: usize> std::ops::Mul for Jet<N> {
    type Output = Self;
    /// The Cauchy product, truncated.
    #[inline]
    fn mul(self, o: Self) -> Self {
        let mut c = [0.0; N];
        for i in 0..N {
            if self.0[i] == 0.0 {
                continue;
            }
            for j in 0..N - i {
                c[i + j] += self.0[i] * o.0[j];
            }
        }
        Jet(c)
    }
}

impl<const N: usize> std::ops::Mul<f64> for Jet<N> {
    type Output = Self;
    #[inline]
    fn mul(mut self, x: f64) -> Self {
        for k in 0..N {
            self.0[k] *= x;
        }
        self
    }
}

impl<const N: usize> std::ops::Add<f64> for Jet<N> {
    type Output = Self;
    #[inline]
    fn add(mut self, x: f64) -> Self {
        self.0[0] += x;
        self
    }
}

/// A 3-vector of jets (a curve's position, tangent, ... as series in δ).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JVec<const N: usize>(pub [Jet<N>; 3]);

impl<const N: usize> JVec<N> {
    /// The constant vector `v`.
    #[inline]
    pub fn constant(v: &Vec3) -> Self {
        JVec([Jet::constant(v.x), Jet::constant(v.y), Jet::constant(v.z)])
    }
    /// The value at δ = 0.
    #[inline]
    pub fn value(&self) -> Vec3 {
        Vec3::new(self.0[0].value(), self.0[1].value(), self.0[2].value())
    }
    /// The k-th derivative's value.
    #[inline]
    pub fn derivative(&self, k: usize) -> Vec3 {
        Vec3::new(self.0[0].derivative(k), self.0[1].derivative(k), self.0[2].derivative(k))
    }
    /// Componentwise d/dδ.
    #[inline]
    pub fn diff(&self) -> Self {
        JVec(self.0.map(|c| c.diff()))
    }
    /// Componentwise antiderivative with value `v0` at δ = 0.
    #[inline]
    pub fn integral(&self, v0: &Vec3) -> Self {
        JVec([self.0[0].integral(v0.x), self.0[1].integral(v0.y), self.0[2].integral(v0.z)])
    }
    /// Dot product.
    #[inline]
    pub fn dot(&self, o: &Self) -> Jet<N> {
        self.0[0] * o.0[0] + self.0[1] * o.0[1] + self.0[2] * o.0[2]
    }
    /// Dot product with a constant vector.
    #[inline]
    pub fn dot_const(&self, v: &Vec3) -> Jet<N> {
        self.0[0] * v.x + self.0[1] * v.y + self.0[2] * v.z
    }
    /// Cross product.
    #[inline]
    pub fn cross(&self, o: &Self) -> Self {
        let (a, b) = (&self.0, &o.0);
        JVec([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])
    }
    /// Scaled by a scalar series.
    #[inline]
    pub fn scale(&self, s: &Jet<N>) -> Self {
        JVec(self.0.map(|c| c * *s))
    }
    /// Sum.
    #[inline]
    pub fn add(&self, o: &Self) -> Self {
        JVec([self.0[0] + o.0[0], self.0[1] + o.0[1], self.0[2] + o.0[2]])
    }
    /// Difference.
    #[inline]
    pub fn sub(&self, o: &Self) -> Self {
        JVec([self.0[0] - o.0[0], self.0[1] - o.0[1], self.0[2] - o.0[2]])
    }
    /// The series evaluated at `d` (see [`Jet::eval`]).
    #[inline]
    pub fn eval<T: DualNum<f64> + Copy + nalgebra::Scalar>(&self, d: T) -> Vector3<T> {
        Vector3::new(self.0[0].eval(d), self.0[1].eval(d), self.0[2].eval(d))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_dual::{Dual2_64, Dual64};

    #[test]
    fn series_arithmetic_reproduces_known_expansions() {
        // at s₀ = 0.3: f = √(1 + s²) / (2 + sin s), against its derivatives by dual numbers of
        // the same expression (num-dual, a separate implementation)
        let s0 = 0.3;
        let x = Jet::<6>::variable(s0);
        let (sn, _) = x.sin_cos();
        let f = (x * x + 1.0).sqrt() * (sn + 2.0).recip();
        let d = Dual2_64::from(s0).derivative();
        let g = (d * d + 1.0).sqrt() / (d.sin() + 2.0);
        assert!((f.value() - g.re).abs() < 1e-15);
        assert!((f.derivative(1) - g.v1).abs() < 1e-14);
        assert!((f.derivative(2) - g.v2).abs() < 1e-14);
        // cos to fifth order at 0: 1 - δ²/2 + δ⁴/24
        let (_, c) = Jet::<6>::variable(0.0).sin_cos();
        assert_eq!(c.0, [1.0, 0.0, -0.5, 0.0, 1.0 / 24.0, 0.0]);
        // d/dδ and ∫ are inverse up to the truncated top coefficient
        let e = (x * 0.7).sin_cos().0;
        let back = e.diff().integral(e.value());
        assert!(back.0[..5].iter().zip(&e.0[..5]).all(|(a, b)| (a - b).abs() < 1e-16));
        // Horner at a dual δ gives value and slope
        let v = f.eval(Dual64::from(0.0).derivative());
        assert!((v.re - g.re).abs() < 1e-15 && (v.eps - g.v1).abs() < 1e-14);
    }
}
