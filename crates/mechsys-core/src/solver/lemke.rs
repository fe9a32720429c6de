//! Lemke's complementary pivoting method for the LCP `w = M z + q`, `0 ≤ z ⊥ w ≥ 0`.
//!
//! The problem is augmented with the artificial variable `z0` and the covering vector `d = e`
//! (all ones): `w − M z − d z0 = q`. Starting from the basis `w` with `z0 = max_i(−q_i)`, every
//! pivot brings in the complement of the variable that just left, keeping the basis almost
//! complementary, until `z0` leaves (a solution) or the entering column has no positive entry
//! (ray termination). For copositive-plus `M` (e.g. positive semidefinite) ray termination proves
//! the LCP infeasible; for a P-matrix (e.g. positive definite) the solution is unique and found.
//!
//! Degeneracy is resolved lexicographically: ties of the ratio test are broken by the rows of the
//! current basis inverse (the tableau's `w` columns) divided by the pivot column, which prevents
//! cycling; `z0` leaves whenever it ties, which ends the run at once. In degenerate problems `z0`
//! can fall to round-off (below 10⁻¹² of its first value) without leaving; the basis is then a
//! solution already and the run ends there. After termination the basic
//! variables are recomputed from the original `M` and `q` with an LU solve of the final basis, so
//! pivoting round-off does not accumulate into the answer.
//!
//! The tableau is dense `n × (2n + 2)` and each pivot costs `O(n²)`; the method is meant for the
//! small, exact problems of impacts and transitions (tens to a few hundred unknowns).

use super::problem::{lcp_residual, lcp_w, Lcp};
use super::{LemkeOptions, Report, Workspace};
use crate::error::{Error, Result};
use crate::math::linalg::{lu_factor, lu_solve};

/// Lemke scratch: tableau, basis, and the LU of the final basis.
#[derive(Debug, Clone, Default)]
pub(crate) struct LemkeWork {
    tableau: Vec<f64>,
    basis: Vec<usize>,
    lu: Vec<f64>,
    piv: Vec<usize>,
    x: Vec<f64>,
}

impl LemkeWork {
    pub(crate) fn reserve(&mut self, n: usize) {
        if self.basis.len() < n {
            self.tableau.resize(n * (2 * n + 2), 0.0);
            self.basis.resize(n, 0);
            self.lu.resize(n * n, 0.0);
            self.piv.resize(n, 0);
            self.x.resize(n, 0.0);
        }
    }
}

/// Solves an [`Lcp`] with Lemke's method.
pub(crate) fn solve_lcp(p: &Lcp, o: &LemkeOptions, z: &mut [f64], ws: &mut Workspace) -> Result<Report> {
    let n = p.size();
    let (pivots, complete) = lemke(&p.m, &p.q, z, o, &mut ws.lemke)?;
    let w = &mut ws.u[..n];
    lcp_w(&p.m, &p.q, z, w);
    Ok(Report { iterations: pivots, residual: lcp_residual(&p.m, &p.q, z, w), converged: complete })
}

/// Lemke's method on row-major `m` (`n × n`, `n = q.len()`), solution into `z`.
///
/// Returns the number of pivots and whether a complementary basis was reached (`false`: the pivot
/// cap stopped it; `z` then holds the `z` part of the last almost-complementary basis).
/// Ray termination is an error.
pub(crate) fn lemke(
    m: &[f64],
    q: &[f64],
    z: &mut [f64],
    o: &LemkeOptions,
    work: &mut LemkeWork,
) -> Result<(usize, bool)> {
    let n = q.len();
    z[..n].fill(0.0);
    if q.iter().all(|&v| v >= 0.0) {
        return Ok((0, true));
    }
    let wd = 2 * n + 2;
    let (z0, rhs) = (2 * n, 2 * n + 1);
    let t = &mut work.tableau[..n * wd];
    let basis = &mut work.basis[..n];
    let scale = m[..n * n].iter().fold(1.0f64, |a, v| a.max(v.abs()));
    let tol = o.pivot_tol * scale;
    // columns: w (identity), z (−M), z0 (−d), right-hand side q
    for i in 0..n {
        let row = &mut t[i * wd..(i + 1) * wd];
        row.fill(0.0);
        row[i] = 1.0;
        for j in 0..n {
            row[n + j] = -m[i * n + j];
        }
        row[z0] = -1.0;
        row[rhs] = q[i];
        basis[i] = i;
    }
    // z0 enters where q_i/d_i is lexicographically smallest: afterwards every rhs is ≥ 0
    let mut r = 0;
    for i in 1..n {
        if lex_less(t, wd, n, i, r, rhs, 1.0, 1.0) {
            r = i;
        }
    }
    pivot(t, wd, n, r, z0);
    let mut entering = n + basis[r]; // complement of the w that left
    basis[r] = z0;
    let max_pivots = o.max_pivots.unwrap_or(50 * (n + 1));
    // z0 at round-off level: the almost-complementary basis is already a solution (in degenerate
    // problems z0 can reach 0 without leaving, and the next column is then round-off only)
    let z0_tol = 1e-12 * t[r * wd + rhs];
    let mut pivots = 1;
    loop {
        if (0..n).any(|i| basis[i] == z0 && t[i * wd + rhs] <= z0_tol) {
            extract(m, q, t, wd, basis, z, work_lu(&mut work.lu, &mut work.piv, &mut work.x, n));
            return Ok((pivots, true));
        }
        if pivots >= max_pivots {
            extract(m, q, t, wd, basis, z, work_lu(&mut work.lu, &mut work.piv, &mut work.x, n));
            return Ok((pivots, false));
        }
        // minimum ratio rhs_i / t_ie over positive entries of the entering column
        let mut theta = f64::INFINITY;
        for i in 0..n {
            let a = t[i * wd + entering];
            if a > tol {
                theta = theta.min(t[i * wd + rhs] / a);
            }
        }
        if !theta.is_finite() {
            return Err(Error::Solver(format!(
                "LCP has no solution (or Lemke's method cannot find one for this M): ray termination after {pivots} pivots"
            )));
        }
        // among the ties: z0 if present, else the lexicographic minimum
        let mut best: Option<usize> = None;
        for i in 0..n {
            let a = t[i * wd + entering];
            if a <= tol {
                continue;
            }
            let ratio = t[i * wd + rhs] / a;
            if (ratio - theta).abs() > 1e-12 * ratio.abs().max(theta.abs()) {
                continue;
            }
            if basis[i] == z0 {
                best = Some(i);
                break;
            }
            best = match best {
                Some(b) if !lex_less(t, wd, n, i, b, usize::MAX, a, t[b * wd + entering]) => Some(b),
                _ => Some(i),
            };
        }
        let Some(r) = best else {
            return Err(Error::Solver(format!(
                "Lemke: non-finite tableau after {pivots} pivots (M or q too badly scaled)"
            )));
        };
        pivot(t, wd, n, r, entering);
        let leaving = basis[r];
        basis[r] = entering;
        pivots += 1;
        if leaving == z0 {
            extract(m, q, t, wd, basis, z, work_lu(&mut work.lu, &mut work.piv, &mut work.x, n));
            return Ok((pivots, true));
        }
        entering = if leaving < n { leaving + n } else { leaving - n };
    }
}

type LuBufs<'a> = (&'a mut [f64], &'a mut [usize], &'a mut [f64]);

fn work_lu<'a>(lu: &'a mut [f64], piv: &'a mut [usize], x: &'a mut [f64], n: usize) -> LuBufs<'a> {
    (&mut lu[..n * n], &mut piv[..n], &mut x[..n])
}

/// Whether row `i` scaled by `1/ai` is lexicographically smaller than row `k` scaled by `1/ak`,
/// comparing first column `first` (unless `usize::MAX`) and then the basis-inverse columns `0..n`.
#[allow(clippy::too_many_arguments)]
fn lex_less(t: &[f64], wd: usize, n: usize, i: usize, k: usize, first: usize, ai: f64, ak: f64) -> bool {
    if first != usize::MAX {
        let (vi, vk) = (t[i * wd + first] / ai, t[k * wd + first] / ak);
        if vi != vk {
            return vi < vk;
        }
    }
    for c in 0..n {
        let (vi, vk) = (t[i * wd + c] / ai, t[k * wd + c] / ak);
        if vi != vk {
            return vi < vk;
        }
    }
    false
}

/// Gauss–Jordan pivot on (r, e).
fn pivot(t: &mut [f64], wd: usize, n: usize, r: usize, e: usize) {
    let p = t[r * wd + e];
    for c in 0..wd {
        t[r * wd + c] /= p;
    }
    t[r * wd + e] = 1.0;
    for i in 0..n {
        if i == r {
            continue;
        }
        let f = t[i * wd + e];
        if f != 0.0 {
            for c in 0..wd {
                let v = t[r * wd + c];
                t[i * wd + c] -= f * v;
            }
            t[i * wd + e] = 0.0;
        }
    }
}

/// Reads `z` from the basis: solves `Σ_k A_k x_k = q` with the original columns of the basic
/// variables (`w_j`: `e_j`; `z_j`: `−M e_j`; `z0`: `−e`), falling back to the tableau's values if
/// that basis matrix is numerically singular.
fn extract(m: &[f64], q: &[f64], t: &[f64], wd: usize, basis: &[usize], z: &mut [f64], (lu, piv, x): LuBufs<'_>) {
    let n = q.len();
    for i in 0..n {
        for k in 0..n {
            let b = basis[k];
            lu[i * n + k] = if b < n {
                if b == i {
                    1.0
                } else {
                    0.0
                }
            } else if b < 2 * n {
                -m[i * n + (b - n)]
            } else {
                -1.0
            };
        }
    }
    let refined = lu_factor(lu, n, piv).is_ok();
    if refined {
        x.copy_from_slice(&q[..n]);
        lu_solve(lu, n, piv, x);
    }
    z[..n].fill(0.0);
    for k in 0..n {
        let b = basis[k];
        if (n..2 * n).contains(&b) {
            let v = if refined && x[k].is_finite() { x[k] } else { t[k * wd + 2 * n + 1] };
            z[b - n] = v.max(0.0);
        }
    }
}
