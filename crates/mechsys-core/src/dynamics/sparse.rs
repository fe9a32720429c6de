//! Sparse solve of the constrained equations of motion `M u̇ = h + τ + Gᵀλ`, `G u̇ = γ`.
//!
//! Two structures make it cheap, both planned once per model:
//! - the mass matrix of a tree has nonzeros only between a velocity and its ancestors, so it
//!   factors without fill as `M = Lᵀ D L` (L unit lower triangular on the same pattern), walking
//!   each velocity's ancestor path from the leaves up;
//! - a constraint row involves only the velocities on the root paths of its bodies (a set closed
//!   under ancestors), so `Y = G L⁻¹` keeps the pattern of `G`, and the Schur complement
//!   `S = G M⁻¹ Gᵀ = Y D⁻¹ Yᵀ` couples two rows only where their paths share a velocity.
//!
//! `S` is positive semidefinite. It is factored as `S = L_S D_S L_Sᵀ` in a minimum-degree order
//! with its fill pattern and every update target computed in advance, so the numeric factorization
//! is a flat loop. A pivot that falls below `tol · max diag S` marks its row dependent: its column
//! is dropped and its multiplier set to zero. For a row of G that is zero (the out-of-plane rows
//! of a planar loop closed by a 3-D joint) that is also the minimum-norm multiplier; a row that is
//! a combination of other nonzero rows is reported ([`Saddle::factor_schur`] returns false) so the
//! caller can take the dense minimum-norm path.

use crate::model::{constraint, Model};

/// Plan and workspace of the sparse constrained solve.
#[derive(Debug, Clone, Default)]
pub struct Saddle {
    nu: usize,
    nc: usize,
    // ---- tree factor of M: velocity k's ancestors are anc_idx[anc_ptr[k]..anc_ptr[k+1]], nearest first
    depth: Vec<usize>,
    anc_ptr: Vec<usize>,
    anc_idx: Vec<usize>,
    /// Off-diagonal M(k, ancestor), then L after [`Saddle::factor_mass`].
    m_off: Vec<f64>,
    /// Diagonal of M, then D.
    m_diag: Vec<f64>,
    /// Velocities starting a dense block of six without ancestors outside it (a free joint on
    /// the ground): each velocity's ancestors are the block's earlier ones, and the factor and
    /// solves run on it with fixed sizes (see [`Saddle::factor_mass`]).
    block6: Vec<bool>,
    // ---- rows of G: velocities row_idx[row_ptr[r]..row_ptr[r+1]], ascending
    row_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Values of G on the row pattern.
    pub(crate) g_val: Vec<f64>,
    /// Values of `Y = G L⁻¹` (or of G for the unweighted product) on the row pattern.
    y_val: Vec<f64>,
    /// Rows reaching velocity i: positions (into the row pattern) `col_pos[col_ptr[i]..col_ptr[i+1]]`.
    col_ptr: Vec<usize>,
    col_pos: Vec<usize>,
    // ---- S in elimination order: column j holds its diagonal first, then rows below, ascending
    /// `perm[new] = old` row.
    perm: Vec<usize>,
    s_ptr: Vec<usize>,
    s_row: Vec<usize>,
    s_val: Vec<f64>,
    /// Targets of the assembly products, in the order velocity i, pairs of its rows (a ≤ b).
    assemble: Vec<u32>,
    /// Targets of the factorization updates, in the order column j, pairs of its entries (a ≤ b).
    update: Vec<u32>,
    /// D_S (0 for dependent rows), elimination order.
    d_s: Vec<f64>,
    /// Diagonal of S before factoring, elimination order.
    s_diag0: Vec<f64>,
    /// Dependent rows (original numbering) at the last factorization.
    pub(crate) dependent: Vec<bool>,
    scratch_u: Vec<f64>,
    scratch_c: Vec<f64>,
}

/// The velocity tree's ancestor lists ([`Model::velocity_parents`]). Returns (parent velocity or
/// `usize::MAX`, depth per velocity, CSR pointers, ancestors nearest first).
pub(crate) fn velocity_ancestors(model: &Model) -> (Vec<usize>, Vec<usize>, Vec<usize>, Vec<usize>) {
    let nu = model.nu;
    let parent = model.velocity_parents();
    let mut depth = vec![0; nu];
    let (mut anc_ptr, mut anc_idx) = (vec![0; nu + 1], Vec::new());
    for k in 0..nu {
        let mut a = parent[k];
        while a != usize::MAX {
            anc_idx.push(a);
            a = parent[a];
        }
        anc_ptr[k + 1] = anc_idx.len();
        depth[k] = anc_ptr[k + 1] - anc_ptr[k];
    }
    (parent, depth, anc_ptr, anc_idx)
}

/// Offsets of the ancestors of the j-th velocity of a block of six among its 15 factor entries
/// (`j (j - 1) / 2`: velocity j has the j before it).
pub(crate) const TRI6: [usize; 6] = [0, 0, 1, 3, 6, 10];

/// Per velocity: whether it starts a block of six in which velocity `k0 + j` has exactly the
/// ancestors `k0 + j - 1, …, k0` (nearest first), as the six velocities of a free joint on the
/// ground have. Blocks do not overlap; what hangs below a block may be anything.
fn dense_blocks6(nu: usize, depth: &[usize], anc_ptr: &[usize], anc_idx: &[usize]) -> Vec<bool> {
    let mut out = vec![false; nu];
    let mut k0 = 0;
    while k0 + 6 <= nu {
        let dense =
            (0..6).all(|j| depth[k0 + j] == j && (0..j).all(|p| anc_idx[anc_ptr[k0 + j] + p] == k0 + j - 1 - p));
        if dense {
            out[k0] = true;
            k0 += 6;
        } else {
            k0 += 1;
        }
    }
    out
}

impl Saddle {
    /// Plans the solve for `model` (structure only; without constraints only the tree factor of M,
    /// which the time-stepping schemes use).
    pub fn new(model: &Model) -> Self {
        let (nu, nc) = (model.nu, model.nc);
        let (_, depth, anc_ptr, anc_idx) = velocity_ancestors(model);
        // row patterns (the same as `Data::g_row_ptr`, `Data::g_row_idx`)
        let (row_ptr, row_idx) = constraint::row_pattern(model);
        // columns: rows reaching each velocity
        let mut col_ptr = vec![0; nu + 1];
        for &i in &row_idx {
            col_ptr[i + 1] += 1;
        }
        for i in 0..nu {
            col_ptr[i + 1] += col_ptr[i];
        }
        let mut fill = col_ptr.clone();
        let mut col_pos = vec![0; row_idx.len()];
        let mut col_rows = vec![0; row_idx.len()];
        for r in 0..nc {
            for p in row_ptr[r]..row_ptr[r + 1] {
                let i = row_idx[p];
                col_pos[fill[i]] = p;
                col_rows[fill[i]] = r;
                fill[i] += 1;
            }
        }
        // graph of S as bitsets, then minimum-degree elimination with fill
        let words = nc.div_ceil(64);
        let mut adj = vec![0u64; nc * words];
        let set = |adj: &mut Vec<u64>, a: usize, b: usize| adj[a * words + b / 64] |= 1 << (b % 64);
        for i in 0..nu {
            let rows = &col_rows[col_ptr[i]..col_ptr[i + 1]];
            for &a in rows {
                for &b in rows {
                    if a != b {
                        set(&mut adj, a, b);
                    }
                }
            }
        }
        let mut alive = vec![true; nc];
        let mut perm = Vec::with_capacity(nc);
        let mut pattern: Vec<Vec<usize>> = Vec::with_capacity(nc); // below-diagonal rows, original numbering
        for _ in 0..nc {
            let (mut best, mut best_deg) = (usize::MAX, usize::MAX);
            for v in 0..nc {
                if alive[v] {
                    let d: u32 = adj[v * words..(v + 1) * words].iter().map(|w| w.count_ones()).sum();
                    if (d as usize) < best_deg {
                        best_deg = d as usize;
                        best = v;
                    }
                }
            }
            let v = best;
            alive[v] = false;
            let nbrs: Vec<usize> = (0..nc).filter(|&w| adj[v * words + w / 64] >> (w % 64) & 1 == 1).collect();
            // the neighbours become a clique; v leaves the graph
            for &a in &nbrs {
                for w in 0..words {
                    let bits = adj[v * words + w];
                    adj[a * words + w] |= bits;
                }
                adj[a * words + a / 64] &= !(1 << (a % 64));
                adj[a * words + v / 64] &= !(1 << (v % 64));
            }
            perm.push(v);
            pattern.push(nbrs);
        }
        let mut inv = vec![0; nc];
        for (new, &old) in perm.iter().enumerate() {
            inv[old] = new;
        }
        // columns of L_S in elimination order: diagonal first, then rows ascending
        let (mut s_ptr, mut s_row) = (vec![0; nc + 1], Vec::new());
        let mut lookup = std::collections::HashMap::new();
        for j in 0..nc {
            let mut rows: Vec<usize> = pattern[j].iter().map(|&o| inv[o]).collect();
            rows.sort_unstable();
            debug_assert!(rows.iter().all(|&r| r > j));
            lookup.insert((j, j), s_row.len());
            s_row.push(j);
            for r in rows {
                lookup.insert((r, j), s_row.len());
                s_row.push(r);
            }
            s_ptr[j + 1] = s_row.len();
        }
        let at = |a: usize, b: usize| -> u32 {
            let (r, c) = if a >= b { (a, b) } else { (b, a) };
            lookup[&(r, c)] as u32
        };
        let mut assemble = Vec::new();
        for i in 0..nu {
            let rows = &col_rows[col_ptr[i]..col_ptr[i + 1]];
            for (x, &a) in rows.iter().enumerate() {
                for &b in &rows[x..] {
                    assemble.push(at(inv[a], inv[b]));
                }
            }
        }
        let mut update = Vec::new();
        for j in 0..nc {
            let below = &s_row[s_ptr[j] + 1..s_ptr[j + 1]];
            for (x, &a) in below.iter().enumerate() {
                for &b in &below[x..] {
                    update.push(at(b, a));
                }
            }
        }
        let block6 = dense_blocks6(nu, &depth, &anc_ptr, &anc_idx);
        Saddle {
            nu,
            nc,
            block6,
            depth,
            anc_ptr,
            m_off: vec![0.0; anc_idx.len()],
            anc_idx,
            m_diag: vec![0.0; nu],
            g_val: vec![0.0; row_idx.len()],
            y_val: vec![0.0; row_idx.len()],
            row_ptr,
            row_idx,
            col_ptr,
            col_pos,
            perm,
            s_val: vec![0.0; s_row.len()],
            s_ptr,
            s_row,
            assemble,
            update,
            d_s: vec![0.0; nc],
            s_diag0: vec![0.0; nc],
            dependent: vec![false; nc],
            scratch_u: vec![0.0; nu],
            scratch_c: vec![0.0; nc],
        }
    }

    /// Sets `M(r, c)` (either triangle; r and c on one root path).
    #[inline]
    pub fn put_mass(&mut self, r: usize, c: usize, v: f64) {
        if r == c {
            self.m_diag[r] = v;
        } else {
            let (hi, lo) = if r > c { (r, c) } else { (c, r) };
            self.m_off[self.anc_ptr[hi] + self.depth[hi] - 1 - self.depth[lo]] = v;
        }
    }

    /// Factors `M = Lᵀ D L` in place; false if a pivot is not positive (M singular).
    pub fn factor_mass(&mut self) -> bool {
        let scale = self.m_diag.iter().fold(0.0f64, |a, &b| a.max(b.abs()));
        let mut k = self.nu;
        while k > 0 {
            k -= 1;
            if k >= 5 && self.block6[k - 5] {
                // the same steps as below, in the same order, on fixed-size views: a free body's
                // 21 entries without index lists
                k -= 5;
                if !self.factor_block6(k, scale) {
                    return false;
                }
                continue;
            }
            let d = self.m_diag[k];
            if !(d > 1e-14 * scale) {
                return false;
            }
            let (s, e) = (self.anc_ptr[k], self.anc_ptr[k + 1]);
            for p in 0..e - s {
                let i = self.anc_idx[s + p];
                let mk = self.m_off[s + p];
                let a = mk / d;
                self.m_diag[i] -= a * mk;
                // M(i, j) -= a M(k, j) for the ancestors j of i, which follow i on k's path
                let si = self.anc_ptr[i];
                for q in p + 1..e - s {
                    self.m_off[si + q - p - 1] -= a * self.m_off[s + q];
                }
                self.m_off[s + p] = a;
            }
        }
        true
    }

    /// The block of six starting at velocity `k0` (see `block6`) factored as [`Saddle::factor_mass`]
    /// factors any velocity: velocity `k0 + j` keeps its ancestors `k0 + j - 1, …, k0` at
    /// `m_off[base + TRI6[j]..]`.
    fn factor_block6(&mut self, k0: usize, scale: f64) -> bool {
        let base = self.anc_ptr[k0];
        // (the lengths follow from the block's pattern; not a singular M)
        let off =
            <&mut [f64; 15]>::try_from(&mut self.m_off[base..base + 15]).expect("a block of six has 15 factor entries");
        let diag = <&mut [f64; 6]>::try_from(&mut self.m_diag[k0..k0 + 6]).expect("a block of six has six pivots");
        for j in (0..6).rev() {
            let d = diag[j];
            if !(d > 1e-14 * scale) {
                return false;
            }
            let s = TRI6[j];
            for p in 0..j {
                let i = j - 1 - p;
                let mk = off[s + p];
                let a = mk / d;
                diag[i] -= a * mk;
                let si = TRI6[i];
                for q in p + 1..j {
                    off[si + q - p - 1] -= a * off[s + q];
                }
                off[s + p] = a;
            }
        }
        true
    }

    /// The factor of M after [`Saddle::factor_mass`]: `L` below the diagonal (per velocity, its
    /// ancestors nearest first, as [`velocity_ancestors`] lists them) and `D`.
    pub(crate) fn mass_factor(&self) -> (&[f64], &[f64]) {
        (&self.m_off, &self.m_diag)
    }

    /// `x ← Lᵀ⁻¹ x` (leaves to root).
    fn solve_lt(&self, x: &mut [f64]) {
        let mut k = self.nu;
        while k > 0 {
            k -= 1;
            if k >= 5 && self.block6[k - 5] {
                k -= 5;
                let (off, xb) = self.block6_views(k, x);
                for j in (0..6).rev() {
                    let xk = xb[j];
                    if xk != 0.0 {
                        for p in 0..j {
                            xb[j - 1 - p] -= off[TRI6[j] + p] * xk;
                        }
                    }
                }
                continue;
            }
            let xk = x[k];
            if xk != 0.0 {
                for p in self.anc_ptr[k]..self.anc_ptr[k + 1] {
                    x[self.anc_idx[p]] -= self.m_off[p] * xk;
                }
            }
        }
    }

    /// `x ← M⁻¹ x` with the factor of [`Saddle::factor_mass`].
    pub fn solve_mass(&self, x: &mut [f64]) {
        self.solve_lt(x);
        let mut k = 0;
        while k < self.nu {
            if self.block6[k] {
                let diag = &self.m_diag[k..k + 6];
                let (off, xb) = self.block6_views(k, x);
                for j in 0..6 {
                    let mut s = xb[j] / diag[j];
                    for p in 0..j {
                        s -= off[TRI6[j] + p] * xb[j - 1 - p];
                    }
                    xb[j] = s;
                }
                k += 6;
                continue;
            }
            let mut s = x[k] / self.m_diag[k];
            for p in self.anc_ptr[k]..self.anc_ptr[k + 1] {
                s -= self.m_off[p] * x[self.anc_idx[p]];
            }
            x[k] = s;
            k += 1;
        }
    }

    /// The factor entries and the unknowns of the block of six starting at `k0`.
    #[inline]
    fn block6_views<'a>(&'a self, k0: usize, x: &'a mut [f64]) -> (&'a [f64; 15], &'a mut [f64; 6]) {
        let base = self.anc_ptr[k0];
        let off = <&[f64; 15]>::try_from(&self.m_off[base..base + 15]).expect("a block of six has 15 factor entries");
        let xb = <&mut [f64; 6]>::try_from(&mut x[k0..k0 + 6]).expect("a block of six has six unknowns");
        (off, xb)
    }

    /// Copies the rows of the dense `G` (nc × nu) onto the row pattern.
    pub fn gather_g(&mut self, g: &nalgebra::DMatrix<f64>) {
        for r in 0..self.nc {
            for p in self.row_ptr[r]..self.row_ptr[r + 1] {
                self.g_val[p] = g[(r, self.row_idx[p])];
            }
        }
    }

    /// Zeroes the rows `rows` of the gathered G (rows left out of a projection).
    pub fn clear_rows(&mut self, rows: std::ops::Range<usize>) {
        let (s, e) = (self.row_ptr[rows.start], self.row_ptr[rows.end]);
        self.g_val[s..e].fill(0.0);
    }

    /// Assembles `S = G M⁻¹ Gᵀ` (weighted, with the mass factor) or `S = G Gᵀ`.
    pub fn assemble_schur(&mut self, weighted: bool) {
        if weighted {
            for r in 0..self.nc {
                let (s, e) = (self.row_ptr[r], self.row_ptr[r + 1]);
                for p in s..e {
                    self.scratch_u[self.row_idx[p]] = self.g_val[p];
                }
                // Lᵀ y = g restricted to the row's velocities (an ancestor-closed set)
                for p in (s..e).rev() {
                    let k = self.row_idx[p];
                    let yk = self.scratch_u[k];
                    if yk != 0.0 {
                        for a in self.anc_ptr[k]..self.anc_ptr[k + 1] {
                            self.scratch_u[self.anc_idx[a]] -= self.m_off[a] * yk;
                        }
                    }
                }
                for p in s..e {
                    let k = self.row_idx[p];
                    self.y_val[p] = self.scratch_u[k];
                    self.scratch_u[k] = 0.0;
                }
            }
        } else {
            self.y_val.copy_from_slice(&self.g_val);
        }
        self.s_val.fill(0.0);
        let mut t = 0;
        for i in 0..self.nu {
            let w = if weighted { 1.0 / self.m_diag[i] } else { 1.0 };
            let pos = &self.col_pos[self.col_ptr[i]..self.col_ptr[i + 1]];
            for (x, &a) in pos.iter().enumerate() {
                let ya = self.y_val[a] * w;
                let targets = &self.assemble[t..t + pos.len() - x];
                t += pos.len() - x;
                // rows that vanish here (the out-of-plane rows of a planar loop) add nothing
                if ya != 0.0 {
                    for (&b, &tgt) in pos[x..].iter().zip(targets) {
                        self.s_val[tgt as usize] += ya * self.y_val[b];
                    }
                }
            }
        }
    }

    /// Factors S in place; dependent rows (pivot ≤ `tol · max diag`) get zero columns. Returns
    /// false if a dependent row was not a zero row of S (a genuine redundancy, whose minimum-norm
    /// multipliers this factor does not give).
    pub fn factor_schur(&mut self, tol: f64) -> bool {
        let nc = self.nc;
        for j in 0..nc {
            self.s_diag0[j] = self.s_val[self.s_ptr[j]];
        }
        let max_diag = self.s_diag0.iter().fold(0.0f64, |a, &b| a.max(b));
        let eps = tol * max_diag.max(f64::MIN_POSITIVE);
        let mut only_zero_rows = true;
        let mut t = 0;
        for j in 0..nc {
            let (s, e) = (self.s_ptr[j], self.s_ptr[j + 1]);
            let d = self.s_val[s];
            let n_below = e - s - 1;
            let n_upd = n_below * (n_below + 1) / 2;
            let old = self.perm[j];
            if !(d > eps) {
                self.dependent[old] = true;
                self.d_s[j] = 0.0;
                if self.s_diag0[j] > eps {
                    only_zero_rows = false;
                }
                self.s_val[s + 1..e].fill(0.0);
                t += n_upd;
                continue;
            }
            self.dependent[old] = false;
            self.d_s[j] = d;
            let inv_d = 1.0 / d;
            for a in s + 1..e {
                let la = self.s_val[a] * inv_d;
                let targets = &self.update[t..t + e - a];
                t += e - a;
                if la != 0.0 {
                    for (b, &tgt) in (a..e).zip(targets) {
                        self.s_val[tgt as usize] -= la * self.s_val[b];
                    }
                }
            }
            for a in s + 1..e {
                self.s_val[a] *= inv_d;
            }
        }
        only_zero_rows
    }

    /// Pivots `D_S` of the last factorization in elimination order (0 for dependent rows) and
    /// the constraint row of each: a pivot that shrinks by orders of magnitude during a run marks
    /// a row that vanishes or turns dependent (a singular configuration).
    pub fn pivots(&self) -> (&[f64], &[usize]) {
        (&self.d_s, &self.perm)
    }

    /// Whether every accepted pivot kept more than `tol` of its row's diagonal (no row nearly
    /// dependent on the rows eliminated before it).
    pub fn well_conditioned(&self, tol: f64) -> bool {
        (0..self.nc).all(|j| self.d_s[j] == 0.0 || self.d_s[j] > tol * self.s_diag0[j])
    }

    /// Number of independent rows at the last factorization.
    pub fn rank(&self) -> usize {
        self.dependent.iter().filter(|d| !**d).count()
    }

    /// `x ← S⁺ x` for the basic solution (dependent rows get zero).
    pub fn solve_schur(&mut self, x: &mut [f64]) {
        let w = &mut self.scratch_c;
        for j in 0..self.nc {
            w[j] = x[self.perm[j]];
        }
        for j in 0..self.nc {
            let wj = w[j];
            for p in self.s_ptr[j] + 1..self.s_ptr[j + 1] {
                w[self.s_row[p]] -= self.s_val[p] * wj;
            }
        }
        for j in 0..self.nc {
            w[j] = if self.d_s[j] > 0.0 { w[j] / self.d_s[j] } else { 0.0 };
        }
        for j in (0..self.nc).rev() {
            let mut s = w[j];
            for p in self.s_ptr[j] + 1..self.s_ptr[j + 1] {
                s -= self.s_val[p] * w[self.s_row[p]];
            }
            w[j] = s;
        }
        for j in 0..self.nc {
            x[self.perm[j]] = w[j];
        }
    }

    /// `out[r] = G_r · v` for every row.
    pub fn g_times(&self, v: &[f64], out: &mut [f64]) {
        for r in 0..self.nc {
            let mut s = 0.0;
            for p in self.row_ptr[r]..self.row_ptr[r + 1] {
                s += self.g_val[p] * v[self.row_idx[p]];
            }
            out[r] = s;
        }
    }

    /// `udot += M⁻¹ Gᵀ λ` (the accelerations the multipliers add), with the mass factor.
    pub fn add_constraint_accelerations(&mut self, lambda: &[f64], udot: &mut [f64]) {
        let mut x = std::mem::take(&mut self.scratch_u);
        self.gt_times(lambda, &mut x);
        self.solve_mass(&mut x);
        for (a, d) in udot.iter_mut().zip(&x) {
            *a += d;
        }
        self.scratch_u = x;
    }

    /// `out = Gᵀ λ`.
    pub fn gt_times(&self, lambda: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        for r in 0..self.nc {
            let l = lambda[r];
            if l != 0.0 {
                for p in self.row_ptr[r]..self.row_ptr[r + 1] {
                    out[self.row_idx[p]] += self.g_val[p] * l;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::Data;
    use crate::math::linalg::{cholesky_semidefinite, cholesky_semidefinite_solve};

    /// A branched spatial tree (ball joints; link4 hangs on link2) with loops between branches.
    fn model() -> Model {
        use crate::model::description::ConstraintDescription as C;
        let mut d = crate::fixtures::chain_description(6, "spherical");
        d.joints[3].parent = "link2".into();
        let dist = |name: &str, b1: &str, b2: &str, p2: [f64; 3]| C::Distance {
            name: name.into(),
            body1: b1.into(),
            point1: [0.5, 0.0, 0.0],
            body2: b2.into(),
            point2: p2,
            length: 0.7,
        };
        d.constraints = vec![
            dist("d1", "link3", "link6", [0.5, 0.0, 0.0]),
            dist("d2", "link5", "ground", [0.3, 0.2, -0.4]),
            C::Point {
                name: "p".into(),
                body1: "link3".into(),
                point1: [0.2, 0.1, 0.0],
                body2: "link5".into(),
                point2: [0.1, 0.0, 0.0],
            },
            dist("d3", "link1", "link4", [0.2, 0.0, 0.1]),
        ];
        Model::from_description(d).unwrap()
    }

    /// The mass matrix of `m` at q0 put into a fresh plan.
    fn planned(m: &Model) -> (Saddle, nalgebra::DMatrix<f64>) {
        let mut d = Data::new(m);
        let q = m.q0().to_vec();
        crate::dynamics::crba::mass_matrix(m, &mut d, 0.0, &q);
        let mut sp = Saddle::new(m);
        for r in 0..m.nu {
            for c in 0..m.nu {
                if d.mass_matrix[(r, c)] != 0.0 {
                    sp.put_mass(r, c, d.mass_matrix[(r, c)]);
                }
            }
        }
        (sp, d.mass_matrix.clone())
    }

    #[test]
    fn blocks_of_six_factor_and_solve_bit_for_bit_as_the_index_lists_do() {
        // free bodies on the ground (one with a revolute and a spherical joint below it), and a
        // chain of eight revolutes whose first six velocities form the same dense pattern
        let mut tree = crate::fixtures::chain_description(5, "revolute");
        for (k, (kind, parent)) in
            [("free", "ground"), ("revolute", "link1"), ("free", "ground"), ("spherical", "link3"), ("free", "ground")]
                .into_iter()
                .enumerate()
        {
            let j = &mut tree.joints[k];
            j.kind = kind.into();
            j.parent = parent.into();
            j.q0 = match kind {
                "free" => Some(vec![0.1 * k as f64, 0.2, -0.3, 0.9, 0.1 * k as f64, -0.3, 0.2]),
                "spherical" => Some(vec![0.8, 0.36, 0.0, 0.48]),
                _ => Some(vec![0.4]),
            };
            if kind != "revolute" {
                j.axis = None;
            }
        }
        let tree = Model::from_description(tree).unwrap();
        for (m, blocks) in [(tree, vec![0, 7, 16]), (crate::fixtures::chain(8, "revolute"), vec![0])] {
            let (mut fast, dense) = planned(&m);
            let starts: Vec<usize> = (0..m.nu).filter(|&k| fast.block6[k]).collect();
            assert_eq!(starts, blocks, "{}: blocks of six found", m.name);
            let mut slow = fast.clone();
            slow.block6.fill(false);
            assert!(fast.factor_mass() && slow.factor_mass());
            assert_eq!(fast.m_diag, slow.m_diag, "{}", m.name);
            assert_eq!(fast.m_off, slow.m_off, "{}", m.name);
            let b: Vec<f64> = (0..m.nu).map(|i| (i as f64 * 0.9).cos() - 0.3).collect();
            let (mut x_fast, mut x_slow) = (b.clone(), b.clone());
            fast.solve_mass(&mut x_fast);
            slow.solve_mass(&mut x_slow);
            assert_eq!(x_fast, x_slow, "{}", m.name);
            // and both are M⁻¹ b: against nalgebra's dense Cholesky
            let x = dense.clone().cholesky().unwrap().solve(&nalgebra::DVector::from_column_slice(&b));
            for i in 0..m.nu {
                assert!((x_fast[i] - x[i]).abs() < 1e-10 * x.amax(), "{} row {i}: {} vs {}", m.name, x_fast[i], x[i]);
            }
        }
    }

    #[test]
    fn mass_factor_solves_like_the_dense_matrix() {
        let m = model();
        let mut d = Data::new(&m);
        let q = m.q0().to_vec();
        crate::dynamics::crba::mass_matrix(&m, &mut d, 0.0, &q);
        let mut sp = Saddle::new(&m);
        for r in 0..m.nu {
            for c in 0..m.nu {
                if d.mass_matrix[(r, c)] != 0.0 {
                    sp.put_mass(r, c, d.mass_matrix[(r, c)]);
                }
            }
        }
        assert!(sp.factor_mass());
        let b: Vec<f64> = (0..m.nu).map(|i| (i as f64 * 0.7).sin() + 0.2).collect();
        let mut x = b.clone();
        sp.solve_mass(&mut x);
        // against nalgebra's dense Cholesky, to the conditioning of M (thin rods: cond ≈ 1e5)
        let dense = d.mass_matrix.clone().cholesky().unwrap().solve(&nalgebra::DVector::from_column_slice(&b));
        let scale = dense.amax();
        for i in 0..m.nu {
            assert!((x[i] - dense[i]).abs() < 1e-10 * scale, "row {i}: {} vs {}", x[i], dense[i]);
        }
    }

    #[test]
    fn schur_solve_matches_the_dense_pivoted_cholesky() {
        let m = model();
        let mut d = Data::new(&m);
        let q = m.q0().to_vec();
        crate::kinematics::positions(&m, &mut d, &q);
        crate::constraints::positions(&m, &mut d, 0.0, &q, &crate::forces::NoCallbacks).unwrap();
        let (nu, nc) = (m.nu, m.nc);
        for weighted in [false, true] {
            crate::dynamics::crba::mass_matrix(&m, &mut d, 0.0, &q);
            let mut sp = Saddle::new(&m);
            for r in 0..nu {
                for c in 0..nu {
                    if d.mass_matrix[(r, c)] != 0.0 {
                        sp.put_mass(r, c, d.mass_matrix[(r, c)]);
                    }
                }
            }
            assert!(sp.factor_mass());
            sp.gather_g(&d.g);
            sp.assemble_schur(weighted);
            // dense S
            let minv = d.mass_matrix.clone().try_inverse().unwrap();
            let s = if weighted { &d.g * minv * d.g.transpose() } else { &d.g * d.g.transpose() };
            let mut a: Vec<f64> = (0..nc * nc).map(|k| s[(k / nc, k % nc)]).collect();
            assert!(sp.factor_schur(1e-12));
            let rhs: Vec<f64> = (0..nc).map(|i| (i as f64 * 1.3).cos()).collect();
            let mut x = rhs.clone();
            sp.solve_schur(&mut x);
            let mut perm = vec![0; nc];
            let rank = cholesky_semidefinite(&mut a, nc, &mut perm, 1e-12);
            assert_eq!(rank, sp.rank());
            let mut y = rhs.clone();
            let mut work = vec![0.0; nc];
            cholesky_semidefinite_solve(&a, nc, &perm, rank, &mut y, &mut work);
            for i in 0..nc {
                assert!(
                    (x[i] - y[i]).abs() < 1e-9 * (1.0 + y[i].abs()),
                    "weighted {weighted} row {i}: {} vs {}",
                    x[i],
                    y[i]
                );
            }
        }
    }
}
