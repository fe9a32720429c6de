//! Forward dynamics with bilateral constraints by Lagrange multipliers (section 2.2.5, eq. 2.70):
//!
//! ```text
//! M u̇ = h + τ + Gᵀ λ,      G u̇ = γ
//! ```
//!
//! solved through the unconstrained accelerations (ABA) and the Schur complement
//! `(G M⁻¹ Gᵀ) λ = γ - G u̇_free`, `u̇ = u̇_free + M⁻¹ Gᵀ λ`. The Schur complement is factored
//! by a pivoted Cholesky decomposition that detects dependent (redundant) constraint rows and gives
//! them zero multipliers. After each step [`project`] puts q and u back on the constraint
//! manifolds (`Φ = 0` by Newton with minimum-norm corrections, then `G u = b`).

use crate::constraints;
use crate::data::Data;
use crate::error::{Error, Result};
use crate::forces::{Callbacks, Powers};
use crate::math::linalg::{cholesky_semidefinite, cholesky_semidefinite_solve};
use crate::model::Model;
use crate::spatial::Motion;

use super::sparse::Saddle;
use super::Workspace;

/// Relative size below which a pivot counts as zero (dependent rows, singular mass matrix).
const RANK_TOL: f64 = 1e-12;

/// Forward dynamics of a constrained model; fills `data.udot`, `data.lambda`, `data.phi`.
#[allow(clippy::too_many_arguments)]
pub fn forward_dynamics(
    model: &Model,
    data: &mut Data,
    ws: &mut Workspace,
    t: f64,
    q: &[f64],
    u: &[f64],
    tau: Option<&[f64]>,
    cb: &dyn Callbacks,
) -> Result<Powers> {
    let nc = model.nc;
    let mut p = super::prepare(model, data, ws, t, q, u, cb)?;
    constraints::positions(model, data, t, q, cb)?;
    // velocity-product accelerations (u̇ = 0, no gravity) for γ
    data.a[0] = Motion::ZERO;
    let zero = std::mem::take(&mut data.zero_u);
    crate::kinematics::accelerations(model, data, &zero);
    data.zero_u = zero;
    constraints::accelerations(model, data, t, q, u, cb)?;
    // the bias forces from the same velocity-product accelerations: M u̇_free = τ - c
    let mut c = std::mem::take(&mut data.udot);
    super::rnea::rnea_inward(model, data, &mut c);
    for (i, ci) in c.iter_mut().enumerate() {
        *ci = tau.map_or(0.0, |x| x[i]) - *ci;
    }
    data.udot = c;
    if !solve_sparse(model, data, &mut ws.saddle, t, u)? {
        solve_dense(model, data, t)?;
    }
    for k in 0..nc {
        // driving constraints do work: λ · b (b = 0 for scleronomic rows)
        p.external += data.lambda[k] * data.b[k];
    }
    // body accelerations of the constrained motion (without gravity), for records and reactions
    data.a[0] = Motion::ZERO;
    let udot = std::mem::take(&mut data.udot);
    crate::kinematics::accelerations(model, data, &udot);
    data.udot = udot;
    Ok(p)
}

/// Baumgarte feedback `Φ̈ + 2α Φ̇ + β² Φ = 0` folded into γ (Φ is zero on velocity-only rows);
/// `gu` holds `G u`.
fn baumgarte(data: &mut Data, gu: &[f64]) {
    if let Some((alpha, beta)) = data.baumgarte {
        for r in 0..data.gamma.len() {
            data.gamma[r] -= 2.0 * alpha * (gu[r] - data.b[r]) + beta * beta * data.phi[r];
        }
    }
}

/// The sparse path (see [`super::sparse`]): `M = LᵀDL` on the tree, `S = G M⁻¹ Gᵀ` on the row
/// patterns, λ and `u̇ += M⁻¹ Gᵀ λ`. `data.udot` holds `τ - c` on entry. Returns false, leaving
/// `data.udot` as the unconstrained accelerations, when the rows are redundant in a way that needs
/// the dense minimum-norm path.
fn solve_sparse(model: &Model, data: &mut Data, sp: &mut Saddle, t: f64, u: &[f64]) -> Result<bool> {
    let nc = model.nc;
    {
        let Data { inertia, s, ic, elastic, .. } = &mut *data;
        super::crba::composite_inertias(model, inertia, s, ic, elastic, |r, c, v| sp.put_mass(r, c, v));
    }
    if !sp.factor_mass() {
        return Err(Error::Solver(format!(
            "the mass matrix is singular at t = {t:.6} s{}",
            crate::elastic::runaway(model, data)
        )));
    }
    sp.solve_mass(&mut data.udot);
    sp.gather_g(&data.g);
    if data.baumgarte.is_some() {
        let mut gu = std::mem::take(&mut data.work2);
        sp.g_times(u, &mut gu[..nc]);
        baumgarte(data, &gu[..nc]);
        data.work2 = gu;
    }
    sp.assemble_schur(true);
    if !sp.factor_schur(RANK_TOL) {
        return Ok(false);
    }
    sp.g_times(&data.udot, &mut data.lambda);
    for r in 0..nc {
        data.lambda[r] = data.gamma[r] - data.lambda[r];
    }
    sp.solve_schur(&mut data.lambda);
    sp.add_constraint_accelerations(&data.lambda, &mut data.udot);
    data.dependent.copy_from_slice(&sp.dependent);
    Ok(true)
}

/// The dense path: Cholesky of M, `S = G M⁻¹ Gᵀ` by pivoted Cholesky, minimum-norm multipliers
/// for redundant rows. `data.udot` holds the unconstrained accelerations on entry.
fn solve_dense(model: &Model, data: &mut Data, t: f64) -> Result<()> {
    let (nu, nc) = (model.nu, model.nc);
    // M = L Lᵀ
    super::crba::crba(model, data);
    for r in 0..nu {
        for c in 0..nu {
            data.m_factor[r * nu + c] = data.mass_matrix[(r, c)];
        }
    }
    let rank_m = cholesky_semidefinite(&mut data.m_factor, nu, &mut data.perm_u, RANK_TOL);
    if rank_m < nu {
        return Err(Error::Solver(format!("the mass matrix is singular at t = {t:.6} s (rank {rank_m} of {nu})")));
    }
    // M⁻¹ Gᵀ column by column
    for k in 0..nc {
        let col = &mut data.minv_gt[k * nu..(k + 1) * nu];
        for i in 0..nu {
            col[i] = data.g[(k, i)];
        }
        cholesky_semidefinite_solve(&data.m_factor, nu, &data.perm_u, nu, col, &mut data.work);
    }
    // (γ already carries the Baumgarte terms: the sparse path ran first)
    // S = G M⁻¹ Gᵀ, rhs = γ - G u̇_free
    for r in 0..nc {
        for c in 0..nc {
            let mut s = 0.0;
            for i in 0..nu {
                s += data.g[(r, i)] * data.minv_gt[c * nu + i];
            }
            data.schur[r * nc + c] = s;
        }
        let mut gu = 0.0;
        for i in 0..nu {
            gu += data.g[(r, i)] * data.udot[i];
        }
        data.lambda[r] = data.gamma[r] - gu;
    }
    data.constraint_rank = cholesky_semidefinite(&mut data.schur, nc, &mut data.perm_c, RANK_TOL);
    cholesky_semidefinite_solve(&data.schur, nc, &data.perm_c, data.constraint_rank, &mut data.lambda, &mut data.work);
    if data.constraint_rank < nc {
        min_norm_multipliers(data, nc);
    }
    for k in 0..nc {
        let l = data.lambda[k];
        for i in 0..nu {
            data.udot[i] += data.minv_gt[k * nu + i] * l;
        }
    }
    mark_dependent(data, nc);
    Ok(())
}

/// Dependent-row flags from the pivot order of a dense pivoted factorization of `data.schur`.
fn mark_dependent(data: &mut Data, nc: usize) {
    data.dependent.fill(false);
    for k in data.constraint_rank..nc {
        data.dependent[data.perm_c[k]] = true;
    }
}

/// Turns the basic solution λ of a rank-deficient `S λ = r` (dependent rows set to zero) into the
/// minimum-norm one by removing its component in the null space of S: with the pivoted factor
/// `[L11 0; L21 ~0]`, the null space is spanned by the columns of `N = [-L11⁻ᵀ L21ᵀ; E]`, and
/// `λ_min = λ - N (NᵀN)⁻¹ Nᵀ λ`. Redundant constraints then share their load equally.
fn min_norm_multipliers(data: &mut Data, nc: usize) {
    let r = data.constraint_rank;
    let k = nc - r;
    // λ in pivot order
    for i in 0..nc {
        data.work[i] = data.lambda[data.perm_c[i]];
    }
    // N (nc × k), column-major in null_basis
    for j in 0..k {
        let col = &mut data.null_basis[j * nc..(j + 1) * nc];
        // solve L11ᵀ x = L21[j, :]ᵀ by back substitution
        for i in (0..r).rev() {
            let mut s = data.schur[(r + j) * nc + i];
            for m in i + 1..r {
                s -= data.schur[m * nc + i] * col[m];
            }
            col[i] = s / data.schur[i * nc + i];
        }
        for v in col.iter_mut().take(r) {
            *v = -*v;
        }
        for (m, v) in col.iter_mut().enumerate().skip(r) {
            *v = if m == r + j { 1.0 } else { 0.0 };
        }
    }
    // (NᵀN) z = Nᵀ λ
    for a in 0..k {
        let mut c = 0.0;
        for i in 0..nc {
            c += data.null_basis[a * nc + i] * data.work[i];
        }
        data.work2[a] = c;
        for b in 0..k {
            let mut s = 0.0;
            for i in 0..nc {
                s += data.null_basis[a * nc + i] * data.null_basis[b * nc + i];
            }
            data.null_gram[a * k + b] = s;
        }
    }
    let mut perm = std::mem::take(&mut data.perm_null);
    let mut z = std::mem::take(&mut data.work2);
    let rank = cholesky_semidefinite(&mut data.null_gram[..k * k], k, &mut perm, RANK_TOL);
    let mut scratch = std::mem::take(&mut data.null_scratch);
    cholesky_semidefinite_solve(&data.null_gram[..k * k], k, &perm, rank, &mut z[..k], &mut scratch);
    for i in 0..nc {
        let mut s = 0.0;
        for a in 0..k {
            s += data.null_basis[a * nc + i] * z[a];
        }
        data.work[i] -= s;
    }
    for i in 0..nc {
        data.lambda[data.perm_c[i]] = data.work[i];
    }
    data.perm_null = perm;
    data.work2 = z;
    data.null_scratch = scratch;
}

/// Minimum-norm correction of a residual `r` (`data.work2[..nc]`): solves `(G Gᵀ) μ = r` and
/// writes `Gᵀ μ` into `data.scratch_u`, with G as last gathered into `sp`. Dependent rows
/// get zero. With `holonomic_only` the non-holonomic rows are left out (their rows of G count as
/// zero, so their μ is zero): the position Newton then solves only `Φ_h = 0` and is not restricted
/// by velocity-only rows. With `reuse`, the sparse factor of `G Gᵀ` from the previous call is kept
/// (a simplified Newton step: G moved by the last correction only, O(|Φ|)). Returns whether the
/// sparse factor was used (false: the dense pivoted one, for redundant rows; it is not kept).
fn min_norm_correction(model: &Model, data: &mut Data, sp: &mut Saddle, holonomic_only: bool, reuse: bool) -> bool {
    let (nu, nc) = (model.nu, model.nc);
    if holonomic_only {
        for con in &model.constraints {
            let rows = con.row + con.holonomic_rows()..con.row + con.rows();
            data.work2[rows.clone()].fill(0.0);
            sp.clear_rows(rows);
        }
    }
    for r in 0..nc {
        if data.skip_rows[r] {
            data.work2[r] = 0.0;
            sp.clear_rows(r..r + 1);
        }
    }
    let sparse = reuse || {
        sp.assemble_schur(false);
        sp.factor_schur(RANK_TOL) || {
            dense_gram_factor(model, data, holonomic_only);
            false
        }
    };
    if sparse {
        sp.solve_schur(&mut data.work2[..nc]);
        sp.gt_times(&data.work2[..nc], &mut data.scratch_u);
    } else {
        let mut rhs = std::mem::take(&mut data.work2);
        cholesky_semidefinite_solve(
            &data.schur,
            nc,
            &data.perm_c,
            data.constraint_rank,
            &mut rhs[..nc],
            &mut data.work,
        );
        for i in 0..nu {
            let mut s = 0.0;
            for k in 0..nc {
                s += data.g[(k, i)] * rhs[k];
            }
            data.scratch_u[i] = s;
        }
        data.work2 = rhs;
    }
    sparse
}

/// Dense pivoted factor of `G Gᵀ` into `data.schur` (rank in `data.constraint_rank`).
fn dense_gram_factor(model: &Model, data: &mut Data, holonomic_only: bool) {
    let (nu, nc) = (model.nu, model.nc);
    for r in 0..nc {
        for c in 0..nc {
            let mut s = 0.0;
            for i in 0..nu {
                s += data.g[(r, i)] * data.g[(c, i)];
            }
            data.schur[r * nc + c] = s;
        }
    }
    if holonomic_only {
        for con in &model.constraints {
            for k in con.holonomic_rows()..con.rows() {
                let r = con.row + k;
                for c in 0..nc {
                    data.schur[r * nc + c] = 0.0;
                    data.schur[c * nc + r] = 0.0;
                }
            }
        }
    }
    for r in 0..nc {
        if data.skip_rows[r] {
            for c in 0..nc {
                data.schur[r * nc + c] = 0.0;
                data.schur[c * nc + r] = 0.0;
            }
        }
    }
    data.constraint_rank = cholesky_semidefinite(&mut data.schur, nc, &mut data.perm_c, RANK_TOL);
}

/// Projects (q, u) at time t onto `Φ(q, t) = 0` and `G u = b`: Newton iterations with minimum-norm
/// corrections (the pseudo-inverse relation of eq. 2.68) over the holonomic rows only, then one
/// velocity correction over all rows (holonomic and non-holonomic).
pub fn project(
    model: &Model,
    data: &mut Data,
    ws: &mut Workspace,
    t: f64,
    q: &mut [f64],
    u: &mut [f64],
    cb: &dyn Callbacks,
) -> Result<()> {
    let sp = &mut ws.saddle;
    let nc = model.nc;
    if nc == 0 {
        return Ok(());
    }
    // one factor of G Gᵀ serves every Newton step and, when every row is holonomic, the velocity
    // correction too: G changes between them only by the O(|Φ|) position corrections
    let all_holonomic = model.constraints.iter().all(|c| c.holonomic_rows() == c.rows());
    let mut factor = false;
    let mut factor_far = false;
    let mut converged = false;
    let mut worst = (0.0, 0usize);
    // rows near a singular configuration are left out (`data.skip_rows`): the frozen factor would
    // not know about them
    let skipping = data.skip_rows.iter().any(|s| *s);
    for _ in 0..20 {
        crate::kinematics::positions(model, data, q);
        constraints::positions(model, data, t, q, cb)?;
        let skip = &data.skip_rows;
        worst = data.phi.iter().enumerate().filter(|(k, _)| !skip[*k]).fold((0.0, 0), |w, (k, v)| {
            if v.abs() > w.0 {
                (v.abs(), k)
            } else {
                w
            }
        });
        if worst.0 <= 1e-13 {
            converged = true;
            break;
        }
        data.work2[..nc].copy_from_slice(&data.phi);
        sp.gather_g(&data.g);
        // a frozen factor only for the small corrections after a step; full Newton from afar
        let small = worst.0 < 1e-8;
        let used = min_norm_correction(model, data, sp, true, small && factor && !skipping);
        // keep only a well-conditioned sparse factor: with nearly dependent rows (a redundancy that
        // is exact only on the manifold) a frozen factor amplifies the change of G
        factor = used && sp.well_conditioned(1e-8);
        // a factor taken far from the manifold does not serve the velocity correction
        factor_far = !small;
        // Δu = -Gᵀ μ, applied on the configuration manifold
        for v in data.scratch_u.iter_mut() {
            *v = -*v;
        }
        data.q_tmp.copy_from_slice(q);
        model.integrate(&data.q_tmp, &data.scratch_u, 1.0, q);
    }
    if !converged && worst.0 > 1e-8 {
        let name = model.constraints.iter().rev().find(|c| c.row <= worst.1).map_or("?", |c| c.name.as_str());
        return Err(Error::Solver(format!(
            "constraint '{name}' cannot be satisfied at t = {t:.6} s (violation {:.3e}): the mechanism does not close",
            worst.0
        )));
    }
    // velocities: u ← u - Gᵀ (G Gᵀ)⁺ (G u - b), with G at the projected q
    sp.gather_g(&data.g);
    let mut r = std::mem::take(&mut data.work2);
    sp.g_times(u, &mut r[..nc]);
    for k in 0..nc {
        r[k] -= data.b[k];
    }
    data.work2 = r;
    min_norm_correction(model, data, sp, false, all_holonomic && !factor_far && factor && !skipping);
    for (v, d) in u.iter_mut().zip(&data.scratch_u) {
        *v -= d;
    }
    Ok(())
}

/// `x ← M̃⁻¹ x`: the accelerations a generalized force `x` causes under the bilateral
/// constraints (`M⁻¹ x` restricted to their tangent space through the factored Schur complement
/// in `sp`); `lambda`, if given, receives the multipliers it adds. `data.work2` is scratch.
pub(crate) fn tangent_inverse_mass(
    data: &mut Data,
    sp: &mut Saddle,
    nc: usize,
    x: &mut [f64],
    lambda: Option<&mut [f64]>,
) {
    sp.solve_mass(x);
    if nc > 0 {
        let mut y = std::mem::take(&mut data.work2);
        y.resize(nc.max(y.len()), 0.0);
        sp.g_times(x, &mut y[..nc]);
        for v in y[..nc].iter_mut() {
            *v = -*v;
        }
        sp.solve_schur(&mut y[..nc]);
        sp.add_constraint_accelerations(&y[..nc], x);
        if let Some(l) = lambda {
            for k in 0..nc {
                l[k] += y[k];
            }
        }
        data.work2 = y;
    }
}
