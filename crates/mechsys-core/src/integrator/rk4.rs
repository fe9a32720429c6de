//! Classical fixed-step Runge–Kutta of order 4. Output times must lie on the step grid
//! (the caller chooses the output interval as a multiple of the step). A state with unit
//! quaternions is stepped on the rotation group (RKMK, [`super::lie_group`]).

use super::lie_group::Chart;
use super::{check_finite, Observer, OdeSystem, Stats};
use crate::error::{Error, Result};

/// Integrates with steps of `dt`; observes at each `t_out` (which must be multiples of `dt` from t0).
pub fn integrate<S: OdeSystem>(
    sys: &mut S,
    t0: f64,
    y0: &[f64],
    dt: f64,
    t_out: &[f64],
    obs: &mut Observer<'_, S>,
) -> Result<Stats> {
    if !(dt.is_finite() && dt > 0.0) {
        return Err(Error::Settings(format!("integrator.dt: must be > 0, got {dt}")));
    }
    let n = sys.dim();
    let chart = Chart::new(n, sys.quaternions());
    if !chart.is_flat() {
        return integrate_on_group(sys, &chart, t0, y0, dt, t_out, obs);
    }
    let mut y = y0.to_vec();
    let (mut k1, mut k2, mut k3, mut k4, mut tmp) =
        (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut stats = Stats::default();
    // output index at each step number
    let mut next = 0usize;
    let mut step = 0u64;
    let t_last = *t_out.last().unwrap_or(&t0);
    let n_steps = ((t_last - t0) / dt - 1e-9).ceil().max(0.0) as u64;
    loop {
        let t = t0 + step as f64 * dt;
        sys.rhs(t, &y, &mut k1)?;
        stats.evaluations += 1;
        while next < t_out.len() && t_out[next] <= t + 1e-9 * dt {
            obs(sys, t, &y, true)?;
            next += 1;
        }
        if step >= n_steps || next >= t_out.len() {
            break;
        }
        let h = dt;
        for i in 0..n {
            tmp[i] = y[i] + 0.5 * h * k1[i];
        }
        sys.rhs(t + 0.5 * h, &tmp, &mut k2)?;
        for i in 0..n {
            tmp[i] = y[i] + 0.5 * h * k2[i];
        }
        sys.rhs(t + 0.5 * h, &tmp, &mut k3)?;
        for i in 0..n {
            tmp[i] = y[i] + h * k3[i];
        }
        sys.rhs(t + h, &tmp, &mut k4)?;
        stats.evaluations += 3;
        for i in 0..n {
            y[i] += h / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
        }
        sys.project(t + h, &mut y)?;
        check_finite(t + h, &y)?;
        sys.accepted(t + h, &mut y)?;
        step += 1;
        stats.steps += 1;
    }
    Ok(stats)
}

/// [`integrate`] in the chart's local coordinates: each stage at `y ⊕ z_i` with
/// `z_i = h Σ a_ij k_j`, the rates `k_i` pulled back by `J_r⁻¹`, the step's end `y ⊕ h Σ b_i k_i`.
fn integrate_on_group<S: OdeSystem>(
    sys: &mut S,
    chart: &Chart,
    t0: f64,
    y0: &[f64],
    dt: f64,
    t_out: &[f64],
    obs: &mut Observer<'_, S>,
) -> Result<Stats> {
    let (n, nl) = (sys.dim(), chart.local_dim());
    let mut y = y0.to_vec();
    let (mut tmp, mut fy) = (vec![0.0; n], vec![0.0; n]);
    let (mut k1, mut k2, mut k3, mut k4, mut z) = (vec![0.0; nl], vec![0.0; nl], vec![0.0; nl], vec![0.0; nl], vec![0.0; nl]);
    let mut stats = Stats::default();
    let mut next = 0usize;
    let mut step = 0u64;
    let t_last = *t_out.last().unwrap_or(&t0);
    let n_steps = ((t_last - t0) / dt - 1e-9).ceil().max(0.0) as u64;
    loop {
        let t = t0 + step as f64 * dt;
        sys.rhs(t, &y, &mut fy)?;
        chart.tangent0(&y, &fy, &mut k1);
        stats.evaluations += 1;
        while next < t_out.len() && t_out[next] <= t + 1e-9 * dt {
            obs(sys, t, &y, true)?;
            next += 1;
        }
        if step >= n_steps || next >= t_out.len() {
            break;
        }
        let h = dt;
        let mut stage = |c: f64, k_prev: &[f64], k: &mut [f64]| -> Result<()> {
            for i in 0..nl {
                z[i] = c * h * k_prev[i];
            }
            chart.retract(&y, &z, &mut tmp);
            sys.rhs(t + c * h, &tmp, &mut fy)?;
            chart.tangent(&tmp, &z, &fy, k);
            Ok(())
        };
        stage(0.5, &k1, &mut k2)?;
        stage(0.5, &k2, &mut k3)?;
        stage(1.0, &k3, &mut k4)?;
        stats.evaluations += 3;
        for i in 0..nl {
            z[i] = h / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
        }
        chart.retract(&y, &z, &mut tmp);
        std::mem::swap(&mut y, &mut tmp);
        sys.project(t + h, &mut y)?;
        check_finite(t + h, &y)?;
        sys.accepted(t + h, &mut y)?;
        step += 1;
        stats.steps += 1;
    }
    Ok(stats)
}
