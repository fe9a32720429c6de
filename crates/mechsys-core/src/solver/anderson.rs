//! Anderson acceleration of a fixed-point iteration `x ← G(x)` (here: Gauss–Seidel sweeps).
//!
//! With the residuals `f_k = G(x_k) − x_k` of the last `m` iterates, the next iterate is the
//! combination of the `G(x_j)` whose residuals' combination is smallest:
//! `γ = argmin ‖f_k − ΔF γ‖`, `x_{k+1} = G(x_k) − ΔG γ`, with `ΔF`, `ΔG` the differences of
//! consecutive `f` and `G(x)` (Walker and Ni's form of Anderson's 1965 mixing). A companion
//! vector that is linear in `x` (the factored sweeps' `z = Y r`) takes the same combination, so
//! it needs no recomputation. The history restarts whenever a residual grows (the safeguard:
//! the nonsmooth map is only piecewise smooth, and across a kink the old differences mislead).
//! When the residual stalls the acceleration pauses: plain sweeps for a while, then a fresh
//! history (a stall is a phase of a solve, e.g. the stick/slip states still settling, not a
//! verdict on the rest of it).
//!
//! The sweep itself writes the weighted residual `f` ([`Anderson::set_residual`]: it has each
//! unknown's change in hand) and its squared norm is the sweep's change, so no pass over the
//! iterate before the sweep is needed. The right-hand side `ΔFᵀ f_k` is updated rather than
//! recomputed: for a held column `b`, `Δf_bᵀ f_k = Δf_bᵀ f_{k−1} + Δf_bᵀ Δf_new`, and the second
//! term is the new Gram row; only the new column takes a product with `f_k`.

/// History and scratch of the acceleration (preallocated by [`Anderson::reserve`]).
#[derive(Debug, Clone, Default)]
pub(crate) struct Anderson {
    depth: usize,
    n: usize,
    nz: usize,
    /// Columns held (≤ depth) and the ring position of the next one.
    cols: usize,
    head: usize,
    f_prev: Vec<f64>,
    g_prev: Vec<f64>,
    z_prev: Vec<f64>,
    f: Vec<f64>,
    has_prev: bool,
    last_norm: f64,
    df: Vec<f64>,
    dg: Vec<f64>,
    dz: Vec<f64>,
    /// `ΔFᵀ ΔF` of the held columns (ring positions).
    gram: [[f64; MAX_DEPTH]; MAX_DEPTH],
    /// `ΔFᵀ f` of the held columns against the latest residual.
    rhs: [f64; MAX_DEPTH],
    /// The smallest change so far and the sweeps since; off once it stalls, for `plain` sweeps.
    best: f64,
    since_best: usize,
    off: bool,
    plain: usize,
}

/// The acceleration pauses when the smallest change of a sweep has not fallen for this many
/// sweeps (on a settling pile one solve thrashed for 10 000 sweeps, four in five restarting, at
/// a change that stayed put; plain sweeps took 1300).
pub(crate) const STALL: usize = 128;

/// Plain sweeps after a stall before the acceleration starts again with a fresh history. Off
/// for the rest of a solve instead, the late steps of the 1000-sphere pour ran mostly plain. One
/// step from each of 20 saved states of the pour (t = 0.60, 0.62, …, 0.98 s) and two more from
/// there, at `Auto(tol=1e-4)`: 137 k sweeps in the 40 warm steps (4 unconverged) never back on,
/// 122 k after 1024 plain sweeps, 121 k after 256, 100 k after 64, 90 k after 32 (1), 96 k after 8.
/// Whole pours (three starts, 1 s): 3.45 M sweeps and 85 steps at the budget before, 2.18 M and
/// 44 now.
pub(crate) const RETRY: usize = 32;

/// Most columns kept (the solvers' `anderson` option is at most this).
pub(crate) const MAX_DEPTH: usize = 8;

impl Anderson {
    /// Storage for up to `n` unknowns and a companion of `nz` entries with [`MAX_DEPTH`]
    /// columns; never shrinks (a solve then allocates nothing).
    pub(crate) fn reserve(&mut self, n: usize, nz: usize) {
        for (v, len) in [
            (&mut self.f_prev, n),
            (&mut self.g_prev, n),
            (&mut self.f, n),
            (&mut self.z_prev, nz),
            (&mut self.df, n * MAX_DEPTH),
            (&mut self.dg, n * MAX_DEPTH),
            (&mut self.dz, nz * MAX_DEPTH),
        ] {
            if v.len() < len {
                v.resize(len, 0.0);
            }
        }
    }

    /// Starts a solve of `n` unknowns with a companion of `nz` entries, keeping `depth` columns
    /// (1..=[`MAX_DEPTH`]); [`Anderson::reserve`] must have made room.
    pub(crate) fn begin(&mut self, n: usize, nz: usize, depth: usize) {
        debug_assert!(self.f.len() >= n && self.z_prev.len() >= nz && (1..=MAX_DEPTH).contains(&depth));
        (self.n, self.nz, self.depth) = (n, nz, depth);
        self.fresh();
    }

    /// On, with no history and no best change yet (a solve's start, and the end of a pause).
    fn fresh(&mut self) {
        (self.best, self.since_best, self.off, self.plain) = (f64::INFINITY, 0, false, 0);
        self.restart();
    }

    /// During a sweep: unknown `i`'s weighted change `w_i (G(x)_i − x_i)`; every unknown's
    /// must be set before [`Anderson::step`].
    #[inline(always)]
    pub(crate) fn set_residual(&mut self, i: usize, f: f64) {
        self.f[i] = f;
    }

    /// The residual terms of the current sweep (what [`Anderson::set_residual`] writes), to be
    /// filled in place.
    pub(crate) fn residuals(&mut self) -> &mut [f64] {
        &mut self.f[..self.n]
    }

    /// Forgets the history.
    pub(crate) fn restart(&mut self) {
        self.cols = 0;
        self.head = 0;
        self.has_prev = false;
        self.last_norm = f64::INFINITY;
    }

    /// After a sweep to `g` with companion `z` whose weighted residual was set by
    /// [`Anderson::set_residual`] with squared norm `norm`: records the step and replaces `g` and
    /// `z` by the accelerated iterate. Returns whether it extrapolated.
    pub(crate) fn step(&mut self, g: &mut [f64], z: &mut [f64], norm: f64) -> bool {
        if self.off {
            self.plain += 1;
            if self.plain >= RETRY {
                // (the history and the best change were the stalled phase's)
                self.fresh();
            }
            return false;
        }
        let (n, nz) = (self.n, self.nz);
        if norm < self.best {
            (self.best, self.since_best) = (norm, 0);
        } else {
            self.since_best += 1;
            if self.since_best >= STALL {
                // stalled: plain sweeps for a while (RETRY)
                self.off = true;
                return false;
            }
        }
        if norm > self.last_norm {
            // the residual grew: the differences mislead (a kink was crossed); start again here
            self.restart();
        }
        self.last_norm = norm;
        if self.has_prev {
            let c = self.head;
            // (zipped slices: no bounds checks, so the loops vectorize)
            difference(&mut self.df[c * n..(c + 1) * n], &self.f[..n], &self.f_prev[..n]);
            difference(&mut self.dg[c * n..(c + 1) * n], &g[..n], &self.g_prev[..n]);
            difference(&mut self.dz[c * nz..(c + 1) * nz], &z[..nz], &self.z_prev[..nz]);
            self.cols = (self.cols + 1).min(self.depth);
            // the new column's products with the others (and itself); the others' right-hand
            // sides move from f_{k−1} to f_k = f_{k−1} + Δf_c
            let dc = &self.df[c * n..(c + 1) * n];
            for b in 0..self.cols {
                let v = dot(dc, &self.df[b * n..(b + 1) * n]);
                self.gram[c][b] = v;
                self.gram[b][c] = v;
                if b != c {
                    self.rhs[b] += v;
                }
            }
            self.rhs[c] = dot(dc, &self.f[..n]);
            self.head = (self.head + 1) % self.depth;
        }
        // (f is rewritten in full by the next sweep: a swap instead of a copy)
        std::mem::swap(&mut self.f_prev, &mut self.f);
        self.g_prev[..n].copy_from_slice(&g[..n]);
        self.z_prev[..nz].copy_from_slice(&z[..nz]);
        self.has_prev = true;
        let k = self.cols;
        if k == 0 {
            return false;
        }
        // normal equations of min ‖f − ΔF γ‖ (k ≤ 8), slightly regularized
        let mut gram = self.gram;
        let mut rhs = self.rhs;
        let trace: f64 = (0..k).map(|a| gram[a][a]).sum();
        if !(trace > 0.0 && trace.is_finite()) {
            self.restart();
            return false;
        }
        for (a, row) in gram.iter_mut().enumerate().take(k) {
            row[a] += 1e-10 * trace;
        }
        let Some(gamma) = solve_spd(&mut gram, &mut rhs, k) else {
            self.restart();
            return false;
        };
        combine(&mut g[..n], &self.dg, n, &gamma[..k]);
        combine(&mut z[..nz], &self.dz, nz, &gamma[..k]);
        true
    }
}

/// `out = a − b`.
#[inline]
fn difference(out: &mut [f64], a: &[f64], b: &[f64]) {
    for ((o, x), y) in out.iter_mut().zip(a).zip(b) {
        *o = x - y;
    }
}

/// `x −= Σ_a γ_a col_a` over the columns of length `n` in `cols`, two columns per pass (half
/// the passes over `x`; the sum per entry in the same order as one column at a time).
#[inline]
fn combine(x: &mut [f64], cols: &[f64], n: usize, gamma: &[f64]) {
    let mut a = 0;
    while a + 1 < gamma.len() {
        let (g0, g1) = (gamma[a], gamma[a + 1]);
        let (c0, c1) = (&cols[a * n..(a + 1) * n], &cols[(a + 1) * n..(a + 2) * n]);
        for ((xi, d0), d1) in x.iter_mut().zip(c0).zip(c1) {
            *xi = (*xi - g0 * d0) - g1 * d1;
        }
        a += 2;
    }
    if a < gamma.len() {
        let (g0, c0) = (gamma[a], &cols[a * n..(a + 1) * n]);
        for (xi, d0) in x.iter_mut().zip(c0) {
            *xi -= g0 * d0;
        }
    }
}

/// Cholesky solve of the `k × k` SPD system in place; `None` if not positive.
fn solve_spd(a: &mut [[f64; MAX_DEPTH]; MAX_DEPTH], b: &mut [f64; MAX_DEPTH], k: usize) -> Option<[f64; MAX_DEPTH]> {
    for j in 0..k {
        let mut d = a[j][j];
        for p in 0..j {
            d -= a[j][p] * a[j][p];
        }
        if !(d > 0.0) {
            return None;
        }
        let d = d.sqrt();
        a[j][j] = d;
        for i in j + 1..k {
            let mut s = a[i][j];
            for p in 0..j {
                s -= a[i][p] * a[j][p];
            }
            a[i][j] = s / d;
        }
    }
    let mut y = *b;
    for i in 0..k {
        for p in 0..i {
            y[i] -= a[i][p] * y[p];
        }
        y[i] /= a[i][i];
    }
    for i in (0..k).rev() {
        for p in i + 1..k {
            y[i] -= a[p][i] * y[p];
        }
        y[i] /= a[i][i];
    }
    Some(y)
}

/// `aᵀ b` with four partial sums (independent chains the compiler can keep in vector registers).
#[inline]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for l in 0..4 {
            acc[l] += x[l] * y[l];
        }
    }
    let mut s = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for (x, y) in ra.iter().zip(rb) {
        s += x * y;
    }
    s
}
