//! A friction-contact problem as an LCP, so that Lemke's method solves planar friction exactly.
//!
//! The tangential reaction is written with `k` directions `D = [d_1 … d_k]` of the tangent plane
//! and nonnegative components `β`: `r_T = D β`. In the plane `k = 2`, `d = ±t`, so `β = (r_T⁺, r_T⁻)`
//! and the cone is represented exactly; in space `d_a = (cos 2πa/k, sin 2πa/k)` spans a pyramid
//! inscribed in the Coulomb cone. With the slack `λ` (the magnitude of the sliding velocity) each
//! contact contributes `k + 2` unknowns `(r_N, β, λ)` and the conditions (Stewart & Trinkle 1996,
//! Anitescu & Potra 1997)
//!
//! ```text
//! 0 ≤ r_N ⊥ u_N = W_NN r_N + W_NT D β + q_N            ≥ 0   (Signorini)
//! 0 ≤ β   ⊥ Dᵀ u_T + λ e = Dᵀ (W_TN r_N + W_TT D β + q_T) + λ e ≥ 0
//! 0 ≤ λ   ⊥ μ r_N − eᵀ β                                 ≥ 0   (friction reserve)
//! ```
//!
//! Sliding (`u_T ≠ 0`) forces `λ > 0`, hence `eᵀβ = μ r_N`, with `β` only on the directions most
//! opposed to `u_T`: eq. 2.200's `λ_T = ∓μ λ_N` for `ġ_T ≷ 0`. Sticking leaves `λ = 0`, `u_T = 0`
//! and a nonnegative reserve.
//!
//! The matrix is copositive but not copositive-plus, so Lemke's classical guarantee does not
//! apply directly. It still ends in a solution when `W` is positive definite (or `q` lies in the
//! range of `W`): a secondary ray `Δz` would have to lie in `SOL(0, M) = {(0, 0, λ)}`, and then
//! `qᵀΔz = 0` contradicts `qᵀΔz = −zᵀ(M + Mᵀ)Δz − z0 eᵀΔz = −Σ μ r_N Δλ − z0 eᵀΔz < 0`. The
//! pyramid directions come in opposite pairs, which makes the LCP degenerate: `z0` can reach zero
//! without leaving the basis, which [`super::lemke`] detects and accepts.

use super::lemke::lemke;
use super::problem::{fc_residual, Delassus, FrictionContact};
use super::{LemkeOptions, Report, Workspace};
use crate::error::Result;

/// Most pyramid sides [`LemkeOptions::facets`] may ask for.
pub const MAX_FACETS: usize = 64;

/// Tangential directions per contact for dimension `d`.
pub(crate) fn directions(d: usize, o: &LemkeOptions) -> usize {
    if d == 2 {
        2
    } else {
        o.facets
    }
}

/// Direction `a` of `k` in tangent coordinates.
fn direction(d: usize, k: usize, a: usize) -> [f64; 2] {
    if d == 2 {
        [if a == 0 { 1.0 } else { -1.0 }, 0.0]
    } else {
        let phi = 2.0 * std::f64::consts::PI * a as f64 / k as f64;
        [phi.cos(), phi.sin()]
    }
}

/// Builds the LCP of the module documentation into `lcp_m` (row-major) and `lcp_q`.
pub(crate) fn build(p: &FrictionContact, k: usize, w: &[f64], lcp_m: &mut [f64], lcp_q: &mut [f64]) {
    let d = p.dim;
    let n = p.contacts();
    let m = d * n;
    let s = k + 2; // unknowns per contact
    let nl = s * n;
    let mut dirs = [[0.0; 2]; MAX_FACETS];
    let dirs = &mut dirs[..k];
    for (a, da) in dirs.iter_mut().enumerate() {
        *da = direction(d, k, a);
    }
    let nt = d - 1;
    lcp_m[..nl * nl].fill(0.0);
    for i in 0..n {
        let (ni, bi, li) = (i * s, i * s + 1, i * s + 1 + k);
        for j in 0..n {
            let (nj, bj) = (j * s, j * s + 1);
            let wij = |a: usize, b: usize| w[(i * d + a) * m + j * d + b];
            lcp_m[ni * nl + nj] = wij(0, 0);
            for (b, db) in dirs.iter().enumerate() {
                // W_NT d_b and d_aᵀ W_TN
                lcp_m[ni * nl + bj + b] = (0..nt).map(|t| wij(0, 1 + t) * db[t]).sum();
            }
            for (a, da) in dirs.iter().enumerate() {
                lcp_m[(bi + a) * nl + nj] = (0..nt).map(|t| da[t] * wij(1 + t, 0)).sum();
                for (b, db) in dirs.iter().enumerate() {
                    let mut v = 0.0;
                    for t in 0..nt {
                        for u in 0..nt {
                            v += da[t] * wij(1 + t, 1 + u) * db[u];
                        }
                    }
                    lcp_m[(bi + a) * nl + bj + b] = v;
                }
            }
        }
        for a in 0..k {
            lcp_m[(bi + a) * nl + li] = 1.0;
            lcp_m[li * nl + bi + a] = -1.0;
        }
        lcp_m[li * nl + ni] = p.mu[i];
        lcp_q[ni] = p.q[i * d];
        for (a, da) in dirs.iter().enumerate() {
            lcp_q[bi + a] = (0..nt).map(|t| da[t] * p.q[i * d + 1 + t]).sum();
        }
        lcp_q[li] = 0.0;
    }
}

/// Maps the LCP solution `z` back to `r = (r_N, D β)` per contact.
pub(crate) fn unpack(d: usize, n: usize, k: usize, z: &[f64], r: &mut [f64]) {
    let s = k + 2;
    for i in 0..n {
        r[i * d] = z[i * s];
        let mut rt = [0.0; 2];
        for a in 0..k {
            let da = direction(d, k, a);
            let beta = z[i * s + 1 + a];
            rt[0] += beta * da[0];
            rt[1] += beta * da[1];
        }
        r[i * d + 1..(i + 1) * d].copy_from_slice(&rt[..d - 1]);
    }
}

/// Solves a friction-contact problem through its LCP with Lemke's method.
pub(crate) fn solve(p: &FrictionContact, o: &LemkeOptions, r: &mut [f64], ws: &mut Workspace) -> Result<Report> {
    let d = p.dim;
    let n = p.contacts();
    let m = d * n;
    let k = directions(d, o);
    let nl = (k + 2) * n;
    let w: &[f64] = match &p.w {
        Delassus::Dense(w) => w,
        Delassus::Blocks(_) => {
            p.w.fill_dense(&mut ws.dense[..m * m]);
            &ws.dense[..m * m]
        }
    };
    build(p, k, w, &mut ws.lcp_m[..nl * nl], &mut ws.lcp_q[..nl]);
    let (pivots, complete) = lemke(&ws.lcp_m[..nl * nl], &ws.lcp_q[..nl], &mut ws.lcp_z[..nl], o, &mut ws.lemke)?;
    unpack(d, n, k, &ws.lcp_z[..nl], r);
    let u = &mut ws.u[..m];
    p.w.velocity(d, r, &p.q, u);
    Ok(Report { iterations: pivots, residual: fc_residual(p, r, u), converged: complete })
}
