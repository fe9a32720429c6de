//! The semismooth Newton method of [`crate::solver::newton`] (Alart–Curnier function,
//! regularized Delassus matrix, Armijo line search, iterative refinement) with its direction
//! solved in body space, for contact problems too large for a factorization of the contact
//! Jacobian: piles of free bodies.
//!
//! With the reduced rows of the parent module `W = Yᵀ Y` (`Y` has one row per velocity), the
//! regularized Newton matrix is `J_ε = C + B Yᵀ Y`, `C = I − (1 − reg) D` and `B = ρ D` block
//! diagonal (one `d × d` block per contact, `D` the projection derivative). `C` is invertible for
//! `reg > 0` (its normal entry is 1 or `reg`, its tangential block has eigenvalues in
//! `[reg, 1]`). For `J_ε Δ = g` put `v = Y Δ`: then `Δ = C⁻¹ (g − B Yᵀ v)` and
//!
//! ```text
//! (I + Y E Yᵀ) v = Y C⁻¹ g,    E = C⁻¹ B  (block diagonal),
//! ```
//!
//! a system in the velocities of the bodies in contact, 6 per free body, whose `6 × 6` blocks are
//! nonzero for bodies that touch ([`BlockLu`]). A settled pile of `N` spheres has about `2N`
//! contacts (`6N` unknowns) but only `6N` velocities coupled along the contact graph, where the
//! contact-space Jacobian couples every pair of contacts on a common sphere. `I + Y E Yᵀ` is the
//! identity plus a positive semidefinite term where contacts stick or are open, so the block LU
//! needs no pivoting between blocks.
//!
//! Where the contacts keep their bodies from one solve to the next (a resting pile), the last
//! factorization is reused as a chord direction with the `C⁻¹` and `E` it was built from; the line
//! search decides, and a fresh factorization follows if the full step fails, as in
//! [`crate::solver::newton`].

use super::factored::Packed;
use super::SparseRows;
use crate::math::block_sparse::BlockLu;
use crate::solver::newton::{alart_curnier, line_search, Stopping, REFINEMENTS};
use crate::solver::{NewtonOptions, NsgsOptions, Report};

/// Scratch and the held factorization of the body-space Newton method.
#[derive(Debug, Clone, Default)]
pub(in crate::integrator::moreau_jean) struct BodyNewton {
    lu: BlockLu<6>,
    /// Block of each velocity that starts a free body in contact (usize::MAX: none), and the
    /// first velocity of each block.
    block_of: Vec<usize>,
    first: Vec<usize>,
    /// The blocks of each contact's one or two bodies (usize::MAX for the ground): the pattern
    /// the held factorization belongs to.
    sig: Vec<[usize; 2]>,
    held_sig: Vec<[usize; 2]>,
    pairs: Vec<(usize, usize)>,
    /// Whether `lu` holds a factorization for `held_sig`.
    held: bool,
    /// Whether `lu` was analyzed for `held_sig`'s pattern.
    analyzed: bool,
    /// Per contact: `D`, and `C⁻¹`, `E = C⁻¹ B` of the held factorization (row-major 3 × 3).
    dblk: Vec<[f64; 9]>,
    cinv: Vec<[f64; 9]>,
    e: Vec<[f64; 9]>,
    phi: Vec<f64>,
    dir: Vec<f64>,
    wdir: Vec<f64>,
    rhs: Vec<f64>,
    r_t: Vec<f64>,
    u_t: Vec<f64>,
    phi_t: Vec<f64>,
    /// Body-space vectors (6 per block) and the solve's work.
    v: Vec<f64>,
    work: Vec<f64>,
    /// Fresh factorizations since construction.
    factorizations: usize,
}

impl BodyNewton {
    /// Fresh factorizations since construction.
    pub(in crate::integrator::moreau_jean) fn factorizations(&self) -> usize {
        self.factorizations
    }
}

/// Inverse of a `d × d` (row-major, stride `d`) matrix into a 3 × 3 row-major array; `None` if
/// singular.
fn invert(d: usize, a: &[f64; 9]) -> Option<[f64; 9]> {
    let mut out = [0.0; 9];
    match d {
        2 => {
            let det = a[0] * a[3] - a[1] * a[2];
            if det == 0.0 || !det.is_finite() {
                return None;
            }
            out[0] = a[3] / det;
            out[1] = -a[1] / det;
            out[2] = -a[2] / det;
            out[3] = a[0] / det;
        }
        _ => {
            let c = [
                a[4] * a[8] - a[5] * a[7],
                a[2] * a[7] - a[1] * a[8],
                a[1] * a[5] - a[2] * a[4],
                a[5] * a[6] - a[3] * a[8],
                a[0] * a[8] - a[2] * a[6],
                a[2] * a[3] - a[0] * a[5],
                a[3] * a[7] - a[4] * a[6],
                a[1] * a[6] - a[0] * a[7],
                a[0] * a[4] - a[1] * a[3],
            ];
            let det = a[0] * c[0] + a[1] * c[3] + a[2] * c[6];
            if det == 0.0 || !det.is_finite() {
                return None;
            }
            for k in 0..9 {
                out[k] = c[k] / det;
            }
        }
    }
    Some(out)
}

/// `ψ = ½|Φ|²` at `r` with `u = W r + q` (`Φ` into `phi`, and the projection derivatives `D`
/// into `dblk` if given), `W`'s diagonal blocks in `diag`.
fn merit<const D: usize>(
    mu: &[f64],
    diag: &[f64],
    r: &[f64],
    u: &[f64],
    phi: &mut [f64],
    mut dblk: Option<&mut [[f64; 9]]>,
) -> f64 {
    let mut psi = 0.0;
    for a in 0..mu.len() {
        let s = a * D..(a + 1) * D;
        let dm = dblk.as_deref_mut().map(|b| &mut b[a]);
        alart_curnier(D, mu[a], 1.0 / diag[a * D * D], &r[s.clone()], &u[s.clone()], &mut phi[s.clone()], dm);
        psi += phi[s].iter().map(|v| v * v).sum::<f64>();
    }
    0.5 * psi
}

/// `y = A x` for a `d × d` block (stride `d`).
#[inline]
fn block_times(d: usize, a: &[f64; 9], x: &[f64]) -> [f64; 3] {
    let mut y = [0.0; 3];
    for r in 0..d {
        for c in 0..d {
            y[r] += a[r * d + c] * x[c];
        }
    }
    y
}

impl SparseRows {
    /// The body-space Newton method on `u = W r + q` with friction coefficients `mu`, warm-started
    /// from `r`; `None` if some contact is not on free bodies and the ground (the method does not
    /// apply). Stopping rules and report as [`crate::solver::newton`]; `u` receives `W r + q` of
    /// the returned `r`.
    pub(in crate::integrator::moreau_jean) fn body_newton(
        &mut self,
        problem: (&[f64], &[f64]),
        order: &[usize],
        r: &mut [f64],
        opts: &NewtonOptions,
        u: &mut [f64],
    ) -> Option<Report> {
        match self.dim {
            3 => self.body_newton_d::<3>(problem, order, r, opts, u),
            _ => self.body_newton_d::<2>(problem, order, r, opts, u),
        }
    }

    fn body_newton_d<const D: usize>(
        &mut self,
        (q, mu): (&[f64], &[f64]),
        order: &[usize],
        r: &mut [f64],
        opts: &NewtonOptions,
        u: &mut [f64],
    ) -> Option<Report> {
        if !self.pack::<D>() {
            return None;
        }
        let n = self.len();
        let m = n * D;
        self.body_pattern();
        let bn = &mut self.newton;
        for v in [&mut bn.phi, &mut bn.dir, &mut bn.wdir, &mut bn.rhs, &mut bn.r_t, &mut bn.u_t, &mut bn.phi_t] {
            v.resize(m, 0.0);
        }
        bn.dblk.resize(n, [0.0; 9]);
        let nv = 6 * bn.first.len();
        bn.v.resize(nv, 0.0);
        bn.work.resize(nv, 0.0);
        let qn = 1.0 + q.iter().map(|v| v * v).sum::<f64>().sqrt();
        let mut stopping = Stopping::new();
        loop {
            self.factored_product::<D>(r);
            if let Some(report) = stopping.check(self.factored_residual::<D>(q, mu, r, u) / qn, opts) {
                return Some(report);
            }
            let bn = &mut self.newton;
            let psi = merit::<D>(mu, &self.diag, r, u, &mut bn.phi, Some(&mut bn.dblk));
            let mut fresh = !(opts.reuse && self.newton.held);
            let mut accepted = false;
            loop {
                if fresh && !self.factor_body_space::<D>(opts.regularization) {
                    break;
                }
                // Δ = J_ε⁻¹ (−Φ), refined against the exact J
                for k in 0..m {
                    self.newton.rhs[k] = -self.newton.phi[k];
                }
                self.direction::<D>(false);
                for _ in 0..REFINEMENTS {
                    if !self.newton.dir.iter().all(|v| v.is_finite()) {
                        break;
                    }
                    self.w_times_dir::<D>();
                    let bn = &mut self.newton;
                    for a in 0..n {
                        let (rho, dm) = (1.0 / self.diag[a * D * D], &bn.dblk[a]);
                        for c in 0..D {
                            let mut jd = bn.dir[a * D + c];
                            for k in 0..D {
                                jd += dm[c * D + k] * (rho * bn.wdir[a * D + k] - bn.dir[a * D + k]);
                            }
                            bn.rhs[a * D + c] = -bn.phi[a * D + c] - jd;
                        }
                    }
                    self.direction::<D>(true);
                }
                if self.newton.dir.iter().all(|v| v.is_finite()) {
                    self.w_times_dir::<D>();
                    let bn = &mut self.newton;
                    let (diag, phi_t) = (&self.diag, &mut bn.phi_t);
                    accepted = line_search(r, u, &bn.dir, &bn.wdir, &mut bn.r_t, &mut bn.u_t, psi, fresh, |rt, ut| {
                        merit::<D>(mu, diag, rt, ut, phi_t, None)
                    });
                }
                if accepted || fresh {
                    break;
                }
                fresh = true;
            }
            if !accepted {
                // where the Newton model fails (kinks, redundant contacts): one sweep
                let one = NsgsOptions { tol: f64::MIN_POSITIVE, max_iter: 1, anderson: 0, ..Default::default() };
                self.gauss_seidel((q, mu), order, r, &one, u);
            }
        }
    }

    /// Blocks of the bodies in contact (`first`, `block_of`), each contact's signature, and the
    /// analysis of the pattern if it changed (which drops the held factorization).
    fn body_pattern(&mut self) {
        let bn = &mut self.newton;
        let nu = self.z.len();
        if bn.block_of.len() < nu {
            bn.block_of.resize(nu, usize::MAX);
        }
        for &iu in &bn.first {
            bn.block_of[iu] = usize::MAX;
        }
        bn.first.clear();
        bn.sig.clear();
        bn.pairs.clear();
        for p in &self.packed {
            let mut s = [usize::MAX; 2];
            for k in 0..p.bodies() {
                let iu = p.iu()[k];
                if bn.block_of[iu] == usize::MAX {
                    bn.block_of[iu] = bn.first.len();
                    bn.first.push(iu);
                }
                s[k] = bn.block_of[iu];
            }
            if s[1] != usize::MAX && s[0] != s[1] {
                bn.pairs.push((s[0], s[1]));
            }
            bn.sig.push(s);
        }
        if !(bn.analyzed && bn.sig == bn.held_sig) {
            bn.lu.analyze(bn.first.len(), &bn.pairs);
            bn.held_sig.clone_from(&bn.sig);
            bn.analyzed = true;
            bn.held = false;
        }
    }

    /// Forms and factors `I + Y E Yᵀ` for the current `D` blocks; false if a block is singular.
    fn factor_body_space<const D: usize>(&mut self, reg: f64) -> bool {
        let bn = &mut self.newton;
        let n = self.packed.len();
        bn.cinv.resize(n, [0.0; 9]);
        bn.e.resize(n, [0.0; 9]);
        bn.held = false;
        bn.lu.zero();
        let mut eye = [0.0; 36];
        for k in 0..6 {
            eye[k * 7] = 1.0;
        }
        for b in 0..bn.first.len() {
            bn.lu.add(b, b, &eye);
        }
        for a in 0..n {
            let dm = &bn.dblk[a];
            let rho = 1.0 / self.diag[a * D * D];
            let mut c = [0.0; 9];
            for i in 0..D {
                for j in 0..D {
                    c[i * D + j] = if i == j { 1.0 } else { 0.0 } - (1.0 - reg) * dm[i * D + j];
                }
            }
            let Some(ci) = invert(D, &c) else { return false };
            let mut e = [0.0; 9];
            for i in 0..D {
                for j in 0..D {
                    e[i * D + j] = (0..D).map(|k| ci[i * D + k] * rho * dm[k * D + j]).sum();
                }
            }
            bn.cinv[a] = ci;
            bn.e[a] = e;
            let p: &Packed = &self.packed[a];
            if e.iter().all(|v| *v == 0.0) {
                continue;
            }
            for k in 0..p.bodies() {
                // P = Y_k E (6 × D)
                let mut pk = [[0.0; 3]; 6];
                for (j, row) in pk.iter_mut().enumerate() {
                    for c in 0..D {
                        row[c] = (0..D).map(|t| p.y(k, t, j) * e[t * D + c]).sum();
                    }
                }
                for l in 0..p.bodies() {
                    let mut blk = [0.0; 36];
                    for i in 0..6 {
                        for j in 0..6 {
                            blk[i * 6 + j] = (0..D).map(|c| pk[i][c] * p.y(l, c, j)).sum();
                        }
                    }
                    bn.lu.add(bn.sig[a][k], bn.sig[a][l], &blk);
                }
            }
        }
        if bn.lu.factor().is_err() {
            return false;
        }
        bn.held = true;
        bn.factorizations += 1;
        true
    }

    /// `newton.dir` (`add`: `+=`) `= J_ε⁻¹ newton.rhs` with the held factorization.
    fn direction<const D: usize>(&mut self, add: bool) {
        let bn = &mut self.newton;
        let n = self.packed.len();
        // t = C⁻¹ g (kept in wdir), then Y t gathered per block
        bn.v.fill(0.0);
        for a in 0..n {
            let t = block_times(D, &bn.cinv[a], &bn.rhs[a * D..(a + 1) * D]);
            bn.wdir[a * D..(a + 1) * D].copy_from_slice(&t[..D]);
            let p = &self.packed[a];
            for k in 0..p.bodies() {
                let b = bn.sig[a][k];
                for j in 0..6 {
                    bn.v[b * 6 + j] += (0..D).map(|c| p.y(k, c, j) * t[c]).sum::<f64>();
                }
            }
        }
        bn.lu.solve(&mut bn.v, &mut bn.work);
        // Δ = t − E Yᵀ v
        for a in 0..n {
            let p = &self.packed[a];
            let mut yv = [0.0; 3];
            for k in 0..p.bodies() {
                let b = bn.sig[a][k];
                for c in 0..D {
                    yv[c] += (0..6).map(|j| p.y(k, c, j) * bn.v[b * 6 + j]).sum::<f64>();
                }
            }
            let ey = block_times(D, &bn.e[a], &yv);
            for c in 0..D {
                let x = bn.wdir[a * D + c] - ey[c];
                if add {
                    bn.dir[a * D + c] += x;
                } else {
                    bn.dir[a * D + c] = x;
                }
            }
        }
    }

    /// `newton.wdir = W newton.dir` through the factored operator.
    fn w_times_dir<const D: usize>(&mut self) {
        let dir = std::mem::take(&mut self.newton.dir);
        self.factored_product::<D>(&dir);
        self.newton.dir = dir;
        for a in 0..self.packed.len() {
            let x = self.packed[a].times::<D>(&self.z);
            self.newton.wdir[a * D..(a + 1) * D].copy_from_slice(&x[..D]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::invert;
    use crate::contact::group::sphere_pile;
    use crate::data::Data;
    use crate::dynamics::Workspace;
    use crate::forces::NoCallbacks;
    use crate::integrator::moreau_jean::MoreauJean;
    use crate::model::{Model, ModelDescription};
    use crate::solver::{Method, NewtonOptions};

    /// 27 spheres poured into a box, stepped with Newton (tol 1e-10) for 0.4 s: once with the
    /// direction in body space (forced at every size), once with the dense factorization of the
    /// contact Jacobian island by island (the method of `solver::newton`). Every step converges in
    /// both, and the spheres end where the other run puts them.
    #[test]
    fn body_space_newton_moves_a_pile_as_the_dense_newton_does() {
        let json = sphere_pile(27, 0.05, 0.1, 0.17, 0.3, 0.0, 3);
        let model = Model::from_description(ModelDescription::from_json(&json).unwrap()).unwrap();
        let h = 1e-3;
        let run = |above: usize| {
            let method = Method::Newton(NewtonOptions { tol: 1e-10, body_space_above: above, ..Default::default() });
            let mut st = MoreauJean::new(&model, h, method).unwrap();
            assert!(st.is_sparse());
            let (mut data, mut ws) = (Data::new(&model), Workspace::new(&model));
            let (mut q, mut u) = (model.q0(), model.u0());
            let (mut most, mut iterations) = (0, 0);
            for k in 0..400 {
                st.step(&model, &mut data, &mut ws, k as f64 * h, &mut q, &mut u, &NoCallbacks).unwrap();
                most = most.max(st.problem_shape().0);
                iterations += st.report.map_or(0, |r| r.iterations);
            }
            (q, st.unconverged.0, st.body_space_factorizations(), most, iterations)
        };
        let (q_body, unconverged_body, factorizations, most, it_body) = run(0);
        let (q_dense, unconverged_dense, none, _, it_dense) = run(usize::MAX);
        eprintln!("iterations: body {it_body}, dense {it_dense}; factorizations {factorizations}");
        // the same Newton steps (a wrong direction would fail the line search and fall back to
        // one sweep per iteration, converging in many more)
        assert!(it_body as f64 <= 1.2 * it_dense as f64 + 20.0, "{it_body} iterations in body space, {it_dense} dense");
        assert!(most >= 27, "only {most} contact points at most");
        assert!(factorizations > 100, "{factorizations} body-space factorizations");
        assert_eq!(none, 0);
        assert_eq!((unconverged_body, unconverged_dense), (0, 0));
        let diff = q_body.iter().zip(&q_dense).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        // (2.7e-12 m measured: round-off of the two factorizations, amplified by the pour)
        assert!(diff < 1e-9, "positions differ by {diff:e}");
        // the spheres have fallen onto the floor or each other (not floating where they started)
        let lowest = (0..27).map(|i| q_body[7 * i + 2]).fold(f64::INFINITY, f64::min);
        assert!((lowest - 0.05).abs() < 1e-3, "lowest sphere centre at {lowest}");
    }

    #[test]
    fn block_inverses_are_inverses() {
        let a3 = [2.0, 0.3, -0.1, 0.2, 1.5, 0.4, -0.3, 0.1, 3.0];
        let i3 = invert(3, &a3).unwrap();
        for r in 0..3 {
            for c in 0..3 {
                let x: f64 = (0..3).map(|k| a3[r * 3 + k] * i3[k * 3 + c]).sum();
                assert!((x - if r == c { 1.0 } else { 0.0 }).abs() < 1e-14);
            }
        }
        let a2 = [2.0, 0.5, -0.25, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let i2 = invert(2, &a2).unwrap();
        assert!(
            (a2[0] * i2[0] + a2[1] * i2[2] - 1.0).abs() < 1e-15 && (a2[2] * i2[1] + a2[3] * i2[3] - 1.0).abs() < 1e-15
        );
        assert!(invert(3, &[1.0, 2.0, 3.0, 2.0, 4.0, 6.0, 0.0, 0.0, 1.0,]).is_none());
    }
}
