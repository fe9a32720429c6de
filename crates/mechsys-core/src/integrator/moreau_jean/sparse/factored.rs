//! Nonsmooth Gauss–Seidel on the Delassus operator in factored form.
//!
//! With the reduced rows `y_a` (see the parent module) `W = Yᵀ Y`, so a sweep needs no
//! off-diagonal block: it keeps `z = Σ_b Y_b r_b` (one entry per velocity) and finds contact
//! `a`'s local problem as `b_a = Y_aᵀ z − W_aa r_a + q_a`, solves it with the same exact local
//! solver as [`crate::solver::nsgs`], and adds `Y_a Δr_a` back into `z`. Per contact that is
//! `2 d ℓ_a` products for a pattern of `ℓ_a` velocities (24 per direction for two free bodies)
//! against `9` per coupled contact with blocks, and the blocks, `O(Σ_pairs ℓ d²)` to form, are
//! never built. A resting stack or pyramid whose warm start converges in a sweep or two thus
//! skips the most expensive part of the assembly; a problem that needs Newton gets its blocks
//! after the sweeps.
//!
//! The sweep order, stopping test (change, then the full residual on a doubling schedule) and
//! residual are those of `nsgs::solve_fc`; the numbers differ from the block form by round-off
//! only (`W r` is summed in another order).

use super::SparseRows;
use crate::solver::nsgs::{local_solve, CheckSchedule};
use crate::solver::{contact_residual_sq, NsgsOptions, Report};

impl SparseRows {
    /// Nonsmooth Gauss–Seidel on the problem `u = W r + q` with friction coefficients `mu`:
    /// up to `opts.max_iter` sweeps in `order` (a permutation of the contacts, else by index),
    /// warm-started from `r`, stopping at the residual `opts.tol` (the measure of
    /// [`crate::solver::Report::residual`]; no relaxation). After a full-residual check, the last
    /// one of the report, `u` holds `W r + q` of the returned `r`; the report's residual is
    /// infinite if no check was made.
    pub(in crate::integrator::moreau_jean) fn gauss_seidel(
        &mut self,
        (q, mu): (&[f64], &[f64]),
        order: &[usize],
        r: &mut [f64],
        opts: &NsgsOptions,
        u: &mut [f64],
    ) -> Report {
        match self.dim {
            3 => self.gauss_seidel_d::<3>(q, mu, order, r, opts, u),
            _ => self.gauss_seidel_d::<2>(q, mu, order, r, opts, u),
        }
    }

    fn gauss_seidel_d<const D: usize>(
        &mut self,
        q: &[f64],
        mu: &[f64],
        order: &[usize],
        r: &mut [f64],
        opts: &NsgsOptions,
        u: &mut [f64],
    ) -> Report {
        let (tol, max_sweeps) = (opts.tol, opts.max_iter);
        let n = self.len();
        let qn = 1.0 + q.iter().map(|v| v * v).sum::<f64>().sqrt();
        let ordered = order.len() == n;
        let mut check = CheckSchedule::new();
        let mut residual = f64::INFINITY;
        self.factored_product::<D>(r);
        for it in 1..=max_sweeps {
            let mut change = 0.0;
            for ii in 0..n {
                let a = if ordered { order[ii] } else { ii };
                let mut blk = [0.0; 9];
                blk[..D * D].copy_from_slice(&self.diag[a * D * D..(a + 1) * D * D]);
                // b = Y_aᵀ z − W_aa r_a + q_a: the velocity of the others' impulses and the free motion
                let mut b = self.rows_times_z::<D>(a);
                let mut old = [0.0; 3];
                old[..D].copy_from_slice(&r[a * D..(a + 1) * D]);
                for c in 0..D {
                    let mut own = 0.0;
                    for k in 0..D {
                        own += blk[c * D + k] * old[k];
                    }
                    b[c] += q[a * D + c] - own;
                }
                let mut new = old;
                local_solve(D, &blk, mu[a], &b, &mut new);
                let mut delta = [0.0; 3];
                for c in 0..D {
                    delta[c] = new[c] - old[c];
                    change += (blk[0] * delta[c]).powi(2);
                }
                if delta.iter().any(|v| *v != 0.0) {
                    self.add_rows_times::<D>(a, &delta[..D]);
                    r[a * D..(a + 1) * D].copy_from_slice(&new[..D]);
                }
            }
            if check.due(it, change.sqrt() / qn <= tol) || it == max_sweeps {
                // a fresh z (the updates' round-off does not accumulate into the residual)
                self.factored_product::<D>(r);
                residual = self.factored_residual::<D>(q, mu, r, u) / qn;
                if residual <= tol {
                    return Report { iterations: it, residual, converged: true };
                }
            }
        }
        Report { iterations: max_sweeps, residual, converged: false }
    }

    /// `z = Σ_a Y_a r_a`.
    fn factored_product<const D: usize>(&mut self, r: &[f64]) {
        self.z.fill(0.0);
        for a in 0..self.len() {
            let ra = &r[a * D..(a + 1) * D];
            if ra.iter().any(|v| *v != 0.0) {
                self.add_rows_times::<D>(a, ra);
            }
        }
    }

    /// `z += Y_a v` (`v` has the problem's dimension `D`).
    #[inline]
    fn add_rows_times<const D: usize>(&mut self, a: usize, v: &[f64]) {
        let (s, e) = (self.pat_ptr[a], self.pat_ptr[a + 1]);
        for (k, y) in self.pat_idx[s..e].iter().zip(self.y[s * D..e * D].chunks_exact(D)) {
            let mut x = 0.0;
            for c in 0..D {
                x += y[c] * v[c];
            }
            self.z[*k] += x;
        }
    }

    /// `Y_aᵀ z` (zero beyond the problem's dimension `D`).
    #[inline]
    fn rows_times_z<const D: usize>(&self, a: usize) -> [f64; 3] {
        let (s, e) = (self.pat_ptr[a], self.pat_ptr[a + 1]);
        let mut out = [0.0; 3];
        for (k, y) in self.pat_idx[s..e].iter().zip(self.y[s * D..e * D].chunks_exact(D)) {
            let zk = self.z[*k];
            for c in 0..D {
                out[c] += y[c] * zk;
            }
        }
        out
    }

    /// `u = Y_aᵀ z + q` for every contact (after [`SparseRows::factored_product`]) and the
    /// unscaled natural-map residual `‖·‖₂` of the solution `r`.
    fn factored_residual<const D: usize>(&self, q: &[f64], mu: &[f64], r: &[f64], u: &mut [f64]) -> f64 {
        let mut sum = 0.0;
        for a in 0..self.len() {
            let ua = self.rows_times_z::<D>(a);
            // (a direction without mobility has zero rows and a zero impulse: the diagonal
            // `couplings` gives it adds nothing to its velocity in the block form either)
            for c in 0..D {
                u[a * D + c] = ua[c] + q[a * D + c];
            }
            let wnn = self.diag[a * D * D];
            sum += contact_residual_sq(D, mu[a], wnn, &r[a * D..(a + 1) * D], &u[a * D..(a + 1) * D]);
        }
        sum.sqrt()
    }
}
