//! Semismooth Newton method on the Alart–Curnier function for friction contact.
//!
//! With `ρ_i = 1/W_NN,i` and `u = W r + q`, per contact
//!
//! ```text
//! x_N = r_N − ρ u_N,    Φ_N = r_N − max(0, x_N)
//! x_T = r_T − ρ u_T,    Φ_T = r_T − proj_{B(μ max(0, x_N))}(x_T)
//! ```
//!
//! `Φ(r) = 0` is exactly Signorini (`0 ≤ r_N ⊥ u_N ≥ 0`) and Coulomb on the disk of radius
//! `μ r_N` (stick inside with `u_T = 0`, slip on its rim opposite to `u_T`). Writing
//! `Φ = r − P(x)` with the projection `P` and `x = r − ρ (W r + q)`, a generalized Jacobian is
//! `J = I − D (I − ρ W)` with `D ∈ ∂P(x)` block-diagonal:
//!
//! - `∂P_N/∂x_N = 1` if `x_N > 0`, else 0;
//! - inside the disk (`|x_T| ≤ R`): `∂P_T/∂x_T = I`, `∂P_T/∂x_N = 0`;
//! - outside: `∂P_T/∂x_T = (R/|x_T|)(I − x̂ x̂ᵀ)`, `∂P_T/∂x_N = μ x̂` (if `x_N > 0`), `x̂ = x_T/|x_T|`.
//!
//! A stack or any statically indeterminate support (four corners of a box on a face) makes `W`
//! singular, and with it `J` on the sticking contacts. The Newton direction is therefore taken
//! with the regularized Delassus matrix `W + ε` (`ε_i = reg · W_NN,i` on contact `i`'s rows):
//! `J_ε Δ = −Φ`. The local velocities of a Delassus problem never have a component in `W`'s
//! null space (`q` lies in the range of the contact Jacobian, orthogonal to the null space of its
//! transpose, which is `W`'s), so on the sticking set the step leaves the velocity
//! error `ε (W + ε)⁻¹ u`: a contraction by `reg / σ` per iteration on each eigenvalue `σ` of the
//! scaled `W`, while the merit and the stopping test stay those of the exact problem. Along the
//! null space the step is `ε`-damped, so the impulses of an indeterminate support stay near the
//! warm start instead of running off. Three passes of iterative refinement against the exact `J`
//! (each an `O((d n)²)` solve with the same factors) take the range components on to `(reg/σ)⁴`,
//! so near the solution the iteration keeps Newton's speed.
//!
//! Each iteration solves `J Δ = −Φ` with an LU on preallocated storage (dense, skipping the zeros beyond each row's profile: contacts along a stack give a banded J) and backtracks
//! `r + α Δ` (α = 1, ½, ¼, …) until Armijo's condition `ψ(r + αΔ) ≤ (1 − 2σα) ψ(r)` holds for
//! the merit `ψ = ½|Φ|²` (σ = 10⁻⁴; `−2ψ` is the directional derivative along a Newton step).
//! When the LU fails or no step is accepted, one nonsmooth Gauss–Seidel sweep is taken instead:
//! it makes progress where the Newton model is wrong (at the kinks of the projection and with
//! redundant contacts, where `J` is singular). Stops when the residual of [`Report::residual`]
//! reaches the tolerance, after one more step unless it is already below a thousandth of it,
//! or (with [`NewtonOptions::stall`], as [`super::Method::Auto`] sets it) unconverged once the
//! residual has not halved for that many iterations: on piles the method can stall far from the
//! solution, and sweeps do better from there. Cost per iteration `O((d n)³)`, so this is the
//! method for accuracy on moderate sizes; NSGS is the one for large ones.

use super::nsgs::{prepare_diagonal, sweep};
use super::problem::{fc_residual, Delassus, FrictionContact};
use super::{NewtonOptions, Report, Workspace};
use crate::error::Result;
use crate::math::linalg::{lu_factor_profile, lu_solve_profile};

/// Newton scratch for `m = d n` unknowns.
#[derive(Debug, Clone, Default)]
pub(crate) struct NewtonWork {
    jac: Vec<f64>,
    piv: Vec<usize>,
    /// Row extents of the factors (a contact problem ordered along a stack is banded).
    ext: Vec<(usize, usize)>,
    phi: Vec<f64>,
    dir: Vec<f64>,
    wdir: Vec<f64>,
    r_trial: Vec<f64>,
    u_trial: Vec<f64>,
    phi_trial: Vec<f64>,
    /// Per-contact `D` blocks (row-major `d × d`).
    dblk: Vec<[f64; 9]>,
    /// The size of the factorization held in `jac` (0: none).
    lu_size: usize,
}

impl NewtonWork {
    /// Whether it holds a factorization (of any size): once Newton has factored a problem here.
    pub(crate) fn holds_factorization(&self) -> bool {
        self.lu_size != 0
    }

    pub(crate) fn reserve(&mut self, m: usize) {
        if self.phi.len() < m {
            self.jac.resize(m * m, 0.0);
            self.piv.resize(m, 0);
            self.ext.resize(m, (0, 0));
            for v in [
                &mut self.phi,
                &mut self.dir,
                &mut self.wdir,
                &mut self.r_trial,
                &mut self.u_trial,
                &mut self.phi_trial,
            ] {
                v.resize(m, 0.0);
            }
            self.dblk.resize(m, [0.0; 9]);
            self.lu_size = 0;
        }
    }
}

const ARMIJO: f64 = 1e-4;
/// Below `POLISH · tol` Newton stops without the extra step.
const POLISH: f64 = 1e-3;
const MAX_BACKTRACKS: usize = 30;
/// Passes of iterative refinement of the regularized Newton direction.
pub(crate) const REFINEMENTS: usize = 3;

/// The stopping rules of the Newton iteration (shared with the body-space variant of the
/// Moreau–Jean scheme): the tolerance with one step past it, the iteration cap, and the stall
/// rule of [`NewtonOptions::stall`].
pub(crate) struct Stopping {
    iterations: usize,
    polished: bool,
    /// The residual last halved at iteration `since`, from `anchor`.
    anchor: f64,
    since: usize,
}

impl Stopping {
    pub(crate) fn new() -> Self {
        Self { iterations: 0, polished: false, anchor: f64::INFINITY, since: 0 }
    }

    /// The report if the iteration stops at `residual`; otherwise counts the next iteration.
    pub(crate) fn check(&mut self, residual: f64, o: &NewtonOptions) -> Option<Report> {
        let iterations = self.iterations;
        if residual <= 0.5 * self.anchor {
            (self.anchor, self.since) = (residual, iterations);
        }
        let stalled = o.stall > 0 && iterations - self.since >= o.stall;
        // one step past the tolerance (nearly free with the factors reused): a time-stepping
        // scheme passes the error left here on to the next step's free velocity, and a solution
        // well inside the tolerance lets the next warm start finish in a sweep
        let done = residual <= o.tol && (self.polished || residual <= POLISH * o.tol);
        if done || iterations >= o.max_iter || (stalled && residual > o.tol) {
            return Some(Report { iterations, residual, converged: residual <= o.tol });
        }
        self.polished = residual <= o.tol;
        self.iterations += 1;
        None
    }
}

/// Armijo's backtracking from `r` (with `u = W r + q`) along `dir` (with `W dir` in `wdir`) for the
/// merit `ψ = ½|Φ|²`, `psi` at `r`; `merit` gives ψ at a trial point. On success `r` takes the
/// step and it returns true. A reused factorization (`fresh` false) gets the full step only.
#[allow(clippy::too_many_arguments)]
pub(crate) fn line_search(
    r: &mut [f64],
    u: &[f64],
    dir: &[f64],
    wdir: &[f64],
    r_t: &mut [f64],
    u_t: &mut [f64],
    psi: f64,
    fresh: bool,
    mut merit: impl FnMut(&[f64], &[f64]) -> f64,
) -> bool {
    let mut alpha = 1.0;
    for _ in 0..MAX_BACKTRACKS {
        for k in 0..r.len() {
            r_t[k] = r[k] + alpha * dir[k];
            u_t[k] = u[k] + alpha * wdir[k];
        }
        if merit(r_t, u_t) <= (1.0 - 2.0 * ARMIJO * alpha) * psi {
            r.copy_from_slice(r_t);
            return true;
        }
        alpha *= 0.5;
        // a reused factorization gets one full step's chance, then a fresh one
        if !fresh {
            break;
        }
    }
    false
}

/// Alart–Curnier function of one contact into `phi`, and optionally `D = ∂P(x)` into `dmat`.
pub(crate) fn alart_curnier(
    d: usize,
    mu: f64,
    rho: f64,
    r: &[f64],
    u: &[f64],
    phi: &mut [f64],
    dmat: Option<&mut [f64; 9]>,
) {
    let xn = r[0] - rho * u[0];
    let pn = xn.max(0.0);
    phi[0] = r[0] - pn;
    let radius = mu * pn;
    let mut xt = [0.0; 2];
    for a in 1..d {
        xt[a - 1] = r[a] - rho * u[a];
    }
    let nt = xt[0].hypot(xt[1]);
    let inside = nt <= radius;
    for a in 1..d {
        let pt = if inside { xt[a - 1] } else { radius * xt[a - 1] / nt };
        phi[a] = r[a] - pt;
    }
    if let Some(dm) = dmat {
        dm[..d * d].fill(0.0);
        if xn > 0.0 {
            dm[0] = 1.0;
        }
        for a in 1..d {
            for b in 1..d {
                dm[a * d + b] = if inside {
                    if a == b {
                        1.0
                    } else {
                        0.0
                    }
                } else {
                    let (ha, hb) = (xt[a - 1] / nt, xt[b - 1] / nt);
                    radius / nt * (if a == b { 1.0 } else { 0.0 } - ha * hb)
                };
            }
            if !inside && xn > 0.0 {
                dm[a * d] = mu * xt[a - 1] / nt;
            }
        }
    }
}

/// `Φ(r)` for all contacts into `phi` given `u = W r + q`, the diagonal cache and, if `dblk` is
/// given, the `D` blocks; returns `ψ = ½|Φ|²`.
pub(crate) fn evaluate(
    p: &FrictionContact,
    diag: &[[f64; 9]],
    r: &[f64],
    u: &[f64],
    phi: &mut [f64],
    mut dblk: Option<&mut [[f64; 9]]>,
) -> f64 {
    let d = p.dim;
    let mut psi = 0.0;
    for i in 0..p.contacts() {
        let s = i * d..(i + 1) * d;
        let dm = dblk.as_deref_mut().map(|b| &mut b[i]);
        alart_curnier(d, p.mu[i], 1.0 / diag[i][0], &r[s.clone()], &u[s.clone()], &mut phi[s.clone()], dm);
        psi += phi[s].iter().map(|v| v * v).sum::<f64>();
    }
    0.5 * psi
}

/// `J = I − D + D diag(ρ) (W + ε)` into `jac` (row-major `m × m`), `ε_i = reg W_NN,i`.
pub(crate) fn assemble(p: &FrictionContact, diag: &[[f64; 9]], dblk: &[[f64; 9]], reg: f64, jac: &mut [f64]) {
    let d = p.dim;
    let n = p.contacts();
    let m = d * n;
    match &p.w {
        Delassus::Dense(w) => {
            for i in 0..n {
                let rho = 1.0 / diag[i][0];
                let dm = &dblk[i];
                for a in 0..d {
                    let row = &mut jac[(i * d + a) * m..(i * d + a + 1) * m];
                    row.fill(0.0);
                    for k in 0..d {
                        let f = rho * dm[a * d + k];
                        if f != 0.0 {
                            for (j, v) in row.iter_mut().zip(&w[(i * d + k) * m..(i * d + k + 1) * m]) {
                                *j += f * v;
                            }
                        }
                    }
                }
            }
        }
        Delassus::Blocks(bw) => {
            jac[..m * m].fill(0.0);
            for i in 0..n {
                let rho = 1.0 / diag[i][0];
                let dm = &dblk[i];
                let mut put = |j: usize, blk: &[f64]| {
                    for a in 0..d {
                        for c in 0..d {
                            let v: f64 = (0..d).map(|k| dm[a * d + k] * blk[k * d + c]).sum();
                            jac[(i * d + a) * m + j * d + c] += rho * v;
                        }
                    }
                };
                put(i, &diag[i][..d * d]);
                for (j, blk) in bw.row_blocks(i) {
                    put(j, blk);
                }
            }
        }
    }
    // I − D, and the regularization D ρ ε I with ε = reg W_NN,i, i.e. reg D
    for i in 0..n {
        for a in 0..d {
            for c in 0..d {
                let id = if a == c { 1.0 } else { 0.0 };
                jac[(i * d + a) * m + i * d + c] += id - (1.0 - reg) * dblk[i][a * d + c];
            }
        }
    }
}

/// Semismooth Newton for a friction-contact problem.
pub(crate) fn solve(p: &FrictionContact, o: &NewtonOptions, r: &mut [f64], ws: &mut Workspace) -> Result<Report> {
    let d = p.dim;
    let n = p.contacts();
    let m = d * n;
    prepare_diagonal(p, &mut ws.diag[..n], &mut ws.local3[..n]);
    let diag = &ws.diag[..n];
    let local3 = &ws.local3[..n];
    let order = &ws.order;
    let u = &mut ws.u[..m];
    let nw = &mut ws.newton;
    let (jac, piv, ext) = (&mut nw.jac[..m * m], &mut nw.piv[..m], &mut nw.ext[..m]);
    let (phi, dir, wdir) = (&mut nw.phi[..m], &mut nw.dir[..m], &mut nw.wdir[..m]);
    let (r_t, u_t, phi_t) = (&mut nw.r_trial[..m], &mut nw.u_trial[..m], &mut nw.phi_trial[..m]);
    let dblk = &mut nw.dblk[..n];
    let mut stopping = Stopping::new();
    loop {
        p.w.velocity(d, r, &p.q, u);
        if let Some(report) = stopping.check(fc_residual(p, r, u), o) {
            return Ok(report);
        }
        let psi = evaluate(p, diag, r, u, phi, Some(&mut *dblk));
        // the factorization of the last solve of this size is reused as a chord direction: for
        // the same projection derivatives D (a resting contact set) it is nearly exact, for a
        // few changed blocks the refinement against the exact J makes up most of the difference;
        // the line search decides, and a fresh Jacobian follows if the full step fails
        let mut fresh = !(o.reuse && nw.lu_size == m);
        let mut accepted = false;
        loop {
            if fresh {
                assemble(p, diag, dblk, o.regularization, jac);
                nw.lu_size = 0;
                if lu_factor_profile(jac, m, piv, ext).is_err() {
                    break;
                }
                nw.lu_size = m;
            }
            for (x, f) in dir.iter_mut().zip(phi.iter()) {
                *x = -f;
            }
            lu_solve_profile(jac, m, piv, ext, dir);
            // iterative refinement against the exact J: each pass shrinks the regularization's
            // error by reg/σ, so the iteration converges as Newton's does, not linearly at rate reg
            for _ in 0..REFINEMENTS {
                if !dir.iter().all(|v| v.is_finite()) {
                    break;
                }
                matvec(&p.w, d, dir, wdir);
                for i in 0..n {
                    let (rho, dm) = (1.0 / diag[i][0], &dblk[i]);
                    for a in 0..d {
                        let mut jd = dir[i * d + a];
                        for c in 0..d {
                            jd += dm[a * d + c] * (rho * wdir[i * d + c] - dir[i * d + c]);
                        }
                        // the right-hand side's residual, −Φ − J Δ
                        phi_t[i * d + a] = -phi[i * d + a] - jd;
                    }
                }
                lu_solve_profile(jac, m, piv, ext, phi_t);
                for (x, c) in dir.iter_mut().zip(phi_t.iter()) {
                    *x += c;
                }
            }
            if dir.iter().all(|v| v.is_finite()) {
                // W Δ once; trial velocities are then u + α W Δ
                matvec(&p.w, d, dir, wdir);
                accepted =
                    line_search(r, u, dir, wdir, r_t, u_t, psi, fresh, |rt, ut| evaluate(p, diag, rt, ut, phi_t, None));
            }
            if accepted || fresh {
                break;
            }
            fresh = true;
        }
        if !accepted {
            sweep(p, (diag, local3), order, r, 1.0, None);
        }
    }
}

/// `out = W x`.
fn matvec(w: &Delassus, d: usize, x: &[f64], out: &mut [f64]) {
    let n = x.len() / d;
    for i in 0..n {
        let mut ui = [0.0; 3];
        w.add_row_product(d, i, x, false, &mut ui);
        out[i * d..(i + 1) * d].copy_from_slice(&ui[..d]);
    }
}
