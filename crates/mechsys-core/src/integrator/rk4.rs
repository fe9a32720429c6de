//! Classical fixed-step Runge–Kutta of order 4. Output times must lie on the step grid
//! (the caller chooses the output interval as a multiple of the step). A state with unit
//! quaternions is stepped on the rotation group (RKMK, [`super::lie_group`]).

use super::lie_group::Chart;
use super::{check_finite, Observer, OdeSystem, Stats};
use crate::error::{Error, Result};

/// Most switches one step is split at.
const MAX_SPLITS: usize = 16;

/// Stages 2–4 of the step `h` from (t, y) with `k1 = f(t, y)`.
fn stages<S: OdeSystem>(
    sys: &mut S,
    t: f64,
    y: &[f64],
    h: f64,
    k1: &[f64],
    (k2, k3, k4): (&mut [f64], &mut [f64], &mut [f64]),
    tmp: &mut [f64],
) -> Result<()> {
    let n = y.len();
    for i in 0..n {
        tmp[i] = y[i] + 0.5 * h * k1[i];
    }
    sys.rhs(t + 0.5 * h, tmp, k2)?;
    for i in 0..n {
        tmp[i] = y[i] + 0.5 * h * k2[i];
    }
    sys.rhs(t + 0.5 * h, tmp, k3)?;
    for i in 0..n {
        tmp[i] = y[i] + h * k3[i];
    }
    sys.rhs(t + h, tmp, k4)
}

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
    let (mut k1, mut k2, mut k3, mut k4, mut tmp, mut ynew) =
        (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut switches = super::switching::Locator::new(sys);
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
        // a step across a switch (a compliant contact's onset) is split there: substeps up to
        // just past each switch found on the continuous extension, then the rest of the step
        let (mut tt, mut rem, mut splits) = (t, h, 0);
        loop {
            if splits > 0 {
                sys.rhs(tt, &y, &mut k1)?;
                stats.evaluations += 1;
            }
            stages(sys, tt, &y, rem, &k1, (&mut k2, &mut k3, &mut k4), &mut tmp)?;
            stats.evaluations += 3;
            for i in 0..n {
                ynew[i] = y[i] + rem / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
            }
            if splits < MAX_SPLITS {
                let (a, b, c, d) = (&k1, &k2, &k3, &k4);
                let yy = &y;
                let dense = |th: f64, out: &mut [f64]| {
                    // the continuous extension of order 3 (Hairer, Nørsett, Wanner II.6)
                    let (t2, t3) = (th * th, th * th * th);
                    let w1 = th - 1.5 * t2 + 2.0 / 3.0 * t3;
                    let w23 = t2 - 2.0 / 3.0 * t3;
                    let w4 = -0.5 * t2 + 2.0 / 3.0 * t3;
                    for i in 0..n {
                        out[i] = yy[i] + rem * (w1 * a[i] + w23 * (b[i] + c[i]) + w4 * d[i]);
                    }
                };
                if let Some(th) = switches.locate(sys, tt, rem, &y, &ynew, dense)? {
                    let h1 = th * rem;
                    stages(sys, tt, &y, h1, &k1, (&mut k2, &mut k3, &mut k4), &mut tmp)?;
                    stats.evaluations += 3;
                    for i in 0..n {
                        y[i] += h1 / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
                    }
                    sys.project(tt + h1, &mut y)?;
                    check_finite(tt + h1, &y)?;
                    sys.accepted(tt + h1, &mut y)?;
                    (tt, rem, splits) = (tt + h1, rem - h1, splits + 1);
                    stats.steps += 1;
                    continue;
                }
            }
            y.copy_from_slice(&ynew);
            break;
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
    let (mut tmp, mut fy, mut ynew) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let (mut k1, mut k2, mut k3, mut k4, mut z, mut zl) =
        (vec![0.0; nl], vec![0.0; nl], vec![0.0; nl], vec![0.0; nl], vec![0.0; nl], vec![0.0; nl]);
    let mut switches = super::switching::Locator::new(sys);
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
        // split at switches as the flat scheme does, the continuous extension in the chart
        let (mut tt, mut rem, mut splits) = (t, h, 0);
        loop {
            if splits > 0 {
                sys.rhs(tt, &y, &mut fy)?;
                chart.tangent0(&y, &fy, &mut k1);
                stats.evaluations += 1;
            }
            group_stages(sys, chart, tt, &y, rem, &k1, (&mut k2, &mut k3, &mut k4), (&mut z, &mut tmp, &mut fy))?;
            stats.evaluations += 3;
            for i in 0..nl {
                z[i] = rem / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
            }
            chart.retract(&y, &z, &mut ynew);
            if splits < MAX_SPLITS {
                let (a, b, c, d, yy, zl) = (&k1, &k2, &k3, &k4, &y, &mut zl);
                let dense = |th: f64, out: &mut [f64]| {
                    let (t2, t3) = (th * th, th * th * th);
                    let (w1, w23, w4) =
                        (th - 1.5 * t2 + 2.0 / 3.0 * t3, t2 - 2.0 / 3.0 * t3, -0.5 * t2 + 2.0 / 3.0 * t3);
                    for i in 0..nl {
                        zl[i] = rem * (w1 * a[i] + w23 * (b[i] + c[i]) + w4 * d[i]);
                    }
                    chart.retract(yy, zl, out);
                };
                if let Some(th) = switches.locate(sys, tt, rem, &y, &ynew, dense)? {
                    let h1 = th * rem;
                    group_stages(
                        sys,
                        chart,
                        tt,
                        &y,
                        h1,
                        &k1,
                        (&mut k2, &mut k3, &mut k4),
                        (&mut z, &mut tmp, &mut fy),
                    )?;
                    stats.evaluations += 3;
                    for i in 0..nl {
                        z[i] = h1 / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
                    }
                    chart.retract(&y, &z, &mut tmp);
                    std::mem::swap(&mut y, &mut tmp);
                    sys.project(tt + h1, &mut y)?;
                    check_finite(tt + h1, &y)?;
                    sys.accepted(tt + h1, &mut y)?;
                    (tt, rem, splits) = (tt + h1, rem - h1, splits + 1);
                    stats.steps += 1;
                    continue;
                }
            }
            std::mem::swap(&mut y, &mut ynew);
            break;
        }
        sys.project(t + h, &mut y)?;
        check_finite(t + h, &y)?;
        sys.accepted(t + h, &mut y)?;
        step += 1;
        stats.steps += 1;
    }
    Ok(stats)
}

/// The stages k2..k4 of a step `h` from (t, y) on the group, `k1` given: each at `y ⊕ c h k_prev`,
/// pulled back into the chart.
#[allow(clippy::too_many_arguments)]
fn group_stages<S: OdeSystem>(
    sys: &mut S,
    chart: &Chart,
    t: f64,
    y: &[f64],
    h: f64,
    k1: &[f64],
    (k2, k3, k4): (&mut [f64], &mut [f64], &mut [f64]),
    (z, tmp, fy): (&mut [f64], &mut [f64], &mut [f64]),
) -> Result<()> {
    let mut stage = |c: f64, k_prev: &[f64], k: &mut [f64]| -> Result<()> {
        for (zi, kp) in z.iter_mut().zip(k_prev) {
            *zi = c * h * kp;
        }
        chart.retract(y, z, tmp);
        sys.rhs(t + c * h, tmp, fy)?;
        chart.tangent(tmp, z, fy, k);
        Ok(())
    };
    stage(0.5, k1, k2)?;
    stage(0.5, k2, k3)?;
    stage(1.0, k3, k4)
}
