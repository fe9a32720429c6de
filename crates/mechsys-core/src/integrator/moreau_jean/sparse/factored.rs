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

use super::domains::{SPLIT_MIN_CONTACTS, SPLIT_MIN_SWEEPS};
use super::SparseRows;

/// One contact's reduced rows on one or two free bodies, transposed for contiguous products:
/// direction `c`'s six entries on body `k` at `y[k][c]`, body `k`'s velocities from `iu[k]`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Packed {
    iu: [usize; 2],
    bodies: usize,
    y: [[[f64; 6]; 3]; 2],
}
use crate::solver::nsgs::{local_solve, CheckSchedule, LocalBlock3, StallWatch};
use crate::solver::{contact_residual_sq, project_onto_cone, NsgsOptions, Report};

/// Sweeps after which a convergence check recomputes `z = Y r` instead of trusting the updated one.
const FRESH_Z_AFTER: usize = 4;

/// Sweeps of a two-domain solve made on the calling thread before the halves go to two threads:
/// handing half a sweep to another thread costs about as much as sweeping it while that thread is
/// asleep (it wakes once per solve), so only a solve that has proved long repays it. (On the
/// pour of 100 spheres, most solves take 1 to 60 sweeps of about 200 contacts, and threads from
/// the first sweep made the whole run 20 % slower than one thread; in the late steps of the
/// 1000-sphere pour, thousands of sweeps of 2000 contacts, they make it 1.5 times faster.)
const SERIAL_SWEEPS: usize = 16;

/// The problem, options and outputs a two-domain solve's sweeps work on: `q`, `mu`, the impulses,
/// the options, the velocities and the residual's scale `1 + ‖q‖`.
type SplitProblem<'a> = (&'a [f64], &'a [f64], &'a mut [f64], &'a NsgsOptions, &'a mut [f64], f64);

/// Where a two-domain solve stands between its serial and its threaded sweeps.
struct SplitRun {
    it: usize,
    check: CheckSchedule,
    stall: StallWatch,
    /// The relaxation (1 until the sweeps stall).
    omega: f64,
    report: Report,
}

impl SparseRows {
    /// Nonsmooth Gauss–Seidel on the problem `u = W r + q` with friction coefficients `mu`:
    /// up to `opts.max_iter` sweeps in `order` (a permutation of the contacts, else by index),
    /// warm-started from `r`, stopping at the residual `opts.tol` (the measure of
    /// [`crate::solver::Report::residual`]), relaxed by `opts.relaxation` with the safeguard of
    /// [`crate::solver::nsgs`]). After a full-residual check, the last
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
        let (mut omega, mut last_change) = (opts.relaxation, f64::INFINITY);
        let packed = self.pack::<D>();
        // (3-D: each block's Cramer cofactors and isotropy once per solve, not once per sweep)
        self.local3.clear();
        if D == 3 {
            for a in 0..n {
                let blk: &[f64; 9] = self.diag[a * 9..(a + 1) * 9].try_into().expect("3 × 3 block");
                self.local3.push(LocalBlock3::new(blk));
            }
        }
        self.factored_product::<D>(r);
        if D == 3
            && packed
            && omega == 1.0
            && n >= SPLIT_MIN_CONTACTS
            && max_sweeps >= SPLIT_MIN_SWEEPS
            && self.dom.plan(&self.packed, order, self.z.len())
        {
            return self.gauss_seidel_split(q, mu, r, opts, u, qn);
        }
        if opts.anderson > 0 {
            // (room for every contact point since the integrator's construction; beyond that,
            // e.g. points of contact groups, it grows once)
            self.aa.reserve(n * D, self.z.len());
            self.aa.begin(n * D, self.z.len(), opts.anderson);
        }
        let mut stall = StallWatch::new(opts.stall);
        let compliant = !self.reg.is_empty();
        for it in 1..=max_sweeps {
            // Anderson's combination of past sweeps (z = Y r is linear in r: it takes the same)
            let accelerate = opts.anderson > 0 && omega == 1.0;
            let mut change = 0.0;
            for ii in 0..n {
                let a = if ordered { order[ii] } else { ii };
                let mut blk = [0.0; 9];
                blk[..D * D].copy_from_slice(&self.diag[a * D * D..(a + 1) * D * D]);
                // b = Y_aᵀ z − W_aa r_a + q_a: the velocity of the others' impulses and the free motion
                let mut b = if packed { self.packed[a].times::<D>(&self.z) } else { self.rows_times_z::<D>(a) };
                let mut old = [0.0; 3];
                old[..D].copy_from_slice(&r[a * D..(a + 1) * D]);
                for c in 0..D {
                    let mut own = 0.0;
                    for k in 0..D {
                        own += blk[c * D + k] * old[k];
                    }
                    b[c] += q[a * D + c] - own;
                }
                if compliant {
                    // (the block holds W_aa + c/h² e_N e_Nᵀ; z only W r)
                    b[0] += self.reg[a] * old[0];
                }
                let mut new = old;
                if D == 3 {
                    self.local3[a].solve(mu[a], &b, &mut new);
                } else {
                    local_solve(D, &blk, mu[a], &b, &mut new);
                }
                if omega != 1.0 {
                    // over- or under-relaxed as in nsgs::sweep (back onto the cone if extrapolated)
                    let mut v = [0.0; 3];
                    for c in 0..D {
                        v[c] = omega * new[c] + (1.0 - omega) * old[c];
                    }
                    new = v;
                    if omega > 1.0 {
                        project_onto_cone(mu[a], &v[..D], &mut new[..D]);
                    }
                }
                let mut delta = [0.0; 3];
                for c in 0..D {
                    delta[c] = new[c] - old[c];
                    let f = blk[0] * delta[c];
                    change += f * f;
                    if accelerate {
                        self.aa.set_residual(a * D + c, f);
                    }
                }
                if delta.iter().any(|v| *v != 0.0) {
                    if packed {
                        self.packed[a].add_to::<D>(&mut self.z, &delta);
                    } else {
                        self.add_rows_times::<D>(a, &delta[..D]);
                    }
                    r[a * D..(a + 1) * D].copy_from_slice(&new[..D]);
                }
            }
            // the safeguard of nsgs::solve_fc: plain sweeps once the extrapolation overshoots
            if omega > 1.0 && change > last_change {
                omega = 1.0;
            }
            last_change = change;
            if stall.stalled(it, change) {
                omega = StallWatch::damped(omega);
            }
            if check.due(it, change.sqrt() / qn <= tol) || it == max_sweeps {
                // a fresh z once many sweeps' updates could have accumulated round-off into it
                // (after a warm step's one or two sweeps the updated z is as good, and the
                // product would be a third of the step's solve)
                if it > FRESH_Z_AFTER {
                    self.factored_product::<D>(r);
                }
                residual = self.factored_residual::<D>(q, mu, r, u) / qn;
                if residual <= tol {
                    return Report { iterations: it, residual, converged: true };
                }
            }
            if accelerate && it < max_sweeps {
                self.aa.step(r, &mut self.z, change);
            }
        }
        Report { iterations: max_sweeps, residual, converged: false }
    }

    /// [`SparseRows::gauss_seidel`] in two domains ([`super::domains`]) after a successful
    /// [`Domains::plan`](super::domains::Domains::plan): the same stopping test and acceleration
    /// on the problem copied into the split's order (3-D, no relaxation, packed rows). The first
    /// [`SERIAL_SWEEPS`] sweeps run on the calling thread, the rest with the halves on two
    /// threads if `parallel`; the impulses are the same either way, bit for bit.
    fn gauss_seidel_split(
        &mut self,
        q: &[f64],
        mu: &[f64],
        r: &mut [f64],
        opts: &NsgsOptions,
        u: &mut [f64],
        qn: f64,
    ) -> Report {
        let n = self.len();
        self.dom.gather(&self.packed, (&self.local3, &self.reg), q, mu, r, &self.z);
        let nz = self.dom.z.len();
        if opts.anderson > 0 {
            self.aa.reserve(n * 3, nz);
            self.aa.begin(n * 3, nz, opts.anderson);
        }
        let mut run = SplitRun {
            it: 0,
            check: CheckSchedule::new(),
            stall: StallWatch::new(opts.stall),
            omega: 1.0,
            report: Report { iterations: opts.max_iter, residual: f64::INFINITY, converged: false },
        };
        let serial = if self.parallel { SERIAL_SWEEPS.min(opts.max_iter) } else { opts.max_iter };
        self.split_sweeps(&mut run, serial, false, (q, mu, r, opts, u, qn));
        if !run.report.converged && run.it < opts.max_iter {
            if rayon::current_thread_index().is_some() {
                self.split_sweeps(&mut run, opts.max_iter, true, (q, mu, r, opts, u, qn));
            } else {
                // the rest of the solve on one of rayon's threads: a sweep's half then goes to the
                // other one through its queue (from outside the pool, each sweep would wait for a
                // thread to wake up: slower than one thread sweeping alone)
                rayon::scope(|_| self.split_sweeps(&mut run, opts.max_iter, true, (q, mu, r, opts, u, qn)));
            }
        }
        self.dom.scatter(r, &mut self.z);
        self.dom.finish();
        run.report
    }

    /// Sweeps of [`SparseRows::gauss_seidel_split`] after `run.it` up to sweep `until` (or
    /// convergence), the halves on two threads if `threads`.
    fn split_sweeps(
        &mut self,
        run: &mut SplitRun,
        until: usize,
        threads: bool,
        (q, mu, r, opts, u, qn): SplitProblem<'_>,
    ) {
        let (tol, max_sweeps) = (opts.tol, opts.max_iter);
        while run.it < until {
            run.it += 1;
            let it = run.it;
            let accelerate = opts.anderson > 0 && run.omega == 1.0;
            let f = accelerate.then(|| self.aa.residuals());
            let change = self.dom.sweep(f, run.omega, threads);
            if run.stall.stalled(it, change) {
                run.omega = StallWatch::damped(run.omega);
            }
            if run.check.due(it, change.sqrt() / qn <= tol) || it == max_sweeps {
                self.dom.scatter(r, &mut self.z);
                if it > FRESH_Z_AFTER {
                    self.factored_product::<3>(r);
                    self.dom.gather_z(&self.z);
                }
                let residual = self.factored_residual::<3>(q, mu, r, u) / qn;
                run.report.residual = residual;
                if residual <= tol {
                    run.report = Report { iterations: it, residual, converged: true };
                    return;
                }
            }
            if accelerate && it < max_sweeps {
                self.aa.step(&mut self.dom.r, &mut self.dom.z, change);
            }
        }
    }

    /// Room for the Anderson acceleration of problems of up to `unknowns` unknowns.
    pub(in crate::integrator::moreau_jean) fn reserve_acceleration(&mut self, unknowns: usize) {
        self.aa.reserve(unknowns, self.z.len());
    }

    /// Packs the rows into `packed` if every contact is on free bodies and the ground (runs of
    /// six velocities, at most two); returns whether it did.
    pub(super) fn pack<const D: usize>(&mut self) -> bool {
        let n = self.len();
        if !self.all_free() {
            return false;
        }
        self.packed.clear();
        for a in 0..n {
            let mut p = Packed { iu: [0; 2], bodies: 0, y: [[[0.0; 6]; 3]; 2] };
            for (k, &(iu, _, e0)) in self.runs[self.run_ptr[a]..self.run_ptr[a + 1]].iter().enumerate() {
                p.iu[k] = iu;
                for j in 0..6 {
                    for c in 0..D {
                        p.y[k][c][j] = self.y[(e0 + j) * D + c];
                    }
                }
            }
            p.bodies = self.run_ptr[a + 1] - self.run_ptr[a];
            self.packed.push(p);
        }
        true
    }

    /// Whether every contact is on free bodies and the ground (its pattern is one or two runs of
    /// six velocities).
    pub(in crate::integrator::moreau_jean) fn all_free(&self) -> bool {
        (0..self.len()).all(|a| {
            let runs = &self.runs[self.run_ptr[a]..self.run_ptr[a + 1]];
            runs.len() <= 2 && runs.iter().all(|r| r.1 == 6)
        })
    }

    /// `z = Σ_a Y_a r_a`.
    pub(super) fn factored_product<const D: usize>(&mut self, r: &[f64]) {
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
        let v: [f64; D] = v.try_into().expect("D values");
        // run by run: contiguous slices of z and y (a free body's run of 6 fully unrolled)
        for &(iu, len, e0) in &self.runs[self.run_ptr[a]..self.run_ptr[a + 1]] {
            let (z, y) = (&mut self.z[iu..iu + len], &self.y[e0 * D..(e0 + len) * D]);
            if len == 6 {
                let z: &mut [f64; 6] = z.try_into().expect("run of 6");
                add_times::<D, 6>(z, y, &v);
            } else {
                for (zk, yk) in z.iter_mut().zip(y.chunks_exact(D)) {
                    *zk += dot::<D>(yk, &v);
                }
            }
        }
    }

    /// `Y_aᵀ z` (zero beyond the problem's dimension `D`).
    #[inline]
    fn rows_times_z<const D: usize>(&self, a: usize) -> [f64; 3] {
        let mut out = [0.0; 3];
        for &(iu, len, e0) in &self.runs[self.run_ptr[a]..self.run_ptr[a + 1]] {
            let (z, y) = (&self.z[iu..iu + len], &self.y[e0 * D..(e0 + len) * D]);
            if len == 6 {
                let z: &[f64; 6] = z.try_into().expect("run of 6");
                transpose_times::<D, 6>(y, z, &mut out);
            } else {
                for (zk, yk) in z.iter().zip(y.chunks_exact(D)) {
                    for c in 0..D {
                        out[c] += yk[c] * zk;
                    }
                }
            }
        }
        out
    }

    /// `u = Y_aᵀ z + q` for every contact (after [`SparseRows::factored_product`]) and the
    /// unscaled natural-map residual `‖·‖₂` of the solution `r`.
    pub(super) fn factored_residual<const D: usize>(&self, q: &[f64], mu: &[f64], r: &[f64], u: &mut [f64]) -> f64 {
        let mut sum = 0.0;
        for a in 0..self.len() {
            let ua = self.rows_times_z::<D>(a);
            // (a direction without mobility has zero rows and a zero impulse: the diagonal
            // `couplings` gives it adds nothing to its velocity in the block form either)
            for c in 0..D {
                u[a * D + c] = ua[c] + q[a * D + c];
            }
            if let Some(reg) = self.reg.get(a) {
                u[a * D] += reg * r[a * D];
            }
            let wnn = self.diag[a * D * D];
            sum += contact_residual_sq(D, mu[a], wnn, &r[a * D..(a + 1) * D], &u[a * D..(a + 1) * D]);
        }
        sum.sqrt()
    }
}

/// `Σ_c y[c] v[c]` over `D` values.
#[inline(always)]
fn dot<const D: usize>(y: &[f64], v: &[f64; D]) -> f64 {
    let mut x = 0.0;
    for c in 0..D {
        x += y[c] * v[c];
    }
    x
}

/// `z[k] += y_kᵀ v` for the `L` rows `y_k` of `D` values each (fixed sizes: unrolled).
#[inline(always)]
fn add_times<const D: usize, const L: usize>(z: &mut [f64; L], y: &[f64], v: &[f64; D]) {
    for (k, zk) in z.iter_mut().enumerate() {
        *zk += dot::<D>(&y[k * D..(k + 1) * D], v);
    }
}

/// `out[c] += Σ_k y_k[c] z[k]` for the `L` rows `y_k` of `D` values each.
#[inline(always)]
fn transpose_times<const D: usize, const L: usize>(y: &[f64], z: &[f64; L], out: &mut [f64; 3]) {
    for (k, zk) in z.iter().enumerate() {
        for c in 0..D {
            out[c] += y[k * D + c] * zk;
        }
    }
}

impl Packed {
    /// Its bodies (1 or 2).
    #[inline(always)]
    pub(super) fn bodies(&self) -> usize {
        self.bodies
    }
    /// The first velocity of each body.
    #[inline(always)]
    pub(super) fn iu(&self) -> [usize; 2] {
        self.iu
    }
    /// Entry `j` (of six) of direction `c`'s reduced row on body `k`.
    #[inline(always)]
    pub(super) fn y(&self, k: usize, c: usize, j: usize) -> f64 {
        self.y[k][c][j]
    }

    /// The same rows on the bodies whose velocities start at `iu` instead.
    #[inline(always)]
    pub(super) fn moved(&self, iu: [usize; 2]) -> Packed {
        Packed { iu, ..*self }
    }

    /// `Y_aᵀ z` (zero beyond `D`).
    #[inline(always)]
    pub(super) fn times<const D: usize>(&self, z: &[f64]) -> [f64; 3] {
        let mut out = [0.0; 3];
        for k in 0..self.bodies {
            let zs: &[f64; 6] = z[self.iu[k]..self.iu[k] + 6].try_into().expect("six velocities");
            for c in 0..D {
                let y = &self.y[k][c];
                // two independent sums of three (shorter dependency chains)
                out[c] += (y[0] * zs[0] + y[1] * zs[1] + y[2] * zs[2]) + (y[3] * zs[3] + y[4] * zs[4] + y[5] * zs[5]);
            }
        }
        out
    }

    /// `z += Y_a v`.
    #[inline(always)]
    pub(super) fn add_to<const D: usize>(&self, z: &mut [f64], v: &[f64; 3]) {
        for k in 0..self.bodies {
            let zs: &mut [f64; 6] = (&mut z[self.iu[k]..self.iu[k] + 6]).try_into().expect("six velocities");
            for j in 0..6 {
                let mut x = 0.0;
                for c in 0..D {
                    x += self.y[k][c][j] * v[c];
                }
                zs[j] += x;
            }
        }
    }
}
