//! Dense LU factorization with partial pivoting on caller-owned storage, so that implicit
//! integrators can factor their iteration matrices every step without allocating.

use crate::error::{Error, Result};

/// Factors the row-major `n × n` matrix `a` in place (L unit-lower, U upper), pivots into `piv`.
pub fn lu_factor(a: &mut [f64], n: usize, piv: &mut [usize]) -> Result<()> {
    for k in 0..n {
        let mut p = k;
        let mut best = a[k * n + k].abs();
        for r in k + 1..n {
            let v = a[r * n + k].abs();
            if v > best {
                best = v;
                p = r;
            }
        }
        piv[k] = p;
        if best == 0.0 || !best.is_finite() {
            return Err(Error::Solver(format!("singular matrix in LU factorization (column {k})")));
        }
        if p != k {
            for c in 0..n {
                a.swap(k * n + c, p * n + c);
            }
        }
        let d = a[k * n + k];
        for r in k + 1..n {
            let l = a[r * n + k] / d;
            a[r * n + k] = l;
            if l != 0.0 {
                for c in k + 1..n {
                    a[r * n + c] -= l * a[k * n + c];
                }
            }
        }
    }
    Ok(())
}

/// Solves `A x = b` in place with the factors of [`lu_factor`].
pub fn lu_solve(a: &[f64], n: usize, piv: &[usize], b: &mut [f64]) {
    for k in 0..n {
        b.swap(k, piv[k]);
    }
    for r in 0..n {
        let mut s = b[r];
        for c in 0..r {
            s -= a[r * n + c] * b[c];
        }
        b[r] = s;
    }
    for r in (0..n).rev() {
        let mut s = b[r];
        for c in r + 1..n {
            s -= a[r * n + c] * b[c];
        }
        b[r] = s / a[r * n + r];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_system_needing_pivoting() {
        // first pivot is zero: fails without row exchange
        let a0 = [0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.0, 1.0];
        let x = [1.0, -2.0, 3.0];
        let mut b = [0.0; 3];
        for r in 0..3 {
            b[r] = (0..3).map(|c| a0[r * 3 + c] * x[c]).sum();
        }
        let mut a = a0;
        let mut piv = [0; 3];
        lu_factor(&mut a, 3, &mut piv).unwrap();
        lu_solve(&a, 3, &piv, &mut b);
        for i in 0..3 {
            assert!((b[i] - x[i]).abs() < 1e-14);
        }
        let mut s = [1.0, 2.0, 2.0, 4.0];
        assert!(lu_factor(&mut s, 2, &mut [0; 2]).is_err());
    }
}
