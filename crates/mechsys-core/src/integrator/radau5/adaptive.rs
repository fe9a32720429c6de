//! Adaptive steps of Radau IIA (see the parent module for the method and its references).

use super::coefficients;
use crate::error::{Error, Result};
use crate::integrator::lie_group::Chart;
use crate::integrator::{check_finite, Observer, OdeSystem, Stats};
use crate::math::linalg::{lu_factor, lu_factor_complex, lu_solve, lu_solve_complex};

/// Most Newton iterations per step (HW's NIT).
const NIT: usize = 7;
/// Newton stops at η ‖ΔZ‖ ≤ KAPPA · fnewt (smaller values, down to 0.01, changed neither the
/// errors nor the steps of the tests measurably; they cost iterations).
const KAPPA: f64 = 1.0;
/// Below this contraction rate Newton counts as fast: the Jacobian is kept for the next step.
const THETA_REUSE: f64 = 1e-3;
/// Safety factor of the step-size controller.
const SAFE: f64 = 0.9;
/// Bounds of the step-size factor per step.
const FAC_MIN: f64 = 0.2;
const FAC_MAX: f64 = 8.0;
/// A proposed growth below this factor keeps h (and the factorizations).
const KEEP_BELOW: f64 = 1.2;

/// The method's constants, derived once from its Butcher matrix (not tabulated, so that the unit
/// tests check the derivation against the literature's values).
pub(crate) struct Tableau {
    pub c: [f64; 3],
    /// Real eigenvalue γ of A⁻¹ and its complex pair α ± iβ.
    pub gamma: f64,
    pub alpha: f64,
    pub beta: f64,
    /// A⁻¹ = T Λ T⁻¹ with Λ = [γ 0 0; 0 α −β; 0 β α].
    pub t: [[f64; 3]; 3],
    pub ti: [[f64; 3]; 3],
    /// γ e_j: weights of the stage increments in the error estimate, err = (γ/h − J)⁻¹
    /// [f(t₀, y₀) + Σ_j dd_j Z_j / h] (eq. 8.20 divided by h γ₀).
    pub dd: [f64; 3],
}

fn inverse3(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut inv = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            // cofactor of (j, i), by cyclic indices
            let (r1, r2, c1, c2) = ((j + 1) % 3, (j + 2) % 3, (i + 1) % 3, (i + 2) % 3);
            inv[i][j] = m[r1][c1] * m[r2][c2] - m[r1][c2] * m[r2][c1];
        }
    }
    let det: f64 = (0..3).map(|k| m[0][k] * inv[k][0]).sum();
    inv.iter_mut().flatten().for_each(|v| *v /= det);
    inv
}

impl Tableau {
    pub fn new() -> Self {
        let (a, c) = coefficients();
        let m = inverse3(&a);
        // characteristic polynomial λ³ − p1 λ² + p2 λ − p3 of A⁻¹
        let p1 = m[0][0] + m[1][1] + m[2][2];
        let p2 = m[0][0] * m[1][1] - m[0][1] * m[1][0] + m[0][0] * m[2][2] - m[0][2] * m[2][0] + m[1][1] * m[2][2]
            - m[1][2] * m[2][1];
        let p3 = 1.0
            / (a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
                + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]));
        // the real root by Newton from above (the cubic is convex and increasing right of it)
        let mut gamma = p1;
        for _ in 0..100 {
            let g = ((gamma - p1) * gamma + p2) * gamma - p3;
            let dg = (3.0 * gamma - 2.0 * p1) * gamma + p2;
            let step = g / dg;
            gamma -= step;
            if step.abs() <= 1e-16 * gamma.abs() {
                break;
            }
        }
        // the quadratic factor λ² − (p1 − γ) λ + p3/γ
        let alpha = 0.5 * (p1 - gamma);
        let beta = (p3 / gamma - alpha * alpha).sqrt();
        // eigenvectors as cross products of two rows of (A⁻¹ − λ I)
        let row = |r: usize, lr: f64, li: f64| -> [(f64, f64); 3] {
            let mut v = [(0.0, 0.0); 3];
            for k in 0..3 {
                v[k] = (m[r][k] - if k == r { lr } else { 0.0 }, if k == r { -li } else { 0.0 });
            }
            v
        };
        let mul = |x: (f64, f64), y: (f64, f64)| (x.0 * y.0 - x.1 * y.1, x.0 * y.1 + x.1 * y.0);
        let cross = |u: [(f64, f64); 3], v: [(f64, f64); 3]| -> [(f64, f64); 3] {
            let mut w = [(0.0, 0.0); 3];
            for k in 0..3 {
                let (i, j) = ((k + 1) % 3, (k + 2) % 3);
                let (p, q) = (mul(u[i], v[j]), mul(u[j], v[i]));
                w[k] = (p.0 - q.0, p.1 - q.1);
            }
            w
        };
        let v = cross(row(0, gamma, 0.0), row(1, gamma, 0.0));
        let w = cross(row(0, alpha, beta), row(1, alpha, beta));
        // A⁻¹ w = (α + iβ) w gives A⁻¹ [Re w, −Im w] = [Re w, −Im w] [α −β; β α]
        let mut t = [[0.0; 3]; 3];
        for k in 0..3 {
            t[k] = [v[k].0, w[k].0, -w[k].1];
        }
        let ti = inverse3(&t);
        // embedded order-3 weights b̂ with the extra node 0 of weight γ₀ = 1/γ:
        // Σ b̂_i c_i^k = 1/(k+1) − γ₀ [k = 0], k = 0, 1, 2 (a Vandermonde system)
        let mut vm = [0.0; 9];
        let mut bh = [1.0 - 1.0 / gamma, 0.5, 1.0 / 3.0];
        for k in 0..3 {
            for i in 0..3 {
                vm[k * 3 + i] = c[i].powi(k as i32);
            }
        }
        let mut piv = [0; 3];
        lu_factor(&mut vm, 3, &mut piv).expect("distinct nodes");
        lu_solve(&vm, 3, &piv, &mut bh);
        // ŷ − y = γ₀ h f₀ + Σ_i (b̂_i − b_i) h f_i and h F = (A⁻¹ ⊗ I) Z: e = (b̂ − b)ᵀ A⁻¹
        let mut dd = [0.0; 3];
        for j in 0..3 {
            dd[j] = gamma * (0..3).map(|i| (bh[i] - a[2][i]) * m[i][j]).sum::<f64>();
        }
        Tableau { c, gamma, alpha, beta, t, ti, dd }
    }

    /// Weights w_i(θ) of the collocation polynomial u(t₀ + θh) = y₀ + Σ w_i(θ) Z_i (Lagrange on
    /// the nodes 0, c₁, c₂, c₃; θ beyond 1 extrapolates into the next step).
    pub fn collocation_weights(&self, th: f64) -> [f64; 3] {
        let nodes = [0.0, self.c[0], self.c[1], self.c[2]];
        let mut w = [1.0; 3];
        for i in 0..3 {
            for (k, &x) in nodes.iter().enumerate() {
                if k != i + 1 {
                    w[i] *= (th - x) / (self.c[i] - x);
                }
            }
        }
        w
    }
}

/// The adaptive scheme's working memory, made once per run. `n` is the number of local
/// coordinates of the state's chart (on the rotation group with quaternions in the state):
/// stages, Jacobian, error and Newton scale live there, states (`tmp`, `ynew`, `yout`) on the group.
struct Adaptive {
    n: usize,
    chart: Chart,
    tab: Tableau,
    /// ∂f/∂y (n × n), at the start of the step where it was last evaluated.
    jac: Vec<f64>,
    /// γ/h − J and its factors (n × n).
    e1: Vec<f64>,
    piv1: Vec<usize>,
    /// (α + iβ)/h − J and its factors (n × n, real and imaginary parts).
    e2r: Vec<f64>,
    e2i: Vec<f64>,
    piv2: Vec<usize>,
    /// Stage increments Z_i = Y_i − y₀ (3n), their transform W = (T⁻¹ ⊗ I) Z, the Newton
    /// correction, the stage derivatives, and Z of the last accepted step.
    z: Vec<f64>,
    w: Vec<f64>,
    dw: Vec<f64>,
    f: Vec<f64>,
    z_prev: Vec<f64>,
    /// f(t₀, y₀), a stage state, a derivative, the error vector, y₁, the Newton scale, an output.
    f0: Vec<f64>,
    tmp: Vec<f64>,
    fy: Vec<f64>,
    err: Vec<f64>,
    ynew: Vec<f64>,
    scal: Vec<f64>,
    yout: Vec<f64>,
    /// The state's rates (full size) and a local increment, for the chart.
    fe: Vec<f64>,
    zl: Vec<f64>,
}

impl Adaptive {
    fn new(chart: Chart, nfull: usize) -> Self {
        let v = |k: usize| vec![0.0; k];
        let n = chart.local_dim();
        Adaptive {
            n,
            chart,
            fe: v(nfull),
            zl: v(n),
            tab: Tableau::new(),
            jac: v(n * n),
            e1: v(n * n),
            piv1: vec![0; n],
            e2r: v(n * n),
            e2i: v(n * n),
            piv2: vec![0; n],
            z: v(3 * n),
            w: v(3 * n),
            dw: v(3 * n),
            f: v(3 * n),
            z_prev: v(3 * n),
            f0: v(n),
            tmp: v(nfull),
            fy: v(n),
            err: v(n),
            ynew: v(nfull),
            scal: v(n),
            yout: v(nfull),
        }
    }

    /// `f0 = f(t, y)` in local coordinates.
    fn rate0<S: OdeSystem>(&mut self, sys: &mut S, t: f64, y: &[f64]) -> Result<()> {
        sys.rhs(t, y, &mut self.fe)?;
        self.chart.tangent0(y, &self.fe, &mut self.f0);
        Ok(())
    }

    /// ∂f/∂z at (t, y), z = 0, by forward differences (`f0 = f(t, y)`).
    fn jacobian<S: OdeSystem>(&mut self, sys: &mut S, t: f64, y: &[f64]) -> Result<()> {
        let n = self.n;
        self.zl.fill(0.0);
        for j in 0..n {
            let d = 1.5e-8 * self.chart.magnitude(j, y, y).max(1e-5);
            self.zl[j] = d;
            self.chart.retract(y, &self.zl, &mut self.tmp);
            sys.rhs(t, &self.tmp, &mut self.fe)?;
            self.chart.tangent(&self.tmp, &self.zl, &self.fe, &mut self.fy);
            self.zl[j] = 0.0;
            for i in 0..n {
                self.jac[i * n + j] = (self.fy[i] - self.f0[i]) / d;
            }
        }
        Ok(())
    }

    /// Factors γ/h − J and (α + iβ)/h − J; false if either is singular.
    fn factor(&mut self, h: f64) -> bool {
        let n = self.n;
        let (g, al, be) = (self.tab.gamma / h, self.tab.alpha / h, self.tab.beta / h);
        for i in 0..n {
            for j in 0..n {
                let (jij, diag) = (self.jac[i * n + j], i == j);
                self.e1[i * n + j] = if diag { g - jij } else { -jij };
                self.e2r[i * n + j] = if diag { al - jij } else { -jij };
                self.e2i[i * n + j] = if diag { be } else { 0.0 };
            }
        }
        lu_factor(&mut self.e1, n, &mut self.piv1).is_ok()
            && lu_factor_complex(&mut self.e2r, &mut self.e2i, n, &mut self.piv2).is_ok()
    }

    /// Starting values of Z for a step of h: the last step's collocation polynomial (of step
    /// h_prev) extrapolated, or zero without one.
    fn start(&mut self, h: f64, h_prev: Option<f64>) {
        let n = self.n;
        let Some(hp) = h_prev else {
            self.z.fill(0.0);
            self.w.fill(0.0);
            return;
        };
        for s in 0..3 {
            // u_prev(1 + c_s h / h_prev) − y₀ with y₀ = u_prev(1) = y_prev + Z_prev,3
            let wt = self.tab.collocation_weights(1.0 + self.tab.c[s] * h / hp);
            for i in 0..n {
                let zp = &self.z_prev;
                self.z[s * n + i] = wt[0] * zp[i] + wt[1] * zp[n + i] + (wt[2] - 1.0) * zp[2 * n + i];
            }
        }
        transform(&self.tab.ti, &self.z, &mut self.w, n);
    }

    /// Simplified Newton on the stage equations from the current Z. Ok(iterations, θ) when
    /// converged, Err(factor for h) when it fails or is predicted to.
    #[allow(clippy::too_many_arguments)]
    fn newton<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        t: f64,
        y: &[f64],
        h: f64,
        fnewt: f64,
        eta: &mut f64,
        stats: &mut Stats,
    ) -> Result<std::result::Result<(usize, f64), f64>> {
        let n = self.n;
        let tab = &self.tab;
        let (g, al, be) = (tab.gamma / h, tab.alpha / h, tab.beta / h);
        let m = (3 * n).max(1) as f64;
        *eta = eta.max(f64::EPSILON).powf(0.8);
        let (mut theta, mut norm_old, mut q_old) = (THETA_REUSE, 0.0, 0.0);
        for k in 0..NIT {
            for s in 0..3 {
                let zs = &self.z[s * n..(s + 1) * n];
                self.chart.retract(y, zs, &mut self.tmp);
                sys.rhs(t + tab.c[s] * h, &self.tmp, &mut self.fe)?;
                self.chart.tangent(&self.tmp, zs, &self.fe, &mut self.f[s * n..(s + 1) * n]);
            }
            stats.evaluations += 3;
            // eq. 8.16: (Λ/h ⊗ I − I ⊗ J) ΔW = (T⁻¹ ⊗ I) F − (Λ/h ⊗ I) W
            for i in 0..n {
                let (f1, f2, f3) = (self.f[i], self.f[n + i], self.f[2 * n + i]);
                let (w1, w2, w3) = (self.w[i], self.w[n + i], self.w[2 * n + i]);
                let tf = |r: usize| tab.ti[r][0] * f1 + tab.ti[r][1] * f2 + tab.ti[r][2] * f3;
                self.dw[i] = tf(0) - g * w1;
                self.dw[n + i] = tf(1) - (al * w2 - be * w3);
                self.dw[2 * n + i] = tf(2) - (be * w2 + al * w3);
            }
            lu_solve(&self.e1, n, &self.piv1, &mut self.dw[..n]);
            let (re, im) = self.dw[n..].split_at_mut(n);
            lu_solve_complex(&self.e2r, &self.e2i, n, &self.piv2, re, im);
            // ΔZ = (T ⊗ I) ΔW, measured in the scaled norm, and the update
            let mut sum = 0.0;
            for i in 0..n {
                let (d1, d2, d3) = (self.dw[i], self.dw[n + i], self.dw[2 * n + i]);
                for s in 0..3 {
                    let dz = tab.t[s][0] * d1 + tab.t[s][1] * d2 + tab.t[s][2] * d3;
                    self.z[s * n + i] += dz;
                    sum += (dz / self.scal[i]).powi(2);
                }
                self.w[i] += d1;
                self.w[n + i] += d2;
                self.w[2 * n + i] += d3;
            }
            let norm = (sum / m).sqrt();
            if !norm.is_finite() {
                return Ok(Err(0.5));
            }
            if k >= 1 {
                let q = norm / norm_old;
                // the rate over the last two iterations once there are two (smoother)
                theta = if k == 1 { q } else { (q * q_old).sqrt() };
                q_old = q;
                if theta >= 0.99 {
                    return Ok(Err(0.5));
                }
                *eta = theta / (1.0 - theta);
                // the error left after the remaining iterations at this rate (eq. 8.12)
                let rest = (NIT - 1 - k) as i32;
                let predicted = *eta * norm * theta.powi(rest) / fnewt;
                if predicted >= 1.0 {
                    let qn = predicted.clamp(1e-4, 20.0);
                    return Ok(Err(0.8 * qn.powf(-1.0 / (4.0 + rest as f64))));
                }
            }
            norm_old = norm;
            if *eta * norm <= KAPPA * fnewt {
                return Ok(Ok((k + 1, theta)));
            }
        }
        Ok(Err(0.5))
    }

    /// The scaled norm of the error estimate (eq. 8.20), refined once more if `refine` and > 1.
    #[allow(clippy::too_many_arguments)]
    fn error<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        t: f64,
        y: &[f64],
        h: f64,
        rtol: f64,
        atol: f64,
        refine: bool,
        stats: &mut Stats,
    ) -> Result<f64> {
        let n = self.n;
        let dd = self.tab.dd;
        let norm = |w: &Self| -> f64 {
            let sum: f64 = (0..n)
                .map(|i| {
                    let sc = atol + rtol * w.chart.magnitude_step(i, y, w.z[2 * n + i]);
                    (w.err[i] / sc).powi(2)
                })
                .sum();
            (sum / n.max(1) as f64).sqrt()
        };
        // Σ dd_j Z_j / h, kept in ynew (free until the step is accepted)
        for i in 0..n {
            self.ynew[i] = (dd[0] * self.z[i] + dd[1] * self.z[n + i] + dd[2] * self.z[2 * n + i]) / h;
            self.err[i] = self.f0[i] + self.ynew[i];
        }
        lu_solve(&self.e1, n, &self.piv1, &mut self.err);
        let mut e = norm(self);
        if refine && e >= 1.0 {
            // the estimate through one more evaluation: bounded as h·λ → ∞ (stiff components)
            self.chart.retract(y, &self.err, &mut self.tmp);
            sys.rhs(t, &self.tmp, &mut self.fe)?;
            self.chart.tangent(&self.tmp, &self.err, &self.fe, &mut self.fy);
            stats.evaluations += 1;
            for i in 0..n {
                self.err[i] = self.fy[i] + self.ynew[i];
            }
            lu_solve(&self.e1, n, &self.piv1, &mut self.err);
            e = norm(self);
        }
        Ok(e)
    }
}

/// out = (P ⊗ I) v for a 3 × 3 P and v of three blocks of n.
fn transform(p: &[[f64; 3]; 3], v: &[f64], out: &mut [f64], n: usize) {
    for i in 0..n {
        let (a, b, c) = (v[i], v[n + i], v[2 * n + i]);
        for r in 0..3 {
            out[r * n + i] = p[r][0] * a + p[r][1] * b + p[r][2] * c;
        }
    }
}

/// Adaptive integration; `max_step = 0` means unlimited, `first_step = 0` means automatic.
#[allow(clippy::too_many_arguments)]
pub fn integrate_adaptive<S: OdeSystem>(
    sys: &mut S,
    t0: f64,
    y0: &[f64],
    t_out: &[f64],
    rtol: f64,
    atol: f64,
    max_step: f64,
    first_step: f64,
    obs: &mut Observer<'_, S>,
) -> Result<Stats> {
    let nfull = sys.dim();
    let t_end = *t_out.last().unwrap_or(&t0);
    let hmax = if max_step > 0.0 { max_step } else { (t_end - t0).abs().max(f64::MIN_POSITIVE) };
    let mut stats = Stats::default();
    let mut wk = Adaptive::new(Chart::new(nfull, sys.quaternions()), nfull);
    let n = wk.n;
    let mut y = y0.to_vec();
    let mut t = t0;
    let mut next = 0usize;

    wk.rate0(sys, t, &y)?;
    stats.evaluations += 1;
    while next < t_out.len() && t_out[next] <= t {
        obs(sys, t, &y, true)?;
        next += 1;
    }
    if next >= t_out.len() {
        return Ok(stats);
    }
    let mut h = if first_step > 0.0 {
        first_step.min(hmax)
    } else {
        stats.evaluations += 1;
        crate::integrator::dopri5::starting_step_on(
            sys,
            &wk.chart,
            t,
            &y,
            &wk.f0,
            (rtol, atol, hmax),
            (&mut wk.tmp, &mut wk.fe, &mut wk.zl, &mut wk.fy),
        )?
    };
    // Newton's tolerance relative to the error tolerance (HW's fnewt)
    let fnewt = (10.0 * f64::EPSILON / rtol).max(0.03f64.min(rtol.sqrt()));
    let mut eta = 1.0; // η of the last Newton iteration, carried into the next step
    let mut jac_here = false; // the Jacobian was evaluated at the current (t, y)
    let mut need_jac = true;
    let mut h_lu = f64::NAN; // the step the factorizations belong to
    let mut h_prev: Option<f64> = None; // the last accepted step (for the starting values)
    let (mut first, mut reject) = (true, false);
    let (mut h_acc, mut err_acc) = (0.0, 0.0); // Gustafsson's memory
    let mut singular = 0u32;
    let mut switches = crate::integrator::switching::Locator::new(sys);
    let mut located: Option<f64> = None; // the step wanted before one was cut at a switch
    let mut retaken = f64::NAN; // the step size of an attempt retaken at a switch (not searched again)

    loop {
        if t_end - t <= 1e-13 * t.abs().max(1.0) {
            // rounding left a sliver: the remaining outputs are at the current state
            while next < t_out.len() {
                obs(sys, t_out[next], &y, false)?;
                next += 1;
            }
            break;
        }
        if !(h >= crate::integrator::step_floor(t, t0, t_end)) {
            return Err(Error::Solver(format!(
                "step size underflow at t = {t:.6} s (h = {h:.3e}) in radau5: Newton does not converge or the error \
                 estimate cannot be met; the model may be singular or discontinuous there"
            )));
        }
        // the last step reaches t_end exactly (stretched by up to 1 % rather than leave a sliver)
        if t + 1.01 * h >= t_end {
            h = t_end - t;
        }
        if need_jac {
            wk.jacobian(sys, t, &y)?;
            stats.evaluations += n;
            stats.jacobians += 1;
            (need_jac, jac_here) = (false, true);
            h_lu = f64::NAN;
        }
        if h != h_lu {
            if !wk.factor(h) {
                // a singular iteration matrix: another step size moves γ/h, α/h off J's spectrum
                singular += 1;
                if singular > 5 {
                    return Err(Error::Solver(format!(
                        "radau5: the iteration matrix is singular at t = {t:.6} s for 6 step sizes down to h = {h:.3e}"
                    )));
                }
                stats.rejected += 1;
                h *= 0.5;
                reject = true;
                h_lu = f64::NAN;
                continue;
            }
            singular = 0;
            h_lu = h;
        }
        wk.start(h, h_prev);
        for i in 0..n {
            wk.scal[i] = atol + rtol * wk.chart.magnitude(i, &y, &y);
        }
        sys.switched(); // only the stages of this attempt count, not the difference quotients
        let (iters, theta) = match wk.newton(sys, t, &y, h, fnewt, &mut eta, &mut stats)? {
            Ok(it) => it,
            Err(factor) => {
                stats.rejected += 1;
                h *= factor;
                reject = true;
                need_jac = !jac_here;
                continue;
            }
        };
        let err = wk.error(sys, t, &y, h, rtol, atol, first || reject, &mut stats)?;
        if !err.is_finite() {
            // an evaluation produced inf/NaN: shrink hard and retry (max() below would hide it)
            stats.rejected += 1;
            h *= 0.1;
            reject = true;
            need_jac = !jac_here;
            continue;
        }
        let err = err.max(1e-10);
        // eq. 8.25 with a safety factor that shrinks with the Newton iterations spent
        let fac = SAFE.min(SAFE * (1 + 2 * NIT) as f64 / (iters + 2 * NIT) as f64);
        let mut quot = (err.powf(0.25) / fac).clamp(1.0 / FAC_MAX, 1.0 / FAC_MIN);
        if err >= 1.0 {
            stats.rejected += 1;
            h = if first { 0.1 * h } else { h / quot };
            reject = true;
            need_jac = !jac_here;
            continue;
        }
        // a switch the error estimate cannot see (a slider's reversal inside the step): shrink
        // the step around it until it is below the tolerance's share of the span
        if sys.switched() && h > rtol * (t_end - t0) {
            stats.rejected += 1;
            h *= 0.25;
            reject = true;
            continue;
        }
        if !first {
            // Gustafsson's predictive controller: also from the last accepted step's history
            let gus = (h_acc / h * (err * err / err_acc).powf(0.25) / SAFE).clamp(1.0 / FAC_MAX, 1.0 / FAC_MIN);
            quot = quot.max(gus);
        }
        // accepted: y₁ = y₀ + Z₃ (stiffly accurate)
        let t_new = t + h;
        wk.chart.retract(&y, &wk.z[2 * n..], &mut wk.ynew);
        if h != retaken {
            // a switch inside the step (a compliant contact's onset): retaken up to just past it;
            // the collocation polynomial in the chart's local coordinates, retracted
            let (tab, z, chart, zl) = (&wk.tab, &wk.z, &wk.chart, &mut wk.zl);
            let yy = &y;
            let dense = |th: f64, out: &mut [f64]| {
                let wt = tab.collocation_weights(th);
                for i in 0..n {
                    zl[i] = wt[0] * z[i] + wt[1] * z[n + i] + wt[2] * z[2 * n + i];
                }
                chart.retract(yy, zl, out);
            };
            if let Some(th) = switches.locate(sys, t, h, &y, &wk.ynew, dense)? {
                located.get_or_insert(h);
                h *= th;
                retaken = h;
                continue;
            }
        }
        (h_acc, err_acc) = (h, err.max(1e-2));
        sys.project(t_new, &mut wk.ynew)?;
        check_finite(t_new, &wk.ynew)?;
        {
            // between the step's ends: the collocation polynomial through the stages
            let (tab, z, chart, zl) = (&wk.tab, &wk.z, &wk.chart, &mut wk.zl);
            let yy = &y;
            next = crate::integrator::step_outputs(sys, obs, t_out, next, t, h, &wk.ynew, &mut wk.yout, |th, out| {
                let wt = tab.collocation_weights(th);
                for i in 0..n {
                    zl[i] = wt[0] * z[i] + wt[1] * z[n + i] + wt[2] * z[2 * n + i];
                }
                chart.retract(yy, zl, out);
            })?;
        }
        sys.accepted(t_new, &mut wk.ynew)?;
        stats.steps += 1;
        t = t_new;
        std::mem::swap(&mut y, &mut wk.ynew);
        std::mem::swap(&mut wk.z, &mut wk.z_prev);
        h_prev = Some(h);
        if next >= t_out.len() || t >= t_end {
            break;
        }
        wk.rate0(sys, t, &y)?;
        stats.evaluations += 1;
        let mut h_new = (h / quot).min(hmax);
        if reject {
            h_new = h_new.min(h);
        }
        (first, reject, jac_here) = (false, false, false);
        if theta <= THETA_REUSE {
            // Newton converged fast with this Jacobian: keep it, and keep h (and the factors)
            // unless the step would grow by more than a little
            if (1.0..=KEEP_BELOW).contains(&(h_new / h)) {
                h_new = h;
            }
        } else {
            need_jac = true;
        }
        if let Some(wanted) = located.take() {
            h_new = wanted.min(hmax);
        }
        h = h_new;
    }
    Ok(stats)
}
