//! Gauss–Legendre quadrature: `∫₋₁¹ f(x) dx ≈ Σ wᵢ f(xᵢ)` with the n zeros xᵢ of the Legendre
//! polynomial Pₙ and the weights `wᵢ = 2 / ((1 − xᵢ²) Pₙ'(xᵢ)²)`, exact for polynomials of degree
//! 2n − 1. The nodes are found once per n by Newton's method on the three-term recurrence
//! `(k + 1) Pₖ₊₁ = (2k + 1) x Pₖ − k Pₖ₋₁` (`Pₙ' = n (x Pₙ − Pₙ₋₁) / (x² − 1)`), started from
//! the asymptotic estimate `cos(π (i − ¼) / (n + ½))`; they are accurate to a few ulps.
//!
//! Used by the path curves (arc length of a spline, the clothoid's position for short arcs).

use std::sync::OnceLock;

/// Nodes and weights of the n-point rule on [-1, 1], ascending nodes.
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    assert!(n >= 1, "a Gauss–Legendre rule needs at least one node");
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    let nf = n as f64;
    // Pₙ(z) and Pₙ₋₁(z) by the recurrence
    let legendre = |z: f64| {
        let (mut p0, mut p1) = (1.0, z);
        for k in 1..n {
            let kf = k as f64;
            let p2 = ((2.0 * kf + 1.0) * z * p1 - kf * p0) / (kf + 1.0);
            p0 = p1;
            p1 = p2;
        }
        (p1, p0)
    };
    for i in 0..n.div_ceil(2) {
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (nf + 0.5)).cos();
        for _ in 0..100 {
            let (p, pm) = legendre(z);
            let dz = p / (nf * (z * p - pm) / (z * z - 1.0));
            z -= dz;
            if dz.abs() <= 1e-16 {
                break;
            }
        }
        let (p, pm) = legendre(z);
        let dp = nf * (z * p - pm) / (z * z - 1.0);
        let wi = 2.0 / ((1.0 - z * z) * dp * dp);
        // z runs from near +1 downwards; fill symmetric pairs
        x[n - 1 - i] = z;
        x[i] = -z;
        w[n - 1 - i] = wi;
        w[i] = wi;
    }
    if n % 2 == 1 {
        x[n / 2] = 0.0;
    }
    (x, w)
}

/// The n-point rule as a fixed array (computed on first use, then shared).
fn fixed<const N: usize>(cell: &'static OnceLock<([f64; N], [f64; N])>) -> &'static ([f64; N], [f64; N]) {
    cell.get_or_init(|| {
        let (x, w) = gauss_legendre(N);
        let mut a = ([0.0; N], [0.0; N]);
        a.0.copy_from_slice(&x);
        a.1.copy_from_slice(&w);
        a
    })
}

/// The 8-point rule (exact to degree 15).
pub fn gl8() -> &'static ([f64; 8], [f64; 8]) {
    static CELL: OnceLock<([f64; 8], [f64; 8])> = OnceLock::new();
    fixed(&CELL)
}

/// The 16-point rule (exact to degree 31).
pub fn gl16() -> &'static ([f64; 16], [f64; 16]) {
    static CELL: OnceLock<([f64; 16], [f64; 16])> = OnceLock::new();
    fixed(&CELL)
}

/// `∫ₐᵇ f` by the rule `(x, w)` on [a, b].
#[inline]
pub fn integrate<const N: usize>(rule: &([f64; N], [f64; N]), a: f64, b: f64, mut f: impl FnMut(f64) -> f64) -> f64 {
    let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
    let mut sum = 0.0;
    for i in 0..N {
        sum += rule.1[i] * f(m + h * rule.0[i]);
    }
    sum * h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules_integrate_polynomials_exactly_and_match_the_known_three_point_rule() {
        for n in [1, 2, 3, 5, 8, 16, 33] {
            let (x, w) = gauss_legendre(n);
            assert!((w.iter().sum::<f64>() - 2.0).abs() < 1e-14, "n = {n}");
            // ∫₋₁¹ x^k = 2/(k+1) for even k, 0 for odd k, up to degree 2n-1
            for k in 0..2 * n {
                let q: f64 = x.iter().zip(&w).map(|(xi, wi)| wi * xi.powi(k as i32)).sum();
                let exact = if k % 2 == 0 { 2.0 / (k as f64 + 1.0) } else { 0.0 };
                assert!((q - exact).abs() < 1e-14, "n = {n}, degree {k}: {q} vs {exact}");
            }
            assert!(x.windows(2).all(|p| p[0] < p[1]));
        }
        // the three-point rule in closed form: ±√(3/5) with 5/9, 0 with 8/9
        let (x, w) = gauss_legendre(3);
        assert!(
            (x[2] - 0.6f64.sqrt()).abs() < 3e-16
                && (w[0] - 5.0 / 9.0).abs() < 5e-16
                && (w[1] - 8.0 / 9.0).abs() < 3e-16
        );
        // a smooth non-polynomial: ∫₀^π sin = 2
        assert!((integrate(gl16(), 0.0, std::f64::consts::PI, f64::sin) - 2.0).abs() < 1e-15);
        assert!((integrate(gl8(), 0.0, 1.0, f64::exp) - (1f64.exp() - 1.0)).abs() < 1e-15);
    }
}
