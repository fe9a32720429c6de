//! Cubic interpolating splines of one variable, C² at the knots: natural (zero second derivative
//! at both ends, extended linearly beyond them) or periodic. Built once (allocation), evaluated
//! per step without allocation: value and three derivatives.

use crate::ensure;
use crate::error::Result;

/// A cubic spline `f(t)` through `(t_i, y_i)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Spline1 {
    /// Knots, strictly increasing (for a periodic spline the last one closes the period).
    knots: Vec<f64>,
    /// Per segment the Taylor coefficients about its first knot: `f = c0 + c1 τ + c2 τ² + c3 τ³`.
    coef: Vec<[f64; 4]>,
    periodic: bool,
}

/// Value and the first three derivatives.
pub type Jet1 = [f64; 4];

impl Spline1 {
    /// A natural spline through `(t_i, y_i)` (at least 2 points); beyond the ends it continues
    /// along its end tangents.
    pub fn natural(t: &[f64], y: &[f64], what: &str) -> Result<Self> {
        check(t, y, 2, what)?;
        let n = t.len() - 1;
        // second derivatives m_i: m_0 = m_n = 0, tridiagonal system for the interior (Thomas)
        let h: Vec<f64> = (0..n).map(|i| t[i + 1] - t[i]).collect();
        let mut m = vec![0.0; n + 1];
        if n >= 2 {
            let k = n - 1;
            let (mut diag, mut rhs) = (vec![0.0; k], vec![0.0; k]);
            let mut sub = vec![0.0; k];
            for j in 0..k {
                let i = j + 1;
                diag[j] = 2.0 * (h[i - 1] + h[i]);
                sub[j] = h[i - 1];
                rhs[j] = 6.0 * ((y[i + 1] - y[i]) / h[i] - (y[i] - y[i - 1]) / h[i - 1]);
            }
            // forward elimination with super-diagonal h[i]
            for j in 1..k {
                let w = sub[j] / diag[j - 1];
                diag[j] -= w * h[j];
                rhs[j] -= w * rhs[j - 1];
            }
            let mut x = vec![0.0; k];
            x[k - 1] = rhs[k - 1] / diag[k - 1];
            for j in (0..k - 1).rev() {
                x[j] = (rhs[j] - h[j + 1] * x[j + 1]) / diag[j];
            }
            m[1..n].copy_from_slice(&x);
        }
        Ok(Spline1 { coef: coefficients(&h, y, &m), knots: t.to_vec(), periodic: false })
    }

    /// A periodic spline through `(t_i, y_i)`, `i = 0..=n`, with `y_n = y_0` required (the period
    /// is `t_n - t_0`; at least 3 distinct points).
    pub fn periodic(t: &[f64], y: &[f64], what: &str) -> Result<Self> {
        check(t, y, 4, what)?;
        let n = t.len() - 1;
        closes(y, what)?;
        let h: Vec<f64> = (0..n).map(|i| t[i + 1] - t[i]).collect();
        // unknowns m_0..m_{n-1} (m_n = m_0); cyclic tridiagonal, solved densely (built once, n small)
        let mut a = vec![0.0; n * n];
        let mut b = vec![0.0; n];
        for i in 0..n {
            let (hp, hn) = (h[(i + n - 1) % n], h[i]);
            let yp = if i == 0 { y[n - 1] } else { y[i - 1] };
            a[i * n + (i + n - 1) % n] += hp;
            a[i * n + i] += 2.0 * (hp + hn);
            a[i * n + (i + 1) % n] += hn;
            b[i] = 6.0 * ((y[i + 1] - y[i]) / hn - (y[i] - yp) / hp);
        }
        let x = solve_dense(n, &mut a, &mut b);
        let mut m = x.clone();
        m.push(x[0]);
        Ok(Spline1 { coef: coefficients(&h, y, &m), knots: t.to_vec(), periodic: true })
    }

    /// Parameter range `[t_0, t_n]`.
    pub fn range(&self) -> (f64, f64) {
        (self.knots[0], self.knots[self.knots.len() - 1])
    }

    /// Knots.
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// Whether the spline is periodic.
    pub fn is_periodic(&self) -> bool {
        self.periodic
    }

    /// `[f, f', f'', f''']` at `t` (periodic: `t` wrapped into the period; natural: linear beyond
    /// the ends). No allocation.
    #[inline]
    pub fn eval(&self, t: f64) -> Jet1 {
        let (lo, hi) = self.range();
        let n = self.coef.len();
        let t = if self.periodic { wrap(t, lo, hi) } else { t };
        if !self.periodic && t < lo {
            let c = &self.coef[0];
            return [c[0] + c[1] * (t - lo), c[1], 0.0, 0.0];
        }
        if !self.periodic && t > hi {
            let j = end_jet(&self.coef[n - 1], hi - self.knots[n - 1]);
            return [j[0] + j[1] * (t - hi), j[1], 0.0, 0.0];
        }
        // segment: the last knot ≤ t
        let i = match self.knots.binary_search_by(|k| k.partial_cmp(&t).unwrap_or(std::cmp::Ordering::Less)) {
            Ok(i) => i.min(n - 1),
            Err(i) => i.saturating_sub(1).min(n - 1),
        };
        end_jet(&self.coef[i], t - self.knots[i])
    }
}

/// A periodic quintic spline on equally spaced knots, C⁴: `f(t) = Σ c_j B₅((t - t_j) / h)` with
/// the centred quintic B-spline `B₅`. Interpolation gives the cyclic system
/// `(c_{i-2} + 26 c_{i-1} + 66 c_i + 26 c_{i+1} + c_{i+2}) / 120 = y_i`, strictly diagonally
/// dominant, solved by Gauss–Seidel when built. A smooth motion law tabulated on such knots keeps
/// four continuous derivatives (a cubic spline's third derivative jumps at every knot, which an
/// error-controlled integrator pays for with rejected steps).
#[derive(Debug, Clone, PartialEq)]
pub struct Quintic1 {
    t0: f64,
    h: f64,
    /// Per segment the polynomial in the local coordinate `τ ∈ [0, 1)`: `Σ a_p τ^p` (built from
    /// the B-spline coefficients once, so evaluation is a stable Horner scheme).
    seg: Vec<[f64; 6]>,
}

/// Value and the first four derivatives.
pub type Jet1x = [f64; 5];

impl Quintic1 {
    /// Through `(t_i, y_i)`, `i = 0..=n`, equally spaced, `y_n = y_0` (at least 6 distinct points);
    /// `None` when the knots are not equally spaced (to 1e-9 of the spacing).
    pub fn periodic(t: &[f64], y: &[f64], what: &str) -> Result<Option<Self>> {
        check(t, y, 7, what)?;
        let n = t.len() - 1;
        let h = (t[n] - t[0]) / n as f64;
        if (0..=n).any(|i| (t[i] - (t[0] + h * i as f64)).abs() > 1e-9 * h) {
            return Ok(None);
        }
        closes(y, what)?;
        let mut c: Vec<f64> = y[..n].to_vec();
        let at = |k: isize| ((k % n as isize + n as isize) % n as isize) as usize;
        for _ in 0..2000 {
            let mut change: f64 = 0.0;
            for i in 0..n {
                let ii = i as isize;
                let off = c[at(ii - 2)] + 26.0 * c[at(ii - 1)] + 26.0 * c[at(ii + 1)] + c[at(ii + 2)];
                let new = (120.0 * y[i] - off) / 66.0;
                change = change.max((new - c[i]).abs());
                c[i] = new;
            }
            if change <= 1e-16 * y.iter().fold(1e-300f64, |a, v| a.max(v.abs())) {
                break;
            }
        }
        // the pieces of B₅ over one unit interval, as polynomials in τ: B₅(τ + m) for the shift
        // m = i - j ∈ {-3, ..., 2} of knot j relative to segment i (exact small-integer arithmetic)
        const BINOM6: [f64; 7] = [1.0, -6.0, 15.0, -20.0, 15.0, -6.0, 1.0];
        const BINOM5: [f64; 6] = [1.0, 5.0, 10.0, 10.0, 5.0, 1.0];
        let mut piece = [[0.0; 6]; 6];
        for (idx, m) in (-3i32..=2).enumerate() {
            for (k, b) in BINOM6.iter().enumerate() {
                let shift = m + 3 - k as i32;
                if shift < 0 {
                    continue;
                }
                // (τ + shift)⁵ = Σ_p C(5, p) shift^(5-p) τ^p
                for (pw, c5) in BINOM5.iter().enumerate() {
                    piece[idx][pw] += b * c5 * (shift as f64).powi(5 - pw as i32) / 120.0;
                }
            }
        }
        let seg = (0..n)
            .map(|i| {
                let mut a = [0.0; 6];
                for (idx, m) in (-3i32..=2).enumerate() {
                    let cj = c[at(i as isize - m as isize)];
                    for p in 0..6 {
                        a[p] += cj * piece[idx][p];
                    }
                }
                a
            })
            .collect();
        Ok(Some(Quintic1 { t0: t[0], h, seg }))
    }

    /// `[f, f', f'', f''', f'''']` at `t` (wrapped into the period). No allocation.
    #[inline]
    pub fn eval(&self, t: f64) -> Jet1x {
        let n = self.seg.len();
        let period = self.h * n as f64;
        let x = (wrap(t, self.t0, self.t0 + period) - self.t0) / self.h;
        let i = (x.floor() as usize).min(n - 1);
        let tau = x - i as f64;
        let a = &self.seg[i];
        // Horner for the value and the derivatives in τ
        let f0 = a[0] + tau * (a[1] + tau * (a[2] + tau * (a[3] + tau * (a[4] + tau * a[5]))));
        let f1 = a[1] + tau * (2.0 * a[2] + tau * (3.0 * a[3] + tau * (4.0 * a[4] + tau * 5.0 * a[5])));
        let f2 = 2.0 * a[2] + tau * (6.0 * a[3] + tau * (12.0 * a[4] + tau * 20.0 * a[5]));
        let f3 = 6.0 * a[3] + tau * (24.0 * a[4] + tau * 60.0 * a[5]);
        let f4 = 24.0 * a[4] + tau * 120.0 * a[5];
        let ih = 1.0 / self.h;
        [f0, f1 * ih, f2 * ih * ih, f3 * ih * ih * ih, f4 * ih * ih * ih * ih]
    }
}

/// `t` wrapped into `[lo, hi)`.
#[inline]
pub fn wrap(t: f64, lo: f64, hi: f64) -> f64 {
    let p = hi - lo;
    let mut x = (t - lo) % p;
    if x < 0.0 {
        x += p;
    }
    // `x` may round to `p` for tiny negative inputs
    if x >= p {
        x -= p;
    }
    lo + x
}

#[inline]
fn end_jet(c: &[f64; 4], tau: f64) -> Jet1 {
    [
        c[0] + tau * (c[1] + tau * (c[2] + tau * c[3])),
        c[1] + tau * (2.0 * c[2] + tau * 3.0 * c[3]),
        2.0 * c[2] + 6.0 * c[3] * tau,
        6.0 * c[3],
    ]
}

fn coefficients(h: &[f64], y: &[f64], m: &[f64]) -> Vec<[f64; 4]> {
    (0..h.len())
        .map(|i| {
            let hi = h[i];
            [
                y[i],
                (y[i + 1] - y[i]) / hi - hi * (2.0 * m[i] + m[i + 1]) / 6.0,
                m[i] / 2.0,
                (m[i + 1] - m[i]) / (6.0 * hi),
            ]
        })
        .collect()
}

/// A periodic spline's data must end where it starts.
fn closes(y: &[f64], what: &str) -> Result<()> {
    let n = y.len() - 1;
    let scale = y.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(1e-300);
    ensure!(
        (y[n] - y[0]).abs() <= 1e-12 * scale,
        Model,
        "{what}: a periodic spline must end where it starts, got {} at the start and {} at the end",
        y[0],
        y[n]
    );
    Ok(())
}

fn check(t: &[f64], y: &[f64], min: usize, what: &str) -> Result<()> {
    ensure!(t.len() == y.len(), Model, "{what}: {} parameters but {} values", t.len(), y.len());
    ensure!(t.len() >= min, Model, "{what}: needs at least {min} points, got {}", t.len());
    for (i, (a, b)) in t.iter().zip(y).enumerate() {
        ensure!(a.is_finite() && b.is_finite(), Model, "{what}: point {i} is not finite ({a}, {b})");
    }
    for i in 0..t.len() - 1 {
        ensure!(
            t[i + 1] > t[i],
            Model,
            "{what}: the parameters must increase strictly, but point {} ({}) does not follow point {i} ({})",
            i + 1,
            t[i + 1],
            t[i]
        );
    }
    Ok(())
}

/// Gaussian elimination with partial pivoting (build time only).
fn solve_dense(n: usize, a: &mut [f64], b: &mut [f64]) -> Vec<f64> {
    for c in 0..n {
        let p = (c..n).max_by(|&i, &j| a[i * n + c].abs().total_cmp(&a[j * n + c].abs())).unwrap_or(c);
        if p != c {
            for k in 0..n {
                a.swap(c * n + k, p * n + k);
            }
            b.swap(c, p);
        }
        let d = a[c * n + c];
        for r in c + 1..n {
            let w = a[r * n + c] / d;
            if w != 0.0 {
                for k in c..n {
                    a[r * n + k] -= w * a[c * n + k];
                }
                b[r] -= w * b[c];
            }
        }
    }
    let mut x = vec![0.0; n];
    for r in (0..n).rev() {
        let s: f64 = (r + 1..n).map(|k| a[r * n + k] * x[k]).sum();
        x[r] = (b[r] - s) / a[r * n + r];
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn natural_spline_reproduces_a_line_and_is_c2() {
        let t = [0.0, 0.3, 1.0, 1.7, 2.0];
        let y: Vec<f64> = t.iter().map(|x| 2.0 * x - 1.0).collect();
        let s = Spline1::natural(&t, &y, "s").unwrap();
        for x in [-0.5, 0.1, 0.99, 1.3, 2.5] {
            let j = s.eval(x);
            assert!((j[0] - (2.0 * x - 1.0)).abs() < 1e-14 && (j[1] - 2.0).abs() < 1e-13 && j[2].abs() < 1e-12);
        }
        // C² at interior knots of a curved spline
        let y2 = [0.0, 1.0, -0.5, 0.7, 0.2];
        let s = Spline1::natural(&t, &y2, "s").unwrap();
        for (i, &k) in t.iter().enumerate().take(4).skip(1) {
            let (a, b) = (s.eval(k - 1e-12), s.eval(k + 1e-12));
            assert!((a[0] - y2[i]).abs() < 1e-11 && (a[1] - b[1]).abs() < 1e-9 && (a[2] - b[2]).abs() < 1e-8);
        }
        assert!(s.eval(0.0)[2].abs() < 1e-12 && s.eval(2.0)[2].abs() < 1e-12);
    }

    #[test]
    fn periodic_spline_of_a_cosine_converges_at_fourth_order() {
        let err = |n: usize| {
            let t: Vec<f64> = (0..=n).map(|i| std::f64::consts::TAU * i as f64 / n as f64).collect();
            let mut y: Vec<f64> = t.iter().map(|x| x.cos()).collect();
            y[n] = y[0];
            let s = Spline1::periodic(&t, &y, "s").unwrap();
            (0..200).map(|k| 0.0314 * k as f64 + 0.01).map(|x| (s.eval(x)[0] - x.cos()).abs()).fold(0.0, f64::max)
        };
        let (e1, e2) = (err(32), err(64));
        assert!(e1 < 1e-5 && (e1 / e2).log2() > 3.8, "{e1} {e2}");
        // the period wraps: f(t + 2π) = f(t), including the derivatives
        let t: Vec<f64> = (0..=16).map(|i| std::f64::consts::TAU * i as f64 / 16.0).collect();
        let y: Vec<f64> = t.iter().map(|x| (2.0 * x).sin()).collect();
        let mut y = y;
        y[16] = y[0];
        let s = Spline1::periodic(&t, &y, "s").unwrap();
        let (a, b) = (s.eval(0.4), s.eval(0.4 + 3.0 * std::f64::consts::TAU));
        assert!(a.iter().zip(&b).all(|(p, q)| (p - q).abs() < 1e-9));
        let (c, d) = (s.eval(-1e-13), s.eval(1e-13));
        assert!((c[1] - d[1]).abs() < 1e-9 && (c[2] - d[2]).abs() < 1e-8);
    }

    #[test]
    fn periodic_quintic_interpolates_is_c4_and_converges_at_sixth_order() {
        let tau = std::f64::consts::TAU;
        let err = |n: usize| {
            let t: Vec<f64> = (0..=n).map(|i| tau * i as f64 / n as f64).collect();
            let mut y: Vec<f64> = t.iter().map(|x| (x.cos() + 0.3 * (2.0 * x).sin()).exp()).collect();
            y[n] = y[0];
            let s = Quintic1::periodic(&t, &y, "q").unwrap().unwrap();
            // interpolates
            for (a, b) in t.iter().zip(&y) {
                assert!((s.eval(*a)[0] - b).abs() < 1e-12);
            }
            let f = |x: f64| (x.cos() + 0.3 * (2.0 * x).sin()).exp();
            (0..300).map(|k| 0.0209 * k as f64 + 0.004).map(|x| (s.eval(x)[0] - f(x)).abs()).fold(0.0, f64::max)
        };
        let (e1, e2) = (err(40), err(80));
        assert!((e1 / e2).log2() > 5.5, "{e1} {e2}");
        // derivatives against differences and continuity of the fourth across a knot
        let n = 24;
        let t: Vec<f64> = (0..=n).map(|i| tau * i as f64 / n as f64).collect();
        let mut y: Vec<f64> = t.iter().map(|x| (3.0 * x).sin() * 0.2 + x.cos()).collect();
        y[n] = y[0];
        let s = Quintic1::periodic(&t, &y, "q").unwrap().unwrap();
        let (x, h) = (0.77, 1e-5);
        let (a, b, c) = (s.eval(x - h), s.eval(x), s.eval(x + h));
        for k in 0..4 {
            let fd = (c[k] - a[k]) / (2.0 * h);
            assert!((fd - b[k + 1]).abs() < 1e-5 * (1.0 + b[k + 1].abs()), "derivative {k}: {fd} vs {}", b[k + 1]);
        }
        let knot = t[5];
        let (l, r) = (s.eval(knot - 1e-10), s.eval(knot + 1e-10));
        assert!((l[4] - r[4]).abs() < 1e-6 * (1.0 + l[4].abs()));
        // unequal spacing: not for this spline
        let mut t2 = t.clone();
        t2[3] += 0.01;
        assert!(Quintic1::periodic(&t2, &y, "q").unwrap().is_none());
    }

    #[test]
    fn bad_data_is_named() {
        let e = Spline1::natural(&[0.0, 1.0, 1.0], &[0.0, 1.0, 2.0], "cam 'c'").unwrap_err().to_string();
        assert!(e.contains("cam 'c'") && e.contains("increase strictly"), "{e}");
        let e = Spline1::periodic(&[0.0, 1.0, 2.0, 3.0], &[0.0, 1.0, 2.0, 0.5], "lift").unwrap_err().to_string();
        assert!(e.contains("end where it starts"), "{e}");
        let e = Spline1::natural(&[0.0, f64::NAN], &[0.0, 1.0], "x").unwrap_err().to_string();
        assert!(e.contains("point 1 is not finite"), "{e}");
    }
}
