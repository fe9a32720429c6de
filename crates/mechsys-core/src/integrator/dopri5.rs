//! Dormand–Prince 5(4): explicit Runge–Kutta pair with local error control (the 5th-order
//! solution is propagated, the embedded 4th-order one estimates the error), first-same-as-last,
//! and the continuous extension of order 4 (Hairer, Nørsett, Wanner, *Solving ODEs I*, II.5–II.6)
//! for output at any requested time without shortening steps. Unit quaternions in the state are
//! stepped on the rotation group (RKMK, [`super::lie_group`]).

use super::lie_group::Chart;
use super::{check_finite, Observer, OdeSystem, Stats};
use crate::error::{Error, Result};

const C2: f64 = 1.0 / 5.0;
const C3: f64 = 3.0 / 10.0;
const C4: f64 = 4.0 / 5.0;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
// error coefficients: 5th-order minus 4th-order weights
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
// dense output
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

/// One Dormand–Prince step with its stages and dense-output coefficients, reusable by drivers
/// that need more than [`integrate`] (the event-driven scheme locates roots on the dense output).
/// On a state with unit quaternions ([`Step::on_group`]) the stages, the error estimate and the
/// dense output live in the local coordinates of [`Chart`] (RKMK), the states on the group.
pub(crate) struct Step {
    n: usize,
    chart: Chart,
    /// Stages (local coordinates); `k[0]` must hold `f(t, y)` before [`Step::attempt`] (see
    /// [`Step::first_rate`]), `k[6]` holds `f(t + h, y_new)` after it (first same as last);
    /// `k[7]` holds the same rate in the chart centred at `y_new` (on the group).
    pub k: Vec<Vec<f64>>,
    tmp: Vec<f64>,
    /// The 5th-order solution of the last attempt.
    pub ynew: Vec<f64>,
    r: Vec<Vec<f64>>,
    /// On the group: the state's rates of the last evaluation, the local increment of the
    /// stage or step, the step's start (dense output) and the dense output's local point.
    fy: Vec<f64>,
    z: Vec<f64>,
    ybase: Vec<f64>,
    zd: std::cell::RefCell<Vec<f64>>,
}

impl Step {
    /// A step on the state of `n` components laid out by `chart`.
    pub fn on_group(chart: Chart, n: usize) -> Self {
        let nl = chart.local_dim();
        let group = !chart.is_flat();
        let m = if group { n } else { 0 };
        Step {
            n,
            k: vec![vec![0.0; nl]; 8],
            tmp: vec![0.0; n],
            ynew: vec![0.0; n],
            r: vec![vec![0.0; nl]; 5],
            fy: vec![0.0; m],
            z: vec![0.0; if group { nl } else { 0 }],
            ybase: vec![0.0; m],
            zd: std::cell::RefCell::new(vec![0.0; if group { nl } else { 0 }]),
            chart,
        }
    }

    /// Evaluates `k[0] = f(t, y)` (in local coordinates on the group).
    pub fn first_rate<S: OdeSystem>(&mut self, sys: &mut S, t: f64, y: &[f64]) -> Result<()> {
        if self.chart.is_flat() {
            sys.rhs(t, y, &mut self.k[0])
        } else {
            sys.rhs(t, y, &mut self.fy)?;
            self.chart.tangent0(y, &self.fy, &mut self.k[0]);
            Ok(())
        }
    }

    /// Tries the step `[t, t + h]` from `y`; returns the scaled error norm (≤ 1 accepts).
    pub fn attempt<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        t: f64,
        y: &[f64],
        h: f64,
        rtol: f64,
        atol: f64,
    ) -> Result<f64> {
        if !self.chart.is_flat() {
            return self.attempt_on_group(sys, t, y, h, rtol, atol);
        }
        let n = self.n;
        let (k, tmp) = (&mut self.k, &mut self.tmp);
        macro_rules! stage {
            ($dst:expr, $c:expr, $($a:expr => $ki:expr),+) => {{
                for i in 0..n {
                    tmp[i] = y[i] + h * (0.0 $(+ $a * k[$ki][i])+);
                }
                let (_, tail) = k.split_at_mut($dst);
                sys.rhs(t + $c * h, tmp, &mut tail[0])?;
            }};
        }
        stage!(1, C2, A21 => 0);
        stage!(2, C3, A31 => 0, A32 => 1);
        stage!(3, C4, A41 => 0, A42 => 1, A43 => 2);
        stage!(4, C5, A51 => 0, A52 => 1, A53 => 2, A54 => 3);
        stage!(5, 1.0, A61 => 0, A62 => 1, A63 => 2, A64 => 3, A65 => 4);
        for i in 0..n {
            self.ynew[i] = y[i] + h * (A71 * k[0][i] + A73 * k[2][i] + A74 * k[3][i] + A75 * k[4][i] + A76 * k[5][i]);
        }
        sys.rhs(t + h, &self.ynew, &mut k[6])?;
        let mut err = 0.0;
        for i in 0..n {
            let e = h * (E1 * k[0][i] + E3 * k[2][i] + E4 * k[3][i] + E5 * k[4][i] + E6 * k[5][i] + E7 * k[6][i]);
            let sc = atol + rtol * y[i].abs().max(self.ynew[i].abs());
            err += (e / sc).powi(2);
        }
        Ok((err / n.max(1) as f64).sqrt())
    }

    /// [`Step::attempt`] in the chart centred at `y`: stages at `y ⊕ z_i`, `z_i = h Σ a_ij k_j`.
    fn attempt_on_group<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        t: f64,
        y: &[f64],
        h: f64,
        rtol: f64,
        atol: f64,
    ) -> Result<f64> {
        let nl = self.chart.local_dim();
        let (k, tmp, z, fy, chart) = (&mut self.k, &mut self.tmp, &mut self.z, &mut self.fy, &self.chart);
        macro_rules! stage {
            ($dst:expr, $c:expr, $($a:expr => $ki:expr),+) => {{
                for i in 0..nl {
                    z[i] = h * (0.0 $(+ $a * k[$ki][i])+);
                }
                chart.retract(y, z, tmp);
                sys.rhs(t + $c * h, tmp, fy)?;
                chart.tangent(tmp, z, fy, &mut k[$dst]);
            }};
        }
        stage!(1, C2, A21 => 0);
        stage!(2, C3, A31 => 0, A32 => 1);
        stage!(3, C4, A41 => 0, A42 => 1, A43 => 2);
        stage!(4, C5, A51 => 0, A52 => 1, A53 => 2, A54 => 3);
        stage!(5, 1.0, A61 => 0, A62 => 1, A63 => 2, A64 => 3, A65 => 4);
        for i in 0..nl {
            z[i] = h * (A71 * k[0][i] + A73 * k[2][i] + A74 * k[3][i] + A75 * k[4][i] + A76 * k[5][i]);
        }
        chart.retract(y, z, &mut self.ynew);
        sys.rhs(t + h, &self.ynew, fy)?;
        chart.tangent(&self.ynew, z, fy, &mut k[6]);
        chart.tangent0(&self.ynew, fy, &mut k[7]);
        let mut err = 0.0;
        for i in 0..nl {
            let e = h * (E1 * k[0][i] + E3 * k[2][i] + E4 * k[3][i] + E5 * k[4][i] + E6 * k[5][i] + E7 * k[6][i]);
            let sc = atol + rtol * chart.magnitude(i, y, &self.ynew);
            err += (e / sc).powi(2);
        }
        Ok((err / nl.max(1) as f64).sqrt())
    }

    /// Dense-output coefficients of the accepted step `[t, t + h]` from `y` (before [`Step::fsal`]).
    pub fn prepare_dense(&mut self, y: &[f64], h: f64) {
        let group = !self.chart.is_flat();
        if group {
            self.ybase.copy_from_slice(y);
        }
        let (k, r) = (&self.k, &mut self.r);
        for i in 0..self.chart.local_dim() {
            // on the group the interpolant runs from z = 0 to the step's increment z
            let (y0, ydiff) = if group { (0.0, self.z[i]) } else { (y[i], self.ynew[i] - y[i]) };
            let bspl = h * k[0][i] - ydiff;
            r[0][i] = y0;
            r[1][i] = ydiff;
            r[2][i] = bspl;
            r[3][i] = ydiff - h * k[6][i] - bspl;
            r[4][i] = h * (D1 * k[0][i] + D3 * k[2][i] + D4 * k[3][i] + D5 * k[4][i] + D6 * k[5][i] + D7 * k[6][i]);
        }
    }

    /// The continuous extension at `θ ∈ [0, 1]` of the step prepared by [`Step::prepare_dense`].
    pub fn dense(&self, th: f64, out: &mut [f64]) {
        let (r, th1) = (&self.r, 1.0 - th);
        if self.chart.is_flat() {
            for i in 0..self.n {
                out[i] = r[0][i] + th * (r[1][i] + th1 * (r[2][i] + th * (r[3][i] + th1 * r[4][i])));
            }
            return;
        }
        let mut zd = self.zd.borrow_mut();
        for (i, v) in zd.iter_mut().enumerate() {
            *v = r[0][i] + th * (r[1][i] + th1 * (r[2][i] + th * (r[3][i] + th1 * r[4][i])));
        }
        self.chart.retract(&self.ybase, &zd, out);
    }

    /// Makes the last stage the first of the next step (first same as last; on the group the
    /// rate in the chart centred at the new state).
    pub fn fsal(&mut self) {
        let last = if self.chart.is_flat() { 6 } else { 7 };
        self.k.swap(0, last);
    }

    /// Hairer's starting step ([`starting_step_on`]) in the step's coordinates.
    pub(crate) fn starting_step<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        t: f64,
        y: &[f64],
        rtol: f64,
        atol: f64,
        hmax: f64,
    ) -> Result<f64> {
        let (k0, rest) = self.k.split_at_mut(1);
        if self.chart.is_flat() {
            return starting_step(sys, t, y, &k0[0], rtol, atol, hmax, (&mut self.tmp, &mut rest[0]));
        }
        let scratch = (&mut self.tmp[..], &mut self.fy[..], &mut self.z[..], &mut rest[0][..]);
        starting_step_on(sys, &self.chart, t, y, &k0[0], (rtol, atol, hmax), scratch)
    }
}

/// [`starting_step`] of a state on the chart `chart` (`k0 = f(t, y)` in its local coordinates);
/// scratch: a state, its rates, a local increment and local rates.
pub(crate) fn starting_step_on<S: OdeSystem>(
    sys: &mut S,
    chart: &Chart,
    t: f64,
    y: &[f64],
    k0: &[f64],
    (rtol, atol, hmax): (f64, f64, f64),
    (tmp, fy, z, k1): (&mut [f64], &mut [f64], &mut [f64], &mut [f64]),
) -> Result<f64> {
    let nl = chart.local_dim();
    let sc = |i: usize| atol + rtol * chart.magnitude(i, y, y);
    let norm =
        |v: &dyn Fn(usize) -> f64| ((0..nl).map(|i| (v(i) / sc(i)).powi(2)).sum::<f64>() / nl.max(1) as f64).sqrt();
    let (d0, d1) = (norm(&|i| chart.magnitude(i, y, y)), norm(&|i| k0[i]));
    let h0 = if d0 < 1e-5 || d1 < 1e-5 { 1e-6 } else { 0.01 * d0 / d1 };
    let h0 = h0.min(hmax);
    for i in 0..nl {
        z[i] = h0 * k0[i];
    }
    chart.retract(y, z, tmp);
    sys.rhs(t + h0, tmp, fy)?;
    chart.tangent(tmp, z, fy, k1);
    let d2 = norm(&|i| k1[i] - k0[i]) / h0;
    let h1 = if d1.max(d2) <= 1e-15 { (h0 * 1e-3).max(1e-6) } else { (0.01 / d1.max(d2)).powf(0.2) };
    Ok((100.0 * h0).min(h1).min(hmax))
}

/// Hairer's starting step from the sizes of y and f (`k0 = f(t, y)`).
#[allow(clippy::too_many_arguments)]
pub(crate) fn starting_step<S: OdeSystem>(
    sys: &mut S,
    t: f64,
    y: &[f64],
    k0: &[f64],
    rtol: f64,
    atol: f64,
    hmax: f64,
    scratch: (&mut [f64], &mut [f64]),
) -> Result<f64> {
    let n = y.len();
    let norm = |v: &[f64]| -> f64 {
        (v.iter().zip(y).map(|(a, b)| (a / (atol + rtol * b.abs())).powi(2)).sum::<f64>() / n.max(1) as f64).sqrt()
    };
    let (d0, d1) = (norm(y), norm(k0));
    let h0 = if d0 < 1e-5 || d1 < 1e-5 { 1e-6 } else { 0.01 * d0 / d1 };
    let h0 = h0.min(hmax);
    let (tmp, k1) = scratch;
    for i in 0..n {
        tmp[i] = y[i] + h0 * k0[i];
    }
    sys.rhs(t + h0, tmp, k1)?;
    let d2 = k1.iter().zip(k0).zip(y).map(|((a, b), yy)| ((a - b) / (atol + rtol * yy.abs())).powi(2)).sum::<f64>();
    let d2 = (d2 / n.max(1) as f64).sqrt() / h0;
    let h1 = if d1.max(d2) <= 1e-15 { (h0 * 1e-3).max(1e-6) } else { (0.01 / d1.max(d2)).powf(0.2) };
    Ok((100.0 * h0).min(h1).min(hmax))
}

/// The PI controller's factor for the next step (β = 0.04) after an accepted step with error `err`.
pub(crate) fn next_factor(err: f64, err_old: f64, rejected: bool) -> f64 {
    let fac = (0.9 * err.max(1e-10).powf(-0.17) * err_old.powf(0.04)).clamp(0.2, 10.0);
    if rejected {
        fac.min(1.0)
    } else {
        fac
    }
}

/// Adaptive integration; `max_step = 0` means unlimited, `first_step = 0` means automatic.
#[allow(clippy::too_many_arguments)]
pub fn integrate<S: OdeSystem>(
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
    if !(rtol > 0.0 && rtol.is_finite() && atol > 0.0 && atol.is_finite()) {
        return Err(Error::Settings(format!("integrator: rtol and atol must be > 0, got rtol={rtol}, atol={atol}")));
    }
    if !(max_step >= 0.0 && first_step >= 0.0) {
        return Err(Error::Settings("integrator: max_step and first_step must be >= 0".into()));
    }
    let n = sys.dim();
    let t_end = *t_out.last().unwrap_or(&t0);
    let hmax = if max_step > 0.0 { max_step } else { (t_end - t0).abs().max(f64::MIN_POSITIVE) };
    let mut stats = Stats::default();
    let mut y = y0.to_vec();
    let mut st = Step::on_group(Chart::new(n, sys.quaternions()), n);
    let mut yout = vec![0.0; n];
    let mut t = t0;
    let mut next = 0usize;

    st.first_rate(sys, t, &y)?;
    stats.evaluations += 1;
    while next < t_out.len() && t_out[next] <= t {
        obs(sys, t, &y, true)?;
        next += 1;
    }
    if next >= t_out.len() {
        return Ok(stats);
    }
    let mut h = if first_step > 0.0 {
        first_step
    } else {
        stats.evaluations += 1;
        st.starting_step(sys, t, &y, rtol, atol, hmax)?
    };
    let mut err_old: f64 = 1e-4;
    let mut reject = false;
    // steps retaken to end just past a switch: the step the controller wanted before
    let mut switches = super::switching::Locator::new(sys);
    let mut located: Option<f64> = None;
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
        if h < super::step_floor(t, t0, t_end) {
            return Err(Error::Solver(format!(
                "step size underflow at t = {t:.6} s (h = {h:.3e}); the system may be stiff (use radau5) or singular"
            )));
        }
        if t + h > t_end {
            h = t_end - t;
        }
        let err = st.attempt(sys, t, &y, h, rtol, atol)?;
        stats.evaluations += 6;
        // a switch the error estimate cannot see (a slider's reversal inside the step): shrink the
        // step around it until it is below the tolerance's share of the span
        if sys.switched() && err <= 1.0 && h > rtol * (t_end - t0) {
            stats.rejected += 1;
            h *= 0.25;
            reject = true;
            continue;
        }
        if !err.is_finite() {
            // a stage produced inf/NaN: shrink hard and retry
            stats.rejected += 1;
            h *= 0.1;
            reject = true;
            continue;
        }
        if err <= 1.0 {
            st.prepare_dense(&y, h);
            if h != retaken {
                if let Some(th) = switches.locate(sys, t, h, &y, &st.ynew, |th, out| st.dense(th, out))? {
                    located.get_or_insert(h);
                    h *= th;
                    retaken = h;
                    continue;
                }
            }
            let t_new = t + h;
            sys.project(t_new, &mut st.ynew)?;
            check_finite(t_new, &st.ynew)?;
            next = super::step_outputs(sys, obs, t_out, next, t, h, &st.ynew, &mut yout, |th, out| st.dense(th, out))?;
            sys.accepted(t_new, &mut st.ynew)?;
            stats.steps += 1;
            t = t_new;
            std::mem::swap(&mut y, &mut st.ynew);
            st.fsal();
            if next >= t_out.len() || t >= t_end {
                break;
            }
            h = (h * next_factor(err, err_old, reject)).min(hmax);
            if let Some(wanted) = located.take() {
                h = wanted.min(hmax);
            }
            err_old = err.max(1e-4);
            reject = false;
        } else {
            stats.rejected += 1;
            reject = true;
            h *= (0.9 * err.powf(-0.2)).max(0.2);
        }
    }
    Ok(stats)
}
