//! Accelerated projected gradient descent (APGD) for friction contact.
//!
//! The iteration is Nesterov's accelerated projected gradient on the cone-constrained quadratic
//! `½ rᵀ W r + qᵀ r`, `r ∈ K = Π_i K_μi`, with the modified velocity `û = u + μ |u_T| e_N` (De Saxcé)
//! in place of the gradient `u = W r + q`, so that its fixed points are the Coulomb solutions of
//! [`super::FrictionContact`] and not those of the convex relaxation (they coincide where nothing
//! slides):
//!
//! ```text
//! r_{k+1} = proj_K(y_k − t D û(y_k)),     y_{k+1} = r_{k+1} + β_k (r_{k+1} − r_k)
//! θ_{k+1} = θ_k (√(θ_k² + 4) − θ_k)/2,  β_k = θ_k (1 − θ_k)/(θ_k² + θ_{k+1})
//! ```
//!
//! - `D` scales contact `i`'s rows by `1/W_NN,i`: a scalar per contact, so the projection onto the
//!   cone is unchanged, and the scaled matrix has a unit normal diagonal whatever the masses.
//! - The step `t = 1/L` adapts: `L` doubles until the quadratic's curvature along the step is below
//!   it (`δᵀ W δ ≤ L Σ_i W_NN,i |δ_i|²`, the sufficient-decrease test of the quadratic, in which
//!   the De Saxcé term, linear for one step, cancels) and shrinks by 0.9 after each iteration.
//! - Adaptive restart: when the step and the last change make an acute angle with the gradient
//!   (`û(y_k) · (r_{k+1} − r_k) > 0`), the momentum is dropped (`θ = 1`, `y = r`).
//! - `u` is affine in `r`, so `u(y)` is extrapolated like `y` itself: one product with `W` per
//!   iteration (more only while `L` grows).
//!
//! Every iterate's residual ([`super::Report::residual`]) is known from its `u`; the best one is
//! returned, and the solve stops at the tolerance. A warm start that already meets it costs one
//! product and no iteration.
//!
//! Cost: `O(nnz(W))` per iteration, no factorization; suited to large problems (piles) where a
//! Gauss–Seidel sweep's information travels one contact per sweep while the gradient step moves
//! all contacts together. Literature (for the method, not the code): Nesterov (1983); Mazhar,
//! Heyn, Negrut & Tasora (2015) for the cone-constrained form in multibody contact; O'Donoghue &
//! Candès (2015) for the restart.

use super::nsgs::cache_diagonal;
use super::problem::{fc_residual, project_onto_cone, FrictionContact};
use super::{ApgdOptions, Report, Workspace};
use crate::error::Result;

/// APGD scratch for `m = d n` unknowns.
#[derive(Debug, Clone, Default)]
pub(crate) struct ApgdWork {
    y: Vec<f64>,
    uy: Vec<f64>,
    u_prev: Vec<f64>,
    r_new: Vec<f64>,
    u_new: Vec<f64>,
    best: Vec<f64>,
}

impl ApgdWork {
    pub(crate) fn reserve(&mut self, m: usize) {
        for v in [&mut self.y, &mut self.uy, &mut self.u_prev, &mut self.r_new, &mut self.u_new, &mut self.best] {
            if v.len() < m {
                v.resize(m, 0.0);
            }
        }
    }
}

/// Accelerated projected gradient for a friction-contact problem (module documentation).
pub(crate) fn solve(p: &FrictionContact, o: &ApgdOptions, r: &mut [f64], ws: &mut Workspace) -> Result<Report> {
    let d = p.dim;
    let n = p.contacts();
    let m = d * n;
    cache_diagonal(p, &mut ws.diag[..n]);
    let diag = &ws.diag[..n];
    let aw = &mut ws.apgd;
    let (y, uy, u_prev) = (&mut aw.y[..m], &mut aw.uy[..m], &mut aw.u_prev[..m]);
    let (r_new, u_new, best) = (&mut aw.r_new[..m], &mut aw.u_new[..m], &mut aw.best[..m]);
    // the current iterate r_k and its velocities
    p.w.velocity(d, r, &p.q, u_prev);
    let mut best_res = fc_residual(p, r, u_prev);
    if best_res <= o.tol {
        return Ok(Report { iterations: 0, residual: best_res, converged: true });
    }
    best.copy_from_slice(r);
    y.copy_from_slice(r);
    uy.copy_from_slice(u_prev);
    // the scaled matrix has unit normal diagonal entries: its largest eigenvalue is of order one
    // per coupled contact; the line search corrects the guess upward within an iteration
    let mut lip = 1.0f64;
    let mut theta = 1.0f64;
    let mut iterations = 0;
    while iterations < o.max_iter {
        iterations += 1;
        // gradient step from y with the De Saxcé velocity, projected; L grows until the
        // quadratic's curvature along the step is below it
        let mut trials = 0;
        loop {
            let t = 1.0 / lip;
            for i in 0..n {
                let k = i * d;
                let s = t / diag[i][0];
                let ut = if d == 3 { uy[k + 1].hypot(uy[k + 2]) } else { uy[k + 1].abs() };
                let mut x = [0.0; 3];
                x[0] = y[k] - s * (uy[k] + p.mu[i] * ut);
                for a in 1..d {
                    x[a] = y[k + a] - s * uy[k + a];
                }
                project_onto_cone(p.mu[i], &x[..d], &mut r_new[k..k + d]);
            }
            p.w.velocity(d, r_new, &p.q, u_new);
            // δᵀ W δ with δ = r_new − y, W δ = u_new − u_y
            let (mut curv, mut size) = (0.0, 0.0);
            for i in 0..n {
                for a in 0..d {
                    let k = i * d + a;
                    let delta = r_new[k] - y[k];
                    curv += delta * (u_new[k] - uy[k]);
                    size += diag[i][0] * delta * delta;
                }
            }
            trials += 1;
            if curv <= lip * size * (1.0 + 1e-12) || trials >= 60 {
                break;
            }
            lip *= 2.0;
        }
        let res = fc_residual(p, r_new, u_new);
        if res < best_res {
            best_res = res;
            best.copy_from_slice(r_new);
            if res <= o.tol {
                break;
            }
        }
        // restart when the gradient at y points along the last change (the momentum overshoots)
        let mut along = 0.0;
        for i in 0..n {
            let k = i * d;
            let ut = if d == 3 { uy[k + 1].hypot(uy[k + 2]) } else { uy[k + 1].abs() };
            along += (uy[k] + p.mu[i] * ut) * (r_new[k] - r[k]);
            for a in 1..d {
                along += uy[k + a] * (r_new[k + a] - r[k + a]);
            }
        }
        if along > 0.0 {
            theta = 1.0;
            y.copy_from_slice(r_new);
            uy.copy_from_slice(u_new);
        } else {
            let next = 0.5 * theta * ((theta * theta + 4.0).sqrt() - theta);
            let beta = theta * (1.0 - theta) / (theta * theta + next);
            theta = next;
            for k in 0..m {
                y[k] = r_new[k] + beta * (r_new[k] - r[k]);
                uy[k] = u_new[k] + beta * (u_new[k] - u_prev[k]);
            }
        }
        r.copy_from_slice(r_new);
        u_prev.copy_from_slice(u_new);
        lip *= 0.9;
    }
    r.copy_from_slice(best);
    Ok(Report { iterations, residual: best_res, converged: best_res <= o.tol })
}
