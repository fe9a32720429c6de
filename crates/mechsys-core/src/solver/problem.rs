//! Problem data (LCP, friction contact, Delassus storage), the Coulomb-cone projection and the
//! residuals every solver reports.

use serde::{Deserialize, Serialize};

use crate::ensure;
use crate::error::{Error, Result};

/// Linear complementarity problem: find `z ≥ 0` with `w = M z + q ≥ 0`, `zᵀw = 0`.
///
/// `m` is the dense `n × n` matrix in row-major order (`M_ij = m[i n + j]`), `n = q.len()`. The
/// fields are public so that a time-stepping scheme can refill one problem in place; they are
/// checked at every [`super::solve`].
#[derive(Debug, Clone, PartialEq)]
pub struct Lcp {
    /// `M`, row-major `n × n`.
    pub m: Vec<f64>,
    /// `q`, length `n`.
    pub q: Vec<f64>,
}

impl Lcp {
    /// An LCP from row-major `M` and `q`, checked.
    pub fn new(m: Vec<f64>, q: Vec<f64>) -> Result<Self> {
        let p = Self { m, q };
        p.check()?;
        Ok(p)
    }

    /// Size `n`.
    pub fn size(&self) -> usize {
        self.q.len()
    }

    pub(crate) fn check(&self) -> Result<()> {
        let n = self.q.len();
        ensure!(
            self.m.len() == n * n,
            Settings,
            "LCP: M has {} entries, expected {} for n = {n} (row-major n × n)",
            self.m.len(),
            n * n
        );
        if let Some(k) = self.m.iter().position(|v| !v.is_finite()) {
            return Err(Error::Settings(format!("LCP: M[{}, {}] is not finite ({})", k / n, k % n, self.m[k])));
        }
        if let Some(k) = self.q.iter().position(|v| !v.is_finite()) {
            return Err(Error::Settings(format!("LCP: q[{k}] is not finite ({})", self.q[k])));
        }
        Ok(())
    }

    /// `w = M z + q` into `w`.
    pub fn w(&self, z: &[f64], w: &mut [f64]) -> Result<()> {
        let n = self.size();
        ensure!(
            z.len() == n && w.len() == n,
            Settings,
            "LCP: z and w need {n} entries, got {} and {}",
            z.len(),
            w.len()
        );
        lcp_w(&self.m, &self.q, z, w);
        Ok(())
    }

    /// The merit of [`super::Report::residual`] at `z` (allocates; for use outside a solve).
    pub fn residual(&self, z: &[f64]) -> Result<f64> {
        let mut w = vec![0.0; self.size()];
        self.w(z, &mut w)?;
        Ok(lcp_residual(&self.m, &self.q, z, &w))
    }
}

/// `w = M z + q` for row-major `M`.
pub(crate) fn lcp_w(m: &[f64], q: &[f64], z: &[f64], w: &mut [f64]) {
    let n = q.len();
    for i in 0..n {
        w[i] = q[i] + dot(&m[i * n..(i + 1) * n], z);
    }
}

/// `‖min(M_ii z_i, w_i)‖₂ / (1 + ‖q‖₂)`; `M_ii ≤ 0` is replaced by 1 (see `Report::residual`).
pub(crate) fn lcp_residual(m: &[f64], q: &[f64], z: &[f64], w: &[f64]) -> f64 {
    let n = q.len();
    let mut s = 0.0;
    for i in 0..n {
        let mii = m[i * n + i];
        let scale = if mii > 0.0 { mii } else { 1.0 };
        let e = (scale * z[i]).min(w[i]);
        s += e * e;
    }
    s.sqrt() / (1.0 + norm(q))
}

pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

pub(crate) fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// Storage of the Delassus matrix `W` (`d n × d n`).
#[derive(Debug, Clone, PartialEq)]
pub enum Delassus {
    /// Dense, row-major: `W_ab = w[a (d n) + b]`.
    Dense(Vec<f64>),
    /// Per-contact `d × d` blocks, only the nonzero ones (contacts that share a body).
    Blocks(BlockDelassus),
}

/// Block-sparse symmetric `W`: the `n` diagonal blocks and the off-diagonal blocks by block row.
///
/// Built with [`BlockDelassusBuilder`]; both `W_ij` and `W_ji = W_ijᵀ` are stored so that a
/// Gauss–Seidel sweep reads one block row.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockDelassus {
    dim: usize,
    n: usize,
    /// `n` row-major `d × d` blocks.
    diag: Vec<f64>,
    /// Off-diagonal blocks of block row `i` are `row_start[i]..row_start[i + 1]`.
    row_start: Vec<usize>,
    col: Vec<usize>,
    /// Row-major `d × d` per off-diagonal block.
    val: Vec<f64>,
}

/// Collects the blocks of a [`BlockDelassus`]; blocks added twice are summed, so contributions
/// `J_ib M_b⁻¹ J_jbᵀ` of each shared body `b` can be added one by one.
#[derive(Debug, Clone)]
pub struct BlockDelassusBuilder {
    dim: usize,
    n: usize,
    diag: Vec<f64>,
    /// (i, j, offset into `val`) with i < j.
    upper: Vec<(usize, usize, usize)>,
    val: Vec<f64>,
}

impl BlockDelassusBuilder {
    /// An all-zero `W` for `n` contacts of dimension `dim` (2 or 3).
    pub fn new(dim: usize, n: usize) -> Result<Self> {
        ensure!(dim == 2 || dim == 3, Settings, "Delassus blocks: dimension must be 2 or 3, got {dim}");
        Ok(Self { dim, n, diag: vec![0.0; n * dim * dim], upper: Vec::new(), val: Vec::new() })
    }

    /// Adds the row-major `d × d` block `W_ij` (and, for `i ≠ j`, its transpose as `W_ji`).
    pub fn add(&mut self, i: usize, j: usize, block: &[f64]) -> Result<()> {
        let (d, n) = (self.dim, self.n);
        ensure!(i < n && j < n, Settings, "Delassus block ({i}, {j}): contact index out of range (n = {n})");
        ensure!(
            block.len() == d * d,
            Settings,
            "Delassus block ({i}, {j}): expected {} entries, got {}",
            d * d,
            block.len()
        );
        if let Some(k) = block.iter().position(|v| !v.is_finite()) {
            return Err(Error::Settings(format!("Delassus block ({i}, {j}): entry {k} is not finite ({})", block[k])));
        }
        if i == j {
            for (a, b) in self.diag[i * d * d..(i + 1) * d * d].iter_mut().zip(block) {
                *a += b;
            }
            return Ok(());
        }
        // store as the upper block (i < j), transposing if needed
        let (lo, hi, transpose) = if i < j { (i, j, false) } else { (j, i, true) };
        let off = self.val.len();
        self.upper.push((lo, hi, off));
        for a in 0..d {
            for b in 0..d {
                self.val.push(if transpose { block[b * d + a] } else { block[a * d + b] });
            }
        }
        Ok(())
    }

    /// The block-sparse matrix (duplicates summed, blocks ordered by row then column).
    pub fn build(self) -> BlockDelassus {
        let (d, n) = (self.dim, self.n);
        let dd = d * d;
        // every upper block appears in row lo as (lo, hi) and in row hi as (hi, lo)ᵀ
        let mut entries: Vec<(usize, usize, usize, bool)> = Vec::with_capacity(2 * self.upper.len());
        for &(lo, hi, off) in &self.upper {
            entries.push((lo, hi, off, false));
            entries.push((hi, lo, off, true));
        }
        entries.sort_by_key(|e| (e.0, e.1));
        let mut row_start = vec![0usize; n + 1];
        let mut col = Vec::new();
        let mut val: Vec<f64> = Vec::new();
        let mut rows = Vec::new();
        for &(i, j, off, tr) in &entries {
            let merge = rows.last() == Some(&i) && col.last() == Some(&j);
            if !merge {
                rows.push(i);
                col.push(j);
                val.extend(std::iter::repeat_n(0.0, dd));
            }
            let base = val.len() - dd;
            for a in 0..d {
                for b in 0..d {
                    val[base + a * d + b] += if tr { self.val[off + b * d + a] } else { self.val[off + a * d + b] };
                }
            }
        }
        for &i in &rows {
            row_start[i + 1] += 1;
        }
        for i in 0..n {
            row_start[i + 1] += row_start[i];
        }
        BlockDelassus { dim: d, n, diag: self.diag, row_start, col, val }
    }
}

/// Resizes `v` to `n` entries, filling with `x` only where it grows.
fn set_len<T: Copy>(v: &mut Vec<T>, n: usize, x: T) {
    if v.len() > n {
        v.truncate(n);
    } else {
        v.resize(n, x);
    }
}

impl Default for BlockDelassus {
    fn default() -> Self {
        BlockDelassus { dim: 3, n: 0, diag: Vec::new(), row_start: vec![0], col: Vec::new(), val: Vec::new() }
    }
}

impl BlockDelassus {
    /// Refills the matrix in place for `n` contacts of dimension `dim` from the row-major
    /// diagonal blocks `diag` (`n d²` entries) and the blocks `W_ij`, `i < j`, listed in `upper`
    /// with their row-major values in `upper_val` (`d²` each, at most one entry per pair); `W_ji`
    /// is stored as the transpose. Reuses the storage: no allocation once the capacities have
    /// grown to the largest problem seen (a time-stepping scheme refills it every step).
    pub fn refill(&mut self, dim: usize, n: usize, diag: &[f64], upper: &[(usize, usize)], upper_val: &[f64]) {
        let dd = dim * dim;
        debug_assert!(diag.len() >= n * dd && upper_val.len() >= upper.len() * dd);
        self.dim = dim;
        self.n = n;
        self.diag.clear();
        self.diag.extend_from_slice(&diag[..n * dd]);
        // counting sort of both triangles by block row
        self.row_start.clear();
        self.row_start.resize(n + 2, 0);
        for &(i, j) in upper {
            debug_assert!(i < j && j < n);
            self.row_start[i + 2] += 1;
            self.row_start[j + 2] += 1;
        }
        for i in 0..n {
            self.row_start[i + 2] += self.row_start[i + 1];
        }
        let m = 2 * upper.len();
        // every slot is written below: sized without zeroing what is already there
        set_len(&mut self.col, m, 0);
        set_len(&mut self.val, m * dd, 0.0);
        // row_start[i + 1] is the next free slot of row i while filling; afterwards the start of row i + 1
        for (k, &(i, j)) in upper.iter().enumerate() {
            let b = &upper_val[k * dd..(k + 1) * dd];
            let s = self.row_start[i + 1];
            self.row_start[i + 1] += 1;
            self.col[s] = j;
            let t = self.row_start[j + 1];
            self.row_start[j + 1] += 1;
            self.col[t] = i;
            if let Ok(b) = <&[f64; 9]>::try_from(b) {
                // fixed-size copies (a slice copy of d² values is a library call)
                let v: &mut [f64; 9] = (&mut self.val[s * 9..s * 9 + 9]).try_into().unwrap();
                *v = *b;
                let v: &mut [f64; 9] = (&mut self.val[t * 9..t * 9 + 9]).try_into().unwrap();
                *v = [b[0], b[3], b[6], b[1], b[4], b[7], b[2], b[5], b[8]];
            } else {
                self.val[s * dd..(s + 1) * dd].copy_from_slice(b);
                let s = t;
                for a in 0..dim {
                    for c in 0..dim {
                        self.val[s * dd + a * dim + c] = b[c * dim + a];
                    }
                }
            }
        }
        self.row_start.truncate(n + 1);
    }

    /// Contact dimension `d`.
    pub fn dim(&self) -> usize {
        self.dim
    }
    /// Number of contacts `n`.
    pub fn contacts(&self) -> usize {
        self.n
    }
    /// Number of stored off-diagonal blocks (both triangles).
    pub fn off_diagonal_blocks(&self) -> usize {
        self.col.len()
    }
    /// The dense row-major `d n × d n` matrix (allocates; for checks and small problems).
    pub fn to_dense(&self) -> Vec<f64> {
        let m = self.dim * self.n;
        let mut out = vec![0.0; m * m];
        self.fill_dense(&mut out);
        out
    }

    pub(crate) fn fill_dense(&self, out: &mut [f64]) {
        let (d, n) = (self.dim, self.n);
        let m = d * n;
        out[..m * m].fill(0.0);
        for i in 0..n {
            for a in 0..d {
                for b in 0..d {
                    out[(i * d + a) * m + i * d + b] = self.diag[i * d * d + a * d + b];
                }
            }
            for k in self.row_start[i]..self.row_start[i + 1] {
                let j = self.col[k];
                for a in 0..d {
                    for b in 0..d {
                        out[(i * d + a) * m + j * d + b] = self.val[k * d * d + a * d + b];
                    }
                }
            }
        }
    }

    /// Off-diagonal blocks of block row `i` as (column contact, row-major block).
    pub(crate) fn row_blocks(&self, i: usize) -> impl Iterator<Item = (usize, &[f64])> {
        let dd = self.dim * self.dim;
        (self.row_start[i]..self.row_start[i + 1]).map(move |k| (self.col[k], &self.val[k * dd..(k + 1) * dd]))
    }

    pub(crate) fn diag_block(&self, i: usize) -> &[f64] {
        let dd = self.dim * self.dim;
        &self.diag[i * dd..(i + 1) * dd]
    }
}

impl Delassus {
    /// `u += W r` restricted to the rows of contact `i`, without the diagonal block if
    /// `skip_diagonal` (the Gauss–Seidel coupling term).
    #[inline]
    pub(crate) fn add_row_product(&self, d: usize, i: usize, r: &[f64], skip_diagonal: bool, u: &mut [f64; 3]) {
        match self {
            Delassus::Dense(w) => {
                let m = r.len();
                for a in 0..d {
                    let row = &w[(i * d + a) * m..(i * d + a + 1) * m];
                    let mut s = dot(row, r);
                    if skip_diagonal {
                        for b in 0..d {
                            s -= row[i * d + b] * r[i * d + b];
                        }
                    }
                    u[a] += s;
                }
            }
            Delassus::Blocks(bw) if d == 3 => {
                // the common spatial case with fixed-size blocks (the inner loops unrolled)
                let (mut u0, mut u1, mut u2) = (0.0, 0.0, 0.0);
                let mut add = |blk: &[f64], x: &[f64]| {
                    let (blk, x): (&[f64; 9], &[f64; 3]) = (blk.try_into().unwrap(), x.try_into().unwrap());
                    u0 += blk[0] * x[0] + blk[1] * x[1] + blk[2] * x[2];
                    u1 += blk[3] * x[0] + blk[4] * x[1] + blk[5] * x[2];
                    u2 += blk[6] * x[0] + blk[7] * x[1] + blk[8] * x[2];
                };
                if !skip_diagonal {
                    add(bw.diag_block(i), &r[3 * i..3 * i + 3]);
                }
                for k in bw.row_start[i]..bw.row_start[i + 1] {
                    let j = bw.col[k];
                    add(&bw.val[9 * k..9 * k + 9], &r[3 * j..3 * j + 3]);
                }
                u[0] += u0;
                u[1] += u1;
                u[2] += u2;
            }
            Delassus::Blocks(bw) => {
                if !skip_diagonal {
                    let blk = bw.diag_block(i);
                    for a in 0..d {
                        u[a] += dot(&blk[a * d..(a + 1) * d], &r[i * d..(i + 1) * d]);
                    }
                }
                for (j, blk) in bw.row_blocks(i) {
                    for a in 0..d {
                        u[a] += dot(&blk[a * d..(a + 1) * d], &r[j * d..(j + 1) * d]);
                    }
                }
            }
        }
    }

    /// `u = W r + q`.
    pub(crate) fn velocity(&self, d: usize, r: &[f64], q: &[f64], u: &mut [f64]) {
        let n = q.len() / d;
        for i in 0..n {
            let mut ui = [0.0; 3];
            self.add_row_product(d, i, r, false, &mut ui);
            for a in 0..d {
                u[i * d + a] = ui[a] + q[i * d + a];
            }
        }
    }

    /// The diagonal block of contact `i`, row-major `d × d` in the first `d²` entries.
    #[inline]
    pub(crate) fn diag_block(&self, d: usize, i: usize, out: &mut [f64; 9]) {
        match self {
            Delassus::Dense(w) => {
                let m = w.len().isqrt();
                for a in 0..d {
                    for b in 0..d {
                        out[a * d + b] = w[(i * d + a) * m + i * d + b];
                    }
                }
            }
            Delassus::Blocks(bw) => out[..d * d].copy_from_slice(bw.diag_block(i)),
        }
    }

    /// Dense row-major copy into `out` (`(d n)²` entries).
    pub(crate) fn fill_dense(&self, out: &mut [f64]) {
        match self {
            Delassus::Dense(w) => out[..w.len()].copy_from_slice(w),
            Delassus::Blocks(bw) => bw.fill_dense(out),
        }
    }
}

/// Contact status read from a friction-contact solution.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactState {
    /// `r = 0`, `u_N ≥ 0`: the contact separates or stays open.
    Open,
    /// Closed with `u_T = 0` (inside the cone, or on its boundary without sliding).
    Stick,
    /// Closed and sliding: `|r_T| = μ r_N`, `r_T` opposite to `u_T`.
    Slip,
}

impl ContactState {
    /// `"open"`, `"stick"` or `"slip"`, as recorded in `contact/<name>/state`.
    pub fn as_str(self) -> &'static str {
        match self {
            ContactState::Open => "open",
            ContactState::Stick => "stick",
            ContactState::Slip => "slip",
        }
    }
}

/// Friction-contact problem `u = W r + q` with Signorini–Coulomb conditions per contact (see the
/// module documentation). Unknowns are stacked per contact as `[r_N, r_T1(, r_T2)]`; `u` and `q`
/// likewise.
///
/// The fields are public so that an integrator can refill one problem in place; they are checked
/// at every [`super::solve`]. `W` is assumed symmetric positive semidefinite (a Delassus matrix
/// `J M⁻¹ Jᵀ`); only `W_NN > 0` per contact is enforced.
#[derive(Debug, Clone, PartialEq)]
pub struct FrictionContact {
    /// Contact dimension `d`: 2 (planar) or 3 (spatial).
    pub dim: usize,
    /// Delassus matrix `W` (`d n × d n`).
    pub w: Delassus,
    /// Free local velocity `q` (`d n`).
    pub q: Vec<f64>,
    /// Friction coefficient per contact (`n`, each `≥ 0`).
    pub mu: Vec<f64>,
}

impl FrictionContact {
    /// A friction-contact problem, checked.
    pub fn new(dim: usize, w: Delassus, q: Vec<f64>, mu: Vec<f64>) -> Result<Self> {
        let p = Self { dim, w, q, mu };
        p.check()?;
        Ok(p)
    }

    /// Number of contacts `n`.
    pub fn contacts(&self) -> usize {
        self.mu.len()
    }

    pub(crate) fn check(&self) -> Result<()> {
        let d = self.dim;
        check_local(d, &self.q, &self.mu)?;
        let n = self.mu.len();
        let m = d * n;
        match &self.w {
            Delassus::Dense(w) => {
                ensure!(
                    w.len() == m * m,
                    Settings,
                    "friction contact: W has {} entries, expected ({m})² for {n} contacts",
                    w.len()
                );
                if let Some(k) = w.iter().position(|v| !v.is_finite()) {
                    return Err(Error::Settings(format!(
                        "friction contact: W[{}, {}] is not finite ({})",
                        k / m,
                        k % m,
                        w[k]
                    )));
                }
            }
            Delassus::Blocks(bw) => {
                ensure!(
                    bw.dim == d && bw.n == n,
                    Settings,
                    "friction contact: W has blocks for {} contacts of dimension {}, the problem has {n} of dimension {d}",
                    bw.n,
                    bw.dim
                );
            }
        }
        let mut blk = [0.0; 9];
        for i in 0..n {
            self.w.diag_block(d, i, &mut blk);
            check_wnn(i, blk[0])?;
        }
        Ok(())
    }

    /// Local velocities `u = W r + q` into `u`.
    pub fn velocity(&self, r: &[f64], u: &mut [f64]) -> Result<()> {
        let m = self.q.len();
        ensure!(
            r.len() == m && u.len() == m,
            Settings,
            "friction contact: r and u need {m} entries, got {} and {}",
            r.len(),
            u.len()
        );
        self.w.velocity(self.dim, r, &self.q, u);
        Ok(())
    }

    /// The merit of [`super::Report::residual`] at `r` (allocates; for use outside a solve).
    pub fn residual(&self, r: &[f64]) -> Result<f64> {
        let mut u = vec![0.0; self.q.len()];
        self.velocity(r, &mut u)?;
        Ok(fc_residual(self, r, &u))
    }

    fn local(&self, i: usize, r: &[f64]) -> Result<([f64; 3], [f64; 3])> {
        let (d, n) = (self.dim, self.contacts());
        ensure!(i < n, Settings, "friction contact: contact {i} does not exist ({n} contacts)");
        ensure!(r.len() == d * n, Settings, "friction contact: r has {} entries, expected {}", r.len(), d * n);
        Ok(self.local_unchecked(i, r))
    }

    /// [`FrictionContact::local`] without the checks of `i` and `r`'s length.
    #[inline]
    fn local_unchecked(&self, i: usize, r: &[f64]) -> ([f64; 3], [f64; 3]) {
        let d = self.dim;
        let mut u = [0.0; 3];
        self.w.add_row_product(d, i, r, false, &mut u);
        let mut ri = [0.0; 3];
        for a in 0..d {
            u[a] += self.q[i * d + a];
            ri[a] = r[i * d + a];
        }
        (ri, u)
    }

    /// The local velocity `(W r + q)_i` of contact `i` (normal, then tangents).
    pub fn local_velocity(&self, i: usize, r: &[f64]) -> Result<[f64; 3]> {
        Ok(self.local(i, r)?.1)
    }

    /// The friction reserve `μ r_N − |r_T|` of contact `i` (section 2.5.2, fig. 2.30): positive
    /// inside the cone, zero on it.
    pub fn friction_reserve(&self, i: usize, r: &[f64]) -> Result<f64> {
        let (ri, _) = self.local(i, r)?;
        Ok(self.mu[i] * ri[0] - (ri[1] * ri[1] + ri[2] * ri[2]).sqrt())
    }

    /// [`FrictionContact::contact_state`] with the scales `1 + ‖r‖∞` and `1 + ‖q‖∞` computed
    /// by the caller once for all contacts (the plain call costs O(n) per contact).
    pub fn contact_state_scaled(
        &self,
        i: usize,
        r: &[f64],
        tol: f64,
        r_scale: f64,
        q_scale: f64,
    ) -> Result<ContactState> {
        let (ri, u) = self.local(i, r)?;
        Ok(classify(&ri, &u, tol, r_scale, q_scale))
    }

    /// [`FrictionContact::contact_state_scaled`] without the checks of `i` and `r` (a stepper's
    /// loop over the contacts of the problem it has just solved).
    pub(crate) fn contact_state_unchecked(
        &self,
        i: usize,
        r: &[f64],
        tol: f64,
        r_scale: f64,
        q_scale: f64,
    ) -> ContactState {
        let (ri, u) = self.local_unchecked(i, r);
        classify(&ri, &u, tol, r_scale, q_scale)
    }

    /// Open, stick or slip for contact `i` of the solution `r`.
    ///
    /// With `tol` relative: open if `r_N ≤ tol (1 + ‖r‖∞)`; otherwise slip if
    /// `|u_T| > tol (1 + ‖q‖∞)`, else stick.
    pub fn contact_state(&self, i: usize, r: &[f64], tol: f64) -> Result<ContactState> {
        ensure!(tol >= 0.0, Settings, "friction contact: state tolerance must be ≥ 0, got {tol}");
        let (ri, u) = self.local(i, r)?;
        let r_scale = 1.0 + r.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let q_scale = 1.0 + self.q.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        Ok(classify(&ri, &u, tol, r_scale, q_scale))
    }
}

/// The checks of a friction-contact problem that do not read `W`: dimension, sizes, finite
/// `q`, finite `μ ≥ 0`.
pub(crate) fn check_local(d: usize, q: &[f64], mu: &[f64]) -> Result<()> {
    ensure!(d == 2 || d == 3, Settings, "friction contact: dimension must be 2 or 3, got {d}");
    let m = d * mu.len();
    ensure!(q.len() == m, Settings, "friction contact: q has {} entries, expected d·n = {m}", q.len());
    if let Some(k) = q.iter().position(|v| !v.is_finite()) {
        return Err(Error::Settings(format!("friction contact: q[{k}] (contact {}) is not finite ({})", k / d, q[k])));
    }
    if let Some(i) = mu.iter().position(|v| !(*v >= 0.0 && v.is_finite())) {
        return Err(Error::Settings(format!("friction contact: contact {i}: μ must be finite and ≥ 0, got {}", mu[i])));
    }
    Ok(())
}

/// Contact `i`'s `W_NN` must be positive (and finite).
pub(crate) fn check_wnn(i: usize, wnn: f64) -> Result<()> {
    ensure!(wnn.is_finite(), Settings, "friction contact: contact {i}: W_NN is not finite ({wnn})");
    ensure!(
        wnn > 0.0,
        Settings,
        "friction contact: contact {i}: W_NN = {wnn} must be > 0 (the contact cannot move along its normal)"
    );
    Ok(())
}

/// Open if `r_N ≤ tol r_scale`, else slip if `|u_T| > tol q_scale`, else stick.
#[inline]
pub(crate) fn classify(ri: &[f64; 3], u: &[f64; 3], tol: f64, r_scale: f64, q_scale: f64) -> ContactState {
    if ri[0] <= tol * r_scale {
        ContactState::Open
    } else if (u[1] * u[1] + u[2] * u[2]).sqrt() > tol * q_scale {
        ContactState::Slip
    } else {
        ContactState::Stick
    }
}

/// Projection of `x = [x_N, x_T]` (length 2 or 3) onto the Coulomb cone `{|x_T| ≤ μ x_N}`.
pub fn project_onto_cone(mu: f64, x: &[f64], out: &mut [f64]) {
    let d = x.len();
    let xn = x[0];
    let t = if d == 3 { (x[1] * x[1] + x[2] * x[2]).sqrt() } else { x[1].abs() };
    if mu * t <= -xn {
        // in the polar cone −K*
        out[..d].fill(0.0);
    } else if t <= mu * xn {
        out[..d].copy_from_slice(x);
    } else {
        // nearest point on the boundary ray through x_T/|x_T|
        let pn = (xn + mu * t) / (1.0 + mu * mu);
        out[0] = pn;
        let s = mu * pn / t;
        for a in 1..d {
            out[a] = s * x[a];
        }
    }
}

/// Squared natural-map residual of one contact in velocity units (see `Report::residual`).
#[inline]
pub(crate) fn contact_residual_sq(d: usize, mu: f64, wnn: f64, r: &[f64], u: &[f64]) -> f64 {
    let rho = 1.0 / wnn;
    let ut = if d == 3 { (u[1] * u[1] + u[2] * u[2]).sqrt() } else { u[1].abs() };
    let mut x = [0.0; 3];
    x[0] = r[0] - rho * (u[0] + mu * ut);
    for a in 1..d {
        x[a] = r[a] - rho * u[a];
    }
    let mut p = [0.0; 3];
    project_onto_cone(mu, &x[..d], &mut p[..d]);
    let mut s = 0.0;
    for a in 0..d {
        let e = (r[a] - p[a]) * wnn;
        s += e * e;
    }
    s
}

/// `‖(r − proj_K(r − ρ û))/ρ‖₂ / (1 + ‖q‖₂)` given `u = W r + q`.
pub(crate) fn fc_residual(p: &FrictionContact, r: &[f64], u: &[f64]) -> f64 {
    let d = p.dim;
    let mut blk = [0.0; 9];
    let mut s = 0.0;
    for i in 0..p.contacts() {
        p.w.diag_block(d, i, &mut blk);
        s += contact_residual_sq(d, p.mu[i], blk[0], &r[i * d..(i + 1) * d], &u[i * d..(i + 1) * d]);
    }
    s.sqrt() / (1.0 + norm(&p.q))
}
