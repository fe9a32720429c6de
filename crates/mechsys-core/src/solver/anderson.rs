//! Anderson acceleration of a fixed-point iteration `x ← G(x)` (here: Gauss–Seidel sweeps).
//!
//! With the residuals `f_k = G(x_k) − x_k` of the last `m` iterates, the next iterate is the
//! combination of the `G(x_j)` whose residuals' combination is smallest:
//! `γ = argmin ‖f_k − ΔF γ‖`, `x_{k+1} = G(x_k) − ΔG γ`, with `ΔF`, `ΔG` the differences of
//! consecutive `f` and `G(x)` (Walker and Ni's form of Anderson's 1965 mixing). A companion
//! vector that is linear in `x` (the factored sweeps' `z = Y r`) takes the same combination, so
//! it needs no recomputation. The history restarts whenever a residual grows (the safeguard:
//! the nonsmooth map is only piecewise smooth, and across a kink the old differences mislead),
//! and the acceleration stops for the rest of a solve when the residual stalls.

/// History and scratch of the acceleration (preallocated by [`Anderson::reserve`]).
#[derive(Debug, Clone, Default)]
pub(crate) struct Anderson {
    depth: usize,
    n: usize,
    nz: usize,
    /// Columns held (≤ depth) and the ring position of the next one.
    cols: usize,
    head: usize,
    /// The iterate before the sweep.
    x: Vec<f64>,
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
    /// The smallest change so far and the sweeps since; off once it stalls.
    best: f64,
    since_best: usize,
    off: bool,
}

/// The acceleration stops for the rest of a solve when the smallest change of a sweep has not
/// fallen for this many sweeps (on a settling pile one solve thrashed for 10 000 sweeps, four
/// in five restarting, at a change that stayed put; plain sweeps took 1300).
const STALL: usize = 128;

/// Most columns kept (the solvers' `anderson` option is at most this).
pub(crate) const MAX_DEPTH: usize = 8;

impl Anderson {
    /// Storage for up to `n` unknowns and a companion of `nz` entries with [`MAX_DEPTH`]
    /// columns; never shrinks (a solve then allocates nothing).
    pub(crate) fn reserve(&mut self, n: usize, nz: usize) {
        for (v, len) in [
            (&mut self.x, n),
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
        debug_assert!(self.x.len() >= n && self.z_prev.len() >= nz && (1..=MAX_DEPTH).contains(&depth));
        (self.n, self.nz, self.depth) = (n, nz, depth);
        (self.best, self.since_best, self.off) = (f64::INFINITY, 0, false);
        self.restart();
    }

    /// Before a sweep: remembers its starting iterate `r`.
    #[inline]
    pub(crate) fn before_sweep(&mut self, r: &[f64]) {
        self.x[..self.n].copy_from_slice(&r[..self.n]);
    }

    /// Forgets the history.
    pub(crate) fn restart(&mut self) {
        self.cols = 0;
        self.head = 0;
        self.has_prev = false;
        self.last_norm = f64::INFINITY;
    }

    /// After a sweep from the iterate of [`Anderson::before_sweep`] to `g` with companion `z`: records the step
    /// (residual weighted by `weight(i)` per unknown) and replaces `g` and `z` by the
    /// accelerated iterate. Returns whether it extrapolated.
    pub(crate) fn step(&mut self, g: &mut [f64], z: &mut [f64], weight: impl Fn(usize) -> f64) -> bool {
        if self.off {
            return false;
        }
        let (n, nz) = (self.n, self.nz);
        let mut norm = 0.0;
        for i in 0..n {
            let f = (g[i] - self.x[i]) * weight(i);
            self.f[i] = f;
            norm += f * f;
        }
        if norm < self.best {
            (self.best, self.since_best) = (norm, 0);
        } else {
            self.since_best += 1;
            if self.since_best >= STALL {
                // stalled: plain sweeps for the rest of the solve
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
            for i in 0..n {
                self.df[c * n + i] = self.f[i] - self.f_prev[i];
                self.dg[c * n + i] = g[i] - self.g_prev[i];
            }
            for i in 0..nz {
                self.dz[c * nz + i] = z[i] - self.z_prev[i];
            }
            self.cols = (self.cols + 1).min(self.depth);
            // the new column's products with the others (and itself)
            let dc = &self.df[c * n..(c + 1) * n];
            for b in 0..self.cols {
                let v = dot(dc, &self.df[b * n..(b + 1) * n]);
                self.gram[c][b] = v;
                self.gram[b][c] = v;
            }
            self.head = (self.head + 1) % self.depth;
        }
        // (f is recomputed in full at the next step: a swap instead of a copy)
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
        let mut rhs = [0.0; MAX_DEPTH];
        for (a, ra) in rhs.iter_mut().enumerate().take(k) {
            *ra = dot(&self.df[a * n..(a + 1) * n], &self.f_prev[..n]);
        }
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
        for (a, ga) in gamma.iter().enumerate().take(k) {
            let dg = &self.dg[a * n..(a + 1) * n];
            for (x, d) in g[..n].iter_mut().zip(dg) {
                *x -= ga * d;
            }
            let dz = &self.dz[a * nz..(a + 1) * nz];
            for (x, d) in z[..nz].iter_mut().zip(dz) {
                *x -= ga * d;
            }
        }
        true
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
