//! Sparse LU factorization of a square matrix of `B × B` blocks with a symmetric block pattern
//! (values need not be symmetric), for systems coupled through a graph: the body-space matrix
//! `I + Σ_contacts Y_a E_a Y_aᵀ` of a pile, whose blocks are nonzero for bodies that touch.
//!
//! - **Ordering** ([`BlockLu::analyze`]): minimum degree on the block graph, played out as the
//!   elimination game (eliminating a block row joins its remaining neighbours into a clique), so
//!   the same pass yields the filled pattern. Ties go to the lowest index: the ordering depends on
//!   the pattern only.
//! - **Numeric factorization** ([`BlockLu::factor`]): right-looking block LU without pivoting
//!   between blocks, `K = L U` with `L` block lower triangular (its diagonal blocks the pivot
//!   blocks) and `U` unit block upper triangular, `U_kj = A_kk⁻¹ A_kj`. Within a pivot block, LU
//!   with partial pivoting, inverted once. Without pivoting between blocks this is stable for block diagonally
//!   dominant and for symmetric positive definite matrices (the body-space matrix is the identity
//!   plus a positive semidefinite term where contacts stick or are open).
//! - **Solve** ([`BlockLu::solve`]): forward and back substitution over the pattern.
//!
//! Cost: `Σ_k |pattern_k|² B³` for the factorization and `Σ_k |pattern_k| B²` per solve, with
//! `pattern_k` the later block rows of elimination step `k` (no fill on a chain or a tree). All
//! storage grows to the largest pattern seen and is reused: after that nothing is allocated.

use crate::math::linalg::{lu_factor, lu_solve};

/// Sparse block LU; see the module documentation.
#[derive(Debug, Clone, Default)]
pub struct BlockLu<const B: usize> {
    n: usize,
    /// Elimination position of each block row, and the block row at each position.
    pos: Vec<usize>,
    order: Vec<usize>,
    /// Later positions coupled to position k (ascending): `idx[ptr[k]..ptr[k + 1]]`.
    ptr: Vec<usize>,
    idx: Vec<usize>,
    /// Inverses of the pivot blocks (row-major `B × B` each), and the pivots of their LU.
    diag: Vec<f64>,
    piv: Vec<usize>,
    /// Block (idx[e], k) of L and block (k, idx[e]) of U at entry `e`, row-major `B × B`.
    lower: Vec<f64>,
    upper: Vec<f64>,
    // scratch of the ordering
    adj: Vec<Vec<usize>>,
    done: Vec<bool>,
    merged: Vec<usize>,
    clique: Vec<usize>,
}

impl<const B: usize> BlockLu<B> {
    const BB: usize = B * B;

    /// Number of block rows of the last [`BlockLu::analyze`].
    pub fn blocks(&self) -> usize {
        self.n
    }

    /// Off-diagonal blocks of the filled pattern (each of L and U).
    pub fn filled(&self) -> usize {
        self.idx.len()
    }

    /// Multiply-adds of one [`BlockLu::factor`].
    pub fn factor_cost(&self) -> usize {
        (0..self.n).map(|k| (self.ptr[k + 1] - self.ptr[k]).pow(2) + 1).sum::<usize>() * B * B * B
    }

    /// Orders the `n` block rows and forms the filled pattern for the coupled pairs `pairs`
    /// (`(i, j)` with `i ≠ j`, each pair once in either order or both; the diagonal is always
    /// present). Entries are left to [`BlockLu::zero`] and [`BlockLu::add`]. Panics if a pair
    /// names a block row `≥ n`.
    pub fn analyze(&mut self, n: usize, pairs: &[(usize, usize)]) {
        self.n = n;
        if self.adj.len() < n {
            self.adj.resize_with(n, Vec::new);
        }
        for a in &mut self.adj[..n] {
            a.clear();
        }
        for &(i, j) in pairs {
            debug_assert!(i < n && j < n && i != j);
            self.adj[i].push(j);
            self.adj[j].push(i);
        }
        for a in &mut self.adj[..n] {
            a.sort_unstable();
            a.dedup();
        }
        self.done.clear();
        self.done.resize(n, false);
        self.pos.resize(n, 0);
        self.order.clear();
        self.ptr.clear();
        self.ptr.push(0);
        self.idx.clear();
        for step in 0..n {
            // the remaining block row of least degree (lowest index on ties)
            let mut v = usize::MAX;
            let mut best = usize::MAX;
            for (c, a) in self.adj[..n].iter().enumerate() {
                if !self.done[c] && a.len() < best {
                    (v, best) = (c, a.len());
                }
            }
            self.done[v] = true;
            self.pos[v] = step;
            self.order.push(v);
            // its neighbours become a clique; they are its column of L and row of U
            self.clique.clear();
            self.clique.extend_from_slice(&self.adj[v]);
            self.idx.extend_from_slice(&self.clique);
            self.ptr.push(self.idx.len());
            for &a in &self.clique {
                let mut merged = std::mem::take(&mut self.merged);
                merged.clear();
                let (old, add) = (&self.adj[a], &self.clique);
                let (mut x, mut y) = (0, 0);
                while x < old.len() || y < add.len() {
                    let next = match (old.get(x), add.get(y)) {
                        (Some(&o), Some(&d)) if o == d => {
                            x += 1;
                            y += 1;
                            o
                        }
                        (Some(&o), Some(&d)) if o < d => {
                            x += 1;
                            o
                        }
                        (Some(_), Some(&d)) | (None, Some(&d)) => {
                            y += 1;
                            d
                        }
                        (Some(&o), None) => {
                            x += 1;
                            o
                        }
                        (None, None) => unreachable!(),
                    };
                    if next != v && next != a {
                        merged.push(next);
                    }
                }
                self.merged = std::mem::replace(&mut self.adj[a], merged);
            }
        }
        // block rows to positions, ascending within each step's pattern
        for e in 0..self.idx.len() {
            self.idx[e] = self.pos[self.idx[e]];
        }
        for k in 0..n {
            self.idx[self.ptr[k]..self.ptr[k + 1]].sort_unstable();
        }
        let nnz = self.idx.len();
        self.diag.resize(n * Self::BB, 0.0);
        self.piv.resize(n * B, 0);
        self.lower.resize(nnz * Self::BB, 0.0);
        self.upper.resize(nnz * Self::BB, 0.0);
    }

    /// Sets every entry to zero (the pattern stays).
    pub fn zero(&mut self) {
        self.diag.fill(0.0);
        self.lower.fill(0.0);
        self.upper.fill(0.0);
    }

    /// The storage of block (i, j) (block rows as given to [`BlockLu::analyze`]); `None` if the
    /// pair is not in the pattern.
    fn block_mut(&mut self, i: usize, j: usize) -> Option<&mut [f64]> {
        let (pi, pj) = (self.pos[i], self.pos[j]);
        Self::slot(&self.ptr, &self.idx, pi, pj).map(|(lower, at)| {
            let v = match (pi == pj, lower) {
                (true, _) => &mut self.diag,
                (false, true) => &mut self.lower,
                (false, false) => &mut self.upper,
            };
            &mut v[at * Self::BB..(at + 1) * Self::BB]
        })
    }

    /// Where block (positions pi, pj) lives: `(in L, block index)`; the diagonal at index `pi`.
    #[inline]
    fn slot(ptr: &[usize], idx: &[usize], pi: usize, pj: usize) -> Option<(bool, usize)> {
        if pi == pj {
            return Some((false, pi));
        }
        let (k, other, lower) = if pi > pj { (pj, pi, true) } else { (pi, pj, false) };
        let seg = &idx[ptr[k]..ptr[k + 1]];
        seg.binary_search(&other).ok().map(|e| (lower, ptr[k] + e))
    }

    /// Adds `blk` (row-major `B × B`) to block (i, j); false if the pair is not in the pattern
    /// (or names a block row beyond it, or `blk` is not `B × B`).
    pub fn add(&mut self, i: usize, j: usize, blk: &[f64]) -> bool {
        if i >= self.n || j >= self.n || blk.len() != Self::BB {
            return false;
        }
        match self.block_mut(i, j) {
            Some(dst) => {
                for (d, s) in dst.iter_mut().zip(blk) {
                    *d += s;
                }
                true
            }
            None => false,
        }
    }

    /// Factors the entries in place. `Err(i)`: the pivot block of block row `i` is singular
    /// (the factors are then unusable until the next factorization).
    pub fn factor(&mut self) -> Result<(), usize> {
        const { assert!(B <= 8, "blocks of up to 8 × 8") };
        let bb = Self::BB;
        for k in 0..self.n {
            // the pivot block's inverse (by its LU with partial pivoting), kept in its place
            let (d, p) = (&mut self.diag[k * bb..(k + 1) * bb], &mut self.piv[k * B..(k + 1) * B]);
            if lu_factor(d, B, p).is_err() || d.iter().any(|v| !v.is_finite()) {
                return Err(self.order[k]);
            }
            let mut inv = [0.0; 64];
            for c in 0..B {
                let mut col = [0.0; B];
                col[c] = 1.0;
                lu_solve(d, B, p, &mut col);
                for r in 0..B {
                    inv[r * B + c] = col[r];
                }
            }
            if inv[..bb].iter().any(|v| !v.is_finite()) {
                return Err(self.order[k]);
            }
            d.copy_from_slice(&inv[..bb]);
            let (lo, hi) = (self.ptr[k], self.ptr[k + 1]);
            // U_kj = A_kk⁻¹ A_kj
            for e in lo..hi {
                let blk = &mut self.upper[e * bb..(e + 1) * bb];
                let mut a = [0.0; 64];
                a[..bb].copy_from_slice(blk);
                for r in 0..B {
                    for c in 0..B {
                        let mut x = 0.0;
                        for t in 0..B {
                            x += inv[r * B + t] * a[t * B + c];
                        }
                        blk[r * B + c] = x;
                    }
                }
            }
            // Schur complement: A_ij −= L_ik U_kj over the clique of step k
            for ei in lo..hi {
                let pi = self.idx[ei];
                let mut l = [0.0; 64];
                l[..bb].copy_from_slice(&self.lower[ei * bb..(ei + 1) * bb]);
                for ej in lo..hi {
                    let pj = self.idx[ej];
                    let (in_lower, at) =
                        Self::slot(&self.ptr, &self.idx, pi, pj).expect("the elimination game closed the clique");
                    let mut u = [0.0; 64];
                    u[..bb].copy_from_slice(&self.upper[ej * bb..(ej + 1) * bb]);
                    let dst = match (pi == pj, in_lower) {
                        (true, _) => &mut self.diag[at * bb..(at + 1) * bb],
                        (false, true) => &mut self.lower[at * bb..(at + 1) * bb],
                        (false, false) => &mut self.upper[at * bb..(at + 1) * bb],
                    };
                    for r in 0..B {
                        for c in 0..B {
                            let mut s = 0.0;
                            for t in 0..B {
                                s += l[r * B + t] * u[t * B + c];
                            }
                            dst[r * B + c] -= s;
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// Solves `K x = b` in place (`x` holds `b` on entry; `B n` entries in the block rows' own
    /// order) with the factors of [`BlockLu::factor`]. `work` has at least `B n` entries.
    pub fn solve(&self, x: &mut [f64], work: &mut [f64]) {
        let (n, bb) = (self.n, Self::BB);
        let z = &mut work[..n * B];
        for (k, &v) in self.order.iter().enumerate() {
            z[k * B..(k + 1) * B].copy_from_slice(&x[v * B..(v + 1) * B]);
        }
        // L z = b: z_k = A_kk⁻¹ b_k, then b_i −= L_ik z_k
        for k in 0..n {
            let (head, tail) = z.split_at_mut((k + 1) * B);
            let zk = &mut head[k * B..];
            let inv = &self.diag[k * bb..(k + 1) * bb];
            let mut b = [0.0; B];
            b.copy_from_slice(zk);
            for r in 0..B {
                let mut x = 0.0;
                for c in 0..B {
                    x += inv[r * B + c] * b[c];
                }
                zk[r] = x;
            }
            for e in self.ptr[k]..self.ptr[k + 1] {
                let pi = self.idx[e];
                let l = &self.lower[e * bb..(e + 1) * bb];
                let zi = &mut tail[(pi - k - 1) * B..(pi - k) * B];
                for r in 0..B {
                    let mut s = 0.0;
                    for c in 0..B {
                        s += l[r * B + c] * zk[c];
                    }
                    zi[r] -= s;
                }
            }
        }
        // U x = z: x_k = z_k − Σ_j U_kj x_j
        for k in (0..n).rev() {
            let (head, tail) = z.split_at_mut((k + 1) * B);
            let zk = &mut head[k * B..];
            for e in self.ptr[k]..self.ptr[k + 1] {
                let pj = self.idx[e];
                let u = &self.upper[e * bb..(e + 1) * bb];
                let xj = &tail[(pj - k - 1) * B..(pj - k) * B];
                for r in 0..B {
                    let mut s = 0.0;
                    for c in 0..B {
                        s += u[r * B + c] * xj[c];
                    }
                    zk[r] -= s;
                }
            }
        }
        for (k, &v) in self.order.iter().enumerate() {
            x[v * B..(v + 1) * B].copy_from_slice(&z[k * B..(k + 1) * B]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic pseudo-random number in [-1, 1).
    fn rnd(state: &mut u64) -> f64 {
        *state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((*state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }

    /// A dense matrix with the given block pattern, random nonsymmetric blocks and dominant
    /// diagonal blocks; also loaded into `lu`.
    fn random_system<const B: usize>(n: usize, pairs: &[(usize, usize)], seed: u64, lu: &mut BlockLu<B>) -> Vec<f64> {
        let m = n * B;
        let mut dense = vec![0.0; m * m];
        let mut s = seed;
        lu.analyze(n, pairs);
        lu.zero();
        let mut put = |i: usize, j: usize, dom: f64, lu: &mut BlockLu<B>, dense: &mut Vec<f64>| {
            let mut blk = vec![0.0; B * B];
            for r in 0..B {
                for c in 0..B {
                    blk[r * B + c] = rnd(&mut s) + if r == c { dom } else { 0.0 };
                    dense[(i * B + r) * m + j * B + c] += blk[r * B + c];
                }
            }
            assert!(lu.add(i, j, &blk));
        };
        for i in 0..n {
            put(i, i, 4.0 * B as f64 * (1.0 + pairs.len() as f64 / n as f64), lu, &mut dense);
        }
        for &(i, j) in pairs {
            put(i, j, 0.0, lu, &mut dense);
            put(j, i, 0.0, lu, &mut dense);
        }
        dense
    }

    fn check_solve<const B: usize>(n: usize, pairs: &[(usize, usize)], seed: u64) -> BlockLu<B> {
        let mut lu = BlockLu::<B>::default();
        let dense = random_system::<B>(n, pairs, seed, &mut lu);
        let m = n * B;
        let mut st = seed ^ 0x9e37;
        let x_true: Vec<f64> = (0..m).map(|_| rnd(&mut st)).collect();
        let mut b: Vec<f64> = (0..m).map(|r| (0..m).map(|c| dense[r * m + c] * x_true[c]).sum()).collect();
        lu.factor().expect("nonsingular");
        let mut work = vec![0.0; m];
        lu.solve(&mut b, &mut work);
        let err = b.iter().zip(&x_true).map(|(a, t)| (a - t).abs()).fold(0.0, f64::max);
        assert!(err < 1e-12, "max error {err:e} for n = {n}, {} pairs", pairs.len());
        lu
    }

    #[test]
    fn a_chain_of_blocks_is_solved_without_fill() {
        let pairs: Vec<_> = (0..9).map(|i| (i, i + 1)).collect();
        let lu = check_solve::<6>(10, &pairs, 1);
        // a path: every elimination leaves one neighbour, so L has exactly the 9 original blocks
        assert_eq!(lu.filled(), 9);
    }

    #[test]
    fn a_grid_of_blocks_matches_the_dense_solution_and_fills_in() {
        // a 6 × 6 grid graph (4 neighbours inside), 3 × 3 blocks
        let k = 6;
        let mut pairs = vec![];
        for r in 0..k {
            for c in 0..k {
                if c + 1 < k {
                    pairs.push((r * k + c, r * k + c + 1));
                }
                if r + 1 < k {
                    pairs.push(((r + 1) * k + c, r * k + c));
                }
            }
        }
        let lu = check_solve::<3>(k * k, &pairs, 7);
        assert!(lu.filled() > pairs.len(), "a grid fills in");
        // minimum degree keeps the fill far below the dense triangle (630 blocks)
        assert!(lu.filled() < 200, "filled {}", lu.filled());
    }

    #[test]
    fn random_graphs_with_several_components_and_repeated_pairs_are_solved() {
        let mut st = 99u64;
        let n = 40;
        let mut pairs = vec![];
        for _ in 0..70 {
            let i = ((rnd(&mut st) + 1.0) * 0.5 * 30.0) as usize; // block rows 30..40 stay apart
            let j = ((rnd(&mut st) + 1.0) * 0.5 * 30.0) as usize;
            if i != j {
                pairs.push((i, j));
            }
        }
        pairs.push((31, 32));
        pairs.push((32, 31));
        let lu = check_solve::<6>(n, &pairs, 3);
        assert_eq!(lu.blocks(), n);
        // the same object re-analyzed for a smaller pattern reuses its storage and stays exact
        let mut lu = lu;
        let dense = random_system::<6>(3, &[(0, 2)], 5, &mut lu);
        let mut b = vec![1.0; 18];
        let rhs = b.clone();
        lu.factor().unwrap();
        lu.solve(&mut b, &mut [0.0; 18]);
        for r in 0..18 {
            let ax: f64 = (0..18).map(|c| dense[r * 18 + c] * b[c]).sum();
            assert!((ax - rhs[r]).abs() < 1e-12);
        }
    }

    #[test]
    fn a_singular_pivot_block_names_its_block_row_and_pairs_outside_the_pattern_are_refused() {
        let mut lu = BlockLu::<2>::default();
        lu.analyze(3, &[(0, 1)]);
        lu.zero();
        for i in [0, 2] {
            assert!(lu.add(i, i, &[1.0, 0.0, 0.0, 1.0]));
        }
        // block row 1 is all zero
        assert_eq!(lu.factor(), Err(1));
        assert!(!lu.add(0, 2, &[1.0; 4]));
        assert!(!lu.add(0, 3, &[1.0; 4]) && !lu.add(0, 0, &[1.0; 9]));
    }
}
