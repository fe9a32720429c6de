//! Dense LU factorization with partial pivoting on caller-owned storage, so that implicit
//! integrators can factor their iteration matrices every step without allocating.

use crate::error::{Error, Result};

/// Factors the row-major `n × n` matrix `a` in place (L unit-lower, U upper), pivots into `piv`.
pub fn lu_factor(a: &mut [f64], n: usize, piv: &mut [usize]) -> Result<()> {
    for k in 0..n {
        pivot(a, n, k, n - 1, |_| 0..n, piv)?;
        let d = a[k * n + k];
        for r in k + 1..n {
            let l = a[r * n + k] / d;
            a[r * n + k] = l;
            if l != 0.0 {
                for c in k + 1..n {
                    a[r * n + c] -= l * a[k * n + c];
                }
            }
        }
    }
    Ok(())
}

/// Partial pivoting at column `k`: the row of the largest `|a[r][k]|`, k ≤ r ≤ `last` (the rows
/// below are zero in the column), swapped into row `k` over the columns `cols` (the two rows are
/// zero outside them) and recorded in `piv[k]` (also returned); an error if the column is zero or
/// not finite. `cols` gets the chosen row.
#[inline]
fn pivot(
    a: &mut [f64],
    n: usize,
    k: usize,
    last: usize,
    cols: impl FnOnce(usize) -> std::ops::Range<usize>,
    piv: &mut [usize],
) -> Result<usize> {
    let mut p = k;
    let mut best = a[k * n + k].abs();
    for r in k + 1..=last {
        let v = a[r * n + k].abs();
        if v > best {
            best = v;
            p = r;
        }
    }
    piv[k] = p;
    if best == 0.0 || !best.is_finite() {
        return Err(Error::Solver(format!("singular matrix in LU factorization (column {k})")));
    }
    if p != k {
        for c in cols(p) {
            a.swap(k * n + c, p * n + c);
        }
    }
    Ok(p)
}

/// Solves `A x = b` in place with the factors of [`lu_factor`].
pub fn lu_solve(a: &[f64], n: usize, piv: &[usize], b: &mut [f64]) {
    for k in 0..n {
        b.swap(k, piv[k]);
    }
    for r in 0..n {
        let mut s = b[r];
        for c in 0..r {
            s -= a[r * n + c] * b[c];
        }
        b[r] = s;
    }
    for r in (0..n).rev() {
        let mut s = b[r];
        for c in r + 1..n {
            s -= a[r * n + c] * b[c];
        }
        b[r] = s / a[r * n + r];
    }
}

/// [`lu_factor`] for a matrix whose rows end early (a banded or profile matrix, such as the
/// Jacobian of a contact problem ordered along a stack): `ext[r] = (lo, hi)` receives, for row `r`
/// of the factors, the first column of L's nonzeros and one past the last of U's, and the
/// elimination, the pivot search, the row exchanges and [`lu_solve_profile`] skip the exact zeros
/// outside them (a banded matrix costs its band, not n² per column). The same pivots and factors
/// as [`lu_factor`], every entry equal: only products with entries that are exactly zero are left
/// out (where the dense routine writes a multiplier 0/d, a zero stays as it was).
pub fn lu_factor_profile(a: &mut [f64], n: usize, piv: &mut [usize], ext: &mut [(usize, usize)]) -> Result<()> {
    // per row its first nonzero (in ext.0 until the end) and one past its last; an update by row
    // k extends row r to row k's end, never to the left of r's first nonzero (row k's entries
    // left of column k are L's, not used in updates)
    for (r, e) in ext[..n].iter_mut().enumerate() {
        let row = &a[r * n..(r + 1) * n];
        e.1 = row.iter().rposition(|v| *v != 0.0).map_or(0, |c| c + 1);
        e.0 = row.iter().position(|v| *v != 0.0).unwrap_or(n);
    }
    // piv[k] until step k: the last row that can hold a nonzero in column k (rows below it start
    // right of k and have not moved: every exchange so far was above it), so the pivot search and
    // the elimination of a banded matrix cost its band, not n
    piv[..n].fill(0);
    for (r, e) in ext[..n].iter().enumerate() {
        if e.0 < n {
            piv[e.0] = piv[e.0].max(r);
        }
    }
    for k in 1..n {
        piv[k] = piv[k].max(piv[k - 1]);
    }
    for k in 0..n {
        let last = piv[k].max(k);
        // both rows are zero outside their extents
        let ext_k = ext[k];
        let p = pivot(a, n, k, last, |p| ext_k.0.min(ext[p].0)..ext_k.1.max(ext[p].1), piv)?;
        ext.swap(k, p);
        let d = a[k * n + k];
        let end = ext[k].1.max(k + 1);
        for r in k + 1..=last {
            let v = a[r * n + k];
            if v == 0.0 {
                continue;
            }
            let l = v / d;
            a[r * n + k] = l;
            if l != 0.0 {
                let (top, bottom) = a.split_at_mut(r * n);
                let urow = &top[k * n + k + 1..k * n + end];
                for (x, u) in bottom[k + 1..end].iter_mut().zip(urow) {
                    *x -= l * u;
                }
                ext[r].1 = ext[r].1.max(end);
            }
        }
    }
    for (r, e) in ext[..n].iter_mut().enumerate() {
        let first = e.0.min(r);
        e.0 = a[r * n + first..r * n + r].iter().position(|v| *v != 0.0).map_or(r, |c| first + c);
    }
    Ok(())
}

/// Solves `A x = b` in place with the factors and row extents of [`lu_factor_profile`].
pub fn lu_solve_profile(a: &[f64], n: usize, piv: &[usize], ext: &[(usize, usize)], b: &mut [f64]) {
    for k in 0..n {
        b.swap(k, piv[k]);
    }
    for r in 0..n {
        let lo = ext[r].0;
        let mut s = b[r];
        for (x, y) in a[r * n + lo..r * n + r].iter().zip(&b[lo..r]) {
            s -= x * y;
        }
        b[r] = s;
    }
    for r in (0..n).rev() {
        let hi = ext[r].1.max(r + 1);
        let mut s = b[r];
        for (x, y) in a[r * n + r + 1..r * n + hi].iter().zip(&b[r + 1..hi]) {
            s -= x * y;
        }
        b[r] = s / a[r * n + r];
    }
}

/// Factors the complex row-major `n × n` matrix `re + i·im` in place, its real and imaginary
/// parts in two arrays laid out as for [`lu_factor`]; pivots (largest modulus) into `piv`.
pub fn lu_factor_complex(re: &mut [f64], im: &mut [f64], n: usize, piv: &mut [usize]) -> Result<()> {
    for k in 0..n {
        let mut p = k;
        let mut best = re[k * n + k].hypot(im[k * n + k]);
        for r in k + 1..n {
            let v = re[r * n + k].hypot(im[r * n + k]);
            if v > best {
                best = v;
                p = r;
            }
        }
        piv[k] = p;
        if best == 0.0 || !best.is_finite() {
            return Err(Error::Solver(format!("singular matrix in complex LU factorization (column {k})")));
        }
        if p != k {
            for c in 0..n {
                re.swap(k * n + c, p * n + c);
                im.swap(k * n + c, p * n + c);
            }
        }
        let (dr, di) = (re[k * n + k], im[k * n + k]);
        let d2 = dr * dr + di * di;
        for r in k + 1..n {
            // l = a_rk / d = a_rk · conj(d) / |d|²
            let (ar, ai) = (re[r * n + k], im[r * n + k]);
            let (lr, li) = ((ar * dr + ai * di) / d2, (ai * dr - ar * di) / d2);
            re[r * n + k] = lr;
            im[r * n + k] = li;
            if lr != 0.0 || li != 0.0 {
                for c in k + 1..n {
                    let (ur, ui) = (re[k * n + c], im[k * n + c]);
                    re[r * n + c] -= lr * ur - li * ui;
                    im[r * n + c] -= lr * ui + li * ur;
                }
            }
        }
    }
    Ok(())
}

/// Solves `A x = b` in place with the factors of [`lu_factor_complex`] (`b = br + i·bi`).
pub fn lu_solve_complex(re: &[f64], im: &[f64], n: usize, piv: &[usize], br: &mut [f64], bi: &mut [f64]) {
    for k in 0..n {
        br.swap(k, piv[k]);
        bi.swap(k, piv[k]);
    }
    for r in 0..n {
        let (mut sr, mut si) = (br[r], bi[r]);
        for c in 0..r {
            let (lr, li) = (re[r * n + c], im[r * n + c]);
            sr -= lr * br[c] - li * bi[c];
            si -= lr * bi[c] + li * br[c];
        }
        br[r] = sr;
        bi[r] = si;
    }
    for r in (0..n).rev() {
        let (mut sr, mut si) = (br[r], bi[r]);
        for c in r + 1..n {
            let (ur, ui) = (re[r * n + c], im[r * n + c]);
            sr -= ur * br[c] - ui * bi[c];
            si -= ur * bi[c] + ui * br[c];
        }
        let (dr, di) = (re[r * n + r], im[r * n + r]);
        let d2 = dr * dr + di * di;
        br[r] = (sr * dr + si * di) / d2;
        bi[r] = (si * dr - sr * di) / d2;
    }
}

/// Cholesky factorization with diagonal pivoting of the symmetric positive semidefinite row-major
/// `n × n` matrix `a`, in place (lower factor). Pivots smaller than `tol` times the largest are
/// treated as zero: their rows are dependent on the others (redundant constraints). Returns the rank;
/// `perm` receives the pivot order.
pub fn cholesky_semidefinite(a: &mut [f64], n: usize, perm: &mut [usize], tol: f64) -> usize {
    for (i, p) in perm.iter_mut().enumerate().take(n) {
        *p = i;
    }
    let max_diag = (0..n).map(|i| a[i * n + i]).fold(0.0f64, f64::max);
    let eps = tol * max_diag.max(f64::MIN_POSITIVE);
    let mut rank = 0;
    for k in 0..n {
        // largest remaining diagonal
        let (mut p, mut best) = (k, a[k * n + k]);
        for i in k + 1..n {
            if a[i * n + i] > best {
                best = a[i * n + i];
                p = i;
            }
        }
        if !(best > eps) {
            break;
        }
        if p != k {
            perm.swap(k, p);
            for c in 0..n {
                a.swap(k * n + c, p * n + c);
            }
            for r in 0..n {
                a.swap(r * n + k, r * n + p);
            }
        }
        let d = a[k * n + k].sqrt();
        a[k * n + k] = d;
        for r in k + 1..n {
            a[r * n + k] /= d;
        }
        // update the whole trailing block (both triangles) so that later symmetric pivoting swaps
        // read valid entries
        for r in k + 1..n {
            let l = a[r * n + k];
            for c in k + 1..n {
                a[r * n + c] -= l * a[c * n + k];
            }
        }
        rank += 1;
    }
    // keep the upper triangle consistent for callers that read it
    for r in 0..n {
        for c in r + 1..n {
            a[r * n + c] = a[c * n + r];
        }
    }
    rank
}

/// Solves `A x = b` with the factor of [`cholesky_semidefinite`] of rank `rank`: the dependent
/// unknowns (pivots beyond the rank) are set to zero, a basic solution of a consistent system.
pub fn cholesky_semidefinite_solve(a: &[f64], n: usize, perm: &[usize], rank: usize, b: &mut [f64], work: &mut [f64]) {
    for i in 0..n {
        work[i] = b[perm[i]];
    }
    for r in 0..rank {
        let mut s = work[r];
        for c in 0..r {
            s -= a[r * n + c] * work[c];
        }
        work[r] = s / a[r * n + r];
    }
    for r in (0..rank).rev() {
        let mut s = work[r];
        for c in r + 1..rank {
            s -= a[c * n + r] * work[c];
        }
        work[r] = s / a[r * n + r];
    }
    for w in work.iter_mut().take(n).skip(rank) {
        *w = 0.0;
    }
    for i in 0..n {
        b[perm[i]] = work[i];
    }
}

/// The minimum-norm solution of the consistent row-major `n × n` system `A x = b`, possibly
/// singular: `x = Aᵀ y` with `(A Aᵀ) y = b` solved by [`cholesky_semidefinite`] (pivots below `tol`
/// of the largest count as zero). Redundant contact constraints (a block resting on four corners)
/// then share their load evenly instead of one taking all. `b` receives x; `aat` (`n²`), `perm`
/// and `work` (`n`) are scratch. Returns the rank.
pub fn solve_min_norm(
    a: &[f64],
    n: usize,
    b: &mut [f64],
    aat: &mut [f64],
    perm: &mut [usize],
    work: &mut [f64],
    tol: f64,
) -> usize {
    for r in 0..n {
        for c in 0..=r {
            let v: f64 = (0..n).map(|k| a[r * n + k] * a[c * n + k]).sum();
            aat[r * n + c] = v;
            aat[c * n + r] = v;
        }
    }
    let rank = cholesky_semidefinite(&mut aat[..n * n], n, perm, tol);
    cholesky_semidefinite_solve(&aat[..n * n], n, perm, rank, b, work);
    for c in 0..n {
        work[c] = (0..n).map(|r| a[r * n + c] * b[r]).sum();
    }
    b[..n].copy_from_slice(&work[..n]);
    rank
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_system_needing_pivoting() {
        // first pivot is zero: fails without row exchange
        let a0 = [0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.0, 1.0];
        let x = [1.0, -2.0, 3.0];
        let mut b = [0.0; 3];
        for r in 0..3 {
            b[r] = (0..3).map(|c| a0[r * 3 + c] * x[c]).sum();
        }
        let mut a = a0;
        let mut piv = [0; 3];
        lu_factor(&mut a, 3, &mut piv).unwrap();
        lu_solve(&a, 3, &piv, &mut b);
        for i in 0..3 {
            assert!((b[i] - x[i]).abs() < 1e-14);
        }
        let mut s = [1.0, 2.0, 2.0, 4.0];
        assert!(lu_factor(&mut s, 2, &mut [0; 2]).is_err());
    }

    #[test]
    fn profile_lu_equals_the_dense_lu_bit_for_bit() {
        // banded with pivoting (small diagonal entries), a block-tridiagonal pattern with empty
        // rows ends, and a full matrix: the same factors and solutions as the dense routines
        let n = 24;
        let mut seed = 7u64;
        let mut rnd = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        // (kl, ku, rows exchanged before factoring: the rows' first nonzeros then do not grow
        // down the matrix, and rows below a pivot's column reach left of it)
        for (kl, ku, shuffle) in [(2usize, 3usize, false), (5, 1, false), (0, 0, false), (n, n, false), (2, 2, true)] {
            let mut a0 = vec![0.0; n * n];
            for r in 0..n {
                for c in r.saturating_sub(kl)..(r + ku + 1).min(n) {
                    a0[r * n + c] = rnd();
                }
                a0[r * n + r] *= 0.01;
            }
            if shuffle {
                for (x, y) in [(0, 9), (3, 17), (5, 6), (12, 23)] {
                    for c in 0..n {
                        a0.swap(x * n + c, y * n + c);
                    }
                }
            }
            let b0: Vec<f64> = (0..n).map(|_| rnd()).collect();
            let (mut a1, mut a2) = (a0.clone(), a0.clone());
            let (mut p1, mut p2, mut ext) = (vec![0; n], vec![0; n], vec![(0, 0); n]);
            lu_factor(&mut a1, n, &mut p1).unwrap();
            lu_factor_profile(&mut a2, n, &mut p2, &mut ext).unwrap();
            assert_eq!(p1, p2, "pivots, band ({kl}, {ku})");
            assert!(a1.iter().zip(&a2).all(|(x, y)| x == y), "factors, band ({kl}, {ku})");
            let (mut x1, mut x2) = (b0.clone(), b0.clone());
            lu_solve(&a1, n, &p1, &mut x1);
            lu_solve_profile(&a2, n, &p2, &ext, &mut x2);
            assert_eq!(x1, x2, "solution, band ({kl}, {ku})");
            // and it solves the system
            for r in 0..n {
                let ax: f64 = (0..n).map(|c| a0[r * n + c] * x2[c]).sum();
                assert!((ax - b0[r]).abs() < 1e-9, "residual row {r}, band ({kl}, {ku})");
            }
            if kl < n && !shuffle {
                // U keeps the band grown by the row exchanges (kl + ku), so the solves skip work
                for (r, &(_, hi)) in ext.iter().enumerate() {
                    assert!(hi <= (r + kl + ku + 1).min(n), "row {r}: U ends at {hi}");
                }
            }
        }
        let mut s = [1.0, 2.0, 2.0, 4.0];
        assert!(lu_factor_profile(&mut s, 2, &mut [0; 2], &mut [(0, 0); 2]).is_err());
    }

    #[test]
    fn complex_lu_agrees_with_the_real_form_of_the_system() {
        // (P + iQ)(x + iy) = b + ic  ⇔  [P -Q; Q P] [x; y] = [b; c], solved by the real LU
        let n = 3;
        let p0 = [0.0, 2.0, 1.0, 1.0, -1.0, 0.5, 3.0, 0.0, 1.0]; // a zero leading real part: pivoting
        let q0 = [0.0, 0.3, -1.0, 2.0, 0.0, 0.1, -0.5, 1.0, 0.2];
        let (b, c) = ([1.0, -2.0, 0.5], [0.0, 4.0, -1.0]);
        let m = 2 * n;
        let mut big = vec![0.0; m * m];
        for r in 0..n {
            for k in 0..n {
                big[r * m + k] = p0[r * n + k];
                big[r * m + n + k] = -q0[r * n + k];
                big[(n + r) * m + k] = q0[r * n + k];
                big[(n + r) * m + n + k] = p0[r * n + k];
            }
        }
        let mut rhs = [b[0], b[1], b[2], c[0], c[1], c[2]];
        let mut piv = [0; 6];
        lu_factor(&mut big, m, &mut piv).unwrap();
        lu_solve(&big, m, &piv, &mut rhs);
        let (mut re, mut im) = (p0, q0);
        let mut cp = [0; 3];
        lu_factor_complex(&mut re, &mut im, n, &mut cp).unwrap();
        let (mut x, mut y) = (b, c);
        lu_solve_complex(&re, &im, n, &cp, &mut x, &mut y);
        for i in 0..n {
            assert!((x[i] - rhs[i]).abs() < 1e-13 && (y[i] - rhs[n + i]).abs() < 1e-13, "{i}");
        }
        let (mut sr, mut si) = ([1.0, 2.0, 2.0, 4.0], [1.0, 0.0, 2.0, 0.0]);
        assert!(lu_factor_complex(&mut sr, &mut si, 2, &mut [0; 2]).is_err());
    }

    #[test]
    fn semidefinite_cholesky_finds_rank_and_solves_consistent_systems() {
        // A = B Bᵀ with B 3×2: rank 2; b in the range of A
        let bm = [[0.1, 0.2], [0.5, -1.0], [0.6, -0.8]]; // third row = first + second; pivots move
        let mut a = [0.0; 9];
        for r in 0..3 {
            for c in 0..3 {
                a[r * 3 + c] = bm[r][0] * bm[c][0] + bm[r][1] * bm[c][1];
            }
        }
        let a0 = a;
        let x_true = [0.3, -0.2, 0.0];
        let mut b = [0.0; 3];
        for r in 0..3 {
            b[r] = (0..3).map(|c| a0[r * 3 + c] * x_true[c]).sum();
        }
        let mut perm = [0; 3];
        let rank = cholesky_semidefinite(&mut a, 3, &mut perm, 1e-12);
        assert_eq!(rank, 2);
        let mut x = b;
        cholesky_semidefinite_solve(&a, 3, &perm, rank, &mut x, &mut [0.0; 3]);
        // any solution reproduces b
        for r in 0..3 {
            let ax: f64 = (0..3).map(|c| a0[r * 3 + c] * x[c]).sum();
            assert!((ax - b[r]).abs() < 1e-12, "row {r}");
        }
    }

    #[test]
    fn min_norm_solves_regular_and_redundant_systems() {
        // regular (non-symmetric, needs pivoting): x = (1, 2, 3)
        let a = [0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 4.0, 0.0, 1.0];
        let x = [1.0, 2.0, 3.0];
        let mut b: Vec<f64> = (0..3).map(|r| (0..3).map(|c| a[r * 3 + c] * x[c]).sum()).collect();
        let (mut aat, mut perm, mut work) = ([0.0; 9], [0; 3], [0.0; 3]);
        assert_eq!(solve_min_norm(&a, 3, &mut b, &mut aat, &mut perm, &mut work, 1e-12), 3);
        for k in 0..3 {
            assert!((b[k] - x[k]).abs() < 1e-12, "{b:?}");
        }
        // two equal constraints on one unknown share it: [1 1; 1 1] x = (2, 2) gives x = (1, 1),
        // the minimum-norm point of the line x1 + x2 = 2
        let a = [1.0, 1.0, 1.0, 1.0];
        let mut b = [2.0, 2.0];
        assert_eq!(solve_min_norm(&a, 2, &mut b, &mut aat, &mut perm, &mut work, 1e-12), 1);
        assert!((b[0] - 1.0).abs() < 1e-14 && (b[1] - 1.0).abs() < 1e-14, "{b:?}");
    }
}
