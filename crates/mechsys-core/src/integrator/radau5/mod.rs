//! Radau IIA with three stages (order 5, stiffly accurate, L-stable), at a fixed step or with
//! adaptive steps under error control.
//!
//! Why this scheme for stiff spring–damper systems: L-stability damps the parasitic fast modes of
//! stiff springs completely instead of letting them ring (as the trapezoidal rule would), order 5
//! keeps the slow motion accurate at large steps, and being a collocation method on the first-order
//! form it needs no special treatment of the q̇ = H*(q) u kinematics, unlike generalized-α.
//!
//! **Fixed step** (`dt`): the stage equations are solved by simplified Newton on the 3n × 3n
//! iteration matrix I − h A ⊗ J with a finite-difference Jacobian at the step start; if Newton
//! does not converge the step is split in halves (up to 2⁸ pieces). A step across a switch (a
//! compliant contact's onset, release or force cut-off, [`crate::integrator::switching`]) is
//! split there as well: the switch is located on the collocation polynomial, the step retaken up
//! to just past it, then the rest of the step (up to 16 splits per step), so no step straddles
//! the kink and the outputs stay on the `dt` grid.
//!
//! **Adaptive** (`rtol`, `atol`; Hairer & Wanner, *Solving ODEs II*, section IV.8):
//! - the iteration matrix is brought to block-diagonal form by the eigen-decomposition
//!   A⁻¹ = T Λ T⁻¹ (one real eigenvalue γ, one complex pair α ± iβ), so each Newton iteration
//!   solves one real n × n system (γ/h − J) and one complex one ((α + iβ)/h − J) (eq. 8.16);
//! - Newton is watched through its contraction rate θ_k = ‖ΔZ_k‖ / ‖ΔZ_{k−1}‖ in the norm scaled
//!   by sc_i = atol + rtol |y_i|; it stops when η_k ‖ΔZ_k‖ ≤ κ · fnewt with η_k = θ_k / (1 − θ_k)
//!   (eq. 8.10–8.12) and gives up (smaller step) when θ ≥ 1 or when the rate predicts no
//!   convergence within the allowed iterations;
//! - its starting values extrapolate the previous step's collocation polynomial;
//! - the error estimate is the embedded order-3 solution filtered through (I − h γ₀ J)⁻¹ with
//!   γ₀ = 1/γ (eq. 8.19–8.20), evaluated once more at y₀ + err on the first step and after
//!   rejections (where stiff components would spoil the plain estimate);
//! - the step size follows h · err^(−1/4) with a safety factor that shrinks with the Newton
//!   iterations spent and Gustafsson's predictive controller (eq. 8.25);
//! - the Jacobian is kept while Newton converges fast (θ small), and recomputed after rejections;
//! - dense output: the collocation polynomial through (0, y₀), (c_i, y₀ + Z_i).

mod adaptive;

pub use adaptive::integrate_adaptive;
#[cfg(test)]
pub(crate) use adaptive::Tableau;

use super::lie_group::Chart;
use super::{check_finite, IntegratorKind, Observer, OdeSystem, Stats};
use crate::error::{Error, Result};
use crate::math::linalg::{lu_factor, lu_solve};

struct Work {
    /// Local coordinates of the state (on the rotation group with quaternions in it).
    chart: Chart,
    jac: Vec<f64>,
    iter: Vec<f64>,
    piv: Vec<usize>,
    z: Vec<f64>,
    dz: Vec<f64>,
    f: Vec<f64>,
    f0: Vec<f64>,
    tmp: Vec<f64>,
    fy: Vec<f64>,
    backup: Vec<f64>,
    /// The state's rates (n) and a local increment (nl), for the chart.
    fe: Vec<f64>,
    zl: Vec<f64>,
    /// The collocation polynomial's local increment at a point of the step (nl), for the search.
    zp: Vec<f64>,
    /// The switch search.
    switches: crate::integrator::switching::Locator,
}

/// Most splits of one fixed step at switches.
const MAX_SPLITS: u32 = 16;

pub(crate) fn coefficients() -> ([[f64; 3]; 3], [f64; 3]) {
    let s6 = 6f64.sqrt();
    let a = [
        [(88.0 - 7.0 * s6) / 360.0, (296.0 - 169.0 * s6) / 1800.0, (-2.0 + 3.0 * s6) / 225.0],
        [(296.0 + 169.0 * s6) / 1800.0, (88.0 + 7.0 * s6) / 360.0, (-2.0 - 3.0 * s6) / 225.0],
        [(16.0 - s6) / 36.0, (16.0 + s6) / 36.0, 1.0 / 9.0],
    ];
    let c = [(4.0 - s6) / 10.0, (4.0 + s6) / 10.0, 1.0];
    (a, c)
}

/// One step of size h from (t, y) into `y` (in place); Err on Newton failure. The stages are
/// `y ⊕ Z_i` in the chart's local coordinates (RKMK on a state with quaternions).
fn step<S: OdeSystem>(
    sys: &mut S,
    w: &mut Work,
    t: f64,
    y: &mut [f64],
    h: f64,
    tol: f64,
    stats: &mut Stats,
) -> Result<bool> {
    let n = w.chart.local_dim();
    let (a, c) = coefficients();
    // Jacobian ∂f/∂z at z = 0 by forward differences
    sys.rhs(t, y, &mut w.fe)?;
    w.chart.tangent0(y, &w.fe, &mut w.f0);
    stats.evaluations += 1;
    w.zl.fill(0.0);
    for j in 0..n {
        let d = 1.5e-8 * w.chart.magnitude(j, y, y).max(1e-5);
        w.zl[j] = d;
        w.chart.retract(y, &w.zl, &mut w.tmp);
        sys.rhs(t, &w.tmp, &mut w.fe)?;
        w.chart.tangent(&w.tmp, &w.zl, &w.fe, &mut w.fy);
        w.zl[j] = 0.0;
        for i in 0..n {
            w.jac[i * n + j] = (w.fy[i] - w.f0[i]) / d;
        }
    }
    stats.evaluations += n;
    stats.jacobians += 1;
    // iteration matrix I - h A ⊗ J (3n × 3n)
    let m = 3 * n;
    for bi in 0..3 {
        for bj in 0..3 {
            for i in 0..n {
                for j in 0..n {
                    let v = -h * a[bi][bj] * w.jac[i * n + j] + if bi == bj && i == j { 1.0 } else { 0.0 };
                    w.iter[(bi * n + i) * m + bj * n + j] = v;
                }
            }
        }
    }
    if lu_factor(&mut w.iter, m, &mut w.piv).is_err() {
        return Ok(false);
    }
    w.z.iter_mut().for_each(|v| *v = 0.0);
    let mut last = f64::INFINITY;
    for _ in 0..12 {
        for s in 0..3 {
            let zs = &w.z[s * n..(s + 1) * n];
            w.chart.retract(y, zs, &mut w.tmp);
            sys.rhs(t + c[s] * h, &w.tmp, &mut w.fe)?;
            w.chart.tangent(&w.tmp, zs, &w.fe, &mut w.f[s * n..(s + 1) * n]);
        }
        stats.evaluations += 3;
        // residual -G(Z) = -Z + h (A ⊗ I) F
        for s in 0..3 {
            for i in 0..n {
                let mut r = -w.z[s * n + i];
                for q in 0..3 {
                    r += h * a[s][q] * w.f[q * n + i];
                }
                w.dz[s * n + i] = r;
            }
        }
        lu_solve(&w.iter, m, &w.piv, &mut w.dz);
        let mut nrm = 0.0f64;
        for k in 0..m {
            w.z[k] += w.dz[k];
            let sc = 1.0 + w.chart.magnitude(k % n, y, y);
            nrm = nrm.max(w.dz[k].abs() / sc);
        }
        if !nrm.is_finite() || nrm > 2.0 * last && last < 1.0 {
            return Ok(false);
        }
        if nrm <= tol {
            // stiffly accurate: y_new = y ⊕ Z_3 (accepted by the caller, after the switch search)
            w.tmp.copy_from_slice(y);
            w.chart.retract(&w.tmp, &w.z[2 * n..], y);
            sys.project(t + h, y)?;
            return Ok(true);
        }
        last = nrm;
    }
    Ok(false)
}

/// Lagrange weights at `th` of the collocation polynomial through (0, 0) and (c_i, Z_i).
fn collocation_weights(c: &[f64; 3], th: f64) -> [f64; 3] {
    let mut l = [0.0; 3];
    for i in 0..3 {
        let mut v = th / c[i];
        for j in 0..3 {
            if j != i {
                v *= (th - c[j]) / (c[i] - c[j]);
            }
        }
        l[i] = v;
    }
    l
}

/// One step of `h` from (t, y), split at Newton failures (`depth`) and, while `splits` allow,
/// at the first switch found on the collocation polynomial.
#[allow(clippy::too_many_arguments)]
fn advance<S: OdeSystem>(
    sys: &mut S,
    w: &mut Work,
    t: f64,
    y: &mut [f64],
    h: f64,
    tol: f64,
    depth: u32,
    splits: u32,
    stats: &mut Stats,
) -> Result<()> {
    w.backup.copy_from_slice(y);
    if step(sys, w, t, y, h, tol, stats)? {
        if splits < MAX_SPLITS && w.switches.active() {
            let n = w.chart.local_dim();
            let (_, c) = coefficients();
            let Work { chart, z, zp, backup, switches, .. } = &mut *w;
            let (z, chart, y0) = (&*z, &*chart, &*backup);
            let dense = |th: f64, out: &mut [f64]| {
                let l = collocation_weights(&c, th);
                for i in 0..n {
                    zp[i] = l[0] * z[i] + l[1] * z[n + i] + l[2] * z[2 * n + i];
                }
                chart.retract(y0, zp, out);
            };
            if let Some(th) = switches.locate(sys, t, h, y0, y, dense)? {
                // retaken up to just past the switch (no search there: the switch sits at its
                // end), then the rest of the step
                y.copy_from_slice(&w.backup);
                advance(sys, w, t, y, th * h, tol, depth, MAX_SPLITS, stats)?;
                return advance(sys, w, t + th * h, y, (1.0 - th) * h, tol, depth, splits + 1, stats);
            }
        }
        sys.accepted(t + h, y)?;
        stats.steps += 1;
        return Ok(());
    }
    y.copy_from_slice(&w.backup);
    stats.rejected += 1;
    if depth >= 8 {
        return Err(Error::Solver(format!(
            "radau5: Newton iteration did not converge at t = {t:.6} s even with step {h:.3e} s"
        )));
    }
    advance(sys, w, t, y, 0.5 * h, tol, depth + 1, splits, stats)?;
    advance(sys, w, t + 0.5 * h, y, 0.5 * h, tol, depth + 1, splits, stats)
}

/// Fixed-step integration with observations at `t_out` (multiples of `dt` from t0).
pub fn integrate_fixed<S: OdeSystem>(
    sys: &mut S,
    t0: f64,
    y0: &[f64],
    dt: f64,
    newton_tol: f64,
    t_out: &[f64],
    obs: &mut Observer<'_, S>,
) -> Result<Stats> {
    if !(dt.is_finite() && dt > 0.0) {
        return Err(Error::Settings(format!("integrator.dt: must be > 0, got {dt}")));
    }
    if !(newton_tol.is_finite() && newton_tol > 0.0) {
        return Err(Error::Settings(format!("integrator.newton_tol: must be > 0, got {newton_tol}")));
    }
    let nfull = sys.dim();
    let chart = Chart::new(nfull, sys.quaternions());
    let n = chart.local_dim();
    let mut w = Work {
        chart,
        jac: vec![0.0; n * n],
        iter: vec![0.0; 9 * n * n],
        piv: vec![0; 3 * n],
        z: vec![0.0; 3 * n],
        dz: vec![0.0; 3 * n],
        f: vec![0.0; 3 * n],
        f0: vec![0.0; n],
        tmp: vec![0.0; nfull],
        fy: vec![0.0; n],
        backup: vec![0.0; nfull],
        fe: vec![0.0; nfull],
        zl: vec![0.0; n],
        zp: vec![0.0; n],
        switches: crate::integrator::switching::Locator::new(sys),
    };
    let mut y = y0.to_vec();
    let mut stats = Stats::default();
    let t_last = *t_out.last().unwrap_or(&t0);
    let n_steps = ((t_last - t0) / dt - 1e-9).ceil().max(0.0) as u64;
    let mut next = 0;
    let mut step_no = 0u64;
    loop {
        let t = t0 + step_no as f64 * dt;
        while next < t_out.len() && t_out[next] <= t + 1e-9 * dt {
            obs(sys, t, &y, false)?;
            next += 1;
        }
        if step_no >= n_steps || next >= t_out.len() {
            break;
        }
        advance(sys, &mut w, t, &mut y, dt, newton_tol, 0, 0, &mut stats)?;
        check_finite(t + dt, &y)?;
        step_no += 1;
    }
    Ok(stats)
}

/// Checks the settings of [`IntegratorKind::Radau5`]; returns whether they ask for adaptive
/// steps (an `rtol`) rather than a fixed step (a `dt`).
pub(crate) fn check(kind: &IntegratorKind) -> Result<bool> {
    let IntegratorKind::Radau5 { dt, newton_tol, rtol, atol, max_step, first_step } = *kind else {
        return Err(Error::Settings("integrator: not radau5".into()));
    };
    let (fixed, adaptive) = (dt != 0.0, rtol != 0.0);
    if fixed && adaptive {
        return Err(Error::Settings(
            "integrator: give radau5 a step dt (fixed) or a tolerance rtol (adaptive), not both".into(),
        ));
    }
    if !fixed && !adaptive {
        return Err(Error::Settings(
            "integrator: give radau5 a step dt (fixed) or a tolerance rtol (adaptive), one of them (dt > 0 or rtol > 0)"
                .into(),
        ));
    }
    crate::ensure!(
        newton_tol.is_finite() && newton_tol > 0.0,
        Settings,
        "integrator.newton_tol: must be > 0, got {newton_tol}"
    );
    if fixed {
        crate::ensure!(dt.is_finite() && dt > 0.0, Settings, "integrator.dt: must be > 0, got {dt}");
        return Ok(false);
    }
    // below ~100 ε the error estimate is round-off: the step size collapses instead of converging
    crate::ensure!(
        rtol.is_finite() && (1e-14..1.0).contains(&rtol),
        Settings,
        "integrator.rtol: must be in [1e-14, 1) (below 1e-14 double precision cannot meet it; 1 and above \
         control nothing), got {rtol:e}"
    );
    crate::ensure!(atol.is_finite() && atol > 0.0, Settings, "integrator.atol: must be > 0, got {atol}");
    crate::ensure!(
        max_step.is_finite() && max_step >= 0.0,
        Settings,
        "integrator.max_step: must be >= 0, got {max_step}"
    );
    crate::ensure!(
        first_step.is_finite() && first_step >= 0.0,
        Settings,
        "integrator.first_step: must be >= 0, got {first_step}"
    );
    Ok(true)
}

/// Runs [`IntegratorKind::Radau5`]: fixed steps of `dt`, or adaptive steps under `rtol`, `atol`.
pub fn integrate<S: OdeSystem>(
    kind: &IntegratorKind,
    sys: &mut S,
    t0: f64,
    y0: &[f64],
    t_out: &[f64],
    obs: &mut Observer<'_, S>,
) -> Result<Stats> {
    let adaptive = check(kind)?;
    let IntegratorKind::Radau5 { dt, newton_tol, rtol, atol, max_step, first_step } = *kind else {
        unreachable!("checked above")
    };
    if adaptive {
        integrate_adaptive(sys, t0, y0, t_out, rtol, atol, max_step, first_step, obs)
    } else {
        integrate_fixed(sys, t0, y0, dt, newton_tol, t_out, obs)
    }
}
