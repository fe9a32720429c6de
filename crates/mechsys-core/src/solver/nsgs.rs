//! Projected Gauss–Seidel for the LCP and nonsmooth Gauss–Seidel (NSGS) for friction contact.
//!
//! A sweep visits the unknowns (LCP) or contacts (friction) in order and solves each one's
//! problem exactly with the others frozen at their newest values. For contact `i` the local
//! problem is `u_i = W_ii r_i + b_i`, `b_i = q_i + Σ_{j≠i} W_ij r_j`, with the Signorini–Coulomb
//! conditions; the local solver finds its solution by cases:
//!
//! - open: `b_N ≥ 0` ⇒ `r = 0`;
//! - stick: `r = −W_ii⁻¹ b` if it lies in the cone;
//! - slip: `u_N = 0`, `r_T = −μ r_N t` with the unit sliding direction `t`. In the plane
//!   `t = ±1` and `r_N = −b_N/(W_NN ∓ μ W_NT)`, tried in both signs. In space `t = (cos θ, sin θ)`
//!   and `u_N = 0` gives `r_N(θ) = −b_N/(W_NN − μ W_NT t)`; the tangential velocity
//!   `u_T(θ) = r_N (W_TN − μ W_TT t) + b_T` must be parallel to `t`, i.e. the scalar equation
//!   `F(θ) = (W_NN − μ W_NT t) · (t^⊥ · u_T(θ)) = 0`, a trigonometric polynomial of degree 2,
//!   solved by Newton from the previous sliding direction, or by bracketing all its roots if that
//!   fails; a root counts if `r_N > 0` and `t · u_T ≥ 0` (the friction force opposes sliding).
//!
//! An isotropic block (`W_NT = 0`, `W_TT = c I`: contacts of spheres, or of bodies with uniform
//! inertia) needs no cases: `r_N = max(0, −b_N/W_NN)` and `r_T` is the stick impulse `−b_T/c`
//! scaled back onto the disk of radius `μ r_N`.
//!
//! Over-relaxation `ω ∈ (1, 2)` extrapolates each local solution (`r_i ← ω r_i,local + (1 − ω)
//! r_i`, projected back onto the cone); the solve drops to `ω = 1` at the first sweep that
//! changes the impulses more than the previous one (the safeguard against overshooting).
//!
//! If no case holds to round-off (a singular or strongly non-symmetric block), a projected
//! fixed-point iteration on the De Saxcé map `r ← proj_K(r − ρ (u + μ|u_T| e_N))` finishes the
//! local problem. Sweeps stop when the velocity-weighted change `‖W_NN,i Δr_i‖` falls below the
//! tolerance and the full residual of [`Report::residual`] confirms it; after a failed
//! confirmation the next one waits 1, 2, 4, … up to 64 sweeps, so the reported sweep count can
//! exceed the first sweep that met the tolerance by that much.

use super::anderson::Anderson;
use super::problem::{dot, fc_residual, lcp_residual, lcp_w, norm, project_onto_cone, FrictionContact, Lcp};
use super::{NsgsOptions, Report, Workspace};
use crate::ensure;
use crate::error::Result;

/// Projected Gauss–Seidel for an LCP with positive diagonal:
/// `z_i ← max(0, z_i − w_i / M_ii)`.
pub(crate) fn solve_lcp(p: &Lcp, o: &NsgsOptions, z: &mut [f64], ws: &mut Workspace) -> Result<Report> {
    let n = p.size();
    for i in 0..n {
        let mii = p.m[i * n + i];
        ensure!(mii > 0.0, Settings, "LCP: projected Gauss–Seidel needs M_ii > 0, but M[{i}, {i}] = {mii}; use Lemke");
    }
    let qn = 1.0 + norm(&p.q);
    let w = &mut ws.u[..n];
    let mut residual = f64::INFINITY;
    let mut check = CheckSchedule::new();
    for it in 1..=o.max_iter {
        let mut change = 0.0;
        for i in 0..n {
            let row = &p.m[i * n..(i + 1) * n];
            let wi = p.q[i] + dot(row, z);
            let new = (z[i] - wi / row[i]).max(0.0);
            let new = o.relaxation * new + (1.0 - o.relaxation) * z[i];
            change += (row[i] * (new - z[i])).powi(2);
            z[i] = new;
        }
        if check.due(it, change.sqrt() / qn <= o.tol) || it == o.max_iter {
            lcp_w(&p.m, &p.q, z, w);
            residual = lcp_residual(&p.m, &p.q, z, w);
            if residual <= o.tol {
                return Ok(Report { iterations: it, residual, converged: true });
            }
        }
    }
    Ok(Report { iterations: o.max_iter, residual, converged: false })
}

/// Nonsmooth Gauss–Seidel for a friction-contact problem.
pub(crate) fn solve_fc(p: &FrictionContact, o: &NsgsOptions, r: &mut [f64], ws: &mut Workspace) -> Result<Report> {
    let n = p.contacts();
    let m = p.dim * n;
    prepare_diagonal(p, &mut ws.diag[..n], &mut ws.local3[..n]);
    let qn = 1.0 + norm(&p.q);
    let mut residual = f64::INFINITY;
    let mut check = CheckSchedule::new();
    // over-relaxation (ω > 1) with a safeguard: when a sweep changes the impulses more than the
    // one before, the extrapolation overshoots; the solve goes on with plain sweeps (ω = 1)
    let mut omega = o.relaxation;
    let mut last_change = f64::INFINITY;
    if o.anderson > 0 {
        ws.anderson.begin(m, 0, o.anderson);
    }
    let mut stall = StallWatch::new(o.stall);
    for it in 1..=o.max_iter {
        let accelerate = o.anderson > 0 && omega == 1.0;
        let steps = if accelerate { Some(&mut ws.anderson) } else { None };
        let change = sweep(p, (&ws.diag[..n], &ws.local3[..n]), &ws.order, r, omega, steps);
        if omega > 1.0 && change > last_change {
            omega = 1.0;
        }
        last_change = change;
        if stall.stalled(it, change) {
            omega = StallWatch::damped(omega);
        }
        if check.due(it, change.sqrt() / qn <= o.tol) || it == o.max_iter {
            let u = &mut ws.u[..m];
            p.w.velocity(p.dim, r, &p.q, u);
            residual = fc_residual(p, r, u);
            if residual <= o.tol {
                return Ok(Report { iterations: it, residual, converged: true });
            }
        }
        if accelerate && it < o.max_iter {
            ws.anderson.step(r, &mut [], change);
        }
    }
    Ok(Report { iterations: o.max_iter, residual, converged: false })
}

/// When to recompute the full residual (one extra product with `W`): once the change of a sweep
/// is below the tolerance, but after a check that fails the next waits 1, 2, 4, … up to 64 sweeps,
/// because with a warm start the change can be small long before the residual is.
pub(crate) struct CheckSchedule {
    next: usize,
    gap: usize,
}

impl CheckSchedule {
    pub(crate) fn new() -> Self {
        Self { next: 1, gap: 1 }
    }

    /// Whether to check at sweep `it`; assumes the check is made (and failed, if the caller goes on).
    pub(crate) fn due(&mut self, it: usize, small_change: bool) -> bool {
        if small_change && it >= self.next {
            self.next = it + self.gap;
            self.gap = (2 * self.gap).min(64);
            true
        } else {
            false
        }
    }
}

/// Whether Gauss–Seidel has stopped converging. The sweeps are cut into windows ending at sweep
/// `stall`, `2 stall`, `4 stall`, … after the start (or the last stall); at the end of a window
/// the smallest change of a sweep in it (the measure of the stopping test) must be at most half
/// that of the window before. Sweeps that converge at any steady rate pass (each window is at
/// least as long as the one before, so it gains at least as much). Some problems of a settling
/// pile make plain sweeps cycle: the residual wanders between 1e-4 and 1e-3 for 20 000 sweeps,
/// where sweeps under-relaxed to ω = 0.9 converge in 2 000. At a stall the solvers therefore
/// damp the sweeps ([`STALL_DAMPING`]).
pub(crate) struct StallWatch {
    stall: usize,
    start: usize,
    next: usize,
    window: f64,
    before: f64,
}

/// The factor on the relaxation `ω` at each stall of [`StallWatch`] (down to [`STALL_MIN_OMEGA`]).
pub(crate) const STALL_DAMPING: f64 = 0.9;
/// The smallest relaxation the stalls lead to.
pub(crate) const STALL_MIN_OMEGA: f64 = 0.5;

impl StallWatch {
    /// `stall = 0`: never stalls.
    pub(crate) fn new(stall: usize) -> Self {
        Self { stall, start: 0, next: stall, window: f64::INFINITY, before: f64::INFINITY }
    }

    /// After sweep `it` with change `change`: whether the sweeps stalled (the windows then start
    /// again from `it`).
    #[inline]
    pub(crate) fn stalled(&mut self, it: usize, change: f64) -> bool {
        if self.stall == 0 {
            return false;
        }
        self.window = self.window.min(change);
        if it < self.next {
            return false;
        }
        let stalled = self.window > 0.5 * self.before;
        if stalled {
            (self.start, self.before) = (it, f64::INFINITY);
        } else {
            self.before = self.window;
        }
        self.window = f64::INFINITY;
        // windows of stall, stall, 2 stall, 4 stall, … after the start
        self.next = it + (it - self.start).max(self.stall);
        stalled
    }

    /// The relaxation after a stall at relaxation `omega`.
    pub(crate) fn damped(omega: f64) -> f64 {
        (STALL_DAMPING * omega.min(1.0)).max(STALL_MIN_OMEGA)
    }
}

/// Copies each contact's diagonal block of `W` (row-major `d × d`).
pub(crate) fn cache_diagonal(p: &FrictionContact, diag: &mut [[f64; 9]]) {
    for (i, blk) in diag.iter_mut().enumerate() {
        p.w.diag_block(p.dim, i, blk);
    }
}

/// [`cache_diagonal`], and for a 3-D problem each block prepared for the sweeps' local solves.
pub(crate) fn prepare_diagonal(p: &FrictionContact, diag: &mut [[f64; 9]], local3: &mut [LocalBlock3]) {
    cache_diagonal(p, diag);
    if p.dim == 3 {
        for (l, blk) in local3.iter_mut().zip(diag.iter()) {
            *l = LocalBlock3::new(blk);
        }
    }
}

/// One Gauss–Seidel sweep over the contacts, in `order` if it holds a permutation of them
/// ([`Workspace::set_order`]), else by index; returns `Σ_i ‖W_NN,i Δr_i‖²` and gives each
/// unknown's term `W_NN,i Δr_i` to the Anderson acceleration `aa` if there is one. The diagonal
/// blocks as [`prepare_diagonal`] left them.
pub(crate) fn sweep(
    p: &FrictionContact,
    (diag, local3): (&[[f64; 9]], &[LocalBlock3]),
    order: &[usize],
    r: &mut [f64],
    relaxation: f64,
    mut aa: Option<&mut Anderson>,
) -> f64 {
    let d = p.dim;
    let mut change = 0.0;
    let nc = p.contacts();
    // the caller's visiting order (a permutation of the contacts), else the natural one
    let ordered = order.len() == nc;
    for ii in 0..nc {
        let i = if ordered { order[ii] } else { ii };
        let mut b = [0.0; 3];
        p.w.add_row_product(d, i, r, true, &mut b);
        let mut old = [0.0; 3];
        for a in 0..d {
            b[a] += p.q[i * d + a];
            old[a] = r[i * d + a];
        }
        let mut new = old;
        if d == 3 {
            local3[i].solve(p.mu[i], &b, &mut new);
        } else {
            local_solve(d, &diag[i], p.mu[i], &b, &mut new);
        }
        let mut v = [0.0; 3];
        for a in 0..d {
            v[a] = relaxation * new[a] + (1.0 - relaxation) * old[a];
        }
        if relaxation > 1.0 {
            // an extrapolated impulse may leave the cone: back onto it
            let x = v;
            project_onto_cone(p.mu[i], &x[..d], &mut v[..d]);
        }
        for a in 0..d {
            let f = diag[i][0] * (v[a] - old[a]);
            change += f * f;
            r[i * d + a] = v[a];
            if let Some(aa) = aa.as_deref_mut() {
                aa.set_residual(i * d + a, f);
            }
        }
    }
    change
}

/// Solves the one-contact problem `u = A r + b` (A row-major `d × d` in the first `d²` entries,
/// `A_NN > 0`) with the Signorini–Coulomb conditions. On entry `r` is the previous value, used
/// as the first guess of the 3-D sliding direction; on exit the solution.
pub(crate) fn local_solve(d: usize, a: &[f64; 9], mu: f64, b: &[f64; 3], r: &mut [f64; 3]) {
    *r = if d == 2 { local_2d(a, mu, b) } else { local_3d(a, mu, b, r) };
}

/// Largest off-diagonal entry of a block, and difference of its two tangential diagonal entries,
/// relative to its trace, for the block to be solved as isotropic. The blocks of sphere
/// contacts come out of the assembly isotropic only to about 1e-13–1e-12 of their trace
/// (measured in a pile of spheres, where most blocks missed a test at 1e-13 and each miss cost
/// the iterative slip solve); the closed form then solves a block within 1e-12 of its trace of
/// the assembled one, inside the tolerances sweeps stop at.
const ISOTROPY_TOL: f64 = 1e-12;

/// Relative slack of the stick and slip sign tests, so that a solution on the cone's edge is
/// accepted by the case that is exact to round-off.
const SLACK: f64 = 1e-12;

fn local_2d(a: &[f64; 9], mu: f64, b: &[f64; 3]) -> [f64; 3] {
    let (ann, ant, atn, att) = (a[0], a[1], a[2], a[3]);
    let (bn, bt) = (b[0], b[1]);
    if bn >= 0.0 {
        return [0.0; 3];
    }
    if mu == 0.0 {
        return [-bn / ann, 0.0, 0.0];
    }
    // stick: A r = −b (Cramer)
    let det = ann * att - ant * atn;
    let mut slip_sign;
    if att > 0.0 && det > 1e-13 * ann * att {
        let rn = (-bn * att + bt * ant) / det;
        let rt = (-ann * bt + atn * bn) / det;
        if rn > 0.0 && rt.abs() <= mu * rn * (1.0 + SLACK) {
            return [rn, rt, 0.0];
        }
        slip_sign = -rt.signum();
    } else {
        // no tangential mobility of its own: r_T = 0 sticks iff the coupling leaves u_T = 0
        let rn = -bn / ann;
        let ut = atn * rn + bt;
        if ut.abs() <= SLACK * (bt.abs() + (atn * rn).abs()) {
            return [rn, 0.0, 0.0];
        }
        slip_sign = ut.signum();
    }
    if slip_sign == 0.0 {
        slip_sign = 1.0;
    }
    // slip with s = sign(u_T): r_T = −s μ r_N, u_N = 0
    for s in [slip_sign, -slip_sign] {
        let den = ann - s * mu * ant;
        if den <= 0.0 {
            continue;
        }
        let rn = -bn / den;
        let rt = -s * mu * rn;
        let ut = atn * rn + att * rt + bt;
        if s * ut >= -SLACK * (bt.abs() + (atn * rn).abs() + (att * rt).abs()) {
            return [rn, rt, 0.0];
        }
    }
    fixed_point(2, a, mu, b, [-bn / ann, 0.0, 0.0])
}

fn local_3d(a: &[f64; 9], mu: f64, b: &[f64; 3], prev: &[f64; 3]) -> [f64; 3] {
    if isotropic(a) {
        let [inv_nn, inv_c] = isotropic_inverses(a);
        return isotropic_3d(inv_nn, inv_c, mu, b);
    }
    let bn = b[0];
    if bn >= 0.0 {
        return [0.0; 3];
    }
    if mu == 0.0 {
        return [-bn / a[0], 0.0, 0.0];
    }
    let stick = solve3(a, &[-b[0], -b[1], -b[2]]);
    slip_or_stick_3d(a, mu, b, prev, stick)
}

/// `1/W_NN` and `1/c` of an isotropic block, `c` the mean of its tangential diagonal.
#[inline(always)]
fn isotropic_inverses(a: &[f64; 9]) -> [f64; 2] {
    [1.0 / a[0], 2.0 / (a[4] + a[8])]
}

/// The local solve on an isotropic block (`W_NT = 0`, `W_TT = c I`, see [`isotropic`]) from
/// `1/W_NN` and `1/c`: the normal impulse decouples, `r_N = max(0, −b_N/W_NN)`, and the
/// tangential one is the stick impulse `−b_T/c` scaled back onto the disk `|r_T| ≤ μ r_N` (sliding
/// then opposes `b_T`: `u_T = b_T (1 − c μ r_N/|b_T|)`). No branch on the contact's state, which
/// a Gauss–Seidel sweep over a pile cannot predict; open (`b_N ≥ 0`) and frictionless contacts
/// come out of the same formula.
#[inline(always)]
fn isotropic_3d(inv_nn: f64, inv_c: f64, mu: f64, b: &[f64; 3]) -> [f64; 3] {
    let x = -b[0] * inv_nn;
    // (NaN stays NaN for the caller's finiteness check)
    let rn = if x < 0.0 { 0.0 } else { x };
    let (t1, t2) = (-b[1] * inv_c, -b[2] * inv_c);
    let (limit, t_sq) = (mu * rn, t1 * t1 + t2 * t2);
    let scale = if t_sq > limit * limit { limit / t_sq.sqrt() } else { 1.0 };
    [rn, scale * t1, scale * t2]
}

/// A contact's 3-D diagonal block with what the local solve derives from the block alone, made
/// once per solve instead of once per sweep ([`LocalBlock3::solve`]): the cofactors and
/// determinant of Cramer's rule for the stick candidate, or an isotropic block's inverses. The
/// solution is the one of [`local_solve`] bit for bit.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct LocalBlock3 {
    a: [f64; 9],
    /// First-row cofactors and determinant; `None` where `A` is nearly singular.
    cramer: Option<([f64; 3], f64)>,
    /// `1/W_NN` and `1/c` of an isotropic block ([`isotropic_3d`]), else `None`.
    iso: Option<[f64; 2]>,
}

impl LocalBlock3 {
    /// From the row-major 3 × 3 block `a` (`A_NN > 0`).
    pub(crate) fn new(a: &[f64; 9]) -> Self {
        LocalBlock3 { a: *a, cramer: cofactors3(a), iso: isotropic(a).then(|| isotropic_inverses(a)) }
    }

    /// The block (row-major 3 × 3).
    #[inline(always)]
    pub(crate) fn block(&self) -> &[f64; 9] {
        &self.a
    }

    /// [`local_solve`] for `d = 3` on this block. (Inlined into the sweeps, with the general
    /// case behind a call that takes and returns values, so that the isotropic case's impulses
    /// stay in registers: a call that wrote them through `r` kept them on the stack, and reading
    /// them back as one 16-byte load from separate 8-byte stores stalled the sweep's chain of
    /// dependent contacts.)
    #[inline(always)]
    pub(crate) fn solve(&self, mu: f64, b: &[f64; 3], r: &mut [f64; 3]) {
        *r = match self.iso {
            Some([inv_nn, inv_c]) => isotropic_3d(inv_nn, inv_c, mu, b),
            None => self.general(mu, *b, *r),
        };
    }

    /// The local solve on a block that is not isotropic, from the previous impulse `prev`.
    #[inline(never)]
    fn general(&self, mu: f64, b: [f64; 3], prev: [f64; 3]) -> [f64; 3] {
        let bn = b[0];
        if bn >= 0.0 {
            [0.0; 3]
        } else if mu == 0.0 {
            [-bn / self.a[0], 0.0, 0.0]
        } else {
            let stick = self.cramer.map(|(c, det)| cramer3(&self.a, c, det, &[-b[0], -b[1], -b[2]]));
            slip_or_stick_3d(&self.a, mu, &b, &prev, stick)
        }
    }
}

/// Whether `W_NT = W_TN = 0` and `W_TT = c I` to [`ISOTROPY_TOL`], e.g. any contact of spheres
/// with uniform inertia: the sliding velocity then stays parallel to `b_T`.
fn isotropic(a: &[f64; 9]) -> bool {
    let tiny = ISOTROPY_TOL * (a[0] + a[4] + a[8]);
    a[1].abs() <= tiny
        && a[2].abs() <= tiny
        && a[3].abs() <= tiny
        && a[6].abs() <= tiny
        && a[5].abs() <= tiny
        && a[7].abs() <= tiny
        && (a[4] - a[8]).abs() <= tiny
        && a[4] > 0.0
}

/// The 3-D local solve after the open and frictionless cases (`b_N < 0`, `μ > 0`), given the
/// stick candidate `−A⁻¹ b` (`None`: `A` nearly singular), on a block that is not isotropic.
fn slip_or_stick_3d(a: &[f64; 9], mu: f64, b: &[f64; 3], prev: &[f64; 3], stick: Option<[f64; 3]>) -> [f64; 3] {
    let (bn, ann) = (b[0], a[0]);
    let guess_dir = match stick {
        Some(x) => {
            if x[0] > 0.0 && (x[1] * x[1] + x[2] * x[2]).sqrt() <= mu * x[0] * (1.0 + SLACK) {
                return x;
            }
            [-x[1], -x[2]]
        }
        None => {
            let rn = -bn / ann;
            let ut = [a[3] * rn + b[1], a[6] * rn + b[2]];
            if ut[0].hypot(ut[1]) <= SLACK * (b[1].hypot(b[2]) + rn * a[3].hypot(a[6])) {
                return [rn, 0.0, 0.0];
            }
            ut
        }
    };
    // the previous sliding direction is the better guess inside a Gauss–Seidel loop
    let theta0 = if prev[0] > 0.0 && prev[1].hypot(prev[2]) > 0.0 {
        (-prev[2]).atan2(-prev[1])
    } else {
        guess_dir[1].atan2(guess_dir[0])
    };
    match slip_3d(a, mu, b, theta0) {
        Some(x) => x,
        None => fixed_point(3, a, mu, b, [-bn / ann, 0.0, 0.0]),
    }
}

/// The first row's cofactors and the determinant of a 3×3 row-major `A`; `None` if `A` is
/// nearly singular (`|det| ≤ 1e-13 |A_00 A_11 A_22|`).
fn cofactors3(a: &[f64; 9]) -> Option<([f64; 3], f64)> {
    let c0 = a[4] * a[8] - a[5] * a[7];
    let c1 = a[5] * a[6] - a[3] * a[8];
    let c2 = a[3] * a[7] - a[4] * a[6];
    let det = a[0] * c0 + a[1] * c1 + a[2] * c2;
    let scale = (a[0] * a[4] * a[8]).abs();
    (det.abs() > 1e-13 * scale).then_some(([c0, c1, c2], det))
}

/// `A x = y` for a 3×3 row-major `A` by Cramer's rule; `None` if nearly singular.
fn solve3(a: &[f64; 9], y: &[f64; 3]) -> Option<[f64; 3]> {
    let (c, det) = cofactors3(a)?;
    Some(cramer3(a, c, det, y))
}

/// Cramer's rule for `A x = y` given `A`'s first-row cofactors `c` and determinant.
#[inline(always)]
fn cramer3(a: &[f64; 9], [c0, c1, c2]: [f64; 3], det: f64, y: &[f64; 3]) -> [f64; 3] {
    let x0 = (y[0] * c0 + a[1] * (a[5] * y[2] - y[1] * a[8]) + a[2] * (y[1] * a[7] - a[4] * y[2])) / det;
    let x1 = (a[0] * (y[1] * a[8] - a[5] * y[2]) + y[0] * c1 + a[2] * (a[3] * y[2] - y[1] * a[6])) / det;
    let x2 = (a[0] * (a[4] * y[2] - y[1] * a[7]) + a[1] * (y[1] * a[6] - a[3] * y[2]) + y[0] * c2) / det;
    [x0, x1, x2]
}

/// Sliding solution of the 3-D local problem (see the module documentation), `b_N < 0`, `μ > 0`.
fn slip_3d(a: &[f64; 9], mu: f64, b: &[f64; 3], theta0: f64) -> Option<[f64; 3]> {
    let ann = a[0];
    let p = [a[1], a[2]]; // W_NT
    let s = [a[3], a[6]]; // W_TN
    let c = [a[4], a[5], a[7], a[8]]; // W_TT row-major
    let (bn, bt) = (b[0], [b[1], b[2]]);
    let cmul = |v: [f64; 2]| [c[0] * v[0] + c[1] * v[1], c[2] * v[0] + c[3] * v[1]];
    let dot2 = |x: [f64; 2], y: [f64; 2]| x[0] * y[0] + x[1] * y[1];
    let f = |th: f64| slip_function(a, mu, b, th);
    let c_norm = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2] + c[3] * c[3]).sqrt();
    let candidate = |th: f64| -> Option<[f64; 3]> {
        let (sn, cs) = th.sin_cos();
        let t = [cs, sn];
        let den = ann - mu * dot2(p, t);
        if !(den > 0.0) {
            return None;
        }
        let rn = -bn / den;
        let ct = cmul(t);
        let ut = [rn * (s[0] - mu * ct[0]) + bt[0], rn * (s[1] - mu * ct[1]) + bt[1]];
        let scale = bt[0].hypot(bt[1]) + rn * (s[0].hypot(s[1]) + mu * c_norm);
        let along = dot2(t, ut);
        let across = ut[1] * t[0] - ut[0] * t[1];
        if along >= -SLACK * scale && across.abs() <= 1e-9 * scale {
            Some([rn, -mu * rn * t[0], -mu * rn * t[1]])
        } else {
            None
        }
    };
    // Newton from the guess
    let mut th = theta0;
    for _ in 0..40 {
        let (fv, fd) = f(th);
        if fv == 0.0 || fd == 0.0 || !fd.is_finite() {
            break;
        }
        let step = (fv / fd).clamp(-0.5, 0.5);
        th -= step;
        if step.abs() <= 1e-14 {
            break;
        }
    }
    if let Some(x) = candidate(th) {
        return Some(x);
    }
    // bracket every sign change of F on a grid and bisect
    const GRID: usize = 72;
    let h = 2.0 * std::f64::consts::PI / GRID as f64;
    let (mut lo, mut flo) = (0.0, f(0.0).0);
    for k in 1..=GRID {
        let hi = h * k as f64;
        let fhi = f(hi).0;
        if flo == 0.0 {
            if let Some(x) = candidate(lo) {
                return Some(x);
            }
        } else if flo * fhi < 0.0 {
            let (mut l, mut u, mut fl) = (lo, hi, flo);
            for _ in 0..60 {
                let mid = 0.5 * (l + u);
                let fm = f(mid).0;
                if fm == 0.0 {
                    l = mid;
                    u = mid;
                    break;
                }
                if (fm < 0.0) == (fl < 0.0) {
                    l = mid;
                    fl = fm;
                } else {
                    u = mid;
                }
            }
            if let Some(x) = candidate(0.5 * (l + u)) {
                return Some(x);
            }
        }
        lo = hi;
        flo = fhi;
    }
    None
}

/// `F(θ)` of the module documentation and `dF/dθ` (using `dt/dθ = t^⊥`, `dt^⊥/dθ = −t`).
pub(crate) fn slip_function(a: &[f64; 9], mu: f64, b: &[f64; 3], theta: f64) -> (f64, f64) {
    let ann = a[0];
    let p = [a[1], a[2]]; // W_NT
    let s = [a[3], a[6]]; // W_TN
    let cmul = |v: [f64; 2]| [a[4] * v[0] + a[5] * v[1], a[7] * v[0] + a[8] * v[1]];
    let dot2 = |x: [f64; 2], y: [f64; 2]| x[0] * y[0] + x[1] * y[1];
    let (bn, bt) = (b[0], [b[1], b[2]]);
    let (sn, cs) = theta.sin_cos();
    let t = [cs, sn];
    let np = [-sn, cs];
    let (ct, cn) = (cmul(t), cmul(np));
    let den = ann - mu * dot2(p, t);
    let fv = -bn * dot2(np, s) + mu * bn * dot2(np, ct) + den * dot2(np, bt);
    let fd =
        bn * dot2(t, s) + mu * bn * (dot2(np, cn) - dot2(t, ct)) - mu * dot2(p, np) * dot2(np, bt) - den * dot2(t, bt);
    (fv, fd)
}

/// Projected fixed point on the De Saxcé map with `ρ = 1/‖A‖_F`; the last resort of the local
/// solve.
fn fixed_point(d: usize, a: &[f64; 9], mu: f64, b: &[f64; 3], mut r: [f64; 3]) -> [f64; 3] {
    let rho = 1.0 / a[..d * d].iter().map(|v| v * v).sum::<f64>().sqrt();
    for _ in 0..2000 {
        let mut u = [0.0; 3];
        for i in 0..d {
            u[i] = b[i] + dot(&a[i * d..(i + 1) * d], &r[..d]);
        }
        let ut = if d == 3 { u[1].hypot(u[2]) } else { u[1].abs() };
        let mut x = [0.0; 3];
        x[0] = r[0] - rho * (u[0] + mu * ut);
        for i in 1..d {
            x[i] = r[i] - rho * u[i];
        }
        let mut next = [0.0; 3];
        project_onto_cone(mu, &x[..d], &mut next[..d]);
        let delta: f64 = (0..d).map(|i| (next[i] - r[i]).abs()).sum();
        let size: f64 = (0..d).map(|i| next[i].abs()).sum();
        r = next;
        if delta <= 1e-15 * size {
            break;
        }
    }
    r
}
